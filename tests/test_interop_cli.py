"""``mitos convert`` and the foreign readers through the commands users run; dialect details
checked against pyfuzzylite where it can read the same system."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from mitos_cli.api import load_rulebase, read_rulebase
from mitos_cli.cli.app import app
from mitos_cli.interop import write_foreign

ROOT = Path(__file__).parents[1]
DATA = ROOT / "tests" / "data" / "interop"
runner = CliRunner(env={"COLUMNS": "200", "NO_COLOR": "1"})


def test_eval_accepts_each_format() -> None:
    for name, args in (("tipper.fis", ["service=2", "food=1"]),
                       ("tipper_jfuzzylogic.fcl", ["service=3", "food=8"]),
                       ("dimmer_fuzzylite.fcl", ["Ambient=0.3"])):
        result = runner.invoke(app, ["eval", str(DATA / name), *args, "--json"])
        assert result.exit_code == 0, result.output
        data = json.loads(result.stdout)
        assert data["outputs"], data
    result = runner.invoke(app, ["eval", str(DATA / "tipper.fis"), "service=2", "food=1",
                                 "--digits", "4"])
    assert "tip = 7.0169" in result.stdout


def test_convert_to_each_format_and_back(tmp_path: Path) -> None:
    source = ROOT / "rulebases" / "mitos.rules"
    for fmt in ("fcl", "fll", "fis"):
        out = tmp_path / f"mitos.{fmt}"
        result = runner.invoke(app, ["convert", str(source), "--to", fmt, "-o", str(out)])
        assert result.exit_code == 0, result.output
        back = load_rulebase(out)
        assert back.evaluate(road=78, size=45, position=4) == pytest.approx(
            load_rulebase(source).evaluate(road=78, size=45, position=4), abs=1e-9)
    result = runner.invoke(app, ["convert", str(source), "--to", "fis"])
    assert result.exit_code == 0 and "[System]" in result.stdout
    # MATLAB returns the middle of the range when no rule fires: said, not hidden
    assert "warning: output `speed`: when no rule fires MATLAB returns the middle" in \
        result.output


def test_convert_to_rules_writes_both_files(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    result = runner.invoke(app, ["convert", str(DATA / "tipper_jfuzzylogic.fcl"), "--to",
                                 "rules"])
    assert result.exit_code == 0, result.output
    rules, terms = tmp_path / "tipper_jfuzzylogic.rules", tmp_path / "tipper_jfuzzylogic.terms.yaml"
    assert rules.is_file() and terms.is_file()
    assert 'terms "tipper_jfuzzylogic.terms.yaml"' in rules.read_text()
    a = load_rulebase(rules).evaluate(service=3, food=8)
    b = load_rulebase(DATA / "tipper_jfuzzylogic.fcl").evaluate(service=3, food=8)
    assert a == pytest.approx(b, abs=1e-12)
    out = tmp_path / "sub" / "named.rules"
    out.parent.mkdir()
    result = runner.invoke(app, ["convert", str(DATA / "tipper.fis"), "--to", "rules",
                                 "-o", str(out)])
    assert result.exit_code == 0 and (out.parent / "named.terms.yaml").is_file()
    assert "sampling = endpoints" in out.read_text()
    assert not list(tmp_path.glob("**/.*.tmp")), "temporary files left behind"


def test_convert_refuses_to_overwrite_its_input(tmp_path: Path) -> None:
    src = tmp_path / "x.fll"
    src.write_text(write_foreign(read_rulebase(DATA / "tipper.fis"), "fll"))
    result = runner.invoke(app, ["convert", str(src), "--to", "fll", "-o", str(src)])
    assert result.exit_code == 2 and "would overwrite the input" in result.output


def flat(output: str) -> str:
    """A usage error's text without Rich's box and line breaks."""
    import re

    return " ".join(re.sub(r"[│╭╮╰╯─]", " ", output).split())


def test_export_refuses_to_overwrite_its_input(tmp_path: Path) -> None:
    """As convert does (exit 2), through a symbolic link named like the output too."""
    src, terms = tmp_path / "x.rules", tmp_path / "mitos.terms.yaml"
    for name in ("mitos.rules", "mitos.terms.yaml", "drive.terms.yaml"):
        (tmp_path / name).write_text((ROOT / "rulebases" / name).read_text())
    (tmp_path / "mitos.rules").rename(src)
    link = tmp_path / "planner.c"
    link.symlink_to(src)
    before = src.read_text()
    result = runner.invoke(app, ["export", str(src), "--to", "c", "-o", str(link)])
    assert result.exit_code == 2 and "would overwrite the input" in flat(result.output)
    (tmp_path / "terms.py").symlink_to(terms)
    result = runner.invoke(app, ["export", str(src), "--to", "python", "-o",
                                 str(tmp_path / "terms.py")])
    assert result.exit_code == 2 and "would overwrite a term set `x.rules` reads" in \
        flat(result.output)
    assert src.read_text() == before and link.is_symlink()


def test_convert_refuses_to_write_over_a_term_set_the_input_reads(tmp_path: Path) -> None:
    """`-o drive.rules` beside mitos.rules writes drive.terms.yaml, which mitos.rules reads."""
    for name in ("mitos.rules", "mitos.terms.yaml", "drive.terms.yaml"):
        (tmp_path / name).write_text((ROOT / "rulebases" / name).read_text())
    before = (tmp_path / "drive.terms.yaml").read_text()
    result = runner.invoke(app, ["convert", str(tmp_path / "mitos.rules"), "--to", "rules",
                                 "-b", "drive", "-o", str(tmp_path / "drive.rules")])
    assert result.exit_code == 2, result.output
    assert "drive.terms.yaml` would overwrite a term set `mitos.rules` reads" in \
        flat(result.output)
    assert (tmp_path / "drive.terms.yaml").read_text() == before
    assert not (tmp_path / "drive.rules").exists()


@pytest.mark.parametrize("args, expected", [
    (["convert", "tipper.fis", "--to", "fcl", "-o", "out.fis"], "--to fcl is written to a .fcl"),
    (["convert", "tipper.fis", "--to", "rules", "-o", "out.fll"], "--to rules is written to a "
                                                                   ".rules"),
    (["convert", "tipper.fis", "--to", "fll", "-o", "out"], "`out` has no extension"),
    (["export", "tipper.fis", "--to", "c", "-o", "out.py"], "--to c is written to a .c"),
    (["export", "tipper.fis", "--to", "python", "-o", "out.c"], "--to python is written to "
                                                                "a .py"),
])
def test_output_extension_must_match_the_format(args, expected, tmp_path, monkeypatch) -> None:
    """As `plot -o t.pdf`: a usage error, nothing written."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "tipper.fis").write_text((DATA / "tipper.fis").read_text())
    result = runner.invoke(app, args)
    assert result.exit_code == 2 and expected in flat(result.output), result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tipper.fis"]
    good = runner.invoke(app, [*args[:-1], args[-1].rsplit(".", 1)[0] + "." + {
        "fcl": "FCL", "rules": "rules", "fll": "fll", "c": "c", "python": "py"}[args[3]]])
    assert good.exit_code == 0, good.output          # any case


def test_convert_to_rules_without_o_never_overwrites(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    assert runner.invoke(app, ["convert", str(DATA / "tipper.fis"), "--to", "rules"]) \
        .exit_code == 0
    result = runner.invoke(app, ["convert", str(DATA / "tipper.fis"), "--to", "rules"])
    assert result.exit_code == 2
    assert "tipper.rules` is already there" in flat(result.output)
    assert "-o tipper.rules` replaces it on purpose" in flat(result.output)
    result = runner.invoke(app, ["convert", str(DATA / "tipper.fis"), "--to", "rules", "-o",
                                 "tipper.rules"])
    assert result.exit_code == 0, result.output     # tipper.rules and the term set it reads


@pytest.mark.parametrize("named", [[], ["-o", "tipper.rules"]])
def test_convert_to_rules_never_replaces_a_term_set_the_user_did_not_name(
        tmp_path: Path, monkeypatch, named) -> None:
    """The user names only tipper.rules; tipper.terms.yaml beside it, which no tipper.rules
    reads, is theirs: refused before anything is written."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "tipper.terms.yaml").write_text("# mine\n")
    (tmp_path / "tipper.rules").write_text('terms "other.terms.yaml"\n')
    result = runner.invoke(app, ["convert", str(DATA / "tipper.fis"), "--to", "rules", *named])
    assert result.exit_code == 2, result.output
    said = flat(result.output)
    assert "tipper.terms.yaml` is already there and no term set of `" in said
    assert ("tipper.rules` would write its term set over it: remove it, or choose another -o"
            in said)
    assert (tmp_path / "tipper.terms.yaml").read_text() == "# mine\n"
    assert (tmp_path / "tipper.rules").read_text() == 'terms "other.terms.yaml"\n'
    (tmp_path / "tipper.terms.yaml").unlink()
    result = runner.invoke(app, ["convert", str(DATA / "tipper.fis"), "--to", "rules",
                                 "-o", "tipper.rules"])
    assert result.exit_code == 0, result.output     # the named file is replaced, as asked


def run_main(args: list[str], capsys) -> tuple[int, str]:
    """The console entry point (which turns MitosError into a message and exit 1)."""
    from mitos_cli.cli.app import main

    with pytest.raises(SystemExit) as info:
        main(args)
    captured = capsys.readouterr()
    return info.value.code, captured.out + captured.err


def test_convert_errors_exit_1_with_location(tmp_path: Path, capsys) -> None:
    bad = tmp_path / "bad.fis"
    bad.write_text((DATA / "tipper.fis").read_text().replace("'gaussmf'", "'gausmf'"))
    code, output = run_main(["convert", str(bad), "--to", "fll"], capsys)
    assert code == 1
    assert f"{bad}:18:5: format error: MF `poor`: membership function type `gausmf`" in output
    assert "did you mean `gaussmf`?" in output
    code, output = run_main(["convert", str(DATA / "dimmer_fuzzylite.fcl"), "--to", "fis"],
                            capsys)
    assert code == 1 and "hedges cannot be written to .fis" in output
    code, output = run_main(["convert", str(DATA / "tipper.fis"), "--to", "xml"], capsys)
    assert code == 1 and "unknown format `xml`" in output   # a wrong name, as a planner's
    code, output = run_main(["convert", str(DATA / "tipper.fis"), "--to", "fll", "-o",
                             str(tmp_path / "missing" / "x.fll")], capsys)
    assert code == 1 and "cannot write" in output and "No such file or directory" in output


def test_convert_to_rules_keeps_behaviors_and_uses(tmp_path: Path) -> None:
    out = tmp_path / "drive.rules"
    result = runner.invoke(app, ["convert", str(ROOT / "rulebases" / "mitos.rules"), "--to",
                                 "rules", "-b", "drive", "-o", str(out)])
    assert result.exit_code == 0, result.output
    text = out.read_text()
    assert text.index("behavior drive:") < text.index("behavior follow_route:")
    assert "use follow_route when" in text
    a = load_rulebase(ROOT / "rulebases" / "mitos.rules", "drive")
    b = load_rulebase(out)
    assert a.inputs == b.inputs
    rng = np.random.default_rng(np.random.SeedSequence(3).spawn(1)[0])
    X = rng.uniform(a.compiled.universe[:, 0], a.compiled.universe[:, 1], (300, len(a.inputs)))
    np.testing.assert_array_equal(a.run(X, strict=False).outputs, b.run(X, strict=False).outputs)


def test_fuzzylite_dialect_fcl_matches_pyfuzzylite() -> None:
    """The fuzzylite-dialect FCL (hedges, Gaussian/Bell/Sigmoid terms, ACCU in DEFUZZIFY, rules
    without `;`) computes what fuzzylite computes for the same engine written as FLL by hand."""
    fl = pytest.importorskip("fuzzylite", reason="pyfuzzylite is not installed")
    fll = """Engine: SimpleDimmer
InputVariable: Ambient
  range: 0.000 1.000
  term: DARK Triangle 0.000 0.250 0.500
  term: MEDIUM Triangle 0.250 0.500 0.750
  term: BRIGHT Triangle 0.500 0.750 1.000
OutputVariable: Power
  range: 0.000 1.000
  aggregation: Maximum
  defuzzifier: Centroid 1000
  default: nan
  term: LOW Gaussian 0.000 0.200
  term: MEDIUM Bell 0.500 0.250 3.000
  term: HIGH Sigmoid 0.750 20.000
RuleBlock:
  conjunction: Minimum
  disjunction: Maximum
  implication: Minimum
  activation: General
  rule: if Ambient is DARK then Power is HIGH
  rule: if Ambient is very MEDIUM then Power is MEDIUM
  rule: if Ambient is somewhat BRIGHT or Ambient is extremely DARK then Power is LOW with 0.5
"""
    engine = fl.FllImporter().from_string(fll)
    x = np.linspace(0.0, 1.0, 257)
    engine.input_variables[0].value = x
    engine.process()
    theirs = np.asarray(engine.output_variables[0].value, dtype=float)
    ours = load_rulebase(DATA / "dimmer_fuzzylite.fcl").run(x[:, None], strict=False).outputs
    np.testing.assert_allclose(ours[:, 0], theirs, rtol=0, atol=1e-9, equal_nan=True)


def test_jfuzzylogic_dialect_reads_as_iec() -> None:
    rb = read_rulebase(DATA / "tipper_jfuzzylogic.fcl")
    food = rb.variables["food"]
    assert [t.shape for t in food.terms] == ["discrete", "right_shoulder"]   # (0,1)(1,1)(3,0)
    assert rb.variables["service"].term("good").shape == "trapezoid"
    assert rb.variables["tip"].term("cheap").params == (0.0, 5.0, 10.0)     # trian 0 5 10
    assert rb.variables["tip"].default == 0.0
    assert rb.variables["tip"].universe == (0.0, 30.0)
    ops = {s.key: s.value for s in rb.operators}
    assert ops["and"] == "min" and ops["or"] == "max"          # OR: the dual of AND (IEC)
    rule = rb.behaviors[0].rules[2]
    assert rule.weight == 0.8 and rule.label == "r3"


def test_fis_reader_matches_fuzzylites_copy_of_the_same_system() -> None:
    """pyfuzzylite ships MATLAB's tipper as FLL; read as .fis at fuzzylite's sampling, MITOS
    reproduces that engine's table."""
    from test_conformance import EXAMPLES, mitos_outputs, worst

    if EXAMPLES is None:
        pytest.skip("pyfuzzylite is not installed")
    from mitos_cli.engine.compile import compile_rulebase
    from mitos_cli.engine.evaluation import evaluate
    from mitos_cli.lang.model import RuleBase, Setting

    rb = read_rulebase(DATA / "tipper.fis")
    fuzzylite_ops = tuple(s for s in rb.operators if s.key not in ("resolution", "sampling")) + (
        Setting("resolution", "1000"),)
    rb = RuleBase(rb.path, rb.termsets, rb.behaviors, fuzzylite_ops)
    _, ref = mitos_outputs(EXAMPLES / "mamdani" / "matlab" / "tipper.fll")
    from test_conformance import read_fld

    header, table = read_fld(EXAMPLES / "mamdani" / "matlab" / "tipper.fld")
    got = evaluate(compile_rulebase(rb), table[:, :2], strict=False).outputs[:, 0]
    assert worst(got, table[:, header.index("tip")]) < 1e-6


def test_dialect_details(tmp_path: Path) -> None:
    # IEC / jFuzzyLogic: consequents joined by `,`
    fcl = (DATA / "tipper_jfuzzylogic.fcl").read_text().replace(
        "	tip : REAL;", "	tip : REAL;\n	tip2 : REAL;").replace(
        "END_DEFUZZIFY", "END_DEFUZZIFY\nDEFUZZIFY tip2\n TERM a := trian 0 1 2;\n"
        " METHOD : COG;\n RANGE := (0 .. 2);\nEND_DEFUZZIFY", 1).replace(
        "THEN tip IS cheap;", "THEN tip IS cheap, tip2 IS a;")
    from mitos_cli.interop.fcl import parse_fcl

    rb = parse_fcl(fcl, "x.fcl")
    assert [c.var for c in rb.behaviors[0].rules[0].consequents] == ["tip", "tip2"]
    # MATLAB R2018b+ writes DisableStructuralChecks in [System]
    fis = (DATA / "tipper.fis").read_text().replace("NumRules=3", "NumRules=3\n"
                                                     "DisableStructuralChecks=0")
    path = tmp_path / "new.fis"
    path.write_text(fis)
    assert load_rulebase(path).evaluate(service=2, food=1)["tip"] == pytest.approx(7.0169,
                                                                                   abs=5e-5)


def test_fis_writer_pushes_not_by_de_morgan(tmp_path: Path) -> None:
    (tmp_path / "t.terms.yaml").write_text(
        "variables:\n  a: {role: input, universe: [0, 10], terms: {low: {shape: triangle, "
        "points: [0, 2, 5]}, high: {shape: triangle, points: [5, 8, 10]}}}\n"
        "  b: {role: input, universe: [0, 10], terms: {low: {shape: triangle, "
        "points: [0, 2, 5]}, high: {shape: triangle, points: [5, 8, 10]}}}\n"
        "  y: {role: output, universe: [0, 1], terms: {lo: 0.2, hi: 0.8}}\n")
    (tmp_path / "t.rules").write_text('terms "t.terms.yaml"\n'
                                      "r1: if not (a is low and b is high) then y is lo\n"
                                      "r2: if not a is high then y is hi\n")
    rb = read_rulebase(tmp_path / "t.rules")
    text = write_foreign(rb, "fis")
    assert "-1 -2, 1 (1) : 2" in text                # not a.low OR not b.high
    assert "-2 0, 2 (1) : 1" in text
    (tmp_path / "back.fis").write_text(text)
    rng = np.random.default_rng(np.random.SeedSequence(9).spawn(1)[0])
    X = rng.uniform(0, 10, (200, 2))
    a = load_rulebase(tmp_path / "t.rules").run(X, strict=False).outputs
    b = load_rulebase(tmp_path / "back.fis").run(X, strict=False).outputs
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-12)


def test_fcl_rule_blocks_with_different_operators_become_behaviors() -> None:
    from mitos_cli.errors import FormatError
    from mitos_cli.interop.fcl import parse_fcl

    text = (DATA / "tipper_jfuzzylogic.fcl").read_text().replace(
        "	RULE 3 :", "END_RULEBLOCK\nRULEBLOCK gentle\n	AND : PROD;\n	RULE 3 :")
    # both blocks conclude `tip`: their rules would feed one output with two AND operators
    with pytest.raises(FormatError, match="AND `product` differs from `min`"):
        parse_fcl(text, "two.fcl")
    text = text.replace("	tip : REAL;", "	tip : REAL;\n	tip2 : REAL;").replace(
        "END_DEFUZZIFY", "END_DEFUZZIFY\nDEFUZZIFY tip2\n TERM generous := trian 0 1 2;\n"
        " METHOD : COG;\n RANGE := (0 .. 2);\nEND_DEFUZZIFY", 1).replace(
        "THEN tip IS generous WITH 0.8", "THEN tip2 IS generous WITH 0.8").replace(
        "AND service IS NOT excellent THEN tip IS average", "AND service IS NOT excellent "
        "THEN tip2 IS generous")
    rb = parse_fcl(text, "two.fcl")
    assert [b.name for b in rb.behaviors] == ["No1", "gentle"]
    ops = {b.name: dict((s.key, s.value) for s in b.operators) for b in rb.behaviors}
    assert ops["No1"]["and"] == "min" and ops["gentle"]["and"] == "product"
    assert ops["gentle"]["or"] == "probabilistic_sum"           # IEC: the dual of PROD
    same = parse_fcl(text.replace("AND : PROD;", "AND : MIN;"), "one.fcl")
    assert [b.name for b in same.behaviors] == ["main"] and len(same.behaviors[0].rules) == 4


def test_convert_warns_only_of_behaviors_it_leaves_out(tmp_path: Path) -> None:
    from mitos_cli.interop import conversion_notes

    rb = read_rulebase(ROOT / "rulebases" / "mitos.rules")
    assert not any("only behavior" in n for n in conversion_notes(rb, "rules", "drive"))
    (note,) = [n for n in conversion_notes(rb, "rules", "cruise") if "only behavior" in n]
    assert "drive" in note and "cruise)" not in note and "avoid_obstacle" in note
    result = runner.invoke(app, ["convert", str(ROOT / "rulebases" / "mitos.rules"), "--to",
                                 "rules", "-b", "drive", "-o", str(tmp_path / "d.rules")])
    assert result.exit_code == 0 and "warning" not in result.output
    original = load_rulebase(ROOT / "rulebases" / "mitos.rules", "drive")
    c = original.compiled
    inputs = {name: float(lo + 0.37 * (hi - lo)) for name, (lo, hi) in zip(c.inputs, c.universe)}
    assert load_rulebase(tmp_path / "d.rules", "drive").evaluate(**inputs) == \
        original.evaluate(**inputs)


def test_export_says_which_behavior_it_exported(tmp_path: Path, capsys) -> None:
    """As `convert` does: the C file holds one behavior (and those it uses), not the file."""
    code, output = run_main(["export", str(ROOT / "rulebases" / "mitos.rules"), "--to", "c",
                             "-o", str(tmp_path / "p.c")], capsys)
    assert code == 0 and "only behavior `avoid_obstacle` is exported" in output
    code, output = run_main(["export", str(DATA / "tipper.fis"), "--to", "c",
                             "-o", str(tmp_path / "t.c")], capsys)
    assert code == 0 and "warning" not in output


def _run(capsys, *args: str) -> tuple[int, str]:
    """``mitos ARGS`` in process: the exit code and what it wrote to stderr."""
    from mitos_cli.cli.app import main

    with pytest.raises(SystemExit) as info:
        main(list(args))
    return int(info.value.code or 0), capsys.readouterr().err


@pytest.mark.parametrize("source, name, looks, statement, rename", [
    ("tipper.fis", "tipper.txt", "a MATLAB .fis file", "[System]", "tipper.fis"),
    ("tipper_jfuzzylogic.fcl", "tipper.rules", "an FCL file", "FUNCTION_BLOCK", "tipper.fcl"),
    ("tipper.fis", "tipper.fll", "a MATLAB .fis file", "[System]", "tipper.fis"),
    ("check_formula_input.fll", "check.fcl", "a fuzzylite FLL file", "Engine:", "check.fll"),
])
def test_a_file_read_by_the_wrong_reader_says_which_format_it_looks_like(
        tmp_path: Path, capsys, source: str, name: str, looks: str, statement: str,
        rename: str) -> None:
    """`mitos eval tipper.txt` read a .fis as rules: "unexpected character `[`" and no more."""
    path = tmp_path / name
    path.write_bytes((DATA / source).read_bytes())
    code, err = _run(capsys, "eval", str(path), "service=2", "food=1")
    assert code == 1
    assert f"hint: `{name}` looks like {looks} (`{statement}` on line " in err, err
    assert "the reader is chosen by the file's extension" in err
    assert f"rename it to `{rename}`" in err


def test_teach_on_a_foreign_file_says_to_convert_it(tmp_path: Path, capsys) -> None:
    path = tmp_path / "tipper.txt"
    path.write_bytes((DATA / "tipper.fis").read_bytes())
    code, err = _run(capsys, "teach", str(path), "--lesson", "-")
    assert code == 1
    assert ("but `mitos teach` reads the MITOS rule language only: rename it to `tipper.fis`, "
            f"then convert it with `mitos convert {tmp_path / 'tipper.fis'} --to rules`") in err


def test_a_rule_file_with_a_mistake_gets_no_format_hint(tmp_path: Path, capsys) -> None:
    rules = (ROOT / "rulebases" / "mitos.rules").read_text().replace("then steering", "thn steering", 1)
    (tmp_path / "m.rules").write_text(rules)
    for f in ("mitos.terms.yaml", "drive.terms.yaml"):
        (tmp_path / f).write_bytes((ROOT / "rulebases" / f).read_bytes())
    code, err = _run(capsys, "check", str(tmp_path / "m.rules"))
    assert code == 1 and "looks like" not in err and "syntax error" in err
