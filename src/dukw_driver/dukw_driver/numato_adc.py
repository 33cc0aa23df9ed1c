"""Numato Lab USB GPIO module with analog inputs (e.g. 8-channel): ASCII protocol. ROS-free.

The module is a USB CDC serial device (``/dev/ttyACM*``; the baud rate is
ignored). A command is ASCII ending in CR; the module echoes it and answers::

    host:   adc read 1\\r
    module: adc read 1\\n\\r512\\n\\r>

The value is the 10-bit conversion, 0..1023, of the pin voltage against the
module's supply. The echo names the channel, so answers are matched to requests
by it even when several requests are in flight or bytes were lost. A request
with no answer within ``timeout_s`` counts as a timeout and may be sent again.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

ADC_MAX_COUNTS = 1023
MAX_CHANNEL = 9
MAX_LINE_BYTES = 64
_ECHO = re.compile(r'^adc read (\d)$')
_VALUE = re.compile(r'^\d{1,4}$')


def adc_read_command(channel: int) -> bytes:
    """The request for one channel."""
    if not 0 <= channel <= MAX_CHANNEL:
        raise ValueError(f'ADC channel must be 0..{MAX_CHANNEL}, got {channel}')
    return f'adc read {channel}\r'.encode('ascii')


@dataclass(frozen=True)
class AdcReading:
    """One conversion: channel, counts 0..1023, and the level counts / 1023."""

    channel: int
    counts: int

    @property
    def level(self) -> float:
        """The reading as a fraction of full scale, 0..1."""
        return self.counts / ADC_MAX_COUNTS


@dataclass
class AdcCounters:
    """What the codec has seen since start."""

    readings: int = 0
    parse_errors: int = 0    # lines that are neither an echo nor a value that follows one
    timeouts: int = 0        # requests never answered

    @property
    def messages(self) -> int:
        """Good readings."""
        return self.readings

    @property
    def errors(self) -> int:
        """Parse errors plus timeouts."""
        return self.parse_errors + self.timeouts


class NumatoAdc:
    """Builds requests and matches the module's answers to them; never raises on bad input."""

    def __init__(self, channels: tuple[int, ...], timeout_s: float) -> None:
        for channel in channels:
            adc_read_command(channel)  # validates
        if len(set(channels)) != len(channels):
            raise ValueError(f'ADC channels must differ, got {channels}')
        if not timeout_s > 0:
            raise ValueError(f'ADC response timeout must be > 0 s, got {timeout_s}')
        self.channels = channels
        self.timeout_s = timeout_s
        self.counters = AdcCounters()
        self._pending: dict[int, float] = {}
        self._echoed: int | None = None
        self._buffer = bytearray()

    def requests(self, now_s: float) -> bytes:
        """Requests for every channel not already waiting for its answer."""
        out = b''
        for channel in self.channels:
            sent_s = self._pending.get(channel)
            if sent_s is not None and now_s - sent_s < self.timeout_s:
                continue
            if sent_s is not None:
                self.counters.timeouts += 1
            self._pending[channel] = now_s
            out += adc_read_command(channel)
        return out

    def reset(self) -> None:
        """Forget requests in flight and partial input (after the link was lost)."""
        self._pending.clear()
        self._echoed = None
        self._buffer.clear()

    def feed(self, data: bytes) -> list[AdcReading]:
        """Add received bytes; return the readings they complete."""
        self._buffer.extend(data.replace(b'>', b'\n'))
        out = []
        while True:
            cut = min((i for i in (self._buffer.find(b'\n'), self._buffer.find(b'\r'))
                       if i >= 0), default=-1)
            if cut < 0:
                break
            line = bytes(self._buffer[:cut]).strip()
            del self._buffer[:cut + 1]
            if line:
                reading = self._line(line)
                if reading is not None:
                    out.append(reading)
        if len(self._buffer) > MAX_LINE_BYTES:
            self.counters.parse_errors += 1
            self._buffer.clear()
        return out

    def _line(self, raw: bytes) -> AdcReading | None:
        try:
            line = raw.decode('ascii')
        except UnicodeDecodeError:
            line = ''
        echo = _ECHO.match(line)
        if echo:
            self._echoed = int(echo.group(1))
            return None
        channel, self._echoed = self._echoed, None
        if channel is None or not _VALUE.match(line) or int(line) > ADC_MAX_COUNTS:
            self.counters.parse_errors += 1
            return None
        if channel not in self._pending:
            self.counters.parse_errors += 1  # an answer nobody asked for (or a stale one)
            return None
        del self._pending[channel]
        self.counters.readings += 1
        return AdcReading(channel, int(line))
