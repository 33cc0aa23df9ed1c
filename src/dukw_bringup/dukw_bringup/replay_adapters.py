"""Adapters that put the stack's cores behind the offline replay harness.

Each adapter does what its node does, without DDS: convert subscribed messages into
the core's inputs and step the core at the node's rate. Only cores that import are
offered (``factories``); a core still missing is named by ``missing``.
"""
from __future__ import annotations

from typing import Callable

from dukw_bringup.replay import CoreAdapter

#: adapter name -> (module that must import, factory)
_REGISTRY: dict[str, tuple[str, Callable[[], CoreAdapter]]] = {}
_MISSING: dict[str, str] = {}


def _register(name: str, module: str):
    def wrap(factory: Callable[[], CoreAdapter]) -> Callable[[], CoreAdapter]:
        _REGISTRY[name] = (module, factory)
        return factory
    return wrap


def factories() -> dict[str, Callable[[], CoreAdapter]]:
    """Factories of the adapters whose core imports."""
    import importlib
    out = {}
    for name, (module, factory) in _REGISTRY.items():
        try:
            importlib.import_module(module)
        except ImportError as exc:
            _MISSING[name] = str(exc)
            continue
        out[name] = factory
    return out


def missing() -> dict[str, str]:
    """Adapters whose core did not import, with the reason."""
    factories()
    return dict(_MISSING)


def _node_params(node_name: str, config_path: str | None) -> dict:
    from dukw_common.config import node_params
    return node_params(node_name, config_path)


def _stamp_or(msg, fallback_s: float) -> float:
    t_s = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
    return t_s if t_s > 0.0 else fallback_s


def _side_row(prefix: str, port: float, stbd: float) -> dict[str, float]:
    return {f'{prefix}.port_pct': float(port), f'{prefix}.stbd_pct': float(stbd)}


def _decision_row(mode, automatic, track_weight, prop_weight, tracks_idle) -> dict[str, float]:
    return {'mode': float(int(mode)), 'automatic': float(bool(automatic)),
            'track_weight': float(track_weight), 'prop_weight': float(prop_weight),
            'tracks_idle': float(bool(tracks_idle))}


class ModeManagerAdapter(CoreAdapter):
    """dukw_control.modes.ModeManager as mode_manager_node drives it."""

    name = 'mode_manager'
    inputs = ('water/contact', 'depth', 'traction', 'tracks/status', 'imu/data')
    outputs = ('drive_mode',)

    def __init__(self, config_path: str | None = None) -> None:
        from dukw_control.modes import ModeManager, settings_from_params
        params = _node_params('mode_manager_node', config_path)
        self.rate_hz = float(params['rate_hz'])
        self.core = ModeManager(settings_from_params(params))

    def feed(self, topic, t_s, msg):
        if topic == 'water/contact':
            self.core.on_water_contact(msg.fore_wet, msg.aft_wet, t_s)
        elif topic == 'depth':
            self.core.on_depth(msg.valid, msg.depth_m, t_s)
        elif topic == 'traction':
            self.core.on_traction(msg.weight_on_tracks_fraction, t_s)
        elif topic == 'tracks/status' and msg.connected:
            self.core.on_track_forces(msg.port.force_n, msg.stbd.force_n, t_s)
        elif topic == 'imu/data':
            self.core.on_attitude(_stamp_or(msg, t_s), t_s)
        return None

    def tick(self, t_s):
        d = self.core.update(t_s)
        return _decision_row(d.mode, d.automatic, d.track_weight, d.prop_weight, d.tracks_idle)

    def recorded(self, topic, msg):
        return _decision_row(msg.mode, msg.automatic, msg.track_weight, msg.prop_weight,
                             msg.tracks_idle)


class DriveControllerAdapter(CoreAdapter):
    """dukw_control.controller.DriveController as drive_controller_node drives it.

    With ``step_on_odometry`` the node steps on every odometry/filtered message and its
    timer steps only while the estimator is silent (1.5 periods); pitch then comes from
    the odometry orientation (older nodes: a step per timer tick, pitch from imu/data).
    """

    name = 'drive_controller'
    inputs = ('cmd_vel', 'authority', 'drive_mode', 'odometry/filtered', 'imu/data',
              'traction', 'tracks/status')
    outputs = ('tracks/cmd', 'props/cmd')

    def __init__(self, config_path: str | None = None) -> None:
        from dukw_common.cmd_vel import read_cmd_vel
        from dukw_control import convert
        from dukw_control.controller import DriveController, settings_from_params
        params = _node_params('drive_controller_node', config_path)
        self.rate_hz = float(params['rate_hz'])
        self.core = DriveController(settings_from_params(params))
        self.convert = convert
        self.read_cmd_vel = read_cmd_vel
        self.step_on_odometry = bool(params.get('step_on_odometry', False))
        self.pitch_from_odometry = hasattr(convert, 'pitch_from_quaternion')
        self.last_event_step_s = -1.0

    def feed(self, topic, t_s, msg):
        core = self.core
        if topic == 'cmd_vel':          # Twist or TwistStamped, whichever the bag holds
            speed_mps, yaw_rate_rps, stamp_s = self.read_cmd_vel(msg)
            core.on_cmd_vel(speed_mps, yaw_rate_rps, t_s, stamp_s)
        elif topic == 'authority':
            usable, detail = self.convert.authority_usable(msg)
            core.on_authority(usable, detail, t_s)
            if not usable:
                return self._step(t_s)  # the node goes neutral at once
        elif topic == 'drive_mode':
            core.on_mode(self.convert.decision_from_msg(msg), t_s)
        elif topic == 'odometry/filtered':
            core.on_odometry(msg.twist.twist.linear.x, msg.twist.twist.angular.z, t_s)
            if self.pitch_from_odometry:
                core.on_pitch(self.convert.pitch_from_quaternion(msg.pose.pose.orientation),
                              t_s)
            if self.step_on_odometry:
                self.last_event_step_s = t_s
                return self._step(t_s)
        elif topic == 'imu/data':
            core.on_attitude(_stamp_or(msg, t_s), t_s)
            if not self.pitch_from_odometry:
                core.on_pitch(self.convert.pitch_from_imu(msg), t_s)
        elif topic == 'traction':
            core.on_slips(msg.port_slip, msg.stbd_slip, t_s)
        elif topic == 'tracks/status' and msg.connected:
            core.on_track_currents(msg.port.current_a, msg.stbd.current_a, t_s)
        return None

    def _step(self, t_s: float) -> dict[str, float]:
        out = self.core.step(t_s)
        return {**_side_row('tracks', out.tracks.port, out.tracks.stbd),
                **_side_row('props', out.props.port, out.props.stbd)}

    def tick(self, t_s):
        if self.step_on_odometry and t_s - self.last_event_step_s < 1.5 / self.rate_hz:
            return None              # stepped on odometry: the timer only guards silence
        return self._step(t_s)

    def recorded(self, topic, msg):
        return _side_row(topic.split('/')[0], msg.port_pct, msg.stbd_pct)


class EkfAdapter(CoreAdapter):
    """dukw_estimation.estimator.Estimator as ekf_node drives it: with ``publish_on_imu``
    it publishes after each IMU sample and its timer only while the IMU is silent."""

    name = 'ekf'
    inputs = ('imu/data', 'gps/fix', 'gps/vel', 'water/contact', 'depth', 'tracks/status',
              'props/status')
    outputs = ('odometry/filtered', 'traction')
    angle_quantities = frozenset({'odom.yaw_rad'})
    #: traction fields compared (the message's float fields)
    TRACTION_FIELDS = ('port_slip', 'stbd_slip', 'submerged_volume_m3', 'effective_weight_n',
                       'weight_on_tracks_fraction', 'waterline_distance_m',
                       'submerged_length_m', 'slope_rad', 'port_force_predicted_n',
                       'stbd_force_predicted_n', 'port_force_measured_n',
                       'stbd_force_measured_n')

    def __init__(self, config_path: str | None = None) -> None:
        from dukw_common.vehicle import Vehicle, soil_params
        from dukw_estimation import ros_convert
        from dukw_estimation.estimator import Estimator
        from dukw_estimation.settings import EkfSettings
        params = _node_params('ekf_node', config_path)
        self.settings = EkfSettings.from_params(params)
        self.rate_hz = float(self.settings.rate_hz)
        self.core = Estimator(Vehicle.from_params(params), self.settings,
                              soil_params(params, self.settings.soil_preset or None))
        c = ros_convert
        self.routes = {
            'imu/data': (c.imu_sample, self.core.add_imu),
            'gps/fix': (c.gps_fix, self.core.add_gps_fix),
            'gps/vel': (c.gps_velocity, self.core.add_gps_velocity),
            'water/contact': (c.water_contact, self.core.add_water_contact),
            'depth': (c.depth, self.core.add_depth),
            'tracks/status': (c.drive_status, self.core.add_tracks),
            'props/status': (c.drive_status, self.core.add_props)}
        self.stamp_or = c.stamp_or
        self.publish_on_imu = bool(params.get('publish_on_imu', False))
        self.last_event_publish_s = -1.0

    def feed(self, topic, t_s, msg):
        convert, add = self.routes[topic]
        add(convert(msg, self.stamp_or(msg, t_s)))
        if topic == 'imu/data' and self.publish_on_imu and self.core.t_s is not None:
            self.last_event_publish_s = t_s
            return self.output()     # the node publishes on each IMU sample
        return None

    def tick(self, t_s):
        est = self.core
        if est.t_s is None or t_s - self.last_event_publish_s < 1.5 / self.rate_hz:
            return None              # nothing measured yet, or the IMU drives the output
        if 0.0 < t_s - est.t_s <= self.settings.sensor_timeout_s:
            est.advance(t_s)
        return self.output()

    def output(self) -> dict[str, float]:
        """The estimates the node would publish now."""
        est = self.core
        odom = est.odometry()
        row = {'odom.x_m': float(odom.x_m), 'odom.y_m': float(odom.y_m),
               'odom.yaw_rad': float(odom.yaw_rad), 'odom.surge_mps': float(odom.surge_mps),
               'odom.yaw_rate_rps': float(odom.yaw_rate_rps)}
        traction = est.traction()
        row.update({f'traction.{name}': float(getattr(traction, name))
                    for name in self.TRACTION_FIELDS if hasattr(traction, name)})
        return row

    @staticmethod
    def _odometry_row(msg) -> dict[str, float]:
        from dukw_common.geometry import euler_from_quaternion
        q = msg.pose.pose.orientation
        return {'odom.x_m': float(msg.pose.pose.position.x),
                'odom.y_m': float(msg.pose.pose.position.y),
                'odom.yaw_rad': float(euler_from_quaternion(q.x, q.y, q.z, q.w)[2]),
                'odom.surge_mps': float(msg.twist.twist.linear.x),
                'odom.yaw_rate_rps': float(msg.twist.twist.angular.z)}

    def recorded(self, topic, msg):
        if topic == 'odometry/filtered':
            return self._odometry_row(msg)
        return {f'traction.{name}': float(getattr(msg, name)) for name in self.TRACTION_FIELDS}


_register('mode_manager', 'dukw_control.modes')(ModeManagerAdapter)
_register('drive_controller', 'dukw_control.controller')(DriveControllerAdapter)
_register('ekf', 'dukw_estimation.estimator')(EkfAdapter)
