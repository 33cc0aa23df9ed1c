"""The hardware drivers and sim_node publish the same topics with the same types (issue 4).

The four driver nodes (the motor controller twice: tracks and propellers) run in
this process against fake devices on ptys (src/dukw_driver/test/fake_*.py and the
part-B fakes in that folder's tests) until every topic they publish has carried a
message; then sim_node runs as its own process, and the published topic names
and types of the two graphs are compared, leaving out what only the simulator
has (sim/truth, /clock, its true pose on /tf) and what every node has (/rosout, /parameter_events).
"""
import importlib
import sys
from pathlib import Path

import pytest

from dukw_common.node_tools import SENSOR_QOS, parameter_overrides
from dukw_common.testing import NodeProcess, ros_node, spin_until

DRIVER_TESTS = Path(__file__).resolve().parents[1] / 'src' / 'dukw_driver' / 'test'
sys.path.insert(0, str(DRIVER_TESTS))

from fake_device import FakeDevice  # noqa: E402
from fake_maestro import FakeMaestro  # noqa: E402
from fake_roboteq import FakeRoboteq  # noqa: E402

pytestmark = [pytest.mark.ros, pytest.mark.slow]
IGNORED = {'/rosout', '/parameter_events', '/clock', '/sim/truth', '/tf'}
DRIVERS = ['servo_switch_node', 'motor_controller_node', 'props_motor_controller_node',
           'imu_gps_node', 'water_sensor_node']


def message_class(type_name: str):
    """'dukw_msgs/msg/Authority' -> the class."""
    package, _, name = type_name.split('/')
    return getattr(importlib.import_module(f'{package}.msg'), name)


def published(probe, node_names, subscribed=False) -> dict[str, str]:
    """{topic: type} the named nodes publish (or subscribe), minus IGNORED."""
    query = (probe.get_subscriber_names_and_types_by_node if subscribed
             else probe.get_publisher_names_and_types_by_node)
    topics = {}
    present = set(probe.get_node_names())
    for name in node_names:
        if name not in present:  # not discovered yet
            continue
        for topic, types in query(name, '/'):
            if topic not in IGNORED:
                topics[topic] = types[0]
    return topics


def all_carry_messages(probe, executor, topics, timeout_s) -> set[str]:
    """Subscribe to every topic; spin until each carried a message; return the silent ones."""
    seen = set()
    for topic, type_name in topics.items():
        probe.create_subscription(message_class(type_name), topic,
                                  lambda _msg, t=topic: seen.add(t), SENSOR_QOS)
    spin_until(executor, lambda: seen >= set(topics), timeout_s)
    return set(topics) - seen


@pytest.fixture
def fake_devices(tmp_path):
    """Every device the drivers talk to, on ptys, with plausible traffic."""
    from test_imu_gps_node import FakeImu, dgps_stream
    from test_water_sensor_node import FakeNumato, FakeSounder
    maestro = FakeMaestro()
    maestro.set_lines(select_rc=False, link_ok=True)
    devices = {
        'maestro': FakeDevice(tmp_path / 'ttyMaestro', respond=maestro.feed),
        'tracks': FakeDevice(tmp_path / 'ttyTracks', respond=FakeRoboteq().feed),
        'props': FakeDevice(tmp_path / 'ttyProps', respond=FakeRoboteq().feed),
        'imu': FakeDevice(tmp_path / 'ttyImu', stream=FakeImu().stream, stream_period_s=0.02),
        'dgps': FakeDevice(tmp_path / 'ttyDgps', stream=dgps_stream, stream_period_s=0.1),
        'adc': FakeDevice(tmp_path / 'ttyAdc', respond=FakeNumato().respond),
        'sounder': FakeDevice(tmp_path / 'ttySounder', stream=FakeSounder().stream,
                              stream_period_s=0.1),
    }
    yield {name: str(device.path) for name, device in devices.items()}
    for device in devices.values():
        device.close()


def driver_nodes(context, ports):
    """The four drivers (five nodes) on the fake devices, in ``context``."""
    from dukw_driver.imu_gps_node import ImuGpsNode
    from dukw_driver.motor_controller_node import MotorControllerNode
    from dukw_driver.servo_switch_node import ServoSwitchNode
    from dukw_driver.water_sensor_node import WaterSensorNode

    def make(cls, cli_args=(), **overrides):
        return cls(context=context, parameter_overrides=parameter_overrides(overrides),
                   cli_args=list(cli_args))
    return [
        make(ServoSwitchNode, port=ports['maestro']),
        make(MotorControllerNode, port=ports['tracks']),
        make(MotorControllerNode, ['--ros-args', '-r', '__node:=props_motor_controller_node'],
             port=ports['props']),
        make(ImuGpsNode, **{'mavlink.port': ports['imu'], 'nmea.port': ports['dgps']}),
        make(WaterSensorNode, **{'adc.port': ports['adc'], 'sounder.port': ports['sounder']}),
    ]


def test_drivers_publish_the_same_topics_and_types_as_sim_node(fake_devices):
    with ros_node('probe_driver_graph') as (probe, executor):
        nodes = driver_nodes(probe.context, fake_devices)
        try:
            for node in nodes:
                executor.add_node(node)
            names = sorted(n.get_name() for n in nodes)
            assert names == sorted(DRIVERS)
            spin_until(executor, lambda: len(published(probe, DRIVERS)) >= 10, timeout_s=10)
            drivers = published(probe, DRIVERS)
            silent = all_carry_messages(probe, executor, drivers, timeout_s=20)
            driver_inputs = published(probe, DRIVERS, subscribed=True)
        finally:
            for node in nodes:
                getattr(node, 'on_shutdown', lambda: None)()
                executor.remove_node(node)
                node.destroy_node()
    assert not silent, f'driver topics that carried no message: {sorted(silent)}'

    with ros_node('probe_sim_graph') as (probe, executor):
        proc = NodeProcess('dukw_sim', 'sim_node')
        try:
            spin_until(executor, lambda: len(published(probe, ['sim_node'])) >= len(drivers),
                       timeout_s=30)
            sim = published(probe, ['sim_node'])
            sim_silent = all_carry_messages(probe, executor, sim, timeout_s=20)
            spin_until(executor, lambda: published(probe, ['sim_node'], subscribed=True),
                       timeout_s=10)
            sim_inputs = published(probe, ['sim_node'], subscribed=True)
        finally:
            code = proc.stop()
    assert code == 0, proc.stderr
    assert not sim_silent, f'sim topics that carried no message: {sorted(sim_silent)}'
    only_drivers = {t: drivers[t] for t in set(drivers) - set(sim)}
    only_sim = {t: sim[t] for t in set(sim) - set(drivers)}
    differing = {t: (drivers[t], sim[t]) for t in set(drivers) & set(sim) if drivers[t] != sim[t]}
    print(f'drivers: {drivers}\nsim_node: {sim}')
    assert not (only_drivers or only_sim or differing), (
        f'only drivers: {only_drivers}; only sim_node: {only_sim}; types differ: {differing}')
    assert driver_inputs == sim_inputs == {'/tracks/cmd': 'dukw_msgs/msg/DiffCommand',
                                           '/props/cmd': 'dukw_msgs/msg/DiffCommand'}
    assert {'/authority', '/rc/input', '/tracks/status', '/props/status', '/imu/data',
            '/gps/fix', '/gps/vel', '/water/contact', '/depth', '/diagnostics'} <= set(sim)
