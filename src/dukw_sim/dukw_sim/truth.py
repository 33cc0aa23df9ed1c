"""The simulator's ground truth at one instant: the contract between the physics core,
the sensor models, sim_node (sim/truth) and the offline evaluation tools.

World frame ``odom``: ENU, z = 0 at the mean water level, x pointing seaward
(the mean waterline is the line x = 0 on the beach; land at x < 0).
Body frame ``base_link`` (REP 103): origin at the centre of the track contact
patch at ground level, midway between the tracks; x forward, y left, z up.
"""
from __future__ import annotations

from dataclasses import dataclass, fields
from enum import IntEnum


class Medium(IntEnum):
    """Where the vehicle is (same values as dukw_msgs/SimTruth MEDIUM_*)."""

    LAND = 0
    TRANSITION = 1
    WATER = 2


@dataclass(slots=True)
class Truth:
    """Everything the simulator knows about the vehicle at time ``t_s``. SI units.

    Slotted: one is built per physics step and read field by field by the sensor models and
    the messages (a quarter cheaper to build, and no per-instance dict).
    """

    t_s: float = 0.0
    # pose of base_link in odom
    x_m: float = 0.0
    y_m: float = 0.0
    z_m: float = 0.0
    roll_rad: float = 0.0
    pitch_rad: float = 0.0           # REP 103: positive nose down
    yaw_rad: float = 0.0             # counter-clockwise positive
    # body-frame velocities (FLU)
    surge_mps: float = 0.0
    sway_mps: float = 0.0
    heave_mps: float = 0.0           # vertical speed of base_link in odom (+ up)
    roll_rate_rps: float = 0.0
    pitch_rate_rps: float = 0.0
    yaw_rate_rps: float = 0.0
    # specific force an IMU at base_link would measure, body FLU (includes +g on z at rest)
    accel_x_mps2: float = 0.0
    accel_y_mps2: float = 0.0
    accel_z_mps2: float = 9.81
    # tracks (port, starboard)
    port_cmd_pct: float = 0.0        # command after the servo switch
    stbd_cmd_pct: float = 0.0
    port_track_speed_mps: float = 0.0
    stbd_track_speed_mps: float = 0.0
    port_slip: float = 0.0
    stbd_slip: float = 0.0
    port_force_n: float = 0.0        # traction force the soil gives each track
    stbd_force_n: float = 0.0
    port_current_a: float = 0.0
    stbd_current_a: float = 0.0
    # propellers
    port_prop_cmd_pct: float = 0.0
    stbd_prop_cmd_pct: float = 0.0
    port_thrust_n: float = 0.0
    stbd_thrust_n: float = 0.0
    port_prop_current_a: float = 0.0
    stbd_prop_current_a: float = 0.0
    battery_voltage_v: float = 24.0
    # submersion and world at the vehicle
    submerged_volume_m3: float = 0.0
    effective_weight_n: float = 0.0
    weight_on_tracks_fraction: float = 1.0
    waterline_distance_m: float = 0.0  # along the slope, base_link seaward of the mean waterline
    slope_rad: float = 0.0             # beach slope under the vehicle
    ground_height_m: float = 0.0       # sea bed / sand under base_link, odom z
    wave_elevation_m: float = 0.0      # water surface above mean level at base_link
    water_depth_m: float = 0.0         # surface minus ground at base_link (<= 0 on dry sand)
    fore_sensor_depth_m: float = 0.0   # surface minus fore water-sensor height (> 0: wet)
    aft_sensor_depth_m: float = 0.0
    sounder_depth_m: float = 0.0       # water below the sounder transducer (<= 0: dry)
    medium: Medium = Medium.LAND
    # appended by the physics core (issue 3)
    wave_surge_force_n: float = 0.0    # wave (Froude-Krylov + diffraction + drift) force, body x
    in_ground_contact: bool = True     # tracks touching the sand

    @classmethod
    def field_names(cls) -> list[str]:
        """Names of all fields, in order (CSV columns, bag fields)."""
        return [f.name for f in fields(cls)]
