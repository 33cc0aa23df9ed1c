"""ROS-free pieces of sim_node: pacing sim time against the wall clock, and its health.

`Pacer` says how many physics steps a timer tick should run so that sim time
follows wall time x real_time_factor (0 = as fast as possible), catching up
after a late tick but never by more than ``max_lag_s``. `SpeedMeter` measures
the real-time factor achieved and the topics' rates between two reports.
"""
from __future__ import annotations

import math
from typing import Mapping

from dukw_common.diagnostics import Health, Level
from dukw_driver.authority import AuthorityState, Holder, Reason


class Pacer:
    """How many physics steps are due for a real-time factor; the timer period it wants.

    The node runs the due steps in a tick until they are done or its wall-clock
    budget is spent (so commands and services get their turn), and reports how many
    it took. The debt a slow or late tick leaves is caught up later, but never more
    than ``max_lag_s`` of it: beyond that the simulator gives up and says so.
    """

    def __init__(self, real_time_factor: float, dt_s: float, steps_per_tick: int,
                 max_lag_s: float, wall_s: float) -> None:
        if real_time_factor < 0 or not math.isfinite(real_time_factor):
            raise ValueError(f'real_time_factor must be >= 0, got {real_time_factor}')
        if dt_s <= 0 or steps_per_tick < 1 or max_lag_s <= 0:
            raise ValueError('need dt_s > 0, steps_per_tick >= 1 and max_lag_s > 0')
        self.rtf = real_time_factor
        self.dt_s = dt_s
        self.steps_per_tick = steps_per_tick
        self.max_lag_steps = max(1, int(max_lag_s / dt_s))
        self.wall0_s = wall_s
        self.steps = 0          # steps taken (as reported to took())
        self.dropped_s = 0.0    # sim time given up because the simulator could not keep up

    @property
    def period_s(self) -> float:
        """Wall-clock timer period: one tick per steps_per_tick steps (0: as often as possible)."""
        return 0.0 if self.rtf == 0 else self.steps_per_tick * self.dt_s / self.rtf

    def steps_due(self, wall_s: float) -> int:
        """Steps owed at ``wall_s`` (as fast as possible: max_lag_s worth per tick)."""
        if self.rtf == 0:
            return self.max_lag_steps
        n = int((wall_s - self.wall0_s) * self.rtf / self.dt_s) - self.steps
        if n > self.max_lag_steps:   # cannot keep up: forget the debt beyond max_lag
            extra = n - self.max_lag_steps
            self.wall0_s += extra * self.dt_s / self.rtf
            self.dropped_s += extra * self.dt_s
            n = self.max_lag_steps
        return max(0, n)

    def took(self, steps: int) -> None:
        """Count the steps a tick ran."""
        self.steps += steps


class SpeedMeter:
    """Real-time factor achieved and per-topic rates (Hz of sim time) between reports."""

    def __init__(self, wall_s: float, sim_s: float) -> None:
        self._mark = (wall_s, sim_s, {})
        self.achieved_rtf = math.nan

    def report(self, wall_s: float, sim_s: float,
               counts: Mapping[str, int]) -> dict[str, float]:
        """Update the achieved factor; return each topic's rate since the last report."""
        wall0, sim0, counts0 = self._mark
        self._mark = (wall_s, sim_s, dict(counts))
        if wall_s > wall0:
            self.achieved_rtf = (sim_s - sim0) / (wall_s - wall0)
        if sim_s <= sim0:
            return {}
        return {k: (n - counts0.get(k, 0)) / (sim_s - sim0) for k, n in counts.items()}


def sim_healths(sim_s: float, asked_rtf: float, meter: SpeedMeter, dropped_s: float,
                values: Mapping[str, object], state: AuthorityState, rejected: int,
                ignored: int, rates_hz: Mapping[str, float]) -> list[Health]:
    """The simulator's speed, the servo switch's authority and the topics' rates."""
    achieved = meter.achieved_rtf
    sim = Health('simulator', values={
        'sim_time_s': f'{sim_s:.2f}', 'real_time_factor': asked_rtf,
        'achieved_real_time_factor': f'{achieved:.2f}', 'dropped_sim_s': f'{dropped_s:.2f}',
        **values})
    if asked_rtf > 0 and achieved < 0.9 * asked_rtf:
        sim.worsen(Level.WARN, f'running at {achieved:.2f}x of the {asked_rtf:g}x asked')
    auth = Health('authority', message=state.detail, values={
        'holder': Holder(state.holder).name, 'reason': Reason(state.reason).name,
        'rc_link_ok': state.rc_link_ok, 'outputs_neutral': state.outputs_neutral,
        'rejected_commands': rejected, 'ignored_commands': ignored})
    if not state.rc_link_ok:
        auth.worsen(Level.WARN, 'RC link lost')
    topics = Health('topics', message='rates in Hz of sim time',
                    values={t: f'{r:.1f}' for t, r in sorted(rates_hz.items())})
    return [sim, auth, topics]
