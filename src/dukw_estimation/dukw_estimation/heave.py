"""The hull's heave and the water surface: where the keel is against the beach and the wave,
ROS-free.

The EKF carries the height of base_link (the keel: the tracks' bottom) above the mean water
level and its rate (``Idx.HEAVE``, ``Idx.HEAVE_RATE``), driven by the IMU's vertical
acceleration and corrected by the DGPS's up velocity (``motion_filter``). Two measurements
tie that height to the surface states (waterline distance s, wave eta):

- on the sand the keel lies on the beach: its height is the beach's under base_link,
  -s sin(slope) (``heave.ground_sigma_m``: the tracks' sinkage and the sand's ripples);
- afloat the keel hangs under the local surface by the dynamic draft. Newton in heave with
  the tracks off the ground, rho g V = Delta + m a + c w (the heave mass and damping from
  the hulls' waterplane and the measured natural frequency and damping, vehicle.md 1 and 5:
  ``seakeeping.heave_constants``, the simulator's too), and the level hulls' section
  (``buoyancy.HullSection``) gives the depth D(V) of the keel under a level surface that
  puts V under water: eta - z = D(V(a, w)) (``heave.surface_sigma_m``: the surface is not
  level over the hulls' length, and the hull pitches).

So afloat the wave at the hulls is measured through the hull's heave (from the beach's height
where it lifted off; starting afloat, the wave's zero mean pins the pair), and at a touchdown
the estimate carries onto the sand the surface the hull floated in: the water over the keel
is the draft it floated at (issue 18: in the surf nothing else measured the wave afloat, and
the surface at a touchdown decided most of a run's volume error).
"""
from __future__ import annotations

import math

import numpy as np

from dukw_common.vehicle import Vehicle
from dukw_estimation.contact import ContactModel
from dukw_estimation.ekf import (HEAVE_STATES, HEAVE_SURFACE_STATES, N_STATES, WAVE_HEAVE_STATES,
                                 Idx, MotionEkf, Outcome)
from dukw_estimation.settings import EkfSettings

#: depth step of the level hulls' volume table, m (the section's area is smooth on this scale)
TABLE_STEP_M = 0.001
_S, _ETA, _HEAVE, _HEAVE_RATE = int(Idx.S), int(Idx.ETA), int(Idx.HEAVE), int(Idx.HEAVE_RATE)


class HeaveObserver:
    """The keel on the beach or under the wave: measurements of the heave and surface states."""

    def __init__(self, vehicle: Vehicle, settings: EkfSettings, contact: ContactModel) -> None:
        self.vehicle = vehicle
        self.settings = settings
        self.contact = contact
        body = vehicle.body
        section = contact.section
        # both level hulls' volume against the water over their bottom, up to the deck
        length = contact.hull_bow_x_m - contact.hull_stern_x_m
        top = section.top_depth_m if math.isfinite(section.top_depth_m) \
            else 2.0 * section.radius_m + 1.0
        depths = np.arange(0.0, top + 0.5 * TABLE_STEP_M, TABLE_STEP_M)
        volumes = 2.0 * length * np.array([float(section.area_m2(d)) for d in depths])
        keep = np.concatenate(([True], np.diff(volumes) > 0.0))   # strictly increasing
        self._volumes = volumes[keep]
        self._depths = depths[keep] + body.hull_clearance_m     # the keel's depth
        self._rho_g = body.water_density_kgpm3 * body.gravity_mps2
        self.reset()

    def reset(self) -> None:
        """Forget the counts and the last contact decision."""
        self.was_afloat = False
        self.surface_updates = 0
        self.ground_updates = 0
        self.last_accel_mps2 = math.nan  # the last heave acceleration short of an impact
        self.impact_drafts = 0           # drafts measured when the sand struck the keel
        self.held_at_beach = 0           # afloat, drafts asking for more water at the beach
        self.track_end_drop_m = 0.0      # the lowest track point below the keel's middle, m

    def keel_depth_m(self, volume_m3: float) -> tuple[float, float]:
        """(The keel's depth under a level surface with ``volume_m3`` of the hulls under it,
        d depth / d volume), m, m/m^3; NaN beyond the empty hulls or the deck awash."""
        v = self._volumes
        if not v[0] < volume_m3 < v[-1]:
            return math.nan, math.nan
        k = int(np.searchsorted(v, volume_m3))
        d0, d1, v0, v1 = self._depths[k - 1], self._depths[k], v[k - 1], v[k]
        per_m3 = (d1 - d0) / (v1 - v0)
        return float(d0 + (volume_m3 - v0) * per_m3), float(per_m3)

    def update(self, ekf: MotionEkf, heave_accel_mps2: float, placed: bool,
               track_end_drop_m: float = 0.0) -> Outcome:
        """The measurement the contact decision implies, for one IMU sample: afloat the keel
        under the wave by the dynamic draft, on the sand the keel on the beach. Nothing before
        the filter is ``placed`` (its first fix: the waterline distance, the contact decision
        follow from there).

        An impact (``ContactModel.impact``: the sand striking the keel) is the touchdown
        itself, whatever the contact decision says (it may have said the sand while the hull
        still floated): the hull floated up to the sample before, so the water over the keel
        is the dynamic draft of that sample's acceleration, measured then, with the keel at
        the beach (the keel-at-beach bound does not apply). ``track_end_drop_m``: the lowest
        track point this far below the keel's middle (``ContactModel.track_end_drop_m``):
        it, not the middle, meets the beach."""
        self.track_end_drop_m = track_end_drop_m
        if not placed:
            return Outcome.IGNORED
        impact = self.contact.impact(heave_accel_mps2)
        floated = self.last_accel_mps2
        if not impact:
            self.last_accel_mps2 = heave_accel_mps2
        elif math.isfinite(floated) and self._afloat(ekf, floated, at_impact=True) \
                is Outcome.ACCEPTED:
            self.impact_drafts += 1
        if self.contact.afloat:
            self.was_afloat = True
            return self._afloat(ekf, heave_accel_mps2)
        touchdown, self.was_afloat = self.was_afloat, False
        return self._on_sand(ekf, touchdown)

    def _beach_row(self, x: np.ndarray) -> tuple[float, np.ndarray]:
        """The lowest track point's height over the estimated beach under base_link,
        heave - track_end_drop_m + s sin(slope), m, and its Jacobian (a hull tilted against
        the beach rests on a track end, its keel's middle above the beach)."""
        sin_t = math.sin(self.contact.slope_rad)
        h = np.zeros(N_STATES)
        h[_HEAVE] = 1.0
        h[_S] = sin_t
        return float(x[_HEAVE] - self.track_end_drop_m + x[_S] * sin_t), h

    def _on_sand(self, ekf: MotionEkf, touchdown: bool) -> Outcome:
        """The keel on the beach. At a touchdown the floating hull's keel meets the beach:
        the heave, the wave and the waterline distance tie (the water over the keel is the
        draft it floated at, whatever the slope). On the sand after it the beach's height under
        the keel follows the estimated slope, which may not be the true one (a steeper beach
        lifts the keel faster than s sin(slope) says), so it moves the heave only."""
        clearance, h = self._beach_row(ekf.x)
        out = ekf.update_scalar(0.0, clearance, h,
                                self.settings.heave_ground_m ** 2, self.settings.heave_gate,
                                only=HEAVE_SURFACE_STATES if touchdown else HEAVE_STATES)
        if out is Outcome.ACCEPTED:
            self.ground_updates += 1
        return out

    def _afloat(self, ekf: MotionEkf, heave_accel_mps2: float, at_impact: bool = False
                ) -> Outcome:
        """Afloat: the keel under the wave by the dynamic draft. But the contact decision
        may say afloat while the keel lies on the sand (it lags a grounding by the IMU's
        motion test, which the landing's jolt itself keeps up, and leads a lift-off): with
        the keel within ``heave.keel_at_beach_m`` of the estimated beach a draft asking for
        more water than the estimate is not used (a hull lying on the sand has at most its
        floating draft of water over its keel; the draft of a stopped hull reads as a
        stopped wave); one asking for less still is. ``at_impact``: the draft the hull
        floated at when the sand struck (``update``)."""
        if not math.isfinite(heave_accel_mps2):
            return Outcome.IGNORED
        x, contact, st = ekf.x, self.contact, self.settings
        if contact.impact(heave_accel_mps2):
            return Outcome.IGNORED       # the sand striking the keel is not a draft
        volume = contact.afloat_volume_m3(heave_accel_mps2, float(x[_HEAVE_RATE]), True)
        depth, per_m3 = self.keel_depth_m(volume)
        if not math.isfinite(depth):
            return Outcome.IGNORED
        if not at_impact and st.heave_keel_at_beach_m > 0.0 \
                and depth > float(x[_ETA] - x[_HEAVE]) \
                and self._beach_row(x)[0] < st.heave_keel_at_beach_m:
            self.held_at_beach += 1
            return Outcome.IGNORED
        h = np.zeros(N_STATES)
        h[_ETA] = 1.0
        h[_HEAVE] = -1.0
        h[_HEAVE_RATE] = -per_m3 * contact.heave_damping_n_per_mps / self._rho_g
        out = ekf.update_scalar(depth, float(x[_ETA] - x[_HEAVE]), h,
                                self.settings.heave_surface_m ** 2, self.settings.heave_gate,
                                only=WAVE_HEAVE_STATES)
        if out is Outcome.ACCEPTED:
            self.surface_updates += 1
        return out
