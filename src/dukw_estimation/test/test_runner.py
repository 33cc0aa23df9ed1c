"""EkfRunner: ekf_node's schedule (routing by topic, publishing on the IMU or the timer)."""
import math

import pytest

from dukw_common.config import node_params
from dukw_common.readings import (DepthReading, DriveStatus, GpsFix, ImuSample, MotorSide,
                                  WaterContact, reading_topic)
from dukw_estimation.ekf import Outcome
from dukw_estimation.runner import EkfRunner, Estimate

SIDE = MotorSide(50.0, 20.0, 1.0, 1632.0)


@pytest.fixture
def runner():
    return EkfRunner.from_params(node_params('ekf_node'))


def _imu(t_s):
    return ImuSample(t_s, 0.0, 0.0, 0.3, 0.0, 0.0, 0.0, 0.0, 0.0, 9.81)


def test_a_drive_status_goes_to_the_drive_its_topic_names(runner):
    est = runner.estimator.motion_filter
    tracks = DriveStatus(1.0, SIDE, SIDE, True, 'tracks')
    props = DriveStatus(1.0, SIDE, SIDE, True, 'props')
    runner.on_sample(reading_topic(tracks), tracks, 1.0)
    assert est.tracks is tracks and est.props is None
    runner.on_sample(reading_topic(props), props, 1.0)
    assert est.props is props and est.tracks is tracks


def test_other_readings_reach_their_counters(runner):
    est = runner.estimator
    for reading in (WaterContact(1.0, True, False), DepthReading(1.0, False, math.nan),
                    GpsFix(1.0, 36.0, -75.0, 0.0, 0.09)):
        assert runner.on_sample(reading_topic(reading), reading, 1.0) is None
    assert sum(est.counters['water'].values()) == 1
    assert sum(est.counters['depth'].values()) == 1
    assert sum(est.counters['gps_fix'].values()) == 1
    assert set(est.counters['gps_fix']) <= set(Outcome)


def test_an_unknown_topic_is_refused_and_changes_nothing(runner):
    with pytest.raises(ValueError, match='no input'):
        runner.on_sample('odometry/filtered', _imu(1.0), 1.0)
    with pytest.raises(ValueError, match='drive'):
        reading_topic(DriveStatus(1.0, SIDE, SIDE))
    assert runner.estimator.t_s is None
    assert runner.estimator.motion_filter.tracks is None


def test_publishes_on_each_imu_sample_and_the_timer_only_while_the_imu_is_silent(runner):
    assert runner.publish_on_imu                       # as configured for the boat
    assert runner.tick(0.5) is None                    # nothing measured yet
    out = runner.on_sample('imu/data', _imu(1.0), 1.0)
    assert out is not None and out.t_s == pytest.approx(1.0)
    assert runner.tick(1.0 + 0.5 * runner.period_s) is None      # the IMU drives the output
    late = 1.0 + 2.0 * runner.period_s
    out = runner.tick(late)                            # silent IMU: the timer publishes
    assert out is not None and out.t_s == pytest.approx(late)


def test_asking_for_the_estimate_changes_nothing(runner):
    runner.on_sample('imu/data', _imu(1.0), 1.0)
    first = runner.estimate()
    for _ in range(3):
        again = runner.estimate()
    assert again.odometry.x_m == first.odometry.x_m
    assert again.traction.weight_on_tracks_fraction == first.traction.weight_on_tracks_fraction


def _drive_on(runner, held: list):
    """IMU samples with the tracks pushing in between; keeps every estimate unread."""
    for k in range(20):
        t_s = 1.0 + 0.01 * k
        status = DriveStatus(t_s, SIDE, SIDE, True, 'tracks')
        runner.on_sample('tracks/status', status, t_s)
        held.append(runner.on_sample('imu/data', _imu(t_s), t_s))


def test_a_held_estimate_keeps_the_traction_of_its_instant(runner):
    eager = EkfRunner.from_params(node_params('ekf_node'))
    expected = []
    for k in range(20):                   # the reference: traction read at once
        t_s = 1.0 + 0.01 * k
        eager.on_sample('tracks/status', DriveStatus(t_s, SIDE, SIDE, True, 'tracks'), t_s)
        expected.append(eager.on_sample('imu/data', _imu(t_s), t_s).traction)
    held = []
    _drive_on(runner, held)               # read only after all the samples went in
    got = [e.traction for e in held]
    assert [t.effective_weight_n for t in got] == [t.effective_weight_n for t in expected]
    assert [t.port_slip for t in got] == [t.port_slip for t in expected]
    assert len({t.effective_weight_n for t in got}) > 1   # it did change over the run


def test_an_estimate_needs_its_traction_or_the_query_for_it(runner):
    runner.on_sample('imu/data', _imu(1.0), 1.0)
    odometry = runner.estimator.odometry()
    with pytest.raises(ValueError, match='either'):
        Estimate(odometry)
    with pytest.raises(ValueError, match='either'):
        Estimate(odometry, runner.estimator.traction(),
                 traction_query=runner.estimator.traction)
