"""The main job: run folder and overlay (no ROS), and a short run end to end (slow)."""
import datetime as dt
import json
import math
import signal
import subprocess
from pathlib import Path

import pytest
import yaml

from dukw_bringup.bag_io import summarize
from dukw_bringup.bringup import load_stack, node_executable, stack_path
from dukw_bringup.mission import MissionState, Progress, load_mission, parse_mission
from dukw_bringup.plots import PLOT_FILES
from dukw_bringup.run_setup import (default_run_dir, format_progress, make_run_dir,
                                    mission_document, prepare_run, with_recorder,
                                    with_shore_link)
from dukw_common.config import ConfigError, default_config_path, load_file

SUMMARY_KEYS = ('reached', 'state', 'time_s', 'mode_timeline', 'track_currents',
                'prop_currents', 'current_limit_a', 'slip', 'submersion', 'ending', 'bag')


def test_default_run_dir_is_a_utc_timestamp(tmp_path):
    now = dt.datetime(2026, 11, 22, 1, 2, 3, tzinfo=dt.timezone.utc)
    assert default_run_dir(tmp_path, now) == tmp_path / 'runs' / '20261122T010203Z'


def test_a_folder_holding_a_run_is_refused(tmp_path):
    make_run_dir(tmp_path / 'new')
    (tmp_path / 'new' / 'summary.json').write_text('{}')
    with pytest.raises(ConfigError, match='already holds a run'):
        make_run_dir(tmp_path / 'new')


def test_prepare_run_writes_config_mission_and_overlay(tmp_path):
    spec = load_mission().with_waypoints(2)
    stack = with_recorder(load_stack(stack_path('sim')), tmp_path / 'bag')
    config, overlay = prepare_run(tmp_path, default_config_path(), stack, spec, 2.5)
    assert config.read_text() == default_config_path().read_text()
    assert load_mission(tmp_path / 'mission.yaml') == spec
    nodes = load_file(overlay)           # a valid ROS 2 parameter file
    assert nodes['sim_node']['real_time_factor'] == 2.5
    assert nodes['sim_node']['start_at'] == 'sand'
    assert nodes['sim_node']['start.sand_x_m'] == pytest.approx(-10.0)
    assert nodes['sim_node']['waves.model'] == 'irregular'
    assert nodes['sim_node']['waves.significant_height_m'] == pytest.approx(0.28)
    assert 'use_sim_time' not in nodes['sim_node']          # the sim makes /clock
    for name in ('recorder', 'ekf_node', 'drive_controller_node', 'mission_node', 'main_job'):
        assert nodes[name]['use_sim_time'] is True
    assert nodes['mission_node']['mission_file'] == str(tmp_path / 'mission.yaml')
    assert stack.nodes[0].name == 'recorder'                 # first up, last down
    sim = load_stack(stack_path('sim'))                      # the stack's graph settings stay
    for extended in (stack, with_shore_link(stack)):
        assert (extended.clock_node, extended.discovery_range) == (sim.clock_node,
                                                                   sim.discovery_range)
        assert extended.discovery_range == 'LOCALHOST'
    with pytest.raises(ConfigError, match='real-time factor'):
        prepare_run(tmp_path / 'x', default_config_path(), stack, spec, -1.0)


def test_mission_document_round_trips():
    spec = load_mission()
    assert parse_mission(yaml.safe_load(yaml.safe_dump(mission_document(spec)))) == spec


def test_progress_line_shows_mode_waypoint_speed_and_currents():
    progress = Progress(state=MissionState.RUNNING, waypoint_index=1, waypoint_name='offshore',
                        waypoints_total=5, distance_m=12.34)
    line = format_progress(42.0, 'WATER', progress, 1.05, (20.0, 21.5), (30.0, math.nan))
    for part in ('t=  42.0s', 'WATER', 'wp 2/5 offshore', '12.3 m', 'speed 1.05 m/s',
                 'tracks 20.0/21.5 A', 'props 30.0/-- A'):
        assert part in line
    assert 'mission done' in format_progress(0.0, 'LAND', Progress(state=MissionState.DONE),
                                             0.0, (0, 0), (0, 0))


def main_job(out: Path, *args: str) -> subprocess.Popen:
    return subprocess.Popen([str(node_executable('dukw_bringup', 'main_job')), '--out', str(out),
                             *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def check_run_folder(out: Path, stdout: str) -> dict:
    assert stdout.strip().splitlines()[-1] == str(out)
    bag = summarize(out / 'bag')                    # readable, metadata written
    summary = json.loads((out / 'summary.json').read_text())
    for key in SUMMARY_KEYS:
        assert key in summary, key
    for name in PLOT_FILES:
        assert (out / name).read_bytes().startswith(b'\x89PNG'), name
    return {'bag': bag, 'summary': summary}


@pytest.mark.ros
@pytest.mark.slow
@pytest.mark.timeout(240)
def test_short_main_job_leaves_bag_summary_and_plots(tmp_path):
    out = tmp_path / 'run'
    proc = main_job(out, '--waypoints', '1', '--time-limit', '120', '--rtf', '2')
    stdout, stderr = proc.communicate(timeout=200)
    result = check_run_folder(out, stdout)
    summary = result['summary']
    assert proc.returncode == 0, f'{summary.get("ending")}; see {out}/logs\n{stderr}'
    assert summary['reached'] is True and summary['waypoints_reached'] == 1
    assert 'LAND' in [m['mode'] for m in summary['mode_timeline']]
    topics = set(summary['bag_topics'])
    assert {'/clock', '/sim/truth', '/imu/data', '/odometry/filtered', '/cmd_vel',
            '/tracks/cmd', '/tracks/status', '/traction', '/drive_mode',
            '/mission/status', '/tf', '/tf_static', '/robot_description',
            '/live_view/beach'} <= topics
    assert '[main_job] live view: ws://127.0.0.1:' in stdout
    assert summary['track_currents']['port']['peak_a'] > 0.0


@pytest.mark.ros
@pytest.mark.slow
@pytest.mark.timeout(240)
def test_ctrl_c_still_closes_the_bag_and_writes_the_summary(tmp_path):
    out = tmp_path / 'run'
    proc = main_job(out, '--time-limit', '120')
    for line in proc.stdout:  # wait until the stack is up and a progress line came
        if line.startswith('[main_job] t='):
            break
    proc.send_signal(signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 130, stderr
    result = check_run_folder(out, stdout)
    assert result['summary']['ending'] == 'interrupted'
