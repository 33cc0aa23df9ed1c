"""MAVLink 2 message signing that a forged packet cannot use to lock the real key out. ROS-free.

pymavlink signs and checks packets (SHA-256 over key + packet, 48-bit timestamp in
units of 10 us since 2015-01-01, one timestamp per stream (link id, system,
component) that must rise). Its stock ``MAVLink.check_signature`` stores the
timestamp of a packet BEFORE it verifies the signature: one forged packet with a
timestamp far in the future makes every later packet of the real ground station on
that stream "old", i.e. a stranger's radio locks the real key out.
``SecureSigning.install`` replaces that check with one that verifies the signature
first (constant-time compare) and only then accepts and records the timestamp, and
counts every rejected packet by reason. ``TimestampStore`` keeps our own and every
stream's timestamp in a file so that a restart neither reuses timestamps nor
accepts packets replayed from before it.
"""
from __future__ import annotations

import hashlib
import hmac
import json
import os
import secrets
import struct
import time
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

from pymavlink.dialects.v20 import common as mavlink

from dukw_common.config import ConfigError

KEY_BYTES = 32
#: 2015-01-01T00:00:00Z, the epoch of MAVLink signing timestamps, in Unix seconds.
SIGNING_EPOCH_UNIX_S = 1420070400
TICKS_PER_S = 100_000                      # one tick = 10 us
#: A new stream may start at most this far behind our timestamp (pymavlink's and the spec's).
NEW_STREAM_MAX_AGE_TICKS = 60 * TICKS_PER_S
#: Unsigned packets accepted even with allow_unsigned false: SiK radios inject RADIO_STATUS
#: unsigned into the stream (as ArduPilot does; it commands nothing).
UNSIGNED_ALLOWED_IDS = frozenset({mavlink.MAVLINK_MSG_ID_RADIO_STATUS})
_SIGN_TS = struct.Struct('<IH')

REASONS = ('unsigned', 'bad_signature', 'replayed', 'stale_stream')


def signing_timestamp(unix_s: float) -> int:
    """Unix time (s) -> MAVLink signing timestamp (10 us ticks since 2015)."""
    return max(0, int((unix_s - SIGNING_EPOCH_UNIX_S) * TICKS_PER_S))


def parse_key(data: bytes, where: str = 'signing key') -> bytes:
    """32 raw bytes, or 64 hex characters (surrounding whitespace ignored) -> the 32-byte key."""
    if len(data) == KEY_BYTES:
        return bytes(data)
    text = data.strip()
    if len(text) == 2 * KEY_BYTES:
        try:
            return bytes.fromhex(text.decode('ascii'))
        except (UnicodeDecodeError, ValueError):
            pass
    raise ConfigError(f'{where}: must hold exactly {KEY_BYTES} raw bytes or {2 * KEY_BYTES} hex '
                      f'characters, got {len(data)} bytes')


def load_key(path: str | os.PathLike) -> bytes:
    """Read the signing key file; ConfigError naming the file when it is missing or malformed."""
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise ConfigError(f'signing_key_file {str(path)!r}: cannot read it ({exc})') from exc
    return parse_key(data, f'signing_key_file {str(path)!r}')


def key_from_passphrase(passphrase: str) -> bytes:
    """The 32-byte key QGroundControl and MAVProxy (``signing key PASSPHRASE``) derive: SHA-256."""
    return hashlib.sha256(passphrase.encode('utf-8')).digest()


def generate_key_file(path: str | os.PathLike) -> tuple[bytes, str]:
    """Make a random passphrase; write its key as 64 hex characters to ``path`` and the
    passphrase to ``<path>.passphrase`` (both mode 0600); return (key, passphrase)."""
    passphrase = secrets.token_urlsafe(18)
    key = key_from_passphrase(passphrase)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True, mode=0o700)
    for target, text in ((path, key.hex()), (Path(f'{path}.passphrase'), passphrase)):
        fd = os.open(target, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        with os.fdopen(fd, 'w') as handle:
            handle.write(text + '\n')
    return key, passphrase


StreamKey = tuple[int, int, int]   # (link id, system id, component id)


@dataclass
class TimestampState:
    """Our next outgoing timestamp and the last accepted one of every incoming stream."""

    timestamp: int = 0
    streams: dict[StreamKey, int] = field(default_factory=dict)


class TimestampStore:
    """Keeps a TimestampState in a JSON file (written atomically); '' = not persisted."""

    def __init__(self, path: str | os.PathLike | None) -> None:
        self.path = Path(path) if path else None

    def load(self) -> TimestampState:
        """The saved state; an empty one when there is no file. ConfigError when malformed."""
        if self.path is None or not self.path.exists():
            return TimestampState()
        try:
            doc = json.loads(self.path.read_text())
            streams = {(int(s[0]), int(s[1]), int(s[2])): int(s[3]) for s in doc['streams']}
            return TimestampState(int(doc['timestamp']), streams)
        except (OSError, ValueError, KeyError, TypeError, IndexError) as exc:
            raise ConfigError(f'signing timestamp file {str(self.path)!r} is unreadable: '
                              f'{exc}') from exc

    def save(self, state: TimestampState) -> None:
        """Write the state (temporary file + rename, so a crash leaves the old one)."""
        if self.path is None:
            return
        doc = {'timestamp': state.timestamp,
               'streams': [[*key, ts] for key, ts in sorted(state.streams.items())]}
        tmp = self.path.with_name(self.path.name + '.tmp')
        tmp.write_text(json.dumps(doc))
        os.replace(tmp, self.path)


class SecureSigning:
    """Signs what a pymavlink ``MAVLink`` sends and checks what it receives, signature first.

    ``rejected`` counts refused packets by reason: ``unsigned`` (no signature, or a
    MAVLink 1 packet), ``bad_signature`` (wrong key or altered), ``replayed``
    (signature good, timestamp not newer than the stream's last), ``stale_stream``
    (signature good, a new stream more than a minute behind our clock).
    """

    def __init__(self, key: bytes, *, link_id: int = 0, allow_unsigned: bool = False,
                 state: TimestampState | None = None,
                 wall_clock: Callable[[], float] = time.time) -> None:
        if len(key) != KEY_BYTES:
            raise ConfigError(f'signing key must be {KEY_BYTES} bytes, got {len(key)}')
        if not 0 <= link_id <= 255:
            raise ConfigError(f'signing link_id must be 0..255, got {link_id}')
        self.key = bytes(key)
        self.link_id = link_id
        self.allow_unsigned = allow_unsigned
        self.wall_clock = wall_clock
        self.state = state or TimestampState()
        self.state.timestamp = max(self.state.timestamp + 1, signing_timestamp(wall_clock()))
        self.rejected: Counter[str] = Counter()
        self.accepted = 0
        self._mav: mavlink.MAVLink | None = None
        self._failed_reason: str | None = None

    def install(self, mav: mavlink.MAVLink) -> None:
        """Make ``mav`` sign everything it sends and check everything it parses this way."""
        signing = mav.signing
        signing.secret_key = self.key
        signing.link_id = self.link_id
        signing.sign_outgoing = True
        signing.timestamp = self.state.timestamp
        signing.stream_timestamps = self.state.streams
        signing.allow_unsigned_callback = self._unsigned_callback
        mav.check_signature = self.check_signature
        self._mav = mav

    def advance_clock(self) -> None:
        """Keep the outgoing timestamp at least at wall time (call before sending)."""
        if self._mav is not None:
            self._mav.signing.timestamp = max(self._mav.signing.timestamp,
                                              signing_timestamp(self.wall_clock()))

    def snapshot(self) -> TimestampState:
        """The state to persist now."""
        if self._mav is not None:
            self.state.timestamp = self._mav.signing.timestamp
        return TimestampState(self.state.timestamp, dict(self.state.streams))

    def verify(self, msgbuf: bytes | bytearray) -> bool:
        """True if the signature block of a signed MAVLink 2 packet matches our key."""
        digest = hashlib.sha256(self.key + bytes(msgbuf[:-6])).digest()[:6]
        return hmac.compare_digest(digest, bytes(msgbuf[-6:]))

    def check_signature(self, msgbuf: bytearray, src_system: int, src_component: int) -> bool:
        """pymavlink's hook: signature first, then the timestamp; record only a good packet."""
        self._failed_reason = None
        if not self.verify(msgbuf):
            return self._fail('bad_signature')
        tlow, thigh = _SIGN_TS.unpack(bytes(msgbuf[-12:-6]))
        timestamp = tlow + (thigh << 32)
        stream = (msgbuf[-13], src_system, src_component)
        streams = self.state.streams
        ours = self._mav.signing.timestamp if self._mav is not None else self.state.timestamp
        if stream in streams:
            if timestamp <= streams[stream]:
                return self._fail('replayed')
        elif timestamp + NEW_STREAM_MAX_AGE_TICKS < ours:
            return self._fail('stale_stream')
        streams[stream] = timestamp
        if self._mav is not None:
            self._mav.signing.timestamp = max(self._mav.signing.timestamp, timestamp)
        self.accepted += 1
        return True

    def _fail(self, reason: str) -> bool:
        self._failed_reason = reason
        return False

    def _unsigned_callback(self, _mav, msg_id: int) -> bool:
        # pymavlink calls this for unsigned packets and for signed ones that failed the check
        if self._failed_reason is not None:
            self.rejected[self._failed_reason] += 1
            self._failed_reason = None
            return False
        if self.allow_unsigned or msg_id in UNSIGNED_ALLOWED_IDS:
            return True
        self.rejected['unsigned'] += 1
        return False

    def counts(self) -> dict[str, int]:
        """Rejected packets by reason (every reason listed) plus the accepted signed ones."""
        return {**{f'rejected_{r}': self.rejected[r] for r in REASONS},
                'accepted_signed': self.accepted}
