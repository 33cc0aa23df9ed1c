"""The PARAM protocol's whitelist: the shore link's own tuning, settable from the GCS. ROS-free.

Only these can be read or set over the radio (names as a ground station shows them):

    SHL_MAN_SPD   m/s    speed at full MANUAL_CONTROL x (0..2, drive controller's max)
    SHL_MAN_YAW   rad/s  yaw rate at full MANUAL_CONTROL r (0..1.5)
    SHL_MAN_TOUT  s      no MANUAL_CONTROL this long: zero cmd_vel (0.05..0.5)
    SHL_FS_TOUT   s      GCS heartbeat lost this long: failsafe (1..60)
    SHL_FS_ACT    -      failsafe action: 0 none (report only), 1 stop, 2 SAFE_STOP mode
    SR_<stream>   Hz     telemetry rate of each stream (0 = off .. 10)

Nothing else of the stack can be changed over the radio. A set outside the range is
refused (PARAM_ERROR, and PARAM_VALUE with the unchanged value).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from enum import IntEnum

from dukw_common.config import ConfigError

MAX_STREAM_RATE_HZ = 10.0


class FailsafeAction(IntEnum):
    """What GCS heartbeat loss does while a shore command is active."""

    NONE = 0        # report only
    STOP = 1        # zero cmd_vel, hold the mission
    SAFE_STOP = 2   # also ask the mode manager for SAFE_STOP


@dataclass
class Tuning:
    """The values the whitelist exposes (defaults from config/dukw.yaml)."""

    manual_max_speed_mps: float
    manual_max_yaw_rate_rps: float
    manual_timeout_s: float
    gcs_timeout_s: float
    failsafe_action: FailsafeAction
    rates_hz: dict[str, float]


@dataclass(frozen=True)
class ParamDef:
    """One whitelisted parameter: name, range, where it lives in Tuning."""

    name: str
    minimum: float
    maximum: float
    attribute: str            # Tuning attribute, or 'rates_hz:<stream>'
    integer: bool = False


STREAM_PARAM_NAMES = {'heartbeat': 'SR_HEARTBEAT', 'sys_status': 'SR_SYS_STATUS',
                      'battery_status': 'SR_BATTERY', 'global_position': 'SR_POSITION',
                      'gps_raw': 'SR_GPS_RAW', 'attitude': 'SR_ATTITUDE', 'vfr_hud': 'SR_VFR_HUD',
                      'named_values': 'SR_NAMED_VALUES', 'mission_current': 'SR_MISSION_CUR'}
PARAMS = (
    ParamDef('SHL_MAN_SPD', 0.0, 2.0, 'manual_max_speed_mps'),
    ParamDef('SHL_MAN_YAW', 0.0, 1.5, 'manual_max_yaw_rate_rps'),
    ParamDef('SHL_MAN_TOUT', 0.05, 0.5, 'manual_timeout_s'),
    ParamDef('SHL_FS_TOUT', 1.0, 60.0, 'gcs_timeout_s'),
    ParamDef('SHL_FS_ACT', 0, 2, 'failsafe_action', integer=True),
    *(ParamDef(name, 0.0, MAX_STREAM_RATE_HZ, f'rates_hz:{stream}')
      for stream, name in STREAM_PARAM_NAMES.items()),
)


class ParamTable:
    """Reads and writes the whitelisted parameters of a Tuning."""

    def __init__(self, tuning: Tuning) -> None:
        self.tuning = tuning
        self.by_name = {p.name: p for p in PARAMS}
        for p in PARAMS:
            value = self.get(p.name)
            if not p.minimum <= value <= p.maximum:
                raise ConfigError(f'shore link tuning {p.attribute} = {value} is outside '
                                  f'[{p.minimum}, {p.maximum}]')

    def names(self) -> list[str]:
        """Every parameter, in index order."""
        return [p.name for p in PARAMS]

    def get(self, name: str) -> float:
        """Current value (KeyError for a name not on the whitelist)."""
        p = self.by_name[name]
        if p.attribute.startswith('rates_hz:'):
            return float(self.tuning.rates_hz[p.attribute.split(':', 1)[1]])
        return float(getattr(self.tuning, p.attribute))

    def set(self, name: str, value: float) -> bool:
        """Apply a new value; False (nothing changed) when outside the range or not a number."""
        p = self.by_name[name]
        if not math.isfinite(value) or not p.minimum <= value <= p.maximum:
            return False
        if p.integer and value != round(value):
            return False
        if p.attribute.startswith('rates_hz:'):
            self.tuning.rates_hz[p.attribute.split(':', 1)[1]] = float(value)
        elif p.attribute == 'failsafe_action':
            self.tuning.failsafe_action = FailsafeAction(int(value))
        else:
            setattr(self.tuning, p.attribute, float(value))
        return True
