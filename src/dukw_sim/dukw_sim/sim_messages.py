"""ROS messages from the simulator's readings (sensors.py, switch.py, truth.py).

The only dukw_sim module besides sim_node that knows message types. Every
builder takes the stamp as sim time in seconds. Messages are built anew each
call (publishing serialises at once, so reuse would also be safe, but the
gain measured small against DDS).
"""
from __future__ import annotations

from dataclasses import dataclass

from builtin_interfaces.msg import Time
from dukw_msgs.msg import Authority, Depth, DrivetrainStatus, MotorSide, RcInput, SimTruth
from dukw_msgs.msg import WaterContact
from geometry_msgs.msg import TwistWithCovarianceStamped
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Imu, NavSatFix, NavSatStatus
from std_msgs.msg import Header

from dukw_driver.authority import AuthorityState
from dukw_sim.sensors import (DepthReading, DrivetrainReading, Fault, GpsFix, GpsVelocity,
                              ImuReading, MotorReading, WaterContactReading)
from dukw_sim.switch import RcReading
from dukw_sim.truth import Truth

#: A variance that says "not measured" in a covariance the message must fill.
UNMEASURED_VAR = 1e6
_FAULT_NAMES = {int(flag): name.lower() for name, flag in Fault.__members__.items()}


@dataclass(frozen=True)
class Frames:
    """frame_id of each stream (config ``frames.*``)."""

    base: str
    imu: str
    gps: str


def stamp(t_s: float) -> Time:
    """Sim time in seconds -> builtin_interfaces/Time."""
    ns = int(round(t_s * 1e9))
    return Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def _diag3(var: tuple) -> list[float]:
    return [var[0], 0.0, 0.0, 0.0, var[1], 0.0, 0.0, 0.0, var[2]]


def imu(r: ImuReading, frames: Frames) -> Imu:
    """sensor_msgs/Imu: orientation ENU (REP 145), rates and specific force in imu_link (FLU)."""
    msg = Imu()
    msg.header.stamp = stamp(r.t_s)
    msg.header.frame_id = frames.imu
    q = msg.orientation
    q.x, q.y, q.z, q.w = r.orientation_xyzw
    w = msg.angular_velocity
    w.x, w.y, w.z = r.angular_velocity_rps
    a = msg.linear_acceleration
    a.x, a.y, a.z = r.linear_acceleration_mps2
    msg.orientation_covariance = _diag3(r.orientation_var)
    msg.angular_velocity_covariance = _diag3(r.angular_velocity_var)
    msg.linear_acceleration_covariance = _diag3(r.linear_acceleration_var)
    return msg


def gps_fix(r: GpsFix, frames: Frames) -> NavSatFix:
    """sensor_msgs/NavSatFix: a differential (GBAS) GPS fix with a known diagonal covariance."""
    msg = NavSatFix()
    msg.header.stamp = stamp(r.t_s)
    msg.header.frame_id = frames.gps
    msg.status.status = NavSatStatus.STATUS_GBAS_FIX
    msg.status.service = NavSatStatus.SERVICE_GPS
    msg.latitude, msg.longitude, msg.altitude = r.latitude_deg, r.longitude_deg, r.altitude_m
    msg.position_covariance = _diag3(r.position_var)
    msg.position_covariance_type = NavSatFix.COVARIANCE_TYPE_DIAGONAL_KNOWN
    return msg


def gps_velocity(r: GpsVelocity, frames: Frames) -> TwistWithCovarianceStamped:
    """geometry_msgs/TwistWithCovarianceStamped: linear = ENU velocity of the antenna."""
    msg = TwistWithCovarianceStamped()
    msg.header.stamp = stamp(r.t_s)
    msg.header.frame_id = frames.gps
    v = msg.twist.twist.linear
    v.x, v.y, v.z = r.velocity_enu_mps
    cov = [0.0] * 36
    cov[0], cov[7], cov[14] = r.velocity_var
    cov[21] = cov[28] = cov[35] = UNMEASURED_VAR
    msg.twist.covariance = cov
    return msg


def water_contact(r: WaterContactReading, frames: Frames) -> WaterContact:
    """dukw_msgs/WaterContact (the sensor points are config sensors.* in base_link)."""
    return WaterContact(header=_header(r.t_s, frames.base), fore_wet=r.fore_wet, aft_wet=r.aft_wet,
                        fore_level=r.fore_level, aft_level=r.aft_level)


def depth(r: DepthReading, frames: Frames) -> Depth:
    """dukw_msgs/Depth."""
    return Depth(header=_header(r.t_s, frames.base), valid=r.valid, depth_m=r.depth_m,
                 offset_m=r.offset_m, water_temp_c=r.water_temp_c)


def _side(m: MotorReading) -> MotorSide:
    flags = int(m.fault_flags)
    return MotorSide(command_pct=m.command_pct, current_a=m.current_a, voltage_v=m.voltage_v,
                     speed_mps=m.speed_mps, force_n=m.force_n, temperature_c=m.temperature_c,
                     fault_flags=flags,
                     faults=[name for bit, name in _FAULT_NAMES.items() if flags & bit])


def drivetrain(r: DrivetrainReading, frames: Frames) -> DrivetrainStatus:
    """dukw_msgs/DrivetrainStatus for tracks/status or props/status."""
    drive = DrivetrainStatus.DRIVE_TRACKS if r.drive == 'tracks' else (
        DrivetrainStatus.DRIVE_PROPELLERS)
    return DrivetrainStatus(header=_header(r.t_s, frames.base), drive=drive,
                            connected=r.connected, port=_side(r.port), stbd=_side(r.stbd))


def rc_input(r: RcReading) -> RcInput:
    """dukw_msgs/RcInput."""
    return RcInput(header=_header(r.t_s, ''), link_ok=r.link_ok, rc_selected=r.rc_selected,
                   channels_us=list(r.channels_us))


def authority(state: AuthorityState, t_s: float) -> Authority:
    """dukw_msgs/Authority from the CommandGate's state."""
    return Authority(header=_header(t_s, ''), holder=int(state.holder),
                     reason=int(state.reason), rc_link_ok=state.rc_link_ok,
                     outputs_neutral=state.outputs_neutral, detail=state.detail)


def sim_truth(t: Truth, frame_id: str = 'odom') -> SimTruth:
    """dukw_msgs/SimTruth: pose in odom, body velocities, traction and world at the vehicle."""
    return SimTruth(
        header=_header(t.t_s, frame_id), x_m=t.x_m, y_m=t.y_m, z_m=t.z_m, yaw_rad=t.yaw_rad,
        roll_rad=t.roll_rad, pitch_rad=t.pitch_rad, surge_mps=t.surge_mps, sway_mps=t.sway_mps,
        yaw_rate_rps=t.yaw_rate_rps, heave_mps=t.heave_mps, port_slip=t.port_slip,
        stbd_slip=t.stbd_slip, port_force_n=t.port_force_n, stbd_force_n=t.stbd_force_n,
        submerged_volume_m3=t.submerged_volume_m3, effective_weight_n=t.effective_weight_n,
        weight_on_tracks_fraction=t.weight_on_tracks_fraction,
        waterline_distance_m=t.waterline_distance_m, water_depth_m=t.water_depth_m,
        wave_elevation_m=t.wave_elevation_m, medium=int(t.medium))


def clock(t_s: float) -> Clock:
    """rosgraph_msgs/Clock."""
    return Clock(clock=stamp(t_s))


def _header(t_s: float, frame_id: str) -> Header:
    return Header(stamp=stamp(t_s), frame_id=frame_id)
