"""Atomic writes: the old file or the new one, never half; new files get the usual mode."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

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


ROOT = Path(__file__).resolve().parents[1]

#: Each of the readers of text files, as a user meets it: (what is written, how the command
#: line reads it).
READERS = {
    "rule file": ("rb/a.rules", ["check", "rb/a.rules"]),
    "term set": ("rb/mitos.terms.yaml", ["check", "rb/mitos.rules"]),
    "world": ("w.yaml", ["simulate", "w.yaml"]),
    "map YAML": ("office02.yaml", ["simulate", "office.yaml"]),
    "lesson": ("a.lesson", ["teach", "rb/mitos.rules", "--lesson", "a.lesson"]),
    "lesson on stdin": ("-", ["teach", "rb/mitos.rules", "--lesson", "-"]),
    "batch CSV": ("b.csv", ["eval", "rb/mitos.rules", "--batch", "b.csv"]),
    "batch CSV on stdin": ("-", ["eval", "rb/mitos.rules", "--batch", "-"]),
    ".fis": ("t.fis", ["check", "t.fis"]),
    ".fcl": ("t.fcl", ["check", "t.fcl"]),
    ".fll": ("t.fll", ["check", "t.fll"]),
}

#: How each encoding is written, its words, and where its first NUL byte is in ``ab...``.
ENCODINGS = {
    "UTF-16LE": (lambda t: t.encode("utf-16-le"),
                 "UTF-16 text (little-endian, without a byte-order mark)", 2),
    "UTF-16BE": (lambda t: t.encode("utf-16-be"),
                 "UTF-16 text (big-endian, without a byte-order mark)", 1),
    "UTF-16LE with its mark": (lambda t: b"\xff\xfe" + t.encode("utf-16-le"),
                               "UTF-16 text (little-endian, with its byte-order mark)", 4),
    "UTF-16BE with its mark": (lambda t: b"\xfe\xff" + t.encode("utf-16-be"),
                               "UTF-16 text (big-endian, with its byte-order mark)", 3),
}


def _good_files(tmp_path: Path) -> dict[str, str]:
    """The UTF-8 text of each reader's file, which reads."""
    import shutil

    rulebases = ROOT / "rulebases"
    (tmp_path / "rb").mkdir()
    for f in rulebases.iterdir():
        if f.is_file():
            shutil.copy(f, tmp_path / "rb" / f.name)
    (tmp_path / "mrpb_office02.pgm").write_bytes((ROOT / "worlds/maps/mrpb_office02.pgm").read_bytes())
    office = (ROOT / "worlds/office.yaml").read_text().replace("maps/mrpb_office02.yaml",
                                                                 "office02.yaml")
    (tmp_path / "office.yaml").write_text(office)
    interop = ROOT / "tests/data/interop"
    return {
        "rb/a.rules": (rulebases / "mitos.rules").read_text(),
        "rb/mitos.terms.yaml": (rulebases / "mitos.terms.yaml").read_text(),
        "w.yaml": (ROOT / "tests/data/tiny.yaml").read_text(),
        "office02.yaml": (ROOT / "worlds/maps/mrpb_office02.yaml").read_text(),
        "a.lesson": "use drive\nshow rules\n",
        "b.csv": "road,size,position\n78,45,4\n",
        "t.fis": (interop / "tipper.fis").read_text(),
        "t.fcl": (interop / "dimmer_fuzzylite.fcl").read_text(),
        "t.fll": (interop / "check_formula_input.fll").read_text(),
    }


def _run(argv: list[str], stdin: bytes | None, capsys, monkeypatch) -> tuple[int, str]:
    import io
    import sys

    from mitos_cli.cli.app import main

    if stdin is not None:
        monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(stdin)))
    with pytest.raises(SystemExit) as info:
        main(argv)
    return info.value.code, capsys.readouterr().err


@pytest.mark.parametrize("encoding", ENCODINGS)
@pytest.mark.parametrize("reader", READERS)
def test_a_file_in_utf16_is_said_to_be_so_by_every_reader(tmp_path, monkeypatch, capsys, reader,
                                                          encoding):
    """A UTF-16 file without its byte-order mark (`iconv -t UTF-16LE`) was refused at its
    first NUL as "unexpected character '\\x00'" (valid UTF-8: ASCII with a NUL after each
    character), with its mark as "not a text file (byte 0xff is not UTF-8)"; each reader now
    says what it looks like, where its first NUL byte is, and to save it as UTF-8."""
    monkeypatch.chdir(tmp_path)
    texts = _good_files(tmp_path)
    name, argv = READERS[reader]
    encode, words, column = ENCODINGS[encoding]
    text = texts["a.lesson" if "lesson" in reader else "b.csv" if "CSV" in reader else name]
    data = encode(text)
    stdin = data if name == "-" else None
    if stdin is None:
        (tmp_path / name).write_bytes(data)
    code, err = _run(argv, stdin, capsys, monkeypatch)
    shown = "<stdin>" if name == "-" else name
    assert code == 1, err
    head, hint = err.splitlines()[0], err.splitlines()[-1]
    assert head.startswith(f"{shown}:1:{column}: ")
    assert head.endswith(f"looks like {words}, not UTF-8 (its first NUL byte is at line 1, "
                         f"column {column})")
    iconv = encoding.split()[0] if "mark" not in encoding else "UTF-16"
    assert hint == (f'hint: save it as UTF-8 (an editor\'s "save with encoding", or `iconv -f '
                    f'{iconv} -t UTF-8 FILE > NEW`)')


@pytest.mark.parametrize("reader", READERS)
def test_every_reader_reads_its_utf8_file(tmp_path, monkeypatch, capsys, reader):
    """The same files in UTF-8 (the check above refuses only UTF-16)."""
    monkeypatch.chdir(tmp_path)
    texts = _good_files(tmp_path)
    name, argv = READERS[reader]
    for file, text in texts.items():
        (tmp_path / file).write_text(text)
    stdin = (texts["a.lesson"] if "lesson" in reader else texts["b.csv"]).encode() \
        if name == "-" else None
    if reader == "map YAML":
        argv = [*argv, "--json"]
    code, err = _run(argv, stdin, capsys, monkeypatch)
    assert code == 0, err


def test_the_whole_message_of_a_utf16_rule_file(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "a.rules").write_bytes("r1: if road is NARROW then steering is LB\n"
                                       .encode("utf-16-le"))
    code, err = _run(["check", "a.rules"], None, capsys, monkeypatch)
    assert code == 1
    assert err == (
        "a.rules:1:2: rule base error: `a.rules` looks like UTF-16 text (little-endian, without "
        "a byte-order mark), not UTF-8 (its first NUL byte is at line 1, column 2)\n"
        "hint: save it as UTF-8 (an editor's \"save with encoding\", or `iconv -f UTF-16LE -t "
        "UTF-8 FILE > NEW`)\n")


@pytest.mark.parametrize(("codec", "encoding"), [
    ("utf-16-le", "UTF-16LE"), ("utf-16-be", "UTF-16BE"), ("utf-32-le", "UTF-32LE"),
    ("utf-32-be", "UTF-32BE"), ("utf-16", "UTF-16"), ("utf-32", "UTF-32")])
@given(text=st.text(st.characters(max_codepoint=0xFF, blacklist_characters="\x00"),
                    min_size=2, max_size=300))
def test_text_below_u0100_in_utf16_or_utf32_is_told_by_its_nul_bytes(codec, encoding, text):
    from mitos_cli.fileio import WideText, decode_text, wide_text

    data = text.encode(codec)
    found = wide_text(data)
    assert isinstance(found, WideText) and found.encoding == encoding
    assert found.start == data.find(b"\0") >= 0
    with pytest.raises(WideText):
        decode_text(data)


@given(text=st.text(st.characters(blacklist_characters="\x00")),
       nuls=st.lists(st.integers(0, 10_000), max_size=3), mark=st.booleans())
def test_utf8_text_is_never_taken_for_utf16(text, nuls, mark):
    """A legitimate UTF-8 text (no NUL) reads as it is, with or without its mark; a stray NUL
    or three in it are left to the reader to refuse at their place, not said to be UTF-16."""
    from mitos_cli.fileio import decode_text, wide_text

    data = (b"\xef\xbb\xbf" if mark else b"") + text.encode()
    assert decode_text(data) == data.decode("utf-8-sig")
    if len(text) > 40:
        for at in nuls:
            at %= len(data)
            data = data[:at] + b"\0" + data[at:]
        assert wide_text(data) is None
