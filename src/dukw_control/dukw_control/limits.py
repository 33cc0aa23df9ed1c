"""Request validation, rate limits, the PI corrector and the motor current limiter.

ROS-free small classes; every ``update`` takes the time step in seconds.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum


def validate_twist(speed_mps: float, yaw_rate_rps: float, max_speed_mps: float,
                   max_yaw_rate_rps: float) -> None:
    """Raise ValueError for a NaN, infinite or out-of-range velocity request."""
    for name, value, limit in (('linear.x', speed_mps, max_speed_mps),
                               ('angular.z', yaw_rate_rps, max_yaw_rate_rps)):
        if not math.isfinite(value):
            raise ValueError(f'{name} is not finite: {value}')
        if abs(value) > limit:
            raise ValueError(f'{name} = {value:.3f} outside +/-{limit:.3f}')


class RateLimiter:
    """Moves toward a target at most ``rate`` units per second."""

    def __init__(self, rate_per_s: float, value: float = 0.0) -> None:
        if not rate_per_s > 0:
            raise ValueError('rate_per_s must be > 0')
        self.rate_per_s = rate_per_s
        self.value = value

    def update(self, target: float, dt_s: float) -> float:
        """Step toward ``target`` and return the new value."""
        step = self.rate_per_s * max(dt_s, 0.0)
        self.value += max(-step, min(step, target - self.value))
        return self.value

    def reset(self, value: float = 0.0) -> None:
        """Jump to ``value``."""
        self.value = value


class PiCorrector:
    """PI on a velocity error, output a velocity correction, with anti-windup.

    The integral is clamped to +/-``integral_limit`` and frozen while the output
    is saturated in the direction the error would push it (conditional integration).
    """

    def __init__(self, kp: float, ki: float, integral_limit: float) -> None:
        if kp < 0 or ki < 0 or integral_limit < 0:
            raise ValueError('PI gains and integral limit must be >= 0')
        self.kp, self.ki, self.integral_limit = kp, ki, integral_limit
        self.integral = 0.0

    def update(self, error: float, dt_s: float, saturated_high: bool = False,
               saturated_low: bool = False) -> float:
        """Return the correction for ``error``; integrate unless that deepens saturation."""
        blocked = (error > 0 and saturated_high) or (error < 0 and saturated_low)
        if not blocked:
            self.integral += error * max(dt_s, 0.0)
            self.integral = max(-self.integral_limit, min(self.integral_limit, self.integral))
        return self.kp * error + self.ki * self.integral

    def reset(self) -> None:
        """Clear the integral."""
        self.integral = 0.0


class CurrentState(Enum):
    """What the current limiter is doing (shown in diagnostics)."""

    OK = 'ok'
    OVERLOAD = 'overload, using the allowance'
    DERATING = 'derating'
    SPENT = 'allowance spent: held at the continuous limit'
    RESTING = 'resting: tracks stopped until the motor cools'


@dataclass(frozen=True)
class CurrentLimitSettings:
    """I2t thermal allowance of one track motor (vehicle.md section 3)."""

    continuous_a: float            # 35 A: 900 W at 24 V
    peak_a: float                  # ceiling while allowance is left
    allowance_a2s: float           # integral of (I^2 - I_c^2) dt allowed before derating fully
    derate_start_fraction: float   # the ceiling starts falling at this share of the allowance
    derate_gain_per_s: float       # command scale lost per second per unit relative overcurrent
    recover_rate_per_s: float      # command scale regained per second below the ceiling
    rest_below_scale: float = 0.0  # derated below this: stop and cool (0: never) ...
    resume_fraction: float = 0.0   # ... until the account is back to this share of it
                                   # (both from config/dukw.yaml current.*; the defaults: off)

    def __post_init__(self) -> None:
        if not 0 < self.continuous_a <= self.peak_a:
            raise ValueError('need 0 < continuous_a <= peak_a')
        if not self.allowance_a2s > 0:
            raise ValueError('allowance_a2s must be > 0')
        if not 0.0 <= self.derate_start_fraction < 1.0:
            raise ValueError('derate_start_fraction must lie in [0, 1)')
        if not (self.derate_gain_per_s > 0 and self.recover_rate_per_s > 0):
            raise ValueError('derate gain and recover rate must be > 0')
        if not (0.0 <= self.rest_below_scale < 1.0 and 0.0 <= self.resume_fraction < 1.0):
            raise ValueError('rest_below_scale and resume_fraction must lie in [0, 1)')


class CurrentLimiter:
    """I2t model of one motor and the command scale that keeps it within its allowance.

    ``heat_a2s`` integrates I^2 - I_c^2 (cooling below the continuous limit, never
    below zero). The current ceiling is ``peak_a`` until ``derate_start_fraction`` of
    the allowance is used, then falls linearly to ``continuous_a`` when it is spent,
    so a spent motor runs at or under its continuous rating. Whenever the measured
    current exceeds the ceiling the command scale falls; it recovers slowly below it.

    Derated below ``rest_below_scale`` with more than ``resume_fraction`` of the allowance
    used, the motor rests (scale 0) until the account has cooled to ``resume_fraction``,
    then gets the full command back. A track spinning at full slip draws the soil's shear
    strength whatever its speed command (vehicle.md 6: H at |i| -> 1), so derating it
    further would not lower its current, only slow the belt below the waves' uprush, which
    it then brakes (README "Main job"): short bursts with rests keep the same I2t account
    and let it move.
    """

    def __init__(self, settings: CurrentLimitSettings) -> None:
        self.s = settings
        self.heat_a2s = 0.0
        self.scale = 1.0
        self.current_a = 0.0
        self.resting = False

    @property
    def used_fraction(self) -> float:
        """Share of the overload allowance used (may exceed 1 briefly)."""
        return self.heat_a2s / self.s.allowance_a2s

    @property
    def ceiling_a(self) -> float:
        """The current the motor may draw now."""
        s = self.s
        over = (self.used_fraction - s.derate_start_fraction) / (1.0 - s.derate_start_fraction)
        over = min(max(over, 0.0), 1.0)
        return s.peak_a - over * (s.peak_a - s.continuous_a)

    @property
    def state(self) -> CurrentState:
        """OK, using the allowance, derating, spent, or resting."""
        if self.resting:
            return CurrentState.RESTING
        if self.used_fraction >= 1.0:
            return CurrentState.SPENT
        if self.scale < 1.0:
            return CurrentState.DERATING
        if self.heat_a2s > 0.0:
            return CurrentState.OVERLOAD
        return CurrentState.OK

    def update(self, current_a: float, dt_s: float) -> float:
        """Account the measured current over ``dt_s``; return the command scale 0..1."""
        if not math.isfinite(current_a):
            raise ValueError(f'current is not finite: {current_a}')
        s, dt = self.s, max(dt_s, 0.0)
        self.current_a = abs(current_a)
        self.heat_a2s = max(self.heat_a2s + (self.current_a ** 2 - s.continuous_a ** 2) * dt,
                            0.0)
        if self.resting:
            self._rest()
            return self.scale
        ceiling = self.ceiling_a
        excess = (self.current_a - ceiling) / ceiling
        if excess > 0.0:
            self.scale -= s.derate_gain_per_s * excess * dt
        else:
            self.scale += min(s.recover_rate_per_s, s.derate_gain_per_s * -excess) * dt
        self.scale = min(max(self.scale, 0.0), 1.0)
        if self.scale < s.rest_below_scale and self.used_fraction > s.resume_fraction:
            self.resting, self.scale = True, 0.0
        return self.scale

    def _rest(self) -> None:
        """Resting: full command back once the account has cooled enough."""
        if self.used_fraction <= self.s.resume_fraction:
            self.resting, self.scale = False, 1.0
