"""ekf_node through real rclpy topics: synthetic sensors in, odometry and traction out."""
import math

import pytest
from diagnostic_msgs.msg import DiagnosticArray
from dukw_msgs.msg import DrivetrainStatus, Traction
from dukw_msgs.srv import SetPose
from geometry_msgs.msg import TwistWithCovarianceStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Imu, NavSatFix
from tf2_msgs.msg import TFMessage

from dukw_common.config import node_params
from dukw_common.geometry import geodetic_from_local_enu, quaternion_from_euler
from dukw_common.node_tools import COMMAND_QOS, SENSOR_QOS
from dukw_common.testing import ros_node, spin_until
from dukw_common.tf_tools import TF_QOS
from dukw_estimation.ekf_node import EkfNode

pytestmark = pytest.mark.ros

PARAMS = node_params('ekf_node')
DATUM = (PARAMS['datum.latitude_deg'], PARAMS['datum.longitude_deg'], 0.0)
START = (-5.0, 2.0)          # odom position the fixes put the vehicle at
YAW = 0.3


def _fix(east: float, north: float) -> NavSatFix:
    msg = NavSatFix()
    msg.latitude, msg.longitude, msg.altitude = geodetic_from_local_enu(east, north, 0.0,
                                                                        *DATUM)
    msg.status.status = 0
    msg.position_covariance = [0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.04]
    msg.position_covariance_type = NavSatFix.COVARIANCE_TYPE_DIAGONAL_KNOWN
    return msg


def _imu() -> Imu:
    msg = Imu()
    q = quaternion_from_euler(0.0, 0.0, YAW)
    msg.orientation.x, msg.orientation.y, msg.orientation.z, msg.orientation.w = q
    msg.orientation_covariance[8] = 1e-4
    msg.linear_acceleration.z = 9.81
    return msg


class Harness:
    """A probe publishing synthetic sensors beside an in-process EkfNode (same context)."""

    def __init__(self, probe, executor) -> None:
        self.probe, self.executor = probe, executor
        self.ekf = EkfNode(context=probe.context)
        executor.add_node(self.ekf)
        self.odom: list[Odometry] = []
        self.traction: list[Traction] = []
        self.diag: list[DiagnosticArray] = []
        probe.create_subscription(Odometry, 'odometry/filtered', self.odom.append, COMMAND_QOS)
        probe.create_subscription(Traction, 'traction', self.traction.append, COMMAND_QOS)
        probe.create_subscription(DiagnosticArray, '/diagnostics', self.diag.append,
                                  COMMAND_QOS)
        self.pubs = {name: probe.create_publisher(cls, name, SENSOR_QOS) for name, cls in (
            ('imu/data', Imu), ('gps/fix', NavSatFix), ('gps/vel', TwistWithCovarianceStamped),
            ('tracks/status', DrivetrainStatus))}
        self.fix_east = START[0]

    def publish(self, topic: str, msg) -> None:
        msg.header.stamp = self.probe.get_clock().now().to_msg()
        self.pubs[topic].publish(msg)

    def tick(self) -> None:
        """One round of sensors, then a little spinning."""
        self.publish('imu/data', _imu())
        self.publish('gps/fix', _fix(self.fix_east, START[1]))
        self.publish('gps/vel', TwistWithCovarianceStamped())
        tracks = DrivetrainStatus()
        tracks.port.speed_mps = tracks.stbd.speed_mps = 0.0
        self.publish('tracks/status', tracks)
        for _ in range(12):   # leave the node's timers room between sensor bursts
            self.executor.spin_once(timeout_sec=0.005)

    def run_until(self, predicate, timeout_s: float = 15.0) -> bool:
        return spin_until(self.executor, lambda: (self.tick(), predicate())[1], timeout_s)

    def counter(self, sensor: str, key: str) -> int:
        for array in reversed(self.diag):
            for status in array.status:
                if status.name.endswith(f': {sensor}'):
                    return int({kv.key: kv.value for kv in status.values}[key])
        return -1


@pytest.fixture
def harness():
    with ros_node('ekf_probe') as (probe, executor):
        h = Harness(probe, executor)
        yield h
        executor.remove_node(h.ekf)
        h.ekf.destroy_node()


def _near_start(h: Harness) -> bool:
    if not h.odom:
        return False
    p = h.odom[-1].pose.pose.position
    return math.hypot(p.x - START[0], p.y - START[1]) < 0.3


def _same_estimate(h: Harness) -> bool:
    # odometry and traction are two topics: compare the pair from one publication
    return bool(h.traction) and h.traction[-1].header.stamp == h.odom[-1].header.stamp


def test_odometry_and_traction_come_out_and_a_nan_fix_is_counted(harness):
    assert harness.run_until(lambda: _near_start(harness) and _same_estimate(harness))
    odom = harness.odom[-1]
    assert odom.header.frame_id == 'odom' and odom.child_frame_id == 'base_link'
    q = odom.pose.pose.orientation
    assert 2 * math.atan2(q.z, q.w) == pytest.approx(YAW, abs=0.02)
    assert 0.0 < odom.pose.covariance[0] < 1.0      # x variance shrank from 10 m sigma
    traction = harness.traction[-1]
    assert traction.weight_on_tracks_fraction == pytest.approx(1.0)   # 5 m up the beach
    assert traction.submerged_volume_m3 == 0.0
    assert traction.waterline_distance_m == pytest.approx(START[0], abs=0.5)

    harness.fix_east = math.nan
    assert harness.run_until(lambda: harness.counter('gps_fix', 'rejected_nan') >= 3)
    harness.fix_east = START[0] + 500.0              # a wild fix: Mahalanobis outlier
    assert harness.run_until(lambda: harness.counter('gps_fix', 'rejected_outlier') >= 3)
    assert _near_start(harness)                      # neither moved the estimate


def test_set_pose_service_moves_the_estimate(harness):
    assert harness.run_until(lambda: _near_start(harness))
    client = harness.probe.create_client(SetPose, 'set_pose')
    assert client.wait_for_service(timeout_sec=5.0)
    future = client.call_async(SetPose.Request(x_m=20.0, y_m=-3.0, yaw_rad=1.0))
    assert spin_until(harness.executor, future.done, 5.0)
    assert future.result().success
    count = len(harness.odom)
    assert spin_until(harness.executor, lambda: len(harness.odom) > count + 2, 5.0)
    odom = harness.odom[-1].pose.pose
    assert (odom.position.x, odom.position.y) == pytest.approx((20.0, -3.0), abs=0.01)
    assert 2 * math.atan2(odom.orientation.z, odom.orientation.w) == pytest.approx(1.0)


def test_odom_to_base_link_goes_on_tf_with_each_estimate(harness):
    tfs = []
    harness.probe.create_subscription(TFMessage, '/tf', tfs.append, TF_QOS)
    assert harness.run_until(lambda: _near_start(harness) and len(tfs) > 5)
    by_stamp = {(o.header.stamp.sec, o.header.stamp.nanosec): o for o in harness.odom}
    checked = 0
    for message in tfs:
        (tf,) = message.transforms
        assert (tf.header.frame_id, tf.child_frame_id) == ('odom', 'base_link')
        odom = by_stamp.get((tf.header.stamp.sec, tf.header.stamp.nanosec))
        if odom is not None:
            assert tf.transform.translation.x == odom.pose.pose.position.x
            assert tf.transform.translation.y == odom.pose.pose.position.y
            assert tf.transform.rotation == odom.pose.pose.orientation
            checked += 1
    assert checked > 0
