"""Every topic of the ROS graph onto Foxglove WebSocket channels, as raw CDR.

Like ``record`` (graph re-scanned for late publishers, QoS matched to the publishers),
but each message goes to a foxglove-sdk Channel with the ``ros2msg`` schema of its type
(full definitions from the rosbags type store, as in the bags), so Foxglove decodes every
ROS message itself: /tf and /tf_static for the 3D panel, NavSatFix for the map, any field
for plots. A WebSocket client has no transient local: the last message of each latched
topic (/tf_static, robot_description, authority, drive_mode) is logged again every
``relog_latched()``, so a viewer that connects late still gets them.
"""
from __future__ import annotations

from typing import Callable

import foxglove
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy
from rclpy.serialization import deserialize_message

from dukw_bringup.bag_io import typestore
from dukw_bringup.record import IGNORED_BY_DEFAULT, matching_qos, message_class

#: History depth of each forwarding subscription.
FORWARD_DEPTH = 100


class GraphForwarder:
    """Forward every topic of ``node``'s graph to Foxglove channels (call ``scan``).

    ``taps``: topic -> callback that also gets the topic's messages, decoded from the same
    subscription (one subscription per topic).
    """

    def __init__(self, node: Node,
                 taps: dict[str, Callable[[object], None]] | None = None) -> None:
        self.node = node
        self.taps = dict(taps or {})
        self.store = typestore()
        self.channels: dict[str, foxglove.Channel] = {}
        self.latched: dict[str, bytes] = {}
        self._subscriptions: dict[str, object] = {}
        self._skipped: set[str] = set()

    def _now_ns(self) -> int:
        return self.node.get_clock().now().nanoseconds

    def scan(self) -> None:
        """Forward every topic that has appeared since the last scan."""
        for topic, types in self.node.get_topic_names_and_types():
            if topic in self._subscriptions or topic in self._skipped \
                    or topic in IGNORED_BY_DEFAULT:
                continue
            if len(types) > 1 or types[0] not in self.store.fielddefs:
                self.node.get_logger().warning(f'not forwarding {topic}: type {types}')
                self._skipped.add(topic)
                continue
            offered = [p.qos_profile for p in self.node.get_publishers_info_by_topic(topic)]
            if offered:
                self._forward(topic, types[0], offered)

    def _forward(self, topic: str, msgtype: str, offered: list) -> None:
        definition, _ = self.store.generate_msgdef(msgtype, ros_version=2)
        schema = foxglove.Schema(name=msgtype, encoding='ros2msg', data=definition.encode())
        channel = foxglove.Channel(topic, schema=schema, message_encoding='cdr')
        self.channels[topic] = channel
        qos = matching_qos(offered, FORWARD_DEPTH)
        latched = qos.durability == DurabilityPolicy.TRANSIENT_LOCAL
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
