"""bringup: start the stack's nodes as processes, watch them, stop them in order.

``launch`` is not on PyPI, so plain Python machines use this runner; a full ROS 2
install can use ``ros2 launch dukw_bringup stack.launch.py`` instead. A stack
file (config/stack_sim.yaml, config/stack_boat.yaml) lists the nodes:

    stack:
      name: sim
      nodes:
        - {name: sim_node, package: dukw_sim, executable: sim_node, args: [-p, rate_hz:=100.0]}

``args`` are ROS arguments (after the parameter files), ``cli_args`` the program's
own (before ``--ros-args``), ``rename: true`` runs the node under ``name``.
``realtime_priority: N`` (1-98) runs the process, all its threads, under the real-time
policy SCHED_FIFO at priority N: the control chain and the devices at its two ends wake at
once when a message arrives, even on a loaded computer (benchmarks/bench_stack.py; it needs
root, CAP_SYS_NICE or an ``rtprio`` limit: without, the runner says so and the node runs at
normal priority; the kernel's real-time throttling still leaves 5 % of each core to others).
``composes: [ekf_node, ...]`` (with ``executable: compose``) runs those nodes in one
process with one executor (dukw_bringup.compose; config/stack_sim_composed.yaml). A stack
with ``clock_node: sim_node`` runs every other node with ``use_sim_time:=true``
(as the launch file and the main job do), so stamps and ages share one clock.
``discovery_range: LOCALHOST`` (both stacks) keeps the ROS graph on the vehicle:
the nodes get ``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`` unless the environment
sets it explicitly (README "Security"). With ``ROS_SECURITY_ENABLE=true`` each
node runs in its SROS2 enclave ``/dukw/<name>`` (config/sros2/dukw_policy.xml).

Each node runs as ``<prefix>/lib/<package>/<executable> --ros-args
[-r __node:=<name>] --params-file <file>... <args>`` in its own session (so a
terminal's Ctrl-C reaches only the runner, which then stops the nodes in
reverse start order: SIGINT, wait, SIGKILL after a timeout). A node that exits
on its own is a failure: the runner says so, stops the rest and exits 1. It
restarts nothing. This module imports no rclpy.
"""
from __future__ import annotations

import argparse
import contextlib
import ctypes
import os
import re
import signal
import subprocess
import sys
import threading
import time
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import IO, Any, Mapping, Sequence


from dukw_bringup.yaml_file import read_yaml
from dukw_common.config import ConfigError, default_config_path

_NAME = re.compile(r'^[A-Za-z][A-Za-z0-9_]*$')
_PR_SET_PDEATHSIG = 1
DISCOVERY_ENV = 'ROS_AUTOMATIC_DISCOVERY_RANGE'
#: SROS2 enclaves of config/sros2/dukw_policy.xml: one per node, /dukw/<node name>
ENCLAVE_ROOT = '/dukw'
DISCOVERY_RANGES = ('LOCALHOST', 'SUBNET', 'OFF', 'SYSTEM_DEFAULT')
#: highest realtime_priority of a stack file (99 stays free for the kernel's watchdogs)
MAX_PRIORITY = 98


@dataclass(frozen=True)
class NodeSpec:
    """One node of a stack: what to run and with which extra arguments."""

    name: str
    package: str
    executable: str
    args: tuple[str, ...] = ()      # ROS arguments, after the parameter files
    rename: bool = False            # run under ``name`` (-r __node:=name), for a second instance
    cli_args: tuple[str, ...] = ()  # the program's own arguments, before --ros-args
    composes: tuple[str, ...] = ()  # ROS nodes this process runs (compose); () = itself
    realtime_priority: int = 0      # SCHED_FIFO priority of the process; 0 = normal

    @property
    def node_names(self) -> tuple[str, ...]:
        """The ROS nodes this process runs (their parameter blocks)."""
        return self.composes or (self.name,)


@dataclass(frozen=True)
class StackSpec:
    """A stack: its nodes in start order."""

    name: str
    nodes: tuple[NodeSpec, ...]
    clock_node: str | None = None   # publishes /clock: every other node uses sim time
    discovery_range: str | None = None   # ROS_AUTOMATIC_DISCOVERY_RANGE unless already set

    def uses_sim_time(self, spec: NodeSpec) -> bool:
        """Whether ``spec`` runs on the clock node's /clock."""
        return self.clock_node is not None and spec.name != self.clock_node

    def node_names(self) -> list[str]:
        """Every ROS node of the stack (a composed process's nodes one by one)."""
        return [name for spec in self.nodes for name in spec.node_names]

    def at_normal_priority(self) -> StackSpec:
        """The same stack with no process under SCHED_FIFO (faster than real time the wall
        clock latency means nothing, and a chain working flat out would hog a core)."""
        return replace(self, nodes=tuple(replace(n, realtime_priority=0) for n in self.nodes))

    def node(self, name: str) -> NodeSpec:
        """The node called ``name``; KeyError if there is none."""
        for spec in self.nodes:
            if spec.name == name:
                return spec
        raise KeyError(name)


def parse_stack(doc: Any, source: str = 'stack') -> StackSpec:
    """Build a StackSpec from a parsed stack file; raise ConfigError naming the fault."""
    if not isinstance(doc, Mapping) or not isinstance(doc.get('stack'), Mapping):
        raise ConfigError(f'{source}: needs a top-level "stack" mapping')
    tree = doc['stack']
    raw_nodes = tree.get('nodes')
    if not isinstance(raw_nodes, list) or not raw_nodes:
        raise ConfigError(f'{source}: stack.nodes must be a non-empty list')
    nodes: list[NodeSpec] = []
    for i, raw in enumerate(raw_nodes):
        if not isinstance(raw, Mapping):
            raise ConfigError(f'{source}: stack.nodes[{i}] must be a mapping')
        for key in ('name', 'package', 'executable'):
            if not isinstance(raw.get(key), str) or not _NAME.match(raw[key]):
                raise ConfigError(f'{source}: stack.nodes[{i}].{key} must be a plain name, '
                                  f'got {raw.get(key)!r}')
        lists = {}
        for key in ('args', 'cli_args'):
            value = raw.get(key, [])
            if not isinstance(value, list) or not all(
                    isinstance(a, (str, int, float)) for a in value):
                raise ConfigError(f'{source}: stack.nodes[{i}].{key} must be a list of strings')
            lists[key] = tuple(str(a) for a in value)
        nodes.append(NodeSpec(raw['name'], raw['package'], raw['executable'], lists['args'],
                              bool(raw.get('rename', False)), lists['cli_args'],
                              _composes(raw, f'{source}: stack.nodes[{i}]'),
                              _priority(raw, f'{source}: stack.nodes[{i}]')))
    names = [n.name for n in nodes]
    if len(set(names)) != len(names):
        raise ConfigError(f'{source}: node names must be unique, got {names}')
    ros_names = [name for n in nodes for name in n.node_names]
    if len(set(ros_names)) != len(ros_names):
        raise ConfigError(f'{source}: a node runs twice (composed and alone?): {ros_names}')
    clock_node = tree.get('clock_node')
    if clock_node is not None and clock_node not in names:
        raise ConfigError(f'{source}: stack.clock_node {clock_node!r} is not one of {names}')
    discovery = tree.get('discovery_range')
    if discovery is not None and discovery not in DISCOVERY_RANGES:
        raise ConfigError(f'{source}: stack.discovery_range must be one of {DISCOVERY_RANGES}, '
                          f'got {discovery!r}')
    return StackSpec(str(tree.get('name', Path(source).stem)), tuple(nodes), clock_node,
                     discovery)


def _composes(raw: Mapping, where: str) -> tuple[str, ...]:
    """A process's ``composes`` list (the nodes of one composed process), checked."""
    value = raw.get('composes', [])
    if not isinstance(value, list) or not all(
            isinstance(n, str) and _NAME.match(n) for n in value):
        raise ConfigError(f'{where}.composes must be a list of node names, got {value!r}')
    if value and raw.get('rename'):
        raise ConfigError(f'{where}: rename would rename every composed node; drop it')
    return tuple(value)


def _priority(raw: Mapping, where: str) -> int:
    """A process's ``realtime_priority`` (SCHED_FIFO 1-98; 0 or absent: normal), checked."""
    value = raw.get('realtime_priority', 0)
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= MAX_PRIORITY:
        raise ConfigError(f'{where}.realtime_priority must be an integer 0..{MAX_PRIORITY} '
                          f'(0 = normal), got {value!r}')
    return value


def load_stack(path: str | Path) -> StackSpec:
    """Read a stack file; raise ConfigError if it is missing or malformed."""
    path = Path(path)
    doc = read_yaml(path, 'stack file')
    return parse_stack(doc, str(path))


def stack_path(name_or_path: str) -> Path:
    """``sim`` -> config/stack_sim.yaml next to the parameter file; a path stays a path."""
    if name_or_path.endswith(('.yaml', '.yml')) or os.sep in name_or_path:
        return Path(name_or_path)
    return default_config_path().parent / f'stack_{name_or_path}.yaml'


def node_executable(package: str, executable: str) -> Path:
    """``<prefix>/lib/<package>/<executable>`` as ``ros2 run`` resolves it (ament index)."""
    from ament_index_python.packages import PackageNotFoundError, get_package_prefix
    try:
        path = Path(get_package_prefix(package)) / 'lib' / package / executable
    except PackageNotFoundError as exc:
        raise ConfigError(f'package {package!r} is not installed (run scripts/setup.sh)') from exc
    if not os.access(path, os.X_OK):
        raise ConfigError(f'no executable {path} (is {package} built?)')
    return path


def node_command(spec: NodeSpec, params_files: Sequence[Path],
                 sim_time: bool = False, secure: bool = False) -> list[str]:
    """The command line that runs one node (``secure``: in its SROS2 enclave)."""
    command = [str(node_executable(spec.package, spec.executable)), *spec.cli_args,
               *spec.composes, '--ros-args']
    if spec.rename:
        command += ['-r', f'__node:={spec.name}']
    if secure:
        command += ['--enclave', f'{ENCLAVE_ROOT}/{spec.name}']
    for params in params_files:
        command += ['--params-file', str(params)]
    if sim_time:
        command += ['-p', 'use_sim_time:=true']
    return command + list(spec.args)


try:
    _PRCTL = ctypes.CDLL(None, use_errno=True).prctl
except (OSError, AttributeError):  # not Linux
    _PRCTL = None


def _die_with_parent() -> None:
    """In the child before exec: get SIGTERM if the runner itself dies (Linux)."""
    if _PRCTL is not None:
        _PRCTL(_PR_SET_PDEATHSIG, int(signal.SIGTERM))


def _child_setup(priority: int):
    """What the child runs before exec: die with the runner; take its real-time priority
    (inherited by every thread it starts; refused without the right: checked afterwards)."""
    def setup() -> None:
        _die_with_parent()
        if priority:
            with contextlib.suppress(OSError):
                os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
    return setup


def realtime_refusal(pid: int, priority: int) -> str:
    """'' when process ``pid`` runs at SCHED_FIFO ``priority`` (or none was asked), else why
    not."""
    if not priority:
        return ''
    try:
        if (os.sched_getscheduler(pid) == os.SCHED_FIFO
                and os.sched_getparam(pid).sched_priority == priority):
            return ''
    except OSError as exc:
        return f'cannot read its scheduling: {exc}'
    return (f'realtime_priority {priority} refused (needs root, CAP_SYS_NICE or an rtprio '
            'limit): it runs at normal priority, its latency suffers when the computer is busy')


@dataclass
class NodeProc:
    """A running node: its process and where its output goes."""

    spec: NodeSpec
    proc: subprocess.Popen
    log: IO[str] | None
    reader: threading.Thread | None = None
    tail: list[str] = field(default_factory=list)   # last lines, for the failure report


class Runner:
    """Starts a StackSpec's nodes, watches them and stops them in reverse order.

    ``echo``: forward every node's output with a ``[name]`` prefix to ``out``;
    ``log_dir``: also write each node's output to ``<log_dir>/<name>.log``.
    """

    TAIL_LINES = 20

    def __init__(self, stack: StackSpec, params_files: Sequence[Path] = (),
                 log_dir: Path | None = None, echo: bool = True, out: IO[str] | None = None,
                 stop_timeout_s: float = 10.0, env: Mapping[str, str] | None = None) -> None:
        self.stack = stack
        self.params_files = [Path(p) for p in params_files] or [default_config_path()]
        self.log_dir = log_dir
        self.echo = echo
        self.out = out or sys.stdout
        self.stop_timeout_s = stop_timeout_s
        self.env = {**os.environ, 'PYTHONUNBUFFERED': '1', **(env or {})}
        if stack.discovery_range and not self.env.get(DISCOVERY_ENV):
            self.env[DISCOVERY_ENV] = stack.discovery_range
        self.procs: list[NodeProc] = []
        self._lock = threading.Lock()
        self._stopping = False

    # -- life cycle
    def start(self) -> None:
        """Start every node in order; on a failure stop those already started and re-raise."""
        secure = self.env.get('ROS_SECURITY_ENABLE', '').lower() == 'true'
        commands = [node_command(spec, self.params_files, self.stack.uses_sim_time(spec),
                                 secure) for spec in self.stack.nodes]
        if self.log_dir is not None:
            self.log_dir.mkdir(parents=True, exist_ok=True)
        try:
            for spec, command in zip(self.stack.nodes, commands, strict=True):
                self._spawn(spec, command)
        except OSError:
            self.stop()
            raise

    def _spawn(self, spec: NodeSpec, command: list[str]) -> None:
        log = open(self.log_dir / f'{spec.name}.log', 'w') if self.log_dir else None
        proc = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, text=True, bufsize=1, env=self.env,
                                start_new_session=True,
                                preexec_fn=_child_setup(spec.realtime_priority))
        node = NodeProc(spec, proc, log)
        node.reader = threading.Thread(target=self._pump, args=(node,), daemon=True,
                                       name=f'bringup-{spec.name}')
        node.reader.start()
        self.procs.append(node)
        self.say(f'started {spec.name} (pid {proc.pid}): {" ".join(command)}')
        refusal = realtime_refusal(proc.pid, spec.realtime_priority)
        if refusal:
            self.say(f'WARNING: {spec.name}: {refusal}')

    def _pump(self, node: NodeProc) -> None:
        if node.proc.stdout is None:
            return
        for line in node.proc.stdout:
            line = line.rstrip('\n')
            node.tail = (node.tail + [line])[-self.TAIL_LINES:]
            if node.log is not None:
                node.log.write(line + '\n')
                node.log.flush()
            if self.echo:
                with self._lock:
                    print(f'[{node.spec.name}] {line}', file=self.out, flush=True)

    def pids(self) -> dict[str, int]:
        """Process id of each node, by name."""
        return {n.spec.name: n.proc.pid for n in self.procs}

    def poll(self) -> NodeProc | None:
        """The first node that has exited on its own, or None while all run."""
        if self._stopping:
            return None
        for node in self.procs:
            if node.proc.poll() is not None:
                return node
        return None

    def report_death(self, node: NodeProc) -> str:
        """Say loudly that ``node`` died, with its last lines; return the message."""
        if node.reader is not None:
            node.reader.join(timeout=2.0)
        code = node.proc.returncode
        how = f'killed by signal {-code}' if code < 0 else f'exit code {code}'
        message = f'node {node.spec.name} exited unexpectedly ({how}); stopping the stack'
        with self._lock:
            print(f'[bringup] ERROR: {message}', file=sys.stderr, flush=True)
            if not self.echo and node.tail:
                print(f'[bringup] last lines of {node.spec.name}:', file=sys.stderr)
                for line in node.tail:
                    print(f'    {line}', file=sys.stderr)
                sys.stderr.flush()
        return message

    def stop(self) -> dict[str, int]:
        """Stop every node in reverse start order (SIGINT, wait, SIGKILL); return exit codes."""
        self._stopping = True
        codes: dict[str, int] = {}
        for node in reversed(self.procs):
            codes[node.spec.name] = self._stop_one(node)
        for node in self.procs:
            if node.reader is not None:
                node.reader.join(timeout=2.0)
            if node.log is not None:
                node.log.close()
        return codes

    def _stop_one(self, node: NodeProc) -> int:
        proc = node.proc
        if proc.poll() is None:
            try:
                proc.send_signal(signal.SIGINT)
                proc.wait(timeout=self.stop_timeout_s)
            except subprocess.TimeoutExpired:
                self.say(f'{node.spec.name} ignored SIGINT for {self.stop_timeout_s:.0f} s: '
                         'SIGKILL', error=True)
                proc.kill()
                proc.wait()
        code = proc.returncode
        self.say(f'{node.spec.name} stopped (exit {code})', error=code not in (0, -2))
        return code

    def say(self, text: str, error: bool = False) -> None:
        """A line of the runner's own, prefixed ``[bringup]``."""
        with self._lock:
            stream = sys.stderr if error else self.out
            print(f'[bringup] {"ERROR: " if error else ""}{text}', file=stream, flush=True)

    def watch(self, stop: threading.Event, poll_s: float = 0.1) -> int:
        """Block until ``stop`` is set (exit 0) or a node dies (exit 1); stop the stack."""
        code = 0
        while not stop.wait(poll_s):
            dead = self.poll()
            if dead is not None:
                self.report_death(dead)
                code = 1
                break
        self.stop()
        return code


def wait_for(predicate, timeout_s: float, poll_s: float = 0.05) -> bool:
    """Poll ``predicate`` until true or ``timeout_s`` passes (for callers and tests)."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(poll_s)
    return bool(predicate())


def install_stop_signals(stop: threading.Event) -> None:
    """SIGINT and SIGTERM set ``stop`` instead of raising (main thread only)."""
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda *_: stop.set())


def main(argv: list[str] | None = None) -> int:
    """Console script: ``bringup [sim|boat|STACK.yaml] [--params-file F]... [--log-dir D]``."""
    parser = argparse.ArgumentParser(prog='bringup', description=__doc__.split('\n')[0])
    parser.add_argument('stack', nargs='?', default='sim',
                        help='stack name (config/stack_<name>.yaml) or a stack file')
    parser.add_argument('--params-file', action='append', type=Path, default=[],
                        help='parameter file for every node (repeat: later ones win); '
                             'default config/dukw.yaml')
    parser.add_argument('--log-dir', type=Path, help='also write <node>.log files here')
    parser.add_argument('--quiet', action='store_true',
                        help="do not forward the nodes' output (use with --log-dir)")
    parser.add_argument('--stop-timeout', type=float, default=10.0,
                        help='seconds to wait after SIGINT before SIGKILL')
    args = parser.parse_args(argv)
    stop = threading.Event()
    install_stop_signals(stop)
    try:
        stack = load_stack(stack_path(args.stack))
        runner = Runner(stack, args.params_file, args.log_dir, echo=not args.quiet,
                        stop_timeout_s=args.stop_timeout)
        runner.start()
    except ConfigError as exc:
        print(f'[bringup] FATAL: {exc}', file=sys.stderr)
        return 2
    runner.say(f'stack {stack.name!r} up: {len(stack.nodes)} nodes; Ctrl-C stops it')
    code = runner.watch(stop)
    runner.say('stack stopped' if code == 0 else 'stack failed', error=code != 0)
    return code


if __name__ == '__main__':
    raise SystemExit(main())

