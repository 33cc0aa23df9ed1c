"""Linters as tests: ruff with ament's conventions (ruff.toml) over the whole workspace."""
import shutil
import subprocess
from pathlib import Path

import pytest

WORKSPACE = Path(__file__).resolve().parents[1]


def test_ruff_finds_nothing():
    ruff = shutil.which('ruff')
    if ruff is None:
        pytest.fail('ruff is not installed: scripts/setup.sh installs it from requirements.txt')
    result = subprocess.run([ruff, 'check', '--output-format', 'concise', 'src', 'tests',
                             'benchmarks', 'conftest.py'], cwd=WORKSPACE, capture_output=True,
                            text=True, timeout=120)
    assert result.returncode == 0, result.stdout + result.stderr
