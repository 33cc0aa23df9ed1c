"""The servo switch's authority rule: the RC operator always wins."""
import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from dukw_driver.authority import (NEUTRAL, CommandGate, Holder, Reason, SideCommand,
                                   validate_command)


def computer_gate():
    gate = CommandGate(command_timeout_s=0.5)
    gate.update_rc(rc_selected=False, rc_link_ok=True)
    return gate


def test_starts_with_nobody_and_neutral():
    gate = CommandGate(0.5)
    assert gate.state.holder == Holder.NONE
    assert gate.outputs(0.0) == {'tracks': NEUTRAL, 'props': NEUTRAL}


def test_computer_commands_pass_while_fresh_then_time_out_to_neutral():
    gate = computer_gate()
    assert gate.command('tracks', SideCommand(60, 56), now_s=1.0)
    assert gate.outputs(1.2)['tracks'] == SideCommand(60, 56)
    assert gate.outputs(1.2)['props'] == NEUTRAL
    assert gate.outputs(1.6)['tracks'] == NEUTRAL
    assert gate.state.reason == Reason.COMMAND_TIMEOUT
    assert gate.state.outputs_neutral


def test_a_second_command_publisher_neutralises_until_it_is_gone():
    gate = computer_gate()
    gate.set_publishers('tracks', 1)
    assert gate.command('tracks', SideCommand(60, 56), now_s=1.0)
    gate.set_publishers('tracks', 2, ('/drive_controller_node', '/stranger'))
    assert not gate.command('tracks', SideCommand(100, -100), now_s=1.05)
    assert gate.outputs(1.1) == {'tracks': NEUTRAL, 'props': NEUTRAL}
    assert gate.state.outputs_neutral and '/stranger' in gate.state.detail
    gate.set_publishers('tracks', 1)
    assert gate.outputs(1.15)['tracks'] == NEUTRAL        # the old command is forgotten
    assert gate.command('tracks', SideCommand(60, 56), now_s=1.2)
    assert gate.outputs(1.2)['tracks'] == SideCommand(60, 56)
    assert not gate.state.outputs_neutral


def test_rc_takeover_blocks_and_forgets_computer_commands():
    gate = computer_gate()
    gate.command('tracks', SideCommand(80, 80), now_s=0.0)
    gate.update_rc(rc_selected=True, rc_link_ok=True)
    assert gate.state.holder == Holder.RC
    assert gate.outputs(0.1)['tracks'] == NEUTRAL
    assert not gate.command('tracks', SideCommand(50, 50), now_s=0.2)
    # authority back: the old command does not come back by itself
    gate.update_rc(rc_selected=False, rc_link_ok=True)
    assert gate.state.holder == Holder.COMPUTER
    assert gate.outputs(0.25)['tracks'] == NEUTRAL


def test_link_loss_is_neutral_whoever_held_authority():
    for selected in (True, False):
        gate = computer_gate()
        gate.command('props', SideCommand(100, 100), now_s=0.0)
        gate.update_rc(rc_selected=selected, rc_link_ok=False)
        assert gate.state.reason == Reason.RC_LINK_LOST
        assert gate.state.outputs_neutral
        assert gate.outputs(0.1)['props'] == NEUTRAL
        assert not gate.command('props', SideCommand(10, 10), 0.2)


def test_device_lost_and_shutdown_are_neutral():
    gate = computer_gate()
    gate.command('tracks', SideCommand(30, 30), 0.0)
    gate.device_lost()
    assert gate.state.holder == Holder.NONE
    assert gate.outputs(0.1)['tracks'] == NEUTRAL
    gate = computer_gate()
    gate.command('tracks', SideCommand(30, 30), 0.0)
    gate.shutdown()
    assert gate.outputs(0.1)['tracks'] == NEUTRAL


def test_changed_flag_is_set_once_per_change():
    gate = computer_gate()
    gate.changed = False
    gate.update_rc(False, True)
    assert not gate.changed
    gate.update_rc(True, True)
    assert gate.changed


@pytest.mark.parametrize('port,stbd', [(math.nan, 0), (0, math.inf), (101, 0), (0, -100.5)])
def test_bad_commands_are_refused(port, stbd):
    with pytest.raises(ValueError):
        validate_command(port, stbd)


def test_unknown_actuator_is_refused():
    with pytest.raises(ValueError, match='unknown actuator'):
        computer_gate().command('rudder', NEUTRAL, 0.0)


@given(st.lists(st.tuples(st.booleans(), st.booleans(), st.floats(-100, 100)), max_size=30))
def test_no_sequence_lets_a_command_through_while_rc_holds(events):
    gate = computer_gate()
    t = 0.0
    for selected, link, value in events:
        t += 0.05
        gate.update_rc(selected, link)
        gate.command('tracks', SideCommand(value, value), t)
        if gate.state.holder != Holder.COMPUTER:
            assert gate.outputs(t) == {'tracks': NEUTRAL, 'props': NEUTRAL}
