"""The offline replay harness: timer grid, input order, deviations that name the quantity."""
import math

import pytest

from dukw_bringup import bag_io
from dukw_bringup import replay as replay_module
from dukw_bringup.replay import CoreAdapter, main, replay, stream

MS = 1_000_000


class SumCore(CoreAdapter):
    """A tiny stand-in core: sums the port_pct inputs it has seen; ticks at 10 Hz."""

    name = 'sum'
    inputs = ('in',)
    outputs = ('out',)
    rate_hz = 10.0

    def __init__(self) -> None:
        self.total = 0.0
        self.ticks: list[float] = []

    def feed(self, topic, t_s, msg):
        self.total += msg.port_pct

    def tick(self, t_s):
        self.ticks.append(round(t_s, 6))
        return {'total': self.total, 'ticks': float(len(self.ticks))}

    def recorded(self, topic, msg):
        return {'total': msg.port_pct, 'ticks': msg.stbd_pct}


def _cmd(store, port, stbd=0.0):
    t = store.types
    return t['dukw_msgs/msg/DiffCommand'](
        header=t['std_msgs/msg/Header'](stamp=t['builtin_interfaces/msg/Time'](sec=0, nanosec=0),
                                        frame_id=''), port_pct=port, stbd_pct=stbd)


def _bag(path, outputs):
    """Inputs of 1.0 every 50 ms from t = 0; recorded outputs (t_ms, total, ticks)."""
    store = bag_io.typestore()
    with bag_io.BagWriter(path) as writer:
        for k in range(10):
            writer.write_message('/in', 'dukw_msgs/msg/DiffCommand', k * 50 * MS, _cmd(store, 1.0))
        for t_ms, total, ticks in outputs:
            writer.write_message('/out', 'dukw_msgs/msg/DiffCommand', t_ms * MS,
                                 _cmd(store, total, ticks))
    return path


def test_ticks_follow_the_node_rate_anchored_on_the_first_output(tmp_path):
    # first output at 100 ms; ticks every 100 ms; a tick sees inputs stamped at or before it
    bag = _bag(tmp_path / 'bag', [(100, 3.0, 1.0), (200, 5.0, 2.0), (300, 7.0, 3.0)])
    core = SumCore()
    result = replay(bag, [core])
    assert core.ticks == [0.1, 0.2, 0.3, 0.4]  # the 0.4 s tick runs when the 450 ms input arrives
    devs = result.deviations['sum']
    assert devs['total'].max_abs == 0.0 and devs['total'].compared == 3
    assert devs['ticks'].max_abs == 0.0
    assert [row['total'] for row in result.rows['sum']] == [3.0, 5.0, 7.0, 9.0]
    assert result.messages == 13
    assert result.exceeding({}, 1e-9) == []
    replay_module.write_csv(result.rows['sum'], tmp_path / 'sum.csv')
    lines = (tmp_path / 'sum.csv').read_text().splitlines()
    assert lines[0] == 't_s,total,ticks' and lines[1] == '0.1,3.0,1.0'   # the time first


def test_a_moved_output_is_named_with_its_size_and_time(tmp_path):
    bag = _bag(tmp_path / 'bag', [(100, 3.0, 1.0), (200, 5.5, 2.0), (300, 7.0, 3.0)])
    result = replay(bag, [SumCore()])
    bad = result.exceeding({'ticks': 0.0}, 0.1)
    assert [d.quantity for d in bad] == ['total']
    text = bad[0].describe()
    assert 'sum.total' in text and 'moved by 0.5' in text and 't=0.200 s' in text
    assert result.exceeding({'sum.total': 0.6}, 0.1) == []


@pytest.mark.parametrize('batch_messages', [1, 2, 3, replay_module.BATCH_MESSAGES])
def test_the_first_worst_deviation_is_named_however_the_bag_is_batched(
        tmp_path, monkeypatch, batch_messages):
    # replayed totals 3, 5, 7, 9 at 0.1 .. 0.4 s; the comparisons of many outputs are folded
    # at once (batch by batch), and must name what comparing one by one in order names
    monkeypatch.setattr(replay_module, 'BATCH_MESSAGES', batch_messages)
    moved = _bag(tmp_path / 'moved', [(100, 3.5, 1.0), (200, 6.0, 2.0), (300, 8.0, 3.0)])
    dev = replay(moved, [SumCore()]).deviations['sum']['total']
    assert (dev.max_abs, dev.compared, dev.replayed, dev.recorded) == (1.0, 3, 5.0, 6.0)
    assert dev.at_s == pytest.approx(0.2)               # the first of the two 1.0s
    lost = _bag(tmp_path / 'lost', [(100, 3.0, 1.0), (200, math.nan, 2.0), (300, 17.0, 3.0),
                                    (400, math.nan, 4.0)])
    dev = replay(lost, [SumCore()]).deviations['sum']['total']
    assert math.isnan(dev.max_abs) and dev.at_s == pytest.approx(0.2) and dev.compared == 4
    assert replay(lost, [SumCore()]).deviations['sum']['ticks'].max_abs == 0.0


def test_nan_on_one_side_is_a_deviation(tmp_path):
    bag = _bag(tmp_path / 'bag', [(100, math.nan, 1.0)])
    result = replay(bag, [SumCore()])
    assert [d.quantity for d in result.exceeding({}, 1e6)] == ['total']


def test_a_bag_without_the_output_is_refused(tmp_path):
    bag = _bag(tmp_path / 'bag', [])
    with pytest.raises(bag_io.BagError, match='out'):
        replay(bag, [SumCore()])


def test_stream_counts_every_message(tmp_path):
    bag = _bag(tmp_path / 'bag', [(100, 3.0, 1.0)])
    assert stream(bag)[0] == 11
    assert stream(bag, decode=True, topics=['out'])[0] == 1


def test_cli_streams_and_refuses_unknown_cores(tmp_path, capsys):
    bag = _bag(tmp_path / 'bag', [(100, 3.0, 1.0)])
    assert main([str(bag), '--stream']) == 0
    assert 'messages/s' in capsys.readouterr().out
    assert main([str(bag), '--cores', 'no_such_core']) == 2
    assert 'no adapter' in capsys.readouterr().err
    assert main([str(tmp_path / 'missing')]) == 2


class ReactingCore(SumCore):
    """Reacts at once (outside its timer) to a negative input, like the controller does
    to a lost authority."""

    name = 'react'

    def feed(self, topic, t_s, msg):
        super().feed(topic, t_s, msg)
        return {'total': -1.0, 'ticks': float(len(self.ticks))} if msg.port_pct < 0 else None


def test_an_immediate_reaction_is_the_latest_output(tmp_path):
    store = bag_io.typestore()
    with bag_io.BagWriter(tmp_path / 'bag') as writer:
        writer.write_message('/out', 'dukw_msgs/msg/DiffCommand', 100 * MS, _cmd(store, 0.0, 1.0))
        writer.write_message('/in', 'dukw_msgs/msg/DiffCommand', 150 * MS, _cmd(store, -5.0))
        writer.write_message('/out', 'dukw_msgs/msg/DiffCommand', 160 * MS, _cmd(store, -1.0, 1.0))
    result = replay(tmp_path / 'bag', [ReactingCore()])
    assert result.exceeding({}, 0.0) == []
    assert [row['t_s'] for row in result.rows['react']] == pytest.approx([0.1, 0.15])


class AngleCore(SumCore):
    """Reports its total as an angle."""

    name = 'angle'
    angle_quantities = frozenset({'total'})


def test_angles_are_compared_modulo_two_pi(tmp_path):
    # replayed totals 3, 5, 7 rad; recorded 3 - 2 pi, 5 + 2 pi, 7.5 (the last really moved)
    tau = 2 * math.pi
    bag = _bag(tmp_path / 'bag', [(100, 3.0 - tau, 1.0), (200, 5.0 + tau, 2.0),
                                  (300, 7.5, 3.0)])
    dev = replay(bag, [AngleCore()]).deviations['angle']['total']
    assert dev.max_abs == pytest.approx(0.5) and dev.at_s == pytest.approx(0.3)
