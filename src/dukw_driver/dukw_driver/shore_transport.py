"""The radio (or UDP) under the shore link: pymavlink's connections, reopened when lost. ROS-free.

``url`` takes pymavlink's connection strings: a serial radio ``/dev/ttyUSB0,57600``
(or just the device: ``radio_baud``), ``udpout:HOST:PORT`` (send to a ground
station listening there, e.g. QGroundControl's 14550) or ``udpin:ADDR:PORT``
(listen; replies go to whoever sent). Its life is ``reconnect.ReconnectingLink``'s, like
``SerialLink``'s: it never raises, and the next ``poll()`` after ``reconnect_period_s``
opens it again.
"""
from __future__ import annotations

import time
from collections.abc import Callable

import serial
from pymavlink import mavutil

from dukw_common.config import ConfigError
from dukw_driver.reconnect import DEVICE_ERRORS, ReconnectingLink
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


class MavlinkPort(ReconnectingLink):
    """One pymavlink connection: read bytes, write bytes, reopen after a failure."""

    def __init__(self, url: str, default_baud: int, reconnect_period_s: float = 1.0,
                 clock: Callable[[], float] = time.monotonic,
                 opener: Callable[..., object] = mavutil.mavlink_connection) -> None:
        self.url, self.baud = parse_url(url, default_baud)
        super().__init__(self.url, reconnect_period_s, reconnect_period_s, clock)
        self.reconnect_period_s = reconnect_period_s
        self._opener = opener

    def _open(self):
        conn = self._opener(self.url, baud=self.baud or 57600, autoreconnect=False)
        port = getattr(conn, 'port', None)
        if isinstance(port, serial.Serial):
            port.write_timeout = WRITE_TIMEOUT_S   # a stalled radio must not block the node
        return conn

    def poll(self) -> bytes:
        """The bytes that arrived (b'' if none or down); reopens when due.

        A UDP connection returns one datagram per read: read until nothing is left
        (at most ``MAX_READS``), so a burst is not spread over later polls.
        """
        if not self._ensure_open():
            return b''
        chunks = []
        for _ in range(MAX_READS):
            try:
                data = self._device.recv(READ_CHUNK)
            except DEVICE_ERRORS as exc:
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
        if not self._ensure_open():
            return False
        try:
            sent = self._device.write(data)
        except DEVICE_ERRORS as exc:
            self._fail(f'write failed: {exc}')
            return False
        if sent == -1 or getattr(self._device, 'portdead', False):
            self._fail('write failed: device gone')
            return False
        self.bytes_out += len(data)
        return True
