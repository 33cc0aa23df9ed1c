"""The field procedure through real processes: maneuver_node zigzag on sim_node, recorded
with the project's recorder, identified by sysid from the bag."""
import json
import time

import pytest

from dukw_bringup.record import Recorder
from dukw_common.testing import NodeProcess, ros_node, spin_until
from dukw_estimation.sysid_cli import main

pytestmark = [pytest.mark.ros, pytest.mark.timeout(120)]

PERIOD_S = 3.0
DURATION_S = 12.0


def test_maneuver_node_zigzag_recorded_and_identified(tmp_path, capsys):
    bag = tmp_path / 'zigzag'
    sim_args = ['--ros-args', '-p', 'start_at:=afloat', '-p', 'real_time_factor:=1.0']
    zigzag = ['--ros-args', '-p', 'maneuver:=zigzag', '-p', 'actuators:=props',
              '-p', 'high_pct:=80.0', '-p', 'low_pct:=0.0', '-p', f'period_s:={PERIOD_S}',
              '-p', f'duration_s:={DURATION_S}']
    with ros_node('sysid_recorder') as (node, executor):
        recorder = Recorder(node, bag, ['props/cmd', 'sim/truth'], rescan_period_s=0.2)
        with NodeProcess('dukw_sim', 'sim_node', sim_args) as sim:
            assert spin_until(executor, lambda: recorder.counts.get('/sim/truth', 0) > 50,
                              30.0), sim.stderr
            with NodeProcess('dukw_control', 'maneuver_node', zigzag) as player:
                deadline = time.monotonic() + DURATION_S + 30.0
                while player.alive() and time.monotonic() < deadline:
                    executor.spin_once(timeout_sec=0.05)
                assert not player.alive(), 'maneuver_node should exit when done'
        recorder.close()
    assert player.proc.returncode == 0, player.stderr
    assert main(['identify', '--medium', 'water', '--truth', '--min-duration', '8',
                 '--out', str(tmp_path / 'water.yaml'), str(bag)]) == 0
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert summary['medium'] == 'water' and summary['order'] == 3
    assert summary['fit_pct']['r'] >= 70.0, summary
