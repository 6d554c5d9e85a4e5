"""Terms as users see them: the shape and parameters a term set writes, never the registry's
internal names (``triangle_pw`` is the paper's eq. 15 triangle, written ``shape: triangle``)."""

from __future__ import annotations

import re

import pytest

from mitos_cli.lang.termfile import parse_termset

TERMS = {
    "PW": ("{shape: triangle, peak: 70, width: 30}", "triangle", "peak 70, width 30"),
    "PLR": ("{shape: triangle, peak: 70, left_width: 10, right_width: 25}", "triangle",
            "peak 70, left_width 10, right_width 25"),
    "ABC": ("{shape: triangle, points: [10, 40, 70]}", "triangle", "points [10, 40, 70]"),
    "TRAP": ("{shape: trapezoid, a: 1, b: 2, c: 3, d: 4}", "trapezoid", "a 1, b 2, c 3, d 4"),
    "LS": ("{shape: left_shoulder, points: [40, 70]}", "left_shoulder", "a 40, b 70"),
    "G": ("{shape: gaussian, mean: 50, sigma: 2.5}", "gaussian", "mean 50, sigma 2.5"),
    "D": ("{shape: discrete, points: [0, 0, 50, 1, 100, 0]}", "discrete",
          "points [0, 0, 50, 1, 100, 0]"),
}


def termset(terms: dict[str, str]):
    body = "".join(f"      {name}: {spec}\n" for name, spec in terms.items())
    return parse_termset("variables:\n  road:\n    role: input\n    universe: [0, 160]\n"
                         f"    terms:\n{body}")


@pytest.mark.parametrize("name", TERMS)
def test_a_term_is_shown_as_its_term_set_writes_it(name):
    spec, shape, params = TERMS[name]
    term = termset({name: spec}).variables[0].term(name)
    assert (term.shape_name, term.params_text()) == (shape, params)
    # what is shown reads back as the same term
    shown = re.sub(r"(\w+) ", r"\1: ", params)
    again = termset({name: f"{{shape: {shape}, {shown}}}"}).variables[0].term(name)
    assert (again.shape, again.params) == (term.shape, term.params)


def test_a_singleton_shows_its_value_alone():
    term = termset({"STOP": "{shape: singleton, value: 0.5}"}).variables[0].term("STOP")
    assert (term.shape_name, term.params_text()) == ("singleton", "0.5")


def test_a_misspelt_key_of_a_triangle_is_pointed_at_with_a_suggestion():
    from mitos_cli.errors import TermSetError

    with pytest.raises(TermSetError) as info:
        termset({"MEDIUM": "{shape: triangle, peek: 70, width: 30}"})
    err = info.value
    assert "unknown key `peek`" in err.message and err.hint == "did you mean `peak`?"
    assert err.span.line == 6 and err.span.column == 33


@pytest.mark.parametrize("spec, words", [
    ("{shape: concave, inflection: 3, end: 3}", "inflection and end must differ, not both 3"),
    ("{shape: binary, start: 3, direction: 3}", "start and direction must differ"),
    ("{shape: arc, start: 3, end: 3}", "start and end must differ"),
])
def test_parameters_that_must_differ_are_named_as_the_shape_names_them(spec, words):
    """`concave` was refused with "start and end must differ": it has no `start`."""
    from mitos_cli.errors import TermSetError

    with pytest.raises(TermSetError, match=words):
        termset({"T": spec})


@pytest.mark.parametrize("name, words", [
    ("very", "term `road.very` is a hedge word"),
    ("not", "term `road.not` is a keyword"),
    ('"a.b"', "term `road.a.b` holds what a name in a rule cannot"),
    ('"1x"', "term `road.1x` holds what a name in a rule cannot"),
])
def test_a_term_name_no_rule_could_write_is_refused_at_its_key(name, words):
    """A term named `very` or `a.b` was read, and every rule naming it was a syntax error in
    the rule file; keywords a rule reads as names where one stands (`end`, `is`) still are."""
    from mitos_cli.errors import TermSetError

    with pytest.raises(TermSetError, match=re.escape(words)) as info:
        termset({name: "{shape: triangle, peak: 70, width: 30}", "W": "80"})
    assert (info.value.span.line, info.value.span.column) == (6, 7)
    for fine in ("end", "is", "x-y", "_a"):
        assert termset({fine: "80"}).variables[0].term(fine)


@pytest.mark.parametrize("value", ["yes", "off", "1"])
def test_frozen_refuses_what_is_not_true_or_false(value):
    """`frozen: yes` froze the term (YAML 1.1 reads it as true) while `frozen: 1` was refused;
    booleans are now read as YAML 1.2 reads them, in term sets as in worlds."""
    from mitos_cli.errors import TermSetError

    with pytest.raises(TermSetError) as info:
        termset({"MID": f"{{shape: triangle, points: [2, 5, 8], frozen: {value}}}"})
    assert f"`frozen` must be true or false, not `{value}`" in info.value.message
    assert info.value.span.line == 6


@pytest.mark.parametrize("value, said", [("null", "`null`"), ("~", "`~`"), ("[1]", "a list")])
def test_frozen_of_nothing_is_quoted_as_written(value, said):
    """`frozen: null` read "not `None`", Python's word for it (the worlds' flags did too)."""
    from mitos_cli.errors import TermSetError

    with pytest.raises(TermSetError) as info:
        termset({"MID": f"{{shape: triangle, points: [2, 5, 8], frozen: {value}}}"})
    assert info.value.message.endswith(f"`frozen` must be true or false, not {said}")


@pytest.mark.parametrize("written", ["7.0e400", "-1.5E+999"])
def test_a_number_past_a_floats_range_is_named_as_written(written):
    """YAML reads `7.0e400` as inf, and the error said "not `inf`" of a number the user
    never wrote as such; `-.inf` written as such is still "not `-inf`"."""
    from mitos_cli.errors import TermSetError

    text = f"x: {{role: input, universe: [0, 10], terms: {{A: {{shape: triangle, peak: {written}, width: 1}}}}}}"
    with pytest.raises(TermSetError) as info:
        parse_termset("variables:\n  " + text + "\n")
    assert info.value.message.endswith(f"peak must be a finite number: `{written}` is past a float's range")
    with pytest.raises(TermSetError) as info:
        parse_termset("variables:\n  " + text.replace(written, "-.inf") + "\n")
    assert info.value.message.endswith("peak must be a finite number, not `-inf`")


@pytest.mark.parametrize("text, words", [
    ("x: {role: input, universe: [-1e308, 1e308], terms: {A: {shape: triangle, "
     "points: [-1, 0, 1]}}}", "universe bound is -1e+308"),
    ("x: {role: input, universe: [0, 10], terms: {A: {shape: triangle, "
     "points: [0, 5, 1e151]}}}", "point is 1e+151"),
    ("y: {role: output, universe: [0, 1.7e308], terms: {B: 1e300}}", "universe bound is 1.7e+308"),
    ("y: {role: output, universe: [0, 1], terms: {B: {shape: linear, "
     "coefficients: {}, constant: -1e200}}}", "constant is -1e+200"),
])
def test_a_number_past_what_the_engine_computes_without_overflow_is_refused_at_it(text, words):
    """As the foreign readers refuse it (interop.md, "Numbers"): a universe of ±1e308 made a
    Mamdani grid's step `inf` (a traceback) or its output a silent 0.0, and two rules
    concluding 1.7e308 averaged to `inf`."""
    from mitos_cli.errors import TermSetError

    with pytest.raises(TermSetError) as info:
        parse_termset("variables:\n  " + text + "\n")
    assert words in info.value.message
    assert "numbers beyond ±1e+150 cannot be evaluated" in info.value.message
    assert info.value.span is not None and info.value.span.line == 2
