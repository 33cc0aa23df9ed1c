"""Line-of-sight waypoint guidance and the mission file, without ROS.

A mission is a list of waypoints in ``odom`` (ENU; x seaward, mean waterline at
x = 0, land at x < 0; see dukw_sim.truth). Guidance follows the straight leg
from the previous waypoint (the start position for the first) to the next one:
it aims at the point ``lookahead_m`` ahead of the vehicle's projection on the
leg (line of sight), turns with a yaw rate proportional to the heading error,
and slows down while the heading error is large. A waypoint is reached inside
``acceptance_radius_m`` or once the vehicle has passed the end of its leg.
The mission ends DONE after the last waypoint, TIMEOUT after ``timeout_s``;
both command a stop.
"""
from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field
from enum import Enum
from pathlib import Path
from typing import Any, Mapping


from dukw_bringup.yaml_file import read_yaml
from dukw_common.config import ConfigError, default_config_path
from dukw_common.geometry import wrap_angle

MISSION_FILE = 'mission.yaml'


class MissionState(Enum):
    """Where a mission stands."""

    WAITING = 'waiting'    # no pose yet, or not started
    RUNNING = 'running'
    DONE = 'done'          # last waypoint reached
    TIMEOUT = 'timeout'    # timeout_s passed first
    ABORTED = 'aborted'    # stopped from outside (shutdown, operator)

    @property
    def finished(self) -> bool:
        """True once the mission has ended, one way or another."""
        return self not in (MissionState.WAITING, MissionState.RUNNING)


@dataclass(frozen=True)
class Waypoint:
    """A point to reach, and the speed of the leg that leads to it."""

    name: str
    x_m: float
    y_m: float
    speed_mps: float


@dataclass(frozen=True)
class StartPose:
    """Where the simulator puts the vehicle at the start (odom; the simulator starts on y = 0)."""

    x_m: float
    yaw_rad: float


@dataclass(frozen=True)
class SeaState:
    """The sea the simulator makes for the mission (irregular, from H1/3 and peak period)."""

    significant_height_m: float
    peak_period_s: float
    seed: int


@dataclass(frozen=True)
class MissionSpec:
    """A whole mission as config/mission.yaml describes it."""

    name: str
    start: StartPose
    sea: SeaState
    waypoints: tuple[Waypoint, ...]
    acceptance_radius_m: float
    lookahead_m: float
    timeout_s: float
    heading_gain_per_s: float
    max_yaw_rate_rps: float
    min_speed_fraction: float
    start_delay_s: float = 0.0

    def __post_init__(self) -> None:
        if not self.waypoints:
            raise ConfigError('mission: needs at least one waypoint')
        positive = {'acceptance_radius_m': self.acceptance_radius_m,
                    'lookahead_m': self.lookahead_m, 'timeout_s': self.timeout_s,
                    'heading_gain_per_s': self.heading_gain_per_s,
                    'max_yaw_rate_rps': self.max_yaw_rate_rps,
                    'sea.peak_period_s': self.sea.peak_period_s}
        for name, value in positive.items():
            if not value > 0.0:
                raise ConfigError(f'mission: {name} must be > 0, got {value}')
        if not 0.0 <= self.min_speed_fraction <= 1.0:
            raise ConfigError('mission: min_speed_fraction must be in [0, 1]')
        if self.start_delay_s < 0.0 or self.sea.significant_height_m < 0.0:
            raise ConfigError('mission: start_delay_s and sea.significant_height_m must be >= 0')
        for wp in self.waypoints:
            if not 0.0 < wp.speed_mps <= 2.0:
                raise ConfigError(f'mission: waypoint {wp.name!r} speed_mps must be in (0, 2]')

    def with_waypoints(self, count: int) -> 'MissionSpec':
        """The same mission cut to its first ``count`` waypoints (short test runs)."""
        if not 1 <= count <= len(self.waypoints):
            raise ConfigError(f'mission: cannot keep {count} of {len(self.waypoints)} waypoints')
        return MissionSpec(**{**self.__dict__, 'waypoints': self.waypoints[:count]})


def _number(tree: Mapping[str, Any], key: str, where: str) -> float:
    if key not in tree:
        raise ConfigError(f'mission: {where}{key} is missing')
    value = tree[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ConfigError(f'mission: {where}{key} must be a finite number, got {value!r}')
    return float(value)


def _mapping(tree: Mapping[str, Any], key: str) -> Mapping[str, Any]:
    value = tree.get(key)
    if not isinstance(value, Mapping):
        raise ConfigError(f'mission: {key} must be a mapping')
    return value


def parse_mission(doc: Any) -> MissionSpec:
    """Build a MissionSpec from the parsed YAML document (top-level key ``mission``)."""
    if not isinstance(doc, Mapping) or not isinstance(doc.get('mission'), Mapping):
        raise ConfigError('mission: the file needs a top-level "mission" mapping')
    tree = doc['mission']
    start, sea = _mapping(tree, 'start'), _mapping(tree, 'sea')
    raw_points = tree.get('waypoints')
    if not isinstance(raw_points, list):
        raise ConfigError('mission: waypoints must be a list')
    waypoints = []
    for i, point in enumerate(raw_points):
        if not isinstance(point, Mapping):
            raise ConfigError(f'mission: waypoint {i} must be a mapping')
        where = f'waypoints[{i}].'
        waypoints.append(Waypoint(str(point.get('name', f'wp{i}')), _number(point, 'x_m', where),
                                  _number(point, 'y_m', where),
                                  _number(point, 'speed_mps', where)))
    seed = sea.get('seed', 0)
    if isinstance(seed, bool) or not isinstance(seed, int):
        raise ConfigError(f'mission: sea.seed must be an integer, got {seed!r}')
    return MissionSpec(
        name=str(tree.get('name', 'mission')),
        start=StartPose(_number(start, 'x_m', 'start.'), _number(start, 'yaw_rad', 'start.')),
        sea=SeaState(_number(sea, 'significant_height_m', 'sea.'),
                     _number(sea, 'peak_period_s', 'sea.'), seed),
        waypoints=tuple(waypoints),
        acceptance_radius_m=_number(tree, 'acceptance_radius_m', ''),
        lookahead_m=_number(tree, 'lookahead_m', ''),
        timeout_s=_number(tree, 'timeout_s', ''),
        heading_gain_per_s=_number(tree, 'heading_gain_per_s', ''),
        max_yaw_rate_rps=_number(tree, 'max_yaw_rate_rps', ''),
        min_speed_fraction=_number(tree, 'min_speed_fraction', ''),
        start_delay_s=float(tree.get('start_delay_s', 0.0)),
    )


def default_mission_path() -> Path:
    """config/mission.yaml next to the stack's parameter file (source tree or installed)."""
    return default_config_path().parent / MISSION_FILE


def load_mission(path: str | Path | None = None) -> MissionSpec:
    """Read a mission file; raise ConfigError naming what is wrong."""
    path = Path(path) if path else default_mission_path()
    doc = read_yaml(path, 'mission file')
    return parse_mission(doc)


@dataclass(frozen=True)
class VelocityCommand:
    """What guidance asks of the controller (geometry_msgs/Twist linear.x, angular.z)."""

    speed_mps: float = 0.0
    yaw_rate_rps: float = 0.0


STOP = VelocityCommand()


@dataclass
class Progress:
    """The mission's progress, as published on ``mission/status`` (JSON)."""

    state: MissionState = MissionState.WAITING
    waypoint_index: int = 0
    waypoint_name: str = ''
    waypoints_total: int = 0
    distance_m: float = math.nan        # to the next waypoint
    cross_track_m: float = 0.0          # + left of the leg
    heading_error_rad: float = 0.0
    elapsed_s: float = 0.0
    reached_s: list[float] = field(default_factory=list)  # elapsed time at each waypoint

    def to_json(self) -> str:
        """One JSON object (NaN as null)."""
        data = asdict(self)
        data['state'] = self.state.value
        return json.dumps({k: (None if isinstance(v, float) and not math.isfinite(v) else v)
                           for k, v in data.items()}, separators=(',', ':'))

    @classmethod
    def from_json(cls, text: str) -> 'Progress':
        """Parse ``to_json``'s output; raise ValueError on anything else."""
        try:
            data = json.loads(text)
            data['state'] = MissionState(data['state'])
            data['distance_m'] = math.nan if data['distance_m'] is None else data['distance_m']
            return cls(**data)
        except (json.JSONDecodeError, KeyError, TypeError) as exc:
            raise ValueError(f'not a mission status: {text[:80]!r}') from exc


def line_of_sight(x_m: float, y_m: float, start: tuple[float, float],
                  end: tuple[float, float], lookahead_m: float) -> tuple[float, float, float]:
    """Return (heading to steer, cross-track error + left, along-track distance) on a leg.

    The aim point is ``lookahead_m`` along the leg from the vehicle's projection
    onto it; a zero-length leg aims straight at its end.
    """
    dx, dy = end[0] - start[0], end[1] - start[1]
    length = math.hypot(dx, dy)
    if length < 1e-9:
        return math.atan2(end[1] - y_m, end[0] - x_m), 0.0, 0.0
    path_angle = math.atan2(dy, dx)
    rx, ry = x_m - start[0], y_m - start[1]
    along = rx * math.cos(path_angle) + ry * math.sin(path_angle)
    cross = -rx * math.sin(path_angle) + ry * math.cos(path_angle)
    return path_angle + math.atan2(-cross, lookahead_m), cross, along


class LosGuidance:
    """Follows a MissionSpec's waypoints; feed it the pose, get a velocity command."""

    def __init__(self, spec: MissionSpec) -> None:
        self.spec = spec
        self.progress = Progress(waypoints_total=len(spec.waypoints),
                                 waypoint_name=spec.waypoints[0].name)
        self._leg_start: tuple[float, float] = (spec.start.x_m, 0.0)
        self._t0_s: float | None = None

    def start(self, t_s: float, x_m: float, y_m: float) -> None:
        """Begin at time ``t_s`` from the vehicle's position (the first leg's start)."""
        self._check(t_s, x_m, y_m, 0.0)
        self._t0_s = t_s
        self._leg_start = (x_m, y_m)
        self.progress.state = MissionState.RUNNING

    def abort(self) -> None:
        """End the mission from outside; guidance commands a stop from now on."""
        if not self.progress.state.finished:
            self.progress.state = MissionState.ABORTED

    def update(self, t_s: float, x_m: float, y_m: float, yaw_rad: float) -> VelocityCommand:
        """Advance with a new pose (odom) at time ``t_s``; return the command to send."""
        self._check(t_s, x_m, y_m, yaw_rad)
        progress = self.progress
        if progress.state is not MissionState.RUNNING or self._t0_s is None:
            return STOP
        progress.elapsed_s = t_s - self._t0_s
        waypoints = self.spec.waypoints
        while progress.waypoint_index < len(waypoints):
            target = waypoints[progress.waypoint_index]
            end = (target.x_m, target.y_m)
            heading, cross, along = line_of_sight(x_m, y_m, self._leg_start, end,
                                                  self.spec.lookahead_m)
            distance = math.hypot(end[0] - x_m, end[1] - y_m)
            leg_length = math.hypot(end[0] - self._leg_start[0], end[1] - self._leg_start[1])
            if distance > self.spec.acceptance_radius_m and along < leg_length:
                break
            progress.reached_s.append(progress.elapsed_s)
            progress.waypoint_index += 1
            self._leg_start = end
        if progress.waypoint_index >= len(waypoints):
            progress.state = MissionState.DONE
            progress.distance_m = 0.0
            return STOP
        progress.waypoint_name = target.name
        progress.distance_m = distance
        progress.cross_track_m = cross
        if progress.elapsed_s >= self.spec.timeout_s:
            progress.state = MissionState.TIMEOUT
            return STOP
        error = wrap_angle(heading - yaw_rad)
        progress.heading_error_rad = error
        limit = self.spec.max_yaw_rate_rps
        yaw_rate = max(-limit, min(limit, self.spec.heading_gain_per_s * error))
        fraction = max(self.spec.min_speed_fraction, math.cos(error))
        return VelocityCommand(target.speed_mps * fraction, yaw_rate)

    @staticmethod
    def _check(t_s: float, x_m: float, y_m: float, yaw_rad: float) -> None:
        if not all(math.isfinite(v) for v in (t_s, x_m, y_m, yaw_rad)):
            raise ValueError(f'guidance needs a finite pose and time, got t={t_s} x={x_m} '
                             f'y={y_m} yaw={yaw_rad}')


def spec_with_plan(spec: MissionSpec, text: str) -> MissionSpec | None:
    """``spec`` with the waypoints of a ``mission/plan`` JSON document; None for an empty plan.

    The document is ``{"waypoints": [{"name", "x_m", "y_m", "speed_mps"}, ...]}`` (odom,
    as the mission file); raises ConfigError naming what is wrong.
    """
    try:
        doc = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ConfigError(f'mission plan: not JSON ({exc})') from exc
    if not isinstance(doc, Mapping) or not isinstance(doc.get('waypoints'), list):
        raise ConfigError('mission plan: needs a "waypoints" list')
    if not doc['waypoints']:
        return None
    tree = {'mission': {**mission_tree(spec), 'waypoints': doc['waypoints']}}
    return parse_mission(tree)


def mission_tree(spec: MissionSpec) -> dict[str, Any]:
    """The mission-file mapping of ``spec`` (without waypoints)."""
    tree = asdict(spec)
    tree.pop('waypoints')
    return tree
