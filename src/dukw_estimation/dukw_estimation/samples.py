"""What the estimator produces: plain dataclasses, SI units, REP 103/105 axes.

What it consumes are the stack's sensor readings (dukw_common.readings).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


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
