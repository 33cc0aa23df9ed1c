"""The parameters sim_node declares: its own with ranges, the rest of its config block generically.

Every value's default comes from config/dukw.yaml (``/**`` and ``sim_node``); a
``--params-file`` or ``-p`` override of any of them reaches the physics core and
the sensor models, which validate their groups themselves (ConfigError, exit 2).
"""
from __future__ import annotations

import math

from dukw_common.config import node_params
from dukw_common.node_tools import ParamSpec, vehicle_specs
from dukw_sim.sensors import SENSOR_STREAMS, SensorNoise

#: Streams sim_node schedules itself (sensors.py schedules SENSOR_STREAMS).
NODE_STREAMS = ('rc', 'authority', 'truth', 'clock', 'diagnostics')
START_CHOICES = ('sand', 'surf', 'afloat')

_OWN = [
    ParamSpec('rate_hz', 'timer ticks per simulated second; each steps the physics by '
              '1/rate_hz (at least one physics step)', min=1.0, max=1000.0),
    ParamSpec('real_time_factor', 'simulated seconds per wall-clock second; 0 = as fast as '
              'possible', min=0.0, max=1000.0),
    ParamSpec('start_at', f'where the vehicle starts: {" | ".join(START_CHOICES)}'),
    ParamSpec('start_yaw_rad', 'heading at the start, rad (0: bow to the sea)',
              min=-math.pi, max=math.pi),
    ParamSpec('seed', 'random seed of sensor noise and sea state', min=0, max=2**31 - 1),
    ParamSpec('command_timeout_s', 'servo switch: neutral when no command came for this long '
              '(sim time), s', min=0.01, max=10.0),
    ParamSpec('tick_budget_s', 'wall-clock seconds one timer tick may spend stepping before '
              'commands and services get their turn', min=0.001, max=1.0),
    ParamSpec('max_lag_s', 'sim seconds the simulator may fall behind wall clock x '
              'real_time_factor before it stops catching up', min=0.01, max=100.0),
    ParamSpec('frames.base', 'frame_id of the vehicle (base_link)'),
    ParamSpec('frames.imu', 'frame_id of imu/data: (0, 0, sensors.imu_z_m) in base_link'),
    ParamSpec('frames.gps', 'frame_id of gps/fix and gps/vel: (0, 0, sensors.gps_antenna_z_m)'),
    ParamSpec('frames.truth', "the true pose's frame: odom -> it on /tf ('' = none)"),
    *[ParamSpec(f'rates.{s}_hz', f'{s} publication rate, Hz of sim time', min=0.01, max=1000.0)
      for s in (*SENSOR_STREAMS, *NODE_STREAMS)],
    *[ParamSpec(f'noise.{n}', f'sensor noise: {n}', min=0.0)
      for n in SensorNoise.__dataclass_fields__],
    *[ParamSpec(f'datum.{n}', f'odom origin {n} (the shared datum.*): the GPS fixes', min=lo,
                max=hi) for n, lo, hi in (('latitude_deg', -90.0, 90.0),
                                          ('longitude_deg', -180.0, 180.0),
                                          ('altitude_m', -1000.0, 10000.0))],
]


def sim_node_specs(node_name: str = 'sim_node', path: str | None = None) -> list[ParamSpec]:
    """ParamSpecs for every key the node's parameter file block holds (own ones with ranges)."""
    specs = list(_OWN) + vehicle_specs()
    known = {s.name for s in specs}
    for name in node_params(node_name, path):
        if name not in known:
            group = name.split('.')[0]
            specs.append(ParamSpec(name, f'simulator {group} parameter (see config/dukw.yaml)'))
    return specs
