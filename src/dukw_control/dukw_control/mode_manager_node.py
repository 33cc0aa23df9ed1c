"""mode_manager_node: decides LAND / TRANSITION / WATER / SAFE_STOP and publishes drive_mode.

A thin shell around dukw_control.runners.ModeManagerRunner (the schedule: drive_mode,
transient local, on every change with its reason and every ``republish_period_s``) and
dukw_control.modes.ModeManager (the decision); the service ``set_mode`` forces a mode
or returns to automatic.
"""
from typing import Callable, Collection

from diagnostic_msgs.msg import DiagnosticArray
from dukw_msgs.msg import Depth, DrivetrainStatus, DriveMode, Traction, WaterContact
from dukw_msgs.srv import SetMode
from rclpy.node import Node
from sensor_msgs.msg import Imu

from dukw_common.config import ConfigError
from dukw_common.diagnostics import Health, Level
from dukw_common.sources import SourceWatch
from dukw_common.node_tools import (COMMAND_QOS, STATE_QOS, LatestSamples, ParamSpec,
                                    declare_parameters, diagnostic_array,
                                    refuse_second_client, run_node, stamp_or,
                                    subscribe_sensors)
from dukw_control.convert import decision_to_msg
from dukw_control.modes import NODE_PARAMS, Mode, ModeDecision
from dukw_control.runners import ModeManagerRunner

#: inputs taken at the decision's rate (only their newest sample counts)
POLLED_INPUTS = ('imu/data',)


class ModeManagerNode(Node):
    """Feeds the state machine and publishes its decisions."""

    def __init__(self, handed_topics: Collection[str] = (), **node_kwargs) -> None:
        """``handed_topics``: inputs a composed process hands over (dukw_bringup.compose)."""
        super().__init__('mode_manager_node', **node_kwargs)
        specs = [ParamSpec(n, d, min=lo, max=hi) for n, d, lo, hi in NODE_PARAMS]
        params = declare_parameters(self, specs)
        try:
            self.runner = ModeManagerRunner.from_params(params)
        except ValueError as exc:
            raise ConfigError(f'mode_manager_node: {exc}') from exc
        self.core = self.runner.core
        self.sources = SourceWatch()          # set_mode: one client, the operator's
        self.mode_pub = self.create_publisher(DriveMode, 'drive_mode', STATE_QOS)
        self.diag_pub = self.create_publisher(DiagnosticArray, '/diagnostics', COMMAND_QOS)
        self.inputs = {'water/contact': (WaterContact, self.on_contact),
                       'depth': (Depth, self.on_depth), 'traction': (Traction, self.on_traction),
                       'tracks/status': (DrivetrainStatus, self.on_tracks),
                       'imu/data': (Imu, self.on_imu)}
        # The IMU only says how old the attitude is, read at each 20 Hz decision: polled, not
        # delivered at 100 Hz (README "Topic contract"); composed, it is handed over.
        polled = {t: self.inputs[t] for t in POLLED_INPUTS if t not in handed_topics}
        subscribe_sensors(self, self.inputs, set(handed_topics) | set(polled))
        self.polled = LatestSamples(self, polled)
        #: called with each published decision (a composed process's direct hand-off)
        self.decision_listeners: list[Callable[[ModeDecision], None]] = []
        self.create_service(SetMode, 'set_mode', self.on_set_mode)
        self.create_timer(1.0 / self.runner.rate_hz, self.on_timer)
        self.create_timer(1.0, self.publish_diagnostics)

    def now_s(self) -> float:
        """Node clock (sim time under use_sim_time), seconds."""
        return self.get_clock().now().nanoseconds * 1e-9

    def on_contact(self, msg: WaterContact) -> None:
        self.runner.on_water_contact(msg.fore_wet, msg.aft_wet, self.now_s())

    def on_depth(self, msg: Depth) -> None:
        self.runner.on_depth(msg.valid, msg.depth_m, self.now_s())

    def on_traction(self, msg: Traction) -> None:
        self.runner.on_traction(msg.weight_on_tracks_fraction, msg.afloat, self.now_s())

    def on_tracks(self, msg: DrivetrainStatus) -> None:
        self.runner.on_track_status(msg.connected, msg.port.force_n, msg.stbd.force_n,
                                    self.now_s())

    def on_imu(self, msg: Imu) -> None:
        now = self.now_s()
        self.runner.on_imu(stamp_or(msg, now), now)

    def on_set_mode(self, request: SetMode.Request, response: SetMode.Response):
        refusal = refuse_second_client(self, self.sources, 'set_mode', self.publish_diagnostics)
        if refusal:
            response.success, response.message = False, refusal
            return response
        if request.automatic:
            self.core.release(self.now_s())
        else:
            try:
                refusal = self.core.force(Mode(request.mode), self.now_s())
            except ValueError:
                refusal = f'unknown mode {request.mode}'
            if refusal:
                self.get_logger().warn(f'set_mode: {refusal}')
                response.success, response.message = False, refusal
                return response
        self.on_timer()
        decision = self.core.decision()
        response.success = True
        response.message = f'{decision.mode.name}: {decision.reason}'
        return response

    def on_timer(self) -> None:
        self.polled.poll()
        publication = self.runner.tick(self.now_s())
        if publication is None:
            return
        decision = publication.decision
        if publication.changed:
            self.get_logger().info(f'drive mode {decision.mode.name}: {decision.reason}')
        self.mode_pub.publish(decision_to_msg(decision, self.get_clock().now().to_msg()))
        for listen in self.decision_listeners:
            listen(decision)

    def publish_diagnostics(self) -> None:
        self.polled.poll()
        now = self.now_s()
        decision = self.core.decision()
        health = Health('mode', message=f'{decision.mode.name}: {decision.reason}', values={
            'automatic': decision.automatic,
            'weight_on_tracks_fraction': f'{self.core.weight_fraction:.2f}',
            'track_force_n': f'{self.core.track_force_n:.0f}',
            'fore_wet': self.core.fore_wet, 'aft_wet': self.core.aft_wet,
            'depth_valid': self.core.depth_valid, 'rejected_inputs': self.core.rejected,
            **{f'{k}_age_s': f'{v:.2f}' for k, v in self.core.input_ages(now).items()}})
        if decision.mode == Mode.SAFE_STOP:
            health.level = Level.ERROR
        if self.sources.fault():
            health.worsen(Level.ERROR, self.sources.fault())
        elif not decision.automatic:
            health.level = Level.WARN
            stale = self.core.stale_inputs(now)
            if stale:
                health.message += f' (forced; {stale})'
        self.diag_pub.publish(diagnostic_array(self, [health]))

    def destroy_node(self) -> None:
        self.polled.destroy()
        super().destroy_node()


def main(args=None) -> int:
    """Console-script entry point."""
    return run_node(ModeManagerNode, args)


if __name__ == '__main__':
    raise SystemExit(main())
