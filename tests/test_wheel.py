"""The grammar and the packaged rule bases work from an installed wheel, not only the checkout."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

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


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> tuple[Path, dict[str, str]]:
    """The wheel built from the checkout, installed in a folder of its own: that folder and
    the environment that imports from it (PYTHONPATH comes before the editable checkout)."""
    tmp_path = tmp_path_factory.mktemp("wheel")
    dist = tmp_path / "dist"
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
                    "-q", "-w", str(dist), str(ROOT)], check=True, capture_output=True,
                   timeout=300)
    (wheel,) = dist.glob("mitos_planner-*.whl")      # the distribution mitos-planner
    site = tmp_path / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target",
                    str(site), str(wheel)], check=True, capture_output=True, timeout=300)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env.update(PYTHONPATH=str(site), COLUMNS="100", NO_COLOR="1")
    return site, env


def test_installed_wheel_carries_grammar_and_rulebases(installed, tmp_path):
    site, env = installed
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


def test_installed_wheel_prints_the_pages_its_hints_name(installed, tmp_path):
    """The help texts and hints name pages as `mitos docs NAME`; the wheel carried no
    docs/ at all, so "(docs/interop.md)" pointed a pip user nowhere."""
    site, env = installed

    def mitos(*args: str) -> subprocess.CompletedProcess:
        return subprocess.run([sys.executable, "-m", "mitos_cli", *args], cwd=tmp_path,
                              env=env, capture_output=True, text=True, timeout=120)

    pages = sorted(p.stem for p in (ROOT / "docs").glob("*.md"))
    listed = mitos("docs")
    assert listed.returncode == 0, listed.stderr
    names = [line.split()[0] for line in listed.stdout.splitlines()[1:]]
    assert names == [*pages, "readme", "worlds"]
    for name, source in (("interop", ROOT / "docs" / "interop.md"),
                         ("readme", ROOT / "README.md"),
                         ("worlds", ROOT / "worlds" / "README.md")):
        proc = mitos("docs", name)
        assert proc.returncode == 0, proc.stderr
        assert proc.stdout == source.read_text(encoding="utf-8")
        where = Path(mitos("docs", name, "--path").stdout.strip())
        assert where.is_relative_to(site / "mitos_cli" / "_data")
        assert where.read_text(encoding="utf-8") == source.read_text(encoding="utf-8")
    assert mitos("docs", "docs/teach.md").stdout == (ROOT / "docs" / "teach.md").read_text(
        encoding="utf-8")
    wrong = mitos("docs", "interopp")
    assert wrong.returncode == 2 and wrong.stdout == ""
    assert "unknown page `interopp`" in wrong.stderr
    assert "did you mean `interop`?" in wrong.stderr
    # no picture nor stray file rides along: the pages and the README only
    installed_docs = sorted(p.name for p in (site / "mitos_cli" / "_data" / "docs").iterdir())
    assert installed_docs == sorted([*(f"{p}.md" for p in pages), "README.md"])
