"""The servo switch's authority rule, one implementation for the boat and the simulator.

The 12-channel servo controller's multiplexer is switched by the RC transmitter:
the RC operator always wins and nothing in software can take authority from the
RC side. Computer commands reach the motors only while the computer holds
authority AND they are fresh; otherwise the computer-side outputs are neutral.
Losing the RC link is a fail-safe: outputs neutral, whoever held authority.
A command topic with more than one publisher is refused (dukw_common.sources):
outputs neutral until only one is left, as no one can tell which is genuine.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from enum import IntEnum

from dukw_common.sources import SourceWatch


class Holder(IntEnum):
    """Who holds authority (dukw_msgs/Authority HOLDER_*)."""

    RC = 0
    COMPUTER = 1
    NONE = 2


class Reason(IntEnum):
    """Why (dukw_msgs/Authority REASON_*)."""

    STARTUP = 0
    RC_SWITCH = 1
    RC_LINK_LOST = 2
    DEVICE_LOST = 3
    COMMAND_TIMEOUT = 4
    SHUTDOWN = 5


@dataclass(frozen=True)
class AuthorityState:
    """What the switch reports on `authority`."""

    holder: Holder
    reason: Reason
    rc_link_ok: bool
    outputs_neutral: bool
    detail: str


@dataclass(frozen=True)
class SideCommand:
    """Port and starboard command, percent of full scale."""

    port_pct: float = 0.0
    stbd_pct: float = 0.0


NEUTRAL = SideCommand(0.0, 0.0)


def validate_command(port_pct: float, stbd_pct: float, limit_pct: float = 100.0) -> SideCommand:
    """Return a SideCommand or raise ValueError for NaN, inf or out-of-range values."""
    for name, value in (('port_pct', port_pct), ('stbd_pct', stbd_pct)):
        if not math.isfinite(value):
            raise ValueError(f'{name} is not finite: {value}')
        if abs(value) > limit_pct:
            raise ValueError(f'{name}={value} outside +/-{limit_pct} %')
    return SideCommand(float(port_pct), float(stbd_pct))


class CommandGate:
    """Decides what the computer side of the multiplexer outputs.

    Feed it the RC state (``update_rc``), the device state (``device_lost`` /
    ``device_back``) and computer commands (``command``); ask it for the
    ``outputs`` each cycle. ``state`` tells who holds authority and why;
    ``changed`` is True once after every change, for publish-on-change.
    """

    ACTUATORS = ('tracks', 'props')

    def __init__(self, command_timeout_s: float) -> None:
        if not command_timeout_s > 0:
            raise ValueError('command_timeout_s must be > 0')
        self.command_timeout_s = command_timeout_s
        self._state = AuthorityState(Holder.NONE, Reason.STARTUP, False, True,
                                     'waiting for the servo controller')
        self._commands = {a: NEUTRAL for a in self.ACTUATORS}
        self._stamps = {a: -math.inf for a in self.ACTUATORS}
        self.sources = SourceWatch()
        self.changed = True

    @property
    def state(self) -> AuthorityState:
        """Current authority state."""
        return self._state

    def _set(self, **kwargs) -> None:
        new = replace(self._state, **kwargs)
        if new != self._state:
            self._state = new
            self.changed = True

    def update_rc(self, rc_selected: bool, rc_link_ok: bool) -> None:
        """Apply what the servo controller reads of the RC side (select line, link)."""
        if not rc_link_ok:
            self._set(holder=Holder.RC if rc_selected else Holder.NONE,
                      reason=Reason.RC_LINK_LOST, rc_link_ok=False, outputs_neutral=True,
                      detail='RC link lost: outputs neutral')
            self._drop_commands()
        elif rc_selected:
            self._set(holder=Holder.RC, reason=Reason.RC_SWITCH, rc_link_ok=True,
                      outputs_neutral=False, detail='RC operator holds authority')
            self._drop_commands()
        elif self._state.holder != Holder.COMPUTER or not self._state.rc_link_ok:
            self._set(holder=Holder.COMPUTER, reason=Reason.RC_SWITCH, rc_link_ok=True,
                      outputs_neutral=True, detail='computer holds authority')

    def device_lost(self, detail: str = 'servo controller not answering') -> None:
        """The servo controller stopped answering: nobody can be forwarded anything."""
        self._set(holder=Holder.NONE, reason=Reason.DEVICE_LOST, outputs_neutral=True,
                  detail=detail)
        self._drop_commands()

    def shutdown(self) -> None:
        """The node is stopping: neutral outputs."""
        self._set(reason=Reason.SHUTDOWN, outputs_neutral=True, detail='shutting down')
        self._drop_commands()

    def set_publishers(self, actuator: str, count: int, names: tuple[str, ...] = ()) -> None:
        """How many nodes publish ``<actuator>/cmd``: more than one neutralises both."""
        if self.sources.update(f'{actuator}/cmd', count, names) and count > 1:
            self._drop_commands()

    def command(self, actuator: str, cmd: SideCommand, now_s: float) -> bool:
        """Store a computer command; return False (ignored) unless the computer holds authority."""
        if actuator not in self._commands:
            raise ValueError(f'unknown actuator {actuator!r}; known: {self.ACTUATORS}')
        if self._state.holder != Holder.COMPUTER or self.sources.fault():
            return False
        self._commands[actuator] = cmd
        self._stamps[actuator] = now_s
        return True

    def outputs(self, now_s: float) -> dict[str, SideCommand]:
        """Computer-side outputs now: the fresh commands, or NEUTRAL per actuator."""
        conflict = self.sources.fault()
        if conflict and self._state.holder == Holder.COMPUTER:
            self._set(outputs_neutral=True, detail=f'second command source: {conflict}; '
                                                   'outputs neutral')
            return {a: NEUTRAL for a in self.ACTUATORS}
        out = {}
        live = False
        for actuator in self.ACTUATORS:
            fresh = now_s - self._stamps[actuator] <= self.command_timeout_s
            out[actuator] = self._commands[actuator] if (
                fresh and self._state.holder == Holder.COMPUTER) else NEUTRAL
            live = live or fresh
        if self._state.holder == Holder.COMPUTER:
            if live:
                self._set(outputs_neutral=False, reason=Reason.RC_SWITCH,
                          detail='computer holds authority')
            elif any(math.isfinite(s) for s in self._stamps.values()):
                self._set(outputs_neutral=True, reason=Reason.COMMAND_TIMEOUT,
                          detail=f'no command for {self.command_timeout_s:.2f} s: neutral')
        return out

    def _drop_commands(self) -> None:
        self._commands = {a: NEUTRAL for a in self.ACTUATORS}
        self._stamps = {a: -math.inf for a in self.ACTUATORS}
