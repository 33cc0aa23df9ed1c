"""Offline replay throughput: messages per second, raw, decoded and through the cores.

Writes a synthetic bag (stack-like mix of small messages) to a temporary folder, then
streams it raw (target >= 100 k messages/s) and decoded, and replays the golden bags
in tests/golden/ through every available core adapter. Prints figures; no pass/fail.

    python benchmarks/bench_replay.py [--messages 200000]
"""
from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from dukw_bringup import bag_io
from dukw_bringup.replay import replay, stream
from dukw_bringup.replay_adapters import ADAPTERS
from figures import report

GOLDEN = Path(__file__).resolve().parents[1] / 'tests' / 'golden'


def write_synthetic(path: Path, n_messages: int) -> float:
    """A bag of ``n_messages`` DiffCommand/WaterContact/Traction messages; returns seconds."""
    store = bag_io.typestore()
    types = store.types
    header = types['std_msgs/msg/Header'](
        stamp=types['builtin_interfaces/msg/Time'](sec=1, nanosec=0), frame_id='base_link')
    samples = {
        '/tracks/cmd': ('dukw_msgs/msg/DiffCommand', types['dukw_msgs/msg/DiffCommand'](
            header=header, port_pct=40.0, stbd_pct=38.0)),
        '/water/contact': ('dukw_msgs/msg/WaterContact', types['dukw_msgs/msg/WaterContact'](
            header=header, fore_wet=True, aft_wet=False, fore_level=0.9, aft_level=0.1)),
        '/traction': ('dukw_msgs/msg/Traction', types['dukw_msgs/msg/Traction'](
            header=header, **{n: 0.5 for n in types['dukw_msgs/msg/Traction'].__dataclass_fields__
                              if n not in ('header', 'afloat', '__msgtype__')}, afloat=False)),
    }
    raws = {topic: store.serialize_cdr(msg, msgtype) for topic, (msgtype, msg) in samples.items()}
    topics = list(samples)
    start = time.perf_counter()
    with bag_io.BagWriter(path, store) as writer:
        for topic, (msgtype, _) in samples.items():
            writer.add_topic(topic, msgtype)
        for k in range(n_messages):
            topic = topics[k % len(topics)]
            writer.write(topic, k * 1_000_000, raws[topic])
    return time.perf_counter() - start


def main() -> None:
    """Print the throughput figures."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--messages', type=int, default=200_000)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        bag = Path(tmp) / 'synthetic'
        seconds = write_synthetic(bag, args.messages)
        print(f'write   : {args.messages} messages in {seconds:.3f} s = '
              f'{args.messages / seconds:,.0f} messages/s')
        for decode in (False, True):
            count, seconds = stream(bag, decode)
            label = 'decoded' if decode else 'raw'
            report(f'replay streaming {label}', count / seconds, 'msg/s',
                   target=None if decode else 100_000.0, better='higher')
            print(f'{label:<8}: {count} messages in {seconds:.3f} s = '
                  f'{count / seconds:,.0f} messages/s' + ('  (target >= 100,000)'
                                                          if not decode else ''))
    available = ADAPTERS
    bags = sorted(p for p in GOLDEN.glob('*') if (p / 'metadata.yaml').is_file())
    if not available or not bags:
        print('through the cores: no golden bags or no core adapters yet')
        return
    for bag in bags:
        for name, factory in sorted(available.items()):
            result = replay(bag, [factory()])
            ticks = len(result.rows[name])
            print(f'cores   : {bag.name:<16} {name:<18} {result.messages:>7} messages, '
                  f'{ticks:>6} ticks in {result.elapsed_s:.3f} s = '
                  f'{result.rate_msgs_per_s:,.0f} messages/s')
        result = replay(bag, [f() for f in available.values()])
        print(f'cores   : {bag.name:<16} {"all together":<18} {result.messages:>7} messages in '
              f'{result.elapsed_s:.3f} s = {result.rate_msgs_per_s:,.0f} messages/s')
        report(f'replay {bag.name} through all cores', result.rate_msgs_per_s, 'msg/s',
               target=50_000.0, better='higher')


if __name__ == '__main__':
    main()
