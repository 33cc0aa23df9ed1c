"""Incline guard and stuck detection (vehicle.md section 3), ROS-free.

Incline: nose-up positive, ``incline_rad = -pitch_rad`` in REP 103 (positive pitch
is nose down). Climbing means driving toward the higher end: forward with the
nose up, astern with the nose down. The guard only ever removes the climbing
part of a request; driving down or turning away stays allowed.
"""
from __future__ import annotations

from enum import Enum


class InclineState(Enum):
    """What the incline guard does."""

    OK = 'ok'
    STEEP = 'beyond the sustained limit: timing'
    STOP_SUSTAINED = 'beyond the sustained limit too long: climbing stopped'
    STOP_BRIEF = 'beyond the brief limit: climbing stopped'


class InclineGuard:
    """Stops climbing beyond 10 deg held too long, or beyond 15 deg at once."""

    def __init__(self, sustained_rad: float, brief_rad: float, sustained_time_s: float,
                 release_margin_rad: float) -> None:
        if not 0 < sustained_rad < brief_rad:
            raise ValueError('need 0 < sustained_rad < brief_rad')
        if sustained_time_s < 0 or release_margin_rad < 0:
            raise ValueError('sustained_time_s and release_margin_rad must be >= 0')
        self.sustained_rad, self.brief_rad = sustained_rad, brief_rad
        self.sustained_time_s, self.release_margin_rad = sustained_time_s, release_margin_rad
        self.state = InclineState.OK
        self.steep_for_s = 0.0
        self.incline_rad = 0.0

    @property
    def stopping(self) -> bool:
        """True while climbing is not allowed."""
        return self.state in (InclineState.STOP_SUSTAINED, InclineState.STOP_BRIEF)

    def update(self, incline_rad: float, dt_s: float) -> InclineState:
        """Feed the nose-up incline over ``dt_s``; return the state."""
        self.incline_rad = incline_rad
        steep = abs(incline_rad)
        if steep > self.brief_rad:
            self.steep_for_s += dt_s
            self.state = InclineState.STOP_BRIEF
        elif steep > self.sustained_rad:
            self.steep_for_s += dt_s
            if self.steep_for_s > self.sustained_time_s:
                self.state = InclineState.STOP_SUSTAINED
            elif not self.stopping:
                self.state = InclineState.STEEP
        elif steep < self.sustained_rad - self.release_margin_rad:
            self.steep_for_s = 0.0
            self.state = InclineState.OK
        return self.state

    def limit(self, speed_mps: float) -> float:
        """Remove the climbing part of a speed request while stopping."""
        if self.stopping and speed_mps * self.incline_rad > 0.0:
            return 0.0
        return speed_mps

    def reset(self) -> None:
        """Forget the history (e.g. after the operator had the vehicle)."""
        self.state, self.steep_for_s = InclineState.OK, 0.0


class StuckDetector:
    """Both tracks slipping near 1 with no progress for a while -> stuck (latched)."""

    def __init__(self, slip_threshold: float, speed_threshold_mps: float,
                 min_command_pct: float, hold_s: float) -> None:
        if not 0 < slip_threshold <= 1:
            raise ValueError('slip_threshold must lie in (0, 1]')
        if speed_threshold_mps < 0 or min_command_pct < 0 or hold_s < 0:
            raise ValueError('stuck thresholds must be >= 0')
        self.slip_threshold, self.speed_threshold_mps = slip_threshold, speed_threshold_mps
        self.min_command_pct, self.hold_s = min_command_pct, hold_s
        self.stuck = False
        self.spinning_for_s = 0.0
        self.reason = ''

    def update(self, port_slip: float, stbd_slip: float, ground_speed_mps: float,
               track_command_pct: float, dt_s: float) -> bool:
        """Feed slips, ground speed and the larger track command; return ``stuck``."""
        spinning = (min(port_slip, stbd_slip) >= self.slip_threshold
                    and abs(ground_speed_mps) < self.speed_threshold_mps
                    and abs(track_command_pct) >= self.min_command_pct)
        self.spinning_for_s = self.spinning_for_s + dt_s if spinning else 0.0
        if not self.stuck and self.spinning_for_s >= self.hold_s:
            self.stuck = True
            self.reason = (f'stuck: slip {port_slip:.2f}/{stbd_slip:.2f} at '
                           f'{ground_speed_mps:.2f} m/s for {self.spinning_for_s:.1f} s')
        return self.stuck

    def clear(self) -> None:
        """Release the latch (a fresh stop request, a reversal, or the operator)."""
        self.stuck, self.spinning_for_s, self.reason = False, 0.0, ''
