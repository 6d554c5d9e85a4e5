"""Nothing a user reads runs code: each attack is planted as it used to work, and runs nothing.

1. Lark's ``cache=True`` unpickled ``$TMPDIR/.lark_cache_*.tmp``, which any account may plant;
2. the rule-base cache unpickled whatever lay in its directory;
(3. generated code and 4. the local Dask cluster have their own tests: test_export_hostile.py,
test_study_dask.py.)
"""

from __future__ import annotations

import hashlib
import hmac
import os
import pickle
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from mitos_cli import api
from mitos_cli.lang import cache
from mitos_cli.lang.resolve import load_rules_file

REPO = Path(__file__).resolve().parents[1]


class Payload:
    """A pickle that, when loaded, creates the file ``marker``: proof that code ran."""

    def __init__(self, marker: Path):
        self.marker = marker

    def __reduce__(self):
        return (exec, (f"open({str(self.marker)!r}, 'w').write('ran')",))


def evil(marker: Path) -> bytes:
    return pickle.dumps(Payload(marker))


OLD_STYLE = """
from lark import Lark
from mitos_cli.resources import grammar_text
Lark(grammar_text(), parser="lalr", propagate_positions=True, maybe_placeholders=True,
     start=["start", "rule", "expr"], cache=True)
"""


def test_a_lark_cache_planted_in_tmpdir_runs_nothing(tmp_path):
    tmpdir, marker = tmp_path / "tmp", tmp_path / "ran"
    tmpdir.mkdir()
    env = dict(os.environ, TMPDIR=str(tmpdir), MITOS_CACHE_DIR=str(tmp_path / "cache"))
    # The attack: let Lark name its cache file, then replace what follows its hash line.
    subprocess.run([sys.executable, "-c", OLD_STYLE], env=env, check=True)
    (planted,) = tmpdir.glob(".lark_cache_*.tmp")
    planted.write_bytes(planted.read_bytes().split(b"\n", 1)[0] + b"\n" + evil(marker))
    subprocess.run([sys.executable, "-c", OLD_STYLE], env=env, check=True)
    assert marker.exists()                              # how the parsers used to be built
    marker.unlink()

    done = subprocess.run([sys.executable, "-m", "mitos_cli", "eval", "road=78", "size=45",
                           "position=4"], env=env, capture_output=True, text=True)
    assert done.returncode == 0 and "steering" in done.stdout
    assert not marker.exists()


def test_no_parser_reads_or_writes_the_shared_temporary_directory(tmp_path):
    tmpdir = tmp_path / "tmp"
    tmpdir.mkdir()
    env = dict(os.environ, TMPDIR=str(tmpdir), MITOS_CACHE_DIR=str(tmp_path / "cache"))
    script = ("from mitos_cli import parse\nfrom mitos_cli.teach import commands\n"
              "from mitos_cli.interop import fcl, fll\n"
              "parse.parser(); commands.parser(); fcl.parser(); fll.rule_parser()\n")
    for _ in range(2):                                   # building, then loading the analyses
        subprocess.run([sys.executable, "-c", script], env=env, check=True)
    assert list(tmpdir.iterdir()) == []
    assert len(list((tmp_path / "cache").glob("grammar-*.pickle"))) == 4


# ---- the rule-base cache ---------------------------------------------------------------------

@pytest.fixture()
def rules(tmp_path, monkeypatch):
    monkeypatch.setenv("MITOS_CACHE_DIR", str(tmp_path / "cache"))
    for name in ("mitos.rules", "mitos.terms.yaml", "drive.terms.yaml"):
        shutil.copy(REPO / "rulebases" / name, tmp_path / name)
    return tmp_path / "mitos.rules"


def entry_of(rules: Path) -> Path:
    return Path(os.environ["MITOS_CACHE_DIR"]) / cache.rulebase_entry(rules, rules.read_bytes())


def test_a_planted_rulebase_entry_is_never_unpickled(rules, tmp_path):
    marker = tmp_path / "ran"
    api.read_rulebase(rules)                              # the directory and its key exist
    entry = entry_of(rules)
    entry.write_bytes(evil(marker))                       # untagged, as the old cache took it
    assert api.read_rulebase(rules) == load_rules_file(rules)
    forged = evil(marker)                                 # tagged with a key that is not ours
    entry.write_bytes(hmac.new(b"k" * 32, entry.name.encode() + b"\0" + forged,
                               hashlib.sha256).digest() + forged)
    assert api.read_rulebase(rules) == load_rules_file(rules)
    assert not marker.exists()


def test_a_directory_others_can_write_is_refused_with_a_warning(rules, tmp_path, capsys):
    marker, where = tmp_path / "ran", tmp_path / "cache"
    where.mkdir(mode=0o700)
    where.chmod(0o777)                # anyone may put a key and an entry tagged with it there
    key = b"x" * 32
    (where / "key").write_bytes(key)
    (where / "key").chmod(0o600)
    name = cache.rulebase_entry(rules, rules.read_bytes())
    payload = evil(marker)
    (where / name).write_bytes(cache._tag(key, name, payload) + payload)
    cache._warn.cache_clear()
    assert api.read_rulebase(rules) == load_rules_file(rules)
    assert not marker.exists()
    assert "writable by its group or others (mode 0777)" in capsys.readouterr().err
    assert cache.status().path is None


def test_a_directory_of_another_user_is_refused(rules, tmp_path, monkeypatch):
    where = tmp_path / "cache"
    where.mkdir(mode=0o700)
    monkeypatch.setattr(os, "geteuid", lambda: where.stat().st_uid + 1)
    st = cache.status()
    assert st.path is None and st.refused and "belongs to another user" in st.reason


def test_a_key_others_can_read_is_not_used(rules, tmp_path):
    api.read_rulebase(rules)
    key = tmp_path / "cache" / "key"
    key.chmod(0o644)
    entry = entry_of(rules)
    assert cache.load_entry(entry.name) is None
    assert api.read_rulebase(rules) == load_rules_file(rules)


def test_the_directory_is_made_private(rules, tmp_path):
    api.read_rulebase(rules)
    where = tmp_path / "cache"
    assert where.stat().st_mode & 0o777 == 0o700
    assert (where / "key").stat().st_mode & 0o777 == 0o600
    assert entry_of(rules).stat().st_mode & 0o077 == 0


def test_a_linked_cache_directory_is_checked_and_used_where_it_leads(rules, tmp_path,
                                                                    monkeypatch):
    """A symbolic link as the cache directory was followed, then used by its name: the cache
    is now the directory it leads to (checked as any other), so a link changed after the
    check leads nowhere new; a link to a directory others may write is refused."""
    target = tmp_path / "elsewhere"
    target.mkdir(mode=0o700)
    link = tmp_path / "linked"
    link.symlink_to(target)
    monkeypatch.setenv("MITOS_CACHE_DIR", str(link))
    assert cache.status().path == target.resolve()
    api.read_rulebase(rules)
    assert (target / "key").exists() and entry_of(rules).exists()
    target.chmod(0o777)
    st = cache.status()
    assert st.path is None and st.refused and f"{target.resolve()} is writable" in st.reason


def test_a_cache_directory_that_is_a_link_to_nothing_is_said_so(tmp_path, monkeypatch):
    """A dangling link as the cache directory said "cannot create ...: File exists"."""
    (tmp_path / "linked").symlink_to(tmp_path / "gone")
    monkeypatch.setenv("MITOS_CACHE_DIR", str(tmp_path / "linked"))
    st = cache.status()
    assert st.path is None and st.reason == (f"no cache: {tmp_path / 'linked'} is a symbolic "
                                             f"link to {tmp_path / 'gone'}, which does not exist")


@pytest.mark.skipif(not hasattr(os, "lchown") or os.geteuid() != 0,
                    reason="giving a link to another user takes root")
def test_a_link_of_another_user_on_the_way_to_the_cache_is_refused(tmp_path, monkeypatch):
    """A link another user made (in a shared XDG_CACHE_HOME) could lead the cache to any
    directory of ours, which passes the checks: refused, naming the link."""
    target = tmp_path / "mine"
    target.mkdir(mode=0o700)
    shared = tmp_path / "shared"
    shared.mkdir()
    (shared / "mitos").symlink_to(target)
    os.lchown(shared / "mitos", 4242, 4242)
    monkeypatch.delenv("MITOS_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(shared))
    st = cache.status()
    assert st.path is None and st.refused
    assert st.reason == (f"no cache: {shared / 'mitos'} is a symbolic link of another user "
                         f"(uid 4242); set MITOS_CACHE_DIR to a directory of yours")
    assert not (target / "key").exists()


def test_without_home_there_is_no_cache_and_it_says_why(monkeypatch):
    for name in ("MITOS_CACHE_DIR", "XDG_CACHE_HOME", "HOME"):
        monkeypatch.delenv(name, raising=False)
    st = cache.status()
    assert st.path is None and not st.refused and "HOME" in st.reason


# ---- a rule file pointing at a file that is not a term set -----------------------------------

@pytest.mark.parametrize("secret", [
    "root:$6$salt$hash:20228:0:99999:7:::\nsecond: line\n",     # YAML, but not a term set
    "password = hunter2\n[section\n",                           # not YAML at all
    "- just\n- a list\n",
])
def test_an_error_quotes_no_line_of_a_file_that_is_not_a_term_set(tmp_path, secret):
    from mitos_cli.errors import TermSetError

    (tmp_path / "private").write_text(secret)
    rules = tmp_path / "r.rules"
    rules.write_text(f'terms "{tmp_path / "private"}"\nif a is lo then y is hi\n')
    with pytest.raises(TermSetError) as exc:
        api.read_rulebase(rules)
    shown = exc.value.render()
    assert "is not a term set" in shown
    for line in secret.splitlines():
        assert line not in shown and line.split(":")[0] not in shown.split("\n", 1)[1]


def test_a_term_set_still_shows_its_bad_line(tmp_path):
    from mitos_cli.errors import TermSetError

    (tmp_path / "t.terms.yaml").write_text("variables:\n  a: {role: input, universe: [0, 1], "
                                           "terms: {lo: 1}}\n  : bad\n")
    rules = tmp_path / "r.rules"
    rules.write_text('terms "t.terms.yaml"\nif a is lo then a is lo\n')
    with pytest.raises(TermSetError) as exc:
        api.read_rulebase(rules)
    assert "  : bad" in exc.value.render()


SECRETS = ["root:$6$salt$hash:20228:0:99999:7:::\nsecond: line\n", "password = hunter2\n[x\n"]


@pytest.mark.parametrize("secret", SECRETS)
def test_a_world_or_map_error_quotes_no_line_of_a_foreign_file(tmp_path, secret):
    from mitos_cli.errors import WorldError
    from mitos_cli.sim.worldfile import load_world

    (tmp_path / "private").write_text(secret)
    (tmp_path / "w.yaml").write_text(with_map(f"  grid: {tmp_path / 'private'}\n"))
    for named in (tmp_path / "private",                       # a lesson's `simulate FILE`
                  tmp_path / "w.yaml"):                         # a world's `grid: FILE`
        with pytest.raises(WorldError) as exc:
            load_world(named)
        shown = exc.value.render()
        assert "is not a" in shown
        for line in secret.splitlines():
            assert line not in shown and line.split(":")[0] not in shown.split("\n", 1)[1]


def with_map(block: str) -> str:
    """The packaged corridor world with its `map:` block replaced by ``block``."""
    lines = (REPO / "worlds" / "corridor.yaml").read_text().split("\n")
    i = lines.index("map:") + 1
    j = i
    while j < len(lines) and (lines[j].startswith(" ") or not lines[j].strip()):
        j += 1
    return "\n".join(lines[:i]) + "\n" + block + "\n".join(lines[j:])


# ---- hostile sizes: deep conditions, huge names ---------------------------------------------

DEEP_FCL = """FUNCTION_BLOCK b
VAR_INPUT
    a : REAL;
END_VAR
VAR_OUTPUT
    y : REAL;
END_VAR
FUZZIFY a
    RANGE := (0 .. 1);
    TERM lo := (0, 1) (1, 0);
END_FUZZIFY
DEFUZZIFY y
    RANGE := (0 .. 1);
    TERM on := 1;
    METHOD : COGS;
    DEFAULT := 0;
END_DEFUZZIFY
RULEBLOCK r
    AND : MIN;
    OR : MAX;
    RULE 1 : IF {cond} THEN y IS on;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""

DEEP_FLL = """Engine: b
InputVariable: a
  range: 0 1
  term: lo Triangle 0 0 1
OutputVariable: y
  range: 0 1
  defuzzifier: WeightedAverage
  default: 0
  term: on Constant 1
RuleBlock: r
  conjunction: Minimum
  disjunction: Maximum
  rule: if {cond} then y is on
"""


@pytest.mark.parametrize("suffix, template, cond", [
    ("fcl", DEEP_FCL, "NOT " * 400 + "a IS lo"),
    ("fcl", DEEP_FCL, "NOT " * 10_000 + "a IS lo"),
    ("fcl", DEEP_FCL, "(a IS lo OR " * 3_000 + "a IS lo" + ")" * 3_000),
    ("fll", DEEP_FLL, "(a is lo or " * 400 + "a is lo" + ")" * 400),
    ("fll", DEEP_FLL, "(a is lo and " * 3_000 + "a is lo" + ")" * 3_000),
])
def test_a_deeply_nested_foreign_rule_is_refused_not_a_recursion_error(tmp_path, suffix,
                                                                       template, cond):
    """400 NOTs of an FCL rule, or nested parentheses of an FLL one, were a RecursionError."""
    from mitos_cli.errors import FormatError

    path = tmp_path / f"deep.{suffix}"
    path.write_text(template.replace("{cond}", cond))
    with pytest.raises(FormatError, match="nested more than 100 deep") as exc:
        api.read_rulebase(path)
    assert exc.value.span is not None and exc.value.span.line > 1


@pytest.mark.parametrize("suffix, template, cond", [
    ("fcl", DEEP_FCL, "NOT " * 50 + "a IS lo"),
    ("fll", DEEP_FLL, "(" * 500 + "a is lo" + ")" * 500),     # parentheses alone nest nothing
])
def test_a_foreign_rule_within_the_limit_still_reads(tmp_path, suffix, template, cond):
    path = tmp_path / f"ok.{suffix}"
    path.write_text(template.replace("{cond}", cond))
    assert api.read_rulebase(path).behaviors


def test_a_huge_unknown_name_is_not_handed_to_difflib(tmp_path, monkeypatch):
    """difflib indexes the name whole: a 100 MB term name in a rule file took 3.8 GB and
    ended in a MemoryError traceback. Here difflib fails as it did, on any call."""
    import difflib

    from mitos_cli.errors import NameError_, closest

    def out_of_memory(*args, **kwargs):
        raise MemoryError

    monkeypatch.setattr(difflib, "get_close_matches", out_of_memory)
    assert closest("R" * 1_000_000, ["LS", "RS"]) is None
    (tmp_path / "t.terms.yaml").write_text(
        "variables:\n  a: {role: input, universe: [0, 1], terms: {lo: 1}}\n"
        "  y: {role: output, universe: [0, 1], terms: {hi: 1}}\n")
    rules = tmp_path / "r.rules"
    rules.write_text('terms "t.terms.yaml"\nif a is lo then y is ' + "R" * 1_000_000 + "\n")
    with pytest.raises(NameError_, match="unknown term") as exc:
        api.read_rulebase(rules)
    assert exc.value.hint is None and "one of hi" in exc.value.render()


@pytest.mark.parametrize("secret", SECRETS)
def test_a_link_named_yaml_to_a_foreign_file_quotes_no_line_of_it(tmp_path, secret):
    """The check was of the name as written: ``x.yaml`` linked to ``/etc/shadow`` printed
    its first line in a term set, map or world error."""
    from mitos_cli.errors import TermSetError, WorldError
    from mitos_cli.sim.worldfile import load_world

    (tmp_path / "private").write_text(secret)
    (tmp_path / "x.yaml").symlink_to(tmp_path / "private")
    rules = tmp_path / "r.rules"
    rules.write_text('terms "x.yaml"\nif a is lo then y is hi\n')
    (tmp_path / "w.yaml").write_text(with_map("  grid: x.yaml\n"))
    shown = []
    with pytest.raises(TermSetError) as exc:
        api.read_rulebase(rules)
    shown.append(exc.value.render())
    for named in (tmp_path / "x.yaml", tmp_path / "w.yaml"):    # `simulate x.yaml`, `grid:`
        with pytest.raises(WorldError) as exc:
            load_world(named)
        shown.append(exc.value.render())
    for text in shown:
        assert "is not a" in text
        for line in secret.splitlines():
            assert line not in text and line.split(":")[0] not in text.split("\n", 1)[1]


# ---- names printed to the terminal ------------------------------------------------------------

ESC_FIS = """[System]
Name='s'
Type='sugeno'
NumInputs=1
NumOutputs=1
NumRules=1

[Input1]
Name='{input}'
Range=[0 1]
NumMFs=1
MF1='{term}':'trimf',[0 0 1]

[Output1]
Name='y'
Range=[0 1]
NumMFs=1
MF1='hi':'constant',[1]

[Rules]
1, 1 (1) : 1
"""


@pytest.mark.parametrize("input_name, term_name", [
    ("a\x1b]0;title\x07", "lo"),          # an OSC sequence: set the terminal's title
    ("a", "lo\x1b[2J"),                   # clear the screen
    ("a\x9b31m", "lo"),                   # a C1 control sequence introducer
    ("a\u202etxt.exe", "lo"),             # a right-to-left override: shown as `aexe.txt`
    ("a", "lo\u2066hidden\u2069"),         # a bidirectional isolate
])
def test_a_control_character_in_a_fis_name_is_refused(tmp_path, input_name, term_name):
    """`mitos eval` and `check` printed a .fis file's names as written: an ESC in one acted
    on the terminal."""
    from mitos_cli.errors import FormatError

    path = tmp_path / "esc.fis"
    path.write_text(ESC_FIS.replace("{input}", input_name).replace("{term}", term_name),
                    encoding="utf-8")
    with pytest.raises(FormatError, match="holds the control character") as exc:
        api.read_rulebase(path)
    assert not any(c in exc.value.render() for c in "\x1b\x07\x9b\u202e\u2066\u2069")


@pytest.mark.parametrize("key", ["description", "unit"])
def test_a_control_character_in_a_term_sets_text_is_refused(tmp_path, key):
    from mitos_cli.errors import TermSetError

    (tmp_path / "t.terms.yaml").write_text(
        f'variables:\n  a: {{role: input, universe: [0, 1], {key}: "in\\e[2J", '
        f"terms: {{lo: 1}}}}\n  y: {{role: output, universe: [0, 1], terms: {{hi: 1}}}}\n")
    rules = tmp_path / "r.rules"
    rules.write_text('terms "t.terms.yaml"\nif a is lo then y is hi\n')
    with pytest.raises(TermSetError, match=f"its {key} holds the control character `.x1b`"):
        api.read_rulebase(rules)


@pytest.mark.parametrize("char, name", [
    ("\u200b", "ZERO WIDTH SPACE"), ("\u200c", "ZERO WIDTH NON-JOINER"),
    ("\u200d", "ZERO WIDTH JOINER"), ("\u200e", "LEFT-TO-RIGHT MARK"),
    ("\u200f", "RIGHT-TO-LEFT MARK"), ("\u061c", "ARABIC LETTER MARK"),
    ("\u2060", "WORD JOINER"), ("\ufeff", "ZERO WIDTH NO-BREAK SPACE"),
    ("\U000e0041", "TAG LATIN CAPITAL LETTER A")])
def test_an_invisible_character_in_a_name_is_refused_by_its_code_point(tmp_path, char, name):
    """Unicode's format characters other than the bidirectional ones were taken in names:
    `road` and `ro\u200bad` printed alike and were two names (a .fis input, a term set's
    term). Refused in every reader's names, the character named; texts keep them (Persian
    writes a zero-width non-joiner), shown as escapes in messages."""
    from mitos_cli.errors import FormatError, MitosError, TermSetError, visible

    escape = visible(char)
    path = tmp_path / "zw.fis"
    path.write_text(ESC_FIS.replace("{input}", f"ro{char}ad").replace("{term}", "lo"),
                    encoding="utf-8")
    with pytest.raises(FormatError) as exc:
        api.read_rulebase(path)
    assert f"its name holds the invisible character `{escape}` ({name})" in exc.value.message
    text = exc.value.render()
    assert char not in text and f"variable `ro{escape}ad`" in text
    (tmp_path / "t.terms.yaml").write_text(
        f'variables:\n  a: {{role: input, universe: [0, 1], description: "a{char}b", '
        f'unit: "in", terms: {{lo: 1, "l{char}o": 1}}}}\n'
        f"  y: {{role: output, universe: [0, 1], terms: {{hi: 1}}}}\n", encoding="utf-8")
    rules = tmp_path / "r.rules"
    rules.write_text('terms "t.terms.yaml"\nif a is lo then y is hi\n')
    with pytest.raises(TermSetError) as exc:
        api.read_rulebase(rules)
    assert exc.value.message == (f"term `a.l{char}o` holds the invisible character "
                                 f"`{escape}` ({name})")
    lines = exc.value.render().splitlines()              # the caret under the name
    assert lines[2].index("^") == lines[1].index('"l\ufffdo"')
    (tmp_path / "t.terms.yaml").write_text((tmp_path / "t.terms.yaml").read_text(
        encoding="utf-8").replace(f', "l{char}o": 1', ""), encoding="utf-8")
    assert api.read_rulebase(rules).variables["a"].description == f"a{char}b"
    with pytest.raises(MitosError, match="unexpected character"):
        rules.write_text(f'terms "t.terms.yaml"\nif a is l{char}o then y is hi\n', encoding="utf-8")
        api.read_rulebase(rules)


# ---- a world naming a pipe ----------------------------------------------------------------------

def _finishes(call, fifo: Path, seconds: float = 20.0):
    """``call()``'s result or exception, run in a thread; a call still waiting on ``fifo``
    after ``seconds`` is released (a writer opens and closes it) and fails the test."""
    import threading

    box: dict = {}

    def run():
        try:
            box["value"] = call()
        except BaseException as exc:        # noqa: BLE001 (handed to the test)
            box["error"] = exc

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    thread.join(seconds)
    if thread.is_alive():
        os.close(os.open(fifo, os.O_WRONLY | os.O_NONBLOCK))
        thread.join(seconds)
        pytest.fail(f"waited on the pipe {fifo.name} for {seconds:g} s")
    return box


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no named pipes here")
def test_a_world_whose_map_is_a_named_pipe_is_refused_not_waited_on(tmp_path):
    """`grid: PIPE.yaml` waited without end for a writer, in `simulate` and in `compare`'s
    digest of the files a world reads; a term set or a world file so named is refused."""
    from mitos_cli.errors import WorldError
    from mitos_cli.sim.worldfile import load_world, map_files
    from mitos_cli.study.simtask import world_digest

    fifo = tmp_path / "pipe.yaml"
    os.mkfifo(fifo)
    world = tmp_path / "w.yaml"
    world.write_text(with_map("  grid: pipe.yaml\n"))
    box = _finishes(lambda: load_world(world), fifo)
    assert isinstance(box.get("error"), WorldError)
    assert "`pipe.yaml` is not a regular file" in box["error"].render()
    assert _finishes(lambda: map_files(world), fifo).get("value") == [fifo]
    assert _finishes(lambda: world_digest(str(world)), fifo).get("value") is None


# ---- what a lesson may write -------------------------------------------------------------------

def test_a_lessons_save_stays_below_the_working_directory(tmp_path, monkeypatch):
    """A lesson's `save /any/where.rules` (or `../`, `~/`, a link that leads out) wrote over
    that file without a word; at the prompt, and with `--save-as`, the user names the place."""
    from mitos_cli.errors import LessonError
    from mitos_cli.teach.lesson import run_lesson
    from mitos_cli.teach.session import Session

    work, away = tmp_path / "work", tmp_path / "away"
    work.mkdir()
    away.mkdir()
    for f in (REPO / "rulebases").iterdir():
        if f.is_file():
            shutil.copy(f, work / f.name)
    victim = away / "mine.rules"
    victim.write_text("# the user's own\n")
    (work / "out").symlink_to(away)
    monkeypatch.chdir(work)
    monkeypatch.setenv("HOME", str(away))               # `~/mine.rules`, were it written
    session = Session(work / "mitos.rules", out=lambda s: None)
    for target in (victim, "../away/mine.rules", "out/mine.rules", "~/mine.rules"):
        with pytest.raises(LessonError, match="a lesson writes files below the working "
                                              "directory") as exc:
            run_lesson(session, f"save {target}\n", "evil.lesson")
        assert exc.value.span.path == "evil.lesson" and exc.value.span.column == 6
    assert victim.read_text() == "# the user's own\n"
    assert run_lesson(session, "save taught/ok.rules\n", "ok.lesson")
    assert (work / "taught" / "ok.rules").is_file()
    session.run(f"save {away / 'asked.rules'}")        # at the prompt: where the user says
    assert (away / "asked.rules").is_file()


def test_a_lessons_plots_stay_below_the_working_directory(tmp_path, monkeypatch):
    """`adapt ... plot /elsewhere/x.png` and `show terms plot ...` in a lesson wrote (over)
    pictures wherever the lesson said."""
    from mitos_cli.errors import LessonError
    from mitos_cli.teach.lesson import run_lesson
    from mitos_cli.teach.session import Session

    pytest.importorskip("matplotlib")
    work, away = tmp_path / "work", tmp_path / "away"
    work.mkdir()
    away.mkdir()
    monkeypatch.chdir(work)
    session = Session(REPO / "rulebases" / "mitos.rules", out=lambda s: None)
    run_lesson(session, "correct road=78 size=45 position=4 -> steering is LM\n", "a.lesson")
    for line in (f"adapt epochs 1 plot {away / 'p.png'}", f"show terms plot {away / 'p.png'}",
                 "adapt epochs 1 plot ../away/p.png"):
        with pytest.raises(LessonError, match="a lesson writes files below the working "
                                              "directory"):
            run_lesson(session, line + "\n", "evil.lesson")
    assert list(away.iterdir()) == []


def test_a_line_break_in_a_unit_is_refused_a_description_may_have_lines(tmp_path):
    """`eval` prints the unit within its lines: `unit: "in\\noutputs:\\n  y = 1"` wrote output
    lines of its own. A description (drawn as a title) may hold several lines."""
    from mitos_cli.errors import TermSetError

    def termset(extra: str) -> Path:
        (tmp_path / "t.terms.yaml").write_text(
            f"variables:\n  a: {{role: input, universe: [0, 1], {extra}, terms: {{lo: 1}}}}\n"
            "  y: {role: output, universe: [0, 1], terms: {hi: 1}}\n")
        rules = tmp_path / "r.rules"
        rules.write_text('terms "t.terms.yaml"\nif a is lo then y is hi\n')
        return rules

    with pytest.raises(TermSetError, match=r"its unit holds the control character `\\n`"):
        api.read_rulebase(termset('unit: "in\\n\\noutputs:\\n  y = 1"'))
    rb = api.read_rulebase(termset('description: "two\\nlines\\tand a tab"'))
    assert rb.termsets[0].variables[0].description == "two\nlines\tand a tab"


def test_a_yaml_file_of_too_many_values_is_refused_early(tmp_path, monkeypatch):
    """A 4 MB term set of one list of 2,000,000 numbers took a GB and over a minute to read
    (PyYAML builds a node and a value for each). Here with a limit of 1,000 for speed."""
    from mitos_cli.errors import TermSetError
    from mitos_cli.lang import yamlpos

    monkeypatch.setattr(yamlpos, "MAX_NODES", 1_000, raising=False)
    text = "variables:\n  a: {role: input, universe: [0, 1], terms: {lo: 1}}\n" \
           "junk: [" + ", ".join(["1"] * 2_000) + "]\n"
    with pytest.raises(TermSetError, match="more than 1,000 values") as exc:
        yamlpos.load(text, "t.terms.yaml", TermSetError)
    assert exc.value.span.line == 3
    assert yamlpos.load(text.split("junk")[0], "t.terms.yaml", TermSetError)


# ---- a world whose corridors double back -----------------------------------------------------

def test_a_world_of_too_many_corridor_points_is_refused(tmp_path):
    """A 60 KB world of one corridor of 1,500 points doubling back on itself took 39 s and
    2 GB to load (every piece's walls clipped by every other piece), 4,000 over minutes."""
    from mitos_cli.errors import WorldError
    from mitos_cli.sim.worldfile import load_world

    def world(n: int) -> Path:
        points = ", ".join(f"[{(i % 2) * 100 + i * 0.01:g}, 0]" for i in range(n))
        path = tmp_path / f"w{n}.yaml"
        path.write_text(with_map(f"  corridors:\n    - points: [[0, 0], [600, 0]]\n"
                                 f"      width: 70\n    - points: [{points}]\n      width: 70\n"))
        return path

    with pytest.raises(WorldError, match="more than 1,000 points") as exc:
        load_world(world(999))                              # and 2 in the first corridor
    assert exc.value.span.line > 1 and "corridor 2" in exc.value.message
    assert load_world(world(998)).corridors


def _clip_one_by_one(seg, rects, shrink=1e-6):
    """The clipping as it was, one rectangle at a time: the reference for the bits."""
    p0, p1 = seg[:2], seg[2:]
    pieces = [(0.0, 1.0)]
    for corners in rects:
        centre = corners.mean(axis=0)
        u, v = corners[1] - corners[0], corners[3] - corners[0]
        nu, nv = np.linalg.norm(u), np.linalg.norm(v)
        if not (nu > 0 and nv > 0):
            continue
        u, v = u / nu, v / nv
        t0, t1 = 0.0, 1.0
        for axis, half in ((u, nu / 2 - shrink), (v, nv / 2 - shrink)):
            a0, da = float(np.dot(p0 - centre, axis)), float(np.dot(p1 - p0, axis))
            if abs(da) < 1e-9:
                if abs(a0) >= half:
                    t0, t1 = 1.0, 0.0
                continue
            ta, tb = float((-half - a0) / da), float((half - a0) / da)
            t0, t1 = max(t0, min(ta, tb)), min(t1, max(ta, tb))
        if t1 <= t0:
            continue
        cut = []
        for a, b in pieces:
            if b <= t0 or a >= t1:
                cut.append((a, b))
                continue
            cut += [(a, t0)] * (a < t0) + [(t1, b)] * (b > t1)
        pieces = cut
    length = float(np.hypot(*(p1 - p0)))
    return [np.concatenate([p0 + a * (p1 - p0), p0 + b * (p1 - p0)]) for a, b in pieces
            if (b - a) * length > 1e-6]


def test_clipping_all_rectangles_at_once_keeps_every_bit():
    """The walls (so every run) are those of one rectangle at a time, to the last bit."""
    from mitos_cli.sim.geometry import clip_segment_outside

    rng = np.random.default_rng(7)
    for _ in range(2_000):
        rects = []
        for _ in range(rng.integers(0, 7)):
            c, a = rng.uniform(-500, 500, 2), rng.uniform(0, np.pi)
            length, width = rng.choice([0.0, rng.uniform(0.1, 600)]), rng.uniform(0.1, 40)
            u, v = np.array([np.cos(a), np.sin(a)]), np.array([-np.sin(a), np.cos(a)])
            rects.append([c + (sx * u * length + sy * v * width) / 2
                          for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))])
        rects = np.array(rects, float).reshape(-1, 4, 2)
        seg = rng.uniform(-600, 600, 4)
        if len(rects) and rng.random() < 0.3:
            seg = np.concatenate([rects[0][0], rects[0][1]])        # a side of its own
        got, want = clip_segment_outside(seg, rects), _clip_one_by_one(seg, rects)
        assert len(got) == len(want) and all(map(np.array_equal, got, want))


def test_a_yaml_file_too_long_is_refused_before_it_is_scanned(monkeypatch):
    """A 250 MB term set (one long description) ran past a minute in PyYAML's scanner.
    Here with a limit of 1,000 characters for speed; the error quotes nothing of the file."""
    from mitos_cli.errors import TermSetError
    from mitos_cli.lang import yamlpos

    monkeypatch.setattr(yamlpos, "MAX_CHARS", 1_000, raising=False)
    text = "variables:\n  a:\n    description: " + "x" * 2_000 + "\n"
    with pytest.raises(TermSetError, match="holds 2,034 characters; .* at most 1,000") as exc:
        yamlpos.load(text, "t.terms.yaml", TermSetError)
    assert "xxx" not in exc.value.render()
    assert yamlpos.load(text[:900], "t.terms.yaml", TermSetError)


@pytest.mark.parametrize("suffix, text", [
    ("rules", 'terms "t.terms.yaml"\n' + "if a is lo then y is hi\n" * 200),
    ("fcl", DEEP_FCL.replace("{cond}", "a IS lo") + "// " + "x" * 5_000 + "\n"),
])
def test_a_rule_file_too_long_is_refused_before_it_is_parsed(tmp_path, monkeypatch, suffix,
                                                             text):
    """A 12 MB rule file of 200,000 rules took a minute and 1.7 GB (Lark: some 5 ms a KB),
    one of 256 MB, which every text file may be, hours. Here with a limit of 4,000
    characters for speed."""
    from mitos_cli.errors import MitosError
    from mitos_cli.lang import parse

    monkeypatch.setattr(parse, "MAX_RULE_FILE_CHARS", 4_000, raising=False)
    path = tmp_path / f"big.{suffix}"
    path.write_text(text)
    with pytest.raises(MitosError, match=f"holds {len(text):,} characters; a rule file may "
                                         f"hold at most 4,000") as exc:
        api.read_rulebase(path)
    assert exc.value.span.line == 1


def test_a_bidirectional_override_is_shown_as_its_escape():
    """Unicode's bidirectional overrides and isolates reorder what a terminal shows ("Trojan
    Source"): refused in names as control characters are, and escaped in messages."""
    from mitos_cli.errors import control_character, visible

    assert visible("a\u202eb\u2066c\x1b") == "a\\u202eb\\u2066c\\x1b"
    assert control_character("road\u202e") == "\\u202e" and control_character("route") is None
    assert visible("Straße, café, 路") == "Straße, café, 路"      # letters are letters
