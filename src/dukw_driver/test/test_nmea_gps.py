"""DGPS over NMEA: fix status from GGA quality, covariance from GST or HDOP, ENU velocity."""
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from dukw_driver.gnss import CovarianceKind, FixStatus, GnssFix, GnssVelocity, UereSettings
from dukw_driver.nmea_gps import GpsNmeaDecoder, NmeaGpsSettings
from damage import damaged_stream
from dukw_driver.nmea_stream import nmea_sentence

SETTINGS = NmeaGpsSettings(UereSettings(autonomous_m=4.0, differential_m=0.7),
                           speed_std_mps=0.1, gst_max_age_s=1.5)


def gga(quality=2, hdop='0.9', lat='3642.000', lat_dir='N', lon='12148.000', lon_dir='W'):
    return nmea_sentence(f'GPGGA,120000.00,{lat},{lat_dir},{lon},{lon_dir},{quality},09,'
                         f'{hdop},10.0,M,-30.0,M,1.0,0042')


GST = nmea_sentence('GPGST,120000.00,0.5,0.40,0.30,10.0,0.30,0.20,0.60')


def test_dgps_fix_with_gst_covariance_in_enu_order():
    dec = GpsNmeaDecoder(SETTINGS)
    assert dec.feed(GST, 0.0) == []
    (fix,) = dec.feed(gga(quality=2), 0.5)
    assert isinstance(fix, GnssFix)
    assert fix.status == FixStatus.GBAS_FIX
    assert fix.latitude_deg == pytest.approx(36.7)
    assert fix.longitude_deg == pytest.approx(-121.8)          # W is negative
    assert fix.altitude_m == pytest.approx(10.0 - 30.0)         # MSL + geoid separation
    # east (longitude error) first, then north (latitude error), then up
    assert fix.covariance_enu_m2 == pytest.approx((0.04, 0.09, 0.36))
    assert fix.covariance_kind == CovarianceKind.DIAGONAL_KNOWN


def test_without_recent_gst_the_covariance_comes_from_hdop():
    dec = GpsNmeaDecoder(SETTINGS)
    dec.feed(GST, 0.0)
    (fix,) = dec.feed(gga(quality=1, hdop='2.0'), 3.0)         # GST 3 s old: too old
    assert fix.status == FixStatus.FIX
    assert fix.covariance_kind == CovarianceKind.APPROXIMATED
    assert fix.covariance_enu_m2 == pytest.approx((64.0, 64.0, 256.0))   # (2.0 * 4 m)^2
    (dfix,) = dec.feed(gga(quality=2, hdop='2.0'), 3.1)
    assert dfix.covariance_enu_m2[0] == pytest.approx((2.0 * 0.7) ** 2)


@pytest.mark.parametrize('quality,status', [(0, FixStatus.NO_FIX), (1, FixStatus.FIX),
                                            (2, FixStatus.GBAS_FIX), (4, FixStatus.GBAS_FIX),
                                            (5, FixStatus.GBAS_FIX), (6, FixStatus.NO_FIX),
                                            (9, FixStatus.SBAS_FIX)])
def test_gga_quality_maps_to_navsat_status(quality, status):
    (fix,) = GpsNmeaDecoder(SETTINGS).feed(gga(quality=quality), 0.0)
    assert fix.status == status
    if status == FixStatus.NO_FIX:
        assert math.isnan(fix.latitude_deg) and fix.covariance_kind == CovarianceKind.UNKNOWN


def test_fix_without_position_is_a_parse_error():
    dec = GpsNmeaDecoder(SETTINGS)
    assert dec.feed(gga(quality=1, lat='', lat_dir='', lon='', lon_dir=''), 0.0) == []
    assert dec.counters.parse_errors == 1


def test_vtg_heading_east_at_10_knots_gives_east_velocity():
    dec = GpsNmeaDecoder(SETTINGS)
    (vel,) = dec.feed(nmea_sentence('GPVTG,090.0,T,,M,10.0,N,18.52,K,D'), 0.0)
    assert isinstance(vel, GnssVelocity)
    assert vel.east_mps == pytest.approx(18.52 / 3.6)
    assert vel.north_mps == pytest.approx(0.0, abs=1e-9)
    assert vel.variance_enu[0] == pytest.approx(0.01) and vel.variance_enu[2] > 1e3


def test_rmc_gives_velocity_only_when_no_vtg_comes():
    dec = GpsNmeaDecoder(SETTINGS)
    rmc = nmea_sentence('GPRMC,120000.00,A,3642.000,N,12148.000,W,2.0,180.0,221126,,,D')
    (vel,) = dec.feed(rmc, 0.0)
    assert vel.north_mps == pytest.approx(-2.0 * 1852 / 3600)
    dec.feed(nmea_sentence('GPVTG,180.0,T,,M,2.0,N,3.704,K,D'), 1.0)
    assert dec.feed(rmc, 1.5) == []
    void = nmea_sentence('GPRMC,120000.00,V,,,,,,,221126,,,N')
    assert dec.feed(void, 10.0) == []


def test_no_velocity_while_the_receiver_says_it_is_not_valid():
    dec = GpsNmeaDecoder(SETTINGS)
    assert dec.feed(nmea_sentence('GPVTG,,T,,M,0.000,N,0.000,K,N'), 0.0) == []   # no fix
    assert dec.feed(nmea_sentence('GPVTG,090.0,T,,M,1.0,N,1.852,K,E'), 0.1) == []  # dead reck.
    void = nmea_sentence('GPRMC,120000.00,V,3642.000,N,12148.000,W,0.0,,221126,,,A')
    assert dec.feed(void, 1.0) == []
    assert dec.feed(nmea_sentence('GPVTG,,T,,M,0.0,N,0.0,K,A'), 1.1) == []  # RMC said void
    rmc = nmea_sentence('GPRMC,120000.00,A,3642.000,N,12148.000,W,0.0,,221126,,,D')
    dec.feed(rmc, 2.0)
    (vel,) = dec.feed(nmea_sentence('GPVTG,,T,,M,0.0,N,0.0,K,D'), 2.1)    # fix back
    assert (vel.east_mps, vel.north_mps) == (0.0, 0.0)


def test_standing_still_without_course_is_zero_velocity():
    (vel,) = GpsNmeaDecoder(SETTINGS).feed(nmea_sentence('GPVTG,,T,,M,0.0,N,0.0,K,A'), 0.0)
    assert (vel.east_mps, vel.north_mps) == (0.0, 0.0)


SENTENCES = [gga(), GST, nmea_sentence('GPVTG,054.7,T,034.4,M,005.5,N,010.2,K,D'),
             nmea_sentence('GPRMC,120000.00,A,3642.000,N,12148.000,W,2.0,180.0,221126,,,D')]


@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(st.sampled_from(SENTENCES), st.integers(0, 80), st.integers(0, 255),
                          st.booleans()), max_size=10), st.binary(max_size=40))
def test_truncated_corrupted_and_random_input_never_raises(parts, noise):
    dec = GpsNmeaDecoder(SETTINGS)
    stream, damaged = damaged_stream(parts)
    out = dec.feed(stream + noise + b'\r\n', 0.0)
    for item in out:
        assert isinstance(item, (GnssFix, GnssVelocity))
    if damaged:
        assert dec.counters.errors >= 1


def test_source_preference_falls_back_only_while_the_preferred_is_silent():
    from dukw_common.config import ConfigError
    from dukw_driver.gnss import GnssSource, SourcePreference, parse_source
    pref = SourcePreference(GnssSource.NMEA, fallback_after_s=2.0)
    assert pref.accept(GnssSource.MAVLINK, 0.0)          # nothing from the DGPS yet
    assert pref.accept(GnssSource.NMEA, 1.0)
    assert not pref.accept(GnssSource.MAVLINK, 2.5)
    assert pref.accept(GnssSource.MAVLINK, 3.5)          # DGPS silent for 2.5 s
    # the DGPS reports 'no fix': the IMU's GPS keeps filling in, the no-fix is not published
    assert not pref.accept(GnssSource.NMEA, 4.0, usable=False)
    assert pref.accept(GnssSource.MAVLINK, 4.1)
    assert pref.accept(GnssSource.NMEA, 4.5)             # the DGPS has its fix back
    assert not pref.accept(GnssSource.MAVLINK, 4.6)
    # nobody has a fix: the preferred receiver's no-fix is published
    lone = SourcePreference(GnssSource.NMEA, fallback_after_s=2.0)
    assert lone.accept(GnssSource.NMEA, 0.0, usable=False)
    assert parse_source('mavlink', 'x') == GnssSource.MAVLINK
    with pytest.raises(ConfigError, match='fix_source'):
        parse_source('glonass', 'fix_source')
