"""The bring-up runner: stack files, starting, a node dying, Ctrl-C, the launch file."""
import os
import py_compile
import re
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from dukw_bringup.bringup import load_stack, parse_stack, stack_path
from dukw_common.config import ConfigError

PACKAGE = Path(__file__).resolve().parents[1]
SMALL_STACK = """
stack:
  name: small
  nodes:
    - {name: sim_node, package: dukw_sim, executable: sim_node}
    - {name: mission_node, package: dukw_bringup, executable: mission_node}
"""


def test_workspace_stacks_parse():
    sim = load_stack(stack_path('sim'))
    boat = load_stack(stack_path('boat'))
    assert [n.name for n in sim.nodes][0] == 'sim_node'
    assert 'mission_node' in [n.name for n in sim.nodes]
    assert 'sim_node' not in [n.name for n in boat.nodes]
    assert {'servo_switch_node', 'imu_gps_node', 'water_sensor_node'} <= {
        n.executable for n in boat.nodes}


@pytest.mark.parametrize('shape', ['sim', 'boat'])
def test_both_stack_shapes_load_with_the_same_nodes(shape):
    """One process per node (sim, boat) and the control chain composed (sim_composed, the
    main job's; boat_composed) run the same ROS nodes; the composed process lists its
    nodes as arguments."""
    from dukw_bringup.bringup import node_command
    separate = load_stack(stack_path(shape))
    composed = load_stack(stack_path(f'{shape}_composed'))
    assert sorted(separate.node_names()) == sorted(composed.node_names())
    assert all(not spec.composes for spec in separate.nodes)
    chain = composed.node('control_chain')
    assert {'ekf_node', 'mode_manager_node', 'drive_controller_node'} <= set(chain.composes)
    assert len(composed.nodes) < len(separate.nodes)
    command = node_command(chain, [Path('p.yaml')], composed.uses_sim_time(chain))
    assert command[0].endswith('lib/dukw_bringup/compose')
    ros_args = command.index('--ros-args')
    assert command[1:ros_args] == list(chain.composes)
    assert '__node:=' not in ' '.join(command)          # a rename would rename them all


@pytest.mark.parametrize('shape', ['sim', 'boat', 'sim_composed', 'boat_composed'])
def test_every_shape_publishes_traction_at_20_hz(shape):
    """README "Topic contract": traction's readers need 20 Hz (the mode manager decides at
    20 Hz, the controller's stuck detection holds 3 s), in both shapes."""
    stack = load_stack(stack_path(shape))
    ekf = next(spec for spec in stack.nodes if 'ekf_node' in spec.node_names)
    assert 'traction_rate_hz:=20.0' in ekf.args


def test_the_run_overlay_puts_every_composed_node_on_sim_time(tmp_path):
    from dukw_bringup.mission import load_mission
    from dukw_bringup.run_setup import prepare_run
    from dukw_common.config import default_config_path, load_file
    stack = load_stack(stack_path('sim_composed'))
    _, overlay = prepare_run(tmp_path, default_config_path(), stack, load_mission(), 1.0)
    params = load_file(overlay)
    for name in stack.node('control_chain').composes:
        assert params[name]['use_sim_time'] is True, name


def test_sim_stack_runs_every_node_but_the_simulator_on_sim_time():
    from dukw_bringup.bringup import node_command
    for name, expected in (('sim', True), ('sim_composed', True), ('boat', False),
                           ('boat_composed', False)):
        stack = load_stack(stack_path(name))
        for spec in stack.nodes:
            command = node_command(spec, [], stack.uses_sim_time(spec))
            on_sim_time = 'use_sim_time:=true' in command
            assert on_sim_time == (expected and spec.name != 'sim_node'), (name, spec.name)


def test_both_stacks_keep_the_ros_graph_on_the_vehicle_unless_told_otherwise():
    from dukw_bringup.bringup import DISCOVERY_ENV, Runner
    for name in ('sim', 'sim_composed', 'boat', 'boat_composed'):
        stack = load_stack(stack_path(name))
        assert Runner(stack, env={DISCOVERY_ENV: ''}).env[DISCOVERY_ENV] == 'LOCALHOST'
        assert Runner(stack, env={DISCOVERY_ENV: 'SUBNET'}).env[DISCOVERY_ENV] == 'SUBNET'


@pytest.mark.parametrize('doc,message', [
    ({}, 'top-level "stack"'),
    ({'stack': {'nodes': []}}, 'non-empty'),
    ({'stack': {'nodes': [{'name': 'a', 'package': 'p'}]}}, 'executable'),
    ({'stack': {'nodes': [{'name': 'a b', 'package': 'p', 'executable': 'e'}]}}, 'name'),
    ({'stack': {'nodes': [{'name': 'a', 'package': 'p', 'executable': 'e', 'args': 'x'}]}},
     'args'),
    ({'stack': {'nodes': [{'name': 'a', 'package': 'p', 'executable': 'e'}] * 2}}, 'unique'),
    ({'stack': {'clock_node': 'b', 'nodes': [{'name': 'a', 'package': 'p', 'executable': 'e'}]}},
     'clock_node'),
    ({'stack': {'discovery_range': 'WORLD',
                'nodes': [{'name': 'a', 'package': 'p', 'executable': 'e'}]}}, 'discovery_range'),
    ({'stack': {'nodes': [{'name': 'a', 'package': 'p', 'executable': 'e',
                           'composes': 'ekf_node'}]}}, 'composes'),
    ({'stack': {'nodes': [{'name': 'a', 'package': 'p', 'executable': 'e', 'rename': True,
                           'composes': ['ekf_node']}]}}, 'rename'),
    ({'stack': {'nodes': [{'name': 'ekf_node', 'package': 'p', 'executable': 'e'},
                          {'name': 'c', 'package': 'p', 'executable': 'e',
                           'composes': ['ekf_node']}]}}, 'runs twice'),
    *[({'stack': {'nodes': [{'name': 'a', 'package': 'p', 'executable': 'e',
                             'realtime_priority': bad}]}}, 'realtime_priority')
      for bad in (99, -1, 'high', True, 20.0)],
])
def test_bad_stack_file_is_refused(doc, message):
    with pytest.raises(ConfigError, match=message):
        parse_stack(doc)


def test_the_chain_and_the_boat_devices_at_its_ends_run_under_sched_fifo():
    for name in ('sim', 'sim_composed', 'boat', 'boat_composed'):
        stack = load_stack(stack_path(name))
        fifo = {n.name for n in stack.nodes if n.realtime_priority}
        chain = ({'control_chain'} if 'composed' in name
                 else {'ekf_node', 'mode_manager_node', 'drive_controller_node'})
        devices = set() if name.startswith('sim') else {'imu_gps_node', 'servo_switch_node'}
        assert fifo == chain | devices
        priority = {n.name: n.realtime_priority for n in stack.nodes}
        assert all(priority[d] < priority[c] for d in devices for c in chain)
        normal = stack.at_normal_priority()     # (main_job faster than real time)
        assert [n.name for n in normal.nodes] == [n.name for n in stack.nodes]
        assert not any(n.realtime_priority for n in normal.nodes)
        # not the simulator: at real_time_factor 0 it steps flat out, a real-time hog


def test_a_process_gets_its_realtime_priority_or_the_runner_says_why_not():
    from dukw_bringup.bringup import _child_setup, realtime_refusal
    allowed = os.geteuid() == 0 or resource.getrlimit(resource.RLIMIT_RTPRIO)[0] >= 10
    procs = [subprocess.Popen(['sleep', '10'], preexec_fn=_child_setup(p)) for p in (10, 0)]
    try:
        fifo, normal = procs
        assert realtime_refusal(normal.pid, 0) == ''
        assert 'refused' in realtime_refusal(normal.pid, 10)      # asked, not granted
        if allowed:
            assert os.sched_getscheduler(fifo.pid) == os.SCHED_FIFO
            assert realtime_refusal(fifo.pid, 10) == ''
            assert 'refused' in realtime_refusal(fifo.pid, 11)
        else:
            assert 'CAP_SYS_NICE' in realtime_refusal(fifo.pid, 10)
    finally:
        for proc in procs:
            proc.kill()
            proc.wait()


def test_launch_file_compiles(tmp_path):
    py_compile.compile(str(PACKAGE / 'launch' / 'stack.launch.py'),
                       cfile=str(tmp_path / 'launch.pyc'), doraise=True)


class Bringup:
    """The installed `bringup` console script on a stack file, output collected."""

    def __init__(self, stack_file: Path, *args: str) -> None:
        from dukw_bringup.bringup import node_executable
        self.proc = subprocess.Popen(
            [str(node_executable('dukw_bringup', 'bringup')), str(stack_file), *args],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)

    def wait_started(self, count: int, timeout_s: float = 30.0) -> dict[str, int]:
        """Read output until ``count`` nodes have started; return their pids."""
        pids: dict[str, int] = {}
        deadline = time.monotonic() + timeout_s
        while len(pids) < count and time.monotonic() < deadline:
            line = self.proc.stdout.readline()
            match = re.search(r'started (\w+) \(pid (\d+)\)', line)
            if match:
                pids[match.group(1)] = int(match.group(2))
        return pids

    def finish(self, timeout_s: float = 60.0) -> tuple[int, str, str]:
        out, err = self.proc.communicate(timeout=timeout_s)
        return self.proc.returncode, out, err


def wait_in_graph(names, timeout_s: float = 30.0) -> bool:
    """True once every node in ``names`` is on the ROS graph (up, signal handlers set)."""
    from dukw_common.testing import ros_node, spin_until
    with ros_node('bringup_probe') as (probe, executor):
        return spin_until(executor, lambda: set(names) <= set(probe.get_node_names()),
                          timeout_s)


def alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return True


@pytest.mark.ros
@pytest.mark.slow
def test_a_node_that_dies_stops_the_stack_with_an_error(tmp_path):
    stack = tmp_path / 'stack.yaml'
    stack.write_text(SMALL_STACK)
    runner = Bringup(stack)
    pids = runner.wait_started(2)
    assert set(pids) == {'sim_node', 'mission_node'}
    assert wait_in_graph(pids)
    os.kill(pids['sim_node'], signal.SIGKILL)
    code, _, err = runner.finish()
    assert code == 1
    assert 'sim_node exited unexpectedly (killed by signal 9)' in err
    assert not alive(pids['mission_node'])


@pytest.mark.ros
@pytest.mark.slow
def test_ctrl_c_stops_every_node_in_reverse_order_and_exits_0(tmp_path):
    stack = tmp_path / 'stack.yaml'
    stack.write_text(SMALL_STACK)
    runner = Bringup(stack, '--log-dir', str(tmp_path / 'logs'), '--quiet')
    pids = runner.wait_started(2)
    assert wait_in_graph(pids)
    runner.proc.send_signal(signal.SIGINT)
    code, out, err = runner.finish()
    assert code == 0, err
    assert not any(alive(pid) for pid in pids.values())
    stopped = re.findall(r'(\w+) stopped \(exit (-?\d+)\)', out)
    assert stopped == [('mission_node', '0'), ('sim_node', '0')]
    assert 'waiting for odometry' in (tmp_path / 'logs' / 'mission_node.log').read_text()


@pytest.mark.ros
def test_missing_package_is_a_clear_error(tmp_path):
    stack = tmp_path / 'stack.yaml'
    stack.write_text('stack: {nodes: [{name: x, package: no_such_pkg, executable: x}]}\n')
    result = subprocess.run([sys.executable, '-m', 'dukw_bringup.bringup', str(stack)],
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 2
    assert "package 'no_such_pkg' is not installed" in result.stderr
