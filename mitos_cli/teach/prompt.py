"""The interactive teaching prompt: line editing, history and completion through ``readline``.

``readline`` (the standard library's GNU readline / libedit binding) gives what a teaching
prompt needs: editing, a history kept in the session directory (so ``--resume`` brings it back)
and tab completion of command words, variable names, term names, behavior names and rule
labels; no extra dependency. Without a terminal (a pipe) the prompt reads plain lines, which is
how the tests drive it. A mistyped line prints what was expected and the prompt goes on;
Ctrl-C cancels the line (or stops an adaptation, keeping the epochs done); Ctrl-D or ``quit``
leaves, and everything told is already in the journal. A SIGTERM or a SIGHUP, which the CLI
raises as :class:`~mitos_cli.errors.Terminated`, ends the prompt where Ctrl-C would have
gone on (an adaptation keeps its epochs done first).
"""

from __future__ import annotations

import contextlib
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import LessonError, MitosError, Span, Terminated
from ..fuzzy.hedges import HEDGES
from .commands import COMMAND_WORDS, SHOW_WHAT, incomplete
from .instructions import HEDGE_STEPS, INSTRUCTIONS
from .session import Session
from .text import quoted_column

if TYPE_CHECKING:
    from collections.abc import Iterator
    from types import ModuleType
    from typing import TextIO


class Completer:
    """Completes the word under the cursor from what the session knows."""

    def __init__(self, session: Session) -> None:
        self.session = session
        self.matches: list[str] = []
        self._robots: dict[str, list[str]] = {}        # world -> its robots' names

    def words(self, line: str) -> list[str]:
        rb = self.session.rulebase
        tokens = line.split()
        first = tokens[0] if tokens else ""
        at_start = len(tokens) == 0 or (len(tokens) == 1 and not line.endswith(" "))
        if at_start:
            return list(COMMAND_WORDS) + ["if"]
        if first == "show":
            return list(SHOW_WHAT) + ["plot"]
        if first == "help":
            from .help import TOPICS

            return list(TOPICS)
        if first == "use":
            return [b.name for b in rb.behaviors] + ["when", "with"]
        if first == "adapt":
            return ["epochs", "rate", "plot", "unconstrained"]
        terms = [f"{v.name}.{t}" for v in rb.variables.values() for t in v.term_names]
        if first == "frozen":
            b = rb.behavior(self.session.focus)
            return [r.label for r in b.rules if r.label] + terms
        if first == "unfrozen":
            return terms
        if first == "simulate":
            return self.simulate_words(line, tokens)
        if first in ("save", "undo", "end", "quit", "exit"):
            return []                   # (a file name, or nothing: no word of the language)
        if first in ("eval", "correct", "at"):
            inputs = [f"{v.name}=" for v in rb.variables.values() if v.role == "input"]
            outputs = [v.name for v in rb.variables.values() if v.role == "output"]
            if first == "eval" or (first == "correct" and "->" not in tokens):
                return inputs + ([] if first == "eval" else ["->"])
            return self.target_words(line, tokens, outputs)
        # a rule: variables, then `is`, then that variable's terms and hedges
        prev = tokens[-1] if line.endswith(" ") else (tokens[-2] if len(tokens) > 1 else "")
        if prev in ("is", "not", *HEDGES):
            back = tokens if line.endswith(" ") else tokens[:-1]
            var = next((t for t in reversed(back) if t in rb.variables), None)
            terms = list(rb.variables[var].term_names) if var else []
            return terms + ["not", *HEDGES]
        return list(rb.variables) + ["is", "and", "or", "not", "then", "with"]

    def simulate_words(self, line: str, tokens: list[str]) -> list[str]:
        """After `simulate`: the packaged worlds, then `seed` and `robot`, and after `robot`
        the robots of the world named (quoted where a name is no bare word)."""
        back = tokens if line.endswith(" ") else tokens[:-1]
        if len(back) == 1:
            from ..resources import packaged_names

            return [n.removesuffix(".yaml") for n in packaged_names("worlds", ".yaml")]
        if back[-1] == "seed" or "robot" in back[:-1]:
            return []                                   # a number, or the end of the line
        if back[-1] == "robot":
            return self.robots(back[1])
        return (["seed"] if "seed" not in back else []) + ["robot"]

    def robots(self, world: str) -> list[str]:
        """The robots of ``world`` by their names, as `simulate ... robot` takes them."""
        import re

        from ..errors import MitosError
        from .simulation import world_path

        if world not in self._robots:
            try:
                from ..sim.worldfile import load_world

                names = [a.name for a in load_world(world_path(world, self.session.base)).agents]
            except (MitosError, OSError):
                names = []
            self._robots[world] = [n if re.fullmatch(r"[A-Za-z_][\w\-]*", n) and
                                   not n.endswith("-") else '"' + n.replace('"', '\\"') + '"'
                                   for n in names]
        return self._robots[world]

    def target_words(self, line: str, tokens: list[str], outputs: list[str]) -> list[str]:
        """The words that go on a target (``correct ... ->`` or ``at TIME``): an output's
        terms after its ``is`` (and a target's hedges), ``and`` after a term, and after ``at
        TIME [to TIME]`` the outputs (``steering=``) and the next word of an instruction
        (``make a wider turn``). It offered ``steering=`` and ``speed=`` alone, also after
        ``steering is``."""
        rb = self.session.rulebase
        back = tokens if line.endswith(" ") else tokens[:-1]
        prev = back[-1] if back else ""
        if prev == "is" or prev in HEDGE_STEPS:
            var = next((t for t in reversed(back) if t in outputs), None)
            terms = list(rb.variables[var].term_names) if var else []
            return terms + (list(HEDGE_STEPS) if prev == "is" else [])
        if len(back) >= 2 and back[-2] == "is" or len(back) >= 3 and back[-3] == "is" \
                and back[-2] in HEDGE_STEPS:
            return ["and"]                                      # after a target's term
        if prev == "and" or prev == "->":
            return [f"{o}=" for o in outputs]           # (`st<tab>`: `steering=` at once)
        if back[:1] != ["at"]:
            return []
        # `at T`, `at T to T2`, then the outputs or the words of an instruction
        said = back[4:] if len(back) >= 4 and back[2] == "to" else back[2:]
        if len(back) < 2 or (len(back) == 3 and back[2] == "to"):
            return []                                           # a time goes here
        words = [] if said else [f"{o}=" for o in outputs]
        if len(back) == 2:
            words.append("to")
        for phrase in INSTRUCTIONS:
            parts = phrase.split()
            if len(parts) > len(said) and parts[:len(said)] == said:
                words.append(parts[len(said)])
        return words

    def complete(self, text: str, state: int) -> str | None:
        if state == 0:
            import readline

            line = readline.get_line_buffer()[:readline.get_endidx()]
            self.matches = sorted(w if w.endswith("=") else w + " "
                                  for w in set(self.words(line)) if w.startswith(text))
        return self.matches[state] if state < len(self.matches) else None


def _setup_readline(session: Session, history: Path | None) -> ModuleType | None:
    try:
        import readline
    except ImportError:                              # pragma: no cover - Windows without it
        return None
    readline.set_completer(Completer(session).complete)
    readline.set_completer_delims(" \t\n")
    if "libedit" in (readline.__doc__ or ""):        # macOS
        readline.parse_and_bind("bind ^I rl_complete")
    else:
        readline.parse_and_bind("tab: complete")
    readline.set_history_length(5000)
    if history is not None:
        try:
            if history.is_file():
                readline.read_history_file(str(history))
            else:
                history.touch()                  # append_history_file needs the file
        except OSError:
            pass
    return readline


def prompt_text(session: Session) -> str:
    block = session.state.block
    return f"{session.state.active}/{block}> " if block else f"{session.state.active}> "


#: Where the prompt's lines are, in error messages (``<prompt>:LINE:COLUMN``).
PROMPT = "<prompt>"


def at_prompt(exc: MitosError, line: str, lineno: int) -> MitosError:
    """``exc`` as the prompt reports it: a failed command is a ``command error`` (a lesson's
    is a ``lesson error``), and an error with no position points at the line typed."""
    if isinstance(exc, LessonError):
        exc.kind = "command error"
    if exc.span is None:
        start, end = quoted_column(exc.message, line)
        exc.span = Span.in_text("\n" * (lineno - 1) + line, PROMPT, lineno, start, end or None)
    return exc


def _undecoded(line: str, lineno: int) -> MitosError | None:
    """A line holding a byte the input's encoding could not read (kept as a lone surrogate),
    said as a lesson says it ("not UTF-8 text"), the byte shown as U+FFFD under the caret."""
    from ..errors import RuleSyntaxError

    at = next((i for i, c in enumerate(line) if "\udc80" <= c <= "\udcff"), None)
    if at is None:
        return None
    try:                                # (a stderr that cannot write U+FFFD: `?`)
        "\ufffd".encode(getattr(sys.stderr, "encoding", None) or "utf-8")
        mark = "\ufffd"
    except (UnicodeEncodeError, LookupError):
        mark = "?"
    shown = "".join(mark if "\udc80" <= c <= "\udcff" else c for c in line)
    row = line.count("\n", 0, at) + 1
    column = at - (line.rfind("\n", 0, at) + 1) + 1
    byte = ord(line[at]) - 0xDC00
    encoding = str(getattr(sys.stdin, "encoding", None) or "utf-8")
    encoding = "UTF-8" if encoding.lower().replace("_", "-") in ("utf-8", "utf8") else encoding
    return RuleSyntaxError(f"the line is not {encoding} text (byte 0x{byte:02x} at column "
                           f"{column})",
                           span=Span.in_text("\n" * (lineno - 1) + shown, PROMPT,
                                             lineno + row - 1, column, column + 1),
                           hint="names are written in ASCII letters, digits, `_` and `-`")


def interact(session: Session, history: Path | None = None) -> None:
    """Read and run commands until ``quit`` or end of input.

    Lines are numbered as they are read (a wrapped rule takes several), so an error reads
    ``<prompt>:LINE:COLUMN``: in commands piped on stdin, LINE is the line of the input.
    """
    tty = sys.stdin.isatty()
    readline = _setup_readline(session, history) if tty else None
    err = sys.stderr
    # a byte the input's encoding cannot read is the line's mistake, said at its place: read
    # strictly (`PYTHONIOENCODING=utf-8`) it was a traceback, the lines read with it lost
    with contextlib.suppress(AttributeError, ValueError, OSError):   # (not a text file)
        sys.stdin.reconfigure(errors="surrogateescape")     # type: ignore[union-attr]
    session.out("MITOS teaching prompt: tell rules, correct, adapt, save. `help` lists the "
                "commands; Ctrl-D or `quit` leaves (nothing is lost).")
    try:
        for line, lineno, ended in _statements(session, tty, err):
            if lineno == 1:                      # a file piped in, written with a BOM
                line = line.removeprefix("\ufeff")
            if not line.strip() or line.lstrip().startswith("#"):
                continue
            bad = _undecoded(line, lineno)
            if bad is not None:
                print(bad.render(), file=err)
                continue
            session.interrupted = None
            try:                                 # Ctrl-C anywhere here keeps the session
                if readline is not None and history is not None:
                    with contextlib.suppress(OSError, AttributeError):
                        readline.append_history_file(1, str(history))
                if not session.run(line, PROMPT, lineno):
                    break
            except MitosError as exc:
                print(at_prompt(exc, line, lineno).render(), file=err)
            except Terminated:
                raise
            except KeyboardInterrupt:
                session.replay()            # the state is exactly what the journal holds
                print("interrupted", file=err)
            if isinstance(session.interrupted, Terminated):
                raise session.interrupted   # an `adapt` kept its epochs done (journaled)
            sys.stdout.flush()
            if ended:
                session.out("")
                break
    except Terminated:                      # the session ends; the caller exits 143 or 129
        session.replay(checked=False)       # the state is exactly what the journal holds
        print("interrupted", file=err)
        raise
    finally:
        _farewell(session, err)


def _statements(session: Session, tty: bool, err: TextIO) -> Iterator[tuple[str, int, bool]]:
    """Each statement read, a rule wrapped over lines joined into one, with the number of
    its first line and whether the input ended inside it (the rule is then said cut short,
    not dropped); until the input ends. Ctrl-C at the prompt drops the line and reads on."""
    lines_read = 0
    while True:
        ended = False                        # the input ended inside a wrapped rule
        try:
            line = input(prompt_text(session) if tty else "")
            lines_read += 1
            lineno = lines_read
            while incomplete(line):          # a rule continued on the next line
                try:
                    more = input("... " if tty else "")
                except EOFError:             # the rule is said cut short, not dropped
                    ended = True
                    break
                lines_read += 1
                if not more.strip():         # an empty line ends it (and says why)
                    break
                line += "\n" + more
        except EOFError:
            session.out("")
            return
        except Terminated:
            raise
        except KeyboardInterrupt:
            print("^C  (the line is dropped; `quit` or Ctrl-D leaves)", file=err)
            continue
        yield line, lineno, ended


def _farewell(session: Session, err: TextIO) -> None:
    """On leaving, what is left undone and the command that takes it up again (nothing is
    lost: the journal holds it)."""
    from .journal import resume_command

    resume = resume_command(session.journal.directory)
    if session.state.block is not None:
        print(f"behavior `{session.state.block}` is still open; `{resume}` keeps it open, "
              f"`end` closes it", file=err)
    if session.unsaved:
        print(f"unsaved changes are kept in the journal; `{resume}` continues, `save PATH` "
              f"writes them", file=err)
