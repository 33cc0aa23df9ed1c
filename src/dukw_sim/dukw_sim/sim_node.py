"""sim_node: the simulator behind exactly the drivers' topics, on sim time (/clock).

Spun, like every node, by run_node's default executor (the EventsExecutor;
DUKW_EXECUTOR=single selects the SingleThreadedExecutor for comparison).
"""
import time

from dukw_msgs.msg import DiffCommand
from dukw_msgs.srv import SetOperator
from rclpy.node import Node
from tf2_msgs.msg import TFMessage

from dukw_common.config import ConfigError
from dukw_common.diagnostics import Level
from dukw_common.node_tools import (COMMAND_QOS, declare_parameters, diagnostic_array,
                                    publisher_sources, run_node)
from dukw_common.tf_tools import TF_QOS
from dukw_driver.authority import CommandGate
from dukw_sim.core import Actuation, SimCore
from dukw_sim.runtime import Pacer, SpeedMeter, sim_healths
from dukw_sim.sensors import Schedule, SensorConfig, SensorModel
from dukw_sim.sim_messages import TOPICS, Frames, SimMessages, set_stamp
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
        self.msgs = SimMessages(Frames(p['frames.base'], p['frames.imu'], p['frames.gps']))
        self.truth = self.core.reset(start=p['start_at'], yaw_rad=p['start_yaw_rad'])
        self.pubs = {topic: self.create_publisher(kind, topic, qos)
                     for topic, kind, qos in TOPICS}
        self.counts = {topic: 0 for topic in self.pubs}
        self.truth_tf_pub = (self.create_publisher(TFMessage, '/tf', TF_QOS)
                             if p['frames.truth'] else None)
        for actuator in CommandGate.ACTUATORS:
            self.create_subscription(DiffCommand, f'{actuator}/cmd',
                                     lambda msg, a=actuator: self.on_command(a, msg), COMMAND_QOS)
        self.create_service(SetOperator, 'sim/set_operator', self.on_set_operator)
        wall = time.monotonic()
        self.pacer = Pacer(p['real_time_factor'], self.core.dt_s,
                           max(1, round(1.0 / (p['rate_hz'] * self.core.dt_s))),
                           p['max_lag_s'], wall)
        self.meter = SpeedMeter(wall, self.truth.t_s)
        self.publish('/clock', self.msgs.clock(self.truth.t_s))
        self.create_timer(self.pacer.period_s, self.on_tick)

    def publish(self, topic: str, msg) -> None:
        """Publish and count."""
        self.pubs[topic].publish(msg)
        self.counts[topic] += 1

    def on_command(self, actuator: str, msg: DiffCommand) -> None:
        """A computer command, through the servo switch's rule (rejected if malformed)."""
        self.switch.gate.set_publishers(actuator, *publisher_sources(self, f'{actuator}/cmd'))
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
        wall = time.monotonic()
        due, deadline, n = self.pacer.steps_due(wall), wall + self.params['tick_budget_s'], 0
        while n < due:
            self.step()
            n += 1
            if time.monotonic() >= deadline:   # let commands and services in
                break
        self.pacer.took(n)

    def step(self) -> None:
        """One physics step, then every message due at the new sim time."""
        out = self.switch.outputs(self.truth.t_s)
        self.truth = self.core.step(Actuation(out.tracks.port_pct, out.tracks.stbd_pct,
                                              out.props.port_pct, out.props.stbd_pct))
        for reading in self.sensors.sample(self.truth):
            self.publish(*self.msgs.reading(reading))
        t = self.truth.t_s
        due = self.schedule.due(t)
        if 'clock' in due:
            self.publish('/clock', self.msgs.clock(t))
        if 'truth' in due:
            self.publish('sim/truth', self.msgs.sim_truth(self.truth))
            self.publish_truth_tf()
        if 'rc' in due:
            self.publish('rc/input', self.msgs.rc_input(self.switch.rc_reading(t)))
        if self.switch.gate.changed or 'authority' in due:
            self.switch.gate.changed = False
            self.publish('authority', self.msgs.authority(self.switch.state, t))
        if 'diagnostics' in due:
            self.publish('/diagnostics', self.diagnostics())

    def publish_truth_tf(self) -> None:
        """odom -> frames.truth: the true pose beside the estimate's odom -> base_link."""
        if self.truth_tf_pub is not None:
            self.truth_tf_pub.publish(self.msgs.truth_tf(self.truth, self.params['frames.truth']))

    def diagnostics(self):
        """Simulator speed, authority, and every topic's rate (Hz of sim time)."""
        t = self.truth.t_s
        rates = self.meter.report(time.monotonic(), t, self.counts)
        healths = sim_healths(
            t, self.pacer.rtf, self.meter, self.pacer.dropped_s,
            {'steps': self.pacer.steps, 'start_at': self.params['start_at'],
             'medium': self.truth.medium.name}, self.switch.state, self.switch.rejected,
            self.switch.ignored, rates)
        if self.switch.gate.sources.fault():       # a second tracks/props commander
            for health in healths:
                if health.name == 'authority':
                    health.worsen(Level.ERROR, self.switch.state.detail)
        array = diagnostic_array(self, healths)
        set_stamp(array.header, t)
        return array

    def on_shutdown(self) -> None:
        """Stopping: the switch goes neutral, and says so."""
        self.switch.gate.shutdown()
        self.publish('authority', self.msgs.authority(self.switch.state, self.truth.t_s))


def main(args=None) -> int:
    """Console-script entry point."""
    return run_node(SimNode, args)


if __name__ == '__main__':
    raise SystemExit(main())
