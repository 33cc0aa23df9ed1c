"""A ground station made of real pymavlink (the far side of the radio) for shore-link tests."""
from __future__ import annotations

import time

from pymavlink.dialects.v20 import common as mavlink

from dukw_driver.mavlink_signing import signing_timestamp

KEY = bytes(range(32))
WRONG_KEY = bytes(range(1, 33))


class Gcs:
    """Encodes what a ground station sends (signed with ``key`` unless None) and parses replies."""

    def __init__(self, key: bytes | None = KEY, system: int = 255, component: int = 190,
                 link_id: int = 1) -> None:
        self.out = _Buffer()
        self.mav = mavlink.MAVLink(self.out, system, component)
        self.mav.robust_parsing = True
        self.rx = mavlink.MAVLink(None, system, component)
        self.rx.robust_parsing = True
        if key is not None:
            self.mav.signing.secret_key = key
            self.mav.signing.sign_outgoing = True
            self.mav.signing.link_id = link_id
            self.mav.signing.timestamp = signing_timestamp(time.time())
            self.rx.signing.secret_key = key
            self.rx.signing.timestamp = self.mav.signing.timestamp
        self.received: list = []

    def pack(self, msg) -> bytes:
        """The packet for ``msg`` (signed, next timestamp)."""
        self.mav.signing.timestamp = max(self.mav.signing.timestamp,
                                         signing_timestamp(time.time()))
        self.mav.send(msg)
        return self.out.take()

    def heartbeat(self) -> bytes:
        return self.pack(self.mav.heartbeat_encode(mavlink.MAV_TYPE_GCS,
                                                   mavlink.MAV_AUTOPILOT_INVALID, 0, 0, 0))

    def manual(self, x: int, r: int = 0) -> bytes:
        return self.pack(self.mav.manual_control_encode(1, x, 0, 500, r, 0))

    def command(self, command: int, *params: float) -> bytes:
        p = list(params) + [0.0] * (7 - len(params))
        return self.pack(self.mav.command_long_encode(1, 1, command, 0, *p))

    def feed(self, data: bytes) -> list:
        """Parse the vehicle's bytes; keep and return the good messages."""
        got = [m for m in (self.rx.parse_buffer(data) or []) if m.get_type() != 'BAD_DATA']
        self.received.extend(got)
        return got

    def of_type(self, kind: str) -> list:
        return [m for m in self.received if m.get_type() == kind]


class _Buffer:
    def __init__(self) -> None:
        self.data = bytearray()

    def write(self, buf: bytes) -> None:
        self.data.extend(buf)

    def take(self) -> bytes:
        out = bytes(self.data)
        self.data.clear()
        return out
