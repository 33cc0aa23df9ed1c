"""water_sensor_node: fore/aft water-contact sensors (Numato ADC) and the DT800 depth sounder.

Polls both ADC channels at ``rate_hz`` and publishes ``water/contact``
(dukw_msgs/WaterContact: debounced wet flags and raw levels 0..1) once both
answered; publishes ``depth`` (dukw_msgs/Depth) for every DPT (or DBT) the sounder
sends; both SENSOR_QOS; ``/diagnostics`` per device. Protocols and the wet/dry
decision live in numato_adc, water_contact and depth_sounder.
"""
import time

from diagnostic_msgs.msg import DiagnosticArray
from dukw_msgs.msg import Depth, WaterContact
from rclpy.node import Node

from dukw_common.config import ConfigError
from dukw_common.node_tools import (SENSOR_QOS, ParamSpec, declare_parameters, diagnostic_array,
                                    run_node)
from dukw_driver.depth_sounder import SounderDepth, DepthSounderDecoder
from dukw_driver.device_channel import DeviceChannel, link_from_params, require_name
from dukw_driver.numato_adc import MAX_CHANNEL, NumatoAdc
from dukw_driver.serial_link import DeviceHealth
from dukw_driver.water_contact import ContactSettings, WaterContactDetector

PARAMS = [
    ParamSpec('rate_hz', 'ADC poll and water/contact rate, Hz', min=1.0, max=100.0),
    ParamSpec('stale_after_s', 'no good message this long: ERROR, s', min=0.05, max=60.0),
    ParamSpec('contact_frame_id', 'frame_id of water/contact'),
    ParamSpec('depth_frame_id', 'frame_id of depth'),
    ParamSpec('adc.port', 'serial device of the Numato ADC module'),
    ParamSpec('adc.baud', 'baud rate of the ADC module (USB CDC ignores it)',
              min=1200, max=921600),
    ParamSpec('adc.fore_channel', 'ADC input of the fore sensor', min=0, max=MAX_CHANNEL),
    ParamSpec('adc.aft_channel', 'ADC input of the aft sensor', min=0, max=MAX_CHANNEL),
    ParamSpec('adc.response_timeout_s', 'unanswered ADC request sent again after, s',
              min=0.01, max=10.0),
    ParamSpec('adc.invert', 'true if the input is pulled up (wet reads low)'),
    ParamSpec('contact.wet_on_level', 'level 0..1 that looks wet', min=0.0, max=1.0),
    ParamSpec('contact.wet_off_level', 'level 0..1 that looks dry again', min=0.0, max=1.0),
    ParamSpec('contact.debounce_s', 'a look must hold this long to switch, s', min=0.0,
              max=10.0),
    ParamSpec('sounder.port', 'serial device of the depth sounder (NMEA 0183)'),
    ParamSpec('sounder.baud', 'baud rate of the depth sounder', min=1200, max=921600),
    ParamSpec('sounder.expected_rate_hz', 'sounder sentences/s; WARN below half', min=0.0,
              max=100.0),
    ParamSpec('sensors.depth_sounder_min_m', 'shallower than this: depth invalid, m (vehicle.md '
              'section 2)', min=0.0, max=100.0),
]


class WaterSensorNode(Node):
    """Polls the ADC, reads the sounder, publishes contact and depth, reports health."""

    def __init__(self, **kwargs) -> None:
        super().__init__('water_sensor_node', **kwargs)
        p = declare_parameters(self, PARAMS)
        self.contact_frame = require_name(p['contact_frame_id'], 'contact_frame_id')
        self.depth_frame = require_name(p['depth_frame_id'], 'depth_frame_id')
        self.invert = bool(p['adc.invert'])
        if p['adc.fore_channel'] == p['adc.aft_channel']:
            raise ConfigError("parameter 'adc.aft_channel' must differ from adc.fore_channel")
        self.sides = {p['adc.fore_channel']: 'fore', p['adc.aft_channel']: 'aft'}
        try:
            contact = ContactSettings(p['contact.wet_on_level'], p['contact.wet_off_level'],
                                      p['contact.debounce_s'])
            self.adc = NumatoAdc(tuple(self.sides), p['adc.response_timeout_s'])
        except ValueError as exc:
            raise ConfigError(f'parameters contact.* / adc.response_timeout_s: {exc}') from exc
        self.detectors = {side: WaterContactDetector(contact) for side in ('fore', 'aft')}
        self._fresh: set[str] = set()
        sounder = DepthSounderDecoder(p['sensors.depth_sounder_min_m'])
        stale_s = p['stale_after_s']
        self.adc_dev = DeviceChannel(
            link_from_params(p, 'adc'), lambda data, _t: self.adc.feed(data), self.adc.counters,
            DeviceHealth('adc', stale_s, expected_rate_hz=2.0 * p['rate_hz']))
        self.sounder_dev = DeviceChannel(
            link_from_params(p, 'sounder'), sounder.feed, sounder.counters,
            DeviceHealth('sounder', stale_s, expected_rate_hz=p['sounder.expected_rate_hz']))
        self.contact_pub = self.create_publisher(WaterContact, 'water/contact', SENSOR_QOS)
        self.depth_pub = self.create_publisher(Depth, 'depth', SENSOR_QOS)
        self.diag_pub = self.create_publisher(DiagnosticArray, '/diagnostics', 10)
        self.create_timer(1.0 / p['rate_hz'], self._poll)
        self.create_timer(1.0, self._report)

    def _poll(self) -> None:
        now_s = time.monotonic()
        for reading in self.adc_dev.poll(now_s):
            side = self.sides[reading.channel]
            level = 1.0 - reading.level if self.invert else reading.level
            self.detectors[side].update(level, now_s)
            self._fresh.add(side)
        if len(self._fresh) == 2:
            self._fresh.clear()
            self.contact_pub.publish(self._contact())
        link = self.adc_dev.link
        if link.connected:
            requests = self.adc.requests(now_s)
            if requests:
                link.write(requests)
        else:
            self.adc.reset()  # nothing in flight on a link that is down
        for reading in self.sounder_dev.poll(now_s):
            self.depth_pub.publish(self._depth(reading))

    def _contact(self) -> WaterContact:
        fore, aft = self.detectors['fore'], self.detectors['aft']
        msg = WaterContact(fore_wet=fore.wet, aft_wet=aft.wet, fore_level=fore.level,
                           aft_level=aft.level)
        msg.header.stamp, msg.header.frame_id = self.get_clock().now().to_msg(), \
            self.contact_frame
        return msg

    def _depth(self, r: SounderDepth) -> Depth:
        msg = Depth(valid=r.valid, depth_m=r.depth_m, offset_m=r.offset_m,
                    water_temp_c=r.water_temp_c)
        msg.header.stamp, msg.header.frame_id = self.get_clock().now().to_msg(), self.depth_frame
        return msg

    def _report(self) -> None:
        now_s = time.monotonic()
        adc = self.adc_dev.status(now_s)
        adc.values.update(fore_wet=self.detectors['fore'].wet, aft_wet=self.detectors['aft'].wet)
        self.diag_pub.publish(diagnostic_array(self, [adc, self.sounder_dev.status(now_s)]))

    def on_shutdown(self) -> None:
        """Release both serial devices."""
        self.adc_dev.close()
        self.sounder_dev.close()


def main(args=None) -> int:
    """Console-script entry point."""
    return run_node(WaterSensorNode, args)


if __name__ == '__main__':
    raise SystemExit(main())
