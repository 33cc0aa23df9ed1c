"""Publish rates per consumer, ROS-free: thin a stream out to the rate its readers need.

The estimate comes at the IMU's 100 Hz; the controller steps on every one of them, but an
observer (a viewer, a recorder, the shore link) needs /tf or traction far less often
(README "Topic contract: rates"). ``Decimator(rate_hz).due(t_s)`` says whether a sample at
``t_s`` goes out: the first one does, then the first at least one period after the last
that went out (less a slack for the jitter of stamps: 5 % of the period, at most 2 ms).
"""
from __future__ import annotations

import math

#: a sample this share of a period early still counts as due (jittered stamps) ...
TOLERANCE = 0.05
#: ... but never more than this early, s
MAX_SLACK_S = 0.002


class Decimator:
    """Lets through at most ``rate_hz`` samples a second of a stream, by sample time."""

    def __init__(self, rate_hz: float) -> None:
        if not (math.isfinite(rate_hz) and rate_hz > 0.0):
            raise ValueError(f'rate must be a finite number of Hz > 0, got {rate_hz!r}')
        self.period_s = 1.0 / rate_hz
        self.min_gap_s = self.period_s - min(TOLERANCE * self.period_s, MAX_SLACK_S)
        self.last_s = -math.inf

    def due(self, t_s: float) -> bool:
        """Whether the sample at ``t_s`` goes out (a step back in time starts afresh)."""
        if t_s < self.last_s or t_s - self.last_s >= self.min_gap_s:
            self.last_s = t_s
            return True
        return False
