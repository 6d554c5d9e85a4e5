"""``mitos simulate --plot`` without matplotlib: the install hint, not a traceback."""

from __future__ import annotations

import sys

import pytest

from mitos_cli.cli.app import main

WORLD = """\
name: tiny
seed: 1
dt: 0.05
time_limit: 0.5
robot:
  model: tricycle
  wheelbase: 16
  footprint: {length: 24, width: 18}
q_init: {x: 30, y: -10, heading: 0}
q_goal: {x: 500, y: -10}
map:
  corridors:
    - points: [[0, 0], [600, 0]]
      width: 70
"""


def test_plot_without_matplotlib_says_how_to_install(tmp_path, monkeypatch, capsys):
    world = tmp_path / "tiny.yaml"
    world.write_text(WORLD, encoding="utf-8")
    for name in [m for m in sys.modules if m == "matplotlib" or m.startswith("matplotlib.")]:
        monkeypatch.setitem(sys.modules, name, None)
    monkeypatch.setitem(sys.modules, "matplotlib", None)      # `import matplotlib` fails
    with pytest.raises(SystemExit) as info:
        main(["simulate", str(world), "--plot", str(tmp_path / "run.png")])
    err = capsys.readouterr().err
    assert info.value.code == 1, err
    assert "drawing pictures needs matplotlib, which is not installed" in err
    assert "pip install 'mitos[plot]'" in err and "Traceback" not in err
    assert not (tmp_path / "run.png").exists()


def test_readme_main_job_installs_what_its_picture_needs():
    """The README's first command draws `run.png`: its install must bring matplotlib."""
    from pathlib import Path

    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text(encoding="utf-8")
    command = next(line for line in readme.splitlines()
                   if line.startswith("python3 -m venv") and "mitos simulate" in line)
    assert "--plot" in command and 'pip install ".[plot]"' in command, command
