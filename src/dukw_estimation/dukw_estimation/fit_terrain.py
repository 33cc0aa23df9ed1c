"""fit_terrain BAG: fit the soil's c, phi, k to the track forces in a recorded rosbag2.

The paper's method (vehicle.md section 6, its Table XIII): least squares of the modified
Wong model H(i, W_e; c, phi, k) to the measured track forces (current x gain,
Kalman-smoothed, less the drivetrain friction: the soil's share), with the
slip and effective weight the estimator published on ``traction`` (dukw_msgs/Traction).
Prints each parameter with its standard deviation (from the Jacobian at the solution) and
the residual; refuses when the slip hardly varies (then c, phi and k cannot be told apart).

    install/lib/dukw_estimation/fit_terrain BAG [--topic traction] [--min-slip-spread 0.05]
                                            [--slip-range 0.05 0.95]
"""
from __future__ import annotations

import argparse
import math
import os
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np
from scipy.optimize import least_squares

from dukw_common.config import ConfigError
from dukw_common.vehicle import SoilParams, Vehicle
from dukw_model import traction

TRACTION_TYPE = 'dukw_msgs/msg/Traction'
MIN_SAMPLES = 20
#: Bounds of (cohesion Pa, friction angle rad, shear modulus m).
LOWER = np.array([0.0, 0.0, 1e-4])
UPPER = np.array([2e4, 1.2, 0.5])
#: Condition number of the scaled normal matrix beyond which the fit is refused (a good
#: fit is ~1e3; c and phi on a constant weight are collinear, ~1e16).
MAX_CONDITION = 1e8
#: |slip| used by default: past the grip regime, short of the clipped slip of a stopped track.
SLIP_RANGE = (0.05, 0.95)


class FitError(ValueError):
    """The data cannot identify the soil (too little slip variation, too few samples)."""


@dataclass(frozen=True)
class TractionSamples:
    """Per-track samples: slip, the track's share of the effective weight, measured force."""

    slip: np.ndarray
    weight_n: np.ndarray
    force_n: np.ndarray


@dataclass(frozen=True)
class SoilFit:
    """Fitted soil, one-sigma uncertainties and the residual."""

    soil: SoilParams
    sigma: tuple[float, float, float]      # cohesion Pa, friction angle rad, shear modulus m
    residual_rms_n: float
    samples: int

    def report(self) -> str:
        """Human-readable lines, the paper's units."""
        c, phi, k = self.soil.cohesion_pa, self.soil.friction_angle_rad, self.soil.shear_modulus_m
        sc, sphi, sk = self.sigma
        return '\n'.join([
            f'track samples: {self.samples}',
            f'cohesion c          = {c / 1000:.3f} +- {sc / 1000:.3f} kPa',
            f'friction angle phi  = {math.degrees(phi):.2f} +- {math.degrees(sphi):.2f} deg '
            f'({phi:.4f} rad)',
            f'shear modulus k     = {k * 100:.2f} +- {sk * 100:.2f} cm',
            f'residual rms        = {self.residual_rms_n:.1f} N',
            f'as config: {{cohesion_pa: {c:.1f}, friction_angle_rad: {phi:.4f}, '
            f'shear_modulus_m: {k:.4f}}}'])


def fit_soil(samples: TractionSamples, contact_area_m2: float, contact_length_m: float,
             min_slip_spread: float = 0.05, initial: SoilParams | None = None,
             slip_range: tuple[float, float] = SLIP_RANGE) -> SoilFit:
    """Least-squares c, phi, k; FitError when the data cannot identify them.

    Only samples with |slip| within ``slip_range`` are used: below it the tracks grip and
    the force is whatever holds them (static friction, not the Wong curve); at the top the
    slip is clipped (a stopped track under a moving vehicle).
    """
    lo_slip, hi_slip = slip_range
    ok = (np.isfinite(samples.slip) & np.isfinite(samples.weight_n) & np.isfinite(samples.force_n)
          & (samples.weight_n > 0.0) & (np.abs(samples.slip) >= lo_slip)
          & (np.abs(samples.slip) <= hi_slip))
    slip, weight, force = samples.slip[ok], samples.weight_n[ok], samples.force_n[ok]
    if slip.size < MIN_SAMPLES:
        raise FitError(f'only {slip.size} usable samples (tracks on the ground, finite values, '
                       f'|slip| {lo_slip:g}-{hi_slip:g}); need at least {MIN_SAMPLES}')
    lo, hi = np.percentile(np.abs(slip), [5, 95])
    if hi - lo < min_slip_spread:
        raise FitError(f'the slip hardly varies (|i| from {lo:.3f} to {hi:.3f}, 5-95 %, spread '
                       f'{hi - lo:.3f} < {min_slip_spread}): c, phi and k cannot be told apart. '
                       'Record runs at several commands or across the transition.')
    start = initial or SoilParams(200.0, math.radians(10.0), 0.05)

    def residuals(p: np.ndarray) -> np.ndarray:
        soil = SoilParams(p[0], p[1], p[2])
        return traction.tractive_force_n(slip, weight, soil, contact_area_m2,
                                         contact_length_m) - force

    x0 = np.clip([start.cohesion_pa, start.friction_angle_rad, max(start.shear_modulus_m, 1e-3)],
                 LOWER, UPPER)
    scale = np.array([100.0, 0.1, 0.01])
    result = least_squares(residuals, x0, bounds=(LOWER, UPPER), x_scale=scale)
    dof = max(slip.size - 3, 1)
    s2 = float(np.sum(result.fun ** 2)) / dof
    scaled = result.jac * scale
    try:
        cov = np.linalg.inv(result.jac.T @ result.jac) * s2
        sigma = tuple(float(math.sqrt(max(v, 0.0))) for v in np.diag(cov))
    except np.linalg.LinAlgError:
        sigma = (math.inf, math.inf, math.inf)
    if not all(math.isfinite(v) for v in sigma) \
            or not np.linalg.cond(scaled.T @ scaled) < MAX_CONDITION:
        spread = float(np.ptp(weight))
        raise FitError('the samples do not determine c, phi and k (singular fit, residual '
                       f'{math.sqrt(np.mean(result.fun ** 2)):.0f} N): c and phi need the '
                       f'weight on the tracks to vary (it spans {spread:.0f} N here), k needs '
                       'slips on the rising part of the curve. Record straight runs at '
                       'several commands and across the transition.')
    p = result.x
    return SoilFit(SoilParams(float(p[0]), float(p[1]), float(p[2])), sigma,
                   float(math.sqrt(np.mean(result.fun ** 2))), int(slip.size))


def msg_dir() -> Path:
    """The dukw_msgs .msg folder: installed share (ament index), else the source tree."""
    try:
        from ament_index_python.packages import get_package_share_directory
        return Path(get_package_share_directory('dukw_msgs')) / 'msg'
    except Exception:  # no ament index here (plain source checkout)
        return Path(__file__).resolve().parents[2] / 'dukw_msgs' / 'msg'


def typestore():
    """rosbags' ROS 2 Jazzy types plus dukw_msgs/Traction from its .msg text."""
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore
    store = get_typestore(Stores.ROS2_JAZZY)
    text = (msg_dir() / 'Traction.msg').read_text()
    store.register(get_types_from_msg(text, TRACTION_TYPE))
    return store


def read_samples(bag: str | os.PathLike, topic: str = 'traction') -> TractionSamples:
    """Both tracks' (slip, W_e / 2, measured force) from a bag's Traction messages."""
    from rosbags.rosbag2 import Reader
    path = Path(bag)
    if not (path / 'metadata.yaml').is_file():
        raise FitError(f'{path}: not a rosbag2 folder (no metadata.yaml)')
    store = typestore()
    rows = []
    with Reader(path) as reader:
        conns = [c for c in reader.connections
                 if c.msgtype == TRACTION_TYPE and c.topic.strip('/').endswith(topic.strip('/'))]
        if not conns:
            raise FitError(f'{path}: no {TRACTION_TYPE} messages on a topic named {topic!r}')
        for conn, _, raw in reader.messages(connections=conns):
            m = store.deserialize_cdr(raw, conn.msgtype)
            half = 0.0 if m.afloat else 0.5 * m.effective_weight_n
            rows.append((m.port_slip, half, m.port_force_measured_n))
            rows.append((m.stbd_slip, half, m.stbd_force_measured_n))
    data = np.array(rows, dtype=float).reshape(-1, 3)
    return TractionSamples(data[:, 0], data[:, 1], data[:, 2])


def main(argv: Sequence[str] | None = None) -> int:
    """Console-script entry point: 0 fitted, 1 refused (data), 2 bad input."""
    parser = argparse.ArgumentParser(prog='fit_terrain', description=__doc__.split('\n\n')[0])
    parser.add_argument('bag', help='rosbag2 folder with dukw_msgs/Traction messages')
    parser.add_argument('--topic', default='traction', help='traction topic (default: traction)')
    parser.add_argument('--min-slip-spread', type=float, default=0.05,
                        help='refuse when the 5-95 %% range of |slip| is narrower (default 0.05)')
    parser.add_argument('--slip-range', type=float, nargs=2, default=SLIP_RANGE,
                        metavar=('MIN', 'MAX'), help='|slip| of the samples used (default '
                        f'{SLIP_RANGE[0]} {SLIP_RANGE[1]}: not gripping, not a stopped track)')
    parser.add_argument('--config', help="parameter file (default: the stack's)")
    args = parser.parse_args(argv)
    try:
        vehicle = Vehicle.load(args.config)
        body = vehicle.body
        samples = read_samples(args.bag, args.topic)
        fit = fit_soil(samples, body.track_width_m * body.track_contact_length_m,
                       body.track_contact_length_m, args.min_slip_spread, vehicle.soil,
                       tuple(args.slip_range))
    except FitError as exc:
        print(f'fit_terrain: refused: {exc}', file=sys.stderr)
        return 1
    except ConfigError as exc:
        print(f'fit_terrain: {exc}', file=sys.stderr)
        return 2
    print(fit.report())
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
