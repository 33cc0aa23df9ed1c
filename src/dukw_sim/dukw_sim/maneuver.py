"""maneuver: the paper's field tests on the simulator core, offline.

    maneuver circle --medium land|water --port P --stbd S [--duration s]
    maneuver zigzag --medium land|water --high H --low L [--period 10] [--duration 30]
    maneuver incline --slope-deg A --command C [--duration s]
    maneuver transition --direction land-to-sea|sea-to-land --command C
                        [--wave-height m] [--wave-period s] [--slope-deg A] [--duration 30]
    maneuver drift --wave-height m [--duration s]

Every sub-command takes ``--csv PATH`` (one row per step, SI units, REP 103 axes),
``--seed N`` and ``--config PATH``, applies the raw commands given (no bias added) and
prints a one-line JSON summary on stdout.
"""
from __future__ import annotations

import argparse
import csv
import json
import math
import sys
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

from dukw_common.config import ConfigError
from dukw_sim.core import Actuation, SimCore
from dukw_sim.forces import mooring, mooring_anchor
from dukw_sim.truth import Medium, Truth

#: CSV columns: name and how it comes from a Truth (issue 3's list first).
CSV_COLUMNS: list[tuple[str, Callable[[Truth], float]]] = [
    ('t', lambda t: t.t_s), ('x', lambda t: t.x_m), ('y', lambda t: t.y_m),
    ('yaw', lambda t: t.yaw_rad), ('u', lambda t: t.surge_mps), ('v', lambda t: t.sway_mps),
    ('r', lambda t: t.yaw_rate_rps), ('z', lambda t: t.z_m), ('roll', lambda t: t.roll_rad),
    ('pitch', lambda t: t.pitch_rad), ('heave_vel', lambda t: t.heave_mps),
    ('port_cmd', lambda t: t.port_cmd_pct), ('stbd_cmd', lambda t: t.stbd_cmd_pct),
    ('port_current_a', lambda t: t.port_current_a),
    ('stbd_current_a', lambda t: t.stbd_current_a),
    ('port_force_n', lambda t: t.port_force_n), ('stbd_force_n', lambda t: t.stbd_force_n),
    ('port_slip', lambda t: t.port_slip), ('stbd_slip', lambda t: t.stbd_slip),
    ('submerged_volume_m3', lambda t: t.submerged_volume_m3),
    ('effective_weight_n', lambda t: t.effective_weight_n),
    ('port_prop_cmd', lambda t: t.port_prop_cmd_pct),
    ('stbd_prop_cmd', lambda t: t.stbd_prop_cmd_pct),
    ('port_thrust_n', lambda t: t.port_thrust_n), ('stbd_thrust_n', lambda t: t.stbd_thrust_n),
    ('port_track_speed_mps', lambda t: t.port_track_speed_mps),
    ('stbd_track_speed_mps', lambda t: t.stbd_track_speed_mps),
    ('wave_elevation_m', lambda t: t.wave_elevation_m),
    ('water_depth_m', lambda t: t.water_depth_m),
    ('wave_surge_force_n', lambda t: t.wave_surge_force_n),
    ('in_ground_contact', lambda t: int(t.in_ground_contact)),
    ('medium', lambda t: int(t.medium)),
]

_INCLINE_LENGTH_M = 60.0     # incline runs: a slope this long (horizontal) above the water
_INCLINE_START_X_M = -10.0   # and start on it this far landward of the waterline


@dataclass
class ManeuverRun:
    """A manoeuvre's record: every step's Truth and the JSON summary."""

    name: str
    rows: list = field(default_factory=list)
    summary: dict = field(default_factory=dict)

    def array(self, getter: Callable[[Truth], float], start_s: float = 0.0) -> np.ndarray:
        """One quantity over the run from ``start_s`` on."""
        return np.array([getter(t) for t in self.rows if t.t_s >= start_s])

    def write_csv(self, path: str) -> None:
        """Write one row per step with CSV_COLUMNS."""
        with open(path, 'w', newline='') as handle:
            out = csv.writer(handle)
            out.writerow([name for name, _ in CSV_COLUMNS])
            for t in self.rows:
                out.writerow([f'{get(t):.6g}' for _, get in CSV_COLUMNS])


def fit_circle(x: np.ndarray, y: np.ndarray) -> tuple[float, float, float]:
    """Least-squares circle through points (Kasa): centre x, centre y, radius, m."""
    if x.size < 3:
        raise ValueError('a circle fit needs at least 3 points')
    a = np.column_stack([x, y, np.ones_like(x)])
    b = x * x + y * y
    (p, q, r), *_ = np.linalg.lstsq(a, b, rcond=None)
    cx, cy = p / 2.0, q / 2.0
    return float(cx), float(cy), float(math.sqrt(max(r + cx * cx + cy * cy, 0.0)))


def _drive(sim: SimCore, run: ManeuverRun, duration_s: float,
           command: Callable[[float], Actuation],
           hook: Callable[[SimCore], None] | None = None) -> None:
    run.rows.append(sim.truth)
    for _ in range(int(round(duration_s / sim.dt_s))):
        if hook is not None:
            hook(sim)
        run.rows.append(sim.step(command(sim.t_s)))


def _tracks(port: float, stbd: float) -> Actuation:
    return Actuation(port_track_pct=port, stbd_track_pct=stbd)


def _props(port: float, stbd: float) -> Actuation:
    return Actuation(port_prop_pct=port, stbd_prop_pct=stbd)


def _mean(values: np.ndarray) -> float:
    return float(np.mean(values)) if values.size else float('nan')


def _rms(values: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(values - np.mean(values))))) if values.size else 0.0


def circle(medium: str, port: float, stbd: float, duration_s: float = 30.0, seed: int = 0,
           config: str | None = None) -> ManeuverRun:
    """Constant commands on flat sand (tracks) or afloat (propellers); fit the circle."""
    sim = SimCore.from_config(config, seed=seed)
    if medium == 'land':
        sim.reset('flat')
        act = _tracks(port, stbd)
    else:
        sim.reset('afloat')
        act = _props(port, stbd)
    run = ManeuverRun('circle')
    _drive(sim, run, duration_s, lambda t: act)
    settle = min(10.0, duration_s / 3.0)
    x, y = run.array(lambda t: t.x_m, settle), run.array(lambda t: t.y_m, settle)
    r = run.array(lambda t: t.yaw_rate_rps, settle)
    u = run.array(lambda t: t.surge_mps, settle)
    radius = fit_circle(x, y)[2] if x.size >= 3 else float('nan')
    run.summary = {
        'maneuver': 'circle', 'medium': medium, 'port_pct': port, 'stbd_pct': stbd,
        'radius_m': radius, 'speed_mps': _mean(np.hypot(u, run.array(lambda t: t.sway_mps,
                                                                      settle))),
        'yaw_rate_dps': math.degrees(_mean(r)),
        'turn': 'port' if _mean(r) > 0 else 'starboard',
        'mean_port_current_a': _mean(run.array(lambda t: t.port_current_a, settle)),
        'mean_stbd_current_a': _mean(run.array(lambda t: t.stbd_current_a, settle)),
    }
    return run


def zigzag(medium: str, high: float, low: float, period_s: float = 10.0,
           duration_s: float = 30.0, seed: int = 0, config: str | None = None,
           lead_in_s: float = 0.0) -> ManeuverRun:
    """Alternate (high, low) and (low, high) every ``period_s`` (the paper's zigzag tests).

    ``lead_in_s`` of zero commands at rest come first (as a field recording started
    before the manoeuvre has): the start from rest is what shows the common-mode gain.
    """
    if lead_in_s < 0.0:
        raise ValueError(f'lead_in_s must be >= 0, got {lead_in_s}')
    sim = SimCore.from_config(config, seed=seed)
    land = medium == 'land'
    if land:
        sim.reset('flat')
    else:
        sim.reset('afloat')
    make = _tracks if land else _props

    def command(t: float) -> Actuation:
        if t < lead_in_s:
            return make(0.0, 0.0)
        first = int((t - lead_in_s) // period_s) % 2 == 0
        return make(high, low) if first else make(low, high)

    run = ManeuverRun('zigzag')
    _drive(sim, run, lead_in_s + duration_s, command)
    r = run.array(lambda t: t.yaw_rate_rps)
    run.summary = {
        'maneuver': 'zigzag', 'medium': medium, 'high_pct': high, 'low_pct': low,
        'period_s': period_s, 'speed_mps': _mean(run.array(lambda t: t.surge_mps)),
        'max_yaw_rate_dps': math.degrees(float(np.max(r))),
        'min_yaw_rate_dps': math.degrees(float(np.min(r))),
        'max_sway_mps': float(np.max(np.abs(run.array(lambda t: t.sway_mps)))),
        'heading_change_deg': math.degrees(run.rows[-1].yaw_rad - run.rows[0].yaw_rad),
    }
    return run


def incline(slope_deg: float, command: float, duration_s: float = 14.0, seed: int = 0,
            config: str | None = None, stbd: float | None = None) -> ManeuverRun:
    """Climb a dry-sand slope of ``slope_deg`` with both tracks at ``command`` %.

    ``stbd`` sets the starboard track apart (e.g. 96 with 100: the 4 % port bias).
    """
    if not 0.0 < slope_deg < 34.0:
        raise ValueError('slope must be in (0, 34) deg')
    sim = SimCore.from_config(config, seed=seed, overrides={
        'site.beach_slope_rad': math.radians(slope_deg),
        'world.flat_start_x_m': -_INCLINE_LENGTH_M})
    sim.reset(x_m=_INCLINE_START_X_M, yaw_rad=math.pi)
    run = ManeuverRun('incline')
    stbd = command if stbd is None else stbd
    _drive(sim, run, duration_s, lambda t: _tracks(command, stbd))
    half = duration_s / 2.0
    climbed = (run.rows[-1].ground_height_m - run.rows[0].ground_height_m) / math.sin(
        math.radians(slope_deg))
    speed = _mean(run.array(lambda t: t.surge_mps, half))
    commanded = abs(command) / 100.0 * sim.vehicle.drivetrain.full_scale_track_speed_mps
    run.summary = {
        'maneuver': 'incline', 'slope_deg': slope_deg, 'command_pct': command,
        'stbd_pct': stbd, 'heading_change_deg': math.degrees(run.rows[-1].yaw_rad
                                                             - run.rows[0].yaw_rad) % 360.0,
        'climbed_m': climbed, 'speed_mps': speed,
        'stalled': bool(speed < 0.1 * commanded),
        'mean_port_current_a': _mean(run.array(lambda t: t.port_current_a, half)),
        'mean_stbd_current_a': _mean(run.array(lambda t: t.stbd_current_a, half)),
        'max_current_a': float(np.max(run.array(lambda t: max(t.port_current_a,
                                                               t.stbd_current_a)))),
        'mean_port_slip': _mean(run.array(lambda t: t.port_slip, half)),
    }
    return run


def _wave_overrides(height_m: float, period_s: float | None) -> dict:
    if height_m <= 0.0:
        return {'waves.model': 'none'}
    out = {'waves.model': 'irregular', 'waves.significant_height_m': height_m}
    if period_s is not None:
        out['waves.peak_period_s'] = period_s
    return out


def transition(direction: str, command: float, wave_height_m: float = 0.0,
               wave_period_s: float | None = None, slope_deg: float | None = None,
               duration_s: float = 30.0, seed: int = 0, config: str | None = None) -> ManeuverRun:
    """Tracks only, propellers off: sand to afloat or afloat to sand (paper section 6)."""
    overrides = _wave_overrides(wave_height_m, wave_period_s)
    if slope_deg is not None:
        overrides['site.beach_slope_rad'] = math.radians(slope_deg)
    sim = SimCore.from_config(config, seed=seed, overrides=overrides)
    if direction == 'land-to-sea':
        sim.reset('sand')
    else:
        sim.reset('sea', yaw_rad=math.pi)
    run = ManeuverRun('transition')
    _drive(sim, run, duration_s, lambda t: _tracks(command, command))
    media = [t.medium for t in run.rows]
    contact = run.array(lambda t: float(t.in_ground_contact))

    def first(medium: Medium) -> float | None:
        return next((t.t_s for t in run.rows if t.medium == medium), None)

    force = run.array(lambda t: t.port_force_n + t.stbd_force_n)
    run.summary = {
        'maneuver': 'transition', 'direction': direction, 'command_pct': command,
        'wave_height_m': wave_height_m, 'start_x_m': run.rows[0].x_m,
        'end_x_m': run.rows[-1].x_m, 'end_medium': media[-1].name,
        't_first_water_s': first(Medium.WATER), 't_first_land_s': first(Medium.LAND),
        'contact_changes': int(np.count_nonzero(np.diff(contact))),
        'max_total_force_n': float(np.max(force)), 'mean_total_force_n': _mean(force),
        'min_effective_weight_n': float(np.min(run.array(lambda t: t.effective_weight_n))),
        'max_submerged_volume_m3': float(np.max(run.array(lambda t: t.submerged_volume_m3))),
    }
    return run


def drift(wave_height_m: float, duration_s: float = 60.0, wave_period_s: float | None = None,
          seed: int = 0, config: str | None = None) -> ManeuverRun:
    """Afloat in the surf, bow to the beach in following seas, loosely held in place by a
    tether. Where the paper drifted (vehicle.md 5, issue 13: in the surf of day 1): just
    afloat over the slope, the 'sea' start (the treads start.sea_tread_clearance_m over the
    sand, ~0.8 m of water), not the 'afloat' start off the slope in 1.5 m of water, where the
    waves' particle velocities and their change along the hulls are smaller. The restraint:
    ``mooring.*`` (a spring and damper to the attachment point's start, or a tension-only
    line to a holder's hand)."""
    sim = SimCore.from_config(config, seed=seed,
                              overrides=_wave_overrides(wave_height_m, wave_period_s))
    sim.reset('sea', yaw_rad=math.pi)
    x0 = sim.x
    moor = sim.params.mooring
    anchor = mooring_anchor(moor, sim.x, sim.y, sim.yaw)

    def hold(s: SimCore) -> None:
        s.set_external_force(*mooring(moor, s.x, s.y, s.yaw, s.u, s.v, s.r, anchor))

    run = ManeuverRun('drift')
    _drive(sim, run, duration_s, lambda t: Actuation(), hook=hold)
    settle = min(5.0, duration_s / 4.0)
    run.summary = {
        'maneuver': 'drift', 'wave_height_m': wave_height_m,
        'rms_heave_m': _rms(run.array(lambda t: t.z_m, settle)),
        'rms_roll_deg': math.degrees(_rms(run.array(lambda t: t.roll_rad, settle))),
        'rms_pitch_deg': math.degrees(_rms(run.array(lambda t: t.pitch_rad, settle))),
        'rms_yaw_deg': math.degrees(_rms(np.unwrap(run.array(lambda t: t.yaw_rad, settle)))),
        'rms_yaw_rate_dps': math.degrees(_rms(run.array(lambda t: t.yaw_rate_rps, settle))),
        'rms_surge_mps': _rms(run.array(lambda t: t.surge_mps, settle)),
        'mean_shoreward_offset_m': -_mean(run.array(lambda t: t.x_m, settle) - x0),
        'rms_wave_force_n': _rms(run.array(lambda t: t.wave_surge_force_n, settle)),
    }
    return run


# ------------------------------------------------------------------------ command line
def _pct(text: str) -> float:
    value = float(text)
    if not math.isfinite(value) or abs(value) > 100.0:
        raise argparse.ArgumentTypeError(f'a command must be within -100..100 %, got {text}')
    return value


def _positive(text: str) -> float:
    value = float(text)
    if not math.isfinite(value) or value <= 0.0:
        raise argparse.ArgumentTypeError(f'must be a positive number, got {text}')
    return value


def _non_negative(text: str) -> float:
    value = float(text)
    if not math.isfinite(value) or value < 0.0:
        raise argparse.ArgumentTypeError(f'must be >= 0, got {text}')
    return value


def _slope(text: str) -> float:
    value = float(text)
    if not math.isfinite(value) or not 0.0 < value < 34.0:
        raise argparse.ArgumentTypeError(f'slope must be in (0, 34) deg, got {text}')
    return value


def build_parser() -> argparse.ArgumentParser:
    """The command line: one sub-parser per manoeuvre."""
    parser = argparse.ArgumentParser(prog='maneuver', description=__doc__.splitlines()[0])
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument('--csv', metavar='PATH', help='write one row per 0.01 s step here')
    common.add_argument('--seed', type=int, default=0, help='random seed (waves)')
    common.add_argument('--config', metavar='PATH', help="parameter file (default: the stack's)")
    sub = parser.add_subparsers(dest='maneuver', required=True)
    p = sub.add_parser('circle', parents=[common], help='constant commands, fit the circle')
    p.add_argument('--medium', choices=['land', 'water'], required=True)
    p.add_argument('--port', type=_pct, required=True)
    p.add_argument('--stbd', type=_pct, required=True)
    p.add_argument('--duration', type=_positive, default=30.0)
    p = sub.add_parser('zigzag', parents=[common], help='alternating differential commands')
    p.add_argument('--medium', choices=['land', 'water'], required=True)
    p.add_argument('--high', type=_pct, required=True)
    p.add_argument('--low', type=_pct, required=True)
    p.add_argument('--period', type=_positive, default=10.0)
    p.add_argument('--duration', type=_positive, default=30.0)
    p.add_argument('--lead-in', type=_non_negative, default=0.0,
                   help='seconds at rest with zero commands first (sysid: use 2)')
    p = sub.add_parser('incline', parents=[common], help='climb a slope on dry sand')
    p.add_argument('--slope-deg', type=_slope, required=True)
    p.add_argument('--command', type=_pct, required=True)
    p.add_argument('--stbd', type=_pct, default=None,
                   help='starboard track apart from --command (default: the same)')
    p.add_argument('--duration', type=_positive, default=14.0)
    p = sub.add_parser('transition', parents=[common], help='land to sea or sea to land')
    p.add_argument('--direction', choices=['land-to-sea', 'sea-to-land'], required=True)
    p.add_argument('--command', type=_pct, required=True)
    p.add_argument('--wave-height', type=_non_negative, default=0.0)
    p.add_argument('--wave-period', type=_positive, default=None)
    p.add_argument('--slope-deg', type=_slope, default=None)
    p.add_argument('--duration', type=_positive, default=30.0)
    p = sub.add_parser('drift', parents=[common],
                       help='afloat in the surf, loosely held, following seas')
    p.add_argument('--wave-height', type=_non_negative, required=True)
    p.add_argument('--wave-period', type=_positive, default=None)
    p.add_argument('--duration', type=_positive, default=60.0)
    return parser


def run_from_args(args: argparse.Namespace) -> ManeuverRun:
    """ManeuverRun the manoeuvre the parsed arguments name."""
    common = {'seed': args.seed, 'config': args.config}
    if args.maneuver == 'circle':
        return circle(args.medium, args.port, args.stbd, args.duration, **common)
    if args.maneuver == 'zigzag':
        return zigzag(args.medium, args.high, args.low, args.period, args.duration,
                      lead_in_s=args.lead_in, **common)
    if args.maneuver == 'incline':
        return incline(args.slope_deg, args.command, args.duration, stbd=args.stbd, **common)
    if args.maneuver == 'transition':
        return transition(args.direction, args.command, args.wave_height, args.wave_period,
                          args.slope_deg, args.duration, **common)
    return drift(args.wave_height, args.duration, args.wave_period, **common)


def main(argv: Sequence[str] | None = None) -> int:
    """Console-script entry point: run, print the JSON summary, write the CSV."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        run = run_from_args(args)
        if args.csv:
            run.write_csv(args.csv)
    except (ConfigError, ValueError, OSError) as exc:
        parser.error(str(exc))
    summary = {k: (None if isinstance(v, float) and not math.isfinite(v) else v)
               for k, v in run.summary.items()}
    print(json.dumps(summary, allow_nan=False, default=_json_default))
    return 0


def _json_default(value):
    if isinstance(value, (np.floating, np.integer)):
        return value.item()
    raise TypeError(f'not JSON serialisable: {value!r}')


if __name__ == '__main__':
    sys.exit(main())
