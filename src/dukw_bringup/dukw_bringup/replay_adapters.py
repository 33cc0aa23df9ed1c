"""The stack's node runners behind the offline replay harness (dukw_bringup.replay).

Each adapter converts a bag's messages as its node does (the same conversion functions)
and hands them to the node's runner, which owns the node's schedule: what it does on each
input and on each timer tick. The adapter only turns the runner's outputs and the
recorded messages into named numbers to compare.
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from operator import attrgetter
from typing import Any, Callable

from dukw_common.cmd_vel import read_cmd_vel
from dukw_common.config import node_params
from dukw_common.geometry import euler_from_quaternion
from dukw_control import convert as control_convert
from dukw_control.controller import ControlOutput
from dukw_control.modes import ModeDecision
from dukw_control.runners import DriveControllerRunner, ModeManagerRunner
from dukw_estimation import ros_convert
from dukw_estimation.runner import EkfRunner, Estimate


class CoreAdapter(ABC):
    """One node's core, driven from bag messages like its node would drive it."""

    #: short name, e.g. 'mode_manager'
    name: str = ''
    #: topic keys (no leading slash) whose messages the node subscribes to
    inputs: tuple[str, ...] = ()
    #: topic keys of the outputs this adapter reproduces and compares
    outputs: tuple[str, ...] = ()
    #: the node's timer rate, Hz
    rate_hz: float = 1.0
    #: quantities that are angles, rad: compared modulo 2 pi
    angle_quantities: frozenset[str] = frozenset()

    @abstractmethod
    def feed(self, topic: str, t_s: float, msg: Any) -> dict[str, float] | None:
        """An input message received at ``t_s`` (bag time, s).

        Return an output when the node reacts at once (outside its timer), else None.
        """

    @abstractmethod
    def tick(self, t_s: float) -> dict[str, float] | None:
        """The node's timer at ``t_s``: step the core and return its output as named
        numbers, or None when the node skips this tick (publishes nothing)."""

    @abstractmethod
    def recorded(self, topic: str, msg: Any) -> dict[str, float]:
        """The same named numbers from a recorded output message on ``topic``."""


def _side_row(prefix: str, port: float, stbd: float) -> dict[str, float]:
    return {f'{prefix}.port_pct': float(port), f'{prefix}.stbd_pct': float(stbd)}


def _decision_row(mode, automatic, track_weight, prop_weight, tracks_idle) -> dict[str, float]:
    return {'mode': float(int(mode)), 'automatic': float(bool(automatic)),
            'track_weight': float(track_weight), 'prop_weight': float(prop_weight),
            'tracks_idle': float(bool(tracks_idle))}


def decision_row(d: ModeDecision) -> dict[str, float]:
    """A mode decision as named numbers."""
    return _decision_row(d.mode, d.automatic, d.track_weight, d.prop_weight, d.tracks_idle)


def control_row(out: ControlOutput | None) -> dict[str, float] | None:
    """A control step's commands as named numbers (None: no step)."""
    if out is None:
        return None
    return {**_side_row('tracks', out.tracks.port, out.tracks.stbd),
            **_side_row('props', out.props.port, out.props.stbd)}


class ModeManagerAdapter(CoreAdapter):
    """mode_manager_node's runner (dukw_control.runners.ModeManagerRunner)."""

    name = 'mode_manager'
    inputs = ('water/contact', 'depth', 'traction', 'tracks/status', 'imu/data')
    outputs = ('drive_mode',)

    def __init__(self, config_path: str | None = None,
                 runner: ModeManagerRunner | None = None) -> None:
        self.runner = runner or ModeManagerRunner.from_params(
            node_params('mode_manager_node', config_path))
        self.rate_hz = self.runner.rate_hz
        self.core = self.runner.core

    def feed(self, topic, t_s, msg):
        r = self.runner
        if topic == 'water/contact':
            r.on_water_contact(msg.fore_wet, msg.aft_wet, t_s)
        elif topic == 'depth':
            r.on_depth(msg.valid, msg.depth_m, t_s)
        elif topic == 'traction':
            r.on_traction(msg.weight_on_tracks_fraction, t_s)
        elif topic == 'tracks/status':
            r.on_track_status(msg.connected, msg.port.force_n, msg.stbd.force_n, t_s)
        elif topic == 'imu/data':
            r.on_imu(control_convert.stamp_or(msg, t_s), t_s)
        return None

    def tick(self, t_s):
        """Every tick's decision is compared (the node publishes only some of them)."""
        self.runner.tick(t_s)
        return decision_row(self.core.decision())

    def recorded(self, topic, msg):
        return _decision_row(msg.mode, msg.automatic, msg.track_weight, msg.prop_weight,
                             msg.tracks_idle)


class DriveControllerAdapter(CoreAdapter):
    """drive_controller_node's runner (dukw_control.runners.DriveControllerRunner)."""

    name = 'drive_controller'
    inputs = ('cmd_vel', 'authority', 'drive_mode', 'odometry/filtered', 'imu/data',
              'traction', 'tracks/status')
    outputs = ('tracks/cmd', 'props/cmd')

    def __init__(self, config_path: str | None = None,
                 runner: DriveControllerRunner | None = None) -> None:
        self.runner = runner or DriveControllerRunner.from_params(
            node_params('drive_controller_node', config_path))
        self.rate_hz = self.runner.rate_hz
        self.core = self.runner.core

    def feed(self, topic, t_s, msg):
        r, c = self.runner, control_convert
        if topic == 'cmd_vel':          # Twist or TwistStamped, whichever the bag holds
            speed_mps, yaw_rate_rps, stamp_s = read_cmd_vel(msg)
            r.on_cmd_vel(speed_mps, yaw_rate_rps, t_s, stamp_s)
        elif topic == 'authority':
            return control_row(r.on_authority(*c.authority_usable(msg), t_s))
        elif topic == 'drive_mode':
            r.on_mode(c.decision_from_msg(msg), t_s)
        elif topic == 'odometry/filtered':
            return control_row(r.on_odometry(
                msg.twist.twist.linear.x, msg.twist.twist.angular.z,
                c.pitch_from_quaternion(msg.pose.pose.orientation), t_s))
        elif topic == 'imu/data':
            r.on_imu(c.stamp_or(msg, t_s), t_s)
        elif topic == 'traction':
            r.on_traction(msg.port_slip, msg.stbd_slip, t_s)
        elif topic == 'tracks/status':
            r.on_track_status(msg.connected, msg.port.current_a, msg.stbd.current_a, t_s)
        return None

    def tick(self, t_s):
        return control_row(self.runner.tick(t_s))

    def recorded(self, topic, msg):
        return _side_row(topic.split('/')[0], msg.port_pct, msg.stbd_pct)


class EkfAdapter(CoreAdapter):
    """ekf_node's runner (dukw_estimation.runner.EkfRunner)."""

    name = 'ekf'
    inputs = tuple(ros_convert.SAMPLE_FROM_MSG)
    outputs = ('odometry/filtered', 'traction')
    angle_quantities = frozenset({'odom.yaw_rad'})
    #: traction fields compared (the message's float fields)
    TRACTION_FIELDS = ros_convert.TRACTION_FIELDS
    #: their row names, and one call reading them all (a row per estimate: keep it cheap)
    _TRACTION_KEYS = tuple(f'traction.{name}' for name in TRACTION_FIELDS)
    _traction_values = staticmethod(attrgetter(*TRACTION_FIELDS))

    def __init__(self, config_path: str | None = None, runner: EkfRunner | None = None) -> None:
        self.runner = runner or EkfRunner.from_params(node_params('ekf_node', config_path))
        self.rate_hz = self.runner.rate_hz
        self.core = self.runner.estimator

    def feed(self, topic, t_s, msg):
        sample = ros_convert.SAMPLE_FROM_MSG[topic](msg, ros_convert.stamp_or(msg, t_s))
        return self.estimate_row(self.runner.on_sample(topic, sample, t_s))

    def tick(self, t_s):
        return self.estimate_row(self.runner.tick(t_s))

    @classmethod
    def estimate_row(cls, estimate: Estimate | None) -> dict[str, float] | None:
        """An estimate as named numbers (None: nothing published)."""
        if estimate is None:
            return None
        odom, traction = estimate.odometry, estimate.traction
        row = {'odom.x_m': float(odom.x_m), 'odom.y_m': float(odom.y_m),
               'odom.yaw_rad': float(odom.yaw_rad), 'odom.surge_mps': float(odom.surge_mps),
               'odom.yaw_rate_rps': float(odom.yaw_rate_rps)}
        row.update(zip(cls._TRACTION_KEYS, map(float, cls._traction_values(traction)),
                       strict=True))
        return row

    @staticmethod
    def _odometry_row(msg) -> dict[str, float]:
        q = msg.pose.pose.orientation
        return {'odom.x_m': float(msg.pose.pose.position.x),
                'odom.y_m': float(msg.pose.pose.position.y),
                'odom.yaw_rad': float(euler_from_quaternion(q.x, q.y, q.z, q.w)[2]),
                'odom.surge_mps': float(msg.twist.twist.linear.x),
                'odom.yaw_rate_rps': float(msg.twist.twist.angular.z)}

    def recorded(self, topic, msg):
        if topic == 'odometry/filtered':
            return self._odometry_row(msg)
        return dict(zip(self._TRACTION_KEYS, map(float, self._traction_values(msg)),
                        strict=True))


#: adapter name -> factory (config path -> adapter)
ADAPTERS: dict[str, Callable[..., CoreAdapter]] = {
    'mode_manager': ModeManagerAdapter, 'drive_controller': DriveControllerAdapter,
    'ekf': EkfAdapter}
