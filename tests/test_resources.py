"""Packaged files are found by name from any directory, as the README's commands assume."""

from __future__ import annotations

import subprocess
import sys

from mitos_cli.api import load_rulebase
from mitos_cli.resources import resolve


def test_packaged_rule_base_from_anywhere(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for name in ("rulebases/mitos.rules", "mitos.rules", "mitos"):
        assert resolve("rulebases", name, ".rules").name == "mitos.rules"
    assert load_rulebase("rulebases/mitos.rules").evaluate(road=78, size=45, position=4)
    assert resolve("rulebases", "nothere.rules", ".rules") is None


def test_a_local_file_wins(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "mitos.rules").write_text("x")
    assert resolve("rulebases", "mitos.rules", ".rules").resolve() == tmp_path / "mitos.rules"


def test_cli_from_another_directory(tmp_path):
    res = subprocess.run([sys.executable, "-m", "mitos_cli", "eval", "rulebases/mitos.rules",
                          "road=78", "size=45", "position=4"], cwd=tmp_path,
                         capture_output=True, text=True)
    assert res.returncode == 0 and "road = (MEDIUM/0.7, WIDE/0.3)" in res.stdout
