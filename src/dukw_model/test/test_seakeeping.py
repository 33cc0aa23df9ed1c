"""Heave, roll and pitch constants from the vehicle's facts (dukw_model.seakeeping)."""
import math

import pytest

from dukw_common.config import shared_params
from dukw_common.vehicle import Vehicle
from dukw_model.buoyancy import HullSection
from dukw_model.seakeeping import heave_constants, heave_waterplane_m2, oscillator_constants

PARAMS = shared_params()
BODY = Vehicle.load().body


@pytest.mark.parametrize('stiffness,hz,zeta', [(9830.0, 0.5731, 0.1), (500.0, 0.39, 0.098),
                                               (1.0, 2.0, 0.0)])
def test_oscillator_rings_at_its_frequency_with_its_damping(stiffness, hz, zeta):
    inertia, damping = oscillator_constants(stiffness, hz, zeta)
    assert math.sqrt(stiffness / inertia) / (2 * math.pi) == pytest.approx(hz)
    assert damping / (2 * math.sqrt(stiffness * inertia)) == pytest.approx(zeta)


def test_heave_constants_from_the_shared_facts():
    hz, zeta = PARAMS['seakeeping.heave_natural_hz'], PARAMS['seakeeping.heave_damping_ratio']
    heave = heave_constants(BODY, hz, zeta)
    area = heave_waterplane_m2(HullSection.of_body(BODY), BODY.hull_length_m)
    rho_g = BODY.water_density_kgpm3 * BODY.gravity_mps2
    assert heave.stiffness_n_per_m == pytest.approx(rho_g * area)
    assert math.sqrt(heave.stiffness_n_per_m / heave.mass_kg) / (2 * math.pi) == pytest.approx(hz)
    # the measured frequency needs added mass on top of the vehicle's own
    assert heave.mass_kg > BODY.mass_kg


@pytest.mark.parametrize('args', [(0.0, 0.5, 0.1), (100.0, 0.0, 0.1), (100.0, 0.5, -0.1)])
def test_bad_oscillator_facts_are_refused(args):
    with pytest.raises(ValueError):
        oscillator_constants(*args)
