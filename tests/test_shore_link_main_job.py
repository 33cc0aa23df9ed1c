"""A signed pymavlink ground station on the main job (simulator stack + shore link), end to end.

It sees the vehicle move, uploads a two-waypoint mission that the mission node flies, drives
with MANUAL_CONTROL and sees it stop when the sticks stop coming, and sees the RC operator's
takeover win over a shore command.
"""
import math
import os
import signal
import subprocess
import threading
import time

import pytest
from dukw_msgs.srv import SetOperator
from pymavlink import mavutil
from pymavlink.dialects.v20 import common as mavlink

from dukw_bringup.bringup import node_executable
from dukw_common.testing import ros_node
from dukw_driver.mavlink_signing import key_from_passphrase

M_PER_DEG = math.radians(1.0) * 6378137.0


class Station:
    """mavutil ground station (udpin, MAVLink 2 common) and the main job's output."""

    def __init__(self, tmp_path):
        os.environ['MAVLINK20'] = '1'
        self.conn = mavutil.mavlink_connection('udpin:127.0.0.1:0', source_system=255,
                                               source_component=190, dialect='common')
        port = self.conn.port.getsockname()[1]
        self.proc = subprocess.Popen(
            [str(node_executable('dukw_bringup', 'main_job')), '--out', str(tmp_path / 'run'),
             '--shore-url', f'udpout:127.0.0.1:{port}', '--time-limit', '200'],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.lines: list[str] = []
        for line in self.proc.stdout:
            self.lines.append(line)
            if 'passphrase' in line:
                self.conn.setup_signing(key_from_passphrase(line.split()[-1]), link_id=1)
                break
        threading.Thread(target=lambda: self.lines.extend(self.proc.stdout), daemon=True).start()
        self.last: dict[str, object] = {}
        self.reached: list[int] = []
        self.heartbeat_s = 0.0

    def pump(self, seconds, predicate=lambda: False, every=None):
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            if time.monotonic() - self.heartbeat_s >= 1.0:    # a GCS's 1 Hz heartbeat
                self.heartbeat_s = time.monotonic()
                self.conn.mav.heartbeat_send(mavlink.MAV_TYPE_GCS, 8, 0, 0, 0)
            msg = self.conn.recv_match(blocking=True, timeout=0.05)
            if msg is not None and msg.get_type() != 'BAD_DATA':
                assert msg.get_signed(), msg
                self.last[msg.get_type()] = msg
                if msg.get_type() == 'MISSION_ITEM_REACHED':
                    self.reached.append(msg.seq)
            if every:
                every()
            if predicate():
                return True
        return predicate()

    def position_m(self):
        """(east, north) of the last GLOBAL_POSITION_INT from its first one."""
        pos = self.last['GLOBAL_POSITION_INT']
        lat0 = 36.1836
        return ((pos.lon * 1e-7 + 75.7510) * M_PER_DEG * math.cos(math.radians(lat0)),
                (pos.lat * 1e-7 - lat0) * M_PER_DEG)

    def speed_mps(self):
        return self.last['VFR_HUD'].groundspeed if 'VFR_HUD' in self.last else math.nan

    def upload(self, points_en):
        mav = self.conn.mav
        mav.mission_count_send(1, 1, len(points_en), 0)
        sent = set()

        def answer():
            req = self.last.get('MISSION_REQUEST_INT')
            if req is not None and req.seq not in sent:
                sent.add(req.seq)
                east, north = points_en[req.seq]
                lat = 36.1836 + north / M_PER_DEG
                lon = -75.7510 + east / (M_PER_DEG * math.cos(math.radians(36.1836)))
                mav.mission_item_int_send(1, 1, req.seq,
                                          mavlink.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
                                          mavlink.MAV_CMD_NAV_WAYPOINT, 0, 1, 0, 0, 0, 0,
                                          int(lat * 1e7), int(lon * 1e7), 0, 0)
        return self.pump(20.0, lambda: 'MISSION_ACK' in self.last, answer)

    def stop(self):
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
        try:
            self.proc.wait(timeout=90)
        except subprocess.TimeoutExpired:
            self.proc.kill()
        self.conn.close()


@pytest.mark.ros
@pytest.mark.slow
@pytest.mark.timeout(300)
def test_ground_station_flies_a_mission_drives_and_yields_to_the_rc_operator(tmp_path):
    gcs = Station(tmp_path)
    try:
        _run(gcs)
    finally:
        gcs.stop()
    assert gcs.proc.returncode == 0, ''.join(gcs.lines[-20:])        # the shore's mission done


def _run(gcs):
    assert gcs.pump(90.0, lambda: 'GLOBAL_POSITION_INT' in gcs.last), ''.join(gcs.lines)
    start = gcs.position_m()
    assert gcs.pump(30.0, lambda: gcs.position_m()[0] > start[0] + 1.0)   # main job's mission
    assert gcs.last['HEARTBEAT'].type == mavlink.MAV_TYPE_GROUND_ROVER

    def sticks(x):
        sent = [0.0]

        def send():                       # 20 Hz, as a joystick would
            if time.monotonic() - sent[0] >= 0.05:
                sent[0] = time.monotonic()
                gcs.conn.mav.manual_control_send(1, x, 0, 500, 0, 0)
        return send
    assert gcs.pump(15.0, lambda: gcs.speed_mps() > 0.5, sticks(1000))     # shore drives
    assert gcs.pump(8.0, lambda: gcs.speed_mps() < 0.05)                   # sticks stop: stop
    operator(rc_selected=True)
    assert gcs.pump(5.0, lambda: gcs.last['HEARTBEAT'].base_mode
                    & mavlink.MAV_MODE_FLAG_MANUAL_INPUT_ENABLED)
    gcs.pump(6.0, every=sticks(1000))                                      # shore asks...
    assert gcs.speed_mps() < 0.05                                          # ...the RC wins
    operator(rc_selected=False)
    here = gcs.position_m()
    assert gcs.upload([(here[0] + 4.0, here[1]), (here[0] + 4.0, here[1] + 3.0)])
    assert gcs.last['MISSION_ACK'].type == mavlink.MAV_MISSION_ACCEPTED
    gcs.conn.mav.command_long_send(1, 1, mavlink.MAV_CMD_MISSION_START, 0, 0, 0, 0, 0, 0, 0, 0)
    assert gcs.pump(60.0, lambda: gcs.reached[-2:] == [0, 1]), (gcs.reached, gcs.position_m())


def operator(rc_selected):
    """The simulator's RC transmitter: take (or give back) authority, sticks centred."""
    with ros_node('shore_e2e_operator') as (probe, executor):
        client = probe.create_client(SetOperator, 'sim/set_operator')
        assert client.wait_for_service(timeout_sec=20.0)
        future = client.call_async(SetOperator.Request(rc_selected=rc_selected, rc_link_ok=True))
        executor.spin_until_future_complete(future, timeout_sec=10.0)
        assert future.result() is not None and future.result().success
