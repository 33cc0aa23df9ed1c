"""The radio (or UDP) under the shore link: pymavlink's connections, reopened when lost. ROS-free.

``url`` takes pymavlink's connection strings: a serial radio ``/dev/ttyUSB0,57600``
(or just the device: ``radio_baud``), ``udpout:HOST:PORT`` (send to a ground
station listening there, e.g. QGroundControl's 14550) or ``udpin:ADDR:PORT``
(listen; replies go to whoever sent). Like ``SerialLink`` the link never raises:
a failed open, read or write marks it down, counts the error and keeps the text;
the next ``poll()`` after ``reconnect_period_s`` opens it again.
"""
from __future__ import annotations

import time
from collections.abc import Callable

import serial
from pymavlink import mavutil

from dukw_common.config import ConfigError
from dukw_driver.serial_link import STANDARD_BAUDS, WRITE_TIMEOUT_S

READ_CHUNK = 4096
MAX_READS = 64
UDP_PREFIXES = ('udpout:', 'udpin:')


def parse_url(url: object, default_baud: int) -> tuple[str, int]:
    """Validate a connection string; return (url for mavutil, serial baud or 0 for UDP)."""
    if not isinstance(url, str) or not url.strip():
        raise ConfigError(f"parameter 'url' must be a pymavlink connection string, got {url!r}")
    if url.startswith(UDP_PREFIXES):
        host, _, port = url.split(':', 1)[1].rpartition(':')
        if not host or not port.isdigit() or not 0 < int(port) < 65536:
            raise ConfigError(f"parameter 'url' {url!r}: expected udpout:HOST:PORT or "
                              'udpin:ADDR:PORT')
        return url, 0
    if ':' in url.split(',')[0] and not url.startswith('/'):
        raise ConfigError(f"parameter 'url' {url!r}: use a serial device (/dev/ttyUSB0,57600), "
                          'udpout:HOST:PORT or udpin:ADDR:PORT')
    device, _, baud_text = url.partition(',')
    baud = int(baud_text) if baud_text.isdigit() else default_baud
    if baud_text and not baud_text.isdigit() or baud not in STANDARD_BAUDS:
        raise ConfigError(f"parameter 'url' {url!r}: baud must be one of {STANDARD_BAUDS}")
    return f'{device},{baud}', baud


class MavlinkPort:
    """One pymavlink connection: read bytes, write bytes, reopen after a failure."""

    def __init__(self, url: str, default_baud: int, reconnect_period_s: float = 1.0,
                 clock: Callable[[], float] = time.monotonic,
                 opener: Callable[..., object] = mavutil.mavlink_connection) -> None:
        self.url, self.baud = parse_url(url, default_baud)
        self.reconnect_period_s = reconnect_period_s
        self._clock = clock
        self._opener = opener
        self._conn = None
        self._next_attempt_s = -float('inf')
        self._ever_connected = False
        self.connected = False
        self.reconnects = 0
        self.errors = 0
        self.last_error = ''
        self.bytes_in = 0
        self.bytes_out = 0

    def poll(self) -> bytes:
        """The bytes that arrived (b'' if none or down); reopens when due.

        A UDP connection returns one datagram per read: read until nothing is left
        (at most ``MAX_READS``), so a burst is not spread over later polls.
        """
        if self._conn is None and not self._try_open():
            return b''
        chunks = []
        for _ in range(MAX_READS):
            try:
                data = self._conn.recv(READ_CHUNK)
            except (serial.SerialException, OSError) as exc:
                self._fail(f'read failed: {exc}')
                break
            data = data.encode('latin-1') if isinstance(data, str) else bytes(data or b'')
            if not data:
                break
            chunks.append(data)
        received = b''.join(chunks)
        self.bytes_in += len(received)
        return received

    def write(self, data: bytes) -> bool:
        """Send ``data``; False (link marked down) on error."""
        if not data:
            return True
        if self._conn is None and not self._try_open():
            return False
        try:
            sent = self._conn.write(data)
        except (serial.SerialException, OSError) as exc:
            self._fail(f'write failed: {exc}')
            return False
        if sent == -1 or getattr(self._conn, 'portdead', False):
            self._fail('write failed: device gone')
            return False
        self.bytes_out += len(data)
        return True

    def close(self) -> None:
        """Close the connection (a later poll opens it again)."""
        conn, self._conn = self._conn, None
        self.connected = False
        if conn is not None:
            try:
                conn.close()
            except (serial.SerialException, OSError):
                pass   # closing a vanished device: nothing left to release

    def _try_open(self) -> bool:
        now = self._clock()
        if now < self._next_attempt_s:
            return False
        try:
            self._conn = self._opener(self.url, baud=self.baud or 57600, autoreconnect=False)
        except (serial.SerialException, OSError, ValueError) as exc:
            self.errors += 1
            self.last_error = f'cannot open {self.url}: {exc}'
            self._next_attempt_s = now + self.reconnect_period_s
            return False
        port = getattr(self._conn, 'port', None)
        if isinstance(port, serial.Serial):
            port.write_timeout = WRITE_TIMEOUT_S   # a stalled radio must not block the node
        self.connected = True
        self.reconnects += int(self._ever_connected)
        self._ever_connected = True
        return True

    def _fail(self, message: str) -> None:
        self.errors += 1
        self.last_error = message
        self.close()
        self._next_attempt_s = self._clock() + self.reconnect_period_s
