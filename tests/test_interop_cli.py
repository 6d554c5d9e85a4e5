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


def _through_a_pipe(tmp_path: Path, name: str, data: bytes, args: list[str]):
    """``mitos eval`` on a named pipe a child process writes ``data`` into; stopped by an
    alarm if the command waits for it."""
    import os
    import signal

    fifo = tmp_path / name
    os.mkfifo(fifo)
    pid = os.fork()
    if pid == 0:                                   # the writer: `cat tipper.fis > pipe.fis &`
        try:
            with open(fifo, "wb") as fh:
                fh.write(data)
        finally:
            os._exit(0)

    def hung(*_):
        raise TimeoutError("the command waits for the pipe")

    old = signal.signal(signal.SIGALRM, hung)
    signal.alarm(20)
    try:
        return runner.invoke(app, ["eval", str(fifo), *args])
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
        os.kill(pid, signal.SIGKILL)
        os.waitpid(pid, 0)


def test_a_foreign_file_that_is_a_named_pipe_is_read_once(tmp_path: Path) -> None:
    """Each reader opened the file twice (a probe, then the read): the probe took the
    writer's data, and the second open waited for a writer that was gone."""
    result = _through_a_pipe(tmp_path, "tipper.fis", (DATA / "tipper.fis").read_bytes(),
                             ["service=2", "food=1"])
    assert result.exit_code == 0 and "tip = 7.0" in result.stdout, result.output
    fll = write_foreign(read_rulebase(DATA / "tipper.fis"), "fll").encode()
    result = _through_a_pipe(tmp_path, "tipper.fll", fll, ["service=2", "food=1"])
    assert result.exit_code == 0 and "tip = 7.0" in result.stdout, result.output
    legacy = b"// Temp\xe9rature\n" + (DATA / "tipper_jfuzzylogic.fcl").read_bytes()
    result = _through_a_pipe(tmp_path, "legacy.fcl", legacy, ["service=3", "food=8"])
    assert result.exit_code == 0 and "Windows-1252" in result.output, result.output
    result = _through_a_pipe(tmp_path, "bom.fcl", b"\xef\xbb\xbf\xe9" + legacy, ["food=8"])
    assert result.exit_code == 1 and "byte-order mark" in str(result.exception), result.output


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


@pytest.mark.parametrize("old, new, line", [
    ("MF1='rancid':'trapmf',[0 0 1 3]", "MF1='rancid':'trapmf',[-5 -4 -3 -2]", 26),
    ("MF1='cheap':'trimf',[0 5 10]", "MF1='cheap':'trimf',[40 45 50]", 33),
])
def test_convert_to_rules_refuses_a_term_outside_its_range_before_writing(
        old, new, line, tmp_path: Path, monkeypatch) -> None:
    """MATLAB accepts a term whose core lies outside its range, a term set does not: the
    conversion wrote both files, then refused them at the term set it had written."""
    monkeypatch.chdir(tmp_path)
    text = (DATA / "tipper.fis").read_text()
    assert old in text
    (tmp_path / "out.fis").write_text(text.replace(old, new))
    result = runner.invoke(app, ["convert", "out.fis", "--to", "rules", "-o", "out.rules"])
    assert result.exit_code == 1
    span = result.exception.span
    assert (span.path, span.line) == ("out.fis", line), result.exception
    assert "needs a term's core (an output term's peak) inside" in result.exception.message
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.fis"]


def test_convert_to_rules_writes_nothing_it_cannot_read_back(tmp_path: Path, monkeypatch) -> None:
    import mitos_cli.interop.rules_writer as writer

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(writer, "write_rules", lambda *a: ('terms "t.terms.yaml"\nr1 if\n', "{}"))
    result = runner.invoke(app, ["convert", str(DATA / "tipper.fis"), "--to", "rules"])
    assert result.exit_code == 1 and "nothing was written" in result.exception.hint
    assert list(tmp_path.iterdir()) == []


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


@pytest.mark.parametrize("command, out, format_", [
    ("convert", "out.fll", "fll"), ("convert", "out.fcl", "fcl"), ("convert", "out.fis", "fis"),
    ("convert", "out.rules", "rules"), ("export", "out.c", "c"), ("export", "out.py", "python"),
])
def test_without_to_the_format_is_the_one_o_names(command, out, format_, tmp_path,
                                                  monkeypatch) -> None:
    """`mitos convert tipper.fis -o tipper.fll` said "Missing option '--to'": the file's
    extension names the format, and what is written is what `--to` writes."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "tipper.fis").write_text((DATA / "tipper.fis").read_text())
    result = runner.invoke(app, [command, "tipper.fis", "-o", out])
    assert result.exit_code == 0, result.output
    written = (tmp_path / out).read_bytes()
    for path in tmp_path.iterdir():
        if path.name != "tipper.fis":
            path.unlink()                               # out.rules: and its out.terms.yaml
    result = runner.invoke(app, [command, "tipper.fis", "--to", format_, "-o", out])
    assert result.exit_code == 0 and (tmp_path / out).read_bytes() == written


@pytest.mark.parametrize("command, args, said", [
    ("convert", [], "say which format to write: --to rules, fcl, fis, fll; or give -o a file "
                    "with the format's extension"),
    ("convert", ["-o", "out.txt"], "say which format to write: --to rules, fcl, fis, fll; "
                                   "`out.txt` has no extension that names one"),
    ("export", [], "say which export language to write: --to c, python"),
])
def test_without_to_or_an_extension_the_format_is_asked_for(command, args, said, tmp_path,
                                                           monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "tipper.fis").write_text((DATA / "tipper.fis").read_text())
    result = runner.invoke(app, [command, "tipper.fis", *args])
    assert result.exit_code == 2 and said in flat(result.output), result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tipper.fis"]


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
    assert code == 2 and "unknown format `xml`" in output   # a wrong name, as a planner's
    code, output = run_main(["convert", str(DATA / "tipper.fis"), "--to", "fll", "-o",
                             str(tmp_path / "missing" / "x.fll")], capsys)
    assert code == 1 and "cannot write" in output and "No such file or directory" in output


def test_an_error_in_a_packaged_rule_base_names_it_as_the_user_does(tmp_path: Path, capsys,
                                                                   monkeypatch) -> None:
    """From anywhere, a place in the packaged rule base reads ``rulebases/mitos.rules:L:C``
    (as ``check`` names it), not where pip put the file."""
    monkeypatch.chdir(tmp_path)
    code, output = run_main(["convert", "rulebases/mitos.rules", "-b", "drive", "--to", "fis",
                             "-o", "x.fis"], capsys)
    assert code == 1
    first = output.splitlines()[0]
    assert first.startswith("rulebases/mitos.rules:") and ": format error: " in first, first


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


@pytest.mark.parametrize("name", ["t.rules", "t.fll", "t.txt"])
def test_a_term_set_given_as_the_rule_base_says_so(tmp_path: Path, capsys, name: str) -> None:
    """A term set under another name got "unexpected `road` ... expected `if`" and no more."""
    (tmp_path / name).write_bytes((ROOT / "rulebases" / "mitos.terms.yaml").read_bytes())
    for command in (["check"], ["eval"], ["teach"]):
        code, err = _run(capsys, *command, str(tmp_path / name), *(["--lesson", "-"] if
                                                                   command == ["teach"] else []))
        assert code == 1
        assert (f"hint: `{name}` looks like a YAML term set (`variables:` on line 3), not a rule "
                f"base: a term set is read through the `terms` line of its .rules file") in err


@pytest.mark.parametrize("command", [["eval"], ["check"], ["teach", "--lesson", "-"]])
def test_a_batch_csv_given_as_the_rule_base_points_to_batch(tmp_path: Path, capsys,
                                                             command: list[str]) -> None:
    """`mitos eval inputs.csv` (the `--batch` left out) said "unexpected `,` ... expected `:`"
    with the hint that `road` is read as a rule's label."""
    (tmp_path / "inputs.csv").write_bytes((ROOT / "tests" / "data" / "inputs.csv").read_bytes())
    path = (tmp_path / "inputs.csv").as_posix()
    code, err = _run(capsys, command[0], path, *command[1:])
    assert code == 1
    assert "inputs.csv:1:5: syntax error: unexpected `,`" in err
    assert (f"hint: `inputs.csv` is a CSV file, not a rule base: to evaluate each of its rows, "
            f"give it to --batch (`mitos eval [RULEBASE] --batch {path}`)") in err
    assert "read as a rule's label" not in err and "Traceback" not in err


def test_a_lesson_given_as_the_rule_base_points_to_lesson(capsys, monkeypatch) -> None:
    """`mitos teach rulebases/lessons/wider-turn.lesson` (the `--lesson` left out) said
    "`simulate` is read as a rule's label", at the lesson's first command past `use drive`."""
    monkeypatch.chdir(ROOT)
    code, err = _run(capsys, "teach", "rulebases/lessons/wider-turn.lesson")
    assert code == 1
    assert "rulebases/lessons/wider-turn.lesson:17:10: syntax error: unexpected `worlds`" in err
    assert ("hint: `wider-turn.lesson` is a lesson, not a rule base: a lesson is run with "
            "--lesson (`mitos teach [RULEBASE] --lesson rulebases/lessons/wider-turn.lesson`)") in err


def test_a_lesson_by_name_given_as_the_rule_base_points_to_lesson(capsys, tmp_path: Path,
                                                                   monkeypatch) -> None:
    """`mitos teach wider-turn` (the packaged lesson, by the name `--lesson` takes) and
    `mitos teach nothere.lesson` said "rule file not found" and pointed to `mitos list`'s
    rule bases."""
    monkeypatch.chdir(tmp_path)
    for given, what in (("wider-turn", "a packaged lesson"),
                        ("wider-turn.lesson", "a packaged lesson"),
                        ("nothere.lesson", "a lesson")):
        code, err = _run(capsys, "teach", given)
        assert code == 1
        assert err.splitlines()[-1] == (
            f"hint: `{given}` is {what}, not a rule base: a lesson is run with --lesson "
            f"(`mitos teach [RULEBASE] --lesson {given}`)")
    assert not (tmp_path / ".mitos").exists()


def test_a_rule_file_with_a_mistake_gets_no_format_hint(tmp_path: Path, capsys) -> None:
    rules = (ROOT / "rulebases" / "mitos.rules").read_text().replace("then steering", "thn steering", 1)
    (tmp_path / "m.rules").write_text(rules)
    for f in ("mitos.terms.yaml", "drive.terms.yaml"):
        (tmp_path / f).write_bytes((ROOT / "rulebases" / f).read_bytes())
    code, err = _run(capsys, "check", str(tmp_path / "m.rules"))
    assert code == 1 and "looks like" not in err and "syntax error" in err


# ---------------------------------------------------------------------------------------------
# FCL that fuzzylite 6 (Debian's `fuzzylite` binary), jFuzzyLogic and IEC 61131-7 read


def _fuzzylite6(fcl: Path, inputs: list[str], rows: list[list[float]], tmp: Path) -> np.ndarray:
    """The `fuzzylite` binary's outputs for ``rows`` of ``inputs`` on ``fcl`` (12 decimals)."""
    import shutil
    import subprocess

    if shutil.which("fuzzylite") is None:
        pytest.skip("the `fuzzylite` binary (Debian's fuzzylite 6) is not installed")
    data = tmp / "in.fld"
    data.write_text(" ".join(inputs) + "\n" + "\n".join(" ".join(map(repr, r)) for r in rows)
                    + "\n")
    out = tmp / "out.fld"
    proc = subprocess.run(["fuzzylite", "-i", str(fcl), "-if", "fcl", "-o", str(out), "-of",
                           "fld", "-d", str(data), "-dheader", "true", "-dinputs", "true",
                           "-decimals", "12"], capture_output=True, text=True, timeout=60)
    assert "error" not in (proc.stdout + proc.stderr).lower(), proc.stdout + proc.stderr
    lines = out.read_text().split("\n")
    header, body = lines[0].split(), [line.split() for line in lines[1:] if line.strip()]
    assert header[:len(inputs)] == inputs and len(body) == len(rows), out.read_text()
    return np.array([[float(x) for x in row[len(inputs):]] for row in body])


def test_written_fcl_loads_in_fuzzylite_6_and_agrees(tmp_path: Path, capsys) -> None:
    """The paper's 27 rules (Takagi-Sugeno, two outputs per rule) and the MATLAB tipper
    (Mamdani) written as FCL give in the `fuzzylite` binary what MITOS gives: the Sugeno file to
    its printed digits, the Mamdani one with `--fidelity fuzzylite6` (its 100 samples)."""
    fcl = tmp_path / "m.fcl"
    code, _ = _run(capsys, "convert", str(ROOT / "rulebases" / "mitos.rules"), "--to", "fcl",
                   "-o", str(fcl))
    assert code == 0
    rows = [[78.0, 45.0, 4.0], [20.0, 90.0, -30.0], [130.0, 12.5, 6.9]]
    got = _fuzzylite6(fcl, ["road", "size", "position"], rows, tmp_path)
    rb = load_rulebase(fcl)
    want = [[rb.evaluate(road=r[0], size=r[1], position=r[2])[o] for o in ("steering", "speed")]
            for r in rows]
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-9)
    assert got[0] == pytest.approx([65.411255411, 32.424242424], abs=1e-9)   # the paper's run

    tip = tmp_path / "tipper.fcl"
    code, _ = _run(capsys, "convert", str(DATA / "tipper.fis"), "--to", "fcl", "-o", str(tip))
    assert code == 0
    # rows where every rule fires above 1e-6 or not at all: fuzzylite 6 activates a rule only
    # above its tolerance of 1e-6 (`Op::isGt`), so at service=2, food=1 its `generous` rule
    # (6.7e-7) is left out and it gives 7.015211 where MITOS (and fuzzylite 8) give 7.015230
    rows = [[3.0, 1.0], [4.0, 5.0], [7.0, 8.0], [5.0, 5.0]]
    got = _fuzzylite6(tip, ["service", "food"], rows, tmp_path)
    for row, value in zip(rows, got[:, 0]):
        code = _eval_json(capsys, str(tip), f"service={row[0]!r}", f"food={row[1]!r}",
                          "--fidelity", "fuzzylite6")
        assert code["tip"] == pytest.approx(value, abs=1e-9)


def _eval_json(capsys, *args: str) -> dict:
    from mitos_cli.cli.app import main

    with pytest.raises(SystemExit) as info:
        main(["eval", *args, "--json"])
    assert not info.value.code
    return json.loads(capsys.readouterr().out)["outputs"]


def test_fcl_dialects_differ_only_where_the_readers_do(tmp_path: Path, capsys) -> None:
    """fuzzylite 6 reads ACCU only in DEFUZZIFY and `and` between conclusions; IEC 61131-7 and
    jFuzzyLogic read ACCU only in the RULEBLOCK and `,`. Both have lower-case rule keywords
    (fuzzylite reads no others) and no resolution after METHOD (no reader but MITOS reads
    one); MITOS reads both back to the same outputs."""
    from mitos_cli.interop.fcl import parse_fcl

    rb = read_rulebase(DATA / "tipper.fis")
    texts = {d: write_foreign(rb, "fcl", dialect=d) for d in ("fuzzylite", "iec")}
    for dialect, text in texts.items():
        block = text[text.index("RULEBLOCK"):]
        assert ("ACCU : MAX;" in block) == (dialect == "iec")
        assert ("ACCU : MAX;" in text[:text.index("RULEBLOCK")]) == (dialect == "fuzzylite")
        assert "METHOD : COG;" in text and "COG 101" not in text
        assert "RULE 1 : if service is poor or food is rancid then tip is cheap;" in text
        assert text.startswith(f"// {'fuzzylite 6' if dialect == 'fuzzylite' else 'IEC'}")
        from mitos_cli.api import LoadedRuleBase

        back = LoadedRuleBase(parse_fcl(text, "x.fcl"))   # FCL `COG`: 1000 midpoints in MITOS
        assert back.evaluate(service=2, food=1)["tip"] == pytest.approx(7.015028, abs=1e-6)
    two = ROOT / "rulebases" / "mitos.rules"
    iec = write_foreign(read_rulebase(two), "fcl", dialect="iec")
    assert "then steering is RS, speed is MEDIUM;" in iec
    assert "then steering is RS and speed is MEDIUM;" in write_foreign(read_rulebase(two), "fcl")
    rules = tmp_path / "r.rules"                   # a resolution FCL cannot carry: said
    rules.write_text((ROOT / "rulebases" / "mitos.rules").read_text())
    for f in ("mitos.terms.yaml", "drive.terms.yaml"):
        (tmp_path / f).write_bytes((ROOT / "rulebases" / f).read_bytes())
    code, err = _run(capsys, "convert", str(DATA / "dimmer_fuzzylite.fcl"), "--to", "rules",
                     "-o", str(rules))
    rules.write_text(rules.read_text().replace("resolution = 1000", "resolution = 300"))
    code, err = _run(capsys, "convert", str(rules), "--to", "fcl", "-o", str(tmp_path / "d.fcl"))
    assert code == 0 and ("FCL has no resolution that fuzzylite 6, jFuzzyLogic and IEC 61131-7 "
                          "read: `METHOD : COG;` is written without this rule base's 300 "
                          "points") in " ".join(err.split()), err
    code, _ = _run(capsys, "convert", str(DATA / "tipper.fis"), "--to", "fll", "--dialect",
                   "iec")
    assert code == 2                               # --dialect is FCL's


@pytest.mark.parametrize("sampling, owner", [
    ("left", "the cells' left ends (jFuzzyLogic's)"),
    ("endpoints", "evenly spaced points including both ends (MATLAB's)")])
def test_fcl_notes_both_the_sampling_and_the_dropped_resolution(tmp_path, capsys, sampling,
                                                                owner):
    """The resolution's note was an `elif` after the sampling's, so a rule base sampled at
    `left` or `endpoints` lost its resolution without a word; `left` was called MATLAB's."""
    terms = "mitos.terms.yaml"
    (tmp_path / terms).write_bytes((ROOT / "rulebases" / terms).read_bytes())
    rules = tmp_path / "s.rules"
    rules.write_text('terms "mitos.terms.yaml"\n'
                     f"operators: inference = mamdani, sampling = {sampling}, resolution = 201\n"
                     "r1: if road is WIDE then speed is FAST\n"
                     "r2: if road is NARROW then speed is SLOW\n")
    code, err = _run(capsys, "convert", str(rules), "--to", "fcl", "-o", str(tmp_path / "s.fcl"))
    err = " ".join(err.split())
    assert code == 0 and f"this rule base samples at {owner}" in err, err
    assert "is written without this rule base's 201 points" in err, err


def test_fuzzylite_dialect_moves_not_onto_propositions(tmp_path: Path) -> None:
    """fuzzylite's `not` is a hedge: `not (a or b)` is written `a is not .. and b is not ..`
    (exact with dual norms), and refused by name where the norms are not duals."""
    from mitos_cli.errors import FormatError
    from mitos_cli.interop.fcl import parse_fcl

    fcl = (DATA / "tipper_jfuzzylogic.fcl").read_text()
    fcl = fcl.replace("RULE 2 : IF service IS good", "RULE 2 : IF NOT (service IS poor OR "
                      "food IS rancid) AND service IS good", 1)
    rb = parse_fcl(fcl, "x.fcl")
    text = write_foreign(rb, "fcl")
    assert "if service is not poor and food is not rancid and service is good" in text, text
    assert "not (service is poor or food is rancid)" in write_foreign(rb, "fcl", dialect="iec")
    X = [dict(service=s, food=f) for s in (0.5, 3.0, 6.0, 9.5) for f in (0.5, 4.0, 8.0)]
    from mitos_cli.api import LoadedRuleBase

    for x in X:
        assert LoadedRuleBase(parse_fcl(text)).evaluate(**x)["tip"] == pytest.approx(
            LoadedRuleBase(rb).evaluate(**x)["tip"], abs=1e-12)
    odd = fcl.replace("AND : MIN;", "AND : MIN; OR : BSUM;", 1)
    with pytest.raises(FormatError, match="fuzzylite's FCL has no `not` over a group"):
        write_foreign(parse_fcl(odd, "x.fcl"), "fcl")


def test_fidelity_fuzzylite6_samples_100_points_where_the_file_gives_none(capsys) -> None:
    """fuzzylite 6 reads an FCL `METHOD : COG;` (and a .fis centroid, an FLL `Centroid`) as
    100 midpoints; fuzzylite 8 reads an FLL `Centroid` as 1000. `--fidelity fuzzylite6` and
    `fuzzylite` sample so; a resolution the file writes is kept by both."""
    import re

    src = DATA / "dimmer_fuzzylite.fcl"
    text = src.read_text()
    assert re.search(r"METHOD\s*:\s*COG\s*;", text)
    six = _eval_json(capsys, str(src), "Ambient=0.3", "--fidelity", "fuzzylite6")
    eight = _eval_json(capsys, str(src), "Ambient=0.3", "--fidelity", "fuzzylite")
    plain = _eval_json(capsys, str(src), "Ambient=0.3")
    assert eight == plain and six != eight
    from mitos_cli.api import LoadedRuleBase
    from mitos_cli.interop.fcl import parse_fcl

    at_100 = re.sub(r"METHOD\s*:\s*COG\s*;", "METHOD : COG 100;", text)
    want = LoadedRuleBase(parse_fcl(at_100, "x.fcl")).evaluate(Ambient=0.3)
    assert six == pytest.approx(dict(want), abs=1e-12)
    at_300 = re.sub(r"METHOD\s*:\s*COG\s*;", "METHOD : COG 300;", text)
    rb = parse_fcl(at_300, "x.fcl")
    from mitos_cli.interop.common import fidelity_settings

    assert LoadedRuleBase(rb, None, fidelity_settings(rb, "fuzzylite6")).evaluate(
        Ambient=0.3) == pytest.approx(dict(LoadedRuleBase(rb).evaluate(Ambient=0.3)))


def test_convert_to_rules_writes_both_files_or_neither(tmp_path: Path, monkeypatch) -> None:
    """The term set was written first and the rule file after it: a rule file that could
    not be written (a directory of its name) left the new term set there alone, and a kill
    between the two a new term set beside the old rule file."""
    import mitos_cli.fileio as fileio

    monkeypatch.chdir(tmp_path)
    (tmp_path / "out.rules").mkdir()
    result = runner.invoke(app, ["convert", str(DATA / "tipper.fis"), "--to", "rules",
                                 "-o", "out.rules"])
    assert result.exit_code == 1 and "is a directory" in result.exception.message
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.rules"]
    (tmp_path / "out.rules").rmdir()
    sets: list = []
    monkeypatch.setattr(fileio, "atomic_write_set", lambda files, anchor, **kw: sets.append(
        ([p.name for p, _ in files], anchor.name)))
    assert runner.invoke(app, ["convert", str(DATA / "tipper.fis"), "--to", "rules", "-o",
                               "out.rules"]).exit_code == 0
    assert sets == [(["out.terms.yaml", "out.rules"], "out.rules")]


def test_convert_to_rules_names_what_it_wrote_as_the_user_would(tmp_path: Path, capsys,
                                                                 monkeypatch) -> None:
    """`mitos convert tipper.fis --to rules` said `wrote /home/.../tipper.rules and ...`
    (absolute), where `export -o` and `convert -o` name what they wrote as given."""
    source = DATA / "tipper.fis"
    monkeypatch.chdir(tmp_path)
    code, err = _run(capsys, "convert", str(source), "--to", "rules")
    assert code == 0 and err.splitlines()[-1] == "wrote tipper.rules and tipper.terms.yaml"
    assert (tmp_path / "tipper.rules").is_file() and (tmp_path / "tipper.terms.yaml").is_file()


def test_convert_to_rules_of_a_file_named_in_another_encoding(tmp_path: Path, capsys,
                                                               monkeypatch) -> None:
    """A source named in bytes that are not UTF-8 (`t\\xff.fis`): `--to rules` was refused
    inside its own output ("invalid YAML: character '\\udcff'", "a defect of `mitos
    convert`"). Its name is written as text (U+FFFD), and a term-set name that cannot be
    (the default one, from the source's) is a usage error asking for -o."""
    import os

    source = Path(os.fsdecode(bytes(tmp_path) + b"/t\xff.fis"))
    source.write_bytes((DATA / "tipper.fis").read_bytes())
    monkeypatch.chdir(tmp_path)
    code, err = _run(capsys, "convert", str(source), "--to", "rules")
    assert code == 2 and "name the output with -o OUT.rules" in " ".join(
        err.replace("│", " ").split()), err
    code, err = _run(capsys, "convert", str(source), "--to", "rules", "-o", "ok.rules")
    assert code == 0, err
    assert (tmp_path / "ok.rules").read_text().startswith(
        "# main: written by `mitos convert` from t\ufffd.fis\n")


def test_convert_and_export_without_a_file_take_the_packaged_rule_base(tmp_path: Path,
                                                                      monkeypatch, capsys) -> None:
    """As `eval`, `check`, `plot` and `simulate` do (the README: "a command that names no rule
    file ... uses the packaged ones"); both said "Missing argument 'FILE'"."""
    from mitos_cli.api import default_rulebase_path

    monkeypatch.chdir(tmp_path)
    packaged = str(default_rulebase_path())
    for args, written in ((["convert", "--to", "fll", "-b", "cruise"], "Engine: cruise"),
                          (["export", "--to", "python"], "def evaluate(")):
        code, told_less = run_main(args, capsys)
        assert code == 0, told_less
        code, named = run_main([args[0], packaged, *args[1:]], capsys)
        assert code == 0 and told_less == named and written in told_less
    code, output = run_main(["convert", "--to", "rules"], capsys)
    assert code == 0 and "wrote mitos.rules and mitos.terms.yaml" in output
    assert (tmp_path / "mitos.rules").is_file()
