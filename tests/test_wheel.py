"""The grammar and the packaged rule bases work from an installed wheel, not only the checkout."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

PROBE = r"""
import json, sys
from pathlib import Path
import mitos_cli
from mitos_cli import load_rulebase
from mitos_cli.api import default_rulebase_path
from mitos_cli.lang.parse import parse_rule
from mitos_cli.resources import data_dir, grammar_text

rb = load_rulebase()
out = rb.evaluate(road=78, size=45, position=4)
print(json.dumps({
    "module": mitos_cli.__file__,
    "rulebase": str(default_rulebase_path()),
    "grammar_dir": str(data_dir("grammar")),
    "grammar_lines": len(grammar_text().splitlines()),
    "rule": parse_rule("if road is WIDE then speed is SLOW").consequents[0].term,
    "steering": out["steering"],
    "speed": out["speed"],
}))
"""


def test_installed_wheel_carries_grammar_and_rulebases(tmp_path):
    dist = tmp_path / "dist"
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
                    "-q", "-w", str(dist), str(ROOT)], check=True, capture_output=True,
                   timeout=300)
    (wheel,) = dist.glob("mitos_planner-*.whl")      # the distribution mitos-planner
    site = tmp_path / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target",
                    str(site), str(wheel)], check=True, capture_output=True, timeout=300)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env["PYTHONPATH"] = str(site)
    # run in the temporary directory: PYTHONPATH comes before the editable checkout
    proc = subprocess.run([sys.executable, "-c", PROBE], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    info = json.loads(proc.stdout)
    assert Path(info["module"]).is_relative_to(site)
    assert Path(info["rulebase"]).is_relative_to(site / "mitos_cli" / "_data" / "rulebases")
    assert Path(info["grammar_dir"]).is_relative_to(site / "mitos_cli" / "_data")
    assert info["grammar_lines"] == len((ROOT / "grammar" / "mitos.lark").read_text(
        encoding="utf-8").splitlines())
    assert info["rule"] == "SLOW"
    assert (round(info["steering"], 1), round(info["speed"], 1)) == (65.4, 32.4)
