"""The teaching language: one line of ``mitos teach`` (prompt or lesson) -> a command object.

The grammar (``grammar/teach.lark``) is appended to the rule language's and parsed by one
LALR parser, so a rule, ``use``, ``frozen`` or ``operators:`` line at the prompt means exactly
what it means in a rule file and gets the same error messages. Errors are
:class:`~mitos_cli.errors.RuleSyntaxError` with ``path:line:col``, the line, a caret and what
was expected, in words.
"""

from __future__ import annotations

import functools
import math
import re
from dataclasses import dataclass, field
from types import SimpleNamespace
from typing import TYPE_CHECKING, Any

from lark import Lark, Token, Tree, v_args
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken

from ..errors import LessonError, RuleSyntaxError, Span, lines_of
from ..lang.cache import lark_parser
from ..lang.lexing import Glued, parse_apart
from ..lang.model import Rule, Setting, Use
from ..lang.parse import (
    TARGETS,
    TERMINAL_WORDS,
    UNSAID,
    _hedge_hint,
    _ToModel,
    _two_words,
    _unquote,
    check_modifiers,
    check_nesting,
    check_settings,
    glued_error,
    glued_name_hint,
    joined_hint,
    keyword_glued,
    keyword_hint,
    not_in_action_before,
    shift,
)
from ..resources import grammar_text
from .instructions import HEDGE_STEPS, INSTRUCTIONS

if TYPE_CHECKING:
    from collections.abc import Iterable

    from lark.tree import Meta

    from ..lang.model import Consequent

WORDS = dict(TERMINAL_WORDS, PATH="a file name", INT="a whole number", ARROW="`->`",
             SHOW_WHAT="rules, terms, examples, behaviors or history", EQUAL="`=`",
             SIGNED_NUMBER="a number", SEED="a seed (a whole number)", DOT="`.`",
             SEED_WORD="`seed`", TARGET_HEDGE="a hedge (" + ", ".join(HEDGE_STEPS) + ")",
             **{"$END": "the end of the line", "<END-OF-FILE>": "the end of the line"})

#: Every command word, for completion and ``help``.
COMMAND_WORDS = ("behavior", "end", "use", "frozen", "unfrozen", "operators", "eval", "correct",
                 "simulate",
                 "at", "adapt", "show", "undo", "save", "help", "quit", "exit")
SHOW_WHAT = ("rules", "terms", "examples", "behaviors", "history")


@functools.cache
def parser() -> Lark:
    """One parser for the rule language plus the teaching commands, built once."""
    text = grammar_text("mitos.lark") + "\n" + grammar_text("teach.lark")
    return lark_parser(text, propagate_positions=True, maybe_placeholders=True, start="command")


# ---- command objects -------------------------------------------------------------------------

@dataclass(frozen=True)
class TellRule:
    rule: Rule


@dataclass(frozen=True)
class TellUse:
    use: Use


@dataclass(frozen=True)
class TellFrozen:
    labels: tuple[str, ...]


@dataclass(frozen=True)
class FreezeTerms:
    """``frozen heading.AHEAD``: terms adaptation keeps as they are."""

    terms: tuple[tuple[str, str], ...]
    span: Span | None = field(default=None, compare=False)


@dataclass(frozen=True)
class ReleaseTerms:
    """``unfrozen heading.AHEAD``: lift a term's freeze or its hold at its point."""

    terms: tuple[tuple[str, str], ...]
    span: Span | None = field(default=None, compare=False)


@dataclass(frozen=True)
class Said:
    """``steering is very LM``: a target in words (``term`` None: a number)."""

    name: str
    term: str | None
    hedges: tuple[str, ...]
    value: float | None
    span: Span | None = field(default=None, compare=False)


@dataclass(frozen=True)
class CorrectSaid:
    inputs: tuple[Assign, ...]
    targets: tuple[Said, ...]


#: where an `at`'s two times are written (for an error about one of them)
Places = tuple[Span | None, Span | None]


@dataclass(frozen=True)
class AtSaid:
    start: float
    stop: float | None
    targets: tuple[Said, ...]
    places: Places = field(default=(None, None), compare=False)


@dataclass(frozen=True)
class AtInstruction:
    """``at 13s to 14.5s make a wider turn``."""

    start: float
    stop: float | None
    words: tuple[str, ...]
    span: Span | None = field(default=None, compare=False)
    places: Places = field(default=(None, None), compare=False)


@dataclass(frozen=True)
class TellOperators:
    settings: tuple[Setting, ...]


@dataclass(frozen=True)
class OpenBehavior:
    name: str


@dataclass(frozen=True)
class CloseBehavior:
    pass


@dataclass(frozen=True)
class Assign:
    """``name=value`` with the span of the name (for "did you mean")."""

    name: str
    value: float
    span: Span | None = field(default=None, compare=False)


@dataclass(frozen=True)
class Eval:
    inputs: tuple[Assign, ...]


@dataclass(frozen=True)
class Correct:
    inputs: tuple[Assign, ...]
    targets: tuple[Assign, ...]


@dataclass(frozen=True)
class Simulate:
    world: str
    seed: str | None = None          # as written: checked to be digits by the session
    robot: str | None = None         # which robot's run `at` corrects (default: the first)
    robot_span: Span | None = field(default=None, compare=False)     # where its name is written


@dataclass(frozen=True)
class At:
    start: float
    stop: float | None
    targets: tuple[Assign, ...]
    places: Places = field(default=(None, None), compare=False)


@dataclass(frozen=True)
class Adapt:
    epochs: float | None = None      # checked to be whole by the session
    rate: float | None = None
    plot: str | None = None
    constrained: bool = True         # `unconstrained`: order and bounds only
    given: tuple[str, ...] = field(default=(), compare=False)   # the options, as written


@dataclass(frozen=True)
class Show:
    what: str
    plot: str | None = None


@dataclass(frozen=True)
class Undo:
    pass


@dataclass(frozen=True)
class Save:
    path: str | None = None


@dataclass(frozen=True)
class Help:
    topic: str | None = None


@dataclass(frozen=True)
class Quit:
    pass


Command = (TellRule | TellUse | TellFrozen | TellOperators | OpenBehavior | CloseBehavior | Eval
           | Correct | Simulate | At | Adapt | Show | Undo | Save | Help | Quit | FreezeTerms
           | ReleaseTerms | CorrectSaid | AtSaid | AtInstruction)


class _ToCommand(_ToModel):
    """Tree -> command objects (the rule-language parts are the rule parser's own)."""

    def command(self, items: list[Any]) -> Command:     # a Rule, a Use or a tagged tuple
        item = items[0]
        if isinstance(item, Rule):
            return TellRule(item)
        if isinstance(item, Use):
            return TellUse(item)
        kind, value = item[0], item[1]
        return TellFrozen(value) if kind == "frozen" else TellOperators(value)

    def open_behavior(self, items: list[Token]) -> OpenBehavior:
        return OpenBehavior(str(items[0]))

    def close_behavior(self, items: list[Token]) -> CloseBehavior:
        return CloseBehavior()

    @v_args(meta=True)
    def assignment(self, meta: Meta, items: list[Any]) -> Assign:    # (name, number)
        return Assign(str(items[0]), float(items[1]), self._s(meta))

    def inputs(self, items: list[Assign]) -> tuple[Assign, ...]:
        return tuple(items)

    targets = inputs

    @v_args(meta=True)
    def said(self, meta: Meta, items: list[Consequent]) -> tuple[Said, ...]:
        out = []
        for c in items:
            out.append(Said(c.var, c.term, tuple(c.hedges), c.value, getattr(c, "span", None)
                            or self._s(meta)))
        return tuple(out)

    def term_ref(self, items: list[Token]) -> tuple[str, str]:
        return (str(items[0]), str(items[1]))

    @v_args(meta=True)
    def freeze_terms(self, meta: Meta, items: list[tuple[str, str]]) -> FreezeTerms:
        return FreezeTerms(tuple(items), self._s(meta))

    @v_args(meta=True)
    def release_terms(self, meta: Meta, items: list[tuple[str, str]]) -> ReleaseTerms:
        return ReleaseTerms(tuple(items), self._s(meta))

    def correct_said(self, items: list[Any]) -> CorrectSaid:          # (inputs, arrow, said)
        return CorrectSaid(items[0], items[2])

    def at_said(self, items: list[Any]) -> AtSaid:
        (start, stop), places, (said,) = _window(items)
        return AtSaid(start, stop, said, places)

    @v_args(meta=True)
    def at_instruction(self, meta: Meta, items: list[Any]) -> AtInstruction:
        """The span is the instruction's words' (an unknown one is marked there, not from
        the `at`)."""
        (start, stop), places, words = _window(items)
        first, last = words[0], words[-1]
        said = SimpleNamespace(empty=False, start_pos=first.start_pos, line=first.line,
                               column=first.column, end_line=last.end_line,
                               end_column=last.end_column)
        return AtInstruction(start, stop, tuple(str(w) for w in words), self._s(said), places)

    def eval_cmd(self, items: list[Assign]) -> Eval:
        return Eval(tuple(items))

    def correct_cmd(self, items: list[Any]) -> Correct:               # (inputs, arrow, targets)
        return Correct(items[0], items[2])

    def filename(self, items: list[Token]) -> str:
        token = items[0]    # quoted as a rule file's `terms` ("C:\Users\..." ended in a traceback)
        return _unquote(token) if token.type == "STRING" else str(token)

    @v_args(meta=True)
    def robot_name(self, meta: Meta, items: list[Token]) -> tuple[str, Span | None]:
        token = items[0]
        return (_unquote(token) if token.type == "STRING" else str(token)), self._s(meta)

    def simulate_cmd(self, items: list[Any]) -> Simulate:             # (world, seed or None, robot or None)
        robot, where = items[2] if items[2] is not None else (None, None)
        return Simulate(items[0], None if items[1] is None else str(items[1]), robot, where)

    @v_args(meta=True)
    def time(self, meta: Meta, items: list[float]) -> tuple[float, Span | None]:
        return float(items[0]), self._s(meta)

    def at_cmd(self, items: list[Any]) -> At:
        (start, stop), places, targets = _window(items)
        return At(start, stop, tuple(targets), places)

    def epochs(self, items: list[Token]) -> tuple[str, float]:
        return ("epochs", float(items[0]))

    def rate(self, items: list[Token]) -> tuple[str, float]:
        return ("rate", float(items[0]))

    def plot(self, items: list[str]) -> tuple[str, str]:
        return ("plot", items[0])

    def unconstrained(self, items: list[Token]) -> tuple[str, bool]:
        return ("constrained", False)

    def adapt_cmd(self, items: list[tuple[str, Any]]) -> Adapt:      # (option, its value)
        return Adapt(**dict(items), given=tuple(key for key, _ in items))

    def show_cmd(self, items: list[Any]) -> Show:                     # (what, plot file or None)
        return Show(str(items[0]), items[1])

    def undo_cmd(self, items: list[Token]) -> Undo:
        return Undo()

    def save_cmd(self, items: list[str | None]) -> Save:
        return Save(items[0])

    def help_cmd(self, items: list[Token | None]) -> Help:
        return Help(None if items[0] is None else str(items[0]))

    def quit_cmd(self, items: list[Token]) -> Quit:
        return Quit()


def _window(items: list) -> tuple[tuple[float, float | None], Places, list]:
    """An `at`'s times (the end ``None`` without `to`), where each is written, and the rest."""
    start, stop, *rest = items
    return ((start[0], None if stop is None else stop[0]),
            (start[1], None if stop is None else stop[1]), rest)


def _not_a_target(exc: UnexpectedInput, line: str, where: str) -> RuleSyntaxError | None:
    """``correct road=1 -> steering is not`` (or a rule's ``then speed is not``): said at the
    `not`, as for ``... is not LM``."""
    if "->" not in line and line.split()[:1] != ["at"]:
        return not_in_action_before(exc, line, where)
    found = not_in_action_before(exc, line, where, r"->|^\s*at\b")
    if found is not None:
        found.message = found.message.replace("an action", TARGETS[0])
        found.hint = TARGETS[1]
    return found


def _keyword_glued(first: Token, second: Token) -> bool:
    """A keyword cut out of one word (`adapt epochs50`, `seed5`, `plotx.png`), as in a rule
    file; a time and its unit are one word as written (`at 12.5s`)."""
    return second.type != "S" and keyword_glued(first, second, parser())


def parse_command(line: str, path: str | None = None, lineno: int = 1) -> Command:
    """Parse one command (``line`` may span several lines for a wrapped rule).

    ``path`` and ``lineno`` place the command in its lesson file, so errors read
    ``lesson.lesson:12:5``.
    """
    where = path or "<prompt>"
    try:
        bad = _bad_number(line, where)
        if bad is not None:
            raise bad
        try:
            tree = parse_apart(parser(), line, apart=_keyword_glued)
        except Glued as glued:
            raise glued_error(glued, line, where, parser(), "command", _expected) from None
        except UnexpectedInput as exc:
            raise _unknown_command(line, line, where, 1) or _not_a_target(exc, line, where) \
                or _syntax_error(exc, line, where) from None
        check_nesting(tree, line, where)
        check_modifiers(tree, line, where, TARGETS if "->" in line or
                        line.split()[:1] == ["at"] else None)
    except RuleSyntaxError as exc:        # parsed alone: put it at its line of the lesson
        exc.span = shift(exc.span, lineno - 1)
        raise
    result = _ToCommand(line, where, lineno - 1).transform(tree)
    if isinstance(result, Tree):            # pragma: no cover - every alternative is handled
        raise RuleSyntaxError(f"cannot read `{line.strip()}`")
    if isinstance(result, TellOperators):
        check_settings(result.settings)
    _check_file_name(result, line, where, lineno)
    if isinstance(result, Adapt):
        _check_once(result, line, where, lineno)
        _check_values(result, line, where, lineno)
    return result


#: a number as the grammar reads it (Lark's SIGNED_NUMBER)
_NUMBER = r"[-+]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?"
#: a word that begins as a number does, up to a blank, `=`, `,` or `#`
_NUMBERISH = r"[-+]?\.?\d[^\s=,#]*"
#: a name, from its first character only: tried from every character of a long word, the
#: search went over the rest of the word each time (`eval` and 20,000 letters took 40 s)
_NAME = r"(?<![\w\-])([A-Za-z_][\w\-]*)"
#: what a number is, in the words `mitos eval` says it
DECIMAL = "a decimal number such as 78, -4.5 or 1e3"
TIME_HINT = "a time is in seconds: `at 5s` or `at 5` (`at 0.005s` for 5 ms)"


def _bad_number(line: str, where: str) -> RuleSyntaxError | None:
    """`road=0x1F`, `7_8`, `at 0x10s`, `at 12ms`: a number glued to letters, which the lexer
    reads as a number and a name, so the error fell on the next word (or `at 0x10s turn
    harder` read `x10s` as an instruction's word). Said at the number, as `mitos eval` says
    it; only where a teaching command takes a number (a rule's are the rule language's)."""
    first = line.split()[:1]
    found: list[tuple[int, str, str, bool]] = []     # (start, word, whose, is a time)
    if first in (["eval"], ["correct"], ["at"]):
        found += [(m.start(2), m.group(2), f"`{m.group(1)}`", False) for m in
                  re.finditer(rf"{_NAME}\s*=\s*({_NUMBERISH})", line)]
        found += [(m.start(2), m.group(2), f"`{m.group(1)}`", False) for m in
                  re.finditer(rf"{_NAME}\s+is\s+({_NUMBERISH})", line)]
    if first == ["at"]:
        found += [(m.start(1), m.group(1), "a time", True) for m in
                  re.finditer(rf"(?:^\s*at|\sto)\s+({_NUMBERISH})", line)]
        glued = re.match(rf"\s*at\s+\S+\s+(to({_NUMBERISH}))", line)
        if glued:       # `at 13s to14s ...`: `to14s` was an instruction's word (or a name)
            column = glued.start(1) + 1
            return RuleSyntaxError(
                f"unexpected `{glued.group(1)}`",
                span=Span.in_text(line, where, 1, column, column + len(glued.group(1))),
                expected="`to` and the time the window ends",
                hint=f"`to` and `{glued.group(2)}` are two words: `to {glued.group(2)}`")
    if first == ["adapt"]:
        found += [(m.start(2), m.group(2), f"`{m.group(1)}`", False) for m in
                  re.finditer(rf"\b(epochs|rate)\s+({_NUMBERISH})", line)]
    for start, word, whose, time in sorted(found):
        if re.fullmatch(_NUMBER + ("s?" if time else ""), word):
            continue
        lineno = line.count("\n", 0, start) + 1
        column = start - (line.rfind("\n", 0, start) + 1) + 1
        return RuleSyntaxError(
            f"{whose} must be a number{' of seconds' if time else ''}, not `{word}`",
            span=Span.in_text(line, where, lineno, column, column + len(word)),
            expected=DECIMAL + (", with or without `s`" if time else ""),
            hint=TIME_HINT if time else None)
    return None


def _check_file_name(c: Command, line: str, where: str, lineno: int) -> None:
    """`simulate ""`, `save ""`, `plot ""`: a quoted file name that is empty names no file
    (``Path('')`` is the current directory: `simulate ""` said "`` is a directory"), as an
    empty path on the command line is a usage error; nor does one no system can open
    (:func:`_name_problem`)."""
    name, example = ((c.world, "simulate worlds/figure4.yaml") if isinstance(c, Simulate) else
                     (c.path, "save taught.rules") if isinstance(c, Save) else
                     (c.plot, "plot terms.png") if isinstance(c, (Show, Adapt)) else
                     (None, ""))
    problem = _name_problem(name) if name is not None else None
    if name is not None and problem is not None:    # (`save`, `plot`: a system's traceback)
        at = line.find(name)
        at = at if at >= 0 else max(line.find('"'), 0)         # (a name written with escapes)
        raise LessonError(f"the file name {problem}", span=Span.in_text(
            "\n" * (lineno - 1) + line, where, lineno, at + 1, at + 1 + len(name)),
            hint=f"give a file name, e.g. `{example}`")
    if name is None or name.strip():
        return
    quoted = re.search(r'"\s*"', line)
    column, end = (quoted.start() + 1, quoted.end() + 1) if quoted else (1, None)
    raise LessonError("the file name is empty: it names no file",
                      span=Span.in_text("\n" * (lineno - 1) + line, where, lineno, column, end),
                      hint=f"give a file name, e.g. `{example}`")


def _name_problem(name: str) -> str | None:
    """What keeps ``name`` from naming a file anywhere (``None``: nothing): a NUL byte, a
    `\\ud800` escape (half a character, which no path can be written in), or a part of more
    than 255 bytes (the longest a file system allows)."""
    if "\0" in name:
        return "holds a NUL byte, which no file name can"
    try:
        parts = name.encode("utf-8").split(b"/")
    except UnicodeEncodeError:
        return "holds a `\\u` escape of half a character (a lone surrogate)"
    if any(len(part) > 255 for part in parts):
        return "has a part of more than 255 bytes, more than a file system allows"
    return None


def _check_once(c: Adapt, line: str, where: str, lineno: int) -> None:
    """`adapt rate 0.9 rate 0.01`: an option given twice is refused at its second place
    (which one was meant cannot be known)."""
    for key in c.given:
        if c.given.count(key) > 1:
            word = "unconstrained" if key == "constrained" else key
            places = [m.start() for m in re.finditer(rf"\b{word}\b", line)]
            column = places[1] + 1 if len(places) > 1 else 1
            raise RuleSyntaxError(f"`{word}` is given twice in one `adapt`",
                                  span=Span.in_text("\n" * (lineno - 1) + line, where, lineno,
                                                    column, column + len(word)),
                                  hint="give each option once")


#: the most epochs one `adapt` runs (the paper's lesson needs 60; an epoch takes milliseconds,
#: and 10^300 epochs would be a hang, not a lesson)
MAX_EPOCHS = 100_000


def _check_values(c: Adapt, line: str, where: str, lineno: int) -> None:
    """`adapt epochs 2.5`, `adapt rate 1e-400`: a value that cannot be used is refused at its
    place in the line, before the session looks for examples, and named as written (1e-400 is
    0 once read)."""
    def refuse(word: str, message: str, hint: str) -> None:
        match = re.search(rf"\b{word}\s+(\S+)", line)
        assert match is not None                      # the grammar put the value there
        raise LessonError(message.format(match.group(1)),
                          span=Span.in_text("\n" * (lineno - 1) + line, where, lineno,
                                            match.start(1) + 1, match.end(1) + 1),
                          hint=hint)

    e = c.epochs
    if e is not None and not (math.isfinite(e) and e == int(e) and e >= 1):
        refuse("epochs", "epochs must be a whole number of at least 1, not {}",
               "for example `adapt epochs 50`")
    if e is not None and e > MAX_EPOCHS:
        refuse("epochs", f"at most {MAX_EPOCHS:,} epochs in one `adapt`, not {{}}",
               "adapt again to go on from where it stopped")
    if c.rate is not None and not 0.0 < c.rate < 1.0:      # (1e-400 is refused as a number)
        refuse("rate", "the learning factor must lie in (0, 1), not {}",
               "the paper's eta: try `rate 0.5`")


def _unknown_command(line: str, text: str, path: str, lineno: int) -> RuleSyntaxError | None:
    """"unknown command `corect`, did you mean `correct`?" when the first word is no command
    (and not a rule label: ``r27: if ...``)."""
    import re

    from ..errors import did_you_mean

    match = re.match(r"\s*([A-Za-z_][A-Za-z0-9_\-]*)(\s*:)?", line)
    if match is None or match.group(2) or match.group(1) in COMMAND_WORDS + ("if",):
        return None
    word = match.group(1)
    column = match.start(1) + 1
    said = starts_instruction(line.split())
    if said is not None:
        return RuleSyntaxError(
            f"unknown command `{word}`: an instruction takes a window of the recorded run, "
            f"`at 13s to 14.5s {said}`",
            span=Span.in_text(text, path, lineno, column, column + len(word)),
            expected="`at START [to END]` before one of the instructions " + INSTRUCTION_LIST,
            hint="`simulate WORLD` records a run; `help at` says more")
    rest = line[match.end():].lstrip()
    said = " ".join(line.split())
    if rest.split()[:1] == ["is"] and "then" in rest.split():
        # `size is SMALL_SZ then speed is SLOW`: a rule without its `if` (the second line of
        # a wrapped rule whose first was dropped by Ctrl-C reads so too)
        return RuleSyntaxError(
            f"unknown command `{word}`: a rule begins with `if`",
            span=Span.in_text(text, path, lineno, column, column + len(word)),
            expected="a rule (`if CONDITION then ACTION`, or `LABEL: if ...`)",
            hint=f"`if {said}`")
    if rest.startswith("=") or rest.split()[:1] == ["is"]:
        # `steering is very LM` or `speed=20` alone (the session knows which names are
        # outputs; the parser does not, so the forms are named, not one to type)
        return RuleSyntaxError(
            f"unknown command `{word}`: `{said}` alone is neither a rule nor a correction",
            span=Span.in_text(text, path, lineno, column, column + len(word)),
            expected=f"a rule (`if ... then {said}`), or a correction (`at TIME {said}`, "
                     f"`correct NAME=VALUE ... -> {said}`)",
            hint="`at 12.5s ...` corrects the run `simulate WORLD` recorded; `help at` and "
                 "`help correct` say more")
    return RuleSyntaxError(f"unknown command `{word}`",
                           span=Span.in_text(text, path, lineno, column, column + len(word)),
                           expected="a rule (`if ... then ...`, or `LABEL: if ...`) or one of "
                                    + ", ".join(COMMAND_WORDS),
                           hint=(f"a rule label ends with a colon: `{word}: if ...`"
                                 if line[match.end():].split()[:1] == ["if"] else
                                 _window_said_otherwise(line.split()) or
                                 did_you_mean(word, COMMAND_WORDS + ("if",)) or "type `help`"))


#: Words said between a window's times for `to` (`at 13s until 14s`).
_TO_SAID_OTHERWISE = frozenset({"until", "till", "til", "through", "thru", "and", "upto"})
#: A time as a window writes it: a decimal number of seconds, with or without `s`.
_TIME = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?s?"


def _window_said_otherwise(words: list[str]) -> str | None:
    """A window of the recorded run written otherwise than `at START [to END]`: `at` glued to
    its time (`at13s`: "type `help`"), or `from 13s to 14s` ("did you mean `frozen`?")."""
    glued = re.fullmatch(rf"at({_TIME})", words[0])
    if glued is not None:
        return (f"`at` and `{glued.group(1)}` are two words: `"
                + " ".join(["at", glued.group(1), *words[1:]]) + "`")
    if words[0] in ("from", "between", "during") and len(words) > 1 \
            and re.fullmatch(_TIME, words[1]):
        if len(words) > 3 and re.fullmatch(_TIME, words[3]):
            return f"a window of the recorded run is written `at {words[1]} to {words[3]} ...`"
        return f"a tick of the recorded run is named `at {words[1]} ...` (a window: `at START " \
               "to END ...`)"
    return None


#: The instructions, as messages list them.
INSTRUCTION_LIST = ", ".join(f"`{k}`" for k in INSTRUCTIONS)


def starts_instruction(words: list[str]) -> str | None:
    """The instruction whose first words ``words`` begin with (or that begins with all of
    ``words``), as written in full: ``turn harder``, ``turn`` -> ``turn harder``."""
    for phrase in INSTRUCTIONS:
        said = phrase.split()
        n = min(len(said), len(words))
        if n and words[:n] == said[:n]:
            return phrase
    return None


def incomplete(line: str) -> bool:
    """True when ``line`` is the start of a rule that continues on the next line."""
    try:
        parser().parse(line)
    except (UnexpectedEOF, UnexpectedToken) as exc:
        at_end = isinstance(exc, UnexpectedEOF) or exc.token.type == "$END"
        if not at_end:
            return False
        words = line.split()
        return bool(words) and (words[0] == "if" or (words[0].endswith(":")
                                                      and "if" in words[1:2]))
    except UnexpectedInput:
        return False
    return False


def _words(name: str) -> str:
    from ..lang.parse import _words as words

    return words(name, WORDS)


def _expected(names: Iterable[str]) -> str | None:
    words = sorted({_words(n) for n in names if not n.startswith("__") and n not in UNSAID})
    if not words:
        return None
    return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " or " + words[-1]


FIRST_WORDS_HINT = ("a line is a rule (`if ... then ...`) or a command: " + ", ".join(
    COMMAND_WORDS[:-1]) + " (type `help`)")


def _syntax_error(exc: UnexpectedInput, text: str, path: str) -> RuleSyntaxError:
    """Lark's exception in words: never ``$END`` or ``Token(...)``."""
    if isinstance(exc, UnexpectedCharacters):
        pos: int = exc.pos_in_stream  # type: ignore[assignment]  # lark declares None; the lexer sets an int
        char = text[pos] if pos < len(text) else ""
        message = f"unexpected character `{char}`" if char.isprintable() else \
            f"unexpected character {char!r}"
        return RuleSyntaxError(message, span=Span.in_text(text, path, exc.line, exc.column),
                               expected=_expected(exc.allowed or ()),
                               hint=FIRST_WORDS_HINT if exc.column == 1 else None)
    expected = set(getattr(exc, "expected", None) or ())
    words = text.split()
    if ("->" in words or words[:1] == ["at"]) and "HEDGE" in expected:
        # a target takes only the hedges that move a value along its scale: offered every
        # hedge of a rule's condition, it then refused `seldom LM` (no meaning for a target)
        expected = expected - {"HEDGE"} | {"TARGET_HEDGE"}
    if isinstance(exc, UnexpectedEOF) or (isinstance(exc, UnexpectedToken)
                                          and exc.token.type == "$END"):
        return _end_error(text, path, expected)
    assert isinstance(exc, UnexpectedToken)      # the third kind, after the two above
    token: Token = exc.token
    assert token.line is not None and token.column is not None   # the lexer places its tokens
    span = Span.in_text(text, path, token.line, token.column,
                        token.column + max(1, len(str(token.value))))
    before = text[:token.start_pos].split() if token.start_pos is not None else []
    expected = _merged_states(before, expected)
    return RuleSyntaxError(f"unexpected {_describe(token)}", span=span,
                           expected=_expected(expected),
                           hint=_token_hint(text, token, before, expected))


def _end_error(text: str, path: str, expected: set[str]) -> RuleSyntaxError:
    """The line ended before its command or rule did, said at its end, with what may follow
    there (less what LALR's merged states offer that cannot)."""
    lines = lines_of(text) or [""]
    line = len(lines_of(text.rstrip())) or 1
    column = len(lines[line - 1]) + 1 if line <= len(lines) else 1
    if text.split()[:1] == ["at"] and "to" in text.split()[2:3]:   # LALR's merged states:
        expected = {e for e in expected if e.upper() != "TO"}     # the `to` is behind us
    if text.split()[:1] == ["simulate"] and text.split()[-1] == "robot":
        expected = {"NAME"}             # (a quoted one is said by the hint)
    return RuleSyntaxError("the line ends too early",
                           span=Span.in_text(text, path, line, column),
                           expected=_expected(expected), hint=_eof_hint(text))


def _merged_states(before: list[str], expected: set[str]) -> set[str]:
    """What may stand after the words ``before``, of what the parser ``expected``: LALR
    merges states the commands share, so it offers options of other commands (an `adapt`
    option after `simulate`), an arrow already behind us, or too few (after `save FILE` the
    line may only end)."""
    if before[:1] == ["save"]:              # `save out dir.rules`: one file name, then the end
        expected = {"$END"}
    if before[:1] == ["adapt"] and before[-1:] not in (["epochs"], ["rate"], ["plot"]):
        # LALR's merged states: after `adapt epochs 50` it read "expected `,`, `->` or a name"
        expected = {"EPOCHS", "RATE", "PLOT", "UNCONSTRAINED", "$END"}
    if before[:1] == ["simulate"] and before[-1:] == ["robot"]:
        expected = {"NAME"}                 # (a quoted one is said by the hint)
    if before[:1] == ["simulate"]:          # LALR's merged states: no `adapt` option here
        expected -= {"EPOCHS", "RATE", "PLOT", "UNCONSTRAINED"}
        if "ROBOT" in expected and "seed" not in before:    # (`seed` is an anonymous token)
            expected.add("SEED_WORD")
    if "->" in before or before[:1] in (["at"], ["eval"]):   # LALR's merged states: no arrow
        expected.discard("ARROW")                           # is behind us or has a place
    if ("->" in before or before[:1] == ["at"]) and "WITH" in expected:
        # a target reuses the rule language's consequent, which a rule's `with` may follow;
        # a target takes no weight, and the line may end after it
        expected = expected - {"WITH"} | {"$END"}
    return expected


def _token_hint(text: str, token: Token, before: list[str], expected: set[str]) -> str | None:
    """What an unexpected ``token`` after the words ``before`` most likely means: a slip the
    prompt knows (:func:`_teach_hint`, a glued name), FCL's `;`, `=` for `is`, a misspelt
    keyword, or what a line begins with."""
    if str(token.value) == ";":          # FCL's `... then speed is SLOW;` (not a hedge)
        return "a rule or command needs no `;` at its end"
    hint = _teach_hint(text, token, before) or glued_name_hint(text, token)
    if hint is not None:
        return hint
    if not before:
        return FIRST_WORDS_HINT
    if str(token.value) == "=" and "IS" in expected and before and "->" not in before \
            and before[:1] != ["at"]:
        # `if road = WIDE then ...`: as in a rule file (`mitos_cli.lang.parse`)
        return f"write `{before[-1]} is ...`: a condition or action reads `variable is " \
               f"TERM` (or `is 5` for a crisp value), not `=`"
    if token.type == "NAME" and "IS" in expected and "->" in before:
        return _target_hint(before)
    if token.type == "NAME" and "IS" in expected:
        return "a condition reads `variable is TERM`"
    if "EQUAL" in expected:
        return "give values as NAME=VALUE, e.g. `road=78`"
    return keyword_hint(token, expected) or (
        joined_hint(text, token) if "if" in before and "->" not in before else None)


def _target_hint(before: list[str]) -> str:
    """After ``correct ... ->``: what a target reads, and where an instruction goes
    (``correct heading=-5 -> turn harder``)."""
    after = before[len(before) - before[::-1].index("->"):]
    said = starts_instruction(after)
    window = (f"`{said}` is an instruction: it takes a window of the recorded run, "
              f"`at 13s to 14.5s {said}`, not inputs" if said is not None else
              "a relative instruction (`turn harder`, ...) takes a window of the recorded run: "
              "`at 13s to 14.5s turn harder`")
    return f"a target reads `OUTPUT=VALUE` or `OUTPUT is TERM`; {window}"


def _teach_hint(text: str, token: Token, before: list[str]) -> str | None:
    """What a mistake of the teaching language most likely is, from the words before the
    token the parser stopped at."""
    at = token.start_pos or 0
    if any(ord(c) > 127 for c in str(token.value)) or (at and ord(text[at - 1]) > 127):
        return "names are written in ASCII letters, digits, `_` and `-`"
    if before[:1] == ["adapt"] and before[-1:] not in (["epochs"], ["rate"]) \
            and re.fullmatch(r"[\d.]+", str(token.value)):     # `adapt 50`: options are named
        option = "epochs" if str(token.value).isdigit() else "rate"
        return (f"adapt's options are named: `adapt {option} {token.value}` "
                + ("(how many epochs)" if option == "epochs" else "(the learning rate)"))
    if before == ["show"]:                  # `show rule`: which one was meant
        from ..errors import did_you_mean

        return did_you_mean(str(token.value), SHOW_WHAT)
    if token.value == "," and before[:1] in (["eval"], ["correct"], ["at"]):
        if re.search(r"\bis\s+\S+\s*\Z", text[:at]):     # a target in words: `-> steering is LS,`
            return ("targets in words are joined with `and`, not `,`: `steering is LS and "
                    "speed is SLOW`")
        return "values are separated by spaces, not commas: `road=78 size=45`"
    glued = at > 0 and not text[at - 1].isspace()
    if before[:1] == ["simulate"] and "robot" in before:
        return _robot_hint(text, token, before)
    if before[:1] == ["simulate"] and (before[-1:] == ["seed"]                  # `seed x`
                                       or before[-2:-1] == ["seed"] and glued):  # `seed 2x`
        return "a seed is a whole number written in digits (such as 42)"
    if before[:1] == ["simulate"] and len(before) == 2:   # `sed 3`: an option, mistyped
        from ..errors import did_you_mean

        close = did_you_mean(str(token.value), ["seed", "robot"])
        if close is not None:
            return close
    if (before[:1] == ["save"] or before[:1] == ["simulate"] and len(before) == 2
            or before[-2:-1] == ["plot"]):                      # just after the file name
        return 'a file name with a space in it is quoted: "my file.rules"'
    if before[:1] == ["at"] and len(before) > 1 and any(
            re.fullmatch(r"[\d.]+(ms|sec|secs|seconds?|min|m|h)", word)
            for word in (before[1], "".join(before[1:3]))):
        return TIME_HINT
    if before[:1] == ["at"] and len(before) in (2, 3) and re.fullmatch(_TIME, before[1]) and (
            len(before) == 3 and before[2] in _TO_SAID_OTHERWISE and re.match(_TIME, text[at:])
            or len(before) == 2 and re.fullmatch(rf"-(?:{_TIME})?", str(token.value))):
        # `at 13s until 14s`, `at 13s - 14s`: the word between the times read as an output
        end = re.match(_TIME, text[at:].lstrip("-").lstrip())
        return (f"a window is written `at {before[1]} to {end.group(0) if end else 'END'}`: "
                "the word between its times is `to`")
    if before[:1] == ["at"] and str(token.value) == "->":   # `correct`'s arrow, copied
        rest = text[token.end_pos or 0:].strip()
        return f"`at` takes no `->`: its targets follow the time, `{' '.join(before)} {rest}`"
    if before[:1] == ["at"] and str(token.value) == "=" and len(before) > 2:
        # `at 13s to 14.5s turn harder steering=50`: an instruction and a target on one line
        window = before[:4] if before[2:3] == ["to"] else before[:2]
        words = before[len(window):]
        said = starts_instruction(words[:-1])
        if said is not None and words[:-1] == said.split():
            head = " ".join(window)
            value = text[token.end_pos or 0:].split()[:1] or ["VALUE"]
            return (f"one correction per `at` line: the instruction, `{head} {said}`, or the "
                    f"target, `{head} {words[-1]}={value[0]}`, each on a line of its own")
    if before[-2:] == ["is", "not"] and ("->" in before or before[:1] == ["at"]):
        return ("a target is a term, with hedges if need be (`steering is very LM`); `not` says "
                "what it should not be, which is no target")
    if ("->" in before or before[:1] == ["at"]) and "is" in before:
        # `-> steering is turn harder`: an instruction said as a term (it was "unexpected
        # `harder`, expected `and`", as if `turn` were a term of steering)
        after = before[len(before) - before[::-1].index("is"):] + [str(token.value)]
        said = starts_instruction(after) if len(after) > 1 else None
        if said is not None:
            where = ("`at 13s to 14.5s " if before[:1] != ["at"] else
                     "`" + " ".join(before[:before.index("is") - 1]) + " ")
            return (f"`{said}` is an instruction, not a term: say it alone after the window, "
                    f"{where}{said}`" + (", not after inputs" if "->" in before else ""))
    if "->" in before or before[:1] == ["at"]:            # targets: the hedges they take
        if re.match(r"\s*=", text[token.end_pos or 0:]):   # `steering is LB speed=3`
            return _hedge_hint(text, token, tuple(HEDGE_STEPS))
        return _hedge_hint(text, token, tuple(HEDGE_STEPS)) or \
            _two_words(text, token, tuple(HEDGE_STEPS))
    return _hedge_hint(text, token)                      # a rule's condition: any hedge


def _robot_hint(text: str, token: Token, before: list[str]) -> str:
    """After `simulate WORLD ... robot`: the seed said after the robot (the grammar takes it
    before), or a robot's name that is no bare name (`cart 2`, `7`, `r-2.b`), which a world
    may give (`name: "cart 2"`) and the line takes quoted."""
    robot = before.index("robot")
    if str(token.value) == "seed" and robot < len(before) - 1:
        seed = text[token.end_pos:].split()[:1] or ["42"]
        return ("the seed comes before the robot: `" + " ".join(
            before[:robot] + ["seed", seed[0]] + before[robot:]) + "`")
    said = list(re.finditer(r"(?<=\s)robot\s+", text[:token.start_pos or len(text)]))
    name = text[said[-1].end():].strip() if said else ""    # (the keyword, not `robots/`)
    name = name.split(" seed ")[0].strip() or "NAME"
    quoted = name if name.startswith('"') else '"' + name.replace('"', '\\"') + '"'
    return (f"a robot's name that is no bare name (a space, a dot, digits alone) is quoted: "
            f"`robot {quoted}`")


def _describe(token: Token) -> str:
    return "the end of the line" if token.type == "$END" else f"`{token.value}`"


def _eof_hint(text: str) -> str | None:
    words = text.split()
    if not words:
        return None
    first = words[0]
    if first == "correct":
        return "write `correct INPUT=VALUE ... -> OUTPUT=VALUE ...`"
    if first == "at":
        return "write `at 12.5s OUTPUT=VALUE ...` (after `simulate WORLD`)"
    if first in ("eval",):
        return "give the inputs as NAME=VALUE, e.g. `eval road=78 size=45 position=4`"
    if first == "simulate" and words[-1] == "seed" and len(words) > 2:
        return f"a seed is a whole number written in digits: `{' '.join(words)} 42`"
    if first == "simulate" and words[-1] == "robot" and len(words) > 2:
        return ("name the robot whose run `at` corrects, as the world names it (its first is "
                "`robot`): `simulate multirobot robot oncoming`, quoted when the name is no "
                'bare name (`robot "cart 2"`)')
    if first == "simulate":
        return "name a world file, e.g. `simulate worlds/figure4.yaml`"
    if first == "unfrozen":
        return ("`unfrozen` releases terms, as `unfrozen steering.LS`; a rule frozen in this "
                "session is released with `undo`")
    return None
