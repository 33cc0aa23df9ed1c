"""The summary table of ``make bench``: every figure against its target and aim.

    python benchmarks/summary.py FIGURES.jsonl

Reads the JSON lines written by benchmarks/figures.py and prints one aligned table;
the status column says 'met', 'NOT met' or '-' (no target), plus 'aim met' when the
aim is reached too. Figures only: the exit code does not depend on the targets.
"""
from __future__ import annotations

import json
import sys
from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class Figure:
    """One measured figure with its optional target and aim."""

    name: str
    value: float
    unit: str
    target: float | None = None
    aim: float | None = None
    better: str = 'lower'

    def reaches(self, bound: float | None) -> bool | None:
        """Whether the value is on the good side of ``bound`` (None without a bound)."""
        if bound is None:
            return None
        return self.value <= bound if self.better == 'lower' else self.value >= bound

    def status(self) -> str:
        """'met', 'met, aim met', 'NOT met' or '-' when there is no target."""
        met = self.reaches(self.target)
        if met is None:
            return '-'
        if not met:
            return 'NOT met'
        return 'met, aim met' if self.reaches(self.aim) else 'met'


def load_figures(path: Path) -> list[Figure]:
    """The figures in a JSON-lines file, in order; a malformed line raises ValueError."""
    figures = []
    for number, line in enumerate(path.read_text(encoding='utf-8').splitlines(), 1):
        if not line.strip():
            continue
        try:
            figures.append(Figure(**json.loads(line)))
        except (json.JSONDecodeError, TypeError) as error:
            raise ValueError(f'{path}:{number}: not a figure line ({error})') from error
    return figures


def _number(value: float) -> str:
    return f'{value:,.0f}' if abs(value) >= 1e4 else f'{value:.4g}'


def _bound(figure: Figure, bound: float | None) -> str:
    if bound is None:
        return ''
    return f'{"<=" if figure.better == "lower" else ">="} {_number(bound)}'


def format_table(figures: list[Figure]) -> str:
    """The aligned plain-text table, one row per figure."""
    header = ('figure', 'value', 'unit', 'target', 'aim', 'status')
    rows = [header] + [(f.name, _number(f.value), f.unit, _bound(f, f.target),
                        _bound(f, f.aim), f.status()) for f in figures]
    widths = [max(len(row[i]) for row in rows) for i in range(len(header))]
    lines = ['  '.join(cell.rjust(w) if i == 1 else cell.ljust(w)
                       for i, (cell, w) in enumerate(zip(row, widths, strict=True))).rstrip()
             for row in rows]
    lines.insert(1, '  '.join('-' * w for w in widths))
    with_target = [f for f in figures if f.target is not None]
    met = sum(f.reaches(f.target) for f in with_target)
    lines.append(f'{met} of {len(with_target)} targets met')
    return '\n'.join(lines)


def main(argv: list[str]) -> int:
    """Print the table of the file named on the command line."""
    if len(argv) != 1:
        print('usage: summary.py FIGURES.jsonl', file=sys.stderr)
        return 2
    figures = load_figures(Path(argv[0]))
    print(format_table(figures) if figures else 'no figures recorded')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
