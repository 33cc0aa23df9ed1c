"""Is the IMU still? A moving-variance stance detector for the zero-velocity update, ROS-free.

Skog et al. 2010 ("Zero-velocity detection -- an algorithm evaluation", IEEE Trans. Biomed.
Eng. 57(11)) compare stance detectors on an IMU's last W samples: the acceleration moving
variance (MV), the angular rate energy (ARE) and their generalized likelihood ratio
(SHOE), each a sum of squared deviations weighted by the sensors' noise variances, compared
with a threshold. This one is the MV form on all six channels: the specific force's and
the angular rates' squared deviations from their window means, each over its noise
variance, summed and divided by their degrees of freedom (6 (n - 1)), so that it is about
1 for an IMU that only measures its noise (its standard deviation sqrt(2 / (6 (n - 1))):
0.08 over 50 samples) and grows with any motion that changes within the window. The rates
are mean-removed too (unlike ARE): a constant gyro bias, which the raw rate energy would
count as motion, does not stop it from firing.

A steady acceleration varies nothing within a window, and Skog's detectors do not see it
either (it tilts the specific force, |f| = sqrt(g^2 + a^2) changes by a^2 / 2g): a wave
sliding the vehicle at 0.25 Hz, 0.24 m/s^2, changes its acceleration by 0.005 m/s^2 RMS
over half a second at its peak while the speed changes by 0.12 m/s. So the window's mean
surge and sway acceleration, gravity removed with the IMU's attitude, must be small too
(``mean_accel_mps2``, the attitude error's gravity leak): between the peaks, where the
mean is small, the acceleration changes fast. Likewise a hull rolling or pitching at a
rate's peak: the window's mean roll and pitch rate must be small too (``mean_rate_rps``; not
the yaw rate, whose gyro bias the filter learns: a vehicle on the sand cannot turn on the
spot with its belts stopped without the acceleration showing).

Blind spot left: a steady drift; a vehicle carried by calm water decelerates by its drag,
0.006 m/s^2 at 0.1 m/s, under the IMU's noise. The caller must rule that out otherwise (the
estimator: not afloat).
"""
from __future__ import annotations

import math
from collections import deque
from math import isfinite
from operator import truediv
from dataclasses import dataclass

from dukw_common.readings import ImuSample

_CHANNELS = 6


@dataclass(frozen=True)
class StanceSettings:
    """The detector's window and threshold, and the noise used where a sample carries none."""

    window_s: float                  # samples within this long before the latest
    threshold: float                 # still below this ratio of the statistic to its noise value
    accel_sigma_mps2: float          # specific force noise (per axis)
    gyro_sigma_rps: float            # angular rate noise (per axis)
    mean_accel_mps2: float           # still while the window's mean gravity-free surge and
                                     # sway acceleration is under this
    mean_rate_rps: float             # and its mean roll and pitch rate under this

    def __post_init__(self) -> None:
        for name in ('window_s', 'threshold', 'accel_sigma_mps2', 'gyro_sigma_rps',
                     'mean_accel_mps2', 'mean_rate_rps'):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise ValueError(f'StanceSettings.{name} must be a positive number, got {value}')
        if self.threshold <= 1.0:
            raise ValueError('StanceSettings.threshold must exceed 1 (the statistic of an IMU '
                             f'measuring only its noise), got {self.threshold}')


def _sigma(var: float, default: float) -> float:
    return math.sqrt(var) if math.isfinite(var) and var > 0.0 else default


class StanceDetector:
    """Feed IMU samples in time order with their gravity-free surge and sway acceleration
    (``add``); ``still`` says whether the last window's motion is within the noise and its
    mean acceleration and roll and pitch rates small. A gap longer than half the window, a
    sample out of order or one without accelerations starts the window again."""

    def __init__(self, settings: StanceSettings) -> None:
        self.settings = settings
        self._sigmas_of: tuple[tuple, tuple[float, ...]] = ((), ())   # (variances, sigmas)
        self.reset()

    def reset(self) -> None:
        """Forget the window."""
        self._window: deque[tuple[float, tuple[float, ...], tuple[float, ...]]] = deque()
        self._sum = [0.0] * _CHANNELS
        self._sum_sq = [0.0] * _CHANNELS
        self._sum_mean = [0.0] * 4        # gravity-free surge, sway accel; roll, pitch rate
        self._since_t = math.nan          # the first sample of the unbroken run
        self._last_t = -math.inf
        self._added = 0                   # since the sums were last recomputed
        self.statistic = math.nan         # the last window's statistic (1 ~ noise alone)
        self.mean_accel_mps2 = math.nan   # and its mean gravity-free acceleration
        self.mean_rate_rps = math.nan     # and its mean roll and pitch rate
        self.still = False

    def add(self, s: ImuSample, accel_mps2: tuple[float, float]) -> bool:
        """Take one sample and its gravity-free surge and sway acceleration ``accel_mps2``;
        returns (and keeps in ``still``) the decision for its window."""
        st = self.settings
        values = (s.accel_x_mps2, s.accel_y_mps2, s.accel_z_mps2, s.roll_rate_rps,
                  s.pitch_rate_rps, s.yaw_rate_rps)
        finite = (isfinite(s.t_s) and all(map(isfinite, values))
                  and isfinite(accel_mps2[0]) and isfinite(accel_mps2[1]))
        if not finite or s.t_s <= self._last_t or s.t_s - self._last_t > 0.5 * st.window_s:
            self.reset()
            if not finite:
                return False
        z = tuple(map(truediv, values, self._sigmas(s)))      # (six of each)
        if math.isnan(self._since_t):
            self._since_t = s.t_s
        self._last_t = s.t_s
        window, total, total_sq = self._window, self._sum, self._sum_sq
        means = self._sum_mean
        raw = (accel_mps2[0], accel_mps2[1], s.roll_rate_rps, s.pitch_rate_rps)
        window.append((s.t_s, z, raw))
        for i in range(_CHANNELS):
            total[i] += z[i]
            total_sq[i] += z[i] * z[i]
        for i in range(4):
            means[i] += raw[i]
        while window[0][0] <= s.t_s - st.window_s:
            _, old, old_raw = window.popleft()
            for i in range(_CHANNELS):
                total[i] -= old[i]
                total_sq[i] -= old[i] * old[i]
            for i in range(4):
                means[i] -= old_raw[i]
        self._added += 1
        n = len(window)
        if self._added >= n:              # the running sums' rounding, once per window
            self._recompute()
        if n < 2 or s.t_s - self._since_t < st.window_s:
            self.statistic = self.mean_accel_mps2 = self.mean_rate_rps = math.nan
            self.still = False
            return False
        return self._decide(n)

    def _sigmas(self, s: ImuSample) -> tuple[float, ...]:
        """The six channels' noise: the sample's own variances, else the settings' (the
        last sample's, when it gave the same variances: an IMU's rarely change)."""
        key = (s.accel_var_m2ps4, s.roll_rate_var_rps2, s.pitch_rate_var_rps2,
               s.yaw_rate_var_rps2)
        if key != self._sigmas_of[0]:
            self._sigmas_of = (key, self._noise(s))
        return self._sigmas_of[1]

    def _noise(self, s: ImuSample) -> tuple[float, ...]:
        st = self.settings
        ax_var, ay_var, az_var = s.accel_var_m2ps4
        return (_sigma(ax_var, st.accel_sigma_mps2), _sigma(ay_var, st.accel_sigma_mps2),
                _sigma(az_var, st.accel_sigma_mps2),
                _sigma(s.roll_rate_var_rps2, st.gyro_sigma_rps),
                _sigma(s.pitch_rate_var_rps2, st.gyro_sigma_rps),
                _sigma(s.yaw_rate_var_rps2, st.gyro_sigma_rps))

    def _decide(self, n: int) -> bool:
        """The window's statistic and means from the running sums of its ``n`` samples, and
        whether all three are under their thresholds."""
        st = self.settings
        total, total_sq = self._sum, self._sum_sq
        deviation = sum(max(total_sq[i] - total[i] * total[i] / n, 0.0)
                        for i in range(_CHANNELS))
        self.statistic = deviation / (_CHANNELS * (n - 1))
        means = self._sum_mean
        self.mean_accel_mps2 = math.hypot(means[0], means[1]) / n
        self.mean_rate_rps = math.hypot(means[2], means[3]) / n
        self.still = (self.statistic < st.threshold and self.mean_accel_mps2 < st.mean_accel_mps2
                      and self.mean_rate_rps < st.mean_rate_rps)
        return self.still

    def _recompute(self) -> None:
        window = self._window
        self._sum = [sum(z[i] for _, z, _ in window) for i in range(_CHANNELS)]
        self._sum_sq = [sum(z[i] * z[i] for _, z, _ in window) for i in range(_CHANNELS)]
        self._sum_mean = [sum(a[k] for _, _, a in window) for k in range(4)]
        self._added = 0
