"""A campaign's output folder: runs.csv / runs.parquet, summary.json, plots; one run's series.

ROS-free. ``runs.csv`` has one row per run (drawn conditions, metrics, error traceback),
``runs.parquet`` the same table typed (pyarrow);
``summary.json`` the percentiles, the share meeting the estimator's targets and the
indices of the runs that raised or missed a target; the plots histograms of the metrics
and the metrics against wave height and soil.
"""
from __future__ import annotations

import csv
import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from dukw_bringup.campaign import SERIES_COLUMNS, Spec

METRICS = ('position_rmse_m', 'heading_rmse_deg', 'slip_rmse', 'volume_error_pct',
           'fraction_error', 'mode_delay_to_water_s', 'mode_delay_to_land_s', 'chatter_count',
           'time_over_limit_s', 'peak_current_a', 'wall_s', 'mission_time_s')
CONDITIONS = ('significant_wave_height_m', 'peak_period_s', 'beach_slope_deg', 'cohesion_kpa',
              'friction_angle_deg', 'shear_modulus_cm', 'speed_mps')
PERCENTILES = (5, 50, 95, 100)


def write_runs_csv(rows: Sequence[Mapping[str, Any]], path: Path) -> None:
    """One row per run, sorted by index; columns the union of the rows' keys."""
    columns: list[str] = []
    for row in rows:
        columns += [k for k in row if k not in columns and not k.startswith('_')]
    with open(path, 'w', newline='', encoding='utf-8') as f:
        writer = csv.DictWriter(f, columns, extrasaction='ignore')
        writer.writeheader()
        for row in sorted(rows, key=lambda r: r['index']):
            writer.writerow(row)


def write_runs_parquet(rows: Sequence[Mapping[str, Any]], path: Path) -> None:
    """The runs table as Parquet (pyarrow), sorted by index: each column typed from its
    values (a run that raised has nulls where the others have metrics)."""
    import pyarrow as pa
    import pyarrow.parquet as pq
    columns: list[str] = []
    for row in rows:
        columns += [k for k in row if k not in columns and not k.startswith('_')]
    ordered = sorted(rows, key=lambda r: r['index'])
    table = pa.table({c: pa.array([r.get(c) for r in ordered]) for c in columns})
    pq.write_table(table, path)


def _values(rows: Sequence[Mapping[str, Any]], key: str) -> np.ndarray:
    vals = [r.get(key) for r in rows if not r.get('error')]
    return np.array([v for v in vals if isinstance(v, (int, float)) and math.isfinite(v)],
                    dtype=float)


def summarize(spec: Spec, rows: Sequence[Mapping[str, Any]]) -> dict:
    """Percentiles, target shares and the lists of failed and out-of-target runs."""
    done = [r for r in rows if not r.get('error')]
    errors = sorted(r['index'] for r in rows if r.get('error'))
    missed = sorted((r for r in done if not r['targets_met']), key=lambda r: r['index'])
    total = len(rows)
    per_target: dict[str, int] = {}
    for r in missed:
        for name in r['failed_targets'].split(';'):
            per_target[name] = per_target.get(name, 0) + 1
    percentiles = {}
    for key in METRICS:
        v = _values(rows, key)
        percentiles[key] = ({f'p{p}': round(float(np.percentile(v, p)), 4) for p in PERCENTILES}
                            | {'n': int(v.size)}) if v.size else {'n': 0}
    return {
        'name': spec.name, 'seed': spec.seed, 'runs': total, 'completed': len(done),
        'duration_s': spec.duration_s, 'targets': dict(spec.targets),
        'share_meeting_targets': round((len(done) - len(missed)) / total, 4) if total else 0.0,
        'missed_per_target': dict(sorted(per_target.items())),
        'by_kind': _by_kind(done),
        **({'missions_done': sum(r['mission_done'] is True for r in done)}
           if any('mission_done' in r for r in done) else {}),
        'conditions_meeting_vs_missing': _conditions_split(done),
        'percentiles': percentiles,
        'wall_s_per_run_mean': round(float(np.mean(_values(rows, 'wall_s'))), 3) if rows else 0,
        'failed_runs': [{'index': r['index'], 'error': r['error'].strip().splitlines()[-1]}
                        for r in sorted(rows, key=lambda r: r['index']) if r.get('error')],
        'failed_indices': errors,
        'out_of_target_runs': [{'index': r['index'], 'kind': r['kind'],
                                'failed': r['failed_targets']} for r in missed],
    }


def _by_kind(done: Sequence[Mapping[str, Any]]) -> dict:
    out = {}
    for kind in sorted({r['kind'] for r in done}):
        sub = [r for r in done if r['kind'] == kind]
        out[kind] = {'runs': len(sub), 'meeting_targets': sum(r['targets_met'] for r in sub)}
    return out


def _conditions_split(done: Sequence[Mapping[str, Any]]) -> dict:
    """Mean drawn conditions of the runs meeting the targets and of those missing them."""
    out = {}
    for key in CONDITIONS:
        met = _values([r for r in done if r['targets_met']], key)
        miss = _values([r for r in done if not r['targets_met']], key)
        out[key] = {'meeting_mean': round(float(met.mean()), 4) if met.size else None,
                    'missing_mean': round(float(miss.mean()), 4) if miss.size else None}
    return out


def write_summary(summary: Mapping[str, Any], path: Path) -> None:
    """summary.json (NaN-free: percentiles ignore NaN metrics)."""
    path.write_text(json.dumps(summary, indent=2) + '\n', encoding='utf-8')


def plot_campaign(rows: Sequence[Mapping[str, Any]], out_dir: Path) -> list[Path]:
    """histograms.png and metrics_vs_conditions.png."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    done = [r for r in rows if not r.get('error')]
    paths = []
    fig, axes = plt.subplots(3, 4, figsize=(14, 9))
    for ax, key in zip(axes.flat, METRICS, strict=False):
        v = _values(done, key)
        ax.hist(v, bins=30)
        ax.set_title(key, fontsize=9)
    fig.tight_layout()
    paths.append(out_dir / 'histograms.png')
    fig.savefig(paths[-1], dpi=80)
    plt.close(fig)
    judged = ('slip_rmse', 'volume_error_pct', 'fraction_error', 'mode_delay_to_land_s',
              'mode_delay_to_water_s')
    against = ('significant_wave_height_m', 'friction_angle_deg', 'cohesion_kpa',
               'shear_modulus_cm', 'beach_slope_deg')
    fig, axes = plt.subplots(len(judged), len(against), figsize=(16, 14))
    for i, key in enumerate(judged):
        for j, cond in enumerate(against):
            pts = [(r[cond], r[key]) for r in done
                   if isinstance(r.get(key), (int, float)) and math.isfinite(r[key])]
            ax = axes[i, j]
            if pts:
                x, y = zip(*pts, strict=True)
                ax.scatter(x, y, s=6)
            ax.set_xlabel(cond, fontsize=8)
            ax.set_ylabel(key, fontsize=8)
    fig.tight_layout()
    paths.append(out_dir / 'metrics_vs_conditions.png')
    fig.savefig(paths[-1], dpi=70)
    plt.close(fig)
    return paths


def write_series(series: np.ndarray, path: Path) -> None:
    """One run's per-step series (SERIES_COLUMNS) as CSV."""
    np.savetxt(path, series, delimiter=',', header=','.join(SERIES_COLUMNS), comments='',
               fmt='%.6g')


def plot_series(series: np.ndarray, path: Path) -> None:
    """Track, estimate vs truth (x, slip, volume, weight share), modes, currents."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    col = {name: series[:, k] for k, name in enumerate(SERIES_COLUMNS)}
    t = col['t_s']
    fig, axes = plt.subplots(6, 1, figsize=(10, 14), sharex=True)
    pairs = (('x_m', 'est_x_m'), ('port_slip', 'est_port_slip'),
             ('volume_m3', 'est_volume_m3'), ('fraction', 'est_fraction'),
             ('medium', 'mode'), ('port_current_a', 'stbd_current_a'))
    for ax, (a, b) in zip(axes, pairs, strict=True):
        ax.plot(t, col[a], label=a)
        ax.plot(t, col[b], label=b, linestyle='--')
        ax.legend(fontsize=8, loc='best')
    axes[-1].set_xlabel('t, s')
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)
