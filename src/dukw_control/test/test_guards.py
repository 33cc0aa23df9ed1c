"""Incline guard and stuck detection."""
import math

import pytest

from dukw_control.guards import InclineGuard, InclineState, StuckDetector

TEN, FIFTEEN = math.radians(10), math.radians(15)


def guard():
    return InclineGuard(TEN, FIFTEEN, sustained_time_s=5.0,
                        release_margin_rad=math.radians(1))


def test_brief_limit_stops_climbing_at_once_but_allows_going_down():
    g = guard()
    g.update(math.radians(16), 0.01)
    assert g.state == InclineState.STOP_BRIEF
    assert g.limit(1.0) == 0.0                # forward, nose up: climbing
    assert g.limit(-0.5) == -0.5              # backing down
    g.update(-math.radians(16), 0.01)         # nose down: astern climbs
    assert g.limit(-0.5) == 0.0 and g.limit(0.5) == 0.5


def test_sustained_limit_needs_its_time():
    g = guard()
    for _ in range(499):
        g.update(math.radians(12), 0.01)
    assert g.state == InclineState.STEEP and g.limit(1.0) == 1.0
    for _ in range(2):
        g.update(math.radians(12), 0.01)
    assert g.state == InclineState.STOP_SUSTAINED and g.limit(1.0) == 0.0
    g.update(math.radians(9.5), 0.01)         # inside the release margin: still stopped
    assert g.stopping
    g.update(math.radians(8.0), 0.01)
    assert g.state == InclineState.OK and g.limit(1.0) == 1.0


def test_guard_refuses_bad_limits():
    with pytest.raises(ValueError):
        InclineGuard(FIFTEEN, TEN, 1.0, 0.0)


def test_stuck_needs_both_slips_no_progress_and_time_and_latches():
    s = StuckDetector(slip_threshold=0.9, speed_threshold_mps=0.05, min_command_pct=10.0,
                      hold_s=3.0)
    for _ in range(299):
        assert not s.update(0.95, 0.97, 0.01, 60.0, 0.01)
    assert s.update(0.95, 0.97, 0.01, 60.0, 0.02)
    assert 'stuck' in s.reason
    assert s.update(0.0, 0.0, 1.0, 60.0, 0.01)     # latched
    s.clear()
    assert not s.stuck
    for _ in range(1000):                           # one track gripping: not stuck
        assert not s.update(0.95, 0.3, 0.01, 60.0, 0.01)
    for _ in range(1000):                           # moving: not stuck
        assert not s.update(0.95, 0.95, 0.5, 60.0, 0.01)
