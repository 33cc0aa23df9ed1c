"""Golden bags for the replay regression tests, generated offline and deterministically.

    python -m dukw_bringup.golden --out tests/golden [--only land_circle]

Each scenario runs the in-process stack (``dukw_bringup.stack_harness``: the simulator
core, its sensor models and servo switch, and the EKF, mode manager and drive controller
runners, each on its node's schedule) with a fixed seed and a scripted ``cmd_vel``, and
writes every topic those nodes exchange to an MCAP bag (zstd chunks), robot_description
and /tf_static at t = 0 as robot_state_node sends them. Every publication goes through
its ROS message: the runners receive what a node decodes from the CDR bytes, so
replaying a golden bag reproduces its recorded outputs exactly (up to float noise). No
DDS and no wall clock are involved: the same code and config give the same bag byte for
byte. The offsets within a step are the harness's (see stack_harness).
"""
from __future__ import annotations

import argparse
import math
import shutil
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Sequence

from dukw_bringup.bag_io import BagWriter, typestore
from dukw_bringup.stack_harness import OFFSET_NS, SENSOR_TOPICS, ClosedLoop, CmdVel

CMD_VEL_EVERY = 10        # the scripted cmd_vel comes at 10 Hz


@dataclass(frozen=True)
class GoldenScenario:
    """A golden run: where it starts, what cmd_vel asks, for how long, with which seed."""

    name: str
    description: str
    start_x_m: float
    start_yaw_rad: float
    duration_s: float
    seed: int
    cmd_vel: Callable[[float], tuple[float, float]]   # t_s -> (speed m/s, yaw rate rad/s)


def _circle(t_s: float) -> tuple[float, float]:
    return (0.5, 0.3) if t_s >= 0.2 else (0.0, 0.0)


def _straight(speed_mps: float) -> Callable[[float], tuple[float, float]]:
    def command(t_s: float) -> tuple[float, float]:
        return (speed_mps, 0.0) if t_s >= 0.2 else (0.0, 0.0)
    return command


#: Short runs: about 55 kB of MCAP (zstd) per second of the 100 Hz stack, so 7-10 s each.
SCENARIOS = {s.name: s for s in (
    GoldenScenario('land_circle', 'on flat dry sand: 0.5 m/s with 0.3 rad/s yaw rate (r ~ 1.7 m)',
             start_x_m=-8.0, start_yaw_rad=0.0, duration_s=7.0, seed=11, cmd_vel=_circle),
    GoldenScenario('land_to_sea', 'from the sand 0.5 m above the waterline straight out to sea: '
             'LAND -> TRANSITION -> WATER', start_x_m=-0.5, start_yaw_rad=0.0,
             duration_s=9.0, seed=12, cmd_vel=_straight(1.2)),
    GoldenScenario('sea_to_land', 'afloat 6.8 m out, bow to the beach, up onto the sand: '
             'WATER -> TRANSITION -> LAND', start_x_m=6.8, start_yaw_rad=math.pi,
             duration_s=10.0, seed=13, cmd_vel=_straight(1.2)),
)}


class BagWire:
    """Carries each publication as its node would: the ROS message is built, serialised,
    written to the bag, and what a subscriber decodes from it is handed over (through the
    nodes' own conversions), so replaying the bag reproduces what the runners saw."""

    def __init__(self, writer: BagWriter, config_path: str | None) -> None:
        from dukw_common.config import node_params
        from dukw_sim.sim_messages import Frames
        self.writer = writer
        self.store = typestore()
        params = node_params('sim_node', config_path)
        self.cmd_vel_stamped = bool(params['cmd_vel_stamped'])    # shared block
        self.frames = Frames(str(params['frames.base']), str(params['frames.imu']),
                             str(params['frames.gps']))
        self.last_odometry = None

    def carry(self, topic: str, t_ns: int, item):
        """Write ``item`` on ``topic`` at ``t_ns``; return it as the subscribers decode it."""
        from rclpy.serialization import serialize_message
        msg = self.message(topic, t_ns, item)
        msgtype = type(msg).__module__.split('.')[0] + '/msg/' + type(msg).__name__
        # rclpy leaves CDR padding bytes uninitialised: re-encode with rosbags (zeroed) so
        # the bag is the same byte for byte on every run
        decoded = self.store.deserialize_cdr(serialize_message(msg), msgtype)
        self.writer.add_topic('/' + topic, msgtype)
        self.writer.write('/' + topic, t_ns, self.store.serialize_cdr(decoded, msgtype))
        return self.received(topic, t_ns, decoded)

    def message(self, topic: str, t_ns: int, item):
        """The ROS message the publishing node sends for ``item``."""
        from dukw_common.cmd_vel import make_cmd_vel
        from dukw_common.node_tools import s_to_stamp
        from dukw_common.tf_tools import odometry_tf
        from dukw_control.convert import decision_to_msg, diff_command
        from dukw_estimation import ros_convert
        from dukw_msgs.msg import Traction
        from dukw_sim import sim_messages
        t_s = t_ns * 1e-9
        if topic in SENSOR_TOPICS:
            return sim_messages.fresh_reading(item, self.frames)[1]
        if topic == 'authority':      # stamped with the step's sim time, as sim_node does
            return sim_messages.fresh_authority(item, (t_ns - OFFSET_NS['authority']) * 1e-9)
        if topic == 'cmd_vel':
            return make_cmd_vel(self.cmd_vel_stamped, item.speed_mps, item.yaw_rate_rps,
                                item.stamp_s)
        if topic == 'odometry/filtered':
            self.last_odometry = ros_convert.odometry_msg(item, s_to_stamp(item.t_s), 'odom',
                                                          'base_link')
            return self.last_odometry
        if topic == 'tf':
            return odometry_tf(self.last_odometry)
        if topic == 'traction':
            return ros_convert.traction_msg(item, s_to_stamp(item.t_s), Traction)
        if topic == 'drive_mode':
            return decision_to_msg(item, s_to_stamp(t_s))
        if topic in ('tracks/cmd', 'props/cmd'):
            return diff_command(item, s_to_stamp(t_s))
        return item                               # already a message (robot_description...)

    @staticmethod
    def received(topic: str, t_ns: int, msg):
        """What a subscribing node makes of ``msg`` (the nodes' conversions)."""
        from dukw_common.cmd_vel import read_cmd_vel
        from dukw_common.node_tools import stamp_or
        from dukw_control.convert import decision_from_msg
        from dukw_estimation import ros_convert
        if topic in SENSOR_TOPICS:
            return ros_convert.SAMPLE_FROM_MSG[topic](msg, stamp_or(msg, t_ns * 1e-9))
        if topic == 'odometry/filtered':
            return ros_convert.odometry_estimate(msg)
        if topic == 'traction':
            return ros_convert.traction_estimate(msg)
        if topic == 'drive_mode':
            return decision_from_msg(msg)
        if topic == 'cmd_vel':
            return CmdVel(*read_cmd_vel(msg))
        return msg


def _describe(wire: BagWire, config_path: str | None) -> None:
    """robot_description and /tf_static at t = 0, as robot_state_node."""
    from dukw_common.config import node_params
    from dukw_common.description import FrameNames, VehicleModel
    from dukw_common.node_tools import s_to_stamp
    from dukw_common.tf_tools import tf_message
    from dukw_common.vehicle import Vehicle
    from std_msgs.msg import String
    params = node_params('robot_state_node', config_path)
    vehicle = Vehicle.from_params(params)
    model = VehicleModel.build(vehicle.body, vehicle.sensors, FrameNames.from_params(params),
                               float(params['deck_thickness_m']))
    wire.carry('robot_description', 0, String(data=model.urdf()))
    wire.carry('tf_static', 0, tf_message(model.static_transforms(), s_to_stamp(0.0)))


def run(scenario: GoldenScenario, writer: BagWriter, config_path: str | None = None) -> ClosedLoop:
    """The scenario on the in-process stack, every publication through the bag."""
    wire = BagWire(writer, config_path)
    _describe(wire, config_path)
    stack = ClosedLoop(seed=scenario.seed, x_m=scenario.start_x_m,
                       yaw_rad=scenario.start_yaw_rad, feedback='ekf',
                       estimator_knows_site=False, config=config_path, wire=wire)
    steps = round(scenario.duration_s / stack.sim.dt_s)
    for k in range(1, steps + 1):
        t_s = k * stack.step_ns * 1e-9
        stack.step(scenario.cmd_vel(t_s) if k % CMD_VEL_EVERY == 0 else None)
    return stack


def generate(scenario: GoldenScenario, out_dir: Path, config_path: str | None = None) -> Path:
    """Write the golden bag of ``scenario`` to ``out_dir/<name>`` (replaced); return it."""
    bag = Path(out_dir) / scenario.name
    if bag.exists():
        shutil.rmtree(bag)
    with BagWriter(bag, compress=True, flush_period_s=None) as writer:   # same bytes each run
        stack = run(scenario, writer, config_path)
    size_kb = sum(p.stat().st_size for p in bag.iterdir()) / 1024
    modes = ' -> '.join(f'{mode.name} ({t:.2f} s)' for t, mode, _ in stack.record.modes)
    truth = stack.sim.truth
    print(f'{scenario.name}: {sum(writer.counts.values())} messages, {size_kb:.0f} kB; '
          f'ends at x={truth.x_m:.2f} m y={truth.y_m:.2f} m ({truth.medium.name}); '
          f'modes: {modes}')
    return bag


def main(argv: Sequence[str] | None = None) -> int:
    """Regenerate the golden bags."""
    parser = argparse.ArgumentParser(prog='golden', description=__doc__.split('\n')[0])
    parser.add_argument('--out', type=Path, required=True, help='folder of the golden bags')
    parser.add_argument('--only', nargs='+', choices=sorted(SCENARIOS), default=None)
    parser.add_argument('--config', default=None, help='parameter file')
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    args.out.mkdir(parents=True, exist_ok=True)
    for name in args.only or SCENARIOS:
        generate(SCENARIOS[name], args.out, args.config)
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
