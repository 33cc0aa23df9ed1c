"""The estimator's accuracy against the simulator's truth: one scoring rule (ROS-free).

``evaluate`` (fixed actuation, ten scenarios) and campaigns (randomized closed-loop runs)
both score with ``accuracy``.
"""
from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

MOVING_TRACK_MPS = 0.1         # slip is scored only where the track turns

#: what the accuracy is computed from: truth and estimate per scored sample
ACCURACY_COLUMNS = ('x_m', 'y_m', 'yaw_rad', 'est_x_m', 'est_y_m', 'est_yaw_rad',
                    'port_slip', 'stbd_slip', 'est_port_slip', 'est_stbd_slip',
                    'port_track_mps', 'stbd_track_mps', 'volume_m3', 'est_volume_m3',
                    'fraction', 'est_fraction')


def _rms(values: np.ndarray) -> float:
    values = values[np.isfinite(values)]
    return float(np.sqrt(np.mean(np.square(values)))) if values.size else 0.0


def accuracy(col: Mapping[str, np.ndarray], displaced_volume_m3: float) -> dict[str, float]:
    """The estimator's errors against the truth over the samples given (ACCURACY_COLUMNS):
    RMS of position (m), heading (deg), slip where the track turns, submerged volume (% of
    the displacement volume) and weight-on-tracks share."""
    yaw_err = np.remainder(col['est_yaw_rad'] - col['yaw_rad'] + math.pi, 2 * math.pi) - math.pi
    slip_err = np.concatenate([
        (col[f'est_{side}_slip'] - col[f'{side}_slip'])[
            np.abs(col[f'{side}_track_mps']) > MOVING_TRACK_MPS] for side in ('port', 'stbd')])
    return {
        'position_rmse_m': _rms(np.hypot(col['est_x_m'] - col['x_m'],
                                         col['est_y_m'] - col['y_m'])),
        'heading_rmse_deg': math.degrees(_rms(yaw_err)),
        'slip_rmse': _rms(slip_err),
        'volume_error_pct': 100.0 * _rms(col['est_volume_m3'] - col['volume_m3'])
        / displaced_volume_m3,
        'fraction_error': _rms(col['est_fraction'] - col['fraction']),
    }
