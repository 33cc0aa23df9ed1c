"""The site's soil learnt online (soil_online.py): converges, stays put without slip, bounded."""
from __future__ import annotations

import math

import numpy as np
import pytest

from dukw_common.config import node_params
from dukw_common.vehicle import SoilParams, Vehicle, soil_params
from dukw_model import traction
from dukw_estimation.estimator import online_soil_settings
from dukw_estimation.settings import EkfSettings
from dukw_estimation.soil_online import OnlineSoil

PARAMS = node_params('ekf_node')
SETTINGS = online_soil_settings(EkfSettings.from_params(PARAMS))
BODY = Vehicle.from_params(PARAMS).body
AREA_M2 = BODY.track_width_m * BODY.track_contact_length_m
LENGTH_M = BODY.track_contact_length_m
WEIGHT_N = 0.5 * BODY.displacement_n * math.cos(math.radians(4.5))
PRIOR = soil_params(PARAMS)                         # the configured 72 % fit


def force(soil: SoilParams, slip: float) -> float:
    return float(traction.tractive_force_n(slip, WEIGHT_N, soil, AREA_M2, LENGTH_M))


def feed(online: OnlineSoil, soil: SoilParams, slips, noise_n: float = 0.0,
         seed: int = 0) -> int:
    rng = np.random.default_rng(seed)
    used = 0
    for n, slip in enumerate(slips):
        measured = force(soil, slip) + noise_n * rng.standard_normal()
        used += online.update(0.1 * n, slip, 0.01, WEIGHT_N, measured, AREA_M2, LENGTH_M)
    return used


def test_slips_across_the_curve_identify_phi_and_k_of_the_site():
    online = OnlineSoil(PRIOR, SETTINGS)
    site = SoilParams(PRIOR.cohesion_pa, math.radians(14.0), 0.15)
    slips = np.tile(np.linspace(0.06, 0.5, 12), 20)
    assert feed(online, site, slips, noise_n=10.0) == slips.size
    assert math.degrees(online.soil.friction_angle_rad) == pytest.approx(14.0, abs=1.0)
    assert online.soil.shear_modulus_m == pytest.approx(0.15, abs=0.02)
    assert online.soil.cohesion_pa == PRIOR.cohesion_pa       # held at the prior
    assert max(online.sigma()) < max(SETTINGS.phi_sigma_rad, SETTINGS.k_sigma_m)


def test_one_slip_learns_the_force_there_although_not_phi_and_k_apart():
    online = OnlineSoil(PRIOR, SETTINGS)
    site = SoilParams(PRIOR.cohesion_pa, math.radians(6.0), 0.12)
    feed(online, site, [-0.11] * 60, noise_n=15.0)
    before = abs(force(PRIOR, -0.11) - force(site, -0.11))
    after = abs(force(online.soil, -0.11) - force(site, -0.11))
    assert before > 40.0
    assert after < 0.2 * before


def test_without_slip_the_prior_stays():
    online = OnlineSoil(PRIOR, SETTINGS)
    site = SoilParams(PRIOR.cohesion_pa, math.radians(15.0), 0.0)
    gripping = [0.0, 0.01, -0.02, 0.5 * SETTINGS.min_slip, -0.9 * SETTINGS.min_slip]
    assert feed(online, site, gripping) == 0
    assert online.soil == PRIOR
    assert not online.update(1.0, 0.2, 0.01, WEIGHT_N, math.nan, AREA_M2, LENGTH_M)
    assert not online.update(1.0, 0.2, 0.01, 0.0, 100.0, AREA_M2, LENGTH_M)   # no weight
    # a start from rest: the force against a slip not yet converged, or the slip unsure
    assert not online.update(1.0, -0.15, 0.01, WEIGHT_N, 200.0, AREA_M2, LENGTH_M)
    assert not online.update(1.0, 0.2, 2 * SETTINGS.max_slip_sigma, WEIGHT_N, 60.0, AREA_M2,
                             LENGTH_M)
    assert online.soil == PRIOR and online.updates == 0


def test_the_estimate_stays_inside_the_papers_fitted_ranges():
    strong = SoilParams(1040.0, math.radians(28.0), 0.01)      # Wong's dry sand
    online = OnlineSoil(PRIOR, SETTINGS)
    feed(online, strong, np.tile(np.linspace(0.06, 0.6, 10), 10))
    assert online.soil.friction_angle_rad == pytest.approx(SETTINGS.phi_max_rad)
    assert SETTINGS.k_min_m <= online.soil.shear_modulus_m <= SETTINGS.k_max_m
    online.reset(PRIOR)
    feed(online, SoilParams(0.0, 0.01, 0.5), np.tile(np.linspace(0.06, 0.6, 10), 10))
    assert online.soil.friction_angle_rad == pytest.approx(SETTINGS.phi_min_rad)
    assert SETTINGS.k_min_m <= online.soil.shear_modulus_m <= SETTINGS.k_max_m


def test_only_a_slipping_track_driving_straight_fast_enough_is_informative():
    online = OnlineSoil(PRIOR, SETTINGS)
    assert online.informative(0.2, 0.8, 0.8)
    assert online.informative(-0.1, 0.8, 0.75)
    assert not online.informative(0.2, 0.8, 0.4)          # a skid-steer turn
    assert not online.informative(0.2, 0.1, 0.1)          # nearly stopped
    assert not online.informative(0.01, 0.8, 0.8)         # gripping
    assert not online.informative(math.nan, 0.8, 0.8)
