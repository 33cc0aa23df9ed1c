"""bag_io: MCAP bags with dukw_msgs types, written and read back without ROS."""
import json
from pathlib import Path

import pytest

from dukw_bringup import bag_io
from dukw_bringup.bag_io import BagError, BagWriter, read_messages, summarize


def _traction(store, seq: int, slip: float):
    types = store.types
    header = types['std_msgs/msg/Header'](
        stamp=types['builtin_interfaces/msg/Time'](sec=seq, nanosec=0), frame_id='base_link')
    values = {name: 0.0 for name in types['dukw_msgs/msg/Traction'].__dataclass_fields__
              if name not in ('header', 'afloat', '__msgtype__')}
    values['port_slip'] = slip
    return types['dukw_msgs/msg/Traction'](header=header, afloat=False, **values)


def test_type_hashes_match_the_built_interfaces():
    # rosbags computes RIHS01 hashes from the .msg text; they must equal rosidl's, or
    # ros2 bag and Foxglove would reject the bag's types.
    store = bag_io.typestore()
    jsons = sorted(bag_io.dukw_msg_dir().glob('*.json'))
    assert len(jsons) >= 10
    for path in jsons:
        expected = {h['type_name']: h['hash_string']
                    for h in json.loads(path.read_text())['type_hashes']}
        name = f'dukw_msgs/msg/{path.stem}'
        assert store.hash_rihs01(name) == expected[name], name


def test_messages_come_back_in_time_order_with_their_bytes(tmp_path):
    store = bag_io.typestore()
    with BagWriter(tmp_path / 'bag') as writer:
        writer.add_topic('/traction', 'dukw_msgs/Traction')
        writer.add_topic('/drive_mode', 'dukw_msgs/msg/DriveMode')
        mode = store.types['dukw_msgs/msg/DriveMode'](
            header=_traction(store, 0, 0.0).header, mode=2, automatic=True, track_weight=0.0,
            prop_weight=1.0, tracks_idle=True, reason='afloat')
        writer.write_message('/drive_mode', 'dukw_msgs/msg/DriveMode', 25, mode)
        for seq in range(5):
            writer.write_message('/traction', 'dukw_msgs/msg/Traction', seq * 10,
                                 _traction(store, seq, 0.1 * seq))
    messages = list(read_messages(tmp_path / 'bag'))
    assert [m.timestamp_ns for m in messages] == [0, 10, 20, 25, 30, 40]
    assert messages[3].topic == '/drive_mode'
    assert bag_io.deserialize(messages[3]).reason == 'afloat'
    slips = [bag_io.deserialize(m).port_slip for m in messages if m.topic == '/traction']
    assert slips == pytest.approx([0.0, 0.1, 0.2, 0.3, 0.4])
    summary = summarize(tmp_path / 'bag')
    assert summary.message_count == 6
    assert summary.duration_s == pytest.approx(40e-9)
    latched = {t.topic: t.latched for t in summary.topics}
    assert latched == {'/drive_mode': True, '/traction': False}


def test_topic_filter_accepts_relative_names(tmp_path):
    with BagWriter(tmp_path / 'bag') as writer:
        for topic in ('/a', '/b'):
            writer.add_topic(topic, 'std_msgs/msg/String')
            writer.write_message(topic, 'std_msgs/msg/String', 1,
                                 writer.store.types['std_msgs/msg/String'](data=topic))
    assert [m.topic for m in read_messages(tmp_path / 'bag', ['b'])] == ['/b']
    assert list(read_messages(tmp_path / 'bag', ['nothing'])) == []


def test_cdr_is_what_rclpy_reads(tmp_path):
    rclpy_serialization = pytest.importorskip('rclpy.serialization')
    from dukw_msgs.msg import Traction
    store = bag_io.typestore()
    with BagWriter(tmp_path / 'bag') as writer:
        writer.write_message('/traction', 'dukw_msgs/msg/Traction', 1,
                             _traction(store, 7, 0.25))
    raw = next(read_messages(tmp_path / 'bag')).raw
    msg = rclpy_serialization.deserialize_message(raw, Traction)
    assert (msg.header.stamp.sec, msg.port_slip, msg.header.frame_id) == (7, 0.25, 'base_link')


def test_bad_input_is_refused(tmp_path):
    with BagWriter(tmp_path / 'bag') as writer:
        with pytest.raises(BagError, match='unknown'):
            writer.add_topic('/x', 'nope_msgs/msg/Nothing')
        with pytest.raises(BagError, match='add_topic'):
            writer.write('/never_added', 1, b'')
        with pytest.raises(BagError, match='type name'):
            writer.add_topic('/x', 'Nothing')
    with pytest.raises(BagError, match='closed'):
        writer.write('/x', 1, b'')
    with pytest.raises(Exception, match='exists'):
        BagWriter(tmp_path / 'bag')
    with pytest.raises(BagError, match='metadata.yaml'):
        list(read_messages(tmp_path / 'not_a_bag'))


def test_missing_message_definitions_are_named(tmp_path, monkeypatch):
    monkeypatch.setenv(bag_io.MSG_DIR_ENV, str(tmp_path))
    bag_io.typestore.cache_clear()
    try:
        with pytest.raises(BagError, match=str(tmp_path)):
            bag_io.typestore()
    finally:
        monkeypatch.delenv(bag_io.MSG_DIR_ENV)
        bag_io.typestore.cache_clear()
    assert Path(bag_io.dukw_msg_dir(), 'Traction.msg').is_file()


def test_mcap_carries_what_foxglove_and_ros2_bag_need(tmp_path):
    # An independent reader (the mcap library): ros2 profile, cdr channels, and schemas
    # with the full ros2msg definition, nested types included.
    from mcap.reader import make_reader
    store = bag_io.typestore()
    with BagWriter(tmp_path / 'bag', compress=True) as writer:
        writer.write_message('/traction', 'dukw_msgs/msg/Traction', 1, _traction(store, 1, 0.5))
    with open(tmp_path / 'bag' / 'bag.mcap', 'rb') as handle:
        reader = make_reader(handle)
        assert reader.get_header().profile == 'ros2'
        summary = reader.get_summary()
        (channel,) = summary.channels.values()
        schema = summary.schemas[channel.schema_id]
        assert (channel.topic, channel.message_encoding) == ('/traction', 'cdr')
        assert (schema.name, schema.encoding) == ('dukw_msgs/msg/Traction', 'ros2msg')
        text = schema.data.decode()
        assert 'float64 weight_on_tracks_fraction' in text and 'MSG: std_msgs/Header' in text
        (message,) = [m for _, _, m in reader.iter_messages()]
    assert bag_io.typestore().deserialize_cdr(message.data, 'dukw_msgs/msg/Traction'
                                              ).port_slip == 0.5


def test_a_bag_whose_writer_died_is_readable_after_recovery(tmp_path):
    import shutil
    store = bag_io.typestore()
    writer = BagWriter(tmp_path / 'live', flush_period_s=3600.0)
    assert (tmp_path / 'live' / 'metadata.yaml').is_file()          # written at once
    writer.add_topic('/traction', 'dukw_msgs/Traction',
                     [bag_io.make_qos(reliable=False, depth=5)])
    for seq in range(4):
        writer.write_message('/traction', 'dukw_msgs/msg/Traction', seq * 10,
                             _traction(store, seq, 0.1 * seq))
    writer.flush()                                                  # what a crash leaves
    writer.write_message('/traction', 'dukw_msgs/msg/Traction', 40, _traction(store, 4, 0.4))
    with pytest.raises(BagError, match='still being recorded'):
        summarize(tmp_path / 'live')                               # live: left alone
    shutil.copytree(tmp_path / 'live', tmp_path / 'crashed')       # the folder at the kill
    writer.close()
    assert summarize(tmp_path / 'crashed').message_count == 4      # recovered on open
    messages = list(read_messages(tmp_path / 'crashed'))
    assert [m.timestamp_ns for m in messages] == [0, 10, 20, 30]
    assert bag_io.deserialize(messages[3]).port_slip == pytest.approx(0.3)
    assert [p.name for p in (tmp_path / 'crashed').glob('*.truncated')] == ['live.mcap.truncated']
    assert not summarize(tmp_path / 'crashed').topics[0].latched


def test_a_bag_killed_before_its_first_flush_has_no_messages_but_opens(tmp_path):
    import shutil
    writer = BagWriter(tmp_path / 'live')
    writer.add_topic('/traction', 'dukw_msgs/Traction')
    shutil.copytree(tmp_path / 'live', tmp_path / 'crashed')
    writer.close()
    assert summarize(tmp_path / 'crashed').message_count == 0
