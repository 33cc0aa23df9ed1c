"""The site's soil learnt online from the track forces on dry sand, ROS-free.

The estimator reads the weight on the tracks (and so the water under the hulls) from the
measured track force through the modified Wong model (vehicle.md 6). With the configured
soil on a beach that is not the configured one, a weaker or stiffer sand reads as water
(issue 18: most submerged-volume and weight-share misses). On dry sand the weight is known
(all of it on the tracks: W_e = Delta cos(theta)), so there the force against the slip
tells the soil instead.

A two-state Kalman filter on (phi, k), the angle of shearing resistance and the shear
deformation modulus, with the cohesion held at its configured value (it adds A c ~ 13 N
per track against W tan(phi) ~ 140-390 N: not identifiable apart from phi on a constant
weight). Prior: the configured soil, one-sigma half the paper's fitted range; the state is
clipped to that range (vehicle.md 6: phi 5.58-15 deg, k 0-18 cm; ``soil_online.*``).
Each update is one track's smoothed soil force at its slip; the slip's own uncertainty
(the ground speed's) joins the force noise through dF/di. Without slip (a gripping or
braking track, |i| under ``soil_online.min_slip``) nothing is learnt: the prior stays.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from dukw_common.vehicle import SoilParams
from dukw_model import traction

PHI_STEP_RAD = 1e-4           # finite-difference steps of the force's Jacobian
K_STEP_M = 1e-4
SLIP_STEP = 1e-3


@dataclass(frozen=True)
class OnlineSoilSettings:
    """Bounds, prior spread and noise of the online soil fit (``ekf_node.soil_online.*``)."""

    enabled: bool
    phi_min_rad: float
    phi_max_rad: float
    k_min_m: float
    k_max_m: float
    phi_sigma_rad: float
    k_sigma_m: float
    force_sigma_n: float
    min_slip: float
    min_track_speed_mps: float
    max_turn_mps: float
    max_slip_sigma: float
    period_s: float

    def __post_init__(self) -> None:
        if not (0.0 <= self.phi_min_rad < self.phi_max_rad < 1.5
                and 0.0 <= self.k_min_m < self.k_max_m):
            raise ValueError('soil_online: bounds must satisfy 0 <= min < max (phi < 1.5 rad)')
        if min(self.phi_sigma_rad, self.k_sigma_m, self.force_sigma_n) <= 0.0:
            raise ValueError('soil_online: sigmas must be positive')


class OnlineSoil:
    """(phi, k) of the site, from one track's force at a known weight and slip at a time."""

    def __init__(self, prior: SoilParams, settings: OnlineSoilSettings) -> None:
        self.settings = settings
        self.reset(prior)

    def reset(self, prior: SoilParams) -> None:
        """Back to ``prior`` (clipped into the bounds) with the prior's spread."""
        st = self.settings
        self.prior = prior
        self.x = self._clip(np.array([prior.friction_angle_rad, prior.shear_modulus_m]))
        self.P = np.diag([st.phi_sigma_rad ** 2, st.k_sigma_m ** 2])
        self.updates = 0
        self.last_t_s = -math.inf

    @property
    def soil(self) -> SoilParams:
        """The present estimate (the prior's cohesion)."""
        return replace(self.prior, friction_angle_rad=float(self.x[0]),
                       shear_modulus_m=float(self.x[1]))

    def sigma(self) -> tuple[float, float]:
        """One-sigma of (phi rad, k m)."""
        return float(math.sqrt(self.P[0, 0])), float(math.sqrt(self.P[1, 1]))

    def _clip(self, x: np.ndarray) -> np.ndarray:
        st = self.settings
        return np.array([min(max(x[0], st.phi_min_rad), st.phi_max_rad),
                         min(max(x[1], st.k_min_m), st.k_max_m)])

    def _force(self, x: np.ndarray, slip: float, weight_n: float, area_m2: float,
               length_m: float) -> float:
        soil = replace(self.prior, friction_angle_rad=float(x[0]), shear_modulus_m=float(x[1]))
        return float(traction.tractive_force_n(slip, weight_n, soil, area_m2, length_m))

    def informative(self, slip: float, track_mps: float, other_track_mps: float) -> bool:
        """Slipping enough (past the grip) on a track turning fast enough, driving straight
        (in a skid-steer turn the tracks' sideways shear adds to their force: the Wong
        model is the longitudinal force only)."""
        st = self.settings
        return (math.isfinite(slip) and abs(slip) >= st.min_slip
                and abs(track_mps) >= st.min_track_speed_mps
                and abs(track_mps - other_track_mps) <= st.max_turn_mps)

    def update(self, t_s: float, slip: float, slip_sigma: float, weight_n: float,
               force_n: float, area_m2: float, length_m: float) -> bool:
        """One track's soil force ``force_n`` (N, signed like the slip) at ``slip`` with the
        track's share of the weight ``weight_n`` on dry sand. False (nothing changes) when
        disabled, non-finite, not informative (the caller checks the speeds), the slip
        too uncertain, or the force not signed like the slip."""
        st = self.settings
        values = (t_s, slip, slip_sigma, weight_n, force_n)
        if not st.enabled or not all(math.isfinite(v) for v in values) or weight_n <= 0.0 \
                or abs(slip) < st.min_slip or slip_sigma > st.max_slip_sigma \
                or slip * force_n <= 0.0:
            return False             # a force against the slip is not the Wong curve (a start
                                     # from rest, static friction, a slip not yet converged)
        predicted = self._force(self.x, slip, weight_n, area_m2, length_m)
        h = np.array([
            (self._force(self.x + [PHI_STEP_RAD, 0.0], slip, weight_n, area_m2, length_m)
             - predicted) / PHI_STEP_RAD,
            (self._force(self.x + [0.0, K_STEP_M], slip, weight_n, area_m2, length_m)
             - predicted) / K_STEP_M])
        step = SLIP_STEP if slip >= 0.0 else -SLIP_STEP
        per_slip = (self._force(self.x, slip + step, weight_n, area_m2, length_m)
                    - predicted) / step
        var = st.force_sigma_n ** 2 + (per_slip * slip_sigma) ** 2
        innovation_var = float(h @ self.P @ h) + var
        gain = self.P @ h / innovation_var
        self.x = self._clip(self.x + gain * (force_n - predicted))
        self.P = self.P - np.outer(gain, h @ self.P)
        self.P = 0.5 * (self.P + self.P.T)
        self.updates += 1
        self.last_t_s = t_s
        return True

    def due(self, t_s: float) -> bool:
        """At most every ``period_s`` (the smoothed force is correlated in time)."""
        return t_s - self.last_t_s >= self.settings.period_s
