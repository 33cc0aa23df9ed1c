"""Pololu Mini Maestro 12 on its compact serial protocol, and the servo switch's core (ROS-free).

Protocol (Pololu Maestro user's guide, section 5):

- Set Target ``0x84, channel, target & 0x7F, (target >> 7) & 0x7F``; target in
  quarter-microseconds (1500 us -> 6000). No reply.
- Get Position ``0x90, channel``; reply: 2 bytes, little-endian. For a channel
  configured as an input it is the voltage, 0..1023 for 0..5 V.
- Get Errors ``0xA1``; reply: 2 bytes, little-endian error register (cleared by
  reading). Bits 0..8 are named in ``ERROR_BITS``.

Wiring this module assumes (documented in the README): four servo outputs go to
the computer side of the RC multiplexer (port/stbd track controller, port/stbd
propeller controller); one input channel reads a logic line that is high while
the multiplexer's select line gives the RC side, another a logic line that is
high while the RC receiver has a valid link (e.g. an RC switch with digital
output on a channel whose receiver fail-safe value turns it off); optional
input channels read the RC receiver's outputs into the multiplexer (port track,
stbd track, port prop, stbd prop, as on ``rc/input``) through pulse-to-voltage
converters (0..5 V spanning the calibrated pulse range); 0 us while the link is
lost. The replies carry no framing, so the parser validates every value and
drops a whole batch on anything odd.
"""
from __future__ import annotations

import collections
import math
from dataclasses import dataclass

from dukw_common.config import ConfigError
from dukw_driver.authority import CommandGate, SideCommand, validate_command

SET_TARGET = 0x84
GET_POSITION = 0x90
GET_ERRORS = 0xA1
MAX_CHANNEL = 11            # Mini Maestro 12: channels 0..11
MAX_TARGET = 0x3FFF         # 14 bits
MAX_INPUT_RAW = 1023        # analog input, 0..5 V

#: Error register bits (user's guide section 4.e).
ERROR_BITS = {
    0: 'serial_signal', 1: 'serial_overrun', 2: 'serial_rx_buffer_full', 3: 'serial_crc',
    4: 'serial_protocol', 5: 'serial_timeout', 6: 'script_stack', 7: 'script_call_stack',
    8: 'script_program_counter',
}


def encode_set_target(channel: int, target_qus: int) -> bytes:
    """Set Target: ``channel`` 0..11, ``target_qus`` in quarter-microseconds (0 = no pulses)."""
    _check_channel(channel)
    if not 0 <= target_qus <= MAX_TARGET:
        raise ValueError(f'target {target_qus} outside 0..{MAX_TARGET} quarter-us')
    return bytes((SET_TARGET, channel, target_qus & 0x7F, (target_qus >> 7) & 0x7F))


def encode_get_position(channel: int) -> bytes:
    """Get Position of ``channel`` (reply: 2 bytes)."""
    _check_channel(channel)
    return bytes((GET_POSITION, channel))


def encode_get_errors() -> bytes:
    """Get Errors (reply: 2 bytes; reading clears the register)."""
    return bytes((GET_ERRORS,))


def decode_errors(register: int) -> list[str]:
    """Names of the set bits of the error register, bit by bit (unknown bits as ``bit_N``)."""
    return [ERROR_BITS.get(bit, f'bit_{bit}') for bit in range(16) if register >> bit & 1]


def _check_channel(channel: int) -> None:
    if not 0 <= channel <= MAX_CHANNEL:
        raise ValueError(f'channel {channel} outside 0..{MAX_CHANNEL}')


@dataclass(frozen=True)
class OutputChannel:
    """One servo output: which channel, and how percent maps to pulse width."""

    name: str
    channel: int
    neutral_us: float = 1500.0
    min_us: float = 1000.0
    max_us: float = 2000.0
    reversed: bool = False

    def __post_init__(self) -> None:
        _check_channel(self.channel)
        if not 0 < self.min_us < self.neutral_us < self.max_us <= MAX_TARGET / 4:
            raise ConfigError(f'output {self.name}: need 0 < min_us < neutral_us < max_us, got '
                              f'{self.min_us}, {self.neutral_us}, {self.max_us}')

    def pulse_us(self, pct: float, deadband_pct: float = 0.0) -> float:
        """Pulse width for a command in percent (-100..100); inside the dead band: neutral."""
        if not math.isfinite(pct) or abs(pct) <= deadband_pct:
            return self.neutral_us
        pct = max(-100.0, min(100.0, -pct if self.reversed else pct))
        span = self.max_us - self.neutral_us if pct > 0 else self.neutral_us - self.min_us
        return self.neutral_us + pct / 100.0 * span

    def target_qus(self, pct: float, deadband_pct: float = 0.0) -> int:
        """Set Target value (quarter-microseconds) for a command in percent."""
        return int(round(4.0 * self.pulse_us(pct, deadband_pct)))


@dataclass(frozen=True)
class SwitchConfig:
    """The servo switch's wiring and calibration (node parameters, validated)."""

    outputs: dict[str, tuple[OutputChannel, OutputChannel]]  # actuator -> (port, stbd)
    select_channel: int
    link_channel: int
    stick_channels: tuple[int, ...] = ()
    input_threshold_raw: int = 512       # logic input: high above, low below (+/- hysteresis)
    input_hysteresis_raw: int = 100
    select_rc_when_high: bool = True
    link_ok_when_high: bool = True
    stick_us_at_0v: float = 1000.0
    stick_us_at_5v: float = 2000.0
    deadband_pct: float = 2.0
    reply_timeout_s: float = 0.1
    device_timeout_s: float = 0.5

    def __post_init__(self) -> None:
        inputs = (self.select_channel, self.link_channel, *self.stick_channels)
        for channel in inputs:
            _check_channel(channel)
        used = [o.channel for pair in self.outputs.values() for o in pair] + list(inputs)
        if len(set(used)) != len(used):
            raise ConfigError(f'servo switch channels are used twice: {sorted(used)}')
        if set(self.outputs) != set(CommandGate.ACTUATORS):
            raise ConfigError(f'outputs must map exactly {CommandGate.ACTUATORS}')
        if not 0 <= self.deadband_pct < 50:
            raise ConfigError(f'deadband_pct must be in [0, 50), got {self.deadband_pct}')
        if not 0 < self.reply_timeout_s <= self.device_timeout_s:
            raise ConfigError('need 0 < reply_timeout_s <= device_timeout_s')


@dataclass(frozen=True)
class RcReading:
    """One complete, validated set of input readings."""

    rc_selected: bool
    link_ok: bool
    channels_us: tuple[float, ...]
    errors: tuple[str, ...]


class ReplyParser:
    """Matches the Maestro's 2-byte replies to the queries sent, in order; never raises.

    ``expect(kinds)`` registers a batch of queries; ``feed`` returns the batch's
    values once all arrived. Bytes that come with nothing pending, values out of
    range and batches not answered within the reply timeout count as parse
    errors and are dropped whole.
    """

    def __init__(self, reply_timeout_s: float) -> None:
        self.reply_timeout_s = reply_timeout_s
        self._pending: collections.deque[str] = collections.deque()
        self._values: list[int] = []
        self._buffer = bytearray()
        self._sent_s = 0.0
        self.parse_errors = 0
        self.timeouts = 0

    @property
    def busy(self) -> bool:
        """True while a batch waits for replies."""
        return bool(self._pending)

    def expect(self, kinds: list[str], now_s: float) -> None:
        """Register a batch: each kind is 'position' or 'errors'."""
        if self._buffer:
            self.parse_errors += 1
            self._buffer.clear()
        self._pending = collections.deque(kinds)
        self._values = []
        self._sent_s = now_s

    def feed(self, data: bytes, now_s: float) -> list[int] | None:
        """Take received bytes; return the batch's values when it is complete."""
        if not self._pending:
            if data:
                self.parse_errors += 1  # unsolicited bytes
            return None
        self._buffer.extend(data)
        while self._pending and len(self._buffer) >= 2:
            value = self._buffer[0] | self._buffer[1] << 8
            del self._buffer[:2]
            kind = self._pending.popleft()
            if (kind == 'position' and value > MAX_INPUT_RAW) or (
                    kind == 'errors' and value >> (max(ERROR_BITS) + 1)):
                self._drop()
                return None
            self._values.append(value)
        if self._pending:
            if now_s - self._sent_s > self.reply_timeout_s:
                self.timeouts += 1
                self._drop()
            return None
        if self._buffer:  # more bytes than asked for: alignment is unknown
            self._drop()
            return None
        return self._values

    def _drop(self) -> None:
        self.parse_errors += 1
        self._pending.clear()
        self._buffer.clear()
        self._values = []


class ServoSwitch:
    """The servo switch: computer commands through the CommandGate to Maestro frames.

    Call ``feed(received, now)`` with what the link read, ``command(...)`` for
    every computer command, and write ``cycle(now)`` to the link each period.
    """

    def __init__(self, config: SwitchConfig, command_timeout_s: float) -> None:
        self.config = config
        self.gate = CommandGate(command_timeout_s)
        self.parser = ReplyParser(config.reply_timeout_s)
        self.last_reading: RcReading | None = None
        self._last_reading_s = -math.inf
        self._select_high = self._link_high = False
        self.device_errors: tuple[str, ...] = ()     # in the last reading
        self._errors_seen: set[str] = set()

    def take_device_errors(self) -> list[str]:
        """Maestro error bits seen since the last call (reading the register clears it)."""
        seen, self._errors_seen = sorted(self._errors_seen), set()
        return seen

    def _queries(self) -> tuple[bytes, list[str]]:
        cfg = self.config
        channels = (cfg.select_channel, cfg.link_channel, *cfg.stick_channels)
        frame = b''.join(encode_get_position(c) for c in channels) + encode_get_errors()
        return frame, ['position'] * len(channels) + ['errors']

    def feed(self, data: bytes, now_s: float) -> RcReading | None:
        """Parse received bytes; on a complete batch update the gate and return the reading."""
        values = self.parser.feed(data, now_s)
        if values is None:
            return None
        cfg = self.config
        self._select_high = self._logic(values[0], self._select_high)
        self._link_high = self._logic(values[1], self._link_high)
        span = cfg.stick_us_at_5v - cfg.stick_us_at_0v
        sticks = tuple(cfg.stick_us_at_0v + raw / MAX_INPUT_RAW * span for raw in values[2:-1])
        self.device_errors = tuple(decode_errors(values[-1]))
        self._errors_seen.update(self.device_errors)
        selected = self._select_high == cfg.select_rc_when_high
        link_ok = self._link_high == cfg.link_ok_when_high
        if not link_ok:  # the receiver's outputs mean nothing now: report "no pulse"
            sticks = (0.0,) * len(sticks)
        self.last_reading = RcReading(selected, link_ok, sticks, self.device_errors)
        self._last_reading_s = now_s
        self.gate.update_rc(rc_selected=selected, rc_link_ok=link_ok)
        return self.last_reading

    def _logic(self, raw: int, was_high: bool) -> bool:
        """Threshold with hysteresis: a high line stays high until below threshold - hysteresis."""
        cfg = self.config
        edge = cfg.input_threshold_raw + (-1 if was_high else 1) * cfg.input_hysteresis_raw
        return raw > edge

    def command(self, actuator: str, port_pct: float, stbd_pct: float, now_s: float) -> bool:
        """Offer a computer command; ValueError if NaN/out of range; False if not forwarded."""
        return self.gate.command(actuator, validate_command(port_pct, stbd_pct), now_s)

    def device_lost(self, detail: str) -> None:
        """The link is down: neutral, and nobody holds authority until the device answers."""
        self.gate.device_lost(detail)
        self.parser.expect([], 0.0)

    def targets(self, outputs: dict[str, SideCommand]) -> bytes:
        """Set Target frames for every output."""
        frames = []
        deadband = self.config.deadband_pct
        for actuator, (port, stbd) in self.config.outputs.items():
            cmd = outputs[actuator]
            frames.append(encode_set_target(port.channel, port.target_qus(cmd.port_pct, deadband)))
            frames.append(encode_set_target(stbd.channel, stbd.target_qus(cmd.stbd_pct, deadband)))
        return b''.join(frames)

    def neutral_frame(self) -> bytes:
        """Every output to neutral."""
        return self.targets({a: SideCommand() for a in self.config.outputs})

    def cycle(self, now_s: float) -> bytes:
        """Bytes to write this period: the outputs, and a query batch if none is pending."""
        if now_s - self._last_reading_s > self.config.device_timeout_s:
            self.gate.device_lost('servo controller not answering')
        frame = self.targets(self.gate.outputs(now_s))
        self.parser.feed(b'', now_s)  # expire an unanswered batch
        if not self.parser.busy:
            queries, kinds = self._queries()
            self.parser.expect(kinds, now_s)
            frame += queries
        return frame

    def shutdown(self) -> bytes:
        """Stop: the gate goes neutral; returns the neutral frame to write."""
        self.gate.shutdown()
        return self.neutral_frame()


#: Output order of the ``output_*`` parameter lists.
OUTPUT_ORDER = (('tracks', 'port'), ('tracks', 'stbd'), ('props', 'port'), ('props', 'stbd'))


def switch_config(params: dict) -> SwitchConfig:
    """Build a SwitchConfig from the node's parameters; ConfigError names a bad one."""
    lists = {}
    for name in ('output_channels', 'output_neutral_us', 'output_min_us', 'output_max_us',
                 'output_reversed'):
        value = list(params[name])
        if len(value) != len(OUTPUT_ORDER):
            raise ConfigError(f'parameter {name!r} needs {len(OUTPUT_ORDER)} values '
                              '(port track, stbd track, port prop, stbd prop), '
                              f'got {len(value)}')
        lists[name] = value
    channels = {}
    for i, (actuator, side) in enumerate(OUTPUT_ORDER):
        try:
            channels[actuator, side] = OutputChannel(
                f'{side}_{actuator}', int(lists['output_channels'][i]),
                float(lists['output_neutral_us'][i]), float(lists['output_min_us'][i]),
                float(lists['output_max_us'][i]), bool(lists['output_reversed'][i]))
        except ValueError as exc:
            raise ConfigError(f'parameter output_* entry {i} ({side} {actuator}): {exc}') from exc
    outputs = {a: (channels[a, 'port'], channels[a, 'stbd']) for a in CommandGate.ACTUATORS}
    try:
        return SwitchConfig(
            outputs, int(params['select_channel']), int(params['link_channel']),
            tuple(int(c) for c in params['stick_channels']),
            int(params['input_threshold_raw']), int(params['input_hysteresis_raw']),
            bool(params['select_rc_when_high']), bool(params['link_ok_when_high']),
            float(params['stick_us_at_0v']), float(params['stick_us_at_5v']),
            float(params['deadband_pct']), float(params['reply_timeout_s']),
            float(params['device_timeout_s']))
    except ConfigError:
        raise
    except ValueError as exc:  # a channel out of range
        raise ConfigError(f'servo switch channel parameters: {exc}') from exc
