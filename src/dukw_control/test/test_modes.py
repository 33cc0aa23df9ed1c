"""The mode state machine: order, debounce, hysteresis, dwell, staleness, forcing."""
import dataclasses

import pytest

from dukw_control.modes import Mode, ModeManager, ModeSettings

DT = 0.05


class Feed:
    """Feeds a manager at 20 Hz with the given evidence and records mode changes."""

    def __init__(self, settings):
        self.mm = ModeManager(settings)
        self.t = 0.0
        self.modes = []

    def run(self, seconds, fraction=1.0, fore=False, aft=False, depth=False, force_n=200.0,
            imu=True, afloat=None):
        """``afloat``: the estimator's contact decision (None: afloat when nothing lies on
        the tracks, fraction 0)."""
        afloat = fraction <= 0.0 if afloat is None else afloat
        for _ in range(int(round(seconds / DT))):
            self.t += DT
            if imu:
                self.mm.on_attitude(self.t, self.t)
            self.mm.on_water_contact(fore, aft, self.t)
            self.mm.on_traction(fraction, afloat, self.t)
            self.mm.on_track_forces(force_n, force_n, self.t)
            self.mm.on_depth(depth, 1.0 if depth else float('nan'), self.t)
            d = self.mm.update(self.t)
            if not self.modes or self.modes[-1][0] != d.mode:
                self.modes.append((d.mode, self.t, d.reason))
        return self.mm.decision()


def test_starts_in_safe_stop_and_classifies_when_inputs_arrive(mode_settings):
    mm = ModeManager(mode_settings)
    d = mm.update(0.0)
    assert d.mode == Mode.SAFE_STOP and 'waiting for' in d.reason
    assert d.track_weight == 0.0 and d.prop_weight == 0.0
    f = Feed(mode_settings)
    assert f.run(0.2).mode == Mode.LAND


def test_land_to_water_goes_through_transition_once_each(mode_settings):
    f = Feed(mode_settings)
    f.run(5.0)
    f.run(4.0, fraction=0.6, fore=True)
    d = f.run(6.0, fraction=0.0, fore=True, aft=True, depth=True, force_n=20.0)
    assert [m for m, *_ in f.modes] == [Mode.LAND, Mode.TRANSITION, Mode.WATER]
    assert d.track_weight == 0.0 and d.prop_weight == 1.0
    assert 'afloat' in d.reason


def test_waves_washing_over_the_sensors_do_not_make_it_chatter(mode_settings):
    f = Feed(mode_settings)
    f.run(2.0)
    for _ in range(10):                      # a wave every 3.6 s wets the fore sensor 0.2 s
        f.run(0.2, fraction=0.97, fore=True)
        f.run(3.4, fraction=0.98)
    assert [m for m, *_ in f.modes] == [Mode.LAND]
    for _ in range(10):                      # in the surf: weight comes and goes with heave
        f.run(1.0, fraction=0.5, fore=True)
        f.run(1.0, fraction=0.95, fore=False)
    assert [m for m, *_ in f.modes] == [Mode.LAND, Mode.TRANSITION]


def test_afloat_intermittent_ground_contact_stays_water_until_it_holds(mode_settings):
    f = Feed(mode_settings)
    f.run(1.0, fraction=0.0, fore=True, aft=True, depth=True, force_n=10.0)
    assert f.mm.mode == Mode.WATER
    for _ in range(5):
        f.run(0.5, fraction=0.5, fore=True, aft=True, depth=True, force_n=10.0)
        f.run(2.0, fraction=0.0, fore=True, aft=True, depth=True, force_n=10.0)
    assert f.mm.mode == Mode.WATER
    f.run(3.0, fraction=0.6, fore=True, aft=True, force_n=300.0)
    f.run(6.0, fraction=1.0)
    assert [m for m, *_ in f.modes] == [Mode.WATER, Mode.TRANSITION, Mode.LAND]


def test_water_needs_the_track_force_at_friction(mode_settings):
    f = Feed(mode_settings)
    f.run(1.0, fraction=0.5, fore=True)
    f.run(10.0, fraction=0.05, fore=True, aft=True, depth=True, force_n=300.0)
    assert f.mm.mode == Mode.TRANSITION


def test_stale_input_gives_safe_stop_with_the_reason_and_recovers(mode_settings):
    f = Feed(mode_settings)
    f.run(1.0)
    t = f.t + 1.0                            # nothing for 1 s
    d = f.mm.update(t)
    assert d.mode == Mode.SAFE_STOP
    assert 'water/contact stale' in d.reason and 'traction stale' in d.reason
    f.t = t
    assert f.run(0.1).mode == Mode.LAND


def test_nan_weight_fraction_is_rejected(mode_settings):
    mm = ModeManager(mode_settings)
    assert not mm.on_traction(float('nan'), True, 0.0)
    assert mm.rejected == 1 and mm.weight_fraction == 1.0


def test_forced_mode_holds_and_release_returns_to_the_evidence(mode_settings):
    f = Feed(mode_settings)
    f.run(1.0, fore=True)                    # a sensor stuck wet keeps it in the transition
    assert f.mm.force(Mode.LAND, f.t) == ''
    d = f.run(2.0, fore=True)
    assert d.mode == Mode.LAND and not d.automatic and 'forced' in d.reason
    f.mm.release(f.t)
    assert f.mm.decision().mode == Mode.TRANSITION and f.mm.automatic


def test_a_silent_imu_is_a_safe_stop(mode_settings):
    f = Feed(mode_settings)
    assert f.run(1.0).mode == Mode.LAND
    d = f.run(mode_settings.imu_timeout_s + 2 * DT, imu=False)
    assert d.mode == Mode.SAFE_STOP and 'imu stale' in d.reason
    assert f.run(0.2).mode == Mode.LAND


def test_forcing_may_only_make_things_safer(mode_settings):
    f = Feed(mode_settings)
    f.run(1.0)
    before = f.mm.decision()
    refusal = f.mm.force(Mode.WATER, f.t)    # on dry sand
    assert 'WATER refused' in refusal and f.mm.decision() == before and f.mm.automatic
    f.run(0.1, fraction=0.0, fore=True, aft=True, depth=True, force_n=0.0)
    f.run(3.0, fraction=0.0, fore=True, aft=True, depth=True, force_n=0.0)
    assert 'LAND refused' in f.mm.force(Mode.LAND, f.t)   # afloat
    f.run(1.0, imu=False)                    # an input goes stale: safe stop ...
    assert f.mm.decision().mode == Mode.SAFE_STOP
    for mode in (Mode.LAND, Mode.TRANSITION, Mode.WATER):   # ... that no forcing lifts
        assert 'refused: imu stale' in f.mm.force(mode, f.t)
    assert f.mm.force(Mode.SAFE_STOP, f.t) == ''


def test_a_held_forced_mode_drops_when_an_input_goes_stale(mode_settings):
    f = Feed(mode_settings)
    f.run(1.0)
    assert f.mm.force(Mode.TRANSITION, f.t) == ''
    d = f.run(mode_settings.water_contact_timeout_s + 2 * DT, imu=False)
    assert d.mode == Mode.SAFE_STOP and d.automatic
    assert 'forcing dropped (TRANSITION refused: imu stale' in f.modes[-1][2]


def test_tracks_idle_afloat_is_a_parameter(mode_settings):
    s = dataclasses.replace(mode_settings, water_tracks_idle=True)
    f = Feed(s)
    d = f.run(1.0, fraction=0.0, fore=True, aft=True, depth=True, force_n=0.0)
    assert d.mode == Mode.WATER and d.tracks_idle


def test_inconsistent_thresholds_are_refused(mode_settings):
    with pytest.raises(ValueError):
        dataclasses.replace(mode_settings, water_enter_fraction=0.5, water_exit_fraction=0.4)
    with pytest.raises(ValueError):
        ModeSettings(**{**dataclasses.asdict(mode_settings), 'transition_prop_weight': 2.0})


def test_on_land_in_the_swash_the_props_keep_pushing_until_the_sensors_stay_dry(mode_settings):
    # the props hang below the water sensors: between run-ups that wet the sensors they
    # still bite, so LAND keeps them for land_prop_hold_s after the last wet reading
    hold_s = mode_settings.land_prop_hold_s
    assert hold_s > 1.0
    f = Feed(mode_settings)
    f.run(2.0, fraction=0.6, fore=True, aft=True, force_n=300.0)     # grounding: TRANSITION
    f.run(3.0, fraction=0.9, aft=True, force_n=300.0)
    d = f.run(1.0, fraction=1.0, force_n=300.0)                      # sensors dry: LAND
    assert d.mode == Mode.LAND and d.track_weight == 1.0
    assert d.prop_weight == mode_settings.transition_prop_weight and 'swash' in d.reason
    assert f.mm.changed                                  # published at once, not at republish
    f.mm.changed = False
    d = f.run(hold_s - 1.5, fraction=1.0, force_n=300.0)
    assert d.prop_weight > 0.0
    d = f.run(1.0, fraction=1.0, force_n=300.0)                      # dry for hold_s: off
    assert d.mode == Mode.LAND and d.prop_weight == 0.0 and 'swash' not in d.reason
    assert f.mm.changed
    d = f.run(0.2, fraction=1.0, aft=True, force_n=300.0)            # a run-up wets it again
    assert d.prop_weight > 0.0
    assert [m for m, *_ in f.modes] == [Mode.TRANSITION, Mode.LAND]


def test_dry_land_never_runs_the_props(mode_settings):
    f = Feed(mode_settings)
    for _ in range(40):
        assert f.run(0.5).prop_weight == 0.0


def test_a_negative_swash_hold_is_refused(mode_settings):
    with pytest.raises(ValueError, match='land_prop_hold_s'):
        ModeSettings(**{**dataclasses.asdict(mode_settings), 'land_prop_hold_s': -1.0})


def test_coming_ashore_land_follows_transition_without_the_dwell(mode_settings):
    # a beached vehicle left dry by a trough right after WATER -> TRANSITION: LAND after
    # enter_land_s, not min_dwell_s; LAND's own dwell still holds it against the next wave
    assert mode_settings.ashore_dwell_s + mode_settings.enter_land_s + 0.5 < \
        mode_settings.min_dwell_s
    f = Feed(mode_settings)
    f.run(mode_settings.min_dwell_s + 0.5, fraction=0.0, fore=True, aft=True, depth=True,
          force_n=10.0)
    f.run(mode_settings.exit_water_s + 0.1, fraction=0.6, fore=True, aft=True,
          force_n=300.0)
    assert f.mm.mode == Mode.TRANSITION
    entered_s = f.modes[-1][1]
    f.run(mode_settings.enter_land_s + mode_settings.ashore_dwell_s + 0.2)
    assert [m for m, *_ in f.modes] == [Mode.WATER, Mode.TRANSITION, Mode.LAND]
    assert f.modes[-1][1] - entered_s < mode_settings.min_dwell_s
    f.run(mode_settings.min_dwell_s - 1.0, fraction=0.6, fore=True)   # the next run-up
    assert f.mm.mode == Mode.LAND


def test_a_short_trough_coming_ashore_is_land_but_not_on_the_way_to_sea(mode_settings):
    # issue 18: the truth's first LAND ashore is often a trough leaving the beached hulls dry
    # for 0.25-0.75 s; with enter_land_s the mode waited for the last run-up, 3-5 s later.
    # On the way to sea the same trough must not send it back to LAND (min_dwell_s would
    # then hold WATER late)
    s = mode_settings
    assert s.ashore_enter_land_s + 0.1 < s.enter_land_s
    trough_s = 0.5 * (s.ashore_enter_land_s + s.enter_land_s)
    ashore = Feed(s)
    ashore.run(s.min_dwell_s + 0.5, fraction=0.0, fore=True, aft=True, depth=True,
               force_n=10.0)
    ashore.run(max(s.exit_water_s, s.ashore_dwell_s) + 0.1, fraction=0.6, fore=True,
               aft=True, force_n=300.0)
    assert ashore.mm.mode == Mode.TRANSITION
    ashore.run(trough_s)
    ashore.run(0.5, fraction=0.7, fore=True)          # the next run-up
    assert [m for m, *_ in ashore.modes] == [Mode.WATER, Mode.TRANSITION, Mode.LAND]
    seaward = Feed(s)
    seaward.run(s.min_dwell_s + 0.5)
    seaward.run(s.min_dwell_s + 0.5, fraction=0.6, fore=True)
    assert seaward.mm.mode == Mode.TRANSITION
    seaward.run(trough_s)
    seaward.run(0.5, fraction=0.7, fore=True)
    assert [m for m, *_ in seaward.modes] == [Mode.LAND, Mode.TRANSITION]


def test_an_ashore_land_debounce_beyond_enter_land_s_is_refused(mode_settings):
    with pytest.raises(ValueError, match='ashore_enter_land_s'):
        ModeSettings(**{**dataclasses.asdict(mode_settings),
                        'ashore_enter_land_s': mode_settings.enter_land_s + 0.1})


def test_back_from_land_transition_keeps_the_full_dwell(mode_settings):
    # LAND -> TRANSITION -> LAND is going back, not onward: min_dwell_s holds
    f = Feed(mode_settings)
    f.run(mode_settings.min_dwell_s + 0.5)
    f.run(0.5, fraction=0.9, fore=True)
    assert f.mm.mode == Mode.TRANSITION
    f.run(mode_settings.min_dwell_s - 1.0)
    assert f.mm.mode == Mode.TRANSITION
    f.run(1.5)
    assert [m for m, *_ in f.modes] == [Mode.LAND, Mode.TRANSITION, Mode.LAND]


def test_to_sea_water_follows_transition_without_the_dwell(mode_settings):
    # issue 18 (seed 2027 run 22): LAND -> TRANSITION -> WATER is onward; min_dwell_s holds
    # a change back, so WATER follows its own evidence after enter_water_s, not the dwell
    s = mode_settings
    assert s.enter_transition_s + s.enter_water_s + 1.2 < s.min_dwell_s
    f = Feed(s)
    f.run(s.min_dwell_s + 0.5)
    f.run(s.enter_transition_s + 0.1, fraction=0.8, fore=True, aft=True)
    assert f.mm.mode == Mode.TRANSITION
    entered_s = f.modes[-1][1]
    # the track force's low pass falls to friction, then enter_water_s
    f.run(s.enter_water_s + 1.0, fraction=0.0, fore=True, aft=True, depth=True, force_n=10.0)
    assert [m for m, *_ in f.modes] == [Mode.LAND, Mode.TRANSITION, Mode.WATER]
    assert f.modes[-1][1] - entered_s < s.min_dwell_s


def _to_sea_transition(s):
    """A manager that went LAND -> TRANSITION (to sea) and has waited out its dwell."""
    f = Feed(s)
    f.run(s.min_dwell_s + 0.5)
    f.run(s.min_dwell_s + 0.5, fraction=0.6, fore=True, aft=True)
    assert [m for m, *_ in f.modes] == [Mode.LAND, Mode.TRANSITION]
    return f


def _float_then_touch_down(f, s, float_s):
    """Afloat for ``float_s`` (track force at friction), then a trough sets the hull on the
    sand for enter_water_s, read between water_enter_fraction and water_exit_fraction, the
    estimator's contact decision on the sand; returns the mode at the float's end."""
    f.run(float_s, fraction=0.0, fore=True, aft=True, depth=True, force_n=10.0)
    afloat_mode = f.mm.mode
    touchdown = 0.5 * (s.water_enter_fraction + s.water_exit_fraction)
    f.run(s.enter_water_s, fraction=touchdown, fore=True, aft=True, force_n=10.0,
          afloat=False)
    return afloat_mode


def test_to_sea_a_light_touchdown_after_the_first_float_keeps_the_water_count(mode_settings):
    # issue 18 (seed 2027 run 108): afloat for 0.3 s, then a trough sets the hull on the sand
    # with the share read over water_enter_fraction (yet under water_exit_fraction, where
    # WATER itself would call it grounded): WATER follows enter_water_s from the first float
    s = mode_settings
    f = _to_sea_transition(s)
    f.run(0.5, fraction=0.0, fore=True, aft=True, depth=True, force_n=10.0)   # force low-passed
    floated_s = f.t
    assert _float_then_touch_down(f, s, 0.3) == Mode.TRANSITION
    assert f.mm.mode == Mode.WATER
    assert f.modes[-1][1] - floated_s <= s.enter_water_s + 0.3 + 2 * DT


def test_to_sea_one_wet_sensor_is_water_enough_for_the_count(mode_settings):
    # issue 18 (seed 2029 run 79): the hull's first float lasted 0.7 s, its bow pitched up
    # on the wave and the fore sensor read dry for 0.3 s of it while the aft one, the share
    # and the estimator's contact decision said afloat; the count waited for both wet and
    # WATER came with the next float, 3.9 s after the truth's. Afloat one sensor is water
    # enough (WATER keeps it, test above); both dry with no depth is the ground's evidence.
    s = mode_settings
    f = _to_sea_transition(s)
    f.run(s.enter_water_s + 0.6, fraction=0.0, aft=True, force_n=10.0)   # force low-passed
    assert f.mm.mode == Mode.WATER
    f = _to_sea_transition(s)
    f.run(s.enter_water_s + 0.6, fraction=0.0, force_n=10.0)    # no water reading at all
    assert f.mm.mode == Mode.TRANSITION


def test_to_sea_a_grounding_past_water_exit_fraction_restarts_the_water_count(mode_settings):
    s = mode_settings
    f = _to_sea_transition(s)
    f.run(0.8, fraction=0.0, fore=True, aft=True, depth=True, force_n=10.0)
    f.run(s.enter_water_s, fraction=s.water_exit_fraction + 0.05, fore=True, aft=True,
          force_n=10.0, afloat=False)
    assert f.mm.mode == Mode.TRANSITION


def _ashore_transition(s):
    """A manager that went WATER -> TRANSITION (coming ashore: the tracks on the ground)."""
    f = Feed(s)
    f.run(s.min_dwell_s + 0.5, fraction=0.0, fore=True, aft=True, depth=True, force_n=10.0)
    f.run(s.exit_water_s + 0.1, fraction=0.6, fore=True, aft=True, force_n=300.0)
    assert f.mm.mode == Mode.TRANSITION
    return f


def test_coming_ashore_a_light_touchdown_restarts_the_count_back_to_water(mode_settings):
    # WATER -> TRANSITION -> WATER is going back: the count holds only under
    # water_enter_fraction, as it starts
    s = mode_settings
    f = _ashore_transition(s)
    f.run(s.min_dwell_s, fraction=0.6, fore=True, aft=True, force_n=10.0)
    assert [m for m, *_ in f.modes] == [Mode.WATER, Mode.TRANSITION]
    assert _float_then_touch_down(f, s, 0.3) == Mode.TRANSITION
    assert f.mm.mode == Mode.TRANSITION


def test_back_to_water_from_an_ashore_transition_keeps_the_full_dwell(mode_settings):
    # WATER -> TRANSITION -> WATER is going back: min_dwell_s holds
    s = mode_settings
    f = _ashore_transition(s)
    f.run(s.min_dwell_s - 1.0, fraction=0.0, fore=True, aft=True, depth=True, force_n=10.0)
    assert f.mm.mode == Mode.TRANSITION
    f.run(1.5, fraction=0.0, fore=True, aft=True, depth=True, force_n=10.0)
    assert [m for m, *_ in f.modes] == [Mode.WATER, Mode.TRANSITION, Mode.WATER]


def test_an_ashore_dwell_beyond_min_dwell_is_refused(mode_settings):
    with pytest.raises(ValueError, match='ashore_dwell_s'):
        ModeSettings(**{**dataclasses.asdict(mode_settings),
                        'ashore_dwell_s': mode_settings.min_dwell_s + 1.0})


def test_grounded_in_the_surf_with_the_tracks_off_leaves_water(mode_settings):
    # the weight on the stopped tracks comes and goes with each wave (10-45 %), never above
    # water_exit_fraction for exit_water_s, and no track force: its mean says resting
    s = mode_settings
    f = Feed(s)
    f.run(s.min_dwell_s + 0.5, fraction=0.0, fore=True, aft=True, depth=True, force_n=10.0)
    assert f.mm.mode == Mode.WATER
    low, high = s.water_enter_fraction + 0.02, s.water_exit_fraction - 0.02
    for _ in range(4):                       # a 3.6 s wave period, below the exit threshold
        f.run(1.8, fraction=low, fore=True, aft=True, force_n=10.0)
        f.run(1.8, fraction=high, fore=True, aft=True, force_n=10.0)
    assert [m for m, *_ in f.modes] == [Mode.WATER, Mode.TRANSITION]
    assert 'mean' in f.modes[-1][2]


def test_afloat_troughs_touching_down_do_not_leave_water(mode_settings):
    s = mode_settings
    f = Feed(s)
    f.run(s.min_dwell_s + 0.5, fraction=0.0, fore=True, aft=True, depth=True, force_n=10.0)
    for _ in range(5):                       # a trough sets the tracks down 0.5 s a wave
        f.run(0.5, fraction=s.water_exit_fraction - 0.02, fore=True, aft=True, force_n=10.0)
        f.run(3.1, fraction=0.0, fore=True, aft=True, depth=True, force_n=10.0)
    assert [m for m, *_ in f.modes] == [Mode.WATER]


def test_a_resting_fraction_outside_the_hysteresis_is_refused(mode_settings):
    with pytest.raises(ValueError, match='resting_fraction'):
        ModeSettings(**{**dataclasses.asdict(mode_settings),
                        'resting_fraction': mode_settings.water_exit_fraction + 0.1})


def test_water_waits_for_the_estimator_to_say_afloat(mode_settings):
    """A receding wave leaves the estimated surface high (share near 0) over a hull the water
    has set down on the sand, lying still: the estimator's contact decision says the sand, and
    the mode stays in TRANSITION until it says afloat (issue 18, campaign runs 122, 139)."""
    s = mode_settings
    assert s.water_needs_estimated_afloat
    f = Feed(s)
    f.run(1.0, fraction=0.5, fore=True)
    f.run(s.min_dwell_s, fraction=0.5, fore=True, aft=True)
    f.run(3.0, fraction=0.0, fore=True, aft=True, force_n=10.0, afloat=False)
    assert f.mm.mode == Mode.TRANSITION
    f.run(s.enter_water_s - 0.1, fraction=0.0, fore=True, aft=True, force_n=10.0, afloat=True)
    assert f.mm.mode == Mode.TRANSITION           # debounced from the first afloat decision
    f.run(0.2, fraction=0.0, fore=True, aft=True, force_n=10.0, afloat=True)
    assert [m for m, *_ in f.modes] == [Mode.TRANSITION, Mode.WATER]


def test_without_the_estimator_afloat_rule_the_share_alone_decides(mode_settings):
    s = dataclasses.replace(mode_settings, water_needs_estimated_afloat=False)
    f = Feed(s)
    f.run(1.0, fraction=0.5, fore=True)
    f.run(s.min_dwell_s, fraction=0.5, fore=True, aft=True)
    f.run(s.enter_water_s + 1.0, fraction=0.0, fore=True, aft=True, force_n=10.0,
          afloat=False)
    assert f.mm.mode == Mode.WATER



def test_start_up_afloat_does_not_wait_for_the_estimator(mode_settings):
    """At start-up the estimator's motion test has no history (a hull lying still): the
    evidence of water alone classifies, as before the contact decision was heard."""
    f = Feed(mode_settings)
    f.run(0.1, fraction=0.0, fore=True, aft=True, depth=True, force_n=10.0, afloat=False)
    assert f.mm.mode == Mode.WATER


def _afloat(s):
    f = Feed(s)
    f.run(s.min_dwell_s + 0.5, fraction=0.0, fore=True, aft=True, depth=True, force_n=10.0)
    assert f.mm.mode == Mode.WATER
    return f


def test_afloat_both_sensors_dry_is_the_ground_holding_the_hulls_up(mode_settings):
    # a floating hull carries its sensors 0.19 m under the waterline: both dry means the
    # ground holds the hulls out of the water, though the estimated share still lags
    # (issue 18, seed 2027 runs 86, 158: WATER 0.4-0.5 s into the truth's first LAND)
    s = mode_settings
    assert s.water_exit_dry_s + 0.1 < s.exit_water_s
    f = _afloat(s)
    f.run(s.water_exit_dry_s + 0.1, fraction=0.05, force_n=10.0)
    assert f.mm.mode == Mode.TRANSITION
    assert 'both sensors dry' in f.modes[-1][2]
    f.run(s.ashore_enter_land_s + 0.1)
    assert [m for m, *_ in f.modes] == [Mode.WATER, Mode.TRANSITION, Mode.LAND]


def test_afloat_one_sensor_or_a_short_dry_spell_keeps_water(mode_settings):
    s = mode_settings
    f = _afloat(s)
    f.run(3.0, fraction=0.0, fore=True, depth=True, force_n=10.0)    # the bow pitched up
    f.run(3.0, fraction=0.0, aft=True, depth=True, force_n=10.0)
    for _ in range(5):                       # a deep trough bares both for a moment
        f.run(s.water_exit_dry_s - 2 * DT, fraction=0.0, depth=True, force_n=10.0)
        f.run(1.0, fraction=0.0, fore=True, aft=True, depth=True, force_n=10.0)
    assert [m for m, *_ in f.modes] == [Mode.WATER]


def test_afloat_dry_sensors_wait_for_the_dwell(mode_settings):
    s = mode_settings
    f = Feed(s)
    f.run(0.2, fraction=0.0, fore=True, aft=True, depth=True, force_n=10.0)
    assert f.mm.mode == Mode.WATER
    f.run(s.min_dwell_s - 0.2 - 2 * DT, fraction=0.0, force_n=10.0)
    assert f.mm.mode == Mode.WATER
    f.run(4 * DT, fraction=0.0, force_n=10.0)
    assert f.mm.mode == Mode.TRANSITION


def test_afloat_two_sensors_stuck_dry_over_deep_water_keep_water(mode_settings):
    """Fault: both wet/dry sensors fail dry in open water. The sounder still sees the water
    column under the hull (valid depth), so the hulls are not out of the water: WATER holds,
    no TRANSITION <-> WATER chatter; the same dry flags with no valid depth are grounded."""
    s = mode_settings
    f = _afloat(s)
    f.run(10.0, fraction=0.0, depth=True, force_n=10.0)
    assert [m for m, *_ in f.modes] == [Mode.WATER]
    f.run(s.water_exit_dry_s + 0.1, fraction=0.0, depth=False, force_n=10.0)
    assert f.mm.mode == Mode.TRANSITION and 'no valid depth' in f.modes[-1][2]
