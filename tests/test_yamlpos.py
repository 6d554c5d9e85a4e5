"""YAML with positions: keys YAML would silently turn into booleans or numbers are refused."""

from __future__ import annotations

from pathlib import Path

import pytest

from mitos_cli.errors import TermSetError
from mitos_cli.lang import yamlpos


@pytest.mark.parametrize("key,kind", [("ON", "true/false"), ("no", "true/false"),
                                      ("12", "a number"), ("1.5", "a number"), ("~", "null")])
def test_non_string_keys_are_refused_with_a_hint(key, kind):
    with pytest.raises(TermSetError) as info:
        yamlpos.load(f"a:\n  {key}: 1\n", "f.yaml", TermSetError)
    err = info.value
    assert (err.span.path, err.span.line, err.span.column) == ("f.yaml", 2, 3)
    assert f"the key `{key}` reads as {kind} in YAML; write it in quotes" in err.message


def test_quoted_keys_and_positions():
    data = yamlpos.load('a:\n  "ON": 1\n  b: [1, 2]\n', "f.yaml", TermSetError)
    assert data["a"]["ON"] == 1
    assert data["a"].key_span("b").line == 3 and data["a"]["b"].item_span(1).column == 10


def test_duplicate_keys_are_refused():
    with pytest.raises(TermSetError, match="duplicate key `a`"):
        yamlpos.load("a: 1\na: 2\n", "f.yaml", TermSetError)


def test_booleans_are_read_as_yaml_1_2_reads_them():
    """Only true and false (in three cases) are booleans; YAML 1.1's yes/no/on/off are the
    text they are, so that a flag given one is refused instead of silently read."""
    data = yamlpos.load("a: [true, True, TRUE, false, False, FALSE]\n"
                        "b: [yes, Yes, YES, no, No, NO, on, On, ON, off, Off, OFF, y, n]\n",
                        "f.yaml", TermSetError)
    assert data["a"] == [True, True, True, False, False, False]
    assert data["b"] == ["yes", "Yes", "YES", "no", "No", "NO", "on", "On", "ON", "off", "Off",
                         "OFF", "y", "n"]
    assert [yamlpos.yaml11_bool(v) for v in data["b"]] == [True] * 3 + [False] * 3 + \
        [True] * 3 + [False] * 3 + [None, None]
    assert yamlpos.yaml11_bool("oN") is None and yamlpos.yaml11_bool(True) is None


@pytest.mark.parametrize("text,where,words,expected", [
    ("a:\n\t- 1\n", (2, 1), "a tab in the indentation, which YAML does not take",
     "spaces: YAML indents with spaces"),
    # a tab at a line's end (an editor's leftover; night 24's rewritings of the shipped files)
    # was said as a tab in the indentation, which YAML does not take: YAML takes it there,
    # PyYAML does not
    ("a: 1\t\nb: 2\n", (1, 5), "a tab at the end of the line, after what it holds",
     "nothing after it on the line: delete the tab"),
    ("a:\t \r\n  b: 1\n", (1, 3), "a tab at the end of the line", "delete the tab"),
    ("a: 1\t# why\n", (1, 5), "a tab at the end of the line", "delete the tab"),
    ("a: b: c\n", (1, 5), "a `:` where no new key can start", "one `key: value` a line"),
    ("x:\n  - 1\n y: 2\n", (3, 2), "indentation matches no key above it", "the indentation of a key"),
    ('a: 1\nx: "abc\n', (2, 4), "a quoted value is not closed", "its closing quote"),
    # a `[` or `{` not closed is said at the bracket: PyYAML said "expected ',' or ']', but
    # got '<scalar>'" at the next line's first word (or at the end of the file, line 2)
    ("x: [1, 2\n", (1, 4), "this `[` is not closed before the end of the file",
     "`]` after its last item"),
    ("p: [[0, 0], [600, 0]\nw: 70\n", (1, 4), "this `[` is not closed before line 2",
     "`]` after its last item (its items apart with `,`)"),
    ("s: {a: 1, b: 2\nw: 70\n", (1, 4), "this `{` is not closed before line 2",
     "`}` after its last item"),
    # on the bracket's own line PyYAML's words stand
    ("s: {a: 1, b: 2 c: 3}\n", (1, 17), "expected ',' or '}', but got ':'", None),
])
def test_the_commonest_yaml_mistakes_are_said_in_words_with_what_was_expected(
        text, where, words, expected):
    """PyYAML's "found character '\\t' that cannot start any token" said neither that a tab
    was the trouble nor what YAML expected; an unclosed quote pointed past the file's end."""
    with pytest.raises(TermSetError) as info:
        yamlpos.load(text, "f.yaml", TermSetError)
    err = info.value
    assert (err.span.line, err.span.column) == where
    assert words in err.message
    assert err.expected == expected if expected is None else expected in err.expected


@pytest.mark.parametrize("text,where,words,expected", [
    ("name: a\n---\nname: b\n", (2, 1), "a second document (`---`) after the first",
     "one document in the file"),
    ("name: a\n...\nname: b\n", (3, 1), "text after the end of the document",
     "nothing after a `...` line"),
    ("name: a\nfoo\nbar: 1\n", (2, 1), "a line that is neither `key: value` nor `- item`",
     "`key: value`"),
    ("a:\n  - 1\n  b: 2\n", (3, 3), "a key among the `- ` items of a list",
     "the key indented as the keys of the item above it (past its `- `)"),
    ("a:\n  b: 1\n  - 2\n", (3, 3), "a `- ` list item among the keys of a mapping",
     "the list under a key of its own"),
    ("a: [1, 2] x\n", (1, 11), "more after the value on this line", "one value after `key:`"),
    ('a: "b" c\n', (1, 8), "more after the value on this line", "one value after `key:`"),
    ("a:\n  - 1\n - 3\n", (3, 2), "this line's indentation matches no key or list above it",
     "the indentation of a key or a `- ` item above it"),
    ("points: - a\n", (1, 9), "a `- ` list item on the line of its key",
     "the items on lines of their own below the key"),
    ("a: ?\n", (1, 4), "`?` cannot start a value", 'the value in quotes: "?"'),
    ("a: *\n", (1, 4), "`*` cannot start a value", "the value in quotes"),
    ("a: & b\n", (1, 4), "`&` cannot start a value", "the value in quotes"),
    ("name: @foo\n", (1, 7), "`@` cannot start a value", 'the value in quotes: "@'),
    ("name: `foo`\n", (1, 7), "`` ` `` cannot start a value", "the value in quotes"),
    ("a: }\n", (1, 4), "`}` cannot start a value", "the value in quotes"),
    ("a: , b\n", (1, 4), "`,` cannot start a value", "the value in quotes"),
    ("a: |+x\n", (1, 6), "after `|` or `>` (a block of text) only", "the text on the lines"),
])
def test_pyyamls_inner_words_are_never_shown(text, where, words, expected):
    """"but found another document", "expected <block end>, but found '?'", "could not find
    expected ':'", "expected the node content, but found '}'": PyYAML's parser talking to
    itself, shown as the error of a world, term set or map file."""
    with pytest.raises(TermSetError) as info:
        yamlpos.load(text, "f.yaml", TermSetError)
    err = info.value
    assert (err.span.line, err.span.column) == where, err.render()
    assert words in err.message and expected in (err.expected or ""), err.render()
    for inner in ("<", "found", "expected", "node", "token", "indicator"):
        assert inner not in err.message, err.message


@pytest.mark.parametrize("text,where,words,expected", [
    # a tab inside a value without quotes was said as one YAML does not take "as indentation
    # or to start a value", and the expected "spaces: YAML indents with spaces only"
    ("name: a\tb\n", (1, 8), "a tab inside a value, after `a` (the YAML reader takes no tab in "
     "a value that is not in quotes)", "a space in place of the tab, or the whole value in quotes"),
    ("a:\n  name: x y\tz  # c\n", (2, 12), "a tab inside a value, after `y`", "in quotes"),
    ("- a\tb\n", (1, 4), "a tab inside a value, after `a`", "a space in place of the tab"),
    ("k: [a\tb]\n", (1, 6), "a tab inside a value, after `a`", "a space in place of the tab"),
    ("name: a-\tb\n", (1, 9), "a tab inside a value, after `a-`", "in quotes"),
    # where the value starts (YAML takes a tab there, PyYAML does not), and before a key's `:`
    ("name:\tx\n", (1, 6), "a tab after `:`, where the value starts", "a space in place of"),
    ("-\tb\n", (1, 2), "a tab after `-`, where the value starts", "a space in place of"),
    ("k: [a,\tb]\n", (1, 7), "a tab after `,`, where the value starts", "a space in place of"),
    ("key\t: 1\n", (1, 4), "a tab between the key `key` and its `:`", "`key: value`"),
])
def test_a_tab_is_said_by_where_it_stands(text, where, words, expected):
    with pytest.raises(TermSetError) as info:
        yamlpos.load(text, "f.yaml", TermSetError)
    err = info.value
    assert (err.span.line, err.span.column) == where
    assert words in err.message and "indent" not in err.message + err.expected
    assert expected in err.expected


def test_a_tab_inside_a_world_files_value_through_the_cli(tmp_path, capsys):
    from mitos_cli.cli.app import main

    world = (Path(__file__).parent / "data" / "tiny.yaml").read_text()
    (tmp_path / "w.yaml").write_text(world.replace("name: tiny", "name: ti\tny"))
    with pytest.raises(SystemExit) as info:
        main(["simulate", str(tmp_path / "w.yaml")])
    assert info.value.code == 1
    assert capsys.readouterr().err.replace(str(tmp_path), "DIR") == (
        "DIR/w.yaml:2:9: world error: invalid YAML: a tab inside a value, after `ti` (the YAML "
        "reader takes no tab in a value that is not in quotes)\n"
        "    name: ti    ny\n"
        "            ^\n"
        "expected a space in place of the tab, or the whole value in quotes (`\"...\"`, which "
        "keeps the tab)\n")


def test_no_mistake_in_a_world_file_shows_pyyamls_own_words():
    """1,000 world files, each of one to three characters added, dropped or changed (`:`,
    `-`, brackets, `&`, `*`, `!`, `%`, `|`, quotes, tabs...): no message names one of
    PyYAML's tokens (`<block end>`, `'<tag>'`), its "node content" or a URI, and each has
    its line and column."""
    import random

    world = (Path(__file__).parents[1] / "worlds" / "multirobot.yaml").read_text()
    rng = random.Random(19)
    marks = list(":-[]{},#&*!|>'\"%@`? \t\n")
    said = 0
    for _ in range(1000):
        text = list(world)
        for _ in range(rng.randint(1, 3)):
            k, op = rng.randrange(len(text)), rng.random()
            if op < 0.4:
                text.insert(k, rng.choice(marks))
            elif op < 0.7:
                del text[k]
            else:
                text[k] = rng.choice(marks)
        try:
            yamlpos.load("".join(text), "w.yaml", TermSetError)
        except TermSetError as err:
            said += 1
            assert err.span is not None and err.span.line >= 1, err.message
            for inner in ("<", "node content", "URI", "cannot start any token", "alphabetic"):
                assert inner not in err.message, err.message
    assert said > 300


@pytest.mark.parametrize("written, hint", [
    ("70in", "write the number alone, without `in`: the numbers are in inches"),
    ("-4.5 in/s", "write the number alone, without `in/s`: the numbers are in inches"),
    ("1e3mm", "write the number alone, without `mm`: the numbers are in inches"),
    ("far", None), ("12 34", None), ("in", None)])
def test_a_number_written_with_a_unit_gets_a_hint(written, hint):
    data = yamlpos.load(f"a: {written}\n", "f.yaml", TermSetError)
    with pytest.raises(TermSetError) as info:
        yamlpos.expect_number(data["a"], data.value_span("a"), TermSetError, "`a`",
                              units="the numbers are in inches")
    assert info.value.message == f"`a` must be a number, not `{written}`"
    assert info.value.hint == hint


FIGURE4 = (Path(__file__).parent.parent / "worlds" / "figure4.yaml").read_text()


@pytest.mark.parametrize("old, new, line, message, hint", [
    # a block key glued to its value is one plain word: the error fell at its line, or at the
    # next key (`name:figure4` then `seed: 3`), in words that did not say why
    ("seed: 3", "seed:3", 6, "invalid YAML: a line that is neither `key: value` nor `- item`",
     "`seed:3` (line 6) is one word to YAML: a key's `:` needs a space after it, `seed: 3`"),
    ("name: figure4", "name:figure4", 6, "invalid YAML: a `:` where no new key can start",
     "`name:figure4` (line 5) is one word to YAML: a key's `:` needs a space after it, "
     "`name: figure4`"),
    ("    - points:", "    -points:", 30, "invalid YAML: this line's indentation matches no",
     "`-points:` (line 29) is one word to YAML: a list item's `-` needs a space after it, "
     "`- points:`"),
    # in a flow mapping `{length:24}` is the key `length:24` (with no value)
    ("{length: 24, width: 18}", "{length:24, width: 18}", 15,
     "unknown key `length:24` in robot footprint", "YAML reads `length:24` as one key: a "
     "key's `:` needs a space after it, `length: 24`"),
    ("{x: 30, y: -12, heading: 0}", "{x: 30, y:-12, heading: 0}", 24,
     "unknown key `y:-12` in q_init", "YAML reads `y:-12` as one key: a key's `:` needs a "
     "space after it, `y: -12`"),
    ("route: {replan: never}", "route:\n  replan:never", 33,
     "route must be a mapping (`key: value` lines)", "YAML reads `replan:never` as one key: "
     "a key's `:` needs a space after it, `replan: never`"),
    ("{name: A, shape: circle,", "{name: A, shape:circle,", 35,
     "unknown key `shape:circle` in obstacle 1", "YAML reads `shape:circle` as one key: a "
     "key's `:` needs a space after it, `shape: circle`"),
])
def test_a_key_glued_to_its_value_is_named_in_the_hint(old, new, line, message, hint):
    from mitos_cli.errors import WorldError
    from mitos_cli.sim.worldfile import parse_world

    assert old in FIGURE4, old
    with pytest.raises(WorldError) as info:
        parse_world(FIGURE4.replace(old, new, 1), "w.yaml")
    err = info.value
    assert err.span.line == line and err.message.startswith(message), err.render()
    assert err.hint == hint



@pytest.mark.parametrize("old, glued, line", [("seed: 3", "seed:3", 6),
                                              ("    - points:", "    -points:", 29)])
def test_the_glued_key_hint_is_linear_in_a_line_of_blanks(old, glued, line):
    """The hint's pattern let a lazy value end at every blank before `[ \\t]*(?:#.*)?$`:
    `seed:3`, 32,000 blanks and a word took 9.6 s to refuse, 200,000 about six minutes."""
    import time

    from mitos_cli.errors import WorldError
    from mitos_cli.sim.worldfile import parse_world

    t0 = time.process_time()
    with pytest.raises(WorldError) as info:
        parse_world(FIGURE4.replace(old, glued + " " * 40_000 + "x", 1), "w.yaml")
    assert time.process_time() - t0 < 2
    assert info.value.hint is not None and info.value.hint.startswith(
        f"`{glued.strip()}` (line {line}) is one word to YAML"), info.value.hint

def test_a_required_key_glued_to_its_value_is_named_in_the_hint():
    """`{shape:triangle, ...}` said "missing `shape`" and "add `shape: ...`", which is there."""
    from mitos_cli.lang.termfile import parse_termset

    text = ("variables:\n  x:\n    role: input\n    universe: [0, 1]\n    terms:\n"
            "      A: {shape:triangle, points: [0, 0.5, 1]}\n")
    with pytest.raises(TermSetError) as info:
        parse_termset(text, "t.yaml")
    assert (info.value.message, info.value.hint) == (
        "missing `shape` in term `x.A`", "YAML reads `shape:triangle` as one key: a key's `:` "
        "needs a space after it, `shape: triangle`")
