"""ROS-free health reporting: what a node says on /diagnostics, and message-rate counting.

Nodes build ``Health`` values from their cores; ``dukw_common.node_tools``
turns them into diagnostic_msgs/DiagnosticArray.
"""
from __future__ import annotations

import collections
from dataclasses import dataclass, field
from enum import IntEnum


class Level(IntEnum):
    """diagnostic_msgs/DiagnosticStatus levels."""

    OK = 0
    WARN = 1
    ERROR = 2
    STALE = 3


@dataclass
class Health:
    """One component's status: level, a sentence, and key figures."""

    name: str
    level: Level = Level.OK
    message: str = 'ok'
    hardware_id: str = ''
    values: dict[str, object] = field(default_factory=dict)

    def worsen(self, level: Level, message: str) -> None:
        """Raise the level to ``level`` (never lower it) and set the message if it rose."""
        if level > self.level:
            self.level = level
            self.message = message
        elif level == self.level and level != Level.OK and message not in self.message:
            self.message = f'{self.message}; {message}'


class RateCounter:
    """Messages per second over a sliding window, from event times in seconds."""

    def __init__(self, window_s: float = 2.0) -> None:
        self.window_s = window_s
        self._times: collections.deque[float] = collections.deque()
        self.total = 0

    def tick(self, now_s: float) -> None:
        """Count one event at ``now_s``."""
        self._times.append(now_s)
        self.total += 1
        self._trim(now_s)

    def rate_hz(self, now_s: float) -> float:
        """Events per second in the last window."""
        self._trim(now_s)
        return len(self._times) / self.window_s

    def age_s(self, now_s: float) -> float:
        """Seconds since the last event (inf if none)."""
        return now_s - self._times[-1] if self._times else float('inf')

    def _trim(self, now_s: float) -> None:
        while self._times and self._times[0] < now_s - self.window_s:
            self._times.popleft()
