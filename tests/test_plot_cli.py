"""`mitos plot terms|surface|rules`: files written by extension, terminal output without
matplotlib, and every user-facing error (exit 1 for ours, 2 for usage), for the packaged rule
base and for imported FIS and FCL files (tests/data/interop/)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from mitos_cli.api import load_rulebase
from mitos_cli.cli.app import main
from mitos_cli.draw import data as plotdata

DATA = Path(__file__).parent / "data" / "interop"
SAMPLE = ["road=78", "size=45", "position=4"]
PNG = b"\x89PNG\r\n\x1a\n"


def run(args, capsys):
    with pytest.raises(SystemExit) as exc:
        main(args)
    out, err = capsys.readouterr()
    return exc.value.code or 0, out, err


def is_svg(path: Path) -> bool:
    text = path.read_text(encoding="utf-8")
    return text.lstrip().startswith(("<?xml", "<svg")) and "</svg>" in text


# ---------------------------------------------------------------- files


SURFACE = ["surface", "steering", "--x", "road", "--y", "position", "--fix", "size=45", "-n", "12"]


@pytest.mark.parametrize("command, ext", [
    (["terms", "-b", "avoid_obstacle", *SAMPLE], "png"),
    (["terms", "-b", "avoid_obstacle", *SAMPLE], "svg"),
    (SURFACE, "png"),
    (SURFACE[:5] + ["position=-15:15"] + SURFACE[6:] + ["--style", "heatmap"], "svg"),
    (["surface", "speed", "--x", "road", "--fix", "size=45", "--fix", "position=4"], "png"),
    (["rules", *SAMPLE], "PNG"),
    (["rules", *SAMPLE], "svg"),
], ids=["terms-png", "terms-svg", "surface-png", "heatmap-svg", "curve-png", "rules-PNG",
        "rules-svg"])
def test_files_are_written_by_extension(tmp_path, capsys, command, ext):
    path = tmp_path / f"picture.{ext}"
    code, out, err = run(["plot", *command, "-o", str(path)], capsys)
    assert code == 0, err
    assert f"wrote {path}" in err and out == ""
    if ext.lower() == "png":
        assert path.read_bytes()[:8] == PNG
    else:
        assert is_svg(path)


def test_svg_is_the_same_bytes_twice(tmp_path, capsys):
    a, b = tmp_path / "a.svg", tmp_path / "b.svg"
    for p in (a, b):
        assert run(["plot", "terms", "--var", "road", "road=78", "-o", str(p)], capsys)[0] == 0
    assert a.read_bytes() == b.read_bytes()


# ---------------------------------------------------------------- terminal


def test_terms_in_the_terminal_without_matplotlib():
    code = ("import sys\n"
            "from mitos_cli.cli.app import main\n"
            "try:\n"
            "    main(['plot', 'terms', '--var', 'road', 'road=78', '--width', '60'])\n"
            "except SystemExit as e:\n"
            "    assert not e.code, e.code\n"
            "print('MPL', 'matplotlib' in sys.modules)\n")
    env = {k: v for k, v in os.environ.items() if k != "NO_COLOR"}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=env, timeout=60)
    assert done.returncode == 0, done.stderr
    out = done.stdout
    assert out.rstrip().endswith("MPL False")
    assert "NARROW" in out and "MEDIUM" in out and "WIDE" in out
    assert "road = 78 in: MEDIUM 0.73, WIDE 0.27" in out
    assert "\x1b[" not in out                          # not a terminal: no colour codes
    plot_lines = [ln for ln in out.splitlines() if ln.startswith(("1.0 ┤", "0.0 ┤"))]
    assert len(plot_lines) == 2 and all(len(ln) == 60 for ln in plot_lines)
    assert any(0x2800 < ord(ch) <= 0x28FF for ch in plot_lines[0])   # Braille dots


def test_terms_terminal_colour_on_request(capsys):
    code, out, _ = run(["plot", "terms", "--var", "size", "--color", "--width", "50"], capsys)
    assert code == 0 and "\x1b[" in out


def test_many_inputs_not_fixed_are_one_note(capsys):
    """`mitos plot surface -b drive steering --x heading` printed twelve notes, one an input
    held at its midpoint: more than two are one note that lists them."""
    code, _, err = run(["plot", "surface", "-b", "drive", "steering", "--x", "heading",
                        "-n", "3"], capsys)
    notes = [line for line in err.splitlines() if line.startswith("note:")]
    assert code == 0 and notes == [
        "note: 12 inputs not fixed, each held at the midpoint of its universe: road = 80, "
        "size = 50, position = 0, obstacle = 100, lane = 0, goal = 200, gap_left = 75, "
        "gap_right = 75, front = 75, opening = 0, clutter = 10, nearest = 30 (give --fix "
        "NAME=VALUE)"]


def test_surface_table_and_notes(capsys):
    code, out, err = run(["plot", "surface", "steering", "--x", "road", "--y", "position",
                          "-n", "5"], capsys)
    assert code == 0
    assert "note: `size` not fixed: held at 50, the midpoint of its universe" in err
    lines = out.splitlines()
    assert lines[0] == "steering [deg] (behavior avoid_obstacle; size = 50 in (midpoint))"
    assert lines[1] == "rows: position [in], columns: road [in]"
    rb = load_rulebase()
    row = lines[6].split("│")             # title, axes, header, rule, -60, -30, then 0
    assert row[0].strip() == "0"
    expected = rb.evaluate(road=np.linspace(0, 160, 5), size=50.0, position=0.0)["steering"]
    assert [float(v) for v in row[1].split()] == [round(v, 1) for v in expected]


def test_surface_table_marks_no_rule(tmp_path, capsys):
    from test_plotdata import GAP_RULES, GAP_TERMS

    (tmp_path / "gap.terms.yaml").write_text(GAP_TERMS)
    (tmp_path / "gap.rules").write_text(GAP_RULES)
    code, out, err = run(["plot", "surface", str(tmp_path / "gap.rules"), "--x", "x",
                          "--fix", "y=0.5", "-n", "11"], capsys)
    assert code == 0
    assert "no rule sets `out` at 3 of 11 grid points" in err
    assert [ln.split()[-1] for ln in out.splitlines()[2:]] == \
        ["10.0"] * 4 + ["-"] * 3 + ["90.0"] * 4


def test_a_curve_table_right_aligns_both_columns(capsys):
    """The output column was left-aligned under a right-aligned input column:
    "      0  5.1" over "    2.5  10.0"."""
    code, out, _ = run(["plot", "surface", str(DATA / "tipper.fis"), "--x", "service",
                        "-n", "5"], capsys)
    assert code == 0
    assert out.splitlines()[1:] == ["service   tip",
                                    "      0   5.1",
                                    "    2.5  10.0",
                                    "      5  15.0",
                                    "    7.5  20.0",
                                    "     10  24.9"]


def test_rules_as_text_match_eval(capsys):
    code, out, _ = run(["plot", "rules", *SAMPLE], capsys)
    assert code == 0
    code, js, _ = run(["eval", *SAMPLE, "--json"], capsys)
    trace = json.loads(js)
    labels = [ln.split()[0] for ln in out.splitlines() if "DOF" in ln and "then" in ln]
    assert labels == [r["label"] for r in trace["rules"]]
    assert f"steering = {trace['outputs']['steering']:.2f} deg" in out


def test_rules_as_text_take_a_width(capsys):
    """`plot rules --width` sets the width of a Mamdani output's plot, as `plot terms
    --width` does for the membership plots (default 72)."""
    tipper = str(DATA / "tipper.fis")
    widths = []
    for extra in ([], ["--width", "40"], ["--width", "120"]):
        code, out, _ = run(["plot", "rules", tipper, "service=5", "food=5", *extra], capsys)
        assert code == 0
        axis = [ln for ln in out.splitlines() if "└" in ln]
        widths.append(len(axis[-1].rstrip()))
    assert widths[1] <= 40 and widths[1] < widths[0] < widths[2] <= 120
    code, _, err = run(["plot", "rules", tipper, "service=5", "food=5", "--width", "10"],
                       capsys)
    assert code == 2 and "--width" in err


def test_a_surface_told_less_draws_the_first_output_over_the_first_inputs(capsys):
    """As MATLAB's gensurf(fis): `mitos plot surface` alone was "Missing option '--x'", and
    without an OUTPUT "name the OUTPUT to draw"; each default is said in a note."""
    code, out, err = run(["plot", "surface", "-n", "5"], capsys)
    assert code == 0, err
    assert "note: drawing `steering`, the first output (name another: speed); over `road` and " \
           "`size`, the first inputs (--x and --y choose others)" in " ".join(err.split())
    said = run(["plot", "surface", "steering", "--x", "road", "--y", "size", "-n", "5"], capsys)
    assert said[0] == 0 and said[1] == out and "note: drawing" not in said[2]
    code, curve, err = run(["plot", "surface", "--x", "road", "-n", "5"], capsys)
    assert code == 0 and "note: drawing `steering`, the first output" in err
    assert "over `road`" not in err and "road [in]  steering" in curve


# ---------------------------------------------------------------- errors


@pytest.mark.parametrize("args, message", [
    (["terms", "-o", "x.pdf"], "`x.pdf` has extension .pdf; the picture formats are .png and "
                               ".svg"),
    (["terms", "-o", "picture"], "`picture` has no extension"),
    (["surface", "--y", "road"], "--y needs --x: name the input on the x axis too"),
    (["surface", "--style", "heatmap"], "--style chooses how a picture of two inputs is drawn"),
    (["surface", "--x", "road", "--style", "heatmap", "-o", "s.png"],
     "--style chooses how a picture of two inputs is drawn"),
    (["surface", "steering", "--x", "road=1"], "write NAME or NAME=LOW:HIGH"),
    (["surface", "steering", "--x", "road", "--fix", "size"], "write NAME=VALUE"),
    (["surface", "steering", "--x", "road", "--fix", "size=1", "--fix", "size=2"],
     "`size` is fixed twice"),
    (["surface", "a", "b", "c", "--x", "road"], "expected [RULEBASE] [OUTPUT], got 3"),
    (["surface", "steering", "--x", "road", "--fix", "size=45", "position=4"],
     "`position=4` is not a rule base or an output; to hold several inputs, repeat --fix: "
     "--fix position=4"),
    (["rules"], "give one NAME=VALUE per input: road=... size=... position=..."),
    (["rules", "road=1", "road=2"], "input `road` is given twice"),
])
def test_usage_errors_exit_2(capsys, args, message):
    code, out, err = run(["plot", *args], capsys)
    assert code == 2
    assert message in " ".join(err.replace("│", " ").split())


@pytest.mark.parametrize("args", [["steerin"], ["steering", "--fix", "sise=4"],
                                  ["steering", "--fix", "size=1e400"],
                                  ["steering", "--fix", "size=nan"]])
def test_a_surface_refused_says_no_note_on_what_it_would_draw(capsys, args):
    """`plot surface steerin` printed "note: drawing over `road` and `size`, the first
    inputs" before "unknown output `steerin`": a note on a drawing that was never made."""
    code, out, err = run(["plot", "surface", *args], capsys)
    assert code in (1, 2) and "note:" not in err and out == "", err


@pytest.mark.parametrize("fix", ["size", "", "size=1 size=2"])
def test_a_malformed_fix_is_refused_before_any_note(capsys, fix):
    """`plot surface steering --fix size` printed "note: drawing over `road` and `size`, the
    first inputs" and then the usage error: a note about a drawing that was never made."""
    fixes = [w for f in fix.split(" ") for w in ("--fix", f)]
    code, out, err = run(["plot", "surface", "steering", *fixes], capsys)
    assert code == 2 and err.startswith("Usage: mitos plot surface"), err


@pytest.mark.parametrize("args, message, hint", [
    (["terms", "--var", "raod"], "unknown variable `raod`", "did you mean `road`?"),
    (["terms", "road=wide"], "input `road` must be a number, not `wide`", None),
    (["surface", "steerin", "--x", "road"], "unknown output `steerin`",
     "did you mean `steering`?"),
    (["surface", "steering", "--x", "rod"], "unknown input (--x) `rod`", "did you mean `road`?"),
    (["surface", "steering", "--x", "road", "--y", "road"], "`road` is on both axes", None),
    (["surface", "steering", "--x", "road", "--fix", "sise=3"], "unknown input (--fix) `sise`",
     "did you mean `size`?"),
    (["surface", "steering", "--x", "road", "--fix", "road=3"],
     "`road` is on an axis and cannot also be fixed", None),
    (["surface", "steering", "--x", "road=0:500"],
     "range 0:500 of `road` is not inside its universe [0, 160]", None),
    (["surface", "steering", "--x", "road", "--y", "position=20:-20"],   # inside, but reversed
     "range 20:-20 of `position` is reversed: LOW comes first", "write position=-20:20"),
    (["surface", "steering", "--x", "road=40:40"], "range 40:40 of `road` is empty", None),
    (["surface", "steering", "--x", "road", "--fix", "size=500"],
     "--fix size=500 is outside its universe [0, 100]", None),
    # NaN and infinity are said to be what they are, not "not inside its universe"
    (["surface", "steering", "--x", "road", "--y", "position=-20:nan", "--fix", "size=45"],
     "range -20:nan of `position`: `nan` is not a number", "give numbers inside the universe"),
    (["surface", "steering", "--x", "road", "--y", "position=-inf:20"],
     "range -inf:20 of `position`: `-inf` is not a finite number", None),
    (["surface", "steering", "--x", "road=0:inf"],
     "range 0:inf of `road`: `inf` is not a finite number", None),
    # 1e400 is said as written (it said "range 0:inf ...: `inf` is not a finite number")
    (["surface", "steering", "--x", "road=0:1e400"],
     "range 0:1e400 of `road` has a number too large for a float: `1e400`", None),
    (["surface", "steering", "--x", "road", "--y", "position=-1e999:4"],
     "range -1e999:4 of `position` has a number too large for a float: `-1e999`", None),
    (["surface", "steering", "--x", "road", "--fix", "size=nan"],
     "--fix size=nan: `nan` is not a number", None),
    (["surface", "steering", "--x", "heading"],
     "behavior `avoid_obstacle` does not use input `heading` (--x)", None),
    (["rules", "road=78", "size=45", "positon=4"], "unknown input `positon`",
     "did you mean `position`?"),
    (["rules", "road=78", "size=45"], "missing input `position`", None),
])
def test_user_errors_exit_1(capsys, args, message, hint):
    code, out, err = run(["plot", *args], capsys)
    assert code == 1, err
    assert message in err
    if hint:
        assert f"hint: {hint}" in err


def test_a_range_is_read_as_numbers_are_everywhere(capsys):
    """`road=1_0:40` was 10:40 through `float`, which the batch and NAME=VALUE refuse."""
    code, _, err = run(["plot", "surface", "steering", "--x", "road=1_0:40"], capsys)
    assert code == 2 and "write NAME or NAME=LOW:HIGH" in err


def test_show_without_a_display_exits_1():
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env["MPLBACKEND"] = "Agg"
    done = subprocess.run([sys.executable, "-m", "mitos_cli", "plot", "terms", "--var", "road",
                           "--show"], capture_output=True, text=True, env=env, timeout=60)
    assert done.returncode == 1
    assert "error: cannot open a window" in done.stderr
    assert "hint: write a file instead with -o FILE.png or -o FILE.svg" in done.stderr
    assert "Traceback" not in done.stderr


def test_unwritable_output_exits_1(tmp_path, capsys):
    code, _, err = run(["plot", "terms", "--var", "road", "-o",
                        str(tmp_path / "missing" / "t.png")], capsys)
    assert code == 1 and "cannot write" in err


def test_clamped_values_are_warned(capsys):
    code, out, err = run(["plot", "terms", "--var", "road", "road=500"], capsys)
    assert code == 0 and "warning: `road` outside its universe [0, 160] was clamped" in err
    code, out, err = run(["plot", "rules", "road=500", "size=45", "position=4"], capsys)
    assert code == 0 and "warning: `road` outside its universe [0, 160] was clamped" in err


@pytest.mark.parametrize("pick", [["--var", "road"], ["-b", "keep_right"]])
def test_a_value_of_a_variable_left_off_the_sheet_is_warned(capsys, pick):
    """`--var road size=3` marked nothing and said nothing: `size` is a variable, not drawn."""
    code, out, err = run(["plot", "terms", *pick, "size=3"], capsys)
    assert code == 0 and "warning: `size` is given a value but not drawn" in err
    assert "add --var size to draw it" in err
    code, out, err = run(["plot", "terms", "--var", "road", "road=3"], capsys)
    assert code == 0 and "not drawn" not in err


# ---------------------------------------------------------------- imported FIS / FCL files


def _foreign_files():
    return sorted(DATA.glob("*.fis")) + sorted(DATA.glob("*.fcl"))


def _reader_available(path: Path) -> bool:
    """Whether mitos_cli.interop can read files like ``path`` yet (issue 6 adds the readers)."""
    import importlib

    try:
        importlib.import_module(f"mitos_cli.interop.{path.suffix[1:].lower()}")
    except ImportError:
        return False
    return True


def _midpoints(rb) -> dict[str, float]:
    return {name: float(np.mean(rb.compiled.universe[k])) + 0.37
            for k, name in enumerate(rb.inputs)}


@pytest.mark.parametrize("path", _foreign_files(), ids=lambda p: p.name)
def test_imported_pictures_and_data(path, tmp_path, capsys):
    if not _reader_available(path):
        pytest.skip(f"no {path.suffix} reader in mitos_cli.interop yet (issue 6)")
    rb = load_rulebase(path)
    values = _midpoints(rb)
    args = [f"{k}={v:g}" for k, v in values.items()]
    # membership sheet: every variable of the file, curves = memberships
    plots = plotdata.sheet(rb.rulebase)
    assert {p.name for p in plots} == set(rb.rulebase.variables)
    for plot in plots:
        var = rb.rulebase.variables[plot.name]
        for curve, term in zip(plot.curves, var.terms):
            if curve.kind == "curve":
                np.testing.assert_array_equal(curve.y, term.membership(curve.x))
    # surface over the first two inputs = the engine at the same points
    out = rb.outputs[0]
    y = rb.inputs[1] if len(rb.inputs) > 1 else None
    s = plotdata.surface(rb.compiled, out, rb.inputs[0], y, resolution=6)
    grid = np.meshgrid(s.x.values, s.y.values) if y else (s.x.values,)
    columns = {f.name: f.value for f in s.fixed}
    columns[rb.inputs[0]] = grid[0].ravel()
    if y:
        columns[y] = grid[1].ravel()
    from mitos_cli.engine.evaluation import as_batch, evaluate

    expected = evaluate(rb.compiled, as_batch(rb.compiled, columns), strict=False).output(out)
    np.testing.assert_array_equal(s.z.ravel(), expected)      # NaN (no rule) included
    # rule viewer = eval's fired rules and DOFs
    view = plotdata.rule_view(rb.compiled, values)
    code, js, _ = run(["eval", str(path), *args, "--json"], capsys)
    trace = json.loads(js)
    assert [(r.label, r.dof) for r in view.rows] == \
        [(r["label"], r["dof"]) for r in trace["rules"]]
    # and the three commands write their files
    commands = [["terms", str(path), *args[:1]],
                ["surface", str(path), out, "--x", rb.inputs[0], "-n", "8"]
                + (["--y", y] if y else []),
                ["rules", str(path), *args]]
    for command, ext in zip(commands, ("png", "svg", "png")):
        target = tmp_path / f"{command[0]}.{ext}"
        code, _, err = run(["plot", *command, "-o", str(target)], capsys)
        assert code == 0, err
        assert target.read_bytes()[:8] == PNG if ext == "png" else is_svg(target)


FLL = """\
Engine: mini
InputVariable: dist
  enabled: true
  range: 0.000 10.000
  lock-range: false
  term: NEAR Triangle 0.000 0.000 5.000
  term: FAR Ramp 3.000 10.000
OutputVariable: power
  enabled: true
  range: 0.000 1.000
  lock-range: false
  aggregation: Maximum
  defuzzifier: Centroid 200
  default: nan
  lock-previous: false
  term: LOW Triangle 0.000 0.250 0.500
  term: HIGH Triangle 0.500 0.750 1.000
RuleBlock: rules
  enabled: true
  conjunction: Minimum
  disjunction: Maximum
  implication: Minimum
  activation: General
  rule: if dist is NEAR then power is LOW
  rule: if dist is FAR then power is HIGH
"""


def test_imported_fll_file(tmp_path, capsys):
    """An imported foreign file (fuzzylite FLL, whose reader is already in place): the same
    pictures and data checks as for FIS, independent of the FIS reader."""
    path = tmp_path / "mini.fll"
    path.write_text(FLL)
    rb = load_rulebase(path)
    view = plotdata.rule_view(rb.compiled, {"dist": 4.0})
    code, js, _ = run(["eval", str(path), "dist=4", "--json"], capsys)
    trace = json.loads(js)
    assert [(r.label, r.dof) for r in view.rows] == \
        [(r["label"], r["dof"]) for r in trace["rules"]]
    assert view.outputs[0].value == trace["outputs"]["power"]
    assert view.outputs[0].aggregate is not None           # a Mamdani file: sets drawn
    s = plotdata.surface(rb.compiled, "power", "dist", resolution=9)
    np.testing.assert_array_equal(s.z, rb.evaluate(dist=s.x.values)["power"])
    for command in (["terms", str(path), "dist=4"], ["surface", str(path), "--x", "dist"],
                    ["rules", str(path), "dist=4"]):
        target = tmp_path / f"{command[0]}.png"
        code, _, err = run(["plot", *command, "-o", str(target)], capsys)
        assert code == 0, err
        assert target.read_bytes()[:8] == PNG


@pytest.mark.parametrize("command", [["terms", "--var", "road"],
                                     ["surface", "steering", "--x", "road"],
                                     ["rules", "road=78", "size=45", "position=4"]])
def test_show_with_a_file_and_no_display_writes_the_file_first(command, tmp_path):
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env["MPLBACKEND"] = "Agg"
    out = tmp_path / "x.png"
    done = subprocess.run([sys.executable, "-m", "mitos_cli", "plot", *command, "--show",
                           "-o", str(out)], capture_output=True, text=True, env=env, timeout=60)
    assert done.returncode == 1 and out.read_bytes().startswith(b"\x89PNG")
    assert f"wrote {out}\nerror: cannot open a window" in done.stderr
    assert f"hint: the picture is in {out}" in done.stderr


def test_a_title_with_dollars_is_drawn_as_written(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    out = tmp_path / "s.png"
    code, _, err = run(["plot", *SURFACE, "-o", str(out), "--title", "é $x^$ %s {}"], capsys)
    assert code == 0, err
    assert out.read_bytes().startswith(PNG)


DOLLARS = """\
variables:
  price:
    role: input
    description: "price in $$ per hour, $x^$"
    unit: "$$"
    universe: [0, 10]
    terms: {LOW: {shape: triangle, points: [0, 0, 10]}, HIGH: {shape: triangle, points: [0, 10, 10]}}
  buy:
    role: output
    universe: [0, 1]
    terms: {NOPE: 0, BUY: 1}
"""


@pytest.mark.parametrize("value", [[], ["price=3"]])
def test_a_description_or_unit_with_dollars_is_drawn_as_written(tmp_path, capsys, value):
    """`plot terms -o` laid the sheet out before the texts were made literal: a `$$` in a
    description stopped matplotlib's mathtext with a traceback."""
    pytest.importorskip("matplotlib")
    (tmp_path / "p.terms.yaml").write_text(DOLLARS)
    rules = tmp_path / "p.rules"
    rules.write_text('terms "p.terms.yaml"\nr1: if price is LOW then buy is BUY\n'
                     "r2: if price is HIGH then buy is NOPE\n")
    out = tmp_path / "p.svg"
    code, _, err = run(["plot", "terms", str(rules), *value, "-o", str(out)], capsys)
    assert code == 0, err
    assert "price in $$ per hour, $x^$" in out.read_text() and "price [$$]" in out.read_text()


def test_a_surface_of_many_fixed_inputs_wraps_its_title_and_warns_of_nothing(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    out = tmp_path / "s.png"
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")            # matplotlib's "constrained_layout not applied"
        code, _, err = run(["plot", "surface", "steering", "--x", "size", "-b", "drive", "-n", "5",
                            "-o", str(out)], capsys)         # a curve: no --style
    assert code == 0, err
    assert "Warning" not in err and out.read_bytes().startswith(PNG)


def test_a_formula_term_outside_0_1_is_drawn_with_a_warning(capsys, tmp_path):
    """`eval` and `check` refuse a formula term that leaves [0, 1]; `plot terms` drew it
    without a word, as if it worked."""
    (tmp_path / "f.terms.yaml").write_text(
        "variables:\n"
        "  x: {role: input, universe: [0, 10], terms: {LO: {shape: left_shoulder, points: [2, 8]},"
        " HI: {shape: formula, formula: \"x/5\"}}}\n"
        "  y: {role: output, universe: [0, 100], default: 50, terms: {A: 0, B: 100}}\n")
    rules = tmp_path / "f.rules"
    rules.write_text('terms "f.terms.yaml"\nr1: if x is LO then y is A\nr2: if x is HI then y is B\n')
    code, out, err = run(["plot", "terms", str(rules)], capsys)
    assert code == 0 and out
    assert "warning: term `x.HI` gives 1." in err and "a membership degree lies in [0, 1]" in err
    code, _, err = run(["plot", "terms"], capsys)
    assert code == 0 and "membership degree" not in err


def test_a_formula_term_that_is_nan_somewhere_is_drawn_in_the_terminal(capsys, tmp_path):
    """`sqrt(x - 6)` is NaN below 6: the terminal sheet raised Python's "cannot convert float
    NaN to integer" (its label's place was the plateau of a curve holding NaN)."""
    (tmp_path / "n.terms.yaml").write_text(
        "variables:\n"
        "  x: {role: input, universe: [0, 10], terms: {LO: {shape: left_shoulder, points: [2, 8]},"
        " HI: {shape: formula, formula: \"sqrt(x - 6) / 2\"}}}\n"
        "  y: {role: output, universe: [0, 100], default: 50, terms: {A: 0, B: 100}}\n")
    rules = tmp_path / "n.rules"
    rules.write_text('terms "n.terms.yaml"\nr1: if x is LO then y is A\nr2: if x is HI then y is B\n')
    code, out, err = run(["plot", "terms", str(rules), "--width", "50", "--no-color"], capsys)
    assert code == 0, err
    assert "HI" in out and "gives nan" in err and "Traceback" not in err
    lines = out.splitlines()
    assert any("HI" in line for line in lines[:3])


def test_the_rule_viewer_sums_a_hedged_consequent_as_the_engine_weighs_it(tmp_path):
    """`then y is very LO` weighs its rule by DOF^2 in the average; the viewer's aggregate
    summed the DOF (0.3 for 0.09), so its stems did not average to the output it printed."""
    (tmp_path / "h.terms.yaml").write_text(
        "variables:\n"
        "  x: {role: input, universe: [0, 10], terms: {R: {shape: ramp, points: [0, 10]}}}\n"
        "  y: {role: output, universe: [0, 100], terms: {LO: 10, HI: 90}}\n")
    rules = tmp_path / "h.rules"
    rules.write_text('terms "h.terms.yaml"\nr1: if x is R then y is HI\n'
                     "r2: if x is R then y is very LO\n")
    view = plotdata.rule_view(load_rulebase(rules).compiled, {"x": 3.0})
    (out,) = view.outputs
    assert dict(out.stems) == pytest.approx({10.0: 0.09, 90.0: 0.3})
    values, weights = np.array(out.stems).T
    assert out.value == pytest.approx(float((values * weights).sum() / weights.sum()))


def test_rules_take_the_inputs_eval_takes(capsys):
    """`mitos eval -b keep_right ...` takes an input of the file the behavior does not test
    (and drops it); `plot rules` with the same words said "does not use input" (exit 1),
    though plots.md says it takes its inputs as `mitos eval` does."""
    from mitos_cli.cli.eval_cmd import unused_inputs

    rb = load_rulebase(None, "avoid_obstacle")
    extra = unused_inputs(rb)[0]
    words = [*SAMPLE, f"{extra}=1"]
    code, _, err = run(["eval", "-b", "avoid_obstacle", *words], capsys)
    assert code == 0, err
    code, out, err = run(["plot", "rules", "-b", "avoid_obstacle", *words], capsys)
    assert code == 0, err
    assert "rules fired (8 of 27)" in out
    code, _, err = run(["plot", "rules", "-b", "avoid_obstacle", *SAMPLE, f"{extra}=nan"],
                       capsys)
    assert code == 1 and f"input `{extra}` is not a number (NaN)" in err


def test_an_output_whose_default_is_nan_is_not_said_to_have_none(tmp_path, capsys):
    """`default: .nan` is a declared default (fuzzylite's `default: nan`); where no rule fires
    the viewer said "it has no default", and so did the surface's note."""
    (tmp_path / "n.terms.yaml").write_text(
        "variables:\n"
        "  x: {role: input, universe: [0, 10], terms: {LO: {shape: left_shoulder, points: [2, 4]},"
        " HI: {shape: right_shoulder, points: [6, 8]}}}\n"
        "  y: {role: output, universe: [-20, 20], default: .nan, terms: {NEG: -10, POS: 10}}\n")
    rules = tmp_path / "n.rules"
    rules.write_text('terms "n.terms.yaml"\nr1: if x is LO then y is NEG\nr2: if x is HI then y is POS\n')
    code, out, _ = run(["plot", "rules", str(rules), "x=5"], capsys)
    assert code == 0 and "y: no rule fired and its default is nan" in out
    code, _, err = run(["plot", "surface", str(rules), "y", "--x", "x", "-n", "5"], capsys)
    assert code == 0 and "no rule sets `y` at 1 of 5 grid points and its default is nan" in err
    assert "no default" not in err


@pytest.mark.parametrize("args", [
    ["surface", "steering", "--x", "road", "--y", "position", "--style", "heatmap"],
    ["surface", "steering", "--x", "road", "--style", "heatmap", "-o", "c.png"],
    ["terms", "--title", "T"],
    ["surface", "steering", "--x", "road", "--title", "T"],
    ["rules", "road=78", "size=45", "position=4", "--title", "T"],
    ["terms", "--width", "50", "-o", "t.png"],
    ["terms", "--no-color", "-o", "t.png"],
    ["rules", "road=78", "size=45", "position=4", "--width", "40", "-o", "r.png"],
])
def test_an_option_of_the_other_way_of_drawing_is_a_usage_error(args, capsys, tmp_path,
                                                               monkeypatch):
    """`--title` in the terminal, `--width` or `--color` with a picture, was ignored without a
    word: exit 2, saying which way of drawing the option belongs to, and nothing drawn."""
    monkeypatch.chdir(tmp_path)
    code, out, err = run(["plot", *args], capsys)
    assert code == 2 and out == "" and not list(tmp_path.iterdir()), err
    said = " ".join(err.replace("│", " ").split())
    assert ("names the picture" in said if "--title" in args else
            "a picture of two inputs" in said if "--style" in args else
            "terminal drawing" in said)
@pytest.mark.parametrize("backend, args, says", [
    ("nonsense", ["-o", "x.png"], "matplotlib cannot use the backend `nonsense` that "
                                  "MPLBACKEND names: not a backend matplotlib has"),
    ("module://no_such_backend", ["--show"], "cannot open a window: matplotlib cannot use the "
                                             "backend `module://no_such_backend`"),
])
def test_a_backend_matplotlib_cannot_use_is_said_without_a_traceback(backend, args, says,
                                                                     tmp_path):
    """MPLBACKEND=nonsense met matplotlib's ValueError on its import (a file asked for too),
    and a backend module that is not there its ModuleNotFoundError at the first window."""
    pytest.importorskip("matplotlib")
    env = {**os.environ, "MPLBACKEND": backend, "DISPLAY": ":0"}
    done = subprocess.run([sys.executable, "-m", "mitos_cli", "plot", "terms", "--var", "road",
                           *args], capture_output=True, text=True, env=env, timeout=60,
                          cwd=tmp_path)
    assert done.returncode == 1 and "Traceback" not in done.stderr, done.stderr
    assert says in done.stderr and "hint: unset MPLBACKEND" in done.stderr


def test_terms_of_a_term_set_alone(tmp_path, capsys):
    """`mitos plot terms X.terms.yaml`: its variables drawn as the rule file's sheet draws
    them (a packaged one from anywhere), values marked; `-b` needs the rule file."""
    code, out, err = run(["plot", "terms", "rulebases/mitos.terms.yaml", "road=78"], capsys)
    assert code == 0, err
    assert "road = 78 in: MEDIUM 0.73, WIDE 0.27" in out and "steering:" in out
    code, out, err = run(["plot", "terms", "rulebases/drive.terms.yaml", "-v", "heading",
                          "-o", str(tmp_path / "h.png")], capsys)
    assert code == 0 and (tmp_path / "h.png").read_bytes()[:8] == PNG
    code, _, err = run(["plot", "terms", "rulebases/drive.terms.yaml", "-b", "drive"], capsys)
    assert code == 2 and "has no behaviors (its terms only)" in err
    code, _, err = run(["plot", "terms", "rulebases/mitos.terms.yaml", "-v", "roadd"], capsys)
    assert code == 1 and "did you mean `road`?" in err
    rb = load_rulebase().rulebase
    alone = plotdata.sheet(rb.termsets[0])
    beside = plotdata.sheet(rb, sorted((v.name for v in rb.termsets[0].variables),
                                       key=lambda n: rb.variables[n].role != "input"))
    assert [p.name for p in alone] == [p.name for p in beside]
    assert all(np.array_equal(a.y, b.y) for p, q in zip(alone, beside)
               for a, b in zip(p.curves, q.curves))


NO_RULES_FCL = """\
FUNCTION_BLOCK terms_only
VAR_INPUT
    x : REAL;
END_VAR
FUZZIFY x
    TERM low := GAUSS 0 2;
    TERM high := GAUSS 10 2;
END_FUZZIFY
END_FUNCTION_BLOCK
"""


def test_terms_of_a_foreign_file_without_rules(tmp_path, capsys):
    """jFuzzyLogic's membership-function tests have terms and no rules: every command refused
    them; `plot terms` and `check` read their terms alone (said so), the others say they can."""
    fcl = tmp_path / "t.fcl"
    fcl.write_text(NO_RULES_FCL)
    code, out, err = run(["plot", "terms", str(fcl), "x=3"], capsys)
    assert code == 0 and f"warning: `{fcl}` has no rules: its terms alone are drawn" in err
    assert out.rstrip().endswith("x = 3: low 0.32")
    code, out, err = run(["check", str(fcl)], capsys)
    assert code == 0 and "its terms alone are checked" in err
    assert "the term set's 1 variable (no rules)" in out
    code, _, err = run(["eval", str(fcl), "x=3"], capsys)
    assert code == 1 and "the file has no rules" in err
    assert "hint: `mitos plot terms` and `mitos check` read its terms alone" in err
    code, _, err = run(["plot", "terms", str(fcl), "-b", "main"], capsys)
    assert code == 2 and "has no behaviors (its terms only)" in err


def test_no_tick_reads_minus_zero():
    from mitos_cli.draw.terminal import _ticks

    ticks = _ticks(-8.0, 24.0, 67)
    assert ticks[0] == 0.0 and f"{ticks[0]:g}" == "0"


def test_terms_on_a_dumb_terminal_are_not_coloured(tmp_path):
    """On a terminal of TERM=dumb the colour codes were printed as text (`^[[34m`); Rich's own
    output is plain there, and so is the drawing now (unless --color asks)."""
    import pty

    def drawn(term: str, *extra: str) -> str:
        master, slave = pty.openpty()
        env = {**{k: v for k, v in os.environ.items() if k != "NO_COLOR"}, "TERM": term}
        subprocess.run([sys.executable, "-m", "mitos_cli", "plot", "terms", "--var", "road",
                        "--width", "40", *extra], stdout=slave, stderr=subprocess.DEVNULL,
                       env=env, timeout=60, check=True)
        os.close(slave)
        out = b""
        while True:
            try:
                chunk = os.read(master, 65536)
            except OSError:                  # EIO: the terminal's other end is closed
                break
            if not chunk:
                break
            out += chunk
        os.close(master)
        return out.decode()

    assert "\x1b[" in drawn("xterm")
    assert "\x1b[" not in drawn("dumb")
    assert "\x1b[" in drawn("dumb", "--color")
