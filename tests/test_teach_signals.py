"""`mitos teach` stopped by a SIGTERM (`kill PID`, a scheduler's time limit) or a SIGHUP (the
terminal closed) as by Ctrl-C: its words, 128 + the signal as its exit code, the journal whole,
and `--resume` going on to what an uninterrupted lesson saves, bit for bit. They ended by the
signals' default (exit -15, -1) without a word; converted, a signal must still never land
between a journal line's write and its fsync, so the journal's writes hold them as Ctrl-C."""

import json
import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from mitos_cli.api import default_rulebase_path

RULEBASES = default_rulebase_path().parent

#: The shipped lesson (Figure 4 -> Figure 10), with the world by its packaged name.
LESSON = """\
use drive
simulate figure4
at 9s to 12.75s steering is ST
at 13s to 14.5s make a wider turn
adapt epochs 60 rate 0.5
simulate figure4
"""
COMMANDS = [line for line in LESSON.splitlines() if line]

#: Runs ``mitos ARGS...`` (``python -c DRIVER SIGNAL HOOK N ARGS...``) and sends itself SIGNAL
#: at the N-th time HOOK comes, so that the moment does not depend on the machine's speed:
#: ``fsync`` between a file's write and its fsync (a journal line's, or a save's files'),
#: ``gradient`` as an adaptation works out Q and its gradient (the first before its first
#: epoch, then one an epoch), ``tick`` at a simulated tick.
DRIVER = """
import os, signal, sys

from mitos_cli.cli.app import main
from mitos_cli.sim import loop
from mitos_cli.teach import adapt

sig, hook, n = getattr(signal, sys.argv[1]), sys.argv[2], int(sys.argv[3])
count = [0]

def come():
    count[0] += 1
    if count[0] == n:
        os.kill(os.getpid(), sig)

fsync, gradient, simulate = os.fsync, adapt.gradient, loop.simulate

def synced(fd):
    come()
    fsync(fd)

def descended(*args, **kwargs):
    come()
    return gradient(*args, **kwargs)

def simulated(*args, on_tick=None, **kwargs):
    def tick(*a, **k):
        come()
        if on_tick is not None:
            on_tick(*a, **k)
    return simulate(*args, on_tick=tick, **kwargs)

if hook == "fsync":
    os.fsync = synced
elif hook == "gradient":
    adapt.gradient = descended
elif hook == "tick":
    loop.simulate = simulated
sys.argv = ["mitos", *sys.argv[4:]]
main()
"""

SAVED = ("taught.rules", "taught.mitos.terms.yaml", "taught.drive.terms.yaml")
STOPPED = "interrupted: every change so far is in the journal; `mitos teach --resume --session "


def _env():
    return dict(os.environ, PYTHONUNBUFFERED="1", COLUMNS="120")


def _work(base: Path) -> Path:
    (base / "rb").mkdir(parents=True)
    for f in RULEBASES.iterdir():
        if f.is_file():
            shutil.copy(f, base / "rb" / f.name)
    (base / "wider.lesson").write_text(LESSON)
    return base


def _mitos(cwd, *args, stdin=None):
    return subprocess.run([sys.executable, "-m", "mitos_cli", *args], cwd=cwd, input=stdin,
                          capture_output=True, text=True, env=_env(), timeout=120)


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """What the lesson saves when nothing stops it."""
    work = _work(tmp_path_factory.mktemp("reference"))
    res = _mitos(work, "teach", "rb/mitos.rules", "--lesson", "wider.lesson", "--save-as",
                 "out/taught.rules")
    assert res.returncode == 0, res.stderr
    return {name: (work / "out" / name).read_bytes() for name in SAVED}


def _whole_journal(work: Path) -> list[dict]:
    """The session's journal, checked whole: every line a JSON object ending in a newline,
    numbered 1, 2, ... without a gap or a repeat (`--resume` then says nothing dropped)."""
    (session,) = (work / ".mitos" / "teach").iterdir()
    raw = (session / "journal.jsonl").read_bytes()
    assert raw.endswith(b"\n")
    entries = [json.loads(line) for line in raw.decode().splitlines()]
    assert [e["seq"] for e in entries] == list(range(1, len(entries) + 1))
    return entries


def _the_rest(entries: list[dict]) -> str:
    """The lesson's commands not yet journaled (each command journals one entry), an `adapt`
    cut short taken back and told again: then the resumed session must end where one
    uninterrupted lesson ends."""
    told = [e for e in entries if e["op"] not in ("start", "save")]
    assert [e["line"] for e in told] == COMMANDS[:len(told)]
    if told and told[-1]["op"] == "adapt" and told[-1].get("stopped") == "interrupted":
        return "undo\n" + "\n".join(COMMANDS[len(told) - 1:]) + "\n"
    return "".join(line + "\n" for line in COMMANDS[len(told):])


@pytest.mark.parametrize(("sig", "hook", "n"), [
    ("SIGTERM", "fsync", 2),        # the journal line of `use drive`, before its fsync
    ("SIGTERM", "tick", 150),       # the first run
    ("SIGTERM", "gradient", 2),     # the adaptation's first epoch: nothing learned to keep
    ("SIGTERM", "gradient", 31),    # the adaptation at its 30th epoch: 29 kept, journaled
    ("SIGTERM", "fsync", 6),        # the adaptation's journal line
    ("SIGTERM", "fsync", 9),        # the save at the lesson's end, its files half written
    ("SIGHUP", "fsync", 4),         # the first `at` line's examples
    ("SIGHUP", "gradient", 45),     # the adaptation at its 44th epoch
    ("SIGHUP", "tick", 500),        # the run after the adaptation
], ids=lambda v: str(v))
def test_a_lesson_stopped_by_a_signal_resumes_to_what_an_uninterrupted_one_saves(
        tmp_path, reference, sig, hook, n):
    work = _work(tmp_path)
    res = subprocess.run([sys.executable, "-c", DRIVER, sig, hook, str(n), "teach",
                          "rb/mitos.rules", "--lesson", "wider.lesson", "--save-as",
                          "out/taught.rules"], cwd=work, capture_output=True, text=True,
                         env=_env(), timeout=120)
    assert res.returncode == 128 + getattr(signal, sig), res.stderr
    last = res.stderr.splitlines()[-1]
    assert last.startswith(STOPPED) and last.endswith("` continues"), res.stderr
    assert "Traceback" not in res.stderr
    entries = _whole_journal(work)
    rest = _the_rest(entries)
    resumed = _mitos(work, "teach", "--resume", "--lesson", "-", "--save-as",
                     "out/taught.rules", stdin=rest)
    assert resumed.returncode == 0, resumed.stderr
    said = resumed.stderr.splitlines()[0]
    assert said.startswith("resumed session mitos-") and ";" not in said, said  # nothing dropped
    assert {name: (work / "out" / name).read_bytes() for name in SAVED} == reference
    _whole_journal(work)


def test_where_the_moments_fall(tmp_path):
    """The moments above, counted in an uninterrupted lesson (so that a change of the lesson's
    course shows here, not as a test that stops elsewhere than it says): 12 fsyncs (7
    journal lines, the save's three files and their directory, the save's line), 61
    gradients (one before the first epoch, one an epoch), 294 ticks in the first run and
    496 in the second."""
    work = _work(tmp_path)
    count = DRIVER.replace("main()\n", "try:\n    main()\nfinally:\n"
                           "    print('came', count[0], file=sys.stderr)\n")
    for hook, came in (("fsync", 12), ("gradient", 61), ("tick", 790)):
        shutil.rmtree(work / ".mitos", ignore_errors=True)
        res = subprocess.run([sys.executable, "-c", count, "SIGTERM", hook, "0", "teach",
                              "rb/mitos.rules", "--lesson", "wider.lesson", "--save-as",
                              f"out/{hook}.rules"], cwd=work, capture_output=True, text=True,
                             env=_env(), timeout=120)
        assert res.returncode == 0, res.stderr
        assert res.stderr.splitlines()[-1] == f"came {came}", hook


@pytest.mark.parametrize("sig", ["SIGTERM", "SIGHUP"])
def test_the_prompt_stopped_by_a_signal_ends_with_its_code_and_keeps_the_session(tmp_path, sig):
    """At the prompt, waiting for the next line, Ctrl-C drops the line and reads on; a SIGTERM
    or a SIGHUP cannot be read on from, so the prompt ends as `quit` does (what is unsaved,
    and how to go on), after "interrupted", with 143 or 129."""
    import select
    import time

    work = _work(tmp_path)
    proc = subprocess.Popen([sys.executable, "-m", "mitos_cli", "teach", "rb/mitos.rules"],
                            cwd=work, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=_env())
    try:
        proc.stdin.write("correct road=78 size=45 position=4 -> steering=60\n")
        proc.stdin.flush()
        seen, end = "", time.monotonic() + 60
        while "example 1:" not in seen and time.monotonic() < end:
            if select.select([proc.stdout], [], [], 1.0)[0]:
                seen += os.read(proc.stdout.fileno(), 65536).decode()
        assert "example 1:" in seen
        time.sleep(0.2)                             # back at the prompt, reading
        proc.send_signal(getattr(signal, sig))
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 128 + getattr(signal, sig), err
    (session,) = (work / ".mitos" / "teach").iterdir()
    assert err.splitlines()[-2:] == [
        "interrupted",
        f"unsaved changes are kept in the journal; `mitos teach --resume --session "
        f"{session.name}` continues, `save PATH` writes them"]
    assert [e["op"] for e in _whole_journal(work)] == ["start", "examples"]
    resumed = _mitos(work, "teach", "--resume", "--lesson", "-", stdin="show examples\n")
    assert resumed.returncode == 0, resumed.stderr
    assert "1  road=78 size=45 position=4 -> steering=60" in resumed.stdout


@pytest.mark.parametrize("sig", ["SIGTERM", "SIGHUP"])
def test_an_adaptation_at_the_prompt_stopped_by_a_signal_keeps_its_epochs_and_ends(tmp_path,
                                                                                  sig):
    """Ctrl-C in an `adapt` at the prompt keeps the epochs done and reads on; a SIGTERM or a
    SIGHUP keeps them too (journaled as an adaptation interrupted after 9 epochs), then ends
    the prompt: the next line is not run."""
    work = _work(tmp_path)
    lines = ["correct road=78 size=45 position=4 -> steering=60",
             "correct road=90 size=30 position=-3 -> steering=120", "adapt epochs 40",
             "show history"]
    res = subprocess.run([sys.executable, "-c", DRIVER, sig, "gradient", "11", "teach",
                          "rb/mitos.rules"], cwd=work, input="\n".join(lines) + "\n",
                         capture_output=True, text=True, env=_env(), timeout=120)
    assert res.returncode == 128 + getattr(signal, sig), res.stderr
    assert "changed (before -> after)" in res.stdout      # what the 9 epochs learned
    assert "adapt epochs 40   (Q" not in res.stdout       # `show history` was not run
    assert res.stderr.splitlines()[-2].startswith("interrupted")
    entries = _whole_journal(work)
    assert [e["op"] for e in entries] == ["start", "examples", "examples", "adapt"]
    assert (entries[-1]["stopped"], entries[-1]["ran"]) == ("interrupted", 9)
