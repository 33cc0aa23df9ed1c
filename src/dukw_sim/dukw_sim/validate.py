"""validate: the simulator against the paper's field measurements (issue 13).

    validate [--reference PATH] [--only GROUP ...] [--plots DIR] [--set NAME=VALUE ...]
             [--seed N] [--config PATH]

Runs each reference manoeuvre of ``config/reference/paper.yaml`` on the simulator core
(dukw_sim.maneuver), prints one line per check (simulated, paper, tolerance, ok/OFF) and
a last line with the score, and exits 1 when a check is OFF. It also runs the land and
water zigzags and reports how well the paper's identified models reproduce the
simulator's u, v, r (fit %, information only). ``--plots DIR`` writes comparison plots.
"""
from __future__ import annotations

import argparse
import math
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Sequence

import numpy as np
import yaml

from dukw_common.config import ConfigError, default_config_path, node_params
from dukw_common.vehicle import Vehicle
from dukw_model import state_space
from dukw_sim import maneuver
from dukw_sim.core import Actuation, SimCore

GROUPS = ('land_turns', 'port_bias', 'inclines', 'water_turns', 'surf_transitions', 'drift')
REFERENCE_FILE = Path('reference') / 'paper.yaml'
#: The paper's identified models (one copy, read by sysid compare-paper too).
PAPER_MODELS_FILE = Path('reference') / 'paper_models.yaml'


@dataclass(frozen=True)
class Check:
    """One simulated figure against the paper's, with the band it must fall in."""

    group: str
    name: str
    simulated: float
    paper: float | str
    low: float
    high: float
    unit: str

    @property
    def ok(self) -> bool:
        """Within [low, high] (a NaN is never ok)."""
        return bool(self.low <= self.simulated <= self.high)

    def line(self) -> str:
        """The check's report line."""
        paper = self.paper if isinstance(self.paper, str) else f'{self.paper:.3g}'
        return (f'{self.group:16s} {self.name:24s} sim {self.simulated:9.3f} {self.unit:5s} '
                f'paper {paper:>9s}  band [{self.low:.3g}, {self.high:.3g}]  '
                f'{"ok" if self.ok else "OFF"}')


def relative(group: str, name: str, simulated: float, paper: float, tol: float,
             unit: str) -> Check:
    """A check within +- tol (relative) of the paper's value."""
    return Check(group, name, float(simulated), paper, paper * (1.0 - tol),
                 paper * (1.0 + tol), unit)


@dataclass
class Results:
    """Every check, the zigzag fits and what the plots need."""

    checks: list = field(default_factory=list)
    fits: dict = field(default_factory=dict)
    series: dict = field(default_factory=dict)


def reference_path() -> Path:
    """The reference file beside the stack's parameter file."""
    return default_config_path().parent / REFERENCE_FILE


def load_reference(path: str | Path | None = None) -> dict:
    """Read the reference file (or another of config/reference); ConfigError when missing
    or not a mapping."""
    path = Path(path) if path is not None else reference_path()
    try:
        doc = yaml.safe_load(path.read_text())
    except (OSError, yaml.YAMLError) as exc:
        raise ConfigError(f'cannot read reference file {path}: {exc}') from exc
    if not isinstance(doc, dict):
        raise ConfigError(f'{path}: expected a mapping of test groups')
    return doc


# ---------------------------------------------------------------------------- groups
def land_turns(ref: dict, res: Results, seed: int, config: str | None) -> None:
    """Constant track commands on flat dry sand: circle radius against the paper's."""
    tol = ref['tolerance_rel']
    rows = []
    for port, stbd, radius in ref['cases']:
        run = maneuver.circle('land', port, stbd, ref['duration_s'], seed, config)
        sim_r = run.summary['radius_m']
        res.checks.append(relative('land_turns', f'{port}/{stbd} radius', sim_r, radius, tol,
                                   'm'))
        rows.append((f'{port}/{stbd}', sim_r, radius))
    res.series['land_turns'] = rows


def water_turns(ref: dict, res: Results, seed: int, config: str | None) -> None:
    """Constant propeller commands afloat: circle radius against the paper's."""
    tol = ref['tolerance_rel']
    rows = []
    for port, stbd, radius in ref['cases']:
        run = maneuver.circle('water', port, stbd, ref['duration_s'], seed, config)
        sim_r = run.summary['radius_m']
        res.checks.append(relative('water_turns', f'{port}/{stbd} radius', sim_r, radius,
                                   tol, 'm'))
        rows.append((f'{port}/{stbd}', sim_r, radius))
    res.series['water_turns'] = rows


def heading_change_deg(port: float, stbd: float, distance_m: float,
                       config: str | None) -> float:
    """Heading change over ``distance_m`` of flat sand once up to speed, deg (+ to port)."""
    sim = SimCore.from_config(config)
    sim.reset(x_m=sim.params.world.flat_start_x_m - 30.0)
    act = Actuation(port, stbd)
    for _ in range(300):
        truth = sim.step(act)
    x0, y0, yaw0 = truth.x_m, truth.y_m, truth.yaw_rad
    while math.hypot(truth.x_m - x0, truth.y_m - y0) < distance_m and truth.t_s < 60.0:
        truth = sim.step(act)
    return math.degrees(truth.yaw_rad - yaw0)


def port_bias(ref: dict, res: Results, seed: int, config: str | None) -> None:
    """Equal commands drift to port; port 60 / starboard 56 goes straight."""
    dist = ref['distance_m']
    straight = heading_change_deg(*ref['straight'], dist, config)
    drifting = heading_change_deg(*ref['drifting'], dist, config)
    lim, need = ref['max_straight_deg'], ref['min_drift_deg']
    p, s = ref['straight']
    res.checks.append(Check('port_bias', f'{p}/{s} heading change', straight, 'straight',
                            -lim, lim, 'deg'))
    p, s = ref['drifting']
    res.checks.append(Check('port_bias', f'{p}/{s} heading change', drifting, 'to port',
                            need, math.inf, 'deg'))


def inclines(ref: dict, res: Results, seed: int, config: str | None) -> None:
    """Equal commands from the base of a dry-sand slope: climbs or stalls, mean currents."""
    tol = ref['tolerance_rel']
    rows = []
    for case in ref['cases']:
        slope = case['slope_deg']
        run = maneuver.incline(slope, ref['command_pct'], case['duration_s'], seed, config)
        s = run.summary
        climbed = not s['stalled']
        res.checks.append(Check('inclines', f'{slope:g} deg climbs', float(climbed),
                                'yes' if case['climbs'] else 'no', float(case['climbs']),
                                float(case['climbs']), ''))
        for side in ('port', 'stbd'):
            res.checks.append(relative('inclines', f'{slope:g} deg {side} current',
                                       s[f'mean_{side}_current_a'], case[f'{side}_current_a'],
                                       tol, 'A'))
        rows.append((slope, s['mean_port_current_a'], s['mean_stbd_current_a'],
                     case['port_current_a'], case['stbd_current_a']))
    res.series['inclines'] = rows


def track_force_gain_n_per_a(config: str | None) -> float:
    """The drivetrain's current-to-force gain of the parameter file, N/A (vehicle.md 3)."""
    return Vehicle.from_params(node_params('sim_node', config)).drivetrain \
        .track_force_gain_n_per_a


def surf_force_per_track_n(run: maneuver.ManeuverRun, gain_n_per_a: float) -> float:
    """Mean track force per track while the tracks carry weight in the surf, N, measured as
    the paper measured it: motor current x the drivetrain's gain (vehicle.md 3 and 6; the
    paper Kalman-filtered the currents, a mean over the window is unaffected by that). So
    it holds the drivetrain friction, the no-load current and the tracks' paddling besides
    the soil's force, as the boat's currents did. The window is the paper's words: weight
    on the tracks and water over the sand under base_link (the middle of the tracks'
    contact), whatever the hulls' immersion; not the truth's medium flag, whose TRANSITION
    needs the hulls immersed and flickers with each wave at the edge of the swash."""
    forces = [0.5 * gain_n_per_a * (t.port_current_a + t.stbd_current_a) for t in run.rows
              if t.water_depth_m > 0.0 and t.effective_weight_n > 0.0]
    return float(np.mean(forces)) if forces else float('nan')


def surf_transitions(ref: dict, res: Results, seed: int, config: str | None) -> None:
    """Tracks only through the day-1 surf, both ways: mean force per track in the surf."""
    rows = []
    gain = track_force_gain_n_per_a(config)
    for direction, key in (('land-to-sea', 'land_to_sea_force_n'),
                           ('sea-to-land', 'sea_to_land_force_n')):
        low, high = ref[key]
        for cmd in ref['commands_pct']:
            run = maneuver.transition(direction, cmd, ref['wave_height_m'],
                                      ref['wave_period_s'], ref['beach_slope_deg'],
                                      ref['duration_s'], seed, config)
            force = surf_force_per_track_n(run, gain)
            res.checks.append(Check('surf_transitions', f'{direction} {cmd:g} % force', force,
                                    f'{low:g}-{high:g}', low, high, 'N'))
            rows.append((direction, cmd, force, low, high))
    res.series['surf_transitions'] = rows


def drift(ref: dict, res: Results, seed: int, config: str | None) -> None:
    """Afloat in the surf, loosely restrained, following seas: RMS motions."""
    run = maneuver.drift(ref['wave_height_m'], ref['duration_s'], seed=seed, config=config)
    settle = min(10.0, ref['duration_s'] / 4.0)

    def rms(getter: Callable) -> float:
        values = run.array(getter, settle)
        return float(np.sqrt(np.mean(np.square(values - np.mean(values)))))

    sim = {'rms_heave_velocity_mps': rms(lambda t: t.heave_mps),
           'rms_pitch_deg': math.degrees(rms(lambda t: t.pitch_rad)),
           'rms_roll_deg': math.degrees(rms(lambda t: t.roll_rad)),
           'rms_yaw_rate_dps': math.degrees(rms(lambda t: t.yaw_rate_rps))}
    units = {'rms_heave_velocity_mps': 'm/s', 'rms_pitch_deg': 'deg', 'rms_roll_deg': 'deg',
             'rms_yaw_rate_dps': 'deg/s'}
    for key, value in sim.items():
        res.checks.append(relative('drift', key, value, ref[key], ref['tolerance_rel'],
                                   units[key]))
    res.series['drift'] = [(key, sim[key], ref[key]) for key in sim]


_RUNNERS: dict[str, Callable] = {
    'land_turns': land_turns, 'port_bias': port_bias, 'inclines': inclines,
    'water_turns': water_turns, 'surf_transitions': surf_transitions, 'drift': drift}


# ---------------------------------------------------------------------------- zigzags
def zigzag_run(medium: str, high: float, low: float, ref: dict, seed: int,
               config: str | None) -> state_space.Run:
    """A simulated zigzag as a system-identification run (commands %, u v r REP 103)."""
    rows = maneuver.zigzag(medium, high, low, ref['period_s'], ref['duration_s'], seed,
                           config).rows
    if medium == 'land':
        cmds = [[t.port_cmd_pct, t.stbd_cmd_pct] for t in rows]
    else:
        cmds = [[t.port_prop_cmd_pct, t.stbd_prop_cmd_pct] for t in rows]
    y = [[t.surge_mps, t.sway_mps, t.yaw_rate_rps] for t in rows]
    return state_space.Run(f'{medium} {high:g}/{low:g}', medium, np.array([t.t_s for t in rows]),
                     np.array(cmds, dtype=float), np.array(y, dtype=float))


def zigzag_fits(ref: dict, res: Results, seed: int, config: str | None,
                paper_models: dict) -> None:
    """The paper's identified models (REP 103 outputs, about each run's own means: their
    operating point is not published) against the simulator's zigzags, fit % of u, v, r
    as MATLAB's compare gives it (dukw_model.state_space)."""
    for medium in ('land', 'water'):
        high, low = ref[medium]
        run = zigzag_run(medium, high, low, ref, seed, config)
        model = state_space.with_offsets_of(state_space.paper_model(paper_models, medium), run)
        comparison = state_space.compare(model, run)
        res.fits[run.name] = comparison.fit_pct
        res.series[f'zigzag_{medium}'] = (run.t_s, run.y, comparison.y_sim)


# ---------------------------------------------------------------------------- run
def run_all(reference: dict, groups: Sequence[str] = GROUPS, zigzags: bool = True,
            seed: int = 0, config: str | None = None) -> Results:
    """Run the named groups (and the zigzag fits) and collect the checks."""
    res = Results()
    for group in groups:
        if group not in _RUNNERS:
            raise ValueError(f'unknown group {group!r}; one of {", ".join(GROUPS)}')
        if group not in reference:
            raise ConfigError(f'reference file has no {group!r} section')
        _RUNNERS[group](reference[group], res, seed, config)
    if zigzags:
        paper_models = load_reference(default_config_path().parent / PAPER_MODELS_FILE)
        zigzag_fits(reference['zigzags'], res, seed, config, paper_models)
    return res


def report(res: Results) -> list[str]:
    """The report's lines: checks, zigzag fits, score."""
    lines = [c.line() for c in res.checks]
    for name, fits in res.fits.items():
        text = ', '.join(f'{k} {v:6.1f} %' for k, v in fits.items())
        lines.append(f'zigzag (info)    {name:24s} paper model fit: {text}')
    ok = sum(c.ok for c in res.checks)
    lines.append(f'score: {ok}/{len(res.checks)} checks ok')
    return lines


def config_with(settings: Sequence[str], config: str | None, folder: Path) -> str:
    """Write the parameter file with ``NAME=VALUE`` settings (sim_node's or the shared
    block's dotted names, numbers) into ``folder``; return its path. ValueError if unknown."""
    source = Path(config) if config else default_config_path()
    doc = yaml.safe_load(source.read_text())
    for setting in settings:
        name, sep, text = setting.partition('=')
        try:
            value = float(text)
        except ValueError:
            value = None
        if not sep or value is None:
            raise ValueError(f'--set needs NAME=NUMBER, got {setting!r}')
        for block in ('sim_node', '/**'):
            tree = doc[block]['ros__parameters']
            *path, leaf = name.split('.')
            for key in path:
                tree = tree.get(key) if isinstance(tree, dict) else None
            if isinstance(tree, dict) and leaf in tree:
                tree[leaf] = value
                break
        else:
            raise ValueError(f'--set: no parameter {name!r} in sim_node or /**')
    out = folder / 'validate_config.yaml'
    out.write_text(yaml.safe_dump(doc))
    return str(out)


def build_parser() -> argparse.ArgumentParser:
    """The command line."""
    parser = argparse.ArgumentParser(prog='validate', description=__doc__.splitlines()[0])
    parser.add_argument('--reference', metavar='PATH', help='reference file (default: '
                        'config/reference/paper.yaml beside the parameter file)')
    parser.add_argument('--only', nargs='+', choices=GROUPS, metavar='GROUP',
                        help=f'run only these groups ({", ".join(GROUPS)})')
    parser.add_argument('--no-zigzags', action='store_true', help='skip the zigzag fits')
    parser.add_argument('--plots', metavar='DIR', help='write comparison plots (PNG) here')
    parser.add_argument('--set', action='append', default=[], metavar='NAME=VALUE',
                        help='run with this parameter changed (sim_node or shared dotted name, '
                        'e.g. land.lateral_friction_coeff=0.11); repeatable')
    parser.add_argument('--seed', type=int, default=0, help='random seed (waves)')
    parser.add_argument('--config', metavar='PATH', help="parameter file (default: the stack's)")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Console-script entry point: 0 when every check is ok, 1 when one is OFF."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        reference = load_reference(args.reference)
        with tempfile.TemporaryDirectory() as folder:
            config = config_with(args.set, args.config, Path(folder)) if args.set \
                else args.config
            res = run_all(reference, args.only or GROUPS, not args.no_zigzags, args.seed,
                          config)
    except (ConfigError, KeyError, ValueError, OSError) as exc:
        parser.error(str(exc))
    for line in report(res):
        print(line, flush=True)
    if args.plots:
        from dukw_sim.validate_plots import write_plots
        for path in write_plots(res, Path(args.plots)):
            print(f'plot: {path}')
    return 0 if all(c.ok for c in res.checks) else 1


if __name__ == '__main__':
    sys.exit(main())
