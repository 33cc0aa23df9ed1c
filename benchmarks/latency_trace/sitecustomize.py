"""Latency trace of the stack's processes for benchmarks/bench_stack.py (benchmark only).

bench_stack starts the stack with this folder first on PYTHONPATH and
DUKW_LATENCY_TRACE=DIR; Python then runs this module in every process before the node
code. It wraps rclpy's ``Publisher.publish`` and the callbacks of subscriptions to the
chain's topics (``TRACED``) and notes, with time.monotonic_ns (one clock for every process
on the machine):

    ('pub',  topic, stamp_ns, start_ns, end_ns, cause)   a publish call
    ('take', topic, stamp_ns, start_ns, end_ns, None)    a callback (executor take to done)

``cause`` is (topic, stamp_ns) of the traced callback the publish happened in (None on a
timer): that is how a command is traced back to the sensor sample that led to it. At
exit the records go to DIR/<pid>.pickle. The nodes' behaviour is unchanged; the cost is a
few microseconds a traced message. Without DUKW_LATENCY_TRACE nothing is wrapped.
"""
import os

TRACE_DIR = os.environ.get('DUKW_LATENCY_TRACE')
#: topics of the control chain (sensor -> estimate -> command), fully qualified
TRACED = frozenset(('/imu/data', '/odometry/filtered', '/tracks/cmd', '/props/cmd'))


def _install(trace_dir: str) -> None:
    import atexit
    import pickle
    import time

    from rclpy.node import Node
    from rclpy.publisher import Publisher

    records: list = []
    cause: list = [None]
    topics: dict[int, str] = {}          # publisher -> its topic (a C call otherwise)
    clock = time.monotonic_ns
    publish, create_subscription = Publisher.publish, Node.create_subscription

    def stamp_ns(msg) -> int:
        stamp = msg.header.stamp
        return stamp.sec * 1_000_000_000 + stamp.nanosec

    def traced_publish(self, msg) -> None:
        topic = topics.get(id(self))
        if topic is None:
            topic = topics[id(self)] = self.topic_name
        if topic not in TRACED:
            return publish(self, msg)
        start = clock()
        publish(self, msg)
        records.append(('pub', topic, stamp_ns(msg), start, clock(), cause[0]))

    def traced_create_subscription(self, msg_type, topic, callback, *args, **kwargs):
        name = topic if topic.startswith('/') else '/' + topic
        if name not in TRACED:
            return create_subscription(self, msg_type, topic, callback, *args, **kwargs)

        def traced_callback(msg) -> None:
            start, stamp, outer = clock(), stamp_ns(msg), cause[0]
            cause[0] = (name, stamp)
            try:
                callback(msg)
            finally:
                cause[0] = outer
            records.append(('take', name, stamp, start, clock(), None))
        return create_subscription(self, msg_type, topic, traced_callback, *args, **kwargs)

    def dump() -> None:
        with open(os.path.join(trace_dir, f'{os.getpid()}.pickle'), 'wb') as out:
            pickle.dump(records, out)

    Publisher.publish = traced_publish
    Node.create_subscription = traced_create_subscription
    atexit.register(dump)


if TRACE_DIR:
    try:
        _install(TRACE_DIR)
    except ImportError:      # a Python without rclpy (e.g. a build tool): nothing to trace
        pass
