"""Wet/dry decision: hysteresis and debouncing with known sample sequences."""
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from dukw_driver.water_contact import ContactSettings, WaterContactDetector

SETTINGS = ContactSettings(wet_on_level=0.5, wet_off_level=0.3, debounce_s=0.2)


def run(detector, samples, dt=0.05):
    return [detector.update(level, i * dt) for i, level in enumerate(samples)]


def test_goes_wet_only_after_the_debounce_time():
    det = WaterContactDetector(SETTINGS)
    states = run(det, [0.0, 0.9, 0.9, 0.9, 0.9, 0.9, 0.9])
    # the look turns wet at t=0.05; the state follows at t=0.25 (5th sample on)
    assert states == [False, False, False, False, False, True, True]


def test_spray_shorter_than_the_debounce_is_ignored():
    det = WaterContactDetector(SETTINGS)
    assert not any(run(det, [0.0, 0.9, 0.9, 0.1, 0.0, 0.9, 0.1, 0.0]))


def test_hysteresis_band_keeps_the_state():
    det = WaterContactDetector(SETTINGS)
    run(det, [0.9] * 10)
    assert det.wet
    for i, level in enumerate([0.45, 0.35, 0.31, 0.4, 0.45]):  # never down to 0.3
        assert det.update(level, 1.0 + i * 0.1)
    assert det.update(0.3, 2.0) and det.update(0.3, 2.25) is False


def test_bad_level_raises_and_changes_nothing():
    det = WaterContactDetector(SETTINGS)
    run(det, [0.9] * 10)
    for bad in (math.nan, -0.1, 1.5, None):
        with pytest.raises(ValueError):
            det.update(bad, 5.0)
    assert det.wet and det.level == 0.9


def test_bad_thresholds_are_refused():
    with pytest.raises(ValueError):
        ContactSettings(wet_on_level=0.3, wet_off_level=0.5, debounce_s=0.1)
    with pytest.raises(ValueError):
        ContactSettings(wet_on_level=0.6, wet_off_level=0.2, debounce_s=-1.0)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(0.0, 1.0), min_size=1, max_size=60))
def test_state_changes_only_after_a_debounce_long_look(levels):
    det = WaterContactDetector(SETTINGS)
    states = run(det, levels)
    looks, look = [], False
    for level in levels:
        look = True if level >= 0.5 else False if level <= 0.3 else look
        looks.append(look)
    for i in range(1, len(states)):
        if states[i] != states[i - 1]:
            # the new state was the look for the last 0.2 s (5 samples of 0.05 s)
            assert all(looks[j] == states[i] for j in range(max(0, i - 4), i + 1))
