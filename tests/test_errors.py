"""Every error a user can meet in the rule language, term sets, inputs and the CLI.

Each test triggers one message and checks what the user reads: the position
(``path:line:col``), the offending line with a caret, what was expected in words, a hint
(did you mean ...), and never ``$END``, ``Token(`` or a traceback.
"""

from __future__ import annotations

import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from mitos_cli import load_rulebase
from mitos_cli.cli.app import main
from mitos_cli.errors import (
    InputError,
    MitosError,
    NameError_,
    NoRuleFiredError,
    RuleBaseError,
    RuleSyntaxError,
    TermSetError,
)
from mitos_cli.lang.model import Consequent, Prop, Rule
from mitos_cli.lang.resolve import check_rule, load_rules_file

ROOT = Path(__file__).resolve().parents[1]
TERMS = (ROOT / "rulebases" / "mitos.terms.yaml").read_text(encoding="utf-8")
GOOD_RULE = ("r1: if road is WIDE and size is SMALL_SZ and position is LEFT "
             "then steering is RS and speed is MEDIUM")


def write(tmp_path: Path, rules: str, terms: str = TERMS) -> Path:
    (tmp_path / "t.terms.yaml").write_text(terms, encoding="utf-8")
    path = tmp_path / "t.rules"
    path.write_text('terms "t.terms.yaml"\n' + rules, encoding="utf-8")
    return path


def error_of(fn, cls=MitosError) -> MitosError:
    with pytest.raises(cls) as info:
        fn()
    exc = info.value
    text = exc.render()
    for leak in ("$END", "Token(", "Traceback", "Tree(", "UnexpectedToken", "lark"):
        assert leak not in text, text
    return exc


def caret_under(exc: MitosError) -> str:
    """The text the caret points at (checks that line, column and caret agree)."""
    lines = exc.render().splitlines()
    src, caret = lines[1], lines[2]
    assert src.startswith("    ") and set(caret.strip()) == {"^"}, exc.render()
    start = caret.index("^")
    return src[start:start + len(caret.strip())]


# ---------------------------------------------------------------------------------------------
# syntax errors


@pytest.mark.parametrize("line, col, at, message, expected, hint", [
    ("r1: if road WIDE then speed is SLOW", 13, "WIDE", "unexpected `WIDE`", "`is`",
     "a condition reads `variable is TERM`"),
    ("r1: if road is WIDE & size is SMALL_SZ then speed is SLOW", 21, "&",
     "unexpected character `&`", None, None),
    ("r1: if road is WIDE speed is SLOW", 21, "speed", "unexpected `speed`", "`then`",
     "start the actions with `then`"),
    ("r1: if road is vary WIDE then speed is SLOW", 21, "WIDE", "unexpected `WIDE`", "`then`",
     "did you mean `very`?"),
    ("r1: if road is WIDE then speed is SLOW with", 44, None, "unexpected end of the input",
     "a number", "incomplete"),
    ("r1: if road is WIDE then speed is", 34, None, "unexpected end of the input", "a name",
     None),
    ("r1: if (road is WIDE then speed is SLOW", 22, "then", "unexpected `then`", "`)`", None),
    # (until 2026-12-07 read as `if f`, then "unexpected `road`": the lexer took `if` off
    # the front of `iff` where only `if` may stand)
    ("r1: iff road is WIDE then speed is SLOW", 5, "iff", "unexpected `iff`", "`if`",
     "did you mean `if`?"),
    ("r1: if road is WIDE thn speed is SLOW", 21, "thn", "unexpected `thn`", "`then`",
     "did you mean `then`?"),
    # `=` for `is`, and FCL's `;` at a rule's end: said how a rule file writes them
    ("r1: if road = WIDE then speed is SLOW", 13, "=", "unexpected `=`", "`is`",
     "write `road is ...`: a condition or action reads `variable is TERM` (or `is 5` for a "
     "crisp value), not `=`"),
    ("r1: if road is WIDE then speed = 5", 32, "=", "unexpected `=`", "`is`",
     "write `speed is ...`"),
    ("r1: if road is WIDE then speed is SLOW;", 39, ";", "unexpected character `;`", None,
     "a rule needs no `;` at its end"),
    # a term frozen as the teaching prompt freezes it (`frozen heading.AHEAD`): a rule file
    # freezes rules, and a term in its term set; it said "expected `,` or a name" alone
    ("behavior b:\n  r1: if road is WIDE then speed is SLOW\n  frozen r1, road.WIDE\n", 18,
     ".", "unexpected character `.`", "`,` or a name",
     "a rule file freezes rules (`frozen r1`); a term is frozen in its term set, `frozen: true` "
     "on `WIDE` of `road` (`frozen road.WIDE` is a `mitos teach` command)"),
    ("behavior b:\n  r1: if road is WIDE then speed is SLOW\n", 41, None,
     "unexpected end of the input", "`end`", "a behavior ends with `end`"),
    # a misspelt statement keyword is read as a rule's label: the word is reported, with
    # which keyword it was
    ("behaviour b:\n", 1, "behaviour", "unexpected `behaviour` after `\"t.terms.yaml\"`",
     "`behavior`", "`behaviour` is not a keyword: did you mean `behavior`?"),
    ("operator: and = product\n", 11, "and", "unexpected `and`", "`if`",
     "`operator` is not a keyword: did you mean `operators`?"),
    ("behavior b:\n  r1: if road is WIDE then speed is SLOW\n  frozn r1\n", 3, "frozn",
     "unexpected `frozn` after `SLOW`", "`frozen`",
     "`frozn` is not a keyword: did you mean `frozen`?"),
    ("behavior b:\n  r1: if road is WIDE then speed is SLOW\nedn\n", 1, "edn",
     "unexpected `edn` after `SLOW`", "`end`", "`edn` is not a keyword: did you mean `end`?"),
    # a stray word at a rule's end is read as the next rule's label: the word is reported
    ("r1: if road is WIDE then speed is MEDIUM wiht 0.5\n", 42, "wiht",
     "unexpected `wiht` after `MEDIUM`", "`with`", "did you mean `with`?"),
    ("r1: if road is WIDE then speed is MEDIUM xyzzy\n", 42, "xyzzy",
     "unexpected `xyzzy` after `MEDIUM`", "a rule's label",
     "`xyzzy` is read as the label of a new rule, which needs `:` after it on the same line"),
    # a label without its `:`
    ("r1 if road is WIDE then speed is SLOW\n", 4, "if", "unexpected `if`", "`:`",
     "a rule's label ends with `:` (`r1: if ...`)"),
    ("foo bar\n", 5, "bar", "unexpected `bar`", "`:`",
     "`foo` is read as a rule's label, which ends with `:`"),
    # a variable's name before a missing `is` is no misspelt keyword (`temp` is not `terms`)
    ("r1: if size is SMALL_SZ and temp SMALL_SZ then speed is SLOW", 34, "SMALL_SZ",
     "unexpected `SMALL_SZ`", "`is`", "a condition reads `variable is TERM`"),
    # a hedge (or `is`) before `then`: `then` is read as the term, and the error is at the
    # word after it, "expected `then`"; the hint says what happened
    ("r1: if road is any then speed is SLOW", 25, "speed", "unexpected `speed`", "`then`",
     "`then` was read as a term: after `is` (and `not` and hedges) a term is named "
     "(`is any TERM`)"),
    ("r1: if road is WIDE and size is not then speed is SLOW", 42, "speed",
     "unexpected `speed`", "`then`", "(`is not TERM`)"),
    # a number past a float's range read as inf: "steering = inf lies outside its universe"
    ("r1: if road is WIDE then steering is 2e400", 38, "2e400", "`2e400` is past a float's range",
     "a number within", None),
    # one too small, read as 0: `with 1e-400` switched the rule off without a word
    ("r1: if road is WIDE then speed is SLOW with 1e-400", 45, "1e-400",
     "`1e-400` is too small for a float: it would read as 0", "at least 5e-324", None),
    ("r1: if road is WIDE then speed is -2.5e-400", 35, "-2.5e-400",
     "`-2.5e-400` is too small for a float", "at least 5e-324", None),
    # joined with a comma, or with nothing, and two words after `is`: said how they are written
    ('r1: if road is WIDE, size is SMALL_SZ then speed is SLOW', 20, ',', 'unexpected `,`', None,
     'conditions are joined with `and` or `or`, not `,`'),
    ('r1: if road is WIDE then steering is RS, speed is SLOW', 40, ',', 'unexpected `,`', None,
     'actions are joined with `and`, not `,`'),
    ('r1: if road is WIDE then steering is RS speed is SLOW', 47, 'is', 'unexpected `is`', '`:`',
     'actions are joined with `and`: `... and speed is ...`'),
    ('r1: if road is FAR WIDE then speed is SLOW', 20, 'WIDE', 'unexpected `WIDE`', '`then`',
     "`FAR WIDE`: a term's name is one word (`FAR_WIDE`), and `FAR` is not a hedge"),
    ('r1: if road is sorta WIDE then speed is SLOW', 22, 'WIDE', 'unexpected `WIDE`', '`then`',
     '`sorta` is not a hedge (very, extremely, somewhat'),
    # `is` glued to the next word: it was read as `is` and the rest (`isWIDE` as `is WIDE`,
    # `iss WIDE` as the term `s`, the error at `WIDE` with a hint about `and` / `or`)
    ('r1: if road isWIDE then speed is SLOW', 13, 'isWIDE', 'unexpected `isWIDE`', '`is`',
     '`is` and `WIDE` are two words: `road is WIDE`'),
    ('r1: if road is WIDE then speed isSLOW', 32, 'isSLOW', 'unexpected `isSLOW`', '`is`',
     '`is` and `SLOW` are two words: `speed is SLOW`'),
    ('r1: if road isnot WIDE then speed is SLOW', 13, 'isnot', 'unexpected `isnot`', '`is`',
     '`is` and `not` are two words: `road is not`'),
    ('r1: if road is WIDE then steering is90', 35, 'is90', 'unexpected `is90`', '`is`',
     '`is` and `90` are two words: `steering is 90`'),
    ('r1: if road iss WIDE then speed is SLOW', 13, 'iss', 'unexpected `iss`', '`is`',
     'did you mean `is`?'),
    ('r1: if (road is WIDE) and size isvery SMALL_SZ then speed is SLOW', 32, 'isvery',
     'unexpected `isvery`', '`is`', '`is` and `very` are two words: `size is very`'),
    # every keyword is a word of its own: where only `if` may stand (after a label), `ifroad`
    # was read as `if road` without a word
    ('r1: ifroad is WIDE then speed is SLOW', 5, 'ifroad', 'unexpected `ifroad`', '`if`',
     '`if` and `road` are two words: `if road`'),
    ('r1: ifnot road is WIDE then speed is SLOW', 5, 'ifnot', 'unexpected `ifnot`', '`if`',
     '`if` and `not` are two words: `if not`'),
    ('r1: ifff road is WIDE then speed is SLOW', 5, 'ifff', 'unexpected `ifff`', '`if`',
     'did you mean `if`?'),
    # a term glued to a joining keyword, or the keyword to the next word, is one name: the
    # error after it said "join conditions with `and` / `or`" (`andspeed is`: "actions are
    # joined with `and`: `... and andspeed is ...`")
    ('r1: if road is WIDEand size is SMALL_SZ then speed is SLOW', 24, 'size',
     'unexpected `size`', '`then`', '`WIDEand` is read as one name: `WIDE` and `and` are '
     'two words'),
    ('r1: if road is WIDEthen speed is SLOW', 25, 'speed', 'unexpected `speed`', '`then`',
     '`WIDEthen` is read as one name: `WIDE` and `then` are two words'),
    ('r1: if road is WIDE andsize is SMALL_SZ then speed is SLOW', 21, 'andsize',
     'unexpected `andsize`', '`then`', '`andsize` is read as one name: `and` and `size` are '
     'two words'),
    ('r1: if road is WIDE then steering is RS andspeed is SLOW', 50, 'is', 'unexpected `is`',
     '`:`', '`andspeed` is read as one name: `and` and `speed` are two words'),
    ('r1: if road is WIDE then speed is SLOWwith 0.5', 44, '0.5', 'unexpected `0.5`', None,
     '`SLOWwith` is read as one name: `SLOW` and `with` are two words'),
])
def test_syntax_errors(tmp_path, line, col, at, message, expected, hint):
    path = write(tmp_path, line)
    exc = error_of(lambda: load_rules_file(path), RuleSyntaxError)
    text = exc.render()
    lineno = 1 + line.rstrip("\n").count("\n") + 1
    assert text.startswith(f"{path}:{lineno}:{col}: syntax error: {message}"), text
    if at is not None:
        assert caret_under(exc) == at
    if expected:
        assert text.splitlines()[3].startswith("expected ")
        assert expected in text.splitlines()[3]
    if hint:
        assert "hint:" in text and hint in text
    assert "did you mean `terms`" not in text


@pytest.mark.parametrize("typo, line, col, message, hint", [
    ("  r1: if road is WIDE then speed is MEDIUM andd\n", 3, 44,
     "unexpected `andd` after `MEDIUM`", "did you mean `and`?"),
    ("  r1: if road is WIDE then speed is MEDIUM\nned\n# comment\n", 4, 1,
     "unexpected `ned` after `MEDIUM`", "did you mean `end`?"),
])
def test_a_stray_word_is_reported_not_the_next_label(tmp_path, typo, line, col, message, hint):
    """A word at a rule's end, or a misspelt `end`, is read as the next rule's label; the
    error was at the next line's `r2` (or `behavior`), "expected `:`". It is at the word."""
    path = write(tmp_path, "behavior a:\n" + typo + "  r2: if road is NARROW then speed is SLOW\n"
                 "end\nbehavior b:\n  r3: if road is WIDE then speed is SLOW\nend\n")
    exc = error_of(lambda: load_rules_file(path), RuleSyntaxError)
    assert exc.message == message and str(exc.span) == f"{path}:{line}:{col}"
    assert caret_under(exc) == message.split("`")[1]
    assert hint in exc.hint and "`:`" not in (exc.expected or "")


@pytest.mark.parametrize("header", ["behavior a", "behavior a   # the first one"])
def test_a_header_without_its_colon_is_said_at_its_end(tmp_path, header):
    """`behavior a` without `:` was "unexpected `r1`, expected `:`" at the next line."""
    path = write(tmp_path, header + "\n  r1: if road is WIDE then speed is SLOW\nend\n")
    exc = error_of(lambda: load_rules_file(path), RuleSyntaxError)
    assert exc.message == "missing `:` after `behavior a`"
    assert str(exc.span) == f"{path}:2:11" and exc.expected == "`:` at the end of the line"
    assert exc.render().splitlines()[2] == "    " + " " * len("behavior a") + "^"


@pytest.mark.parametrize(("operators", "after", "message", "col"), [
    # the next line's first word was read as the value: "unexpected `r1`, expected `if`" two
    # lines down, or "unexpected `:`" at the next rule
    ("operators: accumulation = ", "behavior b:\n  r1: if road is WIDE then speed is SLOW\nend\n",
     "the operators line ends after `accumulation =`: a value is missing", 25),
    ("operators: and =   # the AND", "r1: if road is WIDE then speed is SLOW\n",
     "the operators line ends after `and =`: a value is missing", 16),
    ("operators: and = min,", "\nr1: if road is WIDE then speed is SLOW\n",
     "the operators line ends after `and = min,`: a setting is missing", 21),
])
def test_an_operators_line_cut_short_is_said_at_its_end(tmp_path, operators, after, message,
                                                        col):
    path = write(tmp_path, operators + "\n" + after)
    exc = error_of(lambda: load_rules_file(path), RuleSyntaxError)
    assert exc.message == message and str(exc.span) == f"{path}:2:{col}"
    assert "`NAME = VALUE` settings" in exc.expected


def test_an_operators_line_wrapped_on_purpose_still_reads(tmp_path):
    path = write(tmp_path, "operators: and = min,\n    or = max\n"
                           "r1: if road is WIDE then speed is SLOW\n")
    assert load_rules_file(path).behaviors
    bad = write(tmp_path, "operators: and = min,\n    or = max\n"
                          "r1: if road is WIDE then speed SLOW\n")
    assert "operators line" not in error_of(lambda: load_rules_file(bad), RuleSyntaxError).message


def test_syntax_error_in_a_wrapped_rule_points_at_its_line(tmp_path):
    path = write(tmp_path, "r1: if road is WIDE\n    and size SMALL_SZ\n    then speed is SLOW\n")
    exc = error_of(lambda: load_rules_file(path), RuleSyntaxError)
    assert str(exc.span) == f"{path}:3:14"
    assert caret_under(exc) == "SMALL_SZ"


def test_binary_file_is_refused(tmp_path):
    path = tmp_path / "junk.rules"
    path.write_bytes(b"\x89PNG\r\n\x1a\n\x00\xff\xfe")
    exc = error_of(lambda: load_rules_file(path), RuleBaseError)
    assert "not a text file" in exc.message and exc.span.path == str(path)
    path.write_bytes(b'terms "t.yaml"\nbehavior a:\n  r1: if x is \xe9 then y is z\n')
    exc = error_of(lambda: load_rules_file(path), RuleBaseError)
    assert exc.message.endswith("is not a text file (byte 0xe9 is not UTF-8)")
    assert (exc.span.line, exc.span.column) == (3, 15)


def test_control_characters_are_shown_not_sent_to_the_terminal():
    """A file's ESC (a colour or a cursor move) was echoed raw in the message's quoted line,
    and acted on the terminal: it is now shown as an escape, and in the quoted line as one
    character, so the caret stays under what it points at."""
    from mitos_cli.errors import Span

    line = "eval road=78 \x01size=45\x1b[31m"
    err = RuleSyntaxError("unexpected `\x01size`", span=Span("y.lesson", 1, 14, line,
                                                             end_column=19),
                          expected="`,` \x9b", hint="\x7f")
    text = err.render()
    assert not re.search(r"[\x00-\x08\x0b-\x1f\x7f-\x9f]", text)
    assert text.splitlines() == [
        "y.lesson:1:14: syntax error: unexpected `\\x01size`",
        "    eval road=78 \ufffdsize=45\ufffd[31m",
        "                 ^^^^^",
        "expected `,` \\x9b",
        "hint: \\x7f"]


def test_a_missing_rule_file_guesses_only_a_close_name(tmp_path, capsys):
    """`nosuch.rules` was "did you mean `dup.rules`?": the `.rules` both end in."""
    (tmp_path / "dup.rules").write_text("")
    (tmp_path / "mitos.rules").write_text("")
    for args, hint in ((["simulate", "--rulebase", str(tmp_path / "nosuch.rules")], None),
                       (["eval", str(tmp_path / "nosuch.rules"), "road=1"], None),
                       (["simulate", "--rulebase", str(tmp_path / "mitoss.rules")],
                        f"did you mean `{tmp_path / 'mitos.rules'}`?")):
        with pytest.raises(SystemExit) as info:
            main(args)
        err = capsys.readouterr().err
        # a path over 200 characters is abridged: `.../x.rules` (230 characters) not found
        assert info.value.code == 1
        assert re.search(r"rule file `.*` (\(\d+ characters\) )?not found", err), err
        assert (f"hint: {hint}" in err) if hint else "did you mean" not in err, err


def test_missing_rule_file():
    exc = error_of(lambda: load_rules_file("no/such.rules"), RuleBaseError)
    assert "rule file `no/such.rules` not found" in exc.message


# ---------------------------------------------------------------------------------------------
# unknown names: did you mean


@pytest.mark.parametrize("rule, message, hint, at", [
    ("r1: if raod is WIDE then speed is SLOW", "unknown input variable `raod`",
     "did you mean `road`?", "raod"),          # the name only, not `raod is WIDE`
    ("r1: if road is WIDEE then speed is SLOW", "unknown term `WIDEE` of `road`",
     "did you mean `WIDE`?", "WIDEE"),           # the caret under the term itself
    ("r1: if road is WIDE then sped is SLOW", "unknown output variable `sped`",
     "did you mean `speed`?", "sped"),
    ("r1: if road is WIDE then speed is SLWO", "unknown term `SLWO` of `speed`",
     "did you mean `SLOW`?", "SLWO"),
    ("r1: if road is wide then speed is SLOW", "unknown term `wide` of `road`",
     "did you mean `WIDE`?", "wide"),
    # `not` or a hedge glued to the term: "did you mean `WIDE`?" dropped the `not`, and
    # following it turned the condition over
    ("r1: if road is notWIDE then speed is SLOW", "unknown term `notWIDE` of `road`",
     "`not` and `WIDE` are two words: `road is not WIDE`", "notWIDE"),
    ("r1: if road is veryWIDE then speed is SLOW", "unknown term `veryWIDE` of `road`",
     "`very` and `WIDE` are two words: `road is very WIDE`", "veryWIDE"),
    ("r1: if notroad is WIDE then speed is SLOW", "unknown input variable `notroad`",
     "`not` and `road` are two words", "notroad"),
    ("r1: if road is more_or_lessWIDE then speed is SLOW",
     "unknown term `more_or_lessWIDE` of `road`",
     "`more_or_less` and `WIDE` are two words: `road is more_or_less WIDE`",
     "more_or_lessWIDE"),
])
def test_unknown_names(tmp_path, rule, message, hint, at):
    path = write(tmp_path, rule)
    exc = error_of(lambda: load_rules_file(path), NameError_)
    assert exc.message == message
    assert exc.hint == hint
    assert str(exc.span) == f"{path}:2:{rule.index(at) + 1}"
    assert caret_under(exc) == at
    assert exc.expected.startswith("one of ")


def test_unknown_hedge_through_the_api():
    from mitos_cli.api import load_rulebase as lr

    variables = lr().rulebase.variables
    rule = Rule("r", Prop("road", "WIDE", ("vary",)), (Consequent("speed", "SLOW"),))
    exc = error_of(lambda: check_rule(rule, variables), NameError_)
    assert exc.message == "unknown hedge `vary`" and exc.hint == "did you mean `very`?"


def test_unknown_behavior_in_use(tmp_path):
    path = write(tmp_path, "behavior avoid:\n  " + GOOD_RULE + "\nend\n"
                 "behavior go:\n  use avoud when road is WIDE\nend\n")
    exc = error_of(lambda: load_rules_file(path), NameError_)
    assert exc.message == "unknown behavior `avoud`" and exc.hint == "did you mean `avoid`?"
    assert str(exc.span) == f"{path}:6:7"             # the name, not the whole `use` line
    assert caret_under(exc) == "avoud"


def test_unknown_behavior_in_load_rulebase():
    exc = error_of(lambda: load_rulebase(behavior="avoid_obstacel"), NameError_)
    assert exc.hint == "did you mean `avoid_obstacle`?"


def test_output_in_a_condition(tmp_path):
    path = write(tmp_path, "r1: if speed is SLOW then steering is LS")
    exc = error_of(lambda: load_rules_file(path), RuleBaseError)
    assert exc.message == "`speed` is an output variable and cannot appear in a condition"
    assert caret_under(exc) == "speed"


def test_unknown_operator(tmp_path):
    path = write(tmp_path, "operators: and = mni\n" + GOOD_RULE)
    exc = error_of(lambda: load_rules_file(path), NameError_)
    assert exc.message == "unknown T-norm `mni`" and exc.hint == "did you mean `min`?"
    assert str(exc.span).endswith(":2:12")


def test_behavior_defined_twice_is_reported_at_the_second(tmp_path):
    body = "  " + GOOD_RULE + "\nend\n"
    path = write(tmp_path, "behavior a:\n" + body + "behavior b:\n" + body + "behavior a:\n" + body)
    exc = error_of(lambda: load_rules_file(path), RuleBaseError)
    assert exc.message == "behavior `a` is defined twice (first at line 2)"
    assert str(exc.span) == f"{path}:8:10" and caret_under(exc) == "a"


def test_behavior_main_and_top_level_rules(tmp_path):
    path = write(tmp_path, GOOD_RULE + "\nbehavior main:\n  " + GOOD_RULE + "\nend\n")
    exc = error_of(lambda: load_rules_file(path), RuleBaseError)
    assert "behavior `main` is defined twice" in exc.message and exc.span.line == 3
    assert exc.message.endswith("(also by the rules outside any behavior)")


def test_behavior_main_written_twice_says_where_the_first_is(tmp_path):
    """Two `behavior main:` blocks and no top-level rule were said to clash with "the rules
    outside any behavior", which the file has none of."""
    body = "  " + GOOD_RULE + "\nend\n"
    path = write(tmp_path, "behavior main:\n" + body + "behavior main:\n" + body)
    exc = error_of(lambda: load_rules_file(path), RuleBaseError)
    assert exc.message == "behavior `main` is defined twice (first at line 2)"


def test_top_level_rules_after_behavior_main_are_placed(tmp_path):
    """`behavior main: ... end` and then a rule outside any behavior: the clash was said
    with no file:line:col at all; it is said at the first top-level rule."""
    path = write(tmp_path, "behavior main:\n  " + GOOD_RULE + "\nend\n" + GOOD_RULE + "\n")
    exc = error_of(lambda: load_rules_file(path), RuleBaseError)
    assert exc.message.endswith("(also by the rules outside any behavior)")
    assert (exc.span.line, exc.span.column) == (5, 1)


def test_duplicate_label(tmp_path):
    path = write(tmp_path, GOOD_RULE + "\n" + GOOD_RULE)
    exc = error_of(lambda: load_rules_file(path), RuleBaseError)
    assert "rule label `r1` is used twice" in exc.message and exc.span.line == 3


def test_rule_weight_out_of_range(tmp_path):
    path = write(tmp_path, GOOD_RULE + " with 1.5")
    exc = error_of(lambda: load_rules_file(path), RuleBaseError)
    assert exc.message == "a rule weight must lie in [0, 1], not 1.5"


def test_crisp_consequent_outside_universe(tmp_path):
    path = write(tmp_path, "r1: if road is WIDE then steering is 200")
    exc = error_of(lambda: load_rules_file(path), RuleBaseError)
    assert exc.message == "steering = 200 lies outside its universe [30, 150]"


def test_term_set_not_found(tmp_path):
    path = tmp_path / "t.rules"
    path.write_text('terms "nope.yaml"\n' + GOOD_RULE, encoding="utf-8")
    exc = error_of(lambda: load_rules_file(path), TermSetError)
    assert "term set `nope.yaml` not found" in exc.message and caret_under(exc) == '"nope.yaml"'


def test_a_term_set_that_is_a_device_or_a_directory_is_called_what_it_is(tmp_path):
    """`terms "/dev/zero"` was "is a directory"."""
    import os

    (tmp_path / "d.yaml").mkdir()
    os.mkfifo(tmp_path / "p.yaml")
    for name, found in (("d.yaml", "is a directory"), ("p.yaml", "is not a regular file")):
        path = tmp_path / "t.rules"
        path.write_text(f'terms "{name}"\n' + GOOD_RULE, encoding="utf-8")
        exc = error_of(lambda: load_rules_file(path), TermSetError)
        assert f"term set `{name}` {found} (looked for" in exc.message


def test_a_misspelt_term_set_gets_the_close_one_beside_it(tmp_path):
    """`terms "t.term.yaml"` said only "not found" beside a `t.terms.yaml`."""
    path = write(tmp_path, GOOD_RULE)
    path.write_text('terms "t.term.yaml"\n' + GOOD_RULE, encoding="utf-8")
    exc = error_of(lambda: load_rules_file(path), TermSetError)
    assert "term set `t.term.yaml` not found" in exc.message
    assert caret_under(exc) == '"t.term.yaml"' and exc.span.line == 1
    assert exc.hint == "did you mean `t.terms.yaml`?"
    (tmp_path / "sub").mkdir()
    path.write_text('terms "sub/../t.term.yaml"\n' + GOOD_RULE, encoding="utf-8")
    exc = error_of(lambda: load_rules_file(path), TermSetError)
    assert exc.hint == "did you mean `sub/../t.terms.yaml`?"     # as the line names it
    path.write_text('terms "nothing.yaml"\n' + GOOD_RULE, encoding="utf-8")
    exc = error_of(lambda: load_rules_file(path), TermSetError)
    assert exc.hint == "term-set paths are relative to the rule file, and name a YAML file"


def test_term_set_named_twice(tmp_path):
    """`terms "t.terms.yaml", "./t.terms.yaml"` said "variable `road` is defined in two term
    sets" at the one file that defines it."""
    path = write(tmp_path, GOOD_RULE)
    path.write_text('terms "t.terms.yaml", "./t.terms.yaml"\n' + GOOD_RULE, encoding="utf-8")
    exc = error_of(lambda: load_rules_file(path), TermSetError)
    assert exc.message == "term set `./t.terms.yaml` is named twice (also as `t.terms.yaml`)"
    assert caret_under(exc) == '"./t.terms.yaml"' and exc.span.line == 1


def test_no_term_set(tmp_path):
    path = tmp_path / "t.rules"
    path.write_text(GOOD_RULE, encoding="utf-8")
    exc = error_of(lambda: load_rules_file(path), RuleBaseError)
    assert exc.message == "the rule file names no term set" and "terms \"" in exc.hint


# ---------------------------------------------------------------------------------------------
# bad term sets: each names the YAML file and line


@pytest.mark.parametrize("old, new, marker, message", [
    ("peak: 70, width: 30", "peak: 70, width: 0", "MEDIUM:", "term `road.MEDIUM`: width must be > 0"),
    ("peak: 70, width: 30", "peak: 70, width: -3", "MEDIUM:", "width must be > 0, not -3"),
    ("points: [40, 70]", "points: [70, 40]", "NARROW:",
     "term `road.NARROW`: points must be in order, but a = 70 > b = 40"),
    ("LB: 30", "LB: 10", "LB",
     "term `steering.LB`: its peak 10 lies outside the universe [30, 150]"),
    ("peak: 70, width: 30", "peak: 170, width: 30", "MEDIUM:",
     "term `road.MEDIUM`: its peak 170 lies outside the universe [0, 160]"),
    ("      WIDE:   {shape: right_shoulder, points: [70, 100]}",
     "      WIDE:   {shape: right_shoulder, points: [70, 100]}\n"
     "      MEDIUM: {shape: triangle, peak: 70, width: 30}", "MEDIUM: {shape: triangle, peak: 70, width: 30}",
     "invalid YAML: duplicate key `MEDIUM`"),
    ("    unit: in\n    role: input\n    universe: [0, 160]",
     "    unti: in\n    role: input\n    universe: [0, 160]", "unti",
     "unknown key `unti` in variable `road`"),
    ("    unit: in\n    role: input\n    universe: [0, 160]",
     "    unit: in\n    universe: [0, 160]", "description: width of the road", "missing `role` in variable `road`"),
    # said at the `[` not closed, not at the next line's `terms:` (where PyYAML noticed)
    ("universe: [0, 160]", "universe: [0, 160", "universe: [0, 160",
     "invalid YAML: this `[` is not closed before line"),
    ("universe: [0, 160]", "universe: [160, 0]", "[160, 0]", "universe [160, 0] is empty"),
    # a subnormal width: every term a vertical edge, 1 on both sides of it
    ("universe: [0, 160]", "universe: [0, 1e-320]", "[0, 1e-320]",
     "is too narrow to compute with"),
    ("shape: left_shoulder", "shape: left_shouldr", "left_shouldr", "unknown shape `left_shouldr`"),
    ("role: input\n    universe: [0, 160]", "role: inptu\n    universe: [0, 160]", "inptu",
     "role must be `input` or `output`, not `inptu`"),
    ("peak: 70, width: 30", "peak: abc, width: 30", "abc", "peak must be a number, not `abc`"),
    ("default: 90", "default: 200", "default: 200", "default 200 lies outside the universe [30, 150]"),
])
def test_bad_term_sets(tmp_path, old, new, marker, message):
    assert old in TERMS
    bad = TERMS.replace(old, new, 1)
    # the line the error must name: the first line with the marker after the change
    start = bad.rfind("\n", 0, bad.index(new)) + 1
    line = bad[:bad.index(marker, start if marker in bad[start:] else 0)].count("\n") + 1
    path = write(tmp_path, GOOD_RULE, bad)
    exc = error_of(lambda: load_rules_file(path), TermSetError)
    assert exc.span.path == str(tmp_path / "t.terms.yaml")
    assert exc.span.line == line, exc.render()
    assert message in exc.message, exc.render()
    assert exc.render().startswith(f"{tmp_path / 't.terms.yaml'}:{line}:")


@pytest.mark.parametrize("old, new, at", [
    ("peak: 70, width: 30", "peak: 70, width: -3", "-"),
    ("points: [40, 70]", "points: [70, 40]", "["),
])
def test_a_bad_term_value_is_pointed_at(tmp_path, old, new, at):
    path = write(tmp_path, GOOD_RULE, TERMS.replace(old, new, 1))
    exc = error_of(lambda: load_rules_file(path), TermSetError)
    assert caret_under(exc).startswith(at)


def test_unknown_key_suggests_the_right_one(tmp_path):
    path = write(tmp_path, GOOD_RULE, TERMS.replace("unit: in", "unti: in", 1))
    exc = error_of(lambda: load_rules_file(path), TermSetError)
    assert exc.hint == "did you mean `unit`?" and exc.expected.startswith("one of description")


def test_term_set_that_is_not_a_mapping(tmp_path):
    path = write(tmp_path, GOOD_RULE, "- just\n- a list\n")
    exc = error_of(lambda: load_rules_file(path), TermSetError)
    assert "must be a mapping with a `variables:` key" in exc.message


def test_yaml_is_never_evaluated(tmp_path):
    evil = TERMS.replace("description: width of the road (corridor) ahead, x1",
                         "description: !!python/object/apply:os.system ['echo pwned']")
    path = write(tmp_path, GOOD_RULE, evil)
    exc = error_of(lambda: load_rules_file(path), TermSetError)
    assert exc.message.startswith("invalid YAML") and exc.span.line == 5


# ---------------------------------------------------------------------------------------------
# inputs


@pytest.fixture(scope="module")
def rb():
    return load_rulebase()


def test_nan_input(rb):
    exc = error_of(lambda: rb.evaluate(road=math.nan, size=45, position=4), InputError)
    assert exc.message == "input `road` is not a number (NaN)"


def test_nan_in_a_batch_names_the_sample(rb):
    X = np.array([[78, 45, 4], [78, np.nan, 4]])
    exc = error_of(lambda: rb.run(X), InputError)
    assert exc.message == "input `size` is not a number (NaN) (sample 2)"


def test_non_numeric_input(rb):
    exc = error_of(lambda: rb.evaluate(road="wide", size=45, position=4), InputError)
    assert exc.message == "input `road` must be a number, not `wide`"


def test_missing_input(rb):
    exc = error_of(lambda: rb.evaluate(road=78), InputError)
    assert exc.message == "missing input `size`, `position`"
    assert exc.hint == "give them as size=VALUE position=VALUE"


def test_unknown_input(rb):
    exc = error_of(lambda: rb.evaluate(raod=78, size=45, position=4), InputError)
    assert exc.message == "unknown input `raod`" and exc.hint == "did you mean `road`?"


@pytest.mark.parametrize("path", [3, {"rules": "r1: ..."}])
def test_load_rulebase_of_something_that_is_not_a_path_says_what_it_takes(path):
    """load_rulebase(3) met pathlib's "expected str, bytes or os.PathLike object"."""
    exc = error_of(lambda: load_rulebase(path), RuleBaseError)
    assert exc.message.startswith("a rule base is read from a file: expected a path or a "
                                  "packaged rule base's name, not ")


@pytest.mark.parametrize("name, close", [(3, None), (["drive"], "drive")])
def test_a_behavior_that_is_not_text_is_an_unknown_behavior(rb, name, close):
    """rb.behavior(3) met "'int' object is not iterable" deep in the compiler, and
    rb.behavior(["drive"]) the cache's "unhashable type: 'list'"."""
    for call in (lambda: rb.behavior(name), lambda: load_rulebase(None, name)):
        exc = error_of(call, NameError_)
        assert exc.message == f"unknown behavior `{name!r}`" and "drive" in exc.expected
        assert exc.hint == (f"did you mean `{close}`?" if close else None)
    assert rb.behavior("drive") is rb.behavior("drive")      # still compiled once


def test_an_empty_rule_base_or_behavior_name_is_refused(rb):
    """load_rulebase("") said "`.` is a directory", a path never given, and a behavior ""
    compiled the first behavior, as None does."""
    exc = error_of(lambda: load_rulebase(""), RuleBaseError)
    assert exc.message == "the rule base's name is empty"
    for call in (lambda: rb.behavior(""), lambda: load_rulebase(None, "")):
        assert error_of(call, NameError_).message == "unknown behavior `''`"


def test_a_planner_of_a_rule_base_that_is_not_one_says_what_it_takes():
    """FuzzyPlanner(3) (and a Gymnasium environment's rulebase=3) met "'int' object has no
    attribute 'behavior'"."""
    from mitos_cli.sim import FuzzyPlanner

    for rulebase in (3, 2.5, ["mitos.rules"]):
        exc = error_of(lambda: FuzzyPlanner(rulebase), RuleBaseError)
        assert exc.message.startswith("a rule base is read from a file: expected a path")
    assert FuzzyPlanner(load_rulebase().rulebase).name == "fuzzy:drive"


def test_no_rule_fired_without_default(tmp_path):
    terms = TERMS.replace("    default: 90\n", "")
    path = write(tmp_path, "r1: if road is WIDE then steering is RS and speed is SLOW", terms)
    loaded = load_rulebase(path)
    exc = error_of(lambda: loaded.evaluate(road=20), NoRuleFiredError)
    assert exc.message == "no rule sets `steering` for road=20"
    assert "declare a default for `steering` (`default: VALUE` on the variable" in exc.hint


def test_no_rule_fired_with_default_uses_it(tmp_path):
    path = write(tmp_path, "r1: if road is WIDE then steering is RS and speed is SLOW")
    assert load_rulebase(path).evaluate(road=20) == {"steering": 90.0, "speed": 0.0}


def test_out_of_universe_is_clamped_and_warned(capsys):
    with pytest.raises(SystemExit) as info:
        main(["eval", "road=500", "size=45", "position=-80", "--json"])
    assert info.value.code == 0
    out, err = capsys.readouterr()
    assert "warning: `road` outside its universe [0, 160] was clamped" in err
    assert "warning: `position` outside its universe [-60, 60] was clamped" in err
    assert '"value": 160.0' in out and '"value": -60.0' in out


# ---------------------------------------------------------------------------------------------
# the CLI: exit code 1 for user errors, 2 for usage errors


def run_main(args, capsys):
    with pytest.raises(SystemExit) as info:
        main(args)
    out, err = capsys.readouterr()
    return info.value.code, out, err


@pytest.mark.parametrize("args, message", [
    (["eval", "road=78", "size=45", "position=x"], "input error: input `position` must be a "
                                                   "number, not `x`"),
    (["eval", "road=78", "size=45"], "input error: missing input `position`"),
    (["eval", "road=nan", "size=45", "position=4"], "input `road` is not a number (NaN)"),
    (["eval", "-b", "avoid", "road=78", "size=45", "position=4"],
     "unknown behavior `avoid`"),
    (["eval", "no/such.rules", "road=1"], "rule file `no/such.rules` not found"),
    (["check", "no/such.rules"], "rule file `no/such.rules` not found"),
])
def test_cli_user_errors_exit_1(capsys, args, message):
    code, out, err = run_main(args, capsys)
    assert code == 1 and message in err and out == ""
    assert "Traceback" not in err


@pytest.mark.parametrize("args, message", [
    (["eval", "--bogus"], "No such option"),
    (["eval"], "give one NAME=VALUE per input"),
    (["eval", "road=1", "road=2"], "input `road` is given twice"),
    (["eval", "=1"], "has no input name"),
    (["eval", "road=78", "extra"], "is neither the rule base"),
    (["check", "--threshold", "-1"], "--threshold"),
    (["check", "--resolution", "1"], "--resolution"),
    (["frobnicate"], "No such command"),
    # a single-value option given twice: Click kept the last without a word
    (["eval", "-b", "drive", "-b", "avoid_obstacle", "road=78"], "'-b' is given twice"),
    (["eval", "--behavior=drive", "-bavoid_obstacle", "road=78"], "'-b' is given twice"),
    (["convert", "rulebases/mitos.rules", "--to", "fll", "--to", "fis"], "'--to' is given twice"),
    (["plot", "surface", "steering", "--x", "road", "--x", "size"], "'--x' is given twice"),
    (["check", "--threshold", "0.1", "--threshold", "0.2"], "'--threshold' / '-t' is given twice"),
    # an empty name, as `-b ''` and `mitos check ''` are refused: these were exit 1 ("unknown
    # variable ``", "the rule base's name is empty ... or None for the packaged one": words
    # for a Python caller) or said "`` has no extension"
    (["plot", "terms", ""], "'[RULEBASE] [NAME=VALUE]...': must name something, not be empty"),
    (["plot", "rules", "", "road=1"], "'[RULEBASE] NAME=VALUE...': must name something, not be "
                                      "empty"),
    (["plot", "surface", "", "steering"], "'[RULEBASE] [OUTPUT]': must name something, not be "
                                          "empty"),
    (["plot", "terms", "--var", "road", "--var", ""], "'--var' / '-v': must name something"),
    (["plot", "surface", "--x", ""], "'--x': must name something, not be empty"),
    (["plot", "surface", "--x", "road", "--y", " "], "'--y': must name something, not be empty"),
    (["plot", "terms", "-o", ""], "'--output' / '-o': must name something, not be empty"),
    (["teach", "--resume", "--session", ""], "'--session': must name something, not be empty"),
])
def test_cli_usage_errors_exit_2(capsys, args, message):
    code, out, err = run_main(args, capsys)
    assert code == 2 and message in " ".join(err.replace("│", " ").split()), err


def test_every_command_refuses_a_single_value_option_given_twice():
    """The check is made once, by the class every command is registered with; flags and
    options that take several values (`--fix`) may repeat."""
    import typer

    from mitos_cli.cli.app import build_app
    from mitos_cli.cli.params import OnceCommand

    def leaves(cmd):
        subs = getattr(cmd, "commands", None)
        return [c for s in subs.values() for c in leaves(s)] if subs else [cmd]

    commands = leaves(typer.main.get_command(build_app()))
    assert len(commands) >= 12 and all(isinstance(c, OnceCommand) for c in commands)


def said_in_the_box(err: str) -> str:
    """The message of a usage error, as one line (Rich's box unwrapped; Click's own
    ``Error: ...`` where Typer runs without Rich)."""
    lines = err.splitlines()
    top = next((i for i, line in enumerate(lines) if line.startswith("\u256d")), None)
    if top is None:
        return " ".join(line.removeprefix("Error: ") for line in lines
                        if not line.startswith(("Usage:", "Try ")))
    inside = lines[top + 1:next(i for i, line in enumerate(lines) if line.startswith("\u2570"))]
    return " ".join(" ".join(line.strip("\u2502").split()) for line in inside)


WHOLE = "must be a whole number"
PAST = "(past 1.8e308, the largest number a float holds)"
DIGITS = "(write it with the digits 0 to 9)"


@pytest.mark.parametrize("args, message", [
    # a word, a negative, zero, nan, inf, 1e400, empty, a fraction, an exponent: each option's
    # meaning, what it takes and what was given, where Click said "'abc' is not a valid int
    # range" or "0 is not in the range x>=1"
    (["check", "-n", "abc"], "'--resolution' / '-n': the number of grid points per input "
                             f"{WHOLE} from 2 to 10000, not `abc`"),
    (["check", "-n", "1"], f"'--resolution' / '-n': the number of grid points per input {WHOLE} "
                           "from 2 to 10000, not `1`"),
    (["check", "-n", ""], f"'--resolution' / '-n': the number of grid points per input {WHOLE} "
                          "from 2 to 10000, not an empty value"),
    (["check", "-t", "-1"], "'--threshold' / '-t': the DOF threshold must be a number of 0 or "
                            "more, not `-1`"),
    (["check", "-t", "-inf"], "'--threshold' / '-t': the DOF threshold must be a number of 0 or "
                              "more, not `-inf`"),
    (["check", "-t", "nan"], "'--threshold' / '-t': the DOF threshold must be a number of 0 or "
                             "more, not `nan`"),
    (["check", "-t", "1e400"], "'--threshold' / '-t': the DOF threshold must be a number of 0 or "
                               f"more, not `1e400` {PAST}"),
    (["eval", "--digits", "2.5", "road=1"], f"'--digits': the number of decimals {WHOLE} from 0 "
                                            "to 12, not `2.5`"),
    (["eval", "--digits", "13", "road=1"], f"'--digits': the number of decimals {WHOLE} from 0 "
                                           "to 12, not `13`"),
    (["simulate", "--seed", "-1"], f"'--seed': the seed {WHOLE} of 0 or more, not `-1`"),
    (["simulate", "--seed", "inf"], f"'--seed': the seed {WHOLE} of 0 or more, not `inf`"),
    (["simulate", "--runs", "-1"], "'--runs': the number of randomised runs per world "
                                   f"{WHOLE} from 0 to 100000, not `-1`"),
    (["simulate", "--every", "0"], f"'--every': the number of ticks between traces {WHOLE} of 1 "
                                   "or more, not `0`"),
    (["simulate", "--speed", "x"], "'--speed': the real-time factor must be 0 (as fast as it "
                                   "can) or a number of 0.001 or more, not `x`"),
    (["simulate", "--fps", "0"], "'--fps': the frames per second must be a number from 0.1 to "
                                 "60, not `0`"),
    (["simulate", "--fps", "1e400"], "'--fps': the frames per second must be a number from 0.1 "
                                     f"to 60, not `1e400` {PAST}"),
    (["simulate", "-j", "0"], f"'--workers' / '-j': the number of processes {WHOLE} of 1 or "
                              "more, not `0`"),
    (["compare", "corridor", "--runs", "1e3"], "'--runs': the number of runs per world and "
                                               f"choice {WHOLE} from 1 to 100000, not `1e3` "
                                               "(write it in digits: 1000)"),
    (["compare", "corridor", "-n", "0"], "'-n': the number of runs per world and choice "
                                         f"{WHOLE} from 1 to 100000, not `0`"),
    (["compare", "corridor", "--seed", "abc"], f"'--seed': the study's seed {WHOLE} of 0 or "
                                               "more, not `abc`"),
    (["compare", "corridor", "-j", "2.5"], "'--workers' / '-j': the number of processes "
                                           f"{WHOLE} of 1 or more, not `2.5`"),
    (["plot", "terms", "--width", "5"], "'--width': the plot's width in characters "
                                        f"{WHOLE} from 30 to 400, not `5`"),
    (["plot", "surface", "-n", "nan"], "'--resolution' / '-n': the number of grid points per "
                                       f"axis {WHOLE} from 2 to 1000, not `nan`"),
    (["plot", "rules", "--max-rules", "0", "road=1"], "'--max-rules': the number of fired rules "
                                                      f"to draw {WHOLE} from 1 to 500, not `0`"),
    (["plot", "rules", "--width", "-1", "road=1"], "'--width': the plot's width in characters "
                                                   f"{WHOLE} from 30 to 400, not `-1`"),
    # Python's int() and float() read `1_0` as 10 and other scripts' digits (`١٠`) as 10:
    # a number written as no file format or other option here writes it ran as another
    (["simulate", "--seed", "1_0"], f"'--seed': the seed {WHOLE} of 0 or more, not `1_0` {DIGITS}"),
    (["simulate", "--seed", "\u0661\u0660"], f"'--seed': the seed {WHOLE} of 0 or more, not "
                                             f"`\u0661\u0660` {DIGITS}"),
    (["check", "-t", "0_5"], "'--threshold' / '-t': the DOF threshold must be a number of 0 or "
                             f"more, not `0_5` {DIGITS}"),
    (["simulate", "--seed", "9" * 5000], f"'--seed': the seed {WHOLE} of 0 or more, not "
                                         f"`{'9' * 20}...{'9' * 10}` (5,000 characters): Python "
                                         "reads whole numbers of at most 4,300 digits"),
])
def test_a_number_option_says_what_it_takes(capsys, args, message):
    code, out, err = run_main(args, capsys)
    assert (code, out) == (2, "")
    assert said_in_the_box(err) == f"Invalid value for {message}"


def test_every_number_option_is_read_by_one_type():
    """Click's own number types word their errors in Click's terms ("'abc' is not a valid
    int range"); every option that takes a number takes it through one type,
    :class:`~mitos_cli.cli.params.Number`, which says the option's meaning, the range and
    what was given."""
    import typer.main
    from typer._click.types import FloatParamType, IntParamType

    from mitos_cli.cli.app import build_app
    from mitos_cli.cli.params import Number

    def leaves(cmd, path):
        subs = getattr(cmd, "commands", None)
        return [x for n, s in subs.items() for x in leaves(s, f"{path} {n}".strip())] if subs \
            else [(path, cmd)]

    numbers = {f"{path} {param.opts[0]}": type(param.type).__name__
               for path, cmd in leaves(typer.main.get_command(build_app()), "")
               for param in cmd.params
               if isinstance(param.type, (IntParamType, FloatParamType, Number))}
    assert len(numbers) == 17 and set(numbers.values()) <= {"Number", "Factor"}, numbers


def test_cli_syntax_error_through_a_real_process(tmp_path):
    path = write(tmp_path, "r1: if road is WIDE then speed is\n")
    proc = subprocess.run([sys.executable, "-m", "mitos_cli", "eval", str(path), "road=1"],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 1 and proc.stdout == ""
    lines = proc.stderr.splitlines()
    assert re.match(re.escape(str(path)) + r":2:34: syntax error: unexpected end of the input",
                    lines[0])
    assert lines[1] == "    r1: if road is WIDE then speed is" and lines[2].endswith("^")
    assert "Traceback" not in proc.stderr


def test_cli_usage_error_through_a_real_process():
    proc = subprocess.run([sys.executable, "-m", "mitos_cli", "eval", "--json", "--nope"],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2 and "No such option" in proc.stderr


def test_term_set_that_is_not_utf8(tmp_path):
    path = write(tmp_path, GOOD_RULE)
    (tmp_path / "t.terms.yaml").write_bytes(b"variables:\n  road:\xff\n")
    exc = error_of(lambda: load_rules_file(path), TermSetError)
    assert exc.message.endswith("is not a text file (byte 0xff is not UTF-8)")
    assert (exc.span.line, exc.span.column) == (2, 8)


def test_term_set_name_with_control_character_or_bad_escape(tmp_path):
    for name in ('"a\x01b"', '"a\\qb"'):
        path = tmp_path / "t.rules"
        path.write_text(f"terms {name}\n" + GOOD_RULE, encoding="utf-8")
        exc = error_of(lambda: load_rules_file(path), TermSetError)
        assert "not found" in exc.message and exc.span.line == 1


def test_a_keyword_where_a_condition_should_be(tmp_path):
    (tmp_path / "t.terms.yaml").write_text(TERMS, encoding="utf-8")
    (tmp_path / "t.rules").write_text('terms "t.terms.yaml"\n'
                                      "r1: if road is WIDE and then steering is RS\n")
    from mitos_cli.api import read_rulebase
    from mitos_cli.errors import RuleSyntaxError

    with pytest.raises(RuleSyntaxError) as info:
        read_rulebase(tmp_path / "t.rules")
    assert info.value.hint.startswith("`then` stands where a condition should be")


def test_a_rule_weight_out_of_range_points_at_its_with(tmp_path):
    path = write(tmp_path, "r1: if road is WIDE\n    then speed is SLOW\n    with 1.5")
    exc = error_of(lambda: load_rules_file(path))
    assert exc.render().startswith(f"{path}:4:5: rule base error: a rule weight must lie in")
    assert caret_under(exc) == "with 1.5"


def test_an_operator_set_twice_on_one_line_is_refused(tmp_path):
    from mitos_cli.teach.commands import parse_command

    path = write(tmp_path, "operators: and = min, and = product\n" + GOOD_RULE)
    exc = error_of(lambda: load_rules_file(path), RuleSyntaxError)
    assert "`and` is set twice on one operators line (`min`, then `product`)" in exc.message
    assert caret_under(exc) == "and = product"
    with pytest.raises(RuleSyntaxError, match="set twice"):
        parse_command("operators: or = max, or = sum", "l.lesson", 4)


def test_an_operator_set_again_on_a_later_file_level_line_is_warned_of(tmp_path, capsys):
    """`operators: and = min` then `operators: and = product` merged without a word."""
    path = write(tmp_path, "operators: and = min\noperators: or = max\n"
                           "operators: and = product\n" + GOOD_RULE)
    rb = load_rules_file(path)
    assert rb.notes == (f"{path}:4:12: `and` is set again (`product`; line 2 set `min`): the "
                        f"later line wins for the whole file; keep one `and` (a behavior's own "
                        f"`operators:` line sets it for that behavior)",)
    code, _, err = run_main(["eval", str(path), "road=90", "size=20", "position=-5"], capsys)
    assert code == 0 and f"warning: {path}:4:12: `and` is set again" in err
    assert load_rules_file(write(tmp_path, "operators: and = min\n" + GOOD_RULE)).notes == ()


def test_a_behavior_named_as_a_hedge_is_refused(tmp_path):
    path = write(tmp_path, "behavior very:\n  r1: if road is WIDE then speed is SLOW\nend\n")
    exc = error_of(lambda: load_rules_file(path), RuleBaseError)
    assert "`very` is a reserved word (a hedge), not a name" in exc.message


@pytest.mark.parametrize("cond", ["road is very not WIDE", "road is not very not WIDE",
                                  "road is somewhat very not not WIDE"])
def test_not_after_a_hedge_is_refused_not_read_as_not_first(tmp_path, cond, capsys):
    # `very not WIDE` is very(1 - WIDE); the model holds one `not`, applied last, so it was
    # silently evaluated as `not very WIDE` (1 - WIDE^2): a different number
    path = write(tmp_path, f"r1: if {cond} then speed is SLOW\n")
    exc = error_of(lambda: load_rules_file(path), RuleSyntaxError)
    assert "`not` after a hedge" in exc.message
    line = f"r1: if {cond} then speed is SLOW"
    assert exc.span.line == 2 and caret_under(exc) == "not"
    assert exc.span.column == line.index(" not", line.index("very")) + 2
    assert "a different number" in exc.hint and "define the complement" in exc.hint
    with pytest.raises(SystemExit) as info:
        main(["eval", str(path), "road=80", "size=10", "position=0"])
    assert info.value.code == 1 and "`not` after a hedge" in capsys.readouterr().err


def test_not_before_hedges_and_doubled_not_still_parse(tmp_path):
    path = write(tmp_path, "r1: if road is not not very WIDE then speed is SLOW\n"
                           "r2: if road is not very WIDE then speed is FAST\n")
    rules = load_rules_file(path).behaviors[0].rules
    assert rules[0].antecedent == Prop("road", "WIDE", ("very",), False)
    assert rules[1].antecedent == Prop("road", "WIDE", ("very",), True)


def test_a_frozen_label_naming_no_rule_is_pointed_at(tmp_path):
    path = write(tmp_path, "behavior a:\n  r1: if road is WIDE then speed is SLOW\n"
                           "  frozen r1, r7\nend\n")
    exc = error_of(lambda: load_rules_file(path))
    assert exc.span.line == 4 and caret_under(exc) == "r7"
    assert exc.message == "unknown rule label `r7` in behavior `a`"


@pytest.mark.parametrize("action", [
    "speed is not SLOW", "speed is very not SLOW", "speed is not very SLOW", "speed is not",
    "speed is not with 0.5", "speed is SLOW and steering is not",
])
def test_not_in_an_action_says_so(tmp_path, action):
    # `not` was read as a term and the term after it as a new rule's label without its `:`
    path = write(tmp_path, f"r1: if road is WIDE then {action}\n"
                           "r2: if road is NARROW then speed is FAST\n")
    exc = error_of(lambda: load_rules_file(path), RuleSyntaxError)
    assert exc.message.startswith("`not` is not allowed in an action")
    line = f"r1: if road is WIDE then {action}"
    assert (exc.span.line, exc.span.column) == (2, line.index(" not") + 2)
    assert caret_under(exc) == "not"
    assert "label" not in exc.render() and "not to its complement" in exc.hint


def test_not_in_an_action_after_a_long_rule_is_found_at_its_place(tmp_path):
    # the `not` is looked for back from the error only (a scan of every `X is Y` after the
    # last `then` was quadratic: a 16 KB fuzzed rule took 2 s to be refused)
    long = " and ".join(["road is WIDE"] * 2000)
    line = f"r1: if {long} then speed is SLOW and steering is not"
    path = write(tmp_path, line + "\nr2: if road is NARROW then speed is FAST\n")
    exc = error_of(lambda: load_rules_file(path), RuleSyntaxError)
    assert exc.message == "`not` is not allowed in an action (`steering is not`)"
    assert caret_under(exc) == "not" and exc.span.column == line.rindex(" not") + 2


def test_a_top_level_frozen_label_naming_no_rule_is_pointed_at(tmp_path, capsys):
    path = write(tmp_path, "r1: if road is WIDE then speed is SLOW\n"
                           "avoid_left: if road is NARROW then speed is SLOW\n"
                           "frozen r1, avoid_lft\n")
    exc = error_of(lambda: load_rules_file(path), NameError_)
    assert (exc.span.line, exc.span.column) == (4, 12) and caret_under(exc) == "avoid_lft"
    assert exc.message == ("unknown rule label `avoid_lft` in behavior `main` (the rules "
                           "outside any behavior)")
    assert exc.hint == "did you mean `avoid_left`?"
    with pytest.raises(SystemExit) as info:
        main(["eval", str(path), "road=80", "size=10", "position=0"])
    assert info.value.code == 1 and ":4:12: name error" in capsys.readouterr().err


def test_a_frozen_label_of_another_behavior_says_where_to_write_it(tmp_path):
    path = write(tmp_path, "behavior b1:\n  r9: if road is WIDE then speed is SLOW\nend\n"
                           "r1: if road is WIDE then speed is FAST\nfrozen r1, r9\n")
    exc = error_of(lambda: load_rules_file(path), NameError_)
    assert exc.span.line == 6 and caret_under(exc) == "r9"
    assert exc.hint == ("`r9` is a rule in behavior `b1`: `frozen` names rules of the behavior "
                        "it is written in, so write `frozen r9` there")
    only = write(tmp_path, "behavior b1:\n  r9: if road is WIDE then speed is SLOW\nend\n"
                           "frozen r9\n")
    exc = error_of(lambda: load_rules_file(only), RuleBaseError)
    assert exc.span.line == 5 and caret_under(exc) == "r9"


FORMULA_TERMS = """variables:
  x: {role: input, universe: [0, 10], terms: {LOW: {shape: formula, formula: "1 - x / 10"}}}
  y:
    role: output
    universe: [0, 1]
    default: 0
    terms: {A: {shape: formula, formula: "x"}, B: {shape: clipped_sigmoid_difference,
            points: [0.2, 30, 30, 0.8]}}
"""


def test_a_formula_output_term_under_weighted_inference_is_refused(tmp_path, capsys):
    # its centre was NaN and `mitos eval` printed the default, 0, as if the rules had set it
    path = write(tmp_path, "r1: if x is LOW then y is A\n", FORMULA_TERMS)
    with pytest.raises(SystemExit) as info:
        main(["eval", str(path), "x=3"])
    err = capsys.readouterr().err
    assert info.value.code == 1 and ":2:22: rule base error: `y is A`: `A` is a formula " \
        "term, which has no crisp value for `weighted_average` inference to average" in err
    assert "inference = mamdani" in err
    mamdani = write(tmp_path, "operators: inference = mamdani\n"
                              "r1: if x is LOW then y is A\nr2: if x is very LOW then y is B\n",
                    FORMULA_TERMS)
    assert np.isfinite(load_rulebase(mamdani).evaluate(x=3)["y"])


def test_a_name_cut_short_gets_the_one_name_it_begins():
    from mitos_cli.errors import closest

    behaviors = ["approach_goal", "avoid_obstacle", "cruise", "drive", "keep_clear", "keep_right"]
    assert closest("avoid", behaviors) == "avoid_obstacle"      # difflib's ratio: 0.53
    assert closest("AVOID", behaviors) == "avoid_obstacle"
    assert closest("keep", behaviors) is None                   # two names begin with it
    assert closest("av", behaviors) is None                     # too short to say


def test_a_name_with_an_accent_is_told_names_are_ascii(tmp_path):
    from mitos_cli.errors import RuleSyntaxError
    from mitos_cli.lang.parse import parse_rules

    with pytest.raises(RuleSyntaxError) as exc:
        parse_rules("if température is COLD then fan is HIGH\n", "na.rules")
    text = exc.value.render()
    assert text.startswith("na.rules:1:8: syntax error: unexpected character `é`")
    assert "hint: names are ASCII letters, digits, `_` and `-` (`temperature`)" in text


@pytest.mark.parametrize("written, shown", [("2", "not 2"), ("2.5", "not 2.5"), ("1e9", "not 1e9")])
def test_a_resolution_refused_is_shown_as_written(written, shown):
    from mitos_cli.lang.operators import resolve
    from mitos_cli.lang.parse import parse_rules

    parsed = parse_rules(f"operators: resolution = {written}\nif a is B then c is D\n", "r.rules")
    with pytest.raises(MitosError) as exc:
        resolve(parsed.operators)
    assert exc.value.message.endswith(f"from 3 to 100000, {shown}")


@pytest.mark.parametrize("rules, terms_edit, says", [
    ("r: if road is WIDE then steering is 150.0000001\n", None,
     "steering = 150.0000001 lies outside its universe [30, 150]"),
    ("r: if road is WIDE then steering is LS with 1.0000001\n", None,
     "a rule weight must lie in [0, 1], not 1.0000001"),
    ("r: if road is WIDE then steering is LS\n", ("points: [40, 70]}", "points: [70.0000001, 70]}"),
     "points must be in order, but a = 70.0000001 > b = 70"),
    ("r: if road is WIDE then steering is LS\n", ("default: 90", "default: 150.0000001"),
     "default 150.0000001 lies outside the universe [30, 150]"),
    ("r: if road is WIDE then steering is LS\n", ("universe: [0, 160]", "universe: [0, 1.0000001e150]"),
     "is 1.0000001e+150: numbers beyond ±1e+150 cannot be evaluated"),
])
def test_a_message_that_compares_numbers_prints_them_as_different(tmp_path, rules, terms_edit,
                                                                   says):
    """Numbers were printed to six significant digits: "steering = 150 lies outside its
    universe [30, 150]", "a rule weight must lie in [0, 1], not 1", "b = 5 > c = 5". A number
    that six digits do not tell apart is printed in full."""
    terms = TERMS if terms_edit is None else TERMS.replace(*terms_edit, 1)
    assert terms != TERMS or terms_edit is None
    exc = error_of(lambda: load_rulebase(write(tmp_path, rules, terms)))
    assert says in str(exc)


@pytest.mark.parametrize("name, pool, hint", [
    ("HJ", ["HI", "LO", "SAME"], "HI"),           # one letter off: difflib's ratio is 0.5
    ("ZO", ["NB", "NS", "ZE", "PS", "PB"], "ZE"),
    ("SP", ["NB", "NS", "ZE", "PS", "PB"], "PS"),  # two neighbours swapped
    ("PM", ["NB", "NS", "ZE", "PS", "PB"], None),  # PS and PB both: no guess
    ("QQ", ["NB", "NS", "ZE", "PS", "PB"], None),
    ("x", ["y", "z"], None),                      # one letter is no name to guess from
    ("r9", ["r1", "LO"], None),                   # nor is a digit a typo
])
def test_a_short_name_one_letter_off_gets_a_did_you_mean(name, pool, hint):
    """`x is HJ` for the term HI listed the terms but suggested none: names of two or three
    letters (NB, ZE, PS, as fuzzy terms often are) are too short for difflib's ratio."""
    from mitos_cli.errors import closest

    assert closest(name, pool) == hint


def test_each_extras_hint_names_what_pyproject_installs_for_it() -> None:
    """The hints say the packages of each extra by name (``pip install 'mitos[plot]'`` took
    another project's ``mitos`` from PyPI in MITOS's place): the same packages as the
    installed distribution's metadata, read from pyproject.toml."""
    import re as _re
    from importlib.metadata import metadata

    from mitos_cli.errors import DISTRIBUTION, EXTRAS, install_hint

    def canonical(requirement: str) -> str:
        name, rest = _re.match(r"([A-Za-z0-9._-]+)(.*)", requirement).groups()  # type: ignore[union-attr]
        return _re.sub(r"[-_.]+", "-", name).lower() + rest.replace(" ", "")

    declared: dict[str, set[str]] = {}
    for line in metadata(DISTRIBUTION).get_all("Requires-Dist") or []:
        if (found := _re.fullmatch(r"(.+?); extra == '([a-z]+)'", line)) is not None:
            declared.setdefault(found[2], set()).add(canonical(found[1]))
    for extra, packages in EXTRAS.items():
        assert {canonical(p) for p in packages} == declared[extra], extra
        assert install_hint(extra).startswith("pip install ") and "mitos[" not in install_hint(extra)
    assert install_hint("plot") == "pip install 'matplotlib>=3.6' (the `plot` extra of mitos-planner)"


@pytest.mark.parametrize("char", ["\x0b", "\x0c", "\x1c", "\x85", "\u2028", "\u2029"])
def test_the_line_shown_is_the_one_named_past_a_character_splitlines_breaks_at(char):
    """Lark counts lines at `\\n`; the line under a message was found with `str.splitlines`,
    which also breaks at a form feed or U+2028 in a comment: `r2`'s error was shown under
    `r1`'s line, its caret under `is WIDE` there."""
    from mitos_cli.lang.parse import parse_rules

    text = (f'# a comment {char} of two parts\nterms "mitos.terms.yaml"\nbehavior b:\n'
            "  r1: if road is WIDE then steering is RS\n"
            "  r2: if road isWIDE then steering is RS\nend\n")
    with pytest.raises(RuleSyntaxError) as info:
        parse_rules(text, "x.rules")
    span = info.value.span
    assert (span.line, span.column) == (5, 15)
    assert span.source_line == "  r2: if road isWIDE then steering is RS"


def test_a_rule_file_with_lone_cr_line_ends_reads_as_with_lf():
    """A file from classic Mac OS ends its lines with `\\r` alone: Lark counts lines at `\\n`,
    so the first line's comment ran to the end of the file ("the rule file names no term
    set", at 1:1), and a mistake was named at line 1, column 500."""
    from mitos_cli.lang.parse import parse_rules

    text = (Path(__file__).parent.parent / "rulebases" / "mitos.rules").read_text()
    cr = parse_rules(text.replace("\n", "\r"), "x.rules")
    lf = parse_rules(text, "x.rules")
    assert cr.behaviors == lf.behaviors and len(cr.behaviors[0].rules) == 27
    with pytest.raises(RuleSyntaxError) as info:
        parse_rules(text.replace("r4: if road is WIDE", "r4: if road isWIDE").replace("\n", "\r"),
                    "cr.rules")
    span = info.value.span
    assert (span.line, span.column) == (24, 17)
    assert span.source_line.strip().startswith("r4: if road isWIDE")


def test_is_glued_to_a_term_is_said_in_linear_time_after_a_long_word():
    """The name before a glued `isWIDE` was found with a regex search from the file's start,
    which tried every start in every word: a 40,000-letter word in a comment took 10 s."""
    import time

    from mitos_cli.lang.parse import parse_rules

    text = ("# " + "x" * 40_000 + ".\nterms \"mitos.terms.yaml\"\nbehavior b:\n"
            "  r1: if road isWIDE then steering is RS\nend\n")
    t0 = time.process_time()
    with pytest.raises(RuleSyntaxError) as info:
        parse_rules(text, "x.rules")
    assert time.process_time() - t0 < 2
    assert (info.value.span.line, info.value.span.column) == (4, 15)
    assert info.value.hint == "`is` and `WIDE` are two words: `road is WIDE`"
