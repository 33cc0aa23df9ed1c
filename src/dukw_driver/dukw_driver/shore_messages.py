"""shore_link_node's parameters and its ROS messages <-> core types (kept out of the node)."""
from __future__ import annotations

import json
import math

from dukw_common.geometry import euler_from_quaternion
from dukw_common.node_tools import ParamSpec
from dukw_driver.shore_link import STREAMS, MissionPlan
from dukw_driver.shore_telemetry import DriveTelemetry, Fix, Pose, TractionState


PARAMS = [
    ParamSpec('url', 'pymavlink connection: /dev/ttyUSB0,57600 | udpout:HOST:PORT | udpin:..'),
    ParamSpec('radio_baud', 'radio rate for the byte budget (8N1), baud', min=1200, max=921600),
    ParamSpec('radio_budget_fraction', 'WARN above this share of the radio', min=0.05, max=1.0),
    ParamSpec('system_id', 'our MAVLink system id', min=1, max=255),
    ParamSpec('component_id', 'our MAVLink component id', min=1, max=255),
    ParamSpec('signing', 'MAVLink 2 signing on (false only on a bench)'),
    ParamSpec('signing_key_file', '32 raw bytes or 64 hex characters'),
    ParamSpec('allow_unsigned', 'accept unsigned packets (never on the boat)'),
    ParamSpec('signing_link_id', 'our signing link id', min=0, max=255),
    ParamSpec('timestamp_file', "signing timestamps; '' = <signing_key_file>.timestamps"),
    ParamSpec('timestamp_save_period_s', 'signing timestamps saved this often, s', min=0.5,
              max=600.0),
    ParamSpec('poll_rate_hz', 'radio read / telemetry tick rate, Hz', min=5.0, max=500.0),
    ParamSpec('reconnect_period_s', 'reopen a failed link after, s', min=0.05, max=60.0),
    ParamSpec('diagnostics_period_s', '/diagnostics period, s', min=0.1, max=60.0),
    ParamSpec('drivetrain.continuous_current_limit_a', 'continuous motor current (the shared '
              'drivetrain fact; trk_i_pct), A', min=1.0, max=500.0),
    ParamSpec('drivetrain.full_scale_track_speed_mps', 'top speed (the shared drivetrain '
              'fact): DO_CHANGE_SPEED above it is refused, m/s', min=0.1, max=10.0),
    ParamSpec('mission_speed_mps', 'leg speed before any DO_CHANGE_SPEED, m/s', min=0.05,
              max=2.0),
    *(ParamSpec(f'datum.{n}', f'odom origin {n} (the shared datum.*)', min=lo, max=hi)
      for n, lo, hi in (('latitude_deg', -90.0, 90.0), ('longitude_deg', -180.0, 180.0),
                        ('altitude_m', -1000.0, 10000.0))),
    ParamSpec('manual.max_speed_mps', 'cmd_vel at MANUAL_CONTROL x=1000, m/s', min=0.0, max=2.0),
    ParamSpec('manual.max_yaw_rate_rps', 'cmd_vel at r=1000, rad/s', min=0.0, max=1.5),
    ParamSpec('manual.timeout_s', 'no MANUAL_CONTROL this long: stop, s', min=0.05, max=0.5),
    ParamSpec('failsafe.gcs_timeout_s', 'GCS heartbeat lost after, s', min=1.0, max=60.0),
    ParamSpec('failsafe.action', '0 report, 1 stop + hold, 2 also SAFE_STOP', min=0, max=2),
    *(ParamSpec(f'rates.{n}_hz', f'{n} telemetry rate, Hz (0 off)', min=0.0, max=10.0)
      for n in STREAMS),
]

def pose_from_odometry(msg, rates_flu_rps: tuple[float, float, float]) -> Pose:
    """nav_msgs/Odometry -> Pose (body rates from imu/data)."""
    p, q, v = msg.pose.pose.position, msg.pose.pose.orientation, msg.twist.twist.linear
    roll, pitch, yaw = euler_from_quaternion(q.x, q.y, q.z, q.w)
    return Pose(p.x, p.y, p.z, roll, pitch, yaw, v.x, v.y, v.z, rates_flu_rps)


def fix_from_navsat(msg) -> Fix:
    """sensor_msgs/NavSatFix -> Fix (std devs from the covariance diagonal)."""
    cov = msg.position_covariance
    horizontal = math.sqrt(max(cov[0], cov[4])) if msg.position_covariance_type else math.nan
    vertical = math.sqrt(cov[8]) if msg.position_covariance_type else math.nan
    return Fix(msg.latitude, msg.longitude, msg.altitude, msg.status.status, horizontal,
               vertical)


def drive_from_status(msg) -> DriveTelemetry:
    """dukw_msgs/DrivetrainStatus -> DriveTelemetry (what the shore link reports of a drive)."""
    sides = (msg.port, msg.stbd)
    faults = tuple(f'{side} {name}' for side, s in zip(('port', 'stbd'), sides, strict=True)
                   for name in s.faults)
    return DriveTelemetry(msg.connected, tuple(s.current_a for s in sides),
                 tuple(s.voltage_v for s in sides), tuple(s.command_pct for s in sides), faults)


def traction_from_msg(msg) -> TractionState:
    """dukw_msgs/Traction -> TractionState."""
    return TractionState((msg.port_slip, msg.stbd_slip), msg.submerged_volume_m3,
                         msg.weight_on_tracks_fraction, msg.afloat)


def plan_json(plan: MissionPlan) -> str:
    """The mission node's ``mission/plan``: {"waypoints": [{name, x_m, y_m, speed_mps}, ...]}."""
    return json.dumps({'waypoints': [
        {'name': f'item{w.seq}', 'x_m': round(w.x_m, 3), 'y_m': round(w.y_m, 3),
         'speed_mps': w.speed_mps} for w in plan.waypoints]})


def mission_progress(text: str) -> tuple[int, int, bool, int] | None:
    """``mission/status`` JSON -> (waypoint index, reached, finished, waypoints); None if bad."""
    try:
        data = json.loads(text)
        finished = data['state'] not in ('waiting', 'running')
        return (int(data['waypoint_index']), len(data['reached_s']), finished,
                int(data['waypoints_total']))
    except (ValueError, KeyError, TypeError):
        return None
