"""``mitos teach --lesson FILE --json``: one object, each command with what it printed
(schema in docs/teach.md); golden: tests/data/teach_lesson.json."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from mitos_cli.cli.app import main

GOLDEN = Path(__file__).parent / "data" / "teach_lesson.json"
LESSON = """\
eval road=78 size=45 position=4
# a comment is not a command
show behaviors
"""


def run(args, capsys):
    with pytest.raises(SystemExit) as info:
        main(args)
    out, err = capsys.readouterr()
    return info.value.code, out, err


def test_lesson_json_is_the_documented_object(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    Path("small.lesson").write_text(LESSON)
    code, out, err = run(["teach", "--lesson", "small.lesson", "-o", "taught.rules", "--json"],
                         capsys)
    assert code in (0, None), err
    data = json.loads(out)
    session = data.pop("session")
    journal = Path(f".mitos/teach/{session}/journal.jsonl")
    assert Path(data.pop("journal")).resolve() == journal.resolve() and journal.is_file()
    if os.environ.get("MITOS_UPDATE_GOLDEN"):
        GOLDEN.write_text(json.dumps(data, indent=2) + "\n")
    assert data == json.loads(GOLDEN.read_text())
    assert [c["line"] for c in data["commands"]] == [1, 3]


def test_json_needs_a_lesson(capsys):
    code, _, err = run(["teach", "--json"], capsys)
    assert code == 2 and "--json reports a lesson" in err
