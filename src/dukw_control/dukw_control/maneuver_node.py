"""maneuver_node: plays one of the paper's open-loop tests on tracks/cmd and props/cmd.

Waits for the computer to hold authority, plays the schedule with the port bias
applied, and ends with neutral: when finished, at once when the RC operator takes
over, or when a limit trips (incline, track current allowance). Records nothing
(record with the bag recorder). Exits when done.
"""
from dukw_msgs.msg import Authority, DrivetrainStatus
from rclpy.node import Node
from sensor_msgs.msg import Imu

from dukw_common.config import ConfigError
from dukw_common.node_tools import (COMMAND_QOS, SENSOR_QOS, STATE_QOS, ParamSpec,
                                    declare_parameters, run_node, vehicle_specs)
from dukw_common.vehicle import drivetrain_params, limit_params
from dukw_control.convert import ActuatorPublishers, authority_usable, pitch_from_quaternion
from dukw_control.guards import InclineGuard
from dukw_control.limits import CurrentLimiter, CurrentLimitSettings
from dukw_control.maneuvers import ManeuverPlan, ManeuverPlayer, PlayerState

SPECS = [
    ParamSpec('rate_hz', 'command rate, Hz', 1.0, 1000.0),
    ParamSpec('maneuver', 'circle | zigzag | incline | transition'),
    ParamSpec('actuators', 'tracks | props | both'),
    ParamSpec('port_pct', 'circle: port command, %', -100.0, 100.0),
    ParamSpec('stbd_pct', 'circle: starboard command, %', -100.0, 100.0),
    ParamSpec('high_pct', 'zigzag: high command, %', -100.0, 100.0),
    ParamSpec('low_pct', 'zigzag: low command, %', -100.0, 100.0),
    ParamSpec('period_s', 'zigzag: the pair swaps every period, s', 0.1, 600.0),
    ParamSpec('command_pct', 'incline / transition: straight command, %', -100.0, 100.0),
    ParamSpec('duration_s', 'length of the run, s', 0.1, 3600.0),
    ParamSpec('authority_wait_s', 'give up without authority (and, on tracks, a first '
              'tracks/status) after, s', 0.1, 3600.0),
    ParamSpec('incline_sustained_time_s', 'beyond limits.incline_sustained_rad this long: '
              'abort, s', 0.0, 600.0),
    ParamSpec('current_peak_a', 'track current ceiling while allowance is left, A', 0.0, 200.0),
    ParamSpec('current_allowance_a2s', 'I2t allowance; spent: abort, A^2 s', 1.0, 1e7),
    ParamSpec('status_timeout_s', 'tracks/status older than this while on tracks: abort, s',
              0.01, 60.0),
]


class ManeuverNode(Node):
    """Publishes one manoeuvre's commands, guarded."""

    def __init__(self) -> None:
        super().__init__('maneuver_node')
        p = declare_parameters(self, SPECS + vehicle_specs('drivetrain', 'limits'))
        drive, lim = drivetrain_params(p), limit_params(p)
        try:
            plan = ManeuverPlan(p['maneuver'], p['port_pct'], p['stbd_pct'], p['high_pct'],
                                p['low_pct'], p['period_s'], p['command_pct'], p['duration_s'])
            current = CurrentLimitSettings(drive.continuous_current_limit_a, p['current_peak_a'],
                                           p['current_allowance_a2s'], 0.7, 1.0, 1.0)
            incline = InclineGuard(lim.incline_sustained_rad, lim.incline_brief_rad,
                                   p['incline_sustained_time_s'], 0.0)
            self.player = ManeuverPlayer(plan, p['actuators'], drive.port_bias_pct, incline,
                                         {s: CurrentLimiter(current) for s in ('port', 'stbd')},
                                         p['authority_wait_s'], p['status_timeout_s'])
        except ValueError as exc:
            raise ConfigError(f'maneuver_node: {exc}') from exc
        self.usable = False
        self.incline_rad = 0.0
        self.last_s = self.now_s()
        self.end_s = None
        self.commands = ActuatorPublishers(self, COMMAND_QOS)
        self.create_subscription(Authority, 'authority', self.on_authority, STATE_QOS)
        self.create_subscription(Imu, 'imu/data', self.on_imu, SENSOR_QOS)
        self.create_subscription(DrivetrainStatus, 'tracks/status', self.on_tracks, SENSOR_QOS)
        self.create_timer(1.0 / p['rate_hz'], self.on_timer)
        self.get_logger().info(f'{plan.maneuver} on {p["actuators"]}: waiting for authority')

    def now_s(self) -> float:
        """Node clock, seconds."""
        return self.get_clock().now().nanoseconds * 1e-9

    def on_authority(self, msg: Authority) -> None:
        self.usable = authority_usable(msg)[0]
        if not self.usable:
            self.on_timer()          # neutral at once

    def on_imu(self, msg: Imu) -> None:
        self.incline_rad = -pitch_from_quaternion(msg.orientation)

    def on_tracks(self, msg: DrivetrainStatus) -> None:
        self.player.on_status(self.now_s(), msg.port.current_a, msg.stbd.current_a)

    def on_timer(self) -> None:
        now, player = self.now_s(), self.player
        dt, self.last_s = min(max(now - self.last_s, 0.0), 0.1), now
        before = player.state
        tracks, props = player.step(now, self.usable, self.incline_rad, dt)
        self.commands.publish(tracks, props)
        if player.state != before:
            text = player.state.value + (f': {player.reason}' if player.reason else '')
            if player.state == PlayerState.ABORTED:
                self.get_logger().warn(text)
            else:
                self.get_logger().info(text)
        if player.state in (PlayerState.DONE, PlayerState.ABORTED):
            self.end_s = now if self.end_s is None else self.end_s
            if now - self.end_s > 0.5:    # neutral for a while, then run_node's loop ends
                self.context.try_shutdown()

    def on_shutdown(self) -> None:
        """Last word: neutral on both actuators."""
        self.commands.neutral()


def main(args=None) -> int:
    """Console-script entry point."""
    return run_node(ManeuverNode, args)


if __name__ == '__main__':
    raise SystemExit(main())
