"""Submerged volume of the two SWATH hulls, each a right circular cylinder (vehicle.md section 6).

``submerged_volume_on_slope`` is the paper's model (hull bottom lying on a
beach of slope theta, h2 the submerged length along the bottom), evaluated in
closed form. ``hull_volume_from_depths`` is the general form the simulator
uses against an instantaneous wavy surface: the water height over the hull's
bottom line sampled along its length. For a hull on a slope in calm water the
two agree (tested). Vectorised over arrays of h2.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numba import njit

from dukw_model.scalars import is_scalar
from dukw_model.fast_numpy import clip as _clip, operand as _operand


ArrayLike = float | np.ndarray


def _segment_integral(lo: np.ndarray, hi: np.ndarray, a: np.ndarray, r: float) -> np.ndarray:
    """Closed form of  integral_lo^hi (xi - a) sqrt(r^2 - xi^2) dxi."""
    def antiderivative(xi: np.ndarray) -> np.ndarray:
        xi = np.clip(xi, -r, r)
        root = np.sqrt(np.maximum(r * r - xi * xi, 0.0))
        first = -(root ** 3) / 3.0                                    # int xi sqrt(r^2-xi^2)
        second = 0.5 * (xi * root + r * r * np.arcsin(xi / r))        # int sqrt(r^2-xi^2)
        return first - a * second
    return antiderivative(hi) - antiderivative(lo)


def hull_volume_on_slope(h2_m: ArrayLike, slope_rad: float, radius_m: float,
                         length_m: float = math.inf) -> ArrayLike:
    """Submerged volume of ONE hull from h2 on a slope, m^3 (vehicle.md section 6).

    - h2 < 2r/tan(theta): beta = h2 tan(theta),
      V = 2 int_{r-beta}^{r} h2 (xi - r + beta)/beta sqrt(r^2 - xi^2) dxi
    - h2 >= 2r/tan(theta): V = (h2 - r/tan(theta)) pi r^2
    capped at the whole hull, pi r^2 length. ``slope_rad`` must be > 0.
    """
    if slope_rad <= 0.0:
        raise ValueError('hull_volume_on_slope needs a beach slope > 0 rad')
    r = radius_m
    h2 = np.maximum(np.asarray(h2_m, dtype=float), 0.0)
    tan_t = math.tan(slope_rad)
    full_end = 2.0 * r / tan_t
    beta = np.minimum(h2 * tan_t, 2.0 * r)
    beta_safe = np.where(beta > 0.0, beta, 1.0)
    partial = 2.0 * h2 / beta_safe * _segment_integral(r - beta, np.full_like(beta, r),
                                                       r - beta, r)
    partial = np.where(beta > 0.0, partial, 0.0)
    immersed = (h2 - r / tan_t) * math.pi * r * r
    vol = np.where(h2 < full_end, partial, immersed)
    vol = np.minimum(vol, math.pi * r * r * length_m)
    return float(vol) if vol.ndim == 0 else vol


def submerged_volume_on_slope(h2_m: ArrayLike, slope_rad: float, radius_m: float,
                              length_m: float = math.inf) -> ArrayLike:
    """Submerged volume of BOTH hulls, V = 2 V_h, m^3."""
    return 2.0 * np.asarray(hull_volume_on_slope(h2_m, slope_rad, radius_m, length_m)) \
        if np.ndim(h2_m) else 2.0 * hull_volume_on_slope(h2_m, slope_rad, radius_m, length_m)


def segment_area_m2(depth_m: ArrayLike, radius_m: float) -> ArrayLike:
    """Immersed cross-section of a horizontal circle of radius r, water depth d over its bottom."""
    r = radius_m
    if is_scalar(depth_m):                        # the scalar path, without numpy's overhead
        h = r - min(max(float(depth_m), 0.0), 2.0 * r)
        return (r * r * float(np.arccos(min(max(h / r, -1.0), 1.0)))   # numpy: same bits
                - h * math.sqrt(max(r * r - h * h, 0.0)))
    return _segment_area_array(np.asarray(depth_m, dtype=float), r)


def _segment_area_array(depth_m: np.ndarray, r: float) -> np.ndarray:
    """``segment_area_m2`` of an array: the simulator's strips every step, so its clips are
    ufunc calls (np.clip's Python wrapper costs more than the arithmetic; same bits)."""
    h = r - np.minimum(np.maximum(depth_m, 0.0), 2.0 * r)
    cos_half = h / r
    np.maximum(cos_half, -1.0, out=cos_half)
    np.minimum(cos_half, 1.0, out=cos_half)
    return r * r * np.arccos(cos_half) - h * np.sqrt(np.maximum(r * r - h * h, 0))


@njit(cache=True)
def segment_area_integral_m3_per_m(depth_m: float, radius_m: float) -> float:
    """Integral of the segment area over water depth, int_0^d A(u) du, m^3/m (exact).

    A hull bottom line dipping by g per metre holds F(d2)/g - F(d1)/g between the depths d1
    and d2 at its ends. Beyond 2r the whole circle adds pi r^2 per metre of depth.
    Compiled (numba), like the helpers it calls: the estimator integrates a wet hull's
    line at every sample in the surf (issue 16).
    """
    r = radius_m
    d = max(depth_m, 0.0)
    full = 2.0 * r
    inside = min(d, full)
    return -_segment_antiderivative(r - inside, r) + math.pi * r * r * max(d - full, 0.0)


@njit(cache=True)
def _segment_antiderivative(v: float, r: float) -> float:
    """Antiderivative of the segment area in v = r - u,
    A(v) = r^2 acos(v/r) - v sqrt(r^2 - v^2)."""
    root = math.sqrt(max(r * r - v * v, 0.0))
    return r * r * (v * math.acos(max(-1.0, min(1.0, v / r))) - root) + math.pow(root, 3.0) / 3.0


@njit(cache=True)
def _area_integral(depth_m: float, radius_m: float, float_depth_m: float,
                   strut_width_m: float, top_depth_m: float, float_area_m2: float,
                   top_area_m2: float) -> float:
    """``HullSection.area_integral_m3_per_m`` of the section with these dimensions and its
    areas at the float line and with the deck awash."""
    over_deck = max(depth_m - top_depth_m, 0.0)
    depth_m = min(depth_m, top_depth_m)
    above = max(depth_m - float_depth_m, 0.0)
    return segment_area_integral_m3_per_m(min(depth_m, float_depth_m), radius_m) \
        + float_area_m2 * above \
        + 0.5 * strut_width_m * above * above \
        + (top_area_m2 * over_deck if over_deck > 0.0 else 0.0)


@njit(cache=True)
def _sloped_line_volume(depth0_m: float, gradient: float, bow_x_m: float, stern_x_m: float,
                        radius_m: float, float_depth_m: float, strut_width_m: float,
                        top_depth_m: float, float_area_m2: float, top_area_m2: float) -> float:
    """``HullSection.line_volume_m3`` of a sloping bottom line (gradient not ~0), m^3."""
    bow = _area_integral(depth0_m + gradient * bow_x_m, radius_m, float_depth_m,
                         strut_width_m, top_depth_m, float_area_m2, top_area_m2)
    stern = _area_integral(depth0_m + gradient * stern_x_m, radius_m, float_depth_m,
                           strut_width_m, top_depth_m, float_area_m2, top_area_m2)
    return abs(bow - stern) / abs(gradient)


def cylinder_float_depth_m(displaced_volume_m3: float, radius_m: float,
                           length_m: float) -> float:
    """Water over the bottoms of two level cylinders that displace the volume given, m."""
    target = displaced_volume_m3 / (2.0 * length_m)
    if target >= math.pi * radius_m ** 2:
        raise ValueError('the hulls cannot carry the displacement (hull_radius_m too small)')
    lo, hi = 0.0, 2.0 * radius_m
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if float(segment_area_m2(mid, radius_m)) < target:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


class _SectionOperands(NamedTuple):
    """A HullSection's constants as 0-d arrays: 0, r, r^2, the float line, the segment's
    cap min(float line, 2 r), the strut's width, the deck."""

    zero: np.ndarray
    radius: np.ndarray
    radius_sq: np.ndarray
    float_depth: np.ndarray
    segment_cap: np.ndarray
    strut_width: np.ndarray
    top_depth: np.ndarray


@dataclass(frozen=True)
class HullSection:
    """Cross-section of each SWATH hull: the paper's cylinder up to the float line, then
    wall-sided (the strut) with the waterplane area of vehicle.md section 1 above it, up
    to the deck; water over the deck displaces nothing more.

    The cylinders alone are almost wholly immersed afloat (0.288 of 0.313 m^3), so a crest
    over the float line meets the strut. The simulator's strips and the estimator's
    submersion both use this section.
    """

    radius_m: float
    float_depth_m: float         # water over the hull bottom afloat in calm water
    strut_width_m: float         # wall-sided width above the float line
    top_depth_m: float = math.inf   # the deck, above the hull bottom

    def __post_init__(self) -> None:
        # area_array_m2's constant operands as 0-d arrays (fast_numpy.operand)
        r = self.radius_m
        object.__setattr__(self, '_operands', _SectionOperands(
            _operand(0.0), _operand(r), _operand(r * r), _operand(self.float_depth_m),
            _operand(min(self.float_depth_m, 2.0 * r)), _operand(self.strut_width_m),
            _operand(self.top_depth_m)))

    @functools.cached_property
    def _float_area_m2(self) -> float:
        """The section at the float line, m^2 (``area_integral_m3_per_m``'s constant)."""
        return float(segment_area_m2(self.float_depth_m, self.radius_m))

    @functools.cached_property
    def _top_area_m2(self) -> float:
        """The section with the deck awash, m^2 (``area_integral_m3_per_m``'s constant)."""
        return float(self.area_m2(self.top_depth_m))

    @classmethod
    def of_hulls(cls, displaced_volume_m3: float, radius_m: float, length_m: float,
                 waterplane_area_m2: float, top_depth_m: float = math.inf) -> 'HullSection':
        """Float line from the displacement, strut width from the waterplane of two hulls."""
        return cls(radius_m, cylinder_float_depth_m(displaced_volume_m3, radius_m, length_m),
                   waterplane_area_m2 / (2.0 * length_m), top_depth_m)

    @classmethod
    def of_body(cls, body) -> 'HullSection':
        """The section of ``dukw_common.vehicle`` Body's hulls (deck: keel-to-deck depth)."""
        return cls.of_hulls(body.displaced_volume_m3, body.hull_radius_m, body.hull_length_m,
                            body.waterplane_area_m2,
                            body.depth_keel_to_deck_m - body.hull_clearance_m)

    def area_m2(self, depth_m: ArrayLike) -> ArrayLike:
        """Immersed section from the water height over the hull bottom, m^2 (vectorised)."""
        if is_scalar(depth_m):                        # the scalar path, without numpy's overhead
            d = min(float(depth_m), self.top_depth_m)
            return (segment_area_m2(min(d, self.float_depth_m), self.radius_m)
                    + self.strut_width_m * max(d - self.float_depth_m, 0.0))
        return self.area_array_m2(np.asarray(depth_m, dtype=float))

    def area_array_m2(self, depth_m: np.ndarray,
                      max_depth_m: float | None = None) -> np.ndarray:
        """``area_m2`` of a float array (the simulator's strips, every step), same bits.

        ``max_depth_m``: depth_m.max() if the caller has it; the deck's clip (below the deck)
        and the strut's part (all below the float line) are then skipped where they add
        nothing. The segment's clips fold into one: min(max(d, 0), min(float_depth, 2r))
        selects the same value as clipping min(d, float_depth) into [0, 2r], and then
        |r - d| <= r, so the clip of (r - d) / r into [-1, 1] never acts (correctly rounded
        division), nor does the clip of r^2 - h^2 at 0 (correctly rounded products are
        monotonic: |h| <= r gives h h <= r r).
        """
        k = self._operands
        deck = max_depth_m is None or max_depth_m > self.top_depth_m
        d = np.minimum(depth_m, k.top_depth) if deck else depth_m
        # the same operations on the same operands as
        # h = r - min(max(d, 0), min(float_depth, 2r));
        # r^2 acos(h / r) - h sqrt(r^2 - h^2) + strut max(d - float_depth, 0)
        h = _clip(d, k.zero, k.segment_cap)   # min(max(d, 0), ...): same bits
        np.subtract(k.radius, h, out=h)
        out = np.divide(h, k.radius)
        np.arccos(out, out=out)
        out *= k.radius_sq
        root = h * h
        np.subtract(k.radius_sq, root, out=root)
        np.sqrt(root, out=root)
        root *= h
        out -= root
        if max_depth_m is not None and max_depth_m <= self.float_depth_m:
            return out                        # the strut's part is +0.0 everywhere
        strut = np.subtract(d, k.float_depth, out=d if deck else None)
        np.maximum(strut, k.zero, out=strut)
        strut *= k.strut_width
        out += strut
        return out

    def max_area_m2(self) -> float:
        """The whole section, deck awash (unbounded for a strut without a deck), m^2."""
        if math.isfinite(self.top_depth_m):
            return float(self.area_m2(self.top_depth_m))
        return math.pi * self.radius_m ** 2 if self.strut_width_m == 0.0 else math.inf

    def heave_width_m(self, secant_m: float = 0.02) -> float:
        """Waterline width of one hull for small heaves about the float line, m: the mean of
        the strut's above it and the cylinder's secant over ``secant_m`` below it (the
        cylinder widens downwards). Times rho g and the length: the heave stiffness."""
        d0 = self.float_depth_m
        cylinder = (float(segment_area_m2(d0, self.radius_m))
                    - float(segment_area_m2(d0 - secant_m, self.radius_m))) / secant_m
        return 0.5 * (self.strut_width_m + cylinder)

    def area_integral_m3_per_m(self, depth_m: float) -> float:
        """int_0^d area(u) du, m^3/m: the volume of a hull dipping 1 m per metre to depth d."""
        return _area_integral(depth_m, self.radius_m, self.float_depth_m, self.strut_width_m,
                              self.top_depth_m, self._float_area_m2, self._top_area_m2)

    def line_volume_m3(self, depth0_m: float, gradient: float, bow_x_m: float,
                       stern_x_m: float) -> float:
        """ONE hull from stern_x to bow_x whose bottom line has depth0 + gradient x of water
        over it (body x), m^3, exact."""
        if abs(gradient) < 1e-9:
            return float(self.area_m2(depth0_m)) * (bow_x_m - stern_x_m)
        return _sloped_line_volume(depth0_m, gradient, bow_x_m, stern_x_m, self.radius_m,
                                   self.float_depth_m, self.strut_width_m, self.top_depth_m,
                                   self._float_area_m2, self._top_area_m2)


def warm() -> None:
    """Compile (or load) the kernels (``make setup`` runs this once per build)."""
    section = HullSection(0.2, 0.3, 0.1, 0.5)
    section.line_volume_m3(0.1, 0.05, 1.0, -1.0)
    segment_area_integral_m3_per_m(0.1, 0.2)


def hull_volume_from_depths(depths_m: np.ndarray, radius_m: float, length_m: float) -> float:
    """Submerged volume of ONE hull from the water height over its bottom line, m^3.

    ``depths_m`` samples the height of the water surface above the hull's bottom
    at equally spaced stations along the hull (midpoints of equal slices); the
    cross-section at each station is a circular segment (strip theory).
    """
    depths = np.asarray(depths_m, dtype=float)
    return float(np.sum(segment_area_m2(depths, radius_m)) * length_m / depths.size)


def afloat_volume_m3(displacement_n: float, water_density_kgpm3: float,
                     gravity_mps2: float) -> float:
    """Displaced volume when afloat: Delta / (rho g), m^3."""
    return displacement_n / (water_density_kgpm3 * gravity_mps2)


def submerged_length_m(waterline_distance_m: float, slope_rad: float, hull_clearance_m: float,
                       bow_x_m: float, stern_x_m: float, surface_m: float = 0.0,
                       heading_cos: float = 1.0) -> float:
    """h2: submerged length along the hull bottom from base_link's waterline distance, m.

    base_link (centre of the track contact, on the ground) lies ``waterline_distance_m``
    seaward of the mean waterline, measured along a beach of slope ``slope_rad``; the hull
    bottom runs from ``stern_x_m`` to ``bow_x_m`` (base_link x), ``hull_clearance_m`` above
    the ground. ``surface_m`` lifts the water surface (a wave) above the mean level;
    ``heading_cos`` is cos(yaw - seaward direction): 1 bow to the sea, -1 stern to the sea.
    The result is clipped to [0, bow - stern].
    """
    depth0, gradient = bottom_depth_line(waterline_distance_m, slope_rad, hull_clearance_m,
                                         surface_m, heading_cos)
    return submerged_length_of_line_m(depth0, gradient, bow_x_m, stern_x_m)


def submerged_length_of_line_m(depth0_m: float, gradient: float, bow_x_m: float,
                               stern_x_m: float) -> float:
    """``submerged_length_m`` of the hull bottom line ``bottom_depth_line`` gave, m."""
    length = bow_x_m - stern_x_m
    depth0 = depth0_m
    if abs(gradient) < 1e-9:
        return length if depth0 > 0.0 else 0.0
    deep_x = bow_x_m if gradient > 0.0 else stern_x_m
    deep = depth0 + gradient * deep_x
    return float(min(max(deep / abs(gradient), 0.0), length))


def bottom_depth_line(waterline_distance_m: float, slope_rad: float, hull_clearance_m: float,
                       surface_m: float, heading_cos: float) -> tuple[float, float]:
    """Water depth over the hull bottom (normal to the hull) at base_link x = 0, and its
    gradient per metre of body x, for a vehicle lying on the slope."""
    cos_t = math.cos(slope_rad)
    depth_at_origin = (surface_m + waterline_distance_m * math.sin(slope_rad)) / cos_t \
        - hull_clearance_m
    return depth_at_origin, heading_cos * math.tan(slope_rad)


def grounded_volume_m3(waterline_distance_m: float, slope_rad: float, hull_clearance_m: float,
                       bow_x_m: float, stern_x_m: float, radius_m: float,
                       surface_m: float = 0.0, heading_cos: float = 1.0,
                       section: HullSection | None = None) -> float:
    """Submerged volume of BOTH hulls of a vehicle standing on the slope, m^3.

    Each hull runs from ``stern_x_m`` to ``bow_x_m``; its cross-section is ``section``
    (default: the paper's bare cylinder of ``radius_m``, vehicle.md section 6). Exact for the
    straight bottom line: the section's area integrated between the depths at the ends. Not
    capped at the displacement: compare with ``afloat_volume_m3`` to know whether the
    vehicle floats.
    """
    depth0, gradient = bottom_depth_line(waterline_distance_m, slope_rad, hull_clearance_m,
                                         surface_m, heading_cos)
    if section is None:
        section = HullSection(radius_m, 2.0 * radius_m, 0.0)
    return grounded_volume_of_line_m3(depth0, gradient, bow_x_m, stern_x_m, section)


def grounded_volume_of_line_m3(depth0_m: float, gradient: float, bow_x_m: float,
                               stern_x_m: float, section: HullSection) -> float:
    """``grounded_volume_m3`` of the hull bottom line ``bottom_depth_line`` gave, m^3."""
    return 2.0 * section.line_volume_m3(depth0_m, gradient, bow_x_m, stern_x_m)


def afloat_dynamic_volume_m3(displacement_n: float, heave_mass_kg_: float,
                             vertical_accel_mps2: float, water_density_kgpm3: float,
                             gravity_mps2: float) -> float:
    """Submerged volume of a floating, heaving vehicle from its vertical acceleration, m^3.

    Newton in heave with the tracks off the ground: rho g V = Delta + m_h a_z (damping
    neglected), so the IMU's heave acceleration tells how deep the hulls are pushed.
    """
    return (displacement_n + heave_mass_kg_ * vertical_accel_mps2) / (
        water_density_kgpm3 * gravity_mps2)
