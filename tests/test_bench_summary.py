"""The `make bench` summary: figure lines written by benchmarks/figures.py -> the table."""
from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[1] / 'benchmarks'


def _load(name: str):
    spec = importlib.util.spec_from_file_location(f'bench_{name}', BENCHMARKS / f'{name}.py')
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module          # dataclasses look their module up here
    spec.loader.exec_module(module)
    return module


figures = _load('figures')
summary = _load('summary')


def _row(table: str, name: str) -> str:
    rows = [line for line in table.splitlines() if line.startswith(name + ' ')]
    assert len(rows) == 1, table
    return rows[0]


def test_report_appends_figure_lines_and_table_marks_met_and_not_met(tmp_path, monkeypatch):
    path = tmp_path / 'figures.jsonl'
    monkeypatch.setenv(figures.FIGURES_ENV, str(path))
    figures.report('cpu', 30.0, '%', target=25.0, aim=15.0)             # lower, missed
    figures.report('latency', 1.5, 'ms', target=5.0, aim=2.0)            # lower, aim met
    figures.report('p50', 0.9, 'ms', target=1.0, aim=0.5)                # lower, met only
    figures.report('rtf', 80.0, 'x', target=100.0, better='higher')      # higher, missed
    figures.report('replay', 6e4, 'msg/s', target=5e4, better='higher')  # higher, met
    figures.report('step', 12.0, 'us')                                   # no target
    assert len(path.read_text().splitlines()) == 6
    table = summary.format_table(summary.load_figures(path))
    assert _row(table, 'cpu').endswith('NOT met')
    assert _row(table, 'latency').endswith('met, aim met')
    assert _row(table, 'p50').endswith('  met')
    assert _row(table, 'rtf').endswith('NOT met')
    assert '>= 100' in _row(table, 'rtf')
    assert '60,000' in _row(table, 'replay') and '>= 50,000' in _row(table, 'replay')
    assert _row(table, 'replay').endswith('  met')
    assert _row(table, 'step').endswith('-')
    assert table.splitlines()[-1] == '3 of 5 targets met'


def test_boundary_value_meets_target():
    at_target = summary.Figure('x', 25.0, '%', target=25.0)
    assert at_target.status() == 'met'
    assert summary.Figure('y', 25.0, 'x', target=25.0, better='higher').status() == 'met'


def test_report_without_env_writes_nothing_and_rejects_bad_direction(tmp_path, monkeypatch):
    monkeypatch.delenv(figures.FIGURES_ENV, raising=False)
    monkeypatch.chdir(tmp_path)
    figures.report('cpu', 1.0, '%', target=2.0)
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(ValueError, match='better'):
        figures.report('cpu', 1.0, '%', better='up')


def test_malformed_line_is_a_clear_error(tmp_path):
    path = tmp_path / 'figures.jsonl'
    path.write_text(json.dumps({'name': 'a', 'value': 1.0, 'unit': 'x'}) + '\n{oops\n')
    with pytest.raises(ValueError, match=':2: not a figure line'):
        summary.load_figures(path)
