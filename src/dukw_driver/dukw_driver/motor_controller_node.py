"""motor_controller_node: monitor of one Roboteq dual-channel controller (tracks or propellers).

Queries amps, volts, speed, applied command, temperature and flags over the ASCII
serial protocol and publishes ``tracks/status`` or ``props/status``. It never
sends motor commands: they reach the controller as RC pulses through the
servo switch and the RC multiplexer (why: dukw_driver.motors). One instance per
controller; run the second as ``-r __node:=props_motor_controller_node``.
"""
import time

from diagnostic_msgs.msg import DiagnosticArray
from dukw_msgs.msg import DrivetrainStatus, MotorSide
from rclpy.node import Node
from std_msgs.msg import Header

from dukw_common.diagnostics import Level
from dukw_common.readings import MotorSide as MotorReading
from dukw_common.node_tools import (COMMAND_QOS, SENSOR_QOS, ParamSpec, declare_parameters,
                                    diagnostic_array, run_node, vehicle_specs)
from dukw_common.vehicle import drivetrain_params
from dukw_driver.motors import UNKNOWN_SIDE, Drive, MotorMonitor
from dukw_driver.roboteq import FAULT_FLAG_BITS, QUERIES
from dukw_driver.serial_link import DeviceHealth, SerialLink

SPECS = [
    ParamSpec('rate_hz', 'query and publish rate, Hz', min=1.0, max=100.0),
    ParamSpec('drive', "which motors the controller drives: 'tracks' or 'props'"),
    ParamSpec('port', 'controller serial port (device path or pyserial URL)'),
    ParamSpec('baud', 'serial baud rate (RS232: 115200 on Roboteq controllers)'),
    ParamSpec('port_channel', 'controller channel (1 or 2) driving the port motor', min=1, max=2),
    ParamSpec('stale_after_s', 'replies older than this: not connected, values NaN, s',
              min=0.05, max=5.0),
]
CONTROLLER_FAULTS = {name for _, name in FAULT_FLAG_BITS.values()}


class MotorControllerNode(Node):
    """Thin shell: parameters, serial link, timer, status topic; logic in MotorMonitor."""

    def __init__(self, **node_kwargs) -> None:
        super().__init__('motor_controller_node', **node_kwargs)
        p = declare_parameters(self, SPECS + vehicle_specs('drivetrain'))
        self.drive = Drive.parse(p['drive'])
        self.drivetrain = drivetrain_params(p)
        self.monitor = MotorMonitor(self.drive, self.drivetrain, p['port_channel'],
                                    p['stale_after_s'])
        self.link = SerialLink(p['port'], p['baud'])
        name = self.drive.name.lower()
        self.health = DeviceHealth(f'{name} controller', stale_after_s=p['stale_after_s'],
                                   expected_rate_hz=p['rate_hz'] * len(QUERIES))
        self.status_pub = self.create_publisher(DrivetrainStatus, f'{name}/status', SENSOR_QOS)
        self.diag_pub = self.create_publisher(DiagnosticArray, '/diagnostics', COMMAND_QOS)
        self.last: tuple[MotorReading, MotorReading] = (UNKNOWN_SIDE, UNKNOWN_SIDE)
        self.create_timer(1.0 / p['rate_hz'], self.on_tick)
        self.create_timer(1.0, self.on_diagnostics)

    def on_tick(self) -> None:
        """Read replies, send the next queries, publish the status."""
        now = time.monotonic()
        replies_before = self.monitor.parser.replies
        data = self.link.poll()
        if not self.link.connected:
            self.monitor.forget()
        self.monitor.feed(data, now)
        for _ in range(self.monitor.parser.replies - replies_before):
            self.health.message(now)
        if self.link.connected:
            self.link.write(self.monitor.queries())
        port, stbd = self.last = self.monitor.sides(now)
        self.status_pub.publish(DrivetrainStatus(
            header=Header(stamp=self.get_clock().now().to_msg()), drive=self.drive.value,
            connected=self.link.connected and self.monitor.fresh(now),
            port=self._side(port), stbd=self._side(stbd)))

    @staticmethod
    def _side(side: MotorReading) -> MotorSide:
        return MotorSide(command_pct=side.command_pct, current_a=side.current_a,
                         voltage_v=side.voltage_v, speed_mps=side.speed_mps,
                         force_n=side.force_n, temperature_c=side.temperature_c,
                         fault_flags=side.fault_flags, faults=list(side.faults))

    def on_diagnostics(self) -> None:
        """Link, reply rate, parse errors, faults and watchdog on /diagnostics."""
        now = time.monotonic()
        parser = self.monitor.parser
        self.health.parse_errors = parser.parse_errors
        health = self.health.health(self.link, now)
        health.values.update(nacks=parser.nacks, echoes=parser.echoes,
                             watchdog_ms=self.monitor.watchdog_ms)
        for warning in self.monitor.warnings():
            health.worsen(Level.WARN, warning)
        limit_a = self.drivetrain.continuous_current_limit_a
        for label, side in zip(('port', 'stbd'), self.last, strict=True):
            health.values[f'{label}_faults'] = ','.join(side.faults)
            if not self.monitor.fresh(now):
                continue
            controller = [f for f in side.faults if f in CONTROLLER_FAULTS]
            if controller:
                health.worsen(Level.ERROR, f'{label}: ' + ', '.join(controller))
            elif side.faults:
                health.worsen(Level.WARN, f'{label}: ' + ', '.join(side.faults))
            if abs(side.current_a) > limit_a:
                health.worsen(Level.WARN, f'{label} current {side.current_a:.1f} A above the '
                              f'{limit_a:.0f} A continuous limit')
        self.diag_pub.publish(diagnostic_array(self, [health]))

    def on_shutdown(self) -> None:
        """Release the port (the controller keeps following its pulse input)."""
        self.link.close()


def main(args=None) -> int:
    """Console-script entry point."""
    return run_node(MotorControllerNode, args)


if __name__ == '__main__':
    raise SystemExit(main())
