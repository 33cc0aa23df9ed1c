"""Decimator: a 100 Hz stream thinned out to a consumer's rate, by sample time."""
import pytest

from dukw_common.rates import Decimator


@pytest.mark.parametrize('rate_hz,expected', [(100.0, 100), (50.0, 50), (20.0, 20), (1.0, 1)])
def test_a_100_hz_stream_goes_out_at_the_asked_rate(rate_hz, expected):
    due = Decimator(rate_hz).due
    stamps = [k * 0.01 for k in range(100)]                # float stamps on a 100 Hz grid
    assert sum(due(t) for t in stamps) == expected


def test_the_first_sample_goes_out_and_a_step_back_in_time_starts_afresh():
    due = Decimator(20.0).due
    assert due(5.0) and not due(5.01)
    assert due(1.0)                                         # e.g. a simulator reset
    assert not due(1.02) and due(1.05)


@pytest.mark.parametrize('rate_hz', [0.0, -1.0, float('nan'), float('inf')])
def test_a_rate_that_is_not_a_positive_number_is_refused(rate_hz):
    with pytest.raises(ValueError, match='rate'):
        Decimator(rate_hz)
