"""The machine checks of how the code is kept (pyproject.toml holds each one's settings): ruff's
rule set, mypy at the documented strictness, and the import-layer contract."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def run(tool: str, *args: str) -> subprocess.CompletedProcess:
    # The interpreter's own scripts first: the suite may run from an unactivated venv.
    exe = shutil.which(tool, path=str(Path(sys.executable).parent)) or shutil.which(tool)
    if exe is None:
        pytest.fail(f"{tool} is not installed: pip install -e '.[test]' installs it")
    return subprocess.run([exe, *args], cwd=ROOT, capture_output=True, text=True, timeout=300)


def test_stages_import_only_downward():
    out = run("lint-imports")
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-2000:]
    assert "1 kept, 0 broken" in out.stdout


def test_ruff_finds_nothing():
    out = run("ruff", "check", "mitos_cli", "tests", "benchmarks")
    assert out.returncode == 0, out.stdout[-4000:] + out.stderr[-2000:]


def test_mypy_finds_nothing_in_the_package():
    import numpy as np

    if np.lib.NumpyVersion(np.__version__) < "2.0.0":
        pytest.skip("mypy is checked in the README's environment, against the newest NumPy's "
                    "type stubs; older stubs type some results differently")
    out = run("mypy")                      # files and strictness: [tool.mypy]
    assert out.returncode == 0, out.stdout[-4000:] + out.stderr[-2000:]
    assert "Success: no issues found" in out.stdout
