"""The navigation benchmark's bookkeeping: tasks interleaved, rows scored in task order, notes
counted from the rows (no simulation here; the runs are the benchmark's)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))
bench_nav = pytest.importorskip("bench_nav")


def mrpb_root(tmp_path: Path) -> str:
    for name in ("maze", "office02"):
        (tmp_path / name).mkdir()
        (tmp_path / name / "tests.txt").write_text(
            "test 1: start (0, 0, 0) -> goal (1, 0, 0)\ntest 2: start (0, 0, 0) -> goal (2, 0, 0)\n")
    return str(tmp_path)


def test_tasks_interleave_the_suites(tmp_path, monkeypatch):
    monkeypatch.setattr(bench_nav.mrpb, "COMPLETE", ("maze",))
    monkeypatch.setattr(bench_nav.mrpb, "PARTIALLY_UNKNOWN", {})
    jobs = bench_nav.jobs_for(("mrpb", "barn-unknown", "clutter"), ("fuzzy",),
                              mrpb_root(tmp_path), 3, 0, 1)
    kinds = [j[0] for j in jobs]
    assert kinds[:3] == ["mrpb", "clutter", "barn"]
    assert kinds.count("mrpb") == 2 and kinds.count("barn") == 3
    assert kinds.count("clutter") == len(bench_nav.SHIPPED) + 2


def run(outcome, t=10.0):
    return {"outcome": outcome, "time_s": t, "mrpb_safety": 0.1}


def test_refused_and_failed_tasks_are_counted_in_generated_notes(tmp_path, capsys):
    rows = [
        {"suite": "mrpb", "world": "a", "refused": None, "length": 787.4,
         "runs": {"fuzzy": run("success"), "dwa": run("stuck")}},
        {"suite": "mrpb", "world": "b", "refused": "the only way passes (1, 2)",
         "length": None, "runs": {}},
        {"suite": "barn", "world": "barn field 3", "error": "ValueError: no field",
         "refused": None, "length": None, "runs": {}},
    ]
    results, notes = bench_nav.suite_results(rows, ("mrpb",), ("fuzzy", "dwa"))
    fuzzy = results["mrpb"]["fuzzy"]
    assert fuzzy["runs"] == 2 and fuzzy["success_rate"] == 0.5 and fuzzy["no route_rate"] == 0.5
    assert results["mrpb"]["dwa"]["stuck_rate"] == 0.5
    assert any("barn field 3 failed" in n for n in notes)
    assert any(n.startswith("mrpb: 1 of 2 without a route: b (") for n in notes)
    kept = tmp_path / "rows.jsonl"
    kept.write_text("".join(json.dumps(r) + "\n" for r in rows))
    assert bench_nav.main(["--from-rows", str(kept), "--suites", "mrpb",
                           "--planners", "fuzzy,dwa"]) == 0
    out = capsys.readouterr().out
    assert "| MRPB: every test reached by the fuzzy planner | 1 of 2 | no |" in out


def kept_rows(tmp_path: Path, text: str) -> Path:
    """``rows.jsonl`` in the current directory (a short name: messages shorten long ones)."""
    (tmp_path / "rows.jsonl").write_text(text)
    return Path("rows.jsonl")


def test_from_rows_names_a_damaged_line_by_its_number_and_drops_a_torn_last_one(tmp_path,
                                                                             monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    good = json.dumps({"suite": "mrpb", "world": "a", "refused": None, "length": 787.4,
                       "runs": {"fuzzy": run("success")}}) + "\n"
    kept = kept_rows(tmp_path, good * 3 + '{"bad": \n' + good)
    assert bench_nav.main(["--from-rows", str(kept), "--suites", "mrpb",
                           "--planners", "fuzzy"]) == 1
    assert f"cannot read rows from `{kept}`: line 4: Expecting value" in capsys.readouterr().err
    kept = kept_rows(tmp_path, good * 3 + good[:40])            # a run killed while appending
    assert bench_nav.main(["--from-rows", str(kept), "--suites", "mrpb",
                           "--planners", "fuzzy"]) == 0
    out, err = capsys.readouterr()
    assert "rows.jsonl:4: a torn last line (a stopped run) is left out" in err
    assert "from 3 rows of `rows.jsonl`" in out


def test_from_rows_reads_past_a_byte_order_mark_and_shows_a_damaged_line(tmp_path, monkeypatch,
                                                                         capsys):
    """A rows file saved by a Windows editor starts with a byte-order mark: it was refused as
    "line 1: Unexpected UTF-8 BOM". A damaged line is shown at its place, with what a line
    should be."""
    monkeypatch.chdir(tmp_path)
    good = json.dumps({"suite": "mrpb", "world": "a", "refused": None, "length": 787.4,
                       "runs": {"fuzzy": run("success")}}) + "\n"
    kept = tmp_path / "rows.jsonl"
    kept.write_bytes(b"\xef\xbb\xbf" + (good * 2).encode())
    assert bench_nav.main(["--from-rows", "rows.jsonl", "--suites", "mrpb",
                           "--planners", "fuzzy"]) == 0
    assert "from 2 rows of `rows.jsonl`" in capsys.readouterr().out
    kept.write_text(good + '{"suite": 1,, }\n' + good)
    assert bench_nav.main(["--from-rows", "rows.jsonl"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("rows.jsonl:2:13: error: cannot read rows from `rows.jsonl`: line 2: ")
    assert '    {"suite": 1,, }\n' in err and "expected a JSON object with `suite`" in err


def test_a_reader_that_goes_away_is_not_an_error(tmp_path):
    """`bench_nav.py --from-rows rows.jsonl | head -1`: the table's later lines met a closed
    pipe and the script said "error: Broken pipe"; it says nothing, as `mitos` does."""
    import subprocess

    kept = tmp_path / "rows.jsonl"
    kept.write_text(json.dumps({"suite": "mrpb", "world": "a", "refused": None,
                                "length": 787.4, "runs": {"fuzzy": run("success")}}) + "\n")
    p = subprocess.Popen([sys.executable, str(ROOT / "benchmarks" / "bench_nav.py"),
                          "--from-rows", str(kept)], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE)
    assert p.stdout is not None and p.stderr is not None
    p.stdout.close()                                   # the reader is gone before a line
    err = p.stderr.read().decode()
    assert p.wait() == 1 and err == ""


@pytest.mark.parametrize("text", ["[1, 2]\n", '{"runs": 5}\n', '{"suite": "mrpb"}\n'])
def test_from_rows_refuses_json_that_is_not_a_row(text, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    kept = kept_rows(tmp_path, text)
    assert bench_nav.main(["--from-rows", str(kept)]) == 1
    err = capsys.readouterr().err
    assert f"cannot read rows from `{kept}`: line 1 is not a row" in err and "Traceback" not in err


def test_the_ticks_line_refuses_more_obstacles_than_its_field_holds():
    assert len(bench_nav.ticks_world(348, 0).obstacles) == 348
    with pytest.raises(bench_nav.MitosError, match="holds 348 poles, not 349"):
        bench_nav.ticks_world(349, 0)


def test_the_ticks_line_alone_prints_no_empty_table_nor_suites_it_did_not_run(monkeypatch,
                                                                              capsys):
    """``--suites ticks`` printed the table's header with no row and ended with "BARN: 100
    worlds from seed 0; clutter: 10 draws per world" of a run of neither."""
    monkeypatch.setattr(bench_nav, "TICKS", 10)
    assert bench_nav.main(["--suites", "ticks", "--planners", "fuzzy", "--jobs", "1",
                           "--ticks-obstacles", "20"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("ticks: 20 unknown obstacles (barn-poles-20), one core: fuzzy ")
    assert "| 20 unknown obstacles: the fuzzy planner >= 100 ticks/s on one core |" in out
    last = out.splitlines()[-1]
    assert last.startswith("ticks: the field of seed 0; 0 tasks in ")
    assert "BARN" not in out and "clutter" not in out and "planner  runs" not in out


def test_the_run_line_names_the_suites_run():
    line = bench_nav.run_line(("barn-unknown", "clutter"), 10, 1000, 2, 28, 61.0, 2)
    assert line.startswith("BARN: 10 worlds from seed 1000; clutter: 2 draws per world; "
                           "MRPB safety distance 3.94 in (0.1 m); 28 tasks in 61 s on 2 of ")
    assert bench_nav.run_line(("mrpb",), 10, 0, 2, 34, 5.0, 1).startswith(
        "MRPB safety distance 3.94 in (0.1 m); 34 tasks in 5 s on 1 of ")


def test_the_barn_aim_is_not_met_by_a_run_without_dwa():
    """"At least DWA's success" read "yes" in a run of the fuzzy planner alone."""
    fuzzy = {"success_rate": 0.95, "collision_rate": 0.0, "runs": 20}
    alone = bench_nav.aims({"barn-unknown": {"fuzzy": fuzzy}}, None)[2]
    assert alone.endswith("DWA - (20 fields) | its fuzzy part yes; DWA not run |")
    both = {"barn-unknown": {"fuzzy": fuzzy, "dwa": {**fuzzy, "success_rate": 0.97}}}
    assert bench_nav.aims(both, None)[2].endswith("DWA 97% (20 fields) | no |")
    both["barn-unknown"]["dwa"]["success_rate"] = 0.9
    assert bench_nav.aims(both, None)[2].endswith("DWA 90% (20 fields) | yes |")
    fuzzy["collision_rate"] = 0.1
    assert bench_nav.aims({"barn-unknown": {"fuzzy": fuzzy}}, None)[2].endswith("| no |")
