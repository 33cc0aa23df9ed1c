"""Sensor readings -> ROS messages (the simulator's writer) -> readings (ekf_node's reader).

The two directions must be each other's inverse, so that the estimator sees the same
reading whether it is fed in-process (evaluate, the stack harness) or over ROS (ekf_node,
golden bags): values as precise as the message types carry them.
"""
import dataclasses
import math

import numpy as np
import pytest
from rclpy.serialization import deserialize_message, serialize_message

from dukw_common.node_tools import stamp_to_s
from dukw_common.readings import (DepthReading, DriveStatus, GpsFix, GpsVelocity, ImuSample,
                                  MotorSide, WaterContact)
from dukw_estimation import ros_convert
from dukw_sim.sim_messages import Frames, SimMessages

FRAMES = Frames('base_link', 'imu_link', 'gps_link')
READERS = {ImuSample: ros_convert.imu_sample, GpsFix: ros_convert.gps_fix,
           GpsVelocity: ros_convert.gps_velocity, WaterContact: ros_convert.water_contact,
           DepthReading: ros_convert.depth, DriveStatus: ros_convert.drive_status}
NAN = math.nan


def round_trip(reading):
    """reading -> message -> CDR bytes -> message -> reading, as over DDS."""
    _, msg = SimMessages(FRAMES).reading(reading)
    msg = deserialize_message(serialize_message(msg), type(msg))
    return READERS[type(reading)](msg, stamp_to_s(msg.header.stamp))


def assert_same(got, want, path='reading'):
    """Field by field: NaN matches NaN, floats to 1e-12 (float32 fields pre-rounded)."""
    if dataclasses.is_dataclass(want):
        assert type(got) is type(want), path
        for f in dataclasses.fields(want):
            assert_same(getattr(got, f.name), getattr(want, f.name), f'{path}.{f.name}')
    elif isinstance(want, tuple):
        assert len(got) == len(want), path
        for i, (g, w) in enumerate(zip(got, want, strict=True)):
            assert_same(g, w, f'{path}[{i}]')
    elif isinstance(want, float):
        assert (math.isnan(got) and math.isnan(want)) or got == pytest.approx(
            want, rel=1e-12, abs=1e-12), f'{path}: {got!r} != {want!r}'
    else:
        assert got == want, f'{path}: {got!r} != {want!r}'


def f32(value: float) -> float:
    return float(np.float32(value))


SIDE = MotorSide(60.0, 30.5, 1.1, 2489.6, 24.1, 41.0, 257, ('overheat', 'stall'))
CASES = [
    ImuSample(1.25, 0.1, -0.05, 2.0, 0.01, -0.02, 0.3, 0.2, -0.1, 9.79, 7.6e-5, 9e-6, 1e-5,
              1.1e-5, 8e-6, 8.5e-6, (1e-4, 8.1e-5, 8.2e-5)),
    ImuSample(1.26, NAN, NAN, NAN, 0.01, -0.02, 0.3, NAN, NAN, NAN),   # rates only
    ImuSample(1.27, 0.0, 0.0, -3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 9.81),  # variances unknown
    GpsFix(2.0, 36.18, -75.75, 1.2, 0.09, True, 0.36),
    GpsFix(2.1, NAN, NAN, NAN, NAN, False, NAN),                      # no fix
    GpsFix(2.2, 36.18, -75.75, 1.2),                                  # covariance unknown
    GpsVelocity(2.0, 1.0, -0.5, 0.0025, 0.1, 0.0036),
    GpsVelocity(2.1, 1.0, -0.5),                                      # no vertical, no var
    WaterContact(3.0, True, False, f32(0.9), f32(0.1)),
    WaterContact(3.1, False, True),
    DepthReading(4.0, True, 2.4, -0.25, 17.5),
    DepthReading(4.1, False, NAN),
    DriveStatus(5.0, SIDE, MotorSide(-20.0, -5.0, -0.4, -408.0), True, 'tracks'),
    DriveStatus(5.1, SIDE, SIDE, False, 'props'),
]


@pytest.mark.parametrize('reading', CASES, ids=lambda r: type(r).__name__)
def test_a_reading_survives_the_round_trip_through_its_message(reading):
    assert_same(round_trip(reading), reading)


def test_a_changed_covariance_is_written_again():
    msgs = SimMessages(FRAMES)
    for var in (0.09, NAN, 0.25):
        _, msg = msgs.reading(GpsFix(1.0, 36.0, -75.0, 0.0, var))
        got = ros_convert.gps_fix(msg, 1.0)
        assert_same(got.horizontal_var_m2, var)


def test_every_reading_of_the_sensor_model_survives_the_round_trip():
    from dukw_sim.sensors import SensorModel
    from dukw_sim.truth import Truth
    model = SensorModel.from_config(seed=3)
    truth = Truth(roll_rad=0.05, pitch_rad=-0.1, yaw_rad=2.5, surge_mps=1.0, heave_mps=0.1,
                  fore_sensor_depth_m=0.02, sounder_depth_m=1.5, water_depth_m=2.0,
                  port_cmd_pct=50.0, port_current_a=20.0, port_track_speed_mps=1.0)
    seen = set()
    for k in range(100):
        for reading in model.sample(dataclasses.replace(truth, t_s=k * 0.01)):
            seen.add(type(reading))
            want = reading
            if isinstance(reading, WaterContact):   # levels are float32 in the message
                want = dataclasses.replace(reading, fore_level=f32(reading.fore_level),
                                           aft_level=f32(reading.aft_level))
            assert_same(round_trip(reading), want)
    assert seen == set(READERS)


def test_a_drive_status_must_say_its_drive():
    with pytest.raises(ValueError, match='drive'):
        SimMessages(FRAMES).reading(DriveStatus(1.0, SIDE, SIDE))
    with pytest.raises(ValueError, match='drive'):
        DriveStatus(1.0, SIDE, SIDE, True, 'paddles')


def test_the_estimator_sees_the_same_in_process_and_over_ros():
    """evaluate / the stack harness feed readings directly, ekf_node the messages: one rule."""
    from dukw_common.config import node_params
    from dukw_common.readings import reading_topic
    from dukw_common.vehicle import Vehicle
    from dukw_estimation.runner import EkfRunner
    from dukw_sim.core import Actuation, SimCore
    from dukw_sim.sensors import SensorModel
    sim = SimCore.from_config(seed=5)
    sim.reset('sand', yaw_rad=0.5)
    sensors = SensorModel.from_config(seed=5)
    direct, over_ros = (EkfRunner.from_params(node_params('ekf_node'), vehicle=sim.vehicle)
                        for _ in range(2))
    direct_est, ros_est = direct.estimator, over_ros.estimator
    assert isinstance(sim.vehicle, Vehicle)
    for _ in range(300):
        truth = sim.step(Actuation(80.0, 60.0, 0.0, 0.0))
        for reading in sensors.sample(truth):
            direct.on_sample(reading_topic(reading), reading, truth.t_s)
            over_ros.on_sample(reading_topic(reading), round_trip(reading), truth.t_s)
    a, b = direct_est.odometry(), ros_est.odometry()
    assert (b.x_m, b.y_m, b.yaw_rad, b.surge_mps) == pytest.approx(
        (a.x_m, a.y_m, a.yaw_rad, a.surge_mps), abs=1e-9)
    assert a.surge_mps > 0.3                       # it really drove
    ta, tb = direct_est.traction(), ros_est.traction()
    assert (tb.port_slip, tb.weight_on_tracks_fraction) == pytest.approx(
        (ta.port_slip, ta.weight_on_tracks_fraction), abs=1e-9)
    assert direct_est.counters == ros_est.counters
