"""Benchmark: the composed chain's own path, IMU message in -> tracks/cmd published, in-process.

bench_stack measures sensor -> command across processes on the shared machine, where the
other processes' scheduling swamps the composed process's own fraction of a millisecond.
This builds the composed chain (dukw_bringup.compose: ekf_node, mode_manager_node,
drive_controller_node, real rclpy nodes and publishers, one process) and hands it a golden
bag's messages through its own subscriptions' callbacks, in bag order. For each IMU message
it times, on the thread's CPU clock (preemption by other processes does not count) and on
the wall clock, from the callback's entry to the return of the tracks/cmd publication, and
to the end of the callback (the observers' topics, published after the command).
The nodes run on the wall clock, so the bag's stamped inputs (cmd_vel, authority) are stale
to them and the controller steps to neutral: its mixing (~10 us) is not in the figure.

    python benchmarks/bench_compose_path.py [--bag land_to_sea] [--repeat 3]
"""
from __future__ import annotations

import argparse
import os
import time
from importlib import import_module
from pathlib import Path

import numpy as np
import rclpy
from rclpy.serialization import deserialize_message

from dukw_bringup import bag_io, compose
from dukw_common.config import default_config_path
from figures import report
from profile_text import profile_to_text

GOLDEN = Path(__file__).resolve().parents[1] / 'tests' / 'golden'
CHAIN = ['ekf_node', 'mode_manager_node', 'drive_controller_node']


def get_message(msgtype: str) -> type:
    """``pkg/msg/Name`` -> the rclpy message class."""
    package, _, name = msgtype.split('/')
    return getattr(import_module(f'{package}.msg'), name)


def callbacks(nodes) -> dict[str, object]:
    """Subscribed topic key -> the process's callback for it."""
    return {sub.topic_name.lstrip('/'): sub.callback
            for node in nodes for sub in node.subscriptions}


def feed(bag: Path, nodes) -> dict[str, np.ndarray]:
    """Hand the bag's inputs to the chain; per IMU message the CPU and wall times, s."""
    routes = callbacks(nodes)
    controller = nodes[-1]
    tracks = controller.commands.tracks
    publish = tracks.publish
    out: dict[str, float] = {}

    def timed_publish(msg) -> None:
        publish(msg)
        out.setdefault('cpu', time.thread_time_ns())
        out.setdefault('wall', time.perf_counter_ns())
    tracks.publish = timed_publish
    times: dict[str, list[float]] = {k: [] for k in ('cpu_cmd', 'wall_cmd', 'cpu_all')}
    with bag_io.BagReader(bag) as reader:
        messages = [(bag_io.topic_key(m.topic), m) for m in reader.messages(routes)]
    types: dict[str, type] = {}
    for key, message in messages:
        kind = types.setdefault(message.msgtype, get_message(message.msgtype))
        msg = deserialize_message(message.raw, kind)
        out.clear()
        cpu0, wall0 = time.thread_time_ns(), time.perf_counter_ns()
        routes[key](msg)
        cpu1 = time.thread_time_ns()
        if key == 'imu/data' and 'cpu' in out:
            times['cpu_cmd'].append((out['cpu'] - cpu0) * 1e-9)
            times['wall_cmd'].append((out['wall'] - wall0) * 1e-9)
            times['cpu_all'].append((cpu1 - cpu0) * 1e-9)
    tracks.publish = publish
    return {k: np.array(v) for k, v in times.items()}


def one_pass(bag: Path, profile: str | None = None) -> dict[str, np.ndarray]:
    """A fresh composed chain fed the whole bag (the feeding cProfiled to ``profile``)."""
    nodes = compose.build(CHAIN)
    try:
        if profile:
            return profile_to_text(lambda: feed(bag, nodes), profile, PROFILE_HEADER)
        return feed(bag, nodes)
    finally:
        for node in reversed(nodes):
            node.destroy_node()


PROFILE_HEADER = """cProfile of the composed chain's path (a golden bag through its callbacks):
  python benchmarks/bench_compose_path.py --profile benchmarks/profiles/compose_path.txt
The command goes out before the observers' work: in the IMU callback the EKF step and
odometry(), the controller's step and tracks/cmd + props/cmd; only then the traction
read (Estimate.traction, lazy), the filled Odometry's publication, /tf and traction.
rclpy publish (C: serialisation + Fast DDS write) is the largest single item; the EKF's
add_imu the largest Python one."""


def main() -> None:
    """Print the path's percentiles."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--bag', default='land_to_sea', help='golden bag (tests/golden)')
    parser.add_argument('--repeat', type=int, default=3, help='passes over the bag')
    parser.add_argument('--profile', default=None,
                        help='cProfile the passes, statistics as text to this file')
    args = parser.parse_args()
    rclpy.init(args=['--ros-args', '--params-file', str(default_config_path()),
                     '-p', 'traction_rate_hz:=20.0',    # as config/stack_sim_composed.yaml
                     '--log-level', 'error'])           # (stale-input warnings)
    try:
        runs = [one_pass(GOLDEN / args.bag, args.profile if k == 0 else None)
                for k in range(args.repeat)]
    finally:
        rclpy.try_shutdown()
    times = {k: np.concatenate([r[k] for r in runs]) * 1e3 for k in runs[0]}
    load = ' '.join(f'{x:.2f}' for x in os.getloadavg())
    print(f'composed path, {args.bag} x{args.repeat}: {len(times["cpu_cmd"])} IMU messages '
          f'that led to a command; load average {load}')
    for key, label in (('cpu_cmd', 'IMU callback -> tracks/cmd out, CPU '),
                       ('wall_cmd', 'IMU callback -> tracks/cmd out, wall'),
                       ('cpu_all', 'whole IMU callback (observers too), CPU')):
        p50, p99 = np.percentile(times[key], [50, 99])
        print(f'  {label}: p50 {p50:.3f} ms  p99 {p99:.3f} ms')
    p50 = float(np.percentile(times['cpu_cmd'], 50))
    report('composed path imu->command CPU p50', p50, 'ms')


if __name__ == '__main__':
    main()
