"""Numbers a reader cannot compute with are refused where they are written: a range that is
infinite, NaN, empty or too narrow, or a defuzzifier resolution beyond what MITOS samples
(each once told at the variable's name or at 1:1), in FLL, FIS and FCL."""

from __future__ import annotations

import pytest
from test_interop_errors import FCL, FIS, FLL, line_of

from mitos_cli.errors import MitosError
from mitos_cli.interop.fcl import parse_fcl
from mitos_cli.interop.fis import parse_fis
from mitos_cli.interop.fll import parse_fll


def _refused(parse, text: str, at: str, words: str) -> None:
    """``parse`` refuses ``text`` saying ``words``, its span starting where ``at`` does."""
    with pytest.raises(MitosError) as info:
        parse(text, "bad")
    span = info.value.span
    assert words in info.value.message, info.value.render()
    assert span is not None and span.line == line_of(text, at), info.value.render()
    assert span.column == text.splitlines()[span.line - 1].index(at) + 1, info.value.render()


@pytest.mark.parametrize("old, new, at, words", [
    ("range: 0 10", "range: -inf inf", "-inf inf", "the range is -inf"),
    ("range: 0 10", "range: nan 10", "nan 10", "its ends must be numbers"),
    ("range: 0 10", "range: 10 10", "10 10", "range [10, 10] is empty"),
    ("range: 0 10", "range: 0 1e-302", "0 1e-302", "too narrow to compute with"),
    ("range: 0 10", "range: 0 1e-320", "0 1e-320", "too narrow to compute with"),
    ("defuzzifier: Centroid 200", "defuzzifier: Centroid 1e9", "Centroid 1e9",
     "resolution must be a whole number from 3 to 100000"),
])
def test_fll(old: str, new: str, at: str, words: str) -> None:
    _refused(parse_fll, FLL.replace(old, new, 1), at, words)


@pytest.mark.parametrize("new, words", [
    ("Range=[-inf inf]", "the range is -inf"),
    ("Range=[0 1e-320]", "too narrow to compute with"),
])
def test_fis(new: str, words: str) -> None:
    assert "Range=[0 10]" in FIS
    _refused(parse_fis, FIS.replace("Range=[0 10]", new, 1), new[len("Range="):], words)


@pytest.mark.parametrize("new, words", [
    ("RANGE := (0 .. 1e-320);", "too narrow to compute with"),
    ("RANGE := (-inf .. inf);", "the range is -inf"),
])
def test_fcl(new: str, words: str) -> None:
    assert "RANGE := (0 .. 30);" in FCL
    _refused(parse_fcl, FCL.replace("RANGE := (0 .. 30);", new, 1), new[:-1], words)


# ---- writers: a refusal points at what the source file says -----------------------------------

def test_a_writer_refusing_a_term_gives_the_terms_position(tmp_path) -> None:
    """`MATLAB has no `discrete` membership function` had no file:line:col."""
    from pathlib import Path

    from mitos_cli.api import read_rulebase
    from mitos_cli.interop import write_foreign

    source = Path(__file__).parent / "data" / "interop" / "robot_jfuzzylogic.fcl"
    text = source.read_text().replace("TERM far := (1, 0) (2, 1) (3, 1);",
                                      "TERM far := (1, 0) (2, 1) (3, 0.5);")
    path = tmp_path / "disc.fcl"
    path.write_text(text)
    with pytest.raises(MitosError) as info:
        write_foreign(read_rulebase(path), "fis")
    assert "MATLAB has no `discrete` membership function" in info.value.message
    line = next(i for i, s in enumerate(text.splitlines(), 1) if "TERM far" in s)
    assert str(info.value.span) == f"{path}:{line}:2"


@pytest.mark.parametrize("to, words", [("fis", "MATLAB has no `formula` membership function"),
                                       ("fcl", "FCL has no formula terms")])
def test_a_formula_term_is_refused_at_its_place_by_both_writers(to: str, words: str) -> None:
    """`--to fis` gave the formula term's `check_formula_input.fll:6:21` and source line;
    `--to fcl` refused the same term with neither."""
    from pathlib import Path

    from mitos_cli.api import read_rulebase
    from mitos_cli.interop import write_foreign

    path = Path(__file__).parent / "data" / "interop" / "check_formula_input.fll"
    with pytest.raises(MitosError) as info:
        write_foreign(read_rulebase(path), to)
    assert words in info.value.message
    assert str(info.value.span) == f"{path}:6:21"
    assert "term: lo Function 1 - x" in info.value.render()


def test_a_writer_refusing_an_operator_points_at_the_operators_line(tmp_path):
    from pathlib import Path

    from mitos_cli.api import read_rulebase
    from mitos_cli.errors import FormatError
    from mitos_cli.interop import write_foreign

    terms = Path(__file__).parents[1] / "rulebases" / "mitos.terms.yaml"
    (tmp_path / "mitos.terms.yaml").write_text(terms.read_text())
    path = tmp_path / "lk.rules"
    path.write_text('terms "mitos.terms.yaml"\noperators: and = lukasiewicz\n'
                    "r1: if road is WIDE and size is SMALL_SZ then steering is RS\n")
    with pytest.raises(FormatError) as info:
        write_foreign(read_rulebase(path), "fis")
    assert "FIS has no AND method `lukasiewicz`" in info.value.message
    assert str(info.value.span) == f"{path}:2:12"


def test_a_foreign_files_operator_is_refused_where_the_file_sets_it(tmp_path) -> None:
    from mitos_cli.api import read_rulebase
    from mitos_cli.errors import FormatError
    from mitos_cli.interop import write_foreign

    text = FLL.replace("conjunction: Minimum", "conjunction: NilpotentMinimum")
    path = tmp_path / "n.fll"
    path.write_text(text)
    with pytest.raises(FormatError) as info:
        write_foreign(read_rulebase(path), "fis")
    assert "FIS has no AND method `nilpotent_minimum`" in info.value.message
    assert info.value.span is not None and info.value.span.line == line_of(
        text, "conjunction: NilpotentMinimum")


@pytest.mark.parametrize("fmt", ["fcl", "fll"])
@pytest.mark.parametrize("rule, column", [("if a is extremely high then y is hi", 8),
                                          ("if a is high then y is extremely hi", 23)])
def test_a_hedge_fuzzylite_lacks_is_refused_where_the_rule_uses_it(tmp_path, fmt, rule,
                                                                     column) -> None:
    """`fuzzylite has no hedge like MITOS's `extremely`` had no file:line:col to find it by."""
    from mitos_cli.api import read_rulebase
    from mitos_cli.errors import FormatError
    from mitos_cli.interop import write_foreign

    (tmp_path / "t.terms.yaml").write_text(
        "variables:\n  a: {role: input, universe: [0, 10], terms: {high: {shape: "
        "right_shoulder, points: [2, 8]}}}\n"
        "  y: {role: output, universe: [0, 1], terms: {hi: {shape: triangle, "
        "points: [0.5, 1, 1]}}}\n")
    path = tmp_path / "t.rules"
    # weighted inference: a hedged Mamdani consequent is refused before its hedge is named
    path.write_text(f'terms "t.terms.yaml"\noperators: inference = weighted_average\nr1: {rule}\n')
    with pytest.raises(FormatError, match="fuzzylite has no hedge like MITOS's `extremely`") \
            as info:
        write_foreign(read_rulebase(path), fmt)
    assert str(info.value.span) == f"{path}:3:{column}"


#: characters ``str.splitlines`` breaks a line at, which no editor or reader's lexer does
NOT_BREAKS = ["\x0b", "\x0c", "\x1c", "\x85", "\u2028", "\u2029"]


@pytest.mark.parametrize("char", NOT_BREAKS)
@pytest.mark.parametrize("parse, text, inside, old, new", [
    (parse_fll, FLL, "Engine: test # a", "term: low Triangle 0 2 5", "term low Triangle 0 2 5"),
    (parse_fis, FIS, "[System]\n% a", "Version=2.0", "Versoin=2.0"),
    (parse_fcl, FCL, "// Block definition", "RULE 2 : IF service IS good",
     "RULE 2 : IF service ISgood"),
])
def test_a_line_is_the_editors_line_past_a_character_splitlines_breaks_at(
        char, parse, text, inside, old, new) -> None:
    """A vertical tab, form feed, U+0085 or U+2028 in a line (a comment, a description) put
    every later message a line off: the FLL and ``.fis`` readers numbered lines with
    ``str.splitlines`` (the line after the mistake named), and the caret of FCL's showed the
    line before the one Lark named."""
    where = inside.split("\n")[0].split(" #")[0]     # what ``inside`` adds to
    assert where in text
    bad = text.replace(where, inside + " " + char + " b", 1).replace(old, new, 1)
    with pytest.raises(MitosError) as info:
        parse(bad, "bad")
    span = info.value.span
    line = next(i for i, x in enumerate(bad.split("\n"), 1) if new in x)
    assert span is not None and span.line == line, info.value.render()
    assert span.source_line is not None and new in span.source_line, info.value.render()


def test_an_fcl_file_with_lone_cr_line_ends_reads_as_with_lf() -> None:
    """jFuzzyLogic ends a `//` comment at `\\r` too: the first line's comment took the whole of
    a classic Mac OS file ("unexpected end of file" at line 1), and a mistake was named at
    line 1."""
    cr = parse_fcl(FCL.replace("\n", "\r"), "x.fcl")
    lf = parse_fcl(FCL, "x.fcl")
    assert cr.behaviors == lf.behaviors and len(cr.behaviors[0].rules) == 4
    bad = FCL.replace("IF service IS good", "IF service ISgood").replace("\n", "\r")
    with pytest.raises(MitosError) as info:
        parse_fcl(bad, "cr.fcl")
    span = info.value.span
    assert span is not None and span.line == line_of(FCL, "IF service IS good")
    assert span.source_line is not None and "ISgood" in span.source_line
