"""What the estimator consumes and produces: plain dataclasses, SI units, REP 103/105 axes.

The node converts messages to these; offline tools (evaluate, replay) build them directly.
NaN marks a value the sensor did not give.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

NAN = math.nan


@dataclass(frozen=True)
class ImuSample:
    """IMU at base_link: attitude from its own EKF/compass, body FLU rates and specific force."""

    t_s: float
    roll_rad: float
    pitch_rad: float
    yaw_rad: float                  # NaN: no orientation
    roll_rate_rps: float
    pitch_rate_rps: float
    yaw_rate_rps: float
    accel_x_mps2: float             # NaN: no accelerations
    accel_y_mps2: float
    accel_z_mps2: float
    yaw_var_rad2: float = NAN       # NaN or <= 0: use the configured sigma
    yaw_rate_var_rps2: float = NAN


@dataclass(frozen=True)
class GpsFix:
    """A DGPS fix, geodetic (WGS84), with horizontal variance (NaN: configured sigma)."""

    t_s: float
    latitude_deg: float
    longitude_deg: float
    altitude_m: float
    horizontal_var_m2: float = NAN
    valid: bool = True              # False: no fix (NavSatStatus.STATUS_NO_FIX)


@dataclass(frozen=True)
class GpsVelocity:
    """DGPS ground velocity of the antenna, ENU, with variance per axis (NaN: configured)."""

    t_s: float
    east_mps: float
    north_mps: float
    var_mps2: float = NAN


@dataclass(frozen=True)
class WaterContact:
    """The fore and aft water-contact sensors (debounced)."""

    t_s: float
    fore_wet: bool
    aft_wet: bool


@dataclass(frozen=True)
class DepthReading:
    """Depth sounder: water below the transducer; valid only deeper than about 0.5 m."""

    t_s: float
    valid: bool
    depth_m: float


@dataclass(frozen=True)
class MotorSide:
    """One channel of a motor controller."""

    command_pct: float
    current_a: float
    speed_mps: float                # tracks: belt speed; propellers: 0 (no encoder)
    force_n: float                  # tracks: current x gain; propellers: estimated thrust


@dataclass(frozen=True)
class DriveStatus:
    """A dual-channel controller (tracks or propellers)."""

    t_s: float
    port: MotorSide
    stbd: MotorSide
    connected: bool = True


@dataclass
class OdometryEstimate:
    """The filter's pose and twist of base_link in odom, with 6x6 covariances (REP 105)."""

    t_s: float
    x_m: float
    y_m: float
    z_m: float
    roll_rad: float
    pitch_rad: float
    yaw_rad: float
    surge_mps: float
    sway_mps: float
    yaw_rate_rps: float
    pose_cov: np.ndarray = field(default_factory=lambda: np.zeros((6, 6)))
    twist_cov: np.ndarray = field(default_factory=lambda: np.zeros((6, 6)))


@dataclass
class TractionEstimate:
    """Slip, submersion and track forces (dukw_msgs/Traction)."""

    t_s: float
    port_slip: float
    stbd_slip: float
    submerged_volume_m3: float
    effective_weight_n: float
    weight_on_tracks_fraction: float
    waterline_distance_m: float
    submerged_length_m: float
    slope_rad: float
    port_force_predicted_n: float
    stbd_force_predicted_n: float
    port_force_measured_n: float
    stbd_force_measured_n: float
    afloat: bool
    wave_elevation_m: float = 0.0
