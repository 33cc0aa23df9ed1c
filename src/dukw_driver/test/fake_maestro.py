"""A Pololu Mini Maestro 12 emulator speaking the compact serial protocol (for FakeDevice).

It keeps the 12 channels' targets (quarter-us) as Set Target writes them, answers
Get Position with an input channel's raw value (``inputs``, 0..1023) or an
output's target, answers Get Errors with the error register and clears it, and
sets the serial-protocol error bit on bytes it does not understand, as the
real device does.
"""
import threading

RAW_HIGH = 1023
RAW_LOW = 0


class FakeMaestro:
    """Byte-level Maestro: ``feed(host bytes) -> reply bytes``."""

    def __init__(self, inputs: dict[int, int] | None = None) -> None:
        self.targets = [0] * 12
        self.inputs = dict(inputs or {})
        self.errors = 0
        self.set_targets = 0
        self.lock = threading.Lock()
        self._buffer = bytearray()

    def set_lines(self, select_rc: bool, link_ok: bool, select_channel: int = 4,
                  link_channel: int = 5) -> None:
        """Drive the multiplexer-select and RC-link input lines (active high)."""
        with self.lock:
            self.inputs[select_channel] = RAW_HIGH if select_rc else RAW_LOW
            self.inputs[link_channel] = RAW_HIGH if link_ok else RAW_LOW

    def target_us(self, channel: int) -> float:
        """A channel's target as a pulse width in microseconds."""
        with self.lock:
            return self.targets[channel] / 4.0

    def feed(self, data: bytes) -> bytes:
        """Take bytes from the host; return the replies."""
        with self.lock:
            self._buffer.extend(data)
            reply = bytearray()
            while self._buffer:
                command = self._buffer[0]
                if command == 0x84:
                    if len(self._buffer) < 4:
                        break
                    channel, low, high = self._buffer[1:4]
                    del self._buffer[:4]
                    if channel < 12 and not (low | high) & 0x80:
                        self.targets[channel] = low | high << 7
                        self.set_targets += 1
                    else:
                        self.errors |= 1 << 4
                elif command == 0x90:
                    if len(self._buffer) < 2:
                        break
                    channel = self._buffer[1]
                    del self._buffer[:2]
                    value = self.inputs.get(channel, self.targets[channel % 12])
                    reply += bytes((value & 0xFF, value >> 8 & 0xFF))
                elif command == 0xA1:
                    del self._buffer[:1]
                    reply += bytes((self.errors & 0xFF, self.errors >> 8 & 0xFF))
                    self.errors = 0
                else:
                    del self._buffer[:1]
                    self.errors |= 1 << 4
            return bytes(reply)
