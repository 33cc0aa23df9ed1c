"""The replay's CDR decoders (dukw_bringup.cdr_decode) against rosbags', bit for bit.

Every message of every golden bag, and messages built here to reach what the golden bags
do not hold (frame ids of every length, so every alignment after a string; non-empty
string and float sequences), must decode to the same classes, the same values (floats
compared by their bytes, NaN included) and the same numpy arrays as
``Typestore.deserialize_cdr``; broken bytes must raise rosbags' SerdeError.
"""
import math
import struct
from pathlib import Path

import numpy as np
import pytest
from rosbags.serde import SerdeError

from dukw_bringup import bag_io
from dukw_bringup.cdr_decode import _compile, decoder

GOLDEN = Path(__file__).parent / 'golden'


def _same(mine, theirs, where='msg') -> None:
    assert type(mine) is type(theirs), where
    if isinstance(theirs, float):
        assert struct.pack('<d', mine) == struct.pack('<d', theirs), where
    elif isinstance(theirs, np.ndarray):
        assert (mine.dtype, mine.shape, mine.flags.writeable) == \
            (theirs.dtype, theirs.shape, theirs.flags.writeable), where
        assert mine.tobytes() == theirs.tobytes(), where
    elif hasattr(theirs, '__dataclass_fields__'):
        for name in theirs.__dataclass_fields__:
            _same(getattr(mine, name), getattr(theirs, name), f'{where}.{name}')
    elif isinstance(theirs, list):
        assert len(mine) == len(theirs), where
        for k, (a, b) in enumerate(zip(mine, theirs, strict=True)):
            _same(a, b, f'{where}[{k}]')
    else:
        assert mine == theirs, where


@pytest.mark.parametrize('bag', sorted(p.name for p in GOLDEN.iterdir()))
def test_every_golden_message_decodes_as_rosbags_decodes_it(bag):
    store = bag_io.typestore()
    decoders, count = {}, 0
    with bag_io.BagReader(GOLDEN / bag) as reader:
        for message in reader.messages():
            decode = decoders.get(message.msgtype)
            if decode is None:
                decode = decoders[message.msgtype] = decoder(store, message.msgtype)
            _same(decode(message.raw), store.deserialize_cdr(message.raw, message.msgtype),
                  message.topic)
            count += 1
    assert count > 1000
    # the hot types are decoded here, not handed back to rosbags
    for msgtype in ('sensor_msgs/msg/Imu', 'nav_msgs/msg/Odometry', 'dukw_msgs/msg/Traction',
                    'dukw_msgs/msg/DiffCommand', 'dukw_msgs/msg/DrivetrainStatus'):
        assert msgtype in decoders and _compile(store, msgtype) is not None, msgtype


def _imu(store, frame_id: str):
    t = store.types
    cov = np.arange(9, dtype=np.float64) - 1.5
    return t['sensor_msgs/msg/Imu'](
        header=t['std_msgs/msg/Header'](stamp=t['builtin_interfaces/msg/Time'](sec=-3,
                                                                              nanosec=7),
                                        frame_id=frame_id),
        orientation=t['geometry_msgs/msg/Quaternion'](x=0.1, y=-0.0, z=math.nan, w=1.0),
        orientation_covariance=cov, angular_velocity=t['geometry_msgs/msg/Vector3'](
            x=1e-300, y=math.inf, z=-2.0), angular_velocity_covariance=cov * 2,
        linear_acceleration=t['geometry_msgs/msg/Vector3'](x=9.81, y=0.0, z=-1.0),
        linear_acceleration_covariance=cov * 3)


@pytest.mark.parametrize('frame_id', ['', 'a', 'ab', 'abc', 'abcd', 'abcde', 'abcdef',
                                      'abcdefg', 'base_link', 'é_unicode'])
def test_every_alignment_after_a_string(frame_id):
    store = bag_io.typestore()
    raw = bytes(store.serialize_cdr(_imu(store, frame_id), 'sensor_msgs/msg/Imu'))
    _same(decoder(store, 'sensor_msgs/msg/Imu')(raw),
          store.deserialize_cdr(raw, 'sensor_msgs/msg/Imu'))


@pytest.mark.parametrize('faults', [[], ['OVERHEAT'], ['A', 'STALL', '']])
def test_string_and_float_sequences(faults):
    store = bag_io.typestore()
    t = store.types
    header = t['std_msgs/msg/Header'](stamp=t['builtin_interfaces/msg/Time'](sec=1, nanosec=2),
                                      frame_id='x')
    side = t['dukw_msgs/msg/MotorSide'](command_pct=1.0, current_a=2.0, voltage_v=3.0,
                                        speed_mps=4.0, force_n=5.0, temperature_c=math.nan,
                                        fault_flags=513, faults=faults)
    status = t['dukw_msgs/msg/DrivetrainStatus'](header=header, drive=1, connected=True,
                                                 port=side, stbd=side)
    joints = t['sensor_msgs/msg/JointState'](header=header, name=faults,
                                             position=np.arange(len(faults), dtype=np.float64),
                                             velocity=np.zeros(0), effort=np.ones(2))
    for msg, msgtype in ((status, 'dukw_msgs/msg/DrivetrainStatus'),
                         (joints, 'sensor_msgs/msg/JointState')):
        raw = bytes(store.serialize_cdr(msg, msgtype))
        assert _compile(store, msgtype) is not None
        _same(decoder(store, msgtype)(raw), store.deserialize_cdr(raw, msgtype))


def test_broken_bytes_raise_rosbags_error():
    store = bag_io.typestore()
    raw = bytes(store.serialize_cdr(_imu(store, 'base_link'), 'sensor_msgs/msg/Imu'))
    decode = decoder(store, 'sensor_msgs/msg/Imu')
    for broken in (raw[:40], raw + bytes(16), b'\x07\x07' + raw[2:], raw[:12]):
        with pytest.raises(SerdeError):
            store.deserialize_cdr(broken, 'sensor_msgs/msg/Imu')
        with pytest.raises(SerdeError):
            decode(broken)
