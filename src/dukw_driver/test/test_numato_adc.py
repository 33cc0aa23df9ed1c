"""Numato ADC protocol: requests, echo-matched answers, timeouts, junk counted."""
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from dukw_driver.numato_adc import NumatoAdc, adc_read_command


def answer(channel, counts):
    return f'adc read {channel}\n\r{counts}\n\r>'.encode()


def test_requests_both_channels_then_waits_for_answers():
    adc = NumatoAdc((0, 1), timeout_s=0.5)
    assert adc.requests(0.0) == b'adc read 0\radc read 1\r'
    assert adc.requests(0.1) == b''            # both still in flight
    readings = adc.feed(answer(1, 1023) + answer(0, 12))
    assert [(r.channel, r.counts) for r in readings] == [(1, 1023), (0, 12)]
    assert readings[0].level == pytest.approx(1.0)
    assert adc.requests(0.2) == b'adc read 0\radc read 1\r'


def test_answers_split_anywhere_are_reassembled():
    adc = NumatoAdc((3,), timeout_s=0.5)
    adc.requests(0.0)
    data = answer(3, 517)
    assert adc.feed(data[:7]) == [] and adc.feed(data[7:13]) == []
    assert [r.counts for r in adc.feed(data[13:])] == [517]


def test_unanswered_request_times_out_and_is_sent_again():
    adc = NumatoAdc((0,), timeout_s=0.5)
    adc.requests(0.0)
    assert adc.requests(0.6) == b'adc read 0\r'
    assert adc.counters.timeouts == 1


def test_unrequested_out_of_range_and_orphan_values_are_errors():
    adc = NumatoAdc((0,), timeout_s=0.5)
    assert adc.feed(answer(0, 100)) == []      # never asked
    adc.requests(0.0)
    assert adc.feed(answer(0, 1024)) == []     # 10-bit ADC
    assert adc.feed(b'512\n\r') == []          # value without an echo
    assert adc.counters.parse_errors == 3
    assert adc.counters.readings == 0


def test_bad_configuration_is_refused():
    with pytest.raises(ValueError):
        NumatoAdc((0, 0), 0.5)
    with pytest.raises(ValueError):
        adc_read_command(12)
    with pytest.raises(ValueError):
        NumatoAdc((0,), 0.0)


@settings(max_examples=300, deadline=None)
@given(st.lists(st.binary(max_size=60), max_size=8))
@example([b'\x0b'])            # a vertical tab alone is whitespace to the parser, not junk
def test_random_bytes_never_raise_and_junk_is_counted(chunks):
    adc = NumatoAdc((0, 1), timeout_s=0.5)
    adc.requests(0.0)
    readings = []
    for chunk in chunks:
        readings += adc.feed(chunk)
    for reading in readings:
        assert reading.channel in (0, 1) and 0 <= reading.counts <= 1023
    junk = b''.join(chunks).replace(b'>', b'').strip()      # ASCII whitespace, as the parser
    if junk and not readings:
        adc.feed(b'\n')
        assert adc.counters.parse_errors >= 1 or b'adc read' in junk


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 1023), st.integers(1, 12))
def test_truncated_answer_then_a_good_one(counts, cut):
    adc = NumatoAdc((0,), timeout_s=0.5)
    adc.requests(0.0)
    adc.feed(answer(0, counts)[:cut])
    out = adc.feed(b'\n' + answer(0, counts))
    assert [r.counts for r in out] in ([counts], [])
    assert adc.counters.readings <= 1
