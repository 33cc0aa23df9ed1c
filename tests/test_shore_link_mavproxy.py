"""MAVProxy (pinned, installed --no-deps: requirements-nodeps.txt) as the stock ground station of
shore_link_node, started as the README says (udpin on the node's udpout, ``signing key
<passphrase>``, ``set param_ftp 0``), driven through its console's stdin. With the passphrase it
sees the position move, reads and sets a whitelisted parameter, uploads a two-waypoint mission
(``wp load``) that reaches the mission node's ``mission/plan``, starts and stops it
(``long MISSION_START``, ``long DO_PAUSE_CONTINUE 0``); with a wrong key or none (``signing key
WRONG``, ``signing remove``) its uploads change nothing and its parameter requests go unanswered.
"""
import hashlib
import json
import os
import re
import shutil
import socket
import subprocess
import threading
import time

import pytest
from dukw_msgs.srv import SetMode
from nav_msgs.msg import Odometry
from std_msgs.msg import Bool, String

from dukw_common.geometry import local_enu_from_geodetic
from dukw_common.node_tools import SENSOR_QOS, STATE_QOS
from dukw_common.testing import NodeProcess, ros_node, spin_until

PASSPHRASE = 'beach-day-28cm'
DATUM = (36.1836, -75.7510)
MISSION = ((36.18370, -75.75090), (36.18380, -75.75070))     # ~14 m and ~35 m north-east
STRANGERS_MISSION = ((36.18500, -75.74900),)
SPEED_MPS = 0.5


def free_udp_port():
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        sock.bind(('127.0.0.1', 0))
        return sock.getsockname()[1]


def write_qgc_wpl(path, points):
    """A QGC WPL 110 file: seq current frame command p1-p4 lat lon alt autocontinue."""
    rows = [f'{seq}\t{int(seq == 0)}\t3\t16\t0\t0\t0\t0\t{lat:.7f}\t{lon:.7f}\t0\t1'
            for seq, (lat, lon) in enumerate(points)]
    path.write_text('\n'.join(['QGC WPL 110', *rows]) + '\n')
    return path


class MavProxy:
    """MAVProxy on udpin (commands on its console's stdin, output collected by a thread)."""

    def __init__(self, cwd, port, startup):
        self.proc = subprocess.Popen(
            [shutil.which('mavproxy.py'), f'--master=udpin:127.0.0.1:{port}', f'--cmd={startup}'],
            cwd=cwd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
            text=True, env={**os.environ, 'PYTHONUNBUFFERED': '1'})   # lines as printed
        self.lines: list[str] = []
        threading.Thread(target=lambda: self.lines.extend(self.proc.stdout), daemon=True).start()

    def count(self, text):
        return sum(text in line for line in list(self.lines))

    def command(self, line):
        self.proc.stdin.write(line + '\n')
        self.proc.stdin.flush()

    def close(self):
        self.proc.terminate()
        try:
            self.proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            self.proc.kill()
        return ''.join(self.lines)


class Stack:
    """The rest of the vehicle, seen from ROS: odometry moving east, mission/plan and /hold,
    the mode manager's set_mode service (recording what it is asked)."""

    def __init__(self, probe, executor):
        self.executor = executor
        self.start_s = time.monotonic()
        self.plans: list[dict] = []
        self.holds: list[bool] = []
        self.odom_pub = probe.create_publisher(Odometry, 'odometry/filtered', SENSOR_QOS)
        probe.create_subscription(String, 'mission/plan',
                                  lambda m: self.plans.append(json.loads(m.data)), STATE_QOS)
        probe.create_subscription(Bool, 'mission/hold', lambda m: self.holds.append(m.data),
                                  STATE_QOS)
        probe.create_timer(0.1, self._publish_odometry)
        self.mode_requests: list[tuple[int, bool]] = []
        probe.create_service(SetMode, 'set_mode', self._set_mode)    # the mode manager's

    def _set_mode(self, request, response):
        self.mode_requests.append((request.mode, request.automatic))
        response.success, response.message = True, 'ok'
        return response

    def _publish_odometry(self):
        msg = Odometry()
        msg.pose.pose.position.x = 0.5 * (time.monotonic() - self.start_s)   # east at 0.5 m/s
        msg.pose.pose.orientation.w = 1.0
        msg.twist.twist.linear.x = 0.5
        self.odom_pub.publish(msg)

    def wait(self, predicate, timeout_s):
        return spin_until(self.executor, predicate, timeout_s)


def status_field(gcs, stack, message, field):
    """Ask ``status MESSAGE`` (once a second until MAVProxy has one); the field's integer."""
    pattern = message + r' \{.*?\b' + field + r' : (-?\d+)'
    asked = len(re.findall(pattern, ''.join(gcs.lines)))

    def answered():
        return re.findall(pattern, ''.join(gcs.lines))[asked:]

    for _ in range(10):
        gcs.command(f'status {message}')
        if stack.wait(answered, 1.0):
            return int(answered()[-1])
    raise AssertionError(''.join(gcs.lines))


def expected_plan():
    return [local_enu_from_geodetic(lat, lon, 0.0, *DATUM, 0.0)[:2] for lat, lon in MISSION]


@pytest.mark.ros
@pytest.mark.slow
@pytest.mark.timeout(180)
def test_mavproxy_with_the_passphrase_commands_and_without_it_cannot(tmp_path):
    key_file = tmp_path / 'shore.key'
    key_file.write_text(hashlib.sha256(PASSPHRASE.encode()).hexdigest())
    mission = write_qgc_wpl(tmp_path / 'plan.txt', MISSION)
    strangers = write_qgc_wpl(tmp_path / 'strangers.txt', STRANGERS_MISSION)
    port = free_udp_port()
    node = NodeProcess('dukw_driver', 'shore_link_node', [
        '--ros-args', '-p', f'url:=udpout:127.0.0.1:{port}', '-p',
        f'signing_key_file:={key_file}', '-p', f'datum.latitude_deg:={DATUM[0]}', '-p',
        f'datum.longitude_deg:={DATUM[1]}', '-p', f'mission_speed_mps:={SPEED_MPS}'])
    try:
        with ros_node('probe_mavproxy') as (probe, executor):
            stack = Stack(probe, executor)
            gcs = MavProxy(tmp_path, port, f'set param_ftp 0; signing key {PASSPHRASE}')
            try:
                run_the_session(gcs, stack, mission, strangers)
            finally:
                gcs.close()
    finally:
        code = node.stop()
    assert code == 0, node.stderr


def run_the_session(gcs, stack, mission, strangers):
    assert stack.wait(lambda: gcs.count('Detected vehicle 1:1'), 30.0), gcs.lines
    # (1) the position moves: GLOBAL_POSITION_INT now and 3 s later, east = lon grows
    first = status_field(gcs, stack, 'GLOBAL_POSITION_INT', 'lon')
    stack.wait(lambda: False, 3.0)
    second = status_field(gcs, stack, 'GLOBAL_POSITION_INT', 'lon')
    assert second - first > 100, (first, second)     # > 0.9 m east (0.5 m/s for > 3 s)
    # home (which MAVProxy asks for with GET_HOME_POSITION until it has one) is the datum
    assert status_field(gcs, stack, 'HOME_POSITION', 'latitude') == round(DATUM[0] * 1e7)
    # parameters: the whitelist, and a set that the vehicle confirms in STATUSTEXT
    assert stack.wait(lambda: gcs.count('Received 14 parameters'), 30.0), gcs.lines
    gcs.command('param set SHL_MAN_SPD 0.7')
    assert stack.wait(lambda: gcs.count('SHL_MAN_SPD set to 0.7'), 10.0), gcs.lines
    # (2) a two-waypoint mission -> mission/plan, held until started
    gcs.command(f'wp load {mission}')
    assert stack.wait(lambda: stack.plans, 15.0), gcs.lines
    assert stack.wait(lambda: gcs.count('mission of 2 waypoints loaded'), 10.0), gcs.lines
    waypoints = stack.plans[-1]['waypoints']
    assert len(waypoints) == 2, waypoints
    for waypoint, (east_m, north_m) in zip(waypoints, expected_plan(), strict=True):
        assert waypoint['x_m'] == pytest.approx(east_m, abs=0.01)
        assert waypoint['y_m'] == pytest.approx(north_m, abs=0.01)
        assert waypoint['speed_mps'] == SPEED_MPS
    assert stack.wait(lambda: stack.holds and stack.holds[-1], 5.0), stack.holds
    # (3) start it, then stop it
    gcs.command('long MISSION_START')
    assert stack.wait(lambda: stack.holds[-1] is False, 10.0), (stack.holds, gcs.lines)
    gcs.command('long DO_PAUSE_CONTINUE 0')                  # hold the mission, cmd_vel 0
    assert stack.wait(lambda: stack.holds[-1] is True, 10.0), (stack.holds, gcs.lines)
    gcs.command('long DO_SET_MODE 1 3')                      # custom mode 3: SAFE_STOP
    assert stack.wait(lambda: gcs.count('DO_SET_MODE: ACCEPTED'), 10.0), gcs.lines
    assert stack.mode_requests == [(3, False)]
    # (4) with a wrong key, then with none: an upload changes nothing, parameters go unanswered
    plans_before, received_before = len(stack.plans), gcs.count('Received 14 parameters')
    for signing in (f'signing key not-{PASSPHRASE}', 'signing remove'):
        gcs.command(signing)
        gcs.command(f'wp load {strangers}')
        gcs.command('param fetch')
        assert not stack.wait(lambda: len(stack.plans) > plans_before, 8.0), stack.plans
    assert gcs.count('mission of 1 waypoints loaded') == 0, gcs.lines
    assert gcs.count('Received 14 parameters') == received_before, gcs.lines
    assert stack.plans[-1]['waypoints'] == waypoints
