"""What the vehicle's devices report: one set of reading types for the whole stack. ROS-free.

The simulator's sensor model (dukw_sim.sensors) produces these; the estimator
(dukw_estimation) consumes them. ekf_node builds them from the device topics
(dukw_estimation.ros_convert) and sim_node turns them into those topics
(dukw_sim.sim_messages), with the same rules both ways. Plain dataclasses, SI
units, REP 103/105 axes; NaN marks a value the device did not give (a NaN
variance: the consumer uses its configured sigma). Frame ids and message
covariance layouts are the converters' business, not the readings'.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

NAN = math.nan
#: Values of DriveStatus.drive.
DRIVES = ('tracks', 'props')


@dataclass(frozen=True, slots=True)
class ImuSample:
    """GPS-aided IMU at imu_link (axes of base_link): attitude from its own EKF and compass
    (ENU, REP 145), body FLU rates and specific force, with diagonal variances."""

    t_s: float
    roll_rad: float
    pitch_rad: float
    yaw_rad: float                  # NaN: no orientation; any branch (wrapped by consumers)
    roll_rate_rps: float
    pitch_rate_rps: float
    yaw_rate_rps: float
    accel_x_mps2: float             # NaN: no accelerations
    accel_y_mps2: float
    accel_z_mps2: float
    yaw_var_rad2: float = NAN       # NaN or <= 0: use the configured sigma
    yaw_rate_var_rps2: float = NAN
    roll_var_rad2: float = NAN
    pitch_var_rad2: float = NAN
    roll_rate_var_rps2: float = NAN
    pitch_rate_var_rps2: float = NAN
    accel_var_m2ps4: tuple[float, float, float] = (NAN, NAN, NAN)   # x, y, z


@dataclass(frozen=True, slots=True)
class GpsFix:
    """A DGPS fix of the antenna, geodetic (WGS84), with horizontal and vertical variance."""

    t_s: float
    latitude_deg: float
    longitude_deg: float
    altitude_m: float
    horizontal_var_m2: float = NAN  # NaN: configured sigma
    valid: bool = True              # False: no fix (NavSatStatus.STATUS_NO_FIX)
    vertical_var_m2: float = NAN


@dataclass(frozen=True, slots=True)
class GpsVelocity:
    """DGPS ground velocity of the antenna, ENU, with variance per axis (NaN: configured)."""

    t_s: float
    east_mps: float
    north_mps: float
    var_mps2: float = NAN           # east and north
    up_mps: float = NAN
    up_var_mps2: float = NAN


@dataclass(frozen=True, slots=True)
class WaterContact:
    """The fore and aft water-contact sensors: debounced wet flags and raw levels 0..1."""

    t_s: float
    fore_wet: bool
    aft_wet: bool
    fore_level: float = NAN
    aft_level: float = NAN


@dataclass(frozen=True, slots=True)
class DepthReading:
    """Depth sounder: water below the transducer; valid only deeper than about 0.5 m."""

    t_s: float
    valid: bool
    depth_m: float                  # NaN when not valid
    offset_m: float = NAN           # transducer offset (+ to surface, - to keel)
    water_temp_c: float = NAN


@dataclass(frozen=True, slots=True)
class MotorSide:
    """One channel of a motor controller."""

    command_pct: float
    current_a: float
    speed_mps: float                # tracks: belt speed; propellers: 0 (no encoder)
    force_n: float                  # tracks: current x gain; propellers: estimated thrust
    voltage_v: float = NAN
    temperature_c: float = NAN
    fault_flags: int = 0            # dukw_msgs/MotorSide FAULT_* bits
    faults: tuple[str, ...] = ()    # their names


@dataclass(frozen=True, slots=True)
class DriveStatus:
    """A dual-channel controller: ``drive`` 'tracks' or 'props' ('' when not said)."""

    t_s: float
    port: MotorSide
    stbd: MotorSide
    connected: bool = True
    drive: str = ''

    def __post_init__(self) -> None:
        if self.drive not in ('',) + DRIVES:
            raise ValueError(f'drive must be one of {DRIVES} (or empty), got {self.drive!r}')


#: reading type -> the device topic it goes out on (architecture.md's topic contract)
_TOPICS = {ImuSample: 'imu/data', GpsFix: 'gps/fix', GpsVelocity: 'gps/vel',
           WaterContact: 'water/contact', DepthReading: 'depth'}


def reading_topic(reading) -> str:
    """The device topic of ``reading`` (a DriveStatus by its drive; ValueError without one)."""
    if isinstance(reading, DriveStatus):
        if not reading.drive:
            raise ValueError('a DriveStatus without its drive has no topic')
        return f'{reading.drive}/status'
    return _TOPICS[type(reading)]


def positional_builder(cls: type):
    """A function building ``cls`` (a frozen, slotted dataclass) from all its fields given
    positionally, about 4x cheaper than its __init__ (which sets each field through
    object.__setattr__): an unfrozen slotted twin with the same fields (so the same slot
    layout) is built and takes ``cls`` as its class. The result is an ordinary ``cls``:
    equal to ``cls(*values)``, frozen, hashable. No defaults and no __post_init__ checks:
    for readings built many times a second from values the caller made (the sensor
    models', the IMU and motor conversions of the device topics)."""
    if not dataclasses.is_dataclass(cls) or '__slots__' not in vars(cls):
        raise TypeError(f'{cls.__name__} is not a slotted dataclass')
    twin = dataclasses.make_dataclass(
        f'_{cls.__name__}Fields', [(f.name, f.type) for f in dataclasses.fields(cls)],
        slots=True)

    def build(*values):
        obj = twin(*values)
        obj.__class__ = cls
        return obj
    return build
