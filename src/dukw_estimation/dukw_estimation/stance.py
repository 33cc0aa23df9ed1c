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
sliding the vehicle at 0.25 Hz, 0.24 m/s^2, changes its acceleration by 0.005 m/s^2 RMS over
half a second at its peak while the speed changes by 0.12 m/s. So the window's mean surge
and sway acceleration, gravity removed with the IMU's attitude, must be small too
(``mean_accel_mps2``; the caller gives the accelerations net of its learnt accelerometer
bias, the attitude error's gravity leak, so the bound is that bias's spread, not its size):
between the peaks, where the mean is small, the acceleration changes fast. Likewise a hull
rolling or pitching at a rate's peak: the window's mean roll and pitch rate must be small
too (``mean_rate_rps``; not the yaw rate, whose gyro bias the filter learns: a vehicle on
the sand cannot turn on the spot with its belts stopped without the acceleration showing).

Blind spot left: a steady drift; a vehicle carried by calm water decelerates by its drag,
0.006 m/s^2 at 0.1 m/s, under the IMU's noise. The caller must rule that out otherwise (the
estimator: not afloat).
"""
from __future__ import annotations

import math
from math import isfinite
from dataclasses import dataclass

import numpy as np
from numba import njit

from dukw_common.readings import ImuSample

_CHANNELS = 6
#: the window's first room, samples (grown when a faster IMU fills it)
_START_CAPACITY = 128


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
        self._times = np.zeros(_START_CAPACITY)              # the window: a ring of samples
        self._z = np.zeros((_START_CAPACITY, _CHANNELS))    # their channels over their noise
        self._raw = np.zeros((_START_CAPACITY, 4))          # and the means' four values
        self._sums = np.zeros(2 * _CHANNELS + 4)            # sum z, sum z^2, sum raw
        self._ring = np.zeros(3, dtype=np.int64)            # oldest, count, added since recompute
        self._since_t = math.nan          # the first sample of the unbroken run
        self._last_t = -math.inf
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
        if math.isnan(self._since_t):
            self._since_t = s.t_s
        self._last_t = s.t_s
        raw = (accel_mps2[0], accel_mps2[1], s.roll_rate_rps, s.pitch_rate_rps)
        sigmas = self._sigmas(s)
        while True:
            result = _push(self._times, self._z, self._raw, self._sums, self._ring, s.t_s,
                           values, sigmas, raw, st.window_s)
            if result[0] >= 0:
                break
            self._grow()
        n = result[0]
        if n < 2 or s.t_s - self._since_t < st.window_s:
            self.statistic = self.mean_accel_mps2 = self.mean_rate_rps = math.nan
            self.still = False
            return False
        return self._decide(*result)

    def _grow(self) -> None:
        """The ring is full (a faster IMU): twice the room, its samples oldest first."""
        head, count = int(self._ring[0]), int(self._ring[1])
        order = (np.arange(count) + head) % self._times.shape[0]
        for name in ('_times', '_z', '_raw'):
            old = getattr(self, name)
            grown = np.zeros((2 * old.shape[0],) + old.shape[1:])
            grown[:count] = old[order]
            setattr(self, name, grown)
        self._ring[0] = 0

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

    def _decide(self, n: int, deviation: float, accel_x: float, accel_y: float, rate_x: float,
                rate_y: float) -> bool:
        """The window's statistic and means from its ``n`` samples' summed squared
        deviations and summed values, and whether all three are under their thresholds."""
        st = self.settings
        self.statistic = deviation / (_CHANNELS * (n - 1))
        self.mean_accel_mps2 = math.hypot(accel_x, accel_y) / n
        self.mean_rate_rps = math.hypot(rate_x, rate_y) / n
        self.still = (self.statistic < st.threshold and self.mean_accel_mps2 < st.mean_accel_mps2
                      and self.mean_rate_rps < st.mean_rate_rps)
        return self.still


@njit(cache=True)
def _push(times: np.ndarray, z: np.ndarray, raw: np.ndarray, sums: np.ndarray,
          ring: np.ndarray, t_s: float, values: tuple, sigmas: tuple, raw_values: tuple,
          window_s: float) -> tuple:
    """One sample into the ring (``ring``: oldest index, count, samples added since the sums
    were recomputed), the samples ``window_s`` older out, the running sums kept (recomputed
    once per window: their rounding). Returns (count, the six channels' summed squared
    deviations from their means, the four raw sums); count -1: the ring is full, nothing
    done. Compiled: the per-channel Python loops were most of the detector's ~6 us a sample
    (issue 16); the sums are the same additions in the same order."""
    capacity = times.shape[0]
    head, count = ring[0], ring[1]
    if count == capacity:
        return -1, 0.0, 0.0, 0.0, 0.0, 0.0
    new = (head + count) % capacity
    times[new] = t_s
    for c in range(6):
        value = values[c] / sigmas[c]
        z[new, c] = value
        sums[c] += value
        sums[6 + c] += value * value
    for c in range(4):
        raw[new, c] = raw_values[c]
        sums[12 + c] += raw_values[c]
    count += 1
    while times[head] <= t_s - window_s:
        for c in range(6):
            sums[c] -= z[head, c]
            sums[6 + c] -= z[head, c] * z[head, c]
        for c in range(4):
            sums[12 + c] -= raw[head, c]
        head = (head + 1) % capacity
        count -= 1
    ring[0], ring[1] = head, count
    ring[2] += 1
    if ring[2] >= count:
        _recompute(z, raw, sums, head, count)
        ring[2] = 0
    deviation = 0.0
    for c in range(6):
        deviation += max(sums[6 + c] - sums[c] * sums[c] / count, 0.0)
    return count, deviation, sums[12], sums[13], sums[14], sums[15]


@njit(cache=True)
def _recompute(z: np.ndarray, raw: np.ndarray, sums: np.ndarray, head: int,
               count: int) -> None:
    """The running sums anew from the window's samples, oldest first."""
    capacity = z.shape[0]
    sums[:] = 0.0
    for k in range(count):
        i = (head + k) % capacity
        for c in range(6):
            sums[c] += z[i, c]
            sums[6 + c] += z[i, c] * z[i, c]
        for c in range(4):
            sums[12 + c] += raw[i, c]


def warm() -> None:
    """Compile (or load) the kernels for the types the detector passes (``make setup`` runs
    this once per build, like ``ekf_kernels.warm``)."""
    detector = StanceDetector(StanceSettings(0.5, 2.0, 0.02, 0.002, 0.05, 0.02))
    for k in range(3):
        detector.add(ImuSample(0.1 * k, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 9.8),
                     (0.0, 0.0))
