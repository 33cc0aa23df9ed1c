"""The stance detector (stance.py) on synthetic IMU streams."""
import math

import numpy as np
import pytest

from dukw_common.readings import ImuSample
from dukw_estimation.stance import StanceDetector, StanceSettings

G = 9.81
SETTINGS = StanceSettings(window_s=0.5, threshold=2.0, accel_sigma_mps2=0.01,
                          gyro_sigma_rps=0.003, mean_accel_mps2=0.1, mean_rate_rps=0.02)


def _feed(detector, seconds, t0=0.0, seed=0, accel=lambda t: 0.0, roll_rate=lambda t: 0.0,
          gyro_bias=0.0):
    """An IMU at 100 Hz with its noise; returns (still, statistic) after each sample."""
    rng = np.random.default_rng(seed)
    n = rng.normal
    out = []
    for k in range(1, int(round(seconds / 0.01)) + 1):
        t = t0 + k * 0.01
        a = accel(t)
        s = ImuSample(t, 0.0, 0.0, 0.0, roll_rate(t) + n(0, 0.003), n(0, 0.003),
                      gyro_bias + n(0, 0.003), a + n(0, 0.01), n(0, 0.01), G + n(0, 0.01))
        out.append((detector.add(s, (a + n(0, 0.01), n(0, 0.01))), detector.statistic))
    return out


def test_an_imu_measuring_only_its_noise_is_still_a_gyro_bias_does_not_matter():
    detector = StanceDetector(SETTINGS)
    out = _feed(detector, 3.0, gyro_bias=0.01)          # 3 sigma of bias on the yaw rate
    assert not any(still for still, _ in out[:49])     # the first window is not full yet
    statistics = [stat for _, stat in out[60:]]
    assert np.mean(statistics) == pytest.approx(1.0, abs=0.1)
    assert all(still for still, _ in out[60:])


def test_rolling_in_the_waves_is_motion():
    """The rate changes within the window, or near its peaks its mean is large."""
    detector = StanceDetector(SETTINGS)
    out = _feed(detector, 5.0, roll_rate=lambda t: 0.05 * math.sin(2 * math.pi * 0.3 * t))
    assert not any(still for still, _ in out)
    blind = StanceDetector(StanceSettings(0.5, 2.0, 0.01, 0.003, 0.1, mean_rate_rps=1.0))
    out = _feed(blind, 5.0, roll_rate=lambda t: 0.05 * math.sin(2 * math.pi * 0.3 * t))
    assert any(still for still, _ in out)            # the variance alone misses the peaks


def test_a_steady_push_varies_nothing_but_its_mean_is_motion():
    detector = StanceDetector(SETTINGS)
    out = _feed(detector, 2.0, accel=lambda t: 0.24)
    assert np.mean([stat for _, stat in out[60:]]) < SETTINGS.threshold
    assert not any(still for still, _ in out)
    assert detector.mean_accel_mps2 == pytest.approx(0.24, abs=0.01)


def test_a_gap_or_a_sample_without_accelerations_starts_the_window_again():
    detector = StanceDetector(SETTINGS)
    _feed(detector, 1.0)
    assert detector.still
    out = _feed(detector, 1.0, t0=1.5)                  # 0.5 s silent: more than half a window
    assert not out[0][0] and not out[40][0] and out[-1][0]
    nan = ImuSample(2.6, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, math.nan, math.nan, math.nan)
    assert not detector.add(nan, (math.nan, math.nan))
    assert not _feed(detector, 0.3, t0=2.6)[-1][0]


@pytest.mark.parametrize('bad', [{'threshold': 1.0}, {'window_s': 0.0},
                                 {'accel_sigma_mps2': math.nan}, {'mean_accel_mps2': -1.0}])
def test_bad_settings_are_refused(bad):
    values = dict(window_s=0.5, threshold=2.0, accel_sigma_mps2=0.01, gyro_sigma_rps=0.003,
                  mean_accel_mps2=0.1, mean_rate_rps=0.02)
    values.update(bad)
    with pytest.raises(ValueError, match=next(iter(bad))):
        StanceSettings(**values)


def test_the_noise_follows_the_samples_own_variances_when_they_change():
    """The six sigmas are kept while the samples' variances stay; once an IMU reports four
    times the variance, the same motion counts a quarter as much."""
    changing, reference = StanceDetector(SETTINGS), StanceDetector(SETTINGS)
    rng = np.random.default_rng(3)
    for k in range(1, 201):
        t, noise = k * 0.01, rng.normal(0.0, 0.01, 6)
        values = (t, 0.0, 0.0, 0.0, *(0.003 / 0.01 * noise[:3]), *noise[3:5], G + noise[5])
        variances = [math.nan] * 6 + [(1e-4,) * 3]
        if k > 100:                     # from here on 4x the default variances, all six
            variances = [math.nan, 3.6e-5, math.nan, math.nan, 3.6e-5, 3.6e-5, (4e-4,) * 3]
        changing.add(ImuSample(*values, *variances), (noise[3], noise[4]))
        if k > 100:
            reference.add(ImuSample(*values, *variances), (noise[3], noise[4]))
    assert reference.statistic == pytest.approx(changing.statistic, rel=1e-9)
    assert changing.statistic == pytest.approx(0.25, rel=0.5)


def _window_figures(rows, raws, window_s):
    """The statistic, mean acceleration and mean rate of the samples within ``window_s`` of
    the last one, computed from scratch."""
    last_t = rows[-1][0]
    window = [k for k, (t, _) in enumerate(rows) if t > last_t - window_s]
    z, n = np.array([rows[k][1] for k in window]), len(window)
    statistic = np.sum(np.sum(z * z, axis=0) - np.sum(z, axis=0) ** 2 / n) / (6 * (n - 1))
    means = np.array([raws[k] for k in window]).mean(axis=0)
    return n, statistic, math.hypot(means[0], means[1]), math.hypot(means[2], means[3])


def test_a_fast_imu_fills_a_longer_window_and_the_statistic_is_the_windows():
    """After 2 s at 100 Hz (the ring has wrapped) the IMU goes to 1 kHz: the 0.5 s window
    then holds 500 samples (the ring grows past its first room, oldest first); after every
    sample the statistic and means are those of exactly the samples of the last window_s."""
    detector = StanceDetector(SETTINGS)
    rng = np.random.default_rng(5)
    sigmas = np.array([0.01] * 3 + [0.003] * 3)
    rows, raws, sizes = [], [], set()
    for k in range(1, 1201):
        t = k * 0.01 if k <= 200 else 2.0 + (k - 200) * 0.001
        values = rng.normal(0.0, 1.0, 6) * sigmas + np.array([0, 0, G, 0.02 * t, 0, 0])
        accel = (float(rng.normal(0.0, 0.01)), 0.05)
        detector.add(ImuSample(t, 0.0, 0.0, 0.0, *values[3:], *values[:3]), accel)
        rows.append((t, values / sigmas))
        raws.append((accel[0], accel[1], values[3], values[4]))
        if k < 60:
            continue
        n, statistic, mean_accel, mean_rate = _window_figures(rows, raws, SETTINGS.window_s)
        sizes.add(n)
        assert detector.statistic == pytest.approx(statistic, rel=1e-9), k
        assert detector.mean_accel_mps2 == pytest.approx(mean_accel, rel=1e-9), k
        assert detector.mean_rate_rps == pytest.approx(mean_rate, rel=1e-9), k
    assert max(sizes) >= 500           # (501 where t - window_s rounds onto a sample)
