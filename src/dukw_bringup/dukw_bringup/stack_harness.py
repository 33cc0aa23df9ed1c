"""The in-process stack: the control cores closed around the simulator core.

Used by the closed-loop tests (dukw_control/test/closed_loop.py re-exports it) and by
campaigns (dukw_bringup.campaign). Between the drive controller and the simulator sits
the servo switch's rule (dukw_driver.authority.CommandGate): the computer's commands
reach the motors only while it holds authority and they are fresh.

The controller sees what its node would see: surge speed and yaw rate (odometry),
pitch (IMU), track currents and slips; the mode manager sees water contact, a
valid depth, the weight on the tracks and the track force (current x gain).

``feedback='truth'``: all of it straight from dukw_sim's Truth (water contact wet
when the sensor point is under the surface, depth valid deeper than the sounder's
minimum), status at the drivers' 20 Hz.
``feedback='ekf'``: the simulator's seeded sensor models (dukw_sim.sensors) feed the
estimator core (dukw_estimation) as ekf_node does; odometry and traction come from
the filter, water contact, depth, pitch and motor status from the sensor readings.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from dukw_common.config import node_params
from dukw_common.geometry import euler_from_quaternion
from dukw_control import controller, modes
from dukw_control.controller import ControllerSettings, DriveController
from dukw_control.modes import ModeManager, ModeSettings
from dukw_driver.authority import CommandGate, SideCommand
from dukw_sim.core import Actuation, SimCore
from dukw_sim.truth import Truth

STATUS_EVERY = 5          # 100 Hz / 5 = the motor controllers' and mode manager's 20 Hz


def default_controller_settings() -> ControllerSettings:
    return controller.settings_from_params(node_params('drive_controller_node'))


def default_mode_settings() -> ModeSettings:
    return modes.settings_from_params(node_params('mode_manager_node'))


@dataclass
class Record:
    """What happened, one entry per 0.01 s step."""

    truth: list[Truth] = field(default_factory=list)
    tracks: list[tuple[float, float]] = field(default_factory=list)
    props: list[tuple[float, float]] = field(default_factory=list)
    modes: list[tuple[float, modes.Mode, str]] = field(default_factory=list)


class ClosedLoop:
    """SimCore + ModeManager + DriveController, stepped together at 100 Hz."""

    def __init__(self, sim_overrides=None, seed: int = 0, start: str = 'sand',
                 x_m: float | None = None, yaw_rad: float = 0.0,
                 controller_settings: ControllerSettings | None = None,
                 mode_settings: ModeSettings | None = None, feedback: str = 'truth',
                 estimator_knows_site: bool = True, sensor_filter=None) -> None:
        """``estimator_knows_site=False``: the estimator keeps the configured vehicle, beach
        and soil while ``sim_overrides`` change the simulated ones (model mismatch).
        ``sensor_filter(readings) -> readings``: faults injected between sensors and
        the stack (dropouts, outliers); ekf feedback only."""
        if feedback not in ('truth', 'ekf'):
            raise ValueError(f"feedback must be 'truth' or 'ekf', got {feedback!r}")
        self.sim = SimCore.from_config(overrides=sim_overrides or {}, seed=seed)
        self.truth = self.sim.reset(start, x_m, yaw_rad)
        self.feedback = feedback
        if feedback == 'ekf':
            from dukw_estimation.evaluate import SensorAdapter, build_estimator
            from dukw_sim.sensors import SensorModel
            self.sensors = SensorModel.from_config(seed=seed)
            gps = self.sensors.config.datum
            vehicle = self.sim.vehicle
            if not estimator_knows_site:
                from dukw_common.vehicle import Vehicle
                vehicle = Vehicle.from_params(node_params('ekf_node'))
            self.est = build_estimator(vehicle, (gps.latitude_deg, gps.longitude_deg,
                                                 gps.altitude_m))
            self.adapter = SensorAdapter(self.est)
        self.sensor_filter = sensor_filter
        self.estimate = None
        self.gate = CommandGate(node_params('sim_node')['command_timeout_s'])
        self.gate.update_rc(rc_selected=False, rc_link_ok=True)
        self.ctrl = DriveController(controller_settings or default_controller_settings())
        self.modes = ModeManager(mode_settings or default_mode_settings())
        self.gain = self.sim.vehicle.drivetrain.track_force_gain_n_per_a
        self.min_depth_m = self.sim.vehicle.sensors.depth_sounder_min_m
        self.authority = True
        self.ctrl.on_authority(True, 'computer', 0.0)
        self.k = 0
        self.record = Record()

    def set_authority(self, usable: bool) -> None:
        """The operator takes over (False) or gives the vehicle back (True)."""
        self.gate.update_rc(rc_selected=not usable, rc_link_ok=True)
        self.ctrl.on_authority(usable, 'computer' if usable else 'RC operator',
                               self.truth.t_s)

    def step(self, cmd: tuple[float, float] | None) -> Truth:
        """One 0.01 s cycle; ``cmd`` is a cmd_vel (v, w) arriving now, or None."""
        c, t = self.ctrl, self.truth.t_s
        if cmd is not None:
            c.on_cmd_vel(*cmd, t)
        if self.feedback == 'truth':
            self._feed_truth(t)
        else:
            self._feed_sensors(t)
        if self.k % STATUS_EVERY == 0:
            decision = self.modes.update(t)
            if self.modes.changed:
                self.modes.changed = False
                c.on_mode(decision)
                self.record.modes.append((t, decision.mode, decision.reason))
        out = c.step(t)
        self.k += 1
        self.truth = self.sim.step(self._switch(out, t))
        rec = self.record
        rec.truth.append(self.truth)
        rec.tracks.append((out.tracks.port, out.tracks.stbd))
        rec.props.append((out.props.port, out.props.stbd))
        return self.truth

    def _switch(self, out, t: float) -> Actuation:
        """The servo switch: computer commands pass only while it holds authority, fresh.
        (The operator's sticks are neutral here: RC authority gives neutral outputs.)"""
        self.gate.command('tracks', SideCommand(out.tracks.port, out.tracks.stbd), t)
        self.gate.command('props', SideCommand(out.props.port, out.props.stbd), t)
        sent = self.gate.outputs(t)
        tracks, props = sent['tracks'], sent['props']
        return Actuation(tracks.port_pct, tracks.stbd_pct, props.port_pct, props.stbd_pct)

    def _feed_truth(self, t: float) -> None:
        tr, c, m = self.truth, self.ctrl, self.modes
        c.on_odometry(tr.surge_mps, tr.yaw_rate_rps, t)
        c.on_pitch(tr.pitch_rad, t)
        c.on_attitude(t, t)
        m.on_attitude(t, t)
        c.on_slips(tr.port_slip, tr.stbd_slip, t)
        if self.k % STATUS_EVERY == 0:
            c.on_track_currents(tr.port_current_a, tr.stbd_current_a, t)
            m.on_water_contact(tr.fore_sensor_depth_m > 0.0, tr.aft_sensor_depth_m > 0.0, t)
            m.on_depth(tr.sounder_depth_m > self.min_depth_m, tr.sounder_depth_m, t)
            m.on_traction(tr.weight_on_tracks_fraction, t)
            m.on_track_forces(tr.port_current_a * self.gain, tr.stbd_current_a * self.gain, t)

    def _feed_sensors(self, t: float) -> None:
        c, m = self.ctrl, self.modes
        readings = self.sensors.sample(self.truth)
        if self.sensor_filter is not None:
            readings = self.sensor_filter(readings)
        for reading in readings:
            self.adapter.feed(reading)
            kind = type(reading).__name__
            if kind == 'ImuReading':
                c.on_pitch(euler_from_quaternion(*reading.orientation_xyzw)[1], t)
                c.on_attitude(t, t)
                m.on_attitude(t, t)
            elif kind == 'WaterContactReading':
                m.on_water_contact(reading.fore_wet, reading.aft_wet, t)
            elif kind == 'DepthReading':
                m.on_depth(reading.valid, reading.depth_m, t)
            elif kind == 'DrivetrainReading' and reading.drive == 'tracks' and reading.connected:
                c.on_track_currents(reading.port.current_a, reading.stbd.current_a, t)
                m.on_track_forces(reading.port.force_n, reading.stbd.force_n, t)
        if self.est.t_s is None:
            return
        self.est.advance(t)
        odo, trc = self.est.odometry(), self.est.traction()
        self.estimate = (t, odo, trc)        # what the stack saw at t (campaign metrics)
        c.on_odometry(odo.surge_mps, odo.yaw_rate_rps, t)
        c.on_slips(trc.port_slip, trc.stbd_slip, t)
        m.on_traction(trc.weight_on_tracks_fraction, t)

    def run(self, seconds: float, cmd: tuple[float, float] | None = (1.0, 0.0),
            until=None) -> Truth:
        """Step for ``seconds`` with a cmd_vel every cycle (None: none), or until ``until``."""
        for _ in range(int(round(seconds / self.sim.dt_s))):
            tr = self.step(cmd)
            if until is not None and until(tr):
                break
        return self.truth
