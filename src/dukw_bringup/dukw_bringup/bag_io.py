"""rosbag2 (MCAP) reading and writing without ROS: the `rosbags` library plus dukw_msgs.

The type store is rosbags' ROS 2 Jazzy store (std_msgs, sensor_msgs, geometry_msgs,
nav_msgs, diagnostic_msgs, rosgraph_msgs...) with the dukw_msgs types registered from
their installed ``.msg`` text, so the bags carry the message definitions and RIHS01
type hashes that ``ros2 bag info`` and Foxglove expect. Topic names are stored as the
ROS graph reports them (absolute, ``/tracks/cmd``); ``topic_key`` drops the slash for
matching against the relative names of the topic contract.
"""
from __future__ import annotations

import functools
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable, Iterator, NamedTuple, Sequence

from rosbags.interfaces import (Connection, Qos, QosDurability, QosHistory, QosLiveliness,
                                QosReliability, QosTime)
from rosbags.rosbag2 import CompressionFormat, CompressionMode, Reader, StoragePlugin, Writer
from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.store import Typestore

#: Topics the stack latches (transient local): a late subscriber gets the current value.
LATCHED_TOPICS = ('authority', 'drive_mode', 'tf_static', 'robot_description')
#: Environment variable pointing at a folder of dukw_msgs ``*.msg`` files (overrides lookup).
MSG_DIR_ENV = 'DUKW_MSGS_DIR'

_NEVER = QosTime(sec=0, nsec=0)


class BagError(ValueError):
    """A bag cannot be read or written as asked (missing, malformed, unknown type)."""


def topic_key(topic: str) -> str:
    """Return the topic name without its leading slash (``/tracks/cmd`` -> ``tracks/cmd``)."""
    return topic.lstrip('/')


def dukw_msg_dir() -> Path:
    """Folder holding the dukw_msgs ``.msg`` files: ``$DUKW_MSGS_DIR``, the installed share
    folder (ament index), or the source tree next to this package, in that order."""
    override = os.environ.get(MSG_DIR_ENV)
    if override:
        return Path(override)
    try:
        from ament_index_python.packages import (PackageNotFoundError,
                                                 get_package_share_directory)
        try:
            return Path(get_package_share_directory('dukw_msgs')) / 'msg'
        except PackageNotFoundError:
            pass
    except ImportError:
        pass
    return Path(__file__).resolve().parents[2] / 'dukw_msgs' / 'msg'


@functools.lru_cache(maxsize=4)
def typestore(msg_dir: str | None = None) -> Typestore:
    """rosbags type store: ROS 2 Jazzy standard types plus every dukw_msgs message."""
    folder = Path(msg_dir) if msg_dir else dukw_msg_dir()
    files = sorted(folder.glob('*.msg'))
    if not files:
        raise BagError(f'no dukw_msgs .msg files in {folder} (build the workspace or set '
                       f'{MSG_DIR_ENV})')
    store = get_typestore(Stores.ROS2_JAZZY)
    types: dict[str, Any] = {}
    for path in files:
        types.update(get_types_from_msg(path.read_text(), f'dukw_msgs/msg/{path.stem}'))
    store.register(types)
    return store


def ros_type_name(msgtype: str) -> str:
    """``pkg/msg/Name`` or ``pkg/Name`` -> ``pkg/msg/Name`` (the form rosbag2 stores)."""
    parts = msgtype.split('/')
    if len(parts) == 2:
        return f'{parts[0]}/msg/{parts[1]}'
    if len(parts) == 3 and parts[1] == 'msg':
        return msgtype
    raise BagError(f'not a message type name: {msgtype!r}')


def make_qos(*, reliable: bool = True, transient_local: bool = False,
             depth: int = 10) -> Qos:
    """A rosbag2 offered-QoS record (what the publisher offered), for a bag's metadata."""
    return Qos(history=QosHistory.KEEP_LAST, depth=depth,
               reliability=QosReliability.RELIABLE if reliable else QosReliability.BEST_EFFORT,
               durability=(QosDurability.TRANSIENT_LOCAL if transient_local
                           else QosDurability.VOLATILE),
               deadline=_NEVER, lifespan=_NEVER, liveliness=QosLiveliness.AUTOMATIC,
               liveliness_lease_duration=_NEVER, avoid_ros_namespace_conventions=False)


def default_qos(topic: str) -> Qos:
    """The offered QoS the topic contract gives ``topic`` (latched state or reliable)."""
    return make_qos(transient_local=topic_key(topic) in LATCHED_TOPICS)


class BagMessage(NamedTuple):
    """One serialized message of a bag: CDR bytes, receive time, topic and type.

    A NamedTuple, not a dataclass: it is made once per message while streaming.
    """

    topic: str
    msgtype: str
    timestamp_ns: int
    raw: bytes


@dataclass(frozen=True)
class TopicInfo:
    """A bag's topic: type, count and whether its publisher offered transient-local QoS."""

    topic: str
    msgtype: str
    count: int
    latched: bool


class BagWriter:
    """Write a rosbag2 in MCAP, topic by topic; always a readable bag once ``close``d.

    Use as a context manager, or call ``close()`` (idempotent) from a shutdown path.
    ``compress`` zstd-compresses the MCAP chunks (smaller; every MCAP reader handles it).
    """

    def __init__(self, path: str | Path, store: Typestore | None = None,
                 compress: bool = False) -> None:
        self.path = Path(path)
        self.store = store or typestore()
        self._writer = Writer(self.path, version=Writer.VERSION_LATEST,
                              storage_plugin=StoragePlugin.MCAP)
        if compress:
            self._writer.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
        self._writer.open()
        self._connections: dict[str, Connection] = {}
        self.counts: dict[str, int] = {}
        self.closed = False

    def add_topic(self, topic: str, msgtype: str, qos: Sequence[Qos] = ()) -> None:
        """Declare ``topic`` of ``msgtype``; the type must be in the type store."""
        if self.closed:
            raise BagError(f'{self.path}: bag already closed')
        if topic in self._connections:
            return
        name = ros_type_name(msgtype)
        if name not in self.store.fielddefs:
            raise BagError(f'{topic}: message type {name} unknown to the bag type store')
        self._connections[topic] = self._writer.add_connection(
            topic, name, typestore=self.store,
            offered_qos_profiles=list(qos) or [default_qos(topic)])
        self.counts[topic] = 0

    def has_topic(self, topic: str) -> bool:
        """True when ``topic`` was added."""
        return topic in self._connections

    def write(self, topic: str, timestamp_ns: int, raw: bytes | memoryview) -> None:
        """Append one serialized (CDR) message received at ``timestamp_ns``."""
        if self.closed:
            raise BagError(f'{self.path}: bag already closed')
        if topic not in self._connections:
            raise BagError(f'{topic}: add_topic() it before writing')
        self._writer.write(self._connections[topic], int(timestamp_ns), raw)
        self.counts[topic] += 1

    def write_message(self, topic: str, msgtype: str, timestamp_ns: int, msg: Any) -> None:
        """Serialize a rosbags message object and append it (adds the topic if new)."""
        self.add_topic(topic, msgtype)
        self.write(topic, timestamp_ns, self.store.serialize_cdr(msg, ros_type_name(msgtype)))

    def close(self) -> None:
        """Finish the MCAP file and write metadata.yaml; safe to call more than once."""
        if not self.closed:
            self.closed = True
            self._writer.close()

    def __enter__(self) -> 'BagWriter':
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _open_reader(path: str | Path) -> Reader:
    path = Path(path)
    if not (path / 'metadata.yaml').is_file():
        raise BagError(f'{path}: not a rosbag2 folder (no metadata.yaml)')
    reader = Reader(path)
    reader.open()
    return reader


def _latched(conn: Connection) -> bool:
    profiles = getattr(conn.ext, 'offered_qos_profiles', ()) or ()
    if profiles:
        return any(p.durability == QosDurability.TRANSIENT_LOCAL for p in profiles)
    return topic_key(conn.topic) in LATCHED_TOPICS


def read_messages(path: str | Path, topics: Iterable[str] | None = None
                  ) -> Iterator[BagMessage]:
    """Yield the bag's messages in time order, optionally only of ``topics``.

    Topic names match with or without the leading slash.
    """
    reader = _open_reader(path)
    try:
        wanted = None if topics is None else {topic_key(t) for t in topics}
        conns = [c for c in reader.connections
                 if wanted is None or topic_key(c.topic) in wanted]
        if wanted is not None and not conns:
            return
        for conn, timestamp, raw in reader.messages(connections=conns):
            yield BagMessage(conn.topic, conn.msgtype, timestamp,
                             raw if type(raw) is bytes else bytes(raw))
    finally:
        reader.close()


def deserialize(message: BagMessage, store: Typestore | None = None) -> Any:
    """Decode a message's CDR bytes into a rosbags message object (ROS field names)."""
    return (store or typestore()).deserialize_cdr(message.raw, message.msgtype)


@dataclass
class BagSummary:
    """What ``ros2 bag info`` shows: duration, message counts per topic."""

    path: Path
    start_ns: int = 0
    end_ns: int = 0
    topics: list[TopicInfo] = field(default_factory=list)

    @property
    def duration_s(self) -> float:
        """Time from the first to the last message, s."""
        return (self.end_ns - self.start_ns) * 1e-9

    @property
    def message_count(self) -> int:
        """Messages of every topic."""
        return sum(t.count for t in self.topics)

    def lines(self) -> list[str]:
        """Human-readable summary lines."""
        out = [f'bag: {self.path}', f'duration: {self.duration_s:.3f} s',
               f'messages: {self.message_count}']
        out += [f'  {t.topic:<24} {t.msgtype:<40} {t.count:>8}'
                + ('  (latched)' if t.latched else '') for t in self.topics]
        return out


def summarize(path: str | Path) -> BagSummary:
    """Duration and counts of the bag at ``path`` (from its metadata, no message reads)."""
    reader = _open_reader(path)
    try:
        # rosbags' end_time is one past the last message's time
        end_ns = max(reader.start_time, reader.end_time - 1) if reader.message_count else 0
        start_ns = reader.start_time if reader.message_count else 0
        return BagSummary(Path(path), start_ns, end_ns, sorted(
            (TopicInfo(c.topic, c.msgtype, c.msgcount, _latched(c))
             for c in reader.connections), key=lambda t: t.topic))
    finally:
        reader.close()
