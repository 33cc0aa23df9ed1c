"""record: write chosen or all topics, as serialized messages, to a rosbag2 in MCAP.

    record --out runs/x/bag --all
    record --out bag tracks/cmd traction drive_mode

Topics are found on the ROS graph and re-scanned every ``--rescan`` seconds, so late
publishers are caught. Each subscription matches what the publishers offer: reliable
only if every publisher is reliable, transient local when they all are (so the latched
``authority`` and ``drive_mode`` values arrive). Ctrl-C / SIGTERM closes the bag
cleanly: an interrupted recording is a readable bag. ``Recorder`` does the same
inside another program's node (the main job).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Sequence

from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.utilities import remove_ros_args

from rosbags.interfaces import (Qos, QosDurability, QosHistory, QosLiveliness, QosReliability,
                                QosTime)

from dukw_bringup.bag_io import BagError, BagWriter, topic_key, typestore
from dukw_common.config import ConfigError
from dukw_common.node_tools import check_params_files, run_node

#: Never recorded unless named explicitly: ROS's own chatter.
IGNORED_BY_DEFAULT = ('/rosout', '/parameter_events')
#: History depth of each recording subscription (absorbs bursts between spins).
RECORD_DEPTH = 1000


class Recorder:
    """Record topics of ``node``'s graph into a new MCAP bag at ``out_dir``.

    ``topics`` None records every topic (except /rosout, /parameter_events); names may be
    relative. Call ``close()`` (idempotent) to finish the bag; the node must be spun by
    the caller for messages to arrive.
    """

    def __init__(self, node: Node, out_dir: str | Path, topics: Sequence[str] | None = None,
                 rescan_period_s: float = 0.5) -> None:
        if rescan_period_s <= 0.0:
            raise ValueError(f'rescan_period_s must be > 0, got {rescan_period_s}')
        self.node = node
        self.store = typestore()
        self.writer = BagWriter(out_dir, self.store)
        self.wanted = None if topics is None else {topic_key(t) for t in topics}
        self._subscriptions: dict[str, object] = {}
        self._skipped: set[str] = set()
        self._timer = node.create_timer(rescan_period_s, self.scan)
        self.scan()

    @property
    def path(self) -> Path:
        """The bag folder."""
        return self.writer.path

    @property
    def counts(self) -> dict[str, int]:
        """Messages written so far, per topic."""
        return dict(self.writer.counts)

    def _wants(self, topic: str) -> bool:
        if self.wanted is None:
            return topic not in IGNORED_BY_DEFAULT
        return topic_key(topic) in self.wanted

    def scan(self) -> None:
        """Subscribe to every wanted topic that has appeared since the last scan."""
        if self.writer.closed:
            return
        self.writer.flush_if_due()        # a quiet topic's last messages reach the file too
        for topic, types in self.node.get_topic_names_and_types():
            if topic in self._subscriptions or topic in self._skipped or not self._wants(topic):
                continue
            msgtype = types[0]
            if len(types) > 1 or msgtype not in self.store.fielddefs:
                self.node.get_logger().warning(
                    f'not recording {topic}: type {types} unknown or ambiguous')
                self._skipped.add(topic)
                continue
            publishers = self.node.get_publishers_info_by_topic(topic)
            if not publishers:
                continue  # only subscribers so far: wait for a publisher to learn its QoS
            self._subscribe(topic, msgtype, [p.qos_profile for p in publishers])

    def _subscribe(self, topic: str, msgtype: str, offered: list[QoSProfile]) -> None:
        qos = matching_qos(offered, RECORD_DEPTH)
        self.writer.add_topic(topic, msgtype, [offered_qos(q) for q in offered])
        cls = message_class(msgtype)
        self._subscriptions[topic] = self.node.create_subscription(
            cls, topic, lambda raw, t=topic: self._on_message(t, raw), qos, raw=True)

    def _on_message(self, topic: str, raw: bytes) -> None:
        if not self.writer.closed:
            self.writer.write(topic, self.node.get_clock().now().nanoseconds, raw)

    def close(self) -> None:
        """Stop recording and finish the bag (readable afterwards)."""
        if self.writer.closed:
            return
        self._timer.cancel()
        self.node.destroy_timer(self._timer)
        for subscription in self._subscriptions.values():
            self.node.destroy_subscription(subscription)
        self._subscriptions.clear()
        self.writer.close()


def offered_qos(profile: QoSProfile) -> Qos:
    """A publisher's offered QoS as the graph reports it, every field kept, for the bag
    (DDS discovery does not carry history and depth: they stay as reported, as rosbag2's)."""
    def span(duration) -> QosTime:
        sec, nsec = divmod(int(duration.nanoseconds), 1_000_000_000)
        return QosTime(sec=sec, nsec=nsec)
    return Qos(history=QosHistory(int(profile.history)), depth=int(profile.depth),
               reliability=QosReliability(int(profile.reliability)),
               durability=QosDurability(int(profile.durability)),
               deadline=span(profile.deadline), lifespan=span(profile.lifespan),
               liveliness=QosLiveliness(int(profile.liveliness)),
               liveliness_lease_duration=span(profile.liveliness_lease_duration),
               avoid_ros_namespace_conventions=bool(profile.avoid_ros_namespace_conventions))


def matching_qos(offered: list[QoSProfile], depth: int) -> QoSProfile:
    """A subscription that matches every publisher: reliable only if all are, transient
    local when all are (so latched values arrive)."""
    reliable = all(q.reliability == ReliabilityPolicy.RELIABLE for q in offered)
    latched = all(q.durability == DurabilityPolicy.TRANSIENT_LOCAL for q in offered)
    return QoSProfile(
        history=HistoryPolicy.KEEP_LAST, depth=depth,
        reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE)


def message_class(msgtype: str):
    """The rclpy message class for ``pkg/msg/Name``."""
    import importlib
    package, _, name = msgtype.split('/')
    return getattr(importlib.import_module(f'{package}.msg'), name)


class RecordNode(Node):
    """A node that only records (the ``record`` command)."""

    def __init__(self, out_dir: Path, topics: Sequence[str] | None,
                 rescan_period_s: float) -> None:
        super().__init__('recorder')
        self.recorder = Recorder(self, out_dir, topics, rescan_period_s)
        self.get_logger().info(f'recording to {out_dir}')

    def on_shutdown(self) -> None:
        """Close the bag before the context goes down."""
        self.recorder.close()
        counts = self.recorder.counts
        print(f'recorded {sum(counts.values())} messages on {len(counts)} topics')
        for topic, count in sorted(counts.items()):
            print(f'  {topic:<24} {count:>8}')
        print(self.recorder.path, flush=True)


def parse_args(argv: Sequence[str]) -> argparse.Namespace:
    """Command-line options (ROS arguments already removed)."""
    parser = argparse.ArgumentParser(prog='record', description=__doc__.split('\n')[0])
    parser.add_argument('topics', nargs='*', help='topics to record (relative names work)')
    parser.add_argument('--out', '-o', required=True, type=Path,
                        help='bag folder to create (must not exist)')
    parser.add_argument('--topics', dest='topics_opt', nargs='+', default=[],
                        help='topics to record (same as the positional list)')
    parser.add_argument('--all', '-a', action='store_true', help='record every topic')
    parser.add_argument('--rescan', type=float, default=0.5,
                        help='seconds between graph scans for new topics (default 0.5)')
    args = parser.parse_args(argv)
    args.topics = [*args.topics, *args.topics_opt]
    if not args.all and not args.topics:
        parser.error('name topics to record or pass --all')
    if args.rescan <= 0.0:
        parser.error('--rescan must be > 0')
    return args


def main(argv: Sequence[str] | None = None) -> int:
    """Console-script entry point."""
    argv = list(sys.argv if argv is None else argv)
    try:
        check_params_files(argv)
    except ConfigError as exc:
        print(f'[FATAL] record: {exc}', file=sys.stderr)
        return 2
    args = parse_args(remove_ros_args(argv)[1:])
    if args.out.exists():
        print(f'[FATAL] record: {args.out} exists already; give a new folder', file=sys.stderr)
        return 2
    try:
        typestore()
    except BagError as exc:
        print(f'[FATAL] record: {exc}', file=sys.stderr)
        return 2
    topics = None if args.all else args.topics
    return run_node(lambda: RecordNode(args.out, topics, args.rescan), argv)


if __name__ == '__main__':
    raise SystemExit(main())
