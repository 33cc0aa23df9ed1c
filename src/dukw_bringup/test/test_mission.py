"""The ROS-free mission core: mission file, line of sight, waypoint switching, stop."""
import math

import pytest
import yaml

from dukw_bringup.mission import (STOP, LosGuidance, MissionState, Progress, line_of_sight,
                                  load_mission, parse_mission)
from dukw_common.config import ConfigError

MISSION = {'mission': {
    'name': 'test', 'start': {'x_m': -10.0, 'yaw_rad': 0.0},
    'sea': {'significant_height_m': 0.28, 'peak_period_s': 3.57, 'seed': 1},
    'timeout_s': 100.0, 'acceptance_radius_m': 1.0, 'lookahead_m': 3.0,
    'heading_gain_per_s': 1.0, 'max_yaw_rate_rps': 0.5, 'min_speed_fraction': 0.2,
    'waypoints': [{'name': 'a', 'x_m': 0.0, 'y_m': 0.0, 'speed_mps': 1.0},
                  {'name': 'b', 'x_m': 0.0, 'y_m': 10.0, 'speed_mps': 0.5}]}}


def simulate(guidance, x, y, yaw, t_end_s, dt_s=0.1):
    """Unicycle that does exactly what guidance asks; returns the path."""
    guidance.start(0.0, x, y)
    path, t = [(x, y)], 0.0
    while t < t_end_s and not guidance.progress.state.finished:
        cmd = guidance.update(t, x, y, yaw)
        yaw += cmd.yaw_rate_rps * dt_s
        x += cmd.speed_mps * math.cos(yaw) * dt_s
        y += cmd.speed_mps * math.sin(yaw) * dt_s
        t += dt_s
        path.append((x, y))
    return path


def test_workspace_mission_file_is_the_land_sea_land_mission():
    spec = load_mission()
    assert spec.start.x_m == pytest.approx(-10.0)
    assert spec.sea.significant_height_m == pytest.approx(0.28)
    xs = [wp.x_m for wp in spec.waypoints]
    assert max(xs) >= 20.0 and xs[-1] < 0.0      # swims 20 m out, ends on the sand


def test_line_of_sight_steers_back_to_the_leg():
    heading, cross, along = line_of_sight(5.0, 2.0, (0.0, 0.0), (10.0, 0.0), 2.0)
    assert cross == pytest.approx(2.0) and along == pytest.approx(5.0)
    assert heading == pytest.approx(-math.pi / 4)  # 2 m left, 2 m lookahead: 45 deg to the right
    heading, cross, _ = line_of_sight(5.0, 0.0, (0.0, 0.0), (10.0, 0.0), 2.0)
    assert heading == pytest.approx(0.0) and cross == pytest.approx(0.0)


def test_guidance_visits_every_waypoint_and_stops():
    guidance = LosGuidance(parse_mission(MISSION))
    path = simulate(guidance, -10.0, 0.5, 0.3, t_end_s=90.0)
    assert guidance.progress.state is MissionState.DONE
    assert len(guidance.progress.reached_s) == 2
    assert min(math.hypot(x, y) for x, y in path) < 1.0
    assert min(math.hypot(x, y - 10.0) for x, y in path) < 1.0
    assert guidance.update(100.0, 0.0, 10.0, 0.0) == STOP


def test_guidance_times_out_and_stops():
    doc = yaml.safe_load(yaml.safe_dump(MISSION))
    doc['mission']['timeout_s'] = 3.0
    guidance = LosGuidance(parse_mission(doc))
    simulate(guidance, -10.0, 0.0, 0.0, t_end_s=10.0)
    assert guidance.progress.state is MissionState.TIMEOUT
    assert guidance.update(20.0, 0.0, 0.0, 0.0) == STOP


def test_no_command_before_start_or_after_abort():
    guidance = LosGuidance(parse_mission(MISSION))
    assert guidance.update(0.0, -10.0, 0.0, 0.0) == STOP
    guidance.start(0.0, -10.0, 0.0)
    assert guidance.update(0.1, -10.0, 0.0, 0.0).speed_mps == pytest.approx(1.0)
    guidance.abort()
    assert guidance.progress.state is MissionState.ABORTED
    assert guidance.update(0.2, -10.0, 0.0, 0.0) == STOP


def test_speed_drops_and_yaw_rate_saturates_with_a_large_heading_error():
    guidance = LosGuidance(parse_mission(MISSION))
    guidance.start(0.0, -10.0, 0.0)
    cmd = guidance.update(0.1, -10.0, 0.0, math.pi)  # facing away from the waypoint
    assert cmd.speed_mps == pytest.approx(0.2)
    assert abs(cmd.yaw_rate_rps) == pytest.approx(0.5)


def test_passing_a_waypoint_outside_the_radius_still_switches_legs():
    guidance = LosGuidance(parse_mission(MISSION))
    guidance.start(0.0, -10.0, 0.0)
    guidance.update(1.0, 0.5, -3.0, 0.0)  # beyond the end of leg 1, 3 m off
    assert guidance.progress.waypoint_index == 1 and guidance.progress.waypoint_name == 'b'


def test_nan_pose_is_refused_and_changes_nothing():
    guidance = LosGuidance(parse_mission(MISSION))
    guidance.start(0.0, -10.0, 0.0)
    before = Progress.from_json(guidance.progress.to_json())
    with pytest.raises(ValueError, match='finite'):
        guidance.update(1.0, math.nan, 0.0, 0.0)
    assert guidance.progress == before


def test_progress_json_round_trip():
    progress = Progress(state=MissionState.RUNNING, waypoint_index=1, waypoint_name='b',
                        waypoints_total=2, distance_m=3.5, reached_s=[4.0])
    assert Progress.from_json(progress.to_json()) == progress
    with pytest.raises(ValueError):
        Progress.from_json('{"state": "flying"}')


@pytest.mark.parametrize('change,message', [
    (lambda m: m['mission'].pop('waypoints'), 'waypoints'),
    (lambda m: m['mission'].update(waypoints=[]), 'at least one'),
    (lambda m: m['mission'].update(lookahead_m=0.0), 'lookahead_m'),
    (lambda m: m['mission'].update(timeout_s='long'), 'timeout_s'),
    (lambda m: m['mission']['waypoints'][0].update(speed_mps=5.0), 'speed_mps'),
    (lambda m: m['mission']['waypoints'][1].pop('y_m'), r'waypoints\[1\].y_m'),
    (lambda m: m['mission']['sea'].update(seed=1.5), 'seed'),
])
def test_bad_mission_is_refused_naming_the_field(change, message):
    doc = yaml.safe_load(yaml.safe_dump(MISSION))
    change(doc)
    with pytest.raises(ConfigError, match=message):
        parse_mission(doc)


def test_unreadable_mission_file(tmp_path):
    with pytest.raises(ConfigError, match='cannot read'):
        load_mission(tmp_path / 'none.yaml')
    bad = tmp_path / 'bad.yaml'
    bad.write_text('mission: [unclosed\n')
    with pytest.raises(ConfigError, match='not valid YAML'):
        load_mission(bad)


def test_cut_mission_keeps_the_first_waypoints():
    spec = parse_mission(MISSION).with_waypoints(1)
    assert [wp.name for wp in spec.waypoints] == ['a']
    with pytest.raises(ConfigError):
        spec.with_waypoints(3)


def test_a_plan_from_shore_replaces_the_waypoints_and_keeps_the_rest():
    from dukw_bringup.mission import spec_with_plan
    spec = load_mission()
    plan = '{"waypoints": [{"name": "a", "x_m": -6, "y_m": 0, "speed_mps": 0.8}, ' \
           '{"name": "b", "x_m": -6, "y_m": 4, "speed_mps": 0.8}]}'
    new = spec_with_plan(spec, plan)
    assert [(w.name, w.x_m, w.y_m) for w in new.waypoints] == [('a', -6.0, 0.0), ('b', -6.0, 4.0)]
    assert new.timeout_s == spec.timeout_s and new.start == spec.start
    assert spec_with_plan(spec, '{"waypoints": []}') is None
    for bad, message in (('nope', 'not JSON'), ('{}', 'waypoints'),
                         ('{"waypoints": [{"x_m": 1, "y_m": 0, "speed_mps": 9}]}', 'speed')):
        with pytest.raises(ConfigError, match=message):
            spec_with_plan(spec, bad)
