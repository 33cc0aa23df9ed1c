"""The differential-drive controller: cmd_vel in, safe track and propeller commands out.

ROS-free. Feed it inputs with the ``on_*`` methods (times in seconds on one clock)
and call ``step(now_s)`` at the control rate. Per cycle:

authority -> mode -> sensors the mode needs -> cmd_vel freshness (fade to
neutral at the timeout) -> incline guard and stuck latch -> acceleration limits
-> PI on speed and yaw rate (anti-windup) -> mixers weighted by the mode ->
port bias -> per-motor current limit -> output.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Mapping

from dukw_common.config import ParamValue, require
from dukw_common.diagnostics import Health, Level
from dukw_common.sources import SourceWatch
from dukw_common.vehicle import drivetrain_params, limit_params, vehicle_params

from dukw_control.guards import InclineGuard, InclineState, StuckDetector
from dukw_control.limits import (CurrentLimiter, CurrentLimitSettings, PiCorrector, RateLimiter,
                                 validate_twist)
from dukw_control.mixer import NEUTRAL, LandMixer, SidePair, WaterMixer, apply_port_bias
from dukw_control.model_gains import PiGains, settings_with_model_gains
from dukw_control.modes import Mode, ModeDecision


#: The node's own parameters: (name, description, min, max). Defaults live in config.
NODE_PARAMS: tuple[tuple[str, str, float | None, float | None], ...] = (
    ('rate_hz', 'control and publishing rate, Hz', 1.0, 1000.0),
    ('diagnostics_period_s', '/diagnostics period (also sent at once on a change), s',
     0.01, 60.0),
    ('cmd_timeout_s', 'cmd_vel age at which the output is neutral, s', 0.05, 10.0),
    ('timeout_ramp_s', 'the ramp to neutral starts this long before the timeout, s', 0.01, 10.0),
    ('max_speed_mps', 'cmd_vel linear.x beyond this is rejected, m/s', 0.0, 5.0),
    ('max_yaw_rate_rps', 'cmd_vel angular.z beyond this is rejected, rad/s', 0.0, 5.0),
    ('max_accel_mps2', 'speed setpoint acceleration limit, m/s^2', 0.01, 20.0),
    ('max_yaw_accel_rps2', 'yaw-rate setpoint acceleration limit, rad/s^2', 0.01, 20.0),
    ('weight_rate_per_s', 'rate at which mode weights blend, 1/s', 0.01, 100.0),
    ('closed_loop', 'PI correction from odometry/filtered (false: open loop)', None, None),
    ('speed_kp', 'speed PI proportional gain', 0.0, 10.0),
    ('speed_ki', 'speed PI integral gain, 1/s', 0.0, 10.0),
    ('speed_integral_limit_mps', 'speed PI integral clamp, m/s', 0.0, 5.0),
    ('yaw_kp', 'yaw-rate PI proportional gain', 0.0, 10.0),
    ('yaw_ki', 'yaw-rate PI integral gain, 1/s', 0.0, 10.0),
    ('yaw_integral_limit_rps', 'yaw-rate PI integral clamp, rad/s', 0.0, 5.0),
    ('odometry_timeout_s', 'older odometry: open loop, s', 0.01, 10.0),
    ('imu_timeout_s', 'older attitude (imu/data) or pitch (odometry/filtered): tracks neutral '
     '(incline unguarded), s', 0.01, 10.0),
    ('tracks_status_timeout_s', 'older tracks/status: tracks neutral (current unguarded), s',
     0.01, 10.0),
    ('traction_timeout_s', 'older traction: stuck detection off, s', 0.01, 10.0),
    ('bias_full_above_pct', 'port bias fades in up to this command, %', 0.0, 100.0),
    ('land.effective_track_separation_m', 'skid-steer effective track separation, m', 0.1, 10.0),
    ('land.port_bias_scale', 'share of drivetrain.port_bias_pct applied to the tracks', 0.0, 5.0),
    ('water.port_bias_scale', 'share of drivetrain.port_bias_pct applied to the props', 0.0, 5.0),
    ('water.max_speed_mps', 'top waterborne speed at full thrust, m/s', 0.1, 5.0),
    ('water.yaw_rate_at_full_moment_rps', 'yaw rate with one prop ahead, one astern, rad/s',
     0.01, 5.0),
    ('water.thrust_exponent', 'thrust = max * |cmd/100|^exponent', 0.2, 5.0),
    ('water.idle_track_pct', 'afloat with tracks idling: their command, %', 0.0, 100.0),
    ('current.peak_a', 'track motor current ceiling while allowance is left, A', 0.0, 200.0),
    ('current.allowance_a2s', 'I2t overload allowance, A^2 s', 1.0, 1e7),
    ('current.derate_start_fraction', 'ceiling starts falling at this share of the allowance',
     0.0, 0.99),
    ('current.derate_gain_per_s', 'command scale lost per s per relative overcurrent', 0.01,
     1000.0),
    ('current.recover_rate_per_s', 'command scale regained per s below the ceiling', 0.001,
     100.0),
    ('current.rest_below_scale', 'derated below this scale: rest to cool (0: never)',
     0.0, 0.99),
    ('current.resume_fraction', 'a resting motor resumes at this share of the allowance',
     0.0, 0.99),
    ('incline.sustained_time_s', 'beyond limits.incline_sustained_rad this long: stop climbing, s',
     0.0, 600.0),
    ('incline.release_margin_rad', 'the guard releases this far below the sustained limit, rad',
     0.0, 0.5),
    ('incline.pitch_time_constant_s', 'low-pass of pitch for the guard, s', 0.0, 10.0),
    ('stuck.slip_threshold', 'both slips at or above this ...', 0.0, 1.0),
    ('stuck.speed_threshold_mps', '... with ground speed below this ...', 0.0, 2.0),
    ('stuck.min_command_pct', '... at a track command of at least this ...', 0.0, 100.0),
    ('stuck.hold_s', '... for this long: stuck, s', 0.0, 600.0),
    ('gains.source', "PI gains: 'hand' (the *_kp/*_ki above) or 'model' (IMC from the "
     'identified models below, dukw_control.model_gains)', None, None),
    ('gains.land_model', "land model file of 'sysid identify' (gains.source 'model')", None,
     None),
    ('gains.water_model', "water model file of 'sysid identify' (gains.source 'model')", None,
     None),
    ('gains.lambda_factor', 'IMC: closed-loop time constant / the model time constant',
     0.05, 20.0),
)
GAIN_SOURCES = ('hand', 'model')


@dataclass(frozen=True)
class ControllerSettings:
    """Everything the controller needs, from the shared block and its node block."""

    land: LandMixer
    water: WaterMixer
    current: CurrentLimitSettings
    closed_loop: bool
    port_bias_land_pct: float
    port_bias_water_pct: float
    incline_sustained_rad: float
    incline_brief_rad: float
    cmd_timeout_s: float
    timeout_ramp_s: float
    max_speed_mps: float
    max_yaw_rate_rps: float
    max_accel_mps2: float
    max_yaw_accel_rps2: float
    weight_rate_per_s: float
    speed_kp: float
    speed_ki: float
    speed_integral_limit_mps: float
    yaw_kp: float
    yaw_ki: float
    yaw_integral_limit_rps: float
    odometry_timeout_s: float
    imu_timeout_s: float
    tracks_status_timeout_s: float
    traction_timeout_s: float
    bias_full_above_pct: float
    water_idle_track_pct: float
    incline_sustained_time_s: float
    incline_release_margin_rad: float
    incline_pitch_time_constant_s: float
    stuck_slip_threshold: float
    stuck_speed_threshold_mps: float
    stuck_min_command_pct: float
    stuck_hold_s: float
    water_gains: PiGains | None = None    # afloat PI gains; None: the same as on land

    def __post_init__(self) -> None:
        if not 0 < self.timeout_ramp_s <= self.cmd_timeout_s:
            raise ValueError('need 0 < timeout_ramp_s <= cmd_timeout_s')


def settings_from_params(p: Mapping[str, ParamValue]) -> ControllerSettings:
    """Build settings from dotted parameters (shared block + drive_controller_node block)."""
    body, drive, lim = vehicle_params(p), drivetrain_params(p), limit_params(p)

    def f(name: str) -> float:
        return require(p, name)

    land = LandMixer(drive.full_scale_track_speed_mps, f('land.effective_track_separation_m'),
                     drive.max_differential_ratio)
    water = WaterMixer(drive.max_prop_thrust_n, drive.prop_reverse_thrust_ratio,
                       f('water.thrust_exponent'), body.hull_separation_m / 2.0,
                       f('water.max_speed_mps'), f('water.yaw_rate_at_full_moment_rps'))
    current = CurrentLimitSettings(drive.continuous_current_limit_a, f('current.peak_a'),
                                   f('current.allowance_a2s'),
                                   f('current.derate_start_fraction'),
                                   f('current.derate_gain_per_s'),
                                   f('current.recover_rate_per_s'),
                                   f('current.rest_below_scale'), f('current.resume_fraction'))
    fields = ControllerSettings.__dataclass_fields__
    scalars = {name.replace('.', '_'): f(name) for name, *_ in NODE_PARAMS
               if name.replace('.', '_') in fields and name != 'closed_loop'}
    settings = ControllerSettings(
        land=land, water=water, current=current,
        closed_loop=require(p, 'closed_loop', bool),
        port_bias_land_pct=drive.port_bias_pct * f('land.port_bias_scale'),
        port_bias_water_pct=drive.port_bias_pct * f('water.port_bias_scale'),
        incline_sustained_rad=lim.incline_sustained_rad,
        incline_brief_rad=lim.incline_brief_rad, **scalars)
    source = require(p, 'gains.source', str)
    if source not in GAIN_SOURCES:
        raise ValueError(f'gains.source must be one of {GAIN_SOURCES}, got {source!r}')
    if source == 'hand':
        return settings
    paths = [require(p, f'gains.{m}_model', str) for m in ('land', 'water')]
    if not any(paths):
        raise ValueError("gains.source 'model' needs gains.land_model or gains.water_model")
    return settings_with_model_gains(settings, [x for x in paths if x], f('gains.lambda_factor'))


@dataclass(frozen=True)
class ControlOutput:
    """One cycle's commands and, when neutral, why."""

    tracks: SidePair = NEUTRAL
    props: SidePair = NEUTRAL
    neutral_reason: str = ''


@dataclass
class _Inputs:
    cmd: tuple[float, float] = (0.0, 0.0)
    cmd_s: float = -math.inf
    authority_ok: bool = False
    authority_detail: str = 'no authority message yet'
    authority_back_s: float = -math.inf
    stopped_s: float = -math.inf      # last cycle of a safe stop or a stale-input stop
    mode: ModeDecision | None = None
    odom: tuple[float, float] = (0.0, 0.0)
    stamps: dict[str, float] = field(default_factory=dict)
    slips: tuple[float, float] = (0.0, 0.0)
    weight_on_tracks_fraction: float = 0.0   # estimator: 0 afloat .. 1 dry (traction)
    incline_rad: float = 0.0
    rejected: int = 0
    last_rejection: str = ''


class DriveController:
    """The controller core; see the module docstring for the order of the stages."""

    def __init__(self, settings: ControllerSettings) -> None:
        self.s = settings
        self.i = _Inputs()
        self.speed_ramp = RateLimiter(settings.max_accel_mps2)
        self.yaw_ramp = RateLimiter(settings.max_yaw_accel_rps2)
        self.track_weight = RateLimiter(settings.weight_rate_per_s)
        self.prop_weight = RateLimiter(settings.weight_rate_per_s)
        self.speed_pi = PiCorrector(settings.speed_kp, settings.speed_ki,
                                    settings.speed_integral_limit_mps)
        self.yaw_pi = PiCorrector(settings.yaw_kp, settings.yaw_ki,
                                  settings.yaw_integral_limit_rps)
        self.current = {side: CurrentLimiter(settings.current) for side in ('port', 'stbd')}
        self.incline = InclineGuard(settings.incline_sustained_rad, settings.incline_brief_rad,
                                    settings.incline_sustained_time_s,
                                    settings.incline_release_margin_rad)
        self.stuck = StuckDetector(settings.stuck_slip_threshold,
                                   settings.stuck_speed_threshold_mps,
                                   settings.stuck_min_command_pct, settings.stuck_hold_s)
        self.sources = SourceWatch()      # drive_mode and authority: one publisher each
        self._last_step_s: float | None = None
        self._last_mix_flags = (False, False)   # (speed, yaw) saturated last cycle
        self.output = ControlOutput(neutral_reason='starting')
        self._hand_gains = PiGains(settings.speed_kp, settings.speed_ki, settings.yaw_kp,
                                   settings.yaw_ki)   # made once, not per step

    # --- inputs -----------------------------------------------------------------------
    def on_cmd_vel(self, speed_mps: float, yaw_rate_rps: float, now_s: float,
                   stamp_s: float | None = None) -> bool:
        """A velocity request; False (and counted, nothing changed) if rejected.

        ``stamp_s`` (a TwistStamped's header, on ``now_s``'s clock): the request's age
        counts from its stamp (a stamp ahead of ``now_s`` counts as now), and one already
        ``cmd_timeout_s`` old is refused as timed out: it never refreshes the command.
        """
        try:
            validate_twist(speed_mps, yaw_rate_rps, self.s.max_speed_mps,
                           self.s.max_yaw_rate_rps)
            sent_s = now_s if stamp_s is None else self._sent_time(stamp_s, now_s)
        except ValueError as exc:
            self.i.rejected += 1
            self.i.last_rejection = str(exc)
            return False
        if self.stuck.stuck and (speed_mps == 0.0 or speed_mps * self.i.cmd[0] < 0.0):
            self.stuck.clear()
        self.i.cmd, self.i.cmd_s = (float(speed_mps), float(yaw_rate_rps)), sent_s
        return True

    def _sent_time(self, stamp_s: float, now_s: float) -> float:
        """When a stamped request was sent; ValueError when it is already timed out."""
        if not math.isfinite(stamp_s):
            raise ValueError(f'cmd_vel stamp {stamp_s} is not finite')
        age_s = now_s - stamp_s
        if age_s >= self.s.cmd_timeout_s:
            raise ValueError(f'cmd_vel stamped {age_s:.3f} s ago: older than cmd_timeout_s '
                             f'({self.s.cmd_timeout_s} s), treated as timed out')
        return min(stamp_s, now_s)

    def on_authority(self, usable: bool, detail: str, now_s: float) -> None:
        """Whether the computer holds authority with live outputs (RC operator: False)."""
        if usable and not self.i.authority_ok:
            self.i.authority_back_s = now_s
        if not usable:
            self._reset()
        self.i.authority_ok, self.i.authority_detail = usable, detail

    def on_mode(self, decision: ModeDecision, now_s: float | None = None) -> None:
        """The mode manager's latest decision, arrived at ``now_s``.

        A safe stop, and the end of one, count as stops even between two control steps:
        only a cmd_vel that arrives after them drives again.
        """
        modes = (decision.mode, self.i.mode.mode if self.i.mode else None)
        if now_s is not None and Mode.SAFE_STOP in modes:
            self.i.stopped_s = max(self.i.stopped_s, now_s)
        self.i.mode = decision

    def on_odometry(self, surge_mps: float, yaw_rate_rps: float, now_s: float) -> None:
        """Measured body surge speed and yaw rate (odometry/filtered)."""
        if math.isfinite(surge_mps) and math.isfinite(yaw_rate_rps):
            self.i.odom = (surge_mps, yaw_rate_rps)
            self.i.stamps['odometry'] = now_s

    def on_pitch(self, pitch_rad: float, now_s: float) -> None:
        """REP 103 pitch (positive nose down), low-passed into the nose-up incline."""
        if not math.isfinite(pitch_rad):
            return
        last = self.i.stamps.get('pitch')
        dt = 0.0 if last is None else min(max(now_s - last, 0.0), 1.0)
        alpha = 1.0 if last is None else dt / (self.s.incline_pitch_time_constant_s + dt + 1e-9)
        self.i.incline_rad += alpha * (-pitch_rad - self.i.incline_rad)
        self.i.stamps['pitch'] = now_s

    def on_attitude(self, measured_s: float, now_s: float) -> None:
        """An IMU attitude sample measured at ``measured_s`` arrived at ``now_s``.

        The pitch comes through the estimator, which keeps predicting while the IMU is
        silent, so only the IMU's own samples say how old the attitude is.
        """
        if math.isfinite(measured_s):
            self.i.stamps['imu'] = min(measured_s, now_s)

    def on_track_currents(self, port_a: float, stbd_a: float, now_s: float) -> None:
        """Track motor currents: advance each motor's I2t account."""
        if not (math.isfinite(port_a) and math.isfinite(stbd_a)):
            return
        last = self.i.stamps.get('tracks/status')
        dt = 0.0 if last is None else min(max(now_s - last, 0.0), 0.5)
        self.current['port'].update(port_a, dt)
        self.current['stbd'].update(stbd_a, dt)
        self.i.stamps['tracks/status'] = now_s

    def on_traction(self, port_slip: float, stbd_slip: float,
                    weight_on_tracks_fraction: float, now_s: float) -> None:
        """Track slips and the share of the weight on the tracks, from the estimator
        (traction); a message with a non-finite value changes nothing."""
        if math.isfinite(port_slip) and math.isfinite(stbd_slip) \
                and math.isfinite(weight_on_tracks_fraction):
            self.i.slips = (port_slip, stbd_slip)
            self.i.weight_on_tracks_fraction = min(max(weight_on_tracks_fraction, 0.0), 1.0)
            self.i.stamps['traction'] = now_s

    # --- the cycle --------------------------------------------------------------------
    def _age(self, name: str, now_s: float) -> float:
        return now_s - self.i.stamps.get(name, -math.inf)

    def _reset(self) -> None:
        self.speed_ramp.reset()
        self.yaw_ramp.reset()
        self.speed_pi.reset()
        self.yaw_pi.reset()

    def _neutral(self, reason: str) -> ControlOutput:
        self._reset()
        self.output = ControlOutput(neutral_reason=reason)
        return self.output

    def _stopped(self, reason: str, now_s: float) -> ControlOutput:
        """Neutral for a fault; driving resumes only on a cmd_vel sent after it."""
        self.i.stopped_s = now_s
        return self._neutral(reason)

    def step(self, now_s: float) -> ControlOutput:
        """Run one control cycle at ``now_s`` and return the commands."""
        s, i = self.s, self.i
        dt = 0.0 if self._last_step_s is None else min(max(now_s - self._last_step_s, 0.0), 0.1)
        self._last_step_s = now_s
        if not i.authority_ok:
            return self._neutral(f'no authority: {i.authority_detail}')
        if self.sources.fault():
            return self._stopped(f'second source: {self.sources.fault()}', now_s)
        if i.mode is None or i.mode.mode == Mode.SAFE_STOP:
            self.track_weight.reset()
            self.prop_weight.reset()
            return self._stopped('safe stop: ' + (i.mode.reason if i.mode else 'no drive_mode'),
                                 now_s)
        if i.mode.track_weight > 0.0 or i.mode.tracks_idle:
            for name, limit in (('tracks/status', s.tracks_status_timeout_s),
                                ('imu', s.imu_timeout_s), ('pitch', s.imu_timeout_s)):
                if self._age(name, now_s) > limit:
                    return self._stopped(f'{name} stale: the tracks cannot be guarded', now_s)
        if math.isinf(i.cmd_s):
            return self._neutral('no cmd_vel yet')
        if i.cmd_s < i.authority_back_s:
            return self._neutral('waiting for a fresh cmd_vel since authority came back')
        if i.cmd_s <= i.stopped_s:
            return self._neutral('waiting for a fresh cmd_vel since the stop')
        left_s = s.cmd_timeout_s - (now_s - i.cmd_s)
        fade = min(max(left_s / s.timeout_ramp_s, 0.0), 1.0)
        if left_s <= 1e-9:
            return self._neutral('cmd_vel timed out')
        speed, yaw = i.cmd
        # guards: the incline only matters while tracks carry the vehicle
        if i.mode.track_weight > 0.0:
            self.incline.update(i.incline_rad, dt)
        else:
            self.incline.reset()
        speed = self.incline.limit(speed)
        if self.incline.limit(self.speed_ramp.value) == 0.0:
            self.speed_ramp.reset()           # stop climbing at once, not on the ramp
        self._update_stuck(now_s, dt)
        if self.stuck.stuck:
            return self._neutral(self.stuck.reason)
        speed_sp = self.speed_ramp.update(speed, dt)
        yaw_sp = self.yaw_ramp.update(yaw, dt)
        return self._mix(speed_sp, yaw_sp, fade, dt, now_s)

    def _update_stuck(self, now_s: float, dt: float) -> None:
        if self._age('traction', now_s) > self.s.traction_timeout_s or \
                self.i.mode.track_weight == 0.0:
            self.stuck.update(0.0, 0.0, 0.0, 0.0, dt)   # no evidence: the timer restarts
            return
        biggest = max(abs(self.output.tracks.port), abs(self.output.tracks.stbd))
        self.stuck.update(*self.i.slips, self.i.odom[0], biggest, dt)

    def _mix(self, speed_sp: float, yaw_sp: float, fade: float, dt: float,
             now_s: float) -> ControlOutput:
        s, i = self.s, self.i
        mode = i.mode
        track_w = self.track_weight.update(mode.track_weight, dt)
        prop_w = self.prop_weight.update(mode.prop_weight, dt)
        speed_cmd, yaw_cmd = speed_sp, yaw_sp
        closed = s.closed_loop and self._age('odometry', now_s) <= s.odometry_timeout_s
        if speed_sp == 0.0 and yaw_sp == 0.0:
            self.speed_pi.reset()
            self.yaw_pi.reset()
        elif closed:
            self._use_gains(s.water_gains if prop_w > track_w else None)
            main = self._last_mix_flags
            derated = min(self.current['port'].scale, self.current['stbd'].scale) < 1.0 \
                and track_w > 0
            speed_cmd += self.speed_pi.update(speed_sp - i.odom[0], dt,
                                              main[0] or derated, main[0] or derated)
            yaw_cmd += self.yaw_pi.update(yaw_sp - i.odom[1], dt, main[1], main[1])
        land = s.land.mix(speed_cmd, yaw_cmd)
        water = s.water.mix(speed_cmd, yaw_cmd, self._prop_moment_share(track_w, now_s))
        heavier = land if track_w >= prop_w else water
        self._last_mix_flags = (heavier.speed_saturated, heavier.yaw_saturated)
        tracks = land.sides.scaled(track_w)
        if mode.mode == Mode.WATER and mode.tracks_idle and speed_cmd != 0.0:
            idle = math.copysign(s.water_idle_track_pct, speed_cmd)
            tracks = SidePair(idle, idle)
        props = water.sides.scaled(prop_w)
        tracks = apply_port_bias(tracks, s.port_bias_land_pct, s.bias_full_above_pct)
        props = apply_port_bias(props, s.port_bias_water_pct, s.bias_full_above_pct)
        if not self._descending(speed_sp):
            tracks = tracks.scaled(self._track_scale())
        self.output = ControlOutput(tracks.scaled(fade), props.scaled(fade))
        return self.output

    def _track_scale(self) -> float:
        """Both tracks' command scale: the hotter motor's. Scaled alike, a derated vehicle
        slows along its path instead of turning toward the hotter side, and a resting motor
        rests both (a burst on one track in the swash only slews the vehicle)."""
        return min(self.current['port'].scale, self.current['stbd'].scale)

    def _prop_moment_share(self, track_w: float, now_s: float) -> float:
        """The part of their afloat yaw moment the propellers give: the water's share of the
        weight while the tracks are used (1 afloat or on the propellers alone).

        Grounded, the tracks' skid steer turns the vehicle; the propellers' largest moment
        (~90 N m) is small against the tracks' lateral resistance, and at full differential
        their thrusts cancel, thrust that the tracks need to climb out of the swash
        (README "Main job"). A stale estimate counts as all the weight on the tracks.
        """
        if track_w == 0.0:
            return 1.0
        fresh = self._age('traction', now_s) <= self.s.traction_timeout_s
        on_tracks = self.i.weight_on_tracks_fraction if fresh else 1.0
        return 1.0 - track_w * on_tracks

    def _use_gains(self, gains: PiGains | None) -> None:
        """PI gains of the medium that carries the vehicle (None: the land / hand ones)."""
        g = gains or self._hand_gains
        self.speed_pi.kp, self.speed_pi.ki = g.speed_kp, g.speed_ki
        self.yaw_pi.kp, self.yaw_pi.ki = g.yaw_kp, g.yaw_ki

    def _descending(self, speed_mps: float) -> bool:
        """Driving down a slope steep enough to matter: the way off it is never derated.

        Held or driven on a steep slope the load is gravity whatever the command, so
        derating would only leave the vehicle stalled on it at the same current.
        """
        incline = self.i.incline_rad
        return speed_mps * incline < 0.0 and abs(incline) > self.s.incline_sustained_rad / 2

    # --- diagnostics ------------------------------------------------------------------
    def healths(self, now_s: float) -> list[Health]:
        """Controller, current limiter, incline and stuck status for /diagnostics."""
        i = self.i
        ctrl = Health('controller', values={
            'mode': i.mode.mode.name if i.mode else 'none', 'authority': i.authority_detail,
            'cmd_vel_age_s': f'{now_s - i.cmd_s:.2f}', 'rejected_requests': i.rejected,
            'closed_loop': self.s.closed_loop, 'tracks_pct': _pair(self.output.tracks),
            'props_pct': _pair(self.output.props)})
        if self.output.neutral_reason:
            ctrl.message = 'neutral: ' + self.output.neutral_reason
        if i.rejected:
            ctrl.worsen(Level.WARN, f'rejected {i.rejected} cmd_vel ({i.last_rejection})')
        if self.s.closed_loop and self._age('odometry', now_s) > self.s.odometry_timeout_s:
            ctrl.worsen(Level.WARN, 'odometry/filtered stale: open loop')
        if 'stale' in self.output.neutral_reason or self.sources.fault():
            ctrl.worsen(Level.ERROR, self.output.neutral_reason)
        current = Health('current limiter')
        for side, lim in self.current.items():
            current.values.update({f'{side}_state': lim.state.value,
                                   f'{side}_current_a': f'{lim.current_a:.1f}',
                                   f'{side}_ceiling_a': f'{lim.ceiling_a:.1f}',
                                   f'{side}_allowance_used': f'{lim.used_fraction:.2f}',
                                   f'{side}_command_scale': f'{lim.scale:.2f}'})
            if lim.scale < 1.0 or lim.used_fraction >= 1.0:
                current.worsen(Level.WARN, f'{side} track motor {lim.state.value}')
        incline = Health('incline guard', message=self.incline.state.value, values={
            'incline_deg': f'{math.degrees(self.incline.incline_rad):.1f}',
            'steep_for_s': f'{self.incline.steep_for_s:.1f}'})
        if self.incline.state != InclineState.OK:
            incline.level = Level.WARN
        stale = [n for n in ('imu', 'pitch') if self._age(n, now_s) > self.s.imu_timeout_s]
        if stale:                      # never "ok" on an attitude nobody measured lately
            incline.worsen(Level.ERROR, f'{" and ".join(stale)} stale: incline unguarded, '
                                        'tracks neutral')
        stuck = Health('stuck detection', values={'slips': _pair(SidePair(*i.slips))})
        if self.stuck.stuck:
            stuck.worsen(Level.ERROR, self.stuck.reason)
        return [ctrl, current, incline, stuck]


def _pair(sides: SidePair) -> str:
    return f'{sides.port:.1f}/{sides.stbd:.1f}'
