"""replay: feed a bag's messages through the stack's cores without DDS, deterministically.

    replay BAG [--cores mode_manager drive_controller] [--csv OUT_DIR] [--tolerance 1e-6]
    replay BAG --stream          # raw streaming only: messages per second

Each core sits behind a ``CoreAdapter`` that does what its node does: converts the
messages it subscribes to into the core's inputs and steps the core on its timer. The
timer grid is anchored on the first recorded output of that node (so the phase matches
the recording) and advanced in bag time: a tick at time t sees every input stamped at
or before t. At each recorded output message the adapter's latest replayed output is
compared with it, quantity by quantity; ``ReplayResult.deviations`` says which quantity
moved and by how much. ROS-free: messages are read and decoded with rosbags (field names
as in the .msg files).
"""
from __future__ import annotations

import argparse
import csv
import gc
import math
import sys
import time
from collections import defaultdict
from contextlib import contextmanager
from itertools import islice
from dataclasses import dataclass, field
from operator import itemgetter
from pathlib import Path
from typing import Any, Callable, Iterable, Iterator, Sequence

import numpy as np

from dukw_bringup.bag_fields import read_fields
from dukw_bringup.bag_io import (BagError, BagReader, deserialize, read_messages, topic_key,
                                 typestore)
from dukw_bringup.replay_adapters import ADAPTERS, CoreAdapter
from rosbags.interfaces import Connection
from rosbags.typesys.store import Typestore


@dataclass
class Deviation:
    """How far one replayed quantity moved from the recording, at its worst."""

    adapter: str
    quantity: str
    max_abs: float = 0.0
    at_s: float = math.nan
    replayed: float = math.nan
    recorded: float = math.nan
    compared: int = 0

    def describe(self) -> str:
        """One line for a failure message."""
        return (f'{self.adapter}.{self.quantity}: moved by {self.max_abs:.6g} '
                f'at t={self.at_s:.3f} s '
                f'(replayed {self.replayed:.6g}, recorded {self.recorded:.6g}; '
                f'{self.compared} samples)')


@dataclass
class ReplayResult:
    """Replayed outputs per adapter and their deviations from the recorded outputs."""

    messages: int = 0
    #: seconds through the cores (reading, decoding, stepping, comparing)
    elapsed_s: float = 0.0
    #: seconds to open the bag (parse its metadata), before any message
    open_s: float = 0.0
    #: CPU seconds of this thread over ``elapsed_s`` (wall less what other processes took)
    cpu_s: float = 0.0
    rows: dict[str, list[dict[str, float]]] = field(default_factory=dict)
    deviations: dict[str, dict[str, Deviation]] = field(default_factory=dict)

    @property
    def rate_msgs_per_s(self) -> float:
        """Bag messages processed per wall-clock second."""
        return self.messages / self.elapsed_s if self.elapsed_s > 0 else math.inf

    def exceeding(self, tolerances: dict[str, float], default: float) -> list[Deviation]:
        """Deviations above their tolerance (``tolerances`` by quantity or adapter.quantity)."""
        out = []
        for adapter, devs in self.deviations.items():
            for dev in devs.values():
                tol = tolerances.get(f'{adapter}.{dev.quantity}',
                                     tolerances.get(dev.quantity, default))
                if not dev.max_abs <= tol:  # NaN counts as exceeding
                    out.append(dev)
        return out


class _Driver:
    """Runs one adapter: timer grid in integer nanoseconds, comparisons at outputs."""

    def __init__(self, adapter: CoreAdapter, first_output_ns: int | None) -> None:
        if not adapter.rate_hz > 0.0:
            raise ValueError(f'{adapter.name}: rate_hz must be > 0')
        self.adapter = adapter
        self.period_ns = round(1e9 / adapter.rate_hz)
        self.next_tick_ns = first_output_ns
        self.latest: dict[str, float] | None = None
        self.rows: list[dict[str, float]] = []
        self.deviations: dict[str, Deviation] = {}
        #: per compared topic: (time ns, recorded message, latest replayed row) not compared
        self._pending: defaultdict[str, list[tuple[int, Any, Any]]] = defaultdict(list)

    def run_ticks_until(self, t_ns: int, inclusive: bool) -> None:
        if self.next_tick_ns is None:
            return
        while self.next_tick_ns < t_ns or (inclusive and self.next_tick_ns == t_ns):
            t_s = self.next_tick_ns * 1e-9
            out = self.adapter.tick(t_s)
            if out is not None:
                self._keep(t_s, out)
            self.next_tick_ns += self.period_ns

    def feed(self, topic: str, t_ns: int, msg: Any) -> None:
        t_s = t_ns * 1e-9
        out = self.adapter.feed(topic, t_s, msg)
        if out is not None:
            self._keep(t_s, out)

    def _keep(self, t_s: float, out: dict[str, float]) -> None:
        """An output row, stamped: the adapter's own dict (a new one per output, its
        contract), not a copy of it."""
        out['t_s'] = t_s
        self.latest = out
        self.rows.append(out)

    def compare(self, topic: str, t_ns: int, msg: Any) -> None:
        """Note a recorded output and the latest replayed one (``settle`` compares)."""
        self._pending[topic].append((t_ns, msg, self.latest))

    def settle(self) -> None:
        """Compare the outputs noted since the last call, each quantity over all of them at
        once (the adapter's ``recorded_columns``, numpy for the differences)."""
        angles = self.adapter.angle_quantities
        for topic, pending in self._pending.items():
            times_ns, msgs, replayed = zip(*pending, strict=True)
            recorded = self.adapter.recorded_columns(topic, msgs)
            if not recorded:
                continue
            mine = _replayed_columns(replayed, tuple(recorded))
            for quantity, theirs in recorded.items():
                dev = self.deviations.get(quantity)
                if dev is None:
                    dev = self.deviations[quantity] = Deviation(self.adapter.name, quantity)
                _fold(dev, times_ns, mine[quantity], theirs, quantity in angles)
        self._pending.clear()

    def finish(self) -> None:
        """Compare what is still noted."""
        self.settle()


def _replayed_columns(rows: Sequence[dict[str, float] | None], quantities: tuple[str, ...]
                      ) -> dict[str, Sequence[float]]:
    """Per quantity, its value in each replayed row (NaN where a row lacks it or is None)."""
    try:
        get = itemgetter(*quantities)
        values = [get(row) for row in rows]        # (one C call per row: the usual case)
        if len(quantities) == 1:
            values = [(v,) for v in values]
    except (KeyError, TypeError):
        values = [tuple(math.nan if row is None else row.get(q, math.nan) for q in quantities)
                  for row in rows]
    return dict(zip(quantities, zip(*values, strict=True), strict=True))


def _fold(dev: Deviation, times_ns: Sequence[int], mine: Sequence[float],
          theirs: Sequence[float], angle: bool) -> None:
    """Fold comparisons into ``dev`` as one by one in order would: |replayed - recorded|
    (both NaN: 0, one NaN: NaN; an angle modulo 2 pi), the first worst kept, NaN worst of
    all."""
    replayed, recorded = np.asarray(mine, dtype=float), np.asarray(theirs, dtype=float)
    diff = np.abs(replayed - recorded)
    diff[np.isnan(replayed) & np.isnan(recorded)] = 0.0
    if angle:
        for k in np.flatnonzero(diff > math.pi):
            diff[k] = abs(math.remainder(float(replayed[k]) - float(recorded[k]), math.tau))
    nan = np.isnan(diff)
    k = int(np.argmax(nan)) if nan.any() else int(np.argmax(diff))
    worst = float(diff[k])
    first = dev.compared == 0
    dev.compared += len(diff)
    if first or worst > dev.max_abs or (worst != worst and dev.max_abs == dev.max_abs):
        dev.max_abs, dev.at_s = worst, times_ns[k] * 1e-9
        dev.replayed, dev.recorded = float(replayed[k]), float(recorded[k])


def _first_output_ns(bag: BagReader, topics: set[str]) -> dict[str, int]:
    firsts: dict[str, int] = {}
    for message in bag.messages(topics):
        firsts.setdefault(topic_key(message.topic), message.timestamp_ns)
        if len(firsts) == len(topics):
            break
    return firsts


def replay(bag: str | Path, adapters: Sequence[CoreAdapter]) -> ReplayResult:
    """Feed the bag through ``adapters``; return replayed rows and deviations.

    ``elapsed_s`` times the messages through the cores; opening the bag (a fixed cost:
    its YAML metadata) is ``open_s``, apart.
    """
    start = time.perf_counter()
    with BagReader(bag) as reader:
        result = ReplayResult(open_s=time.perf_counter() - start)
        _replay(reader, Path(bag), adapters, result)
    return result


#: messages read, decoded and fed per batch (a long bag is never held whole)
BATCH_MESSAGES = 20_000


def _replay(reader: BagReader, bag: Path, adapters: Sequence[CoreAdapter],
            result: ReplayResult) -> None:
    drivers, wanted = _drivers(reader, bag, adapters)
    start, start_cpu = time.perf_counter(), time.thread_time()
    result.messages, last_ns = _feed_bag(reader, wanted, drivers)
    if last_ns is not None:     # every driver ticks up to the bag's last message
        for driver in drivers:
            driver.run_ticks_until(last_ns, inclusive=False)
    result.elapsed_s = time.perf_counter() - start
    result.cpu_s = time.thread_time() - start_cpu
    for driver in drivers:
        driver.finish()
        result.rows[driver.adapter.name] = driver.rows
        result.deviations[driver.adapter.name] = driver.deviations


def _drivers(reader: BagReader, bag: Path, adapters: Sequence[CoreAdapter]
             ) -> tuple[list[_Driver], set[str]]:
    """A driver per adapter, its timer anchored on its first recorded output, and the
    topics any of them reads or compares."""
    outputs = set().union(*(a.outputs for a in adapters))
    firsts = _first_output_ns(reader, outputs)
    for adapter in adapters:
        if not any(o in firsts for o in adapter.outputs):
            raise BagError(f'{bag}: no recorded {list(adapter.outputs)} to anchor the '
                           f'{adapter.name} replay on')
    drivers = [_Driver(a, min(firsts[o] for o in a.outputs if o in firsts)) for a in adapters]
    return drivers, outputs.union(*(a.inputs for a in adapters))


def _feed_bag(reader: BagReader, wanted: set[str], drivers: Sequence[_Driver]
              ) -> tuple[int, int | None]:
    """Every wanted message, batch by batch; returns (messages, the last one's time ns)."""
    count, last_ns, records = 0, None, reader.records(wanted)
    while batch := list(islice(records, BATCH_MESSAGES)):
        count, last_ns = count + len(batch), _feed_batch(batch, drivers)
    return count, last_ns


def _routes(batch: Sequence[tuple[Connection, int, bytes]], drivers: Sequence[_Driver]
            ) -> dict[int, tuple[str, list[tuple[_Driver, bool, bool, Callable[[], Any]]]]]:
    """Per connection (topic) of ``batch``, by its id: the topic's key and, for each driver
    that uses it, (driver, feeds, compares, the next of its messages as the driver reads
    them). A driver that names the fields it reads (``CoreAdapter.fields``) gets them as a
    tuple, decoded for the whole batch at once (bag_fields); one that does not gets
    rosbags' message object."""
    store = typestore()
    raws: dict[int, list[bytes]] = {}
    connections: dict[int, Connection] = {}
    for conn, _, raw in batch:
        topic_raws = raws.get(conn.id)
        if topic_raws is None:
            topic_raws = raws[conn.id] = []
            connections[conn.id] = conn
        topic_raws.append(raw)
    routes = {}
    for conn_id, topic_raws in raws.items():
        conn = connections[conn_id]
        key = topic_key(conn.topic)
        users = [d for d in drivers if key in d.adapter.inputs or key in d.adapter.outputs]
        decoded = {paths: _decoded(store, conn.msgtype, topic_raws, paths)
                   for paths in {d.adapter.fields.get(key) for d in users}}
        routes[conn_id] = (key, [(d, key in d.adapter.inputs, key in d.adapter.outputs,
                                  iter(decoded[d.adapter.fields.get(key)]).__next__)
                                 for d in users])
    return routes


def _decoded(store: Typestore, msgtype: str, raws: Sequence[bytes],
             paths: tuple[str, ...] | None) -> list[Any]:
    """Messages as a driver reads them: tuples of the fields ``paths``, or (None) rosbags'
    message objects."""
    if paths:
        return read_fields(store, msgtype, raws, paths)
    return [store.deserialize_cdr(raw, msgtype) for raw in raws]


def _feed_batch(batch: Sequence[tuple[Connection, int, bytes]], drivers: Sequence[_Driver]
                ) -> int:
    """Feed ``batch``'s messages, in order, to the drivers that use them; returns the last
    message's time, ns."""
    with _no_cycle_collection():
        return _feed_batch_in_order(batch, drivers, _routes(batch, drivers))


@contextmanager
def _no_cycle_collection() -> Iterator[None]:
    """The cyclic garbage collector paused (as it was after): the replay allocates tens of
    thousands of rows and tuples, none in a cycle (reference counting frees them), and each
    time they pass its thresholds it scans every object of the process (~170,000 with the
    stack's modules loaded), 10-20 ms a full pass, for nothing."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()


def _feed_batch_in_order(batch: Sequence[tuple[Connection, int, bytes]],
                         drivers: Sequence[_Driver], routes: dict[int, Any]) -> int:
    for conn, t_ns, _ in batch:
        key, steps = routes[conn.id]
        for driver, feeds, compares, take in steps:
            msg = take()
            # a driver's ticks run when its next message comes (the cores are independent:
            # the same ticks, in the same order with its own messages, as at every message)
            if driver.next_tick_ns is not None and driver.next_tick_ns < t_ns:
                driver.run_ticks_until(t_ns, inclusive=False)
            if feeds:
                driver.feed(key, t_ns, msg)
            if compares:
                driver.run_ticks_until(t_ns, inclusive=True)
                driver.compare(key, t_ns, msg)
    for driver in drivers:
        driver.settle()
    return batch[-1][1]


def stream(bag: str | Path, decode: bool = False,
           topics: Iterable[str] | None = None) -> tuple[int, float]:
    """Read every message (and decode it if asked); return (count, seconds)."""
    store = typestore()
    count = 0
    start = time.perf_counter()
    for message in read_messages(bag, topics):
        if decode:
            deserialize(message, store)
        count += 1
    return count, time.perf_counter() - start


def available_adapters() -> dict[str, Callable[[], CoreAdapter]]:
    """Adapter factories by name."""
    return dict(ADAPTERS)


def write_csv(rows: list[dict[str, float]], path: Path) -> None:
    """Write replayed rows (one per tick) to a CSV file."""
    if not rows:
        path.write_text('')
        return
    with path.open('w', newline='') as handle:
        names = [name for name in rows[0] if name != 't_s']
        writer = csv.DictWriter(handle, fieldnames=['t_s', *names])
        writer.writeheader()
        writer.writerows(rows)


def parse_args(argv: Sequence[str]) -> argparse.Namespace:
    """Command-line options."""
    parser = argparse.ArgumentParser(prog='replay', description=__doc__.split('\n')[0])
    parser.add_argument('bag', type=Path, help='rosbag2 folder')
    parser.add_argument('--cores', nargs='+', default=None,
                        help='adapters to run (default: every available one)')
    parser.add_argument('--stream', action='store_true',
                        help='only stream the bag (raw and decoded) and print messages/s')
    parser.add_argument('--csv', type=Path, default=None,
                        help='folder for <core>.csv with the replayed outputs')
    parser.add_argument('--tolerance', type=float, default=1e-6,
                        help='largest |replayed - recorded| accepted (default 1e-6)')
    return parser.parse_args(argv)


def main(argv: Sequence[str] | None = None) -> int:
    """Console-script entry point: 0 when every replayed output matches the recording."""
    args = parse_args(sys.argv[1:] if argv is None else argv)
    try:
        if args.stream:
            for decode in (False, True):
                count, seconds = stream(args.bag, decode)
                label = 'decoded' if decode else 'raw'
                print(f'{label:>8}: {count} messages in {seconds:.3f} s = '
                      f'{count / max(seconds, 1e-9):,.0f} messages/s')
            return 0
        factories = available_adapters()
        names = args.cores or sorted(factories)
        unknown = set(names) - set(factories)
        if unknown:
            print(f'[FATAL] replay: no adapter {sorted(unknown)}; available: '
                  f'{sorted(factories)}', file=sys.stderr)
            return 2
        result = replay(args.bag, [factories[n]() for n in names])
    except (BagError, ValueError) as exc:
        print(f'[FATAL] replay: {exc}', file=sys.stderr)
        return 2
    print(f'replayed {result.messages} messages in {result.elapsed_s:.3f} s '
          f'({result.rate_msgs_per_s:,.0f} messages/s)')
    for name, devs in result.deviations.items():
        for dev in devs.values():
            print(f'  {dev.describe()}')
        if args.csv:
            args.csv.mkdir(parents=True, exist_ok=True)
            write_csv(result.rows[name], args.csv / f'{name}.csv')
    bad = result.exceeding({}, args.tolerance)
    for dev in bad:
        print(f'[FAIL] {dev.describe()}', file=sys.stderr)
    return 1 if bad else 0


if __name__ == '__main__':
    raise SystemExit(main())
