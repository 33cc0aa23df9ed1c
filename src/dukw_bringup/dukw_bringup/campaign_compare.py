"""campaign_compare: two campaign folders of the same spec, run by run (ROS-free).

    install/lib/dukw_bringup/campaign_compare runs/before runs/after

An estimator change is judged on the same draws before and after it (the same spec and
seed: run i's conditions are the same in both). This prints the share meeting the targets
in each, the runs gained (missed before, meet now) and lost, with the metrics that decided
them, the misses per target and the judged metrics' mean and 95th percentile. A held-out
seed is a second pair of folders. Exit 0; 2 when a folder has no runs.csv or the two are
not runs of the same draws (their conditions differ).
"""
from __future__ import annotations

import argparse
import csv
import math
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from dukw_bringup.campaign_report import CONDITIONS

#: the metrics the estimator's targets judge, as runs.csv names them
JUDGED = ('slip_rmse', 'volume_error_pct', 'fraction_error', 'mode_delay_to_water_s',
          'mode_delay_to_land_s')


@dataclass
class Comparison:
    """Two campaigns of the same draws, run by run."""

    runs: int
    meeting: tuple[int, int]                       # runs meeting all targets, before / after
    gained: list[int] = field(default_factory=list)
    lost: list[int] = field(default_factory=list)
    misses: dict[str, tuple[int, int]] = field(default_factory=dict)    # per target
    stats: dict[str, tuple[tuple[float, float], tuple[float, float]]] = field(
        default_factory=dict)                      # metric -> ((mean, p95) before, after)


def read_runs(folder: Path) -> dict[int, dict[str, str]]:
    """A campaign folder's runs.csv by run index (ValueError when it has none)."""
    path = Path(folder) / 'runs.csv'
    if not path.is_file():
        raise ValueError(f'{folder}: no runs.csv (not a campaign output folder)')
    with open(path, encoding='utf-8') as f:
        return {int(row['index']): row for row in csv.DictReader(f)}


def compare(before: Mapping[int, Mapping[str, str]],
            after: Mapping[int, Mapping[str, str]]) -> Comparison:
    """Run by run over the indices both hold (ValueError when a run's drawn conditions
    differ: not the same spec and seed)."""
    common = sorted(set(before) & set(after))
    for i in common:
        differing = [c for c in CONDITIONS if before[i].get(c) != after[i].get(c)]
        if differing:
            raise ValueError(f'run {i}: drawn {", ".join(differing)} differ: the two folders '
                             'are not runs of the same spec and seed')
    met = {name: {i for i in common if rows[i].get('targets_met') == 'True'}
           for name, rows in (('before', before), ('after', after))}
    out = Comparison(len(common), (len(met['before']), len(met['after'])),
                     sorted(met['after'] - met['before']), sorted(met['before'] - met['after']))
    for target in sorted({t for rows in (before, after) for i in common
                          for t in rows[i].get('failed_targets', '').split(';') if t}):
        out.misses[target] = tuple(sum(target in rows[i].get('failed_targets', '').split(';')
                                       for i in common) for rows in (before, after))
    for metric in JUDGED:
        out.stats[metric] = tuple(_mean_p95([rows[i].get(metric, '') for i in common])
                                  for rows in (before, after))
    return out


def _mean_p95(texts: Sequence[str]) -> tuple[float, float]:
    """Mean and 95th percentile of the finite values of |metric| (NaN: none)."""
    values = np.array([abs(float(t)) for t in texts if t not in ('', 'nan')], dtype=float)
    values = values[np.isfinite(values)]
    if not values.size:
        return math.nan, math.nan
    return float(values.mean()), float(np.percentile(values, 95))


def format_comparison(c: Comparison, before: Mapping[int, Mapping[str, str]],
                      after: Mapping[int, Mapping[str, str]]) -> str:
    """The comparison as text: shares, gained and lost runs with what decided them, misses
    per target, the judged metrics' mean and p95."""
    share = [f'{100.0 * m / c.runs:.1f} % ({m}/{c.runs})' if c.runs else '-' for m in c.meeting]
    lines = [f'meeting all targets: {share[0]} -> {share[1]}']
    for name, indices in (('gained', c.gained), ('lost', c.lost)):
        lines.append(f'{name} ({len(indices)}):')
        lines += [f'  {i:4d} {_decided(before[i], after[i])}' for i in indices]
    lines.append('misses per target:')
    lines += [f'  {t:24s} {b:4d} -> {a:4d}' for t, (b, a) in c.misses.items()]
    lines.append('judged metrics, mean / p95 of |value|:')
    lines += [f'  {m:24s} {b[0]:.4g} / {b[1]:.4g} -> {a[0]:.4g} / {a[1]:.4g}'
              for m, (b, a) in c.stats.items()]
    return '\n'.join(lines)


def _decided(before: Mapping[str, str], after: Mapping[str, str]) -> str:
    """The targets missed on either side, with each side's value of their metrics."""
    names = {t for row in (before, after) for t in row.get('failed_targets', '').split(';')
             if t}
    if before.get('error') or after.get('error'):
        names.add('error')
    parts = []
    for name in sorted(names):
        if name == 'error':
            parts.append('raised: ' + ('before' if before.get('error') else 'after'))
        else:
            parts.append(f'{name} {_short(before.get(name))} -> {_short(after.get(name))}')
    return '; '.join(parts)


def _short(text: str | None) -> str:
    try:
        return f'{float(text):.4g}'
    except (TypeError, ValueError):
        return str(text)


def main(argv: Sequence[str] | None = None) -> int:
    """Console-script entry point."""
    p = argparse.ArgumentParser(prog='campaign_compare', description=__doc__.split('\n\n')[0])
    p.add_argument('before', type=Path, help='campaign output folder (runs.csv)')
    p.add_argument('after', type=Path, help='campaign output folder of the same spec and seed')
    args = p.parse_args(argv)
    try:
        before, after = read_runs(args.before), read_runs(args.after)
        result = compare(before, after)
    except ValueError as exc:
        print(f'campaign_compare: {exc}', file=sys.stderr)
        return 2
    print(format_comparison(result, before, after))
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
