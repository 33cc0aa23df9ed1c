"""bag_fields: chosen fields of many CDR messages at once, as rosbags decodes each one."""
from operator import attrgetter
from pathlib import Path

import numpy as np
import pytest
from rosbags.interfaces import Nodetype

from dukw_bringup import bag_fields, bag_io

GOLDEN = Path(__file__).resolve().parents[3] / 'tests' / 'golden' / 'land_to_sea'


def _numeric_paths(store, msgtype: str, prefix: str = ''):
    """Every number and fixed numeric array of ``msgtype``, as dotted paths."""
    for name, (kind, detail) in store.get_msgdef(msgtype).fields:
        if kind == Nodetype.NAME:
            yield from _numeric_paths(store, detail, f'{prefix}{name}.')
        elif kind == Nodetype.BASE and detail[0] != 'string':
            yield prefix + name
        elif kind == Nodetype.ARRAY and detail[0][0] == Nodetype.BASE \
                and detail[0][1][0] != 'string':
            yield prefix + name


def _as_rosbags_reads(store, msgtype, raws, paths):
    get = attrgetter(*paths)
    return [get(store.deserialize_cdr(raw, msgtype)) for raw in raws]


def _same(mine, theirs) -> bool:
    """Equal values of equal Python types (NaN equal to NaN); arrays element by element."""
    if isinstance(theirs, np.ndarray):
        return list(mine) == theirs.tolist()
    same_value = mine == theirs or (mine != mine and theirs != theirs)
    return same_value and type(mine) is type(theirs)


def _golden_topics():
    store = bag_io.typestore()
    topics: dict[tuple[str, str], list[bytes]] = {}
    for message in bag_io.read_messages(GOLDEN):
        topics.setdefault((message.topic, message.msgtype), []).append(message.raw)
    return store, topics


def test_every_number_of_every_golden_topic_reads_as_rosbags_decodes_it():
    store, topics = _golden_topics()
    viewed = 0
    for (topic, msgtype), raws in topics.items():
        paths = tuple(_numeric_paths(store, msgtype))
        if len(paths) < 2:
            continue
        rows = bag_fields.read_fields(store, msgtype, raws, paths)
        expected = _as_rosbags_reads(store, msgtype, raws, paths)
        assert len(rows) == len(expected), topic
        for row, their_row in zip(rows, expected, strict=True):
            assert all(_same(a, b) for a, b in zip(row, their_row, strict=True)), topic
        viewed += bag_fields._columns(store, msgtype, raws, paths) is not None
    assert viewed >= 10     # the numpy view, not only rosbags, was what got compared


def _odometry(frame_id: str, child: str, x_m: float) -> bytes:
    """A nav_msgs/Odometry as rclpy serializes it."""
    from nav_msgs.msg import Odometry
    from rclpy.serialization import serialize_message
    msg = Odometry()
    msg.header.frame_id, msg.child_frame_id = frame_id, child
    msg.pose.pose.position.x = x_m
    msg.twist.covariance[35] = x_m * 2.0
    return serialize_message(msg)


def test_messages_of_other_layouts_are_read_one_by_one_with_the_same_values():
    # the same size, but the strings' lengths traded: the numbers sit elsewhere
    store = bag_io.typestore()
    raws = [_odometry('odom', 'base_link', 1.5), _odometry('odom_', 'base_lin', 2.5)]
    assert len(raws[0]) == len(raws[1])
    paths = ('pose.pose.position.x', 'twist.covariance')
    assert bag_fields._columns(store, 'nav_msgs/msg/Odometry', raws, paths) is None
    rows = bag_fields.read_fields(store, 'nav_msgs/msg/Odometry', raws, paths)
    assert [row[0] for row in rows] == [1.5, 2.5]
    assert [row[1][35] for row in rows] == [3.0, 5.0]


def _drive_status(faults: list[str], current_a: float) -> bytes:
    """A dukw_msgs/DrivetrainStatus as rclpy serializes it."""
    from dukw_msgs.msg import DrivetrainStatus
    from rclpy.serialization import serialize_message
    msg = DrivetrainStatus()
    msg.port.current_a, msg.port.faults = current_a, faults
    msg.stbd.temperature_c = -current_a
    return serialize_message(msg)


def test_empty_string_sequences_read_as_empty_lists_and_any_other_as_rosbags_does():
    store = bag_io.typestore()
    paths = ('port.current_a', 'port.faults', 'stbd.temperature_c')
    empty = [_drive_status([], 1.0), _drive_status([], 2.0)]
    assert bag_fields._columns(store, 'dukw_msgs/msg/DrivetrainStatus', empty, paths)
    assert bag_fields.read_fields(store, 'dukw_msgs/msg/DrivetrainStatus', empty, paths) == [
        (1.0, [], -1.0), (2.0, [], -2.0)]
    mixed = [*empty, _drive_status(['overcurrent'], 3.0)]
    assert bag_fields.read_fields(store, 'dukw_msgs/msg/DrivetrainStatus', mixed, paths) == [
        (1.0, [], -1.0), (2.0, [], -2.0), (3.0, ['overcurrent'], -3.0)]


def test_a_field_the_type_does_not_have_is_refused():
    store = bag_io.typestore()
    raws = [_odometry('odom', 'base_link', 1.0)]
    with pytest.raises(ValueError, match='pose.pose.position.q'):
        bag_fields.read_fields(store, 'nav_msgs/msg/Odometry', raws, ('pose.pose.position.q',))
    assert bag_fields.read_fields(store, 'nav_msgs/msg/Odometry', [], ('child_frame_id',)) == []
