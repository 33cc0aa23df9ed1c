"""The world the vehicle moves in: beach profile, mean waterline and wave field.

Frame ``odom`` (ENU): z = 0 at the mean water level, x seaward, the mean waterline
is the line x = 0 on the beach, land at x < 0. The beach is flat sand landward of
``flat_start_x_m``, then a plane slope (``beach_slope_rad``) down to the flat sea
floor at ``-sea_floor_depth_m``.

Waves are linear (Airy) components travelling shoreward (towards -x, spread by a
small angle), all with the dispersion of one reference depth so that phases stay
coherent over the sloping bed; the kinematics (particle velocity, acceleration)
use the local depth. Depth-limited breaking caps the wave height at
``breaking_ratio`` times the local still-water depth, so the dry beach stays dry.
Optionally (``second_order``) the shallow water's bound second harmonics are added at the
kinematic points: narrow-band Stokes second order, limited to the cnoidal wave's.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from dukw_model.fast_numpy import (
    clip as _clip, dot as _dot, interp as _interp, max_of as _max_of, new_tuple as _new_tuple,
    operand as _operand, sum_of as _sum_of)

GRAVITY_MPS2 = 9.81
_REACH_MARGIN_M = 1e-6     # a point's |R b| against its rounded odom x
_MIN_KINEMATIC_DEPTH_M = 0.05
_ONE, _TWO, _PI = _operand(1.0), _operand(2.0), _operand(math.pi)   # per-step ufunc operands


class WaveModel:
    """Names of the wave models ``waves.model`` may take."""

    NONE = 'none'
    REGULAR = 'regular'
    IRREGULAR = 'irregular'
    ALL = (NONE, REGULAR, IRREGULAR)


class SecondOrder:
    """What ``waves.second_order`` adds to the linear sea (``World``): nothing, the
    second-order horizontal velocity and acceleration, or those and the surface's."""

    NONE = 'none'
    KINEMATICS = 'kinematics'
    FULL = 'full'
    ALL = (NONE, KINEMATICS, FULL)


@dataclass(frozen=True)
class Beach:
    """Flat sand, a plane slope through the mean waterline, a flat sea floor."""

    slope_rad: float
    sea_floor_depth_m: float
    flat_start_x_m: float

    def __post_init__(self) -> None:
        if not 0.0 < self.slope_rad < 0.6:
            raise ValueError(f'beach slope must be in (0, 0.6) rad, got {self.slope_rad}')
        if self.sea_floor_depth_m <= 0.0:
            raise ValueError('sea floor depth must be > 0 m')
        if self.flat_start_x_m >= 0.0:
            raise ValueError('the flat sand must start landward of the waterline (x < 0)')
        object.__setattr__(self, '_tan', math.tan(self.slope_rad))
        object.__setattr__(self, '_floor_x', self.sea_floor_depth_m / math.tan(self.slope_rad))
        object.__setattr__(self, '_heights_operands', (   # heights_m's, as 0-d arrays
            _operand(self.flat_start_x_m), _operand(self._floor_x), _operand(-self._tan)))

    @property
    def sea_floor_x_m(self) -> float:
        """Where the slope meets the sea floor, m."""
        return self._floor_x

    @property
    def sand_height_m(self) -> float:
        """Height of the flat sand above mean water level, m."""
        return -self.flat_start_x_m * self._tan

    def height_m(self, x_m: float) -> float:
        """Ground (sand or sea bed) height at x, odom z, m."""
        x = min(max(x_m, self.flat_start_x_m), self._floor_x)
        return -x * self._tan

    def gradient(self, x_m: float) -> float:
        """dz/dx of the ground at x (negative on the slope)."""
        return -self._tan if self.flat_start_x_m < x_m < self._floor_x else 0.0

    def heights_m(self, x_m: np.ndarray) -> np.ndarray:
        """Vectorised ``height_m``."""
        flat_start_x, floor_x, minus_tan = self._heights_operands
        return np.multiply(_clip(x_m, flat_start_x, floor_x), minus_tan)   # min(max()): bits

    def distance_along_slope_m(self, x_m: float) -> float:
        """Signed distance from the mean waterline measured along the ground, m."""
        x = min(max(x_m, self.flat_start_x_m), self._floor_x)
        return x / math.cos(self.slope_rad) + (x_m - x)


def cos_of_double_in_place(half_angle_rad: np.ndarray) -> np.ndarray:
    """cos(2 a) of an array of half angles a, in place: (1 - t^2) / (1 + t^2) = 2 / (1 + t^2)
    - 1 with t = tan(a), within a few 1e-16 of np.cos (absolute; an infinite t gives -1).
    numpy's float64 tan is vectorised (about 1 ns a value here) and its cos is not (about
    8 ns): the simulator's 38 x 24 phases a step cost 3 instead of 7.5 us."""
    out = np.tan(half_angle_rad, out=half_angle_rad)
    out *= out
    out += _ONE
    np.divide(_TWO, out, out=out)
    out -= _ONE
    return out


def wavenumber(omega_rps: float, depth_m: float) -> float:
    """Linear dispersion omega^2 = g k tanh(k h), solved for k by Newton's method."""
    if omega_rps <= 0.0 or depth_m <= 0.0:
        raise ValueError('wavenumber needs omega > 0 and depth > 0')
    k = max(omega_rps ** 2 / GRAVITY_MPS2, omega_rps / math.sqrt(GRAVITY_MPS2 * depth_m))
    for _ in range(50):
        th = math.tanh(k * depth_m)
        f = GRAVITY_MPS2 * k * th - omega_rps ** 2
        df = GRAVITY_MPS2 * (th + k * depth_m * (1.0 - th * th))
        step = f / df
        k -= step
        if abs(step) < 1e-12 * k:
            break
    return k


def jonswap_density(freq_hz: np.ndarray, significant_height_m: float, peak_period_s: float,
                    gamma: float) -> np.ndarray:
    """JONSWAP spectral density S(f), m^2/Hz, scaled so that 4 sqrt(m0) = Hs on its own grid.

    gamma = 1 gives the Pierson-Moskowitz shape.
    """
    fp = 1.0 / peak_period_s
    f = np.asarray(freq_hz, dtype=float)
    sigma = np.where(f <= fp, 0.07, 0.09)
    peak = gamma ** np.exp(-((f - fp) ** 2) / (2.0 * sigma ** 2 * fp ** 2))
    shape = f ** -5 * np.exp(-1.25 * (fp / f) ** 4) * peak
    m0 = np.trapezoid(shape, f)
    return shape * (significant_height_m / 4.0) ** 2 / m0


@dataclass(frozen=True)
class WaveComponents:
    """Linear wave components: amplitude, angular frequency, wavenumber vector, phase."""

    amplitude_m: np.ndarray
    omega_rps: np.ndarray
    kx: np.ndarray      # wavenumber vector (points where the crest travels), rad/m
    ky: np.ndarray
    phase_rad: np.ndarray

    @property
    def height_scale_m(self) -> float:
        """Height used for depth-limited breaking: H (regular) or Hs (irregular), m."""
        return 4.0 * math.sqrt(0.5 * float(np.sum(self.amplitude_m ** 2)))

    @property
    def count(self) -> int:
        """Number of components."""
        return int(self.amplitude_m.size)


def regular_waves(height_m: float, period_s: float, reference_depth_m: float,
                  direction_rad: float = math.pi) -> WaveComponents:
    """One component of height H and period T travelling along ``direction_rad``."""
    omega = 2.0 * math.pi / period_s
    k = wavenumber(omega, reference_depth_m)
    return WaveComponents(np.array([height_m / 2.0]), np.array([omega]),
                          np.array([k * math.cos(direction_rad)]),
                          np.array([k * math.sin(direction_rad)]), np.array([0.0]))


def cos2s_density(offset_rad: np.ndarray, exponent_s: float) -> np.ndarray:
    """Directional spreading D(theta - theta_mean) = G(s) cos^2s((theta - theta_mean) / 2), 1/rad.

    The cos-2s function of Longuet-Higgins et al. (1963), with Mitsuyasu et al.'s (1975)
    parameter s; G(s) = 2^(2s-1) Gamma(s+1)^2 / (pi Gamma(2s+1)) makes it integrate to 1 over
    [-pi, pi]. Its first circular moment is s / (s + 1).
    """
    if exponent_s <= 0.0:
        raise ValueError(f'the cos-2s spreading exponent must be > 0, got {exponent_s}')
    log_g = ((2.0 * exponent_s - 1.0) * math.log(2.0) + 2.0 * math.lgamma(exponent_s + 1.0)
             - math.log(math.pi) - math.lgamma(2.0 * exponent_s + 1.0))
    half = np.abs(np.cos(0.5 * np.asarray(offset_rad, dtype=float)))
    return math.exp(log_g) * half ** (2.0 * exponent_s)


def spreading_offsets_rad(exponent_s: float, directions: int) -> np.ndarray:
    """Directions of ``directions`` equal-energy bins of the cos-2s spreading, about the mean.

    Each is the median of its bin (the quantile (j + 1/2) / J of D), so every direction
    carries the same share of the energy and the set follows D's shape.
    """
    if directions < 1:
        raise ValueError('directional spreading needs at least one direction')
    grid = np.linspace(-math.pi, math.pi, 4001)
    density = cos2s_density(grid, exponent_s)
    cdf = np.concatenate([[0.0], np.cumsum(0.5 * (density[1:] + density[:-1]) * np.diff(grid))])
    cdf /= cdf[-1]
    return np.interp((np.arange(directions) + 0.5) / directions, cdf, grid)


def mitsuyasu_exponent(freq_over_peak: np.ndarray, s_max: float) -> np.ndarray:
    """The cos-2s spreading exponent at frequency f / f_peak: s_max (f / f_p)^5 up to the peak,
    s_max (f / f_p)^-2.5 above it (Mitsuyasu et al. 1975, as Goda, Random Seas and Design of
    Maritime Structures, 2000, ch. 2, whose s_max = 10 is the wind sea's): the spectrum's
    tail is spread wider than its peak."""
    ratio = np.asarray(freq_over_peak, dtype=float)
    return s_max * np.where(ratio <= 1.0, ratio ** 5.0, ratio ** -2.5)


def irregular_waves(significant_height_m: float, peak_period_s: float, reference_depth_m: float,
                    rng: np.random.Generator, count: int = 32, gamma: float = 3.3,
                    spreading_rad: float = 0.0, direction_rad: float = math.pi,
                    spreading_exponent_s: float = 0.0, directions: int = 1,
                    spreading_by_frequency: bool = False) -> WaveComponents:
    """A JONSWAP sea as ``count`` components with random frequencies, phases and directions.

    Frequencies are drawn uniformly inside equal bins over [0.5, 3] f_peak (no
    repetition period); amplitudes a = sqrt(2 S(f) df), rescaled so that the
    components' 4 sqrt(m0) equals Hs exactly.

    Directions: with ``spreading_exponent_s`` = 0, each component's heading is drawn
    uniformly within +- ``spreading_rad`` of ``direction_rad`` (0: long-crested). With
    s > 0 the sea is short-crested with the cos-2s spreading (``cos2s_density``): the
    spectrum is split into ``directions`` equal-energy direction bins and each run of
    ``directions`` consecutive frequency bins takes them all in random order (a single
    summation: every component keeps its own frequency, so the field stays ergodic and
    the cost stays ``count`` components). ``spreading_by_frequency``: each component's bin
    directions are those of its own frequency's exponent (``mitsuyasu_exponent``, s = s_max
    = ``spreading_exponent_s`` at the peak).
    """
    if count < 1:
        raise ValueError('an irregular sea needs at least one component')
    if spreading_exponent_s < 0.0 or directions < 1:
        raise ValueError('spreading_exponent_s must be >= 0 and directions >= 1')
    if spreading_exponent_s > 0.0 and spreading_rad != 0.0:
        raise ValueError('give either the uniform spreading_rad or the cos-2s '
                         'spreading_exponent_s, not both')
    fp = 1.0 / peak_period_s
    edges = np.linspace(0.5 * fp, 3.0 * fp, count + 1)
    df = np.diff(edges)
    freq = edges[:-1] + rng.uniform(0.0, 1.0, count) * df
    dense = np.linspace(edges[0], edges[-1], 400)
    density = np.interp(freq, dense,
                        jonswap_density(dense, significant_height_m, peak_period_s, gamma))
    amplitude = np.sqrt(2.0 * density * df)
    m0 = 0.5 * float(np.sum(amplitude ** 2))
    if m0 > 0.0:
        amplitude *= significant_height_m / (4.0 * math.sqrt(m0))
    omega = 2.0 * math.pi * freq
    k = np.array([wavenumber(w, reference_depth_m) for w in omega])
    if spreading_exponent_s > 0.0:
        runs = -(-count // directions)
        order = np.concatenate([rng.permutation(directions) for _ in range(runs)])[:count]
        if spreading_by_frequency:
            s_of_f = mitsuyasu_exponent(freq / fp, spreading_exponent_s)
            heading = direction_rad + np.array([
                spreading_offsets_rad(s_i, directions)[j]
                for s_i, j in zip(s_of_f, order, strict=True)])
        else:
            heading = direction_rad + spreading_offsets_rad(spreading_exponent_s,
                                                            directions)[order]
    else:
        heading = direction_rad + spreading_rad * rng.uniform(-1.0, 1.0, count)
    phase = rng.uniform(0.0, 2.0 * math.pi, count)
    return WaveComponents(amplitude, omega, k * np.cos(heading), k * np.sin(heading), phase)


def _mean_wavenumber(waves: WaveComponents, depth_m: float) -> float:
    """Wavenumber of the components' mean frequency m1 / m0 at this depth, rad/m (0: none)."""
    m0 = float(np.sum(waves.amplitude_m ** 2))
    if m0 <= 0.0:
        return 0.0
    return wavenumber(float(np.sum(waves.amplitude_m ** 2 * waves.omega_rps)) / m0, depth_m)


def stokes2_coefficients(k_rpm: float, depth_m: float, z_m: float) -> tuple[float, float]:
    """Stokes second-order coefficients (F, G) of a wave of wavenumber k in depth d at the
    height z (<= 0): for eta = a cos(psi) with the velocity a w cosh k(z+d) / sinh kd cos(psi),
    the second-order velocity is F a^2 w cosh k(z+d) / sinh kd cos(2 psi) =
    (3/4) a^2 w k cosh 2k(z+d) / sinh^4 kd cos(2 psi), the elevation's G a^2 cos(2 psi) =
    (k a^2 / 4) cosh kd (2 + cosh 2kd) / sinh^3 kd cos(2 psi) (Dean and Dalrymple, Water Wave
    Mechanics for Engineers and Scientists, 1991, ch. 11)."""
    if k_rpm <= 0.0:
        return 0.0, 0.0
    kd, kz = k_rpm * depth_m, k_rpm * (z_m + depth_m)
    sh = math.sinh(kd)
    f_u = 0.75 * k_rpm * math.cosh(2.0 * kz) / (sh ** 3 * math.cosh(kz))
    g_eta = 0.25 * k_rpm * math.cosh(kd) * (2.0 + math.cosh(2.0 * kd)) / sh ** 3
    return f_u, g_eta


def _elliptic_k(m: float) -> float:
    """Complete elliptic integral of the first kind K(m), parameter m in [0, 1), by the
    arithmetic-geometric mean."""
    a, b = 1.0, math.sqrt(1.0 - m)
    while abs(a - b) > 1e-15 * a:
        a, b = 0.5 * (a + b), math.sqrt(a * b)
    return math.pi / (2.0 * a)


def cnoidal_second_harmonic(ursell: float) -> float:
    """Second-harmonic to first-harmonic amplitude ratio of a cnoidal wave of Ursell number
    U = H L^2 / d^3: 2q / (1 + q^2), q = exp(-pi K(1 - m) / K(m)) the nome, m from
    U = 16/3 m K(m)^2 (the Fourier series of cn^2; Korteweg and de Vries 1895, Wiegel 1960).
    Small U: 3 U / (32 pi^2), Stokes's second order in shallow water; U -> inf: 1 (solitary)."""
    if ursell <= 0.0:
        return 0.0
    lo, hi, target = 0.0, 1.0 - 1e-12, 3.0 * ursell / 16.0
    for _ in range(60):
        m = 0.5 * (lo + hi)
        lo, hi = (m, hi) if m * _elliptic_k(m) ** 2 < target else (lo, m)
    q = math.exp(-math.pi * _elliptic_k(1.0 - m) / _elliptic_k(m))
    return 2.0 * q / (1.0 + q * q)


def cnoidal_factor(height_m: float, k_rpm: float, depth_m: float) -> float:
    """The cnoidal wave's second harmonic over Stokes's (shallow-water limit) at the Ursell
    number of this wave: 1 in deep and intermediate water, falling where Stokes's second
    order over-predicts (large U, the cnoidal range: Hedges 1995, Regions of validity of
    analytical wave theories, Proc. ICE Water Maritime and Energy 112)."""
    ursell = height_m * (2.0 * math.pi / k_rpm) ** 2 / depth_m ** 3
    if ursell <= 1e-9:
        return 1.0
    return cnoidal_second_harmonic(ursell) / (3.0 * ursell / (32.0 * math.pi ** 2))


def no_waves() -> WaveComponents:
    """Calm water."""
    empty = np.zeros(0)
    return WaveComponents(empty, empty, empty, empty, empty)


# The second-order terms as sums of products of the linear fields' columns at a kinematic
# point: its cosine row [eta, u, v, a_x~, a_y~, a w cos] is 0..5 (a~: sum a w^2 T cos), its
# sine row [eta^, u^, v^, a_x, a_y, eta_dot] 6..11. eta2 = G (eta eta - eta^ eta^),
# u2 = F (eta u - eta^ u^), du2/dt = F (eta_dot u + a w cos u^ + eta a_x + eta^ a_x~);
# (left, right, result column 0..4 = eta2 u2 v2 du2/dt dv2/dt, sign)
_SECOND_ORDER_PAIRS = ((0, 0, 0, 1.0), (6, 6, 0, -1.0),
                       (0, 1, 1, 1.0), (6, 7, 1, -1.0), (0, 2, 2, 1.0), (6, 8, 2, -1.0),
                       (11, 1, 3, 1.0), (5, 7, 3, 1.0), (0, 9, 3, 1.0), (6, 3, 3, 1.0),
                       (11, 2, 4, 1.0), (5, 8, 4, 1.0), (0, 10, 4, 1.0), (6, 4, 4, 1.0))
_PAIR_LEFT = np.array([p[0] for p in _SECOND_ORDER_PAIRS])
_PAIR_RIGHT = np.array([p[1] for p in _SECOND_ORDER_PAIRS])
_SECOND_ORDER_SIGNS = np.zeros((len(_SECOND_ORDER_PAIRS), 5))
for _row, (_left, _right, _column, _sign) in enumerate(_SECOND_ORDER_PAIRS):
    _SECOND_ORDER_SIGNS[_row, _column] = _sign


class WaterSample(NamedTuple):
    """The water at a set of points: surface elevation, and particle kinematics.

    Velocity and acceleration are horizontal, in odom, at the points' heights
    (clipped into the water column). A NamedTuple: one is made every physics step.
    """

    elevation_m: np.ndarray
    velocity_x_mps: np.ndarray
    velocity_y_mps: np.ndarray
    accel_x_mps2: np.ndarray
    accel_y_mps2: np.ndarray


class World:
    """Beach plus waves: ground height, water surface, depth and kinematics anywhere.

    ``sample`` is the simulator's hot path (once per physics step, 20+ points), so it is
    a handful of numpy operations over points x components, whatever their number: the
    phases of all points come from one matrix product with the components' wavenumbers
    (whose time row is refreshed once per instant), one cosine gives the elevations and,
    on extra rows shifted by a quarter period, the sines the accelerations need, and one
    more product with the amplitude and depth-transfer weights gives elevation, velocity
    and acceleration together. The breaking cap and the still depth are piecewise linear
    in x, one interpolation each.
    """

    def __init__(self, beach: Beach, waves: WaveComponents, breaking_ratio: float = 0.78,
                 reference_depth_m: float = 0.76,
                 second_order: str = SecondOrder.NONE) -> None:
        if breaking_ratio <= 0.0:
            raise ValueError('breaking_ratio must be > 0')
        if second_order not in SecondOrder.ALL:
            raise ValueError(f'second_order must be one of {SecondOrder.ALL}, got '
                             f'{second_order!r}')
        self.beach = beach
        self.second_order = second_order != SecondOrder.NONE and waves.count > 0
        self._second_order_surface = second_order == SecondOrder.FULL
        self.waves = waves
        self.breaking_ratio = breaking_ratio
        self.reference_depth_m = reference_depth_m
        self._height_scale = waves.height_scale_m if waves.count else 0.0
        self._cap_per_m = breaking_ratio / self._height_scale if self._height_scale else 0.0
        self._calm = waves.count == 0 or self._height_scale == 0.0
        self._k = np.hypot(waves.kx, waves.ky)
        safe_k = np.where(self._k > 0.0, self._k, 1.0)
        dirs = np.column_stack([waves.kx / safe_k, waves.ky / safe_k])
        a_omega = waves.amplitude_m * waves.omega_rps
        # velocity (a w dir) and acceleration (a w^2 dir) weights before the depth transfer
        self._kin_weights = np.column_stack([a_omega[:, None] * dirs,
                                             (a_omega * waves.omega_rps)[:, None] * dirs])
        # the result weights: amplitude, then the kinematic ones times the depth transfer (and,
        # for the second order, a w: the elevation's rate on the sine rows)
        self._weights = np.zeros((waves.count, 6 if self.second_order else 5))
        self._weights[:, 0] = waves.amplitude_m
        if self.second_order:
            self._weights[:, 5] = a_omega
        self._mean_k = _mean_wavenumber(waves, reference_depth_m)
        self._stokes2 = (0.0, 0.0)      # second-order velocity and elevation coefficients
        self._pair_weights = np.zeros((len(_SECOND_ORDER_PAIRS), 5))
        if self.second_order:           # their cnoidal limit against the still depth
            self._ursell_depth = np.linspace(_MIN_KINEMATIC_DEPTH_M, beach.sea_floor_depth_m, 96)
            hs = waves.height_scale_m
            self._ursell_factor = np.array([
                cnoidal_factor(min(hs, breaking_ratio * d), self._mean_k, d)
                for d in self._ursell_depth])
        # phase = [x, y, 1, quarter] @ [kx; ky; phase - omega t; -pi/2]
        self._wavenumbers = np.zeros((4, waves.count))
        self._wavenumbers[0], self._wavenumbers[1] = waves.kx, waves.ky
        self._wavenumbers[3] = -0.5 * math.pi
        self._time_key: float | None = None
        # sample_rigid: half of [kx; ky; phase; omega] (it takes the half phases, exactly half
        # of the phases: scaling by 0.5 is exact), its (3, 4) coefficients and the phase matrix
        self._rigid_waves = 0.5 * np.vstack([waves.kx, waves.ky, waves.phase_rad,
                                             waves.omega_rps])
        self._rigid_coef = np.zeros((3, 4))
        self._rigid_coef[2, 2] = 1.0
        self._rigid_phase = np.zeros((4, waves.count))
        self._reach_of: np.ndarray | None = None      # sample_rigid's rows, and their reach
        self._offshore_depth: dict[int, float] = {}   # points over the sea floor: their depth
        self._reach_m = math.inf
        self._rigid_phase[3] = -0.25 * math.pi       # half of the sines' -pi/2
        self._rigid_odom = np.zeros(4)
        self._transfer_key: tuple[float, float] | None = None
        self._sinh_depth: float | None = None
        self._kin_per_sinh = np.zeros((waves.count, 4))
        self._k_col = np.zeros((waves.count, 1))
        self._k_by_row = self._k[:, None]
        self._depth_operand = np.zeros(())          # d, then z + d (fast_numpy.operand)
        self._points = np.zeros((0, 4))
        self._points_key = (0, 0)
        self._still_x = np.array([beach.flat_start_x_m, beach.sea_floor_x_m])
        self._still_depth = -beach.heights_m(self._still_x)
        # breaking cap: 0 at the waterline, growing with the depth up to 1 (or the sea floor)
        tan = math.tan(beach.slope_rad)
        full_x = beach.sea_floor_x_m
        if self._cap_per_m > 0.0:
            full_x = min(full_x, 1.0 / (self._cap_per_m * tan))
        self._cap_x = np.array([0.0, full_x])
        self._cap = np.array([0.0, min(full_x * tan * self._cap_per_m, 1.0)])

    @property
    def calm(self) -> bool:
        """True when there are no waves."""
        return self._calm

    def breaking_factor(self, still_depth_m: np.ndarray) -> np.ndarray:
        """Wave-height factor in [0, 1]: H <= breaking_ratio * local still-water depth."""
        if self._calm:
            return np.zeros_like(still_depth_m)
        return np.minimum(np.maximum(still_depth_m, 0.0) * self._cap_per_m, 1.0)

    def _phase_matrix(self, t_s: float) -> np.ndarray:
        """The (4, M) matrix of ``_wavenumbers`` with its time row set for t (once per t)."""
        if t_s != self._time_key:
            np.subtract(self.waves.phase_rad, self.waves.omega_rps * t_s,
                        out=self._wavenumbers[2])
            self._time_key = t_s
        return self._wavenumbers

    def _point_rows(self, x: np.ndarray, y: np.ndarray, kin_points: int) -> np.ndarray:
        """Rows [x, y, 1, 0] of every point, then [x, y, 1, 1] of the kinematic ones."""
        n = x.size
        rows = self._points
        if self._points_key != (n, kin_points):
            rows = np.zeros((n + kin_points, 4))
            rows[:, 2] = 1.0
            rows[n:, 3] = 1.0
            self._points, self._points_key = rows, (n, kin_points)
        rows[:n, 0] = x
        rows[:n, 1] = y
        rows[n:, :2] = rows[:kin_points, :2]
        return rows

    def sample(self, x_m: np.ndarray, y_m: np.ndarray, t_s: float, kin_points: int = 0,
               kin_height_m: float = 0.0) -> WaterSample:
        """Surface elevation at points (x, y) at time t, and particle kinematics at the first
        ``kin_points`` of them at height ``kin_height_m`` (odom z, clipped into the water).

        The kinematics use one depth, the mean still-water depth of those points (a body a
        few metres long on a gentle slope): the depth transfer is computed once per call.
        """
        x = np.asarray(x_m, dtype=float)
        if self._calm:
            zero = np.zeros_like(x)
            kin = np.zeros(kin_points)
            return WaterSample(zero, kin, kin, kin, kin)
        y = np.asarray(y_m, dtype=float)
        shape = x.shape
        if x.ndim != 1 or y.shape != shape:       # grids, scalars: flat points
            x, y = np.broadcast_arrays(x, y)
            shape = x.shape
            x, y = x.ravel(), y.ravel()
        n = x.size
        kin_points = max(min(kin_points, n), 0)
        if n and x.max() <= 0.0:                  # all on the sand: breaking leaves no wave
            kin = np.zeros(kin_points)
            return WaterSample(np.zeros(shape), kin, kin, kin, kin)
        sample = self.sample_points(x, y, t_s, kin_points, kin_height_m)
        return sample if shape == (n,) else sample._replace(elevation_m=sample.elevation_m
                                                            .reshape(shape))

    def sample_points(self, x: np.ndarray, y: np.ndarray, t_s: float, kin_points: int,
                      kin_height_m: float) -> WaterSample:
        """``sample`` of flat float arrays x, y of n points, 0 <= kin_points <= n, waves
        present and some point seaward of the waterline (the simulator's call every step,
        without the checks)."""
        rows = self._point_rows(x, y, kin_points)
        trig = np.cos(rows @ self._phase_matrix(t_s))   # cos on the first n rows, then sin
        return self._combine(trig, rows[:, 0], x.size, kin_points, kin_height_m)

    def rigid_rows(self, body_x_m: np.ndarray, body_y_m: np.ndarray,
                   kin_points: int) -> np.ndarray:
        """The rows ``sample_rigid`` takes for points fixed in a body (body frame x, y):
        [x, y, 1, 0] of every point, then [x, y, 1, 1] of the first ``kin_points``."""
        bx = np.asarray(body_x_m, dtype=float).ravel()
        by = np.asarray(body_y_m, dtype=float).ravel()
        if bx.shape != by.shape or not 0 <= kin_points <= bx.size:
            raise ValueError('rigid_rows needs x and y of the same size, 0 <= kin_points <= n')
        rows = np.zeros((bx.size + kin_points, 4))
        rows[:bx.size, 0], rows[:bx.size, 1] = bx, by
        rows[bx.size:, :2] = rows[:kin_points, :2]
        rows[:, 2] = 1.0
        rows[bx.size:, 3] = 1.0
        return rows

    def sample_rigid(self, rows: np.ndarray, n: int, x_m: float, y_m: float, cos_yaw: float,
                     sin_yaw: float, t_s: float, kin_height_m: float,
                     kinematics: bool = True) -> tuple[np.ndarray, WaterSample]:
        """``sample`` at n points fixed in a body whose origin is at (x, y) with this heading
        (``rows`` from ``rigid_rows``; the kinematics at the rows after the n-th), and the
        points' odom x (one value per row). ``kinematics`` False: the elevation at the n
        points only (their rows alone; the same bits as with the kinematics).

        A point's phase k.(X + R b) + phase - omega t is b_x (R^T k)_x + b_y (R^T k)_y plus
        the body origin's phase: one (3, 4) x (4, M) product per step gives the rotated
        wavenumbers and the origin's phase, which is kept in [0, 2 pi) so that the cosines'
        arguments stay small (a few radians over the body, not k x + omega t). The products
        give half phases, whose cosines ``cos_of_double_in_place`` takes from their tangents.
        """
        if rows is not self._reach_of:            # the points' farthest reach from the origin
            self._reach_m = float(np.hypot(rows[:, 0], rows[:, 1]).max()) + _REACH_MARGIN_M
            self._reach_of = rows
        if not kinematics:
            rows = rows[:n]
        odom = self._rigid_odom
        odom[0], odom[1], odom[2] = cos_yaw, -sin_yaw, x_m
        px = _dot(rows, odom)
        kin_points = rows.shape[0] - n
        seaward_x = x_m - self._reach_m           # no point is nearer the beach than this
        if self._calm or (seaward_x <= 0.0 and _max_of(px[:n]) <= 0.0):  # calm, or on the sand
            kin = np.zeros(kin_points)
            return px, WaterSample(np.zeros(n), kin, kin, kin, kin)
        coef = self._rigid_coef
        coef[0, 0] = coef[1, 1] = cos_yaw
        coef[0, 1], coef[1, 0] = sin_yaw, -sin_yaw
        coef[2, 0], coef[2, 1], coef[2, 3] = x_m, y_m, -t_s
        phase = self._rigid_phase
        _dot(coef, self._rigid_waves, out=phase[:3])
        np.remainder(phase[2], _PI, out=phase[2])    # half the origin phase, in [0, pi)
        trig = cos_of_double_in_place(_dot(rows, phase))   # cos on the first n rows, then sin
        # every point where the breaking cap is 1 (np.interp gives fp[-1] exactly there)
        uncapped = seaward_x >= self._cap_x[1] and self._cap[1] == 1.0
        return px, self._combine(trig, px, n, kin_points, kin_height_m, uncapped,
                                 seaward_x >= self._still_x[1])

    def _combine(self, trig: np.ndarray, row_x: np.ndarray, n: int, kin_points: int,
                 kin_height_m: float, uncapped: bool = False,
                 offshore: bool = False) -> WaterSample:
        """Elevation and kinematics from the rows' cosines (then sines) of the phases
        (``uncapped``: every row where the breaking cap is 1, the factor is skipped;
        ``offshore``: every row over the flat sea floor)."""
        if kin_points:
            self._set_transfer(row_x[:kin_points], kin_height_m, offshore)
        out = _dot(trig, self._weights)   # all columns: the elevation's bits with or without
        if not uncapped:
            out *= _interp(row_x, self._cap_x, self._cap)[:, None]
        if not kin_points:
            kin = np.zeros(0)
            return WaterSample(out[:n, 0], kin, kin, kin, kin)
        if self.second_order:
            self._add_second_order(out, n, kin_points)
        return _new_tuple(WaterSample, (out[:n, 0], out[:kin_points, 1], out[:kin_points, 2],
                                        out[n:, 3], out[n:, 4]))   # all fields: no __new__

    def _set_transfer(self, x_kin: np.ndarray, kin_height_m: float,
                      offshore: bool = False) -> None:
        """Kinematic weights times cosh k(z + d) / sinh k d at the points' mean still depth
        (``offshore``: all over the flat sea floor, where it is the same for any such points,
        np.interp giving the floor's depth exactly: kept per number of points)."""
        depth = self._offshore_depth.get(x_kin.size) if offshore else None
        if depth is None:
            depth = float(_sum_of(_interp(x_kin, self._still_x, self._still_depth))) / x_kin.size
            depth = max(depth, _MIN_KINEMATIC_DEPTH_M)
            if offshore:
                self._offshore_depth[x_kin.size] = depth
        zc = min(max(kin_height_m, -depth), 0.0)
        if (zc, depth) == self._transfer_key:     # e.g. the hull above the water
            return
        k_col = self._k_col                       # (M, 1) buffer: k d, then its sinh, cosh
        depth_operand = self._depth_operand
        if depth != self._sinh_depth:             # e.g. off the slope: the sea floor's depth
            depth_operand[()] = depth
            np.multiply(self._k_by_row, depth_operand, out=k_col)
            np.sinh(k_col, out=k_col)
            np.divide(self._kin_weights, k_col, out=self._kin_per_sinh)
            self._sinh_depth = depth
        depth_operand[()] = zc + depth
        np.multiply(self._k_by_row, depth_operand, out=k_col)
        np.cosh(k_col, out=k_col)
        np.multiply(k_col, self._kin_per_sinh, out=self._weights[:, 1:5])
        self._transfer_key = (zc, depth)
        if self.second_order:
            limit = float(_interp(depth, self._ursell_depth, self._ursell_factor))
            f_u, g_eta = stokes2_coefficients(self._mean_k, depth, zc)
            self._stokes2 = (limit * f_u, limit * g_eta)
            self._pair_weights = _SECOND_ORDER_SIGNS * np.array(
                [limit * g_eta if self._second_order_surface else 0.0] + [limit * f_u] * 4)

    def _add_second_order(self, out: np.ndarray, n: int, kin: int) -> None:
        """Add the narrow-band second-order (Stokes) terms at the kinematic points, in place:
        with the complex linear fields Z = eta + i eta_hat and U = u + i u_hat (cosines on the
        first rows, sines on the rows after the n-th), u2 = F Re(Z U), its time derivative
        F Re(dZ/dt U + Z dU/dt) and eta2 = G Re(Z^2) (``stokes2_coefficients``): products of
        pairs of the rows' columns (``_SECOND_ORDER_PAIRS``), summed by one product."""
        both = np.concatenate((out[:kin], out[n:n + kin]), axis=1)
        pairs = both.take(_PAIR_LEFT, axis=1)
        pairs *= both.take(_PAIR_RIGHT, axis=1)
        terms = _dot(pairs, self._pair_weights)      # eta2, u2, v2 | du2/dt, dv2/dt
        out[:kin, :3] += terms[:, :3]
        out[n:n + kin, 3:5] += terms[:, 3:5]

    def elevation_m(self, x_m: float, y_m: float, t_s: float) -> float:
        """Water surface above mean level at one point, m."""
        return float(self.sample(np.array([x_m]), np.array([y_m]), t_s).elevation_m[0])

    def water_depth_m(self, x_m: float, y_m: float, t_s: float) -> float:
        """Surface minus ground at one point, m (<= 0 on dry sand)."""
        return self.elevation_m(x_m, y_m, t_s) - self.beach.height_m(x_m)
