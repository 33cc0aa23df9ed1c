"""The stack's node runners behind the offline replay harness (dukw_bringup.replay).

Each adapter converts a bag's messages as its node does (the same conversion functions)
and hands them to the node's runner, which owns the node's schedule: what it does on each
input and on each timer tick. The adapter only turns the runner's outputs and the
recorded messages into named numbers to compare.

An adapter names the message fields it reads per topic (``fields``): the replay decodes
only those, as columns of all of a topic's messages at once (dukw_bringup.bag_fields),
and hands each message over as the tuple of them. A topic not in ``fields`` comes as
rosbags' message object (a type that varies, e.g. cmd_vel's Twist or TwistStamped, or a
string the core reads).
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from operator import attrgetter
from types import MappingProxyType
from typing import Any, Callable, Mapping, Sequence

from dukw_common.cmd_vel import read_cmd_vel
from dukw_common.config import node_params
from dukw_common.geometry import euler_from_quaternion
from dukw_common.node_tools import STAMP_FIELDS, stamp_s_or
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
    #: topic key -> the message fields (dotted paths) ``feed``/``recorded`` read, in the
    #: order of the tuple they get; a topic not here: rosbags' message object
    fields: Mapping[str, tuple[str, ...]] = MappingProxyType({})

    @abstractmethod
    def feed(self, topic: str, t_s: float, msg: Any) -> dict[str, float] | None:
        """An input message received at ``t_s`` (bag time, s): the tuple of its ``fields``
        (or the message).

        Return an output when the node reacts at once (outside its timer), else None. An
        output (here and from ``tick``) is a new dict each time: the replay stamps it
        (``t_s``) and keeps it as the row.
        """

    @abstractmethod
    def tick(self, t_s: float) -> dict[str, float] | None:
        """The node's timer at ``t_s``: step the core and return its output as named
        numbers, or None when the node skips this tick (publishes nothing)."""

    def recorded(self, topic: str, msg: Any) -> dict[str, float]:
        """The same named numbers from a recorded output message on ``topic`` (the tuple of
        its ``fields``, or the message). Implement this or ``recorded_columns``."""
        raise NotImplementedError(f'{self.name}: neither recorded nor recorded_columns')

    def recorded_columns(self, topic: str, msgs: Sequence[Any]) -> dict[str, Sequence[float]]:
        """Per quantity, its values in the recorded output messages ``msgs`` on ``topic``
        (the replay compares many at once); by default ``recorded`` of each, which must name
        the same quantities every time."""
        rows = [self.recorded(topic, msg) for msg in msgs]
        names = rows[0].keys()
        if any(row.keys() != names for row in rows):
            raise ValueError(f'{self.name}: the recorded {topic} quantities differ from one '
                             'message to the next')
        return {name: [row[name] for row in rows] for name in names}


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
    tracks, props = out.tracks, out.props
    return {'tracks.port_pct': float(tracks.port), 'tracks.stbd_pct': float(tracks.stbd),
            'props.port_pct': float(props.port), 'props.stbd_pct': float(props.stbd)}


class ModeManagerAdapter(CoreAdapter):
    """mode_manager_node's runner (dukw_control.runners.ModeManagerRunner)."""

    name = 'mode_manager'
    inputs = ('water/contact', 'depth', 'traction', 'tracks/status', 'imu/data')
    outputs = ('drive_mode',)
    fields = MappingProxyType({
        'water/contact': ('fore_wet', 'aft_wet'), 'depth': ('valid', 'depth_m'),
        'traction': ('weight_on_tracks_fraction', 'afloat'),
        'tracks/status': ('connected', 'port.force_n', 'stbd.force_n'),
        'imu/data': STAMP_FIELDS,
        'drive_mode': ('mode', 'automatic', 'track_weight', 'prop_weight', 'tracks_idle')})

    def __init__(self, config_path: str | None = None,
                 runner: ModeManagerRunner | None = None) -> None:
        self.runner = runner or ModeManagerRunner.from_params(
            node_params('mode_manager_node', config_path))
        self.rate_hz = self.runner.rate_hz
        self.core = self.runner.core
        self._handlers = self._handle()

    def feed(self, topic, t_s, msg):
        handler = self._handlers.get(topic)
        if handler is not None:
            handler(msg, t_s)
        return None

    def _handle(self) -> dict[str, Callable[[Any, float], Any]]:
        """Per input topic: message -> runner call (a lookup, not a chain of ifs)."""
        r = self.runner
        return {
            'water/contact': lambda v, t_s: r.on_water_contact(v[0], v[1], t_s),
            'depth': lambda v, t_s: r.on_depth(v[0], v[1], t_s),
            'traction': lambda v, t_s: r.on_traction(v[0], v[1], t_s),
            'tracks/status': lambda v, t_s: r.on_track_status(v[0], v[1], v[2], t_s),
            'imu/data': lambda v, t_s: r.on_imu(stamp_s_or(v[0], v[1], t_s), t_s)}

    def tick(self, t_s):
        """Every tick's decision is compared (the node publishes only some of them)."""
        self.runner.tick(t_s)
        return decision_row(self.core.decision())

    def recorded(self, topic, msg):
        return _decision_row(*msg)


class DriveControllerAdapter(CoreAdapter):
    """drive_controller_node's runner (dukw_control.runners.DriveControllerRunner)."""

    name = 'drive_controller'
    inputs = ('cmd_vel', 'authority', 'drive_mode', 'odometry/filtered', 'imu/data',
              'traction', 'tracks/status')
    outputs = ('tracks/cmd', 'props/cmd')
    #: (cmd_vel, authority and drive_mode come as messages: the first's type varies, the
    #: others carry the strings the core reads; they are few)
    fields = MappingProxyType({
        'odometry/filtered': ('twist.twist.linear.x', 'twist.twist.angular.z',
                              'pose.pose.orientation.x', 'pose.pose.orientation.y',
                              'pose.pose.orientation.z', 'pose.pose.orientation.w'),
        'imu/data': STAMP_FIELDS,
        'traction': ('port_slip', 'stbd_slip', 'weight_on_tracks_fraction'),
        'tracks/status': ('connected', 'port.current_a', 'stbd.current_a'),
        'tracks/cmd': ('port_pct', 'stbd_pct'), 'props/cmd': ('port_pct', 'stbd_pct')})

    def __init__(self, config_path: str | None = None,
                 runner: DriveControllerRunner | None = None) -> None:
        self.runner = runner or DriveControllerRunner.from_params(
            node_params('drive_controller_node', config_path))
        self.rate_hz = self.runner.rate_hz
        self.core = self.runner.core
        self._handlers = self._handle()

    def feed(self, topic, t_s, msg):
        handler = self._handlers.get(topic)
        if handler is None:
            return None
        out = handler[0](msg, t_s)
        return out if handler[1] else None

    def _handle(self) -> dict[str, tuple[Callable[[Any, float], Any], bool]]:
        """Per input topic: (message -> runner call, whether that call steps and its result
        is an output row) -- a lookup, not a chain of ifs."""
        r, c = self.runner, control_convert

        def cmd_vel(msg, t_s):          # Twist or TwistStamped, whichever the bag holds
            speed_mps, yaw_rate_rps, stamp_s = read_cmd_vel(msg)
            r.on_cmd_vel(speed_mps, yaw_rate_rps, t_s, stamp_s)

        def odometry(v, t_s):
            return control_row(r.on_odometry(v[0], v[1], c.quaternion_pitch_rad(*v[2:]), t_s))
        return {
            'cmd_vel': (cmd_vel, False),
            'authority': (lambda msg, t_s: control_row(r.on_authority(
                *c.authority_usable(msg), t_s)), True),
            'drive_mode': (lambda msg, t_s: r.on_mode(c.decision_from_msg(msg), t_s), False),
            'odometry/filtered': (odometry, True),
            'imu/data': (lambda v, t_s: r.on_imu(stamp_s_or(v[0], v[1], t_s), t_s), False),
            'traction': (lambda v, t_s: r.on_traction(v[0], v[1], v[2], t_s), False),
            'tracks/status': (lambda v, t_s: r.on_track_status(v[0], v[1], v[2], t_s), False)}

    def tick(self, t_s):
        return control_row(self.runner.tick(t_s))

    #: recorded output topic -> its row names (made once, not per message)
    _ROW_NAMES = {topic: tuple(_side_row(topic.split('/')[0], 0.0, 0.0)) for topic in outputs}

    def recorded_columns(self, topic, msgs):
        port_name, stbd_name = self._ROW_NAMES[topic]
        port_pct, stbd_pct = zip(*msgs, strict=True)
        return {port_name: port_pct, stbd_name: stbd_pct}


#: nav_msgs/Odometry's fields the EKF's rows compare
_ODOMETRY_FIELDS = ('pose.pose.position.x', 'pose.pose.position.y', 'pose.pose.orientation.x',
                    'pose.pose.orientation.y', 'pose.pose.orientation.z',
                    'pose.pose.orientation.w', 'twist.twist.linear.x', 'twist.twist.angular.z')


class EkfAdapter(CoreAdapter):
    """ekf_node's runner (dukw_estimation.runner.EkfRunner)."""

    name = 'ekf'
    inputs = tuple(ros_convert.SAMPLE_FROM_FIELDS)
    outputs = ('odometry/filtered', 'traction')
    angle_quantities = frozenset({'odom.yaw_rad'})
    #: traction fields compared (the message's float fields)
    TRACTION_FIELDS = ros_convert.TRACTION_FIELDS
    #: each input's header stamp, then the fields its node's conversion reads
    fields = MappingProxyType({
        **{topic: STAMP_FIELDS + ros_convert.SAMPLE_FIELDS[topic] for topic in inputs},
        'odometry/filtered': _ODOMETRY_FIELDS, 'traction': TRACTION_FIELDS})
    #: the traction's row names (a row per estimate: made once)
    _TRACTION_KEYS = tuple(f'traction.{name}' for name in TRACTION_FIELDS)

    def __init__(self, config_path: str | None = None, runner: EkfRunner | None = None) -> None:
        self.runner = runner or EkfRunner.from_params(node_params('ekf_node', config_path))
        self.rate_hz = self.runner.rate_hz
        self.core = self.runner.estimator

    def feed(self, topic, t_s, msg):
        """``msg``: the stamp's fields, then the conversion's (as ekf_node converts)."""
        sample = ros_convert.SAMPLE_FROM_FIELDS[topic](stamp_s_or(msg[0], msg[1], t_s),
                                                        *msg[2:])
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

    _traction_values = staticmethod(attrgetter(*TRACTION_FIELDS))

    def recorded_columns(self, topic, msgs):
        columns = tuple(zip(*msgs, strict=True))
        if topic != 'odometry/filtered':
            return dict(zip(self._TRACTION_KEYS, columns, strict=True))
        x_m, y_m, qx, qy, qz, qw, surge_mps, yaw_rate_rps = columns
        yaw_rad = [euler_from_quaternion(*q)[2] for q in zip(qx, qy, qz, qw, strict=True)]
        return {'odom.x_m': x_m, 'odom.y_m': y_m, 'odom.yaw_rad': yaw_rad,
                'odom.surge_mps': surge_mps, 'odom.yaw_rate_rps': yaw_rate_rps}


#: adapter name -> factory (config path -> adapter)
ADAPTERS: dict[str, Callable[..., CoreAdapter]] = {
    'mode_manager': ModeManagerAdapter, 'drive_controller': DriveControllerAdapter,
    'ekf': EkfAdapter}
