"""GNSS fixes and velocities as the IMU/GPS decoders produce them, in ROS conventions. ROS-free.

Positions are WGS 84 (latitude, longitude in degrees, altitude above the ellipsoid
where the device gives it, else above mean sea level). Covariances are diagonal in
ENU order (east, north, up), as sensor_msgs/NavSatFix wants. Velocities are ENU.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum, IntEnum

from dukw_common.config import ConfigError


class FixStatus(IntEnum):
    """sensor_msgs/NavSatStatus status values."""

    NO_FIX = -1
    FIX = 0
    SBAS_FIX = 1
    GBAS_FIX = 2     # differential from a ground station: DGPS, RTK


class CovarianceKind(IntEnum):
    """sensor_msgs/NavSatFix position_covariance_type values."""

    UNKNOWN = 0
    APPROXIMATED = 1
    DIAGONAL_KNOWN = 2


class GnssSource(str, Enum):
    """Which receiver a fix or velocity came from."""

    NMEA = 'nmea'        # the differential GPS
    MAVLINK = 'mavlink'  # the GPS of the GPS-aided IMU


@dataclass(frozen=True)
class GnssFix:
    """One position fix as a receiver's decoder gives it (before stamping; the estimator's
    reading of the published fix is dukw_common.readings.GpsFix)."""

    source: GnssSource
    status: FixStatus
    latitude_deg: float
    longitude_deg: float
    altitude_m: float
    covariance_enu_m2: tuple[float, float, float]
    covariance_kind: CovarianceKind


@dataclass(frozen=True)
class GnssVelocity:
    """Velocity over ground in ENU, m/s, with diagonal variances (m/s)^2, as a receiver's
    decoder gives it (the published reading: dukw_common.readings.GpsVelocity)."""

    source: GnssSource
    east_mps: float
    north_mps: float
    up_mps: float
    variance_enu: tuple[float, float, float]
    valid: bool = True    # False: the receiver had no fix (never published; the other is used)


@dataclass(frozen=True)
class UereSettings:
    """User-equivalent range error (1 sigma, m) to turn a DOP into a covariance."""

    autonomous_m: float   # plain GPS / SBAS fix
    differential_m: float  # DGPS / RTK fix

    def for_status(self, status: FixStatus) -> float:
        """The UERE that goes with a fix status."""
        return self.differential_m if status == FixStatus.GBAS_FIX else self.autonomous_m


def dop_covariance(hdop: float, status: FixStatus, uere: UereSettings) -> tuple:
    """Approximate ENU variances from the horizontal DOP (vertical taken as twice HDOP)."""
    sigma_h = hdop * uere.for_status(status)
    return (sigma_h ** 2, sigma_h ** 2, (2.0 * sigma_h) ** 2)


def velocity_from_course(speed_mps: float, course_deg: float, variance_mps2: float,
                         source: GnssSource) -> GnssVelocity:
    """Speed and course over ground (clockwise from true north) -> ENU velocity.

    The vertical speed is unknown: reported 0 with a huge variance.
    """
    course = math.radians(course_deg)
    return GnssVelocity(source, speed_mps * math.sin(course), speed_mps * math.cos(course), 0.0,
                       (variance_mps2, variance_mps2, 1.0e6))


def finite(*values: float) -> bool:
    """True when every value is a finite number."""
    return all(isinstance(v, (int, float)) and math.isfinite(v) for v in values)


def parse_source(value: object, name: str) -> GnssSource:
    """Parameter text -> GnssSource; ConfigError naming the parameter if it is neither."""
    try:
        return GnssSource(value)
    except ValueError:
        raise ConfigError(f'parameter {name!r} must be one of '
                          f'{[s.value for s in GnssSource]}, got {value!r}') from None


class SourcePreference:
    """Take one receiver's data; use the other only while the preferred one has nothing usable.

    "Usable" is a fix with a position (a NO_FIX report is not), or any velocity. A
    preferred receiver's unusable data is still published while the other has had
    nothing usable either, so subscribers see the no-fix status.
    """

    def __init__(self, preferred: GnssSource, fallback_after_s: float) -> None:
        self.preferred = preferred
        self.fallback_after_s = fallback_after_s
        self._last_preferred_s = -math.inf
        self._last_fallback_s = -math.inf

    def accept(self, source: GnssSource, now_s: float, usable: bool = True) -> bool:
        """True if data from ``source`` arriving at ``now_s`` should be published."""
        if source == self.preferred:
            if usable:
                self._last_preferred_s = now_s
                return True
            return now_s - self._last_fallback_s > self.fallback_after_s
        if now_s - self._last_preferred_s <= self.fallback_after_s:
            return False
        if usable:
            self._last_fallback_s = now_s
        return True
