"""The controller core: authority, timeout, rejection, mode weights, guards, PI."""
import dataclasses
import math

import pytest

from dukw_common.diagnostics import Level
from dukw_control.controller import DriveController
from dukw_control.modes import Mode, ModeDecision

DT = 0.01
LAND = ModeDecision(Mode.LAND, True, 1.0, 0.0, False, 'test')
WATER = ModeDecision(Mode.WATER, True, 0.0, 1.0, False, 'test')
TRANSITION = ModeDecision(Mode.TRANSITION, True, 1.0, 1.0, False, 'test')


class Rig:
    """A controller with healthy sensors, stepped at 100 Hz."""

    def __init__(self, settings, mode=LAND):
        self.c = DriveController(settings)
        self.t = 0.0
        self.c.on_mode(mode)
        self.c.on_authority(True, 'computer', self.t)
        self.current_a = 20.0
        self.stbd_current_a = None        # None: as the port motor
        self.pitch_rad = 0.0
        self.imu_alive = True
        self.odom = None
        self.weight_on_tracks = 1.0

    def run(self, seconds, cmd=(1.0, 0.0), send_cmd=True):
        out = None
        for _ in range(int(round(seconds / DT))):
            self.t += DT
            if send_cmd:
                self.c.on_cmd_vel(*cmd, self.t)
            stbd_a = self.current_a if self.stbd_current_a is None else self.stbd_current_a
            self.c.on_track_currents(self.current_a, stbd_a, self.t)
            self.c.on_pitch(self.pitch_rad, self.t)
            if self.imu_alive:
                self.c.on_attitude(self.t, self.t)
            self.c.on_traction(0.1, 0.1, self.weight_on_tracks, self.t)
            if self.odom is not None:
                self.c.on_odometry(*self.odom, self.t)
            out = self.c.step(self.t)
        return out


def test_no_authority_no_mode_or_no_cmd_means_neutral(controller_settings):
    c = DriveController(controller_settings)
    assert c.step(0.0).tracks.is_neutral()
    c.on_authority(True, 'computer', 0.0)
    assert 'no drive_mode' in c.step(0.01).neutral_reason
    c.on_mode(LAND)
    c.on_track_currents(0, 0, 0.02)
    c.on_pitch(0, 0.02)
    c.on_attitude(0.02, 0.02)
    assert c.step(0.02).neutral_reason == 'no cmd_vel yet'


def test_straight_request_ramps_up_with_the_port_bias(controller_settings):
    r = Rig(dataclasses.replace(controller_settings, closed_loop=False))
    out = r.run(0.1)
    assert 0 < out.tracks.stbd < 10.0                     # acceleration limit
    out = r.run(3.0)
    assert out.tracks.stbd == pytest.approx(50.0)
    assert out.tracks.port == pytest.approx(54.0)         # 4 % port bias
    assert out.props.is_neutral()


def test_operator_takeover_gives_neutral_in_the_same_cycle_and_needs_a_fresh_cmd(
        controller_settings):
    r = Rig(controller_settings)
    assert not r.run(2.0).tracks.is_neutral()
    r.c.on_authority(False, 'RC operator', r.t)
    out = r.c.step(r.t + DT)
    assert out.tracks.is_neutral() and out.props.is_neutral()
    assert r.c.speed_pi.integral == 0.0 and r.c.speed_ramp.value == 0.0
    r.t += DT
    r.c.on_authority(True, 'computer', r.t)
    out = r.run(0.2, send_cmd=False)                      # old command: not resumed
    assert out.tracks.is_neutral() and 'fresh cmd_vel' in out.neutral_reason
    assert not r.run(0.5).tracks.is_neutral()


def test_losing_cmd_vel_fades_to_neutral_by_the_timeout(controller_settings):
    r = Rig(controller_settings)
    r.run(3.0)
    last_cmd_t = r.t
    neutral_at = None
    for _ in range(100):
        out = r.run(DT, send_cmd=False)
        if out.tracks.is_neutral() and neutral_at is None:
            neutral_at = r.t
    assert neutral_at is not None
    assert neutral_at - last_cmd_t <= controller_settings.cmd_timeout_s + 1e-9
    assert neutral_at - last_cmd_t > controller_settings.cmd_timeout_s - \
        controller_settings.timeout_ramp_s


def test_a_stamp_ages_the_request_and_a_stale_stamp_counts_as_a_timeout(controller_settings):
    r = Rig(controller_settings)
    timeout_s = controller_settings.cmd_timeout_s
    r.run(2.0)
    sent_t = r.t - 0.3
    assert r.c.on_cmd_vel(1.0, 0.0, r.t, stamp_s=sent_t)            # 0.3 s in transit
    neutral_at = next(r.t for _ in range(100) if r.run(DT, send_cmd=False).tracks.is_neutral())
    assert timeout_s - DT < neutral_at - sent_t <= timeout_s + 1e-9  # aged from the stamp
    # a request stamped cmd_timeout_s ago is refused: it does not refresh the command
    r = Rig(controller_settings)
    r.run(2.0)
    last_fresh_t = r.t
    for _ in range(100):
        r.t += DT
        assert not r.c.on_cmd_vel(1.0, 0.0, r.t, stamp_s=r.t - timeout_s)
        r.c.on_track_currents(20.0, 20.0, r.t)
        r.c.on_pitch(0.0, r.t)
        r.c.on_attitude(r.t, r.t)
        out = r.c.step(r.t)
    assert out.neutral_reason == 'cmd_vel timed out' and r.t - last_fresh_t >= timeout_s
    assert 'treated as timed out' in r.c.i.last_rejection
    assert not r.c.on_cmd_vel(1.0, 0.0, r.t, stamp_s=math.nan)
    # a stamp ahead of the controller's clock counts as now, not as a longer life
    assert r.c.on_cmd_vel(1.0, 0.0, r.t, stamp_s=r.t + 5.0) and r.c.i.cmd_s == r.t


def test_bad_requests_are_rejected_and_the_previous_one_stands(controller_settings):
    r = Rig(controller_settings)
    before = r.run(2.0)
    for bad in ((math.nan, 0.0), (0.0, math.inf), (9.0, 0.0)):
        assert not r.c.on_cmd_vel(*bad, r.t)
    assert r.c.i.rejected == 3 and r.c.i.cmd == (1.0, 0.0)
    assert r.c.step(r.t).tracks == before.tracks
    assert any('rejected 3' in h.message for h in r.c.healths(r.t))


def test_water_mode_uses_the_props_and_stops_the_tracks(controller_settings):
    r = Rig(dataclasses.replace(controller_settings, closed_loop=False), mode=WATER)
    out = r.run(5.0, cmd=(0.6, 0.0))
    assert out.tracks.is_neutral()
    assert out.props.stbd == pytest.approx(25.0)          # (0.6/1.2)^2 of full thrust
    assert out.props.port == pytest.approx(29.0)


def test_transition_blends_and_mode_changes_ramp(controller_settings):
    r = Rig(dataclasses.replace(controller_settings, closed_loop=False))
    r.run(3.0)
    r.c.on_mode(TRANSITION)
    full_props = 100.0 * (1.0 / 1.2) ** 2
    out = r.run(0.5)
    assert out.props.stbd == pytest.approx(0.5 * full_props, rel=0.05)   # weight ramping in
    out = r.run(1.0)
    assert out.tracks.stbd == pytest.approx(50.0)
    assert out.props.stbd == pytest.approx(full_props)


@pytest.mark.parametrize('weight_on_tracks', [1.0, 0.9])
def test_grounded_in_the_transition_the_props_push_and_the_tracks_steer(controller_settings,
                                                                        weight_on_tracks):
    open_loop = dataclasses.replace(controller_settings, closed_loop=False)
    afloat = Rig(open_loop, mode=WATER).run(5.0, cmd=(0.8, 0.1))
    steer = afloat.props.stbd - (afloat.props.port - 4.0)      # less the 4 % port bias
    assert steer > 20.0                                        # afloat the props steer
    r = Rig(open_loop, mode=TRANSITION)
    r.weight_on_tracks = weight_on_tracks
    out = r.run(5.0, cmd=(0.8, 0.1))
    assert out.tracks.stbd - out.tracks.port > 5.0             # the tracks turn it ...
    pushing = 100.0 * (0.8 / 1.2) ** 2                         # ... the props push
    assert min(out.props.port, out.props.stbd) > 0.75 * pushing
    grounded_steer = out.props.stbd - (out.props.port - 4.0)
    assert -1e-9 <= grounded_steer <= (1.0 - weight_on_tracks) * steer + 1e-9


def test_a_stale_traction_estimate_counts_as_all_weight_on_the_tracks(controller_settings):
    r = Rig(dataclasses.replace(controller_settings, closed_loop=False), mode=TRANSITION)
    r.weight_on_tracks = 0.0
    out = r.run(2.0, cmd=(0.8, 0.1))
    assert out.props.stbd - (out.props.port - 4.0) > 20.0      # as afloat
    r.c.on_traction(0.1, 0.1, math.nan, r.t)                   # refused: changes nothing
    assert r.c.i.weight_on_tracks_fraction == 0.0
    r.c.i.stamps['traction'] = r.t - 10.0                      # the estimator fell silent
    out = r.c._mix(0.8, 0.1, 1.0, DT, r.t)
    assert out.props.stbd - (out.props.port - 4.0) == pytest.approx(0.0, abs=1e-9)


def test_safe_stop_mode_is_neutral(controller_settings):
    r = Rig(controller_settings)
    r.run(2.0)
    r.c.on_mode(ModeDecision(Mode.SAFE_STOP, True, 0.0, 0.0, False, 'traction stale'))
    out = r.run(DT)
    assert out.tracks.is_neutral() and 'traction stale' in out.neutral_reason


def test_safe_stop_needs_a_cmd_vel_sent_after_it(controller_settings):
    r = Rig(controller_settings)
    r.run(2.0)
    r.c.on_mode(ModeDecision(Mode.SAFE_STOP, True, 0.0, 0.0, False, 'traction stale'))
    r.run(0.1, send_cmd=False)
    r.c.on_mode(LAND)                                     # the input came back
    out = r.run(0.1, send_cmd=False)                      # the old request is not resumed
    assert out.tracks.is_neutral() and 'since the stop' in out.neutral_reason
    assert not r.run(0.5).tracks.is_neutral()


def test_a_safe_stop_between_two_steps_still_needs_a_fresh_cmd_vel(controller_settings):
    r = Rig(controller_settings)
    r.run(2.0)
    r.c.on_mode(ModeDecision(Mode.SAFE_STOP, True, 0.0, 0.0, False, 'forced'), r.t + 0.002)
    r.c.on_mode(LAND, r.t + 0.004)                        # never seen by a step
    r.t += DT
    out = r.c.step(r.t)
    assert out.tracks.is_neutral() and 'since the stop' in out.neutral_reason


def test_a_silent_imu_stops_the_tracks_although_pitch_keeps_coming(controller_settings):
    r = Rig(controller_settings)
    assert not r.run(2.0).tracks.is_neutral()
    r.imu_alive = False                                   # the estimator keeps predicting
    out = r.run(controller_settings.imu_timeout_s + 2 * DT)
    assert out.tracks.is_neutral() and out.neutral_reason.startswith('imu stale')
    incline = next(h for h in r.c.healths(r.t) if h.name == 'incline guard')
    assert incline.level == Level.ERROR and 'imu stale' in incline.message
    r.c.on_attitude(r.t - 5.0, r.t)                       # a sample measured long ago
    assert r.c.step(r.t).tracks.is_neutral()
    r.imu_alive = True
    out = r.run(0.1, send_cmd=False)
    assert out.tracks.is_neutral()                        # back, but waiting for a request
    assert not r.run(0.5).tracks.is_neutral()


def test_a_second_drive_mode_publisher_stops_and_reports_error(controller_settings):
    r = Rig(controller_settings)
    assert not r.run(1.0).tracks.is_neutral()
    r.c.sources.update('drive_mode', 2, ('/mode_manager_node', '/stranger'))
    out = r.run(DT)
    assert out.tracks.is_neutral() and '/stranger' in out.neutral_reason
    assert r.c.healths(r.t)[0].level == Level.ERROR
    r.c.sources.update('drive_mode', 1)
    assert r.run(0.1, send_cmd=False).tracks.is_neutral()
    assert not r.run(0.5).tracks.is_neutral()


def test_stale_imu_or_current_stops_the_tracks(controller_settings):
    r = Rig(controller_settings)
    r.run(2.0)
    t = r.t + 0.6
    r.c.on_cmd_vel(1.0, 0.0, t)
    out = r.c.step(t)
    assert out.tracks.is_neutral() and 'stale' in out.neutral_reason


def test_incline_beyond_15_deg_stops_climbing_at_once_but_not_backing_down(
        controller_settings):
    r = Rig(controller_settings)
    r.run(3.0)
    r.pitch_rad = -math.radians(17)                       # nose up
    out = r.run(0.5)
    assert max(out.tracks.port, out.tracks.stbd) <= 0.0
    assert r.c.incline.stopping
    out = r.run(2.0, cmd=(-0.5, 0.0))
    assert out.tracks.port < 0 and out.tracks.stbd < 0


def test_current_limit_derates_the_track_command(controller_settings):
    r = Rig(dataclasses.replace(controller_settings, closed_loop=False))
    r.current_a = 60.0                                    # above the 58 A ceiling
    out = r.run(3.0)
    assert out.tracks.stbd < 50.0
    assert r.c.current['stbd'].scale < 1.0
    assert any('derating' in h.message for h in r.c.healths(r.t))


def test_one_hot_motor_derates_both_tracks_alike(controller_settings):
    r = Rig(dataclasses.replace(controller_settings, closed_loop=False))
    r.run(1.0, cmd=(1.0, 0.2))
    r.stbd_current_a = 60.0                               # only the starboard motor is hot
    out = r.run(3.0, cmd=(1.0, 0.2))
    assert r.c.current['port'].scale == 1.0 and r.c.current['stbd'].scale < 0.9
    unscaled = r.c.s.land.mix(1.0, 0.2).sides
    ratio = out.tracks.stbd / unscaled.stbd
    assert ratio == pytest.approx(r.c.current['stbd'].scale)
    assert out.tracks.port == pytest.approx((unscaled.port + 4.0) * ratio)   # + port bias


def test_stuck_stops_and_reports_until_a_stop_or_reversal(controller_settings):
    r = Rig(controller_settings)
    r.odom = (0.0, 0.0)
    for _ in range(500):
        r.t += DT
        r.c.on_cmd_vel(1.0, 0.0, r.t)
        r.c.on_track_currents(20, 20, r.t)
        r.c.on_pitch(0, r.t)
        r.c.on_attitude(r.t, r.t)
        r.c.on_traction(1.0, 1.0, 1.0, r.t)
        r.c.on_odometry(0.0, 0.0, r.t)
        out = r.c.step(r.t)
    assert out.tracks.is_neutral() and out.neutral_reason.startswith('stuck')
    r.c.on_cmd_vel(-0.5, 0.0, r.t)
    assert not r.c.stuck.stuck


def test_closed_loop_corrects_a_yaw_rate_error(controller_settings):
    r = Rig(controller_settings)
    r.odom = (1.0, 0.05)                                  # drifting to port
    out = r.run(5.0)
    assert out.tracks.port - out.tracks.stbd > 4.0        # more than the bias alone
    assert r.c.yaw_pi.integral < 0.0
