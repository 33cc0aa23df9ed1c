"""The Airmar DT800 depth sounder on NMEA 0183: DPT, DBT and MTW to depth readings. ROS-free.

- ``DPT`` (preferred): depth below the transducer (m) and the transducer offset
  (+ to the water line, - to the keel). The DT800 sends an empty depth field
  when it has no bottom lock.
- ``DBT``: depth below the transducer in feet / metres / fathoms; used only while
  no DPT came within ``DPT_PREFERRED_S`` (offset then from the last DPT, else 0).
- ``MTW``: water temperature, degrees C; attached to later readings while younger
  than ``TEMP_MAX_AGE_S``.

The sounder gives no trustworthy depth in water shallower than about 0.5 m
(vehicle.md section 2): any depth below ``min_depth_m`` is reported invalid, NaN.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from dukw_driver.gnss import finite
from dukw_driver.nmea_stream import NmeaStream

FOOT_M = 0.3048
FATHOM_M = 1.8288
DPT_PREFERRED_S = 2.0
TEMP_MAX_AGE_S = 10.0


@dataclass(frozen=True)
class SounderDepth:
    """One dukw_msgs/Depth worth of data as the decoder gives it (before stamping; the
    published reading: dukw_common.readings.DepthReading)."""

    valid: bool
    depth_m: float         # NaN when not valid
    offset_m: float
    water_temp_c: float    # NaN when unknown


class DepthSounderDecoder:
    """Bytes from the sounder in, SounderDepth out; never raises on bad input."""

    def __init__(self, min_depth_m: float) -> None:
        if not finite(min_depth_m) or min_depth_m < 0:
            raise ValueError(f'min_depth_m must be a finite depth >= 0, got {min_depth_m!r}')
        self.min_depth_m = min_depth_m
        self._handlers = {'DPT': self._on_dpt, 'DBT': self._on_dbt, 'MTW': self._on_mtw}
        self.stream = NmeaStream(self._handlers)
        self.counters = self.stream.counters
        self._offset_m = 0.0
        self._last_dpt_s = -math.inf
        self._temp_c = math.nan
        self._temp_time_s = -math.inf

    def feed(self, data: bytes, now_s: float) -> list[SounderDepth]:
        """Decode received bytes at time ``now_s``."""
        return self.stream.decode(data, now_s, self._handlers)

    def water_temp_c(self, now_s: float) -> float:
        """The last water temperature if recent, else NaN."""
        return self._temp_c if now_s - self._temp_time_s <= TEMP_MAX_AGE_S else math.nan

    def _on_dpt(self, dpt, now_s: float) -> SounderDepth:
        offset = _number(dpt.offset) if dpt.offset not in (None, '') else 0.0
        depth = _number(dpt.depth) if dpt.depth not in (None, '') else None
        self._offset_m = offset
        self._last_dpt_s = now_s
        return self._reading(depth, now_s)

    def _on_dbt(self, dbt, now_s: float) -> SounderDepth | None:
        if now_s - self._last_dpt_s < DPT_PREFERRED_S:
            return None
        if dbt.depth_meters not in (None, ''):
            depth = _number(dbt.depth_meters)
        elif dbt.depth_feet not in (None, ''):
            depth = _number(dbt.depth_feet) * FOOT_M
        elif dbt.depth_fathoms not in (None, ''):
            depth = _number(dbt.depth_fathoms) * FATHOM_M
        else:
            depth = None
        return self._reading(depth, now_s)

    def _on_mtw(self, mtw, now_s: float) -> None:
        if mtw.units not in ('C', None, ''):
            raise ValueError(f'MTW in unit {mtw.units!r}, expected C')
        temp = _number(mtw.temperature)
        if not -5.0 <= temp <= 60.0:
            raise ValueError(f'water temperature {temp} degC out of range')
        self._temp_c, self._temp_time_s = temp, now_s

    def _reading(self, depth_m: float | None, now_s: float) -> SounderDepth:
        if depth_m is not None and depth_m < 0:
            raise ValueError(f'negative depth {depth_m}')
        valid = depth_m is not None and depth_m >= self.min_depth_m
        return SounderDepth(valid, depth_m if valid else math.nan, self._offset_m,
                            self.water_temp_c(now_s))


def _number(text) -> float:
    value = float(text)
    if not finite(value):
        raise ValueError(f'not a finite number: {text!r}')
    return value
