"""sim_node's real-time factor through ROS, every sensor topic published and received.

Starts the installed sim_node as its own process (real_time_factor 0 = as fast as
possible, and the asked factors), subscribes to all its topics from this process
with the EventsExecutor (so the listener is not the bottleneck), and prints, per
run: the real-time factor achieved (sim seconds from /clock per wall second),
messages received per wall second, sim_node's CPU share and the factor per core
(achieved / CPU share: what a free core would give; on a shared, loaded machine the
achieved factor mostly measures the scheduler). Target (issue 3): >= 10x with all
sensors published. Prints figures; no pass/fail.

    python benchmarks/bench_sim_node.py [--seconds 10] [--factors 0,10,20]
    python benchmarks/bench_sim_node.py --profile-steps 3000   # cProfile of SimNode.step
                                                               # in this process (no listener)
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import rclpy
from rclpy.context import Context
from rclpy.experimental import EventsExecutor
from rclpy.node import Node

from dukw_msgs.msg import DiffCommand

from dukw_common.node_tools import COMMAND_QOS, stamp_to_s
from dukw_common.testing import NodeProcess
from dukw_sim.sim_messages import TOPICS
from figures import report

if 'ROS_DOMAIN_ID' not in os.environ:   # keep clear of a running stack and of tests
    os.environ['ROS_DOMAIN_ID'] = str(90 + os.getpid() % 10)
os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')

def cpu_seconds(pid: int) -> float:
    """User + system CPU seconds of a process (Linux /proc)."""
    fields = Path(f'/proc/{pid}/stat').read_text().rsplit(')', 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


def run(factor: float, seconds: float, executor: str) -> dict:
    """One sim_node process at ``factor``; return the figures."""
    env = {'DUKW_EXECUTOR': executor}
    proc = NodeProcess('dukw_sim', 'sim_node',
                       ['--ros-args', '-p', f'real_time_factor:={factor}'], env=env)
    context = Context()
    rclpy.init(context=context)
    node = Node('bench_sim_listener', context=context)
    counts = {topic: 0 for topic, _, _ in TOPICS}
    clock = {'t': None}

    def on_message(topic, msg):
        counts[topic] += 1
        if topic == '/clock':
            clock['t'] = stamp_to_s(msg.clock)
    for topic, kind, qos in TOPICS:
        node.create_subscription(kind, topic, lambda msg, t=topic: on_message(t, msg), qos)
    cmd = node.create_publisher(DiffCommand, 'tracks/cmd', COMMAND_QOS)
    node.create_timer(0.02, lambda: cmd.publish(DiffCommand(port_pct=50.0, stbd_pct=48.0)))
    executor_ = EventsExecutor(context=context)
    executor_.add_node(node)
    try:
        deadline = time.monotonic() + 30.0
        while clock['t'] is None and time.monotonic() < deadline:
            executor_.spin_once(timeout_sec=0.05)
        if clock['t'] is None:
            raise RuntimeError(f'no /clock from sim_node: {proc.stop() or proc.stderr}')
        warm = time.monotonic() + 2.0
        while time.monotonic() < warm:
            executor_.spin_once(timeout_sec=0.05)
        for topic in counts:
            counts[topic] = 0
        wall0, sim0, cpu0 = time.monotonic(), clock['t'], cpu_seconds(proc.proc.pid)
        while time.monotonic() < wall0 + seconds:
            executor_.spin_once(timeout_sec=0.05)
        wall = time.monotonic() - wall0
        sim, cpu = clock['t'] - sim0, cpu_seconds(proc.proc.pid) - cpu0
    finally:
        executor_.shutdown()
        node.destroy_node()
        rclpy.shutdown(context=context)
        code = proc.stop()
    return {'factor': factor, 'executor': executor, 'achieved': sim / wall,
            'msgs_per_s': sum(counts.values()) / wall, 'sim_cpu': cpu / wall,
            'per_sim_s': {t: c / sim for t, c in counts.items()} if sim > 0 else {},
            'exit': code}


def profile_steps(steps: int) -> None:
    """CPU time per SimNode.step in this process (publishing, no subscriber), then cProfile's
    top entries: where a step of the node goes besides the core and the sensors."""
    import cProfile
    import pstats

    from dukw_sim.sim_node import SimNode
    rclpy.init(args=['--ros-args', '-p', 'real_time_factor:=0.0'])
    try:
        node = SimNode()
        node.switch.command('tracks', 50.0, 48.0, 0.0)
        for _ in range(100):
            node.step()
        cpu0 = time.process_time()
        for _ in range(steps):
            node.step()
        per_step_us = (time.process_time() - cpu0) / steps * 1e6
        print(f'SimNode.step in process: {per_step_us:.1f} us CPU per step '
              f'({1e6 / per_step_us / 100:.1f}x real time per core at 100 Hz)')
        profiler = cProfile.Profile()
        profiler.enable()
        for _ in range(steps):
            node.step()
        profiler.disable()
        pstats.Stats(profiler).sort_stats('tottime').print_stats(40)
        node.destroy_node()
    finally:
        rclpy.shutdown()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--seconds', type=float, default=10.0, help='measured wall seconds')
    parser.add_argument('--factors', default='0,10,20', help='real_time_factor values')
    parser.add_argument('--executors', default='events', help='sim_node executors: events,single')
    parser.add_argument('--profile-steps', type=int, default=0,
                        help='only profile this many SimNode.step calls in this process')
    args = parser.parse_args(argv)
    if args.profile_steps > 0:
        profile_steps(args.profile_steps)
        return 0
    print(f'load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores')
    print(f'{"executor":<8} {"asked":>6} {"achieved":>9} {"msgs/s":>8} {"sim CPU":>8} '
          f'{"per core":>9}')
    results = []
    for executor in args.executors.split(','):
        for factor in (float(f) for f in args.factors.split(',')):
            r = run(factor, args.seconds, executor)
            results.append(r)
            asked = 'max' if factor == 0 else f'{factor:g}x'
            per_core = r['achieved'] / r['sim_cpu'] if r['sim_cpu'] > 0 else float('nan')
            print(f'{executor:<8} {asked:>6} {r["achieved"]:8.1f}x {r["msgs_per_s"]:8.0f} '
                  f'{100 * r["sim_cpu"]:7.0f}% {per_core:8.1f}x', flush=True)
    print('messages received per simulated second (last run):')
    for topic, rate in results[-1]['per_sim_s'].items():
        print(f'  {topic:<16} {rate:7.1f}')
    best = max(r['achieved'] for r in results)
    print(f'best real-time factor through ROS with all sensors: {best:.1f}x (target >= 10x; '
          'issue 16: >= 25x)')
    report('sim through ROS, best real-time factor', best, 'x', target=25.0, better='higher')
    print(f'load average after: {os.getloadavg()[0]:.1f}')
    return 0 if all(r['exit'] == 0 for r in results) else 1


if __name__ == '__main__':
    sys.exit(main())
