"""NMEA framing: checksums checked, garbage skipped, every fault counted, nothing raised."""
from hypothesis import given, settings
from hypothesis import strategies as st

from dukw_driver.nmea_stream import MAX_LINE_BYTES, NmeaStream, nmea_checksum, nmea_sentence

GGA = nmea_sentence('GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,')


def test_checksum_of_the_textbook_gga():
    # the widely quoted example sentence ends in *47
    assert nmea_checksum('GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,') == '47'
    assert GGA.endswith(b'*47\r\n')


def test_sentences_split_across_chunks_come_out_whole():
    stream = NmeaStream(['GGA'])
    assert stream.feed(GGA[:20]) == []
    out = stream.feed(GGA[20:] + GGA)
    assert [s.sentence_type for s in out] == ['GGA', 'GGA']
    assert stream.counters.sentences == 2 and stream.counters.errors == 0


def test_wrong_and_missing_checksums_are_counted_and_dropped():
    stream = NmeaStream(['GGA'])
    bad = GGA.replace(b'4807.038', b'4807.039')
    no_sum = GGA.split(b'*')[0] + b'\r\n'
    assert stream.feed(bad + no_sum) == []
    assert stream.counters.checksum_errors == 2
    assert len(stream.feed(GGA)) == 1


def test_garbage_before_the_dollar_is_skipped_and_other_types_ignored():
    stream = NmeaStream(['GGA'])
    out = stream.feed(b'\x00\xffnoise' + GGA + nmea_sentence('SDMTW,17.5,C'))
    assert len(out) == 1
    assert stream.counters.ignored == 1


def test_a_line_without_end_is_dropped_when_too_long():
    stream = NmeaStream(['GGA'])
    stream.feed(b'$' + b'A' * (MAX_LINE_BYTES + 10))
    assert stream.counters.parse_errors == 1
    assert len(stream.feed(b'\r\n' + GGA)) == 1


@settings(max_examples=300, deadline=None)
@given(st.lists(st.binary(max_size=30), max_size=8))
def test_random_bytes_never_raise_and_every_line_is_accounted_for(chunks):
    stream = NmeaStream(['GGA', 'RMC', 'VTG', 'GST', 'DPT', 'DBT', 'MTW'])
    for chunk in chunks:
        stream.feed(chunk)
    stream.feed(b'\r\n')
    lines = b''.join(chunks).split(b'\n')
    # every line that is not blank ends up as exactly one sentence, error or ignored one
    expected = sum(1 for line in lines if b'$' in line or line.strip())
    c = stream.counters
    assert c.sentences + c.checksum_errors + c.parse_errors + c.ignored == expected


@settings(max_examples=300, deadline=None)
@given(st.integers(0, len(GGA) - 3), st.integers(1, 255))
def test_any_corrupted_byte_is_caught_and_counted(position, flip):
    corrupted = bytearray(GGA)
    corrupted[position] ^= flip
    stream = NmeaStream(['GGA'])
    assert stream.feed(bytes(corrupted) + b'\r\n') == []
    assert stream.counters.errors >= 1


@settings(max_examples=200, deadline=None)
@given(st.integers(1, len(GGA) - 3))
def test_truncated_sentence_is_counted_and_the_next_one_decodes(cut):
    stream = NmeaStream(['GGA'])
    assert stream.feed(GGA[:cut] + b'\r\n') == []
    assert stream.counters.errors == 1
    assert len(stream.feed(GGA)) == 1
