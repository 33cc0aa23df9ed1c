"""Accuracy on simulator runs (issue 5): the evaluate tool's scenarios, offline, scored."""
import json

import pytest

from dukw_estimation import evaluate

DURATION_S = 20.0      # shorter than the tool's 30 s default: every transition is complete by then
MOTION = ('position_rmse_m', 'heading_rmse_deg', 'slip_rmse')
SUBMERSION = ('volume_error_pct', 'fraction_error')
#: Known gap (see the README): in the 28 cm sea the instantaneous wave at the hull while the
#: tracks touch is only seen through the two wet/dry sensors, and the volume error can exceed
#: 10 % of the displacement volume. Checked, and reported as xfail when it does.
ROUGH_SEA = {s.name for s in evaluate.scenarios() if s.wave_height_m > 0.2}
#: What the estimator achieves there today (the four 20 s runs at seed 0: 9.9-12.5 %,
#: 0.092-0.122; seeds 1 and 2 do better, mean over seeds 0-2 8.9 %): a run beyond these
#: has regressed and fails outright, the target gap alone is the xfail.
ROUGH_SEA_BOUNDS = {'volume_error_pct': 15.0, 'fraction_error': 0.15}


@pytest.mark.slow
@pytest.mark.parametrize('scenario', evaluate.scenarios(), ids=lambda s: s.name)
def test_scenario_meets_the_accuracy_targets(scenario):
    result = evaluate.run_scenario(scenario, DURATION_S, seed=0)
    for key in MOTION:
        assert result[key] <= evaluate.TARGETS[key], (key, result)
    assert sum(result['rejected'].values()) <= 20, result       # a clean run, few outliers
    missed = {k: result[k] for k in SUBMERSION if result[k] > evaluate.TARGETS[k]}
    if missed and scenario.name in ROUGH_SEA:
        worse = {k: v for k, v in missed.items() if v > ROUGH_SEA_BOUNDS[k]}
        assert not worse, f'28 cm sea: worse than the known gap: {worse}'
        pytest.xfail(f'known gap in the 28 cm sea: {missed}')
    assert not missed, result


@pytest.mark.slow
@pytest.mark.parametrize('scenario', sorted(ROUGH_SEA))
def test_with_the_true_surface_the_rough_sea_targets_are_met(scenario):
    """The 28 cm gap is the surface estimate's: given the true waterline distance and wave at
    base_link, the submersion model and the float/ground logic meet the targets."""
    chosen = next(s for s in evaluate.scenarios() if s.name == scenario)
    result = evaluate.run_scenario(chosen, DURATION_S, seed=0, oracle_surface=True)
    assert result['oracle'] == 'surface'
    for key in SUBMERSION:
        assert result[key] <= evaluate.TARGETS[key], (key, result)


def test_cli_prints_one_json_object_per_scenario(capsys):
    code = evaluate.main(['--scenario', 'land_circle', '--duration', '4'])
    lines = capsys.readouterr().out.strip().splitlines()
    assert len(lines) == 1
    result = json.loads(lines[0])
    assert result['scenario'] == 'land_circle'
    assert set(evaluate.TARGETS) <= set(result)
    assert code == (0 if result['targets_met'] else 1)


def test_cli_refuses_a_run_shorter_than_the_warm_up():
    with pytest.raises(SystemExit):
        evaluate.main(['--duration', '1'])
