"""mission_node: line-of-sight waypoint guidance on ``cmd_vel`` from ``odometry/filtered``.

Takes the newest ``odometry/filtered`` (nav_msgs/Odometry) at each tick; publishes ``cmd_vel``
(geometry_msgs/TwistStamped stamped with the node's clock, or Twist:
the shared ``cmd_vel_stamped``; reliable) at ``rate_hz`` and ``mission/status``
(std_msgs/String, one JSON object of dukw_bringup.mission.Progress, latched)
on every change of state or waypoint and at ``status_rate_hz``. The shore link
(or anyone) may replace the waypoints with ``mission/plan`` (std_msgs/String,
latched: ``{"waypoints": [{name, x_m, y_m, speed_mps}, ...]}``, empty = clear and
stop) and hold the mission with ``mission/hold`` (std_msgs/Bool, latched): while
held the node sends one zero velocity and then nothing, so another cmd_vel
source (the shore's MANUAL_CONTROL) is not fought. The mission
starts ``start_delay_s`` (mission file) after the first odometry; when it is
done, timed out or the node stops, it sends zero velocity. Time is the node's
clock, so with ``use_sim_time`` the mission runs on the simulator's /clock.
"""
from __future__ import annotations

import math

from nav_msgs.msg import Odometry
from rclpy.duration import Duration
from rclpy.node import Node
from std_msgs.msg import Bool, String

from dukw_bringup.mission import (LosGuidance, MissionState, VelocityCommand, load_mission,
                                  spec_with_plan)
from dukw_common.cmd_vel import CMD_VEL_STAMPED_SPEC, cmd_vel_type, make_cmd_vel
from dukw_common.config import ConfigError
from dukw_common.geometry import euler_from_quaternion
from dukw_common.node_tools import (COMMAND_QOS, STATE_QOS, LatestSamples, ParamSpec,
                                    declare_parameters, run_node)


class MissionNode(Node):
    """Feeds odometry to LosGuidance and its velocity commands to the controller."""

    def __init__(self) -> None:
        super().__init__('mission_node')
        self.params = declare_parameters(self, [
            ParamSpec('rate_hz', 'guidance and cmd_vel rate, Hz', min=1.0, max=100.0),
            ParamSpec('status_rate_hz', 'mission/status rate besides on changes, Hz',
                      min=0.1, max=50.0),
            ParamSpec('mission_file', "mission YAML; '' = config/mission.yaml"),
            ParamSpec('odometry_timeout_s', 'stop (zero cmd_vel) while odometry is older, s',
                      min=0.05, max=10.0),
            CMD_VEL_STAMPED_SPEC,
        ])
        self.stamped = bool(self.params['cmd_vel_stamped'])
        self.guidance = LosGuidance(load_mission(str(self.params['mission_file']) or None))
        self.pose: tuple[float, float, float] | None = None
        self.pose_time_s = -math.inf
        self.first_pose_s: float | None = None
        self.last_key: tuple = ()
        self.held = False
        self.cmd_pub = self.create_publisher(cmd_vel_type(self.stamped), 'cmd_vel', COMMAND_QOS)
        self.status_pub = self.create_publisher(String, 'mission/status', STATE_QOS)
        # guidance needs the newest pose at each tick (20 Hz), not every estimate (100 Hz):
        # taken at the tick (README "Topic contract"); its age counts from that tick
        self.polled = LatestSamples(self, {'odometry/filtered': (Odometry, self.on_odometry)})
        self.create_subscription(String, 'mission/plan', self.on_plan, STATE_QOS)
        self.create_subscription(Bool, 'mission/hold', self.on_hold, STATE_QOS)
        self.create_timer(1.0 / float(self.params['rate_hz']), self.on_tick)
        self.create_timer(1.0 / float(self.params['status_rate_hz']), self.publish_status)
        spec = self.guidance.spec
        self.get_logger().info(f'mission {spec.name!r}: {len(spec.waypoints)} waypoints, '
                               f'timeout {spec.timeout_s:.0f} s; waiting for odometry')

    def now_s(self) -> float:
        """The node's clock (sim time under use_sim_time), s."""
        return self.get_clock().now().nanoseconds * 1e-9

    def on_odometry(self, msg: Odometry) -> None:
        """Keep the latest planar pose; ignore a non-finite one."""
        q = msg.pose.pose.orientation
        _, _, yaw = euler_from_quaternion(q.x, q.y, q.z, q.w)
        pose = (msg.pose.pose.position.x, msg.pose.pose.position.y, yaw)
        if not all(math.isfinite(v) for v in pose):
            self.get_logger().warn('non-finite odometry ignored', throttle_duration_sec=5.0)
            return
        self.pose, self.pose_time_s = pose, self.now_s()
        if self.first_pose_s is None:
            self.first_pose_s = self.pose_time_s

    def on_plan(self, msg: String) -> None:
        """New waypoints: guidance starts over from where the vehicle is; empty: stop."""
        try:
            spec = spec_with_plan(self.guidance.spec, msg.data)
        except ConfigError as exc:
            self.get_logger().error(f'mission/plan refused: {exc}')
            return
        if spec is None:
            self.guidance.abort()
            self.get_logger().info('mission cleared')
            return
        self.guidance = LosGuidance(spec)
        self.last_key = ()
        self.get_logger().info(f'new plan: {len(spec.waypoints)} waypoints')

    def on_hold(self, msg: Bool) -> None:
        """Hold (one zero velocity, then silence) or let the mission run."""
        if msg.data and not self.held:
            self.publish_command(VelocityCommand())
        self.held = msg.data
        self.get_logger().info('mission held' if msg.data else 'mission runs')

    def on_tick(self) -> None:
        """Start when due, advance guidance, publish cmd_vel (nothing while held)."""
        self.polled.poll()
        now = self.now_s()
        if self.held:
            return
        progress = self.guidance.progress
        command = VelocityCommand()
        if self.pose is not None and now - self.pose_time_s <= self.params['odometry_timeout_s']:
            x, y, yaw = self.pose
            if (progress.state is MissionState.WAITING and self.first_pose_s is not None
                    and now - self.first_pose_s >= self.guidance.spec.start_delay_s):
                self.guidance.start(now, x, y)
                self.get_logger().info(f'mission started at x={x:.1f} y={y:.1f}')
            command = self.guidance.update(now, x, y, yaw)
        elif progress.state is MissionState.RUNNING:
            self.get_logger().warn('odometry stale: holding zero velocity',
                                   throttle_duration_sec=2.0)
        self.publish_command(command)
        key = (progress.state, progress.waypoint_index)
        if key != self.last_key:
            self.last_key = key
            if progress.state.finished:
                self.get_logger().info(f'mission {progress.state.value} after '
                                       f'{progress.elapsed_s:.1f} s')
            self.publish_status()

    def publish_command(self, command: VelocityCommand) -> None:
        """Send one cmd_vel."""
        self.cmd_pub.publish(make_cmd_vel(self.stamped, command.speed_mps,
                                          command.yaw_rate_rps, self.now_s()))

    def publish_status(self) -> None:
        """Send the progress as JSON."""
        self.status_pub.publish(String(data=self.guidance.progress.to_json()))

    def on_shutdown(self) -> None:
        """Abort (if running) and leave a zero velocity as the last command."""
        self.guidance.abort()
        self.publish_command(VelocityCommand())
        self.publish_status()
        for publisher in (self.cmd_pub, self.status_pub):  # deliver them before exiting
            publisher.wait_for_all_acked(Duration(seconds=0.5))

    def destroy_node(self) -> None:
        self.polled.destroy()
        super().destroy_node()


def main(args=None) -> int:
    """Console-script entry point."""
    return run_node(MissionNode, args)


if __name__ == '__main__':
    raise SystemExit(main())
