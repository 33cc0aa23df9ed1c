"""The simulated servo switch: the boat's authority rule plus a playable RC operator."""
import math

import pytest

from dukw_common.config import ConfigError, node_params
from dukw_driver.authority import NEUTRAL, Holder, Reason, SideCommand
from dukw_sim.switch import RcChannels, SimServoSwitch

PARAMS = node_params('sim_node')


def switch():
    return SimServoSwitch(PARAMS['command_timeout_s'], RcChannels.from_params(PARAMS))


def test_the_computer_holds_authority_from_the_start_and_its_commands_pass():
    sw = switch()
    assert sw.state.holder == Holder.COMPUTER
    assert sw.outputs(0.0).source == 'neutral'
    assert sw.command('tracks', 50.0, 48.0, now_s=1.0)
    out = sw.outputs(1.1)
    assert (out.tracks, out.props, out.source) == (SideCommand(50.0, 48.0), NEUTRAL, 'computer')
    assert not sw.state.outputs_neutral


def test_computer_commands_time_out_to_neutral_in_sim_time():
    sw = switch()
    sw.command('props', 80.0, 80.0, now_s=2.0)
    assert sw.outputs(2.0 + PARAMS['command_timeout_s'] - 0.01).props == SideCommand(80.0, 80.0)
    out = sw.outputs(2.0 + PARAMS['command_timeout_s'] + 0.01)
    assert (out.props, out.source) == (NEUTRAL, 'neutral')
    assert sw.state.reason == Reason.COMMAND_TIMEOUT


def test_operator_takeover_drives_with_the_sticks_and_blocks_the_computer():
    sw = switch()
    sw.command('tracks', 50.0, 50.0, now_s=0.0)
    sw.set_operator(rc_selected=True, rc_link_ok=True, port_pct=-20.0, stbd_pct=30.0)
    assert sw.state.holder == Holder.RC
    assert not sw.command('tracks', 90.0, 90.0, now_s=0.1)
    assert sw.ignored == 1
    out = sw.outputs(0.1)
    assert (out.tracks, out.props, out.source) == (SideCommand(-20.0, 30.0),) * 2 + ('operator',)
    # the operator hands back: the old computer command does not come back by itself
    sw.set_operator(False, True, 0.0, 0.0)
    assert sw.state.holder == Holder.COMPUTER
    assert sw.outputs(0.2).source == 'neutral'


@pytest.mark.parametrize('selected', [True, False])
def test_link_loss_is_neutral_whoever_held_authority(selected):
    sw = switch()
    sw.command('tracks', 60.0, 56.0, now_s=0.0)
    sw.set_operator(rc_selected=selected, rc_link_ok=False, port_pct=50.0, stbd_pct=50.0)
    out = sw.outputs(0.1)
    assert (out.tracks, out.props, out.source) == (NEUTRAL, NEUTRAL, 'neutral')
    assert sw.state.reason == Reason.RC_LINK_LOST and sw.state.outputs_neutral
    assert not sw.command('tracks', 60.0, 56.0, now_s=0.2)
    reading = sw.rc_reading(0.2)
    assert (reading.link_ok, reading.channels_us) == (False, (0.0,) * 4)


@pytest.mark.parametrize('port,stbd', [(math.nan, 0.0), (0.0, math.inf), (100.5, 0.0)])
def test_malformed_commands_raise_count_and_change_nothing(port, stbd):
    sw = switch()
    sw.command('tracks', 40.0, 40.0, now_s=0.0)
    with pytest.raises(ValueError):
        sw.command('tracks', port, stbd, now_s=0.1)
    assert sw.rejected == 1
    assert sw.outputs(0.2).tracks == SideCommand(40.0, 40.0)


def test_malformed_operator_sticks_change_nothing():
    sw = switch()
    with pytest.raises(ValueError):
        sw.set_operator(True, True, math.nan, 0.0)
    assert sw.state.holder == Holder.COMPUTER and not sw.operator.rc_selected


def test_rc_reading_encodes_the_sticks_as_pulse_widths():
    sw = switch()
    sw.set_operator(True, True, 100.0, -50.0)
    reading = sw.rc_reading(3.0)
    neutral, per_pct = PARAMS['rc.neutral_us'], PARAMS['rc.us_per_pct']
    assert reading.rc_selected and reading.link_ok and reading.t_s == 3.0
    assert reading.channels_us == (neutral + 100 * per_pct, neutral - 50 * per_pct) * 2


def test_changed_flag_marks_each_authority_change():
    sw = switch()
    sw.gate.changed = False
    sw.set_operator(False, True, 0.0, 0.0)
    assert not sw.gate.changed
    sw.set_operator(True, True, 0.0, 0.0)
    assert sw.gate.changed


def test_rc_channel_config_is_validated():
    with pytest.raises(ConfigError, match='us_per_pct'):
        RcChannels.from_params({**PARAMS, 'rc.us_per_pct': 0.0})
