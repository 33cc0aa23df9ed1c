"""The sensor models: rates, noise as configured, geometry, validity, motor-controller faults."""
import math
from dataclasses import FrozenInstanceError, fields, replace

import numpy as np
import pytest

from dukw_common.config import ConfigError, node_params
from dukw_common.geometry import local_enu_from_geodetic
from dukw_common.readings import (DepthReading, DriveStatus, GpsFix, GpsVelocity, ImuSample,
                                  MotorSide, WaterContact)
from dukw_sim.sensors import (Fault, GaussMarkov, Schedule, SensorConfig, SensorModel,
                              positional_builder)
from dukw_sim.truth import Truth

PARAMS = node_params('sim_node')
QUIET = {k: 0.0 for k in PARAMS if k.startswith('noise.') and '_std' in k}


def model(seed=0, **overrides):
    return SensorModel(SensorConfig.from_params({**PARAMS, **overrides}), seed)


def quiet_model(**overrides):
    return model(0, **QUIET, **overrides)


def run(sensor_model, truth, seconds, dt=0.01):
    readings = []
    for k in range(int(round(seconds / dt))):
        readings.extend(sensor_model.sample(replace(truth, t_s=k * dt)))
    return readings


def of(kind, readings, drive=None):
    return [r for r in readings if isinstance(r, kind) and (drive is None or r.drive == drive)]


def test_quiet_config_really_is_quiet():
    assert len(QUIET) == 15   # every noise.* but the two correlation times
    assert 'noise.gyro_bias_std_rps' in QUIET and 'noise.gps_horizontal_std_m' in QUIET


def test_each_device_at_its_configured_rate():
    readings = run(model(), Truth(), 10.0)
    counts = {kind.__name__: len(of(kind, readings)) for kind in (
        ImuSample, GpsFix, GpsVelocity, WaterContact, DepthReading)}
    assert counts == {'ImuSample': 1000, 'GpsFix': 100, 'GpsVelocity': 100,
                      'WaterContact': 200, 'DepthReading': 50}
    assert len(of(DriveStatus, readings, 'tracks')) == 200
    assert len(of(DriveStatus, readings, 'props')) == 200


def test_rates_come_from_config():
    readings = run(model(**{'rates.imu_hz': 50.0, 'rates.depth_hz': 1.0}), Truth(), 4.0)
    assert len(of(ImuSample, readings)) == 200
    assert len(of(DepthReading, readings)) == 4


def test_same_seed_same_readings_and_another_seed_differs():
    truth = Truth(surge_mps=1.0, port_current_a=20.0)
    assert run(model(3), truth, 1.0) == run(model(3), truth, 1.0)
    assert run(model(3), truth, 1.0) != run(model(4), truth, 1.0)


def test_reset_replays_the_same_noise():
    m = model(5)
    first = run(m, Truth(), 0.5)
    m.reset()
    assert run(m, Truth(), 0.5) == first


def test_one_devices_rate_does_not_change_anothers_noise():
    imu_a = of(ImuSample, run(model(1), Truth(), 1.0))
    imu_b = of(ImuSample, run(model(1, **{'rates.gps_hz': 1.0}), Truth(), 1.0))
    assert imu_a == imu_b


def test_imu_noise_matches_table_iii_and_the_gyro_bias_is_constant():
    m = model(11)
    imu = of(ImuSample, run(m, Truth(), 60.0))
    acc = np.array([(r.accel_x_mps2, r.accel_y_mps2, r.accel_z_mps2) for r in imu])
    gyro = np.array([(r.roll_rate_rps, r.pitch_rate_rps, r.yaw_rate_rps) for r in imu])
    np.testing.assert_allclose(acc.std(axis=0), [0.010, 0.009, 0.009], rtol=0.1)
    np.testing.assert_allclose(acc.mean(axis=0), [0.0, 0.0, 9.81], atol=0.002)
    np.testing.assert_allclose(gyro.std(axis=0), math.radians(0.172), rtol=0.1)
    np.testing.assert_allclose(gyro.mean(axis=0), m.gyro_bias_rps, atol=3e-4)
    assert any(abs(b) > 1e-5 for b in m.gyro_bias_rps)
    assert imu[0].accel_var_m2ps4 == pytest.approx((1e-4, 8.1e-5, 8.1e-5))


def test_imu_orientation_is_enu_with_compass_heading_error_as_configured():
    truth = Truth(roll_rad=0.1, pitch_rad=-0.05, yaw_rad=2.0)
    imu = of(ImuSample, run(model(2), truth, 120.0))
    angles = np.array([(r.roll_rad, r.pitch_rad, r.yaw_rad) for r in imu])
    np.testing.assert_allclose(angles.mean(axis=0), [0.1, -0.05, 2.0], atol=0.01)
    yaw_err = angles[:, 2] - 2.0
    assert 0.003 < yaw_err.std() < 0.02          # 0.5 deg configured, correlated over 10 s
    # correlated error: neighbouring samples are nearly equal
    assert np.abs(np.diff(yaw_err)).max() < 0.002
    quiet = of(ImuSample, run(quiet_model(), truth, 0.05))
    q = quiet[0]
    assert (q.roll_rad, q.pitch_rad, q.yaw_rad) == pytest.approx((0.1, -0.05, 2.0))


def test_imu_above_base_link_feels_lever_arm_accelerations():
    h = PARAMS['sensors.imu_z_m']
    m = quiet_model()
    # roll rate rising at 1 rad/s^2: tangential -alpha h on y; yaw rate 1 rad/s with roll rate
    # 0.5 rad/s: centripetal w_z w_x h on x
    readings = [m.imu(Truth(t_s=k * 0.01, roll_rate_rps=0.5 + k * 0.01, yaw_rate_rps=1.0))
                for k in range(3)]
    r = readings[2]
    fx, fy, fz = r.accel_x_mps2, r.accel_y_mps2, r.accel_z_mps2
    assert fy == pytest.approx(-1.0 * h, rel=1e-6)
    assert fx == pytest.approx(1.0 * 0.52 * h, rel=1e-6)
    assert fz == pytest.approx(9.81 - 0.52 ** 2 * h, rel=1e-6)


def gps_enu(fix):
    p = PARAMS
    return local_enu_from_geodetic(fix.latitude_deg, fix.longitude_deg, fix.altitude_m,
                                   p['datum.latitude_deg'], p['datum.longitude_deg'],
                                   p['datum.altitude_m'])


def test_gps_fix_is_the_antenna_from_the_datum():
    h = PARAMS['sensors.gps_antenna_z_m']
    m = quiet_model()
    fix = m.gps_fix(Truth(x_m=100.0, y_m=-20.0, z_m=0.3))
    assert gps_enu(fix) == pytest.approx((100.0, -20.0, 0.3 + h), abs=1e-6)
    assert fix.longitude_deg > PARAMS['datum.longitude_deg']   # x is east
    # pitch nose down (REP 103 positive) moves the antenna forward; roll to starboard... left
    fix = m.gps_fix(Truth(pitch_rad=0.1, yaw_rad=math.pi / 2))
    assert gps_enu(fix)[:2] == pytest.approx((0.0, h * math.sin(0.1)), abs=1e-6)
    fix = m.gps_fix(Truth(roll_rad=0.1))
    assert gps_enu(fix)[:2] == pytest.approx((0.0, -h * math.sin(0.1)), abs=1e-6)


def test_gps_error_and_its_reported_covariance_agree():
    fixes = of(GpsFix, run(model(8, **{'noise.gps_tau_s': 0.0}), Truth(), 60.0))
    enu = np.array([gps_enu(f) for f in fixes])
    std = PARAMS['noise.gps_horizontal_std_m']
    np.testing.assert_allclose(enu[:, :2].std(axis=0), std, rtol=0.15)
    assert fixes[0].horizontal_var_m2 == pytest.approx(std ** 2)
    assert fixes[0].vertical_var_m2 == pytest.approx(PARAMS['noise.gps_vertical_std_m'] ** 2)


def test_gps_velocity_is_enu():
    m = quiet_model()
    vel = m.gps_velocity(Truth(yaw_rad=math.pi / 2, surge_mps=1.2, sway_mps=0.1, heave_mps=0.2))
    assert (vel.east_mps, vel.north_mps, vel.up_mps) == pytest.approx((-0.1, 1.2, 0.2), abs=1e-9)


@pytest.mark.parametrize('depth_m,wet,level', [(0.05, True, 1.0), (-0.05, False, 0.0),
                                               (0.0, True, 0.5), (0.0015, True, 0.75)])
def test_water_contact_wet_only_under_the_surface(depth_m, wet, level):
    reading = quiet_model().water(Truth(fore_sensor_depth_m=depth_m, aft_sensor_depth_m=-1.0))
    assert (reading.fore_wet, reading.fore_level) == (wet, pytest.approx(level))
    assert (reading.aft_wet, reading.aft_level) == (False, 0.0)


def test_water_contact_is_debounced_after_the_first_sample():
    m = quiet_model(**{'water_contact.debounce_samples': 3})
    flags = [m.water(Truth(fore_sensor_depth_m=d)).fore_wet
             for d in (-0.1, 0.1, 0.1, -0.1, 0.1, 0.1, 0.1, 0.1)]
    assert flags == [False, False, False, False, False, False, True, True]
    assert quiet_model().water(Truth(fore_sensor_depth_m=0.1)).fore_wet   # starts wet afloat


def test_depth_sounder_valid_only_deeper_than_its_minimum():
    m = quiet_model()
    deep = m.depth(Truth(sounder_depth_m=1.2, water_depth_m=1.45))
    assert deep.valid and deep.depth_m == pytest.approx(1.2)
    for truth in (Truth(sounder_depth_m=0.2, water_depth_m=0.45),   # shallower than 0.5 m
                  Truth(sounder_depth_m=-0.1, water_depth_m=0.9),   # transducer out of water
                  Truth(sounder_depth_m=-0.3, water_depth_m=-0.2)):  # dry sand
        reading = m.depth(truth)
        assert not reading.valid and math.isnan(reading.depth_m)


def test_tracks_report_force_as_current_times_gain_and_battery_sag():
    m = quiet_model()
    r = m.tracks(Truth(port_cmd_pct=60.0, stbd_cmd_pct=56.0, port_current_a=30.0,
                       stbd_current_a=20.0, port_track_speed_mps=1.2, stbd_track_speed_mps=1.1))
    gain = PARAMS['drivetrain.track_force_gain_n_per_a']
    assert (r.drive, r.connected) == ('tracks', True)
    assert (r.port.command_pct, r.stbd.command_pct) == (60.0, 56.0)
    assert r.port.force_n == pytest.approx(30.0 * gain)
    assert r.stbd.speed_mps == pytest.approx(1.1)
    assert r.port.voltage_v == 24.0            # the pack's voltage is the core's (Truth)
    assert r.port.fault_flags == Fault(0)


def test_props_have_no_encoder_and_estimate_thrust_from_the_command():
    r = quiet_model().props(Truth(port_prop_cmd_pct=50.0, stbd_prop_cmd_pct=-50.0,
                                  port_prop_current_a=10.0))
    max_n = PARAMS['drivetrain.max_prop_thrust_n']
    ratio = PARAMS['drivetrain.prop_reverse_thrust_ratio']
    assert r.drive == 'props' and r.port.speed_mps == 0.0 and r.port.current_a == 10.0
    assert r.port.force_n == pytest.approx(0.5 * max_n)
    assert r.stbd.force_n == pytest.approx(-0.5 * max_n * ratio)
    assert r.port.voltage_v < PARAMS['battery.props_open_circuit_v']


def test_stall_fault_after_the_stall_time_with_the_belt_stopped():
    m = quiet_model()
    stalled = Truth(port_cmd_pct=100.0, port_current_a=60.0, port_track_speed_mps=0.0,
                    stbd_cmd_pct=100.0, stbd_current_a=60.0, stbd_track_speed_mps=1.0)
    tracks = of(DriveStatus, run(m, stalled, 3.0), 'tracks')
    stall_time = PARAMS['motors.stall_time_s']
    flagged = [r.t_s for r in tracks if r.port.fault_flags & Fault.STALL]
    assert flagged and flagged[0] == pytest.approx(stall_time, abs=0.06)
    assert not any(r.stbd.fault_flags & Fault.STALL for r in tracks)   # the belt turns


def test_overheat_and_undervoltage_faults():
    hot = quiet_model(**{'motors.thermal_tau_s': 1.0})
    tracks = of(DriveStatus, run(hot, Truth(port_current_a=70.0), 6.0), 'tracks')
    assert tracks[0].port.temperature_c == pytest.approx(PARAMS['motors.ambient_temp_c'])
    assert tracks[-1].port.temperature_c > PARAMS['motors.overheat_c']
    assert tracks[-1].port.fault_flags & Fault.OVERHEAT
    assert not tracks[-1].stbd.fault_flags & Fault.OVERHEAT
    sagging = quiet_model().tracks(Truth(port_current_a=40.0, battery_voltage_v=19.5))
    assert sagging.port.fault_flags & Fault.UNDERVOLTAGE
    weak = quiet_model(**{'battery.props_open_circuit_v': 10.5})
    assert weak.props(Truth(port_prop_current_a=30.0)).port.fault_flags & Fault.UNDERVOLTAGE


@pytest.mark.parametrize('name,value', [('noise.gyro_std_rps', -1.0), ('rates.imu_hz', 0.0),
                                        ('water_contact.debounce_samples', 0),
                                        ('battery.props_internal_resistance_ohm', float('nan'))])
def test_bad_config_is_refused_naming_the_parameter(name, value):
    with pytest.raises(ConfigError, match=name.split('.')[0]):
        SensorConfig.from_params({**PARAMS, name: value})


def test_missing_parameter_is_named():
    params = {k: v for k, v in PARAMS.items() if k != 'datum.latitude_deg'}
    with pytest.raises(ConfigError, match='datum.latitude_deg'):
        SensorConfig.from_params(params)


def test_schedule_keeps_its_rate_without_drift_or_bursts():
    schedule = Schedule({'a': 20.0, 'b': 3.0})
    due = [schedule.due(k * 0.01) for k in range(1000)]
    assert sum('a' in d for d in due) == 200
    assert sum('b' in d for d in due) == 30      # 3 Hz over 10 s, no drift on a 0.01 s grid
    late = Schedule({'a': 10.0})
    assert late.due(0.0) == ['a'] and late.due(5.0) == ['a'] and late.due(5.05) == []
    with pytest.raises(ValueError):
        Schedule({'a': 0.0})


def test_gauss_markov_is_stationary_with_the_given_std():
    rng = np.random.default_rng(0)
    gm = GaussMarkov(2.0, 1.0, rng.standard_normal())
    values = [gm.step(0.1, d) for d in rng.standard_normal(100_000)]
    assert np.std(values) == pytest.approx(2.0, rel=0.05)
    white = GaussMarkov(2.0, 0.0, 0.0)
    assert white.step(0.1, 1.5) == 3.0


@pytest.mark.parametrize('cls, values', [
    (ImuSample, tuple(0.1 * k for k in range(16)) + ((1.0, 2.0, 3.0),)),
    (MotorSide, (40.0, 12.5, 0.8, 900.0, 24.1, 31.0, 5, ('OVERHEAT', 'STALL')))])
def test_positional_builder_gives_the_reading_its_init_gives(cls, values):
    """The sensor models' cheap constructor: an ordinary frozen reading, equal to __init__'s."""
    built = positional_builder(cls)(*values)
    want = cls(*values)
    assert type(built) is cls and built == want and hash(built) == hash(want)
    assert repr(built) == repr(want)
    with pytest.raises(FrozenInstanceError):
        setattr(built, fields(cls)[0].name, 1.0)
    with pytest.raises(TypeError):
        positional_builder(cls)(*values[:-1])          # every field, positionally
    with pytest.raises(TypeError):
        positional_builder(SensorConfig)               # frozen but not slotted: refused
