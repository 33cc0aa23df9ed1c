"""The paper's open-loop tests as command schedules, and the limits that abort them.

ROS-free. A ``ManeuverPlan`` gives the raw (unbiased) port/starboard command at
time t since the start: circle (constant pair), zigzag (the pair swaps sides every
period, vehicle.md section 4), incline (straight at one command), transition
(straight, tracks and/or props). ``ManeuverPlayer`` adds the port bias, routes the
command to tracks, props or both, and aborts to neutral for good when the RC
operator takes over or a limit trips.
"""
from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

from dukw_control.guards import InclineGuard
from dukw_control.limits import CurrentLimiter
from dukw_control.mixer import NEUTRAL, SidePair, apply_port_bias

MANEUVERS = ('circle', 'zigzag', 'incline', 'transition')
ACTUATORS = ('tracks', 'props', 'both')


@dataclass(frozen=True)
class ManeuverPlan:
    """What to play: kind, command levels (percent) and timing (seconds)."""

    maneuver: str
    port_pct: float = 0.0          # circle
    stbd_pct: float = 0.0
    high_pct: float = 0.0          # zigzag
    low_pct: float = 0.0
    period_s: float = 10.0
    command_pct: float = 0.0       # incline, transition
    duration_s: float = 30.0

    def __post_init__(self) -> None:
        if self.maneuver not in MANEUVERS:
            raise ValueError(f'unknown maneuver {self.maneuver!r}; known: {MANEUVERS}')
        for name in ('port_pct', 'stbd_pct', 'high_pct', 'low_pct', 'command_pct'):
            if not -100.0 <= getattr(self, name) <= 100.0:
                raise ValueError(f'{name} must lie in [-100, 100]')
        if not (self.period_s > 0 and self.duration_s > 0):
            raise ValueError('period_s and duration_s must be > 0')

    def command_at(self, t_s: float) -> SidePair | None:
        """Raw command at ``t_s`` since the start; None once the run is over."""
        if t_s < 0 or t_s >= self.duration_s:
            return None
        if self.maneuver == 'circle':
            return SidePair(self.port_pct, self.stbd_pct)
        if self.maneuver == 'zigzag':
            first_half = int(t_s // self.period_s) % 2 == 0
            return (SidePair(self.high_pct, self.low_pct) if first_half
                    else SidePair(self.low_pct, self.high_pct))
        return SidePair(self.command_pct, self.command_pct)


class PlayerState(Enum):
    """Where the player is."""

    WAITING = 'waiting for authority'
    PLAYING = 'playing'
    DONE = 'done'
    ABORTED = 'aborted'


class ManeuverPlayer:
    """Plays a plan with the bias applied; aborts to neutral on the operator or a limit."""

    def __init__(self, plan: ManeuverPlan, actuators: str, port_bias_pct: float,
                 incline: InclineGuard, current: dict[str, CurrentLimiter],
                 start_wait_s: float, status_timeout_s: float) -> None:
        if actuators not in ACTUATORS:
            raise ValueError(f'unknown actuators {actuators!r}; known: {ACTUATORS}')
        if not (start_wait_s > 0.0 and status_timeout_s > 0.0):
            raise ValueError('start_wait_s and status_timeout_s must be > 0')
        self.plan, self.actuators, self.port_bias_pct = plan, actuators, port_bias_pct
        self.incline, self.current = incline, current
        self.start_wait_s, self.status_timeout_s = start_wait_s, status_timeout_s
        self.state = PlayerState.WAITING
        self.reason = ''
        self._start_s = 0.0
        self._waiting_since_s: float | None = None
        self._status_s: float | None = None     # last tracks/status; None: none yet

    def on_status(self, now_s: float, port_current_a: float, stbd_current_a: float) -> None:
        """A tracks/status at ``now_s``: feeds the current limits, keeps the status fresh."""
        dt_s = 0.0 if self._status_s is None else min(max(now_s - self._status_s, 0.0), 0.5)
        self._status_s = now_s
        self.current['port'].update(port_current_a, dt_s)
        self.current['stbd'].update(stbd_current_a, dt_s)

    def _status_missing(self, now_s: float) -> str:
        """'' when tracks/status is not needed or fresh, else what is wrong with it."""
        if self.actuators == 'props':
            return ''
        if self._status_s is None:
            return 'tracks/status never arrived'
        if now_s - self._status_s > self.status_timeout_s:
            return 'tracks/status stale'
        return ''

    def _wait(self, now_s: float, authority_usable: bool) -> None:
        """Start once authority and a fresh tracks/status are there; give up after
        ``start_wait_s`` (a status not there yet is waited for, not stale)."""
        if self._waiting_since_s is None:
            self._waiting_since_s = now_s
        missing = self._status_missing(now_s)
        if authority_usable and not missing:
            self.state, self._start_s = PlayerState.PLAYING, now_s
        elif now_s - self._waiting_since_s > self.start_wait_s:
            self.abort(missing if authority_usable else 'the computer never got authority')

    def abort(self, reason: str) -> None:
        """Stop for good (neutral from now on)."""
        if self.state in (PlayerState.WAITING, PlayerState.PLAYING):
            self.state, self.reason = PlayerState.ABORTED, reason

    def step(self, now_s: float, authority_usable: bool, incline_rad: float,
             dt_s: float) -> tuple[SidePair, SidePair]:
        """(tracks, props) to publish at ``now_s``."""
        if self.state == PlayerState.WAITING:
            self._wait(now_s, authority_usable)
        if self.state != PlayerState.PLAYING:
            return NEUTRAL, NEUTRAL
        if not authority_usable:
            self.abort('the RC operator took over (or the link dropped)')
        if self._status_missing(now_s):
            self.abort(f'{self._status_missing(now_s)}: the current limit cannot be watched')
        if self.actuators != 'props' and self.incline.update(incline_rad, dt_s) and \
                self.incline.stopping:
            self.abort(f'incline limit: {self.incline.state.value}')
        spent = [side for side, lim in self.current.items() if lim.used_fraction >= 1.0]
        if spent:
            self.abort(f'current allowance spent on the {" and ".join(spent)} track motor')
        raw = self.plan.command_at(now_s - self._start_s)
        if raw is None and self.state == PlayerState.PLAYING:
            self.state, self.reason = PlayerState.DONE, 'finished'
        if self.state != PlayerState.PLAYING:
            return NEUTRAL, NEUTRAL
        biased = apply_port_bias(raw, self.port_bias_pct, 0.0)
        tracks = biased if self.actuators in ('tracks', 'both') else NEUTRAL
        props = biased if self.actuators in ('props', 'both') else NEUTRAL
        return tracks, props
