"""A Roboteq dual-channel controller emulator on its ASCII serial protocol (for FakeDevice).

Answers ``?A ?V ?S ?M ?T ?FF ?FM ?FS`` and ``~RWD`` from its attributes, echoes
every line first (the controller's default), acknowledges ``!`` commands with
``+`` (and records them) and answers anything else with ``-``.
"""
import threading


class FakeRoboteq:
    """Byte-level Roboteq: ``feed(host bytes) -> reply bytes``."""

    def __init__(self, echo: bool = True) -> None:
        self.echo = echo
        self.amps = (12.3, 14.5)          # A, channel 1 : channel 2
        self.battery_v = 24.6
        self.rpm = (1547, -300)
        self.command = (600, 560)         # -1000..1000
        self.temps_c = (35, 41, 43)       # MCU, channel 1, channel 2
        self.fault_flags = 0
        self.motor_flags = (0, 0)
        self.status_flags = 0b10          # pulse mode
        self.watchdog_ms = 1000
        self.commands: list[str] = []
        self.lock = threading.Lock()
        self._buffer = bytearray()

    def _answer(self, query: str) -> str:
        values = {
            'A': [round(a * 10) for a in self.amps],
            'V': [125, round(self.battery_v * 10), 4980],
            'S': list(self.rpm), 'M': list(self.command), 'T': list(self.temps_c),
            'FF': [self.fault_flags], 'FM': list(self.motor_flags), 'FS': [self.status_flags],
            'RWD': [self.watchdog_ms],
        }.get(query)
        return '-' if values is None else f'{query}=' + ':'.join(str(v) for v in values)

    def feed(self, data: bytes) -> bytes:
        """Take bytes from the host; return the replies."""
        with self.lock:
            self._buffer.extend(data)
            out = []
            while (end := self._buffer.find(b'\r')) >= 0:
                line = self._buffer[:end].decode('ascii', 'replace').strip()
                del self._buffer[:end + 1]
                if not line:
                    continue
                if self.echo:
                    out.append(line)
                if line[0] in '?~':
                    out.append(self._answer(line[1:].strip().upper()))
                elif line[0] == '!':
                    self.commands.append(line)
                    out.append('+')
                else:
                    out.append('-')
            return b''.join(f'{line}\r'.encode() for line in out)
