"""Benchmark of the estimator core (dukw_estimation): time of one predict + update step.

Target (issue 5): median <= 100 us for one predict+update. The filter is written with
numpy directly (filterpy's generic ExtendedKalmanFilter cannot gate before it updates);
this prints the figures, it does not judge them.

    python benchmarks/bench_ekf.py [--steps N]
"""
from __future__ import annotations

import argparse
import math
import time

import numpy as np

from dukw_common.config import node_params
from dukw_common.geometry import geodetic_from_local_enu
from dukw_common.vehicle import Vehicle, soil_params
from dukw_estimation.ekf import N_STATES, Idx
from dukw_estimation.estimator import Estimator
from dukw_common.readings import DriveStatus, GpsFix, GpsVelocity, ImuSample, MotorSide
from dukw_estimation.settings import EkfSettings
from figures import report


def _stats(name: str, times_s: list[float], target_us: float | None = None) -> None:
    us = np.array(times_s) * 1e6
    report(f'EKF {name} median', float(np.median(us)), 'us', target=target_us)
    print(f'{name:<44} median {np.median(us):7.1f} us   p99 {np.percentile(us, 99):7.1f} us   '
          f'(n={us.size})')


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--steps', type=int, default=5000)
    args = parser.parse_args()
    params = node_params('ekf_node')
    settings = EkfSettings.from_params(params)
    est = Estimator(Vehicle.from_params(params), settings, soil_params(params))
    datum = (settings.datum_latitude_deg, settings.datum_longitude_deg, settings.datum_altitude_m)
    rng = np.random.default_rng(0)
    imu_t, gps_t, vel_t, trk_t, raw_t, out_t = [], [], [], [], [], []
    yaw = 0.0
    for k in range(args.steps):
        t = 0.01 * (k + 1)
        yaw += 0.002
        imu = ImuSample(t, 0.0, 0.05, yaw + rng.normal(0, 0.005), 0.0, 0.0, 0.2, 0.01, 0.2, 9.8)
        t0 = time.perf_counter()
        est.add_imu(imu)                     # predict 10 ms + gyro and heading updates
        imu_t.append(time.perf_counter() - t0)
        if k % 10 == 0:
            lat, lon, alt = geodetic_from_local_enu(math.cos(yaw), math.sin(yaw), 0.0, *datum)
            t0 = time.perf_counter()
            est.add_gps_fix(GpsFix(t + 1e-4, lat, lon, alt))
            gps_t.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            est.add_gps_velocity(GpsVelocity(t + 2e-4, math.cos(yaw), math.sin(yaw)))
            vel_t.append(time.perf_counter() - t0)
        if k % 5 == 0:
            side = MotorSide(60.0, 12.0, 1.2, 90.0)
            t0 = time.perf_counter()
            est.add_tracks(DriveStatus(t + 3e-4, side, side))
            trk_t.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        est.odometry()
        est.traction()
        out_t.append(time.perf_counter() - t0)
    # the bare filter: one 10 ms predict and one scalar update
    ekf = est.ekf
    h = np.zeros(N_STATES)
    h[Idx.R] = h[Idx.BIAS] = 1.0
    for _ in range(args.steps):
        t0 = time.perf_counter()
        ekf.predict(0.01, (0.01, 0.0))
        ekf.update_scalar(0.2, ekf.x[Idx.R] + ekf.x[Idx.BIAS], h, 1e-5, 1e6)
        raw_t.append(time.perf_counter() - t0)
    print(f'dukw_estimation EKF, {N_STATES} states, numpy {np.__version__}')
    _stats('MotionEkf.predict + one scalar update', raw_t, target_us=100.0)
    _stats('Estimator.add_imu (predict + gyro + heading)', imu_t)
    _stats('Estimator.add_gps_fix (predict + 2-D update)', gps_t)
    _stats('Estimator.add_gps_velocity', vel_t)
    _stats('Estimator.add_tracks (force smoothing)', trk_t)
    _stats('odometry() + traction() (outputs)', out_t)
    step_us = (np.array(imu_t) + np.array(out_t)) * 1e6
    print(f'{"IMU step including its outputs":<44} median {np.median(step_us):7.1f} us')
    report('EKF IMU step incl. outputs median (issue 16)', float(np.median(step_us)), 'us',
           target=100.0)
    print('target: median <= 100 us for one predict+update (issue 5)')


if __name__ == '__main__':
    main()
