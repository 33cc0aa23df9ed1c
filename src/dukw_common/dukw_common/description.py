"""The vehicle's frames and a small URDF of it, built from the shared facts in config.

ROS-free (dataclasses, xml.etree). Every size and offset comes from ``vehicle.*`` and
``sensors.*`` of config/dukw.yaml (the same values the simulator's sensor model uses):

- ``base_link``: centre of the tracks' contact patch at ground level, under the LCG
  (REP 103: x forward, y left, z up);
- the two hulls: cylinders of ``hull_radius_m`` x ``hull_length_m`` at y = +-p
  (``hull_separation_m`` / 2), their bottom ``hull_clearance_m`` above the ground,
  midway between bow (``lcg_from_bow_m`` ahead) and stern;
- the two tracks: ``track_contact_length_m`` x ``track_width_m`` from the ground up to
  the hull bottom, under each hull;
- the deck: ``length_m`` x ``beam_m``, its top ``depth_keel_to_deck_m`` above the keel;
- the sensor frames (same axes as base_link): IMU, GPS antenna, fore/aft water
  contact, depth sounder.

Every link is fixed, so ``static_transforms`` is what a robot_state_publisher would put
on /tf_static for this URDF.
"""
from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Mapping

from dukw_common.config import ParamValue
from dukw_common.geometry import quaternion_from_euler
from dukw_common.vehicle import SensorMounts, VehicleParams

#: URDF colours (drawing only): hull grey, track black, deck sand.
HULL_RGBA = (0.55, 0.58, 0.62, 1.0)
TRACK_RGBA = (0.12, 0.12, 0.12, 1.0)
DECK_RGBA = (0.80, 0.72, 0.52, 1.0)


@dataclass(frozen=True)
class FrameTransform:
    """``child``'s pose in ``parent``: translation (m) and unit quaternion (x, y, z, w)."""

    parent: str
    child: str
    xyz_m: tuple[float, float, float]
    quat_xyzw: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)


def pose_transform(parent: str, child: str, x_m: float, y_m: float, z_m: float,
                   roll_rad: float = 0.0, pitch_rad: float = 0.0,
                   yaw_rad: float = 0.0) -> FrameTransform:
    """A transform from a position and REP 103 Euler angles (e.g. odom -> base_link)."""
    return FrameTransform(parent, child, (float(x_m), float(y_m), float(z_m)),
                          tuple(float(q) for q in quaternion_from_euler(roll_rad, pitch_rad,
                                                                          yaw_rad)))


@dataclass(frozen=True)
class Shape:
    """A link's visual: a box (x, y, z sizes) or a cylinder (radius, length along x)."""

    kind: str                        # 'box' | 'cylinder'
    size_m: tuple[float, ...]
    rgba: tuple[float, float, float, float]


@dataclass(frozen=True)
class Link:
    """One rigid part or sensor frame, fixed to base_link at ``joint``."""

    joint: FrameTransform
    shape: Shape | None = None

    @property
    def name(self) -> str:
        """The link's frame name."""
        return self.joint.child


@dataclass(frozen=True)
class FrameNames:
    """The frame ids of the vehicle (config ``frames.*``)."""

    base: str = 'base_link'
    imu: str = 'imu_link'
    gps: str = 'gps_link'
    fore_water: str = 'fore_water_link'
    aft_water: str = 'aft_water_link'
    depth_sounder: str = 'depth_sounder_link'

    @classmethod
    def from_params(cls, params: Mapping[str, ParamValue], prefix: str = 'frames') -> FrameNames:
        """From dotted parameters ``frames.<field>``; missing ones keep the REP 105 names."""
        values = {name: str(params[f'{prefix}.{name}']) for name in cls.__dataclass_fields__
                  if f'{prefix}.{name}' in params}
        for name, value in values.items():
            if not value or any(c.isspace() for c in value):
                raise ValueError(f'{prefix}.{name}: a frame id must be non-empty, no spaces')
        return cls(**values)


@dataclass(frozen=True)
class VehicleModel:
    """The vehicle's links (parts and sensor frames), all fixed to the base frame."""

    base: str
    links: tuple[Link, ...]

    @classmethod
    def build(cls, body: VehicleParams, mounts: SensorMounts, frames: FrameNames,
              deck_thickness_m: float) -> VehicleModel:
        """Lay out hulls, tracks, deck and sensor frames from the vehicle's facts."""
        if not 0.0 < deck_thickness_m < body.depth_keel_to_deck_m:
            raise ValueError(f'deck_thickness_m must be in (0, {body.depth_keel_to_deck_m}) m, '
                             f'got {deck_thickness_m}')
        b = frames.base
        mid_x = (body.bow_x_m + body.stern_x_m) / 2.0
        half_p = body.hull_separation_m / 2.0
        keel_z = body.hull_clearance_m
        links = []
        for side, y in (('port', half_p), ('stbd', -half_p)):
            links.append(Link(FrameTransform(b, f'{side}_hull', (mid_x, y, keel_z
                                                                   + body.hull_radius_m)),
                              Shape('cylinder', (body.hull_radius_m, body.hull_length_m),
                                    HULL_RGBA)))
            links.append(Link(FrameTransform(b, f'{side}_track', (0.0, y, keel_z / 2.0)),
                              Shape('box', (body.track_contact_length_m, body.track_width_m,
                                            keel_z), TRACK_RGBA)))
        deck_z = keel_z + body.depth_keel_to_deck_m - deck_thickness_m / 2.0
        links.append(Link(FrameTransform(b, 'deck', (mid_x, 0.0, deck_z)),
                          Shape('box', (body.length_m, body.beam_m, deck_thickness_m),
                                DECK_RGBA)))
        for child, x, z in ((frames.imu, 0.0, mounts.imu_z_m),
                            (frames.gps, 0.0, mounts.gps_antenna_z_m),
                            (frames.fore_water, mounts.fore_water_x_m, mounts.fore_water_z_m),
                            (frames.aft_water, mounts.aft_water_x_m, mounts.aft_water_z_m),
                            (frames.depth_sounder, mounts.depth_sounder_x_m,
                             mounts.depth_sounder_z_m)):
            links.append(Link(FrameTransform(b, child, (x, 0.0, z))))
        return cls(b, tuple(links))

    def static_transforms(self) -> list[FrameTransform]:
        """Every fixed joint: what belongs on /tf_static."""
        return [link.joint for link in self.links]

    def link(self, name: str) -> Link:
        """The link called ``name``; KeyError if there is none."""
        for link in self.links:
            if link.name == name:
                return link
        raise KeyError(name)

    def urdf(self, robot_name: str = 'dukw_ling') -> str:
        """The model as URDF text (fixed joints, box/cylinder visuals)."""
        robot = ET.Element('robot', name=robot_name)
        ET.SubElement(robot, 'link', name=self.base)
        for link in self.links:
            element = ET.SubElement(robot, 'link', name=link.name)
            if link.shape is not None:
                _visual(element, link.name, link.shape)
            joint = ET.SubElement(robot, 'joint', name=f'{link.name}_joint', type='fixed')
            ET.SubElement(joint, 'parent', link=link.joint.parent)
            ET.SubElement(joint, 'child', link=link.name)
            ET.SubElement(joint, 'origin', xyz=_triple(link.joint.xyz_m), rpy='0 0 0')
        ET.indent(robot)
        return ET.tostring(robot, encoding='unicode')


def _triple(values) -> str:
    return ' '.join(f'{v:.6g}' for v in values)


def _visual(link: ET.Element, name: str, shape: Shape) -> None:
    visual = ET.SubElement(link, 'visual')
    geometry = ET.SubElement(visual, 'geometry')
    if shape.kind == 'box':
        ET.SubElement(visual, 'origin', xyz='0 0 0', rpy='0 0 0')
        ET.SubElement(geometry, 'box', size=_triple(shape.size_m))
    elif shape.kind == 'cylinder':        # URDF cylinders lie along z: turn onto x
        ET.SubElement(visual, 'origin', xyz='0 0 0', rpy=f'0 {math.pi / 2:.6f} 0')
        radius, length = shape.size_m
        ET.SubElement(geometry, 'cylinder', radius=f'{radius:.6g}', length=f'{length:.6g}')
    else:
        raise ValueError(f'unknown shape kind {shape.kind!r}')
    material = ET.SubElement(visual, 'material', name=f'{name}_colour')
    ET.SubElement(material, 'color', rgba=_triple(shape.rgba))
