"""What the vehicle's devices report, given the simulator's ground truth (ROS-free).

`SensorModel` turns a `Truth` into the readings the real devices give
(dukw_common.readings, the types the estimator consumes), each at
its own rate and with its own noise (config ``sim_node`` block: ``rates.*``,
``noise.*``, ``gps.*``, ``water_contact.*``, ``depth.*``, ``battery.*``, ``motors.*``;
mounting points from the shared ``sensors.*``). Every device has its own
seeded random stream, so one device's rate does not change another's noise.

Frames: the IMU sits at ``imu_link`` = (0, 0, sensors.imu_z_m) in base_link and
the GPS antenna at ``gps_link`` = (0, 0, sensors.gps_antenna_z_m), both with
base_link's axes. The IMU reports its orientation in ENU (REP 145) as its own
EKF does, the yaw coming from the tilt-compensated compass; the GPS velocity is
ENU. Errors of the IMU's attitude and of the DGPS position drift slowly
(first-order Gauss-Markov); rate, acceleration and velocity noise is white.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from enum import IntFlag
from typing import Mapping

import numpy as np

from dukw_common.config import ConfigError, ParamValue, build_settings, node_params, require
from dukw_common.geometry import geodetic_from_local_enu
from dukw_common.readings import (DepthReading, DriveStatus, GpsFix, GpsVelocity, ImuSample,
                                  MotorSide, WaterContact, positional_builder)
from dukw_common.vehicle import (DrivetrainParams, SensorMounts, drivetrain_params,
                                  sensor_mounts)
from dukw_model.lever_arm import (sensor_point_enu, sensor_point_velocity_body,
                                  specific_force_at_sensor)
from dukw_model.propeller import prop_thrust_n
from dukw_sim.truth import Truth

NODE_NAME = 'sim_node'
#: Sensor streams and the config keys of their rates (``rates.<name>_hz``).
SENSOR_STREAMS = ('imu', 'gps', 'water', 'depth', 'motors')


# ----------------------------------------------------------------------------- faults

class Fault(IntFlag):
    """The fault bits of dukw_msgs/MotorSide (FAULT_*) the simulator raises."""

    OVERHEAT = 1
    UNDERVOLTAGE = 4
    STALL = 256

    def names(self) -> tuple[str, ...]:
        """Names of the raised bits, as dukw_msgs/MotorSide.faults lists them."""
        return tuple(f.name.lower() for f in Fault if f in self)


#: FAULT_* bits -> their names, filled as combinations occur (a per-sample enum walk costs
#: more than the rest of a motor channel's model)
_FAULT_NAMES: dict[int, tuple[str, ...]] = {}


def fault_names(bits: int) -> tuple[str, ...]:
    """``Fault(bits).names()``, cached."""
    names = _FAULT_NAMES.get(bits)
    if names is None:
        names = _FAULT_NAMES[bits] = Fault(bits).names()
    return names


# ----------------------------------------------------------------------------- settings

@dataclass(frozen=True)
class SensorRates:
    """Publication rate of each device, Hz."""

    imu_hz: float
    gps_hz: float
    water_hz: float
    depth_hz: float
    motors_hz: float


@dataclass(frozen=True)
class SensorNoise:
    """Standard deviations and correlation times of the device errors."""

    accel_x_std_mps2: float
    accel_y_std_mps2: float
    accel_z_std_mps2: float
    gyro_std_rps: float
    gyro_bias_std_rps: float
    attitude_std_rad: float
    heading_std_rad: float
    attitude_tau_s: float
    gps_horizontal_std_m: float
    gps_vertical_std_m: float
    gps_tau_s: float
    gps_velocity_std_mps: float
    water_level_std: float
    depth_std_m: float
    current_std_a: float
    voltage_std_v: float
    speed_std_mps: float


@dataclass(frozen=True)
class DatumSettings:
    """Geodetic datum of the odom origin (the shared ``datum.*``)."""

    latitude_deg: float
    longitude_deg: float
    altitude_m: float


@dataclass(frozen=True)
class WaterSettings:
    """Water-contact sensors (config ``water_contact.*``)."""

    lead_gap_m: float          # the level ramps 0 -> 1 over this depth around the sensor point
    wet_level: float           # raw level at or above which a sample counts as wet
    debounce_samples: int      # consecutive agreeing samples before the flag changes


@dataclass(frozen=True)
class DepthSettings:
    """Depth sounder (config ``depth.*``)."""

    offset_m: float
    water_temp_c: float


@dataclass(frozen=True)
class BatterySettings:
    """The propellers' battery and both controllers' undervoltage levels (``battery.*``).

    The track pack's voltage under load is the physics core's (``Truth.battery_voltage_v``).
    """

    props_open_circuit_v: float
    props_internal_resistance_ohm: float
    tracks_undervoltage_v: float
    props_undervoltage_v: float


@dataclass(frozen=True)
class MotorSettings:
    """Motor-controller temperature and stall detection (config ``motors.*``)."""

    ambient_temp_c: float
    thermal_tau_s: float
    temp_rise_c_per_a2: float
    overheat_c: float
    stall_current_a: float
    stall_speed_mps: float
    stall_time_s: float


#: Fields that may be negative (everything else is a non-negative quantity).
_SIGNED = {'latitude_deg', 'longitude_deg', 'altitude_m', 'offset_m', 'water_temp_c',
           'ambient_temp_c', 'overheat_c'}


def _group(cls: type, params: Mapping[str, ParamValue], prefix: str):
    """Build dataclass ``cls`` from ``<prefix>.<field>``; counts >= 1, magnitudes >= 0."""
    settings = build_settings(cls, params, prefix)
    for name, value in vars(settings).items():
        low = 1 if isinstance(value, int) else 0.0
        if name not in _SIGNED and value < low:
            raise ConfigError(f'parameter {prefix + "." + name!r} must be >= {low}, got {value}')
    return settings


@dataclass(frozen=True)
class SensorConfig:
    """Everything SensorModel needs, built from dotted parameters."""

    rates: SensorRates
    noise: SensorNoise
    datum: DatumSettings
    water: WaterSettings
    depth: DepthSettings
    battery: BatterySettings
    motors: MotorSettings
    mounts: SensorMounts
    drivetrain: DrivetrainParams

    @classmethod
    def from_params(cls, params: Mapping[str, ParamValue]) -> 'SensorConfig':
        """Build from the parameters sim_node sees (shared block + its own); ConfigError."""
        rates = SensorRates(**{f'{s}_hz': _positive(params, f'rates.{s}_hz')
                               for s in SENSOR_STREAMS})
        return cls(rates, _group(SensorNoise, params, 'noise'),
                   _group(DatumSettings, params, 'datum'),
                   _group(WaterSettings, params, 'water_contact'),
                   _group(DepthSettings, params, 'depth'),
                   _group(BatterySettings, params, 'battery'),
                   _group(MotorSettings, params, 'motors'), sensor_mounts(params),
                   drivetrain_params(params))

    @classmethod
    def from_config(cls, path: str | None = None) -> 'SensorConfig':
        """Load from a parameter file (default: the stack's config/dukw.yaml)."""
        return cls.from_params(node_params(NODE_NAME, path))


def _positive(params: Mapping[str, ParamValue], name: str) -> float:
    value = require(params, name)
    if value <= 0:
        raise ConfigError(f'parameter {name!r} must be > 0, got {value}')
    return value


_imu_sample = positional_builder(ImuSample)
_motor_side = positional_builder(MotorSide)
_gps_fix = positional_builder(GpsFix)
_gps_velocity = positional_builder(GpsVelocity)
_water_contact = positional_builder(WaterContact)
_depth_reading = positional_builder(DepthReading)
_drive_status = positional_builder(DriveStatus)    # drive: 'tracks' or 'props', ours below


# ----------------------------------------------------------------------------- helpers

class NoiseStream:
    """Standard normal numbers from one seeded generator, drawn in blocks (fast per call)."""

    def __init__(self, rng: np.random.Generator, width: int, block: int = 1024) -> None:
        self._rng = rng
        self._width = width
        self._block = block
        self._rows: list[list[float]] = []
        self._next = 0

    def draw(self) -> list[float]:
        """``width`` independent N(0, 1) numbers."""
        if self._next >= len(self._rows):
            self._rows = self._rng.standard_normal((self._block, self._width)).tolist()
            self._next = 0
        row = self._rows[self._next]
        self._next += 1
        return row


class GaussMarkov:
    """First-order Gauss-Markov error: stationary std ``std``, correlation time ``tau_s``.

    ``tau_s`` = 0 gives white noise. The state starts drawn from the stationary law.
    """

    def __init__(self, std: float, tau_s: float, first_draw: float) -> None:
        self.std = std
        self.tau_s = tau_s
        self.value = std * first_draw

    _coeffs = (math.nan, 0.0, 0.0)   # (dt_s, a, sqrt(1 - a^2) std) of the last step's dt

    def step(self, dt_s: float, draw: float) -> float:
        """Advance by ``dt_s`` with a fresh N(0, 1) draw; return the error."""
        if self.tau_s <= 0.0:
            self.value = self.std * draw
        elif dt_s > 0.0:
            last_dt, a, gain = self._coeffs
            if dt_s != last_dt:        # a stream's dt is its fixed period: computed once
                a = math.exp(-dt_s / self.tau_s)
                gain = math.sqrt(1.0 - a * a) * self.std
                self._coeffs = (dt_s, a, gain)
            self.value = a * self.value + gain * draw
        return self.value


class Schedule:
    """Which streams are due at a time, each at its own rate (first sample at t = 0)."""

    def __init__(self, rates_hz: Mapping[str, float]) -> None:
        for name, rate in rates_hz.items():
            if not rate > 0:
                raise ValueError(f'rate of {name!r} must be > 0, got {rate}')
        self._periods = {name: 1.0 / rate for name, rate in rates_hz.items()}
        self._next = {name: -math.inf for name in rates_hz}

    def due(self, t_s: float) -> list[str]:
        """Names due at ``t_s``; each is then scheduled one period later (no burst catch-up)."""
        out = []
        for name, next_s in self._next.items():
            if t_s + 1e-9 >= next_s:
                out.append(name)
                nxt = next_s + self._periods[name]
                self._next[name] = nxt if nxt > t_s + 1e-9 else t_s + self._periods[name]
        return out

    def reset(self) -> None:
        """Make every stream due at the next call."""
        self._next = {name: -math.inf for name in self._next}


def _clip01(value: float) -> float:
    return 0.0 if value < 0.0 else 1.0 if value > 1.0 else value


class _Debounce:
    """A wet flag that changes only after ``samples`` consecutive agreeing raw readings."""

    def __init__(self, samples: int) -> None:
        self.samples = samples
        self.state: bool | None = None   # the first sample is taken as it is
        self._count = 0

    def update(self, raw: bool) -> bool:
        if self.state is None:
            self.state = raw
        elif raw == self.state:
            self._count = 0
        else:
            self._count += 1
            if self._count >= self.samples:
                self.state = raw
                self._count = 0
        return self.state


_OVERHEAT, _UNDERVOLTAGE, _STALL = int(Fault.OVERHEAT), int(Fault.UNDERVOLTAGE), int(Fault.STALL)


class _MotorChannel:
    """Controller temperature (first-order in I^2) and stall timer of one motor channel."""

    def __init__(self, settings: MotorSettings) -> None:
        self.settings = settings
        self.temperature_c = settings.ambient_temp_c
        self.stalled_s = 0.0

    def update(self, dt_s: float, current_a: float, stalling: bool, voltage_v: float,
               undervoltage_v: float) -> int:
        """Advance temperature and stall timer by ``dt_s``; return the FAULT_* bits (int:
        IntFlag arithmetic per sample costs more than the model)."""
        m = self.settings
        target_c = m.ambient_temp_c + m.temp_rise_c_per_a2 * current_a * current_a
        share = min(1.0, dt_s / m.thermal_tau_s) if m.thermal_tau_s > 0 else 1.0
        self.temperature_c += (target_c - self.temperature_c) * share
        self.stalled_s = self.stalled_s + dt_s if stalling else 0.0
        flags = 0
        if self.temperature_c >= m.overheat_c:
            flags |= _OVERHEAT
        if voltage_v < undervoltage_v:
            flags |= _UNDERVOLTAGE
        if stalling and self.stalled_s >= m.stall_time_s:
            flags |= _STALL
        return flags


# ----------------------------------------------------------------------------- the model

class SensorModel:
    """All the vehicle's devices, seeded: `sample(truth)` returns the readings due now."""

    def __init__(self, config: SensorConfig, seed: int = 0) -> None:
        self.config = config
        self.seed = seed
        self.reset()

    @classmethod
    def from_config(cls, path: str | None = None, seed: int = 0) -> 'SensorModel':
        """Build from a parameter file (default: the stack's config/dukw.yaml)."""
        return cls(SensorConfig.from_config(path), seed)

    def reset(self) -> None:
        """Back to the state right after construction (same seed, same noise)."""
        cfg, noise = self.config, self.config.noise
        rngs = [np.random.default_rng(s) for s in np.random.SeedSequence(self.seed).spawn(8)]
        self._noise = {'imu': NoiseStream(rngs[0], 9), 'gps_fix': NoiseStream(rngs[1], 3),
                       'gps_vel': NoiseStream(rngs[2], 3), 'water': NoiseStream(rngs[3], 2),
                       'depth': NoiseStream(rngs[4], 1), 'tracks': NoiseStream(rngs[5], 6),
                       'props': NoiseStream(rngs[6], 6)}
        self._imu_noise = self._noise['imu']
        first = rngs[7].standard_normal(9).tolist()
        self._gyro_bias = tuple(noise.gyro_bias_std_rps * d for d in first[:3])
        att, head, tau = noise.attitude_std_rad, noise.heading_std_rad, noise.attitude_tau_s
        self._attitude_error = [GaussMarkov(att, tau, first[3]), GaussMarkov(att, tau, first[4]),
                                GaussMarkov(head, tau, first[5])]
        hor, ver, tau = noise.gps_horizontal_std_m, noise.gps_vertical_std_m, noise.gps_tau_s
        self._gps_error = [GaussMarkov(hor, tau, first[6]), GaussMarkov(hor, tau, first[7]),
                           GaussMarkov(ver, tau, first[8])]
        g, sx, sy, sz = (noise.gyro_std_rps, noise.accel_x_std_mps2, noise.accel_y_std_mps2,
                         noise.accel_z_std_mps2)
        self._imu_var = (noise.heading_std_rad ** 2, g * g, noise.attitude_std_rad ** 2,
                         (sx * sx, sy * sy, sz * sz))   # the IMU's constant variances
        self._schedule = Schedule({name: getattr(cfg.rates, f'{name}_hz')
                                   for name in SENSOR_STREAMS})
        self._last_t: dict[str, float] = {}
        self._last_rates: tuple[float, float, float] | None = None
        self._fore = _Debounce(cfg.water.debounce_samples)
        self._aft = _Debounce(cfg.water.debounce_samples)
        self._motors = {(drive, side): _MotorChannel(cfg.motors)
                        for drive in ('tracks', 'props') for side in ('port', 'stbd')}

    @property
    def gyro_bias_rps(self) -> tuple[float, float, float]:
        """This run's constant gyro bias (drawn from the seed), rad/s."""
        return self._gyro_bias

    def sample(self, truth: Truth) -> list:
        """The readings due at ``truth.t_s`` (IMU, GPS fix + velocity, water, depth, motors)."""
        out: list = []
        for name in self._schedule.due(truth.t_s):
            if name == 'imu':
                out.append(self.imu(truth))
            elif name == 'gps':
                out.extend((self.gps_fix(truth), self.gps_velocity(truth)))
            elif name == 'water':
                out.append(self.water(truth))
            elif name == 'depth':
                out.append(self.depth(truth))
            else:
                out.extend((self.tracks(truth), self.props(truth)))
        return out

    def _dt(self, stream: str, t_s: float) -> float:
        """Time since this stream's last sample (0 the first time)."""
        last = self._last_t.get(stream)
        self._last_t[stream] = t_s
        return 0.0 if last is None else max(0.0, t_s - last)

    def imu(self, truth: Truth) -> ImuSample:
        """The IMU at imu_link: its EKF's attitude, gyro rates with bias, specific force."""
        noise, h = self.config.noise, self.config.mounts.imu_z_m
        dt = self._dt('imu', truth.t_s)
        d = self._imu_noise.draw()
        roll_err, pitch_err, head_err = self._attitude_error
        err = (roll_err.step(dt, d[6]), pitch_err.step(dt, d[7]), head_err.step(dt, d[8]))
        wx, wy, wz = truth.roll_rate_rps, truth.pitch_rate_rps, truth.yaw_rate_rps
        last = self._last_rates
        if last is not None and dt > 0:
            alpha_x, alpha_y = (wx - last[0]) / dt, (wy - last[1]) / dt
        else:
            alpha_x = alpha_y = 0.0
        self._last_rates = (wx, wy, wz)
        fx, fy, fz = specific_force_at_sensor(
            (truth.accel_x_mps2, truth.accel_y_mps2, truth.accel_z_mps2), (wx, wy, wz),
            (alpha_x, alpha_y), h)
        bias, g = self._gyro_bias, noise.gyro_std_rps
        sx, sy, sz = noise.accel_x_std_mps2, noise.accel_y_std_mps2, noise.accel_z_std_mps2
        head2, g2, att2, accel_var = self._imu_var
        return _imu_sample(      # ImuSample's fields in order (variances: yaw, yaw rate,
            # roll, pitch, roll rate, pitch rate, accel)
            truth.t_s, truth.roll_rad + err[0], truth.pitch_rad + err[1], truth.yaw_rad + err[2],
            wx + bias[0] + g * d[0], wy + bias[1] + g * d[1], wz + bias[2] + g * d[2],
            fx + sx * d[3], fy + sy * d[4], fz + sz * d[5],
            head2, g2, att2, att2, g2, g2, accel_var)

    def antenna_enu(self, truth: Truth) -> tuple[float, float, float]:
        """True position of the GPS antenna in odom (ENU), m: base_link + R (0, 0, h)."""
        return sensor_point_enu((truth.x_m, truth.y_m, truth.z_m), truth.roll_rad,
                                truth.pitch_rad, truth.yaw_rad,
                                self.config.mounts.gps_antenna_z_m)

    def gps_fix(self, truth: Truth) -> GpsFix:
        """DGPS fix of the antenna from the configured datum, with slowly drifting error."""
        noise, datum = self.config.noise, self.config.datum
        dt = self._dt('gps_fix', truth.t_s)
        d = self._noise['gps_fix'].draw()
        east, north, up = self.antenna_enu(truth)
        err = [g.step(dt, d[k]) for k, g in enumerate(self._gps_error)]
        lat, lon, alt = geodetic_from_local_enu(east + err[0], north + err[1], up + err[2],
                                                datum.latitude_deg, datum.longitude_deg,
                                                datum.altitude_m)
        h2, v2 = noise.gps_horizontal_std_m ** 2, noise.gps_vertical_std_m ** 2
        return _gps_fix(truth.t_s, lat, lon, alt, h2, True, v2)   # h. var, valid, v. var

    def gps_velocity(self, truth: Truth) -> GpsVelocity:
        """DGPS velocity of the antenna, ENU: body velocity plus w x r, rotated; white noise."""
        s, h = self.config.noise.gps_velocity_std_mps, self.config.mounts.gps_antenna_z_m
        d = self._noise['gps_vel'].draw()
        u, v = sensor_point_velocity_body(truth.surge_mps, truth.sway_mps,
                                          truth.roll_rate_rps, truth.pitch_rate_rps, h)
        cy, sy = math.cos(truth.yaw_rad), math.sin(truth.yaw_rad)
        return _gps_velocity(truth.t_s, cy * u - sy * v + s * d[0], sy * u + cy * v + s * d[1],
                             s * s, truth.heave_mps + s * d[2], s * s)   # var, up, up var

    def water(self, truth: Truth) -> WaterContact:
        """Water contact: the level ramps 0 -> 1 across the lead gap around the sensor point."""
        water, s = self.config.water, self.config.noise.water_level_std
        d = self._noise['water'].draw()
        gap = max(water.lead_gap_m, 1e-6)
        fore = _clip01(0.5 + truth.fore_sensor_depth_m / gap + s * d[0])
        aft = _clip01(0.5 + truth.aft_sensor_depth_m / gap + s * d[1])
        return _water_contact(truth.t_s, self._fore.update(fore >= water.wet_level),
                              self._aft.update(aft >= water.wet_level), fore, aft)

    def depth(self, truth: Truth) -> DepthReading:
        """Depth below the transducer; invalid (NaN) out of water or shallower than the minimum."""
        cfg = self.config
        d = self._noise['depth'].draw()
        valid = (truth.sounder_depth_m > 0.0
                 and truth.water_depth_m > cfg.mounts.depth_sounder_min_m)
        depth_m = truth.sounder_depth_m + cfg.noise.depth_std_m * d[0] if valid else math.nan
        return _depth_reading(truth.t_s, valid, depth_m, cfg.depth.offset_m,
                              cfg.depth.water_temp_c)

    def tracks(self, truth: Truth) -> DriveStatus:
        """The tracks' controller: command, current, pack voltage, belt speed, force = I x gain."""
        gain = self.config.drivetrain.track_force_gain_n_per_a
        return self._drivetrain(
            truth, 'tracks', (truth.port_cmd_pct, truth.stbd_cmd_pct),
            (truth.port_current_a, truth.stbd_current_a),
            (truth.port_track_speed_mps, truth.stbd_track_speed_mps),
            lambda current_a, pct: current_a * gain)

    def props(self, truth: Truth) -> DriveStatus:
        """The propellers' controller: no encoder (speed 0); thrust estimated from the command
        as motor_controller_node does (dukw_model.propeller.prop_thrust_n)."""
        drivetrain = self.config.drivetrain
        return self._drivetrain(
            truth, 'props', (truth.port_prop_cmd_pct, truth.stbd_prop_cmd_pct),
            (truth.port_prop_current_a, truth.stbd_prop_current_a), None,
            lambda current_a, pct: prop_thrust_n(pct, drivetrain))

    def _drivetrain(self, truth: Truth, drive: str, commands: tuple, currents: tuple,
                    speeds: tuple | None, force_n) -> DriveStatus:
        noise, battery = self.config.noise, self.config.battery
        dt = self._dt(drive, truth.t_s)
        d = self._noise[drive].draw()
        if drive == 'tracks':
            voltage, under_v = truth.battery_voltage_v, battery.tracks_undervoltage_v
        else:
            voltage = battery.props_open_circuit_v - battery.props_internal_resistance_ohm * (
                abs(currents[0]) + abs(currents[1]))
            under_v = battery.props_undervoltage_v
        stall = self.config.motors
        sides = []
        for i, side in enumerate(('port', 'stbd')):
            true_speed = 0.0 if speeds is None else speeds[i]
            stalling = (speeds is not None and commands[i] != 0.0
                        and abs(currents[i]) >= stall.stall_current_a
                        and abs(true_speed) < stall.stall_speed_mps)
            channel = self._motors[drive, side]
            flags = channel.update(dt, currents[i], stalling, voltage, under_v)
            current = currents[i] + noise.current_std_a * d[3 * i]
            speed = 0.0 if speeds is None else true_speed + noise.speed_std_mps * d[3 * i + 1]
            sides.append(_motor_side(      # MotorSide's fields in order
                commands[i], current, speed, force_n(current, commands[i]),
                voltage + noise.voltage_std_v * d[3 * i + 2], channel.temperature_c,
                flags, fault_names(flags)))
        return _drive_status(truth.t_s, sides[0], sides[1], True, drive)   # connected
