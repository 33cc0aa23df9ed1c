"""Wet/dry decision for one water-contact sensor: thresholds, hysteresis, debouncing. ROS-free.

The sensor is two leads 6 mm apart (vehicle.md section 2): one on the ADC
module's +5 V, the other on an analog input with a pull-down resistor to ground.
Dry, the input sits near 0; submerged, sea water between the leads pulls it up,
so the level (counts / full scale) rises towards 1. Spray and humidity only
bridge the gap for moments.

- Hysteresis: the level must reach ``wet_on_level`` to look wet and fall to
  ``wet_off_level`` to look dry again; in between the last look is kept.
- Debouncing: the reported state follows the look only after it held for
  ``debounce_s`` without interruption.
"""
from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class ContactSettings:
    """Thresholds (levels 0..1) and debounce time of the wet/dry decision."""

    wet_on_level: float
    wet_off_level: float
    debounce_s: float

    def __post_init__(self) -> None:
        if not 0.0 <= self.wet_off_level < self.wet_on_level <= 1.0:
            raise ValueError('need 0 <= wet_off_level < wet_on_level <= 1, got '
                             f'{self.wet_off_level} and {self.wet_on_level}')
        if not self.debounce_s >= 0.0:
            raise ValueError(f'debounce_s must be >= 0, got {self.debounce_s}')


class WaterContactDetector:
    """Debounced wet/dry state of one sensor from its level samples."""

    def __init__(self, settings: ContactSettings) -> None:
        self.settings = settings
        self.wet = False
        self.level = math.nan
        self._looks_wet = False
        self._since_s: float | None = None   # when the look last differed from the state

    def update(self, level: float, now_s: float) -> bool:
        """Take one level sample (0..1) at ``now_s``; return the debounced wet state.

        A level that is not a number in [0, 1] raises ValueError and changes nothing.
        """
        if not (isinstance(level, (int, float)) and 0.0 <= level <= 1.0):
            raise ValueError(f'water-contact level must be in [0, 1], got {level!r}')
        s = self.settings
        if level >= s.wet_on_level:
            self._looks_wet = True
        elif level <= s.wet_off_level:
            self._looks_wet = False
        self.level = float(level)
        if self._looks_wet == self.wet:
            self._since_s = None
        elif self._since_s is None:
            self._since_s = now_s
        if self._since_s is not None and now_s - self._since_s >= s.debounce_s:
            self.wet = self._looks_wet
            self._since_s = None
        return self.wet
