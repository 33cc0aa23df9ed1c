"""Frame conventions and angle helpers (REP 103/105), numpy only.

ROS: base_link x forward, y left, z up; odom is ENU; yaw counter-clockwise positive.
Devices (MAVLink IMUs, the paper's body frame) use NED / FRD: y right, z down,
yaw clockwise from north. Convert at the boundary with these functions.
"""
from __future__ import annotations

import math

import numpy as np


def wrap_angle(angle_rad: float) -> float:
    """Wrap an angle to [-pi, pi)."""
    return (angle_rad + math.pi) % (2.0 * math.pi) - math.pi


def quaternion_from_euler(roll_rad: float, pitch_rad: float, yaw_rad: float) -> tuple:
    """Return (x, y, z, w) for intrinsic Z-Y-X (yaw, pitch, roll) rotations."""
    cr, sr = math.cos(roll_rad / 2), math.sin(roll_rad / 2)
    cp, sp = math.cos(pitch_rad / 2), math.sin(pitch_rad / 2)
    cy, sy = math.cos(yaw_rad / 2), math.sin(yaw_rad / 2)
    return (sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
            cr * cp * cy + sr * sp * sy)


def euler_from_quaternion(x: float, y: float, z: float, w: float) -> tuple:
    """Return (roll, pitch, yaw) in rad from a unit quaternion (x, y, z, w)."""
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return roll, pitch, yaw


def ned_to_enu(north: float, east: float, down: float) -> tuple:
    """Convert a NED vector to ENU."""
    return east, north, -down


def frd_to_flu(forward: float, right: float, down: float) -> tuple:
    """Convert a body FRD vector (forward, right, down) to FLU (REP 103 base_link)."""
    return forward, -right, -down


def yaw_ned_to_enu(yaw_ned_rad: float) -> float:
    """Heading clockwise from north -> yaw counter-clockwise from east."""
    return wrap_angle(math.pi / 2 - yaw_ned_rad)


def rotate_body_to_world(yaw_rad: float, u: float, v: float) -> tuple:
    """Planar body velocity (u forward, v left) to world (ENU) velocity."""
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    return c * u - s * v, s * u + c * v


def rotate_world_to_body(yaw_rad: float, vx: float, vy: float) -> tuple:
    """Planar world (ENU) velocity to body (u forward, v left)."""
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    return c * vx + s * vy, -s * vx + c * vy


#: WGS84 equatorial radius, m (the local tangent-plane approximation's scale)
EARTH_RADIUS_M = 6378137.0


def local_enu_from_geodetic(lat_deg: float, lon_deg: float, alt_m: float,
                            lat0_deg: float, lon0_deg: float, alt0_m: float) -> tuple:
    """Local tangent-plane (ENU) offset from a datum; equirectangular, fine over a few km."""
    r_earth = EARTH_RADIUS_M
    east = math.radians(lon_deg - lon0_deg) * r_earth * math.cos(math.radians(lat0_deg))
    north = math.radians(lat_deg - lat0_deg) * r_earth
    return east, north, alt_m - alt0_m


def geodetic_from_local_enu(east_m: float, north_m: float, up_m: float,
                            lat0_deg: float, lon0_deg: float, alt0_m: float) -> tuple:
    """Inverse of local_enu_from_geodetic: (lat_deg, lon_deg, alt_m)."""
    r_earth = EARTH_RADIUS_M
    lat = lat0_deg + math.degrees(north_m / r_earth)
    lon = lon0_deg + math.degrees(east_m / (r_earth * math.cos(math.radians(lat0_deg))))
    return lat, lon, alt0_m + up_m


def rotation_matrix_z(yaw_rad: float) -> np.ndarray:
    """2x2 planar rotation by yaw."""
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    return np.array([[c, -s], [s, c]])
