"""Maestro compact protocol codec and the servo switch core, without ROS."""
import random

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from dukw_common.config import ConfigError, node_params
from dukw_driver.authority import Holder, Reason
from dukw_driver.maestro import (ERROR_BITS, OutputChannel, ReplyParser, ServoSwitch,
                                 decode_errors, encode_get_errors, encode_get_position,
                                 encode_set_target, switch_config)
from fake_maestro import FakeMaestro


def test_set_target_matches_the_users_guide_example():
    # Pololu user's guide 5.e: channel 2 to 1500 us -> 0x84, 0x02, 0x70, 0x2E
    assert encode_set_target(2, 6000) == bytes((0x84, 0x02, 0x70, 0x2E))
    assert encode_get_position(5) == bytes((0x90, 5))
    assert encode_get_errors() == bytes((0xA1,))


@pytest.mark.parametrize('channel,target', [(12, 6000), (-1, 6000), (0, 0x4000), (0, -1)])
def test_out_of_range_frames_are_refused(channel, target):
    with pytest.raises(ValueError):
        encode_set_target(channel, target)


def test_error_register_decoded_bit_by_bit():
    assert decode_errors(0) == []
    assert decode_errors(1 << 4 | 1 << 5) == ['serial_protocol', 'serial_timeout']
    assert decode_errors(1 << 8) == ['script_program_counter']
    assert decode_errors(1 << 12) == ['bit_12']
    assert len(ERROR_BITS) == 9


def test_percent_to_pulse_with_end_points_dead_band_and_reversal():
    out = OutputChannel('port_track', 0, neutral_us=1500, min_us=1100, max_us=1900)
    assert out.pulse_us(0) == 1500
    assert out.pulse_us(100) == 1900
    assert out.pulse_us(-100) == 1100
    assert out.pulse_us(50) == 1700
    assert out.pulse_us(1.5, deadband_pct=2.0) == 1500
    assert out.pulse_us(250) == 1900  # clamped
    assert out.target_qus(50) == 6800
    rev = OutputChannel('stbd_track', 1, reversed=True)
    assert rev.pulse_us(60) == 1200
    with pytest.raises(ConfigError, match='port_track'):
        OutputChannel('port_track', 0, neutral_us=2100)


PARAMS = node_params('servo_switch_node')
CONFIG = switch_config(PARAMS)


def params(**overrides):
    return {**PARAMS, **overrides}


def test_switch_config_from_the_parameter_file_and_bad_values():
    cfg = switch_config(params())
    assert cfg.outputs['tracks'][0].channel == 0 and cfg.outputs['props'][1].channel == 3
    with pytest.raises(ConfigError, match='output_channels'):
        switch_config(params(output_channels=[0, 1, 2]))
    with pytest.raises(ConfigError, match='used twice'):
        switch_config(params(select_channel=0))
    with pytest.raises(ConfigError, match='channel'):
        switch_config(params(stick_channels=[6, 12]))


def make_switch():
    return ServoSwitch(CONFIG, command_timeout_s=0.5)


def run(switch, maestro, t0, t1, dt=0.02):
    """Drive the core against the emulator from t0 to t1; return the last time."""
    t = t0
    reply = b''
    while t < t1:
        switch.feed(reply, t)
        reply = maestro.feed(switch.cycle(t))
        t += dt
    switch.feed(reply, t)
    return t


def test_core_against_the_emulator_forwards_only_while_the_computer_holds():
    switch, maestro = make_switch(), FakeMaestro()
    maestro.set_lines(select_rc=False, link_ok=True)
    t = run(switch, maestro, 0.0, 0.1)
    assert switch.gate.state.holder == Holder.COMPUTER
    assert switch.command('tracks', 60.0, 56.0, t)
    t = run(switch, maestro, t, t + 0.1)
    assert maestro.target_us(0) == 1800 and maestro.target_us(1) == 1780
    assert maestro.target_us(2) == 1500  # props not commanded
    maestro.set_lines(select_rc=True, link_ok=True)
    t = run(switch, maestro, t, t + 0.1)
    assert switch.gate.state.holder == Holder.RC
    assert not switch.command('tracks', 60.0, 56.0, t)
    assert [maestro.target_us(c) for c in range(4)] == [1500.0] * 4
    assert switch.parser.parse_errors == 0


def test_core_device_silence_is_device_lost_and_neutral():
    switch, maestro = make_switch(), FakeMaestro()
    maestro.set_lines(select_rc=False, link_ok=True)
    t = run(switch, maestro, 0.0, 0.1)
    switch.command('props', 80.0, 80.0, t)
    frame = b''
    while t < 1.0:  # the device stops answering
        switch.feed(b'', t)
        frame = switch.cycle(t)
        t += 0.02
    assert switch.gate.state.reason == Reason.DEVICE_LOST
    assert switch.gate.state.holder == Holder.NONE
    assert frame.startswith(switch.neutral_frame())
    assert switch.parser.timeouts >= 1


def test_input_hysteresis_holds_the_line_state_near_the_threshold():
    switch, maestro = make_switch(), FakeMaestro()
    maestro.inputs.update({4: 700, 5: 1023})
    t = run(switch, maestro, 0.0, 0.1)
    assert switch.last_reading.rc_selected
    maestro.inputs[4] = 450  # below 512 but above 512 - 100: still high
    t = run(switch, maestro, t, t + 0.1)
    assert switch.last_reading.rc_selected
    maestro.inputs[4] = 300
    run(switch, maestro, t, t + 0.1)
    assert not switch.last_reading.rc_selected


def test_sticks_are_scaled_to_microseconds():
    switch, maestro = make_switch(), FakeMaestro()
    maestro.set_lines(select_rc=True, link_ok=True)
    maestro.inputs.update({6: 0, 7: 1023, 8: 512, 9: 256})
    run(switch, maestro, 0.0, 0.1)
    us = switch.last_reading.channels_us
    assert us[0] == 1000 and us[1] == 2000 and round(us[2]) == 1500 and round(us[3]) == 1250
    maestro.set_lines(select_rc=True, link_ok=False)
    run(switch, maestro, 0.1, 0.2)
    assert switch.last_reading.channels_us == (0.0,) * 4  # no pulse while the link is lost


def test_maestro_errors_are_reported_by_name():
    switch, maestro = make_switch(), FakeMaestro()
    maestro.set_lines(select_rc=True, link_ok=True)
    maestro.errors = 1 << 5 | 1 << 0
    reading = switch.feed(maestro.feed(switch.cycle(0.0)), 0.01)
    assert reading.errors == ('serial_signal', 'serial_timeout')
    assert switch.device_errors == reading.errors
    reading = switch.feed(maestro.feed(switch.cycle(0.02)), 0.03)
    assert reading.errors == ()  # reading the register cleared it
    assert switch.take_device_errors() == ['serial_signal', 'serial_timeout']  # kept for /diag
    assert switch.take_device_errors() == []


def test_parser_counts_unsolicited_short_and_out_of_range_replies():
    parser = ReplyParser(reply_timeout_s=0.1)
    assert parser.feed(b'\x01', 0.0) is None and parser.parse_errors == 1
    parser.expect(['position', 'errors'], 0.0)
    assert parser.feed(b'\xff\x7f', 0.0) is None  # 32767 > 1023
    assert parser.parse_errors == 2
    parser.expect(['position', 'errors'], 1.0)
    assert parser.feed(b'\x00', 1.0) is None
    assert parser.feed(b'', 1.5) is None and parser.timeouts == 1
    parser.expect(['position', 'errors'], 2.0)
    assert parser.feed(b'\x10\x02\x20\x00', 2.0) == [0x210, 0x20]
    parser.expect(['position'], 3.0)
    assert parser.feed(b'\x10\x02\x20', 3.0) is None  # one byte too many
    assert parser.parse_errors == 4


@settings(max_examples=300, deadline=None)
@given(st.lists(st.binary(max_size=20), max_size=20), st.randoms(use_true_random=False))
def test_random_bytes_never_raise(chunks, rnd):
    switch = make_switch()
    t = 0.0
    for chunk in chunks:
        assert switch.cycle(t).startswith(switch.neutral_frame())
        t += rnd.choice((0.001, 0.02, 0.2))
        reading = switch.feed(chunk, t)
        if reading is not None and reading.link_ok:
            assert all(1000 <= us <= 2000 for us in reading.channels_us)
        elif reading is not None:
            assert set(reading.channels_us) == {0.0}


@settings(max_examples=300, deadline=None)
@given(st.binary(min_size=1, max_size=40))
def test_one_random_reply_is_a_reading_or_exactly_one_counted_error(data):
    switch = make_switch()
    switch.cycle(0.0)
    reading = switch.feed(data, 0.01)
    switch.feed(b'', 1.0)  # let an incomplete batch expire
    assert (reading is not None) + switch.parser.parse_errors == 1


@settings(max_examples=100, deadline=None)
@given(st.lists(st.binary(min_size=1, max_size=8), min_size=1, max_size=10))
def test_unsolicited_bytes_are_each_counted(chunks):
    parser = ReplyParser(reply_timeout_s=0.1)
    for chunk in chunks:
        assert parser.feed(chunk, 0.0) is None
    assert parser.parse_errors == len(chunks)


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 6))
def test_corrupted_replies_are_counted_and_never_forward_while_rc_holds(seed, flips):
    rnd = random.Random(seed)
    switch, maestro = make_switch(), FakeMaestro()
    maestro.set_lines(select_rc=True, link_ok=True)
    t = 0.0
    reply = b''
    for _ in range(40):
        if reply and rnd.random() < 0.3:
            data = bytearray(reply)
            for _ in range(flips):
                op = rnd.choice(('flip', 'drop', 'add'))
                if op == 'flip' and data:
                    data[rnd.randrange(len(data))] ^= 1 << rnd.randrange(8)
                elif op == 'drop' and data:
                    del data[rnd.randrange(len(data))]
                else:
                    data.insert(rnd.randrange(len(data) + 1), rnd.randrange(256))
            reply = bytes(data)
        switch.feed(reply, t)
        switch.command('tracks', 90.0, 90.0, t)  # the operator holds: never forwarded
        frame = switch.cycle(t)
        if switch.gate.state.holder != Holder.COMPUTER:
            assert frame.startswith(switch.neutral_frame())
        reply = maestro.feed(frame)
        t += 0.02
