"""NMEA 0183 framing over a byte stream: lines, checksums, pynmea2 sentences. ROS-free.

A sentence is ``$<talker><type>,<fields>*<hh>\\r\\n`` with ``hh`` the XOR of every
character between ``$`` and ``*`` in hex. Every sentence must carry a checksum
(NMEA 0183 v2+ devices, the DGPS and the Airmar DT800, always send one); a line
without one, or with a wrong one, is counted and dropped. Garbage before the
``$`` (a half line after a reconnect, noise) is skipped.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Iterable, Mapping

import pynmea2

#: NMEA 0183 allows 82 characters; leave room for proprietary sentences.
MAX_LINE_BYTES = 256


def nmea_checksum(body: str) -> str:
    """Return the two-hex-digit checksum of ``body`` (the text between '$' and '*')."""
    value = 0
    for char in body.encode('ascii'):
        value ^= char
    return f'{value:02X}'


def nmea_sentence(body: str) -> bytes:
    """Frame ``body`` (e.g. 'SDMTW,17.5,C') as a complete sentence with checksum and CRLF."""
    return f'${body}*{nmea_checksum(body)}\r\n'.encode('ascii')


@dataclass
class NmeaCounters:
    """What the framer has seen since start."""

    sentences: int = 0          # checksum good and understood by pynmea2
    checksum_errors: int = 0    # missing or wrong checksum
    parse_errors: int = 0       # framing or field errors (non-ASCII, overlong, malformed)
    ignored: int = 0            # well-formed sentences of a type nobody asked for

    @property
    def messages(self) -> int:
        """Good sentences."""
        return self.sentences

    @property
    def errors(self) -> int:
        """Checksum plus parse errors."""
        return self.checksum_errors + self.parse_errors


class NmeaStream:
    """Cut a byte stream into checked pynmea2 sentences of the wanted types.

    ``feed(data)`` never raises: bad input only increments ``counters``.
    """

    def __init__(self, sentence_types: Iterable[str]) -> None:
        self.sentence_types = frozenset(sentence_types)
        self.counters = NmeaCounters()
        self._buffer = bytearray()

    def reset(self) -> None:
        """Drop a partial line (after a reconnect the rest of it never comes)."""
        self._buffer.clear()

    def feed(self, data: bytes) -> list[pynmea2.NMEASentence]:
        """Add received bytes; return the complete, valid sentences of the wanted types."""
        self._buffer.extend(data)
        out = []
        while True:
            end = self._buffer.find(b'\n')
            if end < 0:
                break
            line = bytes(self._buffer[:end])
            del self._buffer[:end + 1]
            sentence = self._parse_line(line)
            if sentence is not None:
                out.append(sentence)
        if len(self._buffer) > MAX_LINE_BYTES:  # no line end in sight: noise, drop it
            self.counters.parse_errors += 1
            self._buffer.clear()
        return out

    def decode(self, data: bytes, now_s: float,
               handlers: Mapping[str, Callable[[Any, float], Any]]) -> list:
        """Feed ``data`` and pass each sentence to ``handlers[type](sentence, now_s)``.

        Returns the handlers' results that are not None. A handler that finds a field
        unusable raises ValueError (or pynmea2's own field errors): counted, skipped.
        """
        out = []
        for sentence in self.feed(data):
            try:
                result = handlers[sentence.sentence_type](sentence, now_s)
            except (ValueError, TypeError, AttributeError, ArithmeticError):
                self.counters.parse_errors += 1
                continue
            if result is not None:
                out.append(result)
        return out

    def _parse_line(self, raw: bytes) -> pynmea2.NMEASentence | None:
        start = raw.rfind(b'$')
        if start < 0:
            if raw.strip():
                self.counters.parse_errors += 1
            return None
        raw = raw[start:].strip()
        if len(raw) > MAX_LINE_BYTES:
            self.counters.parse_errors += 1
            return None
        try:
            line = raw.decode('ascii')
        except UnicodeDecodeError:
            self.counters.parse_errors += 1
            return None
        body, star, given = line[1:].partition('*')
        if not star or given.upper() != nmea_checksum(body):
            self.counters.checksum_errors += 1
            return None
        kind = body.split(',', 1)[0]
        if kind[-3:] not in self.sentence_types:
            self.counters.ignored += 1
            return None
        try:
            sentence = pynmea2.parse(line)
        except (pynmea2.ParseError, ValueError, TypeError, AttributeError):
            self.counters.parse_errors += 1
            return None
        self.counters.sentences += 1
        return sentence
