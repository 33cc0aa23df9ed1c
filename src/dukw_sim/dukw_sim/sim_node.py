"""sim_node: the simulator behind exactly the drivers' topics, on sim time (/clock)."""
import math
import time

from dukw_msgs.msg import (Authority, Depth, DiffCommand, DrivetrainStatus, RcInput, SimTruth,
                           WaterContact)
from dukw_msgs.srv import SetOperator
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import TwistWithCovarianceStamped
from rclpy.node import Node
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Imu, NavSatFix

from dukw_common.config import ConfigError
from dukw_common.diagnostics import Health, Level, RateCounter
from dukw_common.node_tools import (COMMAND_QOS, SENSOR_QOS, STATE_QOS, declare_parameters,
                                    diagnostic_array, run_node)
from dukw_driver.authority import CommandGate, Holder, Reason
from dukw_sim import sim_messages as m
from dukw_sim.core import Actuation, SimCore
from dukw_sim.sensors import (DepthReading, DrivetrainReading, GpsFix, GpsVelocity, ImuReading,
                              Schedule, SensorConfig, SensorModel, WaterContactReading)
from dukw_sim.sim_params import NODE_STREAMS, START_CHOICES, sim_node_specs
from dukw_sim.switch import RcChannels, SimServoSwitch


class SimNode(Node):
    """Steps SimCore on a timer, publishes what the drivers publish, obeys the servo switch."""

    def __init__(self) -> None:
        super().__init__('sim_node')
        p = self.params = declare_parameters(self, sim_node_specs(self.get_name()))
        if p['start_at'] not in START_CHOICES:
            raise ConfigError(f"sim_node: start_at must be one of {START_CHOICES}, "
                              f"got {p['start_at']!r}")
        self.core = SimCore.from_config(overrides=p, seed=p['seed'])
        self.sensors = SensorModel(SensorConfig.from_params(p), seed=p['seed'])
        self.switch = SimServoSwitch(p['command_timeout_s'], RcChannels.from_params(p))
        self.schedule = Schedule({s: p[f'rates.{s}_hz'] for s in NODE_STREAMS})
        self.frames = m.Frames(p['frames.base'], p['frames.imu'], p['frames.gps'])
        self.truth = self.core.reset(start=p['start_at'], yaw_rad=p['start_yaw_rad'])
        self.counters: dict[str, RateCounter] = {}
        self.pubs = {topic: self.create_publisher(kind, topic, qos) for topic, kind, qos in (
            ('imu/data', Imu, SENSOR_QOS), ('gps/fix', NavSatFix, SENSOR_QOS),
            ('gps/vel', TwistWithCovarianceStamped, SENSOR_QOS),
            ('water/contact', WaterContact, SENSOR_QOS), ('depth', Depth, SENSOR_QOS),
            ('tracks/status', DrivetrainStatus, SENSOR_QOS),
            ('props/status', DrivetrainStatus, SENSOR_QOS), ('rc/input', RcInput, SENSOR_QOS),
            ('authority', Authority, STATE_QOS), ('sim/truth', SimTruth, SENSOR_QOS),
            ('/clock', Clock, COMMAND_QOS), ('/diagnostics', DiagnosticArray, COMMAND_QOS))}
        f = self.frames
        self.builders = {ImuReading: ('imu/data', lambda r: m.imu(r, f)),
                         GpsFix: ('gps/fix', lambda r: m.gps_fix(r, f)),
                         GpsVelocity: ('gps/vel', lambda r: m.gps_velocity(r, f)),
                         WaterContactReading: ('water/contact', lambda r: m.water_contact(r, f)),
                         DepthReading: ('depth', lambda r: m.depth(r, f))}
        for actuator in CommandGate.ACTUATORS:
            self.create_subscription(DiffCommand, f'{actuator}/cmd',
                                     lambda msg, a=actuator: self.on_command(a, msg), COMMAND_QOS)
        self.create_service(SetOperator, 'sim/set_operator', self.on_set_operator)
        self.rtf = p['real_time_factor']
        self.steps_per_tick = max(1, round(1.0 / (p['rate_hz'] * self.core.dt_s)))
        period_s = 0.0 if self.rtf == 0 else self.steps_per_tick * self.core.dt_s / self.rtf
        self.wall0, self.steps = time.monotonic(), 0
        self.diag_mark = (self.wall0, self.truth.t_s)
        self.achieved_rtf = math.nan
        self.publish('/clock', m.clock(self.truth.t_s))
        self.create_timer(period_s, self.on_tick)

    def publish(self, topic: str, msg) -> None:
        """Publish and count (rates in sim time)."""
        self.pubs[topic].publish(msg)
        self.counters.setdefault(topic, RateCounter()).tick(self.truth.t_s)

    def on_command(self, actuator: str, msg: DiffCommand) -> None:
        """A computer command, through the servo switch's rule (rejected if malformed)."""
        try:
            self.switch.command(actuator, msg.port_pct, msg.stbd_pct, self.truth.t_s)
        except ValueError as exc:
            self.get_logger().warning(f'{actuator}/cmd rejected: {exc}',
                                      throttle_duration_sec=1.0)

    def on_set_operator(self, request, response):
        """Play the RC operator: take over, hand back, drop the link, move the sticks."""
        try:
            self.switch.set_operator(request.rc_selected, request.rc_link_ok,
                                     request.port_pct, request.stbd_pct)
        except ValueError as exc:
            response.success, response.message = False, f'refused: {exc}'
            return response
        response.success, response.message = True, self.switch.state.detail
        return response

    def on_tick(self) -> None:
        """Step the physics as far as the wall clock times the real-time factor asks."""
        n = self.steps_per_tick
        if self.rtf > 0:
            wall = time.monotonic()
            n = int((wall - self.wall0) * self.rtf / self.core.dt_s) - self.steps
            if n > self.params['max_steps_per_tick']:   # cannot keep up: drop the debt
                n = self.params['max_steps_per_tick']
                self.wall0 = wall - (self.steps + n) * self.core.dt_s / self.rtf
        for _ in range(max(n, 0)):
            self.step()

    def step(self) -> None:
        """One physics step, then every message due at the new sim time."""
        out = self.switch.outputs(self.truth.t_s)
        self.truth = self.core.step(Actuation(out.tracks.port_pct, out.tracks.stbd_pct,
                                              out.props.port_pct, out.props.stbd_pct))
        self.steps += 1
        for reading in self.sensors.sample(self.truth):
            if isinstance(reading, DrivetrainReading):
                self.publish(f'{reading.drive}/status', m.drivetrain(reading, self.frames))
            else:
                topic, build = self.builders[type(reading)]
                self.publish(topic, build(reading))
        t = self.truth.t_s
        due = self.schedule.due(t)
        if 'clock' in due:
            self.publish('/clock', m.clock(t))
        if 'truth' in due:
            self.publish('sim/truth', m.sim_truth(self.truth))
        if 'rc' in due:
            self.publish('rc/input', m.rc_input(self.switch.rc_reading(t)))
        if self.switch.gate.changed or 'authority' in due:
            self.switch.gate.changed = False
            self.publish('authority', m.authority(self.switch.state, t))
        if 'diagnostics' in due:
            self.publish('/diagnostics', self.diagnostics())

    def diagnostics(self) -> DiagnosticArray:
        """Simulator speed, authority, and every topic's rate (Hz of sim time)."""
        wall, t = time.monotonic(), self.truth.t_s
        if wall > self.diag_mark[0]:
            self.achieved_rtf = (t - self.diag_mark[1]) / (wall - self.diag_mark[0])
        self.diag_mark = (wall, t)
        sim = Health('simulator', values={
            'sim_time_s': f'{t:.2f}', 'real_time_factor': self.rtf,
            'achieved_real_time_factor': f'{self.achieved_rtf:.2f}', 'steps': self.steps,
            'start_at': self.params['start_at'], 'medium': self.truth.medium.name})
        if self.rtf > 0 and self.achieved_rtf < 0.9 * self.rtf:
            sim.worsen(Level.WARN, f'running at {self.achieved_rtf:.2f}x of {self.rtf}x asked')
        state = self.switch.state
        auth = Health('authority', message=state.detail, values={
            'holder': Holder(state.holder).name, 'reason': Reason(state.reason).name,
            'rc_link_ok': state.rc_link_ok, 'rejected_commands': self.switch.rejected,
            'ignored_commands': self.switch.ignored})
        if not state.rc_link_ok:
            auth.level = Level.WARN
        rates = Health('topics', message='rates in Hz of sim time', values={
            topic: f'{c.rate_hz(t):.1f}' for topic, c in sorted(self.counters.items())})
        array = diagnostic_array(self, [sim, auth, rates])
        array.header.stamp = m.stamp(t)
        return array

    def on_shutdown(self) -> None:
        """Stopping: the switch goes neutral, and says so."""
        self.switch.gate.shutdown()
        self.publish('authority', m.authority(self.switch.state, self.truth.t_s))


def main(args=None) -> int:
    """Console-script entry point."""
    return run_node(SimNode, args)


if __name__ == '__main__':
    raise SystemExit(main())
