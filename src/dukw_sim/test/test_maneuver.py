"""The maneuver tool: every sub-command, its CSV and JSON, bad arguments."""
import csv
import json
import math
import subprocess
import sys

import pytest
import yaml

from dukw_common.config import default_config_path
from dukw_sim import maneuver
from dukw_sim.core import SimCore

REQUIRED = ('t,x,y,yaw,u,v,r,z,roll,pitch,heave_vel,port_cmd,stbd_cmd,port_current_a,'
            'stbd_current_a,port_force_n,stbd_force_n,port_slip,stbd_slip,submerged_volume_m3,'
            'effective_weight_n').split(',')

CASES = [
    (['circle', '--medium', 'land', '--port', '44', '--stbd', '100', '--duration', '6'],
     ['radius_m', 'speed_mps', 'yaw_rate_dps'], 6.0),
    (['circle', '--medium', 'water', '--port', '100', '--stbd', '-100', '--duration', '4'],
     ['radius_m', 'turn'], 4.0),
    (['zigzag', '--medium', 'land', '--high', '56', '--low', '32', '--period', '1',
      '--duration', '3'], ['max_yaw_rate_dps', 'min_yaw_rate_dps'], 3.0),
    (['zigzag', '--medium', 'water', '--high', '80', '--low', '0', '--duration', '2'],
     ['speed_mps'], 2.0),
    (['incline', '--slope-deg', '11', '--command', '100', '--duration', '3'],
     ['mean_port_current_a', 'climbed_m', 'stalled'], 3.0),
    (['transition', '--direction', 'land-to-sea', '--command', '64', '--wave-height', '0.28',
      '--wave-period', '3.6', '--duration', '5'], ['t_first_water_s', 'contact_changes'], 5.0),
    (['transition', '--direction', 'sea-to-land', '--command', '100', '--slope-deg', '6',
      '--duration', '3'], ['end_medium', 'max_submerged_volume_m3'], 3.0),
    (['drift', '--wave-height', '0.08', '--duration', '4'],
     ['rms_heave_m', 'rms_roll_deg', 'rms_pitch_deg', 'rms_yaw_rate_dps'], 4.0),
]


@pytest.mark.parametrize('argv, keys, duration', CASES, ids=[c[0][0] + '-' + c[0][2]
                                                           for c in CASES])
def test_every_subcommand_writes_csv_and_json(argv, keys, duration, tmp_path, capsys):
    path = tmp_path / 'run.csv'
    assert maneuver.main(argv + ['--csv', str(path), '--seed', '3']) == 0
    out = capsys.readouterr().out.strip().splitlines()
    assert len(out) == 1
    summary = json.loads(out[0])
    assert summary['maneuver'] == argv[0]
    for key in keys:
        assert key in summary
    with open(path, newline='') as handle:
        rows = list(csv.DictReader(handle))
    assert set(REQUIRED) <= set(rows[0])
    assert len(rows) == round(duration / 0.01) + 1              # one row per 0.01 s
    times = [float(r['t']) for r in rows]
    assert times[0] == 0.0 and times[1] == pytest.approx(0.01)
    assert times[-1] == pytest.approx(duration)


def test_commands_are_raw_no_bias_added(tmp_path):
    path = tmp_path / 'c.csv'
    maneuver.main(['circle', '--medium', 'land', '--port', '60', '--stbd', '60',
                   '--duration', '1', '--csv', str(path)])
    with open(path, newline='') as handle:
        rows = list(csv.DictReader(handle))
    assert {float(r['port_cmd']) for r in rows[1:]} == {60.0}
    assert {float(r['stbd_cmd']) for r in rows[1:]} == {60.0}


def test_land_circle_turns_the_right_way():
    assert maneuver.circle('land', 44, 100, 8.0).summary['turn'] == 'port'
    assert maneuver.circle('land', 100, 44, 8.0).summary['turn'] == 'starboard'


def test_seed_changes_the_sea_and_repeats_it(capsys):
    argv = ['drift', '--wave-height', '0.28', '--duration', '3']
    maneuver.main(argv + ['--seed', '1'])
    maneuver.main(argv + ['--seed', '1'])
    maneuver.main(argv + ['--seed', '2'])
    a, b, c = capsys.readouterr().out.strip().splitlines()
    assert a == b and a != c


@pytest.mark.parametrize('argv', [
    [], ['spin'], ['circle', '--medium', 'land', '--port', '44'],
    ['circle', '--medium', 'mud', '--port', '44', '--stbd', '100'],
    ['circle', '--medium', 'land', '--port', '144', '--stbd', '100'],
    ['circle', '--medium', 'land', '--port', 'nan', '--stbd', '100'],
    ['zigzag', '--medium', 'land', '--high', '56', '--low', '32', '--period', '0'],
    ['incline', '--slope-deg', '-3', '--command', '100'],
    ['transition', '--direction', 'sideways', '--command', '64'],
    ['transition', '--direction', 'land-to-sea', '--command', '64', '--wave-height', '-1'],
    ['drift', '--wave-height', '0.1', '--duration', 'inf'],
    ['drift', '--wave-height', '0.1', '--seed', 'x'],
])
def test_bad_arguments_exit_2(argv, capsys):
    with pytest.raises(SystemExit) as exc:
        maneuver.main(argv)
    assert exc.value.code == 2
    assert capsys.readouterr().out == ''


def test_installed_console_script_runs():
    proc = subprocess.run([sys.executable, '-m', 'dukw_sim.maneuver', 'incline', '--slope-deg',
                           '19', '--command', '100', '--duration', '2'],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)['maneuver'] == 'incline'
    bad = subprocess.run([sys.executable, '-m', 'dukw_sim.maneuver', 'incline'],
                         capture_output=True, text=True, timeout=120)
    assert bad.returncode == 2 and 'usage' in bad.stderr


def test_circle_fit_recovers_a_circle():
    import numpy as np
    a = np.linspace(0, 5, 50)
    cx, cy, r = maneuver.fit_circle(3 + 2 * np.cos(a), -1 + 2 * np.sin(a))
    assert (cx, cy, r) == pytest.approx((3, -1, 2))
    with pytest.raises(ValueError):
        maneuver.fit_circle(np.zeros(2), np.zeros(2))


def test_drift_floats_in_the_surf_bow_to_the_beach():
    """Issue 13: the paper drifted in the surf, not off the slope: the 'sea' start (afloat
    over the slope, the treads start.sea_tread_clearance_m over the sand)."""
    run = maneuver.drift(0.28, 1.0, seed=3)
    start = run.rows[0]
    sim = SimCore.from_config()
    assert start.x_m == pytest.approx(sim.start_x_m('sea'))
    assert start.x_m < sim.world.beach.sea_floor_x_m            # over the slope
    assert abs(abs(start.yaw_rad) - math.pi) < 1e-9             # bow to the beach
    assert not any(t.in_ground_contact for t in run.rows[:10])  # afloat


def test_drift_held_by_a_line_from_seaward_stays_off_the_beach_bow_first(tmp_path):
    """Issue 13, mooring.model 'line': a person seaward of the stern holds a tension-only
    line; the waves' mean drift keeps it taut on average, so the vehicle stays within the
    line's reach of the hand, afloat and bow to the beach (the spring lets it 0.7 m in)."""
    doc = yaml.safe_load(default_config_path().read_text())
    moor = doc['sim_node']['ros__parameters']['mooring']
    moor['model'] = 'line'
    config = tmp_path / 'line.yaml'
    config.write_text(yaml.safe_dump(doc))
    held = maneuver.drift(0.28, 30.0, seed=0, config=str(config))
    sprung = maneuver.drift(0.28, 30.0, seed=0)
    reach_m = moor['line_holder_distance_m'] + moor['line_slack_m']
    assert 0.0 < held.summary['mean_shoreward_offset_m'] < 0.5 * reach_m
    assert sprung.summary['mean_shoreward_offset_m'] > held.summary['mean_shoreward_offset_m']
    assert max(t.x_m for t in held.rows) - held.rows[0].x_m < reach_m   # never past the hand
    assert all(abs(abs(t.yaw_rad) - math.pi) < math.radians(30.0) for t in held.rows)
    assert sum(t.in_ground_contact for t in held.rows) < 0.05 * len(held.rows)
