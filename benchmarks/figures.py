"""Figures of the benchmarks: one human line each, and a JSON line for the summary table.

``report`` prints the figure and, when the environment variable DUKW_BENCH_FIGURES
names a file (scripts/bench.sh sets it), appends one JSON object per figure to it;
benchmarks/summary.py prints the table of all of them at the end of ``make bench``.
"""
from __future__ import annotations

import json
import os

FIGURES_ENV = 'DUKW_BENCH_FIGURES'
BETTER = ('lower', 'higher')


def report(name: str, value: float, unit: str, target: float | None = None,
           aim: float | None = None, better: str = 'lower', echo: bool = False) -> None:
    """Record one figure; ``better`` says which way is good; ``echo`` also prints it here.

    Benchmarks keep their own detailed lines, so by default nothing is printed here.
    """
    if better not in BETTER:
        raise ValueError(f'better must be one of {BETTER}, not {better!r}')
    if echo:
        print(f'{name}: {value:.4g} {unit}')
    path = os.environ.get(FIGURES_ENV)
    if not path:
        return
    line = {'name': name, 'value': float(value), 'unit': unit, 'target': target,
            'aim': aim, 'better': better}
    with open(path, 'a', encoding='utf-8') as out:
        out.write(json.dumps(line) + '\n')
