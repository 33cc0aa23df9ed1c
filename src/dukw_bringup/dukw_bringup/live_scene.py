"""What the live view draws, free of ROS and of the Foxglove SDK (numpy, dataclasses).

- the beach and the sea bed as a grid mesh in ``odom`` (the simulator's Beach profile,
  or the site's slope on the boat);
- the water surface as a grid mesh in ``odom`` at a given time: the simulator's own wave
  field (same seed and sea state, so it is the sea the vehicle meets) or the mean level;
- the vehicle's parts (hulls, tracks, deck) as boxes and cylinders in its frame, from
  dukw_common.description (the URDF's geometry);
- the estimated position as latitude/longitude for the map (the EKF's datum).

dukw_bringup.live_view_node turns these into Foxglove SceneUpdate and LocationFix.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Mapping

import numpy as np

from dukw_common.config import ParamValue
from dukw_common.description import VehicleModel
from dukw_common.geometry import geodetic_from_local_enu, quaternion_from_euler

#: Colours (drawing only): sand, water, the true pose's ghost.
SAND_RGBA = (0.86, 0.78, 0.58, 1.0)
WATER_RGBA = (0.15, 0.45, 0.75, 0.55)
TRUTH_ALPHA = 0.35

HeightField = Callable[[np.ndarray, np.ndarray], np.ndarray]          # (x, y) -> z
SurfaceField = Callable[[np.ndarray, np.ndarray, float], np.ndarray]  # (x, y, t) -> z


@dataclass(frozen=True)
class SceneArea:
    """The patch of beach and sea drawn, odom metres (config ``area.*``)."""

    x_min_m: float
    x_max_m: float
    y_min_m: float
    y_max_m: float
    step_m: float

    def __post_init__(self) -> None:
        if not (self.x_min_m < self.x_max_m and self.y_min_m < self.y_max_m):
            raise ValueError(f'scene area must have min < max, got {self}')
        cells = ((self.x_max_m - self.x_min_m) / self.step_m) * \
            ((self.y_max_m - self.y_min_m) / self.step_m) if self.step_m > 0 else math.inf
        if not 1 <= cells <= 20000:
            raise ValueError(f'scene area step_m {self.step_m} gives {cells} cells '
                             '(1..20000 allowed)')

    @classmethod
    def from_params(cls, params: Mapping[str, ParamValue], prefix: str = 'area') -> SceneArea:
        """From dotted parameters ``area.x_min_m`` ..."""
        return cls(*(float(params[f'{prefix}.{name}']) for name in cls.__dataclass_fields__))

    def grid(self) -> tuple[np.ndarray, np.ndarray]:
        """Grid node coordinates (x along the shore normal, y along the shore)."""
        nx = int(round((self.x_max_m - self.x_min_m) / self.step_m)) + 1
        ny = int(round((self.y_max_m - self.y_min_m) / self.step_m)) + 1
        return np.linspace(self.x_min_m, self.x_max_m, nx), \
            np.linspace(self.y_min_m, self.y_max_m, ny)


@dataclass(frozen=True)
class Mesh:
    """A triangle mesh: points (N, 3), triangle corner indices (3 M,), one colour."""

    name: str
    points: np.ndarray
    indices: np.ndarray
    rgba: tuple[float, float, float, float]


def grid_mesh(name: str, x: np.ndarray, y: np.ndarray, z: np.ndarray,
              rgba: tuple[float, float, float, float]) -> Mesh:
    """Two triangles per grid cell over z[i, j] at (x[i], y[j])."""
    xx, yy = np.meshgrid(x, y, indexing='ij')
    points = np.column_stack([xx.ravel(), yy.ravel(), np.asarray(z, float).ravel()])
    ny = len(y)
    i, j = np.meshgrid(np.arange(len(x) - 1), np.arange(ny - 1), indexing='ij')
    a = (i * ny + j).ravel()
    b, c, d = a + ny, a + 1, a + ny + 1
    indices = np.column_stack([a, b, c, c, b, d]).ravel().astype(np.uint32)
    return Mesh(name, points, indices, rgba)


class LiveScene:
    """Meshes of the ground and the water over ``area``."""

    def __init__(self, area: SceneArea, ground: HeightField,
                 surface: SurfaceField | None = None) -> None:
        self.x, self.y = area.grid()
        self._xx, self._yy = np.meshgrid(self.x, self.y, indexing='ij')
        self.ground = ground
        self.surface = surface

    def beach(self) -> Mesh:
        """The sand and the sea bed (fixed)."""
        return grid_mesh('beach', self.x, self.y, self.ground(self._xx, self._yy), SAND_RGBA)

    def water(self, t_s: float) -> Mesh:
        """The water surface at ``t_s``, only where it is above the ground."""
        if self.surface is None:
            return self._water('water', np.zeros_like(self._xx))
        eta = self.surface(self._xx.ravel(), self._yy.ravel(), t_s).reshape(self._xx.shape)
        return self._water('water', eta)

    def sea_level(self) -> Mesh:
        """The mean sea level (fixed)."""
        return self._water('sea_level', np.zeros_like(self._xx))

    def _water(self, name: str, eta: np.ndarray) -> Mesh:
        ground = self.ground(self._xx, self._yy)   # below the sand where it is dry
        return grid_mesh(name, self.x, self.y, np.maximum(eta, ground - 0.01), WATER_RGBA)


@dataclass(frozen=True)
class Part:
    """One drawn part in the vehicle's frame: a box (x, y, z sizes) or cylinder."""

    name: str
    kind: str                             # 'cube' | 'cylinder'
    xyz_m: tuple[float, float, float]
    quat_xyzw: tuple[float, float, float, float]
    size_m: tuple[float, float, float]
    rgba: tuple[float, float, float, float]


def vehicle_parts(model: VehicleModel, alpha: float = 1.0) -> list[Part]:
    """The model's parts as Foxglove-style primitives (cylinders along their own z)."""
    along_x = tuple(quaternion_from_euler(0.0, math.pi / 2, 0.0))
    parts = []
    for link in model.links:
        if link.shape is None:
            continue
        rgba = (*link.shape.rgba[:3], link.shape.rgba[3] * alpha)
        if link.shape.kind == 'cylinder':
            radius, length = link.shape.size_m
            parts.append(Part(link.name, 'cylinder', link.joint.xyz_m, along_x,
                              (2 * radius, 2 * radius, length), rgba))
        else:
            parts.append(Part(link.name, 'cube', link.joint.xyz_m, link.joint.quat_xyzw,
                              tuple(link.shape.size_m), rgba))
    return parts


@dataclass(frozen=True)
class MapOrigin:
    """The odom origin on the earth (the EKF's ``datum.*``)."""

    latitude_deg: float
    longitude_deg: float
    altitude_m: float

    def to_geodetic(self, x_m: float, y_m: float, z_m: float = 0.0) -> tuple[float, ...]:
        """(lat, lon, alt) of an odom (ENU) position."""
        return geodetic_from_local_enu(x_m, y_m, z_m, self.latitude_deg, self.longitude_deg,
                                       self.altitude_m)


def site_ground(slope_rad: float, sea_floor_depth_m: float) -> HeightField:
    """The site's beach without the simulator: a plane slope through the mean waterline
    (odom x = 0, +x seaward) down to a flat sea floor."""
    tan = math.tan(slope_rad)
    return lambda x, y: np.maximum(-np.asarray(x, float) * tan, -sea_floor_depth_m)


def sim_world_fields(overrides: Mapping[str, ParamValue], seed: int,
                     config_path: str | None = None) -> tuple[HeightField, SurfaceField]:
    """The simulator's beach and wave field for sim_node's parameters and seed: the same
    construction as SimCore's, so the surface drawn is the sea the vehicle meets."""
    from dukw_sim.core import SimCore
    world = SimCore.from_config(config_path, overrides=overrides, seed=seed).world
    return (lambda x, y: world.beach.heights_m(np.asarray(x, float)),
            lambda x, y, t: world.sample(np.asarray(x, float), np.asarray(y, float),
                                         t).elevation_m)
