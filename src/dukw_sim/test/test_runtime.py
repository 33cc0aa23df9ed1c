"""sim_node's ROS-free pacing and health, and its message builders (no DDS)."""
import math

import pytest
from dukw_msgs.msg import Authority, DrivetrainStatus, MotorSide, SimTruth

from dukw_common.diagnostics import Level
from dukw_common.readings import (DepthReading, DriveStatus, GpsFix, GpsVelocity, ImuSample,
                                  WaterContact)
from dukw_common.readings import MotorSide as SideReading
from dukw_driver.authority import AuthorityState, Holder, Reason
from dukw_sim.runtime import Pacer, SpeedMeter, sim_healths
from dukw_sim.sensors import Fault
from dukw_sim.sim_messages import TOPICS, Frames, SimMessages
from dukw_sim.switch import RcPulses
from dukw_sim.truth import Medium, Truth

DT = 0.01


def pacer(rtf, **kw):
    args = {'steps_per_tick': 1, 'max_lag_s': 0.5, 'wall_s': 100.0}
    return Pacer(rtf, DT, **{**args, **kw})


def run_ticks(p, walls, budget=None):
    """Take every due step (or at most ``budget`` per tick, as a tick out of time does)."""
    taken = []
    for wall in walls:
        n = p.steps_due(wall)
        n = n if budget is None else min(n, budget)
        p.took(n)
        taken.append(n)
    return taken


def test_pacer_follows_the_wall_clock_times_the_factor():
    p = pacer(10.0)
    assert p.period_s == pytest.approx(0.001)
    steps = sum(run_ticks(p, [100.0 + k * 0.001 for k in range(1, 1001)]))
    assert steps == pytest.approx(1000, abs=1)      # 1 s of wall = 10 s of sim = 1000 steps
    assert p.dropped_s == 0.0


def test_pacer_catches_up_over_later_ticks_but_not_beyond_max_lag():
    p = pacer(1.0)
    assert run_ticks(p, [100.15]) == [15]                         # 150 ms late: at once
    assert run_ticks(p, [100.45, 100.45, 100.45], budget=20) == [20, 10, 0]
    assert p.dropped_s == 0.0
    assert run_ticks(p, [103.0], budget=20) == [20]               # 2.55 s behind:
    assert p.dropped_s == pytest.approx(2.05, abs=0.011)          # all but 0.5 s dropped
    assert sum(run_ticks(p, [103.0] * 5)) == 30
    assert p.steps_due(103.0) == 0


def test_pacer_as_fast_as_possible_asks_for_max_lag_per_tick():
    p = pacer(0.0, steps_per_tick=3)
    assert p.period_s == 0.0
    assert [p.steps_due(w) for w in (100.0, 100.0, 500.0)] == [50, 50, 50]


@pytest.mark.parametrize('rtf', [-1.0, math.nan])
def test_pacer_refuses_a_bad_factor(rtf):
    with pytest.raises(ValueError):
        pacer(rtf)


def test_speed_meter_and_healths():
    meter = SpeedMeter(wall_s=10.0, sim_s=0.0)
    rates = meter.report(12.0, 10.0, {'imu/data': 1000, 'gps/fix': 100})
    assert meter.achieved_rtf == pytest.approx(5.0)
    assert rates == {'imu/data': 100.0, 'gps/fix': 10.0}
    assert meter.report(12.0, 10.0, {'imu/data': 1000}) == {}
    state = AuthorityState(Holder.NONE, Reason.RC_LINK_LOST, False, True, 'RC link lost')
    sim, auth, topics = sim_healths(10.0, 10.0, meter, 0.0, {'steps': 1000}, state, 2, 3,
                                    {'imu/data': 100.0})
    assert sim.level == Level.WARN and '5.00x' in sim.message   # asked 10x, got 5x
    assert auth.level == Level.WARN and auth.values['rejected_commands'] == 2
    assert auth.values['holder'] == 'NONE' and auth.values['reason'] == 'RC_LINK_LOST'
    assert topics.values == {'imu/data': '100.0'}
    computer = AuthorityState(Holder.COMPUTER, Reason.RC_SWITCH, True, False, 'computer')
    ok = sim_healths(10.0, 0.0, meter, 0.0, {}, computer, 0, 0, {})
    assert ok[0].level == Level.OK and ok[1].level == Level.OK   # 0 = as fast as possible


FRAMES = Frames('base_link', 'imu_link', 'gps_link')


def test_topics_are_the_contract_with_the_right_qos():
    names = [t for t, _, _ in TOPICS]
    assert len(names) == len(set(names)) == 12
    assert all(not t.startswith('/') for t in names if t not in ('/clock', '/diagnostics'))
    qos = {t: q for t, _, q in TOPICS}
    assert qos['authority'].durability.name == 'TRANSIENT_LOCAL'
    assert qos['imu/data'].reliability.name == 'BEST_EFFORT'


def test_readings_become_messages_on_their_topics():
    msgs = SimMessages(FRAMES)
    imu = ImuSample(1.25, 0.0, 0.0, 2 * math.atan2(0.6, 0.8), 0.1, 0.2, 0.3, 0.0, 0.1, 9.8,
                    yaw_var_rad2=7e-5, yaw_rate_var_rps2=9e-6, roll_var_rad2=1e-5,
                    pitch_var_rad2=1e-5, roll_rate_var_rps2=9e-6, pitch_rate_var_rps2=9e-6,
                    accel_var_m2ps4=(1e-4, 8.1e-5, 8.1e-5))
    topic, msg = msgs.reading(imu)
    assert topic == 'imu/data' and msg.header.frame_id == 'imu_link'
    assert (msg.header.stamp.sec, msg.header.stamp.nanosec) == (1, 250_000_000)
    assert (msg.orientation.z, msg.orientation.w) == pytest.approx((0.6, 0.8), abs=1e-15)
    assert msg.angular_velocity.z == 0.3
    assert list(msg.orientation_covariance) == [1e-5, 0, 0, 0, 1e-5, 0, 0, 0, 7e-5]
    topic, fix = msgs.reading(GpsFix(2.0, 36.1, -75.7, 1.0, 0.09, True, 0.36))
    assert topic == 'gps/fix' and fix.latitude == 36.1 and fix.position_covariance[8] == 0.36
    assert fix.position_covariance_type == fix.COVARIANCE_TYPE_DIAGONAL_KNOWN
    assert fix.status.status == fix.status.STATUS_GBAS_FIX
    topic, vel = msgs.reading(GpsVelocity(2.0, 1.0, -0.5, 0.0025, 0.1, 0.0025))
    assert topic == 'gps/vel' and vel.twist.twist.linear.y == -0.5
    assert vel.twist.covariance[7] == 0.0025 and vel.twist.covariance[35] > 1e3
    topic, water = msgs.reading(WaterContact(2.0, True, False, 0.9, 0.1))
    assert topic == 'water/contact' and water.fore_wet and not water.aft_wet
    topic, depth = msgs.reading(DepthReading(2.0, False, math.nan, 0.0, 18.0))
    assert topic == 'depth' and not depth.valid and math.isnan(depth.depth_m)


def test_drivetrain_faults_are_decoded_to_names():
    msgs = SimMessages(FRAMES)
    flags = Fault.STALL | Fault.OVERHEAT
    side = SideReading(100.0, 60.0, 0.0, 489.6, 23.0, 80.0, int(flags), flags.names())
    ok = SideReading(50.0, 10.0, 1.0, 81.6, 24.0, 30.0, 0, Fault(0).names())
    topic, msg = msgs.reading(DriveStatus(3.0, side, ok, True, 'tracks'))
    assert topic == 'tracks/status' and msg.drive == DrivetrainStatus.DRIVE_TRACKS
    assert msg.port.fault_flags == MotorSide.FAULT_STALL | MotorSide.FAULT_OVERHEAT
    assert sorted(msg.port.faults) == ['overheat', 'stall'] and list(msg.stbd.faults) == []
    topic, msg = msgs.reading(DriveStatus(3.0, ok, ok, True, 'props'))
    assert topic == 'props/status' and msg.drive == DrivetrainStatus.DRIVE_PROPELLERS
    # the same side clears its faults when they go
    topic, msg = msgs.reading(DriveStatus(3.1, ok, ok, True, 'tracks'))
    assert msg.port.fault_flags == 0 and list(msg.port.faults) == []


def test_sim_faults_have_the_message_bits():
    for flag in Fault:
        assert getattr(MotorSide, f'FAULT_{flag.name}') == int(flag)


def test_every_sim_truth_field_is_filled_from_truth():
    truth = Truth(**{name: float(k + 1) for k, name in enumerate(Truth.field_names())
                     if name != 'medium'}, medium=Medium.WATER)
    msg = SimMessages(FRAMES).sim_truth(truth)
    for name in SimTruth.get_fields_and_field_types():
        if name not in ('header', 'medium'):
            assert getattr(msg, name) == getattr(truth, name), name
    assert msg.medium == SimTruth.MEDIUM_WATER and msg.header.frame_id == 'odom'


def test_truth_tf_in_place_is_the_fresh_tf_message_bit_for_bit():
    """sim_node's cached odom -> truth TF must be what tf_message(pose_transform) builds
    (repr: every float's shortest exact form, -0.0 too; CDR padding bytes are not set)."""
    from dukw_common.description import pose_transform
    from dukw_common.node_tools import s_to_stamp
    from dukw_common.tf_tools import tf_message
    msgs = SimMessages(FRAMES)
    for k, t_s in enumerate([0.0, 0.01, 1.005, 2.9999999999, 123.456789]):
        truth = Truth(t_s=t_s, x_m=1.5 + k, y_m=-0.25 * k, z_m=-0.1, roll_rad=0.02 * k,
                      pitch_rad=-0.03, yaw_rad=2.5 - k)
        fresh = tf_message([pose_transform('odom', 'base_link_truth', truth.x_m, truth.y_m,
                                           truth.z_m, truth.roll_rad, truth.pitch_rad,
                                           truth.yaw_rad)], s_to_stamp(t_s))
        cached = msgs.truth_tf(truth, 'base_link_truth')
        assert cached == fresh and repr(cached) == repr(fresh), t_s
    assert msgs.truth_tf(truth, 'other').transforms[0].child_frame_id == 'other'


def test_rc_authority_and_clock_messages():
    msgs = SimMessages(FRAMES)
    rc = msgs.rc_input(RcPulses(4.0, True, True, (1350.0, 1600.0)))
    assert rc.rc_selected and list(rc.channels_us) == [1350.0, 1600.0]
    state = AuthorityState(Holder.RC, Reason.RC_SWITCH, True, False, 'RC operator')
    auth = msgs.authority(state, 4.0)
    assert (auth.holder, auth.reason) == (Authority.HOLDER_RC, Authority.REASON_RC_SWITCH)
    clock = msgs.clock(12.345)
    assert (clock.clock.sec, clock.clock.nanosec) == (12, 345_000_000)


def test_one_off_builders_return_fresh_messages():
    from dukw_sim import sim_messages as sm
    topic, a = sm.fresh_reading(DepthReading(1.0, True, 1.5, 0.0, 18.0), FRAMES)
    _, b = sm.fresh_reading(DepthReading(2.0, True, 2.5, 0.0, 18.0), FRAMES)
    assert topic == 'depth'
    assert (a.depth_m, b.depth_m) == (1.5, 2.5) and a.header.frame_id == 'base_link'
    state = AuthorityState(Holder.COMPUTER, Reason.RC_SWITCH, True, False, 'computer')
    assert sm.fresh_authority(state, 1.0).holder == Authority.HOLDER_COMPUTER


def test_sim_node_declares_every_key_of_its_config_block_own_ones_with_ranges():
    from dukw_common.config import node_params
    from dukw_sim.sim_params import sim_node_specs
    specs = {s.name: s for s in sim_node_specs()}
    assert set(node_params('sim_node')) <= set(specs)
    for name in ('real_time_factor', 'rates.imu_hz', 'noise.gyro_std_rps', 'tick_budget_s'):
        assert specs[name].min is not None, name
    assert specs['real_time_factor'].min == 0.0
    assert all(s.description for s in specs.values())
