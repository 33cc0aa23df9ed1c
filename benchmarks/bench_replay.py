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
from functools import partial
from pathlib import Path

from dukw_bringup import bag_io
from dukw_bringup import replay as replay_module
from dukw_bringup.replay import replay, stream
from dukw_bringup.replay_adapters import ADAPTERS, CoreAdapter, EkfAdapter
from dukw_common.node_tools import stamp_or
from dukw_estimation import ros_convert
from figures import report
from profile_text import profile_to_text

GOLDEN = Path(__file__).resolve().parents[1] / 'tests' / 'golden'
#: replays of each golden bag through all cores (the best is reported: shared machine)
REPEAT = 3


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


def estimator_inputs(bag: Path) -> list[tuple[str, float, object]]:
    """The estimator's inputs of ``bag``, decoded and converted: (topic key, t_s, sample)."""
    store = bag_io.typestore()
    with bag_io.BagReader(bag) as reader:
        convert = ros_convert.SAMPLE_FROM_MSG
        return [(key, t_s, convert[key](msg, stamp_or(msg, t_s)))
                for key, t_s, msg in ((bag_io.topic_key(m.topic), m.timestamp_ns * 1e-9,
                                       bag_io.deserialize(m, store))
                                      for m in reader.messages(EkfAdapter.inputs))]


def run_estimator(samples: list[tuple[str, float, object]],
                  adapter: EkfAdapter) -> dict[str, tuple[int, float]]:
    """A fresh ``adapter``'s EkfRunner.on_sample/tick over ``samples`` and the estimate's
    reads (odometry and traction, as the replay compares both), timed per input topic:
    (count, seconds) on the thread's CPU clock."""
    runner, clock = adapter.runner, time.thread_time
    per_topic: dict[str, tuple[int, float]] = {}
    next_tick_s, period_s = samples[0][1], 1.0 / adapter.rate_hz
    for key, t_s, sample in samples:
        start = clock()
        while next_tick_s < t_s:              # the timer, as the replay runs it
            estimate = runner.tick(next_tick_s)
            if estimate is not None:
                _ = estimate.odometry, estimate.traction
            next_tick_s += period_s
        estimate = runner.on_sample(key, sample, t_s)
        if estimate is not None:
            _ = estimate.odometry, estimate.traction
        count, seconds = per_topic.get(key, (0, 0.0))
        per_topic[key] = (count + 1, seconds + clock() - start)
    return per_topic


def estimator_bound(bag: Path) -> tuple[float, dict[str, tuple[int, float]]]:
    """The estimator's own work in a replay of ``bag``: its inputs decoded and converted
    beforehand, only the estimator timed (``run_estimator``). Returns (seconds, per input
    topic: (count, seconds)), on the thread's CPU clock; no replay through the cores can
    beat it."""
    per_topic = run_estimator(estimator_inputs(bag), EkfAdapter())
    return sum(s for _, s in per_topic.values()), per_topic


def print_bound(bag: Path, messages: int, rate: float) -> None:
    """What the estimator alone allows through all the cores, and its cost per class."""
    seconds, per_topic = min((estimator_bound(bag) for _ in range(3)), key=lambda r: r[0])
    imu = per_topic.get('imu/data', (0, 0.0))
    print(f'bound   : {bag.name:<16} the estimator alone takes {seconds * 1e3:.1f} ms CPU of '
          f'the {messages} messages = at most {messages / seconds:,.0f} messages/s through all '
          f'cores (CPU clock: reached {rate / (messages / seconds):.0%} of it); imu/data is '
          f'{imu[0] / messages:.0%} of the messages at {imu[1] / max(imu[0], 1) * 1e6:.0f} us '
          'each (step + odometry + traction)')
    print('          per class (us each): ' + ', '.join(
        f'{key} {s / n * 1e6:.0f} (x{n})' for key, (n, s) in
        sorted(per_topic.items(), key=lambda item: -item[1][1])))
    report(f'replay {bag.name} estimator-alone bound', messages / seconds, 'msg/s',
           better='higher')
    # the 100 us is for the IMU step with its outputs: here on the bag's own samples
    report(f'replay {bag.name} estimator imu/data step + outputs, mean',
           imu[1] / max(imu[0], 1) * 1e6, 'us', target=100.0)


class IdleCore(CoreAdapter):
    """A core that does nothing, with ``real``'s topics, fields and timer: the replay's
    reading, decoding and loop around it, without its work."""

    def __init__(self, real: CoreAdapter) -> None:
        self.name, self.inputs, self.outputs = real.name, real.inputs, real.outputs
        self.rate_hz, self.fields = real.rate_hz, real.fields

    def feed(self, topic, t_s, msg):
        return None

    def tick(self, t_s):
        return None

    def recorded_columns(self, topic, msgs):
        return {}


def replay_phases(bag: Path, adapters: list[CoreAdapter]) -> tuple[float, float, float]:
    """One replay of ``bag`` (one batch) in its three steps, each on the thread's CPU clock:
    reading the records, decoding them (every topic's fields as columns, the routes) and
    feeding them through the cores (their steps, outputs and comparisons). Seconds. Drives
    dukw_bringup.replay's own steps, as replay() does, apart."""
    clock = time.thread_time
    with bag_io.BagReader(bag) as reader:
        drivers, wanted = replay_module._drivers(reader, bag, adapters)
        start = clock()
        batch = list(reader.records(wanted))
        read = clock()
        with replay_module._no_cycle_collection():
            routes = replay_module._routes(batch, drivers)
            decoded = clock()
            replay_module._feed_batch_in_order(batch, drivers, routes)
        return read - start, decoded - read, clock() - decoded


def print_phases(bag: Path, repeat: int = 7) -> None:
    """The phases of a replay through all cores, and each core's own feeding (the others
    idle), best of ``repeat`` each."""
    def best(make) -> list[float]:
        runs = [replay_phases(bag, make()) for _ in range(repeat)]
        return [min(run[k] for run in runs) * 1e3 for k in range(3)]
    best(lambda: [f() for f in ADAPTERS.values()])                      # warm up
    read, decode, feed = best(lambda: [f() for f in ADAPTERS.values()])
    print(f'phases  : {bag.name:<16} all cores: read {read:.1f} ms, decode {decode:.1f} ms, '
          f'feed {feed:.1f} ms (CPU clock, best of {repeat} each)')
    idle = best(lambda: [IdleCore(f()) for f in ADAPTERS.values()])[2]
    own = {name: best(partial(_alone, name))[2] - idle for name in ADAPTERS}
    print(f"          feeding: the loop with idle cores {idle:.1f} ms; each core's own work "
          '(its steps, conversions, rows, comparisons): '
          + ', '.join(f'{name} {ms:.1f} ms' for name, ms in own.items()))


def _alone(name: str) -> list[CoreAdapter]:
    """The core ``name`` and the others idle."""
    return [ADAPTERS[n]() if n == name else IdleCore(ADAPTERS[n]()) for n in ADAPTERS]


PROFILE_HEADER = """cProfile of one replay of tests/golden/land_to_sea through all cores:
  python benchmarks/bench_replay.py --profile benchmarks/profiles/replay_through_cores.txt
Before issue 16's replay work the bag was opened twice (anchor pass + replay) and one
open (metadata.yaml and every topic's QoS YAML, pure-Python ruamel) was timed with the
messages: 40-80 ms per open, more than a quarter of a 7 s bag's replay. Now: one open,
timed apart (bag_io.BagReader, ReplayResult.open_s). Then (branch ekfperf) the estimator's
hot paths. Then (branch i16replay, 2026-11-25) the replay's own work, results
bit-identical (golden bags regenerate unchanged): outputs equal to the recording bit for
bit are compared with one dict-view check; a core only visits the messages it uses;
adapters dispatch by topic; the drive controller makes its hand PI gains once and
SidePair.scaled(1.0) returns the pair. Reading and decoding are rosbags' (BagReader.messages
over rosbags' Reader with the connections filtered once; Typestore.deserialize_cdr, its
bound method taken once): a hand-written MCAP chunk reader and CDR decoder generator were
faster (reading + decoding 37 -> 23 ms of land_to_sea) but were dropped for the project's
library rule. Interleaved A/B against bdc8249 (04:28-04:33 UTC, CPU clock, best of 5 per
run, eight rounds, load average 4-6): 19.9-24.2 k (median 22.8) -> 21.3-25.3 k (22.5)
msg/s land_circle, 20.0-22.1 (21.4) -> 17.7-23.1 (21.7) land_to_sea, 20.4-23.2 (21.6) ->
18.3-23.6 (21.2) sea_to_land: no difference the noise lets through. What limits it,
measured: the estimator alone (the 'bound' line) is ~110 ms CPU of land_to_sea's ~240 ms
(at most ~49 k msg/s with nothing else), so 50 k through all cores is out of reach
without a cheaper estimator; of the rest: rosbags' CDR decoding (~24 ms, ~20 % here) and
MCAP reading (~11 ms, ~11 % here), the estimator's message conversions and rows, the
drive controller core (~13 ms) and its conversions, the mode manager, the comparisons
and the replay loop.
Then (branch i16g, 2026-11-27) the estimator: bit-identical steps first (the tracks' Wong
force through traction.track_force_f with its patch remembered, the hulls' bottom line once
per state, the state read as floats, settings and per-status soil forces looked up once),
then the EKF's predict and updates as numba kernels (dukw_estimation.ekf_kernels; the
covariance's last bits change, golden bags regenerated). Interleaved rounds against 8ac9fe6
(16:25-16:29 UTC, CPU clock, best of 5 per run, five rounds, load average 4.9-5.6), medians:
land_circle 28.6 k -> 31.8 k (bit-identical steps) -> 35.6 k msg/s (numba), land_to_sea
26.8 k -> 32.0 k -> 36.2 k, sea_to_land 26.7 k -> 31.1 k -> 35.7 k. Not met (>= 50 k): of
land_to_sea's ~155 ms, reading + decoding + the loop with cores that do nothing are ~35 ms
(rosbags'), the estimator ~50 ms, its adapter (conversions, rows, comparisons) ~25 ms, the
drive controller ~21 ms, the mode manager ~4 ms.
Then (branch i16i, 2026-11-27) the replay's per-message work, results bit-identical (rows
and deviations of every golden bag, all cores and each alone, pickled and compared with
main's, float types included): each adapter names the fields it reads
(CoreAdapter.fields) and the replay decodes only those, as numpy columns of a whole
topic's batch (dukw_bringup.bag_fields: a layout from rosbags' message definitions, checked
against every message; rosbags per message where they differ), not a rosbags object per
message; ros_convert's rules take fields (SAMPLE_FROM_MSG reads them from a message with
one attrgetter: one rule for ekf_node and the replay); recorded outputs are compared batch
by batch, a quantity over all its messages with numpy (recorded_columns), not a dict per
message; the cyclic GC is paused while a batch is fed; the IMU sample and motor sides are
built positionally; the stance detector keeps its sigmas; rosbags' records are batched
without a BagMessage each. Interleaved with the branch point 3618656 (19:18-19:19 UTC,
CPU clock, best of 7, four rounds, load 2.8-4.6): land_circle 117.4-121.3 -> 89.6-94.3 ms,
land_to_sea 153.6-157.2 -> 120.3-124.9 ms (34-35 k -> 43-45 k msg/s), sea_to_land
169.8-172.9 -> 134.2-142.3 ms: 17-25 % less per round, not the 30 % that 50 k needs.
Phases after, merged with main 0566b12 (--phases, 19:23, load 0.8): reading 9.7 ms
(rosbags' MCAP reader; the mcap library's iter_messages is slower), decoding 4.6 ms,
feeding 106 ms: the loop with idle cores 4.8, mode manager 2.2, drive controller 17.7
(its step ~12 us x 900), EKF 72.1 of which the estimator ~57-60 (the 'bound' line) and
its conversions, rows, ticks and comparisons ~12. What limits it: the estimator alone is
about half of the time; with it as it is, everything else would have to fall under ~45 ms
for 50 k.
Then (main, 2026-11-28 00:00-00:55) the estimator's remaining hot spots and one copy in the
replay: the force smoother on scalars, the stance window and the hull line's integrals as
numba kernels, the covariance propagation over F's listed nonzeros, each IMU sample's
accelerations once, no repeated contact decision after a heave-only update, the core's
output dict kept as its row, the submersion's key without a cosine (docs/performance_log.md).
Idle (00:52): 53.2-55.1 k msg/s through all cores, the target met; land_to_sea's ~100 ms:
reading 8.6, decoding 2.9, loop 3.1, mode manager 2.4, drive controller 15.6, EKF 56.2 of
which the estimator ~44 ms."""

ESTIMATOR_PROFILE_HEADER = """cProfile of the estimator alone (EkfRunner, odometry and
traction read per estimate, as the replay does) on tests/golden/land_to_sea's inputs,
decoded beforehand:
  python benchmarks/bench_replay.py --profile-estimator benchmarks/profiles/estimator_alone.txt
(branch ekfperf, issue 16) Per message class on the CPU clock see the 'bound' lines.
(branch i16g, 2026-11-27) The EKF's predict and updates are numba kernels (ekf_kernels: one
call each, ~1-1.5 us) and the traction query and submersion work on floats: the estimator
alone on land_to_sea ~91 -> ~50 ms CPU.
(branch i16i, 2026-11-27) The stance detector keeps the sigmas of the IMU's variances
while they stay (3.8 instead of 4.9 us a sample); its inputs here are converted with the
same ros_convert rules the replay now calls with fields.
(main, 2026-11-28) The force smoother on scalars, the stance window and the hull line's
integrals compiled, the propagation over F's nonzeros, the IMU's accelerations once, no
repeated contact decision after a heave-only update: ~62 -> ~47 ms on land_to_sea."""


def main() -> None:
    """Print the throughput figures."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--messages', type=int, default=200_000)
    parser.add_argument('--profile', default=None,
                        help='cProfile one replay of land_to_sea through all cores, as text '
                             'to this file, and stop')
    parser.add_argument('--phases', action='store_true',
                        help="print land_to_sea's replay phases (reading, decoding, each "
                             "core's feeding) and stop")
    parser.add_argument('--profile-estimator', default=None,
                        help="cProfile the estimator alone on land_to_sea's inputs (the "
                             "'bound' line's work), as text to this file, and stop")
    args = parser.parse_args()
    if args.phases:
        print_phases(GOLDEN / 'land_to_sea')
        return
    if args.profile_estimator:
        samples = estimator_inputs(GOLDEN / 'land_to_sea')
        run_estimator(samples, EkfAdapter())                          # warm up
        adapter = EkfAdapter()
        profile_to_text(lambda: run_estimator(samples, adapter), args.profile_estimator,
                        ESTIMATOR_PROFILE_HEADER)
        return
    if args.profile:
        replay(GOLDEN / 'land_to_sea', [f() for f in ADAPTERS.values()])  # rosbags' codegen
        adapters = [f() for f in ADAPTERS.values()]
        profile_to_text(lambda: replay(GOLDEN / 'land_to_sea', adapters), args.profile,
                        PROFILE_HEADER)
        return
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
        runs = [replay(bag, [f() for f in available.values()]) for _ in range(REPEAT)]
        result = min(runs, key=lambda r: r.elapsed_s)
        cpu_rate = result.messages / min(r.cpu_s for r in runs)
        print(f'cores   : {bag.name:<16} {"all together":<18} {result.messages:>7} messages in '
              f'{result.elapsed_s:.3f} s = {result.rate_msgs_per_s:,.0f} messages/s '
              f'(best of {REPEAT}; on the CPU clock {cpu_rate:,.0f}/s; bag open '
              f'{result.open_s * 1e3:.0f} ms apart)  target >= 50,000')
        report(f'replay {bag.name} through all cores', result.rate_msgs_per_s, 'msg/s',
               target=50_000.0, better='higher')
        print_bound(bag, result.messages, cpu_rate)


if __name__ == '__main__':
    main()
