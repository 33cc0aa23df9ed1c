"""Campaigns: many randomized runs of the in-process stack, judged against the truth.

ROS-free core of ``campaign`` (campaign_cli.py runs it on Dask). A spec (YAML, example in
config/campaigns/) names the scenario kinds and the distributions of the conditions; run
``index`` draws its conditions from ``numpy.random.default_rng([seed, index])`` alone, so
any run can be reproduced from (campaign seed, run index).

Model mismatch: the simulator's beach slope, soil and sea are the drawn ones, while the
estimator keeps the configured vehicle, beach and soil (``estimator_knows_site=False``).
A spec's ``oracle_site: true`` is the diagnostic counterpart: the estimator is handed the
drawn slope and soil, so what is left of the misses is not due to the mismatch.

The ``mission`` kind flies a mission file (``dukw_bringup.mission``, as mission_node does:
line-of-sight guidance on the EKF's odometry at mission_node's rate, started
``start_delay_s`` after the first odometry) from the mission's start pose (plus the drawn
start offset along x) through the drawn beach and sea; the run ends when the mission does
(or after ``duration_s``). Its row adds ``mission_done`` and ``mission_time_s``; a mission
not done misses the target ``mission_done``.
"""
from __future__ import annotations

import dataclasses
import math
import time
import traceback
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import yaml

from dukw_bringup.accuracy import ACCURACY_COLUMNS, accuracy
from dukw_bringup.mission import LosGuidance, MissionSpec, MissionState, load_mission
from dukw_common.config import ConfigError, node_params
from dukw_common.geometry import geodetic_from_local_enu

KINDS = ('land_to_sea', 'sea_to_land', 'land_circle', 'water_circle', 'mission')
#: Drawn per run, in this order (the order is part of reproducibility: never reorder).
DRAWS = ('kind', 'significant_wave_height_m', 'peak_period_s', 'spreading_rad',
         'beach_slope_deg', 'soil_preset', 'cohesion_kpa', 'friction_angle_deg',
         'shear_modulus_cm', 'speed_mps', 'start_offset_m', 'sim_seed', 'sensor_seed',
         'yaw_rate_rps')
#: Draws a spec may leave out, and their constant value then.
OPTIONAL_DRAWS = {'yaw_rate_rps': 0.0}
#: Physical bounds a spec's distribution must stay inside (a typo is refused, not run).
BOUNDS = {'significant_wave_height_m': (0.0, 1.0), 'peak_period_s': (1.0, 20.0),
          'spreading_rad': (0.0, math.pi), 'beach_slope_deg': (0.5, 30.0),
          'cohesion_kpa': (0.0, 5.0), 'friction_angle_deg': (0.0, 60.0),
          'shear_modulus_cm': (0.0, 100.0), 'speed_mps': (0.05, 2.0),
          'start_offset_m': (-10.0, 10.0), 'sim_seed': (0, 2 ** 32 - 1),
          'sensor_seed': (0, 2 ** 32 - 1), 'yaw_rate_rps': (-1.5, 1.5)}
FAULTS = {'gps_dropout': ('start_s', 'duration_s'), 'gps_outlier': ('start_s', 'offset_m')}
TARGET_NAMES = ('slip_rmse', 'volume_error_pct', 'fraction_error', 'mode_delay_s')


class SpecError(ValueError):
    """The campaign spec is malformed; the message names the field."""


# ------------------------------------------------------------------------------- spec

@dataclass(frozen=True)
class Spec:
    """A validated campaign spec (plain data: it travels to the Dask workers)."""

    name: str
    seed: int
    runs: int
    duration_s: float
    warm_up_s: float
    kinds: tuple[str, ...]
    draws: Mapping[str, Any]
    faults: Mapping[str, Mapping[str, Any]]
    targets: Mapping[str, float]
    sim_overrides: Mapping[str, Any]
    oracle_site: bool = False
    mission: MissionSpec | None = None     # the mission kind's mission (loaded, cut)
    oracle_surface: bool = False           # diagnostic: the water over grounded hulls known


def load_spec(path: str) -> Spec:
    """Read and validate a spec file; SpecError with the field's name when it is wrong."""
    try:
        with open(path, encoding='utf-8') as f:
            raw = yaml.safe_load(f)
    except OSError as exc:
        raise SpecError(f'cannot read campaign spec {path}: {exc}') from exc
    except yaml.YAMLError as exc:
        raise SpecError(f'campaign spec {path} is not valid YAML: {exc}') from exc
    return parse_spec(raw)


def parse_spec(raw: Any) -> Spec:
    """Validate a spec mapping (the YAML's content)."""
    if not isinstance(raw, dict):
        raise SpecError('campaign spec must be a mapping')
    known = {'name', 'seed', 'runs', 'duration_s', 'warm_up_s', 'kinds', 'draws', 'faults',
             'targets', 'sim_overrides', 'oracle_site', 'oracle_surface', 'mission'}
    _no_unknown(raw, known, 'spec')
    seed = _int(raw, 'seed', 0, 2 ** 63 - 1)
    runs = _int(raw, 'runs', 1, 10_000_000)
    duration = _number(raw, 'duration_s', 1.0, 3600.0)
    warm_up = _number(raw, 'warm_up_s', 0.0, duration - 0.5)
    kinds = raw.get('kinds')
    if not isinstance(kinds, list) or not kinds or any(k not in KINDS for k in kinds):
        raise SpecError(f'kinds must be a non-empty list of {list(KINDS)}, got {kinds!r}')
    draws = _section(raw, 'draws')
    _no_unknown(draws, set(DRAWS) - {'kind'}, 'draws')
    checked = {}
    for name in DRAWS[1:]:
        if name not in draws and name not in OPTIONAL_DRAWS:
            raise SpecError(f'draws.{name} is missing')
        checked[name] = _distribution(draws.get(name, OPTIONAL_DRAWS.get(name)),
                                      f'draws.{name}', BOUNDS.get(name))
    _check_presets(checked['soil_preset'])
    faults = _faults(raw.get('faults', {}))
    targets = _section(raw, 'targets')
    _no_unknown(targets, set(TARGET_NAMES), 'targets')
    for name in TARGET_NAMES:
        _number(targets, name, 0.0, 1e6, prefix='targets.')
    overrides = raw.get('sim_overrides', {}) or {}
    if not isinstance(overrides, dict):
        raise SpecError('sim_overrides must be a mapping of dotted sim_node parameters')
    for key, value in overrides.items():
        _distribution(value, f'sim_overrides.{key}', None)
    oracle, oracle_surface = (_flag(raw, name) for name in ('oracle_site', 'oracle_surface'))
    mission = _mission(raw.get('mission', {}), 'mission' in kinds)
    return Spec(str(raw.get('name', 'campaign')), seed, runs, duration, warm_up, tuple(kinds),
                checked, faults, {k: float(targets[k]) for k in TARGET_NAMES}, dict(overrides),
                oracle, mission, oracle_surface)


def _flag(raw: Mapping[str, Any], name: str) -> bool:
    value = raw.get(name, False)
    if not isinstance(value, bool):
        raise SpecError(f'{name} must be true or false, got {value!r}')
    return value


def _mission(raw: Any, needed: bool) -> MissionSpec | None:
    """``mission: {file: PATH ('' or absent: config/mission.yaml), waypoints: N (the first
    N only; absent: all)}``, loaded here so the workers need not read it."""
    if not isinstance(raw, dict):
        raise SpecError('mission must be a mapping {file: PATH, waypoints: N}')
    _no_unknown(raw, {'file', 'waypoints'}, 'mission')
    if not needed:
        return None
    path = raw.get('file', '') or None
    if path is not None and not isinstance(path, str):
        raise SpecError(f'mission.file must be a path, got {path!r}')
    try:
        spec = load_mission(path)
        if 'waypoints' in raw:
            count = raw['waypoints']
            if isinstance(count, bool) or not isinstance(count, int):
                raise SpecError(f'mission.waypoints must be an integer, got {count!r}')
            spec = spec.with_waypoints(count)
    except ConfigError as exc:
        raise SpecError(f'mission: {exc}') from exc
    return spec


def _no_unknown(section: Mapping, known: set, where: str) -> None:
    unknown = sorted(set(section) - known)
    if unknown:
        raise SpecError(f'{where}: unknown field(s) {unknown}; known: {sorted(known)}')


def _section(raw: Mapping, name: str) -> dict:
    value = raw.get(name)
    if not isinstance(value, dict):
        raise SpecError(f'{name} must be a mapping, got {value!r}')
    return value


def _number(raw: Mapping, name: str, low: float, high: float, prefix: str = '') -> float:
    value = raw.get(name)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not (
            low <= value <= high):
        raise SpecError(f'{prefix}{name} must be a number in [{low}, {high}], got {value!r}')
    return float(value)


def _int(raw: Mapping, name: str, low: int, high: int) -> int:
    value = raw.get(name)
    if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
        raise SpecError(f'{name} must be an integer in [{low}, {high}], got {value!r}')
    return value


def _distribution(value: Any, where: str, bounds: tuple[float, float] | None) -> Any:
    """A constant, {uniform: [lo, hi]}, {integers: [lo, hi]} or {choice: [...]}."""
    if not isinstance(value, dict):
        if bounds is not None and not (isinstance(value, (int, float)) and not isinstance(
                value, bool) and bounds[0] <= value <= bounds[1]):
            raise SpecError(f'{where} must lie in {list(bounds)}, got {value!r}')
        return value
    if len(value) != 1 or next(iter(value)) not in ('uniform', 'integers', 'choice'):
        raise SpecError(f'{where} must be a constant or one of {{uniform: [lo, hi]}}, '
                        f'{{integers: [lo, hi]}}, {{choice: [...]}}; got {value!r}')
    kind, args = next(iter(value.items()))
    if kind == 'choice':
        if not isinstance(args, list) or not args:
            raise SpecError(f'{where}.choice must be a non-empty list, got {args!r}')
        for item in args:
            _distribution(item, where, bounds)
        return value
    if (not isinstance(args, list) or len(args) != 2 or any(
            isinstance(a, bool) or not isinstance(a, (int, float)) for a in args)
            or args[0] > args[1]):
        raise SpecError(f'{where}.{kind} must be [low, high] numbers with low <= high, '
                        f'got {args!r}')
    if kind == 'integers' and not all(isinstance(a, int) for a in args):
        raise SpecError(f'{where}.integers bounds must be integers, got {args!r}')
    if bounds is not None and not (bounds[0] <= args[0] and args[1] <= bounds[1]):
        raise SpecError(f'{where} {args} must lie in {list(bounds)}')
    return value


def _check_presets(dist: Any) -> None:
    names = node_params('sim_node').get('soil_presets.names', [])
    values = dist['choice'] if isinstance(dist, dict) and 'choice' in dist else [dist]
    for v in values:
        if v not in ('', *names):
            raise SpecError(f"draws.soil_preset: unknown preset {v!r}; known: {names} or '' "
                            '(the drawn cohesion, friction angle and k)')


def _faults(raw: Any) -> dict:
    if not isinstance(raw, dict):
        raise SpecError('faults must be a mapping')
    _no_unknown(raw, set(FAULTS), 'faults')
    out = {}
    for name, fields in FAULTS.items():
        f = raw.get(name, {'probability': 0.0, 'start_s': 0.0, fields[1]: 0.0})
        if not isinstance(f, dict):
            raise SpecError(f'faults.{name} must be a mapping')
        _no_unknown(f, {'probability', *fields}, f'faults.{name}')
        _number(f, 'probability', 0.0, 1.0, prefix=f'faults.{name}.')
        for field in fields:
            if field not in f:
                raise SpecError(f'faults.{name}.{field} is missing')
            _distribution(f[field], f'faults.{name}.{field}', (0.0, 1000.0))
        out[name] = f
    return out


# ------------------------------------------------------------------------------ draws

def _draw(rng: np.random.Generator, dist: Any) -> Any:
    if not isinstance(dist, dict):
        return dist
    kind, args = next(iter(dist.items()))
    if kind == 'uniform':
        return float(rng.uniform(args[0], args[1]))
    if kind == 'integers':
        return int(rng.integers(args[0], args[1], endpoint=True))
    return _draw(rng, args[int(rng.integers(len(args)))])


def draw_conditions(spec: Spec, index: int) -> dict:
    """Run ``index``'s conditions, from (spec.seed, index) only."""
    rng = np.random.default_rng([spec.seed, index])
    out: dict[str, Any] = {'kind': spec.kinds[int(rng.integers(len(spec.kinds)))]}
    for name in DRAWS[1:]:
        out[name] = _draw(rng, spec.draws[name])
    if out['soil_preset']:
        soil = node_params('sim_node')
        p = f'soil_presets.{out["soil_preset"]}.'
        out['cohesion_kpa'] = soil[p + 'cohesion_pa'] / 1000.0
        out['friction_angle_deg'] = math.degrees(soil[p + 'friction_angle_rad'])
        out['shear_modulus_cm'] = soil[p + 'shear_modulus_m'] * 100.0
    for name, fields in FAULTS.items():
        f = spec.faults[name]
        active = bool(rng.random() < f['probability'])
        drawn = [_draw(rng, f[field]) for field in fields]
        for field, value in zip(fields, drawn, strict=True):
            out[f'{name}_{field}'] = value if active else 0.0
        out[name] = active
    for key in sorted(spec.sim_overrides):
        out[f'sim.{key}'] = _draw(rng, spec.sim_overrides[key])
    return out


def sim_overrides(cond: Mapping[str, Any]) -> dict:
    """The simulator's dotted overrides for these conditions (the estimator keeps config)."""
    height = cond['significant_wave_height_m']
    out = {'waves.model': 'irregular' if height > 0.0 else 'none',
           'waves.significant_height_m': max(height, 1e-3),
           'waves.peak_period_s': cond['peak_period_s'],
           # the campaign draws the uniform spread: it replaces the default cos-2s one
           'waves.spreading_rad': cond['spreading_rad'], 'waves.spreading_exponent_s': 0.0,
           'waves.directions': 1,
           'site.beach_slope_rad': math.radians(cond['beach_slope_deg']),
           'soil.cohesion_pa': cond['cohesion_kpa'] * 1000.0,
           'soil.friction_angle_rad': math.radians(cond['friction_angle_deg']),
           'soil.shear_modulus_m': cond['shear_modulus_cm'] / 100.0}
    out.update({k[4:]: v for k, v in cond.items() if k.startswith('sim.')})
    return out


# ----------------------------------------------------------------------------- faults

class SensorFaults:
    """Injected between the sensor models and the stack: GPS dropout and a GPS outlier."""

    def __init__(self, cond: Mapping[str, Any]) -> None:
        self.dropout = (cond['gps_dropout_start_s'],
                        cond['gps_dropout_start_s'] + cond['gps_dropout_duration_s']
                        ) if cond['gps_dropout'] else None
        self.outlier_s = cond['gps_outlier_start_s'] if cond['gps_outlier'] else None
        self.outlier_m = cond['gps_outlier_offset_m']

    def __call__(self, readings: list) -> list:
        out = []
        for r in readings:
            kind = type(r).__name__
            if kind in ('GpsFix', 'GpsVelocity') and self.dropout and (
                    self.dropout[0] <= r.t_s < self.dropout[1]):
                continue
            if kind == 'GpsFix' and self.outlier_s is not None and r.t_s >= self.outlier_s:
                self.outlier_s = None           # one fix, thrown north-east by offset_m
                d_m = self.outlier_m / math.sqrt(2.0)
                lat, lon, _ = geodetic_from_local_enu(d_m, d_m, 0.0, r.latitude_deg,
                                                      r.longitude_deg, r.altitude_m)
                r = dataclasses.replace(r, latitude_deg=lat, longitude_deg=lon)
            out.append(r)
        return out


# -------------------------------------------------------------------------------- run

SERIES_COLUMNS = ('t_s', 'x_m', 'y_m', 'yaw_rad', 'est_x_m', 'est_y_m', 'est_yaw_rad',
                  'port_slip', 'stbd_slip', 'est_port_slip', 'est_stbd_slip',
                  'volume_m3', 'est_volume_m3', 'fraction', 'est_fraction', 'medium', 'mode',
                  'port_current_a', 'stbd_current_a', 'port_track_pct', 'stbd_track_pct',
                  'port_prop_pct', 'stbd_prop_pct', 'port_track_mps', 'stbd_track_mps')


def _surface_oracle(loop) -> Callable[[str, int, Any], None]:
    """A listener that, at each sensor reading while the truth's hulls touch the sand, pins
    the estimator's surface to the truth's: the water depth at base_link (the waterline
    distance on the estimator's own slope that gives it) and the wave there. Not
    ``evaluate --oracle-surface``'s pin of the true waterline distance itself: here the
    estimator keeps its configured slope, so the same distance would put another depth under
    the hulls; and only grounded, since afloat over the flat sea floor the truth's slope is
    0 and the depth says nothing of the distance."""
    from dukw_bringup.stack_harness import SENSOR_TOPICS
    from dukw_sim.truth import Medium

    def pin(topic: str, t_ns: int, item: Any) -> None:
        truth, est = loop.truth, loop.est
        if topic in SENSOR_TOPICS and truth.medium != Medium.WATER:
            depth_m = truth.waterline_distance_m * math.sin(truth.slope_rad)
            est.pin_surface(depth_m / math.sin(est.contact.slope_rad), truth.wave_elevation_m)
    return pin


def build_loop(spec: Spec, cond: Mapping[str, Any]):
    """The in-process stack for these conditions, placed at its start."""
    from dukw_bringup.stack_harness import ClosedLoop
    loop = ClosedLoop(sim_overrides(cond), seed=cond['sim_seed'], feedback='ekf',
                      estimator_knows_site=spec.oracle_site, sensor_filter=SensorFaults(cond))
    if spec.oracle_site:                 # diagnostic: the estimator knows the drawn soil too
        loop.est.set_soil(loop.sim.vehicle.soil)
    if spec.oracle_surface:
        loop.listeners.append(_surface_oracle(loop))
    loop.sensors.seed = cond['sensor_seed']
    loop.sensors.reset()
    if cond['kind'] == 'mission':
        start = spec.mission.start
        loop.truth = loop.sim.reset('sand' if start.x_m < 0.0 else 'afloat',
                                    start.x_m + cond['start_offset_m'], start.yaw_rad)
        return loop
    start, yaw = {'land_to_sea': ('sand', 0.0), 'land_circle': ('flat', 0.0),
                  'water_circle': ('afloat', 0.0)}.get(cond['kind'], ('sea', math.pi))
    x_m = loop.sim.start_x_m(start) + cond['start_offset_m']     # (the slope: site.*, above)
    loop.truth = loop.sim.reset(x_m=x_m, yaw_rad=yaw)
    return loop


class MissionPilot:
    """mission_node's behaviour in the loop: guidance on the EKF's odometry at ``rate_hz``,
    started ``start_delay_s`` after the first odometry; zero velocity before."""

    def __init__(self, mission: MissionSpec, rate_hz: float) -> None:
        self.guidance = LosGuidance(mission)
        self.period_s = 1.0 / rate_hz
        self.next_s = 0.0
        self.first_pose_s: float | None = None

    @property
    def state(self) -> MissionState:
        return self.guidance.progress.state

    def command(self, t_s: float, estimate) -> tuple[float, float] | None:
        """The cmd_vel due at ``t_s`` (None between the node's ticks)."""
        if t_s < self.next_s - 1e-9:
            return None
        self.next_s = t_s + self.period_s
        if estimate is None:
            return (0.0, 0.0)
        odo = estimate.odometry
        if self.first_pose_s is None:
            self.first_pose_s = t_s
        if self.state is MissionState.WAITING and \
                t_s - self.first_pose_s >= self.guidance.spec.start_delay_s:
            self.guidance.start(t_s, odo.x_m, odo.y_m)
        out = self.guidance.update(t_s, odo.x_m, odo.y_m, odo.yaw_rad)
        return (out.speed_mps, out.yaw_rate_rps)


def simulate(spec: Spec, cond: Mapping[str, Any]) -> tuple[np.ndarray, list, Any]:
    """Run the stack; the per-step series (SERIES_COLUMNS) and the mode changes."""
    loop = build_loop(spec, cond)
    cmd = (cond['speed_mps'], cond['yaw_rate_rps'])
    pilot = loop.pilot = MissionPilot(spec.mission, float(node_params('mission_node')[
        'rate_hz'])) if cond['kind'] == 'mission' else None
    rows = []
    for _ in range(int(round(spec.duration_s / loop.sim.dt_s))):
        before = loop.truth
        if pilot is not None:
            if pilot.state.finished:
                break
            cmd = pilot.command(before.t_s, loop.estimate)
        loop.step(cmd)
        if loop.estimate is None:
            continue
        odo, trc = loop.estimate.odometry, loop.estimate.traction
        tracks, props = loop.record.tracks[-1], loop.record.props[-1]
        mode_now = loop.record.modes[-1][1] if loop.record.modes else -1
        rows.append((before.t_s, before.x_m, before.y_m, before.yaw_rad, odo.x_m, odo.y_m,
                     odo.yaw_rad, before.port_slip, before.stbd_slip, trc.port_slip,
                     trc.stbd_slip, before.submerged_volume_m3, trc.submerged_volume_m3,
                     before.weight_on_tracks_fraction, trc.weight_on_tracks_fraction,
                     int(before.medium), int(mode_now), before.port_current_a,
                     before.stbd_current_a, *tracks, *props, before.port_track_speed_mps,
                     before.stbd_track_speed_mps))
    return np.array(rows, dtype=float), loop.record.modes, loop


def score(spec: Spec, cond: Mapping[str, Any], s: np.ndarray, mode_log: list, loop) -> dict:
    """The run's metrics from its series (estimate vs truth, modes vs medium, currents)."""
    col = {name: s[:, k] for k, name in enumerate(SERIES_COLUMNS)}
    scored = col['t_s'] >= spec.warm_up_s
    current = np.maximum(np.abs(col['port_current_a']), np.abs(col['stbd_current_a']))
    limit_a = loop.sim.vehicle.drivetrain.continuous_current_limit_a
    to_water, to_land = _mode_delays(col['t_s'], col['medium'], mode_log,
                                     returns=cond['kind'] == 'mission')
    out = {
        **accuracy({name: col[name][scored] for name in ACCURACY_COLUMNS},
                   loop.sim.vehicle.body.displaced_volume_m3),
        'mode_delay_to_water_s': to_water,
        'mode_delay_to_land_s': to_land,
        'chatter_count': _chatter(col['medium'], mode_log),
        'time_over_limit_s': float(np.count_nonzero(current > limit_a)) * loop.sim.dt_s,
        'peak_current_a': float(current.max()) if current.size else 0.0,
        'end_x_m': float(col['x_m'][-1]) if len(s) else math.nan,
        'end_medium': int(col['medium'][-1]) if len(s) else -1,
        'end_mode': int(col['mode'][-1]) if len(s) else -1,
    }
    pilot = getattr(loop, 'pilot', None)
    if pilot is not None:
        done = pilot.state is MissionState.DONE
        out['mission_done'] = done
        out['mission_time_s'] = pilot.guidance.progress.elapsed_s if done else math.nan
    out = {k: (round(v, 6) if isinstance(v, float) else v) for k, v in out.items()}
    failed = failed_targets(out, spec.targets)
    out['targets_met'] = not failed
    out['failed_targets'] = ';'.join(failed)
    return out


def _first(t: np.ndarray, mask: np.ndarray) -> float:
    hits = np.flatnonzero(mask)
    return float(t[hits[0]]) if hits.size else math.nan


def _mode_delays(t: np.ndarray, medium: np.ndarray, mode_log: list,
                 returns: bool = False) -> tuple[float, float]:
    """Mode WATER (LAND) minus truth WATER (LAND), first time each reaches it after the start
    in the other medium; NaN when neither happens. When only one side happens the delay
    runs to the end of the run (a lower bound; negative: the mode changed, the truth not).
    ``returns`` (a mission: land, sea, land): starting in the target medium, the delay of
    the return to it, counted from the truth's first time in the other one."""
    if not t.size:
        return math.nan, math.nan
    end = float(t[-1])
    out = []
    for target in (2, 0):                    # WATER, LAND (Medium and Mode share values)
        since = _first(t, medium == 2 - target) if medium[0] == target else -math.inf
        if math.isnan(since) or (medium[0] == target and not returns):
            out.append(math.nan)
            continue
        truth_t = _first(t, (medium == target) & (t >= since))
        modes = [when for when, mode, _ in mode_log if int(mode) == target and when >= since]
        mode_t = modes[0] if modes else math.nan
        if math.isnan(truth_t) and math.isnan(mode_t):
            out.append(math.nan)
        elif math.isnan(mode_t):
            out.append(end - truth_t)
        elif math.isnan(truth_t):
            out.append(mode_t - end)
        else:
            out.append(mode_t - truth_t)
    return out[0], out[1]


def _chatter(medium: np.ndarray, mode_log: list) -> int:
    """Mode changes beyond the fewest that lead from the start medium to the end one."""
    modes = [int(m) for _, m, _ in mode_log]
    changes = sum(1 for a, b in zip(modes, modes[1:], strict=False) if a != b)
    expected = abs(int(medium[-1]) - int(medium[0])) if medium.size else 0
    return max(0, changes - expected)


def failed_targets(metrics: Mapping[str, Any], targets: Mapping[str, float]) -> list[str]:
    """Which of the estimator's targets this run misses."""
    out = [k for k in ('slip_rmse', 'volume_error_pct', 'fraction_error')
           if not metrics[k] <= targets[k]]
    for name in ('mode_delay_to_water_s', 'mode_delay_to_land_s'):
        if not math.isnan(metrics[name]) and abs(metrics[name]) > targets['mode_delay_s']:
            out.append(name)
    if metrics.get('mission_done') is False:
        out.append('mission_done')
    return out


def run_one(spec: Spec, index: int, keep_series: bool = False) -> dict:
    """One run: its index, drawn conditions and metrics; a run that raises is returned with
    its traceback in ``error`` (never raised: a campaign goes on)."""
    start = time.perf_counter()
    row: dict[str, Any] = {'index': index}
    try:
        cond = draw_conditions(spec, index)
        row.update(cond)
        series, mode_log, loop = simulate(spec, cond)
        row.update(score(spec, cond, series, mode_log, loop))
        row['error'] = ''
        if keep_series:
            row['_series'] = series
    except Exception:  # noqa: BLE001 (recorded with its traceback: the campaign goes on)
        row['targets_met'] = False
        row['error'] = traceback.format_exc()
    row['wall_s'] = round(time.perf_counter() - start, 3)
    return row


RunFunction = Callable[[Spec, int], dict]
