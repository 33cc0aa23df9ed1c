"""Validation, rate limiter, PI anti-windup, I2t current limiter."""
import dataclasses
import math

import pytest

from dukw_control.limits import (CurrentLimiter, CurrentLimitSettings, CurrentState,
                                 PiCorrector, RateLimiter, validate_twist)

CURRENT = CurrentLimitSettings(continuous_a=35.0, peak_a=58.0, allowance_a2s=15000.0,
                               derate_start_fraction=0.7, derate_gain_per_s=3.0,
                               recover_rate_per_s=0.05)


@pytest.mark.parametrize('v,w', [(math.nan, 0.0), (0.0, math.inf), (2.5, 0.0), (0.0, -2.0)])
def test_bad_twists_are_rejected(v, w):
    with pytest.raises(ValueError):
        validate_twist(v, w, 2.0, 1.5)


def test_rate_limiter_steps_at_its_rate():
    lim = RateLimiter(0.5)
    values = [lim.update(1.0, 0.1) for _ in range(30)]
    assert values[0] == pytest.approx(0.05)
    assert values[19] == pytest.approx(1.0)
    assert values[-1] == 1.0


def test_pi_integrates_and_freezes_when_saturated():
    pi = PiCorrector(kp=0.5, ki=1.0, integral_limit=0.3)
    for _ in range(10):
        pi.update(0.1, 0.1)
    assert pi.integral == pytest.approx(0.1)
    pi.update(0.1, 0.1, saturated_high=True)
    assert pi.integral == pytest.approx(0.1)          # frozen
    pi.update(-0.1, 0.1, saturated_high=True)         # unwinding is allowed
    assert pi.integral == pytest.approx(0.09)
    for _ in range(100):
        pi.update(1.0, 0.1)
    assert pi.integral == 0.3                         # clamped


def test_current_limiter_lets_a_short_overload_pass_then_holds_the_continuous_limit():
    lim = CurrentLimiter(CURRENT)
    # a load that needs 50 A at any command: the current follows command scale
    demand_a, history = 50.0, []
    for _ in range(60 * 100):
        current = demand_a * lim.scale
        lim.update(current, 0.01)
        history.append(current)
    assert history[100] == pytest.approx(50.0)         # the first seconds run unlimited
    tail = history[-20 * 100:]
    assert math.sqrt(sum(c * c for c in tail) / len(tail)) <= 35.0 + 0.5
    assert max(tail) <= 36.0
    assert lim.state in (CurrentState.SPENT, CurrentState.DERATING)
    assert lim.scale < 0.75


def test_current_limiter_cools_and_recovers():
    lim = CurrentLimiter(CURRENT)
    for _ in range(3000):
        lim.update(50.0 * lim.scale, 0.01)
    for _ in range(200 * 100):
        lim.update(10.0, 0.01)
    assert lim.heat_a2s == 0.0 and lim.scale == 1.0 and lim.state == CurrentState.OK


def test_a_motor_held_at_its_limit_whatever_the_command_rests_then_gets_it_back():
    # a track at full slip: the soil's shear strength sets the current (50 A) at any
    # command above zero, so derating lowers only the belt speed; the limiter rests instead
    lim = CurrentLimiter(dataclasses.replace(CURRENT, rest_below_scale=0.5,
                                             resume_fraction=0.3))
    scales, currents, states = [], [], set()
    for _ in range(120 * 100):
        current = 50.0 if lim.scale > 0.0 else 0.0
        lim.update(current, 0.01)
        scales.append(lim.scale)
        currents.append(current)
        states.add(lim.state)
        assert lim.used_fraction < 1.1                # the account is kept
    assert CurrentState.RESTING in states
    rest = scales.index(0.0)
    back = scales.index(1.0, rest)                    # full command again after the rest
    assert lim.heat_a2s <= 15000.0 or lim.resting
    assert 0.0 < min(scales[:rest]) and min(scales[:rest]) < 0.5 + 0.05
    assert back - rest > 5 * 100                      # cooled for seconds, not a flicker
    tail = currents[-60 * 100:]
    assert math.sqrt(sum(c * c for c in tail) / len(tail)) <= 35.0 + 1.0
    assert max(scales[-60 * 100:]) == 1.0             # bursts keep coming


def test_a_motor_the_foldback_holds_just_short_of_spent_rests_too():
    # in the swash: the soil's 32 A at any speed, 6 A of belt friction at full command and
    # the waves' +-8 A: the ceiling's foldback derates on each crest while the account
    # creeps towards spent; the motor rests before it is spent, not only after
    lim = CurrentLimiter(dataclasses.replace(CURRENT, rest_below_scale=0.5,
                                             resume_fraction=0.3))
    most_used = 0.0
    for k in range(120 * 100):
        wave_a = 8.0 * math.sin(2.0 * math.pi * k * 0.01 / 3.57)
        lim.update(32.0 + 6.0 * lim.scale + wave_a if lim.scale > 0.0 else 0.0, 0.01)
        if lim.resting:
            break
        most_used = max(most_used, lim.used_fraction)
    assert lim.state == CurrentState.RESTING
    assert most_used < 1.0                            # it rested before the account was spent


def test_without_a_rest_scale_a_motor_only_derates():
    lim = CurrentLimiter(CURRENT)
    for _ in range(60 * 100):
        lim.update(50.0 if lim.scale > 0.0 else 0.0, 0.01)
        assert lim.state != CurrentState.RESTING
    assert lim.scale < 0.5


def test_current_limiter_refuses_nan():
    with pytest.raises(ValueError):
        CurrentLimiter(CURRENT).update(math.nan, 0.01)
    with pytest.raises(ValueError):
        CurrentLimitSettings(40.0, 35.0, 1.0, 0.5, 1.0, 1.0)
    with pytest.raises(ValueError):
        CurrentLimitSettings(35.0, 58.0, 1.0, 0.5, 1.0, 1.0, rest_below_scale=1.0)
