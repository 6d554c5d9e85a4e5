"""``mitos simulate``: the --json, --out, --plot, --trace and --require contract."""

from __future__ import annotations

import csv
import io
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from mitos_cli.cli.app import app, main
from mitos_cli.sim.perception import INPUTS

RUNNER = CliRunner()
KEYS = {"world", "seed", "outcome", "reached_goal", "collisions", "time_s", "path_length_in",
        "min_clearance_in", "mean_speed_in_s", "steering_total_variation_deg", "ticks",
        "replans", "backouts", "near_miss"}
SHORT = """\
name: short
seed: 2
dt: 0.05
time_limit: 3
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
obstacles:
  - {name: box, shape: circle, at: [100, -12], radius: 8}
"""


@pytest.fixture()
def short(tmp_path: Path) -> Path:
    p = tmp_path / "short.yaml"
    p.write_text(SHORT, encoding="utf-8")
    return p


def run(*args):
    return RUNNER.invoke(app, ["simulate", *map(str, args)])


def run_main(capsys, *args) -> tuple[int, str]:
    """Through ``main``, which turns our errors into a message and exit 1."""
    with pytest.raises(SystemExit) as info:
        main(["simulate", *map(str, args)])
    return info.value.code, capsys.readouterr().err


def test_json_has_exactly_the_contract_keys(short):
    res = run(short, "--json")
    assert res.exit_code == 0, res.output
    data = json.loads(res.stdout)
    assert set(data) == KEYS
    assert data["world"] == "short" and data["seed"] == 2 and data["outcome"] == "timeout"
    assert data["ticks"] == 60 and isinstance(data["reached_goal"], bool)


def test_json_matches_the_library(short):
    from mitos_cli.sim.loop import simulate
    from mitos_cli.sim.worldfile import load_world

    data = json.loads(run(short, "--json", "--seed", 4).stdout)
    assert data["near_miss"] is False
    assert data == simulate(load_world(short), seed=4).summary()    # near_miss included


def test_human_output_is_a_verdict_and_a_table(short):
    res = run(short)
    assert res.exit_code == 0
    first = res.stdout.splitlines()[0]
    assert first.startswith("short: TIMEOUT after 3.00 s (seed 2, fuzzy:drive)")
    assert "min clearance" in res.stdout and "path length" in res.stdout


def test_out_writes_one_row_per_tick(short, tmp_path):
    out = tmp_path / "run.csv"
    res = run(short, "--out", out)
    assert res.exit_code == 0
    rows = list(csv.DictReader(io.StringIO(out.read_text())))
    assert len(rows) == 60
    head = rows[0].keys()
    for col in ["t", "x", "y", "pose_heading_deg", "speed", "steering", "range_0", "range_35",
                "fired", *INPUTS, *(f"true_{k}" for k in INPUTS)]:
        assert col in head
    assert "follow_route/" in rows[0]["fired"]


def test_out_keeps_a_far_robots_moves(short, tmp_path):
    """A world 2.5 km from the origin (100,000 in) was written to 6 significant digits, to
    the inch: the path recomputed from the file's x and y came out 5% longer than the
    summary's (76.9 in for 73.4). Written to the hundredth, it agrees to 0.05%."""
    far = short.read_text().replace("x: 30, y: -10", "x: 100030, y: 99990").replace(
        "x: 500, y: -10", "x: 100500, y: 99990").replace(
        "[[0, 0], [600, 0]]", "[[100000, 100000], [100600, 100000]]").replace(
        "at: [100, -12]", "at: [100100, 99988]")
    world = tmp_path / "far.yaml"
    world.write_text(far, encoding="utf-8")
    out = tmp_path / "run.csv"
    res = run(world, "--out", out, "--json")
    assert res.exit_code == 0, res.output
    path = json.loads(res.stdout)["path_length_in"]
    rows = list(csv.DictReader(io.StringIO(out.read_text())))
    xy = [(float(r["x"]), float(r["y"])) for r in rows]
    driven = sum(math.dist(a, b) for a, b in zip(xy, xy[1:]))
    assert driven == pytest.approx(path, rel=5e-4)
    assert len(rows[-1]["x"].split(".")[1]) == 2           # 100,0xx.xx in


def test_out_columns_are_unique_and_documented(short, tmp_path):
    """Every column of --out has one name (the robot's heading is `pose_heading_deg`, the rule
    input `heading` the route's bearing) and a row in worlds/README.md's table."""
    out = tmp_path / "run.csv"
    assert run(short, "--out", out).exit_code == 0
    header = out.read_text().splitlines()[0].split(",")
    assert len(header) == len(set(header))
    assert header.count("heading") == 1 and "pose_heading_deg" in header
    rows = list(csv.DictReader(io.StringIO(out.read_text())))
    assert float(rows[0]["pose_heading_deg"]) == pytest.approx(0.0, abs=1e-6)
    readme = (Path(__file__).parents[1] / "worlds" / "README.md").read_text()
    table = readme.split("## The `--out` CSV")[1].split("\n## ")[0]
    documented = set(re.findall(r"^\| `([a-z_<>0-9.]+)`", table, flags=re.M))
    for col in header:
        name = ("range_<b>" if col.startswith("range_") else
                "true_<input>" if col.startswith("true_") else col)
        assert name in documented, col


@pytest.mark.parametrize("suffix, magic", [(".png", b"\x89PNG"), (".svg", b"<?xml")])
def test_plot_writes_png_and_svg(short, tmp_path, suffix, magic):
    pic = tmp_path / f"run{suffix}"
    res = run(short, "--plot", pic)
    assert res.exit_code == 0, res.output
    assert pic.read_bytes().startswith(magic)


def test_trace_every_n_ticks(short):
    res = run(short, "--trace", "--every", 20)
    assert res.exit_code == 0
    assert res.stdout.count("--- tick ") == 4             # ticks 0, 20, 40 and the last
    assert "rules fired" in res.stdout and "perceived:" in res.stdout and "true:" in res.stdout


NOT_RULES = "is not a rule base: no DOF trace, only each tick's pose and inputs)"


@pytest.mark.parametrize("planner", ["dwa", "potential_field"])
def test_trace_of_a_planner_that_is_not_a_rule_base(short, planner):
    """`--planner dwa --trace` printed one line, "(planner dwa is not a rule base: no DOF
    trace)": each traced tick has its pose and inputs, as the fuzzy planner's, without the
    rules, under a line that says so."""
    res = run(short, "--planner", planner, "--trace", "--every", 20)
    assert res.exit_code == 0, res.output
    assert res.stdout.startswith(f"(planner {planner} {NOT_RULES}\n\n--- tick 0, t = 0.00 s: "
                                 f"robot at (30.0, -10.0) in, pose heading 0.0 deg, speed ")
    trace = res.stdout[:res.stdout.index("short: ")]
    ticks = [int(k) for k in re.findall(r"^--- tick (\d+), t = ", trace, re.M)]
    last = json.loads(run(short, "--planner", planner, "--json").stdout)["ticks"] - 1
    assert set(ticks) >= {0, 20, 40, last} and ticks == sorted(set(ticks))
    assert trace.count("\n  perceived: road ") == trace.count("\n  true:      road ") == len(ticks)
    assert "rules fired" not in trace and "fuzzified" not in trace
    fewer = run(short, "--planner", planner, "--trace", "--every", 30).stdout     # --every
    assert set(re.findall(r"^--- tick (\d+), ", fewer, re.M)) >= {"0", "30", str(last)}
    assert "--- tick 20, " not in fewer


@pytest.mark.parametrize("planner", ["fuzzy", "dwa"])
def test_trace_with_json_goes_to_stderr(short, capsys, planner):
    with pytest.raises(SystemExit) as info:
        main(["simulate", str(short), "--planner", planner, "--trace", "--json"])
    out, err = capsys.readouterr()
    assert info.value.code in (0, None)
    assert json.loads(out)["ticks"] > 0                           # stdout: the JSON alone
    assert err.count("--- tick ") >= 3 and "  perceived: " in err and "  true:      " in err
    assert ("rules fired" in err) == (planner == "fuzzy") and (NOT_RULES in err) == (
        planner != "fuzzy")


def test_a_trace_without_rules_is_the_fuzzy_trace_without_its_dof_part(short):
    """The same run traced by a planner that explains (the rules) and by one that does not:
    each tick's head and inputs are the same lines."""
    from mitos_cli.sim import load_world, simulate
    from mitos_cli.sim.export import traces
    from mitos_cli.sim.planner import FuzzyPlanner

    world = load_world(short)
    planner = FuzzyPlanner(None, world.behavior)
    res = simulate(world, planner, world.seed)
    note, *bare = traces(res, object(), 20).split("\n\n")
    assert note == f"(planner fuzzy:drive {NOT_RULES}"
    full = traces(res, planner, 20).split("\n\n--- tick ")
    assert len(bare) == len(full)
    for without, block in zip(bare, full):
        head = block.split("\n\nrule base ")[0]
        assert without == (head if head.startswith("--- tick ") else "--- tick " + head)


def test_require_success_exits_3_when_not_success(short):
    assert run(short, "--require", "success").exit_code == 3
    assert run(short).exit_code == 0


def test_require_takes_only_success(short, capsys):
    """Another name is a usage error (exit 2, with the names), as a planner's is."""
    code, err = run_main(capsys, short, "--require", "collision")
    assert code == 2 and "expected one of success" in err
    code, err = run_main(capsys, short, "--require", "sucess")
    assert code == 2 and "did you mean `success`?" in err


def test_a_bad_option_value_is_a_usage_error_whatever_its_kind(short, capsys):
    """A new user's third review: `--planner dwb` and `--require succes` exited 1 where
    `--seed -1`, `--fps 0` and `--plot x.jpg` exit 2. All are mistakes in the command line:
    exit 2, with "did you mean" where a name is misspelt. A behavior is looked up in the rule
    file, which may be what is wrong: that stays a name error (exit 1)."""
    for args in (["--planner", "dwb"], ["--require", "succes"], ["--seed", "-1"],
                 ["--fps", "0"], ["--plot", "x.jpg"]):
        code, err = run_main(capsys, short, *args)
        assert code == 2, (args, err)
    code, err = run_main(capsys, short, "--planner", "dwb")
    assert "usage error: unknown planner `dwb`" in err and "did you mean `dwa`?" in err
    code, err = run_main(capsys, short, "-b", "driv")
    assert code == 1 and "did you mean `drive`?" in err


def test_an_option_without_the_one_it_tunes_is_a_usage_error(short, capsys, monkeypatch):
    """`--every 5` without `--trace` printed no trace, `--fps 5` without `--animate` drew
    nothing and `-j 4` of one run started no process: each ran without a word."""
    from mitos_cli.sim import loop

    monkeypatch.setattr(loop, "simulate", lambda *a, **k: pytest.fail("the run started"))
    for args, partner in ((["--every", "5"], "--trace"), (["--fps", "5"], "--animate"),
                          (["-j", "2"], "--runs")):
        code, err = run_main(capsys, short, *args)
        assert code == 2 and f"add {partner}" in " ".join(err.replace("│", " ").split()), args


def test_a_plot_that_is_not_a_picture_is_refused_before_the_run(short, capsys, monkeypatch):
    """As `plot -o` refuses it (a usage error, exit 2), not after the run (exit 1)."""
    from mitos_cli.sim import loop

    monkeypatch.setattr(loop, "simulate", lambda *a, **k: pytest.fail("the run started"))
    code, err = run_main(capsys, short, "--plot", "run.jpg")
    assert code == 2 and "`run.jpg` has extension .jpg" in err and ".svg" in err


@pytest.mark.parametrize("option, name", [("--plot", "missing/runs.png"),
                                          ("--out", "missing/run.csv"),
                                          ("--animate", "missing/run.gif"),
                                          ("--out", ".")])
def test_an_output_that_cannot_be_written_is_refused_before_the_run(short, tmp_path, capsys,
                                                                     monkeypatch, option,
                                                                     name):
    """`--runs 1000 --plot typo/runs.png` ran every run, then failed on the picture and lost
    them all: a missing directory (or a directory's name) is refused first."""
    from mitos_cli.sim import loop, runs

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(loop, "simulate", lambda *a, **k: pytest.fail("the run started"))
    monkeypatch.setattr(runs, "run_many", lambda *a, **k: pytest.fail("the runs started"))
    code, err = run_main(capsys, short, option, name)
    assert code == 1 and f"cannot write `{name}`: " in err
    assert ("No such file or directory" in err) != (name == ".")
    if option == "--plot":
        code, err = run_main(capsys, short, "--runs", 3, option, name)
        assert code == 1 and f"cannot write `{name}`: No such file or directory" in err


def test_runs_print_a_table_of_rates(short, tmp_path):
    other = tmp_path / "other.yaml"
    other.write_text(SHORT.replace("name: short", "name: other"), encoding="utf-8")
    res = run(short, other, "--json")
    assert res.exit_code == 0
    rows = json.loads(res.stdout)
    assert len(rows) == 2 and rows[0]["timeout_rate"] == 1.0
    assert [r["world"] for r in rows] == ["short", "other"]
    assert set(rows[0]["time_s"]) == {"mean", "std"}
    table = run(short, "--runs", 2, "--workers", 1).stdout
    assert "success" in table.splitlines()[0] and "±" in table
    # the short world times out: the figures are over every run, each until it ended
    assert ("(time, path, min clear, speed, replans and backed out: mean ± standard deviation "
            "over every run, a collision's or a timeout's until it ended;") in " ".join(
                table.split())


@pytest.mark.parametrize("again", ["{p}", "{d}/./short.yaml", "corridor.yaml"])
def test_a_world_given_twice_is_a_usage_error(short, again):
    """`simulate corridor corridor` ran the world twice and printed two identical rows under
    one name; `compare` refuses it, and so does `simulate` now (exit 2, before any run)."""
    first = "corridor" if again == "corridor.yaml" else str(short)
    res = run(first, again.format(p=short, d=short.parent))
    assert res.exit_code == 2, res.output
    said = " ".join(res.output.replace("│", " ").split())    # the usage box wraps a long path
    assert "is given twice" in said and "success" not in said


def test_runs_report_replans_and_backouts_beside_the_other_figures(short):
    """A run's summary says `replans` and `backed out`; `--runs` said neither, in its table
    or in its JSON (only each run's own summary, under runs_detail, had them)."""
    rows = json.loads(run(short, "--runs", 3, "--workers", 1, "--json").stdout)
    detail = rows[0]["runs_detail"]
    for key in ("replans", "backouts"):
        counts = [s[key] for s in detail]
        assert rows[0][key] == {"mean": pytest.approx(np.mean(counts)),
                                "std": pytest.approx(np.std(counts, ddof=1))}
    table = run(short, "--runs", 3, "--workers", 1).stdout.splitlines()
    assert table[0].split()[-3:] == ["replans", "backed", "out"]
    assert len({len(line) for line in table[:2]}) == 1          # the columns line up


def test_the_runs_table_shows_replans_and_backouts_as_mean_and_spread():
    from mitos_cli.cli.simulate_cmd import _runs_table
    from mitos_cli.sim.runs import Runs, WorldRuns

    def summary(outcome: str, replans: int, backouts: int) -> dict:
        return {"outcome": outcome, "time_s": 10.0, "path_length_in": 300.0,
                "min_clearance_in": 3.0, "mean_speed_in_s": 30.0,
                "steering_total_variation_deg": 10.0, "replans": replans, "backouts": backouts}

    runs = Runs((WorldRuns("w", (summary("success", 2, 0), summary("timeout", 6, 4),
                                 summary("success", 1, 0))),))
    head, row, *note = _runs_table(runs).splitlines()
    assert row.endswith("  3.0 ± 2.6   1.3 ± 2.3")
    assert head.endswith("  replans  backed out") and len(head) == len(row)
    assert "replans and backed out: mean ± standard deviation over every run" in " ".join(note)
    one = Runs((WorldRuns("w", (summary("success", 2, 1),)),))
    assert _runs_table(one).splitlines()[1].endswith("      2.0         1.0")


def test_too_many_runs_is_a_usage_error_not_a_full_memory(short):
    """`--runs 100000000000000000000` listed that many seeds before the first run."""
    res = run(short, "--runs", "1" + "0" * 20)
    said = " ".join(res.output.replace("│", " ").split())
    assert res.exit_code == 2 and "a whole number from 0 to 100000, not `1000" in said


def test_per_run_outputs_need_one_run(short, tmp_path):
    res = run(short, "--runs", 2, "--out", tmp_path / "x.csv")
    assert res.exit_code == 2


def test_a_bad_world_is_exit_1_with_position(tmp_path, capsys):
    p = tmp_path / "bad.yaml"
    p.write_text(SHORT.replace("dt: 0.05", "dtt: 0.05"), encoding="utf-8")
    code, err = run_main(capsys, p)
    assert code == 1
    assert "bad.yaml:3:1" in err and "did you mean `dt`?" in err


def test_a_rule_base_without_the_inputs_is_refused(short, tmp_path, capsys):
    rules = tmp_path / "x.rules"
    terms = tmp_path / "x.terms.yaml"
    terms.write_text("variables:\n  speedometer:\n    role: input\n    universe: [0, 1]\n"
                     "    terms: {LOW: {shape: left_shoulder, points: [0, 1]}}\n"
                     "  steering:\n    role: output\n    universe: [30, 150]\n"
                     "    terms: {ST: 90}\n  speed:\n    role: output\n    universe: [0, 60]\n"
                     "    terms: {SLOW: 20}\n", encoding="utf-8")
    rules.write_text('terms "x.terms.yaml"\nbehavior drive:\n  if speedometer is LOW then '
                     'steering is ST and speed is SLOW\nend\n', encoding="utf-8")
    code, err = run_main(capsys, short, "--rulebase", rules)
    assert code == 1 and "does not perceive" in err


def test_json_says_near_miss_as_the_text_does(tmp_path):
    text = (Path(__file__).parents[1] / "worlds" / "corridor.yaml").read_text()
    world = tmp_path / "close.yaml"
    world.write_text(text.replace("safety_margin: 2 ", "safety_margin: 9 "))
    shown = CliRunner().invoke(app, ["simulate", str(world)])
    assert shown.exit_code == 0 and "closer than the safety margin (9 in)" in shown.stdout
    data = json.loads(CliRunner().invoke(app, ["simulate", str(world), "--json"]).stdout)
    assert data["near_miss"] is True and data["outcome"] == "success"
    data = json.loads(CliRunner().invoke(app, ["simulate", "corridor.yaml", "--json"]).stdout)
    assert data["near_miss"] is False


def test_the_verdict_prints_a_clearance_on_the_side_of_the_margin_it_lies():
    from types import SimpleNamespace

    from mitos_cli.cli.simulate_cmd import _summary, _verdict
    from mitos_cli.sim.world import Robot

    def run(clear: float, outcome: str = "success") -> SimpleNamespace:
        agent = SimpleNamespace(name="robot", robot=Robot())
        m = {"outcome": outcome, "reached_goal": True, "collisions": 0, "time_s": 1.0,
             "ticks": 20, "path_length_in": 1.0, "mean_speed_in_s": 1.0,
             "min_clearance_in": clear, "steering_total_variation_deg": 0.0, "replans": 0,
             "backouts": 0}
        return SimpleNamespace(metrics=m, world=SimpleNamespace(agents=[agent], name="w"),
                               robot_metrics=[m], outcome=outcome, robot_outcomes=[outcome],
                               seed=1, planner="fuzzy:drive", summary=lambda: m)

    assert _verdict(run(1.99)).endswith(
        "min clearance 1.99 in; closer than the safety margin (2 in)")
    assert "  min clearance             1.99 in\n" in _summary(run(1.99))
    assert _verdict(run(2.01)).endswith("min clearance 2.0 in")
    assert _verdict(run(-0.03, "collision")).endswith("min clearance 0.0 in")
    assert "  min clearance             0.0 in\n" in _summary(run(-0.03, "collision"))
    assert _verdict(run(-0.1, "collision")).endswith("min clearance -0.1 in")


def test_the_verdict_names_every_robot_that_came_closer_than_its_margin():
    """Of two robots, `closer than the safety margin (two) (2 in)` read as a margin named
    `two`, and a second robot as close was not named."""
    from dataclasses import replace
    from types import SimpleNamespace

    from mitos_cli.cli.simulate_cmd import _verdict
    from mitos_cli.sim.world import Robot

    def run(*clears: float, margins: tuple[float, ...] = (2, 2)) -> SimpleNamespace:
        agents = [SimpleNamespace(name=n, robot=replace(Robot(), safety_margin=m))
                  for n, m in zip(("robot", "two"), margins)]
        each = [{"min_clearance_in": c} for c in clears]
        m = {"time_s": 1.0, "min_clearance_in": min(clears)}
        return SimpleNamespace(metrics=m, world=SimpleNamespace(agents=agents, name="w"),
                               robot_metrics=each, outcome="success",
                               robot_outcomes=["success"] * 2, seed=1, planner="fuzzy:drive")

    assert _verdict(run(2.2, 0.4)).endswith(
        "min clearance 0.4 in; two came closer than its safety margin (2 in)")
    assert _verdict(run(1.1, 1.1)).endswith(
        "min clearance 1.1 in; robot and two came closer than their safety margin (2 in)")
    assert _verdict(run(2.5, 2.5, margins=(3, 2))).endswith(
        "min clearance 2.5 in; robot came closer than its safety margin (3 in)")
    assert _verdict(run(1.5, 2.5, margins=(2, 3))).endswith(
        "min clearance 1.5 in; robot came closer than its safety margin (2 in), two than its "
        "(3 in)")
    assert _verdict(run(2.5, 2.5)).endswith("min clearance 2.5 in")


def test_one_run_shows_no_spread():
    out = CliRunner().invoke(app, ["simulate", "corridor.yaml", "--runs", "1"]).stdout
    row = out.splitlines()[1].split()
    assert "±" not in out and row[0] == "corridor" and float(row[-3]) > 0     # the speed
    (run,) = json.loads(CliRunner().invoke(app, ["simulate", "corridor.yaml", "--runs", "1",
                                                 "--json"]).stdout)[0]["runs_detail"]
    assert row[-2:] == [f"{run['replans']:.1f}", f"{run['backouts']:.1f}"]


@pytest.mark.parametrize("option", [["--speed", "nan"], ["--fps", "nan", "--animate", "a.gif"]])
def test_a_nan_option_is_a_usage_error(short, option):
    res = run(short, *option)
    said = " ".join(res.output.replace("│", " ").split())
    assert res.exit_code == 2 and "must be" in said and "not `nan`" in said


@pytest.mark.parametrize("given", ["4.9e-324", "1e-310", "1e-400", "0.0009", "-1", "abc"])
def test_a_speed_too_slow_to_pace_is_a_usage_error(short, given):
    """`--speed 4.9e-324` waited 1e323 seconds for its first tick: past what `time.sleep`
    takes, a traceback (and `1e-9` thirty years per simulated second)."""
    res = run(short, "--speed", given)
    said = " ".join(res.output.replace("│", " ").split())
    assert res.exit_code == 2, res.output
    assert ("the real-time factor must be 0 (as fast as it can) or a number of 0.001 or more, "
            f"not `{given}`") in said


def test_an_empty_behavior_is_a_usage_error(short):
    res = run(short, "-b", "")
    assert res.exit_code == 2 and "must name something" in res.output


@pytest.mark.parametrize("args", [
    ["simulate", ""], ["simulate", "corridor", ""], ["simulate", "corridor", "--rulebase", ""],
    ["compare", "", "--runs", "1"], ["teach", ""], ["teach", "--lesson", ""],
    ["eval", "", "x=1"], ["check", ""],
    ["compare", "corridor", "--runs", "1", "-o", ""],     # wrote its study into the cwd
    ["eval", "--batch", ""],
    # Path-typed: Click made `''` the current directory before any check saw it
    ["simulate", "corridor", "-o", ""], ["simulate", "corridor", "--plot", ""],
    ["simulate", "corridor", "--animate", ""],
    ["convert", "rulebases/mitos.rules", "--to", "fcl", "-o", ""], ["convert", "", "--to", "fcl"],
    ["export", "rulebases/mitos.rules", "--to", "c", "-o", ""], ["export", "", "--to", "c"],
])
def test_an_empty_path_is_a_usage_error(args):
    """`Path('')` is the current directory: an empty world, rule file or lesson was "``
    is a directory, not a world file", exit 1, where the same empty `-b` is a usage error."""
    res = CliRunner().invoke(app, args)
    said = re.sub(r"[\s\u2502]+", " ", res.output)          # (the box Click draws wraps it)
    assert res.exit_code == 2 and "must name something, not be empty" in said
    assert "directory" not in said


@pytest.mark.parametrize("args", [
    ["simulate", "corridor", "-o", "d.csv/"],
    ["simulate", "corridor", "--plot", "run.png/"],
    ["convert", "rulebases/mitos.rules", "--to", "fcl", "-o", "x.fcl/"],
    ["export", "rulebases/mitos.rules", "--to", "c", "-o", "x.c/"],
    ["plot", "terms", "rulebases/mitos.rules", "--var", "road", "-o", "p.png/"],
])
def test_a_file_named_with_a_trailing_slash_is_a_usage_error(args, tmp_path, monkeypatch):
    """`Path('d.csv/')` is `d.csv`: the slash, which names a directory, was dropped and a
    file written under the name without it."""
    monkeypatch.chdir(tmp_path)
    root = Path(__file__).parents[1]
    args = [str(root / a) if a.startswith("rulebases/") else a for a in args]
    res = CliRunner().invoke(app, args)
    said = re.sub(r"[\s\u2502]+", " ", res.output)
    assert res.exit_code == 2 and "so it names a directory, not a file" in said
    assert list(tmp_path.iterdir()) == []


def test_a_file_named_without_its_extension_gets_the_file_as_its_did_you_mean(
        tmp_path, capsys, monkeypatch):
    """`mitos simulate tiny` beside `tiny.yaml` (night 24's fuzzing) said "world file `tiny`
    not found" and listed the packaged worlds, with no word of the file there; `mitos check
    my` beside `my.rules`, and `--lesson a` beside `a.lesson`, said only "not found": the
    name is too far from `tiny.yaml` for the closest-name match."""
    root = Path(__file__).parents[1]
    monkeypatch.chdir(tmp_path)
    (tmp_path / "tiny.yaml").write_text((root / "tests" / "data" / "tiny.yaml").read_text())
    (tmp_path / "my.rules").write_text("")
    (tmp_path / "a.lesson").write_text("quit\n")
    assert run_main(capsys, "tiny") == (1, (
        "world error: world file `tiny` not found\n"
        "expected one of the packaged worlds: corridor, detour, figure4, intersection, moving, "
        "multirobot, office, slalom\n"
        "hint: did you mean `tiny.yaml`?\n"))
    with pytest.raises(SystemExit) as info:
        main(["check", "my"])
    assert (info.value.code, capsys.readouterr().err) == (1, (
        "rule base error: rule file `my` not found\nhint: did you mean `my.rules`?\n"))
    with pytest.raises(SystemExit) as info:
        main(["teach", str(root / "rulebases" / "mitos.rules"), "--lesson", "a",
              "--save-as", "o.rules"])
    assert (info.value.code, capsys.readouterr().err) == (1, (
        "lesson error: lesson `a` not found\n"
        "expected a lesson file, or a packaged lesson: wider-turn\n"
        "hint: did you mean `a.lesson`?\n"))
    assert run_main(capsys, "slalm")[1].endswith("hint: did you mean `slalom`?\n")


def test_a_world_that_is_a_link_to_nothing_is_said_so(tmp_path, capsys, monkeypatch):
    """A loop or a dangling link was "world file `loop1.yaml` not found", with "did you mean
    `loop1.yaml`?"."""
    monkeypatch.chdir(tmp_path)
    Path("loop1.yaml").symlink_to("loop2.yaml")
    Path("loop2.yaml").symlink_to("loop1.yaml")
    Path("dangling.yaml").symlink_to("nonexist.yaml")
    assert run_main(capsys, "loop1.yaml") == (1, (
        "world error: cannot read world file `loop1.yaml`: Too many levels of symbolic links\n"))
    with pytest.raises(SystemExit) as info:
        main(["compare", "dangling.yaml", "--runs", "1", "-o", "s"])
    assert (info.value.code, capsys.readouterr().err) == (1, (
        "world error: `dangling.yaml` is a link to `nonexist.yaml`, which does not exist\n"))


def test_an_output_is_never_an_input_nor_another_output(short, capsys):
    before = short.read_bytes()
    code, err = run_main(capsys, short, "--out", short)       # replaced the world with a CSV
    said = " ".join(err.replace("│", " ").split())
    assert code == 2 and "is a file this command reads" in said
    assert short.read_bytes() == before
    same = short.parent / "same.png"
    code, err = run_main(capsys, short, "--out", same, "--plot", same)
    said = " ".join(err.replace("│", " ").split())
    assert code == 2 and "is named by --out too" in said and not same.exists()


def test_randomise_with_runs_says_why(short, capsys):
    code, err = run_main(capsys, short, "--randomise", "--runs", 2)
    said = " ".join(err.replace("│", " ").split())
    assert code == 2 and "--runs randomises every run already" in said     # was "give one world"


def test_one_run_options_say_the_way_out_that_fits(short, capsys, tmp_path):
    """`simulate corridor --runs 3 --out x.csv` said "drop --runs or give one world" to a user
    who gave one world: the message names the options given and the one way out that fits."""
    csv = tmp_path / "x.csv"
    cases = [((short, "--runs", 3, "--out", csv),
              "--out works on one run of one world, not --runs 3: drop --runs (--randomise "
              "--seed SEED replays one randomised run)"),
             ((short, short.with_name("other.yaml"), "--trace"),
              "--trace works on one run of one world, not 2 worlds: give one world"),
             ((short, short.with_name("other.yaml"), "--runs", 2, "--speed", 3, "--out", csv),
              "--out and --live/--speed work on one run of one world, not 2 worlds and --runs "
              "2: drop --runs and give one world")]
    short.with_name("other.yaml").write_text(short.read_text())
    for args, message in cases:
        code, err = run_main(capsys, *args)
        said = " ".join(err.replace("│", " ").split())
        assert code == 2 and message in said, said
        assert "or give one world" not in said
    assert not csv.exists()


def test_a_pattern_the_shell_did_not_expand_is_said_to_be_one(capsys, tmp_path, monkeypatch):
    """The README's `mitos simulate worlds/*.yaml --runs 20` away from the checkout reached
    MITOS as the pattern itself ("world file `worlds/*.yaml` not found", and a hint about
    `mitos list` that did not say why): the hint says no file matched the pattern."""
    monkeypatch.chdir(tmp_path)
    code, err = run_main(capsys, "worlds/*.yaml", "--runs", 2)
    assert code == 1 and err.splitlines() == [
        "world error: world file `worlds/*.yaml` not found",
        "hint: no file here matches the pattern, so the shell passed `worlds/*.yaml` on as "
        "written; the packaged worlds go by name: `mitos list` shows them"]


def test_a_rule_base_without_the_worlds_behavior_says_how_to_choose_one(short, capsys):
    """`mitos simulate figure4 --rulebase tipper.fis` stood at the world's `behavior: drive`
    with "unknown behavior `drive`, expected one of main" and no word of how to go on."""
    tipper = Path(__file__).parent / "data" / "interop" / "tipper.fis"
    code, err = run_main(capsys, short, "--rulebase", tipper)
    assert code == 1 and "unknown behavior `drive`" in err
    assert err.splitlines()[-1] == (
        "hint: the world is driven by its `behavior: drive`, which this rule base lacks: "
        "choose one of its behaviors (--behavior NAME; behavior= from Python)")


def test_one_runs_spread_is_null_as_in_compare(short):
    data = json.loads(run(short, "--runs", 1, "--json").stdout)
    row = data[0] if isinstance(data, list) else data["worlds"][0]
    assert row["time_s"]["std"] is None            # was 0.0; compare --json says null


@pytest.mark.parametrize("name, has", [("run.txt", "extension .txt"),
                                       ("run.json", "extension .json"),
                                       ("run", "no extension")])
def test_out_that_is_not_a_csv_is_refused_before_the_run(short, tmp_path, capsys, monkeypatch,
                                                         name, has):
    """As --plot, --animate and convert -o: a usage error (exit 2), before the run."""
    from mitos_cli.sim import loop

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(loop, "simulate", lambda *a, **k: pytest.fail("the run started"))
    code, err = run_main(capsys, short, "--out", name)
    said = " ".join(err.replace("│", " ").split())
    assert code == 2 and f"`{name}` has {has}; the table of ticks (--out) is written to a .csv " \
        "file" in said
    assert not (tmp_path / name).exists()


def test_out_takes_any_case_of_csv_and_a_device(short, tmp_path, capsys):
    code, _ = run_main(capsys, short, "--out", tmp_path / "RUN.CSV")
    assert code == 0 and (tmp_path / "RUN.CSV").read_text().startswith("tick,t,")
    code, _ = run_main(capsys, short, "--out", "/dev/null")
    assert code == 0


def test_the_trace_says_one_object_not_one_objects():
    from mitos_cli import load_rulebase

    trace = load_rulebase(None, "drive").trace(**{
        k: v for k, v in dict(road=100, size=0, position=50, obstacle=0, heading=0, lane=0,
                              goal=500, gap_left=60, gap_right=60, front=150, opening=0,
                              clutter=1, nearest=60).items()})
    text = trace.render()
    assert "clutter = 1 object" in text and "1 objects" not in text



def _raw_and_commanded(world: Path, tmp_path: Path) -> tuple[np.ndarray, np.ndarray]:
    """The rules' own speed for every row of `simulate --out` (what `eval --batch` gives)
    and the row's `cmd_speed`."""
    from mitos_cli.engine.csvio import read_batch
    from mitos_cli.engine.evaluation import evaluate
    from mitos_cli.sim.planner import FuzzyPlanner

    out = tmp_path / f"{world.stem}.csv"
    assert run(world, "--out", out).exit_code == 0
    compiled = FuzzyPlanner().compiled
    text = out.read_text()
    raw = evaluate(compiled, read_batch(text, str(out), compiled.inputs)).outputs
    table = list(csv.DictReader(io.StringIO(text)))
    return raw[:, compiled.outputs.index("speed")], np.array([float(r["cmd_speed"])
                                                              for r in table])


def test_cmd_speed_is_the_command_after_the_brake(tmp_path):
    """A new user's third review: the docs called `cmd_speed` "the speed the planner asked
    for", but the robot's own brake caps it (24.9 in/s with 10 in free, a tick counted, where the rules asked
    33). As worlds/README.md now says: the brake only ever lowers it, and without the brake
    it is the rules' own request (to the CSV's rounding)."""
    from mitos_cli.sim.worldfile import resolve_world_path

    slalom = resolve_world_path("slalom")
    raw, cmd = _raw_and_commanded(slalom, tmp_path)
    assert (cmd <= raw + 1e-3).all() and (cmd < raw - 5).any()       # capped by a pole
    free = tmp_path / "free.yaml"
    free.write_text(slalom.read_text().replace("robot:\n", "robot:\n  brake: false\n", 1))
    raw, cmd = _raw_and_commanded(free, tmp_path)
    assert np.allclose(raw, cmd, atol=1e-3)


def test_the_readme_says_the_default_trace_size(capsys):
    """README.md said the default `simulate --trace` is "about 45 KB": it is 39,477 bytes.
    The figure, and that it fits in a pipe's 64 KiB (why `| head -1` races), are checked."""
    readme = (Path(__file__).parents[1] / "README.md").read_text(encoding="utf-8")
    said = re.search(r"a trace every 20 ticks, about (\d+) KB, less than the\s+pipe's 64 KiB",
                     readme)
    assert said is not None
    with pytest.raises(SystemExit) as info:
        main(["simulate", "--trace"])
    size = len(capsys.readouterr().out.encode("utf-8"))
    assert info.value.code in (0, None)
    assert abs(size / 1000 - int(said.group(1))) < 1 and size < 64 * 1024, size


@pytest.mark.parametrize("planner", ["fuzzy", "dwa"])
def test_a_trace_of_a_robot_at_its_goal_from_the_start_says_so(tmp_path: Path, planner):
    """A robot that starts at its goal drives no tick: `--trace` printed a bare blank line."""
    world = tmp_path / "there.yaml"
    world.write_text(SHORT.replace("q_goal: {x: 500, y: -10}", "q_goal: {x: 30, y: -10}"),
                     encoding="utf-8")
    res = run(world, "--trace", "--planner", planner)
    assert res.exit_code == 0, res.output
    assert "(robot drove no tick: it stood at its goal from the start)\n" in res.stdout
    assert not res.stdout.startswith("\n")


def test_runs_table_never_rounds_a_rate_to_none_or_all():
    """1 collision in 200 runs read `0%` (and 199 successes `100%`) in `simulate --runs`."""
    from mitos_cli.cli.simulate_cmd import _runs_table
    from mitos_cli.sim.runs import METRICS, Runs, WorldRuns

    summaries = tuple({"outcome": "collision" if i == 0 else "success",
                       **dict.fromkeys(METRICS, 1.0)} for i in range(200))
    row = _runs_table(Runs((WorldRuns("w", summaries),))).splitlines()[1].split()
    assert row[:6] == ["w", "200", "99.5%", "0.5%", "0%", "0%"]


def test_runs_of_a_world_that_randomises_nothing_are_said_to_be_copies(short):
    """`--runs 3` of a world with no `randomise:` range and no sensor noise ran one run three
    times, its `± 0.0` read as a spread of three runs, without a word."""
    said = "the world randomises nothing (no `randomise:` range, no sensor noise): its 2 runs " \
           "are one run 2 times"
    res = run(short, "--runs", 2)
    assert res.exit_code == 0 and said in res.stderr
    assert "randomises nothing" not in run(short).stderr                    # one run, as written
    noisy = short.with_name("noisy.yaml")
    noisy.write_text(SHORT + "randomise:\n  sensor_noise: [0, 1]\n", encoding="utf-8")
    assert "randomises nothing" not in run(noisy, "--runs", 2).stderr


def test_a_ctrl_c_while_the_runs_files_are_written_says_which_are_there(
        tmp_path: Path, capsys, monkeypatch) -> None:
    """Ctrl-C while `--plot` drew (after `--out` was written) ended the command with exit 130
    and not a word: run.csv was there, and nothing said so."""
    import mitos_cli.draw.world as world_draw

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(world_draw, "draw_run", interrupted)
    out, plot = tmp_path / "run.csv", tmp_path / "run.png"
    with pytest.raises(SystemExit) as info:
        main(["simulate", "corridor", "--out", str(out), "--plot", str(plot)])
    err = capsys.readouterr().err
    assert info.value.code == 130
    assert err.endswith(f"interrupted: wrote the ticks to {out}; the rest is not written\n"), err
    assert out.is_file() and not plot.exists()


def test_runs_default_to_no_more_processes_than_the_cpus_allowed(monkeypatch) -> None:
    """`simulate --runs`' default -j counted the machine's CPUs: under `taskset -c 0` it
    started two processes on one CPU, where `compare` counts the CPUs allowed. It was also
    capped at 2, so an 8-core machine ran `--runs 1000` on a quarter of its cores; the engine's
    threads, `simulate` and `compare` now count the CPUs in one place."""
    import os

    from mitos_cli import machine
    from mitos_cli.engine.threads import thread_count
    from mitos_cli.sim.runs import default_workers
    from mitos_cli.study import executors

    if not hasattr(os, "sched_getaffinity"):
        pytest.skip("no CPU affinity on this platform")
    monkeypatch.delenv("MITOS_NUM_THREADS", raising=False)
    monkeypatch.setattr(machine, "available_memory", lambda: None)
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0})
    monkeypatch.setattr(os, "cpu_count", lambda: 8)
    assert default_workers() == 1 and thread_count() == 1
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0, 1, 2})
    assert default_workers() == 3 and thread_count() == 3
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: set(range(8)))
    assert default_workers() == 8 and thread_count() == 4       # threads: at most DEFAULT_MAX
    assert not hasattr(executors, "default_workers")            # one count, not three


def test_runs_default_to_the_workers_the_memory_available_holds(monkeypatch) -> None:
    """Each worker steps a lockstep batch of up to 128 runs with their maps (0.7 GB for
    `office`): on 8 CPUs with 2 GB free, 8 workers of office would swap or be killed. The
    default takes what the memory holds, at least one; a world of small maps takes more."""
    import os

    from mitos_cli import machine
    from mitos_cli.resources import packaged_path
    from mitos_cli.sim.lockstep import batch_for, map_bytes
    from mitos_cli.sim.runs import RUN_BYTES, WORKER_BYTES, default_workers
    from mitos_cli.sim.worldfile import load_world

    if not hasattr(os, "sched_getaffinity"):
        pytest.skip("no CPU affinity on this platform")
    office = load_world(packaged_path("worlds", "office.yaml"))
    slalom = load_world(packaged_path("worlds", "slalom.yaml"))
    per = WORKER_BYTES + batch_for(office) * (map_bytes(office) + RUN_BYTES)
    assert 0.5e9 < per < 1e9            # about what /usr/bin/time measured: 701 MB
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: set(range(8)))
    free = 2 * per + per // 2
    monkeypatch.setattr(machine, "available_memory", lambda: free)
    assert default_workers([office]) == 2
    assert default_workers([slalom, office]) == 2                # the largest batch counts
    small = WORKER_BYTES + batch_for(slalom) * (map_bytes(slalom) + RUN_BYTES)
    assert default_workers([slalom]) == free // small > 2
    monkeypatch.setattr(machine, "available_memory", lambda: per // 3)
    assert default_workers([office]) == 1


def test_a_second_planner_given_apart_is_said_to_be_a_planner(capsys):
    """`mitos simulate slalom --planner dwa potential_field` read `potential_field` as a world
    ("world file `potential_field` not found", exit 1): simulate drives with one planner."""
    code, err = run_main(capsys, "slalom", "--planner", "dwa", "potential_field")
    flat = " ".join(err.replace("│", " ").split())
    assert code == 2
    assert ("`potential_field` is a planner, read here as a world: simulate drives with one "
            "(--planner NAME); `mitos compare --planner dwa,potential_field` compares them") in flat
