"""Figures of a running stack, without ROS: CPU time of a process, sensor-to-command latency
(from the trace benchmarks/latency_trace records in each process).

Used by benchmarks/bench_stack.py (which explains the pairing in full).
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

CLOCK_TICKS = os.sysconf('SC_CLK_TCK')
#: a sensor message no command followed within this long counts as lost, s
PAIR_WINDOW_S = 0.1


def cpu_seconds(pid: int) -> float:
    """utime + stime of a process from /proc/<pid>/stat, s (NaN once it is gone)."""
    try:
        fields = Path(f'/proc/{pid}/stat').read_text().rsplit(')', 1)[1].split()
    except OSError:
        return float('nan')
    return (int(fields[11]) + int(fields[12])) / CLOCK_TICKS


def thread_cpu_seconds(pid: int, prefix: str = 'dds.') -> float:
    """utime + stime of a process's threads whose name starts with ``prefix``, s (Fast DDS
    names its transport and event threads dds.*; the rest of a node's CPU is its executor's
    thread: taking, converting and handling the messages). NaN once the process is gone."""
    total = 0
    try:
        tasks = list(Path(f'/proc/{pid}/task').iterdir())
    except OSError:
        return float('nan')
    for task in tasks:
        try:
            stat = (task / 'stat').read_text()
        except OSError:                      # the thread ended meanwhile
            continue
        name, rest = stat.split('(', 1)[1].rsplit(')', 1)
        if name.startswith(prefix):
            fields = rest.split()
            total += int(fields[11]) + int(fields[12])
    return total / CLOCK_TICKS


@dataclass(frozen=True)
class ChainLatency:
    """Sensor sample -> actuator command, one entry per sample that led to a command, s;
    split into the sensor's delivery to the chain, the chain's work up to the command's
    publish call, and the command's publish and delivery to the actuator."""

    total_s: np.ndarray
    sensor_delivery_s: np.ndarray
    in_chain_s: np.ndarray
    command_delivery_s: np.ndarray
    lost: int


def chain_latencies(traces: Mapping[int, Sequence[tuple]],
                    actuator_takes: Sequence[tuple[int, int]],
                    window_ns: tuple[int, int], sensor: str = '/imu/data',
                    command: str = '/tracks/cmd',
                    pair_window_s: float = PAIR_WINDOW_S) -> ChainLatency:
    """Latency of each ``sensor`` sample published in ``window_ns`` to the first ``command``
    it caused, as taken at the actuator (``actuator_takes``: (monotonic ns, stamp_ns)).

    ``traces``: process -> events ``(kind, topic, stamp_ns, start_ns, end_ns, cause)`` as
    benchmarks/latency_trace records them (kind 'pub' or 'take'; ``cause`` the (topic,
    stamp_ns) of the callback a publish ran in). A command is traced back through the
    causes (e.g. tracks/cmd <- odometry/filtered <- imu/data) to its sample; each command
    publish is paired with the first unpaired actuator take at or after its start that has
    its stamp. A sample with no command taken within ``pair_window_s`` counts as lost.
    """
    causes, sensor_start, takes, commands = {}, {}, {}, []
    for process, events in traces.items():
        for kind, topic, stamp, start, _end, cause in events:
            if kind == 'take':
                takes[(process, topic, stamp)] = start
            elif topic == command:
                commands.append((start, stamp, process, cause))
            else:
                causes[(topic, stamp)] = (process, cause)
                if topic == sensor:
                    sensor_start[stamp] = start
    rows: dict[int, tuple[int, int, int, int]] = {}
    for start, take, process, cause in _received(sorted(commands, key=lambda c: c[0]),
                                                         actuator_takes):
        origin = _origin(process, cause, causes, sensor)
        if origin is None or origin[1] in rows or origin[1] not in sensor_start:
            continue
        first_take = takes.get((origin[0], sensor, origin[1]))
        if first_take is not None:
            rows[origin[1]] = (sensor_start[origin[1]], first_take, start, take)
    window = [s for s, t in sensor_start.items() if window_ns[0] <= t <= window_ns[1]]
    kept = np.array([rows[s] for s in window if s in rows
                     and rows[s][3] - rows[s][0] <= pair_window_s * 1e9],
                    dtype=float).reshape(-1, 4) * 1e-9
    return ChainLatency(kept[:, 3] - kept[:, 0], kept[:, 1] - kept[:, 0],
                        kept[:, 2] - kept[:, 1], kept[:, 3] - kept[:, 2],
                        len(window) - len(kept))


def _received(commands: list, actuator_takes: Sequence[tuple[int, int]], lookahead: int = 4):
    """(publish start, actuator take, process, cause) of each command the actuator took: the
    first take not yet paired, at or after the publish, with the command's stamp."""
    takes = sorted(actuator_takes)
    times = np.array([t for t, _ in takes], dtype=np.int64)
    used = -1
    for start, stamp, process, cause in commands:
        first = max(int(np.searchsorted(times, start)), used + 1)
        for j in range(first, min(first + lookahead, len(takes))):
            if takes[j][1] == stamp:
                used = j
                yield start, takes[j][0], process, cause
                break


def _origin(process, cause, causes: dict, sensor: str, max_hops: int = 8):
    """(process that took the sensor sample, its stamp_ns) a publish's cause leads back to."""
    for _ in range(max_hops):
        if cause is None:
            return None
        if cause[0] == sensor:
            return process, cause[1]
        process, cause = causes.get(cause, (process, None))
    return None
