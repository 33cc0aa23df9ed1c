"""imu_gps_node: the GPS-aided IMU (MAVLink 2) and the differential GPS (NMEA 0183) -> ROS.

Publishes ``imu/data`` (sensor_msgs/Imu, frame ``imu_frame_id``: ENU orientation,
FLU rates and specific force), ``gps/fix`` (NavSatFix) and ``gps/vel``
(TwistWithCovarianceStamped, ENU axes, frame ``gps_frame_id``), all SENSOR_QOS,
and ``/diagnostics``. Decoding lives in mavlink_imu and nmea_gps.
"""
import math
import time

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import TwistWithCovarianceStamped
from rclpy.node import Node
from sensor_msgs.msg import Imu, NavSatFix, NavSatStatus

from dukw_common.node_tools import (SENSOR_QOS, ParamSpec, declare_parameters, diagnostic_array,
                                    run_node)
from dukw_driver.device_channel import DeviceChannel, link_from_params, require_name
from dukw_driver.gnss import (FixStatus, GnssFix, GnssVelocity, SourcePreference, UereSettings,
                              parse_source)
from dukw_driver.mavlink_imu import DecodedImu, ImuSettings, MavlinkImuDecoder
from dukw_driver.nmea_gps import GpsNmeaDecoder, NmeaGpsSettings
from dukw_driver.serial_link import DeviceHealth

STD = dict(min=0.0, max=100.0)
PARAMS = [
    ParamSpec('rate_hz', 'serial read rate, Hz', min=1.0, max=1000.0),
    ParamSpec('stale_after_s', 'no good message this long: ERROR, s', min=0.05, max=60.0),
    ParamSpec('mavlink.port', 'serial device of the IMU (MAVLink 2)'),
    ParamSpec('mavlink.baud', 'baud rate of the IMU', min=1200, max=921600),
    ParamSpec('mavlink.expected_rate_hz', 'IMU packets/s; WARN below half', min=0.0, max=1e4),
    ParamSpec('nmea.port', 'serial device of the DGPS (NMEA 0183)'),
    ParamSpec('nmea.baud', 'baud rate of the DGPS', min=1200, max=921600),
    ParamSpec('nmea.expected_rate_hz', 'DGPS sentences/s; WARN below half', min=0.0, max=1e4),
    ParamSpec('imu_frame_id', 'frame_id of imu/data'),
    ParamSpec('gps_frame_id', 'frame_id of gps/fix and gps/vel'),
    ParamSpec('fix_source', 'gps/fix from "nmea" (DGPS) or "mavlink" (IMU GPS)'),
    ParamSpec('vel_source', 'gps/vel from "nmea" (DGPS) or "mavlink" (IMU EKF)'),
    ParamSpec('source_fallback_s', 'preferred receiver silent this long: use the other, s',
              min=0.0, max=60.0),
    *(ParamSpec(f'imu.{n}', f'IMU {n} (vehicle.md section 2)', **STD) for n in (
        'accel_std_surge_mps2', 'accel_std_sway_mps2', 'accel_std_heave_mps2', 'gyro_std_dps',
        'orientation_std_roll_rad', 'orientation_std_pitch_rad', 'orientation_std_yaw_rad')),
    *(ParamSpec(f'gps.{n}', f'GPS {n}', **STD) for n in (
        'uere_autonomous_m', 'uere_differential_m', 'gst_max_age_s', 'speed_std_mps',
        'velocity_std_mps')),
]
UNKNOWN_VARIANCE = 1.0e6  # gps/vel angular rates: not measured


class ImuGpsNode(Node):
    """Reads both devices on a timer, publishes what they decode, reports their health."""

    def __init__(self, **kwargs) -> None:
        super().__init__('imu_gps_node', **kwargs)
        p = declare_parameters(self, PARAMS)
        self.imu_frame = require_name(p['imu_frame_id'], 'imu_frame_id')
        self.gps_frame = require_name(p['gps_frame_id'], 'gps_frame_id')
        self.fix_pref = SourcePreference(parse_source(p['fix_source'], 'fix_source'),
                                         p['source_fallback_s'])
        self.vel_pref = SourcePreference(parse_source(p['vel_source'], 'vel_source'),
                                         p['source_fallback_s'])
        uere = UereSettings(p['gps.uere_autonomous_m'], p['gps.uere_differential_m'])
        mav = MavlinkImuDecoder(ImuSettings(
            tuple(p[f'imu.orientation_std_{a}_rad'] for a in ('roll', 'pitch', 'yaw')),
            math.radians(p['imu.gyro_std_dps']),
            tuple(p[f'imu.accel_std_{a}_mps2'] for a in ('surge', 'sway', 'heave')),
            p['gps.velocity_std_mps'], uere))
        gps = GpsNmeaDecoder(NmeaGpsSettings(uere, p['gps.speed_std_mps'],
                                             p['gps.gst_max_age_s']))
        self.devices = [self._channel(p, 'mavlink', mav), self._channel(p, 'nmea', gps)]
        self.imu_pub = self.create_publisher(Imu, 'imu/data', SENSOR_QOS)
        self.fix_pub = self.create_publisher(NavSatFix, 'gps/fix', SENSOR_QOS)
        self.vel_pub = self.create_publisher(TwistWithCovarianceStamped, 'gps/vel', SENSOR_QOS)
        self.diag_pub = self.create_publisher(DiagnosticArray, '/diagnostics', 10)
        self.create_timer(1.0 / p['rate_hz'], self._poll)
        self.create_timer(1.0, self._report)

    @staticmethod
    def _channel(p: dict, name: str, decoder) -> DeviceChannel:
        health = DeviceHealth(name, p['stale_after_s'], p[f'{name}.expected_rate_hz'])
        return DeviceChannel(link_from_params(p, name), decoder.feed, decoder.counters, health)

    def _poll(self) -> None:
        now_s = time.monotonic()
        stamp = self.get_clock().now().to_msg()
        for device in self.devices:
            for item in device.poll(now_s):
                if isinstance(item, DecodedImu):
                    self.imu_pub.publish(self._imu(item, stamp))
                elif isinstance(item, GnssFix) and self.fix_pref.accept(
                        item.source, now_s, usable=item.status != FixStatus.NO_FIX):
                    self.fix_pub.publish(self._fix(item, stamp))
                elif isinstance(item, GnssVelocity) and self.vel_pref.accept(
                        item.source, now_s, usable=item.valid) and item.valid:
                    self.vel_pub.publish(self._vel(item, stamp))

    def _imu(self, s: DecodedImu, stamp) -> Imu:
        msg = Imu()
        msg.header.stamp, msg.header.frame_id = stamp, self.imu_frame
        o, w = msg.orientation, msg.angular_velocity
        o.x, o.y, o.z, o.w = s.orientation_xyzw
        w.x, w.y, w.z = s.angular_velocity_flu_rps
        if s.linear_acceleration_flu_mps2 is not None:
            a = msg.linear_acceleration
            a.x, a.y, a.z = s.linear_acceleration_flu_mps2
        msg.orientation_covariance = list(s.orientation_covariance)
        msg.angular_velocity_covariance = list(s.angular_velocity_covariance)
        msg.linear_acceleration_covariance = list(s.linear_acceleration_covariance)
        return msg

    def _fix(self, f: GnssFix, stamp) -> NavSatFix:
        msg = NavSatFix()
        msg.header.stamp, msg.header.frame_id = stamp, self.gps_frame
        msg.status = NavSatStatus(status=int(f.status), service=NavSatStatus.SERVICE_GPS)
        msg.latitude, msg.longitude, msg.altitude = (
            f.latitude_deg, f.longitude_deg, f.altitude_m)
        e, n, u = f.covariance_enu_m2
        msg.position_covariance = [e, 0.0, 0.0, 0.0, n, 0.0, 0.0, 0.0, u]
        msg.position_covariance_type = int(f.covariance_kind)
        return msg

    def _vel(self, v: GnssVelocity, stamp) -> TwistWithCovarianceStamped:
        msg = TwistWithCovarianceStamped()
        msg.header.stamp, msg.header.frame_id = stamp, self.gps_frame
        lin = msg.twist.twist.linear
        lin.x, lin.y, lin.z = v.east_mps, v.north_mps, v.up_mps
        diagonal = [*v.variance_enu, UNKNOWN_VARIANCE, UNKNOWN_VARIANCE, UNKNOWN_VARIANCE]
        msg.twist.covariance = [diagonal[i // 6] if i % 7 == 0 else 0.0 for i in range(36)]
        return msg

    def _report(self) -> None:
        now_s = time.monotonic()
        self.diag_pub.publish(diagnostic_array(self, [d.status(now_s) for d in self.devices]))

    def on_shutdown(self) -> None:
        """Release both serial devices."""
        for device in self.devices:
            device.close()


def main(args=None) -> int:
    """Console-script entry point."""
    return run_node(ImuGpsNode, args)


if __name__ == '__main__':
    raise SystemExit(main())
