"""``mitos list``: every packaged world, rule base and lesson, by a name the commands accept.

The listing itself is golden (``tests/golden/list``, ``tests/golden/list_json``)."""

from __future__ import annotations

import json

import pytest

from mitos_cli.cli.app import main
from mitos_cli.cli.list_cmd import catalogue, first_comment_line, first_sentence, render, shorten
from mitos_cli.resources import packaged_names, resolve
from mitos_cli.sim.worldfile import load_world, resolve_world_path


def run_main(args, capsys):
    with pytest.raises(SystemExit) as info:
        main(args)
    out, err = capsys.readouterr()
    return info.value.code, out, err


def test_json_is_the_catalogue(capsys):
    code, out, err = run_main(["list", "--json"], capsys)
    assert code in (0, None) and err == ""
    assert json.loads(out) == catalogue()


def test_every_packaged_file_is_listed_by_a_name_the_commands_accept():
    cat = catalogue()
    assert [e["name"] + ".yaml" for e in cat["worlds"]] == list(packaged_names("worlds", ".yaml"))
    assert [e["name"] for e in cat["rulebases"]] == list(packaged_names("rulebases", ".rules"))
    assert [e["name"] + ".lesson" for e in cat["lessons"]] == \
        list(packaged_names("rulebases/lessons", ".lesson"))
    for e in cat["worlds"]:
        assert load_world(resolve_world_path(e["name"])).name == e["world_name"]
        assert e["description"]
    for e in cat["rulebases"]:
        assert resolve("rulebases", e["name"], ".rules") is not None
        assert "drive" in e["behaviors"]
    for e in cat["lessons"]:
        assert resolve("rulebases/lessons", e["name"], ".lesson") is not None
        assert e["description"]
    # the term sets, by the name `plot terms` and `check` take from anywhere
    from mitos_cli.api import read_termset

    assert [e["name"] for e in cat["termsets"]] == ["drive.terms.yaml", "mitos.terms.yaml"]
    for e in cat["termsets"]:
        assert [v.name for v in read_termset(e["name"]).variables] == e["variables"]


@pytest.mark.parametrize("text, expected", [
    ("# One line.\nname: x\n", "One line."),
    ("\n#\n#   Indented words\nname: x\n", "Indented words"),
    ("# goes on\n# in the next line\n", "goes on ..."),
    # a sentence that ends in the line, then one cut short: the whole sentence alone
    ("# A robot. It is given the corridors (its\n# map)\n", "A robot."),
    ("# Maps at 0.05 m. It is\n# given\n", "Maps at 0.05 m."),
    ("# a list follows:\n# - one\n", "a list follows:"),
    ("# last comment line\nname: x\n", "last comment line"),
    ("name: x\n# a later comment\n", ""),
    ("", ""),
])
def test_first_comment_line(text, expected):
    assert first_comment_line(text) == expected


def test_a_second_argument_is_a_usage_error(capsys):
    code, out, err = run_main(["list", "worlds", "lessons"], capsys)
    assert code == 2 and out == ""
    assert "unexpected extra argument" in err.lower()


@pytest.mark.parametrize("text, expected", [
    ("# One line.\nname: x\n", "One line."),
    # a sentence over three lines: whole, up to its end
    ("# goes on\n# in the next line\n# and ends here. Another one\n# follows\n",
     "goes on in the next line and ends here."),
    ("# goes on\n# in the next line\n", "goes on in the next line"),
    # a blank comment line ends the paragraph
    ("# goes on\n#\n# A new paragraph.\n", "goes on"),
    ("# A robot. It is given the corridors (its\n# map)\n", "A robot."),
    ("# a list follows:\n# - one\n", "a list follows:"),
    ("# Maps (CC0-1.0; see\n# maps/LICENSE.md), at 5 cm. The robot\n",
     "Maps (CC0-1.0; see maps/LICENSE.md), at 5 cm."),
    ("name: x\n# a later comment\n", ""),
    ("", ""),
])
def test_first_sentence(text, expected):
    assert first_sentence(text) == expected


def test_json_carries_whole_descriptions_and_the_text_cuts_them(capsys):
    """`mitos list --json` cut figure4's description at its comment's first line, with "...":
    JSON is for programs, which get the whole sentence; the text listing cuts at a word."""
    cat = catalogue()
    figure4 = next(e for e in cat["worlds"] if e["name"] == "figure4")
    assert figure4["description"].endswith("a little right of the new corridor's centre line.")
    for entries in cat.values():
        for e in entries:
            assert not e["description"].endswith("..."), e
    assert shorten("a b c", 100) == "a b c"
    assert shorten("word " * 30, 20) == "word word word ..."
    assert len(shorten(figure4["description"])) <= 100
    code, out, _ = run_main(["list"], capsys)
    assert code in (0, None)
    line = next(ln for ln in out.splitlines() if ln.strip().startswith("figure4"))
    assert line.endswith(" ...") and "centre line" not in line
    assert "take_opening, mind_the_body, drive" in out      # a rule base's behaviors: whole


@pytest.mark.parametrize("kind, key", [("worlds", "worlds"), ("world", "worlds"),
                                       ("Rule-Bases", "rulebases"), ("rule base", "rulebases"),
                                       ("termsets", "termsets"), ("lesson", "lessons")])
def test_one_kind_alone(kind, key, capsys):
    code, out, err = run_main(["list", kind, "--json"], capsys)
    assert code in (0, None) and err == ""
    assert json.loads(out) == {key: catalogue()[key]}
    code, out, _ = run_main(["list", kind], capsys)
    assert out.splitlines()[0] == render({key: []}).splitlines()[0]
    assert len(out.splitlines()) == 1 + len(catalogue()[key])


def test_an_unknown_kind_is_a_usage_error_with_the_kinds(capsys):
    code, out, err = run_main(["list", "wrlds"], capsys)
    assert code == 2 and out == ""
    assert "unknown kind `wrlds`" in err and "did you mean `worlds`?" in err
    assert "lessons, rulebases, termsets, worlds" in err
