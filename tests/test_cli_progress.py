"""Watching long commands: ``--live`` paced by ``--speed``, progress bars only on a terminal,
and Ctrl-C on ``simulate --runs`` and ``compare`` (what finished is kept, exit 130)."""

from __future__ import annotations

import io
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from rich.console import Console

from mitos_cli.cli.app import main
from mitos_cli.cli.progress import INTERRUPTED, progress_bar
from mitos_cli.sim import runs as runs_mod
from mitos_cli.sim.live import LiveView, Pacer
from mitos_cli.sim.loop import prepare, simulate
from mitos_cli.sim.worldfile import load_world

ROOT = Path(__file__).resolve().parent.parent
TINY = Path(__file__).parent / "data" / "tiny.yaml"


class FakeClock:
    """A wall clock that only moves when slept on (or by ``step`` per reading)."""

    def __init__(self, step: float = 0.0) -> None:
        self.now, self.step, self.slept = 100.0, step, 0.0

    def __call__(self) -> float:
        self.now += self.step
        return self.now

    def sleep(self, dt: float) -> None:
        self.now += dt
        self.slept += dt


def run(capsys, *args) -> tuple[int, str, str]:
    try:
        main([*map(str, args)])
        code = 0
    except SystemExit as exc:
        code = exc.code or 0
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("speed, due", [(1.0, 2.0), (4.0, 0.5), (0.0, 0.0)])
def test_pacer_holds_a_run_to_its_real_time_factor(speed, due):
    clock = FakeClock()
    pacer = Pacer(speed, clock, clock.sleep)
    assert pacer.wait(0.05) == 0.0                   # the first tick is due at once
    for k in range(2, 42):
        pacer.wait(0.05 * k)
    assert clock.slept == pytest.approx(due, abs=1e-9)


def test_pacer_refuses_a_negative_or_nan_speed():
    for bad in (-1.0, float("nan")):
        with pytest.raises(ValueError):
            Pacer(bad)


def test_live_view_paces_caps_its_frames_and_ends_on_the_last_tick():
    world = load_world(TINY)
    scene = prepare(world)
    clock = FakeClock()
    screen = io.StringIO()
    with LiveView(world, scene, speed=2.0, fps=10.0, console=Console(file=screen, width=80),
                  clock=clock, sleep=clock.sleep) as view:
        res = simulate(world, seed=1, scene=scene, on_tick=view.update)
    t_end = float(res.t[-1])
    assert clock.slept == pytest.approx((t_end - float(res.t[0])) / 2, abs=1e-6)
    # 10 frames a wall second over t_end / 2 wall seconds, and the last tick
    assert view.frames <= int(t_end / 2 * 10) + 2 and view.frames >= int(t_end / 2 * 10) - 1
    last = screen.getvalue()
    assert f"t = {t_end:6.2f} s (x2)" in last and "R" in last and "#" in last


def test_speed_implies_live_and_is_one_run_only(capsys):
    code, _, err = run(capsys, "simulate", TINY, "--runs", 2, "--speed", 4)
    assert code == 2 and "--speed" in err
    code, _, err = run(capsys, "simulate", TINY, "--speed", -1)
    assert code == 2


def test_progress_bar_is_silent_off_a_terminal(capsys):
    with progress_bar("runs") as bar:                # pytest's stderr is not a terminal
        bar.update(1, 2)
        assert bar.progress is None
    with progress_bar("runs", quiet=True) as bar:
        assert bar.progress is None
    assert capsys.readouterr().err == ""


def test_progress_lines_off_a_terminal_every_few_percent(capsys):
    """``compare`` piped to a log: a plain line each 5% (and at the end), none with --json."""
    with progress_bar("runs (local)", lines=True) as bar:
        for done in range(0, 41):
            bar.update(done, 40)
    lines = capsys.readouterr().err.splitlines()
    assert lines[0] == "runs (local): 0 of 40 (0%)" and lines[-1] == "runs (local): 40 of 40 (100%)"
    assert len(lines) == 21 and "runs (local): 2 of 40 (5%)" in lines
    with progress_bar("runs (local)", quiet=True, lines=True) as bar:
        bar.update(40, 40)
    assert capsys.readouterr().err == ""


def test_a_status_leaves_the_lines_off_a_terminal_as_they_were(capsys):
    """Where the runs are (`runs at 12 s`) goes on the bar only: a piped log's lines keep
    their words (describe() would have made them `runs (local): at 12 s: 2 of 40`)."""
    with progress_bar("runs (local)", lines=True) as bar:
        bar.update(0, 40)
        bar.status("at 12 s")
        bar.update(2, 40)
    assert capsys.readouterr().err.splitlines() == ["runs (local): 0 of 40 (0%)",
                                                     "runs (local): 2 of 40 (5%)"]


def test_compare_piped_prints_progress_lines(capsys, tmp_path):
    code, _, err = run(capsys, "compare", TINY, "--runs", 2, "--out", tmp_path / "study")
    assert code == 0
    shown = [line for line in err.splitlines() if line.startswith("runs (local): ")]
    total = shown[0].split(" of ")[1].split()[0]
    assert shown[0] == f"runs (local): 0 of {total} (0%)"
    assert shown[-1] == f"runs (local): {total} of {total} (100%)"


def test_run_many_reports_progress_and_keeps_what_finished_on_ctrl_c(monkeypatch):
    world = load_world(TINY)
    seen = []
    result = runs_mod.run_many([world], runs=2, seed=4, workers=1,
                               on_progress=lambda d, t: seen.append((d, t)))
    assert seen == [(0, 2), (1, 2), (2, 2)]     # the total from the start
    real = runs_mod._chunk_runs

    def interrupted_after_one(job):          # Ctrl-C while the chunk's second run goes on
        for part in real(job):
            yield part
            if len(part) == 3:
                raise KeyboardInterrupt

    monkeypatch.setattr(runs_mod, "_chunk_runs", interrupted_after_one)
    with pytest.raises(runs_mod.RunsInterrupted) as stop:
        runs_mod.run_many([world], runs=2, seed=4, workers=1)
    assert stop.value.finished == 1 and stop.value.total == 2
    assert stop.value.runs.worlds[0].summaries[0] in result.worlds[0].summaries


def test_run_many_tells_where_its_batches_are_between_the_runs_ends():
    """Runs in lockstep end together, late in their batch: `simulate --runs 60` showed 0/60
    till its last seconds. Each chunk now sends where its runs are every simulated second;
    ``on_clock`` hears the earliest batch going, and the runs are the same as without."""
    world = load_world(TINY)
    seen: list[tuple] = []
    result = runs_mod.run_many([world], runs=3, seed=4, workers=1,
                               on_progress=lambda d, t: seen.append(("runs", d)),
                               on_clock=lambda s: seen.append(("clock", s)))
    assert result == runs_mod.run_many([world], runs=3, seed=4, workers=1)
    clocks = [s for what, s in seen if what == "clock"]
    first_end = seen.index(("runs", 1))
    assert seen[0] == ("runs", 0) and first_end > 1                  # clocks before any end
    assert clocks == sorted(clocks) and clocks[0] >= runs_mod.CLOCK_EVERY
    assert all(b - a <= runs_mod.CLOCK_EVERY + world.dt for a, b in zip(clocks, clocks[1:]))
    ended = max(s["time_s"] for s in result.worlds[0].summaries)
    assert clocks[-1] <= ended < clocks[-1] + runs_mod.CLOCK_EVERY + world.dt


def test_simulate_runs_ctrl_c_prints_the_finished_runs_and_exits_130(capsys, monkeypatch):
    world = load_world(TINY)
    done = runs_mod.run_many([world], runs=2, seed=1, workers=1)

    def interrupted(*args, **kwargs):
        raise runs_mod.RunsInterrupted(done, 5)

    monkeypatch.setattr(runs_mod, "run_many", interrupted)
    code, out, err = run(capsys, "simulate", TINY, "--runs", 5)
    assert code == INTERRUPTED == 130
    assert out.splitlines()[1].split()[:2] == ["tiny", "2"]
    assert "interrupted: the table has the 2 of 5 runs that had finished" in err


def test_compare_ctrl_c_says_what_is_kept_and_how_to_resume(capsys, monkeypatch, tmp_path):
    import mitos_cli.study as study_mod

    def interrupted(study, out, *, on_start, on_result, **kwargs):
        on_start(1, 6)
        on_result(None, {})
        on_result(None, {})
        raise KeyboardInterrupt

    monkeypatch.setattr(study_mod, "run_study", interrupted)
    code, _, err = run(capsys, "compare", TINY, "--and", "min,product", "--runs", 2,
                       "-o", tmp_path / "s")
    assert code == 130 and "Traceback" not in err
    assert f"interrupted: 3 of 6 runs kept in {tmp_path / 's' / 'results.csv'}" in err
    assert "(2 now, 1 from before)" in err and err.rstrip().endswith("--resume")


def test_compare_ctrl_c_goes_on_the_way_the_study_was_run(capsys, monkeypatch, tmp_path):
    """The command to go on was the study's alone: a study run with `--no-plots`, `--json` or
    `-j 1` (or on a Dask cluster) went on drawing plots, printing tables, on every core (or
    on the local pool). It keeps the options that say how the study runs and reports."""
    import mitos_cli.study as study_mod

    def interrupted(study, out, *, on_start, on_result, **kwargs):
        on_start(0, 4)
        on_result(None, {})
        raise KeyboardInterrupt

    monkeypatch.setattr(study_mod, "run_study", interrupted)
    code, _, err = run(capsys, "compare", TINY, "--and", "min,product", "--runs", 2,
                       "-o", tmp_path / "s", "-j", 1, "--no-plots", "--json")
    assert code == 130
    last = err.rstrip().splitlines()[-1]
    assert last.endswith(f"-o {tmp_path / 's'} -j 1 --no-plots --json --resume"), last
    code, _, err = run(capsys, "compare", TINY, "--and", "min", "--runs", 2,
                       "-o", tmp_path / "t")
    assert err.rstrip().endswith(f"-o {tmp_path / 't'} --resume")


def test_compare_ctrl_c_counts_a_run_written_as_it_came(capsys, monkeypatch, tmp_path):
    """A Ctrl-C in the fsync of a run's row left the row in results.csv, but uncounted: the
    message said one run fewer than the file held (16 of 48 kept, 17 there)."""
    from mitos_cli.study.store import ResultStore

    append = ResultStore.append
    written: list[dict] = []

    def append_then_ctrl_c(self, row):
        append(self, row)
        written.append(row)
        if len(written) == 2:
            raise KeyboardInterrupt          # (the row is on disk: as in os.fsync's return)

    monkeypatch.setattr(ResultStore, "append", append_then_ctrl_c)
    code, _, err = run(capsys, "compare", TINY, "--planner", "dwa", "--runs", 3, "-j", 1,
                       "-o", tmp_path / "s", "--no-plots")
    assert code == 130 and len(ResultStore(tmp_path / "s").load()) == 2
    assert f"interrupted: 2 of 3 runs kept in {tmp_path / 's' / 'results.csv'} (2 now, 0 " \
           f"from before)" in err


def test_compare_ctrl_c_while_the_report_is_written_says_how_to_write_it(capsys, monkeypatch,
                                                                          tmp_path):
    """A Ctrl-C in the plots exited 130 without a word, report.md perhaps of fewer runs than
    results.csv held."""
    import mitos_cli.study as study_mod

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(study_mod, "write_report", interrupted)
    code, _, err = run(capsys, "compare", TINY, "--planner", "dwa", "--runs", 1, "-j", 1,
                       "-o", tmp_path / "s")
    assert code == 130 and "Traceback" not in err
    assert f"interrupted while writing the report: every run of the study (1 run) is in " \
           f"{tmp_path / 's' / 'results.csv'}; write it with:" in err
    assert err.rstrip().endswith("--resume")


def test_compare_ctrl_c_before_the_study_began_says_start_it_again(capsys, monkeypatch,
                                                                    tmp_path):
    """Stopped before a study was there, `... --resume` would be refused (no study in DIR)."""
    import mitos_cli.study as study_mod

    def interrupted(study, out, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(study_mod, "run_study", interrupted)
    code, _, err = run(capsys, "compare", TINY, "--and", "min", "--runs", 2,
                       "-o", tmp_path / "s")
    assert code == 130 and "Traceback" not in err
    assert f"interrupted before the study began in {tmp_path / 's'}; start it with:" in err
    assert "--resume" not in err and err.rstrip().endswith(str(tmp_path / "s"))


@pytest.mark.skipif(not hasattr(os, "killpg"), reason="process groups")
@pytest.mark.parametrize("executor", ["local", "dask"])
def test_ctrl_c_on_a_compare_pool_leaves_no_worker_tracebacks(tmp_path, executor):
    """A real Ctrl-C reaches the whole process group, workers included (a LocalCluster's
    workers printed distributed's tracebacks and warnings under the "interrupted:" line)."""
    if executor == "dask":
        pytest.importorskip("distributed")
    out = tmp_path / "s"
    args = [sys.executable, "-m", "mitos_cli", "compare", str(TINY), "--and", "min,product",
            "--planner", "fuzzy", "--runs", "6", "-o", str(out), "-j", "2", "--no-plots",
            "--executor", executor]
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    # a test worker (pytest -n) may ignore SIGINT, and an ignored signal stays ignored
    # across exec: the child gets Python's own Ctrl-C back
    proc = subprocess.Popen(args, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        deadline = time.monotonic() + 60
        csv_file = out / "results.csv"
        while time.monotonic() < deadline and proc.poll() is None:
            if csv_file.exists() and len(csv_file.read_text().splitlines()) >= 2:
                break
            time.sleep(0.02)
        os.killpg(proc.pid, signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    if proc.returncode == 0:
        pytest.skip("the study finished before Ctrl-C arrived")
    assert proc.returncode == 130, err
    assert "Traceback" not in err and "ForkPoolWorker" not in err and "Process " not in err
    assert "WARNING" not in err and "ERROR" not in err
    assert "interrupted:" in err and "--resume" in err


def test_live_once_off_a_terminal_ends_with_the_last_frame(capsys):
    code, out, err = run(capsys, "simulate", TINY, "--speed", 0)
    assert code == 0 and "SUCCESS" in out
    assert "(unpaced)" in err and err.count("t = ") == 1        # the last frame, once


def test_gym_human_render_without_a_display_falls_back_to_the_terminal_view(monkeypatch,
                                                                            capsys):
    pytest.importorskip("gymnasium")
    from mitos_cli import gym as mgym
    from mitos_cli.draw import frame
    from mitos_cli.draw.output import DrawError

    def no_display(*args, **kwargs):
        raise DrawError("cannot open a window: no display")

    monkeypatch.setattr(frame, "RunFrame", no_display)
    env = mgym.MitosEnv(TINY, render_mode="human")
    env.reset(seed=1)
    for _ in range(3):
        env.step(env.fuzzy_policy(env.unwrapped._observe()))
        assert env.render() is None
    env.close()
    assert "t =   0.15 s (unpaced)" in capsys.readouterr().err


def test_ctrl_c_in_a_single_run_says_so(capsys, monkeypatch, tmp_path):
    from mitos_cli.sim import loop

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(loop, "simulate", interrupted)
    code, out, err = run(capsys, "simulate", TINY, "--out", tmp_path / "t.csv")
    assert code == 130 and out == ""
    assert err.strip() == "interrupted before the run ended: nothing written"
    assert not (tmp_path / "t.csv").exists()


#: Runs ``mitos ARGS...`` (``python -c DRIVER OUT SIGNAL HOOK ARGS...``) and sends this process
#: the signal SIGNAL at a place HOOK names, so that a test does not depend on how fast the
#: machine runs: ``run`` once the first run of ``--runs`` has finished (the pool's worker
#: processes written to OUT), ``tick`` at the 10th tick of a single run, ``draw`` as its
#: picture is drawn (after the CSV is written). SIGNAL ``WAIT`` sends none: it waits there
#: for one from outside.
SIGNAL_DRIVER = """
import multiprocessing, os, signal, sys
from pathlib import Path

from mitos_cli.cli.app import main
from mitos_cli.draw import world as draw_world
from mitos_cli.sim import loop, runs

out, sig, hook = Path(sys.argv[1]), sys.argv[2], sys.argv[3]
execute, simulate, draw_run = runs._execute, loop.simulate, draw_world.draw_run

def stop():
    if sig == "WAIT":
        signal.pause()
    else:
        os.kill(os.getpid(), getattr(signal, sig))

def stopped_after_the_first_run(jobs, workers):
    for part in execute(jobs, workers):
        yield part
        if len(part) == 3:                       # a run's summary (not a clock)
            out.write_text(" ".join(str(p.pid) for p in multiprocessing.active_children()))
            stop()

def stopped_at_tick_10(*args, **kwargs):
    ticks = []
    def tick(*a, **k):
        ticks.append(1)
        if len(ticks) == 10:
            stop()
    return simulate(*args, **{**kwargs, "on_tick": tick})

def stopped_drawing(*args, **kwargs):
    stop()
    return draw_run(*args, **kwargs)

if hook == "run":
    runs._execute = stopped_after_the_first_run
elif hook == "tick":
    loop.simulate = stopped_at_tick_10
elif hook == "draw":
    draw_world.draw_run = stopped_drawing
sys.argv = ["mitos", *sys.argv[4:]]
main()
"""


def _signalled(tmp_path: Path, sig: str, hook: str, *args: object) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run([sys.executable, "-c", SIGNAL_DRIVER, str(tmp_path / "pids"), sig, hook,
                           *map(str, args)], env=env, cwd=tmp_path, capture_output=True,
                          text=True, timeout=60)


def _alive(pids: list[int]) -> list[int]:
    """Those of ``pids`` still running (not ended, nor a zombie)."""
    alive = []
    for pid in pids:
        try:
            if Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z":
                alive.append(pid)
        except (OSError, IndexError):
            pass
    return alive


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="finds the workers in /proc")
@pytest.mark.parametrize("sig, code", [("SIGTERM", 143), ("SIGHUP", 129), ("SIGINT", 130)])
def test_a_signal_stops_simulate_runs_as_ctrl_c_does(tmp_path, sig, code):
    """`simulate --runs` on a SIGTERM (`kill PID`, a scheduler's time limit) or a SIGHUP (the
    terminal closed) ended without a word, the finished runs lost (exit -15, -1). It stops
    as on Ctrl-C now: the table of the runs that had finished, the same words, the
    workers gone at once; exit 143, 129 (128 + the signal, as a shell says it)."""
    proc = _signalled(tmp_path, sig, "run", "simulate", TINY, "--runs", 40, "-j", 2)
    assert proc.returncode == code, proc.stderr
    gone = time.monotonic() + 1.0
    workers = [int(p) for p in (tmp_path / "pids").read_text().split()]
    while _alive(workers) and time.monotonic() < gone:
        time.sleep(0.01)
    assert len(workers) == 2 and not _alive(workers), "the workers ran on"
    table = proc.stdout.splitlines()
    assert table[0].split()[:2] == ["world", "runs"] and table[1].split()[0] == "tiny"
    done = int(table[1].split()[1])
    assert 1 <= done < 40
    assert proc.stderr == (f"interrupted: the table has the {done} of 40 runs that had "
                           f"finished (their seeds: runs_detail in --json)\n")


@pytest.mark.skipif(not hasattr(os, "openpty") or not Path("/proc/self/stat").exists(),
                    reason="a pseudo-terminal; finds the workers in /proc")
@pytest.mark.parametrize("log", [True, False], ids=["stderr-to-a-file", "stderr-on-it"])
def test_a_closed_terminal_stops_simulate_runs_cleanly(tmp_path, log):
    """The terminal `simulate --runs` runs on is closed (the window, an ssh session): its
    SIGHUP ended the command at once (exit -1), and, answered, every write to the terminal
    gone failed (EIO), so that the stop ended in "cannot write the output: Input/output
    error" and exit 1. It stops with exit 129 now, the words in a log that stderr goes to."""
    import select

    master, slave = os.openpty()
    name = os.ttyname(slave)
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    errors = open(tmp_path / "err.txt", "w") if log else slave     # noqa: SIM115
    proc = subprocess.Popen(
        [sys.executable, "-c", SIGNAL_DRIVER, str(tmp_path / "pids"), "WAIT", "run",
         "simulate", str(TINY), "--runs", "40", "-j", "2"], env=env, cwd=tmp_path,
        stdin=slave, stdout=slave, stderr=errors, start_new_session=True,
        # its controlling terminal, which hangs up when the master closes
        preexec_fn=lambda: os.close(os.open(name, os.O_RDWR)))
    os.close(slave)
    if log:
        errors.close()
    try:
        deadline = time.monotonic() + 30
        while not (tmp_path / "pids").exists() and time.monotonic() < deadline:
            if select.select([master], [], [], 0.05)[0]:
                os.read(master, 65536)                  # (a full terminal would block it)
        assert (tmp_path / "pids").exists(), "no run finished"
        os.close(master)                                # the terminal closes
        code = proc.wait(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    workers = [int(p) for p in (tmp_path / "pids").read_text().split()]
    gone = time.monotonic() + 1.0
    while _alive(workers) and time.monotonic() < gone:
        time.sleep(0.01)
    assert code == 129 and not _alive(workers)
    if log:
        said = (tmp_path / "err.txt").read_text()
        assert said.startswith("interrupted: the table has the ") and said.endswith(
            " of 40 runs that had finished (their seeds: runs_detail in --json)\n"), said


@pytest.mark.parametrize("sig, code", [("SIGTERM", 143), ("SIGHUP", 129)])
def test_a_signal_stops_a_single_run_writing_nothing(tmp_path, sig, code):
    """One run (`simulate WORLD --out --plot --trace`) on a SIGTERM ended without a word;
    now as on Ctrl-C: nothing written, nothing left half-written beside the targets."""
    proc = _signalled(tmp_path, sig, "tick", "simulate", TINY, "--trace", "--out", "t.csv",
                      "--plot", "t.png")
    assert proc.returncode == code, proc.stderr
    assert proc.stdout == ""
    assert proc.stderr == "interrupted before the run ended: nothing written\n"
    assert list(tmp_path.iterdir()) == []


def test_a_sigterm_while_the_files_are_written_says_which_are(tmp_path):
    """A SIGTERM as the picture is drawn: the CSV written whole, no picture and no temporary
    file beside it (saves are atomic, and the one going is removed), said; exit 143."""
    pytest.importorskip("matplotlib")
    proc = _signalled(tmp_path, "SIGTERM", "draw", "simulate", TINY, "--out", "t.csv",
                      "--plot", "t.png")
    assert proc.returncode == 143, proc.stderr
    assert proc.stderr == "interrupted: wrote the ticks to t.csv; the rest is not written\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.csv"]
    assert proc.stdout == ""


@pytest.mark.parametrize("sig, code", [("SIGHUP", 129), ("SIGTERM", 143)])
def test_a_hangup_stops_compare_as_a_sigterm_does(tmp_path, sig, code):
    """A closed terminal's SIGHUP ended `compare` without a word (exit -1), where a SIGTERM
    said what was kept and how to go on: both do now (exit 129, 143)."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    out = tmp_path / "s"
    proc = subprocess.Popen([sys.executable, "-m", "mitos_cli", "compare", str(TINY), "--and",
                             "min", "--planner", "fuzzy", "--runs", "40", "-j", "1", "-o",
                             str(out), "--no-plots"], env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline and proc.poll() is None:
            if (out / "results.csv").exists():      # the study begins (its count follows)
                break
            time.sleep(0.01)
        time.sleep(0.2)
        proc.send_signal(getattr(signal, sig))
        _, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == code, err
    assert f"runs kept in {out / 'results.csv'}" in err and err.rstrip().endswith("--resume")
