"""Roboteq dual-channel motor controller, ASCII serial protocol: queries and replies (ROS-free).

The host sends queries ``?A\\r`` and the controller answers ``A=123:145\\r``
(values separated by ':'); with echo on (the factory default) it first echoes
the query line back. Commands (``!G 1 500``) and configuration writes are
answered ``+`` (accepted) or ``-`` (refused). The queries used here:

===== =========================================== ======================
query reply                                       unit
===== =========================================== ======================
?A    motor amps, channel 1 : channel 2           0.1 A
?V    internal volts : battery volts : 5 V output 0.1 V, 0.1 V, mV
?S    encoder speed, channel 1 : channel 2        motor RPM
?M    motor command applied, ch 1 : ch 2          -1000 .. 1000
?T    temperature MCU : channel 1 : channel 2     degC
?FF   fault flags (controller)                    bit field
?FM   motor status flags, ch 1 : ch 2             bit field
?FS   status flags (controller)                   bit field
~RWD  serial watchdog period                      ms (0 = disabled)
===== =========================================== ======================

Flags are decoded bit by bit into the dukw_msgs/MotorSide FAULT_* values
(mirrored here without importing message types) and names.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

# dukw_msgs/MotorSide FAULT_* (same values; test_roboteq checks they match)
FAULT_OVERHEAT = 1
FAULT_OVERVOLTAGE = 2
FAULT_UNDERVOLTAGE = 4
FAULT_SHORT_CIRCUIT = 8
FAULT_EMERGENCY_STOP = 16
FAULT_SENSOR = 32
FAULT_MOSFET = 64
FAULT_CONFIG = 128
FAULT_STALL = 256
FAULT_COMM_TIMEOUT = 512

#: ?FF fault flags: bit -> (MotorSide FAULT_*, name). Bit 8 is "safe torque off" (newer firmware).
FAULT_FLAG_BITS = {
    0: (FAULT_OVERHEAT, 'overheat'), 1: (FAULT_OVERVOLTAGE, 'overvoltage'),
    2: (FAULT_UNDERVOLTAGE, 'undervoltage'), 3: (FAULT_SHORT_CIRCUIT, 'short_circuit'),
    4: (FAULT_EMERGENCY_STOP, 'emergency_stop'), 5: (FAULT_SENSOR, 'motor_sensor_setup'),
    6: (FAULT_MOSFET, 'mosfet_failure'), 7: (FAULT_CONFIG, 'default_config_loaded'),
    8: (FAULT_EMERGENCY_STOP, 'safe_torque_off'),
}
#: ?FM motor status flags per channel: bit -> (MotorSide FAULT_* or 0, name, is a fault).
MOTOR_FLAG_BITS = {
    0: (0, 'amps_limit', False), 1: (FAULT_STALL, 'stall', True),
    2: (0, 'loop_error', True), 3: (0, 'safety_stop', True),
    4: (0, 'forward_limit', False), 5: (0, 'reverse_limit', False),
    6: (0, 'amps_trigger', False),
}
#: ?FS status flags (controller): bit -> name.
STATUS_FLAG_BITS = {
    0: 'serial_mode', 1: 'pulse_mode', 2: 'analog_mode', 3: 'power_stage_off',
    4: 'stall_detected', 5: 'at_limit', 7: 'script_running',
}

#: Queries sent every cycle and how many values each reply must carry (min, max).
QUERIES = {'A': (2, 2), 'V': (2, 3), 'S': (2, 2), 'M': (2, 2), 'T': (3, 3), 'FF': (1, 1),
           'FM': (2, 2), 'FS': (1, 1)}
#: Configuration read once per connection.
CONFIG_QUERIES = {'RWD': (1, 1)}
MAX_LINE = 64
_REPLY = re.compile(r'^([A-Z]{1,4})=(-?\d{1,7}(?::-?\d{1,7}){0,7})$')


def query_frame(names=QUERIES) -> bytes:
    """The bytes asking for every runtime query (``?A\\r?V\\r...``)."""
    return b''.join(f'?{name}\r'.encode() for name in names)


def config_frame(names=CONFIG_QUERIES) -> bytes:
    """The bytes reading configuration values (``~RWD\\r``)."""
    return b''.join(f'~{name}\r'.encode() for name in names)


@dataclass(frozen=True)
class FaultReport:
    """Decoded fault flags of one motor channel."""

    flags: int                 # MotorSide FAULT_* bits
    names: tuple[str, ...]


def decode_faults(fault_flags: int, motor_flags: int) -> FaultReport:
    """Decode the controller's ?FF and one channel's ?FM, bit by bit."""
    flags, names = 0, []
    for bit, (fault, name) in FAULT_FLAG_BITS.items():
        if fault_flags >> bit & 1:
            flags |= fault
            names.append(name)
    for bit, (fault, name, is_fault) in MOTOR_FLAG_BITS.items():
        if motor_flags >> bit & 1 and is_fault:
            flags |= fault
            names.append(name)
    unknown = fault_flags >> (max(FAULT_FLAG_BITS) + 1)
    if unknown:
        names.append(f'unknown_fault_bits_{unknown << (max(FAULT_FLAG_BITS) + 1):#x}')
    return FaultReport(flags, tuple(names))


def decode_status(status_flags: int) -> list[str]:
    """Names of the set ?FS status flags."""
    return [name for bit, name in STATUS_FLAG_BITS.items() if status_flags >> bit & 1]


class ReplyParser:
    """Splits the byte stream into lines and parses replies; never raises.

    ``feed`` returns ``{name: values}`` for every well-formed reply in the bytes.
    Echoed queries, ``+`` and ``-`` are counted; anything else is a parse error.
    """

    def __init__(self, expected: dict[str, tuple[int, int]] | None = None) -> None:
        self.expected = dict(expected or {**QUERIES, **CONFIG_QUERIES})
        self._buffer = bytearray()
        self.parse_errors = 0
        self.replies = 0
        self.echoes = 0
        self.acks = 0
        self.nacks = 0

    def feed(self, data: bytes) -> dict[str, tuple[int, ...]]:
        """Parse complete lines in ``data`` (partial lines wait for the rest)."""
        self._buffer.extend(data.replace(b'\n', b'\r'))
        parsed: dict[str, tuple[int, ...]] = {}
        while True:
            end = self._buffer.find(b'\r')
            if end < 0:
                if len(self._buffer) > MAX_LINE:  # no terminator in sight: garbage
                    self.parse_errors += 1
                    self._buffer.clear()
                return parsed
            line = bytes(self._buffer[:end])
            del self._buffer[:end + 1]
            reply = self._parse_line(line)
            if reply is not None:
                parsed[reply[0]] = reply[1]

    def _parse_line(self, line: bytes) -> tuple[str, tuple[int, ...]] | None:
        try:
            text = line.decode('ascii').strip()
        except UnicodeDecodeError:
            self.parse_errors += 1
            return None
        if not text:
            return None
        if text[0] in '?!~^#%':
            self.echoes += 1
            return None
        if text == '+':
            self.acks += 1
            return None
        if text == '-':
            self.nacks += 1
            return None
        match = _REPLY.match(text)
        if match is None or match.group(1) not in self.expected:
            self.parse_errors += 1
            return None
        values = tuple(int(v) for v in match.group(2).split(':'))
        low, high = self.expected[match.group(1)]
        if not low <= len(values) <= high:
            self.parse_errors += 1
            return None
        self.replies += 1
        return match.group(1), values
