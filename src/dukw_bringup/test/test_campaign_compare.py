"""campaign_compare: two campaign folders of the same draws, run by run."""
import pytest

from dukw_bringup import campaign_compare
from dukw_bringup.campaign_report import CONDITIONS, write_runs_csv


def _run(index, failed=(), volume=5.0, **conditions):
    row = {'index': index, **{c: 0.1 * index for c in CONDITIONS}, **conditions,
           'slip_rmse': 0.02, 'volume_error_pct': volume, 'fraction_error': 0.05,
           'mode_delay_to_water_s': 0.5, 'mode_delay_to_land_s': float('nan'),
           'targets_met': not failed, 'failed_targets': ';'.join(failed), 'error': ''}
    return row


def _folder(tmp_path, name, rows):
    folder = tmp_path / name
    folder.mkdir()
    write_runs_csv(rows, folder / 'runs.csv')
    return folder


@pytest.fixture
def pair(tmp_path):
    before = _folder(tmp_path, 'before', [
        _run(0), _run(1, ('volume_error_pct',), volume=12.0),
        _run(2, ('volume_error_pct', 'fraction_error'), volume=15.0), _run(3)])
    after = _folder(tmp_path, 'after', [
        _run(0), _run(1, volume=8.0),
        _run(2, ('volume_error_pct',), volume=11.0), _run(3, ('slip_rmse',))])
    return before, after


def test_gained_lost_and_misses_per_target(pair):
    before, after = (campaign_compare.read_runs(f) for f in pair)
    c = campaign_compare.compare(before, after)
    assert c.runs == 4
    assert c.meeting == (2, 2)
    assert c.gained == [1] and c.lost == [3]
    assert c.misses == {'fraction_error': (1, 0), 'slip_rmse': (0, 1),
                        'volume_error_pct': (2, 1)}
    mean_before, mean_after = c.stats['volume_error_pct']
    assert mean_before[0] == pytest.approx((5 + 12 + 15 + 5) / 4)
    assert mean_after[0] == pytest.approx((5 + 8 + 11 + 5) / 4)


def test_the_printout_names_what_decided_each_run(pair, capsys):
    assert campaign_compare.main([str(pair[0]), str(pair[1])]) == 0
    text = capsys.readouterr().out
    assert 'meeting all targets: 50.0 % (2/4) -> 50.0 % (2/4)' in text
    assert '1 volume_error_pct 12 -> 8' in text
    assert '3 slip_rmse 0.02 -> 0.02' in text


def test_campaigns_of_other_draws_are_refused(tmp_path, pair, capsys):
    other = _folder(tmp_path, 'other', [_run(0, beach_slope_deg=4.9), _run(1)])
    assert campaign_compare.main([str(pair[0]), str(other)]) == 2
    assert 'run 0: drawn beach_slope_deg differ' in capsys.readouterr().err


def test_a_folder_without_runs_is_refused(tmp_path, pair, capsys):
    assert campaign_compare.main([str(pair[0]), str(tmp_path)]) == 2
    assert 'no runs.csv' in capsys.readouterr().err
