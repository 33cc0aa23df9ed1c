"""The MAVLink mission protocol (upload, download, clear) over odom waypoints. ROS-free.

Items accepted: ``MAV_CMD_NAV_WAYPOINT`` in a global frame (lat/lon as
MISSION_ITEM_INT, 1e7 degrees; altitude ignored) -> a waypoint in odom through
the datum, and ``MAV_CMD_DO_CHANGE_SPEED`` (param2 m/s) -> the speed of the
legs after it (``default_speed_mps`` before any). Anything else is refused with
``MAV_MISSION_UNSUPPORTED`` and the old mission stays. Only the plain mission
type is kept; fence and rally downloads answer an empty list.
"""
from __future__ import annotations

from dataclasses import dataclass

from pymavlink.dialects.v20 import common as mavlink

from dukw_common.geometry import local_enu_from_geodetic
from dukw_driver.shore_telemetry import Datum

GLOBAL_FRAMES = frozenset({mavlink.MAV_FRAME_GLOBAL, mavlink.MAV_FRAME_GLOBAL_INT,
                           mavlink.MAV_FRAME_GLOBAL_RELATIVE_ALT,
                           mavlink.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT})
MAX_ITEMS = 100
#: The vehicle's speed range for a leg (mission.py accepts (0, 2] m/s).


@dataclass(frozen=True)
class PlanWaypoint:
    """A waypoint in odom (ENU) with the speed of the leg to it, and its mission item seq."""

    seq: int
    x_m: float
    y_m: float
    speed_mps: float


@dataclass(frozen=True)
class MissionItem:
    """One stored MISSION_ITEM_INT (what a download returns)."""

    seq: int
    frame: int
    command: int
    params: tuple[float, float, float, float]
    x: int
    y: int
    z: float


def _item_from_message(msg) -> MissionItem:
    x, y = msg.x, msg.y
    if msg.get_type() == 'MISSION_ITEM':        # float degrees (deprecated form)
        x, y = int(round(msg.x * 1e7)), int(round(msg.y * 1e7))
    return MissionItem(msg.seq, msg.frame, msg.command,
                       (msg.param1, msg.param2, msg.param3, msg.param4), x, y, msg.z)


def plan_from_items(items: list[MissionItem], datum: Datum, default_speed_mps: float,
                    max_speed_mps: float) -> tuple[list[PlanWaypoint], int]:
    """Items -> waypoints; returns (waypoints, MAV_MISSION_RESULT). A DO_CHANGE_SPEED
    above ``max_speed_mps`` (the vehicle's top speed) is refused."""
    speed = default_speed_mps
    plan = []
    for item in items:
        if item.command == mavlink.MAV_CMD_DO_CHANGE_SPEED:
            new_speed = item.params[1]
            if not (0.0 < new_speed <= max_speed_mps):
                return [], mavlink.MAV_MISSION_INVALID_PARAM2
            speed = new_speed
        elif item.command == mavlink.MAV_CMD_NAV_WAYPOINT:
            if item.frame not in GLOBAL_FRAMES:
                return [], mavlink.MAV_MISSION_UNSUPPORTED_FRAME
            lat, lon = item.x * 1e-7, item.y * 1e-7
            if not (-90.0 <= lat <= 90.0 and -180.0 <= lon <= 180.0):
                return [], mavlink.MAV_MISSION_INVALID_PARAM5_X
            east, north, _ = local_enu_from_geodetic(lat, lon, 0.0, datum.latitude_deg,
                                                     datum.longitude_deg, 0.0)
            plan.append(PlanWaypoint(item.seq, east, north, speed))
        else:
            return [], mavlink.MAV_MISSION_UNSUPPORTED
    return plan, mavlink.MAV_MISSION_ACCEPTED


class MissionProtocol:
    """Upload / download / clear with one ground station at a time; send() gets replies."""

    def __init__(self, mav: mavlink.MAVLink, datum: Datum, default_speed_mps: float,
                 max_speed_mps: float, item_timeout_s: float = 1.5, retries: int = 5) -> None:
        self.mav = mav
        self.datum = datum
        self.default_speed_mps = default_speed_mps
        self.max_speed_mps = max_speed_mps
        self.item_timeout_s = item_timeout_s
        self.retries = retries
        self.items: list[MissionItem] = []
        self.waypoint_seqs: list[int] = []
        self._upload: dict | None = None
        self.completed: list[PlanWaypoint] | None = None   # set when an upload finished

    def handle(self, msg, gcs: tuple[int, int], now_s: float) -> list:
        """React to one mission message; returns the messages to send."""
        kind = msg.get_type()
        mission_type = getattr(msg, 'mission_type', mavlink.MAV_MISSION_TYPE_MISSION)
        if kind == 'MISSION_COUNT':
            return self._start_upload(msg.count, mission_type, gcs, now_s)
        if kind in ('MISSION_ITEM_INT', 'MISSION_ITEM'):
            return self._item(msg, gcs, now_s)
        if kind == 'MISSION_REQUEST_LIST':
            count = len(self.items) if mission_type == mavlink.MAV_MISSION_TYPE_MISSION else 0
            return [self.mav.mission_count_encode(*gcs, count, mission_type)]
        if kind in ('MISSION_REQUEST_INT', 'MISSION_REQUEST'):
            return self._send_item(msg.seq, mission_type, gcs)
        if kind == 'MISSION_CLEAR_ALL':
            if mission_type == mavlink.MAV_MISSION_TYPE_MISSION:
                self.items, self.waypoint_seqs, self._upload = [], [], None
                self.completed = []
            return [self.mav.mission_ack_encode(*gcs, mavlink.MAV_MISSION_ACCEPTED,
                                                mission_type)]
        return []   # MISSION_ACK from the GCS ends a download: nothing to answer

    def _start_upload(self, count: int, mission_type: int, gcs, now_s: float) -> list:
        if mission_type != mavlink.MAV_MISSION_TYPE_MISSION:
            return [self.mav.mission_ack_encode(*gcs, mavlink.MAV_MISSION_UNSUPPORTED,
                                                mission_type)]
        if count > MAX_ITEMS:
            return [self.mav.mission_ack_encode(*gcs, mavlink.MAV_MISSION_NO_SPACE, mission_type)]
        if count == 0:
            self.items, self.waypoint_seqs, self.completed = [], [], []
            return [self.mav.mission_ack_encode(*gcs, mavlink.MAV_MISSION_ACCEPTED, 0)]
        self._upload = {'count': count, 'items': [], 'gcs': gcs, 'sent_s': now_s, 'tries': 0}
        return [self._request(0)]

    def _request(self, seq: int):
        up = self._upload
        return self.mav.mission_request_int_encode(*up['gcs'], seq, 0)

    def _item(self, msg, gcs, now_s: float) -> list:
        up = self._upload
        if up is None or msg.mission_type != mavlink.MAV_MISSION_TYPE_MISSION:
            return [self.mav.mission_ack_encode(*gcs, mavlink.MAV_MISSION_DENIED,
                                                msg.mission_type)]
        expected = len(up['items'])
        if msg.seq != expected:
            return [self._request(expected)] if msg.seq < expected else [
                self.mav.mission_ack_encode(*gcs, mavlink.MAV_MISSION_INVALID_SEQUENCE, 0)]
        up['items'].append(_item_from_message(msg))
        up['sent_s'], up['tries'] = now_s, 0
        if len(up['items']) < up['count']:
            return [self._request(len(up['items']))]
        self._upload = None
        plan, result = plan_from_items(up['items'], self.datum, self.default_speed_mps,
                                       self.max_speed_mps)
        if result == mavlink.MAV_MISSION_ACCEPTED and not plan:
            result = mavlink.MAV_MISSION_INVALID   # a mission needs a waypoint
        if result == mavlink.MAV_MISSION_ACCEPTED:
            self.items = up['items']
            self.waypoint_seqs = [w.seq for w in plan]
            self.completed = plan
        return [self.mav.mission_ack_encode(*gcs, result, 0)]

    def _send_item(self, seq: int, mission_type: int, gcs) -> list:
        if mission_type != mavlink.MAV_MISSION_TYPE_MISSION or not 0 <= seq < len(self.items):
            return [self.mav.mission_ack_encode(*gcs, mavlink.MAV_MISSION_INVALID_SEQUENCE,
                                                mission_type)]
        it = self.items[seq]
        return [self.mav.mission_item_int_encode(*gcs, it.seq, it.frame, it.command, 0, 1,
                                                 *it.params, it.x, it.y, it.z, 0)]

    def tick(self, now_s: float) -> list:
        """Ask again for an item that did not come; give the upload up after ``retries``."""
        up = self._upload
        if up is None or now_s - up['sent_s'] < self.item_timeout_s:
            return []
        up['tries'] += 1
        up['sent_s'] = now_s
        if up['tries'] > self.retries:
            self._upload = None
            return [self.mav.mission_ack_encode(*up['gcs'],
                                                mavlink.MAV_MISSION_OPERATION_CANCELLED, 0)]
        return [self._request(len(up['items']))]

    def take_completed(self) -> list[PlanWaypoint] | None:
        """A newly accepted plan (empty = cleared), once; None if nothing new."""
        plan, self.completed = self.completed, None
        return plan
