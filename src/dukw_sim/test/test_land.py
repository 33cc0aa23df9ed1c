"""Track drives on the soil: the loaded speed loops in series with the Wong force."""
import math

import pytest

from dukw_common.vehicle import SoilParams
from dukw_sim.land import (TrackContact, belt_equivalent_mass_kg, belt_mass_kg, inertial_loop,
                           linearise, predicted_speeds)

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


def test_belt_equivalent_mass_reflects_the_rotor_through_the_reduction():
    """J_rotor (N / r)^2 + m_belt + J_wheels / r^2, r the sprocket's radius."""
    assert belt_equivalent_mass_kg(0.01, 3.0, 0.4, 2.0, 0.08) == pytest.approx(
        0.01 * (3.0 / 0.2) ** 2 + 2.0 + 0.08 / 0.2 ** 2)
    assert belt_equivalent_mass_kg(0.0, 7.0, 0.1727, 0.0, 0.0) == 0.0
    # the belt around two sprockets at the contact's ends: 2 l + pi d
    assert belt_mass_kg(10.0, 0.1, 1.0, 0.2) == pytest.approx(10.0 * 0.1 * (2.0 + 0.2 * math.pi))


@pytest.mark.parametrize('args', [(-1e-4, 7.0, 0.17, 3.0, 0.0), (6e-4, 0.0, 0.17, 3.0, 0.0),
                                  (6e-4, 7.0, 0.0, 3.0, 0.0), (6e-4, 7.0, 0.17, math.nan, 0.0),
                                  (6e-4, 7.0, 0.17, 3.0, -1.0)])
def test_belt_equivalent_mass_rejects_bad_input(args):
    with pytest.raises(ValueError):
        belt_equivalent_mass_kg(*args)


def _belt_after_force_step(mass_kg: float, k: float, force_n: float, dt_s: float,
                           steps: int) -> list[float]:
    """A loaded loop's belt (ref 0, at rest) after a force step, stepped as the simulator
    does: the inertial loop's speed v = ref' - F / k' each step."""
    speeds, v = [], 0.0
    for _ in range(steps):
        k_eff, ref_eff = inertial_loop(k, 0.0, v, mass_kg / dt_s)
        v = ref_eff - force_n / k_eff
        speeds.append(v)
    return speeds


def test_a_loaded_belt_relaxes_with_the_time_constant_m_eq_times_droop():
    """The belt's speed after a force step F approaches -F/k as 1 - exp(-t / tau), tau =
    m_eq / k = m_eq x droop (to the implicit step's first order in dt / tau)."""
    mass_kg, k, force_n, dt_s = 8.1, 1000.0, 250.0, 1e-5
    tau_s = mass_kg / k
    speeds = _belt_after_force_step(mass_kg, k, force_n, dt_s, int(round(3.0 * tau_s / dt_s)))
    final = -force_n / k
    for t_s in (0.5 * tau_s, tau_s, 2.0 * tau_s):
        n = int(round(t_s / dt_s))
        assert speeds[n - 1] == pytest.approx(final * (1.0 - math.exp(-t_s / tau_s)),
                                              rel=2e-3)


def test_a_loaded_belt_does_not_jump_to_its_loaded_speed_in_one_step():
    """At the simulator's 10 ms step the first step covers dt / (tau + dt) of the way (the
    implicit step); without inertia all of it."""
    mass_kg, k, force_n, dt_s = 8.1, 1000.0, 250.0, 0.01
    first = _belt_after_force_step(mass_kg, k, force_n, dt_s, 1)[0]
    tau_s = mass_kg / k
    assert first == pytest.approx(-force_n / k * dt_s / (tau_s + dt_s))
    assert abs(first) < 0.6 * force_n / k
    assert _belt_after_force_step(0.0, k, force_n, dt_s, 1)[0] == pytest.approx(-force_n / k)


def test_a_held_loop_or_no_inertia_leaves_the_loop_as_it_is():
    assert inertial_loop(math.inf, 0.3, 0.1, 810.0) == (math.inf, 0.3)
    assert inertial_loop(1000.0, 0.3, 0.1, 0.0) == (1000.0, 0.3)
    k, ref = inertial_loop(1000.0, 0.3, 0.1, 810.0)
    assert k == pytest.approx(1810.0) and ref == pytest.approx((300.0 + 81.0) / 1810.0)
