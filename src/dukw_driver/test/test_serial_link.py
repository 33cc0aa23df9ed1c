"""SerialLink: opens, reads, writes, survives unplug/replug, backs off, never raises."""
import itertools
import time

import pytest
import serial

from dukw_common.config import ConfigError
from dukw_common.diagnostics import Level
from dukw_driver.serial_link import DeviceHealth, SerialLink
from fake_device import FakeDevice


def poll_until(link, predicate, timeout_s=3.0):
    """Poll ``link`` until ``predicate(collected bytes)``; return the bytes."""
    got = b''
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        got += link.poll()
        if predicate(got):
            return got
        time.sleep(0.005)
    return got


@pytest.fixture
def echo(tmp_path):
    with FakeDevice(tmp_path / 'ttyEcho', respond=lambda data: data.upper()) as dev:
        yield dev


def test_write_and_read_through_a_pty(echo):
    link = SerialLink(str(echo.path), 115200)
    assert link.write(b'ping\r')
    assert link.connected
    assert poll_until(link, lambda b: b'PING\r' in b) == b'PING\r'
    assert link.bytes_out == 5 and link.bytes_in == 5
    assert link.errors == 0 and link.reconnects == 0
    link.close()


def test_unplug_marks_down_and_replug_reconnects_within_the_backoff(echo):
    link = SerialLink(str(echo.path), 115200)
    assert link.write(b'a')
    assert poll_until(link, lambda b: b == b'A')
    echo.unplug()
    deadline = time.monotonic() + 2.0
    while link.connected and time.monotonic() < deadline:
        link.poll()
    assert not link.connected
    assert link.errors >= 1 and link.last_error
    for _ in range(20):  # keeps failing (no such file) without raising
        assert link.poll() == b''
        assert not link.write(b'x')
    echo.replug()
    replugged = time.monotonic()
    while not link.connected and time.monotonic() < replugged + 2.0:
        link.poll()
        time.sleep(0.01)
    assert link.connected
    assert time.monotonic() - replugged < 1.5
    assert link.reconnects == 1
    assert link.write(b'b')
    assert poll_until(link, lambda b: b'B' in b).endswith(b'B')
    link.close()


def test_missing_device_never_raises_and_counts_errors(tmp_path):
    link = SerialLink(str(tmp_path / 'nothing'), 9600, backoff_initial_s=0.001,
                      backoff_max_s=0.001)
    for _ in range(5):
        assert link.poll() == b''
        time.sleep(0.002)
    assert not link.connected
    assert link.errors == 5
    assert 'cannot open' in link.last_error


class FakeClock:
    def __init__(self):
        self.t = 0.0

    def __call__(self):
        return self.t


def failing_opener(calls):
    def opener(*args, **kwargs):
        calls.append(args[0])
        raise serial.SerialException('no device')
    return opener


def test_backoff_doubles_up_to_the_maximum():
    clock, calls = FakeClock(), []
    link = SerialLink('/dev/ttyX', 9600, backoff_initial_s=0.125, backoff_max_s=0.375,
                      clock=clock, opener=failing_opener(calls))  # binary fractions: exact sums
    attempt_times = []
    while clock.t < 2.0:
        before = len(calls)
        link.poll()
        if len(calls) > before:
            attempt_times.append(clock.t)
        clock.t += 1 / 128
    gaps = [b - a for a, b in itertools.pairwise(attempt_times)]
    assert gaps[:3] == [0.125, 0.25, 0.375]
    assert max(gaps) == 0.375


class FlakyDevice:
    """A pyserial-like device whose read fails once."""

    def __init__(self):
        self.reads = 0
        self.closed = False

    def read(self, size):
        self.reads += 1
        if self.reads == 2:
            raise serial.SerialException('read failed: [Errno 5] Input/output error')
        return b'ok'

    def write(self, data):
        raise OSError(5, 'Input/output error')

    def close(self):
        self.closed = True


def test_read_error_closes_and_the_next_open_is_after_the_initial_backoff():
    clock = FakeClock()
    devices = []
    link = SerialLink('/dev/ttyX', 9600, clock=clock,
                      opener=lambda *a, **k: devices.append(FlakyDevice()) or devices[-1])
    assert link.poll() == b'ok'
    assert link.poll() == b''
    assert not link.connected and devices[0].closed and link.errors == 1
    assert link.poll() == b'' and len(devices) == 1  # still backing off
    clock.t = 0.1
    assert link.poll() == b'ok' and link.reconnects == 1
    assert not link.write(b'x') and link.errors == 2 and 'write failed' in link.last_error


@pytest.mark.parametrize('port,baud,name', [('', 9600, 'port'), (None, 9600, 'port'),
                                            ('/dev/ttyACM0', 12345, 'baud'),
                                            ('/dev/ttyACM0', '9600', 'baud'),
                                            ('/dev/ttyACM0', True, 'baud')])
def test_bad_port_or_baud_is_a_config_error_naming_it(port, baud, name):
    with pytest.raises(ConfigError, match=f"'{name}'"):
        SerialLink(port, baud)


def test_device_health_levels(echo):
    link = SerialLink(str(echo.path), 115200)
    health = DeviceHealth('maestro', stale_after_s=0.5, expected_rate_hz=10.0)
    assert health.health(link, 0.0).level == Level.ERROR  # never opened
    link.poll()
    for i in range(20):
        health.message(i * 0.1)
    ok = health.health(link, 2.0)
    assert ok.level == Level.OK, ok.message
    assert ok.values['messages'] == 20 and ok.values['connected'] is True
    health.parse_error(3)
    warn = health.health(link, 2.0)
    assert warn.level == Level.WARN and '3 new parse errors' in warn.message
    assert health.health(link, 2.0).level == Level.OK  # reported once
    assert health.health(link, 3.0).level == Level.ERROR  # stale
    link.close()
