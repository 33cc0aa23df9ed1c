"""Every topic of the ROS graph onto Foxglove WebSocket channels, as raw CDR.

Like ``record`` (graph re-scanned for late publishers, QoS matched to the publishers),
but each message goes to a foxglove-sdk Channel with the ``ros2msg`` schema of its type
(full definitions from the rosbags type store, as in the bags), so Foxglove decodes every
ROS message itself: /tf and /tf_static for the 3D panel, NavSatFix for the map, any field
for plots. A WebSocket client has no transient local: the last message of each latched
topic (/tf_static, robot_description, authority, drive_mode) is logged again every
``relog_latched()``, so a viewer that connects late still gets them.

Like foxglove_bridge, a topic is subscribed on the ROS graph only while a Foxglove client
subscribes to its channel (``SubscriberDemand``, picked up at the next ``scan``), except the
latched ones (kept for late viewers) and the tapped ones: with no viewer connected the view
costs the stack no per-message work on its 100 Hz topics.
"""
from __future__ import annotations

import threading
from typing import Callable

import foxglove
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy
from rclpy.serialization import deserialize_message

from dukw_bringup.bag_io import typestore
from dukw_bringup.record import IGNORED_BY_DEFAULT, matching_qos, message_class

#: History depth of each forwarding subscription.
FORWARD_DEPTH = 100


class SubscriberDemand:
    """The topics Foxglove clients subscribe to (a foxglove ``ServerListener``: its callbacks
    run on the server's thread, ``topics()`` on the executor's)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._clients: dict[str, int] = {}

    def on_subscribe(self, client, channel) -> None:
        """A client subscribed to ``channel``."""
        with self._lock:
            self._clients[channel.topic] = self._clients.get(channel.topic, 0) + 1

    def on_unsubscribe(self, client, channel) -> None:
        """A client unsubscribed from ``channel`` (or disconnected)."""
        with self._lock:
            left = self._clients.get(channel.topic, 0) - 1
            if left > 0:
                self._clients[channel.topic] = left
            else:
                self._clients.pop(channel.topic, None)

    def topics(self) -> set[str]:
        """The topics at least one client subscribes to now."""
        with self._lock:
            return set(self._clients)


class GraphForwarder:
    """Forward every topic of ``node``'s graph to Foxglove channels (call ``scan``).

    ``taps``: topic -> callback that also gets the topic's messages, decoded from the same
    subscription (one subscription per topic). ``demand``: subscribe a topic only while a
    client wants it (None: every topic, always).
    """

    def __init__(self, node: Node,
                 taps: dict[str, Callable[[object], None]] | None = None,
                 demand: SubscriberDemand | None = None) -> None:
        self.node = node
        self.taps = dict(taps or {})
        self.demand = demand
        self.store = typestore()
        self.channels: dict[str, foxglove.Channel] = {}
        self.latched: dict[str, bytes] = {}
        self._routes: dict[str, tuple[str, object, bool]] = {}   # topic: type, QoS, latched
        self._subscriptions: dict[str, object] = {}
        self._skipped: set[str] = set()

    def _now_ns(self) -> int:
        return self.node.get_clock().now().nanoseconds

    def scan(self) -> None:
        """Advertise every topic that has appeared since the last scan, and subscribe or
        unsubscribe the topics as the clients' demand changed."""
        for topic, types in self.node.get_topic_names_and_types():
            if topic in self._routes or topic in self._skipped \
                    or topic in IGNORED_BY_DEFAULT:
                continue
            if len(types) > 1 or types[0] not in self.store.fielddefs:
                self.node.get_logger().warning(f'not forwarding {topic}: type {types}')
                self._skipped.add(topic)
                continue
            offered = [p.qos_profile for p in self.node.get_publishers_info_by_topic(topic)]
            if offered:
                self._advertise(topic, types[0], offered)
        self._follow_demand()

    def _advertise(self, topic: str, msgtype: str, offered: list) -> None:
        definition, _ = self.store.generate_msgdef(msgtype, ros_version=2)
        schema = foxglove.Schema(name=msgtype, encoding='ros2msg', data=definition.encode())
        self.channels[topic] = foxglove.Channel(topic, schema=schema, message_encoding='cdr')
        qos = matching_qos(offered, FORWARD_DEPTH)
        self._routes[topic] = (msgtype, qos, qos.durability == DurabilityPolicy.TRANSIENT_LOCAL)

    def _follow_demand(self) -> None:
        wanted = None if self.demand is None else self.demand.topics()
        for topic, (msgtype, qos, latched) in self._routes.items():
            needed = wanted is None or latched or topic in self.taps or topic in wanted
            if needed and topic not in self._subscriptions:
                self._subscribe(topic, msgtype, qos, latched)
            elif not needed and topic in self._subscriptions:
                self.node.destroy_subscription(self._subscriptions.pop(topic))

    def _subscribe(self, topic: str, msgtype: str, qos, latched: bool) -> None:
        channel = self.channels[topic]
        cls, tap = message_class(msgtype), self.taps.get(topic)

        def on_message(raw: bytes) -> None:
            channel.log(raw, log_time=self._now_ns())
            if latched:
                self.latched[topic] = raw
            if tap is not None:
                tap(deserialize_message(raw, cls))
        self._subscriptions[topic] = self.node.create_subscription(
            cls, topic, on_message, qos, raw=True)

    def relog_latched(self) -> None:
        """Log the last message of each latched topic again (for late viewers)."""
        now = self._now_ns()
        for topic, raw in self.latched.items():
            self.channels[topic].log(raw, log_time=now)
