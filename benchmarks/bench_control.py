"""Control cores: time of one DriveController.step and one ModeManager.update (prints figures).

The node runs the controller at 100 Hz, so one step must take well under 10 ms.
"""
import statistics
import time

from dukw_common.config import node_params
from dukw_control import controller, modes
from figures import report


def timed(fn, n):
    out = []
    for k in range(n):
        t0 = time.perf_counter()
        fn(k)
        out.append(time.perf_counter() - t0)
    out.sort()
    return statistics.median(out) * 1e6, out[int(0.99 * n)] * 1e6


def main() -> None:
    ctrl = controller.DriveController(
        controller.settings_from_params(node_params('drive_controller_node')))
    ctrl.on_authority(True, 'computer', 0.0)
    ctrl.on_mode(modes.ModeDecision(modes.Mode.TRANSITION, True, 1.0, 1.0, False, 'bench'))

    def control_cycle(k):
        t = k * 0.01
        ctrl.on_cmd_vel(1.0, 0.1, t)
        ctrl.on_odometry(0.95, 0.09, t)
        ctrl.on_pitch(-0.05, t)
        ctrl.on_traction(0.1, 0.12, 1.0, t)
        ctrl.on_track_currents(30.0, 32.0, t)
        ctrl.step(t)

    manager = modes.ModeManager(modes.settings_from_params(node_params('mode_manager_node')))

    def mode_cycle(k):
        t = k * 0.05
        manager.on_water_contact(k % 40 < 5, False, t)
        manager.on_traction(0.9 if k % 40 < 5 else 1.0, False, t)
        manager.on_track_forces(150.0, 160.0, t)
        manager.update(t)

    for name, fn in (('controller cycle (inputs + step)', control_cycle),
                     ('mode manager cycle (inputs + update)', mode_cycle)):
        median_us, p99_us = timed(fn, 20000)
        print(f'{name}: median {median_us:.1f} us, p99 {p99_us:.1f} us')
        report(f'{name} median', median_us, 'us')


if __name__ == '__main__':
    main()
