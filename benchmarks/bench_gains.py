"""The main job's mission offline, with the hand-tuned and the model-derived gains.

Runs config/mission.yaml (land -> sea -> land in the 28 cm sea) on the simulator core
with the mode manager and drive controller cores closed around it (truth feedback, as
dukw_bringup.stack_harness) and the mission's line-of-sight guidance at 20 Hz.
Prints per gain set and medium: RMS heading error, RMS speed error (request - surge),
the number of sign changes of the yaw-rate error and of the propeller differential,
how many times a second the propeller command swings by more than 20 %, and how
often a propeller current drops by 10 A within 0.3 s (and how many of those drops come
with a steady command: not the controller's doing; the simulator's thrust falls only as a
propeller nears or leaves the surface).

    python benchmarks/bench_gains.py [--models land.yaml water.yaml] [--calm]
"""
from __future__ import annotations

import argparse
import math

import numpy as np

from dukw_bringup.mission import LosGuidance, load_mission
from dukw_bringup.run_setup import sim_overrides
from dukw_bringup.stack_harness import ClosedLoop, default_controller_settings
from dukw_common.geometry import wrap_angle

GUIDANCE_EVERY = 5        # 100 Hz / 5 = mission_node's 20 Hz
SWING_PCT = 20.0          # a propeller command step larger than this counts as a swing
DROP_A = 10.0             # a propeller current falling by more than this ...
DROP_WINDOW_S = 0.3       # ... within this long counts as a drop


def _sign_changes(values: np.ndarray, deadband: float) -> int:
    signs = np.sign(np.where(np.abs(values) > deadband, values, 0.0))
    signs = signs[signs != 0]
    return int(np.count_nonzero(np.diff(signs)))


def _current_drops(sel: np.ndarray, secs: float) -> dict[str, float]:
    """Falls of a propeller current by > DROP_A within DROP_WINDOW_S, and how many of them
    came with a steady command (< 2 % change): those are not the controller's doing."""
    drops = steady = 0
    n = int(DROP_WINDOW_S / 0.01)
    for cmd_col, cur_col in ((6, 8), (7, 9)):
        k = 0
        while k + n < sel.shape[0]:
            if sel[k, cur_col] - sel[k + n, cur_col] > DROP_A:
                drops += 1
                steady += int(np.ptp(sel[k:k + n + 1, cmd_col]) < 2.0)
                k += n
            k += 1
    return {'prop_current_drops_per_s': drops / secs,
            'drops_with_steady_command_per_s': steady / secs}


def run_mission(settings, seconds: float, calm: bool = False) -> dict[str, dict[str, float]]:
    """Fly the mission once; figures per medium (land: tracks carry it; water: afloat)."""
    spec = load_mission()
    over = sim_overrides(spec, 1.0)
    loop = ClosedLoop(sim_overrides={'waves.model': 'none' if calm else over['waves']['model'],
                                     'waves.significant_height_m': spec.sea.significant_height_m,
                                     'waves.peak_period_s': spec.sea.peak_period_s},
                      seed=spec.sea.seed, x_m=spec.start.x_m, yaw_rad=spec.start.yaw_rad,
                      controller_settings=settings)
    guide = LosGuidance(spec)
    tr = loop.truth
    guide.start(tr.t_s, tr.x_m, tr.y_m)
    rows, cmd = [], (0.0, 0.0)
    for k in range(int(seconds / loop.sim.dt_s)):
        if k % GUIDANCE_EVERY == 0:
            c = guide.update(tr.t_s, tr.x_m, tr.y_m, tr.yaw_rad)
            cmd = (c.speed_mps, c.yaw_rate_rps)
            heading_err = guide.progress.heading_error_rad
        tr = loop.step(cmd)
        props = loop.record.props[-1]
        rows.append((tr.t_s, int(tr.medium), heading_err, cmd[0] - tr.surge_mps,
                     cmd[1] - tr.yaw_rate_rps, props[0] - props[1], props[0], props[1],
                     tr.port_prop_current_a, tr.stbd_prop_current_a))
        if guide.progress.state.finished:
            break
    data = np.array(rows)
    out = {'mission': {'state': guide.progress.state.value, 'time_s': float(data[-1, 0]),
                       'waypoints': guide.progress.waypoint_index}}
    for name, code in (('land', 0), ('water', 2)):
        sel = data[(data[:, 1] == code) & (np.abs(data[:, 3]) < 5)]
        if not sel.size:
            continue
        secs = sel.shape[0] * loop.sim.dt_s
        swings = np.abs(np.diff(sel[:, 6])) + np.abs(np.diff(sel[:, 7]))
        out[name] = {
            'seconds': secs,
            'rms_heading_error_deg': math.degrees(float(np.sqrt(np.mean(
                [wrap_angle(e) ** 2 for e in sel[:, 2]])))),
            'rms_speed_error_mps': float(np.sqrt(np.mean(sel[:, 3] ** 2))),
            'yaw_rate_error_sign_changes_per_s': _sign_changes(sel[:, 4], 0.01) / secs,
            'prop_differential_sign_changes_per_s': _sign_changes(sel[:, 5], 1.0) / secs,
            'prop_swings_per_s': int(np.count_nonzero(swings > SWING_PCT)) / secs,
            **_current_drops(sel, secs)}
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--models', nargs='*', default=[],
                        help='identified model files (sysid identify) for the model gains')
    parser.add_argument('--seconds', type=float, default=150.0)
    parser.add_argument('--lambda-factor', type=float, default=1.0)
    parser.add_argument('--calm', action='store_true', help='no waves (the mission has 28 cm)')
    args = parser.parse_args()
    sets = {'hand-tuned': default_controller_settings()}
    if args.models:
        from dukw_control.model_gains import settings_with_model_gains
        sets['model'] = settings_with_model_gains(default_controller_settings(), args.models,
                                                  args.lambda_factor)
    for label, settings in sets.items():
        result = run_mission(settings, args.seconds, args.calm)
        print(f'{label}: {result.pop("mission")}')
        for medium, figures in result.items():
            print(f'  {medium:<5} ' + '  '.join(f'{k} {v:.3g}' for k, v in figures.items()))


if __name__ == '__main__':
    main()
