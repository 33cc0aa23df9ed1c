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
import shutil
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable, Iterator, NamedTuple, Sequence

from rosbags.interfaces import (Connection, Qos, QosDurability, QosHistory, QosLiveliness,
                                QosReliability, QosTime)
from rosbags.rosbag2 import CompressionFormat, CompressionMode, Reader, StoragePlugin, Writer
from rosbags.rosbag2.errors import ReaderError
from rosbags.rosbag2.metadata import dump_qos_v8, dump_qos_v9, parse_qos
from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.store import Typestore

#: Topics the stack latches (transient local): a late subscriber gets the current value.
LATCHED_TOPICS = ('authority', 'drive_mode', 'tf_static', 'robot_description')
#: Environment variable pointing at a folder of dukw_msgs ``*.msg`` files (overrides lookup).
MSG_DIR_ENV = 'DUKW_MSGS_DIR'

_NEVER = QosTime(sec=0, nsec=0)
#: A live bag's pending MCAP chunk is written out (and metadata.yaml refreshed) this often,
#: so a recorder killed mid-run loses at most this much (issue 17).
FLUSH_PERIOD_S = 1.0
_MCAP_MAGIC = b'\x89MCAP0\r\n'
#: Held (flock) by a live BagWriter: a bag with it held is being recorded, not broken.
WRITER_LOCK = '.writing.lock'


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
    Crash-safe: metadata.yaml is written at once and, with the pending chunk, at least
    every ``flush_period_s`` of writing, so a writer killed mid-run leaves a bag that
    ``ros2 bag info`` reads and that ``recover_bag`` (called by this module's readers)
    turns into a complete one.
    """

    def __init__(self, path: str | Path, store: Typestore | None = None,
                 compress: bool = False, flush_period_s: float | None = FLUSH_PERIOD_S) -> None:
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
        self.flush_period_s = flush_period_s
        self._flushed_s = time.monotonic()
        self._lock = _hold_writer_lock(self.path)   # released by the OS if the writer dies
        if flush_period_s is not None:
            self._write_metadata()

    def flush(self) -> None:
        """Write the pending chunk to the file and refresh metadata.yaml."""
        storage = self._writer.storage
        if self.closed or storage is None:
            return
        if storage.chunk.msgs:
            storage.close_chunk()
        storage.bio.flush()
        self._write_metadata()
        self._flushed_s = time.monotonic()

    def flush_if_due(self) -> None:
        """``flush`` when ``flush_period_s`` has passed since the last one."""
        if self.flush_period_s is not None and \
                time.monotonic() - self._flushed_s >= self.flush_period_s:
            self.flush()

    def _write_metadata(self) -> None:
        """metadata.yaml as rosbags writes it on close, for the messages so far."""
        import yaml
        w = self._writer
        count = sum(w.counts.values())
        start = w.min_timestamp if count else 0
        duration = max(0, w.max_timestamp - w.min_timestamp) if count else 0
        dump_qos = dump_qos_v9 if w.version >= 9 else dump_qos_v8
        name = f'{self.path.name}.mcap'
        info = {
            'version': w.version, 'storage_identifier': 'mcap', 'relative_file_paths': [name],
            'duration': {'nanoseconds': duration},
            'starting_time': {'nanoseconds_since_epoch': start}, 'message_count': count,
            'topics_with_message_count': [
                {'topic_metadata': {'name': c.topic, 'type': c.msgtype,
                                    'serialization_format': c.ext.serialization_format,
                                    'offered_qos_profiles': dump_qos(c.ext.offered_qos_profiles),
                                    'type_description_hash': c.digest},
                 'message_count': w.counts[c.id]} for c in w.connections],
            'compression_format': '', 'compression_mode': '',
            'files': [{'path': name, 'starting_time': {'nanoseconds_since_epoch': start},
                       'duration': {'nanoseconds': duration}, 'message_count': count}],
            'custom_data': None, 'ros_distro': 'rosbags'}
        tmp = self.path / 'metadata.yaml.tmp'
        tmp.write_text(yaml.safe_dump({'rosbag2_bagfile_information': info},
                                      default_flow_style=False))
        tmp.replace(self.path / 'metadata.yaml')

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
        self.flush_if_due()

    def write_message(self, topic: str, msgtype: str, timestamp_ns: int, msg: Any) -> None:
        """Serialize a rosbags message object and append it (adds the topic if new)."""
        self.add_topic(topic, msgtype)
        self.write(topic, timestamp_ns, self.store.serialize_cdr(msg, ros_type_name(msgtype)))

    def close(self) -> None:
        """Finish the MCAP file and write metadata.yaml; safe to call more than once."""
        if not self.closed:
            self.closed = True
            self._writer.close()
            self._lock.close()
            (self.path / WRITER_LOCK).unlink(missing_ok=True)

    def __enter__(self) -> 'BagWriter':
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _hold_writer_lock(path: Path):
    import fcntl
    handle = (path / WRITER_LOCK).open('w')
    fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
    return handle


def being_written(path: str | Path) -> bool:
    """True while a live BagWriter holds the bag (its lock dies with its process)."""
    import fcntl
    lock = Path(path) / WRITER_LOCK
    if not lock.is_file():
        return False
    with lock.open('a') as handle:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            return True
        fcntl.flock(handle, fcntl.LOCK_UN)
    return False


def _open_reader(path: str | Path) -> Reader:
    path = Path(path)
    if being_written(path):
        raise BagError(f'{path}: still being recorded; open it once the recorder stopped')
    if unfinished_mcap(path) is not None:
        count = recover_bag(path)
        print(f'[bag_io] {path}: its writer died; recovered {count} messages (the file as '
              'found is kept as *.mcap.truncated)', file=sys.stderr)
    if not (path / 'metadata.yaml').is_file():
        raise BagError(f'{path}: not a rosbag2 folder (no metadata.yaml)')
    reader = Reader(path)
    try:
        reader.open()
    except ReaderError as exc:
        raise BagError(f'{path}: {exc}') from exc
    return reader


def unfinished_mcap(path: str | Path) -> Path | None:
    """The bag folder's MCAP file if its writer never finished it (no footer), else None."""
    files = sorted(Path(path).glob('*.mcap'))
    if len(files) != 1 or files[0].stat().st_size < 2 * len(_MCAP_MAGIC):
        return files[0] if len(files) == 1 else None
    with files[0].open('rb') as f:
        f.seek(-len(_MCAP_MAGIC), os.SEEK_END)
        return None if f.read() == _MCAP_MAGIC else files[0]


def recover_bag(path: str | Path) -> int:
    """Rebuild a bag whose writer died from the complete records of its MCAP (the schemas,
    channels with their offered QoS, and messages up to the first cut record); the file
    as found is kept beside it as ``*.mcap.truncated``. Returns the messages recovered."""
    from mcap.records import Channel, Message, Schema
    from mcap.stream_reader import StreamReader
    path = Path(path)
    source = unfinished_mcap(path)
    if source is None:
        raise BagError(f'{path}: no unfinished MCAP file to recover')
    schemas, channels, messages = {}, {}, []
    with source.open('rb') as f:
        try:
            for record in StreamReader(f).records:
                if isinstance(record, Schema):
                    schemas[record.id] = record.name
                elif isinstance(record, Channel):
                    channels[record.id] = record
                elif isinstance(record, Message):
                    messages.append(record)
        except Exception:  # noqa: BLE001 -- the cut record at the crash: keep what came before
            pass
    scratch = path.parent / f'.{path.name}.recovering'
    shutil.rmtree(scratch, ignore_errors=True)
    scratch.mkdir()
    with BagWriter(scratch / path.name, flush_period_s=None) as writer:
        topics = {}
        for cid, channel in channels.items():
            qos = parse_qos(channel.metadata.get('offered_qos_profiles', ''))
            writer.add_topic(channel.topic, schemas[channel.schema_id], qos)
            topics[cid] = channel.topic
        for message in messages:
            writer.write(topics[message.channel_id], message.log_time, message.data)
    source.rename(source.with_name(source.name + '.truncated'))
    (path / WRITER_LOCK).unlink(missing_ok=True)
    for name in (f'{path.name}.mcap', 'metadata.yaml'):
        (scratch / path.name / name).replace(path / name)
    shutil.rmtree(scratch)
    return len(messages)


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
    with BagReader(path) as bag:
        yield from bag.messages(topics)


class BagReader:
    """An open bag read several times (e.g. a first pass, then a full one) for one open:
    opening parses metadata.yaml and every topic's QoS YAML, which costs more than
    thousands of messages. A context manager; ``messages`` as ``read_messages``."""

    def __init__(self, path: str | Path) -> None:
        self.reader = _open_reader(path)
        self._open = True

    def __enter__(self) -> 'BagReader':
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Close the bag (idempotent)."""
        if self._open:
            self._open = False
            self.reader.close()

    def messages(self, topics: Iterable[str] | None = None) -> Iterator[BagMessage]:
        """The bag's messages in time order, optionally only of ``topics``."""
        for conn, timestamp, raw in self.records(topics):
            yield BagMessage(conn.topic, conn.msgtype, timestamp,
                             raw if type(raw) is bytes else bytes(raw))

    def records(self, topics: Iterable[str] | None = None
                ) -> Iterator[tuple[Connection, int, bytes | memoryview]]:
        """rosbags' own (connection, receive time ns, CDR bytes) in time order, optionally
        only of ``topics``: ``messages`` without a BagMessage made per message (the replay
        groups them by connection)."""
        wanted = None if topics is None else {topic_key(t) for t in topics}
        conns = [c for c in self.reader.connections
                 if wanted is None or topic_key(c.topic) in wanted]
        if wanted is not None and not conns:
            return iter(())
        return self.reader.messages(connections=conns)


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
