"""Lever arms of the sensors mounted on the mast: base_link <-> sensor point (vehicle.md 2).

The IMU (``sensors.imu_z_m``) and the GPS antenna (``sensors.gps_antenna_z_m``) sit at
r = (0, 0, h) in base_link, same axes. The simulator's sensor model goes forward (true
base_link -> what the sensor sees), the estimator goes back (what the sensor saw ->
base_link) or predicts forward from its state; both use these functions. Rotation
R = Rz(yaw) Ry(pitch) Rx(roll), ENU.
"""
from __future__ import annotations

import math

Vector3 = tuple[float, float, float]


def lever_arm_enu(roll_rad: float, pitch_rad: float, yaw_rad: float,
                  lever_z_m: float) -> Vector3:
    """R (0, 0, h): where the sensor point is from base_link, in ENU axes, m."""
    a = lever_z_m * math.sin(pitch_rad) * math.cos(roll_rad)
    b = lever_z_m * math.sin(roll_rad)
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    return (c * a + s * b, s * a - c * b, lever_z_m * math.cos(pitch_rad) * math.cos(roll_rad))


def sensor_point_enu(base_enu: Vector3, roll_rad: float, pitch_rad: float, yaw_rad: float,
                     lever_z_m: float) -> Vector3:
    """The sensor point in ENU from base_link's position and attitude: base + R (0, 0, h)."""
    offset = lever_arm_enu(roll_rad, pitch_rad, yaw_rad, lever_z_m)
    return (base_enu[0] + offset[0], base_enu[1] + offset[1], base_enu[2] + offset[2])


def base_from_sensor_point(sensor_enu: Vector3, roll_rad: float, pitch_rad: float,
                           yaw_rad: float, lever_z_m: float) -> Vector3:
    """base_link's position in ENU from the sensor point's: sensor - R (0, 0, h)."""
    offset = lever_arm_enu(roll_rad, pitch_rad, yaw_rad, lever_z_m)
    return (sensor_enu[0] - offset[0], sensor_enu[1] - offset[1], sensor_enu[2] - offset[2])


def sensor_point_velocity_body(surge_mps: float, sway_mps: float, roll_rate_rps: float,
                               pitch_rate_rps: float, lever_z_m: float) -> tuple[float, float]:
    """Horizontal body-axis velocity of the sensor point: base_link's plus (w x r)_xy."""
    return surge_mps + pitch_rate_rps * lever_z_m, sway_mps - roll_rate_rps * lever_z_m


def specific_force_at_sensor(accel_mps2: Vector3, rates_rps: Vector3,
                             angular_accel_xy_rps2: tuple[float, float],
                             lever_z_m: float) -> Vector3:
    """Specific force at the sensor point from base_link's: f + alpha x r + w x (w x r).

    Body axes; ``rates_rps`` = (p, q, r), ``angular_accel_xy_rps2`` = (dp/dt, dq/dt) (the
    yaw acceleration does not act on a point on the z axis).
    """
    (fx, fy, fz), (wx, wy, wz), (alpha_x, alpha_y) = accel_mps2, rates_rps, angular_accel_xy_rps2
    h = lever_z_m
    return (fx + alpha_y * h + wz * wx * h,
            fy - alpha_x * h + wz * wy * h,
            fz - (wx * wx + wy * wy) * h)


def specific_force_at_base(accel_mps2: Vector3, rates_rps: Vector3,
                           angular_accel_xy_rps2: tuple[float, float],
                           lever_z_m: float) -> Vector3:
    """base_link's specific force from the sensor point's: the inverse of
    ``specific_force_at_sensor`` (same rates and angular acceleration)."""
    (fx, fy, fz), (wx, wy, wz), (alpha_x, alpha_y) = accel_mps2, rates_rps, angular_accel_xy_rps2
    h = lever_z_m
    return (fx - (alpha_y + wz * wx) * h,
            fy + (alpha_x - wz * wy) * h,
            fz + (wx * wx + wy * wy) * h)
