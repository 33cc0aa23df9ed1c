"""play: publish a bag's messages in time order at a rate factor, as they were recorded.

    play BAG [--rate 2.0] [--clock] [--topics tracks/cmd ...]
         [--wait-for-subscribers N | --wait-for TOPIC ...] [--wait-timeout 10]

Starts paused until the subscribers have matched (the rosbag2 lesson: messages sent
before discovery are lost), then publishes the raw CDR bytes with reliable keep-all
QoS (transient local for latched topics), retries a publish that fails with RCLError,
and waits for every message to be acknowledged before it exits. Unless the caller set
one, a Fast DDS profile with a 50 ms heartbeat period is used: with the defaults, burst
replays stalled for 3 or 6 s (shared docs, platform.md).
"""
from __future__ import annotations

import argparse
import os
import signal
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Sequence

import rclpy
from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions
from rclpy.utilities import remove_ros_args

from dukw_bringup.bag_io import BagError, read_messages, summarize, topic_key

#: Fast DDS writer profile: heartbeats every 50 ms so a lost sample is repaired at once.
FASTDDS_PROFILE_XML = """<?xml version="1.0" encoding="UTF-8" ?>
<profiles xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <data_writer profile_name="dukw_play_writer" is_default_profile="true">
    <times>
      <heartbeatPeriod><sec>0</sec><nanosec>50000000</nanosec></heartbeatPeriod>
    </times>
  </data_writer>
</profiles>
"""
PROFILE_ENV = 'FASTRTPS_DEFAULT_PROFILES_FILE'
#: Publish attempts before a message counts as failed.
PUBLISH_ATTEMPTS = 5


def use_fastdds_profile() -> str:
    """Point Fast DDS at the 50 ms heartbeat profile unless a profile is already set.

    Must run before ``rclpy.init``. Returns the profile file in use.
    """
    if os.environ.get(PROFILE_ENV):
        return os.environ[PROFILE_ENV]
    path = Path(tempfile.gettempdir()) / 'dukw_play_fastdds.xml'
    if not path.exists() or path.read_text() != FASTDDS_PROFILE_XML:
        tmp = path.with_suffix(f'.{os.getpid()}.tmp')
        tmp.write_text(FASTDDS_PROFILE_XML)
        tmp.replace(path)
    os.environ[PROFILE_ENV] = str(path)
    return str(path)


def publisher_qos(latched: bool) -> QoSProfile:
    """Reliable keep-all; transient local for latched topics."""
    return QoSProfile(history=HistoryPolicy.KEEP_ALL, depth=1,
                      reliability=ReliabilityPolicy.RELIABLE,
                      durability=(DurabilityPolicy.TRANSIENT_LOCAL if latched
                                  else DurabilityPolicy.VOLATILE))


@dataclass
class PlayResult:
    """What a play did."""

    published: int = 0
    failed: int = 0
    unacked_topics: tuple[str, ...] = ()
    elapsed_s: float = 0.0
    stopped: bool = False


class Player:
    """Publish the messages of ``bag`` from ``node``, in time order at ``rate`` x real time."""

    def __init__(self, node: Node, bag: str | Path, rate: float = 1.0,
                 topics: Sequence[str] | None = None, publish_clock: bool = False,
                 clock_hz: float = 100.0) -> None:
        if not rate > 0.0:
            raise ValueError(f'rate must be > 0, got {rate}')
        if not clock_hz > 0.0:
            raise ValueError(f'clock_hz must be > 0, got {clock_hz}')
        self.node = node
        self.bag = Path(bag)
        self.rate = rate
        self.clock_period_ns = int(1e9 / clock_hz)
        summary = summarize(self.bag)
        wanted = None if topics is None else {topic_key(t) for t in topics}
        self.topics = [t for t in summary.topics if wanted is None or topic_key(t.topic) in wanted]
        if wanted is not None:
            missing = wanted - {topic_key(t.topic) for t in self.topics}
            if missing:
                raise BagError(f'{self.bag}: no topic(s) {sorted(missing)} in the bag')
        from dukw_bringup.record import message_class
        self.publishers = {
            t.topic: node.create_publisher(message_class(t.msgtype), t.topic,
                                           publisher_qos(t.latched))
            for t in self.topics}
        self.clock_publisher = None
        if publish_clock:
            from rosgraph_msgs.msg import Clock
            self.clock_publisher = node.create_publisher(Clock, '/clock', publisher_qos(False))

    def matched(self) -> dict[str, int]:
        """Matched subscriptions per played topic (and /clock if published), now."""
        pubs = dict(self.publishers)
        if self.clock_publisher is not None:
            pubs['/clock'] = self.clock_publisher
        return {topic: pub.get_subscription_count() for topic, pub in pubs.items()}

    def wait_for_subscribers(self, total: int = 0, topics: Sequence[str] = (),
                             timeout_s: float = 10.0,
                             stop: threading.Event | None = None) -> bool:
        """Wait until ``total`` subscriptions over all topics have matched and each of
        ``topics`` (bag topics or /clock) has at least one; False on timeout (or stop)."""
        keys = {topic_key(t) for t in topics}
        unknown = keys - {topic_key(t) for t in self.matched()}
        if unknown:
            raise BagError(f'cannot wait for {sorted(unknown)}: not played from this bag')

        def ready() -> bool:
            counts = {topic_key(t): n for t, n in self.matched().items()}
            return sum(counts.values()) >= total and all(counts[k] > 0 for k in keys)

        deadline = time.monotonic() + timeout_s
        stop = stop or threading.Event()
        while not ready():
            if time.monotonic() > deadline or stop.is_set():
                return False
            stop.wait(0.02)
        return True

    def _publish(self, publisher, raw: bytes) -> bool:
        from rclpy._rclpy_pybind11 import RCLError
        for attempt in range(PUBLISH_ATTEMPTS):
            try:
                publisher.publish(raw)
                return True
            except RCLError as exc:
                if attempt == PUBLISH_ATTEMPTS - 1:
                    self.node.get_logger().error(f'publish failed {PUBLISH_ATTEMPTS}x: {exc}')
                time.sleep(0.001 * (attempt + 1))
        return False

    def _publish_clock(self, t_ns: int) -> None:
        from rclpy.serialization import serialize_message
        from rosgraph_msgs.msg import Clock
        from builtin_interfaces.msg import Time
        clock = Clock(clock=Time(sec=t_ns // 1_000_000_000, nanosec=t_ns % 1_000_000_000))
        self._publish(self.clock_publisher, serialize_message(clock))

    def play(self, stop: threading.Event | None = None, ack_timeout_s: float = 10.0,
             on_message: Callable[[int], None] | None = None) -> PlayResult:
        """Publish every message at its time (scaled by the rate), then wait for acks."""
        stop = stop or threading.Event()
        result = PlayResult()
        start = time.monotonic()
        first_ns = None
        last_clock_ns = None
        for message in read_messages(self.bag, [t.topic for t in self.topics]):
            if stop.is_set():
                result.stopped = True
                break
            if first_ns is None:
                first_ns = message.timestamp_ns
            due = start + (message.timestamp_ns - first_ns) * 1e-9 / self.rate
            delay = due - time.monotonic()
            if delay > 0.0 and stop.wait(delay):
                result.stopped = True
                break
            if self.clock_publisher is not None and (
                    last_clock_ns is None
                    or message.timestamp_ns - last_clock_ns >= self.clock_period_ns):
                self._publish_clock(message.timestamp_ns)
                last_clock_ns = message.timestamp_ns
            if self._publish(self.publishers[message.topic], message.raw):
                result.published += 1
            else:
                result.failed += 1
            if on_message is not None:
                on_message(result.published)
        timeout = Duration(seconds=ack_timeout_s)
        pubs = dict(self.publishers)
        if self.clock_publisher is not None:
            pubs['/clock'] = self.clock_publisher
        result.unacked_topics = tuple(sorted(
            topic for topic, pub in pubs.items() if not pub.wait_for_all_acked(timeout)))
        result.elapsed_s = time.monotonic() - start
        return result


def parse_args(argv: Sequence[str]) -> argparse.Namespace:
    """Command-line options (ROS arguments already removed)."""
    parser = argparse.ArgumentParser(prog='play', description=__doc__.split('\n')[0])
    parser.add_argument('bag', type=Path, help='rosbag2 folder')
    parser.add_argument('--rate', '-r', type=float, default=1.0,
                        help='rate factor: 2.0 plays twice as fast (default 1.0)')
    parser.add_argument('--topics', nargs='+', default=None, help='play only these topics')
    parser.add_argument('--clock', action='store_true', help='publish the bag time on /clock')
    parser.add_argument('--clock-hz', type=float, default=100.0,
                        help='/clock rate in bag time, Hz (default 100)')
    parser.add_argument('--wait-for-subscribers', type=int, default=0, metavar='N',
                        help='start once N subscriptions over all topics have matched')
    parser.add_argument('--wait-for', nargs='+', default=[], metavar='TOPIC',
                        help='start once each of these topics has a subscriber')
    parser.add_argument('--wait-timeout', type=float, default=10.0,
                        help='seconds to wait for subscribers before giving up (default 10)')
    parser.add_argument('--start-anyway', action='store_true',
                        help='play even if the subscribers did not match in time')
    parser.add_argument('--ack-timeout', type=float, default=10.0,
                        help='seconds to wait for acknowledgements at the end (default 10)')
    args = parser.parse_args(argv)
    for name in ('rate', 'clock_hz'):
        if not getattr(args, name) > 0.0:
            parser.error(f'--{name.replace("_", "-")} must be > 0')
    if args.wait_for_subscribers < 0 or args.wait_timeout < 0 or args.ack_timeout < 0:
        parser.error('counts and timeouts must be >= 0')
    return args


def main(argv: Sequence[str] | None = None) -> int:
    """Console-script entry point: 0 when every message went out and was acknowledged."""
    argv = list(sys.argv if argv is None else argv)
    args = parse_args(remove_ros_args(argv)[1:])
    use_fastdds_profile()
    rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
    stop = threading.Event()
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda *_: stop.set())
    node = Node('player')
    try:
        try:
            player = Player(node, args.bag, args.rate, args.topics, args.clock, args.clock_hz)
        except (BagError, ValueError) as exc:
            print(f'[FATAL] play: {exc}', file=sys.stderr)
            return 2
        if args.wait_for_subscribers or args.wait_for:
            if not player.wait_for_subscribers(args.wait_for_subscribers, args.wait_for,
                                               args.wait_timeout, stop):
                print(f'[WARN] play: subscribers not matched after {args.wait_timeout} s: '
                      f'{player.matched()}', file=sys.stderr)
                if not args.start_anyway or stop.is_set():
                    return 1
        result = player.play(stop, args.ack_timeout)
        print(f'published {result.published} messages in {result.elapsed_s:.2f} s'
              f' ({result.failed} failed)' + (', stopped' if result.stopped else ''))
        if result.unacked_topics:
            print(f'[WARN] play: not acknowledged in time: {", ".join(result.unacked_topics)}',
                  file=sys.stderr)
        return 0 if not (result.failed or result.unacked_topics) else 1
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    raise SystemExit(main())
