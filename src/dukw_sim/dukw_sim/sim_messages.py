"""ROS messages from the simulator's readings (sensors.py, switch.py, truth.py).

Sensor readings (dukw_common.readings) are written so that the estimator's reader,
dukw_estimation.ros_convert, gives the same reading back: a NaN variance becomes 0
("unknown"), a reading without orientation or accelerations gets covariance[0] = -1,
a fix without horizontal variance COVARIANCE_TYPE_UNKNOWN, a valid fix the DGPS's
STATUS_GBAS_FIX and an invalid one STATUS_NO_FIX.

The only dukw_sim module besides sim_node that knows message types. Each topic
has one message object that is updated in place and returned: publishing
serialises at once, and setting fields costs a tenth of building a message
(constant covariances and frame ids are set once). A caller that keeps a
returned message beyond the next call of the same builder must copy it.
Stamps are sim time.
"""
from __future__ import annotations

from dataclasses import dataclass

from diagnostic_msgs.msg import DiagnosticArray
from dukw_msgs.msg import Authority, Depth, DrivetrainStatus, RcInput, SimTruth
from dukw_msgs.msg import MotorSide as MotorSideMsg
from dukw_msgs.msg import WaterContact as WaterContactMsg
from geometry_msgs.msg import TransformStamped, TwistWithCovarianceStamped
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Imu, NavSatFix, NavSatStatus
from tf2_msgs.msg import TFMessage

from dukw_common.geometry import quaternion_from_euler
from dukw_common.node_tools import COMMAND_QOS, SENSOR_QOS, STATE_QOS
from dukw_common.readings import (DepthReading, DriveStatus, GpsFix, GpsVelocity, ImuSample,
                                  MotorSide, WaterContact, reading_topic)
from dukw_driver.authority import AuthorityState
from dukw_sim.switch import RcPulses
from dukw_sim.truth import Truth

#: What sim_node publishes: the drivers' topic contract (architecture.md) plus sim/truth, /clock.
TOPICS = [('imu/data', Imu, SENSOR_QOS), ('gps/fix', NavSatFix, SENSOR_QOS),
          ('gps/vel', TwistWithCovarianceStamped, SENSOR_QOS),
          ('water/contact', WaterContactMsg, SENSOR_QOS), ('depth', Depth, SENSOR_QOS),
          ('tracks/status', DrivetrainStatus, SENSOR_QOS),
          ('props/status', DrivetrainStatus, SENSOR_QOS), ('rc/input', RcInput, SENSOR_QOS),
          ('authority', Authority, STATE_QOS), ('sim/truth', SimTruth, SENSOR_QOS),
          ('/clock', Clock, COMMAND_QOS), ('/diagnostics', DiagnosticArray, COMMAND_QOS)]
#: A variance that says "not measured" in a covariance the message must fill.
UNMEASURED_VAR = 1e6
#: SimTruth fields copied from Truth fields of the same name.
_TRUTH_FIELDS = [f for f in SimTruth.get_fields_and_field_types()
                 if f not in ('header', 'medium') and f in Truth.__dataclass_fields__]


@dataclass(frozen=True)
class Frames:
    """frame_id of each stream (config ``frames.*``)."""

    base: str
    imu: str
    gps: str
    odom: str = 'odom'


def set_time(time_msg, t_s: float) -> None:
    """Write ``t_s`` seconds into a builtin_interfaces/Time in place."""
    time_msg.sec, time_msg.nanosec = divmod(int(round(t_s * 1e9)), 1_000_000_000)


def set_stamp(header, t_s: float) -> None:
    """Write sim time ``t_s`` (seconds) into ``header.stamp``."""
    set_time(header.stamp, t_s)


def set_stamp_as_s_to_stamp(time_msg, t_s: float) -> None:
    """``t_s`` into a builtin_interfaces/Time in place, as dukw_common's s_to_stamp rounds."""
    sec = int(t_s // 1)
    time_msg.sec, time_msg.nanosec = sec, int(round((t_s - sec) * 1e9)) % 1_000_000_000


def _given(var: float) -> float:
    """A variance as a covariance entry: 0 ("unknown") where the reading has NaN."""
    return var if var == var else 0.0


def _diag3(var: tuple) -> list[float]:
    return [_given(var[0]), 0.0, 0.0, 0.0, _given(var[1]), 0.0, 0.0, 0.0, _given(var[2])]


#: covariance[0] = -1: the field is not given (REP 145, sensor_msgs/Imu)
_NOT_GIVEN = [-1.0] + [0.0] * 8
#: DriveStatus.drive -> dukw_msgs/DrivetrainStatus.drive
DRIVE_VALUES = {'tracks': DrivetrainStatus.DRIVE_TRACKS,
                'props': DrivetrainStatus.DRIVE_PROPELLERS}


def _fill_side(side: MotorSideMsg, m: MotorSide) -> None:
    side.command_pct, side.current_a, side.voltage_v = m.command_pct, m.current_a, m.voltage_v
    side.speed_mps, side.force_n, side.temperature_c = m.speed_mps, m.force_n, m.temperature_c
    side.fault_flags, side.faults = m.fault_flags, list(m.faults)


class SimMessages:
    """One in-place message per topic, filled from the simulator's dataclasses."""

    def __init__(self, frames: Frames) -> None:
        self.frames = frames
        self._imu = Imu()
        self._imu.header.frame_id = frames.imu
        self._imu_var: tuple | None = None
        self._fix = NavSatFix(status=NavSatStatus(status=NavSatStatus.STATUS_GBAS_FIX,
                                                  service=NavSatStatus.SERVICE_GPS),
                              position_covariance_type=NavSatFix.COVARIANCE_TYPE_DIAGONAL_KNOWN)
        self._fix.header.frame_id = frames.gps
        self._fix_var: tuple | None = None
        self._vel = TwistWithCovarianceStamped()
        self._vel.header.frame_id = frames.gps
        self._vel_var: tuple | None = None
        self._water = WaterContactMsg()
        self._water.header.frame_id = frames.base
        self._depth = Depth()
        self._depth.header.frame_id = frames.base
        self._drives = {name: DrivetrainStatus(drive=value)
                        for name, value in DRIVE_VALUES.items()}
        for msg in self._drives.values():
            msg.header.frame_id = frames.base
        self._rc = RcInput()
        self._authority = Authority()
        self._truth = SimTruth()
        self._truth.header.frame_id = frames.odom
        self._clock = Clock()
        self._truth_tf: TFMessage | None = None
        self._by_type = {ImuSample: self.imu, GpsFix: self.gps_fix,
                         GpsVelocity: self.gps_velocity, WaterContact: self.water_contact,
                         DepthReading: self.depth}

    def reading(self, r) -> tuple[str, object]:
        """(topic, message) for any reading SensorModel.sample gives."""
        if isinstance(r, DriveStatus):
            return reading_topic(r), self.drivetrain(r)
        return reading_topic(r), self._by_type[type(r)](r)

    def imu(self, r: ImuSample) -> Imu:
        """sensor_msgs/Imu: orientation ENU (REP 145), rates and specific force in imu_link."""
        msg = self._imu
        set_stamp(msg.header, r.t_s)
        q, w, a = msg.orientation, msg.angular_velocity, msg.linear_acceleration
        has_attitude = r.yaw_rad == r.yaw_rad
        has_accel = r.accel_x_mps2 == r.accel_x_mps2
        q.x, q.y, q.z, q.w = (quaternion_from_euler(r.roll_rad, r.pitch_rad, r.yaw_rad)
                              if has_attitude else (0.0, 0.0, 0.0, 1.0))
        w.x, w.y, w.z = r.roll_rate_rps, r.pitch_rate_rps, r.yaw_rate_rps
        a.x, a.y, a.z = ((r.accel_x_mps2, r.accel_y_mps2, r.accel_z_mps2) if has_accel
                         else (0.0, 0.0, 0.0))
        var = (has_attitude, r.roll_var_rad2, r.pitch_var_rad2, r.yaw_var_rad2,
               r.roll_rate_var_rps2, r.pitch_rate_var_rps2, r.yaw_rate_var_rps2,
               has_accel, r.accel_var_m2ps4)
        if var != self._imu_var:        # NaN != NaN: rebuilt each time then, still right
            self._imu_var = var
            msg.orientation_covariance = (_diag3(var[1:4]) if has_attitude else _NOT_GIVEN)
            msg.angular_velocity_covariance = _diag3(var[4:7])
            msg.linear_acceleration_covariance = (_diag3(r.accel_var_m2ps4) if has_accel
                                                  else _NOT_GIVEN)
        return msg

    def gps_fix(self, r: GpsFix) -> NavSatFix:
        """sensor_msgs/NavSatFix: a differential (GBAS) fix, diagonal covariance (ENU)."""
        msg = self._fix
        set_stamp(msg.header, r.t_s)
        msg.latitude, msg.longitude, msg.altitude = r.latitude_deg, r.longitude_deg, r.altitude_m
        msg.status.status = (NavSatStatus.STATUS_GBAS_FIX if r.valid
                             else NavSatStatus.STATUS_NO_FIX)
        var = (r.horizontal_var_m2, r.vertical_var_m2)
        if var != self._fix_var:
            self._fix_var = var
            known = r.horizontal_var_m2 == r.horizontal_var_m2
            msg.position_covariance_type = (NavSatFix.COVARIANCE_TYPE_DIAGONAL_KNOWN if known
                                            else NavSatFix.COVARIANCE_TYPE_UNKNOWN)
            msg.position_covariance = _diag3((r.horizontal_var_m2, r.horizontal_var_m2,
                                              r.vertical_var_m2))
        return msg

    def gps_velocity(self, r: GpsVelocity) -> TwistWithCovarianceStamped:
        """geometry_msgs/TwistWithCovarianceStamped: linear = the antenna's ENU velocity."""
        msg = self._vel
        set_stamp(msg.header, r.t_s)
        v = msg.twist.twist.linear
        v.x, v.y, v.z = r.east_mps, r.north_mps, r.up_mps
        var = (r.var_mps2, r.up_var_mps2)
        if var != self._vel_var:
            self._vel_var = var
            cov = [0.0] * 36
            cov[0] = cov[7] = _given(r.var_mps2)
            cov[14] = _given(r.up_var_mps2)
            cov[21] = cov[28] = cov[35] = UNMEASURED_VAR
            msg.twist.covariance = cov
        return msg

    def water_contact(self, r: WaterContact) -> WaterContactMsg:
        """dukw_msgs/WaterContact (the sensor points are config sensors.* in base_link)."""
        msg = self._water
        set_stamp(msg.header, r.t_s)
        msg.fore_wet, msg.aft_wet = r.fore_wet, r.aft_wet
        msg.fore_level, msg.aft_level = r.fore_level, r.aft_level
        return msg

    def depth(self, r: DepthReading) -> Depth:
        """dukw_msgs/Depth."""
        msg = self._depth
        set_stamp(msg.header, r.t_s)
        msg.valid, msg.depth_m = r.valid, r.depth_m
        msg.offset_m, msg.water_temp_c = r.offset_m, r.water_temp_c
        return msg

    def drivetrain(self, r: DriveStatus) -> DrivetrainStatus:
        """dukw_msgs/DrivetrainStatus for tracks/status or props/status."""
        if r.drive not in self._drives:
            raise ValueError(f"DriveStatus.drive must be 'tracks' or 'props', got {r.drive!r}")
        msg = self._drives[r.drive]
        set_stamp(msg.header, r.t_s)
        msg.connected = r.connected
        _fill_side(msg.port, r.port)
        _fill_side(msg.stbd, r.stbd)
        return msg

    def rc_input(self, r: RcPulses) -> RcInput:
        """dukw_msgs/RcInput."""
        msg = self._rc
        set_stamp(msg.header, r.t_s)
        msg.link_ok, msg.rc_selected = r.link_ok, r.rc_selected
        msg.channels_us = list(r.channels_us)
        return msg

    def authority(self, state: AuthorityState, t_s: float) -> Authority:
        """dukw_msgs/Authority from the CommandGate's state."""
        msg = self._authority
        set_stamp(msg.header, t_s)
        msg.holder, msg.reason = int(state.holder), int(state.reason)
        msg.rc_link_ok, msg.outputs_neutral = state.rc_link_ok, state.outputs_neutral
        msg.detail = state.detail
        return msg

    def sim_truth(self, t: Truth) -> SimTruth:
        """dukw_msgs/SimTruth: pose in odom, body velocities, traction, world at the vehicle."""
        msg = self._truth
        set_stamp(msg.header, t.t_s)
        for name in _TRUTH_FIELDS:
            setattr(msg, name, float(getattr(t, name)))
        msg.medium = int(t.medium)
        return msg

    def truth_tf(self, t: Truth, child_frame: str) -> TFMessage:
        """tf2_msgs/TFMessage odom -> ``child_frame`` at the true pose (what tf_tools'
        tf_message(pose_transform(...)) gives, one message updated in place: building it
        afresh per step cost as much as the rest of the step's messages)."""
        msg = self._truth_tf
        if msg is None or msg.transforms[0].child_frame_id != child_frame:
            tf = TransformStamped()
            tf.header.frame_id, tf.child_frame_id = self.frames.odom, child_frame
            msg = self._truth_tf = TFMessage(transforms=[tf])
        tf = msg.transforms[0]
        set_stamp_as_s_to_stamp(tf.header.stamp, t.t_s)
        p, q = tf.transform.translation, tf.transform.rotation
        p.x, p.y, p.z = float(t.x_m), float(t.y_m), float(t.z_m)
        q.x, q.y, q.z, q.w = (float(v) for v in quaternion_from_euler(t.roll_rad, t.pitch_rad,
                                                                      t.yaw_rad))
        return msg

    def clock(self, t_s: float) -> Clock:
        """rosgraph_msgs/Clock."""
        set_time(self._clock.clock, t_s)
        return self._clock


# One-off builders returning a fresh message each call (offline tools, e.g. golden bags);
# sim_node uses a SimMessages instance, which updates one message per topic in place.
def fresh_reading(r, frames: Frames) -> tuple[str, object]:
    """(topic, a fresh message) for any reading SensorModel.sample gives."""
    return SimMessages(frames).reading(r)


def fresh_authority(state: AuthorityState, t_s: float) -> Authority:
    """A fresh dukw_msgs/Authority."""
    return SimMessages(Frames('', '', '')).authority(state, t_s)
