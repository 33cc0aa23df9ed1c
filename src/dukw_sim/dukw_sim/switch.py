"""The simulated servo switch and RC side (ROS-free), on the boat's own authority rule.

The rule itself is `dukw_driver.authority.CommandGate`, shared with
servo_switch_node: the RC operator always wins, computer commands pass only while
the computer holds authority and they are fresh, a lost RC link is neutral. This
module adds what the boat has in hardware: the operator (select switch, link,
sticks) and the RC receiver's pulse widths. While the operator holds authority
the sticks drive both the tracks and the propellers (one stick pair on the
transmitter; the propellers push nothing on land and the tracks little afloat).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from dukw_common.config import ConfigError, ParamValue, require
from dukw_driver.authority import (NEUTRAL, AuthorityState, CommandGate, Holder, SideCommand,
                                   validate_command)


@dataclass(frozen=True)
class RcChannels:
    """How the RC receiver's pulses encode the sticks and the select switch (config ``rc.*``)."""

    neutral_us: float
    us_per_pct: float

    @classmethod
    def from_params(cls, params: Mapping[str, ParamValue]) -> 'RcChannels':
        """Build from ``rc.*`` parameters; ConfigError if missing or not positive."""
        values = {name: require(params, f'rc.{name}') for name in cls.__dataclass_fields__}
        for name, value in values.items():
            if value <= 0:
                raise ConfigError(f'parameter rc.{name!r} must be > 0, got {value}')
        return cls(**values)


@dataclass(frozen=True)
class OperatorState:
    """What the RC operator does: select switch, link, sticks (percent)."""

    rc_selected: bool = False
    rc_link_ok: bool = True
    sticks: SideCommand = NEUTRAL


@dataclass(frozen=True)
class RcPulses:
    """The RC side as the servo controller reads it (dukw_msgs/RcInput)."""

    t_s: float
    link_ok: bool
    rc_selected: bool
    channels_us: tuple[float, ...]   # tracks port, stbd, props port, stbd; 0 = no pulse


@dataclass(frozen=True)
class SwitchOutputs:
    """What reaches the motor controllers this cycle, and from whom."""

    tracks: SideCommand
    props: SideCommand
    source: str                      # 'computer' | 'operator' | 'neutral'


class SimServoSwitch:
    """The servo switch with a simulated operator; time is the simulator's."""

    def __init__(self, command_timeout_s: float, channels: RcChannels) -> None:
        self.gate = CommandGate(command_timeout_s)
        self.channels = channels
        self.operator = OperatorState()
        self.rejected = 0      # malformed computer commands (NaN, inf, out of range)
        self.ignored = 0       # valid computer commands while the computer lacks authority
        self.gate.update_rc(rc_selected=False, rc_link_ok=True)  # the device is always there

    @property
    def state(self) -> AuthorityState:
        """Who holds authority and why (dukw_msgs/Authority)."""
        return self.gate.state

    def set_operator(self, rc_selected: bool, rc_link_ok: bool, port_pct: float,
                     stbd_pct: float) -> OperatorState:
        """Play the operator; ValueError (and no change) for NaN or out-of-range sticks."""
        sticks = validate_command(port_pct, stbd_pct)
        self.operator = OperatorState(bool(rc_selected), bool(rc_link_ok), sticks)
        self.gate.update_rc(rc_selected=self.operator.rc_selected,
                            rc_link_ok=self.operator.rc_link_ok)
        return self.operator

    def command(self, actuator: str, port_pct: float, stbd_pct: float, now_s: float) -> bool:
        """Offer a computer command; False if ignored (no authority); ValueError if malformed."""
        try:
            cmd = validate_command(port_pct, stbd_pct)
        except ValueError:
            self.rejected += 1
            raise
        accepted = self.gate.command(actuator, cmd, now_s)
        if not accepted:
            self.ignored += 1
        return accepted

    def outputs(self, now_s: float) -> SwitchOutputs:
        """The commands that drive the motors now (call once per simulation step)."""
        computer = self.gate.outputs(now_s)
        state = self.gate.state
        if state.holder == Holder.RC and state.rc_link_ok:
            sticks = self.operator.sticks
            return SwitchOutputs(sticks, sticks, 'operator')
        if state.holder == Holder.COMPUTER and not state.outputs_neutral:
            return SwitchOutputs(computer['tracks'], computer['props'], 'computer')
        return SwitchOutputs(NEUTRAL, NEUTRAL, 'neutral')

    def rc_reading(self, t_s: float) -> RcPulses:
        """The four stick channels (the servo switch's stick_channels, in its output order:
        tracks port, stbd, props port, stbd) around neutral, none without link."""
        op, ch = self.operator, self.channels
        if not op.rc_link_ok:
            return RcPulses(t_s, False, op.rc_selected, (0.0,) * 4)
        port = ch.neutral_us + ch.us_per_pct * op.sticks.port_pct
        stbd = ch.neutral_us + ch.us_per_pct * op.sticks.stbd_pct
        return RcPulses(t_s, True, op.rc_selected, (port, stbd, port, stbd))
