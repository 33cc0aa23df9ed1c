"""The live view's ROS-free scene: meshes over the simulator's beach and sea, the parts."""
import math

import numpy as np
import pytest

from dukw_bringup.live_scene import (LiveScene, SceneArea, grid_mesh, sim_world_fields,
                                     site_ground, vehicle_parts)
from dukw_common.description import FrameNames, VehicleModel
from dukw_common.vehicle import Vehicle

SEA = {'waves.model': 'irregular', 'waves.significant_height_m': 0.28,
       'waves.peak_period_s': 3.6}


def test_grid_mesh_has_two_triangles_per_cell_over_the_given_heights():
    x, y = np.array([0.0, 1.0, 2.0]), np.array([0.0, 1.0])
    z = np.array([[0.0, 0.1], [0.2, 0.3], [0.4, 0.5]])
    mesh = grid_mesh('m', x, y, z, (1, 1, 1, 1))
    assert mesh.points.shape == (6, 3) and len(mesh.indices) == 2 * 2 * 3
    assert mesh.points[3].tolist() == [1.0, 1.0, 0.3]        # (x[1], y[1], z[1, 1])
    assert mesh.indices.max() == 5


def test_water_surface_is_the_simulators_sea_and_it_moves():
    from dukw_sim.core import SimCore
    area = SceneArea(-5.0, 15.0, -2.0, 2.0, 1.0)
    scene = LiveScene(area, *sim_world_fields(SEA, seed=7))
    world = SimCore.from_config(overrides=SEA, seed=7).world
    water = scene.water(12.3)
    seaward = water.points[water.points[:, 0] == 10.0]
    expected = world.sample(seaward[:, 0], seaward[:, 1], 12.3).elevation_m
    assert seaward[:, 2] == pytest.approx(expected)
    assert np.abs(expected).max() > 0.01                     # a real sea, not a plane
    assert not np.allclose(scene.water(14.1).points[:, 2], water.points[:, 2])
    beach = scene.beach().points
    assert beach[beach[:, 0] == -5.0, 2] == pytest.approx(world.beach.height_m(-5.0))
    on_sand = water.points[:, 0] == -5.0                     # dry sand: water under it
    assert np.all(water.points[on_sand, 2] < beach[on_sand, 2])


def test_site_ground_without_the_simulator_is_the_slope_down_to_the_floor():
    ground = site_ground(0.1, 1.5)
    assert ground(np.array([-10.0, 0.0, 5.0, 100.0]), None) == pytest.approx(
        [10 * math.tan(0.1), 0.0, -5 * math.tan(0.1), -1.5])
    flat = LiveScene(SceneArea(-2.0, 2.0, -1.0, 1.0, 1.0), ground).water(3.0)
    assert np.all(flat.points[flat.points[:, 0] > 0.0, 2] == 0.0)


def test_bad_areas_are_refused():
    with pytest.raises(ValueError, match='min < max'):
        SceneArea(5.0, -5.0, 0.0, 1.0, 1.0)
    with pytest.raises(ValueError, match='cells'):
        SceneArea(-100.0, 100.0, -100.0, 100.0, 0.01)


def test_parts_are_the_models_hulls_tracks_and_deck():
    vehicle = Vehicle.load()
    model = VehicleModel.build(vehicle.body, vehicle.sensors, FrameNames(), 0.05)
    parts = {p.name: p for p in vehicle_parts(model, alpha=0.5)}
    assert set(parts) == {'port_hull', 'stbd_hull', 'port_track', 'stbd_track', 'deck'}
    hull = parts['port_hull']
    r = vehicle.body.hull_radius_m
    assert hull.kind == 'cylinder'
    assert hull.size_m == pytest.approx((2 * r, 2 * r, vehicle.body.hull_length_m))
    assert parts['deck'].size_m[:2] == pytest.approx((vehicle.body.length_m,
                                                      vehicle.body.beam_m))
    assert all(p.rgba[3] == 0.5 for p in parts.values())
