"""One error hierarchy for everything a user can get wrong.

Every error a user can meet is a :class:`MitosError`. It carries where the problem is (a
:class:`Span` with file, line, column and the offending source line), what was expected and a
hint saying what to do next. The CLI prints :meth:`MitosError.render` and exits 1; anything that
is not a ``MitosError`` is a bug and keeps its traceback.
"""

from __future__ import annotations

import difflib
import functools
import re
import unicodedata
from collections.abc import Iterable
from dataclasses import dataclass


@dataclass(frozen=True)
class Span:
    """A position in a source file (1-based line and column)."""

    path: str | None
    line: int
    column: int
    source_line: str | None = None
    end_column: int | None = None
    #: the column where ``source_line`` starts (a long line is kept only around the column)
    source_start: int = 1

    def __str__(self) -> str:
        where = self.path or "<input>"
        return f"{where}:{self.line}:{self.column}"

    def ending(self, token: str) -> Span:
        """This span narrowed to ``token`` where the text it covers ends with it (the unknown
        term of ``speed is MEDUIM``); itself where it cannot tell."""
        if self.source_line is None or self.end_column is None:
            return self
        start = self.end_column - len(token)
        i = start - self.source_start
        if start < self.column or i < 0 or self.source_line[i:i + len(token)] != token:
            return self
        return type(self)(self.path, self.line, start, self.source_line, self.end_column,
                          self.source_start)      # (``replace``'s, without its generic walk)

    def naming(self, token: str) -> Span:
        """This span narrowed to the first whole word ``token`` it covers on its line (the
        unknown variable of ``raod is WIDE``, the name of ``behavior a:``); itself where it
        cannot tell."""
        if self.source_line is None:
            return self
        i = self.column - self.source_start
        stop = None if self.end_column is None else self.end_column - self.source_start
        found = _whole_word(token).search(
            self.source_line, max(i, 0), stop if stop is not None else len(self.source_line))
        if i < 0 or found is None:
            return self
        column = found.start() + self.source_start
        return type(self)(self.path, self.line, column, self.source_line,
                          column + len(token), self.source_start)

    @classmethod
    def in_text(cls, text: str, path: str | None, line: int, column: int,
                end_column: int | None = None) -> Span:
        """A span at ``line``/``column`` of ``text``, remembering that line for the caret.

        The text's lines are split once and kept for the next call with the same text: a
        reader that gives every line or node a span (FLL, ``.fis``, FCL) split the whole text
        again each time, quadratic in the file (8,000 FLL rules took 50 s).
        """
        lines = _lines(text)
        source = lines[line - 1] if 0 < line <= len(lines) else None
        return cls(path, line, column, source, end_column)

    @classmethod
    def at(cls, text: str, path: str | None, index: int, line: int, column: int,
           end_column: int | None = None, breaks: re.Pattern[str] | None = None) -> Span:
        """A span at character ``index`` of ``text`` (which is at ``line``/``column``).

        Looks at no more than about :data:`SHOWN` characters either side of ``index``, not at
        the whole text or the whole line, so a reader can give every node of a large file a
        span (splitting the whole text per node made parsing quadratic in the file, and
        searching for the end of the line quadratic in a long line: one rule of 80,000
        conditions on one line took 20 s). Lines longer than :data:`SHOWN` keep only the part
        around the column.
        """
        index = min(max(index, 0), len(text))
        if breaks is None or breaks is _NEWLINE:   # as below (one window: SHOWN < 256), faster
            found = text.find("\n", index, index + SHOWN)
            end = found if found >= 0 else min(len(text), index + SHOWN)
            lo = max(0, index - 256)
            start = text.rfind("\n", lo, index) + 1 or lo
            first = max(start, index - SHOWN // 2)
            return cls(path, line, column, text[first:min(end, first + SHOWN)], end_column,
                       column - (index - first))
        # the kept part ends by `index + SHOWN` at the latest: no need to look further
        stop = breaks.search(text, index, index + SHOWN)
        end = stop.start() if stop else min(len(text), index + SHOWN)
        start, window = 0, 256
        while True:
            lo = max(0, index - window)
            last = None
            for last in breaks.finditer(text, lo, index):  # noqa: B007 - keep the last match
                pass
            if last is not None:
                start = last.end()
                break
            if lo == 0 or window > SHOWN:
                start = lo
                break
            window *= 4
        first = max(start, index - SHOWN // 2)
        source = text[first:min(end, first + SHOWN)]
        return cls(path, line, column, source, end_column, column - (index - first))


@functools.lru_cache(maxsize=1024)
def _whole_word(token: str) -> re.Pattern[str]:
    """``token`` as a whole word (not inside a longer name), compiled once: every rule's
    names are placed with it (escaping and compiling per call was a third of the check)."""
    return re.compile(rf"(?<![\w\-]){re.escape(token)}(?![\w\-])")


@functools.lru_cache(maxsize=2)
def _lines(text: str) -> tuple[str, ...]:
    """``lines_of(text)``, kept for the last texts (a str caches its hash, and a cache hit
    on the same object compares by identity: after the first call, O(1))."""
    return tuple(lines_of(text))


_BREAK = re.compile(r"\r\n|\r|\n")


_LONE_CR = re.compile(r"\r(?!\n)")


def lone_cr_as_lf(text: str) -> str:
    """``text`` with each ``\r`` that ends a line alone (classic Mac OS files) as ``\n``, for
    a lexer that counts lines at ``\n`` (Lark): it read such a file as one line, so a ``#``
    or ``//`` comment on the first line took every line after it (a rule file "names no term
    set", an FCL file ended early) and every message was at line 1. Offsets stay as they were."""
    return _LONE_CR.sub("\n", text) if "\r" in text else text


def lines_of(text: str) -> list[str]:
    """The lines of ``text`` as an editor and the readers' lexers count them, at ``\n``,
    ``\r\n`` and ``\r``. ``str.splitlines`` also breaks at a vertical tab, a form feed,
    U+001C to U+001E, U+0085, U+2028 and U+2029 inside a line, so a message about a later
    line showed the line before it (a rule file with U+2028 in a comment: `r2`'s error, under
    `r1`'s line) and the FLL and ``.fis`` readers numbered every later line one too far on."""
    lines = _BREAK.split(text)
    return lines[:-1] if lines[-1:] == [""] else lines


#: how much of a long source line a span keeps (characters, around the column)
SHOWN = 240
#: a quoted token of input in a message (`...`, no spaces: the words between two quotes of
#: one message are not a token) too long to be read
_QUOTED = re.compile(r"`([^`\s]{201,})`")


def _shorten(match: re.Match[str]) -> str:
    """A long quoted piece of a message as its start and end (a mutated file's 200,000-digit
    number quoted whole buries the message). Past 200 characters, not 80: a file's path in a
    deep directory (`/home/.../taught.rules`, 85 characters) was abridged where the user needs
    it whole."""
    quoted = match.group(1)
    return f"`{quoted[:40]}...{quoted[-20:]}` ({len(quoted):,} characters)"


_NEWLINE = re.compile(r"\n")
#: control characters (C0 but tab and newline, DEL, C1): what a mutated file or a pasted
#: escape sequence holds, shown rather than sent to the terminal (an ESC would act there); and
#: Unicode's bidirectional embeddings, overrides and isolates, which reorder what the terminal
#: shows (a name with U+202E reads backwards: "Trojan Source", CVE-2021-42574)
_CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f\u202a-\u202e\u2066-\u2069]")


#: Unicode's format characters (category Cf, as of Unicode 15) besides those: zero-width
#: spaces and joiners, LRM/RLM and the Arabic letter mark, the word joiner, a BOM inside the
#: text, soft hyphens, tags. Invisible, so two names that differ by one look the same
#: (``road`` and ``ro\u200bad``) and a caret after one stands a column off
_INVISIBLE = re.compile("[\u00ad\u0600-\u0605\u061c\u06dd\u070f\u0890\u0891\u08e2\u180e"
                        "\u200b-\u200f\u202a-\u202e\u2060-\u2064\u2066-\u206f\ufeff"
                        "\ufff9-\ufffb\U000110bd\U000110cd\U00013430-\U0001343f"
                        "\U0001bca0-\U0001bca3\U0001d173-\U0001d17a\U000e0001"
                        "\U000e0020-\U000e007f]")


def _escape(char: str) -> str:
    code = ord(char)
    return (f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}" if code < 0x10000
            else f"\\U{code:08x}")


def visible(text: str) -> str:
    """``text`` with each control or format character as its escape (``\\x1b``,
    ``\\u202e``, ``\\u200b``)."""
    text = _CONTROL.sub(lambda m: _escape(m.group()), text)
    return _INVISIBLE.sub(lambda m: _escape(m.group()), text)


def invisible_character(text: str) -> str | None:
    """The first format character of ``text`` (:data:`_INVISIBLE`) as its escape and name
    (`` `\\u200b` (ZERO WIDTH SPACE)``), or None: a name that holds one looks like another."""
    found = None if text.isascii() else _INVISIBLE.search(text)
    if found is None:
        return None
    char = found.group()
    return f"`{_escape(char)}` ({unicodedata.name(char, 'a format character')})"


def control_character(text: str) -> str | None:
    """The first control character of ``text`` as its escape (``\\x1b``), or None: a name
    that holds one would act on the terminal wherever it is printed."""
    found = _CONTROL.search(text)
    return visible(found.group()) if found else None


def excerpt(span: Span | None, whole_lines: bool = True) -> list[str]:
    """The line ``span`` points into and a caret under what it covers, indented, as an error
    and a ``mitos check`` finding show them (nothing where the span kept no line);
    ``whole_lines`` false: one caret where the span runs to the line's end (a finding about
    a whole rule, or a behavior, which points at its first rule)."""
    if span is None or span.source_line is None:
        return []
    raw = span.source_line.rstrip("\r\n")
    col = span.column - span.source_start                # 0-based in ``raw``
    if len(raw) > SHOWN:                # a very long line: only the part around the column
        first = min(max(0, col - SHOWN // 2), len(raw) - SHOWN)
        raw, col = raw[first:first + SHOWN], col - first
    raw = _CONTROL.sub("\ufffd", raw)            # (one character each: the caret stays)
    raw = _INVISIBLE.sub("\ufffd", raw)          # (a zero-width one put it a column off)
    src = raw.expandtabs(4)
    col = len(raw[:max(0, col)].expandtabs(4))
    width = max(1, (span.end_column or span.column + 1) - span.column)
    if not whole_lines and span.end_column is not None \
            and span.end_column - span.source_start >= len(raw.rstrip()):
        width = 1
    return [f"    {src}", "    " + " " * col + "^" * min(width, max(1, len(src) - col))]


class MitosError(Exception):
    """An error in something the user wrote or asked for.

    ``message`` says what is wrong, ``expected`` what would have been right, ``hint`` what to
    do next. ``span`` points into the file when there is one.
    """

    kind = "error"
    #: The CLI's exit code: 1 for a mistake in what the user wrote or asked for.
    exit_code = 1

    def __init__(self, message: str, *, span: Span | None = None, expected: str | None = None,
                 hint: str | None = None) -> None:
        super().__init__(message)
        self.message = message
        self.span = span
        self.expected = expected
        self.hint = hint

    def render(self) -> str:
        """The message as the CLI prints it: ``path:line:col: error: ...``, line, caret, hint."""
        head = f"{self.span}: " if self.span else ""
        out = [f"{head}{self.kind}: {visible(_QUOTED.sub(_shorten, self.message))}"]
        out += excerpt(self.span)
        if self.expected:
            out.append(f"expected {visible(self.expected)}")
        if self.hint:
            out.append(f"hint: {visible(self.hint)}")
        return "\n".join(out)

    def __str__(self) -> str:
        return self.render()


class RuleSyntaxError(MitosError):
    """A rule file, prompt line or lesson that does not parse."""

    kind = "syntax error"


class NameError_(MitosError):
    """A name (variable, term, hedge, behavior, operator) that is not defined."""

    kind = "name error"


class UsageError(NameError_):
    """An option given a name from a fixed list that is not on it (``--planner dwb``,
    ``--require succes``, ``--to fxl``): a mistake in the command line, so exit 2 as Click's
    own bad option values (``--seed -1``) are, with the names and "did you mean". A name looked
    up in a file the user gave (a behavior, an input) stays a name error (exit 1): the file may
    be what is wrong."""

    kind = "usage error"
    exit_code = 2


class TermSetError(MitosError):
    """A term set (YAML) that is malformed or inconsistent."""

    kind = "term set error"


class RuleBaseError(MitosError):
    """A rule base that parses but makes no sense (duplicate labels, cycles, ...)."""

    kind = "rule base error"


class InputError(MitosError):
    """Bad input values for an evaluation (missing, NaN, non-numeric)."""

    kind = "input error"


class CommandError(InputError, ValueError):
    """A driving command (``Simulation.step(command)``, a planner's output, a Gymnasium action)
    that is not finite ``[steering deg, speed in/s]`` numbers of the right shape. Also a
    ``ValueError``, which these were before they were ``MitosError``s."""


class NoRuleFiredError(MitosError):
    """No rule fired for some input and the output declares no default."""

    kind = "no rule fired"


class EmptyOutputError(NoRuleFiredError):
    """Rules that set an output fired, yet left it no value (a Mamdani set that its sampling
    misses), and the output declares no default: a :class:`NoRuleFiredError` to a caller,
    told as what happened, not as "no rule fired"."""

    kind = "no output value"


class WorldError(MitosError):
    """A world file that is malformed or impossible."""

    kind = "world error"


class LessonError(MitosError):
    """A teaching command or lesson that cannot be carried out."""

    kind = "lesson error"


class WriteError(MitosError):
    """A file that cannot be written: its directory missing or read-only, a full disk. One
    kind and one wording ("error: cannot write `X`: why") from every command, whatever the file
    holds: `export` called it a format error and `simulate` an error."""


class FormatError(MitosError):
    """A foreign file (FCL, FIS, FLL) that cannot be read or written."""

    kind = "format error"


class NoRulesError(FormatError):
    """A foreign file whose variables and terms are whole but that has no rules (jFuzzyLogic's
    membership-function tests): no rule base, but ``termset`` for what draws or checks terms."""

    def __init__(self, message: str, *, termset: object, span: Span | None = None) -> None:
        super().__init__(message, span=span, hint="`mitos plot terms` and `mitos check` read "
                                                  "its terms alone")
        self.termset = termset


class Terminated(KeyboardInterrupt):
    """A SIGTERM (``kill PID``, a batch scheduler's time limit) or a SIGHUP (the terminal
    closed, an ssh session dropped) raised where the command is, as Ctrl-C raises
    KeyboardInterrupt: what stops cleanly on one stops so on the others. ``code`` is the
    exit code a shell expects of the signal (143, 129). Not a user's mistake, but here, the
    lowest stage, since the teaching prompt, which goes on after a Ctrl-C, must tell it from
    one and end (the handler that raises it is the CLI's,
    :func:`mitos_cli.cli.progress.terminate_as_interrupt`)."""

    def __init__(self, code: int = 143) -> None:
        super().__init__()
        self.code = code


def closest(name: str, candidates: Iterable[str]) -> str | None:
    """The candidate closest to ``name`` (as written, then in any case, then the one name it
    begins), or ``None`` when nothing is close. A name over thrice the longest candidate is
    close to none (difflib's ratio stays below 0.5) and is not handed to difflib, which indexes
    it whole: a 100 MB name in a rule file was a MemoryError."""
    pool = list(candidates)
    if not pool or len(name) > 3 * max(map(len, pool)):
        return None
    close = difflib.get_close_matches(name, pool, n=1, cutoff=0.6)
    if not close:
        lowered = {c.lower(): c for c in pool}
        hit = lowered.get(name.lower())
        close = [hit] if hit else difflib.get_close_matches(name.lower(), list(lowered), n=1,
                                                            cutoff=0.6)
        close = [lowered.get(c, c) for c in close]
    if not close and len(name) >= 3:         # `avoid` for `avoid_obstacle`: too short for difflib
        close = [c for c in pool if c.lower().startswith(name.lower())]
        close = close if len(close) == 1 else []
    if not close and 2 <= len(name) <= 3:    # `HJ` for `HI`: difflib's ratio is 0.5
        close = [c for c in pool if _one_letter_off(name, c)]
        close = close if len(close) == 1 else []
    return close[0] if close else None


def _one_letter_off(a: str, b: str) -> bool:
    """Whether ``a`` and ``b`` (short names, as fuzzy terms often are: NB, ZE, PS) differ in
    one letter, or in two neighbours swapped; not in a digit (`r9` is no typo of `r1`)."""
    if len(a) != len(b) or a == b:
        return False
    off = [i for i, (x, y) in enumerate(zip(a, b)) if x != y]
    if not all(a[i].isalpha() and b[i].isalpha() for i in off):
        return False
    return len(off) == 1 or (len(off) == 2 and off[1] == off[0] + 1
                             and a[off[0]] == b[off[1]] and a[off[1]] == b[off[0]])


def closest_file(name: str, candidates: Iterable[str]) -> str | None:
    """The file name among ``candidates`` closest to ``name``, comparing stems where the
    extension is the same: a shared ``.yaml`` made ``nosuch.yaml`` close to ``office.yaml``
    for difflib. A misspelt extension (``mitos.rule``) is still close to ``mitos.rules``."""
    pool = list(candidates)
    stem, dot, suffix = name.rpartition(".")
    if dot and stem:
        same = {c[:-len(suffix) - 1]: c for c in pool
                if c.endswith("." + suffix) and len(c) > len(suffix) + 1}
        if same:
            hit = closest(stem, same)
            if hit is not None:
                return same[hit]
            pool = [c for c in pool if c not in same.values()]
    return closest(name, pool)


def did_you_mean(name: str, candidates: Iterable[str]) -> str | None:
    """The closest candidate to ``name`` as a hint, or ``None`` when nothing is close."""
    close = closest(name, candidates)
    return f"did you mean `{close}`?" if close is not None else None


def unknown(what: str, name: str, candidates: Iterable[str], *, span: Span | None = None,
            cls: type[MitosError] = NameError_, owner: str | None = None) -> MitosError:
    """An "unknown X `name` [of `owner`]" error with a did-you-mean hint and the valid names."""
    pool = sorted(set(candidates))
    hint = did_you_mean(name, pool)
    listing = ", ".join(pool) if len(pool) <= 12 else ", ".join(pool[:12]) + ", ..."
    expected = f"one of {listing}" if pool else None
    of = f" of `{owner}`" if owner else ""
    return cls(f"unknown {what} `{name}`{of}", span=span, expected=expected, hint=hint)


#: The name MITOS is installed under (``pip list``, ``pip show``). Not ``mitos``: on PyPI that
#: is another project, which ``pip install mitos`` (or ``-U``) would put in MITOS's place.
DISTRIBUTION = "mitos-planner"

#: What each optional extra of :data:`DISTRIBUTION` installs, as pyproject.toml's
#: ``[project.optional-dependencies]`` says (``tests/test_errors.py`` holds the two alike).
EXTRAS = {
    "plot": ("matplotlib>=3.6",),
    "maps": ("Pillow>=9",),
    "dask": ("dask[distributed]>=2024.1", "cryptography>=41"),
    "gym": ("gymnasium>=1.0",),
}


def install_hint(extra: str) -> str:
    """How to install what an optional extra holds: its packages by name, which works however
    MITOS was installed (from a checkout, a wheel), where ``pip install 'mitos[plot]'`` took
    another project's ``mitos`` from PyPI."""
    import shlex

    packages = " ".join(shlex.quote(p) for p in EXTRAS[extra])
    return f"pip install {packages} (the `{extra}` extra of {DISTRIBUTION})"
