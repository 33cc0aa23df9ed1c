"""ekf_node: fuses IMU, DGPS, water contact, depth and motor status into odometry and traction.

Subscribes (sensor QoS) imu/data, gps/fix, gps/vel, water/contact, depth, tracks/status,
props/status; publishes odometry/filtered (odom -> base_link; also on /tf with
``publish_tf``, as robot_localization), traction and /diagnostics;
serves set_pose (dukw_msgs/srv/SetPose). All the work is in dukw_estimation.estimator.
"""
from __future__ import annotations

from diagnostic_msgs.msg import DiagnosticArray
from dukw_msgs.msg import Depth, DrivetrainStatus, Traction, WaterContact
from dukw_msgs.srv import SetPose
from geometry_msgs.msg import TwistWithCovarianceStamped
from nav_msgs.msg import Odometry
from rclpy.node import Node
from sensor_msgs.msg import Imu, NavSatFix
from tf2_msgs.msg import TFMessage

from dukw_common.config import node_params, section
from dukw_common.diagnostics import Health, Level
from dukw_common.node_tools import (COMMAND_QOS, SENSOR_QOS, ParamSpec, declare_parameters,
                                    diagnostic_array, refuse_second_client, run_node,
                                    s_to_stamp, vehicle_specs)
from dukw_common.sources import SourceWatch
from dukw_common.tf_tools import TF_QOS, odometry_tf
from dukw_common.vehicle import Vehicle, soil_params
from dukw_estimation import ros_convert as conv
from dukw_estimation.estimator import Estimator
from dukw_estimation.settings import EkfSettings, setting_specs

DIAGNOSTICS_PERIOD_S = 1.0


class EkfNode(Node):
    """Thin shell around Estimator: messages in, estimates out at rate_hz."""

    def __init__(self, **node_kwargs) -> None:
        super().__init__('ekf_node', **node_kwargs)
        specs = [ParamSpec(n, d, min=lo, max=hi) for n, d, lo, hi in setting_specs()]
        specs += vehicle_specs()
        specs.append(ParamSpec('publish_on_imu', 'publish after each IMU sample, not only on '
                               'the timer'))
        specs.append(ParamSpec('publish_tf', 'broadcast odom -> base_link on /tf'))
        specs += [ParamSpec(f'soil_presets.{name}', 'soil preset value (vehicle.md 6)', min=0.0)
                  for name in section(node_params('ekf_node'), 'soil_presets')
                  if name != 'names']
        params = declare_parameters(self, specs)
        self.settings = EkfSettings.from_params(params)
        self.publish_on_imu = bool(params['publish_on_imu'])
        self.last_event_publish_s = -1.0
        self.sources = SourceWatch()               # set_pose: one client, the operator's
        soil = soil_params(params, self.settings.soil_preset or None)
        self.estimator = Estimator(Vehicle.from_params(params), self.settings, soil)
        self.odom_pub = self.create_publisher(Odometry, 'odometry/filtered', COMMAND_QOS)
        self.traction_pub = self.create_publisher(Traction, 'traction', COMMAND_QOS)
        self.diag_pub = self.create_publisher(DiagnosticArray, '/diagnostics', COMMAND_QOS)
        self.tf_pub = (self.create_publisher(TFMessage, '/tf', TF_QOS)
                       if params['publish_tf'] else None)
        est = self.estimator
        for msg_type, topic, convert, add in (
                (Imu, 'imu/data', conv.imu_sample, est.add_imu),
                (NavSatFix, 'gps/fix', conv.gps_fix, est.add_gps_fix),
                (TwistWithCovarianceStamped, 'gps/vel', conv.gps_velocity,
                 est.add_gps_velocity),
                (WaterContact, 'water/contact', conv.water_contact, est.add_water_contact),
                (Depth, 'depth', conv.depth, est.add_depth),
                (DrivetrainStatus, 'tracks/status', conv.drive_status, est.add_tracks),
                (DrivetrainStatus, 'props/status', conv.drive_status, est.add_props)):
            self.create_subscription(msg_type, topic, self._handler(convert, add), SENSOR_QOS)
        self.create_service(SetPose, 'set_pose', self._on_set_pose)
        self.create_timer(1.0 / self.settings.rate_hz, self._on_timer)
        self.create_timer(DIAGNOSTICS_PERIOD_S, self._on_diagnostics)

    def _now_s(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    def _handler(self, convert, add):
        publish = self.publish_on_imu and add == self.estimator.add_imu

        def callback(msg) -> None:
            now = self._now_s()
            add(convert(msg, conv.stamp_or(msg, now)))
            if publish and self.estimator.t_s is not None:
                self.last_event_publish_s = now
                self._publish()
        return callback

    def _on_timer(self) -> None:
        est = self.estimator
        now = self._now_s()
        if est.t_s is None or now - self.last_event_publish_s < 1.5 / self.settings.rate_hz:
            return  # nothing measured yet, or the IMU drives the output
        if 0.0 < now - est.t_s <= self.settings.sensor_timeout_s:
            est.advance(now)  # predict to the present, never further than a timeout
        self._publish()

    def _publish(self) -> None:
        est = self.estimator
        stamp = s_to_stamp(est.t_s)
        odom = conv.odometry_msg(est.odometry(), stamp, 'odom', 'base_link')
        self.odom_pub.publish(odom)
        if self.tf_pub is not None:
            self.tf_pub.publish(odometry_tf(odom))
        self.traction_pub.publish(conv.traction_msg(est.traction(), stamp, Traction))

    def _on_diagnostics(self) -> None:
        healths = self.estimator.health(self._now_s())
        if self.sources.fault():                   # a second set_pose client
            healths.append(Health('set_pose', Level.ERROR, self.sources.fault()))
        self.diag_pub.publish(diagnostic_array(self, healths))

    def _on_set_pose(self, request, response):
        refusal = refuse_second_client(self, self.sources, 'set_pose', self._on_diagnostics)
        if refusal:                                # one client (the operator's) or none
            response.success, response.message = False, refusal
            return response
        response.success = self.estimator.set_pose(request.x_m, request.y_m, request.yaw_rad)
        response.message = 'pose set' if response.success else 'refused: non-finite pose'
        return response


def main(args=None) -> int:
    """Console-script entry point."""
    return run_node(EkfNode, args)


if __name__ == '__main__':
    raise SystemExit(main())
