"""The control nodes' schedules, ROS-free: what each node does on each input and tick.

mode_manager_node and drive_controller_node, the offline replay (replay_adapters), the
golden-bag generator and the in-process stack harness (dukw_bringup.stack_harness) all
drive these runners, so a timing rule of a node lives here and nowhere else:

- ModeManagerRunner: inputs update the state machine as they arrive; on each timer tick
  (``rate_hz``) it decides, and ``drive_mode`` goes out on a change or every
  ``republish_period_s``.
- DriveControllerRunner: with ``step_on_odometry`` it steps on every estimate (the
  estimator's rate sets the control rate) and its timer steps only while the estimator has
  been silent for 1.5 periods; an authority loss steps at once (neutral now, not at the
  next tick).

Each handler takes the message's content (SI units), never a message: the nodes and the
replay convert messages with dukw_control.convert, the harness passes core outputs.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from dukw_common.config import ParamValue
from dukw_control.controller import ControlOutput, ControllerSettings, DriveController
from dukw_control.controller import settings_from_params as controller_settings
from dukw_control.modes import ModeDecision, ModeManager, ModeSettings
from dukw_control.modes import settings_from_params as mode_settings

#: the controller's timer steps when the estimator has been silent this many periods
SILENT_PERIODS = 1.5


@dataclass(frozen=True)
class ModePublication:
    """A drive_mode to publish: the decision and whether it is a change (log it)."""

    decision: ModeDecision
    changed: bool


class ModeManagerRunner:
    """mode_manager_node's schedule around dukw_control.modes.ModeManager."""

    def __init__(self, core: ModeManager, rate_hz: float, republish_period_s: float) -> None:
        if not (rate_hz > 0.0 and republish_period_s > 0.0):
            raise ValueError('mode manager: rate_hz and republish_period_s must be > 0')
        self.core = core
        self.rate_hz = float(rate_hz)
        self.republish_period_s = float(republish_period_s)
        self.last_publish_s: float | None = None

    @classmethod
    def from_params(cls, params: Mapping[str, ParamValue],
                    settings: ModeSettings | None = None) -> 'ModeManagerRunner':
        """As mode_manager_node configures it (raises ValueError on bad settings);
        ``settings`` replaces the parameters' decision settings (tests, tuning)."""
        return cls(ModeManager(settings or mode_settings(params)), float(params['rate_hz']),
                   float(params['republish_period_s']))

    # --- inputs (each as it arrives) ---------------------------------------------------
    def on_water_contact(self, fore_wet: bool, aft_wet: bool, now_s: float) -> None:
        self.core.on_water_contact(fore_wet, aft_wet, now_s)

    def on_depth(self, valid: bool, depth_m: float, now_s: float) -> None:
        self.core.on_depth(valid, depth_m, now_s)

    def on_traction(self, weight_on_tracks_fraction: float, afloat: bool, now_s: float) -> None:
        self.core.on_traction(weight_on_tracks_fraction, afloat, now_s)

    def on_track_status(self, connected: bool, port_force_n: float, stbd_force_n: float,
                        now_s: float) -> None:
        """A disconnected controller's zeros are not a force: the input goes stale instead."""
        if connected:
            self.core.on_track_forces(port_force_n, stbd_force_n, now_s)

    def on_imu(self, stamp_s: float, now_s: float) -> None:
        """The attitude's age guards the decision (a frozen IMU is a stale input)."""
        self.core.on_attitude(stamp_s, now_s)

    # --- timer ---------------------------------------------------------------------------
    def tick(self, now_s: float) -> ModePublication | None:
        """Decide; return what to publish (on a change or when the republish period is up)."""
        decision = self.core.update(now_s)
        changed = self.core.changed
        due = (self.last_publish_s is None
               or now_s - self.last_publish_s >= self.republish_period_s)
        if not (changed or due):
            return None
        self.core.changed = False
        self.last_publish_s = now_s
        return ModePublication(decision, changed)


class DriveControllerRunner:
    """drive_controller_node's schedule around dukw_control.controller.DriveController."""

    def __init__(self, core: DriveController, rate_hz: float, step_on_odometry: bool) -> None:
        if not rate_hz > 0.0:
            raise ValueError('drive controller: rate_hz must be > 0')
        self.core = core
        self.rate_hz = float(rate_hz)
        self.period_s = 1.0 / self.rate_hz
        self.step_on_odometry = bool(step_on_odometry)
        self.last_event_step_s = -float('inf')

    @classmethod
    def from_params(cls, params: Mapping[str, ParamValue],
                    settings: ControllerSettings | None = None) -> 'DriveControllerRunner':
        """As drive_controller_node configures it (raises ValueError on bad settings);
        ``settings`` replaces the parameters' control settings (tests, tuning)."""
        return cls(DriveController(settings or controller_settings(params)),
                   float(params['rate_hz']), bool(params.get('step_on_odometry', False)))

    # --- inputs (each as it arrives; some step at once) ---------------------------------
    def on_cmd_vel(self, speed_mps: float, yaw_rate_rps: float, now_s: float,
                   stamp_s: float | None = None) -> bool:
        """False when the request is refused (the core says why)."""
        return self.core.on_cmd_vel(speed_mps, yaw_rate_rps, now_s, stamp_s)

    def on_authority(self, usable: bool, detail: str, now_s: float) -> ControlOutput | None:
        """An authority loss steps at once: neutral now, not at the next tick."""
        self.core.on_authority(usable, detail, now_s)
        return None if usable else self.core.step(now_s)

    def on_mode(self, decision: ModeDecision, now_s: float) -> None:
        self.core.on_mode(decision, now_s)

    def on_odometry(self, surge_mps: float, yaw_rate_rps: float, pitch_rad: float,
                    now_s: float) -> ControlOutput | None:
        """The estimate (speed, yaw rate, pitch); with step_on_odometry a control step."""
        self.core.on_odometry(surge_mps, yaw_rate_rps, now_s)
        self.core.on_pitch(pitch_rad, now_s)
        if not self.step_on_odometry:
            return None
        self.last_event_step_s = now_s
        return self.core.step(now_s)

    def on_imu(self, stamp_s: float, now_s: float) -> None:
        self.core.on_attitude(stamp_s, now_s)

    def on_traction(self, port_slip: float, stbd_slip: float,
                    weight_on_tracks_fraction: float, now_s: float) -> None:
        self.core.on_traction(port_slip, stbd_slip, weight_on_tracks_fraction, now_s)

    def on_track_status(self, connected: bool, port_a: float, stbd_a: float,
                        now_s: float) -> None:
        """A silent (disconnected) controller's currents go stale, and the tracks stop."""
        if connected:
            self.core.on_track_currents(port_a, stbd_a, now_s)

    # --- timer ---------------------------------------------------------------------------
    def tick(self, now_s: float) -> ControlOutput | None:
        """A step, unless the estimator stepped the controller within 1.5 periods."""
        if now_s - self.last_event_step_s < SILENT_PERIODS * self.period_s:
            return None
        return self.core.step(now_s)
