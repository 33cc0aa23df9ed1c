"""Golden bags for the replay regression tests, generated offline and deterministically.

    python -m dukw_bringup.golden --out tests/golden [--only land_circle]

Each scenario runs the simulator's physics core (``dukw_sim.core.SimCore``), its sensor
models and servo switch, the EKF (``Estimator``), the mode manager and the drive
controller in one closed loop on the simulator's fixed step, with a fixed seed and a
scripted ``cmd_vel``, and writes every topic those nodes exchange to an MCAP bag (zstd
chunks). No DDS and no wall clock are involved, so the same code and config give the
same bag byte for byte. The cores are driven through the very adapters the offline
replay uses (``replay_adapters``), fed with the messages as decoded from their CDR
bytes, on the nodes' timer grids with fixed offsets inside each step:

    T        sensor messages of the step (stamped T), authority, cmd_vel (+0.1/0.2 ms)
    0        robot_description and /tf_static (latched), as robot_state_node sends them
    T+0.5 ms the EKF's output on the IMU sample: odometry/filtered (the controller steps
             on it: tracks/cmd, props/cmd at +0.5 us), traction (+1 us), /tf (+2 us)
    T+1 ms   ekf timer tick (publishes only while the IMU is silent)
    T+2 ms   mode manager tick (every 5th step at 20 Hz): drive_mode on change or 1 s
    T+3 ms   controller timer tick (if it steps): tracks/cmd, props/cmd -> servo switch;
             the switch output drives the next physics step

so replaying a golden bag reproduces its recorded outputs exactly (up to float noise).
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

MS_NS = 1_000_000


@dataclass(frozen=True)
class Scenario:
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
    Scenario('land_circle', 'on flat dry sand: 0.5 m/s with 0.3 rad/s yaw rate (r ~ 1.7 m)',
             start_x_m=-8.0, start_yaw_rad=0.0, duration_s=7.0, seed=11, cmd_vel=_circle),
    Scenario('land_to_sea', 'from the sand 0.5 m above the waterline straight out to sea: '
             'LAND -> TRANSITION -> WATER', start_x_m=-0.5, start_yaw_rad=0.0,
             duration_s=9.0, seed=12, cmd_vel=_straight(1.2)),
    Scenario('sea_to_land', 'afloat 6.8 m out, bow to the beach, up onto the sand: '
             'WATER -> TRANSITION -> LAND', start_x_m=6.8, start_yaw_rad=math.pi,
             duration_s=10.0, seed=13, cmd_vel=_straight(1.2)),
)}


class _Loop:
    """The closed loop of one scenario, writing every exchanged message to ``writer``."""

    def __init__(self, scenario: Scenario, writer: BagWriter,
                 config_path: str | None) -> None:
        from dukw_common.config import node_params
        from dukw_sim.core import SimCore
        from dukw_sim.sensors import SensorModel
        from dukw_sim.switch import RcChannels, SimServoSwitch

        from dukw_bringup.replay_adapters import (DriveControllerAdapter, EkfAdapter,
                                                  ModeManagerAdapter)
        self.scenario = scenario
        self.writer = writer
        self.config_path = config_path
        self.store = typestore()
        sim_params = node_params('sim_node', config_path)
        self.cmd_vel_stamped = bool(sim_params['cmd_vel_stamped'])   # shared block
        self.sim = SimCore.from_config(config_path, seed=scenario.seed)
        self.sim.reset(x_m=scenario.start_x_m, yaw_rad=scenario.start_yaw_rad)
        self.sensors = SensorModel.from_config(config_path, seed=scenario.seed)
        self.switch = SimServoSwitch(float(sim_params['command_timeout_s']),
                                     RcChannels.from_params(sim_params))
        from dukw_sim.sim_messages import Frames
        self.frames = Frames(str(sim_params['frames.base']), str(sim_params['frames.imu']),
                             str(sim_params['frames.gps']))
        self.ekf = EkfAdapter(config_path)
        self.modes = ModeManagerAdapter(config_path)
        self.controller = DriveControllerAdapter(config_path)
        self.republish_ns = round(float(
            node_params('mode_manager_node', config_path)['republish_period_s']) * 1e9)
        self.last_mode_ns: int | None = None
        self.step_ns = round(self.sim.dt_s * 1e9)
        for name, rate in (('ekf', self.ekf.rate_hz), ('controller', self.controller.rate_hz)):
            if round(1e9 / rate) != self.step_ns:
                raise ValueError(f'golden: {name} rate {rate} Hz must equal the sim step')
        self.mode_every = round(1e9 / self.modes.rate_hz) // self.step_ns
        self.last_authority_ns: int | None = None
        self.ekf_pending: tuple | None = None
        self.timeline: list[tuple[float, str]] = []

    # --- messages ------------------------------------------------------------------
    def _emit(self, topic: str, t_ns: int, msg, consumers=()) -> None:
        """Serialize ``msg`` (rclpy), write it, feed its decoded form to ``consumers``."""
        from rclpy.serialization import serialize_message
        msgtype = type(msg).__module__.split('.')[0] + '/msg/' + type(msg).__name__
        # rclpy leaves CDR padding bytes uninitialised: re-encode with rosbags (zeroed) so
        # the bag is the same byte for byte on every run
        decoded = self.store.deserialize_cdr(serialize_message(msg), msgtype)
        raw = self.store.serialize_cdr(decoded, msgtype)
        self.writer.add_topic('/' + topic, msgtype)
        self.writer.write('/' + topic, t_ns, raw)
        for adapter in consumers:
            if topic in adapter.inputs:
                out = adapter.feed(topic, t_ns * 1e-9, decoded)
                if out is not None and adapter is self.controller:
                    self._command(t_ns + 500, out)  # 0.5 us after its cause
                elif out is not None and adapter is self.ekf:
                    # built now (what the EKF knows after this IMU sample), written after
                    # this step's other sensor messages
                    self.ekf_pending = self._estimate_messages()

    def _command(self, t_ns: int, out: dict[str, float]) -> None:
        from dukw_common.node_tools import s_to_stamp
        from dukw_control.convert import diff_command
        from dukw_control.mixer import SidePair
        stamp = s_to_stamp(t_ns * 1e-9)
        for actuator in ('tracks', 'props'):
            port, stbd = out[f'{actuator}.port_pct'], out[f'{actuator}.stbd_pct']
            self._emit(f'{actuator}/cmd', t_ns, diff_command(SidePair(port, stbd), stamp))
            self.switch.command(actuator, port, stbd, t_ns * 1e-9)

    def _estimate_messages(self) -> tuple:
        """odometry/filtered and traction as ekf_node would publish them now."""
        from dukw_common.node_tools import s_to_stamp
        from dukw_estimation.ros_convert import odometry_msg, traction_msg
        from dukw_msgs.msg import Traction
        est = self.ekf.core
        stamp = s_to_stamp(est.t_s)
        return (odometry_msg(est.odometry(), stamp, 'odom', 'base_link'),
                traction_msg(est.traction(), stamp, Traction))

    def _publish_estimates(self, t_ns: int, messages: tuple) -> None:
        """As ekf_node: odometry, then traction and /tf (1 and 2 us later, in that order)."""
        from dukw_common.tf_tools import odometry_tf
        everyone = (self.ekf, self.modes, self.controller)
        self._emit('odometry/filtered', t_ns, messages[0], everyone)
        self._emit('traction', t_ns + 1_000, messages[1], everyone)
        self._emit('tf', t_ns + 2_000, odometry_tf(messages[0]))

    # --- one step --------------------------------------------------------------------
    def step(self, k: int) -> None:
        from dukw_common.node_tools import s_to_stamp
        from dukw_control.convert import decision_to_msg
        from dukw_sim import sim_messages as sm
        from dukw_sim.core import Actuation
        from dukw_common.cmd_vel import make_cmd_vel

        t_prev_s = self.sim.t_s
        out = self.switch.outputs(t_prev_s)
        truth = self.sim.step(Actuation(out.tracks.port_pct, out.tracks.stbd_pct,
                                        out.props.port_pct, out.props.stbd_pct))
        t_ns = k * self.step_ns
        everyone = (self.ekf, self.modes, self.controller)
        for reading in self.sensors.sample(truth):
            topic, msg = sm.fresh_reading(reading, self.frames)
            self._emit(topic, t_ns, msg, everyone)
        state = self.switch.state
        if (self.switch.gate.changed or self.last_authority_ns is None
                or t_ns - self.last_authority_ns >= 1_000 * MS_NS):
            self.switch.gate.changed = False
            self.last_authority_ns = t_ns
            self._emit('authority', t_ns + MS_NS // 10, sm.fresh_authority(state, truth.t_s),
                       everyone)
        if k % 10 == 0:
            speed, yaw_rate = self.scenario.cmd_vel(t_ns * 1e-9)
            t_cmd_ns = t_ns + MS_NS // 5
            self._emit('cmd_vel', t_cmd_ns, make_cmd_vel(self.cmd_vel_stamped, speed, yaw_rate,
                                                         t_cmd_ns * 1e-9), everyone)
        if self.ekf_pending is not None:           # the EKF published on the IMU sample
            self._publish_estimates(t_ns + MS_NS // 2, self.ekf_pending)
            self.ekf_pending = None
        # ekf timer (publishes only while the IMU is silent)
        t_ekf = t_ns + MS_NS
        if self.ekf.tick(t_ekf * 1e-9) is not None:
            self._publish_estimates(t_ekf, self._estimate_messages())
        # mode manager (as mode_manager_node.on_timer)
        if k % self.mode_every == 0:
            t_mm = t_ns + 2 * MS_NS
            self.modes.tick(t_mm * 1e-9)
            core = self.modes.core
            if core.changed or t_mm - self.last_mode_ns >= self.republish_ns:
                decision = core.decision()
                if core.changed:
                    self.timeline.append((t_mm * 1e-9, decision.mode.name))
                core.changed = False
                self.last_mode_ns = t_mm
                self._emit('drive_mode', t_mm, decision_to_msg(decision, s_to_stamp(
                    t_mm * 1e-9)), everyone)
        # controller timer (it may also have stepped on odometry above)
        t_ctrl = t_ns + 3 * MS_NS
        out = self.controller.tick(t_ctrl * 1e-9)
        if out is not None:
            self._command(t_ctrl, out)

    def _describe(self) -> None:
        """robot_description and /tf_static at t = 0, as robot_state_node."""
        from dukw_common.config import node_params
        from dukw_common.description import FrameNames, VehicleModel
        from dukw_common.node_tools import s_to_stamp
        from dukw_common.tf_tools import tf_message
        from dukw_common.vehicle import Vehicle
        from std_msgs.msg import String
        params = node_params('robot_state_node', self.config_path)
        vehicle = Vehicle.from_params(params)
        model = VehicleModel.build(vehicle.body, vehicle.sensors, FrameNames.from_params(params),
                                   float(params['deck_thickness_m']))
        self._emit('robot_description', 0, String(data=model.urdf()))
        self._emit('tf_static', 0, tf_message(model.static_transforms(), s_to_stamp(0.0)))

    def run(self) -> None:
        self._describe()
        steps = round(self.scenario.duration_s * 1e9 / self.step_ns)
        for k in range(1, steps + 1):
            self.step(k)
        truth = self.sim.truth
        self.final = (truth.x_m, truth.y_m, truth.medium.name)


def generate(scenario: Scenario, out_dir: Path, config_path: str | None = None) -> Path:
    """Write the golden bag of ``scenario`` to ``out_dir/<name>`` (replaced); return it."""
    bag = Path(out_dir) / scenario.name
    if bag.exists():
        shutil.rmtree(bag)
    with BagWriter(bag, compress=True, flush_period_s=None) as writer:   # same bytes each run
        loop = _Loop(scenario, writer, config_path)
        loop.run()
    size_kb = sum(p.stat().st_size for p in bag.iterdir()) / 1024
    modes = ' -> '.join(f'{name} ({t:.2f} s)' for t, name in loop.timeline)
    print(f'{scenario.name}: {sum(writer.counts.values())} messages, {size_kb:.0f} kB; '
          f'ends at x={loop.final[0]:.2f} m y={loop.final[1]:.2f} m ({loop.final[2]}); '
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
