"""Airmar DT800 over NMEA: DPT/DBT/MTW, shallow water invalid, checksums enforced."""
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from dukw_driver.depth_sounder import SounderDepth, DepthSounderDecoder
from damage import damaged_stream
from dukw_driver.nmea_stream import nmea_sentence


def test_dpt_depth_offset_and_temperature():
    dec = DepthSounderDecoder(min_depth_m=0.5)
    assert dec.feed(nmea_sentence('YXMTW,17.5,C'), 0.0) == []
    (reading,) = dec.feed(nmea_sentence('SDDPT,2.40,-0.25,100'), 0.5)
    assert reading == SounderDepth(True, 2.40, -0.25, 17.5)


def test_shallower_than_half_a_metre_or_no_bottom_is_invalid_nan():
    dec = DepthSounderDecoder(min_depth_m=0.5)
    (shallow,) = dec.feed(nmea_sentence('SDDPT,0.45,0.0'), 0.0)
    (no_lock,) = dec.feed(nmea_sentence('SDDPT,,0.0'), 0.1)
    (edge,) = dec.feed(nmea_sentence('SDDPT,0.50,0.0'), 0.2)
    assert not shallow.valid and math.isnan(shallow.depth_m)
    assert not no_lock.valid and math.isnan(no_lock.depth_m)
    assert edge.valid and edge.depth_m == 0.5
    assert math.isnan(edge.water_temp_c)


def test_dbt_used_only_without_dpt_and_falls_back_to_feet():
    dec = DepthSounderDecoder(min_depth_m=0.5)
    (metres,) = dec.feed(nmea_sentence('SDDBT,10.0,f,3.05,M,1.7,F'), 0.0)
    assert metres.depth_m == pytest.approx(3.05)
    (feet,) = dec.feed(nmea_sentence('SDDBT,10.0,f,,M,,F'), 0.1)
    assert feet.depth_m == pytest.approx(3.048)
    dec.feed(nmea_sentence('SDDPT,3.0,0.3'), 0.2)
    assert dec.feed(nmea_sentence('SDDBT,10.0,f,3.05,M,1.7,F'), 0.3) == []


def test_bad_checksum_and_bad_values_are_counted():
    dec = DepthSounderDecoder(min_depth_m=0.5)
    good = nmea_sentence('SDDPT,2.40,0.0')
    assert dec.feed(good.replace(b'2.40', b'2.41'), 0.0) == []
    assert dec.feed(nmea_sentence('SDDPT,-1.0,0.0'), 0.0) == []
    assert dec.feed(nmea_sentence('SDMTW,99.0,C'), 0.0) == []
    assert dec.feed(nmea_sentence('SDDPT,abc,0.0'), 0.0) == []
    assert dec.counters.checksum_errors == 1 and dec.counters.parse_errors == 3


def test_old_temperature_is_forgotten():
    dec = DepthSounderDecoder(min_depth_m=0.5)
    dec.feed(nmea_sentence('YXMTW,17.5,C'), 0.0)
    (reading,) = dec.feed(nmea_sentence('SDDPT,2.0,0.0'), 60.0)
    assert math.isnan(reading.water_temp_c)


def test_negative_minimum_is_refused():
    with pytest.raises(ValueError):
        DepthSounderDecoder(min_depth_m=-0.1)


SENTENCES = [nmea_sentence('SDDPT,2.40,-0.25,100'), nmea_sentence('SDDBT,7.9,f,2.40,M,1.3,F'),
             nmea_sentence('YXMTW,17.5,C')]


@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(st.sampled_from(SENTENCES), st.integers(0, 60), st.integers(0, 255),
                          st.booleans()), max_size=10), st.binary(max_size=40))
def test_truncated_corrupted_and_random_input_never_raises(parts, noise):
    dec = DepthSounderDecoder(min_depth_m=0.5)
    stream, damaged = damaged_stream(parts)
    for reading in dec.feed(noise + stream + b'\r\n', 0.0):
        assert reading.valid == (reading.depth_m >= 0.5)
        assert reading.valid or math.isnan(reading.depth_m)
    if damaged:
        assert dec.counters.errors >= 1
