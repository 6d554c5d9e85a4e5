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


def test_an_example_file_of_the_repository_named_from_elsewhere_says_where_it_is(tmp_path):
    """The README's `mitos eval tests/data/interop/tipper.fis ...` and `--batch
    tests/data/inputs.csv`, run from another directory, said "not found" and no more: those
    files are the repository's, not packaged; so is docs/api.md's `tests/data/tiny.yaml`, a
    world. From a directory with its own `tests/` the
    usual "did you mean" (or nothing) stands."""
    said = ("hint: `tests/` is a folder of the MITOS repository, which `pip install` does not "
            "copy: run the example from the repository's root, or name a file of your own")
    for args in (["eval", "tests/data/interop/tipper.fis", "service=2", "food=1"],
                 ["eval", "--batch", "tests/data/inputs.csv"],
                 ["convert", "tests/data/interop/robot_jfuzzylogic.fcl", "--to", "rules"],
                 # docs/api.md's `load_world("tests/data/tiny.yaml")`: a world said to look
                 # among the packaged worlds by name, which this one is not
                 ["simulate", "tests/data/tiny.yaml"],
                 ["compare", "tests/data/tiny.yaml", "--runs", "1"]):
        res = subprocess.run([sys.executable, "-m", "mitos_cli", *args], cwd=tmp_path,
                             capture_output=True, text=True)
        assert res.returncode == 1 and "not found" in res.stderr and said in res.stderr, args
    (tmp_path / "tests").mkdir()
    res = subprocess.run([sys.executable, "-m", "mitos_cli", "eval", "tests/tipper.fis", "x=1"],
                         cwd=tmp_path, capture_output=True, text=True)
    assert res.returncode == 1 and "not found" in res.stderr and "repository" not in res.stderr


def test_a_studys_report_names_a_packaged_world_by_its_name(tmp_path):
    """report.md listed `mitos compare corridor`'s world as the path pip put it at
    (`/.../site-packages/.../worlds/corridor.yaml`): a packaged world is shown by its name,
    marked packaged; any other world as given."""
    from mitos_cli.resources import display_world, packaged_path
    from mitos_cli.study.report import render_markdown

    assert display_world(str(packaged_path("worlds", "corridor.yaml"))) == "corridor (packaged)"
    mine = tmp_path / "corridor.yaml"
    mine.write_text("name: mine\n")
    assert display_world(str(mine)) == str(mine)
    text = render_markdown({"worlds": [str(packaged_path("worlds", "slalom.yaml")), str(mine)],
                            "choices": [], "runs": 1, "seed": 1}, [], [], {}, 0, 0)
    assert f"- worlds: `slalom (packaged)`, `{mine}`" in text.splitlines()


def test_a_rule_base_reached_through_a_symbolic_link_is_named_as_given(tmp_path, monkeypatch,
                                                                         capsys):
    """In a checkout reached through a linked folder (`tests -> /elsewhere/tests`), `mitos
    eval tests/data/interop/tipper.fis ...` headed its trace `rule base
    ../../elsewhere/tests/data/interop/tipper.fis`, and `mitos check` named the file so in its
    summary but as given in its findings: the label followed the link. It names the file as
    the user gave it, relative to here, as the findings do."""
    from pathlib import Path

    from mitos_cli.cli.app import main
    from mitos_cli.resources import display_path

    real = tmp_path / "elsewhere" / "data"
    real.mkdir(parents=True)
    source = Path(__file__).parent / "data" / "interop" / "tipper.fis"
    (real / "tipper.fis").write_bytes(source.read_bytes())
    here = tmp_path / "here"
    here.mkdir()
    (here / "linked").symlink_to(real, target_is_directory=True)
    monkeypatch.chdir(here)
    assert display_path("linked/tipper.fis") == "linked/tipper.fis"
    assert display_path(str(here / "linked" / "tipper.fis")) == "linked/tipper.fis"
    try:
        main(["eval", "linked/tipper.fis", "service=2", "food=1"])
    except SystemExit as exc:
        assert not exc.code
    assert capsys.readouterr().out.startswith("rule base linked/tipper.fis, behavior main")
