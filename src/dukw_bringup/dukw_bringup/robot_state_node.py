"""robot_state_node: the vehicle's URDF on ``robot_description`` and its frames on /tf_static.

What robot_state_publisher does for a URDF of fixed joints, without a URDF file: the
model is built by dukw_common.description from the shared ``vehicle.*`` and ``sensors.*``
facts (the values the simulator's sensor model uses), so the drawing, the sensor frames
and the physics cannot drift apart. Both topics are latched (transient local) and sent
once: ``robot_description`` (std_msgs/String) and ``/tf_static`` (tf2_msgs/TFMessage:
base_link -> hulls, tracks, deck, imu_link, gps_link, the water sensors, the sounder).
"""
from __future__ import annotations

from rclpy.node import Node
from std_msgs.msg import String
from tf2_msgs.msg import TFMessage

from dukw_common.config import ConfigError
from dukw_common.description import FrameNames, VehicleModel
from dukw_common.node_tools import STATE_QOS, ParamSpec, declare_parameters, run_node, \
    vehicle_specs
from dukw_common.tf_tools import TF_STATIC_QOS, tf_message
from dukw_common.vehicle import sensor_mounts, vehicle_params


class RobotStateNode(Node):
    """Builds the model once and latches its description and static transforms."""

    def __init__(self) -> None:
        super().__init__('robot_state_node')
        specs = [ParamSpec('deck_thickness_m', 'deck plate thickness in the drawing, m',
                           min=0.001, max=0.5)]
        specs += [ParamSpec(f'frames.{name}', f'frame id of the {name} frame')
                  for name in FrameNames.__dataclass_fields__]
        params = declare_parameters(self, specs + vehicle_specs('vehicle', 'sensors'))
        try:
            self.model = VehicleModel.build(vehicle_params(params), sensor_mounts(params),
                                            FrameNames.from_params(params),
                                            float(params['deck_thickness_m']))
        except ValueError as exc:
            raise ConfigError(f'robot_state_node: {exc}') from exc
        self.description_pub = self.create_publisher(String, 'robot_description', STATE_QOS)
        self.tf_static_pub = self.create_publisher(TFMessage, '/tf_static', TF_STATIC_QOS)
        self.description_pub.publish(String(data=self.model.urdf()))
        stamp = self.get_clock().now().to_msg()
        self.tf_static_pub.publish(tf_message(self.model.static_transforms(), stamp))
        self.get_logger().info(f'robot_description and /tf_static: '
                               f'{len(self.model.links)} links fixed to {self.model.base}')

    def release_clock(self) -> RobotStateNode:
        """Drop this node's /clock subscription: it reads no clock after its one publication,
        and under use_sim_time its TimeSource would take /clock at 100 Hz for nothing (~2 %
        of a core in its own process, bench_stack --stack sim). Only for a process of its own:
        composed, the first node's TimeSource drives every node's clock (compose.share_clock).
        """
        self._time_source.detach_node()      # rclpy keeps it private, as compose.share_clock
        return self


def main(args=None) -> int:
    """Console-script entry point."""
    return run_node(lambda: RobotStateNode().release_clock(), args)


if __name__ == '__main__':
    raise SystemExit(main())
