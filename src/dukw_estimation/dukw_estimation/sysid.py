"""System identification core: recorded runs -> discrete state-space model.

ROS-free (numpy, scipy, nfoursid). Runs, models, simulation and the fit score are
``dukw_model.state_space`` (shared with the simulator's validation). ``resample`` puts a
run on a fixed period (commands held, outputs interpolated), ``identify`` removes and
records the operating point (means) and fits a model with N4SID (the ``nfoursid``
package, Verhaegen's PO-MOESP form).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np
import scipy.linalg

from dukw_model.state_space import (INPUTS, MEDIA, OUTPUTS, PAPER_DT_S, PAPER_ORDER, Model, Run,
                                    SysIdError, compare, fit_pct)

#: Block rows of the Hankel matrices: 0.1 s of past and future at the paper's period.
DEFAULT_BLOCK_ROWS = 10
#: Shortest run accepted, s: three of the paper's 10 s zigzag half-periods would be 30 s;
#: below one half-period there is no turn reversal to learn from.
DEFAULT_MIN_DURATION_S = 5.0
#: An input that stays within this band of its most common value ...
EXCITATION_BAND_PCT = 0.5
#: ... for more than this share of the run does not excite the vehicle.
EXCITATION_MAX_STILL_FRACTION = 0.95


def _hold(t_src: np.ndarray, values: np.ndarray, t_new: np.ndarray) -> np.ndarray:
    """Zero-order hold: the last value at or before each new time (commands are held)."""
    idx = np.clip(np.searchsorted(t_src, t_new, side='right') - 1, 0, t_src.size - 1)
    return values[idx]


def resample(run: Run, dt_s: float = PAPER_DT_S, t_u_s: np.ndarray | None = None) -> Run:
    """``run`` on a uniform grid of ``dt_s``: commands held, outputs interpolated.

    ``t_u_s`` gives the commands' own time stamps when they differ from ``run.t_s``.
    """
    if not dt_s > 0.0:
        raise SysIdError(f'the sample period must be > 0, got {dt_s}')
    t_u = run.t_s if t_u_s is None else np.asarray(t_u_s, float)
    if run.t_s.size < 2 or t_u.size < 1:
        raise SysIdError(f'{run.name}: too short a run ({run.t_s.size} samples)')
    start, end = max(run.t_s[0], t_u[0]), run.t_s[-1]
    t_new = start + dt_s * np.arange(int(math.floor((end - start) / dt_s + 1e-9)) + 1)
    y = np.column_stack([np.interp(t_new, run.t_s, run.y[:, j]) for j in range(run.y.shape[1])])
    return Run(run.name, run.medium, t_new, _hold(t_u, run.u_pct, t_new), y)


def check_run(run: Run, medium: str, min_duration_s: float = DEFAULT_MIN_DURATION_S) -> None:
    """Refuse a run that cannot identify or check a ``medium`` model (SysIdError)."""
    if medium not in MEDIA:
        raise SysIdError(f'unknown medium {medium!r}; known: {MEDIA}')
    if run.medium != medium:
        raise SysIdError(f'{run.name}: recorded {run.medium}, but the model is for {medium} '
                         '(mismatched media)')
    if run.duration_s < min_duration_s:
        raise SysIdError(f'{run.name}: too short a run ({run.duration_s:.2f} s < '
                         f'{min_duration_s:g} s)')
    if not (np.all(np.isfinite(run.u_pct)) and np.all(np.isfinite(run.y))):
        raise SysIdError(f'{run.name}: commands or velocities hold NaN/inf')
    for j, name in enumerate(INPUTS):
        col = run.u_pct[:, j]
        values, counts = np.unique(np.round(col / EXCITATION_BAND_PCT), return_counts=True)
        still = np.mean(np.abs(col - values[np.argmax(counts)] * EXCITATION_BAND_PCT)
                        <= EXCITATION_BAND_PCT)
        if still > EXCITATION_MAX_STILL_FRACTION:
            raise SysIdError(f'{run.name}: no excitation: {name} stays at one value for '
                             f'{100 * still:.0f} % of the run (a zigzag swaps the sides)')


@dataclass
class Identification:
    """What ``identify`` found: the model and the singular values for the order."""

    model: Model
    singular_values: np.ndarray
    suggested_order: int


def _stack(runs: Sequence[Run]) -> tuple[np.ndarray, np.ndarray]:
    return np.vstack([r.u_pct for r in runs]), np.vstack([r.y for r in runs])


def suggest_order(singular_values: np.ndarray, max_order: int = 10) -> int:
    """The order before the largest drop (log ratio) of consecutive singular values."""
    s = np.asarray(singular_values, float)[:max_order + 1]
    s = s[s > 0]
    if s.size < 2:
        return 1
    return int(np.argmax(np.log(s[:-1] / s[1:]))) + 1


def _kalman_gain(A, C, noise_cov: np.ndarray, ny: int) -> np.ndarray | None:
    """Predictor gain from nfoursid's [[R, S^T], [S, Q]] residual covariance (DARE)."""
    r, s, q = noise_cov[:ny, :ny], noise_cov[ny:, :ny], noise_cov[ny:, ny:]
    try:
        p = scipy.linalg.solve_discrete_are(A.T, C.T, q, r, s=s)
        return (A @ p @ C.T + s) @ np.linalg.inv(C @ p @ C.T + r)
    except (np.linalg.LinAlgError, ValueError):
        return None


def identify(runs: Sequence[Run], medium: str, order: int = PAPER_ORDER,
             block_rows: int = DEFAULT_BLOCK_ROWS,
             min_duration_s: float = DEFAULT_MIN_DURATION_S) -> Identification:
    """N4SID model of ``medium`` from resampled ``runs`` (all of one period)."""
    import pandas as pd
    from nfoursid.nfoursid import NFourSID
    if not runs:
        raise SysIdError('no runs given')
    for run in runs:
        check_run(run, medium, min_duration_s)
    dts = {round(float(np.mean(np.diff(r.t_s))), 9) for r in runs}
    if len(dts) != 1:
        raise SysIdError(f'runs of different sample periods {sorted(dts)}: resample first')
    if not 1 <= order <= block_rows * len(OUTPUTS):
        raise SysIdError(f'order must be in 1..{block_rows * len(OUTPUTS)}, got {order}')
    u, y = _stack(runs)
    u_offset, y_offset = u.mean(axis=0), y.mean(axis=0)
    frame = pd.DataFrame(np.column_stack([u - u_offset, y - y_offset]),
                         columns=list(INPUTS) + list(OUTPUTS))
    n4sid = NFourSID(frame, output_columns=list(OUTPUTS), input_columns=list(INPUTS),
                     num_block_rows=block_rows)
    n4sid.subspace_identification()
    singular = np.diagonal(n4sid.R32_decomposition.eigenvalues).copy()
    ss, noise_cov = n4sid.system_identification(rank=order)
    k_gain = _kalman_gain(ss.a, ss.c, noise_cov, len(OUTPUTS))
    model = Model(medium, dts.pop(), ss.a, ss.b, ss.c, ss.d, u_offset, y_offset, k_gain,
                  source='nfoursid N4SID (PO-MOESP) on ' + ', '.join(r.name for r in runs))
    model.fit_pct = fit_pct(np.vstack([r.y for r in runs]),
                            np.vstack([compare(model, r).y_sim for r in runs]))
    return Identification(model, singular, suggest_order(singular))


