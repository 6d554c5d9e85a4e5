"""``mitos list``: every packaged world, rule base and lesson, by a name the commands accept.

The listing itself is golden (``tests/golden/list``, ``tests/golden/list_json``)."""

from __future__ import annotations

import json

import pytest

from mitos_cli.cli.app import main
from mitos_cli.cli.list_cmd import catalogue, first_comment_line
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


def test_an_argument_is_a_usage_error(capsys):
    code, out, err = run_main(["list", "worlds"], capsys)
    assert code == 2 and out == ""
    assert "unexpected extra argument" in err.lower()
