"""The differential GPS on NMEA 0183: GGA, RMC, VTG and GST to fixes and velocities. ROS-free.

- GGA gives the fix; its quality field gives the status (2 = DGPS, 4/5 = RTK:
  a ground-based correction, GBAS_FIX; 9 = WAAS/SBAS; 1 = autonomous; 0, 6
  (dead reckoning), 7 (manual) and 8 (simulator) = no fix).
- GST gives the 1-sigma latitude, longitude and altitude errors; a GST younger
  than ``gst_max_age_s`` makes the fix's covariance DIAGONAL_KNOWN, otherwise it
  is APPROXIMATED from HDOP times a UERE.
- VTG (preferred) or RMC (when no VTG came within ``VTG_PREFERRED_S``) gives
  speed and course over ground -> ENU velocity, only while the receiver says it
  is valid: a VTG or RMC mode indicator N (not valid) or E (dead reckoning), an
  RMC status V, or a VTG within ``VTG_PREFERRED_S`` of an RMC with status V gives
  no velocity (a receiver without a fix sends "0.0": not a standing still).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from dukw_driver.gnss import (CovarianceKind, FixStatus, GnssSource, GnssFix, GnssVelocity,
                              UereSettings, dop_covariance, finite, velocity_from_course)
from dukw_driver.nmea_stream import NmeaStream

KNOT_MPS = 1852.0 / 3600.0
#: An RMC velocity is dropped while VTG sentences keep coming within this time.
VTG_PREFERRED_S = 2.0

#: NMEA 2.3 mode indicators (VTG, RMC) that mean the speed is not a measurement.
INVALID_MODES = ('N', 'E')

GGA_STATUS = {1: FixStatus.FIX, 2: FixStatus.GBAS_FIX, 3: FixStatus.GBAS_FIX,
              4: FixStatus.GBAS_FIX, 5: FixStatus.GBAS_FIX, 9: FixStatus.SBAS_FIX}


@dataclass(frozen=True)
class NmeaGpsSettings:
    """How the decoder turns the receiver's figures into covariances."""

    uere: UereSettings
    speed_std_mps: float      # 1 sigma of speed over ground per axis (not reported by NMEA)
    gst_max_age_s: float      # a GST older than this no longer describes the fix


class GpsNmeaDecoder:
    """Bytes from the DGPS in, GnssFix and GnssVelocity out; never raises on bad input."""

    def __init__(self, settings: NmeaGpsSettings) -> None:
        self.settings = settings
        self._handlers = {'GGA': self._on_gga, 'RMC': self._on_rmc, 'VTG': self._on_vtg,
                          'GST': self._on_gst}
        self.stream = NmeaStream(self._handlers)
        self.counters = self.stream.counters
        self._gst: tuple[float, float, float, float] | None = None  # lat, lon, alt std, time
        self._last_vtg_s = -math.inf
        self._rmc_void_s = -math.inf    # when an RMC last said status V

    def reset(self) -> None:
        """Forget partial input and the last GST (after a reconnect)."""
        self.stream.reset()
        self._gst = None

    def feed(self, data: bytes, now_s: float) -> list[GnssFix | GnssVelocity]:
        """Decode received bytes at time ``now_s``."""
        return self.stream.decode(data, now_s, self._handlers)

    def _on_gga(self, gga, now_s: float) -> GnssFix:
        quality = gga.gps_qual
        status = GGA_STATUS.get(quality if quality is not None else 0, FixStatus.NO_FIX)
        if status == FixStatus.NO_FIX:
            nan = math.nan
            return GnssFix(GnssSource.NMEA, status, nan, nan, nan, (0.0, 0.0, 0.0),
                          CovarianceKind.UNKNOWN)
        if not gga.lat or not gga.lon:
            raise ValueError('fix without a position')
        latitude, longitude = float(gga.latitude), float(gga.longitude)
        altitude = float(gga.altitude) + (float(gga.geo_sep) if gga.geo_sep else 0.0)
        if not finite(latitude, longitude, altitude) or abs(latitude) > 90 or abs(
                longitude) > 180:
            raise ValueError('position out of range')
        covariance, kind = self._covariance(gga, status, now_s)
        return GnssFix(GnssSource.NMEA, status, latitude, longitude, altitude, covariance, kind)

    def _covariance(self, gga, status: FixStatus, now_s: float) -> tuple:
        if self._gst is not None and now_s - self._gst[3] <= self.settings.gst_max_age_s:
            lat_std, lon_std, alt_std, _ = self._gst
            return (lon_std ** 2, lat_std ** 2, alt_std ** 2), CovarianceKind.DIAGONAL_KNOWN
        if gga.horizontal_dil:
            hdop = float(gga.horizontal_dil)
            if finite(hdop) and hdop > 0:
                return dop_covariance(hdop, status, self.settings.uere), \
                    CovarianceKind.APPROXIMATED
        return (0.0, 0.0, 0.0), CovarianceKind.UNKNOWN

    def _on_gst(self, gst, now_s: float) -> None:
        stds = (gst.std_dev_latitude, gst.std_dev_longitude, gst.std_dev_altitude)
        if any(s is None for s in stds) or not finite(*stds) or min(stds) < 0:
            raise ValueError('GST without usable standard deviations')
        self._gst = (*(float(s) for s in stds), now_s)

    def _on_vtg(self, vtg, now_s: float) -> GnssVelocity | None:
        self._last_vtg_s = now_s
        if getattr(vtg, 'faa_mode', '') in INVALID_MODES or \
                now_s - self._rmc_void_s < VTG_PREFERRED_S:
            return None
        if vtg.spd_over_grnd_kmph is not None:
            speed = float(vtg.spd_over_grnd_kmph) / 3.6
        elif vtg.spd_over_grnd_kts is not None:
            speed = float(vtg.spd_over_grnd_kts) * KNOT_MPS
        else:
            return None
        return self._velocity(speed, vtg.true_track)

    def _on_rmc(self, rmc, now_s: float) -> GnssVelocity | None:
        if rmc.status != 'A' or getattr(rmc, 'mode_indicator', '') in INVALID_MODES:
            self._rmc_void_s = now_s
            return None
        self._rmc_void_s = -math.inf
        if now_s - self._last_vtg_s < VTG_PREFERRED_S:
            return None
        if rmc.spd_over_grnd is None:
            return None
        return self._velocity(float(rmc.spd_over_grnd) * KNOT_MPS, rmc.true_course)

    def _velocity(self, speed_mps: float, course_deg) -> GnssVelocity | None:
        if not finite(speed_mps) or speed_mps < 0:
            raise ValueError('bad speed over ground')
        if course_deg is None:
            if speed_mps > 0:
                return None  # moving with no course: nothing to publish
            course_deg = 0.0
        course = float(course_deg)
        if not finite(course):
            raise ValueError('bad course over ground')
        return velocity_from_course(speed_mps, course, self.settings.speed_std_mps ** 2,
                                    GnssSource.NMEA)
