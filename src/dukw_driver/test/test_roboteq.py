"""Roboteq ASCII protocol parsing, fault decoding and the motor monitor, without ROS."""
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from dukw_common.config import ConfigError
from dukw_common.vehicle import Vehicle
from dukw_driver import roboteq
from dukw_driver.motors import Drive, MotorMonitor, track_speed_mps
from dukw_model.propeller import prop_thrust_n
from dukw_driver.roboteq import ReplyParser, decode_faults, decode_status, query_frame
from fake_roboteq import FakeRoboteq

DRIVETRAIN = Vehicle.load().drivetrain


def test_fault_constants_match_the_message():
    from dukw_msgs.msg import MotorSide
    for name in dir(MotorSide):
        if name.startswith('FAULT_'):
            assert getattr(roboteq, name) == getattr(MotorSide, name), name


def test_replies_echoes_and_acknowledgements():
    parser = ReplyParser()
    got = parser.feed(b'?A\rA=123:-145\r?V\rV=125:246:4980\r+\r-\rFF=0\r')
    assert got == {'A': (123, -145), 'V': (125, 246, 4980), 'FF': (0,)}
    assert (parser.echoes, parser.acks, parser.nacks, parser.parse_errors) == (2, 1, 1, 0)


def test_a_reply_split_across_reads_is_joined():
    parser = ReplyParser()
    assert parser.feed(b'S=15') == {}
    assert parser.feed(b'47:-300\r') == {'S': (1547, -300)}


@pytest.mark.parametrize('line', [b'A=12\r', b'A=1:2:3\r', b'A=x:2\r', b'Q=1\r', b'A=1::2\r',
                                  b'\xff\xfe\r', b'garbage\r', b'A=99999999:1\r'])
def test_malformed_lines_are_counted(line):
    parser = ReplyParser()
    assert parser.feed(line) == {}
    assert parser.parse_errors == 1


def test_a_line_without_terminator_is_dropped_when_too_long():
    parser = ReplyParser()
    parser.feed(b'A' * 100)
    assert parser.parse_errors == 1
    assert parser.feed(b'\rA=1:2\r') == {'A': (1, 2)}


def test_fault_flags_decoded_bit_by_bit():
    report = decode_faults(0b1_0000_0101, 0b110)
    assert report.flags == (roboteq.FAULT_OVERHEAT | roboteq.FAULT_UNDERVOLTAGE
                            | roboteq.FAULT_EMERGENCY_STOP | roboteq.FAULT_STALL)
    assert report.names == ('overheat', 'undervoltage', 'safe_torque_off', 'stall', 'loop_error')
    assert decode_faults(0, 0b1).flags == 0  # amps limit active is not a fault
    assert decode_faults(0, 0b1).names == ()
    assert decode_faults(1 << 12, 0).names == ('unknown_fault_bits_0x1000',)
    for bit in range(8):
        assert decode_faults(1 << bit, 0).flags == 1 << bit
    assert decode_status(0b1001) == ['serial_mode', 'power_stage_off']


def test_query_frame():
    assert query_frame() == b'?A\r?V\r?S\r?M\r?T\r?FF\r?FM\r?FS\r'


def test_track_speed_and_thrust_models():
    # 2 m/s belt speed: 221 sprocket RPM, x 7 = 1548 motor RPM
    rpm = 2.0 / (math.pi * DRIVETRAIN.sprocket_diameter_m) * 60 * DRIVETRAIN.gear_reduction
    assert track_speed_mps(rpm, DRIVETRAIN) == pytest.approx(2.0)
    assert prop_thrust_n(100.0, DRIVETRAIN) == pytest.approx(133.0)
    reverse = prop_thrust_n(-100.0, DRIVETRAIN)
    assert reverse == pytest.approx(-133.0 * DRIVETRAIN.prop_reverse_thrust_ratio)
    assert -133.0 < reverse < 0.0                      # reverse weaker (config: 0.69)


def run(monitor, device, t0, t1, dt=0.05):
    t = t0
    reply = b''
    while t < t1:
        monitor.feed(reply, t)
        reply = device.feed(monitor.queries())
        t += dt
    monitor.feed(reply, t)
    return t


def test_monitor_against_the_emulator_tracks():
    monitor, device = MotorMonitor(Drive.TRACKS, DRIVETRAIN, port_channel=1), FakeRoboteq()
    assert monitor.sides(0.0)[0].fault_flags == roboteq.FAULT_COMM_TIMEOUT
    assert math.isnan(monitor.sides(0.0)[0].current_a)
    t = run(monitor, device, 0.0, 0.2)
    port, stbd = monitor.sides(t)
    assert port.current_a == pytest.approx(12.3) and stbd.current_a == pytest.approx(14.5)
    assert port.force_n == pytest.approx(12.3 * 8.16)
    assert port.command_pct == 60.0 and stbd.command_pct == 56.0
    assert port.voltage_v == pytest.approx(24.6)
    assert port.speed_mps == pytest.approx(track_speed_mps(1547, DRIVETRAIN))
    assert port.temperature_c == 41 and stbd.temperature_c == 43
    assert port.fault_flags == 0 and port.faults == ()
    assert monitor.watchdog_ms == 1000 and monitor.warnings() == []
    assert monitor.parser.parse_errors == 0 and monitor.parser.echoes > 0
    assert device.commands == []  # a monitor never commands the motors
    assert not monitor.fresh(t + 1.0)  # the controller went quiet


def test_monitor_props_channel_swap_faults_and_warnings():
    monitor, device = MotorMonitor(Drive.PROPS, DRIVETRAIN, port_channel=2), FakeRoboteq()
    device.fault_flags, device.motor_flags = 0b1, (0, 0b10)
    device.watchdog_ms, device.status_flags = 0, 0b1001
    t = run(monitor, device, 0.0, 0.2)
    port, stbd = monitor.sides(t)
    assert port.current_a == pytest.approx(14.5) and port.speed_mps == 0.0
    assert port.force_n == pytest.approx(prop_thrust_n(56.0, DRIVETRAIN))
    assert port.faults == ('overheat', 'stall') and stbd.faults == ('overheat',)
    assert port.fault_flags == roboteq.FAULT_OVERHEAT | roboteq.FAULT_STALL
    warnings = ' '.join(monitor.warnings())
    assert 'watchdog disabled' in warnings and 'serial command mode' in warnings
    assert 'power stage off' in warnings


def test_bad_drive_and_channel_are_config_errors():
    with pytest.raises(ConfigError, match="'drive'"):
        Drive.parse('rudder')
    with pytest.raises(ConfigError, match="'port_channel'"):
        MotorMonitor(Drive.TRACKS, DRIVETRAIN, port_channel=3)


@settings(max_examples=300, deadline=None)
@given(st.lists(st.binary(max_size=80), max_size=20))
def test_random_bytes_never_raise(chunks):
    monitor = MotorMonitor(Drive.TRACKS, DRIVETRAIN)
    for i, chunk in enumerate(chunks):
        monitor.feed(chunk, i * 0.05)
        monitor.sides(i * 0.05)
        monitor.warnings()


@settings(max_examples=300, deadline=None)
@given(st.binary(min_size=1, max_size=60).filter(lambda b: b'\r' not in b and b'\n' not in b))
def test_every_random_line_is_a_reply_an_echo_an_ack_or_a_counted_error(line):
    parser = ReplyParser()
    parser.feed(line + b'\r')
    counted = parser.replies + parser.echoes + parser.acks + parser.nacks + parser.parse_errors
    assert counted == int(meaningful(line))


def meaningful(line: bytes) -> bool:
    """A line the parser must account for: not blank once decoded and stripped."""
    try:
        return bool(line.decode('ascii').strip())
    except UnicodeDecodeError:
        return True


@settings(max_examples=200, deadline=None)
@given(st.data())
def test_corrupted_reply_streams_are_counted_line_by_line(data):
    good = FakeRoboteq().feed(query_frame())
    corrupt = bytearray(good)
    for _ in range(data.draw(st.integers(1, 5))):
        i = data.draw(st.integers(0, len(corrupt) - 1))
        corrupt[i] = data.draw(st.integers(0, 255).filter(lambda b: b not in b'\r\n'))
    parser = ReplyParser()
    parsed = parser.feed(bytes(corrupt))
    for name, values in parsed.items():
        low, high = roboteq.QUERIES[name]
        assert low <= len(values) <= high
    *complete, _waiting = bytes(corrupt).split(b'\r')  # an unterminated tail waits for more
    lines = [line for line in complete if meaningful(line)]
    counted = parser.replies + parser.echoes + parser.acks + parser.nacks + parser.parse_errors
    assert counted == len(lines)
