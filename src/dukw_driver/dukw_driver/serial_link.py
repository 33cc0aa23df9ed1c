"""One serial device's life: open, read, write, notice loss, reconnect with back-off (ROS-free).

Every hardware node owns one ``SerialLink`` per device and calls ``poll()`` from a
timer. The reconnecting life is ``reconnect.ReconnectingLink``'s: the link never raises a
serial error, and the next ``poll()`` after the back-off (0.1 s doubling up to at most
1 s by default) tries to open the port again, so a node publishes again well within 2 s
of a cable coming back. ``DeviceHealth`` turns the counters into a
``dukw_common.diagnostics.Health`` for ``/diagnostics``.
"""
from __future__ import annotations

import time
from collections.abc import Callable

import serial

from dukw_common.config import ConfigError
from dukw_common.diagnostics import Health, Level, RateCounter
from dukw_driver.reconnect import DEVICE_ERRORS, ReconnectingLink

#: Baud rates a UART on the vehicle can be set to.
STANDARD_BAUDS = (1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200, 230400, 460800, 921600)
#: Longest time one write may block when the device stops reading, s.
WRITE_TIMEOUT_S = 0.05
#: Most bytes one ``poll()`` reads.
READ_CHUNK = 4096


def validate_port(port: object, name: str = 'port') -> str:
    """Return ``port`` if it is a non-empty device path or pyserial URL; else raise ConfigError."""
    if not isinstance(port, str) or not port.strip():
        raise ConfigError(f'parameter {name!r} must name a serial device (e.g. /dev/ttyACM0), '
                          f'got {port!r}')
    return port


def validate_baud(baud: object, name: str = 'baud') -> int:
    """Return ``baud`` if it is a standard baud rate; else raise ConfigError naming it."""
    if isinstance(baud, bool) or not isinstance(baud, int) or baud not in STANDARD_BAUDS:
        raise ConfigError(f'parameter {name!r} must be one of {STANDARD_BAUDS}, got {baud!r}')
    return baud


class SerialLink(ReconnectingLink):
    """Owns one serial device: open, read/write, reconnect with back-off; never raises."""

    def __init__(self, port: str, baud: int, *, backoff_initial_s: float = 0.1,
                 backoff_max_s: float = 1.0, clock: Callable[[], float] = time.monotonic,
                 opener=serial.serial_for_url) -> None:
        self.port = validate_port(port)
        self.baud = validate_baud(baud)
        super().__init__(self.port, backoff_initial_s, backoff_max_s, clock)
        self._opener = opener

    def _open(self):
        return self._opener(self.port, baudrate=self.baud, timeout=0,
                            write_timeout=WRITE_TIMEOUT_S, exclusive=True)

    def poll(self) -> bytes:
        """Return the bytes available now (b'' if none or closed); reopen when back-off allows."""
        if not self._ensure_open():
            return b''
        try:
            data = self._device.read(READ_CHUNK)
        except DEVICE_ERRORS as exc:
            self._fail(f'read failed: {exc}')
            return b''
        self.bytes_in += len(data)
        return bytes(data)

    def write(self, data: bytes) -> bool:
        """Send ``data``; False (and the link marked down) on error or when closed."""
        if not self._ensure_open():
            return False
        try:
            sent = self._device.write(data)
        except DEVICE_ERRORS as exc:
            self._fail(f'write failed: {exc}')
            return False
        if sent is not None and sent < len(data):
            self.bytes_out += sent
            self._fail(f'short write: {sent} of {len(data)} bytes')
            return False
        self.bytes_out += len(data)
        return True


class DeviceHealth:
    """Message rate, parse errors and link counters of one device, as a Health for /diagnostics.

    ERROR while the link is down or no good message came for ``stale_after_s``;
    WARN when parse errors rose since the last report or the rate is below half
    of ``expected_rate_hz``; OK otherwise.
    """

    def __init__(self, name: str, stale_after_s: float = 1.0,
                 expected_rate_hz: float = 0.0, window_s: float = 2.0) -> None:
        self.name = name
        self.stale_after_s = stale_after_s
        self.expected_rate_hz = expected_rate_hz
        self.rate = RateCounter(window_s)
        self.parse_errors = 0
        self._reported_parse_errors = 0

    def message(self, now_s: float) -> None:
        """Count one well-formed message from the device."""
        self.rate.tick(now_s)

    def parse_error(self, count: int = 1) -> None:
        """Count malformed input."""
        self.parse_errors += count

    def fresh(self, now_s: float) -> bool:
        """True if a good message came within ``stale_after_s``."""
        return self.rate.age_s(now_s) <= self.stale_after_s

    def health(self, link: SerialLink, now_s: float) -> Health:
        """Build the Health of this device now (resets the 'new parse errors' mark)."""
        rate_hz = self.rate.rate_hz(now_s)
        health = Health(self.name, hardware_id=link.port, values={
            'connected': link.connected, 'message_rate_hz': round(rate_hz, 2),
            'messages': self.rate.total, 'parse_errors': self.parse_errors,
            'reconnects': link.reconnects, 'serial_errors': link.errors,
            'bytes_in': link.bytes_in, 'bytes_out': link.bytes_out,
            'last_error': link.last_error})
        if not link.connected:
            health.worsen(Level.ERROR, f'{link.port} not connected: {link.last_error}')
        elif not self.fresh(now_s):
            health.worsen(Level.ERROR, f'no valid message for {self.stale_after_s:.1f} s')
        if self.parse_errors > self._reported_parse_errors:
            health.worsen(Level.WARN, f'{self.parse_errors - self._reported_parse_errors} '
                          'new parse errors')
            self._reported_parse_errors = self.parse_errors
        if self.expected_rate_hz > 0 and rate_hz < 0.5 * self.expected_rate_hz:
            health.worsen(Level.WARN, f'rate {rate_hz:.1f} Hz below '
                          f'{self.expected_rate_hz:.1f} Hz expected')
        return health
