"""Atomic writes: the old file or the new one, never half; new files get the usual mode."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from mitos_cli.errors import MitosError, TermSetError
from mitos_cli.fileio import atomic_file, atomic_write


def test_replaces_and_uses_the_umask(tmp_path):
    target = tmp_path / "a.txt"
    old = os.umask(0o022)
    try:
        atomic_write(target, "one")
        atomic_write(target, b"two")
    finally:
        os.umask(old)
    assert target.read_text() == "two"
    assert target.stat().st_mode & 0o777 == 0o644
    assert [p.name for p in tmp_path.iterdir()] == ["a.txt"]


def test_an_error_inside_keeps_the_old_file(tmp_path):
    target = tmp_path / "a.txt"
    target.write_text("old")
    with pytest.raises(RuntimeError), atomic_file(target) as fh:
        fh.write("half")
        raise RuntimeError("crash")
    assert target.read_text() == "old" and len(list(tmp_path.iterdir())) == 1


def test_a_missing_directory_is_the_callers_error(tmp_path):
    with pytest.raises(TermSetError, match="cannot write .*nowhere.*No such file"):
        atomic_write(tmp_path / "nowhere" / "a.txt", "x", error=TermSetError)


@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="a directory no file can be made in")
def test_a_write_that_fails_is_a_write_error(tmp_path):
    """One kind for every command's write failure (export's was a format error), whether
    the check before the work or the write itself finds it."""
    from mitos_cli.errors import WriteError
    from mitos_cli.fileio import check_writable

    with pytest.raises(WriteError) as info:
        atomic_write("/proc/mitos-x.txt", "x")
    assert info.value.kind == "error"
    assert info.value.message.startswith("cannot write `/proc/mitos-x.txt`: ")
    with pytest.raises(WriteError) as info:
        check_writable(tmp_path / "nowhere" / "a.txt")
    assert info.value.message == (f"cannot write `{tmp_path / 'nowhere' / 'a.txt'}`: No such "
                                  f"file or directory")


@pytest.mark.parametrize("under", ["x.csv", "a/x.csv"])
def test_a_file_where_a_directory_goes_is_named(tmp_path, under):
    """`simulate -o notes.txt/x.csv` said "No such file or directory" and hinted to check
    that the directory exists, where it is a file in the way: the check before the work and
    the write itself both name it."""
    from mitos_cli.errors import WriteError
    from mitos_cli.fileio import check_writable

    (tmp_path / "notes.txt").write_text("x\n")
    target = tmp_path / "notes.txt" / under
    for write in (check_writable, lambda p: atomic_write(p, "x")):
        with pytest.raises(WriteError) as info:
            write(target)
        assert info.value.message == (f"cannot write `{target}`: `{tmp_path / 'notes.txt'}` "
                                      f"is a file, not a directory")
        assert info.value.hint == "give a path inside a directory"


def test_replace_failing_is_an_error_and_leaves_nothing(tmp_path, monkeypatch):
    target = tmp_path / "a.txt"
    target.write_text("old")
    monkeypatch.setattr(os, "replace", lambda *a: (_ for _ in ()).throw(OSError("disk full")))
    with pytest.raises(MitosError, match="disk full"):
        atomic_write(target, "new")
    assert target.read_text() == "old" and len(list(tmp_path.iterdir())) == 1


def test_a_link_is_written_through_and_stays_a_link(tmp_path):
    real = tmp_path / "real.txt"
    real.write_text("old", encoding="utf-8")
    link = tmp_path / "link.txt"
    link.symlink_to(real)
    atomic_write(link, "new")
    assert link.is_symlink() and real.read_text(encoding="utf-8") == "new"


@pytest.mark.skipif(not os.path.exists("/dev/null"), reason="needs /dev/null")
def test_a_device_is_written_to_not_replaced():
    import stat

    atomic_write("/dev/null", "nothing to keep")
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)


def test_a_directory_is_refused_by_name(tmp_path):
    with pytest.raises(MitosError, match="it is a directory"):
        atomic_write(tmp_path, "x")


def test_read_text_drops_a_byte_order_mark(tmp_path):
    from mitos_cli.fileio import read_text

    (tmp_path / "a.txt").write_bytes(b"\xef\xbb\xbfroad,size\n")
    assert read_text(tmp_path / "a.txt") == "road,size\n"


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="needs /dev/zero")
def test_read_text_stops_a_device_instead_of_reading_it_without_end():
    from mitos_cli.fileio import read_text

    with pytest.raises(OSError, match="larger than 256 MB"):
        read_text("/dev/zero")


def test_read_text_reads_a_pipe(tmp_path):
    from mitos_cli.fileio import read_text

    fifo = tmp_path / "rows"
    os.mkfifo(fifo)
    pid = os.fork()
    if pid == 0:                                   # the writer: `<(printf ...)`
        with open(fifo, "w") as fh:
            fh.write("road\n1\n")
        os._exit(0)
    try:
        assert read_text(fifo) == "road\n1\n"
    finally:
        os.waitpid(pid, 0)


def test_why_unreadable_says_where_the_bytes_stop_being_text(tmp_path):
    from mitos_cli.fileio import read_text, why_unreadable

    (tmp_path / "b.lesson").write_bytes(b"use drive\nat \xff\n")
    with pytest.raises(UnicodeDecodeError) as info:
        read_text(tmp_path / "b.lesson")
    assert why_unreadable(info.value) == "it is not UTF-8 text (byte 0xff at line 2, column 4)"


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="needs /dev/zero")
@pytest.mark.parametrize("argv", [["eval", "/dev/zero", "road=1"],
                                  ["eval", "--batch", "/dev/zero"]])
def test_a_device_named_as_a_file_is_refused_at_once(argv, capsys):
    from mitos_cli.cli.app import main

    with pytest.raises(SystemExit) as info:
        main(argv)
    assert info.value.code == 1 and "larger than 256 MB" in capsys.readouterr().err


@pytest.mark.skipif(not os.path.exists("/dev/stdout"), reason="needs /dev/stdout")
def test_a_link_to_a_pipe_is_written_through(tmp_path):
    """`convert ... -o /dev/stdout | less`: the link was followed to `/proc/N/fd/pipe:[...]`,
    a name that is not there, and the write failed."""
    import subprocess
    import sys

    code = ("from mitos_cli.fileio import atomic_write; "
            "atomic_write('/dev/stdout', 'through the pipe\\n')")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout == "through the pipe\n"


@pytest.fixture
def links(tmp_path):
    """A loop of two links, a dangling link and a chain of two ending nowhere."""
    (tmp_path / "loop1.yaml").symlink_to("loop2.yaml")
    (tmp_path / "loop2.yaml").symlink_to("loop1.yaml")
    (tmp_path / "dangling.yaml").symlink_to("nonexist.yaml")
    (tmp_path / "a.yaml").symlink_to("b.yaml")
    (tmp_path / "b.yaml").symlink_to("gone.yaml")
    return tmp_path


def test_a_link_that_leads_nowhere_is_said_so(links):
    """A dangling link or a loop is in its directory: it was "not found, did you mean" itself."""
    from mitos_cli.fileio import broken_link

    assert broken_link("world file", links / "dangling.yaml") == (
        f"`{links / 'dangling.yaml'}` is a link to `nonexist.yaml`, which does not exist")
    assert broken_link("world file", links / "a.yaml") == (
        f"`{links / 'a.yaml'}` is a link to `gone.yaml` (through `{links / 'b.yaml'}`), which "
        "does not exist")
    assert broken_link("world file", links / "loop1.yaml") == (
        f"cannot read world file `{links / 'loop1.yaml'}`: Too many levels of symbolic links")
    assert broken_link("world file", links / "nothing.yaml") is None
    (links / "real.yaml").write_text("x")
    (links / "good.yaml").symlink_to("real.yaml")
    assert broken_link("world file", links / "good.yaml") is None


def test_did_you_mean_never_names_the_file_given_nor_a_broken_link(links):
    from mitos_cli.fileio import nearby_name

    assert nearby_name(links / "loop1.yaml", (".yaml",)) is None
    assert nearby_name(links / "dangling.yaml", (".yaml",)) is None
    assert nearby_name(links / "danglin.yaml", (".yaml",)) is None
    (links / "office.yaml").write_text("x")
    assert nearby_name(links / "ofice.yaml", (".yaml",)) == "office.yaml"


def test_did_you_mean_never_names_a_directory(tmp_path, capsys):
    """`mitos eval mitoss.rules` beside a directory `mitos.rules` said "did you mean
    `mitos.rules`?", which was then refused: "`mitos.rules` is a directory"."""
    from mitos_cli.cli.app import main
    from mitos_cli.fileio import nearby_name

    (tmp_path / "mitos.rules").mkdir()
    assert nearby_name(tmp_path / "mitoss.rules") is None
    with pytest.raises(SystemExit) as done:
        main(["eval", str(tmp_path / "mitoss.rules"), "road=1"])
    assert done.value.code == 1
    assert "did you mean" not in capsys.readouterr().err
    (tmp_path / "mitos.fll").write_text("x")
    assert nearby_name(tmp_path / "mitoss.rules") == "mitos.fll"
@pytest.mark.parametrize("mode", [0o600, 0o755, 0o640])
def test_a_file_replaced_keeps_its_permissions(tmp_path, mode):
    """The temporary file that replaced a file had 0666 less the umask: a private (0600) rule
    file saved over became readable by all, an exported script lost its execute bit."""
    from mitos_cli.fileio import atomic_write_set

    one, two = tmp_path / "one.rules", tmp_path / "two.yaml"
    for path in (one, two):
        path.write_text("old\n")
        path.chmod(mode)
    atomic_write(one, "new\n")
    assert one.read_text() == "new\n" and one.stat().st_mode & 0o777 == mode
    atomic_write_set([(two, "new\n"), (one, "newer\n")], one)
    assert {p.stat().st_mode & 0o777 for p in (one, two)} == {mode}


@pytest.mark.parametrize("argv, name", [
    (["simulate", "figure4", "--out", "{}"], "out.csv"),
    (["simulate", "figure4", "--plot", "{}"], "out.png"),
    (["convert", "{rules}", "--to", "fis", "-b", "avoid_obstacle", "-o", "{}"], "out.fis"),
    (["convert", "{rules}", "--to", "rules", "-b", "avoid_obstacle", "-o", "{}"], "out.rules"),
    (["export", "{rules}", "--to", "python", "-o", "{}"], "out.py"),
    (["plot", "terms", "{rules}", "-o", "{}"], "out.png"),
    (["teach", "{rules}", "--save-as", "{}"], "out.rules"),
])
def test_an_output_named_by_a_link_in_a_loop_is_refused(tmp_path, capsys, monkeypatch, argv,
                                                         name):
    """`Path.resolve` of a link in a loop raised a RuntimeError: every command writing a file
    there ended in a traceback."""
    from mitos_cli.api import default_rulebase_path
    from mitos_cli.cli.app import main
    from mitos_cli.fileio import check_writable

    monkeypatch.chdir(tmp_path)
    stem, suffix = name.split(".")
    (tmp_path / name).symlink_to(f"{stem}2.{suffix}")
    (tmp_path / f"{stem}2.{suffix}").symlink_to(name)
    rules = str(default_rulebase_path())
    with pytest.raises(SystemExit) as info:
        main([a.format(tmp_path / name, rules=rules) for a in argv])
    err = capsys.readouterr().err
    assert info.value.code == 1 and "Too many levels of symbolic links" in err, err
    assert "Traceback" not in err and (tmp_path / name).is_symlink()
    with pytest.raises(MitosError, match="symbolic links"):
        check_writable(tmp_path / name)
    with pytest.raises(MitosError, match="symbolic links"):
        atomic_write(tmp_path / name, "x")
