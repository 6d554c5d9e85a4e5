"""The `mitos` app: every command is listed, and each invocation builds only its command."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
import typer.main

from mitos_cli.cli.app import COMMANDS, build_app


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "mitos_cli", *args], capture_output=True,
                          text=True)


def test_help_lists_every_command() -> None:
    out = run("--help")
    assert out.returncode == 0
    for name in COMMANDS:
        assert name in out.stdout


def test_one_command_is_built_alone_and_runs() -> None:
    group = typer.main.get_group(build_app("eval"))
    assert sorted(group.commands) == ["eval"]
    assert sorted(typer.main.get_group(build_app()).commands) == sorted(COMMANDS)
    out = run("eval", "road=78", "size=45", "position=4")
    assert out.returncode == 0 and "steering = 65.4 deg" in out.stdout


def test_unknown_command_is_a_usage_error_with_a_suggestion() -> None:
    out = run("evl", "road=78")
    assert out.returncode == 2
    assert "No such command 'evl'" in out.stderr and "Did you mean 'eval'?" in out.stderr


def test_version_is_the_package_version() -> None:
    from pathlib import Path

    from mitos_cli import __version__

    out = run("--version")
    assert out.returncode == 0 and out.stdout == f"mitos {__version__}\n"
    said = run("version")                # as `git version`: it was "No such command", exit 2
    assert (said.returncode, said.stdout, said.stderr) == (0, out.stdout, "")
    pyproject = (Path(__file__).parent.parent / "pyproject.toml").read_text()
    assert 'dynamic = ["version"]' in pyproject          # one source: mitos_cli/_version.py
    from importlib.metadata import version

    from mitos_cli.errors import DISTRIBUTION

    assert version(DISTRIBUTION) == __version__         # what pip installed says the same


def test_version_has_a_help_and_takes_no_argument() -> None:
    """`mitos version --help` and `mitos help version` said "No such command 'version'"
    (exit 2) while `mitos version` printed the version; `mitos help help` said the same of
    `help`."""
    helped = run("version", "--help")
    assert helped.returncode == 0 and helped.stderr == ""
    assert "Usage: mitos version" in helped.stdout and "mitos --version" in helped.stdout
    assert run("help", "version").stdout == helped.stdout
    extra = run("version", "now")
    assert extra.returncode == 2 and "unexpected extra argument" in extra.stderr and "(now)" in extra.stderr
    assert "No such command" not in extra.stderr
    threads = subprocess.run([sys.executable, "-m", "mitos_cli", "version"], text=True,
                             capture_output=True, env={**os.environ, "MITOS_NUM_THREADS": "x"})
    assert threads.returncode == 0 and threads.stdout.startswith("mitos ")   # as --version
    twice = run("help", "help")
    assert twice.returncode == 0 and twice.stdout == run("--help").stdout


def test_a_value_outside_an_options_names_is_a_mistake_in_a_value(capsys) -> None:
    """As an unknown planner or T-norm: a usage error (exit 2, as Typer's own choice check
    said, and as `--seed -1` is), with the names and "did you mean" (which Typer's check did
    not give). Any case is read."""
    import pytest

    from mitos_cli.cli.app import main

    cases = [
        (["convert", "rulebases/mitos.rules", "--to", "fsl"], "unknown format `fsl`", "fll"),
        (["export", "rulebases/mitos.rules", "--to", "pyhton"], "unknown export language",
         "python"),
        (["eval", "road=78", "size=45", "position=4", "--fidelity", "matlb"],
         "unknown engine `matlb`", "matlab"),
        (["eval", "--batch", "-", "--on-no-rule", "skp"], "unknown --on-no-rule policy", "skip"),
        (["plot", "surface", "steering", "--x", "road", "--style", "heat"], "unknown style",
         "heatmap"),
    ]
    for args, message, meant in cases:
        with pytest.raises(SystemExit) as info:
            main(args)
        err = capsys.readouterr().err
        assert info.value.code == 2 and message in err, err
        assert err.startswith("usage error: "), err
        assert f"did you mean `{meant}`?" in err, err
    with pytest.raises(SystemExit) as info:
        main(["export", "rulebases/mitos.rules", "--to", "PYTHON"])
    assert info.value.code == 0 and "def evaluate(X" in capsys.readouterr().out


def test_an_options_names_are_shown_and_completed() -> None:
    import os

    assert "[c|python]" in run("export", "-h").stdout
    env = {**os.environ, "_MITOS_COMPLETE": "complete_bash",
           "COMP_WORDS": "mitos convert tipper.fis --to f", "COMP_CWORD": "4"}
    out = subprocess.run([sys.executable, "-m", "mitos_cli"], env=env, capture_output=True,
                         text=True)
    assert out.stdout.split() == ["fcl", "fis", "fll"]


def test_a_reader_that_stops_early_is_what_the_readme_says(tmp_path) -> None:
    """README, "A reader that stops early": a trace larger than the pipe's buffer ends with
    exit 1 and nothing on stderr; the default trace fits in it, and its exit (0 or 1) is a
    race between the verdict written after it and ``head`` exiting, quiet either way."""
    import os
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    env = dict(os.environ, PYTHONPATH=str(root))
    mitos = f"{sys.executable} -m mitos_cli simulate --trace"
    for extra, codes in ((" --every 1", {1}), ("", {0, 1})):
        res = subprocess.run(["bash", "-c", f"{mitos}{extra} 2>{tmp_path / 'err'} | head -1; "
                              "exit ${PIPESTATUS[0]}"], capture_output=True, text=True,
                             env=env, cwd=tmp_path, timeout=120)
        assert res.returncode in codes, extra
        assert res.stdout.startswith("--- tick 0, t = 0.00 s")
        assert (tmp_path / "err").read_text() == ""
    readme = " ".join((root / "README.md").read_text(encoding="utf-8").split())
    assert "(`mitos simulate --trace --every 1 | head -1`) ends the command quietly, with " \
           "exit 1" in readme


@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="a directory no file can be made in")
@pytest.mark.parametrize("args, target", [
    (["export", "rulebases/mitos.rules", "--to", "c", "-o"], "/proc/mitos-x.c"),
    (["convert", "mitos", "--to", "fll", "-o"], "/proc/mitos-x.fll"),
    (["simulate", "corridor", "--out"], "/proc/mitos-x.csv"),
    (["plot", "terms", "--var", "road", "-o"], "/proc/mitos-x.png"),
])
def test_a_file_that_cannot_be_written_is_said_alike_by_every_command(args, target) -> None:
    """`export -o /proc/x.c` said "format error: cannot write ...", `simulate` "error: cannot
    write ...": one kind of error (WriteError), one wording."""
    proc = run(*args, target)
    assert proc.returncode == 1, proc.stderr
    said = [line for line in proc.stderr.splitlines() if "cannot write" in line]
    assert len(said) == 1 and said[0].startswith(f"error: cannot write `{target}`: "), \
        proc.stderr
    assert "Traceback" not in proc.stderr


def test_a_ctrl_c_in_pythons_clean_up_ends_the_process_without_a_word(tmp_path) -> None:
    """A Ctrl-C landing after the command, in Python's clean-up (here: the clean-up that joins
    the batch threads), printed "Exception ignored ... KeyboardInterrupt" and exited 0. It
    ends the process as the signal does now, after what the command wrote is flushed."""
    import os
    import signal

    root = Path(__file__).resolve().parents[1]
    script = ("import os, signal, sys, threading, time\n"
              "def ctrl_c():\n"
              "    os.kill(os.getpid(), signal.SIGINT)\n"
              "    time.sleep(1)\n"
              "threading._register_atexit(ctrl_c)\n"
              "sys.argv = ['mitos', 'list', '--json']\n"
              "import runpy\n"
              "runpy.run_module('mitos_cli', run_name='__main__')\n")
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          cwd=tmp_path, env=dict(os.environ, PYTHONPATH=str(root)), timeout=120)
    assert proc.stderr == ""
    assert proc.returncode == -signal.SIGINT
    assert proc.stdout.rstrip().endswith("}")          # the JSON, whole


def test_a_ctrl_c_before_the_command_runs_exits_130_without_a_traceback(monkeypatch) -> None:
    """While Typer builds the command (before it answers Ctrl-C itself), a Ctrl-C printed a
    traceback of Typer's inspection of the signatures."""
    import mitos_cli.cli.app as app

    def interrupted(only=None):
        raise KeyboardInterrupt

    monkeypatch.setattr(app, "build_app", interrupted)
    try:
        app.main(["eval", "road=78"])
    except KeyboardInterrupt:
        pytest.fail("the Ctrl-C went through main as a traceback")
    except SystemExit as exc:
        assert exc.code == 130


def test_a_closed_stdout_or_stderr_is_said_or_kept_out_of_the_data(tmp_path) -> None:
    """`>&-`: Python makes sys.stdout None, and every command that prints ended in an
    AttributeError's traceback (`--help`: nothing, exit 0). `2>&-`: its warnings and errors
    were printed into stdout, the first line of an exported C file."""
    import os

    root = Path(__file__).resolve().parents[1]
    env = dict(os.environ, PYTHONPATH=str(root))
    mitos = f"{sys.executable} -m mitos_cli"
    for args in ("eval road=78 size=45 position=4", "list", "--help"):
        proc = subprocess.run(["bash", "-c", f"{mitos} {args} >&-"], capture_output=True,
                              text=True, env=env, cwd=root, timeout=120)
        assert proc.returncode == 1, (args, proc.stderr)
        assert proc.stderr == "error: cannot write the output: standard output is closed\n" \
                              "hint: write it to a file, or to /dev/null to drop it\n", args
    proc = subprocess.run(["bash", "-c", f"{mitos} export rulebases/mitos.rules --to c 2>&-"],
                          capture_output=True, text=True, env=env, cwd=root, timeout=120)
    assert proc.returncode == 0
    assert proc.stdout.startswith("/* Generated by `mitos export --to c`"), proc.stdout[:200]


@pytest.mark.parametrize("name, value", [("COLUMNS", "0"), ("COLUMNS", "3"),
                                         ("COLUMNS", "99999999999"), ("TERMINAL_WIDTH", "abc")])
def test_a_terminal_width_out_of_reason_still_shows_the_message(name, value) -> None:
    """COLUMNS=0 (as some CI runners set it) printed an empty help and a usage error without
    its message (exit 2, nothing said); COLUMNS=3 cut the message to pieces; COLUMNS of 11
    digits ended in a MemoryError, a TERMINAL_WIDTH not a number in a ValueError."""
    import os

    env = {**os.environ, name: value}
    proc = subprocess.run([sys.executable, "-m", "mitos_cli", "eval", "--jsn"], env=env,
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    said = " ".join(proc.stderr.replace("│", " ").split())         # (wrapped at 20)
    assert "No such option: --jsn (Possible options: --json)" in said, proc.stderr
    proc = subprocess.run([sys.executable, "-m", "mitos_cli", "--help"], env=env,
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0 and "Usage: mitos" in proc.stdout, proc.stderr
    assert max(len(line) for line in proc.stdout.splitlines()) <= 1000


def test_the_names_of_every_fixed_list_are_read_in_any_case(capsys) -> None:
    """`--to FLL`, `--style HEATMAP` and `--fidelity MATLAB` were read, `--planner DWA`,
    `--and MIN` and `--executor LOCAL` refused ("unknown planner `DWA`, did you mean `dwa`?",
    exit 2). Each is read now: these commands go on to the world, which is not there (exit 1)."""
    from mitos_cli.cli.app import main

    for args in (["simulate", "nosuch", "--planner", "DWA"],
                 ["compare", "nosuch", "--planner", "DWA,Fuzzy", "--and", "MIN", "--or", "Max",
                  "--inference", "MAMDANI", "--executor", "LOCAL"]):
        with pytest.raises(SystemExit) as info:
            main(args)
        err = capsys.readouterr().err
        assert info.value.code == 1 and "world file `nosuch` not found" in err, err


def test_a_closed_stdin_reads_as_empty() -> None:
    """`<&-`: Python makes sys.stdin None, and `eval --batch -`, `teach --lesson -` and the
    teaching prompt ended in an AttributeError's traceback."""
    import os

    root = Path(__file__).resolve().parents[1]
    env = dict(os.environ, PYTHONPATH=str(root))
    proc = subprocess.run(["bash", "-c", f"{sys.executable} -m mitos_cli eval --batch - <&-"],
                          capture_output=True, text=True, env=env, cwd=root, timeout=120)
    assert proc.returncode == 1
    assert proc.stderr.startswith("<stdin>:1:1: input error: the batch CSV is empty\n")


def test_output_its_encoding_cannot_write_is_said() -> None:
    """PYTHONIOENCODING=ascii (or an ASCII or Latin-1 locale, a Windows code page): the plots'
    Braille or a table's `±` ended in a UnicodeEncodeError's traceback."""
    import os

    env = {**os.environ, "PYTHONIOENCODING": "ascii"}
    proc = subprocess.run([sys.executable, "-m", "mitos_cli", "plot", "terms", "--var", "road"],
                          env=env, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 1 and "Traceback" not in proc.stderr
    assert proc.stderr == ("error: cannot write the output: standard output's encoding (ascii) "
                           "has no `\\u2524` (U+2524)\n"
                           "hint: set PYTHONIOENCODING=utf-8, or use a UTF-8 locale\n")


def test_a_ctrl_c_while_the_last_output_is_flushed_is_not_a_traceback(tmp_path) -> None:
    """The output left in stdout's buffer is flushed once the command is done, which a slow
    reader can hold up; a Ctrl-C there escaped main as a traceback. It ends the process as
    the signal does, as one in the clean-up after it does."""
    import os
    import signal

    root = Path(__file__).resolve().parents[1]
    script = ("import io, os, runpy, signal, sys, time\n"
              "class Held(io.StringIO):\n"
              "    def flush(self):\n"
              "        os.kill(os.getpid(), signal.SIGINT)\n"
              "        time.sleep(1)\n"
              "sys.stdout = Held()\n"
              "sys.argv = ['mitos', 'list', '--json']\n"
              "runpy.run_module('mitos_cli', run_name='__main__')\n")
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          cwd=tmp_path, env=dict(os.environ, PYTHONPATH=str(root)), timeout=120)
    assert proc.stderr == "" and proc.returncode == -signal.SIGINT


def test_no_argument_shows_a_type_name_in_help():
    """Typer prints an argument's type beside its metavar (`<str>`, `<file_arg>`), which tells a
    user nothing the metavar does not; every positional argument's type leaves it out."""
    import re

    from typer.testing import CliRunner

    app = build_app()
    runner = CliRunner()
    group = typer.main.get_command(app)

    def commands(cmd, words):
        subs = getattr(cmd, "commands", {})
        yield words
        for name, sub in subs.items():
            yield from commands(sub, [*words, name])

    seen = 0
    for words in commands(group, []):
        out = runner.invoke(app, [*words, "--help"], env={"COLUMNS": "160"}).output
        assert not re.search(r"<(str|function|file_arg|text)>", out), (words, out)
        seen += "Arguments" in out
    assert seen >= 10
