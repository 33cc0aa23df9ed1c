"""CPU cost of the IMU/GPS and water-sensor decoders per second of device traffic.

Builds one second of what each device sends at its assumed rate (MAVLink IMU at
100 Hz attitude + 100 Hz IMU + 10 Hz GPS + 10 Hz velocity; DGPS GGA/GST/VTG/RMC at
10 Hz; DT800 DPT/MTW at 5 Hz; the ADC answering 2 channels at 20 Hz), decodes it
--repeat times in 20 ms chunks (as the nodes' timers do) and prints the CPU share of
one core that decoding costs, plus decoded messages per second. Figures only.
"""
from __future__ import annotations

import argparse
import math
import time

from pymavlink.dialects.v20 import common as mavlink

from dukw_driver.depth_sounder import DepthSounderDecoder
from dukw_driver.gnss import UereSettings
from dukw_driver.mavlink_imu import ImuSettings, MavlinkImuDecoder
from dukw_driver.nmea_gps import GpsNmeaDecoder, NmeaGpsSettings
from dukw_driver.nmea_stream import nmea_sentence
from dukw_driver.numato_adc import NumatoAdc
from figures import report

UERE = UereSettings(4.0, 0.7)


def imu_second() -> bytes:
    enc = mavlink.MAVLink(None, srcSystem=1, srcComponent=1)
    out = b''
    for i in range(100):
        out += mavlink.MAVLink_attitude_quaternion_message(
            i, 1.0, 0.0, 0.0, 0.0, 0.01, 0.0, -0.2).pack(enc)
        out += mavlink.MAVLink_highres_imu_message(
            i, 0.1, 0.0, -9.8, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xFFFF).pack(enc)
        if i % 10 == 0:
            out += mavlink.MAVLink_gps_raw_int_message(
                i, 3, 361836000, -757510000, 5000, 90, 150, 0, 0, 12).pack(enc)
            out += mavlink.MAVLink_global_position_int_message(
                i, 0, 0, 0, 0, 100, 0, 0, 0).pack(enc)
    return out


def dgps_second() -> bytes:
    epoch = (nmea_sentence('GPGGA,120000.00,3611.016,N,07545.060,W,2,09,0.9,2.0,M,-35.0,M,,')
             + nmea_sentence('GPGST,120000.00,0.5,0.40,0.30,10.0,0.30,0.20,0.60')
             + nmea_sentence('GPVTG,000.0,T,,M,2.9,N,5.4,K,D')
             + nmea_sentence('GPRMC,120000.00,A,3611.016,N,07545.060,W,2.9,0.0,221126,,,D'))
    return epoch * 10


def sounder_second() -> bytes:
    return (nmea_sentence('SDDPT,2.40,-0.25,') + nmea_sentence('YXMTW,17.5,C')) * 5


def run(name: str, data: bytes, decode, repeat: int) -> None:
    size = max(1, len(data) // 50)  # 20 ms of traffic per timer tick
    chunks = [data[i:i + size] for i in range(0, len(data), size)]
    count = 0
    cpu = time.process_time()
    for r in range(repeat):
        for k, chunk in enumerate(chunks):
            count += len(decode(chunk, r + k * 0.02))
    cpu = time.process_time() - cpu
    print(f'{name:34s} {100.0 * cpu / repeat:6.2f} % of a core, '
          f'{count / cpu:9.0f} decoded/s CPU, {len(data):6d} B per device second')
    report(f'decoder {name}', 100.0 * cpu / repeat, '% of a core')


def main() -> None:
    """Decode each device's second of traffic --repeat times and print the figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--repeat', type=int, default=20, help='device seconds per decoder')
    args = parser.parse_args()
    imu = MavlinkImuDecoder(ImuSettings((0.01,) * 3, math.radians(0.172), (0.01,) * 3,
                                        0.1, UERE))
    run('MAVLink IMU (~230 packets/s)', imu_second(), imu.feed, args.repeat)
    gps = GpsNmeaDecoder(NmeaGpsSettings(UERE, 0.1, 1.5))
    run('NMEA DGPS (40 sentences/s)', dgps_second(), gps.feed, args.repeat)
    sounder = DepthSounderDecoder(0.5)
    run('NMEA DT800 (10 sentences/s)', sounder_second(), sounder.feed, args.repeat)
    adc = NumatoAdc((0, 1), timeout_s=0.5)
    answers = b'adc read 0\n\r512\n\r>adc read 1\n\r20\n\r>' * 20

    def adc_decode(chunk, now_s):
        adc.requests(now_s)
        return adc.feed(chunk)
    run('Numato ADC (40 answers/s)', answers, adc_decode, args.repeat)


if __name__ == '__main__':
    main()
