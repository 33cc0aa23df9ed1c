"""Track drives on the soil: the loaded speed loops in series with the Wong force."""
import math

import pytest

from dukw_common.vehicle import SoilParams
from dukw_sim.land import TrackContact, linearise, predicted_speeds

DRY_SAND = SoilParams(1040.0, 0.4887, 0.01)


def contact():
    return TrackContact(1447.0, DRY_SAND, 0.0826 * 1.07, 1.07)


def test_held_loops_run_at_their_references():
    lin = linearise(contact(), (1.0, 1.2), (0.98, 1.15))
    assert lin.speed_mps == [1.0, 1.2]
    assert lin.force_n[0] > 0.0 and lin.dforce_dground[0] < 0.0


@pytest.mark.parametrize('ground', [(0.9, 1.3), (1.0, 1.0), (0.5, 1.6)])
def test_loaded_loops_balance_the_soil_and_give_under_load(ground):
    """v = ref - (F + o) / k at the solution; the series derivative is about k at most
    (a little more from the slip's denominator)."""
    k, others = 700.0, (8.0, 24.0)
    lin = linearise(contact(), (1.0, 1.2), ground, others, (k, k))
    for i in range(2):
        motor = lin.force_n[i] + others[i]
        assert lin.speed_mps[i] == pytest.approx((1.0, 1.2)[i] - motor / k, abs=1e-4)
        assert -1.2 * k <= lin.dforce_dground[i] <= 0.0
    assert abs(lin.force_n[0] + lin.force_n[1]) < 2.0 * 900.0


def test_a_held_track_beside_a_loaded_one():
    lin = linearise(contact(), (0.0, 1.0), (0.0, 0.9), (0.0, 8.0), (math.inf, 700.0))
    assert lin.speed_mps[0] == 0.0 and lin.speed_mps[1] < 1.0


def test_predicted_speeds_start_near_the_next_solution():
    """The first-order prediction at new ground speeds is far nearer the solution there than
    the old speeds (the soft track), and a held track keeps its reference."""
    k, others, ref = (700.0, math.inf), (8.0, 24.0), (1.0, 1.2)
    before, after = (0.9, 1.15), (0.92, 1.16)
    lin = linearise(contact(), ref, before, others, k)
    guess = predicted_speeds(lin, k, before, after)
    want = linearise(contact(), ref, after, others, k).speed_mps
    assert abs(guess[0] - want[0]) < 0.05 * abs(lin.speed_mps[0] - want[0])
    assert guess[1] == 1.2
