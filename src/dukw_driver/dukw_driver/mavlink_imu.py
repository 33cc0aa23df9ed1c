"""The GPS-aided IMU on MAVLink 2 (common dialect): attitude, rates, accelerations, GPS. ROS-free.

The device speaks NED (world) and FRD (body: x forward, y right, z down; heading
clockwise from north). Everything leaving this module is ROS: ENU world, FLU body
(REP 103), yaw counter-clockwise from east.

Messages used:

- ``ATTITUDE_QUATERNION`` (preferred once seen) or ``ATTITUDE``: orientation and
  body rates. Each one yields an ``DecodedImu``, with the latest acceleration.
- ``HIGHRES_IMU`` (m/s^2), else ``SCALED_IMU``, else ``RAW_IMU`` (both taken as
  milli-g, as ArduPilot and PX4 fill them): the specific force (at rest +g on
  the FLU z axis). A lower-priority source is ignored once a better one is seen.
- ``GPS_RAW_INT``: the IMU's GPS fix (``h_acc``/``v_acc`` when reported, else
  HDOP times a UERE).
- ``GLOBAL_POSITION_INT``: the IMU's EKF velocity (NED cm/s) -> ENU; valid only
  while the latest ``GPS_RAW_INT`` reports a fix (ArduPilot keeps sending zeros
  without one, which must not read as standing still).
"""
from __future__ import annotations

import math
import struct
from dataclasses import dataclass, field

from pymavlink.dialects.v20 import common as mavlink

from dukw_common.geometry import frd_to_flu, ned_to_enu, quaternion_from_euler, yaw_ned_to_enu
from dukw_driver.gnss import (CovarianceKind, FixStatus, GnssSource, GnssFix, GnssVelocity,
                              UereSettings, dop_covariance, finite)

STANDARD_GRAVITY_MPS2 = 9.80665
#: An acceleration older than this is not paired with a new attitude.
ACCEL_MAX_AGE_S = 0.5
#: GPS_RAW_INT fix_type -> NavSatStatus (5, 6 = RTK float/fixed; 4 = DGPS, usually SBAS).
GPS_FIX_STATUS = {2: FixStatus.FIX, 3: FixStatus.FIX, 4: FixStatus.SBAS_FIX,
                  5: FixStatus.GBAS_FIX, 6: FixStatus.GBAS_FIX, 7: FixStatus.FIX,
                  8: FixStatus.FIX}
IMU_PRIORITY = {'RAW_IMU': 1, 'SCALED_IMU': 2, 'HIGHRES_IMU': 3}
UINT16_UNKNOWN = 65535
START_MARKERS = (mavlink.PROTOCOL_MARKER_V1, mavlink.PROTOCOL_MARKER_V2)

_HALF_SQRT2 = math.sqrt(0.5)
#: Rotation NED -> ENU (180 deg about (1, 1, 0)/sqrt 2) and FLU -> FRD (180 deg about x), xyzw.
_Q_ENU_FROM_NED = (_HALF_SQRT2, _HALF_SQRT2, 0.0, 0.0)
_Q_FRD_FROM_FLU = (1.0, 0.0, 0.0, 0.0)


def quaternion_multiply(a: tuple, b: tuple) -> tuple:
    """Hamilton product a * b of (x, y, z, w) quaternions."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz)


def orientation_enu_flu_from_ned_frd(q_ned_frd_xyzw: tuple) -> tuple:
    """Body-to-world quaternion NED/FRD -> ENU/FLU (x, y, z, w), w >= 0."""
    q = quaternion_multiply(quaternion_multiply(_Q_ENU_FROM_NED, q_ned_frd_xyzw),
                            _Q_FRD_FROM_FLU)
    return q if q[3] >= 0 else tuple(-c for c in q)


def orientation_enu_flu_from_euler_ned(roll_rad: float, pitch_rad: float,
                                       yaw_rad: float) -> tuple:
    """MAVLink Euler angles (FRD body in NED) -> ENU/FLU quaternion (x, y, z, w).

    Roll keeps its sign, pitch flips (FRD nose up is FLU nose down), and the
    heading clockwise from north becomes yaw counter-clockwise from east.
    """
    q = quaternion_from_euler(roll_rad, -pitch_rad, yaw_ned_to_enu(yaw_rad))
    return q if q[3] >= 0 else tuple(-c for c in q)


def diagonal3(values: tuple) -> tuple:
    """Row-major 3x3 matrix with ``values`` on the diagonal."""
    a, b, c = values
    return (a, 0.0, 0.0, 0.0, b, 0.0, 0.0, 0.0, c)


@dataclass(frozen=True)
class ImuSettings:
    """Accuracies the device does not report (vehicle.md section 2, config ``imu.*``)."""

    orientation_std_rad: tuple[float, float, float]   # roll, pitch, yaw
    gyro_std_rps: float
    accel_std_mps2: tuple[float, float, float]         # surge, sway, heave
    velocity_std_mps: float
    uere: UereSettings


@dataclass(frozen=True)
class DecodedImu:
    """One sensor_msgs/Imu worth of data in ENU/FLU, as decoded (the published reading:
    dukw_common.readings.ImuSample); covariances row-major 3x3.

    ``linear_acceleration_flu_mps2`` is None when no recent acceleration came:
    then the message marks it unknown (covariance[0] = -1, REP 145).
    """

    orientation_xyzw: tuple[float, float, float, float]
    angular_velocity_flu_rps: tuple[float, float, float]
    linear_acceleration_flu_mps2: tuple[float, float, float] | None
    orientation_covariance: tuple
    angular_velocity_covariance: tuple
    linear_acceleration_covariance: tuple


@dataclass
class MavlinkCounters:
    """What the decoder has seen since start."""

    packets: int = 0        # well-formed packets (CRC good) of any type
    frame_errors: int = 0   # bad CRC or length, junk between packets
    unknown_ids: int = 0    # well-framed packets of ids the common dialect lacks (unchecked)
    parse_errors: int = 0   # well-formed packets with unusable values (NaN, out of range)
    ignored: int = 0        # packets of types not used (or superseded)
    by_type: dict[str, int] = field(default_factory=dict)

    @property
    def messages(self) -> int:
        """Good packets."""
        return self.packets

    @property
    def errors(self) -> int:
        """Frame plus value errors."""
        return self.frame_errors + self.parse_errors


Decoded = DecodedImu | GnssFix | GnssVelocity


class MavlinkImuDecoder:
    """Bytes from the IMU in, DecodedImu / GnssFix / GnssVelocity out; never raises."""

    def __init__(self, settings: ImuSettings) -> None:
        self.settings = settings
        self.counters = MavlinkCounters()
        self._parser = self._new_parser()
        self._suspect: tuple[object, bytes] | None = None   # an unknown-id frame, undecided
        self._use_quaternion = False
        self._imu_priority = 0
        self._accel: tuple[float, float, float] | None = None
        self._accel_time_s = -math.inf
        self._velocity_variance = settings.velocity_std_mps ** 2
        self._gps_has_fix = False       # until a GPS_RAW_INT reports one

    def feed(self, data: bytes, now_s: float) -> list[Decoded]:
        """Decode received bytes at time ``now_s``."""
        try:
            messages = self._frames(data)
        except (mavlink.MAVError, struct.error, ValueError, TypeError, IndexError):
            self.counters.frame_errors += 1
            self._parser, self._suspect = self._new_parser(), None
            return []
        out: list[Decoded] = []
        for msg, trusted in messages:
            kind = msg.get_type()
            if not trusted:
                self.counters.frame_errors += 1
                continue
            if kind.startswith('UNKNOWN_'):  # another dialect's message, or a corrupted id
                self.counters.unknown_ids += 1
                continue
            self.counters.packets += 1
            self.counters.by_type[kind] = self.counters.by_type.get(kind, 0) + 1
            handler = getattr(self, f'_on_{kind.lower()}', None)
            if handler is None:
                self.counters.ignored += 1
                continue
            try:
                result = handler(msg, now_s)
            except (ValueError, TypeError, ArithmeticError):
                self.counters.parse_errors += 1
                continue
            if result is not None:
                out.append(result)
        return out

    def _frames(self, data: bytes) -> list[tuple[object, bool]]:
        """Parse frame by frame into (message, trusted); rescan after a frame that is broken.

        pymavlink's parser trusts a frame's length byte and drops the whole frame on a
        bad CRC, so one corrupted length byte would swallow up to 280 good bytes. A
        frame with a bad CRC, or with an unknown id (no CRC check possible) that is not
        followed by a start marker, is rescanned from its second byte instead. An
        unknown-id frame at the end of the input waits for the next byte to decide.
        """
        frames: list[tuple[object, bool]] = []
        if self._suspect is not None and data:
            msg, frame = self._suspect
            self._suspect = None
            trusted = data[0] in START_MARKERS
            frames.append((msg, trusted))
            if not trusted:
                self._parser = self._new_parser()
                data = frame[1:] + data
        parser = self._parser
        pending = bytes(parser.buf[parser.buf_index:]) + data
        msg = parser.parse_char(data)
        while msg is not None:
            kind, left = msg.get_type(), parser.buf_len()
            frame, pending = pending[:len(pending) - left], pending[len(pending) - left:]
            broken = kind == 'BAD_DATA' and msg.reason != 'Bad prefix'
            if kind.startswith('UNKNOWN_'):
                if not pending:
                    self._suspect = (msg, frame)
                    break
                broken = pending[0] not in START_MARKERS
            frames.append((msg, not broken and kind != 'BAD_DATA'))
            if broken:
                pending = frame[1:] + pending
                self._parser = parser = self._new_parser()
                msg = parser.parse_char(pending)
            else:
                msg = parser.parse_char(b'')
        return frames

    @staticmethod
    def _new_parser() -> mavlink.MAVLink:
        parser = mavlink.MAVLink(None)
        parser.robust_parsing = True
        return parser

    # --- attitude -> DecodedImu
    def _on_attitude(self, msg, now_s: float) -> DecodedImu | None:
        if self._use_quaternion:
            self.counters.ignored += 1
            return None
        angles = (msg.roll, msg.pitch, msg.yaw)
        if not finite(*angles):
            raise ValueError('attitude not finite')
        return self._sample(orientation_enu_flu_from_euler_ned(*angles), msg, now_s)

    def _on_attitude_quaternion(self, msg, now_s: float) -> DecodedImu:
        q = (msg.q2, msg.q3, msg.q4, msg.q1)  # MAVLink q1 is w
        norm = math.sqrt(sum(c * c for c in q)) if finite(*q) else math.nan
        if not abs(norm - 1.0) < 0.1:
            raise ValueError('attitude quaternion not unit length')
        self._use_quaternion = True
        q = tuple(c / norm for c in q)
        return self._sample(orientation_enu_flu_from_ned_frd(q), msg, now_s)

    def _sample(self, orientation: tuple, msg, now_s: float) -> DecodedImu:
        rates = (msg.rollspeed, msg.pitchspeed, msg.yawspeed)
        if not finite(*rates):
            raise ValueError('body rates not finite')
        accel = self._accel if now_s - self._accel_time_s <= ACCEL_MAX_AGE_S else None
        s = self.settings
        accel_covariance = diagonal3(tuple(a ** 2 for a in s.accel_std_mps2))
        if accel is None:
            accel_covariance = (-1.0,) + (0.0,) * 8
        return DecodedImu(orientation, frd_to_flu(*rates), accel,
                         diagonal3(tuple(a ** 2 for a in s.orientation_std_rad)),
                         diagonal3((s.gyro_std_rps ** 2,) * 3), accel_covariance)

    # --- accelerations
    def _on_highres_imu(self, msg, now_s: float) -> None:
        if msg.fields_updated & 0x7 == 0x7:
            self._set_accel('HIGHRES_IMU', (msg.xacc, msg.yacc, msg.zacc), 1.0, now_s)
        else:
            self.counters.ignored += 1

    def _on_scaled_imu(self, msg, now_s: float) -> None:
        self._set_accel('SCALED_IMU', (msg.xacc, msg.yacc, msg.zacc),
                        STANDARD_GRAVITY_MPS2 / 1000.0, now_s)

    def _on_raw_imu(self, msg, now_s: float) -> None:
        self._set_accel('RAW_IMU', (msg.xacc, msg.yacc, msg.zacc),
                        STANDARD_GRAVITY_MPS2 / 1000.0, now_s)

    def _set_accel(self, kind: str, frd: tuple, scale: float, now_s: float) -> None:
        priority = IMU_PRIORITY[kind]
        if priority < self._imu_priority:
            self.counters.ignored += 1
            return
        if not finite(*frd):
            raise ValueError(f'{kind} acceleration not finite')
        self._imu_priority = priority
        self._accel = frd_to_flu(*(a * scale for a in frd))
        self._accel_time_s = now_s

    # --- GPS
    def _on_gps_raw_int(self, msg, _now_s: float) -> GnssFix:
        if msg.vel_acc > 0:
            self._velocity_variance = (msg.vel_acc / 1000.0) ** 2
        status = GPS_FIX_STATUS.get(msg.fix_type, FixStatus.NO_FIX)
        self._gps_has_fix = status != FixStatus.NO_FIX
        if status == FixStatus.NO_FIX:
            nan = math.nan
            return GnssFix(GnssSource.MAVLINK, status, nan, nan, nan, (0.0, 0.0, 0.0),
                          CovarianceKind.UNKNOWN)
        latitude, longitude = msg.lat * 1e-7, msg.lon * 1e-7
        if abs(latitude) > 90 or abs(longitude) > 180:
            raise ValueError('position out of range')
        altitude = (msg.alt_ellipsoid if msg.alt_ellipsoid else msg.alt) / 1000.0
        if msg.h_acc > 0 and msg.v_acc > 0:
            h, v = msg.h_acc / 1000.0, msg.v_acc / 1000.0
            covariance, kind = (h * h, h * h, v * v), CovarianceKind.DIAGONAL_KNOWN
        elif msg.eph not in (0, UINT16_UNKNOWN):
            covariance = dop_covariance(msg.eph / 100.0, status, self.settings.uere)
            kind = CovarianceKind.APPROXIMATED
        else:
            covariance, kind = (0.0, 0.0, 0.0), CovarianceKind.UNKNOWN
        return GnssFix(GnssSource.MAVLINK, status, latitude, longitude, altitude, covariance,
                      kind)

    def _on_global_position_int(self, msg, _now_s: float) -> GnssVelocity:
        east, north, up = ned_to_enu(msg.vx / 100.0, msg.vy / 100.0, msg.vz / 100.0)
        variance = self._velocity_variance
        return GnssVelocity(GnssSource.MAVLINK, east, north, up, (variance,) * 3,
                           valid=self._gps_has_fix)
