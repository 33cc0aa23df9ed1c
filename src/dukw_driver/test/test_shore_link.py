"""The shore link's ROS-free core against a real pymavlink ground station (no ROS, no sockets)."""
import math
import time

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pymavlink.dialects.v20 import common as mavlink

from dukw_common.config import ConfigError, node_params
from dukw_driver.mavlink_signing import (SecureSigning, TimestampStore, generate_key_file,
                                         key_from_passphrase, load_key, parse_key,
                                         signing_timestamp)
from dukw_driver.shore_link import (DriveCommand, MissionHold, MissionPlan, ModeRequest,
                                    ShoreLink, settings_from_params)
from dukw_driver.shore_telemetry import DriveTelemetry, Fix, Pose, TractionState
from shore_gcs import KEY, WRONG_KEY, Gcs


def make_link(now_s=0.0, signing=True, state=None, **overrides):
    params = {**node_params('shore_link_node'), **overrides}
    shore_settings, tuning = settings_from_params(params)
    signer = SecureSigning(KEY, state=state) if signing else None
    return ShoreLink(shore_settings, tuning, signer, now_s)


def full_state(link):
    link.state.pose = Pose(x_m=-5.0, y_m=2.0, yaw_rad=0.3, surge_mps=1.0)
    link.state.fix = Fix(36.18, -75.75, 1.0, 2, 0.3, 0.6)
    link.update_mode(0, True, 'on the sand')
    link.update_authority(1, True, 'startup')
    drive = DriveTelemetry(True, (20.0, 22.0), (24.5, 24.4), (50.0, 52.0))
    link.update_drive('tracks', drive)
    link.update_drive('props', drive)
    link.state.traction = TractionState((0.1, 0.12), 0.05, 0.9, False)


# ---- the key ---------------------------------------------------------------------------------
def test_key_is_32_raw_bytes_or_64_hex_characters(tmp_path):
    assert parse_key(KEY) == KEY
    assert parse_key(KEY.hex().encode() + b'\n') == KEY
    for bad in (b'', b'short', KEY + b'x', b'zz' * 32):
        with pytest.raises(ConfigError, match='32 raw bytes or 64 hex'):
            parse_key(bad)
    key, passphrase = generate_key_file(tmp_path / 'k' / 'shore.key')
    assert load_key(tmp_path / 'k' / 'shore.key') == key == key_from_passphrase(passphrase)
    assert (tmp_path / 'k' / 'shore.key.passphrase').read_text().strip() == passphrase
    assert (tmp_path / 'k' / 'shore.key').stat().st_mode & 0o077 == 0
    with pytest.raises(ConfigError, match='cannot read'):
        load_key(tmp_path / 'missing.key')


# ---- signing ---------------------------------------------------------------------------------
def test_signed_packets_are_accepted_others_rejected_and_counted_by_reason():
    link, gcs = make_link(), Gcs()
    good = gcs.heartbeat()
    link.receive(good, 0.0)
    assert link.gcs == (255, 190)
    link.receive(Gcs(key=None).manual(800), 0.1)               # unsigned
    link.receive(Gcs(key=WRONG_KEY).manual(800), 0.2)          # a stranger's key
    link.receive(good, 0.3)                                    # replayed
    forged = bytearray(gcs.manual(800))
    forged[12] ^= 0x01                                         # altered payload, CRC fixed below
    assert link.receive(bytes(forged), 0.4) == []
    counts = link.signing.counts()
    assert counts['rejected_unsigned'] == 1
    assert counts['rejected_bad_signature'] == 1
    assert counts['rejected_replayed'] == 1
    assert counts['accepted_signed'] == 1
    assert 'MANUAL_CONTROL' not in link.packets_in


def test_unsigned_accepted_only_when_allowed():
    signer = SecureSigning(KEY, allow_unsigned=True)
    shore_settings, tuning = settings_from_params(node_params('shore_link_node'))
    link = ShoreLink(shore_settings, tuning, signer, 0.0)
    assert link.receive(Gcs(key=None).manual(500), 0.0) == [
        MissionHold(True), DriveCommand(0.5, 0.0)]


def test_future_timestamp_forgery_locks_out_stock_pymavlink_but_not_the_shore_link():
    gcs, stranger = Gcs(link_id=1), Gcs(key=WRONG_KEY, link_id=1)   # same stream id
    stranger.mav.signing.timestamp = signing_timestamp(time.time() + 86400.0)  # a day ahead
    forged = stranger.manual(1000)
    real = [gcs.manual(300) for _ in range(3)]
    stock = mavlink.MAVLink(None, 1, 1)                    # pymavlink's own check
    stock.robust_parsing = True
    stock.signing.secret_key = KEY
    stock.signing.timestamp = signing_timestamp(time.time())
    stock.parse_buffer(forged)
    stock_got = [m for m in stock.parse_buffer(b''.join(real)) or []
                 if m.get_type() == 'MANUAL_CONTROL']
    assert stock_got == [], 'stock pymavlink should be locked out (the flaw this guards against)'
    link = make_link()
    assert link.receive(forged, 0.0) == []
    actions = link.receive(b''.join(real), 0.1)
    assert [a for a in actions if isinstance(a, DriveCommand)] == [DriveCommand(0.3, 0.0)] * 3
    assert link.signing.counts()['rejected_bad_signature'] == 1


def test_timestamps_survive_a_restart(tmp_path):
    store = TimestampStore(tmp_path / 'ts.json')
    link, gcs = make_link(), Gcs()
    old = gcs.manual(500)
    link.receive(gcs.heartbeat(), 0.0)
    link.receive(old, 0.0)
    link.tick(0.0)
    sent = link.signing.snapshot().timestamp
    store.save(link.signing.snapshot())
    restarted = make_link(state=store.load())
    assert restarted.signing.snapshot().timestamp > sent
    assert restarted.receive(old, 0.0) == []                   # replayed across the restart
    assert restarted.signing.counts()['rejected_replayed'] == 1
    assert [a for a in restarted.receive(gcs.manual(500), 0.1)
            if isinstance(a, DriveCommand)] == [DriveCommand(0.5, 0.0)]
    (tmp_path / 'bad.json').write_text('{"timestamp": "x"}')
    with pytest.raises(ConfigError, match='unreadable'):
        TimestampStore(tmp_path / 'bad.json').load()


# ---- telemetry -------------------------------------------------------------------------------
def test_default_telemetry_fits_half_a_57600_baud_radio():
    link, gcs = make_link(), Gcs()
    full_state(link)
    duration_s, step_s = 20.0, 0.02
    total = 0
    for i in range(int(duration_s / step_s)):
        link.tick(i * step_s)
        data = link.take_output()
        total += len(data)
        gcs.feed(data)
    bytes_per_s = total / duration_s
    print(f'telemetry {bytes_per_s:.0f} B/s of {57600 / 10:.0f} B/s')
    assert 500.0 < bytes_per_s < 0.5 * 57600 / 10
    assert len(gcs.of_type('HEARTBEAT')) == pytest.approx(20, abs=1)
    assert len(gcs.of_type('GLOBAL_POSITION_INT')) == pytest.approx(80, abs=2)
    assert len(gcs.of_type('NAMED_VALUE_FLOAT')) == pytest.approx(9 * 20, abs=9)
    assert all(m.get_signed() for m in gcs.received)


def test_telemetry_reports_the_vehicle_in_mavlink_frames():
    link, gcs = make_link(), Gcs()
    full_state(link)
    for name in ('heartbeat', 'global_position', 'attitude', 'vfr_hud', 'named_values',
                 'battery_status', 'sys_status', 'gps_raw'):
        link._emit(name, 1.0)
    link.tick(0.0)
    gcs.feed(link.take_output())
    hb = gcs.of_type('HEARTBEAT')[0]
    assert hb.type == mavlink.MAV_TYPE_GROUND_ROVER and hb.custom_mode == 0
    assert hb.base_mode & mavlink.MAV_MODE_FLAG_SAFETY_ARMED
    pos = gcs.of_type('GLOBAL_POSITION_INT')[0]
    assert pos.lat / 1e7 == pytest.approx(36.1836 + math.degrees(2.0 / 6378137.0), abs=1e-7)
    assert pos.lon / 1e7 < -75.7510                           # 5 m west of the datum
    assert pos.hdg == pytest.approx(round((90 - math.degrees(0.3)) * 100), abs=1)
    att = gcs.of_type('ATTITUDE')[0]
    assert att.yaw == pytest.approx(math.pi / 2 - 0.3)
    values = {m.name: m.value for m in gcs.of_type('NAMED_VALUE_FLOAT')}
    assert values['trk_i_pct'] == pytest.approx(22.0 / 35.0 * 100.0, rel=1e-5)
    assert values['sub_vol_m3'] == pytest.approx(0.05)
    assert gcs.of_type('BATTERY_STATUS')[0].voltages[0] == 24500
    link.update_mode(2, False, 'forced by operator')
    link.tick(2.0)
    gcs.feed(link.take_output())
    texts = [m.text for m in gcs.of_type('STATUSTEXT')]
    assert 'mode LAND: on the sand' in texts
    assert 'mode WATER (forced): forced by operator' in texts
    link.update_drive('tracks', DriveTelemetry(True, faults=('overheat',)))
    link.update_authority(0, True, 'rc switch')
    link.tick(3.0)
    gcs.feed(link.take_output())
    texts = [m.text for m in gcs.of_type('STATUSTEXT')]
    assert 'tracks fault: overheat' in texts
    assert 'authority: RC operator: rc switch' in texts


# ---- commands --------------------------------------------------------------------------------
def test_manual_control_drives_and_its_loss_stops_within_half_a_second():
    link, gcs = make_link(), Gcs()
    actions = link.receive(gcs.manual(1000, r=500), 0.0)
    assert actions == [MissionHold(True), DriveCommand(1.0, -0.25)]   # r > 0: turn right
    assert link.tick(0.2) == []
    assert link.receive(gcs.manual(-500), 0.25) == [DriveCommand(-0.5, 0.0)]
    stops = [t for t in (0.3, 0.4, 0.5, 0.6, 0.7) if DriveCommand(0.0, 0.0) in link.tick(t)]
    assert stops and stops[0] - 0.25 <= 0.5
    assert len(stops) == 1


def test_set_mode_goes_to_the_mode_manager_and_is_acknowledged_after_it():
    link, gcs = make_link(), Gcs()
    custom = mavlink.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
    [request] = link.receive(gcs.command(mavlink.MAV_CMD_DO_SET_MODE, custom, 2), 0.0)
    assert request == ModeRequest(2, False, mavlink.MAV_CMD_DO_SET_MODE, (255, 190))
    busy = link.receive(gcs.pack(gcs.mav.set_mode_encode(1, custom, 4)), 0.1)
    assert busy == []
    link.mode_result(request, True, 'forced WATER')
    [auto] = link.receive(gcs.pack(gcs.mav.set_mode_encode(1, custom, 4)), 0.2)
    assert auto.automatic
    link.mode_result(auto, False, 'service unavailable')
    assert link.receive(gcs.command(mavlink.MAV_CMD_DO_SET_MODE, custom, 9), 0.3) == []
    gcs.feed(link.take_output())
    acks = [(a.command, a.result) for a in gcs.of_type('COMMAND_ACK')]
    assert acks == [(mavlink.MAVLINK_MSG_ID_SET_MODE, mavlink.MAV_RESULT_TEMPORARILY_REJECTED),
                    (mavlink.MAV_CMD_DO_SET_MODE, mavlink.MAV_RESULT_ACCEPTED),
                    (mavlink.MAVLINK_MSG_ID_SET_MODE, mavlink.MAV_RESULT_FAILED),
                    (mavlink.MAV_CMD_DO_SET_MODE, mavlink.MAV_RESULT_DENIED)]


def test_connect_requests_and_unknown_commands_are_answered():
    link, gcs = make_link(), Gcs()
    link.receive(gcs.command(mavlink.MAV_CMD_REQUEST_MESSAGE,
                             mavlink.MAVLINK_MSG_ID_AUTOPILOT_VERSION), 0.0)
    link.receive(gcs.command(mavlink.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES, 1), 0.0)
    link.receive(gcs.command(mavlink.MAV_CMD_NAV_RETURN_TO_LAUNCH), 0.0)
    link.receive(gcs.command(mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 1), 0.0)
    link.receive(gcs.command(mavlink.MAV_CMD_SET_MESSAGE_INTERVAL,
                             mavlink.MAVLINK_MSG_ID_ATTITUDE, 500000), 0.0)
    gcs.feed(link.take_output())
    assert len(gcs.of_type('AUTOPILOT_VERSION')) == 2
    assert gcs.of_type('AUTOPILOT_VERSION')[0].capabilities & \
        mavlink.MAV_PROTOCOL_CAPABILITY_MAVLINK2
    results = {a.command: a.result for a in gcs.of_type('COMMAND_ACK')}
    assert results[mavlink.MAV_CMD_NAV_RETURN_TO_LAUNCH] == mavlink.MAV_RESULT_UNSUPPORTED
    assert results[mavlink.MAV_CMD_COMPONENT_ARM_DISARM] == mavlink.MAV_RESULT_DENIED
    assert results[mavlink.MAV_CMD_SET_MESSAGE_INTERVAL] == mavlink.MAV_RESULT_ACCEPTED
    assert link.scheduler.rates_hz['attitude'] == 2.0


def test_home_position_is_the_datum_when_asked_either_way():
    link, gcs = make_link(), Gcs()
    link.receive(gcs.command(mavlink.MAV_CMD_GET_HOME_POSITION), 0.0)      # MAVProxy's way
    link.receive(gcs.command(mavlink.MAV_CMD_REQUEST_MESSAGE,
                             mavlink.MAVLINK_MSG_ID_HOME_POSITION), 0.0)    # the current way
    gcs.feed(link.take_output())
    datum = link.settings.datum
    homes = gcs.of_type('HOME_POSITION')
    assert len(homes) == 2
    for home in homes:
        assert home.latitude == round(datum.latitude_deg * 1e7)
        assert home.longitude == round(datum.longitude_deg * 1e7)
        assert home.altitude == round(datum.altitude_m * 1000)
    results = {a.command: a.result for a in gcs.of_type('COMMAND_ACK')}
    assert results == {mavlink.MAV_CMD_GET_HOME_POSITION: mavlink.MAV_RESULT_ACCEPTED,
                       mavlink.MAV_CMD_REQUEST_MESSAGE: mavlink.MAV_RESULT_ACCEPTED}


def test_param_protocol_serves_only_the_whitelist():
    link, gcs = make_link(), Gcs()
    link.receive(gcs.pack(gcs.mav.param_request_list_encode(1, 1)), 0.0)
    gcs.feed(link.take_output())
    names = {m.param_id: m.param_value for m in gcs.of_type('PARAM_VALUE')}
    assert names['SHL_MAN_SPD'] == pytest.approx(1.0) and names['SR_POSITION'] == 4.0
    assert len(names) == gcs.of_type('PARAM_VALUE')[0].param_count
    link.receive(gcs.pack(gcs.mav.param_set_encode(1, 1, b'SHL_MAN_SPD', 0.5, 9)), 0.0)
    link.receive(gcs.pack(gcs.mav.param_set_encode(1, 1, b'SHL_MAN_TOUT', 3.0, 9)), 0.0)
    link.receive(gcs.pack(gcs.mav.param_set_encode(1, 1, b'SR_POSITION', 0.0, 9)), 0.0)
    link.receive(gcs.pack(gcs.mav.param_request_read_encode(1, 1, b'MOT_PWM_MAX', -1)), 0.0)
    gcs.feed(link.take_output())
    assert link.tuning.manual_max_speed_mps == 0.5
    assert link.tuning.manual_timeout_s == 0.3                 # 3 s refused: stop within 0.5 s
    assert link.scheduler.rates_hz['global_position'] == 0.0
    errors = [(e.param_id, e.error) for e in gcs.of_type('PARAM_ERROR')]
    assert errors == [('SHL_MAN_TOUT', mavlink.MAV_PARAM_ERROR_VALUE_OUT_OF_RANGE),
                      ('MOT_PWM_MAX', mavlink.MAV_PARAM_ERROR_DOES_NOT_EXIST)]
    assert link.receive(gcs.manual(1000), 0.0)[-1] == DriveCommand(0.5, 0.0)


def test_gcs_heartbeat_loss_during_a_shore_command_stops_and_reports():
    link, gcs = make_link(), Gcs()
    link.receive(gcs.heartbeat(), 0.0)
    link.receive(gcs.manual(500), 0.0)
    for t in (1.0, 2.0, 3.0, 4.0):
        link.receive(gcs.heartbeat(), t)
        link.receive(gcs.manual(500), t)
        assert MissionHold(True) not in link.tick(t)
    actions = []
    for t in (5.0, 7.0, 9.1, 9.5):
        actions += link.tick(t)
    assert MissionHold(True) in actions and DriveCommand(0.0, 0.0) in actions
    assert link.failsafes == 1
    assert link.health(0.0, 0.0).values['gcs_failsafes'] == 1
    gcs.feed(link.take_output())
    assert 'GCS heartbeat lost: failsafe STOP' in [m.text for m in gcs.of_type('STATUSTEXT')]
    link2 = make_link(**{'failsafe.action': 2})
    link2.receive(gcs.manual(500), 0.0)
    assert any(isinstance(a, ModeRequest) and a.mode == 3 for a in link2.tick(6.0))


# ---- mission ---------------------------------------------------------------------------------
def upload(link, gcs, items, now_s=0.0):
    gcs.feed(b'')
    link.receive(gcs.pack(gcs.mav.mission_count_encode(1, 1, len(items), 0)), now_s)
    actions = []
    for item in items:
        gcs.feed(link.take_output())
        request = gcs.of_type('MISSION_REQUEST_INT')[-1]
        actions += link.receive(gcs.pack(item(request.seq)), now_s)
    gcs.feed(link.take_output())
    return actions


def test_mission_upload_download_and_clear():
    link, gcs = make_link(), Gcs()
    lat0, lon0 = 36.1836, -75.7510
    m_per_deg = math.radians(1.0) * 6378137.0
    frame = mavlink.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT

    def speed(seq):
        return gcs.mav.mission_item_int_encode(1, 1, seq, 2, mavlink.MAV_CMD_DO_CHANGE_SPEED, 0,
                                               1, 1, 0.8, -1, 0, 0, 0, 0)

    def waypoint(east_m, north_m):
        lat = lat0 + north_m / m_per_deg
        lon = lon0 + east_m / (m_per_deg * math.cos(math.radians(lat0)))
        return lambda seq: gcs.mav.mission_item_int_encode(
            1, 1, seq, frame, mavlink.MAV_CMD_NAV_WAYPOINT, 0, 1, 0, 0, 0, 0,
            int(round(lat * 1e7)), int(round(lon * 1e7)), 0)
    actions = upload(link, gcs, [speed, waypoint(-6.0, 0.0), waypoint(-6.0, 4.0)])
    assert gcs.of_type('MISSION_ACK')[-1].type == mavlink.MAV_MISSION_ACCEPTED
    plan = [a for a in actions if isinstance(a, MissionPlan)][0].waypoints
    assert [(w.seq, round(w.x_m, 2), round(w.y_m, 2), w.speed_mps) for w in plan] == [
        (1, -6.0, 0.0, pytest.approx(0.8)), (2, -6.0, 4.0, pytest.approx(0.8))]
    link.receive(gcs.pack(gcs.mav.mission_request_list_encode(1, 1, 0)), 1.0)
    gcs.feed(link.take_output())
    assert gcs.of_type('MISSION_COUNT')[-1].count == 3
    link.receive(gcs.pack(gcs.mav.mission_request_int_encode(1, 1, 2, 0)), 1.0)
    gcs.feed(link.take_output())
    assert gcs.of_type('MISSION_ITEM_INT')[-1].command == mavlink.MAV_CMD_NAV_WAYPOINT
    link.update_mission(1, 1, False, 5)            # the old mission's status: not ours
    link.update_mission(1, 1, False, 2)
    gcs.feed(link.take_output())
    assert [m.seq for m in gcs.of_type('MISSION_ITEM_REACHED')] == [1]
    started = link.receive(gcs.command(mavlink.MAV_CMD_MISSION_START), 2.0)
    assert started == [MissionHold(False)]
    bad = upload(link, gcs, [lambda seq: gcs.mav.mission_item_int_encode(
        1, 1, seq, frame, mavlink.MAV_CMD_NAV_LOITER_UNLIM, 0, 1, 0, 0, 0, 0, 0, 0, 0)])
    assert bad == [] and gcs.of_type('MISSION_ACK')[-1].type == mavlink.MAV_MISSION_UNSUPPORTED
    assert len(link.mission.items) == 3                        # the old mission stays
    cleared = link.receive(gcs.pack(gcs.mav.mission_clear_all_encode(1, 1, 0)), 3.0)
    assert MissionPlan(()) in cleared


def test_mission_upload_asks_again_for_a_lost_item_then_gives_up():
    link, gcs = make_link(), Gcs()
    link.receive(gcs.pack(gcs.mav.mission_count_encode(1, 1, 2, 0)), 0.0)
    for t in (1.0, 2.0, 3.5, 5.0, 6.5, 8.0, 9.5):
        link.tick(t)
    gcs.feed(link.take_output())
    assert len(gcs.of_type('MISSION_REQUEST_INT')) == 6       # first ask + 5 retries
    assert gcs.of_type('MISSION_ACK')[-1].type == mavlink.MAV_MISSION_OPERATION_CANCELLED


# ---- robustness ------------------------------------------------------------------------------
@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.binary(max_size=300), max_size=8))
def test_fuzzed_bytes_never_crash_the_parser(chunks):
    link = make_link()
    for chunk in chunks:
        assert isinstance(link.receive(chunk, 0.0), list)
    link.tick(1.0)


_GOOD = [Gcs().manual(300), Gcs().heartbeat(), Gcs(key=None).manual(300)]


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(_GOOD), st.lists(st.tuples(st.integers(0, 60), st.integers(0, 255)),
                                        max_size=6), st.binary(max_size=20))
def test_damaged_packets_never_crash_nor_pass_as_commands(packet, flips, junk):
    data = bytearray(packet)
    for index, value in flips:
        if index < len(data):
            data[index] = value
    link = make_link()
    actions = link.receive(junk + bytes(data), 0.0)
    assert all(isinstance(a, (DriveCommand, MissionHold)) for a in actions)
    if actions:          # only an intact signed packet may command
        assert bytes(data) == packet and packet == _GOOD[0]


def test_signing_can_be_off_for_a_bench():
    link = make_link(signing=False)
    assert link.receive(Gcs(key=None).manual(1000), 0.0)[-1] == DriveCommand(1.0, 0.0)
    assert 'rejected_unsigned' not in link.health(0.0, 0.0).values
