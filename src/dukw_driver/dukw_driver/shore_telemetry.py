"""What the shore link tells the ground station: vehicle state -> MAVLink messages. ROS-free.

The node converts its topics into the dataclasses below; ``TelemetryEncoder``
builds the pymavlink messages from them (ENU/FLU -> NED/FRD at this boundary)
and ``RateScheduler`` says which are due. Units follow MAVLink's definitions.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from pymavlink.dialects.v20 import common as mavlink

from dukw_common.config import ConfigError
from dukw_common.geometry import geodetic_from_local_enu, wrap_angle

#: DriveMode.LAND / TRANSITION / WATER / SAFE_STOP: HEARTBEAT custom_mode (dukw_msgs/DriveMode).
MODE_NAMES = {0: 'LAND', 1: 'TRANSITION', 2: 'WATER', 3: 'SAFE_STOP'}
MODE_WATER, MODE_SAFE_STOP = 2, 3
#: Authority.holder values (dukw_msgs/Authority).
HOLDER_RC, HOLDER_COMPUTER, HOLDER_NONE = 0, 1, 2
HOLDER_NAMES = {HOLDER_RC: 'RC operator', HOLDER_COMPUTER: 'computer', HOLDER_NONE: 'nobody'}
UINT16_UNKNOWN = 65535
SENSORS = (mavlink.MAV_SYS_STATUS_SENSOR_3D_GYRO | mavlink.MAV_SYS_STATUS_SENSOR_3D_ACCEL
           | mavlink.MAV_SYS_STATUS_SENSOR_GPS | mavlink.MAV_SYS_STATUS_SENSOR_MOTOR_OUTPUTS
           | mavlink.MAV_SYS_STATUS_SENSOR_RC_RECEIVER)
#: Telemetry streams: name -> the MAVLink message id a GCS may ask for.
STREAM_IDS = {
    'heartbeat': mavlink.MAVLINK_MSG_ID_HEARTBEAT,
    'sys_status': mavlink.MAVLINK_MSG_ID_SYS_STATUS,
    'battery_status': mavlink.MAVLINK_MSG_ID_BATTERY_STATUS,
    'global_position': mavlink.MAVLINK_MSG_ID_GLOBAL_POSITION_INT,
    'gps_raw': mavlink.MAVLINK_MSG_ID_GPS_RAW_INT,
    'attitude': mavlink.MAVLINK_MSG_ID_ATTITUDE,
    'vfr_hud': mavlink.MAVLINK_MSG_ID_VFR_HUD,
    'named_values': mavlink.MAVLINK_MSG_ID_NAMED_VALUE_FLOAT,
    'mission_current': mavlink.MAVLINK_MSG_ID_MISSION_CURRENT,
}


@dataclass
class Pose:
    """odometry/filtered in odom (ENU) and base_link (FLU); imu/data fills the body rates."""

    x_m: float = 0.0
    y_m: float = 0.0
    z_m: float = 0.0
    roll_rad: float = 0.0
    pitch_rad: float = 0.0
    yaw_rad: float = 0.0
    surge_mps: float = 0.0
    sway_mps: float = 0.0
    heave_mps: float = 0.0
    rates_flu_rps: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass
class Fix:
    """gps/fix: status -1 no fix, 0 fix, 1 SBAS, 2 GBAS (NavSatStatus); std devs in m."""

    latitude_deg: float = math.nan
    longitude_deg: float = math.nan
    altitude_m: float = math.nan
    status: int = -1
    horizontal_std_m: float = math.nan
    vertical_std_m: float = math.nan


@dataclass
class DriveTelemetry:
    """tracks/status or props/status: per side current, voltage, command; the faults' names."""

    connected: bool = False
    current_a: tuple[float, float] = (math.nan, math.nan)
    voltage_v: tuple[float, float] = (math.nan, math.nan)
    command_pct: tuple[float, float] = (0.0, 0.0)
    faults: tuple[str, ...] = ()


@dataclass
class TractionState:
    """traction: slip per track, submerged volume, share of the weight on the tracks."""

    slip: tuple[float, float] = (math.nan, math.nan)
    submerged_volume_m3: float = math.nan
    weight_on_tracks_fraction: float = math.nan
    afloat: bool = False


@dataclass
class VehicleState:
    """Everything the telemetry reports, as the node last heard it (None = not yet)."""

    pose: Pose | None = None
    fix: Fix | None = None
    mode: int | None = None
    mode_automatic: bool = True
    mode_reason: str = ''
    holder: int | None = None
    rc_link_ok: bool = False
    authority_detail: str = ''
    tracks: DriveTelemetry = field(default_factory=DriveTelemetry)
    props: DriveTelemetry = field(default_factory=DriveTelemetry)
    traction: TractionState = field(default_factory=TractionState)


@dataclass(frozen=True)
class Datum:
    """Geodetic origin of odom (the EKF's datum): converts odom positions to lat/lon."""

    latitude_deg: float
    longitude_deg: float
    altitude_m: float


class RateScheduler:
    """Which streams are due: each at its own rate (Hz; 0 = off), spread over the second."""

    def __init__(self, rates_hz: dict[str, float]) -> None:
        self.rates_hz: dict[str, float] = {}
        self._next_s: dict[str, float] = {}
        for name, rate in rates_hz.items():
            self.set_rate(name, rate)

    def set_rate(self, name: str, rate_hz: float) -> None:
        """Change one stream's rate (0 turns it off); ValueError for a bad rate or name."""
        if name not in STREAM_IDS:
            raise ConfigError(f'unknown telemetry stream {name!r}')
        if not (0.0 <= rate_hz <= 50.0) or math.isnan(rate_hz):
            raise ConfigError(f'telemetry rate of {name} must be 0..50 Hz, got {rate_hz}')
        self.rates_hz[name] = float(rate_hz)
        self._next_s.pop(name, None)

    def due(self, now_s: float) -> list[str]:
        """Streams due at ``now_s`` (each one's next time moves on by its period)."""
        names = []
        for index, (name, rate) in enumerate(self.rates_hz.items()):
            if rate <= 0.0:
                continue
            period = 1.0 / rate
            next_s = self._next_s.setdefault(name, now_s + 0.01 * index)
            if now_s >= next_s:
                names.append(name)
                self._next_s[name] = max(next_s + period, now_s)
        return names


def _cm(v: float) -> int:
    return int(round(v * 100.0)) if math.isfinite(v) else 0


def _clamp_int(value: float, lo: int, hi: int, unknown: int) -> int:
    return int(min(hi, max(lo, round(value)))) if math.isfinite(value) else unknown


def _name(text: str) -> bytes:
    return text.encode('ascii')[:10]


class TelemetryEncoder:
    """Builds the telemetry messages from a VehicleState."""

    def __init__(self, mav: mavlink.MAVLink, datum: Datum, current_limit_a: float) -> None:
        self.mav = mav
        self.datum = datum
        self.current_limit_a = current_limit_a

    def heartbeat(self, s: VehicleState) -> mavlink.MAVLink_message:
        """Type by medium, custom_mode = drive mode; armed = the computer drives."""
        afloat = s.mode == MODE_WATER or s.traction.afloat
        kind = mavlink.MAV_TYPE_SURFACE_BOAT if afloat else mavlink.MAV_TYPE_GROUND_ROVER
        base = mavlink.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
        if s.mode_automatic:
            base |= mavlink.MAV_MODE_FLAG_AUTO_ENABLED
        if s.holder == HOLDER_COMPUTER:
            base |= mavlink.MAV_MODE_FLAG_SAFETY_ARMED | mavlink.MAV_MODE_FLAG_GUIDED_ENABLED
        elif s.holder == HOLDER_RC:
            base |= mavlink.MAV_MODE_FLAG_MANUAL_INPUT_ENABLED
        if s.mode is None or s.holder is None:
            status = mavlink.MAV_STATE_BOOT
        elif s.mode == MODE_SAFE_STOP or s.tracks.faults or s.props.faults:
            status = mavlink.MAV_STATE_CRITICAL
        elif s.holder == HOLDER_COMPUTER:
            status = mavlink.MAV_STATE_ACTIVE
        else:
            status = mavlink.MAV_STATE_STANDBY
        return self.mav.heartbeat_encode(kind, mavlink.MAV_AUTOPILOT_GENERIC, base,
                                         s.mode if s.mode is not None else 0, status)

    def sys_status(self, s: VehicleState) -> mavlink.MAVLink_message:
        """Sensors present/healthy, the track pack's voltage and current."""
        health = SENSORS
        if s.fix is None or s.fix.status < 0:
            health &= ~mavlink.MAV_SYS_STATUS_SENSOR_GPS
        if s.tracks.faults or s.props.faults or not s.tracks.connected:
            health &= ~mavlink.MAV_SYS_STATUS_SENSOR_MOTOR_OUTPUTS
        if not s.rc_link_ok:
            health &= ~mavlink.MAV_SYS_STATUS_SENSOR_RC_RECEIVER
        volts, amps = self._pack(s.tracks)
        return self.mav.sys_status_encode(
            SENSORS, SENSORS, health, 0, _clamp_int(volts * 1000.0, 0, 65534, UINT16_UNKNOWN),
            _clamp_int(amps * 100.0, 0, 32767, -1), -1, 0, 0, 0, 0, 0, 0)

    def battery_status(self, s: VehicleState) -> list[mavlink.MAVLink_message]:
        """Battery 0: the track pack; battery 1: the propeller pack (voltage, current)."""
        messages = []
        for index, drive in enumerate((s.tracks, s.props)):
            volts, amps = self._pack(drive)
            cells = [_clamp_int(volts * 1000.0, 0, 65534, UINT16_UNKNOWN)] + [UINT16_UNKNOWN] * 9
            messages.append(self.mav.battery_status_encode(
                index, mavlink.MAV_BATTERY_FUNCTION_PROPULSION, mavlink.MAV_BATTERY_TYPE_UNKNOWN,
                32767, cells, _clamp_int(amps * 100.0, 0, 32767, -1), -1, -1, -1))
        return messages

    @staticmethod
    def _pack(drive: DriveTelemetry) -> tuple[float, float]:
        volts = [v for v in drive.voltage_v if math.isfinite(v)]
        amps = [abs(a) for a in drive.current_a if math.isfinite(a)]
        return (max(volts) if volts else math.nan, sum(amps) if amps else math.nan)

    def global_position(self, s: VehicleState, time_ms: int) -> mavlink.MAVLink_message | None:
        """Odometry on the datum: lat/lon, NED velocity, heading."""
        p = s.pose
        if p is None:
            return None
        lat, lon, alt = geodetic_from_local_enu(p.x_m, p.y_m, p.z_m, self.datum.latitude_deg,
                                                self.datum.longitude_deg, self.datum.altitude_m)
        c, sn = math.cos(p.yaw_rad), math.sin(p.yaw_rad)
        east, north = c * p.surge_mps - sn * p.sway_mps, sn * p.surge_mps + c * p.sway_mps
        return self.mav.global_position_int_encode(
            time_ms, int(round(lat * 1e7)), int(round(lon * 1e7)), int(round(alt * 1000)),
            int(round(p.z_m * 1000)), _cm(north), _cm(east), _cm(-p.heave_mps),
            int(round(self.heading_deg(p) * 100)) % 36000)

    @staticmethod
    def heading_deg(p: Pose) -> float:
        """Compass heading (clockwise from north, 0..360) of an ENU yaw."""
        return math.degrees(wrap_angle(math.pi / 2 - p.yaw_rad)) % 360.0

    def gps_raw(self, s: VehicleState, time_us: int) -> mavlink.MAVLink_message | None:
        """The receiver's fix as it came (RTK/DGPS/3D by NavSatStatus)."""
        f = s.fix
        if f is None:
            return None
        fix_type = {-1: mavlink.GPS_FIX_TYPE_NO_FIX, 0: mavlink.GPS_FIX_TYPE_3D_FIX,
                    1: mavlink.GPS_FIX_TYPE_DGPS, 2: mavlink.GPS_FIX_TYPE_RTK_FIXED}.get(
                        f.status, mavlink.GPS_FIX_TYPE_NO_FIX)
        ok = fix_type != mavlink.GPS_FIX_TYPE_NO_FIX and math.isfinite(f.latitude_deg)
        lat = int(round(f.latitude_deg * 1e7)) if ok else 0
        lon = int(round(f.longitude_deg * 1e7)) if ok else 0
        alt = int(round(f.altitude_m * 1000)) if ok and math.isfinite(f.altitude_m) else 0
        return self.mav.gps_raw_int_encode(
            time_us, fix_type, lat, lon, alt, UINT16_UNKNOWN, UINT16_UNKNOWN, UINT16_UNKNOWN,
            UINT16_UNKNOWN, 255, 0, _clamp_int(f.horizontal_std_m * 1000, 0, 2**31, 0),
            _clamp_int(f.vertical_std_m * 1000, 0, 2**31, 0))

    def attitude(self, s: VehicleState, time_ms: int) -> mavlink.MAVLink_message | None:
        """Euler angles and rates of FRD in NED (pitch and yaw-rate signs flip from FLU)."""
        p = s.pose
        if p is None:
            return None
        wx, wy, wz = p.rates_flu_rps
        return self.mav.attitude_encode(time_ms, p.roll_rad, -p.pitch_rad,
                                        wrap_angle(math.pi / 2 - p.yaw_rad), wx, -wy, -wz)

    def vfr_hud(self, s: VehicleState) -> mavlink.MAVLink_message | None:
        """Speed over ground, heading, throttle (the active drive's mean |command|)."""
        p = s.pose
        if p is None:
            return None
        drive = s.props if s.mode == MODE_WATER else s.tracks
        throttle = sum(abs(c) for c in drive.command_pct) / 2.0
        return self.mav.vfr_hud_encode(
            0.0, math.hypot(p.surge_mps, p.sway_mps), int(self.heading_deg(p)),
            _clamp_int(throttle, 0, 100, 0), p.z_m, p.heave_mps)

    def named_values(self, s: VehicleState, time_ms: int) -> list[mavlink.MAVLink_message]:
        """Motor currents (and the highest as % of the continuous limit), slip, volume, weight."""
        t, pr, tr = s.tracks, s.props, s.traction
        track_a = [abs(a) for a in t.current_a if math.isfinite(a)]
        values = {'trk_p_a': t.current_a[0], 'trk_s_a': t.current_a[1],
                  'prp_p_a': pr.current_a[0], 'prp_s_a': pr.current_a[1],
                  'trk_i_pct': (100.0 * max(track_a) / self.current_limit_a if track_a
                                else math.nan),
                  'slip_p': tr.slip[0], 'slip_s': tr.slip[1],
                  'sub_vol_m3': tr.submerged_volume_m3, 'w_tracks': tr.weight_on_tracks_fraction}
        return [self.mav.named_value_float_encode(time_ms, _name(name), float(value))
                for name, value in values.items()]
