"""Message <-> core conversions shared by the control nodes (the only place with both)."""
from __future__ import annotations

from dukw_common.geometry import euler_from_quaternion
from dukw_msgs.msg import Authority, DiffCommand, DriveMode

from dukw_control.mixer import NEUTRAL, SidePair
from dukw_control.modes import Mode, ModeDecision

#: Authority reasons that hold the outputs at neutral whoever holds authority.
_NEUTRAL_REASONS = (Authority.REASON_RC_LINK_LOST, Authority.REASON_DEVICE_LOST,
                    Authority.REASON_SHUTDOWN)


def authority_usable(msg: Authority) -> tuple[bool, str]:
    """(computer commands reach the motors, why) from an Authority message.

    ``outputs_neutral`` alone is not a loss: the switch reports it while the
    computer holds authority but has not sent a command yet.
    """
    usable = (msg.holder == Authority.HOLDER_COMPUTER and msg.rc_link_ok
              and msg.reason not in _NEUTRAL_REASONS)
    holder = {Authority.HOLDER_RC: 'RC operator', Authority.HOLDER_COMPUTER: 'computer',
              Authority.HOLDER_NONE: 'nobody'}.get(msg.holder, f'holder {msg.holder}')
    return usable, f'{holder}: {msg.detail}' if msg.detail else holder


def decision_to_msg(decision: ModeDecision, stamp) -> DriveMode:
    """Core decision -> dukw_msgs/DriveMode."""
    msg = DriveMode(mode=int(decision.mode), automatic=decision.automatic,
                    track_weight=float(decision.track_weight),
                    prop_weight=float(decision.prop_weight),
                    tracks_idle=decision.tracks_idle, reason=decision.reason)
    msg.header.stamp = stamp
    return msg


def decision_from_msg(msg: DriveMode) -> ModeDecision:
    """dukw_msgs/DriveMode -> core decision (an unknown mode becomes SAFE_STOP)."""
    try:
        mode = Mode(msg.mode)
    except ValueError:
        return ModeDecision(Mode.SAFE_STOP, msg.automatic, 0.0, 0.0, False,
                            f'unknown mode {msg.mode}')
    return ModeDecision(mode, msg.automatic, msg.track_weight, msg.prop_weight,
                        msg.tracks_idle, msg.reason)


def diff_command(sides: SidePair, stamp, frame_id: str = 'base_link') -> DiffCommand:
    """Core SidePair -> dukw_msgs/DiffCommand."""
    msg = DiffCommand(port_pct=float(sides.port), stbd_pct=float(sides.stbd))
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    return msg


class ActuatorPublishers:
    """The pair every commanding node has: tracks/cmd and props/cmd (reliable)."""

    def __init__(self, node, qos) -> None:
        self.node = node
        self.tracks = node.create_publisher(DiffCommand, 'tracks/cmd', qos)
        self.props = node.create_publisher(DiffCommand, 'props/cmd', qos)

    def publish(self, tracks: SidePair, props: SidePair) -> None:
        """Both commands with one stamp of the node's clock."""
        stamp = self.node.get_clock().now().to_msg()
        self.tracks.publish(diff_command(tracks, stamp))
        self.props.publish(diff_command(props, stamp))

    def neutral(self) -> None:
        """Neutral on both actuators (a node's last word)."""
        self.publish(NEUTRAL, NEUTRAL)


def pitch_from_quaternion(q) -> float:
    """REP 103 pitch (positive nose down) from a geometry_msgs/Quaternion."""
    return quaternion_pitch_rad(q.x, q.y, q.z, q.w)


def quaternion_pitch_rad(x: float, y: float, z: float, w: float) -> float:
    """REP 103 pitch (positive nose down) from a quaternion's components."""
    return euler_from_quaternion(x, y, z, w)[1]

