"""fit_terrain on bags written here with rosbags from a known soil plus noise."""
import math
from pathlib import Path

import numpy as np
import pytest
from rosbags.rosbag2 import Writer

from dukw_common.config import shared_params
from dukw_common.vehicle import SoilParams, Vehicle, soil_params
from dukw_estimation import fit_terrain
from dukw_model import traction

VEHICLE = Vehicle.load()
BODY = VEHICLE.body
AREA = BODY.track_width_m * BODY.track_contact_length_m
#: the paper's beach fits' upper end (phi 15 deg, k 0.18 m: its 80 % slope fit, config/dukw.yaml)
PAPER_BEACH_MAX = soil_params(shared_params(), 'beach_80')
TRUE = SoilParams(cohesion_pa=150.0, friction_angle_rad=math.radians(9.93), shear_modulus_m=0.053)


def write_bag(path, slips, weights, noise_n=5.0, seed=0):
    """A rosbag2 with Traction messages whose forces follow TRUE (plus Gaussian noise)."""
    rng = np.random.default_rng(seed)
    store = fit_terrain.typestore()
    types = store.types
    Traction = types['dukw_msgs/msg/Traction']
    Header = types['std_msgs/msg/Header']
    Time = types['builtin_interfaces/msg/Time']
    with Writer(path, version=Writer.VERSION_LATEST) as writer:
        conn = writer.add_connection('/traction', fit_terrain.TRACTION_TYPE, typestore=store)
        for n, (slip, weight) in enumerate(zip(slips, weights, strict=True)):
            force = traction.tractive_force_n(slip, weight / 2, TRUE, AREA,
                                              BODY.track_contact_length_m)
            t_ns = 1_000_000_000 + n * 10_000_000
            msg = Traction(
                header=Header(stamp=Time(sec=t_ns // 10**9, nanosec=t_ns % 10**9),
                              frame_id='base_link'),
                port_slip=slip, stbd_slip=slip * 0.9, submerged_volume_m3=0.0,
                effective_weight_n=weight, weight_on_tracks_fraction=weight / 2894.0,
                waterline_distance_m=0.0, submerged_length_m=0.0, slope_rad=0.08,
                port_force_predicted_n=force, stbd_force_predicted_n=force,
                port_force_measured_n=force + rng.normal(0.0, noise_n),
                stbd_force_measured_n=traction.tractive_force_n(
                    slip * 0.9, weight / 2, TRUE, AREA, BODY.track_contact_length_m)
                + rng.normal(0.0, noise_n),
                afloat=False)
            writer.write(conn, t_ns, store.serialize_cdr(msg, fit_terrain.TRACTION_TYPE))
    return path


def test_recovers_a_known_soil_from_a_bag(tmp_path, capsys):
    rng = np.random.default_rng(1)
    slips = rng.uniform(0.01, 0.8, 600)
    weights = rng.uniform(400.0, 2894.0, 600)
    bag = write_bag(tmp_path / 'bag', slips, weights)
    assert fit_terrain.main([str(bag)]) == 0
    out = capsys.readouterr().out
    assert 'cohesion c' in out and 'residual rms' in out and '+-' in out
    fit = fit_terrain.fit_soil(fit_terrain.read_samples(bag), AREA, BODY.track_contact_length_m)
    assert fit.soil.cohesion_pa == pytest.approx(TRUE.cohesion_pa, rel=0.2)
    assert fit.soil.friction_angle_rad == pytest.approx(TRUE.friction_angle_rad, rel=0.05)
    assert fit.soil.shear_modulus_m == pytest.approx(TRUE.shear_modulus_m, rel=0.15)
    assert fit.residual_rms_n == pytest.approx(5.0, rel=0.2)      # the noise put in
    assert all(0.0 < s < math.inf for s in fit.sigma)
    # the true values lie within a few sigma
    assert abs(fit.soil.friction_angle_rad - TRUE.friction_angle_rad) < 4 * fit.sigma[1]


def test_refuses_a_bag_with_flat_slip(tmp_path, capsys):
    n = 300
    bag = write_bag(tmp_path / 'flat', np.full(n, 0.2), np.linspace(500.0, 2894.0, n))
    assert fit_terrain.main([str(bag)]) == 1
    err = capsys.readouterr().err
    assert 'slip hardly varies' in err


def test_refuses_a_bag_whose_weight_never_changes(tmp_path, capsys):
    """Slip varies but the weight does not: A c + W tan(phi) is one number, c and phi are
    not separately determined - refused, not printed as a fit."""
    n = 300
    bag = write_bag(tmp_path / 'dry', np.linspace(0.01, 0.8, n), np.full(n, 2894.0))
    assert fit_terrain.main([str(bag)]) == 1
    err = capsys.readouterr().err
    assert 'do not determine c, phi and k' in err and 'weight on the tracks to vary' in err


def test_recovers_the_simulated_beach_from_a_recorded_surf_run(capsys):
    """The golden sea-to-land bag (simulator on the beach_72 soil, the EKF's traction as
    recorded, scripts/make_golden.sh): c within three of the fit's own sigmas of the truth,
    phi and k above it and inside the paper's fitted ranges. The sand there is saturated:
    its strength also grows with the slip velocity (the shared saturated_sand.* pore
    suction, issue 13), which this rate-independent fit (the paper's) cannot follow, so it
    reads a stronger sand whose shear builds more slowly: phi 14.8 +- 1.5 deg against 9.9
    and k 9.1 +- 1.2 cm against 5.3 (the bag since the simulator's touchdown kinematics,
    issue 18; 14.7 +- 1.8 deg and 9.1 +- 1.3 cm before, both at the 3-sigma edge of the
    test this replaced; before the tracks started in the surf: 9.7 deg, k 2.2 cm below the
    truth, residual 57 N)."""
    bag = Path(__file__).resolve().parents[3] / 'tests' / 'golden' / 'sea_to_land'
    assert fit_terrain.main([str(bag)]) == 0
    assert 'residual rms' in capsys.readouterr().out
    fit = fit_terrain.fit_soil(fit_terrain.read_samples(bag), AREA,
                               BODY.track_contact_length_m, initial=VEHICLE.soil)
    truth = VEHICLE.soil                  # the simulator's wet beach
    assert truth.friction_angle_rad < fit.soil.friction_angle_rad \
        < PAPER_BEACH_MAX.friction_angle_rad
    assert truth.shear_modulus_m < fit.soil.shear_modulus_m < PAPER_BEACH_MAX.shear_modulus_m
    assert abs(fit.soil.cohesion_pa - truth.cohesion_pa) < 3 * fit.sigma[0]
    assert fit.residual_rms_n < 50.0
    # all samples, the stopped tracks' clipped slips and the gripping ones included: off
    everything = fit_terrain.fit_soil(fit_terrain.read_samples(bag), AREA,
                                      BODY.track_contact_length_m, initial=VEHICLE.soil,
                                      slip_range=(0.0, 1.0))
    names = ('cohesion_pa', 'friction_angle_rad', 'shear_modulus_m')
    assert any(abs(getattr(everything.soil, name) - getattr(truth, name)) > 3 * sigma
               for name, sigma in zip(names, everything.sigma, strict=True))


def test_refuses_what_is_not_a_bag(tmp_path, capsys):
    assert fit_terrain.main([str(tmp_path)]) == 1
    assert 'not a rosbag2 folder' in capsys.readouterr().err


def test_afloat_samples_are_not_used():
    samples = fit_terrain.TractionSamples(np.linspace(0, 0.5, 30), np.zeros(30), np.ones(30))
    with pytest.raises(fit_terrain.FitError, match='usable samples'):
        fit_terrain.fit_soil(samples, AREA, BODY.track_contact_length_m)
