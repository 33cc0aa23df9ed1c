"""The shore link's core: MAVLink 2 vehicle (system 1, component 1) for a ground station. ROS-free.

Bytes in (``receive``) are parsed by pymavlink with ``SecureSigning`` checking
every packet; what a ground station asks becomes replies (COMMAND_ACK,
MISSION_ACK, PARAM_VALUE...) and *actions* for the node: ``DriveCommand``
(cmd_vel), ``ModeRequest`` (the mode manager's set_mode service),
``MissionPlan`` and ``MissionHold`` (the mission node). ``tick`` sends the
telemetry that is due, stops a MANUAL_CONTROL that stopped coming
(``manual_timeout_s``) and runs the GCS failsafe; ``take_output`` returns the
bytes to put on the radio. Nothing here reaches a motor: the node publishes
cmd_vel, which goes through the drive controller and the servo switch like every
computer command, so the RC operator always wins.

Custom modes (HEARTBEAT.custom_mode, DO_SET_MODE param2, SET_MODE.custom_mode):
0 LAND, 1 TRANSITION, 2 WATER, 3 SAFE_STOP (dukw_msgs/DriveMode); to request,
4 = back to automatic. MAV_MODE_FLAG_AUTO_ENABLED is set while the mode manager
decides by itself; SAFETY_ARMED while the computer holds authority.
"""
from __future__ import annotations

import math
import struct
from dataclasses import dataclass

from pymavlink.dialects.v20 import common as mavlink

from dukw_common.config import ConfigError
from dukw_common.diagnostics import Health, Level
from dukw_driver.mavlink_signing import SecureSigning
from dukw_driver.shore_mission import MissionProtocol, PlanWaypoint
from dukw_driver.shore_params import STREAM_PARAM_NAMES, FailsafeAction, ParamTable, Tuning
from dukw_driver.shore_telemetry import (HOLDER_NAMES, MODE_NAMES, MODE_SAFE_STOP, STREAM_IDS,
                                         Datum, DriveTelemetry, RateScheduler, TelemetryEncoder,
                                         VehicleState)

MODE_AUTOMATIC = 4
MAVLINK_TYPE_GCS = mavlink.MAV_TYPE_GCS
INT16_UNUSED = 32767              # MANUAL_CONTROL: axis not used
BITS_PER_BYTE_ON_AIR = 10         # 8N1 serial framing
SEVERITY = {'info': mavlink.MAV_SEVERITY_INFO, 'notice': mavlink.MAV_SEVERITY_NOTICE,
            'warning': mavlink.MAV_SEVERITY_WARNING, 'error': mavlink.MAV_SEVERITY_ERROR}
MISSION_MESSAGES = frozenset({'MISSION_COUNT', 'MISSION_ITEM_INT', 'MISSION_ITEM',
                              'MISSION_REQUEST_LIST', 'MISSION_REQUEST_INT', 'MISSION_REQUEST',
                              'MISSION_CLEAR_ALL', 'MISSION_ACK'})
CAPABILITIES = (mavlink.MAV_PROTOCOL_CAPABILITY_MAVLINK2
                | mavlink.MAV_PROTOCOL_CAPABILITY_MISSION_INT
                | mavlink.MAV_PROTOCOL_CAPABILITY_COMMAND_INT
                | mavlink.MAV_PROTOCOL_CAPABILITY_PARAM_FLOAT)
#: What fuzzed or damaged input may make pymavlink raise besides its own MAVError.
PARSE_ERRORS = (mavlink.MAVError, struct.error, ValueError, IndexError, TypeError)


@dataclass(frozen=True)
class DriveCommand:
    """Publish cmd_vel (linear.x, angular.z; TwistStamped or Twist as cmd_vel_stamped says)."""

    speed_mps: float
    yaw_rate_rps: float


@dataclass(frozen=True)
class ModeRequest:
    """Call set_mode; answer with ``ShoreLink.mode_result(request, ok, text)``."""

    mode: int
    automatic: bool
    command: int                  # the MAVLink command (or SET_MODE's id) to acknowledge
    gcs: tuple[int, int]


@dataclass(frozen=True)
class MissionPlan:
    """New waypoints for the mission node (empty: cleared)."""

    waypoints: tuple[PlanWaypoint, ...]


@dataclass(frozen=True)
class MissionHold:
    """Hold (True) or run (False) the mission node's mission."""

    hold: bool


@dataclass(frozen=True)
class ShoreSettings:
    """Fixed settings (config/dukw.yaml shore_link_node)."""

    datum: Datum
    current_limit_a: float
    mission_speed_mps: float
    max_speed_mps: float             # the vehicle's top speed (drivetrain fact)
    radio_baud: int
    budget_fraction: float = 0.5
    system_id: int = 1
    component_id: int = 1

    @property
    def radio_bytes_per_s(self) -> float:
        """What the radio carries at most (8N1)."""
        return self.radio_baud / BITS_PER_BYTE_ON_AIR


class _Sink:
    """The file pymavlink writes packed messages to."""

    def __init__(self) -> None:
        self.data = bytearray()

    def write(self, buf: bytes) -> None:
        self.data.extend(buf)


class ShoreLink:
    """Parses, answers and schedules; see the module docstring."""

    def __init__(self, settings: ShoreSettings, tuning: Tuning,
                 signing: SecureSigning | None, now_s: float) -> None:
        self.settings = settings
        self.tuning = tuning
        self.params = ParamTable(tuning)
        self.signing = signing
        self._sink = _Sink()
        self.mav = mavlink.MAVLink(self._sink, settings.system_id, settings.component_id)
        self.mav.robust_parsing = True
        if signing is not None:
            signing.install(self.mav)
        self.scheduler = RateScheduler(tuning.rates_hz)
        self.state = VehicleState()
        self.encoder = TelemetryEncoder(self.mav, settings.datum, settings.current_limit_a)
        self.mission = MissionProtocol(self.mav, settings.datum, settings.mission_speed_mps,
                                       settings.max_speed_mps)
        self.mission_index = 0
        self.mission_reached = 0
        self.t0_s = now_s
        self.gcs: tuple[int, int] | None = None
        self.gcs_heard_s: float | None = None
        self.manual_s: float | None = None       # last MANUAL_CONTROL while active
        self.shore_active = False                # a shore command is in force
        self.failsafes = 0
        self.pending_mode: ModeRequest | None = None
        self.parse_errors = 0
        self.packets_in: dict[str, int] = {}
        self.bytes_out_by_type: dict[str, int] = {}
        self.bytes_in = 0
        self.bytes_out = 0
        self._statustexts: list[tuple[int, str]] = []

    # ---- radio side -------------------------------------------------------------------------
    def receive(self, data: bytes, now_s: float) -> list:
        """Parse bytes from the radio; answer what is asked; return the actions (never raises)."""
        self.bytes_in += len(data)
        actions: list = []
        for msg in self._parse(data):
            actions.extend(self._dispatch(msg, now_s))
        return actions

    def _parse(self, data: bytes) -> list:
        messages, chunk = [], data
        for _ in range(len(self.mav.buf) + len(data) + 2):   # each round consumes bytes
            try:
                msg = self.mav.parse_char(chunk)
            except PARSE_ERRORS:
                self.parse_errors += 1
                chunk = b''
                continue
            chunk = b''
            if msg is None:
                break
            if msg.get_type() != 'BAD_DATA':
                messages.append(msg)
            elif 'signature' not in str(getattr(msg, 'reason', '')):
                self.parse_errors += 1          # rejected packets are counted by reason
        return messages

    def take_output(self) -> bytes:
        """The bytes sent since the last call."""
        out = bytes(self._sink.data)
        self._sink.data.clear()
        return out

    def _send(self, msg) -> None:
        if self.signing is not None:
            self.signing.advance_clock()
        before = len(self._sink.data)
        self.mav.send(msg)
        size = len(self._sink.data) - before
        self.bytes_out += size
        kind = msg.get_type()
        self.bytes_out_by_type[kind] = self.bytes_out_by_type.get(kind, 0) + size

    def statustext(self, severity: str, text: str) -> None:
        """Queue a STATUSTEXT (sent on the next tick; 50 characters)."""
        self._statustexts.append((SEVERITY[severity], text))

    # ---- messages from the ground station ---------------------------------------------------
    def _dispatch(self, msg, now_s: float) -> list:
        kind = msg.get_type()
        self.packets_in[kind] = self.packets_in.get(kind, 0) + 1
        source = (msg.get_srcSystem(), msg.get_srcComponent())
        if kind == 'HEARTBEAT':
            if msg.type == MAVLINK_TYPE_GCS:
                self.gcs, self.gcs_heard_s = source, now_s
            return []
        if not self._for_us(msg):
            return []
        if kind == 'MANUAL_CONTROL':
            return self._manual(msg, source, now_s)
        if kind in ('COMMAND_LONG', 'COMMAND_INT'):
            return self._command(msg, source)
        if kind == 'SET_MODE':
            return self._mode(msg.base_mode, msg.custom_mode, mavlink.MAVLINK_MSG_ID_SET_MODE,
                              source)
        if kind.startswith('PARAM_'):
            self._param(msg, source)
            return []
        if kind in MISSION_MESSAGES:
            for reply in self.mission.handle(msg, source, now_s):
                self._send(reply)
            return self._mission_actions()
        return []

    def _for_us(self, msg) -> bool:
        system = getattr(msg, 'target_system', getattr(msg, 'target', 0))
        component = getattr(msg, 'target_component', 0)
        return (system in (0, self.settings.system_id)
                and component in (0, self.settings.component_id))

    def _manual(self, msg, source, now_s: float) -> list:
        def axis(value: int) -> float:
            return 0.0 if value == INT16_UNUSED else max(-1.0, min(1.0, value / 1000.0))
        actions = []
        if self.manual_s is None:
            self.statustext('notice', 'shore manual control: mission held')
            actions.append(MissionHold(True))
        self.manual_s = now_s
        self.shore_active = True
        if self.gcs_heard_s is None:
            self.gcs, self.gcs_heard_s = source, now_s
        t = self.tuning   # MANUAL_CONTROL r > 0 turns right (clockwise): ROS yaw rate < 0
        actions.append(DriveCommand(axis(msg.x) * t.manual_max_speed_mps,
                                    -axis(msg.r) * t.manual_max_yaw_rate_rps))
        return actions

    def _ack(self, command: int, result: int, gcs: tuple[int, int]) -> None:
        self._send(self.mav.command_ack_encode(command, result, 0, 0, *gcs))

    def _command(self, msg, gcs) -> list:
        c = msg.command
        if c == mavlink.MAV_CMD_DO_SET_MODE:
            return self._mode(int(msg.param1), int(msg.param2), c, gcs)
        if c == mavlink.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES:
            self._ack(c, mavlink.MAV_RESULT_ACCEPTED, gcs)
            self._send(self._autopilot_version())
            return []
        if c == mavlink.MAV_CMD_REQUEST_MESSAGE:
            self._request_message(int(msg.param1), gcs)
            return []
        if c == mavlink.MAV_CMD_GET_HOME_POSITION:     # MAVProxy asks every 2 s until answered
            self._ack(c, mavlink.MAV_RESULT_ACCEPTED, gcs)
            self._send(self._home_position())
            return []
        if c == mavlink.MAV_CMD_SET_MESSAGE_INTERVAL:
            self._ack(c, self._set_interval(int(msg.param1), msg.param2), gcs)
            return []
        if c == mavlink.MAV_CMD_MISSION_START or (
                c == mavlink.MAV_CMD_DO_PAUSE_CONTINUE and msg.param1 == 1):
            if not self.mission.waypoint_seqs:
                self._ack(c, mavlink.MAV_RESULT_DENIED, gcs)
                return []
            self._ack(c, mavlink.MAV_RESULT_ACCEPTED, gcs)
            self.shore_active = True
            self.statustext('info', 'mission started from shore')
            return [MissionHold(False)]
        if c == mavlink.MAV_CMD_DO_PAUSE_CONTINUE:
            self._ack(c, mavlink.MAV_RESULT_ACCEPTED, gcs)
            return [MissionHold(True), DriveCommand(0.0, 0.0)]
        if c == mavlink.MAV_CMD_COMPONENT_ARM_DISARM:
            self._ack(c, mavlink.MAV_RESULT_DENIED, gcs)
            self.statustext('warning', "arming is the RC transmitter's switch")
            return []
        self._ack(c, mavlink.MAV_RESULT_UNSUPPORTED, gcs)
        return []

    def _autopilot_version(self):
        return self.mav.autopilot_version_encode(CAPABILITIES, 0, 0, 0, 0, [0] * 8, [0] * 8,
                                                 [0] * 8, 0, 0, 0)

    def _home_position(self):
        """Home = the datum (odom's origin on the mean waterline): where the GCS draws H."""
        d = self.settings.datum
        return self.mav.home_position_encode(
            int(round(d.latitude_deg * 1e7)), int(round(d.longitude_deg * 1e7)),
            int(round(d.altitude_m * 1000)), 0.0, 0.0, 0.0, [1.0, 0.0, 0.0, 0.0], 0.0, 0.0, 0.0)

    def _request_message(self, msg_id: int, gcs) -> None:
        once = {mavlink.MAVLINK_MSG_ID_AUTOPILOT_VERSION: self._autopilot_version,
                mavlink.MAVLINK_MSG_ID_HOME_POSITION: self._home_position}
        if msg_id in once:
            self._ack(mavlink.MAV_CMD_REQUEST_MESSAGE, mavlink.MAV_RESULT_ACCEPTED, gcs)
            self._send(once[msg_id]())
            return
        streams = [name for name, sid in STREAM_IDS.items() if sid == msg_id]
        result = mavlink.MAV_RESULT_ACCEPTED if streams else mavlink.MAV_RESULT_UNSUPPORTED
        self._ack(mavlink.MAV_CMD_REQUEST_MESSAGE, result, gcs)
        for name in streams:
            self._emit(name, self.t0_s)

    def _set_interval(self, msg_id: int, interval_us: float) -> int:
        streams = [name for name, sid in STREAM_IDS.items() if sid == msg_id]
        if not streams or not math.isfinite(interval_us):
            return mavlink.MAV_RESULT_DENIED
        if interval_us == 0:
            return mavlink.MAV_RESULT_ACCEPTED            # the default: keep the current rate
        rate = 0.0 if interval_us < 0 else 1e6 / interval_us
        name = streams[0]
        if not self.params.set(STREAM_PARAM_NAMES[name], rate):
            return mavlink.MAV_RESULT_DENIED
        self.scheduler.set_rate(name, rate)
        return mavlink.MAV_RESULT_ACCEPTED

    def _mode(self, base_mode: int, custom_mode: int, command: int, gcs) -> list:
        if not base_mode & mavlink.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED or not (
                custom_mode in MODE_NAMES or custom_mode == MODE_AUTOMATIC):
            self._ack(command, mavlink.MAV_RESULT_DENIED, gcs)
            return []
        if self.pending_mode is not None:
            self._ack(command, mavlink.MAV_RESULT_TEMPORARILY_REJECTED, gcs)
            return []
        automatic = custom_mode == MODE_AUTOMATIC
        self.pending_mode = ModeRequest(0 if automatic else custom_mode, automatic, command, gcs)
        return [self.pending_mode]

    def mode_result(self, request: ModeRequest, ok: bool, text: str) -> None:
        """The set_mode service answered (or could not be called): acknowledge to the GCS."""
        if self.pending_mode == request:
            self.pending_mode = None
        result = mavlink.MAV_RESULT_ACCEPTED if ok else mavlink.MAV_RESULT_FAILED
        if request.command:                      # 0: the failsafe's own request
            self._ack(request.command, result, request.gcs)
        if not ok:
            self.statustext('warning', f'mode request refused: {text}')

    def _param(self, msg, gcs) -> None:
        kind = msg.get_type()
        names = self.params.names()
        if kind == 'PARAM_REQUEST_LIST':
            for name in names:
                self._param_value(name)
            return
        if kind not in ('PARAM_REQUEST_READ', 'PARAM_SET'):
            return
        name = msg.param_id
        if kind == 'PARAM_REQUEST_READ' and msg.param_index >= 0:
            name = names[msg.param_index] if msg.param_index < len(names) else ''
        if name not in self.params.by_name:
            self._send(self.mav.param_error_encode(*gcs, name.encode()[:16], -1,
                                                   mavlink.MAV_PARAM_ERROR_DOES_NOT_EXIST))
            return
        if kind == 'PARAM_SET':
            if self.params.set(name, msg.param_value):
                for stream, rate in self.tuning.rates_hz.items():
                    if self.scheduler.rates_hz[stream] != rate:
                        self.scheduler.set_rate(stream, rate)
                self.statustext('info', f'{name} set to {self.params.get(name):g}')
            else:
                self._send(self.mav.param_error_encode(
                    *gcs, name.encode(), names.index(name),
                    mavlink.MAV_PARAM_ERROR_VALUE_OUT_OF_RANGE))
        self._param_value(name)

    def _param_value(self, name: str) -> None:
        names = self.params.names()
        self._send(self.mav.param_value_encode(name.encode(), self.params.get(name),
                                               mavlink.MAV_PARAM_TYPE_REAL32, len(names),
                                               names.index(name)))

    def _mission_actions(self) -> list:
        plan = self.mission.take_completed()
        if plan is None:
            return []
        self.mission_index = self.mission_reached = 0
        text = f'mission of {len(plan)} waypoints loaded' if plan else 'mission cleared'
        self.statustext('info', text + ('' if not plan else ': MISSION_START to go'))
        return [MissionHold(True), MissionPlan(tuple(plan))]

    # ---- vehicle side -----------------------------------------------------------------------
    def update_mode(self, mode: int, automatic: bool, reason: str) -> None:
        """drive_mode: a change of mode or of automatic is reported in a STATUSTEXT."""
        s = self.state
        if (mode, automatic) != (s.mode, s.mode_automatic) or s.mode is None:
            name = MODE_NAMES.get(mode, str(mode))
            severity = 'warning' if mode == MODE_SAFE_STOP else 'info'
            self.statustext(severity, f'mode {name}{"" if automatic else " (forced)"}: '
                            f'{reason}')
        s.mode, s.mode_automatic, s.mode_reason = mode, automatic, reason

    def update_authority(self, holder: int, rc_link_ok: bool, detail: str) -> None:
        """authority: a change of holder or RC link is reported in a STATUSTEXT."""
        s = self.state
        if (holder, rc_link_ok) != (s.holder, s.rc_link_ok) or s.holder is None:
            link = '' if rc_link_ok else ', RC link lost'
            self.statustext('notice', f'authority: {HOLDER_NAMES.get(holder, holder)}{link}: '
                            f'{detail}')
        s.holder, s.rc_link_ok, s.authority_detail = holder, rc_link_ok, detail

    def update_drive(self, which: str, drive: DriveTelemetry) -> None:
        """tracks/status or props/status: new faults are reported in a STATUSTEXT."""
        old: DriveTelemetry = getattr(self.state, which)
        new_faults = [f for f in drive.faults if f not in old.faults]
        if new_faults:
            self.statustext('error', f'{which} fault: {", ".join(new_faults)}')
        setattr(self.state, which, drive)

    def update_mission(self, index: int, reached: int, finished: bool, total: int) -> None:
        """mission/status: MISSION_ITEM_REACHED for each newly reached waypoint (a status of
        another mission than the one uploaded, e.g. from before the upload, is ignored)."""
        seqs = self.mission.waypoint_seqs
        if seqs and total != len(seqs):
            return
        while self.mission_reached < reached:
            i = self.mission_reached
            self._send(self.mav.mission_item_reached_encode(seqs[i] if i < len(seqs) else i))
            self.mission_reached += 1
        self.mission_index = index
        if finished:
            self.shore_active = False

    # ---- time -------------------------------------------------------------------------------
    def tick(self, now_s: float) -> list:
        """Manual-control timeout, failsafe, mission retries, telemetry due now; the actions."""
        actions = []
        if self.manual_s is not None and now_s - self.manual_s > self.tuning.manual_timeout_s:
            self.manual_s = None
            self.statustext('warning', 'shore manual control stopped coming: stop')
            actions.append(DriveCommand(0.0, 0.0))
        actions.extend(self._failsafe(now_s))
        for reply in self.mission.tick(now_s):
            self._send(reply)
        while self._statustexts:
            severity, text = self._statustexts.pop(0)
            self._send(self.mav.statustext_encode(severity, text.encode('utf-8')[:50]))
        for name in self.scheduler.due(now_s):
            self._emit(name, now_s)
        return actions

    def gcs_lost(self, now_s: float) -> bool:
        """True when a GCS was heard once and not for ``gcs_timeout_s``."""
        return (self.gcs_heard_s is not None
                and now_s - self.gcs_heard_s > self.tuning.gcs_timeout_s)

    def _failsafe(self, now_s: float) -> list:
        if not (self.shore_active and self.gcs_lost(now_s)):
            return []
        self.shore_active = False
        self.failsafes += 1
        self.manual_s = None
        action = self.tuning.failsafe_action
        self.statustext('error', f'GCS heartbeat lost: failsafe {action.name}')
        if action == FailsafeAction.NONE:
            return []
        actions = [MissionHold(True), DriveCommand(0.0, 0.0)]
        if action == FailsafeAction.SAFE_STOP and self.pending_mode is None:
            self.pending_mode = ModeRequest(MODE_SAFE_STOP, False, 0, (0, 0))
            actions.append(self.pending_mode)
        return actions

    def _emit(self, name: str, now_s: float) -> None:
        s, enc = self.state, self.encoder
        time_ms = int((now_s - self.t0_s) * 1000) & 0xFFFFFFFF
        built = {
            'heartbeat': lambda: enc.heartbeat(s),
            'sys_status': lambda: enc.sys_status(s),
            'battery_status': lambda: enc.battery_status(s),
            'global_position': lambda: enc.global_position(s, time_ms),
            'gps_raw': lambda: enc.gps_raw(s, time_ms * 1000),
            'attitude': lambda: enc.attitude(s, time_ms),
            'vfr_hud': lambda: enc.vfr_hud(s),
            'named_values': lambda: enc.named_values(s, time_ms),
            'mission_current': lambda: self.mav.mission_current_encode(
                self._current_seq(), len(self.mission.items)),
        }[name]()
        for msg in built if isinstance(built, list) else [built]:
            if msg is not None:
                self._send(msg)

    def _current_seq(self) -> int:
        seqs = self.mission.waypoint_seqs
        return seqs[min(self.mission_index, len(seqs) - 1)] if seqs else 0

    # ---- diagnostics ------------------------------------------------------------------------
    def health(self, bytes_out_per_s: float, bytes_in_per_s: float) -> Health:
        """Rates, radio load against the budget, parse errors, rejections, failsafe."""
        budget = self.settings.radio_bytes_per_s * self.settings.budget_fraction
        values = {'bytes_out_per_s': round(bytes_out_per_s, 1),
                  'bytes_in_per_s': round(bytes_in_per_s, 1),
                  'radio_budget_bytes_per_s': round(budget, 1),
                  'radio_load_pct': round(100.0 * bytes_out_per_s
                                          / self.settings.radio_bytes_per_s, 1),
                  'parse_errors': self.parse_errors, 'gcs_failsafes': self.failsafes,
                  'gcs': f'{self.gcs[0]}/{self.gcs[1]}' if self.gcs else 'none',
                  'manual_control_active': self.manual_s is not None,
                  **{f'rate_{k}_hz': v for k, v in self.scheduler.rates_hz.items()},
                  'packets_in': sum(self.packets_in.values())}
        if self.signing is not None:
            values.update(self.signing.counts())
        health = Health('shore link', values=values)
        if bytes_out_per_s > budget:
            health.worsen(Level.WARN, f'telemetry {bytes_out_per_s:.0f} B/s over the budget '
                          f'{budget:.0f} B/s')
        if self.failsafes:
            health.worsen(Level.WARN, f'{self.failsafes} GCS failsafes')
        return health


STREAMS = tuple(STREAM_IDS)


def settings_from_params(p: dict) -> tuple[ShoreSettings, Tuning]:
    """ShoreSettings and Tuning from the node's parameters (config/dukw.yaml shore_link_node)."""
    datum = Datum(p['datum.latitude_deg'], p['datum.longitude_deg'], p['datum.altitude_m'])
    settings = ShoreSettings(datum, p['drivetrain.continuous_current_limit_a'],
                             p['mission_speed_mps'], p['drivetrain.full_scale_track_speed_mps'],
                             int(p['radio_baud']), p['radio_budget_fraction'],
                             int(p['system_id']), int(p['component_id']))
    try:
        action = FailsafeAction(int(p['failsafe.action']))
    except ValueError as exc:
        raise ConfigError(f"parameter 'failsafe.action' must be 0, 1 or 2: {exc}") from exc
    tuning = Tuning(p['manual.max_speed_mps'], p['manual.max_yaw_rate_rps'],
                    p['manual.timeout_s'], p['failsafe.gcs_timeout_s'], action,
                    {name: float(p[f'rates.{name}_hz']) for name in STREAMS})
    return settings, tuning
