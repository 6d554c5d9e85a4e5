"""``mitos eval`` end to end: golden outputs and the --json / --batch contract.

Golden cases live in ``tests/golden/<case>/``: ``cmd`` (one command line, run from the
repository root in a fresh process), optional ``stdin``, and the expected ``stdout``.
Regenerate them after a deliberate change with ``MITOS_UPDATE_GOLDEN=1 pytest
tests/test_cli_eval.py`` and review the diff.
"""

from __future__ import annotations

import io
import json
import os
import shlex
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from mitos_cli import load_rulebase
from mitos_cli.cli.app import main
from mitos_cli.engine.csvio import read_batch
from mitos_cli.errors import InputError

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = ROOT / "tests" / "golden"
CASES = sorted(p.name for p in GOLDEN.iterdir() if (p / "cmd").is_file())


def run_cli(argv: list[str], stdin: str | None = None,
            cwd: Path = ROOT) -> subprocess.CompletedProcess:
    env = dict(os.environ, COLUMNS="100", NO_COLOR="1")
    return subprocess.run([sys.executable, "-m", "mitos_cli", *argv], cwd=cwd, input=stdin,
                          capture_output=True, text=True, timeout=120, env=env)


@pytest.mark.parametrize("case", CASES)
def test_golden(case, tmp_path):
    folder = GOLDEN / case
    argv = shlex.split((folder / "cmd").read_text(encoding="utf-8"))
    assert argv[0] == "mitos"
    stdin = (folder / "stdin").read_text(encoding="utf-8") if (folder / "stdin").exists() \
        else None
    # a teaching session's journal lives where the command runs: not in the repository, where
    # `mitos teach --resume` would continue the test's session (the packaged files are found
    # from anywhere)
    proc = run_cli(argv[1:], stdin, cwd=tmp_path if argv[1] == "teach" else ROOT)
    expected_code = int((folder / "exit_code").read_text()) if (folder / "exit_code").exists() \
        else 0
    if os.environ.get("MITOS_UPDATE_GOLDEN"):
        (folder / "stdout").write_text(proc.stdout, encoding="utf-8")
    assert proc.returncode == expected_code, proc.stderr
    assert proc.stdout == (folder / "stdout").read_text(encoding="utf-8")
    assert "Traceback" not in proc.stderr


def run_main(args, capsys):
    with pytest.raises(SystemExit) as info:
        main(args)
    out, err = capsys.readouterr()
    return info.value.code, out, err


@pytest.fixture(scope="module")
def rb():
    return load_rulebase()


def test_json_matches_the_library(rb, capsys):
    code, out, err = run_main(["eval", "road=78", "size=45", "position=4", "--json"], capsys)
    assert code == 0 and err == ""
    data = json.loads(out)
    assert {"rulebase", "inputs", "rules", "outputs"} <= set(data)
    trace = rb.trace(road=78, size=45, position=4)
    assert data == json.loads(json.dumps(trace.to_json()))
    assert data["outputs"] == rb.evaluate(road=78, size=45, position=4)
    assert [r["label"] for r in data["rules"]] == ["r4", "r5", "r7", "r8", "r22", "r23", "r25",
                                                   "r26"]
    assert all(set(r) == {"label", "text", "dof"} and r["dof"] > 0 for r in data["rules"])
    assert data["inputs"]["road"] == {"value": 78.0, "given": 78.0, "clamped": False,
                                      "memberships": {
        "NARROW": 0.0, "MEDIUM": pytest.approx(22 / 30), "WIDE": pytest.approx(8 / 30)}}


def test_batch_equals_single_evaluations(rb, capsys, tmp_path):
    rng = np.random.default_rng(np.random.SeedSequence(2))
    lo, hi = rb.compiled.universe[:, 0], rb.compiled.universe[:, 1]
    X = rng.uniform(lo, hi, size=(50, 3)).round(3)
    csv = tmp_path / "in.csv"
    csv.write_text("position,road,size\n" + "\n".join(
        f"{p},{r},{s}" for r, s, p in X) + "\n", encoding="utf-8")
    code, out, err = run_main(["eval", "--batch", str(csv)], capsys)
    assert code == 0 and err == ""
    header, *rows = out.splitlines()
    assert header == "road,size,position,steering,speed"
    table = np.loadtxt(io.StringIO("\n".join(rows)), delimiter=",")
    assert np.array_equal(table[:, :3], X)
    for row in table:
        single = rb.evaluate(road=row[0], size=row[1], position=row[2])
        assert row[3] == pytest.approx(single["steering"], rel=1e-11)
        assert row[4] == pytest.approx(single["speed"], rel=1e-11)


def test_batch_warns_about_clamping(capsys, tmp_path):
    csv = tmp_path / "in.csv"
    csv.write_text("road,size,position\n500,45,4\n78,45,4\n999,45,4\n", encoding="utf-8")
    code, out, err = run_main(["eval", "--batch", str(csv)], capsys)
    assert code == 0
    assert err == "warning: `road` outside its universe [0, 160] was clamped (2 samples)\n"
    rows = [line.split(",") for line in out.splitlines()[1:]]
    assert [r[0] for r in rows] == ["500", "78", "999"]     # the inputs as given
    assert rows[0][3:] == rows[2][3:]                          # both evaluated at road = 160


@pytest.mark.parametrize("text, message", [
    ("", "the batch CSV is empty"),
    ("road,size,positon\n1,2,3\n", "column `positon` is passed through as it is: did you mean "
                                     "`position`?"),
    ("road,size,road\n1,2,3\n", "batch column `road` is named twice (columns 1 and 3)"),
    ("road,size\n1,2\n", "the batch CSV has no column for position"),
    ("road,size,position\n1,2\n", "row has 2 values, the header 3"),
    ("road,size,position\n1,2,x\n", "`x` is not a number"),
    ("road,size,position\n1,nan,3\n", "input `size` is not a number (NaN)"),
])
def test_batch_errors(capsys, tmp_path, text, message):
    csv = tmp_path / "in.csv"
    csv.write_text(text, encoding="utf-8")
    code, out, err = run_main(["eval", "--batch", str(csv)], capsys)
    assert code == 1 and message in err and out == ""


def test_a_batch_that_is_not_utf8_is_placed_at_its_byte(capsys, tmp_path, monkeypatch):
    """The fuzz audit: the place was in prose only, where every other reader puts it first.
    (Named relative: a long temporary path is shortened in the message.)"""
    monkeypatch.chdir(tmp_path)
    csv = Path("bad.csv")
    csv.write_bytes(b"road,size,position\n78,45,4\n78,\xff,4\n")
    code, out, err = run_main(["eval", "--batch", str(csv)], capsys)
    assert code == 1 and err.startswith(f"{csv}:3:4: input error: cannot read batch file `{csv}`: "
                                        "it is not UTF-8 text (byte 0xff at line 3, column 4)")
    proc = subprocess.run([sys.executable, "-m", "mitos_cli", "eval", "--batch", "-"], cwd=ROOT,
                          input=csv.read_bytes(), capture_output=True, timeout=120)
    assert proc.returncode == 1
    assert proc.stderr.decode().startswith("<stdin>:3:4: input error: cannot read the batch from "
                                           "stdin: it is not UTF-8 text")


def test_batch_passes_other_columns_through(capsys, tmp_path):
    """Columns that are not inputs come out after the outputs as they went in (text, quotes,
    empty cells); one named like an output is written as `given_NAME`."""
    csv = tmp_path / "in.csv"
    csv.write_text('id,road,size,note,position,steering\n'
                   'a,78,45,"x, y",4,1\n'
                   'b,100,65,,18,2\n', encoding="utf-8")
    code, out, err = run_main(["eval", "--batch", str(csv)], capsys)
    assert code == 0
    assert "`steering` as `given_steering`" in err
    lines = out.splitlines()
    assert lines[0] == "road,size,position,steering,speed,id,note,given_steering"
    assert lines[1].startswith("78,45,4,65.41125541125541,32.42424242424243,")
    assert lines[1].endswith(',a,"x, y",1') and lines[2].endswith(",b,,2")


def test_batch_reads_a_simulate_out_csv(capsys, tmp_path):
    """`simulate --out` feeds `eval --batch -b drive`: the outputs are the planner's commands."""
    import csv as csvmod

    run = tmp_path / "run.csv"
    code, _, _ = run_main(["simulate", str(ROOT / "worlds" / "corridor.yaml"), "--out",
                           str(run)], capsys)
    assert code == 0
    code, out, _ = run_main(["eval", "-b", "drive", "--batch", str(run)], capsys)
    assert code == 0
    given = list(csvmod.DictReader(run.open(encoding="utf-8")))
    got = list(csvmod.DictReader(out.splitlines()))
    assert len(got) == len(given) and got[0]["pose_heading_deg"] == given[0]["pose_heading_deg"]
    for a, b in zip(given, got):
        assert float(b["steering"]) == pytest.approx(float(a["cmd_steering"]), abs=1e-3)
        assert b["given_steering"] == a["steering"] and b["fired"] == a["fired"]


@pytest.mark.parametrize("text, message, where", [
    ("road,size,position\n1,2,3\n4,,6\n", "input `size` is empty in row 2 (column 2)",
     "in.csv:3:3"),
    ("id,road,size,position\nx,1,2,3\n\n\"q, r\",4,5,\n", "input `position` is empty in row 2",
     "in.csv:4:12"),
    ("road,size,position\n1,nan,3\n", "input `size` is not a number (NaN) in row 1", "in.csv:2:3"),
    ("road,size,position,id\n1,2,x,a\n", "`x` is not a number (input `position`, row 1)",
     "in.csv:2:5"),
])
def test_batch_cell_errors_name_column_row_and_position(text, message, where):
    with pytest.raises(InputError) as info:
        read_batch(text, "in.csv", ("road", "size", "position"))
    assert message in str(info.value.message) and str(info.value.span) == where


def test_batch_unused_inputs_and_no_rule_still_work(capsys, tmp_path):
    """Inputs the behavior's rules never test (`size`, `position`) are read and come out
    passed through; `--on-no-rule` still adds its `no_rule` column last, after them."""
    terms = (ROOT / "rulebases" / "mitos.terms.yaml").read_text(encoding="utf-8")
    (tmp_path / "t.terms.yaml").write_text(terms, encoding="utf-8")
    (tmp_path / "t.rules").write_text(
        'terms "t.terms.yaml"\nif road is WIDE then speed is FAST\n', encoding="utf-8")
    csv = tmp_path / "in.csv"
    csv.write_text("road,size,position,id\n120,45,4,a\n10,1,2,b\n", encoding="utf-8")
    code, out, _ = run_main(["eval", str(tmp_path / "t.rules"), "--batch", str(csv),
                             "--on-no-rule", "nan"], capsys)
    assert code == 0
    lines = out.splitlines()
    assert lines[0] == "road,speed,size,position,id,no_rule"
    assert lines[1].endswith(",45,4,a,") and lines[2].endswith(",1,2,b,speed")
    code, out, _ = run_main(["eval", str(tmp_path / "t.rules"), "--batch", str(csv),
                             "--on-no-rule", "skip"], capsys)
    assert code == 0 and out.splitlines()[1:] == [out.splitlines()[1]]


def test_batch_error_positions():
    with pytest.raises(Exception) as info:
        read_batch("road,size,position\n1,2,3\n4,five,6\n", "in.csv", ("road", "size", "position"))
    assert str(info.value.span) == "in.csv:3:3"


def test_batch_and_values_are_exclusive(capsys):
    code, _, err = run_main(["eval", "--batch", "-", "road=1"], capsys)
    assert code == 2 and "not both" in err


def test_batch_refuses_json(capsys):
    """--batch writes CSV: --json beside it is refused, not silently ignored."""
    code, out, err = run_main(["eval", "--batch", "-", "--json"], capsys)
    assert code == 2 and out == "" and "--batch writes a CSV; --json is for one evaluation" \
        in " ".join(err.replace("│", " ").split())


def test_behavior_option(tmp_path, capsys):
    terms = (ROOT / "rulebases" / "mitos.terms.yaml").read_text(encoding="utf-8")
    (tmp_path / "t.terms.yaml").write_text(terms, encoding="utf-8")
    (tmp_path / "t.rules").write_text(
        'terms "t.terms.yaml"\nbehavior cruise:\n  if road is WIDE then speed is FAST\nend\n'
        "behavior careful:\n  if road is WIDE then speed is SLOW\nend\n", encoding="utf-8")
    outs = []
    for extra in ([], ["--behavior", "careful"]):
        code, out, _ = run_main(["eval", str(tmp_path / "t.rules"), "road=120", "--json",
                                 *extra], capsys)
        assert code == 0
        outs.append(json.loads(out)["outputs"]["speed"])
    assert outs == [50.0, 20.0]


@pytest.mark.parametrize("text, default", [
    ("behavior b1:\n  r1: if road is WIDE then speed is SLOW\nend\n"
     "r9: if road is WIDE then speed is FAST\n", "b1"),
    ("r9: if road is WIDE then speed is FAST\n"
     "behavior b1:\n  r1: if road is WIDE then speed is SLOW\nend\n", "main"),
    ("behavior b1:\n  r1: if road is WIDE then speed is SLOW\nend\n"
     "use b1 when road is WIDE\nbehavior b2:\n  r2: if road is WIDE then speed is TOP\nend\n"
     "r9: if road is WIDE then speed is FAST\n", "b1"),
])
def test_the_default_behavior_is_the_first_of_the_file(tmp_path, capsys, text, default):
    """Top-level rules form `main` where the first of them stands: a behavior written before
    them is the file's first, and the default (docs/language.md), not `main`."""
    terms = (ROOT / "rulebases" / "mitos.terms.yaml").read_text(encoding="utf-8")
    (tmp_path / "t.terms.yaml").write_text(terms, encoding="utf-8")
    (tmp_path / "t.rules").write_text('terms "t.terms.yaml"\n' + text, encoding="utf-8")
    code, out, _ = run_main(["eval", str(tmp_path / "t.rules"), "road=120", "--json"], capsys)
    assert code == 0 and json.loads(out)["behavior"] == default
    assert load_rulebase(tmp_path / "t.rules").rulebase.default_behavior == default


def test_a_hedged_consequent_hedges_its_rules_dof_for_that_output(tmp_path, capsys):
    """docs/language.md, Actions: under the weighted average `then speed is very FAST`
    weighs the rule by DOF^2 for `speed` only; its other action keeps the DOF."""
    terms = (ROOT / "rulebases" / "mitos.terms.yaml").read_text(encoding="utf-8")
    (tmp_path / "t.terms.yaml").write_text(terms, encoding="utf-8")
    (tmp_path / "t.rules").write_text(
        'terms "t.terms.yaml"\n'
        "r1: if road is WIDE then speed is very FAST and steering is RS\n"
        "r2: if road is MEDIUM then speed is SLOW and steering is LS\n", encoding="utf-8")
    code, out, _ = run_main(["eval", str(tmp_path / "t.rules"), "road=78", "--json"], capsys)
    data = json.loads(out)
    wide, medium = (data["inputs"]["road"]["memberships"][t] for t in ("WIDE", "MEDIUM"))
    assert code == 0 and 0 < wide < 1 and 0 < medium < 1
    assert data["outputs"]["speed"] == pytest.approx(
        (wide ** 2 * 50 + medium * 20) / (wide ** 2 + medium))
    assert data["outputs"]["steering"] == pytest.approx(
        (wide * 110 + medium * 70) / (wide + medium))


@pytest.mark.parametrize("inference", ["weighted_average", "weighted_sum", "tsukamoto"])
def test_a_consequent_hedged_with_any_counts_only_where_its_rule_fires(tmp_path, capsys,
                                                                         inference):
    """`any` is 1 at every degree, 0 included: `then speed is any FAST` weighed a rule that did
    not fire fully, so at road=150 (NARROW 0) speed was 35 (beside r2's 20), and with r2 gone
    50 printed as "its default" (0). A hedged consequent now weighs a rule only where it fires,
    as the trace and `mitos check` say."""
    (tmp_path / "t.terms.yaml").write_text(
        "variables:\n"
        "  road: {role: input, universe: [0, 160], terms: {NARROW: {shape: left_shoulder, "
        "points: [40, 70]}, WIDE: {shape: right_shoulder, points: [70, 100]}}}\n"
        "  speed: {role: output, universe: [0, 60], default: 0, terms: {"
        "SLOW: {shape: ramp, points: [60, 0]}, FAST: {shape: ramp, points: [0, 60]}}}\n",
        encoding="utf-8")
    rules = tmp_path / "t.rules"
    rules.write_text(f'terms "t.terms.yaml"\noperators: inference = {inference}\n'
                     "r1: if road is NARROW then speed is any FAST\n"
                     "r2: if road is WIDE then speed is SLOW\n", encoding="utf-8")
    code, out, _ = run_main(["eval", str(rules), "road=150", "--json"], capsys)
    assert code == 0 and json.loads(out)["outputs"]["speed"] == 0.0   # SLOW's point at DOF 1
    rules.write_text(f'terms "t.terms.yaml"\noperators: inference = {inference}\n'
                     "r1: if road is NARROW then speed is any FAST\n", encoding="utf-8")
    code, out, _ = run_main(["eval", str(rules), "road=150"], capsys)
    assert code == 0 and "speed = 0.0   (its default: no rule sets it here)" in out
    code, out, _ = run_main(["eval", str(rules), "road=20", "--json"], capsys)
    assert json.loads(out)["outputs"]["speed"] > 0                  # where it fires, it counts


def test_the_trace_shows_every_membership_its_fired_rules_read(capsys):
    """At position=6.7, CENTER is 0.043: the fuzzified line left it out ("RIGHT/1.0" alone),
    yet four rules on `position is CENTER` were listed as fired with DOF 0.04. A membership
    the digits round to 0 is shown as a small DOF is, with its first significant digit."""
    code, out, _ = run_main(["eval", "road=78", "size=45", "position=6.7"], capsys)
    assert code == 0
    assert "position = (CENTER/0.04, RIGHT/1.0)" in out
    assert "position is CENTER then steering is LS and speed is MEDIUM, DOF = 0.04" in out
    code, out, _ = run_main(["eval", "road=78", "size=45", "position=4", "--digits", "0"],
                            capsys)
    assert "position = (CENTER/0.4, RIGHT/1)" in out


def test_no_output_is_negative_zero(tmp_path, capsys):
    """A weighted sum of rules that did not fire over a negative value is 0 * -10 = -0.0, and
    a crisp `-0` averages to -0.0: the trace, --json, --batch and the library said `-0.0`."""
    (tmp_path / "t.terms.yaml").write_text(
        "variables:\n"
        "  x: {role: input, universe: [0, 10], terms: {LO: {shape: left_shoulder, points: [2, 4]},"
        " HI: {shape: right_shoulder, points: [6, 8]}}}\n"
        "  y: {role: output, universe: [-20, 20], terms: {NEG: -10, POS: 10}}\n",
        encoding="utf-8")
    rules = tmp_path / "t.rules"
    rules.write_text('terms "t.terms.yaml"\noperators: inference = weighted_sum\n'
                     "r1: if x is LO then y is NEG\nr2: if x is HI then y is -0\n",
                     encoding="utf-8")
    code, out, _ = run_main(["eval", str(rules), "x=5"], capsys)
    assert code == 0 and "y = 0.0" in out and "-0" not in out.split("outputs:")[1]
    code, out, _ = run_main(["eval", str(rules), "x=9", "--json"], capsys)
    assert out.count('"y": 0.0') == 1
    rb = load_rulebase(rules)
    for x in (5.0, 9.0):
        assert np.signbit(rb.evaluate(x=np.array([x]))["y"]).sum() == 0
        assert not np.signbit(rb.evaluate(x=x)["y"])


@pytest.mark.parametrize("policy", [[], ["--on-no-rule", "error"], ["--on-no-rule", "default"]])
def test_a_batch_where_no_rule_fires_hints_only_choices_that_work(tmp_path, capsys, policy):
    """Without a default, `--on-no-rule default` is what just failed (it is what a batch does
    when not told), yet the hint offered it: it offers nan and skip, and declaring one."""
    (tmp_path / "t.terms.yaml").write_text(
        "variables:\n"
        "  x: {role: input, universe: [0, 10], terms: {LO: {shape: left_shoulder, points: [2, 4]},"
        " HI: {shape: right_shoulder, points: [6, 8]}}}\n"
        "  y: {role: output, universe: [0, 100], terms: {A: 10, B: 90}}\n", encoding="utf-8")
    rules = tmp_path / "t.rules"
    rules.write_text('terms "t.terms.yaml"\nr1: if x is LO then y is A\nr2: if x is HI then y is B\n',
                     encoding="utf-8")
    (tmp_path / "in.csv").write_text("x\n1\n5\n", encoding="utf-8")
    code, _, err = run_main(["eval", str(rules), "--batch", str(tmp_path / "in.csv"), *policy],
                            capsys)
    assert code == 1 and "no rule sets `y` for x=5" in err
    assert "hint: `y` declares no default: declare one, or give --on-no-rule nan or skip" in err
    assert "default, nan or skip" not in err


def test_batch_digits_write_a_huge_output_in_full_not_in_300_digits(tmp_path, capsys):
    """`--digits 2` wrote an output of 1e300 as 301 digits and 2 decimals, most of them
    noise; from 1e15 on it is written in full (`1e+300`), as the trace writes it."""
    (tmp_path / "t.terms.yaml").write_text(
        "variables:\n"
        "  x: {role: input, universe: [0, 1e150], terms: {R: {shape: ramp, points: [0, 1e150]}}}\n"
        "  y: {role: output, universe: [-1e150, 1e150], terms: {L: {shape: linear, "
        "coefficients: {x: 1e150}, constant: 0}, S: 5}}\n", encoding="utf-8")
    rules = tmp_path / "t.rules"
    rules.write_text('terms "t.terms.yaml"\nr1: if x is R then y is L\nr2: if x is not R then y is S\n',
                     encoding="utf-8")
    (tmp_path / "in.csv").write_text("x\n1e150\n0\n", encoding="utf-8")
    code, out, _ = run_main(["eval", str(rules), "--batch", str(tmp_path / "in.csv"),
                             "--digits", "2"], capsys)
    assert code == 0
    assert out.splitlines()[1:] == ["1e150,9.999999999999999e+299", "0,5.00"]


def test_trace_says_when_an_output_is_its_default(tmp_path, capsys):
    """With `and = drastic` no rule fires at the sample run: both outputs are their defaults,
    and the trace says so instead of printing 90 / 0 as if the rules had computed them."""
    terms = (ROOT / "rulebases" / "mitos.terms.yaml").read_text(encoding="utf-8")
    (tmp_path / "t.terms.yaml").write_text(terms, encoding="utf-8")
    (tmp_path / "t.rules").write_text(
        'terms "t.terms.yaml"\noperators: and = drastic\n'
        "r1: if road is MEDIUM and size is MED_SZ then steering is LS and speed is SLOW\n"
        "r2: if road is WIDE and size is SMALL_SZ then speed is FAST\n", encoding="utf-8")
    code, out, _ = run_main(["eval", str(tmp_path / "t.rules"), "road=78", "size=45"], capsys)
    assert code == 0
    assert "steering = 90.0 deg   (its default: no rule sets it here)" in out
    assert "speed = 0.0 in/s   (its default: no rule sets it here)" in out
    code, out, _ = run_main(["eval", str(tmp_path / "t.rules"), "road=100", "size=5"], capsys)
    assert "speed = 50.0 in/s\n" in out + "\n"                     # r2 fired: no note
    assert "steering = 90.0 deg   (its default" in out              # nothing sets steering
    code, out, _ = run_main(["eval", "road=78", "size=45", "position=4"], capsys)
    assert "default" not in out


def test_trace_shows_a_huge_or_tiny_output_readably(tmp_path, capsys):
    """An output of 1.7e148 was printed as 149 digits to one decimal; one of -1e-30 as -0.0."""
    (tmp_path / "h.terms.yaml").write_text(
        "variables:\n"
        "  x: {role: input, universe: [0, 10], terms: {A: {shape: triangle, points: [0, 5, 10]}}}\n"
        "  y: {role: output, universe: [0, 1e149], terms: {B: 1.7e148}}\n"
        "  z: {role: output, universe: [-1, 1], terms: {N: -1e-30}}\n", encoding="utf-8")
    (tmp_path / "h.rules").write_text('terms "h.terms.yaml"\nr1: if x is A then y is B and z is N\n',
                                      encoding="utf-8")
    code, out, _ = run_main(["eval", str(tmp_path / "h.rules"), "x=5"], capsys)
    assert code == 0 and "  y = 1.7e+148\n" in out and "  z = -1e-30" in out, out
    code, out, _ = run_main(["eval", str(tmp_path / "h.rules"), "x=5", "--digits", "8"], capsys)
    assert "  y = 1.7e+148\n" in out, out


def test_trace_render_takes_the_digits_eval_takes(rb):
    """`render(-1)` and `render(True)` raised "Format specifier missing precision", `render(1.5)`
    a TypeError, and `render(99)` was taken where `eval --digits` allows 0 to 12."""
    trace = rb.trace(road=78, size=45, position=4)
    for digits in (-1, 13, 99, 1.5, True, np.True_, "2", None):
        with pytest.raises(InputError, match=r"digits is a whole number from 0 to 12 "):
            trace.render(digits)
    assert "  speed = 32 in/s" in trace.render(0)
    assert "  speed = 32.424242424242 in/s" in trace.render(np.int64(12))


def test_json_names_the_outputs_that_are_their_default(tmp_path, capsys):
    """The text trace's "(its default: no rule sets it here)", for machines: `defaulted`."""
    terms = (ROOT / "rulebases" / "mitos.terms.yaml").read_text(encoding="utf-8")
    (tmp_path / "t.terms.yaml").write_text(terms, encoding="utf-8")
    (tmp_path / "t.rules").write_text(
        'terms "t.terms.yaml"\n'
        "r1: if road is NARROW and size is MED_SZ then steering is LS and speed is SLOW\n"
        "r2: if road is WIDE and size is SMALL_SZ then speed is FAST\n", encoding="utf-8")
    code, out, _ = run_main(["eval", str(tmp_path / "t.rules"), "road=150", "size=5",
                             "--json"], capsys)
    data = json.loads(out)
    assert code == 0 and data["defaulted"] == ["steering"]
    assert data["outputs"]["steering"] == 90.0 and data["outputs"]["speed"] == 50.0
    code, out, _ = run_main(["eval", "road=78", "size=45", "position=4", "--json"], capsys)
    assert json.loads(out)["defaulted"] == []


def test_an_input_without_its_equals_sign_is_a_usage_error(capsys):
    """`road78` was read as a rule file: "cannot read rule file `road78`"."""
    code, out, err = run_main(["eval", "road78", "size=45", "position=4"], capsys)
    assert code == 2 and out == ""
    assert "`road78` is neither a rule file nor NAME=VALUE" in " ".join(
        err.replace("│", " ").split())
    code, _, err = run_main(["eval", "missing.rules", "road=78"], capsys)
    assert code == 1 and "rule file `missing.rules` not found" in err


@pytest.mark.parametrize("args, said, meant", [
    (["road", "78"], "`road 78`", "road=78"),
    (["road", "78", "size=45", "position=4"], "`road 78`", "road=78"),
    (["road=", "78", "size=45"], "`road= 78`", "road=78"),
    (["road", "=78"], "`road =78`", "road=78"),
    (["mitos", "size", "45"], "`size 45`", "size=45"),
    (["road=78", "size", "45", "position=4"], "`size 45`", "size=45"),
    (["road78", "size=45", "position=4"], "`road78` is neither", "road=78"),
    (["position-4.5", "road=78"], "`position-4.5` is neither", "position=-4.5")])
def test_an_input_name_apart_from_its_number_is_told_as_meant(args, said, meant, capsys):
    """`mitos eval road 78` said "`78` is neither the rule base (which comes first) nor
    NAME=VALUE", pointing nowhere near the lost `=`."""
    code, out, err = run_main(["eval", *args], capsys)
    text = " ".join(err.replace("│", " ").split())
    assert code == 2 and out == ""
    assert said in text and f"did you mean `{meant}`?" in text, text


def test_a_long_word_of_digits_is_told_as_neither_at_once(capsys):
    """The lost `=` was looked for with a lazy name before `\\d+\\.?\\d*`, which tried every
    split of a run of digits: 2,000 digits took 20 s, 5,000 would take minutes."""
    word = "a" + "1" * 5000 + "x"
    code, out, err = run_main(["eval", word, "road=78"], capsys)
    assert code == 2 and out == "" and "is neither a rule file nor NAME=VALUE" in " ".join(
        err.replace("│", " ").split())
    code, _, err = run_main(["eval", "x2y78", "road=78"], capsys)
    assert code == 2 and "did you mean `x2y=78`?" in " ".join(err.replace("│", " ").split())


def test_a_misspelt_rule_file_or_its_term_set_named_instead_say_what_was_meant(capsys):
    code, _, err = run_main(["eval", "rulebases/mitos.rule", "road=78"], capsys)
    assert code == 1 and "did you mean `rulebases/mitos.rules`?" in err
    code, _, err = run_main(["eval", "rulebases/mitos.terms.yaml", "road=78"], capsys)
    assert code == 1 and "is a YAML file (a term set, or a world), not a rule base" in err
    assert "a term set is read through the `terms` line of its .rules file" in err
    code, _, err = run_main(["eval", "rulebases/mitoss.rules", "road=78"], capsys)
    assert code == 1 and "did you mean `rulebases/mitos.rules`?" in err


@pytest.mark.parametrize("command", [["eval", "rulebases/mitoss.rules", "road=78"],
                                     ["check", "rulebases/mitoss.rules"],
                                     ["simulate", "corridor", "--rulebase",
                                      "rulebases/mitoss.rules"],
                                     ["teach", "rulebases/mitoss.rules", "--lesson", "-"],
                                     ["eval", "mitoss.rules", "road=78"]])
def test_a_misspelt_packaged_rule_file_from_elsewhere_gets_a_did_you_mean(
        command, tmp_path, monkeypatch, capsys):
    """Where there is no `rulebases/` (a user's own directory), `rulebases/mitos.rules` is the
    packaged file, so a misspelling of it is suggested from the packaged ones, as worlds are."""
    monkeypatch.chdir(tmp_path)
    code, _, err = run_main(command, capsys)
    name = command[1] if command[0] != "simulate" else command[3]
    assert code == 1 and f"rule file `{name}` not found" in err
    assert f"did you mean `{name.replace('mitoss', 'mitos')}`?" in err, err
    code, _, err = run_main(["eval", "nope/mitoss.rules", "road=78"], capsys)
    assert code == 1 and "did you mean" not in err      # another directory: not the packaged


@pytest.mark.parametrize("files", [(), ("mitos.fll",)])
def test_eval_finds_rule_files_as_the_other_commands_do(files, tmp_path, monkeypatch, capsys):
    """eval had a lookup of its own: `mitos` (the packaged rule base to `check`, `plot`,
    `convert`, `simulate --rulebase`) and `mitos.rule` were "neither a rule file nor
    NAME=VALUE" (exit 2), and beside a `mitos.fll` the typo's hint was that file."""
    monkeypatch.chdir(tmp_path)
    for name in files:
        (tmp_path / name).write_text("")
    sample = ["road=78", "size=45", "position=4"]
    code, out, _ = run_main(["eval", "mitos", *sample], capsys)
    assert code == 0 and "steering" in out
    for command in (["eval", "mitos.rule", *sample], ["check", "mitos.rule"]):
        code, out, err = run_main(command, capsys)
        assert code == 1 and out == "", command
        assert "rule file `mitos.rule` not found" in err
        assert "hint: did you mean `mitos.rules`?" in err, err
    code, _, err = run_main(["eval", "nosuch", *sample], capsys)   # no file's name: a lost `=`
    assert code == 2 and "neither a rule file nor NAME=VALUE" in " ".join(
        err.replace("│", " ").split())
    code, _, err = run_main(["eval", "nosuch.txt", *sample], capsys)
    assert code == 1 and "rule file `nosuch.txt` not found" in err


def test_a_mistyped_batch_file_gets_the_one_beside_it(tmp_path, monkeypatch, capsys):
    """`--batch bach.csv` beside `batch.csv` was "not found" with no guess, where a mistyped
    rule file or world gets the file beside it."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "batch.csv").write_text("road,size,position\n78,45,4\n")
    code, _, err = run_main(["eval", "--batch", "bach.csv"], capsys)
    assert code == 1 and "batch file `bach.csv` not found" in err
    assert "hint: did you mean `batch.csv`?" in err
    code, _, err = run_main(["eval", "--batch", "nosuch.csv"], capsys)
    assert code == 1 and "did you mean" not in err


def test_used_rules_take_the_operators_of_the_behavior_that_uses_them(tmp_path):
    """docs/language.md: `cruise` (and = product) evaluates avoid_obstacle's rules with
    product, so their DOFs there are not the ones avoid_obstacle alone gives."""
    import re

    from mitos_cli.api import load_rulebase

    doc = (ROOT / "docs" / "language.md").read_text(encoding="utf-8")
    rules_text, terms_text = re.findall(r"```\w*\n(.*?)```", doc, re.S)[:2]
    (tmp_path / "corridor.rules").write_text(rules_text, encoding="utf-8")
    (tmp_path / "corridor.terms.yaml").write_text(terms_text, encoding="utf-8")
    x = dict(road=78.0, size=45.0, position=4.0)
    alone = load_rulebase(str(tmp_path / "corridor.rules"), "avoid_obstacle").trace(**x)
    used = load_rulebase(str(tmp_path / "corridor.rules"), "cruise").trace(**x)
    a = {r.label: r.dof for r in alone.rules}
    u = {r.label: r.dof for r in used.rules}
    center, large = 3 / 7, (5 / 30) ** 2                   # CENTER(4), very LARGE_SZ(45)
    assert a["r2"] == pytest.approx(min(center, large) * 0.8)
    assert u["avoid_obstacle/r2"] == pytest.approx(center * large * 0.8)


def test_counts_are_singular_for_one(tmp_path, capsys):
    """The trace said "(1 rules; ...)" and a batch "(1 samples)"."""
    terms = (ROOT / "rulebases" / "mitos.terms.yaml").read_text(encoding="utf-8")
    (tmp_path / "t.terms.yaml").write_text(terms, encoding="utf-8")
    (tmp_path / "t.rules").write_text(
        'terms "t.terms.yaml"\nr1: if road is WIDE then speed is FAST\n', encoding="utf-8")
    code, out, _ = run_main(["eval", str(tmp_path / "t.rules"), "road=120"], capsys)
    assert code == 0 and "(1 rule; " in out
    csv = tmp_path / "in.csv"
    csv.write_text("road\n500\n78\n", encoding="utf-8")
    code, out, err = run_main(["eval", str(tmp_path / "t.rules"), "--batch", str(csv)], capsys)
    assert err == "warning: `road` outside its universe [0, 160] was clamped (1 sample)\n"


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
def test_a_full_disk_under_stdout_is_an_error_not_a_traceback():
    with open("/dev/full", "w") as full:
        proc = subprocess.run([sys.executable, "-m", "mitos_cli", "eval", "road=78", "size=45",
                               "position=4"], cwd=ROOT, stdout=full, stderr=subprocess.PIPE,
                              text=True, timeout=60)
    assert proc.returncode == 1 and "Traceback" not in proc.stderr
    assert "cannot write the output: No space left on device" in proc.stderr


@pytest.mark.parametrize("header, row", [("road,size,position", "7_8,45,4"),
                                         ("road,size,position,id", "7_8,45,4,b"),
                                         ("road,size,position", "\u0667\u0668,45,4")])
def test_a_cell_python_alone_would_read_is_not_a_number(header, row):
    """``float`` takes ``7_8`` (78) and other scripts' digits; with or without a pass-through
    column, the cell is refused where it stands."""
    with pytest.raises(InputError) as info:
        read_batch(f"{header}\n78,45,4{',a' if 'id' in header else ''}\n{row}\n", "in.csv",
                   ("road", "size", "position"))
    assert info.value.span.line == 3 and "is not a number (input `road`, row 2)" in \
        info.value.message


@pytest.mark.parametrize("cell", ["1e400", "-1e999", "00.5e999"])
def test_a_cell_past_a_floats_range_is_refused_where_it_stands(cell):
    """`1e400` was read as inf and clamped, where the API refuses `10**400`; `-inf` as written
    stays infinite."""
    with pytest.raises(InputError) as info:
        read_batch(f"road,size,position\n78,45,4\n{cell},45,4\n", "in.csv",
                   ("road", "size", "position"))
    assert info.value.span.line == 3 and info.value.span.column == 1
    assert f"input `road` has a number too large for a float: `{cell}` (row 2)" in \
        info.value.message
    X = read_batch("road,size,position\n-inf,45,Infinity\n", "in.csv", ("road", "size", "position"))
    assert X[0, 0] == -np.inf and X[0, 2] == np.inf


def test_json_is_strict_a_nan_output_is_null(capsys):
    """A rule base that answers NaN where no rule fires (`default: nan`, as asked): --json
    writes null, which every JSON parser reads, not the bare NaN that strict ones refuse."""
    path = ROOT / "tests" / "data" / "interop" / "dimmer_fuzzylite.fcl"
    code, out, _ = run_main(["eval", str(path), "Ambient=0", "--json"], capsys)
    assert code == 0 and "NaN" not in out
    json.loads(out, parse_constant=lambda c: pytest.fail(f"non-strict JSON: {c}"))


def test_a_batch_whose_header_is_not_first_says_so():
    with pytest.raises(InputError, match="first line is empty: the header comes first"):
        read_batch("\nroad,size,position\n1,2,3\n", "in.csv", ("road", "size", "position"))
    with pytest.raises(InputError, match="the batch CSV is empty"):
        read_batch("\n\n", "in.csv", ("road", "size", "position"))


def test_an_output_outside_its_universe_is_said(tmp_path, capsys):
    for name in ("mitos.terms.yaml", "drive.terms.yaml"):
        (tmp_path / name).write_text((ROOT / "rulebases" / name).read_text(encoding="utf-8"),
                                     encoding="utf-8")
    rules = tmp_path / "ws.rules"
    rules.write_text('terms "mitos.terms.yaml", "drive.terms.yaml"\n'
                     "operators: inference = weighted_sum\n"
                     "r1: if road is MEDIUM then steering is RB\n"
                     "r2: if road is MEDIUM then steering is RM\n", encoding="utf-8")
    code, out, err = run_main(["eval", str(rules), "road=70"], capsys)
    assert code == 0 and "steering = 280" in out
    assert "output `steering` lies outside its universe [30, 150] (280)" in err


# ---- batch CSV as the csv module reads it ---------------------------------------------------------

def test_batch_passes_line_breaks_and_form_feeds_in_cells_through(capsys, tmp_path):
    """`text.splitlines()` ran before the CSV parse: a quoted note's line break was lost and a
    row was split at a form feed or NEL; pass-through cells come out exactly as read."""
    import csv as csvmod
    import io

    notes = ["two\nlines", "crlf\r\nkept", "form\x0cfeed", "nel\x85here", 'say "hi", bye']
    rows = [[78, 45, 4, n] for n in notes]
    buf = io.StringIO(newline="")
    w = csvmod.writer(buf, lineterminator="\r\n")
    w.writerow(["road", "size", "position", "note"])
    w.writerows(rows)
    path = tmp_path / "in.csv"
    path.write_bytes(buf.getvalue().encode("utf-8"))
    code, out, err = run_main(["eval", "--batch", str(path)], capsys)
    assert code == 0, err
    got = list(csvmod.reader(io.StringIO(out, newline="")))
    assert [r[-1] for r in got[1:]] == notes
    assert all(r[:3] == ["78", "45", "4"] for r in got[1:])


def test_batch_from_stdin_keeps_crlf_inside_cells(tmp_path):
    text = 'road,size,position,note\r\n78,45,4,"a\r\nb"\r\n'
    proc = subprocess.run([sys.executable, "-m", "mitos_cli", "eval", "--batch", "-"], cwd=ROOT,
                          input=text.encode(), capture_output=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.decode().endswith(',"a\r\nb"\n')


@pytest.mark.parametrize("body", ['"78",45,4\n', '"78","45","4"\n', '"78",45,4,x\n'])
def test_batch_reads_quoted_numbers(body):
    header = "road,size,position" + (",id" if body.endswith("x\n") else "")
    X = read_batch(f"{header}\n{body}", "q.csv", ("road", "size", "position"))
    assert X.tolist() == [[78.0, 45.0, 4.0]]


@pytest.mark.parametrize("text, message, where, expected", [
    ('road,size,position\n1,2,3\n4,"5,6\n7,8,9\n', "this quote opens a cell that is never "
     "closed", "q.csv:3:3", 'a closing `"` before the end of the file'),
    ('road,size,position\n1,2,3\n"4"x,5,6\n', "`x` after a quoted cell's closing quote",
     "q.csv:3:4", "`,` or the end of the line"),
    ('road,"size\n', "this quote opens a cell that is never closed", "q.csv:1:6",
     'a closing `"` before the end of the file'),
])
def test_malformed_csv_is_reported_where_it_breaks(text, message, where, expected):
    """It was `q.csv:1:1: the batch CSV could not be read`, wherever the problem was."""
    with pytest.raises(InputError) as info:
        read_batch(text, "q.csv", ("road", "size", "position"))
    assert message in info.value.message and str(info.value.span) == where
    assert info.value.expected == expected


def test_batch_cell_positions_count_lines_inside_quoted_cells():
    text = 'id,road,size,position\n"a\nb",1,2,3\n"c",4,x,6\n'
    with pytest.raises(InputError) as info:
        read_batch(text, "q.csv", ("road", "size", "position"))
    assert "`x` is not a number (input `size`, row 2)" in info.value.message
    assert str(info.value.span) == "q.csv:4:7"


def test_a_cell_past_the_csv_modules_field_limit_is_an_error_at_its_row():
    """The fast reading takes a 131,073-character cell; finding its row for the message
    went through the csv module, whose field limit then escaped as an internal exception."""
    text = "road,size,position\n" + "a" * 140_000 + "\n"
    with pytest.raises(InputError) as info:
        read_batch(text, "q.csv", ("road", "size", "position"))
    assert str(info.value.span).startswith("q.csv:2:")


def test_batch_writes_inputs_as_given_and_outputs_in_full(capsys, tmp_path):
    """Every number was rewritten with 12 significant digits, the user's inputs included, and
    --digits was ignored with --batch."""
    path = tmp_path / "in.csv"
    path.write_text("road,size,position\n78.000,4.5e1,+4\n", encoding="utf-8")
    code, out, _ = run_main(["eval", "--batch", str(path)], capsys)
    assert code == 0
    row = out.splitlines()[1].split(",")
    assert row[:3] == ["78.000", "4.5e1", "+4"]
    single = load_rulebase().evaluate(road=78, size=45, position=4)
    assert [float(v) for v in row[3:]] == [single["steering"], single["speed"]]   # bit for bit
    assert row[3] == repr(single["steering"])
    code, out, _ = run_main(["eval", "--batch", str(path), "--digits", "3"], capsys)
    assert code == 0 and out.splitlines()[1] == "78.000,4.5e1,+4,65.411,32.424"


@pytest.mark.parametrize("sep, name", [(";", "`;`"), ("\t", "a tab")])
def test_a_semicolon_or_tab_separated_file_is_named_as_such(sep, name):
    text = sep.join(["road", "size", "position"]) + "\n" + sep.join(["78", "45", "4"]) + "\n"
    with pytest.raises(InputError) as info:
        read_batch(text, "s.csv", ("road", "size", "position"))
    assert info.value.message == (f"the header has one column; is the separator {name}? "
                                  "MITOS reads comma-separated values")
    assert str(info.value.span) == "s.csv:1:1"


@pytest.mark.parametrize("line", ["sep=,", "sep=;", "SEP=,", '"sep=,"'])
def test_excels_separator_line_is_named_as_such(line):
    """A CSV saved by Excel may start with `sep=,`, the separator for Excel: the header was
    that line, "no column for road, size, position" (`sep=;` asked whether the separator is
    `;`), with no word of the line to delete."""
    text = line + "\nroad,size,position\n78,45,4\n"
    with pytest.raises(InputError) as info:
        read_batch(text, "x.csv", ("road", "size", "position"))
    assert info.value.message == "the batch CSV starts with Excel's separator line, not a header"
    assert str(info.value.span) == "x.csv:1:1"
    assert info.value.hint == ("delete the first line (`sep=...`), so that the header naming "
                               "road, size, position comes first")


def test_every_misspelt_column_is_named():
    with pytest.raises(InputError) as info:
        read_batch("road,sise,positon\n78,45,4\n", "m.csv", ("road", "size", "position"))
    assert info.value.message == "the batch CSV has no column for size, position"
    assert str(info.value.span) == "m.csv:1:6"
    assert info.value.hint == ("columns `sise`, `positon` are passed through as they are: did "
                               "you mean `size`, `position`?")


@pytest.mark.parametrize("header, at, hint", [
    # two names in one column: "columns `road size`, `road size` are passed through as they
    # are: did you mean `road`, `size`?", the column named twice and no word of the comma
    ("road size,position", "1:1", "column `road size` names `road` and `size`: columns are "
     "separated by commas, `road,size`"),
    ("roadsize,position", "1:1", "column `roadsize` names `road` and `size`: columns are "
     "separated by commas, `road,size`"),
    ("road,sizeposition", "1:6", "column `sizeposition` names `size` and `position`: columns "
     "are separated by commas, `size,position`"),
    ("roadsizeposition", "1:1", "column `roadsizeposition` names `road`, `size` and "
     "`position`: columns are separated by commas, `road,size,position`"),
])
def test_names_glued_in_one_column_are_said_apart(header, at, hint):
    with pytest.raises(InputError) as info:
        read_batch(header + "\n78,45,4\n", "g.csv", ("road", "size", "position"))
    assert str(info.value.span) == f"g.csv:{at}" and info.value.hint == hint



def test_names_glued_in_a_long_column_are_said_apart_in_linear_time():
    """Reading the column's names copied the rest of the cell and the names so far at each
    place: a header cell of 25,000 `road`s took 5 CPU s (tonight's hint, before it 0.01 s)."""
    import time

    t0 = time.process_time()
    with pytest.raises(InputError) as info:
        read_batch("road" * 25_000 + "size,position\n78,45,4\n", "g.csv",
                   ("road", "size", "position"))
    assert time.process_time() - t0 < 1.5
    assert info.value.hint is not None and info.value.hint.endswith(
        "columns are separated by commas, `" + "road," * 25_000 + "size`")

def test_a_header_ending_in_a_comma_is_named():
    """`road,size,position,` has a fourth column without a name: "row has 3 values, the
    header 4" did not say where the fourth is."""
    with pytest.raises(InputError) as info:
        read_batch("road,size,position,\n78,45,4\n", "t.csv", ("road", "size", "position"))
    assert info.value.message == "row has 3 values, the header 4"
    assert info.value.hint == "the header ends in `,`: its last column has no name; delete " \
                              "that comma"


def test_a_bad_cell_early_in_a_large_batch_stops_the_reading(monkeypatch):
    """The reading goes chunk by chunk and stops at the first bad one: the rows after it are
    never converted."""
    from mitos_cli.engine import csvio

    calls = []
    real = csvio._convert
    monkeypatch.setattr(csvio, "_convert", lambda *a: calls.append(1) or real(*a))
    monkeypatch.setattr(csvio, "CHUNK", 4)
    body = "1,2,3\nx,2,3\n" + "1,2,3\n" * 1000
    with pytest.raises(InputError) as info:
        read_batch("road,size,position\n" + body, "b.csv", ("road", "size", "position"))
    assert str(info.value.span) == "b.csv:3:1" and len(calls) == 1


@pytest.mark.parametrize("value", ["1_000", "\u0667\u0668", "0x10", " "])
def test_a_single_value_is_read_as_a_batch_cell_is(value, capsys):
    """`road=1_000` and `road=٧٨` were taken (by `float`) where the batch refuses them."""
    code, out, err = run_main(["eval", f"road={value}", "size=45", "position=4"], capsys)
    assert code == 1 and out == ""
    assert f"input `road` must be a number, not `{value}`" in err
    code, _, _ = run_main(["eval", "road=+7.8e1", "size=45", "position=4"], capsys)
    assert code == 0


def test_a_rule_file_not_found_points_at_the_packaged_ones(capsys, tmp_path, monkeypatch):
    """`mitos eval nope.rules road=1` said "rule file `nope.rules` not found" and no more,
    where a world not found points at `mitos list`; nothing close beside it, it does too."""
    monkeypatch.chdir(tmp_path)
    code, out, err = run_main(["eval", "nope.rules", "road=1"], capsys)
    assert code == 1 and out == ""
    assert err.splitlines() == [
        "rule base error: rule file `nope.rules` not found",
        "hint: `mitos list` shows the packaged rule bases, which are found by name "
        "(`mitos.rules`)"]
    code, _, err = run_main(["eval", "some/dir/nope.rules", "road=1"], capsys)
    assert code == 1 and "hint" not in err          # a path of its own: not a packaged name


def test_an_input_without_a_value_is_said_to_be_empty(capsys):
    """`mitos eval road= size=45 position=4` said "must be a number, not ``"."""
    code, out, err = run_main(["eval", "road=", "size=45", "position=4"], capsys)
    assert code == 1 and out == ""
    assert err.splitlines() == ["input error: input `road` must be a number, not empty",
                                "expected a decimal number such as 78, -4.5 or 1e3",
                                "hint: give it after the `=`, in the same word: `road=78`"]


@pytest.mark.parametrize("args, apart", [
    (["road=78,size=45,position=4"], "road=78 size=45 position=4"),
    (["road=78;size=45;position=4"], "road=78 size=45 position=4"),
    (["road=78, size=45, position=4"], "road=78 size=45 position=4"),
    # glued without a separator, the hint wrote the word back as it was (`road=78size=45`)
    (["road=78size=45position=4"], "road=78 size=45 position=4"),
    (["road=78size=45", "position=4"], "road=78 size=45"),
])
def test_inputs_run_together_are_shown_apart(args, apart, capsys):
    """`mitos eval road=78,size=45,position=4` said only that `road` must be a number, not
    `78,size=45,position=4`: the hint now writes the inputs as the command takes them."""
    code, out, err = run_main(["eval", *args], capsys)
    assert code == 1 and out == ""
    assert f"hint: give each input as a word of its own, apart with spaces: `{apart}`" in err
    code, _, err = run_main(["eval", "road=78,", "size=45,", "position=4"], capsys)
    assert code == 1
    assert "hint: inputs are apart with spaces only: write `road=78`, without `,`" in err
    code, _, err = run_main(["eval", "road=78,5", "size=45", "position=4"], capsys)
    assert code == 1 and "hint: the decimal separator is `.`: `road=78.5`" in err
    code, _, err = run_main(["eval", "road=1,000", "size=45", "position=4"], capsys)
    assert code == 1 and "hint: a number has `.` for its decimals and no thousands " \
                         "separator: `road=1.000` or `road=1000`" in err
    code, _, err = run_main(["eval", "road=7x", "size=45", "position=4"], capsys)
    assert code == 1 and "hint" not in err               # a mistyped number: no such hint


def test_a_decimal_comma_in_a_batch_says_the_separator_is_a_point(tmp_path, capsys):
    """A spreadsheet's `"78,5"` said only "`78,5` is not a number"."""
    (tmp_path / "b.csv").write_text('road,size,position\n"78,5",45,4\n', encoding="utf-8")
    code, out, err = run_main(["eval", "--batch", str(tmp_path / "b.csv")], capsys)
    assert code == 1 and out == ""
    assert "b.csv:2:1: input error: `78,5` is not a number (input `road`, row 1)" in err
    assert "hint: the decimal separator is `.`: `78.5`" in err


@pytest.mark.parametrize("value", ["1e400", "-1e999"])
def test_a_single_value_past_a_floats_range_is_refused(value, capsys):
    """`road=1e400` was read as inf and only warned of as clamped; `road=inf` is still
    taken as written."""
    code, out, err = run_main(["eval", f"road={value}", "size=45", "position=4"], capsys)
    assert code == 1 and out == ""
    assert f"input `road` has a number too large for a float: `{value}`" in err
    code, _, err = run_main(["eval", "road=inf", "size=45", "position=4"], capsys)
    assert code == 0 and "clamped" in err


def test_nan_is_refused_for_an_input_no_rule_tests(capsys):
    """`unused=nan` was taken (the value is dropped before the engine, which refuses NaN)
    where `unused=abc` was refused; NaN inputs are an error (language.md)."""
    fll = str(ROOT / "tests" / "data" / "interop" / "check_termless_input.fll")
    for name, given in (("unused", ["a=0.5", "unused=nan"]), ("a", ["a=NaN", "unused=3"])):
        code, out, err = run_main(["eval", fll, *given], capsys)
        assert code == 1 and out == "" and f"input `{name}` is not a number (NaN)" in err, err
    code, out, _ = run_main(["eval", fll, "a=0.5", "unused=3"], capsys)
    assert code == 0


def test_network_refuses_what_it_would_ignore(capsys, tmp_path):
    """`--batch ok.csv --network` printed the network and ignored the batch."""
    csv = tmp_path / "ok.csv"
    csv.write_text("road,size,position\n78,45,4\n", encoding="utf-8")
    for extra in (["--batch", str(csv)], ["road=78", "size=45", "position=4"], ["--json"],
                  ["--digits", "3"]):
        code, out, err = run_main(["eval", "--network", *extra], capsys)
        assert code == 2 and out == "" and "--network prints the rule base's network" in err
    code, out, _ = run_main(["eval", "--network"], capsys)
    assert code == 0 and out


def test_json_refuses_digits_it_would_ignore(capsys):
    """`--json --digits 3` was taken and printed every digit: --json keeps them all."""
    code, out, err = run_main(["eval", "road=78", "size=45", "position=4", "--json",
                               "--digits", "3"], capsys)
    assert code == 2 and out == "" and "--json gives every digit" in err


def test_json_says_an_input_was_clamped_and_what_was_given(capsys):
    """`--json` reported a clamped input's clamped value with no flag."""
    code, out, err = run_main(["eval", "road=500", "size=45", "position=4", "--json"], capsys)
    assert code == 0 and "`road` outside its universe [0, 160] was clamped" in err
    road, size = (json.loads(out)["inputs"][k] for k in ("road", "size"))
    assert (road["value"], road["given"], road["clamped"]) == (160.0, 500.0, True)
    assert (size["value"], size["given"], size["clamped"]) == (45.0, 45.0, False)
    code, out, _ = run_main(["eval", "road=160", "size=45", "position=4", "--json"], capsys)
    assert json.loads(out)["inputs"]["road"]["clamped"] is False     # on the edge: as given
    code, out, _ = run_main(["eval", "road=500", "size=45", "position=4"], capsys)
    assert "road = 160 in (given 500, clamped to its universe)" in out


def test_json_keeps_an_infinite_input_as_given(capsys):
    """`road=inf` gave `"given": null`, which reads as "nothing given": JSON has no infinity,
    so --json writes it as the text "inf" ("-inf"); a NaN output stays null."""
    code, out, _ = run_main(["eval", "road=inf", "size=45", "position=-inf", "--json"], capsys)
    inputs = json.loads(out)["inputs"]
    assert code == 0 and (inputs["road"]["value"], inputs["road"]["given"]) == (160.0, "inf")
    assert (inputs["position"]["value"], inputs["position"]["given"]) == (-60.0, "-inf")
    assert float(inputs["road"]["given"]) == np.inf       # the files' number grammar reads it


def _narrow_cheap(tmp_path) -> Path:
    fis = tmp_path / "f.fis"
    fis.write_text((ROOT / "tests/data/interop/tipper.fis").read_text()
                   .replace("[0 5 10]", "[4.9 5 5.1]"), encoding="utf-8")
    return fis


def test_a_fired_rule_concluding_a_term_between_the_sample_points_is_told(capsys, tmp_path):
    """MATLAB samples the same 101 points and prints the same 15: the number stays, and the
    user is told (once) why `tip is cheap` at DOF 1 changes nothing."""
    fis = _narrow_cheap(tmp_path)
    code, out, err = run_main(["eval", str(fis), "service=2", "food=1"], capsys)
    assert code == 0 and "tip = 15.0" in out
    assert err.count("warning:") == 1
    assert ("warning: term `cheap` of output `tip` falls between the 101 points its output is "
            "sampled at (every 0.3): its rules do not change `tip`, though r1 fired (DOF up "
            "to 1)\n  hint: widen it;") in err
    code, out, err = run_main(["eval", str(fis), "service=2", "food=1", "--fidelity",
                               "fuzzylite"], capsys)
    assert "tip = 14.3" in out and "undersampled" not in err and "warning" not in err


def test_a_fidelity_that_changes_nothing_says_so(capsys):
    """`--fidelity matlab` on a weighted-average rule base (nothing sampled) gave the same
    numbers without a word, as if MATLAB's sampling had been applied and agreed."""
    sample = ["road=78", "size=45", "position=4"]
    code, plain, _ = run_main(["eval", *sample], capsys)
    code, out, err = run_main(["eval", *sample, "--fidelity", "matlab"], capsys)
    assert code == 0 and out == plain
    assert ("warning: --fidelity matlab changes nothing here: behavior `avoid_obstacle` infers "
            "by weighted_average, and only Mamdani outputs are sampled") in err
    tipper = str(ROOT / "tests" / "data" / "interop" / "tipper.fis")
    code, _, err = run_main(["eval", tipper, "service=2", "food=1", "--fidelity", "matlab"],
                            capsys)
    assert code == 0 and "changes nothing" not in err


def test_the_batch_tells_it_once_too(capsys, tmp_path):
    fis = _narrow_cheap(tmp_path)
    csv = tmp_path / "in.csv"
    csv.write_text("service,food\n2,1\n3,2\n", encoding="utf-8")
    code, out, err = run_main(["eval", str(fis), "--batch", str(csv)], capsys)
    assert code == 0 and err.count("term `cheap` of output `tip` falls between") == 1


def test_inputs_are_told_as_given_where_six_digits_do_not_tell(tmp_path, capsys):
    """Inputs were printed to six significant digits: `road=160.0000001` read "road = 160
    (given 160, clamped to its universe)", and "no rule sets `y` for x=5" was said of
    x=5.0000001, where a rule fires at 5. (The echo of the value the rules saw stays rounded,
    as the memberships are: `mitos simulate --trace` prints its sensors' readings so.)"""
    code, out, _ = run_main(["eval", "road=160.0000001", "size=45", "position=3.14159265"],
                            capsys)
    assert code == 0
    assert "road = 160 in (given 160.0000001, clamped to its universe)" in out
    assert "position = 3.14159 in" in out
    (tmp_path / "t.terms.yaml").write_text(
        "variables:\n"
        "  x: {role: input, universe: [0, 10], terms: {LO: {shape: triangle, points: [0, 0, 4]},"
        " MID: {shape: triangle, points: [5, 5, 5]}}}\n"
        "  y: {role: output, universe: [0, 100], terms: {A: 10, B: 50}}\n", encoding="utf-8")
    rules = tmp_path / "t.rules"
    rules.write_text('terms "t.terms.yaml"\nr1: if x is LO then y is A\nr2: if x is MID then y is B\n',
                     encoding="utf-8")
    assert run_main(["eval", str(rules), "x=5"], capsys)[0] == 0
    code, _, err = run_main(["eval", str(rules), "x=5.0000001"], capsys)
    assert code == 1 and "no rule sets `y` for x=5.0000001" in err


def test_a_hedged_consequent_whose_weight_underflows_is_told_without_mamdanis_hint(tmp_path,
                                                                                    capsys):
    """A rule firing at 1e-16 through `very` five times weighs 0: the output has no value,
    which is said as such, with no hint to widen terms or raise a Mamdani `resolution`."""
    (tmp_path / "t.terms.yaml").write_text(
        "variables:\n"
        "  x: {role: input, universe: [0, 10], terms: {LO: {shape: left_shoulder, points: [0, 10]}}}\n"
        "  w: {role: output, universe: [0, 100], terms: {A: 10}}\n", encoding="utf-8")
    rules = tmp_path / "t.rules"
    rules.write_text('terms "t.terms.yaml"\nq: if x is LO then w is very very very very very A\n',
                     encoding="utf-8")
    code, _, err = run_main(["eval", str(rules), "x=9.999999999999998"], capsys)
    assert code == 1 and "the rules that set `w` fire (q at DOF 1.1e-16)" in err
    assert "underflows" in err and "resolution" not in err


def test_the_no_rule_column_is_not_named_like_an_output(tmp_path, capsys):
    """An output named `no_rule` and `--on-no-rule`'s column made a header `x,no_rule,no_rule`:
    which column was which could not be told. The flag column is `mitos_no_rule` then."""
    (tmp_path / "t.terms.yaml").write_text(
        "variables:\n"
        "  x: {role: input, universe: [0, 10], terms: {LO: {shape: left_shoulder, points: [3, 7]}}}\n"
        "  no_rule: {role: output, universe: [0, 100], terms: {A: 10}}\n", encoding="utf-8")
    rules = tmp_path / "t.rules"
    rules.write_text('terms "t.terms.yaml"\nq: if x is LO then no_rule is A\n', encoding="utf-8")
    (tmp_path / "in.csv").write_text("x\n1\n9\n", encoding="utf-8")
    code, out, _ = run_main(["eval", str(rules), "--batch", str(tmp_path / "in.csv"),
                             "--on-no-rule", "nan"], capsys)
    assert code == 0 and out.splitlines() == ["x,no_rule,mitos_no_rule", "1,10.0,",
                                              "9,nan,no_rule"]
