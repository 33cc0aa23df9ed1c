"""cmd_vel -> per-side commands: skid-steer tracks on land, a thrust model afloat.

ROS-free. REP 103: forward speed ``v`` (m/s), yaw rate ``w`` (rad/s, counter-clockwise
positive), so a positive ``w`` runs the starboard side faster. Commands are percent
of full scale, -100 .. +100 (vehicle.md section 2). Saturation keeps the
differential (yaw priority) and gives up forward speed first.
"""
from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class SidePair:
    """Port and starboard values (percent of full scale unless a name says otherwise)."""

    port: float = 0.0
    stbd: float = 0.0

    def scaled(self, factor: float) -> 'SidePair':
        """Both sides times ``factor`` (itself for 1.0: a float times 1.0 is itself, bit for
        bit; the controller scales by 1.0 on most cycles)."""
        if factor == 1.0 and type(self.port) is float and type(self.stbd) is float:
            return self
        return SidePair(self.port * factor, self.stbd * factor)

    def is_neutral(self) -> bool:
        """True when both sides are exactly zero."""
        return self.port == 0.0 and self.stbd == 0.0


NEUTRAL = SidePair()


@dataclass(frozen=True)
class Mix:
    """A mixer's result, with what the saturation gave up (for anti-windup)."""

    sides: SidePair
    speed_saturated: bool = False
    yaw_saturated: bool = False


def saturate_yaw_priority(common: float, differential: float, low: float,
                          high: float) -> tuple[float, float, bool, bool]:
    """Fit ``common -/+ differential`` into [low, high], keeping the differential first.

    Returns (common, differential, speed_saturated, yaw_saturated).
    """
    half_span = (high - low) / 2.0
    yaw_sat = abs(differential) > half_span
    d = max(-half_span, min(half_span, differential))
    c_lo, c_hi = low + abs(d), high - abs(d)
    c = max(c_lo, min(c_hi, common))
    return c, d, c != common, yaw_sat


@dataclass(frozen=True)
class LandMixer:
    """Skid-steer track kinematics with a calibrated effective track separation.

    The geometric separation (hull centrelines, 0.81 m) is too small for a skid
    steer: the tracks slip sideways in a turn, so the track-speed difference per
    unit yaw rate is larger. ``effective_track_separation_m`` comes from the turning
    radii (config gives the derivation).
    """

    full_scale_track_speed_mps: float
    effective_track_separation_m: float
    max_differential_ratio: float     # slower/faster side never below this (44/100)

    def __post_init__(self) -> None:
        if not (self.full_scale_track_speed_mps > 0 and self.effective_track_separation_m > 0):
            raise ValueError('track speed scale and separation must be > 0')
        if not 0.0 <= self.max_differential_ratio <= 1.0:
            raise ValueError('max_differential_ratio must lie in [0, 1]')

    def mix(self, speed_mps: float, yaw_rate_rps: float) -> Mix:
        """Track commands for (v, w); the differential obeys the 44/100 limit."""
        scale = 100.0 / self.full_scale_track_speed_mps
        common = speed_mps * scale
        diff = yaw_rate_rps * self.effective_track_separation_m / 2.0 * scale
        c, d, speed_sat, yaw_sat = saturate_yaw_priority(common, diff, -100.0, 100.0)
        r = self.max_differential_ratio
        max_d = abs(c) * (1.0 - r) / (1.0 + r)   # (|c|-|d|)/(|c|+|d|) >= r
        if abs(d) > max_d:
            d = math.copysign(max_d, d)
            yaw_sat = True
        return Mix(SidePair(c - d, c + d), speed_sat, yaw_sat)

    def yaw_rate_of(self, sides: SidePair) -> float:
        """Yaw rate the kinematics give for track commands (inverse of ``mix``)."""
        return ((sides.stbd - sides.port) / 100.0 * self.full_scale_track_speed_mps
                / self.effective_track_separation_m)


@dataclass(frozen=True)
class WaterMixer:
    """Two propellers: a surge force from quadratic drag, a yaw moment from their spacing.

    Steady state: the total thrust that holds speed v is F = F_max (v / v_max)^2
    (v_max the top waterborne speed at full thrust); the moment that holds yaw rate
    w is N = N_full (w / w_full)^2, with N_full = (T_fwd + T_rev) p the moment of one
    propeller ahead and one astern, p half the hull separation. Each propeller's
    thrust curve is T = T_max |cmd/100|^exponent, reverse T_max x reverse ratio.
    """

    max_thrust_n: float               # each, forward
    reverse_thrust_ratio: float
    thrust_exponent: float
    prop_arm_m: float                 # half the hull separation
    max_speed_mps: float              # at full forward thrust on both
    yaw_rate_at_full_moment_rps: float

    def __post_init__(self) -> None:
        for name in ('max_thrust_n', 'reverse_thrust_ratio', 'thrust_exponent', 'prop_arm_m',
                     'max_speed_mps', 'yaw_rate_at_full_moment_rps'):
            if not getattr(self, name) > 0:
                raise ValueError(f'{name} must be > 0')

    def thrust_to_pct(self, thrust_n: float) -> float:
        """Command giving ``thrust_n`` (negative: astern) on the thrust curves."""
        limit = self.max_thrust_n * (1.0 if thrust_n >= 0 else self.reverse_thrust_ratio)
        share = min(abs(thrust_n) / limit, 1.0)
        return math.copysign(100.0 * share ** (1.0 / self.thrust_exponent), thrust_n)

    def pct_to_thrust(self, pct: float) -> float:
        """Thrust of one propeller at ``pct`` (inverse of ``thrust_to_pct``)."""
        limit = self.max_thrust_n * (1.0 if pct >= 0 else self.reverse_thrust_ratio)
        return math.copysign(limit * min(abs(pct) / 100.0, 1.0) ** self.thrust_exponent, pct)

    def mix(self, speed_mps: float, yaw_rate_rps: float, moment_share: float = 1.0) -> Mix:
        """Propeller commands for (v, w) with yaw priority on the thrust limits.

        ``moment_share`` (0..1): the part of the afloat yaw moment the propellers give (the
        controller's share while the tracks carry weight and turn the vehicle)."""
        t_fwd = self.max_thrust_n
        t_rev = self.max_thrust_n * self.reverse_thrust_ratio
        force_n = math.copysign(2.0 * t_fwd * (speed_mps / self.max_speed_mps) ** 2, speed_mps)
        full_moment = (t_fwd + t_rev) * self.prop_arm_m
        moment_nm = math.copysign(
            full_moment * (yaw_rate_rps / self.yaw_rate_at_full_moment_rps) ** 2, yaw_rate_rps)
        if moment_share != 1.0:
            moment_nm *= min(max(moment_share, 0.0), 1.0)
        common, diff = force_n / 2.0, moment_nm / (2.0 * self.prop_arm_m)
        c, d, speed_sat, yaw_sat = saturate_yaw_priority(common, diff, -t_rev, t_fwd)
        return Mix(SidePair(self.thrust_to_pct(c - d), self.thrust_to_pct(c + d)),
                   speed_sat, yaw_sat)


def apply_port_bias(sides: SidePair, bias_pct: float, full_above_pct: float) -> SidePair:
    """Add the straight-line correction to the port side (vehicle.md section 3: 60/56).

    The bias follows the port command's sign and fades in over the first
    ``full_above_pct`` so that neutral stays neutral; if port then exceeds 100 %,
    both sides give up the excess so the difference is kept.
    """
    if sides.port == 0.0 or bias_pct == 0.0:
        return sides
    fade = min(abs(sides.port) / full_above_pct, 1.0) if full_above_pct > 0 else 1.0
    port = sides.port + math.copysign(bias_pct * fade, sides.port)
    stbd = sides.stbd
    excess = abs(port) - 100.0
    if excess > 0.0:
        port = math.copysign(100.0, port)
        stbd = stbd - math.copysign(excess, port)
    return SidePair(port, max(-100.0, min(100.0, stbd)))
