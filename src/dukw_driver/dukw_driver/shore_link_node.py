"""shore_link_node: the vehicle as a signed MAVLink 2 vehicle for a ground station (issue 15).

Radio (``url``) <-> dukw_driver.shore_link core. Subscribes odometry/filtered, gps/fix,
imu/data, traction, tracks/status, props/status (sensor QoS), drive_mode, authority,
mission/status (latched); publishes cmd_vel (MANUAL_CONTROL, reliable),
mission/plan and mission/hold (latched, for mission_node), /diagnostics; calls
set_mode (the mode manager) for DO_SET_MODE / SET_MODE. Shore commands reach the
motors only through cmd_vel -> drive controller -> servo switch.
"""
import time
from pathlib import Path

from diagnostic_msgs.msg import DiagnosticArray
from dukw_msgs.msg import Authority, DriveMode, DrivetrainStatus, Traction
from dukw_msgs.srv import SetMode
from nav_msgs.msg import Odometry
from rclpy.node import Node
from sensor_msgs.msg import Imu, NavSatFix
from std_msgs.msg import Bool, String

from dukw_common.cmd_vel import CMD_VEL_STAMPED_SPEC, cmd_vel_type, make_cmd_vel
from dukw_common.config import ConfigError
from dukw_common.diagnostics import Level
from dukw_common.node_tools import (COMMAND_QOS, SENSOR_QOS, STATE_QOS, declare_parameters,
                                    diagnostic_array, run_node)
from dukw_driver import shore_messages as conv
from dukw_driver.mavlink_signing import SecureSigning, TimestampStore, load_key
from dukw_driver.shore_link import (DriveCommand, MissionHold, MissionPlan, ModeRequest,
                                    ShoreLink, settings_from_params)
from dukw_driver.shore_transport import MavlinkPort


class ShoreLinkNode(Node):
    """Moves bytes between the radio and the core, and the core's actions onto ROS."""

    def __init__(self, **kwargs) -> None:
        super().__init__('shore_link_node', **kwargs)
        p = declare_parameters(self, [*conv.PARAMS, CMD_VEL_STAMPED_SPEC])
        settings, tuning = settings_from_params(p)
        self.store, signing = TimestampStore(None), None
        if p['signing']:
            if not p['signing_key_file']:
                raise ConfigError("shore_link_node: 'signing_key_file' is required while "
                                  "'signing' is true")
            key_file = Path(p['signing_key_file']).expanduser()
            self.store = TimestampStore(p['timestamp_file'] or f'{key_file}.timestamps')
            signing = SecureSigning(load_key(key_file), link_id=p['signing_link_id'],
                                    allow_unsigned=p['allow_unsigned'], state=self.store.load())
        self.port = MavlinkPort(p['url'], settings.radio_baud, p['reconnect_period_s'])
        self.core = ShoreLink(settings, tuning, signing, time.monotonic())
        self.last = (time.monotonic(), 0, 0)
        self.stamped = bool(p['cmd_vel_stamped'])
        self.cmd_pub = self.create_publisher(cmd_vel_type(self.stamped), 'cmd_vel', COMMAND_QOS)
        self.plan_pub = self.create_publisher(String, 'mission/plan', STATE_QOS)
        self.hold_pub = self.create_publisher(Bool, 'mission/hold', STATE_QOS)
        self.diag_pub = self.create_publisher(DiagnosticArray, '/diagnostics', 10)
        self.set_mode = self.create_client(SetMode, 'set_mode')
        self._subscribe()
        self.create_timer(1.0 / p['poll_rate_hz'], self._poll)
        self.create_timer(p['diagnostics_period_s'], self._report)
        self.create_timer(p['timestamp_save_period_s'], self._save)
        self.get_logger().info(f'shore link on {self.port.url}, signing '
                               f'{"on" if signing else "OFF"}')

    def _subscribe(self) -> None:
        core, sub = self.core, self.create_subscription
        self.rates_flu = (0.0, 0.0, 0.0)
        sub(Imu, 'imu/data', self._on_imu, SENSOR_QOS)
        sub(Odometry, 'odometry/filtered', lambda m: setattr(
            core.state, 'pose', conv.pose_from_odometry(m, self.rates_flu)), SENSOR_QOS)
        sub(NavSatFix, 'gps/fix', lambda m: setattr(core.state, 'fix', conv.fix_from_navsat(m)),
            SENSOR_QOS)
        sub(Traction, 'traction', lambda m: setattr(
            core.state, 'traction', conv.traction_from_msg(m)), SENSOR_QOS)
        for which in ('tracks', 'props'):
            sub(DrivetrainStatus, f'{which}/status', lambda m, w=which: core.update_drive(
                w, conv.drive_from_status(m)), SENSOR_QOS)
        sub(DriveMode, 'drive_mode', lambda m: core.update_mode(m.mode, m.automatic, m.reason),
            STATE_QOS)
        sub(Authority, 'authority', lambda m: core.update_authority(
            m.holder, m.rc_link_ok, m.detail), STATE_QOS)
        sub(String, 'mission/status', self._on_mission, STATE_QOS)

    def _on_imu(self, msg: Imu) -> None:
        w = msg.angular_velocity
        self.rates_flu = (w.x, w.y, w.z)

    def _on_mission(self, msg: String) -> None:
        progress = conv.mission_progress(msg.data)
        if progress is not None:
            self.core.update_mission(*progress)

    def _poll(self) -> None:
        now = time.monotonic()
        actions = self.core.receive(self.port.poll(), now) + self.core.tick(now)
        for action in actions:
            if isinstance(action, DriveCommand):
                stamp_s = self.get_clock().now().nanoseconds * 1e-9
                self.cmd_pub.publish(make_cmd_vel(self.stamped, action.speed_mps,
                                                  action.yaw_rate_rps, stamp_s))
            elif isinstance(action, MissionHold):
                self.hold_pub.publish(Bool(data=action.hold))
            elif isinstance(action, MissionPlan):
                self.plan_pub.publish(String(data=conv.plan_json(action)))
            elif isinstance(action, ModeRequest):
                self._request_mode(action)
        self.port.write(self.core.take_output())

    def _request_mode(self, request: ModeRequest) -> None:
        if not self.set_mode.service_is_ready():
            self.core.mode_result(request, False, 'set_mode service not available')
            return
        future = self.set_mode.call_async(SetMode.Request(mode=request.mode,
                                                          automatic=request.automatic))
        future.add_done_callback(lambda f: self.core.mode_result(
            request, f.result() is not None and f.result().success,
            f.result().message if f.result() is not None else 'no answer'))

    def _report(self) -> None:
        now, port = time.monotonic(), self.port
        t0, in0, out0 = self.last
        dt = max(now - t0, 1e-6)
        self.last = (now, port.bytes_in, port.bytes_out)
        health = self.core.health((port.bytes_out - out0) / dt, (port.bytes_in - in0) / dt)
        health.hardware_id = port.url
        health.values.update(connected=port.connected, reconnects=port.reconnects,
                             link_errors=port.errors, last_error=port.last_error)
        if not port.connected:
            health.worsen(Level.ERROR, f'{port.url} not connected: {port.last_error}')
        self.diag_pub.publish(diagnostic_array(self, [health]))

    def _save(self) -> None:
        if self.core.signing is not None:
            self.store.save(self.core.signing.snapshot())

    def on_shutdown(self) -> None:
        """Save the signing timestamps, release the radio."""
        self._save()
        self.port.close()


def main(args=None) -> int:
    """Console-script entry point."""
    return run_node(ShoreLinkNode, args)


if __name__ == '__main__':
    raise SystemExit(main())
