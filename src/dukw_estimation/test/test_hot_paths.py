"""The estimator's fast paths (issue 16) give the very bits of the generic forms they replace."""
import math

import numpy as np
import pytest
from filterpy.common import Q_discrete_white_noise
from filterpy.kalman import KalmanFilter

from dukw_common.config import node_params
from dukw_common.vehicle import Vehicle, soil_params
from dukw_model import buoyancy, traction
from dukw_estimation.contact import ContactModel
from dukw_estimation.force_filter import ForceSmoother
from dukw_estimation.settings import EkfSettings

PARAMS = node_params('ekf_node')
SETTINGS = EkfSettings.from_params(PARAMS)
VEHICLE = Vehicle.from_params(PARAMS)


def test_force_smoother_matches_filterpys_kalman_filter_to_rounding():
    smoother = ForceSmoother(200.0, 15.0)
    kf = KalmanFilter(dim_x=2, dim_z=1)
    kf.H = np.array([[1.0, 0.0]])
    kf.R = np.array([[15.0 ** 2]])
    rng = np.random.default_rng(3)
    t_s = 0.0
    for k in range(3000):
        t_s += float(rng.choice([0.05, 0.0, 0.01, 0.0500001]))
        force_n = float(rng.normal(100.0, 50.0))
        smoother.update(t_s, force_n)
        if k == 0:
            kf.x, kf.P, last_s = np.array([[force_n], [0.0]]), np.diag([15.0 ** 2, 1e4]), t_s
            continue
        dt = t_s - last_s
        if dt > 0.0:
            kf.F = np.array([[1.0, dt], [0.0, 1.0]])
            kf.Q = Q_discrete_white_noise(2, dt, 200.0 ** 2)
            kf.predict()
        kf.update(np.array([[force_n]]))
        last_s = t_s
        assert np.allclose(smoother.x, kf.x[:, 0], rtol=1e-12, atol=1e-9), k
        assert np.allclose(smoother.P, kf.P.ravel(), rtol=1e-12, atol=1e-12), k
    assert smoother.force_n == pytest.approx(float(kf.x[0, 0]), rel=1e-12)


def test_contact_volumes_and_weight_are_the_models_bits_dry_or_wet():
    contact = ContactModel(VEHICLE, SETTINGS, soil_params(PARAMS))
    body = VEHICLE.body
    dry = 0
    for slope in (contact.slope_rad, 0.02, 0.1):
        contact.slope_rad = slope
        for waterline in np.linspace(-12.0, 8.0, 81):
            for surface in (-0.4, 0.0, 0.13):
                for heading_cos in (1.0, 0.3, -1.0, 0.0):
                    mine = contact.grounded_volume_m3(waterline, surface, heading_cos)
                    model = buoyancy.grounded_volume_m3(
                        waterline, slope, body.hull_clearance_m, contact.hull_bow_x_m,
                        contact.hull_stern_x_m, body.hull_radius_m, surface, heading_cos,
                        contact.section)
                    assert mine == model and math.copysign(1.0, mine) == math.copysign(1.0, model)
                    dry += mine == 0.0
                    volume = min(model, body.displaced_volume_m3)
                    assert contact.weight_n(mine, False) == traction.effective_weight_n(
                        body.displacement_n, volume, slope, body.water_density_kgpm3,
                        body.gravity_mps2)
    assert dry > 100          # the dry shortcut was taken, and gave the model's 0.0
