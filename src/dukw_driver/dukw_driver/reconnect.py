"""A device that is opened on demand and reopened with back-off after a failure (ROS-free).

The life every device link of the vehicle shares (``serial_link.SerialLink`` for the
motor controllers, IMU/GNSS and water sensors; ``shore_transport.MavlinkPort`` for the
shore radio): it never raises a device error. A failed open, read or write marks it down,
counts the error and keeps the text in ``last_error``; the next use after the back-off
(``backoff_initial_s``, doubling after each failed open up to ``backoff_max_s``) opens it
again. Subclasses say how to open (``_open``) and how to read and write.
"""
from __future__ import annotations

import time
from collections.abc import Callable

import serial

from dukw_common.config import ConfigError

#: what a failing device may raise on open, read, write or close
DEVICE_ERRORS = (serial.SerialException, OSError)


class ReconnectingLink:
    """Open on demand, reopen after a failure with back-off, count what happened."""

    def __init__(self, name: str, backoff_initial_s: float, backoff_max_s: float,
                 clock: Callable[[], float] = time.monotonic) -> None:
        if not 0 < backoff_initial_s <= backoff_max_s:
            raise ConfigError(f'{name}: back-off needs 0 < initial <= max, '
                              f'got {backoff_initial_s} and {backoff_max_s}')
        self.name = name
        self.backoff_initial_s = backoff_initial_s
        self.backoff_max_s = backoff_max_s
        self._clock = clock
        self._device = None
        self._backoff_s = backoff_initial_s
        self._next_attempt_s = -float('inf')
        self._ever_connected = False
        self.connected = False
        self.reconnects = 0          # successful opens after the first one
        self.errors = 0              # failed opens, reads and writes
        self.last_error = ''
        self.bytes_in = 0
        self.bytes_out = 0

    def _open(self):
        """Open the device and return its handle (may raise DEVICE_ERRORS or ValueError)."""
        raise NotImplementedError

    def _ensure_open(self) -> bool:
        """True when the device is open (opening it now if the back-off allows)."""
        if self._device is not None:
            return True
        now = self._clock()
        if now < self._next_attempt_s:
            return False
        try:
            self._device = self._open()
        except (*DEVICE_ERRORS, ValueError) as exc:
            self.errors += 1
            self.last_error = f'cannot open {self.name}: {exc}'
            self._next_attempt_s = now + self._backoff_s
            self._backoff_s = min(2.0 * self._backoff_s, self.backoff_max_s)
            return False
        self.connected = True
        self.reconnects += int(self._ever_connected)
        self._ever_connected = True
        self._backoff_s = self.backoff_initial_s
        return True

    def close(self) -> None:
        """Close the device (a later use opens it again)."""
        device, self._device = self._device, None
        self.connected = False
        if device is not None:
            try:
                device.close()
            except DEVICE_ERRORS:
                pass  # closing a vanished device: nothing left to release

    def seconds_until_retry(self) -> float:
        """Seconds until the next open attempt (0 when connected or due)."""
        if self.connected:
            return 0.0
        return max(0.0, self._next_attempt_s - self._clock())

    def _fail(self, message: str) -> None:
        self.errors += 1
        self.last_error = message
        self.close()
        self._next_attempt_s = self._clock() + self.backoff_initial_s
