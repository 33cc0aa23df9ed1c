"""compose: several of the stack's nodes in ONE process spun by ONE executor.

    install/lib/dukw_bringup/compose ekf_node mode_manager_node drive_controller_node \\
        --ros-args --params-file config/dukw.yaml

The composed bring-up (what ROS 2 users do with a component container; `bringup
sim_composed`, config/stack_sim_composed.yaml). rclpy has no intra-process
communication, so this module hands the cores' outputs over itself:

- ekf_node's estimate goes straight to drive_controller_node (on_odometry: with
  ``step_on_odometry`` it steps and publishes the commands at once; the slips) and to
  mode_manager_node (the weight on the tracks);
- mode_manager_node's decision goes straight to drive_controller_node;
- each sensor topic (imu/data, tracks/status, ...) is subscribed ONCE in the process and
  every message handed to each node that takes it.

Every topic of the contract is still published for observers (odometry/filtered,
traction, /tf, drive_mode, tracks/cmd, props/cmd, /diagnostics). The composed controller
takes odometry, traction and the mode only from its own process: a stranger publishing
them on the graph cannot steer it; a second drive_mode publisher still puts it to
neutral (the one-source rule, as in the one-process-per-node shape). A node that raises
ends the whole process: then no estimate reaches the controller, and its odometry goes
stale as when a separate ekf_node dies; `bringup` stops the stack.

Nodes are built in the order of ``NODES`` whatever the command line's order, so that
drive_controller_node is last and its neutral goes out first on shutdown.
"""
from __future__ import annotations

import sys
from importlib import import_module
from typing import Any, Callable, Sequence

from rclpy.node import Node

from dukw_common.node_tools import SENSOR_QOS, run_nodes

#: node name -> (module, class), in build order (the controller last: neutral first)
NODES = {
    'robot_state_node': ('dukw_bringup.robot_state_node', 'RobotStateNode'),
    'ekf_node': ('dukw_estimation.ekf_node', 'EkfNode'),
    'mode_manager_node': ('dukw_control.mode_manager_node', 'ModeManagerNode'),
    'mission_node': ('dukw_bringup.mission_node', 'MissionNode'),
    'drive_controller_node': ('dukw_control.drive_controller_node', 'DriveControllerNode'),
}
#: the nodes with a ``handed_topics`` option and an ``inputs`` table
CHAIN = ('ekf_node', 'mode_manager_node', 'drive_controller_node')
#: inputs the process subscribes once (or gets from ekf_node) and hands to each node
HANDED = frozenset(('imu/data', 'gps/fix', 'gps/vel', 'water/contact', 'depth',
                    'tracks/status', 'props/status', 'odometry/filtered', 'traction'))
#: what ekf_node hands over directly when it is in the process
EKF_OUTPUTS = frozenset(('odometry/filtered', 'traction'))


def now_s(node: Node) -> float:
    """The node's clock (sim time under use_sim_time), seconds."""
    return node.get_clock().now().nanoseconds * 1e-9


def build(names: Sequence[str]) -> list[Node]:
    """Construct ``names`` (in NODES order) in the current context and wire them."""
    unknown = sorted(set(names) - set(NODES))
    if unknown or not names:
        raise ValueError(f'compose: unknown node(s) {unknown}; choose from {list(NODES)}')
    present = [n for n in NODES if n in names]
    handed = HANDED | ({'drive_mode'} if 'mode_manager_node' in present else set())
    nodes: dict[str, Node] = {}
    for name in present:
        module, cls = NODES[name]
        factory = getattr(import_module(module), cls)
        nodes[name] = factory(handed_topics=handed) if name in CHAIN else factory()
    wire(nodes)
    share_clock(list(nodes.values()))
    return list(nodes.values())


def share_clock(nodes: list[Node]) -> None:
    """One /clock subscription for the process: under use_sim_time every node's
    TimeSource would subscribe /clock (100 Hz each); the first node's drives all clocks.
    (rclpy keeps the TimeSource private: ``_time_source``, as rclpy's own Node sets it.)"""
    if not all(node.get_parameter('use_sim_time').value for node in nodes):
        return
    source = nodes[0]._time_source
    for node in nodes[1:]:
        node._time_source.detach_node()
        source.attach_clock(node.get_clock())


def wire(nodes: dict[str, Node]) -> None:
    """Direct hand-offs between the chain's nodes, and one subscription per input."""
    ekf = nodes.get('ekf_node')
    mode_manager = nodes.get('mode_manager_node')
    controller = nodes.get('drive_controller_node')
    if ekf is not None:
        ekf.estimate_listeners.append(estimate_handoff(ekf, mode_manager, controller))
    if mode_manager is not None and controller is not None:
        mode_manager.decision_listeners.append(
            lambda decision: controller.runner.on_mode(decision, now_s(controller)))
    chain = [nodes[n] for n in CHAIN if n in nodes]
    produced = EKF_OUTPUTS if ekf is not None else frozenset()
    for topic in sorted(HANDED - produced):
        takers = [node.inputs[topic] for node in chain if topic in node.inputs]
        if takers:
            chain[0].create_subscription(takers[0][0], topic, fan_out([t[1] for t in takers]),
                                         SENSOR_QOS)


def fan_out(callbacks: list[Callable[[Any], None]]) -> Callable[[Any], None]:
    """One subscription's callback that hands the message to each node's callback."""
    if len(callbacks) == 1:
        return callbacks[0]

    def deliver(msg: Any) -> None:
        for callback in callbacks:
            callback(msg)
    return deliver


def estimate_handoff(ekf: Node, mode_manager: Node | None, controller: Node | None):
    """ekf_node's estimate -> the controller (a step, commands out now) and the mode
    manager (weight on the tracks), as their nodes take odometry/filtered and traction."""
    def on_estimate(estimate) -> None:
        now = now_s(ekf)
        odom = estimate.odometry
        if controller is not None:          # the command out first, then the rest
            controller.publish(controller.runner.on_odometry(
                odom.surge_mps, odom.yaw_rate_rps, odom.pitch_rad, now))
        traction = estimate.traction        # (read from the estimator only now)
        if controller is not None:
            controller.runner.on_traction(traction.port_slip, traction.stbd_slip,
                                         traction.weight_on_tracks_fraction, now)
        if mode_manager is not None:
            mode_manager.runner.on_traction(traction.weight_on_tracks_fraction,
                                            traction.afloat, now)
    return on_estimate


def main(args: list[str] | None = None) -> int:
    """Console script: ``compose NODE... [--ros-args ...]``."""
    argv = list(sys.argv if args is None else args)
    own = argv[1:argv.index('--ros-args')] if '--ros-args' in argv else argv[1:]
    names = [a for a in own if not a.startswith('-')]
    if not names or any(a.startswith('-') for a in own) or set(names) - set(NODES):
        print(f'usage: compose NODE... [--ros-args ...]; NODE one of {", ".join(NODES)}',
              file=sys.stderr)
        return 2
    return run_nodes(lambda: build(names), argv)


if __name__ == '__main__':
    raise SystemExit(main())
