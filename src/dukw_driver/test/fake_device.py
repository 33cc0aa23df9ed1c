"""A fake serial device on a pseudo-terminal, for driver tests (shared by every driver's tests).

How it works: ``os.openpty()`` gives a master/slave pair. The node under test
opens a *symlink* (``FakeDevice.path``, e.g. ``tmp_path / 'ttyMaestro'``) that
points at the slave (``/dev/pts/N``), exactly as it would open ``/dev/ttyACM0``.
A thread plays the device on the master side:

- ``respond(data) -> bytes``: called with every chunk the host wrote; what it
  returns is written back (request/response devices: Maestro, Roboteq). A
  stateful emulator keeps its own buffer for requests split across chunks.
- ``stream() -> bytes``: called every ``stream_period_s``; what it returns is
  written (streaming devices: NMEA sounders, MAVLink autopilots).
- ``send(data)``: write bytes from the test itself (e.g. garbage).
- ``silent = True``: the device stops answering but stays plugged in.

``unplug()`` stops the thread, closes master and slave and removes the symlink:
the host's reads fail (EIO) and reopening fails (no such file), like a USB
cable pulled out. ``replug()`` makes a new pty and a new symlink at the same
path, like the cable coming back. Everything the host wrote is in
``received`` (a bytearray; guarded by ``lock``).

Use as a context manager, or call ``close()``::

    with FakeDevice(tmp_path / 'ttyMaestro', respond=maestro.feed) as dev:
        node = make_node(port=str(dev.path))
        ...
        dev.unplug(); ...; dev.replug()
"""
from __future__ import annotations

import os
import select
import threading
import time
import tty
from pathlib import Path
from collections.abc import Callable


class FakeDevice:
    """A device emulator on the master side of a pty, reachable at a symlink path."""

    def __init__(self, path: str | os.PathLike, respond: Callable[[bytes], bytes] | None = None,
                 stream: Callable[[], bytes] | None = None,
                 stream_period_s: float = 0.1) -> None:
        self.path = Path(path)
        self.respond = respond
        self.stream = stream
        self.stream_period_s = stream_period_s
        self.silent = False
        self.received = bytearray()
        self.lock = threading.Lock()
        self.plugs = 0
        self._master = -1
        self._slave = -1
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self.errors: list[str] = []   # exceptions raised by respond/stream (should stay empty)
        self.replug()

    @property
    def plugged(self) -> bool:
        """True while the device is plugged in."""
        return self._thread is not None

    def replug(self) -> None:
        """Plug the device in: a new pty and the symlink pointing at its slave."""
        if self.plugged:
            return
        self._master, self._slave = os.openpty()
        tty.setraw(self._slave)  # no echo, no CR/NL translation before the host configures it
        os.set_blocking(self._master, False)  # a host that stops reading must not hang the thread
        if self.path.is_symlink() or self.path.exists():
            self.path.unlink()
        self.path.symlink_to(os.ttyname(self._slave))
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name=f'fake:{self.path.name}',
                                        daemon=True)
        self._thread.start()
        self.plugs += 1

    def unplug(self) -> None:
        """Pull the cable: stop answering, close the pty and remove the symlink."""
        if not self.plugged:
            return
        self._stop.set()
        self._thread.join(timeout=2.0)
        self._thread = None
        if self.path.is_symlink():
            self.path.unlink()
        for fd in (self._master, self._slave):
            try:
                os.close(fd)
            except OSError:
                pass
        self._master = self._slave = -1

    def send(self, data: bytes) -> None:
        """Write ``data`` to the host now (from the test thread)."""
        if self.plugged:
            self._write(self._master, data)

    def take_received(self) -> bytes:
        """Return and clear what the host wrote so far."""
        with self.lock:
            data = bytes(self.received)
            self.received.clear()
        return data

    def wait_for(self, predicate: Callable[[bytes], bool], timeout_s: float = 5.0) -> bool:
        """Wait until ``predicate(received bytes)`` is true (test helper; sleeps)."""
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            with self.lock:
                if predicate(bytes(self.received)):
                    return True
            time.sleep(0.01)
        return False

    def close(self) -> None:
        """Unplug for good."""
        self.unplug()

    def __enter__(self) -> 'FakeDevice':
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def _run(self) -> None:
        master, stop = self._master, self._stop
        next_stream = time.monotonic()
        while not stop.is_set():
            ready, _, _ = select.select([master], [], [], 0.005)
            if ready:
                try:
                    data = os.read(master, 4096)
                except OSError:  # host side not open right now (EIO): wait for it
                    stop.wait(0.01)
                    data = b''
                if data:
                    with self.lock:
                        self.received.extend(data)
                    if self.respond is not None and not self.silent:
                        self._write(master, self._call(self.respond, data))
            if self.stream is not None and time.monotonic() >= next_stream:
                next_stream += self.stream_period_s
                if not self.silent:
                    self._write(master, self._call(self.stream))

    def _call(self, func, *args) -> bytes:
        try:
            return func(*args) or b''
        except Exception as exc:  # a broken emulator must show up in the test, not kill the thread
            self.errors.append(repr(exc))
            return b''

    @staticmethod
    def _write(master: int, data: bytes) -> None:
        while data:
            try:
                written = os.write(master, data)
            except OSError:  # buffer full (host not reading) or closed: the bytes are lost
                return
            data = data[written:]
