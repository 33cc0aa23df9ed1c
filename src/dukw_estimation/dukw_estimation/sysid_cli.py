"""sysid: identify the vehicle's manoeuvring model from recorded zigzags, and check it.

    sysid identify --medium land|water [--order N] [--out MODEL.yaml] RUN [RUN ...]
    sysid validate MODEL.yaml RUN [RUN ...] [--detrend]
    sysid compare-paper MODEL.yaml [RUN ...]

A RUN is a rosbag2 folder recorded by the project (tracks/cmd or props/cmd by medium,
u, v, r from odometry/filtered, or from sim/truth with --truth) or a ``maneuver --csv``
file. Each sub-command takes ``--plots DIR`` and ends with one JSON line on stdout.
Exit status: 0 done, 2 refused (bad input, too short, no excitation, wrong medium,
missing topics), with the reason on stderr.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import Any, Sequence

import numpy as np
import yaml

from dukw_estimation import sysid
from dukw_model import state_space
from dukw_model.state_space import Model, SysIdError
from dukw_estimation.sysid_io import read_run

PAPER_MODELS_FILE = Path('reference') / 'paper_models.yaml'


def _clean(value: Any) -> Any:
    """JSON-safe: non-finite floats become None."""
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    return value


def _fmt_fit(fit: dict[str, float] | None) -> str:
    if fit is None:
        return 'n/a (no Kalman gain)'
    return '  '.join(f'{k} {v:7.1f} %' for k, v in fit.items())


def load_runs(paths: Sequence[str], medium: str, truth: bool, dt_s: float,
              min_duration_s: float) -> list[state_space.Run]:
    """Read, resample and check every run (SysIdError on the first bad one)."""
    runs = []
    for path in paths:
        run = sysid.resample(read_run(path, medium, truth), dt_s)
        sysid.check_run(run, medium, min_duration_s)
        runs.append(run)
    return runs


def load_model(path: str) -> Model:
    """A MODEL.yaml written by ``identify``."""
    try:
        data = yaml.safe_load(Path(path).read_text())
    except (OSError, yaml.YAMLError) as exc:
        raise SysIdError(f'{path}: cannot read the model: {exc}') from exc
    return Model.from_dict(data)


def save_model(model: Model, path: str) -> None:
    """Write the model YAML (plain lists: readable by anyone with numpy)."""
    Path(path).write_text(yaml.safe_dump(model.to_dict(), sort_keys=False, width=100))


def _report_runs(comparisons: Sequence[state_space.Comparison]) -> list[dict[str, Any]]:
    out = []
    for comp in comparisons:
        print(f'{comp.run.name}: {comp.run.duration_s:.1f} s')
        print(f'  simulated fit:   {_fmt_fit(comp.fit_pct)}')
        print(f'  one-step fit:    {_fmt_fit(comp.one_step_fit_pct)}')
        out.append({'run': comp.run.name, 'fit_pct': comp.fit_pct,
                    'one_step_fit_pct': comp.one_step_fit_pct})
    return out


def cmd_identify(args: argparse.Namespace) -> dict[str, Any]:
    """Fit, print singular values and fits, write the model (and plots)."""
    runs = load_runs(args.runs, args.medium, args.truth, args.dt, args.min_duration)
    result = sysid.identify(runs, args.medium, args.order, args.block_rows, args.min_duration)
    model, sv = result.model, result.singular_values
    print('singular values (order selection): '
          + ' '.join(f'{s:.4g}' for s in sv[:12]))
    print(f'suggested order: {result.suggested_order} (largest drop); using {model.order}')
    print(f'operating point: commands {np.round(model.u_offset, 2).tolist()} %, '
          f'u v r {np.round(model.y_offset, 4).tolist()}')
    comparisons = [state_space.compare(model, run) for run in runs]
    per_run = _report_runs(comparisons)
    if args.out:
        save_model(model, args.out)
        print(f'model written to {args.out}')
    plots = []
    if args.plots:
        from dukw_estimation.sysid_plots import plot_comparisons, plot_singular_values
        plots = [str(p) for p in plot_comparisons(comparisons, args.plots, 'identification',
                                                  args.medium)]
        plots.append(str(plot_singular_values(sv[:20], args.plots, model.order)))
    return {'command': 'identify', 'medium': model.medium, 'order': model.order,
            'dt_s': model.dt_s, 'fit_pct': model.fit_pct,
            'one_step_fit_pct': state_space.pooled_fit(comparisons, one_step=True),
            'singular_values': sv[:12].tolist(), 'suggested_order': result.suggested_order,
            'poles': [p['abs'] for p in state_space.describe_poles(model)], 'runs': per_run,
            'model': args.out, 'plots': plots}


def cmd_validate(args: argparse.Namespace) -> dict[str, Any]:
    """Simulate the model on each run; fits per output, pooled over the runs."""
    model = load_model(args.model)
    runs = load_runs(args.runs, model.medium, args.truth, model.dt_s, args.min_duration)
    models = [state_space.with_offsets_of(model, r) if args.detrend else model for r in runs]
    comparisons = [state_space.compare(m, r) for m, r in zip(models, runs, strict=True)]
    print(f'{model.medium} model, order {model.order}, operating point: '
          + ("each run's own means (--detrend)" if args.detrend else "the model's"))
    per_run = _report_runs(comparisons)
    fit, one_step = state_space.pooled_fit(comparisons), state_space.pooled_fit(comparisons, True)
    print(f'all runs: simulated fit {_fmt_fit(fit)}')
    plots = []
    if args.plots:
        from dukw_estimation.sysid_plots import plot_comparisons
        plots = [str(p) for p in plot_comparisons(comparisons, args.plots, 'validation',
                                                  model.medium)]
    return {'command': 'validate', 'medium': model.medium, 'order': model.order,
            'fit_pct': fit, 'one_step_fit_pct': one_step,
            'offsets': 'run' if args.detrend else 'model', 'runs': per_run, 'plots': plots}


def _paper_reference(path: str | None) -> dict:
    if path is None:
        from dukw_common.config import ConfigError, default_config_path
        try:
            path = str(default_config_path().parent / PAPER_MODELS_FILE)
        except ConfigError as exc:
            raise SysIdError(f'cannot find the paper models: {exc}') from exc
    try:
        return yaml.safe_load(Path(path).read_text())
    except (OSError, yaml.YAMLError) as exc:
        raise SysIdError(f'{path}: cannot read the paper models: {exc}') from exc


def _print_model(title: str, model: Model) -> dict[str, Any]:
    poles = state_space.describe_poles(model)
    gain = model.dc_gain()
    print(f'{title}')
    for p in poles:
        print(f'  pole {p["re"]:+.5f}{p["im"]:+.5f}j  |p| {p["abs"]:.5f}  '
              f'tau {p["time_constant_s"]:.3g} s')
    print('  steady-state gain per % (port, stbd):')
    for name, row in zip(state_space.OUTPUTS, gain, strict=True):
        print(f'    {name}: {row[0]:+.3e} {row[1]:+.3e}')
    return {'poles': poles, 'dc_gain_per_pct': gain.tolist()}


def cmd_compare_paper(args: argparse.Namespace) -> dict[str, Any]:
    """Poles and steady-state gains beside the paper's; both models' fits on the runs."""
    model = load_model(args.model)
    paper = state_space.paper_model(_paper_reference(args.reference), model.medium)
    print('paper outputs converted to REP 103: v and r sign-flipped (the paper has y to '
          'starboard and a negative yaw rate in a port turn)')
    ours = _print_model(f'identified {model.medium} model (order {model.order})', model)
    theirs = _print_model(f'paper {model.medium} model (order {paper.order})', paper)
    out: dict[str, Any] = {'command': 'compare-paper', 'medium': model.medium,
                           'order': model.order, 'identified': ours, 'paper': theirs}
    if args.runs:
        runs = load_runs(args.runs, model.medium, args.truth, model.dt_s, args.min_duration)
        print("fits on the runs, each model about each run's own means (the paper's "
              'operating point is not published):')
        for key, base in (('fit_pct', model), ('paper_fit_pct', paper)):
            comps = [state_space.compare(state_space.with_offsets_of(base, r), r) for r in runs]
            out[key] = state_space.pooled_fit(comps)
            print(f'  {"identified" if base is model else "paper":<10} {_fmt_fit(out[key])}')
    return out


def build_parser() -> argparse.ArgumentParser:
    """The command line."""
    parser = argparse.ArgumentParser(prog='sysid', description=__doc__.splitlines()[0])
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument('--truth', action='store_true',
                        help='bags: outputs from sim/truth instead of odometry/filtered')
    common.add_argument('--plots', metavar='DIR', help='write PNG plots here')
    common.add_argument('--min-duration', type=float, default=sysid.DEFAULT_MIN_DURATION_S,
                        help='refuse shorter runs, s (default %(default)s)')
    sub = parser.add_subparsers(dest='command', required=True)
    p = sub.add_parser('identify', parents=[common], help='fit a model (N4SID)')
    p.add_argument('--medium', choices=state_space.MEDIA, required=True)
    p.add_argument('--order', type=int, default=state_space.PAPER_ORDER,
                   help='model order (default %(default)s, as the paper)')
    p.add_argument('--dt', type=float, default=state_space.PAPER_DT_S,
                   help='resampling period, s (default %(default)s, as the paper)')
    p.add_argument('--block-rows', type=int, default=sysid.DEFAULT_BLOCK_ROWS,
                   help='Hankel block rows (default %(default)s)')
    p.add_argument('--out', metavar='MODEL.yaml', help='write the model here')
    p.add_argument('runs', nargs='+', metavar='RUN')
    p = sub.add_parser('validate', parents=[common], help='simulate a model on runs')
    p.add_argument('model', metavar='MODEL.yaml')
    p.add_argument('--detrend', action='store_true',
                   help="about each run's own means (MATLAB's detrend of the validation "
                        "data) instead of the model's operating point")
    p.add_argument('runs', nargs='+', metavar='RUN')
    p = sub.add_parser('compare-paper', parents=[common],
                       help="poles, gains and fits beside the paper's models")
    p.add_argument('model', metavar='MODEL.yaml')
    p.add_argument('--reference', metavar='YAML',
                   help='paper models (default: config/reference/paper_models.yaml)')
    p.add_argument('runs', nargs='*', metavar='RUN')
    return parser


COMMANDS = {'identify': cmd_identify, 'validate': cmd_validate,
            'compare-paper': cmd_compare_paper}


def main(argv: Sequence[str] | None = None) -> int:
    """Console-script entry point: 0 done, 2 refused."""
    args = build_parser().parse_args(argv)
    try:
        summary = COMMANDS[args.command](args)
    except SysIdError as exc:
        print(f'sysid: refused: {exc}', file=sys.stderr)
        return 2
    print(json.dumps(_clean(summary), allow_nan=False))
    return 0


if __name__ == '__main__':
    sys.exit(main())
