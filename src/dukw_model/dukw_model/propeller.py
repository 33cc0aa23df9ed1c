"""Propeller thrust: from the command and from the hub's depth (vehicle.md section 3).

One implementation for the simulator (``dukw_sim.core``), the motor-controller monitor
(``dukw_driver.motors``: the thrust estimate it reports) and the simulated drivetrain
status (``dukw_sim.sensors``).
"""
from __future__ import annotations

import math

from dukw_common.vehicle import DrivetrainParams


def prop_thrust_n(command_pct: float, drivetrain: DrivetrainParams) -> float:
    """Open-water propeller thrust from the applied command, N (reverse weaker).

    Linear up to ``max_prop_thrust_n`` at 100 %, ``prop_reverse_thrust_ratio`` of it
    backwards.
    """
    ratio = 1.0 if command_pct >= 0 else drivetrain.prop_reverse_thrust_ratio
    return drivetrain.max_prop_thrust_n * ratio * command_pct / 100.0


def propeller_thrust_factor(hub_depth_m: float, diameter_m: float,
                            ventilation_depth_m: float) -> float:
    """Share of its open-water thrust a propeller gives at this hub depth, 0..1.

    The thrust follows the part of the propeller disc that works in solid water: the disc
    below a plane ``ventilation_depth_m`` under the local surface (closer to the surface the
    blades draw air). A propeller whose tip circle is deeper than that gives full thrust, a
    half-emerged one about half, one out of the water none. Only the propeller's own depth
    counts, not the hull's: a pitching hull loses no thrust while its propeller stays under.
    """
    radius_m = diameter_m / 2.0
    h = min(max((hub_depth_m - ventilation_depth_m) / radius_m, -1.0), 1.0)
    return (math.acos(-h) + h * math.sqrt(1.0 - h * h)) / math.pi
