"""The study machinery without the simulator: statistics, seeds, store, executors, resume."""

from __future__ import annotations

import functools
import math
import os
import re
import signal
import zlib
from pathlib import Path

import numpy as np
import pytest

from mitos_cli.errors import MitosError
from mitos_cli.study import Study, make_choices, run_study
from mitos_cli.study.executors import chunks, execute, lockstep_chunks
from mitos_cli.study.spec import Choice, expand, split_list, task_seeds
from mitos_cli.study.stats import mean_interval, t_cdf, t_quantile, wilson
from mitos_cli.study.store import ResultStore, StudyError
from mitos_cli.study.summary import mcnemar, rank, summaries


def fake_sim(task, log=None) -> dict:
    """A deterministic stand-in for the simulator: a function of the seed and the choice."""
    if log is not None:
        log.append(task.index)
    salt = zlib.crc32(task.choice.label.encode())
    rng = np.random.default_rng([task.seed, salt])
    u = rng.random()
    outcome = "success" if u < 0.7 else "collision" if u < 0.85 else "timeout"
    return {"outcome": outcome, "collisions": int(outcome == "collision"),
            "time_s": float(10 + rng.random() * 5), "path_length_in": float(300 + rng.random()),
            "min_clearance_in": float(rng.normal(8, 2)) / 3.0,
            "mean_speed_in_s": float(30 + rng.random()),
            "steering_total_variation_deg": float(rng.random() * 100), "ticks": 200,
            "replans": int(u * 4), "backouts": int(outcome == "timeout")}


class Crash(Exception):
    pass


def crashing_sim(task, after: int, log: list):
    if len(log) >= after:
        raise Crash("killed")
    return fake_sim(task, log)


# -- statistics ----------------------------------------------------------------------------

@pytest.mark.parametrize("df, expected", [(1, 12.706204736), (2, 4.302652730), (5, 2.570581836),
                                          (10, 2.228138852), (30, 2.042272456),
                                          (1000, 1.962339081)])
def test_t_quantile_matches_tables(df, expected):
    assert t_quantile(0.975, df) == pytest.approx(expected, abs=1e-8)
    assert t_cdf(t_quantile(0.975, df), df) == pytest.approx(0.975, abs=1e-12)


def test_wilson_interval():
    r = wilson(5, 10)
    assert (r.lo, r.hi) == (pytest.approx(0.236593, abs=1e-6), pytest.approx(0.763407, abs=1e-6))
    assert wilson(0, 20).lo == 0.0 and 0.0 < wilson(0, 20).hi < 0.2
    assert wilson(20, 20).hi == 1.0 and wilson(20, 20).lo > 0.8
    assert math.isnan(wilson(0, 0).lo)


def test_mean_interval_small_samples():
    m = mean_interval([1.0, 2.0, 3.0])
    assert m.mean == 2.0 and m.std == 1.0
    assert m.hi - m.mean == pytest.approx(4.302652730 / math.sqrt(3))
    assert mean_interval([]).mean is None
    one = mean_interval([5.0])
    assert one.mean == 5.0 and one.std is None and one.lo is None


def test_mean_interval_cut_at_its_floor_only_below_it():
    """Three runs' replans (0, 4, 4) read [-2.50, 7.84] with a t interval: a count cut at 0."""
    free = mean_interval([0.0, 4.0, 4.0])
    assert free.lo is not None and free.lo < 0
    cut = mean_interval([0.0, 4.0, 4.0], floor=0.0)
    assert (cut.mean, cut.std, cut.lo, cut.hi) == (free.mean, free.std, 0.0, free.hi)
    assert mean_interval([10.0, 11.0, 12.0], floor=0.0) == mean_interval([10.0, 11.0, 12.0])


def test_study_metrics_that_cannot_be_negative_have_intervals_from_0():
    from mitos_cli.study.summary import METRICS, NOT_NEGATIVE, Choice, summarize

    rows = [{"outcome": "success", "time_s": t, "path_length_in": 10.0, "min_clearance_in": c,
             "steering_total_variation_deg": 1.0, "mean_speed_in_s": 5.0, "replans": k,
             "backouts": 0} for t, c, k in ((1.0, -0.5, 0), (9.0, 0.5, 4), (9.0, 0.2, 4))]
    s = summarize("w", Choice("fuzzy", "min", "max", "weighted_average"), rows)
    assert s.metrics["replans"].lo == 0.0 and s.metrics["time_s"].lo == 0.0
    assert s.metrics["min_clearance_in"].lo is not None and s.metrics["min_clearance_in"].lo < 0
    assert {f for f, *_ in METRICS} > NOT_NEGATIVE


def test_mcnemar_exact():
    assert mcnemar(0, 0) == 1.0
    assert mcnemar(0, 6) == pytest.approx(2 / 64)
    assert mcnemar(3, 3) == 1.0


@pytest.mark.parametrize("wins, losses", [(0, 2000), (500, 600), (1000, 1024), (7, 1500)])
def test_mcnemar_past_a_thousand_pairs(wins, losses):
    """Over 1023 discordant pairs ``2.0 ** n`` is no float: a study of that many runs stopped
    at its end with an OverflowError, its report unwritten."""
    n = wins + losses
    exact = 2 * sum(math.comb(n, i) for i in range(min(wins, losses) + 1)) / 2 ** n
    assert mcnemar(wins, losses) == pytest.approx(min(1.0, exact), rel=1e-9, abs=1e-300)


def test_rank_of_a_study_with_thousands_of_discordant_runs():
    rows = [{"world": "w", "planner": p, "and": "", "or": "", "inference": "", "run": r,
             "outcome": "success" if p == "dwa" else "collision",
             **dict.fromkeys(("time_s", "path_length_in", "min_clearance_in", "mean_speed_in_s",
                              "steering_total_variation_deg", "replans", "backouts"), 1.0)}
            for r in range(1100) for p in ("dwa", "potential_field")]
    ranks = rank(rows, summaries(rows, ["w"], [Choice("dwa"), Choice("potential_field")]))
    assert [(r.wins, r.losses) for r in ranks] == [(0, 0), (0, 1100)]
    assert ranks[1].p_value == 0.0


@pytest.mark.parametrize("k, n, shown", [(1, 200, "0.5%"), (199, 200, "99.5%"),
                                         (1, 3000, "0.03%"), (2999, 3000, "99.97%"),
                                         (0, 200, "0%"), (200, 200, "100%"), (3, 8, "38%"),
                                         (1, 7, "14%")])
def test_a_rate_that_is_neither_none_nor_all_never_reads_as_either(k, n, shown):
    """199 successes in 200 runs read `100%`, 1 collision in 200 `0%`: in a published table,
    a planner that never failed, never collided."""
    from mitos_cli.study.report import _compact_rate, fmt_rate

    rate = wilson(k, n)
    assert fmt_rate(rate, ci=False) == shown
    assert fmt_rate(rate).startswith(shown + " [") and _compact_rate(rate).startswith(shown)


# -- choices and seeds ---------------------------------------------------------------------

def test_choices_cross_and_dual():
    cs = make_choices(["fuzzy", "potential_field"], ["min", "prod"], ["dual"], [])
    assert [c.label for c in cs] == ["fuzzy and=min or=max", "fuzzy and=product or=probabilistic_sum",
                                     "potential_field"]
    assert len(make_choices(["fuzzy"], ["min", "product"], ["max", "bounded_sum"],
                            ["weighted_average", "mamdani"])) == 8
    assert split_list(" min, product,,min ") == ["min", "product"]


def test_choices_default_to_the_rule_bases_settings_by_keyword():
    """make_choices needed all four lists (``make_choices(["fuzzy"], ands=[...])`` was a
    TypeError, "missing 2 required positional arguments"); the last three default to none,
    the rule base's own setting, as an empty list does."""
    assert make_choices(["fuzzy"], ands=["min", "product"]) == \
        make_choices(["fuzzy"], ["min", "product"], [], [])
    assert make_choices(["fuzzy", "dwa"]) == make_choices(["fuzzy", "dwa"], [], [], [])
    assert [c.label for c in make_choices(["fuzzy"], inferences=("mamdani",))] == \
        ["fuzzy inference=mamdani"]


@pytest.mark.parametrize("args, message, hint", [
    ((["fuzzy"], ["einstien"], [], []), "unknown T-norm `einstien`", "einstein"),
    ((["fuzzy"], ["min"], ["mx"], []), "unknown S-norm `mx`", "max"),
    ((["fuzy"], [], [], []), "unknown planner `fuzy`", "fuzzy"),
    ((["fuzzy"], [], [], ["mamdany"]), "unknown inference method `mamdany`", "mamdani"),
])
def test_choice_errors_say_did_you_mean(args, message, hint):
    with pytest.raises(MitosError) as exc:
        make_choices(*args)
    assert message in exc.value.message and hint in (exc.value.hint or "")


@pytest.mark.parametrize("args, message, hint", [
    # read a letter at a time: "unknown planner `f`", "unknown T-norm `m`"
    (("fuzzy", [], [], []), "planners are a list of names, not the string `fuzzy`", "['fuzzy']"),
    ((["fuzzy"], "min, product", [], []), "T-norms are a list of names, not the string "
     "`min, product`", "['min', 'product']"),
    ((["fuzzy"], [], None, []), "S-norms are a list of names, not NoneType `None`",
     "make_choices("),
    ((["fuzzy"], [], [], [1]), "inference methods are a list of names, not of int `1`",
     "make_choices("),
])
def test_choices_are_lists_of_names(args, message, hint):
    from mitos_cli.errors import InputError

    with pytest.raises(InputError) as exc:
        make_choices(*args)
    assert exc.value.message == message and hint in exc.value.hint
    assert make_choices(("fuzzy",), ("min",), (), ()) == [Choice("fuzzy", "min")]


def test_seeds_are_paired_and_extend():
    choices = make_choices(["fuzzy", "potential_field"], ["min", "product"], [], [])
    tasks = expand(["a.yaml", "b.yaml"], choices, 4, seed=7)
    assert len(tasks) == 2 * 3 * 4 and [t.index for t in tasks] == list(range(24))
    by = {}
    for t in tasks:
        by.setdefault((t.world, t.run), set()).add(t.seed)
    assert all(len(s) == 1 for s in by.values())               # every choice: same seed
    assert len({next(iter(s)) for s in by.values()}) == 8      # distinct per (world, run)
    # more runs later keep the first runs' seeds (SeedSequence children are keyed by index)
    assert [row[:4] for row in task_seeds(7, 2, 10)] == task_seeds(7, 2, 4)
    assert task_seeds(8, 2, 4) != task_seeds(7, 2, 4)


def test_chunks_cover_every_task_once():
    tasks = expand(["w"], [Choice("potential_field")], 100, 0)
    parts = chunks(tasks, 2)
    assert [t for p in parts for t in p] == tasks and max(map(len, parts)) <= 8


def test_lockstep_chunks_keep_one_world_and_choice_each_and_cover_every_task_once():
    tasks = expand(["a", "b"], make_choices(["fuzzy", "potential_field"], ["min"], [], []),
                   100, 0)
    for workers, most, size in ((1, 64, 50), (2, 64, 50), (3, 16, 12), (2, 200, 50)):
        parts = lockstep_chunks(tasks, workers, most)
        assert sorted(t.index for p in parts for t in p) == list(range(len(tasks)))
        assert all(len({(t.world, t.choice) for t in p}) == 1 for p in parts)
        assert max(map(len, parts)) == size and len(parts) % workers == 0
        assert [p[0].index for p in parts] == sorted(p[0].index for p in parts)
    assert len(lockstep_chunks(tasks[:3], 2)) == 3                 # one world and choice each


def test_the_simulator_steps_a_chunk_together_with_each_task_s_bits_alone(tmp_path):
    from mitos_cli.study.simtask import StudyContext, run_task, run_tasks

    world = tmp_path / "tiny.yaml"
    world.write_text((Path(__file__).parent / "data" / "tiny.yaml").read_text())
    tasks = expand([str(world)], make_choices(["fuzzy", "potential_field"], ["min", "product"],
                                               [], []), 3, 5)
    context = StudyContext()
    together = dict(run_tasks(context, tasks))
    assert sorted(t.index for t in together) == [t.index for t in tasks]
    for task in tasks:
        assert together[task] == run_task(context, task)


def test_a_studys_default_workers_are_counted_with_its_worlds_maps(monkeypatch):
    """A study's default workers were counted without the worlds' maps (they are read in the
    workers): 16 workers each stepping a batch of `office` runs (0.7 GB) on a machine with
    2 GB free. The simulator gives the executors its tasks' worlds to count them with."""
    from mitos_cli import machine
    from mitos_cli.resources import packaged_path
    from mitos_cli.sim.lockstep import batch_for, map_bytes
    from mitos_cli.sim.runs import RUN_BYTES, WORKER_BYTES
    from mitos_cli.study import executors
    from mitos_cli.study.run import default_task_fn

    if not hasattr(os, "sched_getaffinity"):
        pytest.skip("no CPU affinity on this platform")
    office, slalom = (str(packaged_path("worlds", f"{n}.yaml")) for n in ("office", "slalom"))
    study = Study([slalom, office], make_choices(["fuzzy"], ["min"], [], []), runs=4, seed=1)
    fn = default_task_fn(study)
    assert [w.name for w in fn.worlds(study.tasks())] == ["slalom", "office"]
    per = WORKER_BYTES + batch_for(fn.worlds(study.tasks())[1]) * (
        map_bytes(fn.worlds(study.tasks())[1]) + RUN_BYTES)
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: set(range(16)))
    monkeypatch.setattr(machine, "available_memory", lambda: 2 * per + per // 2)
    used = []
    monkeypatch.setattr(executors, "run_local", lambda fn, tasks, workers: used.append(workers)
                        or iter(()))
    list(execute(fn, study.tasks()))
    assert used == [2]
    list(execute(fake_sim, study.tasks()))         # a task function without worlds: CPUs
    assert used[-1] == 16


def test_a_study_tells_where_its_runs_are_between_their_ends(tmp_path):
    """Runs in lockstep end together, late in their chunk: a study of one world and choice
    showed 0 of N till then. The simulator says where its chunk's runs are every simulated
    second; ``on_clock`` hears the earliest chunk going, and the results are the same."""
    from mitos_cli.study.executors import Going, chunk_list
    from mitos_cli.study.run import default_task_fn

    world = tmp_path / "tiny.yaml"
    world.write_text((Path(__file__).parent / "data" / "tiny.yaml").read_text())
    study = Study([str(world)], make_choices(["fuzzy"], ["min"], [], []), runs=3, seed=4)
    seen: list[tuple] = []
    outcome = run_study(study, tmp_path / "a", workers=1,
                        on_result=lambda task, row: seen.append(("run", task.index)),
                        on_clock=lambda s: seen.append(("clock", s)))
    again = run_study(study, tmp_path / "b", workers=1)
    assert outcome.rows == again.rows
    clocks = [s for what, s in seen if what == "clock"]
    assert seen[0][0] == "clock" and clocks == sorted(clocks) and clocks[0] >= 1.0
    fn = default_task_fn(study)
    assert not any(isinstance(p, Going) for p in chunk_list(fn, study.tasks()))   # Dask's


def test_a_chunk_whose_run_ended_before_it_told_its_clock_is_forgotten_when_done():
    from mitos_cli.study.executors import Going
    from mitos_cli.study.run import Clocks

    heard: list[float] = []
    clocks = Clocks(heard.append)
    clocks.ended(0)                             # a run of chunk (0, 1) ended in its first second
    clocks.told(Going(1.0, (0, 1)))
    clocks.told(Going(1.0, (2, 3)))
    clocks.told(Going(5.0, (2, 3)))
    clocks.ended(1)                             # chunk (0, 1) has ended: (2, 3) is the earliest
    clocks.told(Going(6.0, (2, 3)))
    assert heard == [1.0, 1.0, 1.0, 6.0]
    clocks.ended(2)
    clocks.ended(3)
    assert clocks.seconds == {}


def test_an_edited_world_or_rule_base_is_run_as_it_is_now(tmp_path):
    """The worker's caches were keyed on the path: a second study of the session ran the
    world and rule base as first read (a 10.55 s success in a world of time_limit 2), while
    study.json recorded the digest of the edited file."""
    import hashlib
    import json
    import shutil

    data = Path(__file__).parent.parent
    world = tmp_path / "w.yaml"
    world.write_text((data / "tests" / "data" / "tiny.yaml").read_text())
    shutil.copytree(data / "rulebases", tmp_path / "rb", ignore=shutil.ignore_patterns("lessons"))
    rules = tmp_path / "rb" / "mitos.rules"

    def run(name: str) -> tuple[str, str]:
        study = Study([world], make_choices(["fuzzy"], ["min"], [], []), runs=1, seed=1,
                      rulebase=str(rules))
        row = run_study(study, tmp_path / name, workers=1).rows[0]
        digests = json.loads((tmp_path / name / "study.json").read_text())["digests"]
        assert digests[str(world)] == hashlib.sha256(world.read_bytes()).hexdigest()[:16]
        return row["outcome"], row["path_length_in"]

    first = run("a")
    text = world.read_text()
    world.write_text(text.replace("time_limit: 15", "time_limit: 2"))
    assert run("b")[0] == "timeout"
    world.write_text(text)
    assert run("c") == first
    rules.write_text(rules.read_text().replace("road is WIDE then speed is FAST",
                                               "road is WIDE then speed is SLOW"))
    slow = run("d")
    assert slow[0] == "success" and slow[1] != first[1]


def test_a_file_changed_while_the_study_runs_is_refused():
    """Runs of a world as it is now under the digest study.json recorded of it before."""
    from mitos_cli.study.simtask import StudyContext, run_task

    world = str(Path(__file__).parent / "data" / "tiny.yaml")
    task = expand([world], [Choice("potential_field")], 1, 1)[0]
    with pytest.raises(StudyError, match="changed while the study ran") as exc:
        run_task(StudyContext(digests=((world, "0123456789abcdef"),)), task)
    assert f"`{world}`" in exc.value.message and "--resume" in exc.value.hint


def _parts(n: int):
    if n == 5:
        os.kill(os.getpid(), signal.SIGKILL)          # the out-of-memory killer, say
    for i in range(n):
        if n == 3 and i == 1:
            raise Crash("killed")
        yield (lambda: i) if n == 6 else (n, i)       # n == 6: a part pickle refuses


def test_a_streaming_pool_gives_every_part_as_made_and_raises_a_worker_s_error():
    from mitos_cli.sim.runs import WorkerLost, pool_streaming

    got = sorted(pool_streaming(_parts, [1, 2, 4, 0], 2))
    assert got == [(1, 0), (2, 0), (2, 1), (4, 0), (4, 1), (4, 2), (4, 3)]
    with pytest.raises(Crash, match="killed"):
        list(pool_streaming(_parts, [1, 3, 2], 2))
    with pytest.raises(AttributeError, match="pickle"):               # not a hang
        list(pool_streaming(_parts, [1, 6], 2))
    with pytest.raises(WorkerLost, match="unfinished") as lost:      # not a hang either
        list(pool_streaming(_parts, [1, 5, 2], 2))
    assert "fewer workers" in lost.value.hint


# -- executors, store, resume --------------------------------------------------------------

def small_study(runs=6) -> Study:
    return Study(["w1.yaml", "w2.yaml"],
                 make_choices(["fuzzy", "potential_field"], ["min", "einstein"], [], []),
                 runs=runs, seed=3)


def test_process_pool_equals_serial_bit_for_bit(tmp_path):
    study = small_study()
    serial = run_study(study, tmp_path / "s", workers=1, task_fn=fake_sim)
    pooled = run_study(study, tmp_path / "p", workers=2, task_fn=fake_sim)
    assert serial.rows == pooled.rows and len(serial.rows) == 36
    # the files hold the same rows (arrival order may differ), floats read back exactly
    a = ResultStore(tmp_path / "s").load()
    b = ResultStore(tmp_path / "p").load()
    key = lambda r: (r["world"], r["planner"], r["and"], r["run"])  # noqa: E731
    assert sorted(a, key=key) == sorted(b, key=key) == sorted(serial.rows, key=key)


def test_resume_recomputes_nothing_finished(tmp_path):
    study = small_study()
    log: list[int] = []
    with pytest.raises(Crash):
        run_study(study, tmp_path, workers=1, task_fn=functools.partial(crashing_sim, after=13,
                                                                         log=log))
    assert len(ResultStore(tmp_path).load()) == 13              # every finished run was kept
    log2: list[int] = []
    outcome = run_study(study, tmp_path, workers=1, resume=True,
                        task_fn=functools.partial(fake_sim, log=log2))
    assert outcome.skipped == 13 and outcome.executed == len(log2) == 36 - 13
    assert set(log2).isdisjoint(log)
    fresh = run_study(study, tmp_path / "fresh", workers=1, task_fn=fake_sim)
    assert outcome.rows == fresh.rows


def test_cut_off_last_line_is_recomputed(tmp_path):
    study = small_study(runs=2)
    run_study(study, tmp_path, workers=1, task_fn=fake_sim)
    path = tmp_path / "results.csv"
    data = path.read_bytes()
    path.write_bytes(data[:-20])                                # killed in the middle of a row
    log: list[int] = []
    out = run_study(study, tmp_path, workers=1, resume=True,
                    task_fn=functools.partial(fake_sim, log=log))
    assert len(log) == 1 and out.complete
    assert path.read_bytes() == data or len(ResultStore(tmp_path).load()) == len(out.rows)


def test_a_whole_last_row_without_its_newline_is_a_row(tmp_path):
    """A file saved by an editor ends without a newline: its last row, whole, was cut off the
    file as if a kill had torn it, and run again."""
    study = small_study(runs=1)
    run_study(study, tmp_path, workers=1, task_fn=fake_sim)
    path = tmp_path / "results.csv"
    data = path.read_bytes()
    path.write_bytes(data.rstrip(b"\n"))
    assert len(ResultStore(tmp_path).load()) == 6
    log: list[int] = []
    out = run_study(study, tmp_path, workers=1, resume=True,
                    task_fn=functools.partial(fake_sim, log=log))
    assert (out.skipped, out.executed, log) == (6, 0, [])
    assert path.read_bytes() == data                          # its newline given back
    wider = run_study(small_study(runs=2), tmp_path, workers=1, resume=True, task_fn=fake_sim)
    assert (wider.skipped, wider.executed) == (6, 6) and len(ResultStore(tmp_path).load()) == 12


@pytest.mark.parametrize("cut", [1, 20])     # the newline only; a row torn in two
@pytest.mark.parametrize("how", ["no --resume", "another seed", "narrower"])
def test_a_refused_study_writes_nothing(tmp_path, cut, how):
    """A refused `compare` cut the last row off a file without a final newline (and counted
    one result fewer in its refusal), though it said it changed nothing."""
    run_study(small_study(runs=1), tmp_path, workers=1, task_fn=fake_sim)
    path = tmp_path / "results.csv"
    path.write_bytes(path.read_bytes()[:-cut])
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    study = {"no --resume": small_study(runs=1),
             "another seed": Study(**{**small_study(runs=1).__dict__, "seed": 4}),
             "narrower": Study(**{**small_study(runs=1).__dict__, "worlds": ["w1.yaml"]})}[how]
    with pytest.raises(StudyError) as exc:
        run_study(study, tmp_path, workers=1, resume=how != "no --resume", task_fn=fake_sim)
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    if how == "no --resume":
        assert f"already holds {6 if cut == 1 else 5} results" in exc.value.message


def test_existing_results_need_resume(tmp_path):
    study = small_study(runs=1)
    run_study(study, tmp_path, workers=1, task_fn=fake_sim)
    with pytest.raises(StudyError) as exc:
        run_study(study, tmp_path, workers=1, task_fn=fake_sim)
    assert "already holds 6 results" in exc.value.message and "--resume" in exc.value.hint


def test_resume_of_a_directory_without_a_study_is_refused(tmp_path):
    """`compare --resume -o typo` began a new study there ("5 runs now, 0 from before")."""
    for where in (tmp_path / "nosuch", tmp_path):
        with pytest.raises(StudyError) as exc:
            run_study(small_study(runs=1), where, workers=1, resume=True, task_fn=fake_sim)
        assert exc.value.message == f"`{where}` holds no study to resume (no study.json or " \
                                    f"results.csv)"
        assert "leave out --resume to start a study there" in exc.value.hint
    assert not (tmp_path / "nosuch").exists() and not any(tmp_path.iterdir())
    # a study stopped before its first run finished holds no row, but is one: it resumes
    study = small_study(runs=1)
    with pytest.raises(Crash):
        run_study(study, tmp_path, workers=1, task_fn=functools.partial(crashing_sim, after=0,
                                                                        log=[]))
    assert ResultStore(tmp_path).load() == []
    outcome = run_study(study, tmp_path, workers=1, resume=True, task_fn=fake_sim)
    assert outcome.skipped == 0 and outcome.executed == 6


def test_a_directory_a_study_runs_in_is_refused_to_another(tmp_path):
    """Two studies in one directory (a --resume started while the study still ran) both
    appended to its results.csv: each run was there twice, and both said they had finished."""
    study = small_study(runs=1)
    running = ResultStore(tmp_path)
    running.start(study.manifest(), study.tasks(), resume=False)
    for resume in (True, False):
        with pytest.raises(StudyError) as exc:
            run_study(study, tmp_path, workers=1, resume=resume, task_fn=fake_sim)
        assert exc.value.message == f"`{tmp_path}` is in use by another study (a `mitos " \
                                    f"compare` still running there)"
    assert ResultStore(tmp_path).load() == []
    running.close()
    outcome = run_study(study, tmp_path, workers=1, resume=True, task_fn=fake_sim)
    assert outcome.executed == 6 and len(ResultStore(tmp_path).load()) == 6


@pytest.mark.skipif(not hasattr(os, "fork"), reason="a child that shares the lock is forked")
def test_a_child_forked_while_a_study_runs_does_not_hold_its_directory(tmp_path):
    """A flock belongs to the open file, which a forked child shares: the pool's workers of a
    study killed with `kill -9` held its directory while they ran on, and a --resume at once
    was refused ("in use by another study")."""
    study = small_study(runs=1)
    running = ResultStore(tmp_path)
    running.start(study.manifest(), study.tasks(), resume=False)
    r, w = os.pipe()
    ready_r, ready_w = os.pipe()
    pid = os.fork()
    if pid == 0:                        # the child: lives until the parent lets it end
        os.close(w)
        os.write(ready_w, b"1")         # (fork returned here: its at-fork hooks have run)
        os.read(r, 1)
        os._exit(0)
    os.close(r)
    os.close(ready_w)
    assert os.read(ready_r, 1) == b"1"  # (a lock tried before the child's hooks ran failed)
    os.close(ready_r)
    try:
        running.close()                 # the study's process lets go; its child lives on
        outcome = run_study(study, tmp_path, workers=1, resume=True, task_fn=fake_sim)
        assert outcome.executed == 6 and len(ResultStore(tmp_path).load()) == 6
    finally:
        os.close(w)
        os.waitpid(pid, 0)


def test_a_choice_given_twice_is_refused(tmp_path):
    """Its runs shared one key: each summarized both (n = 2 of 1 run) and were written
    twice, which the study's own --resume then refused."""
    with pytest.raises(MitosError) as exc:
        Study(["w.yaml"], [Choice("fuzzy", "min"), Choice("dwa"), Choice("fuzzy", "min")],
              runs=1, seed=1)
    assert exc.value.message == "the choice `fuzzy and=min` is given twice"
    assert Study(["w.yaml"], (Choice("dwa"), Choice("fuzzy")), runs=1, seed=1).choices == [
        Choice("dwa"), Choice("fuzzy")]


def test_write_report_takes_plots_true_or_false(tmp_path):
    """plots="no" drew the pictures, as any true value did."""
    from mitos_cli.study import write_report

    with pytest.raises(MitosError, match="plots is True or False, not `'no'`"):
        write_report(None, tmp_path, plots="no")          # type: ignore[arg-type]
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("choices, says", [
    ([], "a Study needs at least one choice"),
    (Choice("fuzzy"), "a Study's choices are a list of choices, not Choice"),
    (["fuzzy"], "a Study's choices are choices, not str `'fuzzy'`"),
    (None, "a Study's choices are a list of choices, not NoneType"),
])
def test_choices_that_are_not_a_list_of_choices_are_refused(choices, says):
    """No choice ran 0 of 0 runs into a report that compared nothing (runs=0 is refused for
    that); one Choice not in a list met "'Choice' object is not iterable", a name an
    AttributeError later."""
    with pytest.raises(MitosError) as exc:
        Study(["w.yaml"], choices, runs=1, seed=1)
    assert exc.value.message.startswith(says) and "make_choices" in exc.value.hint


@pytest.mark.parametrize("name", ["results.csv", "study.json"])
@pytest.mark.parametrize("resume", [False, True])
def test_a_pipe_or_device_in_the_study_directory_is_refused(tmp_path, name, resume):
    """A named pipe (or a link to /dev/zero) where results.csv or study.json goes: the study
    waited for ever, reading it or writing study.json to it."""
    if name == "results.csv":
        os.symlink(os.devnull if resume else "/dev/zero", tmp_path / name)
    else:
        os.mkfifo(tmp_path / name)
    with pytest.raises(StudyError) as exc:
        run_study(small_study(runs=1), tmp_path, workers=1, resume=resume, task_fn=fake_sim)
    assert exc.value.message.startswith(f"`{tmp_path / name}` is not a regular file, so not a")


def test_a_world_named_as_the_pooled_rows_is_refused(tmp_path):
    """A world file `all worlds` (given so) had its rows taken for the pooled ones: the
    ranking listed each choice twice, once with that world's figures alone."""
    with pytest.raises(MitosError) as exc:
        Study(["all worlds", "w.yaml"], [Choice("dwa")], runs=1, seed=1)
    assert exc.value.message == "a world named `all worlds` is not told apart from the rows " \
                                "pooled over the worlds"
    assert Study([str(tmp_path / "all worlds")], [Choice("dwa")], runs=1, seed=1).worlds == [
        str(tmp_path / "all worlds")]


def test_resume_with_another_seed_is_refused(tmp_path):
    run_study(small_study(runs=1), tmp_path, workers=1, task_fn=fake_sim)
    other = Study(**{**small_study(runs=1).__dict__, "seed": 4})
    with pytest.raises(StudyError) as exc:
        run_study(other, tmp_path, workers=1, resume=True, task_fn=fake_sim)
    assert "was made with --seed 3, not 4" in exc.value.message
    span = exc.value.span                                # where study.json records it
    assert span is not None and str(span.path).endswith("study.json")
    assert span.source_line is not None and span.source_line.strip().startswith('"seed": 3')


def test_resume_with_worlds_reordered_is_refused(tmp_path):
    run_study(small_study(runs=1), tmp_path, workers=1, task_fn=fake_sim)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    swapped = Study(**{**small_study(runs=1).__dict__, "worlds": ["w2.yaml", "w1.yaml"]})
    with pytest.raises(StudyError) as exc:
        run_study(swapped, tmp_path, workers=1, resume=True, task_fn=fake_sim)
    assert "same order" in exc.value.hint
    # refused before anything is written: study.json still describes the study on disk
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_resume_may_add_runs_but_not_leave_finished_ones_out(tmp_path):
    """`compare W --resume --and product` on a study of two worlds and two norms rewrote its
    report and study.json for the narrower selection, with results.csv still holding all."""
    run_study(small_study(runs=1), tmp_path, workers=1, task_fn=fake_sim)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    narrower = Study(**{**small_study(runs=1).__dict__, "worlds": ["w1.yaml"]})
    with pytest.raises(StudyError) as exc:
        run_study(narrower, tmp_path, workers=1, resume=True, task_fn=fake_sim)
    assert exc.value.message.endswith("holds 3 finished runs this study leaves out (the "
                                      "first: run 0 of w2.yaml, fuzzy, and=min); resuming "
                                      "would report on part of the file")
    # at that run's row, its key underlined (it had no place)
    span = exc.value.span
    lines = (tmp_path / "results.csv").read_text().splitlines()
    assert span is not None and lines[span.line - 1].startswith("w2.yaml,fuzzy,min,,,0,")
    assert (span.column, span.end_column) == (1, 1 + len("w2.yaml,fuzzy,min,,,0"))
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    wider = run_study(small_study(runs=2), tmp_path, workers=1, resume=True, task_fn=fake_sim)
    assert (wider.skipped, wider.executed) == (6, 6)


def test_the_command_that_resumes_names_the_directory_being_resumed(tmp_path):
    """A study copied to another directory was told to resume "as it was made", with the
    -o of the directory it was made in."""
    import shutil

    study = Study(**{**small_study(runs=1).__dict__,
                     "command": "mitos compare w1.yaml w2.yaml --runs 1 --seed 3 -o 'old dir'"})
    run_study(study, tmp_path / "old dir", workers=1, task_fn=fake_sim)
    shutil.copytree(tmp_path / "old dir", tmp_path / "new")
    narrower = Study(**{**small_study(runs=1).__dict__, "worlds": ["w1.yaml"]})
    with pytest.raises(StudyError) as exc:
        run_study(narrower, tmp_path / "new", workers=1, resume=True, task_fn=fake_sim)
    assert exc.value.hint == (f"resume the study as it was made: mitos compare w1.yaml w2.yaml "
                              f"--runs 1 --seed 3 -o {tmp_path / 'new'} --resume, or choose "
                              f"another directory with -o")


def test_hand_edited_results_are_reported(tmp_path):
    run_study(small_study(runs=1), tmp_path, workers=1, task_fn=fake_sim)
    path = tmp_path / "results.csv"
    lines = path.read_text().splitlines(keepends=True)
    path.write_text("".join(lines[:2]) + "w1.yaml,fuzzy,min\n")
    with pytest.raises(StudyError) as exc:
        ResultStore(tmp_path).load()
    assert exc.value.message == "expected 17 values in a row, found 3"
    assert (exc.value.span.line, exc.value.span.column) == (3, 1)
    assert exc.value.span.path.endswith("results.csv")
    path.write_text("world,oops\n")
    with pytest.raises(StudyError) as exc:
        ResultStore(tmp_path).load()
    assert "not a results file" in exc.value.message
    assert (exc.value.span.line, exc.value.span.column) == (1, 1)       # the header's line
    assert exc.value.span.source_line == "world,oops"


def test_a_results_file_with_a_byte_order_mark_resumes(tmp_path):
    """A results.csv saved "UTF-8 with BOM" (Excel, an editor) was "not a results file of
    this version of mitos", with the columns it has as the ones expected."""
    study = small_study(runs=2)
    with pytest.raises(Crash):
        run_study(study, tmp_path, workers=1, task_fn=functools.partial(crashing_sim, after=5,
                                                                         log=[]))
    path = tmp_path / "results.csv"
    path.write_bytes(b"\xef\xbb\xbf" + path.read_bytes())
    outcome = run_study(study, tmp_path, workers=1, resume=True, task_fn=fake_sim)
    assert (outcome.skipped, outcome.executed) == (5, 7)
    assert outcome.rows == run_study(study, tmp_path / "fresh", workers=1, task_fn=fake_sim).rows
    assert ResultStore(tmp_path).load() == ResultStore(tmp_path / "fresh").load() != []


@pytest.mark.parametrize("copy", ["same", "other figures"])
def test_a_run_held_twice_is_refused_at_its_second_row(tmp_path, copy):
    """A row copied (or two results files joined) ended `--resume` in an IndexError."""
    run_study(small_study(runs=1), tmp_path, workers=1, task_fn=fake_sim)
    path = tmp_path / "results.csv"
    lines = path.read_text().splitlines(keepends=True)
    again = lines[2] if copy == "same" else lines[2].replace(",200,", ",201,")
    path.write_text("".join(lines) + again)
    before = path.read_bytes()
    with pytest.raises(StudyError) as exc:
        run_study(small_study(runs=1), tmp_path, workers=1, resume=True, task_fn=fake_sim)
    row = lines[2].split(",")
    assert exc.value.message == (f"run 0 of {row[0]} ({row[1]}, and={row[2]}) is here a "
                                 f"second time: its first row is line 3")
    span = exc.value.span
    assert (span.line, span.column) == (8, 1) and span.path == str(path)
    assert span.source_line[:span.end_column - 1] == ",".join(row[:6])
    assert "remove one of the two lines" in exc.value.hint
    assert path.read_bytes() == before


def test_alike_worlds_resumed_by_other_paths_keep_their_order(tmp_path, monkeypatch):
    """Two worlds of the same text, made from their directory and resumed from another by
    their full paths: each is found by its digest, the first world not yet taken first."""
    home = tmp_path / "home"
    home.mkdir()
    for name in ("w1.yaml", "w2.yaml"):
        (home / name).write_text("the same world\n")
    monkeypatch.chdir(home)
    run_study(small_study(runs=1), tmp_path / "s", workers=1, task_fn=fake_sim)
    monkeypatch.chdir(tmp_path)
    given = Study(**{**small_study(runs=2).__dict__,
                     "worlds": [str(home / "w1.yaml"), str(home / "w2.yaml")]})
    out = run_study(given, tmp_path / "s", workers=1, resume=True, task_fn=fake_sim)
    assert (out.skipped, out.executed) == (6, 6)
    assert [r["world"] for r in ResultStore(tmp_path / "s").load()] == \
        [r["world"] for r in ResultStore(tmp_path / "s").load()[:6]] * 2
    assert {r["world"] for r in ResultStore(tmp_path / "s").load()} == {"w1.yaml", "w2.yaml"}
    assert {r["world"] for r in out.rows} == set(given.worlds)


def test_a_run_held_under_two_names_of_its_world_is_refused(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for name in ("w1.yaml", "w2.yaml"):
        Path(name).write_text(name + "\n")
    run_study(small_study(runs=1), "s", workers=1, task_fn=fake_sim)
    path = tmp_path / "s" / "results.csv"
    lines = path.read_text().splitlines(keepends=True)
    world, rest = lines[1].split(",", 1)
    path.write_text("".join(lines) + f"{tmp_path / world},{rest}")
    with pytest.raises(StudyError) as exc:
        run_study(small_study(runs=1), "s", workers=1, resume=True, task_fn=fake_sim)
    assert "is here a second time: its first row is line 2" in exc.value.message
    assert exc.value.span.line == 8


def test_unknown_executor():
    with pytest.raises(MitosError) as exc:
        list(execute(fake_sim, small_study(1).tasks(), "dusk"))
    assert "unknown executor `dusk`" in exc.value.message and "dask" in exc.value.hint


def test_summaries_and_ranking():
    study = small_study(runs=10)
    rows = [{"world": t.world, "planner": t.choice.planner, "and": t.choice.and_,
             "or": t.choice.or_, "inference": t.choice.inference, "run": t.run, "seed": t.seed,
             **fake_sim(t)} for t in study.tasks()]
    s = summaries(rows, study.worlds, study.choices)
    assert len(s) == 2 * 3 + 3 and s[-1].world == "all worlds" and s[-1].n == 20
    ranks = rank(rows, [x for x in s if x.world == "all worlds"])
    rates = [r.summary.rates["success"].value for r in ranks]
    assert rates == sorted(rates, reverse=True) and ranks[0].p_value is None
    for r in ranks[1:]:
        assert r.paired_n == 20 and 0.0 < r.p_value <= 1.0
    # time to goal uses successful runs only
    t = s[0]
    assert t.metrics["time_s"].n == t.rates["success"].k
    assert t.metrics["min_clearance_in"].n == t.n
    # replans and backouts count over every run, as the collisions are counted
    mine = [r for r in rows if r["world"] == t.world and r["planner"] == t.choice.planner
            and r["and"] == t.choice.and_]
    for key in ("replans", "backouts"):
        assert t.metrics[key].n == t.n
        assert t.metrics[key].mean == pytest.approx(np.mean([r[key] for r in mine]))


def test_results_carry_replans_and_backouts_as_whole_numbers(tmp_path):
    outcome = run_study(small_study(runs=2), tmp_path, workers=1, task_fn=fake_sim)
    header = (tmp_path / "results.csv").read_text().splitlines()[0].split(",")
    assert header[-2:] == ["replans", "backouts"]
    back = ResultStore(tmp_path).load()
    assert back == outcome.rows and {type(r[k]) for r in back for k in header[-2:]} == {int}


def test_results_of_the_version_before_replans_are_refused_as_such(tmp_path):
    """A results.csv written before the rows had replans and backouts: resuming it would
    report them over part of the runs; it is refused, saying why (not "not a results file")."""
    run_study(small_study(runs=1), tmp_path, workers=1, task_fn=fake_sim)
    path = tmp_path / "results.csv"
    old = ["".join(line.rsplit(",", 2)[:1]) for line in path.read_text().splitlines()]
    path.write_text("\n".join(old) + "\n")
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    with pytest.raises(StudyError) as exc:
        run_study(small_study(runs=1), tmp_path, workers=1, resume=True, task_fn=fake_sim)
    assert exc.value.message == (f"{path} was written by an earlier version of mitos: its "
                                 f"rows have no replans and backouts, which this version "
                                 f"reports for every run")
    assert exc.value.hint == "run the study again in another directory with -o"
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_non_numeric_value_in_results(tmp_path):
    run_study(small_study(runs=1), tmp_path, workers=1, task_fn=fake_sim)
    path = tmp_path / "results.csv"
    lines = path.read_text().splitlines(keepends=True)
    cells = lines[1].split(",")
    cells[9] = "fast"                                          # time_s
    lines[1] = ",".join(cells)
    path.write_text("".join(lines))
    with pytest.raises(StudyError) as exc:
        ResultStore(tmp_path).load()
    assert exc.value.message == "`time_s` is `fast`, not a number"
    span = exc.value.span
    assert (span.line, span.column) == (2, len(",".join(cells[:9])) + 2)
    assert span.source_line[span.column - 1:span.end_column - 1] == "fast"


@pytest.mark.parametrize("field, value, said", [
    ("outcome", "succes", "not an outcome of a run"),         # in no column of the table
    ("time_s", "nan", "which no run reports"),                # left out of the mean
    ("min_clearance_in", "inf", "which no run reports"),      # a mean of inf, a std of nan
    ("min_clearance_in", "-inf", "which no run reports"),
    ("ticks", "1.5", "not a number"),
    ("time_s", "-5", "which no run reports"),                # averaged into the time to goal
    ("path_length_in", "-0.5", "which no run reports"),
    ("ticks", "-1", "which no run reports"),
    ("replans", "-1", "which no run reports"),
    ("backouts", "-2", "which no run reports"),
    ("collisions", "-1", "which no run reports"),
    ("path_length_in", "1e308", "more than any run reports"),   # a mean of inf: `inf±inf`
    ("min_clearance_in", "-2e15", "more than any run reports"),
    ("backouts", "1" + "0" * 39, "more than any run reports"),  # an OverflowError in the mean
])
def test_a_row_no_run_reports_is_refused(tmp_path, field, value, said):
    """A hand-edited row that parses but is no run's (``--resume`` once took a misspelt
    outcome, counted in no column, and a ``nan``, left out of the means) names the field."""
    from mitos_cli.study.store import COLUMNS

    run_study(small_study(runs=1), tmp_path, workers=1, task_fn=fake_sim)
    path = tmp_path / "results.csv"
    lines = path.read_text().splitlines(keepends=True)
    cells = lines[1].rstrip("\n").split(",")
    cells[COLUMNS.index(field)] = value
    lines[1] = ",".join(cells) + "\n"
    path.write_text("".join(lines))
    with pytest.raises(StudyError) as exc:
        ResultStore(tmp_path).load()
    assert exc.value.message == f"`{field}` is `{value}`, {said}"
    assert exc.value.span.line == 2
    if field == "outcome":
        assert exc.value.hint == "did you mean `success`?"
    if value.startswith("-") and value != "-inf" and said != "more than any run reports":
        assert exc.value.expected.endswith(", 0 or more")
    if said == "more than any run reports":
        assert exc.value.expected.endswith(", within ±1e+15")


@pytest.mark.parametrize("outcome, collisions", [("success", "3"), ("timeout", "1"),
                                                  ("stuck", "2"), ("collision", "0")])
def test_a_row_whose_outcome_contradicts_its_collisions_is_refused(tmp_path, outcome,
                                                                   collisions):
    """The simulator's outcome is `collision` exactly when a robot collided; `--resume` took
    a hand-edited `success` with 3 collisions and averaged it in."""
    from mitos_cli.study.store import COLUMNS

    run_study(small_study(runs=1), tmp_path, workers=1, task_fn=fake_sim)
    path = tmp_path / "results.csv"
    lines = path.read_text().splitlines(keepends=True)
    cells = lines[1].rstrip("\n").split(",")
    cells[COLUMNS.index("outcome")], cells[COLUMNS.index("collisions")] = outcome, collisions
    lines[1] = ",".join(cells) + "\n"
    path.write_text("".join(lines))
    with pytest.raises(StudyError) as exc:
        run_study(small_study(runs=1), tmp_path, workers=1, resume=True, task_fn=fake_sim)
    assert exc.value.message == f"`collisions` is `{collisions}` in a row whose outcome is " \
                                f"`{outcome}`"
    span = exc.value.span
    assert span.line == 2 and span.source_line[span.column - 1:span.end_column - 1] == collisions
    assert exc.value.hint == "the file was edited by hand; remove that line"


def test_output_directory_that_is_a_file(tmp_path):
    target = tmp_path / "taken"
    target.write_text("not a directory")
    with pytest.raises(StudyError) as exc:
        run_study(small_study(runs=1), target, workers=1, task_fn=fake_sim)
    assert exc.value.message.endswith("taken` is a file, not a directory for the study's results")
    assert target.read_text() == "not a directory"


def test_unreadable_manifest_on_resume(tmp_path):
    run_study(small_study(runs=1), tmp_path, workers=1, task_fn=fake_sim)
    (tmp_path / "study.json").write_text("{not json")
    with pytest.raises(StudyError) as exc:
        run_study(small_study(runs=1), tmp_path, workers=1, resume=True, task_fn=fake_sim)
    assert "study.json is not JSON" in exc.value.message
    assert exc.value.span is not None and (exc.value.span.line, exc.value.span.column) == (1, 2)


@pytest.mark.parametrize("manifest, says", [
    ("[1]", "is not a study manifest"),                    # JSON, but not an object
    ('{"seed": 1, "digests": 5}', "is not a study manifest"),
    ('{"seed": ' + "9" * 5000 + "}", "is not a study manifest"),   # past int()'s digits
    ('{"seed": 1, "command": []}', "is not a study manifest"),
    # a seed that is no whole number: "made with --seed 1, not 1", "resume with --seed None"
    ('{"seed": "1"}', 'its `seed` is `"1"`, not a whole number'),
    ('{"seed": null}', "its `seed` is `null`, not a whole number"),
    ('{"seed": true}', "its `seed` is `true`, not a whole number"),    # (true == 1: resumed)
    ('{"seed": 1.0}', "its `seed` is `1.0`, not a whole number"),
    ("{}", "its `seed` is missing, not a whole number"),
    ("[" * 100_000, "nests too deep to read"),             # past the JSON reader's recursion
    (b"{\"seed\": \xff}", "it is not UTF-8 text"),
])
def test_a_broken_manifest_is_refused_with_what_it_is(tmp_path, manifest, says):
    run_study(small_study(runs=1), tmp_path, workers=1, task_fn=fake_sim)
    path = tmp_path / "study.json"
    path.write_bytes(manifest if isinstance(manifest, bytes) else manifest.encode())
    with pytest.raises(StudyError, match=says) as exc:
        run_study(small_study(runs=1), tmp_path, workers=1, resume=True, task_fn=fake_sim)
    assert "remove" in (exc.value.hint or "")


@pytest.mark.parametrize("manifest, says, place", [
    # these named no place: the whole, `digests`, `command`, a number past int()'s digits
    ("[1]", "it holds a list, not an object", (1, 1)),
    ('{"seed": 1,\n "digests": 5}', "its `digests` is `5`, not an object of file digests",
     (2, 2)),
    ('{"seed": 1,\n  "command": []}', "its `command` is `[]`, not a string", (2, 3)),
    ('{"seed": ' + "9" * 5000 + "}", "is not a study manifest", (1, 10)),
    # 1e400 is read as infinity, and was shown as `Infinity`
    ('{"seed": 1e400}', "its `seed` is `1e400`, not a whole number", (1, 2)),
])
def test_a_misshapen_manifest_is_refused_at_its_place(tmp_path, manifest, says, place):
    run_study(small_study(runs=1), tmp_path, workers=1, task_fn=fake_sim)
    (tmp_path / "study.json").write_text(manifest)
    with pytest.raises(StudyError, match=re.escape(says)) as exc:
        run_study(small_study(runs=1), tmp_path, workers=1, resume=True, task_fn=fake_sim)
    span = exc.value.span
    assert span is not None and span.path.endswith("study.json")
    assert (span.line, span.column) == place


@pytest.mark.parametrize("results, says, line", [
    (b"\xff\n", "it is not UTF-8 text", 2),
    ("x" * 140_000 + "\n", "line 2 is not a row of results", 2),     # past csv's field limit
])
def test_a_broken_results_file_is_refused_at_its_line(tmp_path, results, says, line):
    run_study(small_study(runs=1), tmp_path, workers=1, task_fn=fake_sim)
    path = tmp_path / "results.csv"
    header = path.read_bytes().splitlines(keepends=True)[0]
    path.write_bytes(header + (results if isinstance(results, bytes) else results.encode()))
    with pytest.raises(StudyError, match=says) as exc:
        run_study(small_study(runs=1), tmp_path, workers=1, resume=True, task_fn=fake_sim)
    assert exc.value.span is not None and exc.value.span.line == line


def test_a_results_file_that_is_a_directory_is_refused(tmp_path):
    (tmp_path / "results.csv").mkdir()
    with pytest.raises(StudyError, match="is a directory, not a results file"):
        run_study(small_study(runs=1), tmp_path, workers=1, resume=True, task_fn=fake_sim)


def test_dask_missing_says_how_to_install(monkeypatch):
    import sys

    from mitos_cli.study.executors import dask_client

    monkeypatch.setitem(sys.modules, "distributed", None)     # import distributed -> ImportError
    with pytest.raises(StudyError) as exc:
        dask_client(None, 2)
    assert "needs dask.distributed" in exc.value.message and "'dask[distributed]>=2024.1'" in exc.value.hint


@pytest.mark.parametrize("changes, says", [
    ({"runs": -1}, "`runs` is a whole number, 1 or more, not `-1`"),    # NumPy's OverflowError
    ({"runs": 0}, "`runs` is a whole number, 1 or more, not `0`"),      # compared nothing
    ({"runs": True}, "`runs` is a whole number, 1 or more, not `True`"),
    ({"seed": -1}, "a seed is a whole number, 0 or more, not `-1`"),    # NumPy's ValueError
    ({"seed": True}, "a seed is a whole number, 0 or more, not `True`"),  # ran as seed 1
])
def test_a_study_checks_runs_and_seed_as_compare_does(changes, says):
    from mitos_cli.errors import InputError

    with pytest.raises(InputError) as exc:
        Study(["a.yaml"], [Choice("potential_field")], **{"runs": 1, "seed": 1, **changes})
    assert exc.value.message == says
    study = Study(["a.yaml"], [Choice("dwa")], runs=np.int64(2), seed=np.uint8(3))
    assert (type(study.runs), type(study.seed)) == (int, int) and len(study.tasks()) == 2


@pytest.mark.parametrize("worlds, says, hint", [
    # read a character at a time: "world file `t` not found"
    ("tests/data/tiny.yaml", "takes a list of world files, not the path `tests/data/tiny.yaml`",
     "Study(['tests/data/tiny.yaml'], ...)"),
    (Path("a.yaml"), "not the path `a.yaml`", "Study(['a.yaml'], ...)"),
    (["a.yaml", 3], "runs world files, not int `3`", "Study(['worlds/corridor.yaml'], ...)"),
    ([], "a Study needs at least one world file", None),
    # each row summarized the runs of both (n 4 for 2 runs); `mitos compare` refuses it
    (["a.yaml", "b.yaml", "a.yaml"], "the world `a.yaml` is given twice", "runs=N"),
    (["a.yaml", "./a.yaml"], "the world `./a.yaml` is given twice (as `a.yaml`)", "runs=N"),
])
def test_a_study_says_what_its_worlds_are(worlds, says, hint):
    from mitos_cli.errors import InputError

    with pytest.raises(InputError) as exc:
        Study(worlds, [Choice("dwa")], runs=1, seed=1)
    assert says in exc.value.message
    assert exc.value.hint is None if hint is None else hint in exc.value.hint


@pytest.mark.parametrize("workers", [0, -5, 2.5, True])
def test_run_study_checks_workers_as_run_many_does(tmp_path, workers):
    """All four ran (serially) without a word; run_many refuses them."""
    from mitos_cli.errors import InputError

    with pytest.raises(InputError) as exc:
        run_study(small_study(runs=1), tmp_path / "out", workers=workers, task_fn=fake_sim)
    assert exc.value.message == f"`workers` is a whole number, 1 or more, not `{workers!r}`"
    assert not (tmp_path / "out").exists()


def test_a_study_runs_world_paths_and_refuses_loaded_worlds(tmp_path):
    """A Path failed in study.json's JSON, a World in `Path()`: both bare TypeErrors."""
    from mitos_cli.errors import InputError
    from mitos_cli.sim import load_world

    study = Study([tmp_path / "w1.yaml", "w2.yaml"], [Choice("dwa")], runs=1, seed=1)
    assert study.worlds == [str(tmp_path / "w1.yaml"), "w2.yaml"]
    out = run_study(study, tmp_path / "out", workers=1, task_fn=fake_sim)
    assert [r["world"] for r in out.rows] == study.worlds
    tiny = load_world(Path(__file__).parent / "data" / "tiny.yaml")
    for worlds in ([tiny], tiny):
        with pytest.raises(InputError, match="world files, not (loaded worlds|one World)") as exc:
            Study(worlds, [Choice("dwa")], runs=1, seed=1)
        assert exc.value.hint == f"give its file: Study([{tiny.path!r}], ...)"


@pytest.mark.parametrize("under", ["study", "a/study"])
def test_an_output_directory_under_a_file_is_said_so(tmp_path, under):
    """`compare -o notes.txt/study` said "`notes.txt` does not exist" and hinted `mkdir -p
    notes.txt`, which fails: the file is in the way, and the message names it."""
    (tmp_path / "notes.txt").write_text("x\n")
    out = tmp_path / "notes.txt" / under
    with pytest.raises(StudyError) as exc:
        run_study(small_study(runs=1), out, workers=1, task_fn=fake_sim)
    assert exc.value.message == (f"cannot create the output directory `{out}`: "
                                 f"`{tmp_path / 'notes.txt'}` is a file, not a directory")
    assert exc.value.hint == "choose another directory with -o"


def test_an_output_directory_whose_parent_is_missing_is_refused(tmp_path):
    """`compare -o a/b/study` made every missing directory where `simulate --out`, `convert
    -o`, `export -o` and `plot -o` refuse a missing one: it makes the last one alone now, and
    refuses before any run (nothing computed is lost, nothing made by a typo is left)."""
    out = tmp_path / "a" / "b" / "study"
    with pytest.raises(StudyError) as exc:
        run_study(small_study(runs=1), out, workers=1, task_fn=fake_sim)
    assert exc.value.message == (f"cannot create the output directory `{out}`: "
                                 f"`{out.parent}` does not exist")
    assert f"mkdir -p {out.parent}" in exc.value.hint
    assert not (tmp_path / "a").exists()
    run_study(small_study(runs=1), tmp_path / "new", workers=1, task_fn=fake_sim)   # one level
    assert (tmp_path / "new" / "results.csv").is_file()
