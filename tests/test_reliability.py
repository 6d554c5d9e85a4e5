"""Malformed input gets a positioned message, never a traceback, a hang or a wrong number.

One test per defect the fuzzing campaign (``benchmarks/fuzz.py``) found, from its minimal
reproducer, and a bounded fuzzing run per input kind (the campaign's own mutators).
"""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

import pytest

from mitos_cli.engine.compile import compile_rulebase
from mitos_cli.engine.csvio import read_batch
from mitos_cli.errors import (
    InputError,
    LessonError,
    MitosError,
    RuleBaseError,
    RuleSyntaxError,
    Span,
    TermSetError,
    WorldError,
)
from mitos_cli.lang import yamlpos
from mitos_cli.lang.parse import parse_rules
from mitos_cli.sim.gridmap import load_map_yaml
from mitos_cli.sim.pgm import parse_pgm
from mitos_cli.teach.commands import parse_command

ROOT = Path(__file__).resolve().parents[1]


def _positioned(exc: MitosError, line: int | None = None) -> None:
    assert exc.span is not None and exc.span.line >= 1
    if line is not None:
        assert exc.span.line == line


# ---- YAML --------------------------------------------------------------------------------------

@pytest.mark.parametrize("text, words", [
    ("x: " + "[" * 3000 + "]" * 3000, "nested more than"),
    ("x:\n" + "".join("  " * i + f"k{i}:\n" for i in range(1, 200)), "nested more than"),
    ("a: &a [1, 2]\nb: *a\n", "anchors"),
    ("b: {x: 1}\nc:\n  <<: {x: 2}\n", "merge keys"),
    ("x: !!binary aGk=\n", "tags"),
    ("x: !!python/name:os.system\n", "tags"),
    ("x: !!int abc\n", "tags"),
    ("x: \x00\n", "not allowed"),
])
def test_yaml_refusals_are_positioned(text, words):
    with pytest.raises(TermSetError) as info:
        yamlpos.load(text, "t.yaml", TermSetError)
    assert words in info.value.message
    _positioned(info.value)


def test_yaml_alias_bomb_is_refused_at_once():
    rows = ["a0: &a0 [x, x, x, x, x, x, x, x, x, x]"]
    rows += [f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 10) + "]" for i in range(1, 12)]
    t0 = time.perf_counter()
    with pytest.raises(TermSetError):
        yamlpos.load("\n".join(rows), "t.yaml", TermSetError)
    assert time.perf_counter() - t0 < 2.0


def test_huge_integer_is_refused_not_overflowing():
    doc = yamlpos.load("x: " + "9" * 400 + "\n", "t.yaml", TermSetError)
    with pytest.raises(TermSetError, match="finite number"):
        yamlpos.expect_number(doc["x"], doc.value_span("x"), TermSetError, "x")


def test_a_long_run_of_digits_where_a_number_belongs_is_refused_at_once():
    """A value of digits YAML reads as text (`111...1 2`) was searched for a unit with
    `\\d+\\.?\\d*`, which split the run every way: a fuzzed 200,000-digit value in a teach
    journal's term set ran past the campaign's limit (about half an hour alone)."""
    doc = yamlpos.load("x: " + "1" * 200_000 + " 2\n", "t.yaml", TermSetError)
    with pytest.raises(TermSetError, match="must be a number") as info:
        yamlpos.expect_number(doc["x"], doc.value_span("x"), TermSetError, "x")
    assert info.value.hint is None
    doc = yamlpos.load("x: 16in\n", "t.yaml", TermSetError)
    with pytest.raises(TermSetError) as info:
        yamlpos.expect_number(doc["x"], doc.value_span("x"), TermSetError, "x", units="in")
    assert info.value.hint == "write the number alone, without `in`: in"


def test_span_of_a_long_line_keeps_the_part_around_the_column():
    text = "a" * 100_000 + " bad " + "b" * 100_000
    span = Span.at(text, "f", 100_001, 1, 100_002)
    rendered = MitosError("here", span=span).render().splitlines()
    assert rendered[0].startswith("f:1:100002")
    assert len(rendered[1]) < 300 and rendered[2].index("^") == rendered[1].index("bad")


# ---- maps ----------------------------------------------------------------------------------------

def _map(tmp_path: Path, extra: str) -> Path:
    (tmp_path / "m.pgm").write_bytes(b"P5\n2 2\n255\n" + bytes([0, 255, 255, 0]))
    (tmp_path / "m.yaml").write_text("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n"
                                     + extra)
    return tmp_path / "m.yaml"


@pytest.mark.parametrize("extra, line", [("occupied_thresh: high\n", 4),
                                         ("free_thresh: [1]\n", 4),
                                         ('negate: "0"\n', 4), ("negate: 2\n", 4)])
def test_map_settings_are_checked(tmp_path, extra, line):
    with pytest.raises(WorldError) as info:
        load_map_yaml(_map(tmp_path, extra))
    _positioned(info.value, line)


@pytest.mark.parametrize("written, said", [("null", "`null`"), ("", "nothing (an empty value)"),
                                           ('"0"', "`0`"), ("[0]", "a list")])
def test_map_negate_of_nothing_is_quoted_as_written(tmp_path, written, said):
    """`negate: null` read "not `None`", Python's word for it."""
    with pytest.raises(WorldError) as info:
        load_map_yaml(_map(tmp_path, f"negate: {written}\n"))
    assert info.value.message == f"negate must be 0 or 1, not {said}"


def test_map_negate_unquoted_still_reads(tmp_path):
    grid = load_map_yaml(_map(tmp_path, "negate: 1\n"))
    assert grid.occupied.sum() == 2


def test_pgm_huge_header_is_checked_against_the_data_first():
    with pytest.raises(ValueError, match="holds 2 of its"):
        parse_pgm(b"P5 7999 7999 255\n\0\0")
    with pytest.raises(ValueError, match="a map image may have at most 64,000,000"):
        parse_pgm(b"P5 99999999999 99999999999 255\n\0\0")      # (past any map: said so)
    with pytest.raises(ValueError):
        parse_pgm(b"P2 3 1 9\n1 2 " + b"9" * 40 + b"\n")


@pytest.mark.skipif(not Path("/dev/zero").exists(), reason="needs /dev/zero")
def test_map_image_that_is_a_device_is_refused(tmp_path):
    (tmp_path / "m.yaml").write_text("image: /dev/zero\nresolution: 0.05\norigin: [0, 0, 0]\n")
    with pytest.raises(WorldError, match="not a regular file") as info:
        load_map_yaml(tmp_path / "m.yaml")
    _positioned(info.value, 1)


# ---- rule files ----------------------------------------------------------------------------------

def test_deep_not_is_a_positioned_error():
    text = 'terms "mitos.terms.yaml"\nif ' + "not " * 5000 + "road is WIDE then speed is FAST"
    with pytest.raises(RuleSyntaxError, match="nested more than") as info:
        parse_rules(text, "deep.rules")
    _positioned(info.value, 2)


def test_deep_parentheses_parse():
    text = 'terms "x"\nif ' + "(" * 3000 + "road is WIDE" + ")" * 3000 + " then speed is FAST"
    assert len(parse_rules(text, "p.rules").rules) == 1


def test_empty_behavior_is_refused_at_compile(tmp_path):
    from mitos_cli.lang.resolve import load_rules_file

    (tmp_path / "mitos.terms.yaml").write_text(
        (ROOT / "rulebases" / "mitos.terms.yaml").read_text())
    (tmp_path / "s.rules").write_text('terms "mitos.terms.yaml"\nbehavior a:\nend\n'
                                      "behavior b:\nuse a\nend\n")
    rb = load_rules_file(tmp_path / "s.rules")
    with pytest.raises(RuleBaseError, match="has no rules") as info:
        compile_rulebase(rb, "b")
    _positioned(info.value, 4)


def test_parsing_is_linear_in_the_number_of_rules():
    def cost(n: int) -> float:
        text = 'terms "mitos.terms.yaml"\n' + "\n".join(
            f"z{i}: if road is WIDE and size is SMALL_SZ then speed is SLOW" for i in range(n))
        t0 = time.process_time()
        parse_rules(text, "many.rules")
        return time.process_time() - t0

    cost(50)
    small, large = min(cost(200) for _ in range(2)), min(cost(1600) for _ in range(2))
    assert large < 8 * small * 2.5          # 8x the rules: linear, with room for noise


def test_parsing_makes_no_wrapper_per_node_and_no_ordered_walk(monkeypatch):
    """Lark's dispatch of a ``v_args`` method made a wrapper object at every node, and the
    check of misplaced `not`s walked the tree in Lark's order: a third of what our own code
    cost on 10,000 rules. Neither runs now where no `not` is misplaced; same model."""
    import functools

    from lark import Tree, visitors

    text = 'terms "mitos.terms.yaml"\n' + "\n".join(
        f"z{i}: if road is WIDE and not size is very SMALL_SZ then speed is SLOW with 0.5"
        for i in range(50))
    expected = repr(parse_rules(text, "many.rules"))
    made = []
    real = visitors.update_wrapper

    def counted(*args, **kwargs):
        made.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(visitors, "update_wrapper", counted)
    monkeypatch.setattr(Tree, "iter_subtrees", lambda self: pytest.fail("ordered walk"))
    assert repr(parse_rules(text, "many.rules")) == expected
    assert made == [] and functools.update_wrapper is real


def test_a_names_span_is_placed_without_compiling_a_pattern_per_name(monkeypatch):
    """Each name of each rule was placed (``Span.naming``) by escaping and compiling its
    pattern again, a third of the checks of 10,000 FCL rules: a name's pattern is compiled
    once now, and the spans are the same."""
    import re
    import types

    from mitos_cli import errors

    text = 'terms "mitos.terms.yaml"\n' + "\n".join(
        f"z{i}: if road is WIDE and size is SMALL_SZ then speed is SLOW" for i in range(20))
    span = Span.in_text(text, "r.rules", 2, 1, 60)
    first = [span.naming(w) for w in ("road", "size", "WIDE", "speed")]
    compiled = []
    proxy = types.SimpleNamespace(**{k: getattr(re, k) for k in dir(re) if not k.startswith("__")})
    proxy.compile = lambda *a, **k: compiled.append(a) or re.compile(*a, **k)
    monkeypatch.setattr(errors, "re", proxy)
    assert [span.naming(w) for w in ("road", "size", "WIDE", "speed")] == first
    assert compiled == [] and [s.column for s in first] == [8, 25, 16, 47]


def test_a_span_is_the_same_without_the_regex():
    """``Span.at`` finds a line's ends by ``str.find`` where it looks for newlines (every
    node of a parse): the same span as the regex search it replaces, short or long lines."""
    import random
    import re

    slow = re.compile(r"\n")                # another pattern object: the regex way
    rng = random.Random(7)
    for _ in range(3000):
        n = rng.choice([0, 1, 9, 200, 255, 256, 257, 600])
        text = "".join(rng.choice("ab \n") if rng.random() < 0.2 else "x" for _ in range(n))
        i = rng.randint(-2, n + 2)
        assert Span.at(text, "f", i, 3, 4, 9) == Span.at(text, "f", i, 3, 4, 9, breaks=slow)


# ---- teach -----------------------------------------------------------------------------------------

def test_deep_teach_command_is_a_positioned_error():
    with pytest.raises(RuleSyntaxError, match="nested more than") as info:
        parse_command("if " + "not " * 3000 + "road is WIDE then speed is FAST", "l.lesson", 7)
    _positioned(info.value, 7)


def test_command_errors_keep_their_lesson_line():
    with pytest.raises(RuleSyntaxError) as info:
        parse_command("eval road=", "l.lesson", 12)
    assert info.value.span.line == 12 and info.value.span.path == "l.lesson"


def test_teach_time_overflow_is_refused():
    from mitos_cli.teach.session import _whole

    with pytest.raises(LessonError):
        _whole(float("inf"), "seed", 0)


def test_long_world_name_in_teach_is_an_error(tmp_path):
    from mitos_cli.teach.simulation import world_path

    with pytest.raises(MitosError):
        world_path("w" * 300 + ".yaml", tmp_path)


# ---- batch CSV -------------------------------------------------------------------------------------

@pytest.mark.parametrize("text, line", [
    ("road,size,position\n1,2,\x003\n", 2),
    ('road,size,position\n"' + "9" * 200_000 + '",1,2\n', 2),
    ("road,si\x00ze,position\n1,2,3\n", 1),
])
def test_batch_csv_errors_are_positioned(text, line):
    with pytest.raises(InputError) as info:
        read_batch(text, "b.csv", ("road", "size", "position"))
    _positioned(info.value, line)


# ---- journals --------------------------------------------------------------------------------------

def _session(tmp_path: Path, monkeypatch):
    from mitos_cli.teach.journal import Journal
    from mitos_cli.teach.session import Session

    monkeypatch.chdir(tmp_path)
    d = tmp_path / "s"
    session = Session(ROOT / "rulebases" / "mitos.rules", journal=Journal.create(d),
                      out=lambda s: None)
    session.run("r28: if road is NARROW and position is RIGHT then steering is LS")
    session.run("correct road=78 size=45 position=4 -> steering=100")
    return d


def test_torn_last_line_is_dropped_and_kept_aside(tmp_path, monkeypatch):
    from mitos_cli.teach.journal import Journal
    from mitos_cli.teach.session import Session

    d = _session(tmp_path, monkeypatch)
    path = d / "journal.jsonl"
    whole = path.read_bytes()
    path.write_bytes(whole + b'{"seq": 4, "op": "rule", "te')
    journal = Journal.open(d)
    assert journal.skipped_tail and len(journal.entries) == 3
    assert path.read_bytes() == whole
    assert journal.aside.read_bytes().endswith(b'"te')
    assert len(Session.resume(journal, out=lambda s: None).state.examples) == 1


@pytest.mark.parametrize("bad", [b"{not json", b'{"seq": 2, "op": "examples"}',
                                 b'{"seq": 2, "op": "rule", "text": 5, "behavior": "x"}',
                                 b"[]", b'{"seq": 2, "op": "nonsense"}'])
def test_damaged_middle_line_is_named_and_recoverable(tmp_path, monkeypatch, bad):
    from mitos_cli.teach.journal import Journal
    from mitos_cli.teach.session import Session

    d = _session(tmp_path, monkeypatch)
    path = d / "journal.jsonl"
    lines = path.read_bytes().split(b"\n")
    lines[1] = bad
    path.write_bytes(b"\n".join(lines))
    with pytest.raises(LessonError) as info:
        Journal.open(d)
    assert info.value.span.path == str(path) and info.value.span.line == 2
    journal = Journal.open(d, recover=True)
    assert journal.recovered_at == 2 and len(journal.entries) == 1
    Session.resume(journal, out=lambda s: None)
    assert journal.aside.is_file()


def test_a_damaged_start_offers_no_recovery_and_recovery_keeps_the_journal(tmp_path,
                                                                           monkeypatch):
    """A damaged first line (the session's start) was offered `--recover`, which then cut the
    journal to nothing and said "not a teaching journal"; there is nothing before it."""
    from mitos_cli.teach.journal import Journal

    d = _session(tmp_path, monkeypatch)
    path = d / "journal.jsonl"
    path.write_bytes(path.read_bytes().replace(b'"op":"start"', b'"op":"strt"', 1))
    damaged = path.read_bytes()
    for recover in (False, True):
        with pytest.raises(LessonError) as info:
            Journal.open(d, recover=recover)
        assert info.value.span.line == 1 and "--recover" not in info.value.hint
        assert "nothing to continue" in info.value.hint
    assert path.read_bytes() == damaged


def test_entry_that_cannot_be_applied_names_its_line(tmp_path, monkeypatch):
    from mitos_cli.teach.journal import Journal
    from mitos_cli.teach.session import Session

    d = _session(tmp_path, monkeypatch)
    path = d / "journal.jsonl"
    lines = path.read_text().splitlines()
    entry = json.loads(lines[1])
    entry["text"] = "if nothing then"
    lines[1] = json.dumps(entry)
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(LessonError) as info:
        Session.resume(Journal.open(d), out=lambda s: None)
    assert info.value.span.line == 2
    session = Session.resume(Journal.open(d), out=lambda s: None, recover=True)
    assert session.journal.recovered_at == 2 and not session.state.examples



def test_entry_naming_an_unknown_behavior_keeps_its_did_you_mean(tmp_path, monkeypatch):
    """The journal's refusal said "unknown behavior `drvie`" and dropped the inner error's
    "did you mean" for its own hint (--recover); it now gives both."""
    from mitos_cli.teach.journal import Journal
    from mitos_cli.teach.session import Session

    d = _session(tmp_path, monkeypatch)
    path = d / "journal.jsonl"
    with path.open("a") as f:
        f.write(json.dumps({"seq": 4, "op": "activate", "line": "use drvie",
                            "behavior": "drvie"}) + "\n")
    with pytest.raises(LessonError) as info:
        Session.resume(Journal.open(d), out=lambda s: None)
    assert info.value.span.line == 4
    assert "did you mean `drive`?" in info.value.hint and "--recover" in info.value.hint

# ---- the command line --------------------------------------------------------------------------------

@pytest.mark.parametrize("args", [["eval", "{long}.rules", "road=1"], ["check", "{long}.rules"],
                                  ["simulate", "{long}.yaml"], ["plot", "{long}.rules"],
                                  ["convert", "{long}.fcl", "-o", "x.rules"],
                                  ["teach", "{long}.rules"]])
def test_long_paths_are_errors_not_tracebacks(args, tmp_path, monkeypatch):
    from mitos_cli.cli.app import main

    monkeypatch.chdir(tmp_path)
    long = "x" * 300
    with pytest.raises(SystemExit) as info:
        main([a.format(long=long) for a in args])
    assert info.value.code in (1, 2)


def test_long_paths_named_inside_files_are_positioned_errors(tmp_path, monkeypatch):
    """A term set, a map image or a lesson named by a path the system cannot look up (a part
    over 255 characters) is the reader's refusal, in process too: Path.exists and is_file
    raise OSError for such a name."""
    from mitos_cli.lang.resolve import load_rules_file
    from mitos_cli.teach.lesson import read_lesson

    monkeypatch.chdir(tmp_path)
    long = "y" * 300
    rules = tmp_path / "long.rules"
    rules.write_text(f'terms "{long}.yaml"\nbehavior b:\n  r1: if a is X then b is Y\nend\n')
    with pytest.raises(TermSetError) as info:
        load_rules_file(rules)
    _positioned(info.value, 1)
    m = tmp_path / "m.yaml"
    m.write_text(f"image: {long}.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\n"
                 "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
    with pytest.raises(WorldError, match="too long") as info:
        load_map_yaml(m)
    _positioned(info.value, 1)
    with pytest.raises(LessonError, match="too long"):
        read_lesson(long + ".lesson")


def test_check_threshold_nan_is_a_usage_error(capsys):
    from mitos_cli.cli.app import main

    with pytest.raises(SystemExit) as info:
        main(["check", "--threshold", "nan"])
    assert info.value.code == 2


def test_a_number_past_a_floats_range_is_said_as_such(capsys):
    """``-t 1e400`` said "must be a finite number, not inf", a value the user never wrote:
    it is said as written, with why it is no number here."""
    from mitos_cli.cli.app import main

    with pytest.raises(SystemExit) as info:
        main(["check", "--threshold", "1e400"])
    said = " ".join(capsys.readouterr().err.replace("│", " ").split())
    assert info.value.code == 2
    assert ("the DOF threshold must be a number of 0 or more, not `1e400` (past 1.8e308, the "
            "largest number a float holds)") in said


# ---- bounded fuzzing, every input kind -----------------------------------------------------------

@pytest.fixture(scope="module")
def kinds(tmp_path_factory):
    sys.path.insert(0, str(ROOT / "benchmarks"))
    import fuzz

    work = tmp_path_factory.mktemp("fuzz")
    import os

    cwd = os.getcwd()
    os.chdir(work)
    try:
        yield fuzz, work, fuzz.Kinds(work).build()
    finally:
        os.chdir(cwd)


KIND_NAMES = ["rule files", "term-set YAML", "world YAML", "map YAML + PGM", "FCL", ".fis",
              "FLL", "teach commands", "eval --batch CSV", "teach journals", "CLI arguments",
              "fleet worlds", "fleet numbers", "lessons in words",
              "simulate and compare arguments"]
#: a whole command (or a simulation, a lesson) each: fewer inputs, mutated ones only
FEWER = {"CLI arguments": 10, "fleet worlds": 4, "fleet numbers": 4, "lessons in words": 4,
         "simulate and compare arguments": 4}


@pytest.mark.parametrize("name", KIND_NAMES)
def test_fuzz_kind_has_no_foreign_exceptions(kinds, name):
    import os

    fuzz, work, all_kinds = kinds
    kind = next(k for k in all_kinds if k.name == name)
    os.chdir(work)
    bad = []
    first = len(kind.seeds) if name in FEWER and name != "CLI arguments" else 0
    for i in range(first, first + FEWER.get(name, 25)):
        _, data = fuzz.make_input(kind, i, fuzz.SEED + 7)
        scratch = work / "scratch"
        scratch.mkdir(exist_ok=True)
        outcome, sig = fuzz.classify(kind, data, scratch, 10.0, 5.0)
        if outcome in fuzz.BAD:
            bad.append((i, outcome, sig))
    assert not bad


def test_campaign_shards_are_numbered_from_zero_and_sum_to_one_campaign(kinds):
    """`--shard 2/2` used to run inputs 2, 4, ... (input 0 of every kind skipped): refused;
    `--jobs` sums its shards' tables."""
    import argparse

    fuzz, _, _ = kinds
    assert fuzz.shard_of("1/2") == (1, 2) and fuzz.shard_of("0") == (0, 1)
    for bad in ("2/2", "-1/2", "x", "1/0"):
        with pytest.raises(argparse.ArgumentTypeError):
            fuzz.shard_of(bad)
    part = [{"name": "FLL", "tried": 3, "counts": dict.fromkeys(fuzz.OUTCOMES, 1), "cpu": 0.5,
             "seconds": 2.0, "large": [(70000, 0.1)]}]
    (fll,) = fuzz.merged([part, part])
    assert (fll.tried, fll.counts["foreign"], fll.cpu, len(fll.large)) == (6, 2, 1.0, 2)


def test_cli_route_classifies_what_the_user_sees(kinds, tmp_path):
    """``--via cli``: the CLI's main in this process, its exit code and stderr classified."""
    fuzz, _, _ = kinds
    rules = tmp_path / "a.rules"
    rules.write_text('terms "nowhere.terms.yaml"\n')
    code, err, _ = fuzz.cli_in_process(["check", str(rules)], tmp_path)
    assert code == 1 and fuzz.cli_outcome(code, err) == ("refused+pos", "")
    code, err, out = fuzz.cli_in_process(["eval", "--digits", "x"], tmp_path)
    assert (code, fuzz.cli_outcome(code, err, out)) == (2, ("refused", "usage error"))
    assert fuzz.cli_outcome(1, "Traceback (most recent call last):\n  ...\nKeyError: 'x'\n") \
        == ("foreign", "traceback: KeyError: 'x'")
    assert fuzz.cli_outcome(0, "f.py:3: RuntimeWarning: invalid value\n")[0] == "warning"


GAP_TERMS = """variables:
  road:
    role: input
    universe: [0, 100]
    terms:
      NARROW: {shape: left_shoulder, points: [10, 20]}
  steering:
    role: output
    universe: [0, 180]
    terms: {ST: 90}
"""


@pytest.mark.parametrize("as_json", [False, True])
def test_cli_route_reads_a_checks_errors_on_stdout(kinds, tmp_path, as_json):
    """``mitos check`` prints the errors it finds in a rule base, positioned, on stdout and
    exits 1 with stderr empty: that was "refused without a position: (no message)" (FCL input
    283 of the campaign of 2026-12-03). The route now reads stdout when stderr is empty."""
    fuzz, _, _ = kinds
    (tmp_path / "g.terms.yaml").write_text(GAP_TERMS)
    rules = tmp_path / "g.rules"
    rules.write_text('terms "g.terms.yaml"\nr1: if road is NARROW then steering is ST\n')
    argv = ["check", str(rules), "-n", "5"] + (["--json"] if as_json else [])
    code, err, out = fuzz.cli_in_process(argv, tmp_path)
    assert (code, err) == (1, "") and "error" in out
    assert fuzz.cli_outcome(code, err, out) == ("refused+pos", "")


def test_cli_route_says_what_stdout_held_when_nothing_is_positioned(kinds):
    """An exit 1 with stderr empty and an error without a position on stdout is a refusal
    without one, named by that line; with nothing on either, "(no message)"."""
    fuzz, _, _ = kinds
    out = "warning: x [w]\nerror: no rule sets steering [gap]\n\nchecked a: ...\n"
    assert fuzz.cli_outcome(1, "", out) == ("refused", "error: no rule sets steering [gap]")
    assert fuzz.cli_outcome(1, "", "") == ("refused", "(no message)")
    assert fuzz.cli_outcome(1, "", '{"findings": [{"severity": "error", "message": "m", '
                                   '"span": null}]}') == ("refused", "error: m")
    assert fuzz.cli_outcome(1, "", "{not json") == ("refused", "(no message)")


def test_cli_route_reads_stdout_when_stderr_holds_only_warnings(kinds):
    """`mitos check` of an FLL file that its reader warns about (a chained engine) and that
    holds a conflict: the warning on stderr, the positioned error on stdout. The campaign took
    the warning for an unpositioned refusal (FLL input 113 of seed 20261208)."""
    fuzz, _, _ = kinds
    err = "warning: f.fll: 7 rules chain outputs into inputs\n"
    out = "f.fll:40:9: error: `r9` has the same antecedent as `r6` [conflict]\n\nchecked ...\n"
    assert fuzz.cli_outcome(1, err, out) == ("refused+pos", "")
    assert fuzz.cli_outcome(1, err, "") == ("refused", "warning: f.fll: 7 rules chain outputs into inputs")
    assert fuzz.cli_outcome(1, "world error: bad\n", out) == ("refused", "world error: bad")


def test_a_long_token_is_shortened_in_the_message(tmp_path):
    """A 200,000-digit number in a rule file was quoted whole in the message and under a
    200,000-caret line (and the campaign's classification of it was quadratic)."""
    text = 'terms "mitos.terms.yaml"\noperators: and ' + "9" * 200_000 + "\n"
    with pytest.raises(RuleSyntaxError) as info:
        parse_rules(text, "big.rules")
    shown = info.value.render().splitlines()
    assert shown[0].startswith("big.rules:2:16: syntax error: unexpected `9999")
    assert "(200,000 characters)" in shown[0] and len(shown[0]) < 200
    assert max(len(line) for line in shown) < 300


def test_one_wide_rule_does_not_pad_its_level(tmp_path):
    from mitos_cli.lang.resolve import load_rules_file

    (tmp_path / "mitos.terms.yaml").write_text(
        (ROOT / "rulebases" / "mitos.terms.yaml").read_text())
    wide = " and ".join("road is WIDE" if i % 2 else "size is SMALL_SZ" for i in range(10_000))
    narrow = "\n".join(f"n{i}: if road is WIDE and size is SMALL_SZ and position is LEFT "
                       f"then steering is {40 + i}" for i in range(27))
    (tmp_path / "w.rules").write_text(f'terms "mitos.terms.yaml"\n{narrow}\n'
                                      f"w: if {wide} then steering is 90\n")
    compiled = compile_rulebase(load_rules_file(tmp_path / "w.rules"))
    cells = sum(g.children.size for level in compiled.levels for g in level)
    fan_in = sum(int((g.children >= 2).sum()) for level in compiled.levels for g in level)
    assert cells <= 2 * fan_in + 64          # padding at most doubles a group, not x 370


def test_teaching_killed_while_saving_keeps_a_whole_set(tmp_path, monkeypatch):
    """One trial of ``benchmarks/kill.py`` (50 of them give the figures in the docs): the kill
    lands at a random moment of a lesson that saves six times."""
    import random

    sys.path.insert(0, str(ROOT / "benchmarks"))
    import kill

    monkeypatch.chdir(tmp_path)
    pairs, changes = kill.reference(tmp_path / "reference")
    work = tmp_path / "trial"
    work.mkdir()
    result = kill.trial(work, pairs, changes, random.Random().uniform(1.5, 6.0))
    assert 0 <= result["saved"] <= kill.ROUNDS


def test_interrupted_set_save_is_finished_or_dropped(tmp_path):
    from mitos_cli.fileio import _manifest, atomic_write_set, finish_saves

    a, b = tmp_path / "x.rules", tmp_path / "x.terms.yaml"
    atomic_write_set([(b, "old terms"), (a, "old rules")], a)
    # a crash after the manifest: the next read carries the save out
    (tmp_path / ".x.terms.yaml.999999.ab.tmp").write_text("new terms")
    (tmp_path / ".x.rules.999999.cd.tmp").write_text("new rules")
    _manifest(a).write_text('[[".x.terms.yaml.999999.ab.tmp", "x.terms.yaml"], '
                            '[".x.rules.999999.cd.tmp", "x.rules"]]')
    assert finish_saves(a)
    assert (a.read_text(), b.read_text()) == ("new rules", "new terms")
    # a crash before it: the old set stays and the temporary file goes
    (tmp_path / ".x.rules.999999.ef.tmp").write_text("newer rules")
    assert not finish_saves(a)
    assert a.read_text() == "new rules"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.rules", "x.terms.yaml"]


def test_frozen_outside_a_behavior_is_positioned():
    from mitos_cli.lang.resolve import build_rulebase
    from mitos_cli.lang.termfile import load_termset

    text = 'terms "mitos.terms.yaml"\n\n  frozen r1\n'
    ts = load_termset(ROOT / "rulebases" / "mitos.terms.yaml")
    with pytest.raises(RuleBaseError) as info:
        build_rulebase(parse_rules(text, "f.rules"), (ts,), ("mitos.terms.yaml",))
    assert (info.value.span.line, info.value.span.column) == (3, 10)             # at the label


def test_batch_nan_cell_is_positioned():
    with pytest.raises(InputError, match="input `size` is not a number") as info:
        read_batch("road,size,position\n1,2,3\n\n4,nan,6\n", "b.csv", ("road", "size", "position"))
    _positioned(info.value, 4)


def test_adapt_epochs_are_bounded():
    from mitos_cli.teach.session import Session

    session = Session(ROOT / "rulebases" / "mitos.rules", out=lambda s: None)
    session.run("correct road=78 size=45 position=4 -> steering=100")
    with pytest.raises(LessonError, match="at most"):
        session.run("adapt epochs 4e300")


def test_a_use_cycle_is_reported_at_the_use_that_closes_it(tmp_path):
    """The cycle error pointed at the top level (`main`), which has no position."""
    from mitos_cli.lang.resolve import load_rules_file

    (tmp_path / "mitos.terms.yaml").write_text((ROOT / "rulebases" / "mitos.terms.yaml")
                                               .read_text())
    rules = tmp_path / "c.rules"
    rules.write_text('terms "mitos.terms.yaml"\nbehavior b:\n  r1: if road is WIDE then '
                     'steering is RS\n  use b\nend\nuse b\n')
    with pytest.raises(RuleBaseError, match="in a cycle: b -> b") as info:
        load_rules_file(rules)
    assert (info.value.span.line, info.value.span.column) == (4, 3)


def _uses(tmp_path, text: str) -> Path:
    (tmp_path / "mitos.terms.yaml").write_text((ROOT / "rulebases" / "mitos.terms.yaml")
                                               .read_text())
    rules = tmp_path / "u.rules"
    rules.write_text('terms "mitos.terms.yaml"\n' + text)
    return rules


def test_behaviors_that_use_the_same_two_again_are_refused_before_they_double_out(tmp_path):
    """Two behaviors a level, each using both of the next level's: written out they double
    at each level, and a 2 KB file took `check` minutes and gigabytes (the cycle check alone
    walked every path). They are refused at the `use` that passes the limit, at once."""
    from mitos_cli.lang.resolve import MAX_WRITTEN_RULES, load_rules_file

    levels = 16
    text = "".join(f"behavior {n}{i}:\n  r: if road is WIDE then steering is RS\n"
                   + (f"  use b{i + 1}\n  use c{i + 1}\n" if i < levels - 1 else "") + "end\n"
                   for i in range(levels) for n in "bc")
    with pytest.raises(RuleBaseError, match=f"would hold more than {MAX_WRITTEN_RULES:,} rules "
                                            "once the behaviors it uses are written out") as info:
        load_rules_file(_uses(tmp_path, text))
    assert info.value.span.source_line.strip().startswith("use ")


def test_a_chain_of_uses_deeper_than_the_limit_is_refused_not_a_recursion_error(tmp_path):
    """1,000 behaviors each using the next met Python's recursion limit (a traceback)."""
    from mitos_cli.lang.resolve import MAX_USE_DEPTH, load_rules_file

    text = "".join(f"behavior b{i}:\n  r{i}: if road is WIDE then steering is RS\n"
                   + (f"  use b{i + 1}\n" if i < 999 else "") + "end\n" for i in range(1000))
    with pytest.raises(RuleBaseError, match=f"use each other more than {MAX_USE_DEPTH} deep"):
        load_rules_file(_uses(tmp_path, text))
    fine = "".join(f"behavior b{i}:\n  r{i}: if road is WIDE then steering is RS\n"
                   + (f"  use b{i + 1}\n" if i < MAX_USE_DEPTH else "") + "end\n"
                   for i in range(MAX_USE_DEPTH + 1))
    assert len(load_rules_file(_uses(tmp_path, fine)).behaviors) == MAX_USE_DEPTH + 1


def test_edges_too_narrow_for_a_float_slope_give_numbers_not_warnings(recwarn):
    """FLL terms 1e-320 wide: an infinite slope (or 2 / width) times 0 at the corner was NaN,
    with NumPy's "invalid value" / "overflow" warnings printed to the user."""
    import numpy as np

    from mitos_cli.fuzzy import shapes
    from mitos_cli.interop.fll import parse_fll

    assert shapes.gaussian(np.array([0.0, 1.0]), 0.0, 2.1e-321).tolist() == [1.0, 0.0]
    assert shapes.cosine(np.array([-15.0, 0.0]), -15.0, 3.01e-318).tolist() == [1.0, 0.0]
    rb = parse_fll("InputVariable: a\n  range: -45 45\n  term: ahead Triangle -20 0 1e-320\n"
                   "OutputVariable: t\n  range: 0 1\n  defuzzifier: Centroid\n"
                   "  term: hi Triangle 0 1 1\nRuleBlock: main\n  implication: Minimum\n"
                   "  rule: if a is ahead then t is hi\n", "narrow.fll")
    from mitos_cli.engine.evaluation import evaluate

    res = evaluate(compile_rulebase(rb), np.array([[0.0], [-10.0], [1.0]]), strict=False)
    dof = res.dof[:, 0]
    assert dof.tolist() == [1.0, 0.5, 0.0]
    from mitos_cli.engine.check import check_rulebase
    check_rulebase(parse_fll(       # its partition checks take the edge as a vertical one
        "InputVariable: a\n  range: -45 45\n  term: ahead Triangle -20 0 1e-320\n"
        "  term: left Triangle -45 -20 0\nOutputVariable: t\n  range: 0 1\n"
        "  aggregation: Maximum\n  defuzzifier: Centroid\n  term: hi Triangle 0 1 1\n"
        "RuleBlock: main\n  implication: Minimum\n  rule: if a is ahead then t is hi\n"
        "  rule: if a is left then t is hi\n", "narrow.fll"))
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]


@pytest.mark.parametrize("header", ['positi"on,road,size45\n', 'position"road,,\n4,78,45\n'])
def test_a_quote_inside_a_header_cell_is_positioned(header):
    """A quote inside a cell (not at its start) is a character to the ``csv`` module, but the
    column finder took it for an opening quote: ``IndexError`` instead of the message."""
    with pytest.raises(InputError) as info:
        read_batch(header, "q.csv", ("road", "size", "position"))
    assert info.value.span.line == 1


def test_cell_starts_agree_with_the_csv_module():
    """The scanner that finds cells again for an error splits records as the ``csv`` module
    (strict) does, line breaks in quotes included, and refuses what it refuses."""
    import csv
    import io
    import random

    from mitos_cli.engine.csvio import _scan

    rng = random.Random(3)
    for _ in range(3000):
        text = "".join(rng.choice('ab",\n') for _ in range(rng.randrange(12))) + "\n"
        starts, problem = _scan(text, 0)
        try:
            first = next(csv.reader(io.StringIO(text, newline=""), strict=True), [])
        except csv.Error:
            assert problem is not None, repr(text)
            continue
        assert problem is None, repr(text)
        if first:
            assert len(starts) == len(first), repr(text)


def test_only_a_long_token_is_shortened_not_the_words_between_two_quotes():
    words = "x " * 60
    err = RuleSyntaxError(f"term `a` {words}is not a `b` term")
    assert err.render() == f"syntax error: term `a` {words}is not a `b` term"


@pytest.mark.parametrize("change", ['"save_as": true', '"save_as": 3'])
def test_a_journal_start_whose_save_path_is_not_a_path_is_named(tmp_path, monkeypatch, change):
    """`"save_as": true` in a journal's first line was a TypeError in `Session`."""
    from mitos_cli.teach.journal import Journal

    monkeypatch.chdir(tmp_path)
    d = tmp_path / "s"
    d.mkdir()
    rules = str(ROOT / "rulebases" / "mitos.rules")
    (d / "journal.jsonl").write_text(json.dumps({"seq": 1, "op": "start", "rules": rules,
                                                 "behavior": "avoid_obstacle"})[:-1]
                                     + f", {change}}}\n" + '{"seq": 2, "op": "save"}\n')
    with pytest.raises(LessonError, match="save_as` is not a path") as info:
        Journal.open(d)
    assert info.value.span.line == 1


def test_a_start_far_outside_a_grid_map_is_outside_without_a_warning(recwarn):
    """`q_init: {y: 1e38}` on a grid map: the cell index's int64 cast warned "invalid value"."""
    import numpy as np

    from mitos_cli.sim.staticmap import build_static
    from mitos_cli.sim.worldfile import load_world

    static = build_static(load_world(ROOT / "worlds" / "office.yaml"))
    assert static.grid is not None
    assert not static.free(np.array([[-275.0, 1e38], [-275.0, np.nan]])).any()
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]


@pytest.mark.parametrize("key", ["obstacles", "robots"])
def test_a_world_list_given_as_a_mapping_is_positioned(key):
    """`obstacles:` followed by a mapping (one space of indentation lost) was an
    AttributeError in the world reader."""
    from mitos_cli.sim.worldfile import parse_world

    text = (ROOT / "worlds" / "office.yaml").read_text()
    text = text.replace("\n  - {name: trolley", "\n   {name: trolley", 1) \
        if key == "obstacles" else text + "robots:\n  name: r2\n"
    with pytest.raises(WorldError, match=f"`{key}` must be a list") as info:
        parse_world(text, str(ROOT / "worlds" / "w.yaml"))   # the map beside it
    assert info.value.span is not None and info.value.span.line > 1


TINY_WORLD = Path(__file__).parent / "data" / "tiny.yaml"


@pytest.mark.parametrize("old, new, col", [
    ("[[0, 0], [280, 0]]", "[[0, 0], [280, 1.0e+37]]", 30),       # at the number
    ("width: 70", "width: 8.0e+178", 14),
])
def test_world_numbers_too_large_for_the_geometry_are_refused(tmp_path, old, new, col):
    """A coordinate or width of 1e37 in made the wall geometry divide inf by inf (NumPy's
    'invalid value' warning, then NaN walls); the reader refuses beyond 1e7 in."""
    import warnings

    from mitos_cli.errors import WorldError
    from mitos_cli.sim.worldfile import load_world

    path = tmp_path / "big.yaml"
    path.write_text(TINY_WORLD.read_text().replace(old, new))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(WorldError, match=r"within ±1e\+07") as err:
            load_world(path)
    assert (err.value.span.line, err.value.span.column) == (21 if "[" in old else 22, col)


def test_a_term_set_named_twice_is_refused_at_its_line_before_it_is_read_again(tmp_path):
    """The fuzz pass of 2026-12-03 (`mitos check` through the CLI, seed 20261211, rule files
    input 257): `terms "mitos.terms.yaml"` repeated 20,000 times (500 KB) parsed the YAML once
    per line (2,000 lines: 30 CPU s; the whole file about 13 minutes) to end in "variable
    `road` is defined in two term sets" at the YAML. Now the second line is the error."""
    from mitos_cli.lang.resolve import load_rules_file
    from mitos_cli.resources import packaged_path

    (tmp_path / "t.terms.yaml").write_text(
        packaged_path("rulebases", "mitos.terms.yaml").read_text(encoding="utf-8"))
    rules = tmp_path / "twice.rules"
    rules.write_text('terms "t.terms.yaml"\n' * 2000 + "if road is WIDE then speed is 20\n")
    start = time.process_time()
    with pytest.raises(TermSetError, match=r"term set `t.terms.yaml` is named twice") as info:
        load_rules_file(rules)
    assert time.process_time() - start < 5
    assert (info.value.span.line, info.value.span.column) == (2, 7)
    rules.write_text('terms "t.terms.yaml"\nterms "./t.terms.yaml"\n')
    with pytest.raises(TermSetError, match="`./t.terms.yaml` is named twice"):
        load_rules_file(rules)


@pytest.mark.parametrize("width", ["1e-320", "1e-20"])
def test_a_corridor_too_thin_for_a_float_has_no_inside_and_no_warning(tmp_path, width):
    """The fuzz pass of 2026-12-03: a corridor `width: 1e-320` (or any width lost against its
    coordinates) gave a rectangle side of length 0, which the wall clipper divided by (NumPy's
    'invalid value' / 'divide by zero' warnings). Such a rectangle has no inside: it clips
    nothing, and the world reads as with any other width the robot cannot use."""
    import warnings

    from mitos_cli.sim.worldfile import load_world

    thin = "    - points: [[100, -100], [100, -35]]\n      width: " + width + "\n"
    path = tmp_path / "thin.yaml"
    path.write_text(TINY_WORLD.read_text().replace("obstacles:", thin + "obstacles:", 1))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        world = load_world(path)                    # a side corridor no route needs
        assert len(world.corridors) == 2
        path.write_text(TINY_WORLD.read_text().replace("width: 70", "width: " + width))
        with pytest.raises(WorldError, match=r"the start \(q_init\) at \(30, -10\) lies inside"):
            load_world(path)


def test_world_seed_may_be_large(tmp_path):
    from mitos_cli.sim.worldfile import load_world

    path = tmp_path / "seeded.yaml"
    path.write_text(TINY_WORLD.read_text().replace("seed: 1\n", "seed: 20261202123\n"))
    assert load_world(path).seed == 20261202123


def test_a_vertical_edge_on_a_huge_universe_does_not_warn(tmp_path):
    """A trapezoid's vertical edge (slope capped at 1e300) times a distance of 1e38 overflows
    to inf, which the membership clips to 0 or 1: the right answer, without NumPy's warning."""
    import warnings

    import numpy as np

    from mitos_cli.api import read_rulebase
    from mitos_cli.engine.compile import compile_rulebase
    from mitos_cli.engine.evaluation import evaluate

    path = tmp_path / "wide.fis"
    path.write_text("[System]\nName='wide'\nType='mamdani'\n[Input1]\nName='food'\n"
                    "Range=[0 99999999999999999999999999999999999999]\n"
                    "MF1='rancid':'trapmf',[0 0 1 3]\nMF2='delicious':'trapmf',[7 9 10 10]\n"
                    "[Output1]\nName='tip'\nRange=[0 30]\nMF1='cheap':'trimf',[0 5 10]\n"
                    "MF2='generous':'trimf',[20 25 30]\n[Rules]\n1, 1 (1) : 1\n2, 2 (1) : 1\n")
    rb = read_rulebase(path)
    X = np.array([[0.5], [9.5], [10.0], [5e37], [1e38]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = evaluate(compile_rulebase(rb), X, strict=False).outputs[:, 0]
    assert np.all(np.isfinite(out[:3]))
    assert np.isclose(out[1], 25.0, atol=0.5) and np.isclose(out[0], 5.0, atol=0.5)


def test_a_hash_in_a_batch_row_is_a_bad_value_not_a_comment(tmp_path):
    """NumPy's loadtxt took `#` for a comment: a row `#` gave its 'no data' warning, and
    `2,80,30 # note` lost its note silently; every row is data, as with extra columns."""
    import warnings

    from mitos_cli.errors import InputError

    for body, where in (("#\n", (2, 1)), ("1,70,20\n2,80,30 # note\n", (3, 6))):
        path = tmp_path / "hash.csv"
        path.write_text("position,road,size\n" + body)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            with pytest.raises(InputError) as err:
                read_batch(path.read_text(), str(path), ("position", "road", "size"))
        assert (err.value.span.line, err.value.span.column) == where


@pytest.mark.parametrize("line, words", [
    # the campaign's minimal reproducer (seed 20261203): `op` is an array
    (b'{"seq":1,"opes":"/","op":[{"ts":{"st":10},"soe":"correct"}]}', "is a JSON array"),
    (b'{"seq":1,"op":{"start":1}}', "is a JSON object"),
    (b'{"seq":1,"op":5}', "is 5, not a string"),
    (b'{"seq":1}', "is missing"),
    (b'{"seq":[' + b"1," * 50000 + b'1],"op":"start"}', "found a JSON array"),
])
def test_a_journal_change_name_that_is_not_a_string_is_named(tmp_path, line, words):
    """`"op": [...]` (an unhashable value) was a TypeError in `journal._problem`; the message
    also quotes a long value only by its JSON type."""
    from mitos_cli.teach.journal import Journal

    d = tmp_path / "s"
    d.mkdir()
    (d / "journal.jsonl").write_bytes(line + b"\n" + b'{"seq": 2, "op": "save"}\n')
    with pytest.raises(LessonError, match="damaged") as info:
        Journal.open(d)
    assert words in info.value.message and len(info.value.message) < 200
    assert info.value.span.path == str(d / "journal.jsonl") and info.value.span.line == 1


# ---- large files: time in proportion (found by timing growing files after the seed-20261203 campaign)

def _chain_fll(outputs: int, condition: str) -> str:
    """A fuzzylite chained engine: `y0` from the input, each `yI` from `y(I-1)`."""
    lines = ["Engine: chain", "InputVariable: x", "  range: 0 1", "  term: A Triangle 0 0.5 1"]
    for i in range(outputs):
        lines += [f"OutputVariable: y{i}", "  range: 0 1", "  aggregation: Maximum",
                  "  defuzzifier: Centroid 100", "  default: 0.5", "  term: A Triangle 0 0.5 1"]
    lines += ["RuleBlock: main", "  conjunction: Minimum", "  disjunction: Maximum",
              "  implication: Minimum", "  activation: General", "  rule: if x is A then y0 is A"]
    lines += [f"  rule: if {condition.format(p=f'y{i - 1}')} then y{i} is A"
              for i in range(1, outputs)]
    return "\n".join(lines) + "\n"


def test_a_chain_that_doubles_at_each_step_is_refused_not_written_out():
    """Each rule testing the previous output twice: 2^k propositions written out (22 rules, a
    5 KB file, took 6 s; 30 rules would take hours). Refused at the test crossing 100,000."""
    from mitos_cli.errors import FormatError
    from mitos_cli.interop.fll import parse_fll

    t0 = time.process_time()
    with pytest.raises(FormatError, match="more than 100,000 propositions") as info:
        parse_fll(_chain_fll(22, "{p} is A and {p} is A"), "chain.fll")
    assert time.process_time() - t0 < 5
    assert info.value.span.source_line.strip() == "rule: if y15 is A and y15 is A then y16 is A"
    assert info.value.span.column == 25         # the test of `y15` that crosses the bound
    parse_fll(_chain_fll(12, "{p} is A and {p} is A"), "chain.fll")   # 2^12: read


def test_a_chain_that_nests_deeper_than_rules_may_is_refused():
    """A chain of 300 rules each adding a level: the restated condition nested 300 deep (1,000
    was a RecursionError in `resolve.check_expr`)."""
    from mitos_cli.errors import FormatError
    from mitos_cli.interop.fll import parse_fll

    for outputs in (300, 1000):
        with pytest.raises(FormatError, match="nests 101 deep, more than 100") as info:
            parse_fll(_chain_fll(outputs, "{p} is A and x is A"), "chain.fll")
        assert "then y100 is A" in info.value.span.source_line
    parse_fll(_chain_fll(60, "{p} is A and x is A"), "chain.fll")


def _cost(read, text: str) -> float:
    t0 = time.process_time()
    read(text)
    return time.process_time() - t0


@pytest.mark.parametrize("fmt", ["fll", "fis", "fcl"])
def test_reading_a_foreign_file_is_linear_in_its_rules(fmt):
    """Every line's (FLL, `.fis`) or node's (FCL) span split the whole text again (8,000 FLL
    rules took 50 s); a rule WITH a weight looked at every rule (8,000 FCL rules, 2 minutes)."""
    from mitos_cli.api import read_rulebase
    from mitos_cli.interop import fcl, fis, fll

    interop = ROOT / "tests" / "data" / "interop"
    if fmt == "fll":
        seed = fll.write_fll(read_rulebase(ROOT / "rulebases" / "mitos.rules"))
        rule = next(x for x in seed.splitlines() if x.strip().startswith("rule:")) + "\n"

        def text(n):
            return seed.replace(rule, rule * n, 1)
        read = fll.parse_fll
    elif fmt == "fis":
        seed = (interop / "tipper.fis").read_text()
        rule = seed[seed.index("[Rules]"):].splitlines()[1] + "\n"

        def text(n):
            return seed.replace("NumRules=3", f"NumRules={n + 3}").rstrip("\n") + "\n" + rule * n
        read = fis.parse_fis
    else:
        seed = (interop / "robot_jfuzzylogic.fcl").read_text()

        def text(n):
            return seed.replace("END_RULEBLOCK", "".join(
                f"RULE {k + 100} : IF dist IS near AND angle IS right THEN turn IS hard_left "
                f", speed IS slow WITH 0.9;\n" for k in range(n)) + "END_RULEBLOCK")
        read = fcl.parse_fcl
    small_text, large_text = text(250), text(2000)
    _cost(read, small_text)
    small = min(_cost(read, small_text) for _ in range(2))
    large = min(_cost(read, large_text) for _ in range(2))
    assert large < 8 * small * 2.5          # 8x the rules: linear, with room for noise


def test_readers_pause_the_cyclic_collector_and_restore_it():
    """The collector's passes over a growing parse tree made reading super-linear (8,000 FCL
    rules 0.28 ms a rule, 0.12 paused); a reader pauses it and gives it back as it found it,
    also after an error."""
    import gc

    from mitos_cli.lang.bulk import without_cyclic_gc

    seen = []

    @without_cyclic_gc
    def read(fail: bool) -> None:
        seen.append(gc.isenabled())
        if fail:
            raise RuleSyntaxError("bad", span=Span("x.rules", 1, 1))

    assert gc.isenabled()
    read(False)
    with pytest.raises(RuleSyntaxError):
        read(True)
    assert seen == [False, False] and gc.isenabled()
    gc.disable()
    try:
        read(False)
        assert not gc.isenabled()               # a paused collector stays paused
    finally:
        gc.enable()
    with pytest.raises(RuleSyntaxError):        # a real reader, on a malformed file
        parse_rules("behavior b:\n r1: if if\nend\n", "x.rules")
    assert gc.isenabled()


def test_a_span_on_a_long_line_looks_only_around_its_column():
    """`Span.at` searched for the end of the line from the node: a node per condition of one
    line of 80,000 conditions (1.3 MB) made parsing it take 20 s."""
    short, long = "x" * 1_000, "x" * 4_000_000

    def cost(text):
        t0 = time.process_time()
        for i in range(300):
            Span.at(text, "f", i, 1, i + 1)
        return time.process_time() - t0

    cost(short)
    assert min(cost(long) for _ in range(2)) < 10 * min(cost(short) for _ in range(2)) + 0.05
    assert Span.at(long, "f", 10, 1, 11).source_line == "x" * 240


def _lesson_cost(n: int) -> float:
    from mitos_cli.teach.lesson import run_lesson
    from mitos_cli.teach.session import Session

    session = Session(ROOT / "rulebases" / "mitos.rules", out=lambda s: None)
    text = "".join(f"if road is WIDE and size is SMALL_SZ then speed is {k % 7 * 10}\n"
                   if k % 2 else f"z{k}: if road is NARROW and position is LEFT then speed is 20\n"
                   for k in range(n))
    t0 = time.process_time()
    run_lesson(session, text, "many.lesson")
    return time.process_time() - t0


def test_telling_many_rules_is_linear():
    """Each told rule walked every rule to find its label, a free label and the rules with its
    condition (written out again for each), and `state._put_rule` copied the rules in a Python
    loop: 4,000 rules took 32 s, 16,000 (1 MB) would take minutes; now about 9 s."""
    _lesson_cost(50)
    small, large = min(_lesson_cost(250) for _ in range(2)), _lesson_cost(2000)
    assert large < 8 * small * 2.5          # 8x the rules: linear, with room for noise


def test_a_told_rule_names_at_most_five_rules_with_its_condition():
    from mitos_cli.teach.session import Session

    out: list[str] = []
    session = Session(ROOT / "rulebases" / "mitos.rules", out=out.append)
    for k in range(8):
        session.run(f"z{k}: if road is NARROW and position is LEFT then speed is {20 + k % 2}")
    out.clear()
    session.run("z8: if position is LEFT and road is NARROW then speed is 20")
    lines = "\n".join(out).splitlines()
    assert lines[2:] == ["  note: z0 says the same",
                         "  conflict: z1 has the same condition but says speed is 21",
                         "  note: z2 says the same",
                         "  conflict: z3 has the same condition but says speed is 21",
                         "  note: z4 says the same", "  and 3 more rules with the same condition"]
    out.clear()                             # replaced in place: the others keep their order
    session.run("z0: if road is NARROW and position is LEFT then speed is 21")
    assert "\n".join(out).splitlines()[2:4] == [
        "  note: z1 says the same", "  conflict: z2 has the same condition but says speed is 20"]
    assert [r.label for r in session.rulebase.behavior("avoid_obstacle").rules][-9:] == \
        [f"z{k}" for k in range(9)]


def test_looking_up_a_behavior_does_not_walk_them_all():
    """`RuleBase.behavior` walked the behaviors: a file of 8,000 behaviors spent 3.7 s there."""
    from mitos_cli.lang.model import Behavior, RuleBase

    rb = RuleBase(None, (), tuple(Behavior(f"b{i}") for i in range(20_000)) + (Behavior("b0"),))
    t0 = time.process_time()
    assert all(rb.behavior(f"b{i}").name == f"b{i}" for i in range(20_000))
    assert time.process_time() - t0 < 2.0           # walking them: 200 million steps
    assert rb.behavior("b0") is rb.behaviors[0] and rb.behavior() is rb.behaviors[0]
    with pytest.raises(MitosError, match="unknown behavior `b20000`"):
        rb.behavior("b20000")


def _fleet(n: int) -> str:
    """A world of ``n`` robots after the first, far apart in a wide corridor, each to a goal
    of its own."""
    rows = "".join(f"  - {{name: r{i}, q_init: {{x: {60 + 60 * i}, y: 30}}, "
                   f"q_goal: {{x: {90 + 60 * i}, y: -30}}}}\n" for i in range(n))
    end = 60 * (n + 2)
    return ("name: fleet\ndt: 0.05\ntime_limit: 10\nrobot:\n  model: tricycle\n"
            "  wheelbase: 16\n  footprint: {length: 24, width: 18}\n"
            f"q_init: {{x: 30, y: -100}}\nq_goal: {{x: {end - 40}, y: -100}}\n"
            f"robots:\n{rows}map:\n  corridors:\n    - points: [[0, 0], [{end}, 0]]\n"
            "      width: 260\n")


def test_a_fleet_loads_in_time_near_linear_in_its_robots():
    """Every two robots' starts were measured box against box (night 24's campaign, by hand: 400
    robots took 4.1 to 4.6 CPU s to load, 800 took 16); only robots whose bodies' circles meet are
    measured now. What is left of the pairs is the goals' check, microseconds each."""
    from mitos_cli.sim.worldfile import parse_world

    def cost(n: int) -> float:
        text = _fleet(n)
        t0 = time.process_time()
        parse_world(text, "fleet.yaml")
        return time.process_time() - t0

    cost(10)
    small, large = min(cost(50) for _ in range(2)), min(cost(400) for _ in range(2))
    assert large < 8 * small * 2.5          # 8x the robots: near linear, with room for noise


def test_reading_many_fll_variables_is_linear():
    """The input names were listed again for each variable (8,000 variables: 2.4 s)."""
    from mitos_cli.interop.fll import parse_fll

    def text(n):
        out = ["Engine: many"] + [x for i in range(n) for x in (
            f"InputVariable: x{i}", "  range: 0 1", "  term: A Triangle 0 0.5 1")]
        out += ["OutputVariable: y", "  range: 0 1", "  aggregation: Maximum",
                "  defuzzifier: Centroid", "  term: A Triangle 0 0.5 1", "RuleBlock: main",
                "  implication: Minimum"] + [f"  rule: if x{i} is A then y is A" for i in range(n)]
        return "\n".join(out) + "\n"

    small_text, large_text = text(750), text(6000)
    _cost(parse_fll, small_text)
    small = min(_cost(parse_fll, small_text) for _ in range(2))
    assert _cost(parse_fll, large_text) < 8 * small * 2.5


@pytest.mark.parametrize("names, line", [(["a", "b", "a"], 1), (["a", "b", "b"], 2)])
def test_duplicate_obstacle_names_are_named_at_the_first(tmp_path, names, line):
    """The check counts names once (a count per obstacle was N^2); it still names the first
    obstacle whose name is used twice."""
    from mitos_cli.sim.worldfile import parse_world

    corridor = (ROOT / "worlds" / "corridor.yaml").read_text()
    items = "".join(f"  - {{name: {n}, shape: circle, at: [{100 + 40 * i}, 20], radius: 2}}\n"
                    for i, n in enumerate(names))
    text = corridor.replace("obstacles:\n", "obstacles:\n" + items, 1)
    first = text.splitlines().index("obstacles:") + 1
    with pytest.raises(WorldError, match=f"two obstacles are named `{names[line - 1]}`") as info:
        parse_world(text, str(tmp_path / "w.yaml"))
    assert info.value.span.line == first + line


def test_repeated_term_names_are_renamed_in_linear_time():
    """A `.fis` MF or an FLL term repeated 20,000 times (the seed-20261203 campaign's 16 slow
    inputs): each repeat gathered every name again and tried every suffix an earlier repeat
    had taken (60 s); the names are the same as before."""
    from mitos_cli.interop.common import distinct_names
    from mitos_cli.lang.terms import Term

    terms = [Term("low", "triangle", (0.0, 1.0, 2.0)) for _ in range(4)] + \
        [Term("low_2_2", "triangle", (0.0, 1.0, 2.0))]
    notes: list[str] = []
    assert [t.name for t in distinct_names(terms, "x", notes, "why")] == \
        ["low", "low_2", "low_2_3", "low_2_4", "low_2_2"]
    assert [t.name for t in distinct_names(terms[:3], "x", [], "why", keep_last=True)] == \
        ["low_2_2", "low_2", "low"]
    many = [Term("low", "triangle", (0.0, 1.0, 2.0))] * 20_000
    t0 = time.process_time()
    names = [t.name for t in distinct_names(many, "x", notes, "why")]
    assert time.process_time() - t0 < 2.0
    assert len(set(names)) == 20_000 and names[-1] == "low_2_19999"


# --- paths in a directory this user cannot enter -----------------------------------------------

LOCKED_COMMANDS = [
    (["convert", "{rules}", "--to", "rules", "-o", "{locked}/y.rules"], "cannot write"),
    (["compare", "corridor", "--runs", "1", "--out", "{locked}/study"],
     "study error: cannot use the output directory"),
    (["teach", "{locked}/r.rules"], "rule base error: cannot read rule file"),
]


def _locked_run(args, tmp_path, capsys):
    from mitos_cli.api import default_rulebase_path
    from mitos_cli.cli.app import main

    filled = [a.format(rules=default_rulebase_path(), locked=tmp_path / "locked") for a in args]
    with pytest.raises(SystemExit) as info:
        main(filled)
    return info.value.code, capsys.readouterr().err


@pytest.mark.parametrize(("args", "says"), LOCKED_COMMANDS)
def test_a_path_in_a_directory_that_cannot_be_entered_is_said_in_words(args, says, tmp_path,
                                                                       capsys, monkeypatch):
    """As another user (`sudo -u`, a HOME of 0700), asking whether a path inside such a
    directory exists is itself refused: `convert -o` (its term set's stray check), `compare
    --out` and `teach FILE` ended in a `PermissionError` traceback. Each is a message and
    exit 1 now. (Root enters every directory: the refusal is played by the path's stat.)"""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "locked").mkdir()
    real_stat, real_lstat = Path.stat, Path.lstat

    def denied(real):
        def stat(self, *a, **k):
            if "locked" in self.parts and self.name != "locked":
                raise PermissionError(13, "Permission denied", str(self))
            return real(self, *a, **k)
        return stat

    monkeypatch.setattr(Path, "stat", denied(real_stat))
    monkeypatch.setattr(Path, "lstat", denied(real_lstat))
    code, err = _locked_run(args, tmp_path, capsys)
    assert code == 1 and says in err and "Traceback" not in err


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() == 0,
                    reason="root enters any directory")
@pytest.mark.parametrize(("args", "says"), LOCKED_COMMANDS)
def test_a_directory_that_cannot_be_entered_as_its_user_meets_it(args, says, tmp_path, capsys,
                                                                monkeypatch):
    monkeypatch.chdir(tmp_path)
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o000)
    try:
        code, err = _locked_run(args, tmp_path, capsys)
    finally:
        locked.chmod(0o700)
    assert code == 1 and says in err and "Traceback" not in err
