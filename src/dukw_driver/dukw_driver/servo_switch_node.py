"""servo_switch_node: the Pololu Mini Maestro 12 between the computer and the RC multiplexer.

Forwards ``tracks/cmd`` / ``props/cmd`` as pulse widths only while the computer
holds authority (dukw_driver.authority.CommandGate); publishes ``authority`` (on
change and at 1 Hz, transient local) and ``rc/input``. Protocol and wiring:
dukw_driver.maestro; serial life: dukw_driver.serial_link.
"""
import time

from diagnostic_msgs.msg import DiagnosticArray
from dukw_msgs.msg import Authority, DiffCommand, RcInput
from rclpy.node import Node
from std_msgs.msg import Header

from dukw_common.diagnostics import Level
from dukw_common.node_tools import (COMMAND_QOS, SENSOR_QOS, STATE_QOS, ParamSpec,
                                    declare_parameters, diagnostic_array, publisher_sources,
                                    run_node)
from dukw_driver.maestro import ServoSwitch, switch_config
from dukw_driver.serial_link import DeviceHealth, SerialLink

SPECS = [
    ParamSpec('rate_hz', 'output and query rate, Hz', min=1.0, max=200.0),
    ParamSpec('port', 'Maestro command port (device path or pyserial URL)'),
    ParamSpec('baud', 'serial baud rate (USB: any; TTL: as set in the Maestro)'),
    ParamSpec('command_timeout_s', 'neutral when no command came for this long, s',
              min=0.05, max=5.0),
    ParamSpec('authority_period_s', 'authority is re-published at least this often, s',
              min=0.1, max=10.0),
    ParamSpec('deadband_pct', 'commands within +/- this are neutral, %', min=0.0, max=49.0),
    ParamSpec('output_channels', 'Maestro channels: port track, stbd track, port prop, '
              'stbd prop'),
    ParamSpec('output_neutral_us', 'neutral pulse width per output, us'),
    ParamSpec('output_min_us', 'pulse width at -100 % per output, us'),
    ParamSpec('output_max_us', 'pulse width at +100 % per output, us'),
    ParamSpec('output_reversed', 'reverse the direction per output'),
    ParamSpec('select_channel', 'input channel on the multiplexer select status line',
              min=0, max=11),
    ParamSpec('link_channel', 'input channel on the RC link-ok line', min=0, max=11),
    ParamSpec('stick_channels', 'input channels on RC stick pulse-to-voltage converters'),
    ParamSpec('input_threshold_raw', 'logic threshold of the input lines, 0..1023',
              min=1, max=1022),
    ParamSpec('input_hysteresis_raw', 'hysteresis around the threshold, raw', min=0, max=500),
    ParamSpec('select_rc_when_high', 'the select line is high while the RC side is selected'),
    ParamSpec('link_ok_when_high', 'the link line is high while the RC link is valid'),
    ParamSpec('stick_us_at_0v', 'RC pulse width a stick input reads at 0 V, us'),
    ParamSpec('stick_us_at_5v', 'RC pulse width a stick input reads at 5 V, us'),
    ParamSpec('reply_timeout_s', 'a query batch not answered in this time is dropped, s',
              min=0.005, max=2.0),
    ParamSpec('device_timeout_s', 'no valid reply for this long: device lost, neutral, s',
              min=0.05, max=5.0),
]


class ServoSwitchNode(Node):
    """Thin shell: parameters, the serial link, timers, topics; logic in ServoSwitch."""

    def __init__(self, **node_kwargs) -> None:
        super().__init__('servo_switch_node', **node_kwargs)
        p = declare_parameters(self, SPECS)
        self.switch = ServoSwitch(switch_config(p), p['command_timeout_s'])
        self.link = SerialLink(p['port'], p['baud'])
        self.health = DeviceHealth('maestro', stale_after_s=p['device_timeout_s'],
                                   expected_rate_hz=p['rate_hz'] / 2)
        self.authority_period_s = p['authority_period_s']
        self.rejected = 0
        self._authority_sent_s = -1e9
        self.authority_pub = self.create_publisher(Authority, 'authority', STATE_QOS)
        self.rc_pub = self.create_publisher(RcInput, 'rc/input', SENSOR_QOS)
        self.diag_pub = self.create_publisher(DiagnosticArray, '/diagnostics', COMMAND_QOS)
        for actuator in self.switch.gate.ACTUATORS:
            self.create_subscription(DiffCommand, f'{actuator}/cmd',
                                     lambda msg, a=actuator: self.on_command(a, msg), COMMAND_QOS)
        self.create_timer(1.0 / p['rate_hz'], self.on_tick)
        self.create_timer(1.0, self.on_diagnostics)

    def on_command(self, actuator: str, msg: DiffCommand) -> None:
        """Offer a computer command to the gate; refuse NaN / out-of-range with a warning."""
        self.switch.gate.set_publishers(actuator, *publisher_sources(self, f'{actuator}/cmd'))
        try:
            self.switch.command(actuator, msg.port_pct, msg.stbd_pct, time.monotonic())
        except ValueError as exc:
            self.rejected += 1
            self.get_logger().warning(f'{actuator}/cmd refused: {exc}',
                                      throttle_duration_sec=1.0)

    def on_tick(self) -> None:
        """Read replies, update authority, write outputs and the next queries."""
        now = time.monotonic()
        reading = self.switch.feed(self.link.poll(), now)
        if reading is not None:
            self.health.message(now)
            self.rc_pub.publish(RcInput(header=self._header(), link_ok=reading.link_ok,
                                        rc_selected=reading.rc_selected,
                                        channels_us=[float(c) for c in reading.channels_us]))
        if self.link.connected:
            self.link.write(self.switch.cycle(now))
        else:
            self.switch.device_lost(f'servo controller link down: {self.link.last_error}')
        self.publish_authority(now)

    def publish_authority(self, now: float) -> None:
        """Publish on every change and at least every authority_period_s."""
        gate = self.switch.gate
        if not gate.changed and now - self._authority_sent_s < self.authority_period_s:
            return
        gate.changed = False
        self._authority_sent_s = now
        state = gate.state
        self.authority_pub.publish(Authority(
            header=self._header(), holder=int(state.holder), reason=int(state.reason),
            rc_link_ok=state.rc_link_ok, outputs_neutral=state.outputs_neutral,
            detail=state.detail))

    def on_diagnostics(self) -> None:
        """Link, reply and authority health on /diagnostics."""
        now = time.monotonic()
        self.health.parse_errors = self.switch.parser.parse_errors
        health = self.health.health(self.link, now)
        state = self.switch.gate.state
        device_errors = self.switch.take_device_errors()
        health.values.update(reply_timeouts=self.switch.parser.timeouts,
                             commands_refused=self.rejected, holder=state.holder.name,
                             reason=state.reason.name, device_errors=','.join(device_errors))
        if device_errors:
            health.worsen(Level.WARN, 'Maestro errors: ' + ', '.join(device_errors))
        if self.switch.gate.sources.fault():
            health.worsen(Level.ERROR, state.detail)
        self.diag_pub.publish(diagnostic_array(self, [health]))

    def on_shutdown(self) -> None:
        """Every output to neutral on the device, and say so on `authority`."""
        self.link.write(self.switch.shutdown())
        self.publish_authority(time.monotonic())
        self.link.close()

    def _header(self) -> Header:
        return Header(stamp=self.get_clock().now().to_msg())


def main(args=None) -> int:
    """Console-script entry point."""
    return run_node(ServoSwitchNode, args)


if __name__ == '__main__':
    raise SystemExit(main())
