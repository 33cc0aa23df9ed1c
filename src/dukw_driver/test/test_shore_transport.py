"""MavlinkPort: pymavlink connection strings, and reopening a link that failed (real sockets)."""
import socket

import pytest

from dukw_common.config import ConfigError
from dukw_driver.shore_transport import MavlinkPort, parse_url


def test_connection_strings():
    assert parse_url('/dev/ttyUSB0,57600', 115200) == ('/dev/ttyUSB0,57600', 57600)
    assert parse_url('/dev/ttyUSB0', 57600) == ('/dev/ttyUSB0,57600', 57600)
    assert parse_url('udpout:127.0.0.1:14550', 57600) == ('udpout:127.0.0.1:14550', 0)
    assert parse_url('udpin:0.0.0.0:14551', 57600)[1] == 0
    for bad in ('', 'udpout:127.0.0.1', 'udpin::99999', 'tcp:1.2.3.4:5760', '/dev/ttyS0,12345',
                '/dev/ttyS0,fast', 42):
        with pytest.raises(ConfigError, match="'url'"):
            parse_url(bad, 57600)


def test_a_port_that_cannot_open_is_retried_and_recovers():
    clock = [0.0]
    blocker = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    blocker.bind(('127.0.0.1', 0))
    port_no = blocker.getsockname()[1]
    port = MavlinkPort(f'udpin:127.0.0.1:{port_no}', 57600, reconnect_period_s=1.0,
                       clock=lambda: clock[0])
    assert port.poll() == b'' and not port.connected and port.errors == 1
    assert 'cannot open' in port.last_error
    blocker.close()
    clock[0] = 0.5
    assert port.poll() == b'' and port.errors == 1             # waits for the period
    clock[0] = 1.1
    port.poll()
    assert port.connected
    sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    for _ in range(3):
        sender.sendto(b'\xfd' * 10, ('127.0.0.1', port_no))
    sender.close()
    data = b''
    for _ in range(50):
        data += port.poll()
        if len(data) == 30:
            break
    assert data == b'\xfd' * 30                                 # every datagram, in one poll
    port.close()
