"""Discrete state-space models of the vehicle's body velocities from the two commands.

The paper's identified models (vehicle.md section 4, config/reference/paper_models.yaml)
and the ones ``dukw_estimation.sysid`` identifies from zigzags share this form; the
simulator's validation (``dukw_sim.validate``) and the system identification both run and
score them here. A run is a time series of the two side commands (percent) and the body
velocities u, v, r (REP 103: x forward, y left, r positive counter-clockwise).
``simulate`` runs a model on a run's commands (free run, not one-step prediction) and
``fit_pct`` scores it as MATLAB's ``compare`` does: 100 (1 - |y - yhat| / |y - mean(y)|).

Model: x[n+1] = A x[n] + B (u[n] - u_offset), y[n] = C x[n] + D (u[n] - u_offset)
+ y_offset; the one-step predictor adds K (y[n] - yhat[n]).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

INPUTS = ('port_cmd', 'stbd_cmd')
OUTPUTS = ('u', 'v', 'r')
MEDIA = ('land', 'water')
#: The paper's sample period (vehicle.md section 4), s.
PAPER_DT_S = 0.01
#: The paper's model order (vehicle.md section 4).
PAPER_ORDER = 3

class SysIdError(ValueError):
    """The data cannot give (or check) a model: too short, not excited, wrong medium."""


@dataclass
class Run:
    """One recorded run: commands ``u_pct`` (N x 2) and outputs ``y`` (N x 3) at ``t_s``."""

    name: str
    medium: str
    t_s: np.ndarray
    u_pct: np.ndarray
    y: np.ndarray

    @property
    def duration_s(self) -> float:
        """Time from the first to the last sample, s."""
        return float(self.t_s[-1] - self.t_s[0]) if self.t_s.size else 0.0


@dataclass
class Model:
    """A discrete state-space model with its operating point (see the module docstring)."""

    medium: str
    dt_s: float
    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    u_offset: np.ndarray
    y_offset: np.ndarray
    K: np.ndarray | None = None
    fit_pct: dict[str, float] = field(default_factory=dict)
    source: str = ''

    @property
    def order(self) -> int:
        """Number of states."""
        return int(self.A.shape[0])

    def poles(self) -> np.ndarray:
        """Eigenvalues of A (discrete poles)."""
        return np.linalg.eigvals(self.A)

    def dc_gain(self) -> np.ndarray:
        """Steady-state gain d y / d u (3 x 2): C (I - A)^-1 B + D."""
        return self.C @ np.linalg.solve(np.eye(self.order) - self.A, self.B) + self.D

    def to_dict(self) -> dict[str, Any]:
        """Plain lists and numbers, for YAML (readable by anyone with numpy)."""
        out: dict[str, Any] = {
            'medium': self.medium, 'dt_s': float(self.dt_s), 'inputs': list(INPUTS),
            'input_units': 'percent of full scale',
            'outputs': list(OUTPUTS), 'output_units': ['m/s', 'm/s', 'rad/s'],
            'axes': 'REP 103 body axes: x forward, y left, yaw rate counter-clockwise',
            'equations': 'x[n+1] = A x + B (u - u_offset); y = C x + D (u - u_offset) '
                         '+ y_offset',
            'A': self.A.tolist(), 'B': self.B.tolist(), 'C': self.C.tolist(),
            'D': self.D.tolist(), 'u_offset': self.u_offset.tolist(),
            'y_offset': self.y_offset.tolist(),
            'fit_pct': {k: float(v) for k, v in self.fit_pct.items()}, 'source': self.source}
        if self.K is not None:
            out['K'] = self.K.tolist()
        return out

    @classmethod
    def from_dict(cls, data: Any) -> 'Model':
        """Read ``to_dict``'s form back; SysIdError on anything malformed."""
        if not isinstance(data, dict):
            raise SysIdError('a model file must hold a mapping')
        try:
            mats = {k: np.asarray(data[k], dtype=float) for k in
                    ('A', 'B', 'C', 'D', 'u_offset', 'y_offset')}
            k_gain = np.asarray(data['K'], dtype=float) if data.get('K') is not None else None
            model = cls(str(data['medium']), float(data['dt_s']), mats['A'], mats['B'],
                        mats['C'], mats['D'], mats['u_offset'], mats['y_offset'], k_gain,
                        {str(k): float(v) for k, v in (data.get('fit_pct') or {}).items()},
                        str(data.get('source', '')))
        except (KeyError, TypeError, ValueError) as exc:
            raise SysIdError(f'malformed model: {exc}') from exc
        model.validate_shapes()
        return model

    def validate_shapes(self) -> None:
        """Refuse inconsistent matrix sizes, a bad medium or period."""
        n, nu, ny = self.A.shape[0] if self.A.ndim == 2 else 0, len(INPUTS), len(OUTPUTS)
        want = {'A': (n, n), 'B': (n, nu), 'C': (ny, n), 'D': (ny, nu),
                'u_offset': (nu,), 'y_offset': (ny,)}
        if self.K is not None:
            want['K'] = (n, ny)
        for name, shape in want.items():
            value = getattr(self, name)
            if n == 0 or value.shape != shape or not np.all(np.isfinite(value)):
                raise SysIdError(f'malformed model: {name} must be finite of shape {shape}')
        if self.medium not in MEDIA or not self.dt_s > 0.0:
            raise SysIdError(f'malformed model: medium {self.medium!r}, dt_s {self.dt_s}')


def _free_response(model: Model, n: int) -> np.ndarray:
    """Stacked C A^k, k = 0..n-1 ((n * ny) x order): the output of an initial state."""
    rows, power = [], np.eye(model.order)
    for _ in range(n):
        rows.append(model.C @ power)
        power = model.A @ power
    return np.vstack(rows)


def simulate(model: Model, u_pct: np.ndarray, x0: np.ndarray | None = None,
             y_measured: np.ndarray | None = None) -> np.ndarray:
    """Outputs (N x 3) of the model driven by ``u_pct``; with ``y_measured`` and a K, the
    one-step-ahead prediction instead of the free run."""
    du = np.asarray(u_pct, float) - model.u_offset
    x = np.zeros(model.order) if x0 is None else np.asarray(x0, float)
    out = np.empty((du.shape[0], model.C.shape[0]))
    predict = y_measured is not None and model.K is not None
    for n in range(du.shape[0]):
        out[n] = model.C @ x + model.D @ du[n] + model.y_offset
        x = model.A @ x + model.B @ du[n]
        if predict:
            x = x + model.K @ (y_measured[n] - out[n])
    return out


def fit_pct(y: np.ndarray, y_hat: np.ndarray) -> dict[str, float]:
    """MATLAB compare's fit per output, %: 100 (1 - |y - yhat| / |y - mean(y)|)."""
    err = np.linalg.norm(y - y_hat, axis=0)
    spread = np.linalg.norm(y - y.mean(axis=0), axis=0)
    fits = 100.0 * (1.0 - err / np.where(spread > 0, spread, np.nan))
    return {name: (float(f) if math.isfinite(f) else float('-inf'))
            for name, f in zip(OUTPUTS, fits, strict=True)}


@dataclass
class Comparison:
    """A model against one run: free-run and one-step outputs, their fits."""

    run: Run
    y_sim: np.ndarray
    y_one_step: np.ndarray | None
    fit_pct: dict[str, float]
    one_step_fit_pct: dict[str, float] | None


def estimate_initial_state(model: Model, run: Run, horizon: int = 1000) -> np.ndarray:
    """Least-squares initial state over the first ``horizon`` samples (compare's 'e')."""
    n = min(horizon, run.u_pct.shape[0])
    zero_start = simulate(model, run.u_pct[:n])
    x0, *_ = np.linalg.lstsq(_free_response(model, n), (run.y[:n] - zero_start).reshape(-1),
                             rcond=None)
    return x0


def compare(model: Model, run: Run) -> Comparison:
    """Simulate ``model`` on ``run`` (estimated initial state) and score it."""
    x0 = estimate_initial_state(model, run)
    y_sim = simulate(model, run.u_pct, x0)
    y_one = simulate(model, run.u_pct, x0, run.y) if model.K is not None else None
    return Comparison(run, y_sim, y_one, fit_pct(run.y, y_sim),
                      fit_pct(run.y, y_one) if y_one is not None else None)


def with_offsets_of(model: Model, run: Run) -> Model:
    """``model`` with the run's own means as operating point (MATLAB's detrend on the
    validation data): checks the dynamics alone, not the extrapolation between points."""
    return Model(model.medium, model.dt_s, model.A, model.B, model.C, model.D,
                 run.u_pct.mean(axis=0), run.y.mean(axis=0), model.K, dict(model.fit_pct),
                 model.source)


def pooled_fit(comparisons: Sequence[Comparison], one_step: bool = False
               ) -> dict[str, float] | None:
    """Fit over every run together (each run simulated on its own)."""
    preds = [c.y_one_step if one_step else c.y_sim for c in comparisons]
    if any(p is None for p in preds) or not preds:
        return None
    return fit_pct(np.vstack([c.run.y for c in comparisons]), np.vstack(preds))


#: The paper's outputs (x forward, y starboard, yaw rate clockwise) to REP 103.
PAPER_TO_REP103 = np.diag([1.0, -1.0, -1.0])


def paper_model(reference: Any, medium: str) -> Model:
    """The paper's published ``medium`` model (config/reference/paper_models.yaml) in REP
    103 outputs: C and D premultiplied by diag(1, -1, -1). Its operating point is not
    published: the offsets are zero (use ``with_offsets_of`` a run)."""
    try:
        entry = reference[medium]
        a, b, c = (np.asarray(entry[k], float) for k in ('A', 'B', 'C'))
        model = Model(medium, float(entry['dt_s']), a, b, PAPER_TO_REP103 @ c,
                      np.zeros((len(OUTPUTS), len(INPUTS))), np.zeros(len(INPUTS)),
                      np.zeros(len(OUTPUTS)), source=str(reference.get('source', 'paper')))
    except (KeyError, TypeError, ValueError, AttributeError) as exc:
        raise SysIdError(f'malformed paper reference for {medium}: {exc}') from exc
    model.validate_shapes()
    return model


def describe_poles(model: Model) -> list[dict[str, float]]:
    """Each discrete pole with its magnitude and continuous time constant, s."""
    out = []
    for pole in sorted(model.poles(), key=lambda p: -abs(p)):
        mag = abs(pole)
        tau = -model.dt_s / math.log(mag) if 0.0 < mag < 1.0 else float('inf')
        out.append({'re': float(pole.real), 'im': float(pole.imag), 'abs': float(mag),
                    'time_constant_s': tau})
    return out
