"""live_scene's meshes and parts as foxglove-sdk messages (no ROS here)."""
from __future__ import annotations

from foxglove.messages import (Color, CubePrimitive, CylinderPrimitive, LocationFix,
                               LocationFixPositionCovarianceType, Point3, Pose, Quaternion,
                               SceneEntity, SceneUpdate, Timestamp, TriangleListPrimitive,
                               Vector3)

from dukw_bringup.live_scene import Mesh, Part

_IDENTITY = Pose(position=Vector3(), orientation=Quaternion(w=1.0))


def timestamp(t_ns: int) -> Timestamp:
    """Foxglove Timestamp of nanoseconds."""
    return Timestamp(t_ns // 1_000_000_000, t_ns % 1_000_000_000)


def _color(rgba) -> Color:
    return Color(r=rgba[0], g=rgba[1], b=rgba[2], a=rgba[3])


def _pose(xyz, quat) -> Pose:
    return Pose(position=Vector3(x=xyz[0], y=xyz[1], z=xyz[2]),
                orientation=Quaternion(x=quat[0], y=quat[1], z=quat[2], w=quat[3]))


def mesh_entity(mesh: Mesh, frame_id: str, t_ns: int) -> SceneEntity:
    """A triangle-list entity (id = the mesh's name) in ``frame_id``."""
    points = [Point3(x=float(x), y=float(y), z=float(z)) for x, y, z in mesh.points]
    triangles = TriangleListPrimitive(pose=_IDENTITY, points=points, color=_color(mesh.rgba),
                                      indices=[int(i) for i in mesh.indices])
    return SceneEntity(timestamp=timestamp(t_ns), frame_id=frame_id, id=mesh.name,
                       triangles=[triangles])


def parts_entity(name: str, parts: list[Part], frame_id: str, t_ns: int) -> SceneEntity:
    """Boxes and cylinders that follow ``frame_id`` (frame locked)."""
    cubes = [CubePrimitive(pose=_pose(p.xyz_m, p.quat_xyzw),
                           size=Vector3(x=p.size_m[0], y=p.size_m[1], z=p.size_m[2]),
                           color=_color(p.rgba)) for p in parts if p.kind == 'cube']
    cylinders = [CylinderPrimitive(pose=_pose(p.xyz_m, p.quat_xyzw),
                                   size=Vector3(x=p.size_m[0], y=p.size_m[1], z=p.size_m[2]),
                                   bottom_scale=1.0, top_scale=1.0, color=_color(p.rgba))
                 for p in parts if p.kind == 'cylinder']
    return SceneEntity(timestamp=timestamp(t_ns), frame_id=frame_id, id=name,
                       frame_locked=True, cubes=cubes, cylinders=cylinders)


def scene(*entities: SceneEntity) -> SceneUpdate:
    """One SceneUpdate of ``entities``."""
    return SceneUpdate(entities=list(entities))


def location_fix(t_ns: int, frame_id: str, lat_deg: float, lon_deg: float, alt_m: float,
                 covariance_enu: list[float]) -> LocationFix:
    """A LocationFix with an ENU diagonal covariance (m^2), for the map panel."""
    return LocationFix(timestamp=timestamp(t_ns), frame_id=frame_id, latitude=lat_deg,
                       longitude=lon_deg, altitude=alt_m,
                       position_covariance=[float(c) for c in covariance_enu],
                       position_covariance_type=LocationFixPositionCovarianceType.DiagonalKnown)
