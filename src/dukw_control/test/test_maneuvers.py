"""Manoeuvre schedules and the player's aborts."""
import math

import pytest

from dukw_control.guards import InclineGuard
from dukw_control.limits import CurrentLimiter, CurrentLimitSettings
from dukw_control.maneuvers import ManeuverPlan, ManeuverPlayer, PlayerState
from dukw_control.mixer import NEUTRAL, SidePair


def player(plan, actuators='tracks'):
    current = CurrentLimitSettings(35.0, 58.0, 15000.0, 0.7, 1.0, 1.0)
    return ManeuverPlayer(plan, actuators, 4.0,
                          InclineGuard(math.radians(10), math.radians(15), 10.0, 0.0),
                          {s: CurrentLimiter(current) for s in ('port', 'stbd')})


def test_zigzag_swaps_every_period_and_ends():
    plan = ManeuverPlan('zigzag', high_pct=56, low_pct=32, period_s=10, duration_s=30)
    assert plan.command_at(1.0) == SidePair(56, 32)
    assert plan.command_at(12.0) == SidePair(32, 56)
    assert plan.command_at(25.0) == SidePair(56, 32)
    assert plan.command_at(30.0) is None


def test_unknown_maneuver_or_range_is_refused():
    with pytest.raises(ValueError):
        ManeuverPlan('loop')
    with pytest.raises(ValueError):
        ManeuverPlan('circle', port_pct=120)


def test_player_waits_for_authority_plays_with_bias_and_finishes():
    p = player(ManeuverPlan('circle', port_pct=44, stbd_pct=100, duration_s=1.0))
    assert p.step(0.0, False, 0.0, 0.02) == (NEUTRAL, NEUTRAL)
    assert p.state == PlayerState.WAITING
    tracks, props = p.step(0.1, True, 0.0, 0.02)
    assert tracks == SidePair(48, 100) and props == NEUTRAL
    assert p.step(1.2, True, 0.0, 0.02) == (NEUTRAL, NEUTRAL)
    assert p.state == PlayerState.DONE


def test_player_aborts_for_good_when_the_operator_takes_over():
    p = player(ManeuverPlan('transition', command_pct=64), actuators='both')
    tracks, props = p.step(0.0, True, 0.0, 0.02)
    assert tracks == props == SidePair(68, 64)
    assert p.step(0.02, False, 0.0, 0.02) == (NEUTRAL, NEUTRAL)
    assert p.state == PlayerState.ABORTED and 'RC operator' in p.reason
    assert p.step(0.04, True, 0.0, 0.02) == (NEUTRAL, NEUTRAL)


def test_player_aborts_on_a_steep_incline_or_a_spent_current_allowance():
    p = player(ManeuverPlan('incline', command_pct=100))
    p.step(0.0, True, 0.0, 0.02)
    assert p.step(0.02, True, math.radians(16), 0.02) == (NEUTRAL, NEUTRAL)
    assert 'incline' in p.reason
    p = player(ManeuverPlan('incline', command_pct=100))
    p.step(0.0, True, 0.0, 0.02)
    p.current['port'].heat_a2s = 15000.0
    assert p.step(0.02, True, 0.0, 0.02) == (NEUTRAL, NEUTRAL)
    assert 'current allowance' in p.reason
