"""drive_controller_node: cmd_vel -> tracks/cmd and props/cmd within the vehicle's limits.

A thin shell around dukw_control.runners.DriveControllerRunner (when to step) and
dukw_control.controller.DriveController (what to command): it converts messages and
publishes the commands (neutral on shutdown).
"""
from typing import Collection

from diagnostic_msgs.msg import DiagnosticArray
from dukw_msgs.msg import Authority, DrivetrainStatus, DriveMode, Traction
from nav_msgs.msg import Odometry
from rclpy.node import Node
from sensor_msgs.msg import Imu

from dukw_common.cmd_vel import CMD_VEL_STAMPED_SPEC, cmd_vel_type, read_cmd_vel
from dukw_common.config import ConfigError
from dukw_common.node_tools import (COMMAND_QOS, STATE_QOS, ParamSpec, declare_parameters,
                                    diagnostic_array, publisher_sources, run_node, stamp_or,
                                    subscribe_sensors, vehicle_specs)
from dukw_control.controller import NODE_PARAMS, ControlOutput
from dukw_control.convert import (ActuatorPublishers, authority_usable, decision_from_msg,
                                  pitch_from_quaternion)
from dukw_control.runners import DriveControllerRunner


class DriveControllerNode(Node):
    """Subscribes the requests and the vehicle's state; publishes guarded commands."""

    def __init__(self, handed_topics: Collection[str] = (), **node_kwargs) -> None:
        """``handed_topics``: inputs a composed process hands over (dukw_bringup.compose);
        a handed drive_mode is still watched for a second source, its content ignored."""
        super().__init__('drive_controller_node', **node_kwargs)
        specs = [ParamSpec(n, d, min=lo, max=hi) for n, d, lo, hi in NODE_PARAMS]
        specs.append(ParamSpec('step_on_odometry', 'run a control step on each estimate'))
        specs.append(CMD_VEL_STAMPED_SPEC)
        params = declare_parameters(self, specs + vehicle_specs('vehicle', 'drivetrain',
                                                                'limits'))
        try:
            self.runner = DriveControllerRunner.from_params(params)
        except ValueError as exc:
            raise ConfigError(f'drive_controller_node: {exc}') from exc
        self.core = self.runner.core
        self.commands = ActuatorPublishers(self, COMMAND_QOS)
        self.diag_pub = self.create_publisher(DiagnosticArray, '/diagnostics', COMMAND_QOS)
        self.create_subscription(cmd_vel_type(params['cmd_vel_stamped']), 'cmd_vel',
                                 self.on_cmd_vel, COMMAND_QOS)
        self.create_subscription(Authority, 'authority', self.on_authority, STATE_QOS)
        self.create_subscription(DriveMode, 'drive_mode', self.watch_mode_sources
                                 if 'drive_mode' in handed_topics else self.on_mode, STATE_QOS)
        self.inputs = {'odometry/filtered': (Odometry, self.on_odometry),
                       'imu/data': (Imu, self.on_imu), 'traction': (Traction, self.on_traction),
                       'tracks/status': (DrivetrainStatus, self.on_tracks),
                       'props/status': (DrivetrainStatus, self.on_props)}
        subscribe_sensors(self, self.inputs, handed_topics)
        self.props_connected = None
        self.last_reason = None
        self.create_timer(self.runner.period_s, self.on_tick)
        self.create_timer(params['diagnostics_period_s'], self.publish_diagnostics)

    def now_s(self) -> float:
        """Node clock (sim time under use_sim_time), seconds."""
        return self.get_clock().now().nanoseconds * 1e-9

    def on_cmd_vel(self, msg) -> None:
        """geometry_msgs/TwistStamped (its stamp ages it) or Twist, as cmd_vel_stamped says."""
        speed_mps, yaw_rate_rps, stamp_s = read_cmd_vel(msg)
        if not self.runner.on_cmd_vel(speed_mps, yaw_rate_rps, self.now_s(), stamp_s):
            self.get_logger().warn(f'cmd_vel rejected: {self.core.i.last_rejection}',
                                   throttle_duration_sec=1.0)

    def on_authority(self, msg: Authority) -> None:
        self.core.sources.update('authority', *publisher_sources(self, 'authority'))
        self.publish(self.runner.on_authority(*authority_usable(msg), self.now_s()))

    def on_mode(self, msg: DriveMode) -> None:
        self.watch_mode_sources(msg)
        self.runner.on_mode(decision_from_msg(msg), self.now_s())

    def watch_mode_sources(self, msg: DriveMode) -> None:
        """A second drive_mode publisher is a fault (neutral) even where the mode is handed
        over in-process: the rule of one source holds in both bring-up shapes."""
        self.core.sources.update('drive_mode', *publisher_sources(self, 'drive_mode'))

    def on_odometry(self, msg: Odometry) -> None:
        self.publish(self.runner.on_odometry(
            msg.twist.twist.linear.x, msg.twist.twist.angular.z,
            pitch_from_quaternion(msg.pose.pose.orientation), self.now_s()))

    def on_imu(self, msg: Imu) -> None:
        now = self.now_s()
        self.runner.on_imu(stamp_or(msg, now), now)

    def on_tick(self) -> None:
        self.publish(self.runner.tick(self.now_s()))

    def on_traction(self, msg: Traction) -> None:
        self.runner.on_traction(msg.port_slip, msg.stbd_slip, msg.weight_on_tracks_fraction,
                                self.now_s())

    def on_tracks(self, msg: DrivetrainStatus) -> None:
        self.runner.on_track_status(msg.connected, msg.port.current_a, msg.stbd.current_a,
                                    self.now_s())

    def on_props(self, msg: DrivetrainStatus) -> None:
        self.props_connected = msg.connected

    def publish(self, out: ControlOutput | None) -> None:
        """Publish a step's commands (None: the runner did not step)."""
        if out is None:
            return
        self.commands.publish(out.tracks, out.props)
        if out.neutral_reason != self.last_reason:
            self.last_reason = out.neutral_reason
            if out.neutral_reason:
                self.get_logger().info(f'neutral: {out.neutral_reason}')
            self.publish_diagnostics()

    def publish_diagnostics(self) -> None:
        healths = self.core.healths(self.now_s())
        healths[0].values['props_connected'] = self.props_connected
        self.diag_pub.publish(diagnostic_array(self, healths))

    def on_shutdown(self) -> None:
        """Last word: neutral on both actuators."""
        self.commands.neutral()


def main(args=None) -> int:
    """Console-script entry point."""
    return run_node(DriveControllerNode, args)


if __name__ == '__main__':
    raise SystemExit(main())
