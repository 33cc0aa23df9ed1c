"""Thin rclpy helpers every DUKW-Ling node uses: QoS by intent, parameters, main loop.

This is the only module of dukw_common that imports rclpy.
"""
from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
from dataclasses import dataclass
from typing import Any, Callable, Collection, Mapping, Sequence

import rclpy
from rclpy.executors import Executor, ExternalShutdownException, SingleThreadedExecutor
from rclpy.experimental import EventsExecutor
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import (DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy,
                       qos_profile_sensor_data)
from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
from rclpy.signals import SignalHandlerOptions

from dukw_common.config import ConfigError, ParamValue, load_file, node_params
from dukw_common.diagnostics import Health

#: Sensor streams: best effort, keep last 5 (rclpy's sensor-data profile).
SENSOR_QOS = qos_profile_sensor_data
#: Commands and status that must not be dropped.
COMMAND_QOS = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.VOLATILE, history=HistoryPolicy.KEEP_LAST)
#: Latched state (authority, drive_mode): a late subscriber gets the current value at once.
STATE_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                       durability=DurabilityPolicy.TRANSIENT_LOCAL,
                       history=HistoryPolicy.KEEP_LAST)


@dataclass(frozen=True)
class ParamSpec:
    """A parameter a node declares: its name, meaning and allowed range.

    The default value comes from the stack's parameter file (config/dukw.yaml),
    never from code; ``--params-file`` and ``-p`` override it as usual. Nodes build
    their cores once from these values, so every parameter is read-only at run time:
    a ``set_parameters`` call is refused ("read-only"), never accepted and ignored.
    """

    name: str
    description: str
    min: float | None = None
    max: float | None = None
    read_only: bool = True


def declare_parameters(node: Node, specs: Sequence[ParamSpec],
                       config_path: str | None = None) -> dict[str, ParamValue]:
    """Declare ``specs`` on ``node`` with defaults from the parameter file; return the values.

    Raises ConfigError naming the parameter when the file lacks a default or a
    value is out of its range.
    """
    defaults = node_params(node.get_name(), config_path)
    values: dict[str, ParamValue] = {}
    for spec in specs:
        if spec.name not in defaults:
            raise ConfigError(f'{node.get_name()}: parameter {spec.name!r} has no default in '
                              'the parameter file (config/dukw.yaml)')
        default = defaults[spec.name]
        descriptor = ParameterDescriptor(description=spec.description, read_only=spec.read_only)
        if spec.min is not None or spec.max is not None:
            lo = spec.min if spec.min is not None else -sys.float_info.max
            hi = spec.max if spec.max is not None else sys.float_info.max
            if isinstance(default, int) and not isinstance(default, bool):
                descriptor.integer_range = [IntegerRange(from_value=int(lo), to_value=int(hi))]
            else:
                descriptor.floating_point_range = [
                    FloatingPointRange(from_value=float(lo), to_value=float(hi))]
        try:
            value = node.declare_parameter(spec.name, default, descriptor).value
        except Exception as exc:  # InvalidParameterValueException & co. from an override
            raise ConfigError(f'{node.get_name()}: parameter {spec.name!r}: {exc}') from exc
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            if (spec.min is not None and value < spec.min) or (
                    spec.max is not None and value > spec.max):
                raise ConfigError(f'{node.get_name()}: parameter {spec.name!r} = {value} is '
                                  f'outside [{spec.min}, {spec.max}]')
        values[spec.name] = value
    return values


def param_value(node: Node, name: str) -> ParamValue:
    """Return a declared parameter's current value."""
    return node.get_parameter(name).value


def parameter_overrides(overrides: dict[str, ParamValue]) -> list[Parameter]:
    """Turn a dict into rclpy Parameters (for tests constructing nodes directly)."""
    return [Parameter(k, value=v) for k, v in overrides.items()]


EXECUTOR_ENV = 'DUKW_EXECUTOR'


def default_executor() -> Executor:
    """The executor every node spins: rclpy's EventsExecutor, or ``DUKW_EXECUTOR=single``.

    Measured on the 2-core target (benchmarks/bench_stack.py): the
    SingleThreadedExecutor rebuilds its wait set for every callback and cost the
    stack without the simulator more than a whole core at 100 Hz; the
    EventsExecutor does the same work for a fraction. It must be spun with a
    timeout (platform.md), which run_node does.
    """
    if os.environ.get(EXECUTOR_ENV, 'events') == 'single':
        return SingleThreadedExecutor()
    return EventsExecutor()


def run_node(factory: Callable[[], Node], args: list[str] | None = None,
             executor_factory: Callable[[], Executor] = default_executor) -> int:
    """Run one node until SIGINT/SIGTERM, or until it shuts its context down itself, then
    let it stop safely and exit 0.

    The node may define ``on_shutdown()``: it runs while the context is still up,
    so it can publish a last neutral command. A ConfigError at construction
    prints a clear message and exits 2. ``executor_factory`` may give another
    executor; every executor is spun with a timeout.
    """
    return run_nodes(lambda: [factory()], args, executor_factory)


def run_nodes(factory: Callable[[], Sequence[Node]], args: list[str] | None = None,
              executor_factory: Callable[[], Executor] = default_executor) -> int:
    """run_node for several nodes in one process, spun by ONE executor (a composed
    bring-up, as a ROS 2 component container): ``factory()`` builds and wires them.

    On the way out every node's ``on_shutdown()`` runs in reverse order of the list
    (list the commanding node last: its neutral goes out first), then all are destroyed.
    """
    try:
        check_params_files(sys.argv if args is None else args)
        rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    except (ConfigError, _rclpy.RCLError) as exc:   # e.g. malformed ROS arguments
        print(f'[FATAL] {exc}', file=sys.stderr)
        return 2
    stop = threading.Event()
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda *_: stop.set())
    nodes: Sequence[Node] = ()
    code = 0
    try:
        try:
            nodes = factory()
        except _rclpy.RCLError as exc:   # e.g. DDS-Security asked of a DDS without it
            raise ConfigError(f'cannot create the node: {exc}') from exc
        executor = executor_factory()
        for node in nodes:
            executor.add_node(node)
        with profiled(os.environ.get(PROFILE_ENV, '').format(
                node=nodes[-1].get_name() if nodes else '', pid=os.getpid())):
            while not stop.is_set() and rclpy.ok():
                executor.spin_once(timeout_sec=0.05)
    except ExternalShutdownException:
        pass                     # the node ended itself (context.try_shutdown()): exit 0
    except ConfigError as exc:
        print(f'[FATAL] {exc}', file=sys.stderr)
        code = 2
    finally:
        _shut_down(nodes)
    return code


#: DUKW_PROFILE=FILE: profile the spin loop with cProfile, stats as text to FILE on exit;
#: ``{node}`` in FILE is the (last) node's name, ``{pid}`` the process id
PROFILE_ENV = 'DUKW_PROFILE'


@contextlib.contextmanager
def profiled(path: str | None):
    """cProfile the block when ``path`` is given; write its top 40 (by own time) as text."""
    if not path:
        yield
        return
    import cProfile
    import io
    import pstats
    profile = cProfile.Profile()
    profile.enable()
    try:
        yield
    finally:
        profile.disable()
        text = io.StringIO()
        pstats.Stats(profile, stream=text).sort_stats('tottime').print_stats(40)
        with open(path, 'w') as out:
            out.write(text.getvalue())


def _shut_down(nodes: Sequence[Node]) -> None:
    """Each node's on_shutdown (reverse order, while the context is up), then destroy all."""
    for node in reversed(nodes):
        shutdown_hook = getattr(node, 'on_shutdown', None)
        if callable(shutdown_hook) and rclpy.ok():
            shutdown_hook()
    for node in nodes:
        node.destroy_node()
    rclpy.try_shutdown()


def subscribe_sensors(node: Node, inputs: Mapping[str, tuple[type, Callable[[Any], None]]],
                      handed: Collection[str] = ()) -> None:
    """Subscribe (sensor QoS) each of ``inputs`` (topic -> (type, callback)) but those in
    ``handed``: a composed process (dukw_bringup.compose) subscribes those once itself and
    hands each message to every node's callback, or hands over a core output directly."""
    for topic, (msg_type, callback) in inputs.items():
        if topic not in handed:
            node.create_subscription(msg_type, topic, callback, SENSOR_QOS)


#: A polled input keeps only its newest sample until its reader takes it.
POLLED_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.BEST_EFFORT,
                        durability=DurabilityPolicy.VOLATILE, history=HistoryPolicy.KEEP_LAST)


class LatestSamples:
    """Inputs a node reads at its own (lower) rate, taken when it needs them.

    Each topic is subscribed (KEEP_LAST 1) on a companion node that no executor spins, so
    no sample wakes the node's executor; ``poll()`` takes the newest sample of each and
    hands it to the node's callback. In rclpy every delivered sample costs its executor the
    take, the conversion and the dispatch (about 2 % of a core per 100 Hz topic in its own
    process, README "Topic contract"); polled at the reader's 20 Hz only the newest one
    is taken. What the reader then sees at a poll is what it would have seen with every
    sample (the newest), so keep it to inputs whose callbacks only store their latest value
    and read it at the poll's rate. The companion ignores the process's ROS arguments (no
    ``use_sim_time``, so no /clock of its own) and subscribes the host's resolved names.
    """

    def __init__(self, host: Node,
                 inputs: Mapping[str, tuple[type, Callable[[Any], None]]]) -> None:
        self.node: Node | None = None
        self._takers: list[tuple[Any, Callable[[Any], None]]] = []
        if not inputs:
            return
        self.node = Node(f'{host.get_name()}_polled', namespace=host.get_namespace(),
                         context=host.context, use_global_arguments=False,
                         enable_rosout=False, start_parameter_services=False)
        for topic, (msg_type, callback) in inputs.items():
            subscription = self.node.create_subscription(
                msg_type, host.resolve_topic_name(topic), _never_called, POLLED_QOS)
            self._takers.append((subscription, callback))

    def poll(self) -> int:
        """Hand each topic's newest sample since the last poll to its callback; how many."""
        count = 0
        for subscription, callback in self._takers:
            with subscription.handle:
                taken = subscription.handle.take_message(subscription.msg_type, False)
            if taken is not None:
                callback(taken[0])
                count += 1
        return count

    def destroy(self) -> None:
        """Destroy the companion node (with its host)."""
        if self.node is not None:
            self.node.destroy_node()
            self.node, self._takers = None, []


def _never_called(_msg: Any) -> None:
    """A polled subscription's callback: no executor spins its node."""


def check_params_files(argv: Sequence[str]) -> None:
    """Raise ConfigError naming the file if a ``--params-file`` is missing or malformed
    (rcl would only say RCLError, with a traceback)."""
    argv = list(argv)
    for i, arg in enumerate(argv):
        if arg == '--params-file':
            if i + 1 >= len(argv):
                raise ConfigError('--params-file needs a file name')
            load_file(argv[i + 1])


def vehicle_specs(*groups: str) -> list[ParamSpec]:
    """ParamSpecs for the shared physical facts (``vehicle``, ``drivetrain``, ``soil``...).

    Every value is a non-negative physical quantity except the port bias, which
    may correct either way. Sources are in config/dukw.yaml and vehicle.md.
    """
    from dukw_common import vehicle as v
    classes = {'vehicle': v.VehicleParams, 'drivetrain': v.DrivetrainParams,
               'soil': v.SoilParams, 'limits': v.LimitParams, 'site': v.SiteParams,
               'sensors': v.SensorMounts, 'saturated_sand': v.SaturatedSandParams}
    specs = []
    for group in groups or tuple(classes):
        for name in classes[group].__dataclass_fields__:
            signed = name == 'port_bias_pct' or name.endswith('_x_m')
            lo = -100.0 if signed else 0.0
            hi = 100.0 if name.endswith('_pct') else None
            specs.append(ParamSpec(f'{group}.{name}', f'{group} {name} (see vehicle.md)',
                                   min=lo, max=hi))
    return specs


def diagnostic_array(node: Node, healths: Sequence[Health]):
    """Convert core Health values into a stamped diagnostic_msgs/DiagnosticArray."""
    from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
    array = DiagnosticArray()
    array.header.stamp = node.get_clock().now().to_msg()
    for health in healths:
        status = DiagnosticStatus(level=bytes([int(health.level)]),
                                  name=f'{node.get_name()}: {health.name}',
                                  message=health.message, hardware_id=health.hardware_id)
        status.values = [KeyValue(key=str(k), value=str(v)) for k, v in health.values.items()]
        array.status.append(status)
    return array


def stamp_to_s(stamp) -> float:
    """builtin_interfaces/Time -> seconds."""
    return stamp.sec + stamp.nanosec * 1e-9


#: a header stamp's fields, as ``stamp_s_or`` takes them (readers that take fields)
STAMP_FIELDS = ('header.stamp.sec', 'header.stamp.nanosec')


def stamp_s_or(sec: int, nanosec: int, fallback_s: float) -> float:
    """A header stamp in seconds (as ``stamp_to_s``), or ``fallback_s`` when it is unset
    (zero)."""
    t_s = sec + nanosec * 1e-9
    return t_s if t_s > 0.0 else fallback_s


def stamp_or(msg, fallback_s: float) -> float:
    """A message's header stamp in seconds, or ``fallback_s`` when it is unset (zero)."""
    stamp = msg.header.stamp
    return stamp_s_or(stamp.sec, stamp.nanosec, fallback_s)


def s_to_stamp(t_s: float):
    """Seconds -> builtin_interfaces/Time."""
    from builtin_interfaces.msg import Time
    sec = int(t_s // 1)
    return Time(sec=sec, nanosec=int(round((t_s - sec) * 1e9)) % 1_000_000_000)


def publisher_sources(node, topic: str) -> tuple[int, tuple[str, ...]]:
    """How many publishers ``topic`` has in the ROS graph, and (only when more than one,
    as that costs more) the fully qualified names of their nodes."""
    count = node.count_publishers(topic)
    if count <= 1:
        return count, ()
    infos = node.get_publishers_info_by_topic(node.resolve_topic_name(topic))
    return count, tuple(f'{i.node_namespace.rstrip("/")}/{i.node_name}' for i in infos)


def refuse_second_client(node, sources, service: str, report: Callable[[], None]) -> str:
    """Single-source rule for a state-changing ``service``: count its clients into the
    SourceWatch ``sources``; on a second client (or when the verdict changes) call
    ``report`` (publish /diagnostics now). Returns the refusal, '' when the call may go on."""
    if sources.update(service, node.count_clients(service)) or sources.fault():
        report()
    if not sources.fault():
        return ''
    refusal = f'refused: {sources.fault()}'   # no one can tell which client is the operator
    node.get_logger().error(f'{service} {refusal}')
    return refusal
