"""The in-process stack: simulator, sensors, servo switch and the nodes' runners, one loop.

Evaluation (evaluate), the closed-loop tests, campaigns, the golden-bag generator and the
gains benchmark all drive this one harness. Each node's behaviour comes from its runner
(dukw_estimation.runner, dukw_control.runners), exactly as the node runs it; the harness
only plays the executor: it delivers every publication to the runners that subscribe to
it and calls their timers on the simulator's fixed step, in this order within a step:

    T        physics step with what the servo switch passes; the step's sensor samples
             (EKF, mode manager, controller); authority (+0.1 ms, on a change or 1 s);
             cmd_vel (+0.2 ms) when one arrives
    T+0.5 ms what the EKF published on the IMU sample: odometry/filtered (the controller
             may step on it: tracks/cmd, props/cmd +0.5 us), traction (+1 us), /tf (+2 us)
    T+1 ms   EKF timer;  T+2 ms mode manager timer (drive_mode);  T+3 ms controller timer

Publications go over a ``Wire``: ``DirectWire`` hands the objects over as they are (fast:
campaigns, evaluation); the golden-bag generator's wire serialises each one to its ROS
message, writes it and hands over what the nodes would decode from it.

``feedback='truth'`` replaces the EKF by an oracle that publishes the simulator's truth
(odometry and traction) on each IMU sample: the control chain judged on perfect estimates.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

from dukw_common.config import node_params
from dukw_common.vehicle import Vehicle
from dukw_control import modes
from dukw_control.controller import ControlOutput, ControllerSettings, DriveController
from dukw_control.controller import settings_from_params as controller_settings
from dukw_control.modes import ModeDecision, ModeManager, ModeSettings
from dukw_control.runners import DriveControllerRunner, ModeManagerRunner, ModePublication
from dukw_estimation.runner import INPUTS as EKF_INPUTS
from dukw_estimation.runner import EkfRunner, Estimate
from dukw_estimation.samples import OdometryEstimate, TractionEstimate
from dukw_control.convert import authority_usable
from dukw_common.readings import reading_topic
from dukw_sim.core import Actuation, SimCore
from dukw_sim.params import apply_overrides
from dukw_sim.sensors import SensorConfig, SensorModel
from dukw_sim.switch import RcChannels, SimServoSwitch
from dukw_sim.truth import Truth

MS_NS = 1_000_000
SENSOR_TOPICS = frozenset(EKF_INPUTS)     # the device topics (the EKF subscribes all)
AUTHORITY_PERIOD_NS = 1_000 * MS_NS    # the servo switch re-sends authority every second

#: offsets within a step, ns (see the module docstring)
OFFSET_NS = {'authority': MS_NS // 10, 'cmd_vel': MS_NS // 5, 'estimate': MS_NS // 2,
             'ekf_tick': MS_NS, 'mode_tick': 2 * MS_NS, 'control_tick': 3 * MS_NS}


@dataclass(frozen=True)
class CmdVel:
    """A cmd_vel request: speed (m/s), yaw rate (rad/s), its stamp (s)."""

    speed_mps: float
    yaw_rate_rps: float
    stamp_s: float


class DirectWire:
    """Publications handed over as objects (no messages)."""

    def carry(self, topic: str, t_ns: int, item: Any) -> Any:
        return item


@dataclass
class Record:
    """What happened, one entry per step (and one per mode change)."""

    truth: list[Truth] = field(default_factory=list)
    tracks: list[tuple[float, float]] = field(default_factory=list)
    props: list[tuple[float, float]] = field(default_factory=list)
    modes: list[tuple[float, modes.Mode, str]] = field(default_factory=list)


class TruthOracle:
    """Stands in for the EKF runner: the simulator's truth as the estimate, on each IMU
    sample (``feedback='truth'``)."""

    def __init__(self) -> None:
        self.truth = Truth()

    def on_sample(self, topic: str, sample: Any, now_s: float) -> Estimate | None:
        return self.estimate() if topic == 'imu/data' else None

    def tick(self, now_s: float) -> Estimate | None:
        return None

    def estimate(self) -> Estimate:
        tr = self.truth
        odom = OdometryEstimate(tr.t_s, tr.x_m, tr.y_m, tr.z_m, tr.roll_rad, tr.pitch_rad,
                                tr.yaw_rad, tr.surge_mps, tr.sway_mps, tr.yaw_rate_rps)
        traction = TractionEstimate(
            tr.t_s, tr.port_slip, tr.stbd_slip, tr.submerged_volume_m3, tr.effective_weight_n,
            tr.weight_on_tracks_fraction, tr.waterline_distance_m, 0.0, tr.slope_rad,
            tr.port_force_n, tr.stbd_force_n, tr.port_force_n, tr.stbd_force_n,
            not tr.in_ground_contact, tr.wave_elevation_m)
        return Estimate(odom, traction)


def default_controller_settings() -> ControllerSettings:
    return controller_settings(node_params('drive_controller_node'))



class Stack:
    """Simulator + sensors + servo switch + EKF, mode manager and controller runners."""

    def __init__(self, sim: SimCore, sensors: SensorModel, ekf: EkfRunner | TruthOracle,
                 mode_manager: ModeManagerRunner, controller: DriveControllerRunner,
                 switch: SimServoSwitch, wire: DirectWire | None = None,
                 sensor_filter: Callable[[list], list] | None = None,
                 actuation: Actuation | None = None) -> None:
        """``sensor_filter(readings) -> readings``: faults between sensors and the stack.
        ``actuation``: drive the simulator with this fixed actuation (open loop)."""
        self.sim, self.sensors, self.switch = sim, sensors, switch
        self.ekf, self.mode_manager, self.controller = ekf, mode_manager, controller
        self.wire = wire or DirectWire()
        self.sensor_filter = sensor_filter
        self.actuation = actuation
        self.step_ns = round(sim.dt_s * 1e9)
        self.mode_every = max(1, round(1e9 / mode_manager.rate_hz) // self.step_ns)
        self.k = 0
        self.truth = sim.truth
        self.last_authority_ns: int | None = None
        self.last_output = ControlOutput()
        self.estimate: Estimate | None = None      # the latest published estimate
        self.record = Record()
        self.listeners: list[Callable[[str, int, Any], None]] = []

    def place(self, start: str = 'sand', x_m: float | None = None,
              yaw_rad: float = 0.0) -> Truth:
        """Put the vehicle at its start (before the first step; SimCore.reset's arguments)."""
        self.truth = self.sim.reset(start, x_m, yaw_rad)
        return self.truth

    # --- publication and delivery ------------------------------------------------------
    def publish(self, topic: str, t_ns: int, item: Any) -> None:
        """Put ``item`` on ``topic`` at ``t_ns``, deliver it to its subscribers, then tell
        the listeners (observers: evaluation, recording)."""
        item = self.wire.carry(topic, t_ns, item)
        deliver = self._ROUTES.get(topic)
        if deliver is not None:
            deliver(self, topic, t_ns, item)
        for listen in self.listeners:
            listen(topic, t_ns, item)

    def _sample(self, topic: str, t_ns: int, sample) -> None:
        t_s = t_ns * 1e-9
        self._pending = self.ekf.on_sample(topic, sample, t_s) or self._pending
        if topic == 'imu/data':
            self.mode_manager.on_imu(sample.t_s, t_s)
            self.controller.on_imu(sample.t_s, t_s)
        elif topic == 'water/contact':
            self.mode_manager.on_water_contact(sample.fore_wet, sample.aft_wet, t_s)
        elif topic == 'depth':
            self.mode_manager.on_depth(sample.valid, sample.depth_m, t_s)
        elif topic == 'tracks/status':
            self.mode_manager.on_track_status(sample.connected, sample.port.force_n,
                                              sample.stbd.force_n, t_s)
            self.controller.on_track_status(sample.connected, sample.port.current_a,
                                            sample.stbd.current_a, t_s)

    def _odometry(self, topic: str, t_ns: int, odom: OdometryEstimate) -> None:
        self._command(t_ns + 500, self.controller.on_odometry(
            odom.surge_mps, odom.yaw_rate_rps, odom.pitch_rad, t_ns * 1e-9))

    def _traction(self, topic: str, t_ns: int, traction: TractionEstimate) -> None:
        self.mode_manager.on_traction(traction.weight_on_tracks_fraction, traction.afloat,
                                      t_ns * 1e-9)
        self.controller.on_traction(traction.port_slip, traction.stbd_slip,
                                    traction.weight_on_tracks_fraction, t_ns * 1e-9)

    def _drive_mode(self, topic: str, t_ns: int, decision: ModeDecision) -> None:
        self.controller.on_mode(decision, t_ns * 1e-9)

    def _authority(self, topic: str, t_ns: int, state) -> None:
        """AuthorityState or dukw_msgs/Authority: the controller's rule reads either."""
        self._command(t_ns + 500, self.controller.on_authority(*authority_usable(state),
                                                               t_ns * 1e-9))

    def _cmd_vel(self, topic: str, t_ns: int, cmd: CmdVel) -> None:
        self.controller.on_cmd_vel(cmd.speed_mps, cmd.yaw_rate_rps, t_ns * 1e-9, cmd.stamp_s)

    _ROUTES = {**dict.fromkeys(SENSOR_TOPICS, _sample),
               'odometry/filtered': _odometry, 'traction': _traction,
               'drive_mode': _drive_mode, 'authority': _authority, 'cmd_vel': _cmd_vel}

    def _command(self, t_ns: int, out: ControlOutput | None) -> None:
        """The controller's output goes to tracks/cmd and props/cmd, and the servo switch."""
        if out is None:
            return
        self.last_output = out
        self.publish('tracks/cmd', t_ns, out.tracks)
        self.publish('props/cmd', t_ns, out.props)
        t_s = t_ns * 1e-9
        self.switch.command('tracks', out.tracks.port, out.tracks.stbd, t_s)
        self.switch.command('props', out.props.port, out.props.stbd, t_s)

    def _publish_estimate(self, t_ns: int, estimate: Estimate) -> None:
        self.estimate = estimate
        self.publish('odometry/filtered', t_ns, estimate.odometry)
        if estimate.traction_due:
            self.publish('traction', t_ns + 1_000, estimate.traction)
        if estimate.tf_due:
            self.publish('tf', t_ns + 2_000, estimate.odometry)

    # --- one step ------------------------------------------------------------------------
    def step(self, cmd_vel: tuple[float, float] | None = None) -> Truth:
        """One simulator step of the whole stack; ``cmd_vel`` (m/s, rad/s) arrives in it."""
        self.k += 1
        t_ns = self.k * self.step_ns
        self.truth = truth = self.sim.step(self._actuation())
        if isinstance(self.ekf, TruthOracle):
            self.ekf.truth = truth
        self._pending: Estimate | None = None
        self._sensors(t_ns, truth)
        self._authority_if_due(t_ns, truth)
        if cmd_vel is not None:
            t_cmd = t_ns + OFFSET_NS['cmd_vel']
            self.publish('cmd_vel', t_cmd, CmdVel(*cmd_vel, t_cmd * 1e-9))
        if self._pending is not None:         # what the EKF published on the IMU sample
            self._publish_estimate(t_ns + OFFSET_NS['estimate'], self._pending)
        self._timers(t_ns)
        self._record(truth)
        return truth

    def _actuation(self) -> Actuation:
        if self.actuation is not None:
            return self.actuation
        out = self.switch.outputs(self.sim.t_s)
        return Actuation(out.tracks.port_pct, out.tracks.stbd_pct, out.props.port_pct,
                         out.props.stbd_pct)

    def _sensors(self, t_ns: int, truth: Truth) -> None:
        readings = self.sensors.sample(truth)
        if self.sensor_filter is not None:
            readings = self.sensor_filter(readings)
        for reading in readings:
            self.publish(reading_topic(reading), t_ns, reading)

    def _authority_if_due(self, t_ns: int, truth: Truth) -> None:
        gate = self.switch.gate
        if not (gate.changed or self.last_authority_ns is None
                or t_ns - self.last_authority_ns >= AUTHORITY_PERIOD_NS):
            return
        gate.changed = False
        self.last_authority_ns = t_ns
        self.publish('authority', t_ns + OFFSET_NS['authority'], self.switch.state)

    def _timers(self, t_ns: int) -> None:
        t_ekf = t_ns + OFFSET_NS['ekf_tick']
        estimate = self.ekf.tick(t_ekf * 1e-9)
        if estimate is not None:
            self._publish_estimate(t_ekf, estimate)
        if self.k % self.mode_every == 0:
            t_mode = t_ns + OFFSET_NS['mode_tick']
            publication = self.mode_manager.tick(t_mode * 1e-9)
            if publication is not None:
                self._mode(t_mode, publication)
        t_ctrl = t_ns + OFFSET_NS['control_tick']
        self._command(t_ctrl, self.controller.tick(t_ctrl * 1e-9))

    def _mode(self, t_ns: int, publication: ModePublication) -> None:
        decision = publication.decision
        modes = self.record.modes
        if publication.changed and (not modes or modes[-1][1] != decision.mode):
            modes.append((t_ns * 1e-9, decision.mode, decision.reason))   # changes of mode
        self.publish('drive_mode', t_ns, decision)

    def _record(self, truth: Truth) -> None:
        rec, out = self.record, self.last_output
        rec.truth.append(truth)
        rec.tracks.append((out.tracks.port, out.tracks.stbd))
        rec.props.append((out.props.port, out.props.stbd))

    # --- the operator ----------------------------------------------------------------------
    def set_authority(self, usable: bool) -> None:
        """The operator takes over (False) or gives the vehicle back (True)."""
        self.switch.set_operator(rc_selected=not usable, rc_link_ok=True, port_pct=0.0,
                                 stbd_pct=0.0)

    def run(self, seconds: float, cmd: tuple[float, float] | None = (1.0, 0.0),
            until: Callable[[Truth], bool] | None = None) -> Truth:
        """Step for ``seconds`` with a cmd_vel every step (None: none), or until ``until``."""
        for _ in range(int(round(seconds / self.sim.dt_s))):
            truth = self.step(cmd)
            if until is not None and until(truth):
                break
        return self.truth


class ClosedLoop(Stack):
    """The stack as the nodes configure it, around a simulator built from config."""

    def __init__(self, sim_overrides=None, seed: int = 0, start: str = 'sand',
                 x_m: float | None = None, yaw_rad: float = 0.0,
                 controller_settings: ControllerSettings | None = None,
                 mode_settings: ModeSettings | None = None, feedback: str = 'truth',
                 estimator_knows_site: bool = True, sensor_filter=None,
                 config: str | None = None, actuation: Actuation | None = None,
                 wire: DirectWire | None = None) -> None:
        """``estimator_knows_site=False``: the estimator keeps the configured vehicle, beach
        and soil while ``sim_overrides`` change the simulated ones (model mismatch)."""
        if feedback not in ('truth', 'ekf'):
            raise ValueError(f"feedback must be 'truth' or 'ekf', got {feedback!r}")
        sim = SimCore.from_config(config, overrides=sim_overrides or {}, seed=seed)
        sim.reset(start, x_m, yaw_rad)
        # the overrides reach the sensor models and the servo switch too (noise.*, rates.*)
        sim_params = apply_overrides(node_params('sim_node', config), sim_overrides or {})
        switch = SimServoSwitch(float(sim_params['command_timeout_s']),
                                RcChannels.from_params(sim_params))
        ekf_params = node_params('ekf_node', config)
        ekf = (TruthOracle() if feedback == 'truth' else EkfRunner.from_params(
            ekf_params, vehicle=sim.vehicle if estimator_knows_site else Vehicle.from_params(
                ekf_params)))
        mode_manager = ModeManagerRunner.from_params(node_params('mode_manager_node', config),
                                                     mode_settings)
        controller = DriveControllerRunner.from_params(
            node_params('drive_controller_node', config), controller_settings)
        sensors = SensorModel(SensorConfig.from_params(sim_params), seed)
        super().__init__(sim, sensors, ekf, mode_manager,
                         controller, switch, wire, sensor_filter, actuation)
        self.feedback = feedback

    @property
    def ctrl(self) -> DriveController:
        return self.controller.core

    @property
    def modes(self) -> ModeManager:
        return self.mode_manager.core

    @property
    def est(self):
        """The estimator core (ekf feedback only)."""
        return self.ekf.estimator
