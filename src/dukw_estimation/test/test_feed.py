"""feed(): each sensor reading goes to the estimator's matching add_* (and nothing else does)."""
import pytest

from dukw_common.config import node_params
from dukw_common.readings import DepthReading, DriveStatus, GpsFix, MotorSide, WaterContact
from dukw_common.vehicle import Vehicle
from dukw_estimation.ekf import Outcome
from dukw_estimation.evaluate import build_estimator
from dukw_estimation.feed import feed

SIDE = MotorSide(50.0, 20.0, 1.0, 1632.0)


@pytest.fixture
def est():
    return build_estimator(Vehicle.from_params(node_params('ekf_node')), (36.0, -75.0, 0.0))


def test_a_drive_status_goes_to_the_drive_it_names(est):
    tracks = DriveStatus(1.0, SIDE, SIDE, True, 'tracks')
    props = DriveStatus(1.0, SIDE, SIDE, True, 'props')
    feed(est, tracks)
    assert est.tracks is tracks and est.props is None
    feed(est, props)
    assert est.props is props and est.tracks is tracks


def test_other_readings_reach_their_counters(est):
    feed(est, WaterContact(1.0, True, False))
    feed(est, DepthReading(1.0, False, float('nan')))
    assert feed(est, GpsFix(1.0, 36.0, -75.0, 0.0, 0.09)) in set(Outcome)
    assert sum(est.counters['water'].values()) == 1
    assert sum(est.counters['depth'].values()) == 1
    assert sum(est.counters['gps_fix'].values()) == 1


def test_what_is_no_reading_is_refused_and_changes_nothing(est):
    with pytest.raises(TypeError, match='not a sensor reading'):
        feed(est, (1.0, True, False))
    with pytest.raises(ValueError, match='drive'):
        feed(est, DriveStatus(1.0, SIDE, SIDE))
    assert est.tracks is None and est.props is None and est.t_s is None
