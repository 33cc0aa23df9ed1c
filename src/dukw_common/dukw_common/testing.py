"""Helpers for tests of the stack through real rclpy and real processes."""
from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import time
from pathlib import Path
from typing import Callable, Iterator, Sequence

import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node


def executable(package: str, name: str) -> Path:
    """Return ``<prefix>/lib/<package>/<name>`` as ``ros2 run`` resolves it (ament index)."""
    from ament_index_python.packages import get_package_prefix
    return Path(get_package_prefix(package)) / 'lib' / package / name


@contextlib.contextmanager
def ros_node(name: str = 'test_probe') -> Iterator[tuple[Node, SingleThreadedExecutor]]:
    """An rclpy node in its own isolated context, with an executor to spin it."""
    context = Context()
    rclpy.init(context=context)
    node = Node(name, context=context)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    try:
        yield node, executor
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.shutdown(context=context)


def spin_until(executor: SingleThreadedExecutor, predicate: Callable[[], bool],
               timeout_s: float) -> bool:
    """Spin ``executor`` until ``predicate()`` is true or ``timeout_s`` passes; return it."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if predicate():
            return True
        executor.spin_once(timeout_sec=0.02)
    return predicate()


def moving_before_neutral(commands: Sequence[tuple[float, object]], since: float) -> int:
    """How many moving commands (``stbd_pct`` not 0) of the (receive time, DiffCommand)
    list came after ``since`` before the first neutral one: "at once" counted in commands,
    which a busy machine does not stretch as it stretches wall seconds."""
    after = [m for t, m in commands if t > since]
    return next(i for i, m in enumerate(after) if m.stbd_pct == 0.0)


class NodeProcess:
    """An installed node run as its own process, stopped with SIGINT like Ctrl-C."""

    def __init__(self, package: str, name: str, args: Sequence[str] = (),
                 env: dict[str, str] | None = None) -> None:
        self.command = [str(executable(package, name)), *args]
        self.proc = subprocess.Popen(self.command, stdout=subprocess.PIPE,
                                     stderr=subprocess.PIPE, text=True,
                                     env={**os.environ, **(env or {})})
        self.stdout = ''
        self.stderr = ''

    def alive(self) -> bool:
        """True while the process runs."""
        return self.proc.poll() is None

    def stop(self, timeout_s: float = 10.0) -> int:
        """Send SIGINT, wait, and return the exit code (SIGKILL after the timeout)."""
        if self.alive():
            self.proc.send_signal(signal.SIGINT)
        try:
            self.stdout, self.stderr = self.proc.communicate(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.stdout, self.stderr = self.proc.communicate()
        return self.proc.returncode

    def finish(self, timeout_s: float = 30.0) -> int:
        """Wait for a program that ends by itself, and return its exit code.

        A program that overstays ``timeout_s`` is stopped like :meth:`stop`. Sending SIGINT
        to one that is already tearing down would kill it by the signal (exit -2) once the
        interpreter has given SIGINT back to its default action.
        """
        try:
            self.stdout, self.stderr = self.proc.communicate(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            return self.stop()
        return self.proc.returncode

    def __enter__(self) -> 'NodeProcess':
        return self

    def __exit__(self, *exc) -> None:
        self.stop()


def sample_message(cls, seed: int = 1):
    """Build a message of type ``cls`` with every field set to a distinct non-default value."""
    import importlib
    msg = cls()
    for i, (field, kind) in enumerate(cls.get_fields_and_field_types().items()):
        value_seed = seed * 31 + i
        setattr(msg, field, _sample_value(kind, value_seed, importlib))
    return msg


def _sample_value(kind: str, seed: int, importlib):
    if kind.startswith('sequence<'):
        inner = kind[len('sequence<'):-1].split(',')[0]
        return [_sample_value(inner, seed + k, importlib) for k in range(3)]
    if kind in ('double', 'float'):
        return float(seed % 97) + 0.5
    if kind == 'boolean':
        return seed % 2 == 0
    if kind.startswith(('uint', 'int', 'octet', 'byte', 'char')):
        return seed % 120 + 1
    if kind.startswith('string'):
        return f'value-{seed}'
    if kind == 'builtin_interfaces/Time':
        from builtin_interfaces.msg import Time
        return Time(sec=seed, nanosec=seed * 1000)
    package, name = kind.split('/')
    module = importlib.import_module(f'{package}.msg')
    return sample_message(getattr(module, name), seed)
