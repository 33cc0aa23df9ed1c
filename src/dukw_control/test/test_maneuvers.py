"""Manoeuvre schedules and the player's aborts."""
import math

import pytest

from dukw_control.guards import InclineGuard
from dukw_control.limits import CurrentLimiter, CurrentLimitSettings
from dukw_control.maneuvers import ManeuverPlan, ManeuverPlayer, PlayerState
from dukw_control.mixer import NEUTRAL, SidePair


def player(plan, actuators='tracks', status=True):
    current = CurrentLimitSettings(35.0, 58.0, 15000.0, 0.7, 1.0, 1.0)
    p = ManeuverPlayer(plan, actuators, 4.0,
                       InclineGuard(math.radians(10), math.radians(15), 10.0, 0.0),
                       {s: CurrentLimiter(current) for s in ('port', 'stbd')},
                       start_wait_s=30.0, status_timeout_s=0.5)
    if status:                      # a tracks/status at t = 0, fresh for 0.5 s
        p.on_status(0.0, 10.0, 10.0)
    return p


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
    p.on_status(1.1, 10.0, 10.0)
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


def test_a_status_not_there_yet_is_waited_for_then_stale_once_playing():
    p = player(ManeuverPlan('circle', port_pct=44, stbd_pct=100, duration_s=60.0), status=False)
    assert p.step(0.0, True, 0.0, 0.02) == (NEUTRAL, NEUTRAL)    # authority first
    assert p.step(5.0, True, 0.0, 0.02) == (NEUTRAL, NEUTRAL)
    assert p.state == PlayerState.WAITING
    p.on_status(5.1, 10.0, 10.0)
    tracks, _ = p.step(5.12, True, 0.0, 0.02)
    assert p.state == PlayerState.PLAYING and tracks == SidePair(48, 100)
    assert p.step(5.7, True, 0.0, 0.02) == (NEUTRAL, NEUTRAL)   # 0.6 s without a status
    assert p.state == PlayerState.ABORTED and 'tracks/status stale' in p.reason


def test_the_start_wait_gives_up_saying_what_never_came():
    p = player(ManeuverPlan('circle'), status=False)
    p.step(0.0, True, 0.0, 0.02)
    p.step(30.1, True, 0.0, 0.02)
    assert p.state == PlayerState.ABORTED and p.reason == 'tracks/status never arrived'
    p = player(ManeuverPlan('circle'))
    p.step(0.0, False, 0.0, 0.02)
    p.step(30.1, False, 0.0, 0.02)
    assert p.state == PlayerState.ABORTED and 'never got authority' in p.reason
    p = player(ManeuverPlan('transition', command_pct=64), actuators='props', status=False)
    assert p.step(0.0, True, 0.0, 0.02)[1] == SidePair(68, 64)   # props need no status


def test_start_wait_and_status_timeout_must_be_positive():
    with pytest.raises(ValueError):
        ManeuverPlayer(ManeuverPlan('circle'), 'tracks', 4.0, None, {}, 0.0, 0.5)
