"""The vehicle model: its URDF parses, and every size and offset is the config's."""
import dataclasses
import math
import xml.etree.ElementTree as ET

import pytest

from dukw_common.config import node_params
from dukw_common.description import FrameNames, VehicleModel, pose_transform
from dukw_common.geometry import euler_from_quaternion
from dukw_common.vehicle import Vehicle

PARAMS = node_params('robot_state_node')


def build(vehicle=None):
    vehicle = vehicle or Vehicle.load()
    return VehicleModel.build(vehicle.body, vehicle.sensors, FrameNames.from_params(PARAMS),
                              float(PARAMS['deck_thickness_m']))


def floats(text):
    return [float(v) for v in text.split()]


def parsed(model):
    robot = ET.fromstring(model.urdf())
    links = {link.get('name'): link for link in robot.findall('link')}
    origins = {j.find('child').get('link'): floats(j.find('origin').get('xyz'))
               for j in robot.findall('joint')}
    assert {j.get('type') for j in robot.findall('joint')} == {'fixed'}
    assert {j.find('parent').get('link') for j in robot.findall('joint')} == {'base_link'}
    return robot, links, origins


def test_urdf_parts_and_sensor_frames_have_the_configs_dimensions():
    vehicle = Vehicle.load()
    body, sensors = vehicle.body, vehicle.sensors
    robot, links, origins = parsed(build(vehicle))
    assert robot.get('name') == 'dukw_ling'
    assert set(links) == {'base_link', 'port_hull', 'stbd_hull', 'port_track', 'stbd_track',
                          'deck', 'imu_link', 'gps_link', 'fore_water_link', 'aft_water_link',
                          'depth_sounder_link'}
    hull = links['port_hull'].find('visual/geometry/cylinder')
    assert float(hull.get('radius')) == pytest.approx(body.hull_radius_m)
    assert float(hull.get('length')) == pytest.approx(body.hull_length_m)
    assert origins['port_hull'][1] == pytest.approx(body.hull_separation_m / 2)
    assert origins['stbd_hull'][1] == pytest.approx(-body.hull_separation_m / 2)
    assert origins['port_hull'][2] == pytest.approx(body.hull_clearance_m + body.hull_radius_m)
    track = floats(links['stbd_track'].find('visual/geometry/box').get('size'))
    assert track == pytest.approx([body.track_contact_length_m, body.track_width_m,
                                   body.hull_clearance_m])
    deck = floats(links['deck'].find('visual/geometry/box').get('size'))
    assert deck[:2] == pytest.approx([body.length_m, body.beam_m])
    deck_top = origins['deck'][2] + deck[2] / 2
    assert deck_top == pytest.approx(body.hull_clearance_m + body.depth_keel_to_deck_m)
    assert origins['imu_link'] == pytest.approx([0.0, 0.0, sensors.imu_z_m])
    assert origins['gps_link'] == pytest.approx([0.0, 0.0, sensors.gps_antenna_z_m])
    assert origins['fore_water_link'] == pytest.approx(
        [sensors.fore_water_x_m, 0.0, sensors.fore_water_z_m])
    assert origins['aft_water_link'] == pytest.approx(
        [sensors.aft_water_x_m, 0.0, sensors.aft_water_z_m])
    assert origins['depth_sounder_link'] == pytest.approx(
        [sensors.depth_sounder_x_m, 0.0, sensors.depth_sounder_z_m])


def test_a_changed_fact_moves_the_drawing_and_the_static_frames_alike():
    vehicle = Vehicle.load()
    wider = dataclasses.replace(vehicle, body=dataclasses.replace(vehicle.body,
                                                                  hull_separation_m=1.5),
                                sensors=dataclasses.replace(vehicle.sensors, imu_z_m=0.7))
    model = build(wider)
    _, _, origins = parsed(model)
    assert origins['port_hull'][1] == pytest.approx(0.75)
    static = {t.child: t for t in model.static_transforms()}
    assert static['imu_link'].xyz_m == pytest.approx((0.0, 0.0, 0.7))
    assert set(static) == {link for link in origins}
    assert all(t.parent == 'base_link' and t.quat_xyzw == (0, 0, 0, 1) for t in static.values())


def test_bad_frame_names_and_deck_are_refused():
    with pytest.raises(ValueError, match='frames.imu'):
        FrameNames.from_params({'frames.imu': 'imu link'})
    vehicle = Vehicle.load()
    with pytest.raises(ValueError, match='deck_thickness_m'):
        VehicleModel.build(vehicle.body, vehicle.sensors, FrameNames(), 0.0)


def test_pose_transform_carries_position_and_yaw():
    t = pose_transform('odom', 'base_link_truth', 1.0, -2.0, 0.3, 0.0, 0.1, 2.0)
    assert t.xyz_m == (1.0, -2.0, 0.3)
    assert euler_from_quaternion(*t.quat_xyzw) == pytest.approx((0.0, 0.1, 2.0))
    assert math.isclose(sum(q * q for q in t.quat_xyzw), 1.0)
