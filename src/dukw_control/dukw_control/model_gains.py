"""PI gains of the drive controller from identified models (sysid), by IMC / lambda tuning.

ROS-free; reads the model files ``sysid identify`` writes (numpy + YAML only:
x[n+1] = A x + B (u - u_offset), y = C x + D (u - u_offset) + y_offset, inputs
port/stbd %, outputs u, v, r). Per medium the model gives two first-order channels,
each from a simulated step: surge speed per % of common command (both sides) and yaw
rate per % of differential command (stbd up, port down): gain K and the time to 63 %
of the final value, tau. The PI corrector's output is a velocity added to the setpoint
before the mixer, so the plant it sees is mixer then vehicle: K_loop = K x (% per unit
of velocity of the mixer at the model's operating point). IMC (lambda) tuning of a
first-order plant, closed-loop time constant lambda = lambda_factor x tau:

    kp = tau / (K_loop lambda),   ki = kp / tau = 1 / (K_loop lambda)

(Skogestad's SIMC rule without dead time). Afloat the mixer's yaw map is quadratic
(moment ~ r|r|, no slope at r = 0), so its slope is taken at half the yaw rate of full
moment.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import yaml

if TYPE_CHECKING:
    from dukw_control.controller import ControllerSettings

#: Step size of the simulated steps, % (small against the range, large against noise).
STEP_PCT = 10.0
#: Length of the simulated steps, s (the paper's water model settles within ~40 s).
STEP_LENGTH_S = 60.0
#: Gains are clamped to the controller's parameter ranges (controller.NODE_PARAMS).
MAX_GAIN = 10.0


class ModelGainError(ValueError):
    """A model file that cannot give gains (unreadable, unstable, no response)."""


@dataclass(frozen=True)
class PiGains:
    """Speed and yaw-rate PI gains of one medium."""

    speed_kp: float
    speed_ki: float
    yaw_kp: float
    yaw_ki: float


@dataclass(frozen=True)
class Channel:
    """A first-order approximation: gain per % and time constant, s."""

    gain_per_pct: float
    tau_s: float


def load_model(path: str | Path) -> dict:
    """The model file's matrices as numpy arrays, plus medium, dt_s and offsets."""
    try:
        data = yaml.safe_load(Path(path).read_text())
        model = {k: np.asarray(data[k], float) for k in ('A', 'B', 'C', 'D', 'y_offset',
                                                         'u_offset')}
        model['medium'], model['dt_s'] = str(data['medium']), float(data['dt_s'])
    except (OSError, yaml.YAMLError, KeyError, TypeError, ValueError) as exc:
        raise ModelGainError(f'{path}: not a sysid model file: {exc}') from exc
    n = model['A'].shape[0]
    if model['A'].shape != (n, n) or model['B'].shape != (n, 2) or model['C'].shape != (3, n):
        raise ModelGainError(f'{path}: model matrices of the wrong shapes')
    if np.max(np.abs(np.linalg.eigvals(model['A']))) >= 1.0:
        raise ModelGainError(f'{path}: the model is unstable (a pole on or outside |z| = 1)')
    return model


def step_channel(model: dict, du_pct: np.ndarray, output: int) -> Channel:
    """Gain and 63 % time of ``output`` after a step ``du_pct`` of the inputs."""
    a, b, c, d = model['A'], model['B'], model['C'], model['D']
    steps = int(STEP_LENGTH_S / model['dt_s'])
    x, y = np.zeros(a.shape[0]), np.empty(steps)
    for k in range(steps):
        y[k] = c[output] @ x + d[output] @ du_pct
        x = a @ x + b @ du_pct
    final = float(np.linalg.solve(np.eye(a.shape[0]) - a, b @ du_pct) @ c[output]
                  + d[output] @ du_pct)
    if abs(final) < 1e-9:
        raise ModelGainError('the model shows no steady response on this channel')
    reached = np.nonzero(y / final >= 1.0 - np.exp(-1.0))[0]
    tau = float(reached[0] if reached.size else steps) * model['dt_s']
    return Channel(final / STEP_PCT, max(tau, model['dt_s']))


def model_channels(model: dict) -> tuple[Channel, Channel]:
    """(surge per % common command, yaw rate per % differential command)."""
    common = np.array([STEP_PCT, STEP_PCT])
    differential = np.array([-STEP_PCT, STEP_PCT])
    return step_channel(model, common, 0), step_channel(model, differential, 2)


def imc_pi(channel: Channel, pct_per_unit: float, lambda_factor: float) -> tuple[float, float]:
    """(kp, ki) of a PI on a first-order channel seen through a mixer slope."""
    k_loop = channel.gain_per_pct * pct_per_unit
    if not k_loop > 0.0:
        raise ModelGainError(f'the loop gain must be positive, got {k_loop:.3g} (a sign or '
                             'axis convention differs from REP 103?)')
    lam = lambda_factor * channel.tau_s
    kp = channel.tau_s / (k_loop * lam)
    return float(min(kp, MAX_GAIN)), float(min(kp / channel.tau_s, MAX_GAIN))


def _mixer_slopes(settings: 'ControllerSettings', medium: str, model: dict
                  ) -> tuple[float, float]:
    """% of common command per m/s and % of differential per rad/s at the operating point."""
    if medium == 'land':
        scale = 100.0 / settings.land.full_scale_track_speed_mps
        return scale, scale * settings.land.effective_track_separation_m / 2.0
    mixer, h = settings.water, 1e-3
    v0 = max(float(model['y_offset'][0]), 0.2)
    r0 = 0.5 * mixer.yaw_rate_at_full_moment_rps

    def common(v: float) -> float:
        sides = mixer.mix(v, 0.0).sides
        return (sides.port + sides.stbd) / 2.0

    def diff(r: float) -> float:
        sides = mixer.mix(0.0, r).sides
        return (sides.stbd - sides.port) / 2.0

    return (common(v0 + h) - common(v0 - h)) / (2 * h), (diff(r0 + h) - diff(r0 - h)) / (2 * h)


def gains_from_model(settings: 'ControllerSettings', path: str | Path,
                     lambda_factor: float) -> tuple[str, PiGains]:
    """(medium, IMC gains) from one model file."""
    if not lambda_factor > 0.0:
        raise ModelGainError(f'lambda_factor must be > 0, got {lambda_factor}')
    model = load_model(path)
    if model['medium'] not in ('land', 'water'):
        raise ModelGainError(f'{path}: unknown medium {model["medium"]!r}')
    surge, yaw = model_channels(model)
    speed_slope, yaw_slope = _mixer_slopes(settings, model['medium'], model)
    speed_kp, speed_ki = imc_pi(surge, speed_slope, lambda_factor)
    yaw_kp, yaw_ki = imc_pi(yaw, yaw_slope, lambda_factor)
    return model['medium'], PiGains(speed_kp, speed_ki, yaw_kp, yaw_ki)


def settings_with_model_gains(settings: 'ControllerSettings', paths, lambda_factor: float = 1.0
                              ) -> 'ControllerSettings':
    """``settings`` with the land gains and the afloat gains replaced from model files."""
    found = dict(gains_from_model(settings, p, lambda_factor) for p in paths)
    out = settings
    if 'land' in found:
        out = dataclasses.replace(out, **dataclasses.asdict(found['land']))
    if 'water' in found:
        out = dataclasses.replace(out, water_gains=found['water'])
    return out
