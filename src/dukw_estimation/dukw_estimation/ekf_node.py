"""ekf_node: fuses IMU, DGPS, water contact, depth and motor status into odometry and traction.

Subscribes (sensor QoS) imu/data, gps/fix, gps/vel, water/contact, depth, tracks/status,
props/status; publishes odometry/filtered (odom -> base_link; also on /tf with
``publish_tf``, as robot_localization), traction and /diagnostics;
serves set_pose (dukw_msgs/srv/SetPose). The schedule (when the estimate goes out) is
dukw_estimation.runner's, the estimation dukw_estimation.estimator's.
"""
from __future__ import annotations

from typing import Callable, Collection

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
from dukw_common.node_tools import (COMMAND_QOS, ParamSpec, declare_parameters,
                                    diagnostic_array, refuse_second_client, run_node,
                                    s_to_stamp, stamp_or, subscribe_sensors,
                                    vehicle_specs)
from dukw_common.sources import SourceWatch
from dukw_common.tf_tools import TF_QOS, odometry_tf
from dukw_estimation import ros_convert as conv
from dukw_estimation.runner import EkfRunner, Estimate
from dukw_estimation.settings import setting_specs

DIAGNOSTICS_PERIOD_S = 1.0


class EkfNode(Node):
    """Thin shell around EkfRunner: messages in, estimates out."""

    def __init__(self, handed_topics: Collection[str] = (), **node_kwargs) -> None:
        """``handed_topics``: inputs a composed process hands over (dukw_bringup.compose)."""
        super().__init__('ekf_node', **node_kwargs)
        specs = [ParamSpec(n, d, min=lo, max=hi) for n, d, lo, hi in setting_specs()]
        specs += vehicle_specs()
        specs.append(ParamSpec('publish_on_imu', 'publish after each IMU sample, not only on '
                               'the timer'))
        specs.append(ParamSpec('publish_tf', 'broadcast odom -> base_link on /tf'))
        specs += [ParamSpec(f'{name}_rate_hz', f'most {name} messages a second (observers)',
                            min=0.1, max=1000.0) for name in ('tf', 'traction')]
        specs += [ParamSpec(f'soil_presets.{name}', 'soil preset value (vehicle.md 6)', min=0.0)
                  for name in section(node_params('ekf_node'), 'soil_presets')
                  if name != 'names']
        params = declare_parameters(self, specs)
        self.runner = EkfRunner.from_params(params)
        self.estimator = self.runner.estimator
        self.sources = SourceWatch()               # set_pose: one client, the operator's
        self.odom_pub = self.create_publisher(Odometry, 'odometry/filtered', COMMAND_QOS)
        self._odom_msg = Odometry()                # filled anew for each estimate
        self.traction_pub = self.create_publisher(Traction, 'traction', COMMAND_QOS)
        self.diag_pub = self.create_publisher(DiagnosticArray, '/diagnostics', COMMAND_QOS)
        self.tf_pub = (self.create_publisher(TFMessage, '/tf', TF_QOS)
                       if params['publish_tf'] else None)
        self.inputs = {topic: (msg_type, self._handler(topic)) for msg_type, topic in (
            (Imu, 'imu/data'), (NavSatFix, 'gps/fix'), (TwistWithCovarianceStamped, 'gps/vel'),
            (WaterContact, 'water/contact'), (Depth, 'depth'),
            (DrivetrainStatus, 'tracks/status'), (DrivetrainStatus, 'props/status'))}
        subscribe_sensors(self, self.inputs, handed_topics)
        #: called with each published estimate (a composed process's direct hand-off)
        self.estimate_listeners: list[Callable[[Estimate], None]] = []
        self.create_service(SetPose, 'set_pose', self._on_set_pose)
        self.create_timer(1.0 / self.runner.rate_hz, self._on_timer)
        self.create_timer(DIAGNOSTICS_PERIOD_S, self._on_diagnostics)

    def _now_s(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    def _handler(self, topic: str):
        convert = conv.SAMPLE_FROM_MSG[topic]

        def callback(msg) -> None:
            now = self._now_s()
            self._publish(self.runner.on_sample(topic, convert(msg, stamp_or(msg, now)),
                                                now))
        return callback

    def _on_timer(self) -> None:
        self._publish(self.runner.tick(self._now_s()))

    def _publish(self, estimate: Estimate | None) -> None:
        if estimate is None:
            return
        for listen in self.estimate_listeners:   # in-process consumers (commands) first,
            listen(estimate)                     # before the observers' messages
        stamp = s_to_stamp(estimate.t_s)
        odom = conv.odometry_msg(estimate.odometry, stamp, 'odom', 'base_link', self._odom_msg)
        self.odom_pub.publish(odom)
        if self.tf_pub is not None and estimate.tf_due:
            self.tf_pub.publish(odometry_tf(odom))
        if estimate.traction_due:
            self.traction_pub.publish(conv.traction_msg(estimate.traction, stamp, Traction))

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
        self.runner.seal()                         # (a held estimate keeps its traction)
        response.success = self.estimator.set_pose(request.x_m, request.y_m, request.yaw_rad)
        response.message = 'pose set' if response.success else 'refused: non-finite pose'
        return response


def main(args=None) -> int:
    """Console-script entry point."""
    return run_node(EkfNode, args)


if __name__ == '__main__':
    raise SystemExit(main())
