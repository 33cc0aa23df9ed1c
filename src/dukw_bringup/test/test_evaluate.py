"""Accuracy on simulator runs (issue 5): the evaluate tool's scenarios, offline, scored."""
import json

import pytest

from dukw_bringup import evaluate

DURATION_S = 20.0      # shorter than the tool's 30 s default: every transition is complete by then
TOOL_DURATION_S = 30.0  # the evaluate tool's default run, over which its targets are stated
MOTION = ('position_rmse_m', 'heading_rmse_deg', 'slip_rmse')
SUBMERSION = ('volume_error_pct', 'fraction_error')
ROUGH_SEA = [s for s in evaluate.scenarios() if s.wave_height_m > 0.2]


def _assert_targets_met(result):
    for key in MOTION + SUBMERSION:
        assert result[key] <= evaluate.TARGETS[key], (key, result)
    assert sum(result['rejected'].values()) <= 20, result       # a clean run, few outliers
    assert result['targets_met'], result


@pytest.mark.slow
@pytest.mark.parametrize('scenario', evaluate.scenarios(), ids=lambda s: s.name)
def test_scenario_meets_the_accuracy_targets(scenario):
    _assert_targets_met(evaluate.run_scenario(scenario, DURATION_S, seed=0))


@pytest.mark.slow
@pytest.mark.parametrize('seed', [1, 2])
@pytest.mark.parametrize('scenario', ROUGH_SEA, ids=lambda s: s.name)
def test_rough_sea_targets_hold_for_other_sea_states(scenario, seed):
    """The 28 cm runs are the hardest (the wave at the hulls is seen through two wet/dry
    sensors and the track forces): other wave trains and sensor noise meet the targets too,
    over the tool's own 30 s runs. (On the short-crested sea, 20 s of land_to_sea_64pct
    seed 1 gives 10.2 %: the surface estimate runs ~0.1 m^3 high for about a second as the
    first crests reach the sensors at x 3-5 m; see the issue 13 note.)"""
    _assert_targets_met(evaluate.run_scenario(scenario, TOOL_DURATION_S, seed=seed))


@pytest.mark.slow
@pytest.mark.parametrize('scenario', ROUGH_SEA, ids=lambda s: s.name)
def test_with_the_true_surface_the_rough_sea_targets_are_met(scenario):
    """With the true waterline distance and wave at base_link handed over, what is left of
    the submersion error is the model's and the float/ground logic's: within the targets."""
    oracle = evaluate.run_scenario(scenario, DURATION_S, seed=0, oracle_surface=True)
    assert oracle['oracle'] == 'surface'
    for key in SUBMERSION:
        assert oracle[key] <= evaluate.TARGETS[key], (key, oracle)


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
