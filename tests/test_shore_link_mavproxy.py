"""MAVProxy (pinned, installed --no-deps: requirements-nodeps.txt) as the ground station of
shore_link_node: with the passphrase it reads the whitelisted parameters and sets one; without
it the node answers nothing it asks."""
import hashlib
import shutil
import socket
import subprocess
import threading
import time

import pytest

from dukw_common.testing import NodeProcess

PASSPHRASE = 'beach-day-28cm'


def free_udp_port():
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        sock.bind(('127.0.0.1', 0))
        return sock.getsockname()[1]


class MavProxy:
    """MAVProxy on udpin (commands on its console's stdin, output collected by a thread)."""

    def __init__(self, cwd, port, startup=''):
        self.proc = subprocess.Popen(
            [shutil.which('mavproxy.py'), f'--master=udpin:127.0.0.1:{port}',
             *([f'--cmd={startup}'] if startup else [])], cwd=cwd, stdin=subprocess.PIPE,
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        self.lines: list[str] = []
        threading.Thread(target=lambda: self.lines.extend(self.proc.stdout), daemon=True).start()

    def wait_for(self, text, timeout_s):
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            if any(text in line for line in self.lines):
                return True
            time.sleep(0.1)
        return False

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


@pytest.mark.ros
@pytest.mark.slow
@pytest.mark.timeout(180)
def test_mavproxy_with_the_passphrase_commands_and_without_it_cannot(tmp_path):
    key_file = tmp_path / 'shore.key'
    key_file.write_text(hashlib.sha256(PASSPHRASE.encode()).hexdigest())
    port = free_udp_port()
    node = NodeProcess('dukw_driver', 'shore_link_node', [
        '--ros-args', '-p', f'url:=udpout:127.0.0.1:{port}', '-p',
        f'signing_key_file:={key_file}'])
    try:
        friend = MavProxy(tmp_path, port, f'signing key {PASSPHRASE}')
        try:
            assert friend.wait_for('Detected vehicle 1:1', 30.0), friend.lines
            assert friend.wait_for('Received 14 parameters', 60.0), friend.lines  # whitelist
            friend.command('param set SHL_MAN_SPD 0.7')
            assert friend.wait_for('SHL_MAN_SPD set to 0.7', 10.0), friend.lines  # STATUSTEXT
        finally:
            friend.close()
        stranger = MavProxy(tmp_path, port)
        try:
            assert stranger.wait_for('Detected vehicle 1:1', 30.0), stranger.lines  # can read
            time.sleep(1.0)
            stranger.command('param fetch')
            answered = stranger.wait_for('Received 14 parameters', 25.0)
        finally:
            output = stranger.close()
    finally:
        code = node.stop()
    assert code == 0, node.stderr
    assert not answered, output                                  # but cannot command
