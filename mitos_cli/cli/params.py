"""The types and checks of option values: numbers, names, files, choices, repeats."""

from __future__ import annotations

import math
import os
import re
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from enum import Enum
from pathlib import Path
from typing import Any, TypeVar

import typer
from typer._click import Context, Parameter
from typer._click.exceptions import NoSuchOption
from typer._click.types import FloatRange, ParamType
from typer.core import TyperCommand, TyperOption

from ..errors import NameError_, UsageError, unknown, visible
from ..numbers import exact, parse_number

E = TypeVar("E", bound=Enum)
V = TypeVar("V", bound="str | list[str] | None")

#: The most randomised runs ``simulate --runs`` and ``compare --runs`` take per world (and
#: choice): about a day of one core's time. A few zeros too many (``--runs 1000000000``) made
#: the list of seeds and tasks before the first run, eating the machine's memory for minutes
#: with nothing on the screen; now it is a number outside the option's range (exit 2).
MAX_RUNS = 100_000


class Number(FloatRange):
    """The type of every option that takes a number: a ``whole`` one (a count, a seed) or
    any finite one, from ``min`` to ``max`` (either may be left open). Anything else is a
    usage error (exit 2) saying what the option means, what it takes and what was given
    ("the number of grid points per input must be a whole number from 2 to 10000, not
    `abc`"), where Click's range types said "'abc' is not a valid int range" or "0 is not in
    the range x>=1", naming neither. (Typer's help still shows the range, ``[2<=x<=10000]``,
    as for Click's own range types: this is one.)

    Numbers are read as every file here reads them (:func:`~mitos_cli.numbers.parse_number`:
    ASCII decimal, an optional exponent). Python's ``int`` and ``float`` also read ``1_0``
    and ``١٠`` (Arabic-Indic digits) as 10, which ran without a word. ``nan`` passes any
    range (every comparison with NaN is false) and an infinity turns a check off: both are
    refused, and ``1e400`` is said as it was written, not as the ``inf`` it reads as."""

    def __init__(self, what: str, min: float | None = None, max: float | None = None,
                 whole: bool = True) -> None:
        super().__init__(min=min, max=max)
        self.what = what
        self.whole = whole
        self.name = "whole number" if whole else "number"

    def convert(self, value: Any, param: Parameter | None, ctx: Context | None) -> Any:
        if not isinstance(value, str):        # a default, or a value converted already
            return value
        number = self.read(value)
        if number is None or (self.min is not None and number < self.min) \
                or (self.max is not None and number > self.max):
            self.fail(self.wrong(value), param, ctx)
        return number

    def read(self, text: str) -> int | float | None:
        """``text`` as this option's number, or None (not a number it takes)."""
        if self.whole:
            try:
                return int(text) if _WHOLE.fullmatch(text) else None
            except ValueError:                  # past Python's 4,300 digits
                return None
        try:
            x = parse_number(text)
        except ValueError:
            return None
        return x if math.isfinite(x) else None

    def wrong(self, text: str) -> str:
        """What is wrong with ``text``, in words: the option's meaning, the numbers it
        takes, what was given and, where it helps, how to write it."""
        kind = "a whole number" if self.whole else "a number"
        if self.min is not None and self.max is not None:
            kind += f" from {exact(self.min)} to {exact(self.max)}"
        elif self.min is not None:
            kind += f" of {exact(self.min)} or more"
        elif self.max is not None:
            kind += f" of {exact(self.max)} or less"
        return f"{self.what} must be {kind}, not {given(text)}{self.how(text)}"

    def how(self, text: str) -> str:
        """How to write ``text`` as a number this option takes, where that can be told."""
        try:
            x = parse_number(text)
        except ValueError:
            try:
                float(text)                     # Python's reading: `1_0`, `١٠`
            except ValueError:
                return ""
            return " (write it with the digits 0 to 9)"
        if not self.whole and math.isinf(x) and "inf" not in text.lower():
            return " (past 1.8e308, the largest number a float holds)"
        if self.whole and abs(x) < 1e18 and x == int(x) and not _WHOLE.fullmatch(text):
            return f" (write it in digits: {int(x)})"
        most = getattr(sys, "get_int_max_str_digits", lambda: 0)()    # (0: no limit)
        if self.whole and _WHOLE.fullmatch(text) and 0 < most < len(text.strip().lstrip("+-")):
            return f": Python reads whole numbers of at most {most:,} digits"
        return ""


class Factor(Number):
    """A factor that is 0 or at least ``least`` (``simulate --speed``): a run paced to a
    factor of ``4.9e-324`` waited ``t / 4.9e-324`` seconds for its first tick, past what
    ``time.sleep`` takes (a traceback, "timestamp out of range for platform time_t"), and
    ``1e-9`` thirty years a second of the run. Below ``least``, a usage error that says so."""

    def __init__(self, what: str, least: float, zero: str) -> None:
        super().__init__(what, 0.0, whole=False)
        self.least, self.zero = least, zero

    def read(self, text: str) -> int | float | None:
        x = super().read(text)
        if x == 0 and re.search(r"[1-9]", text.lower().split("e")[0]):
            return None                 # `1e-400`: a factor too small for a float, not 0
        return None if x is not None and 0 < x < self.least else x

    def wrong(self, text: str) -> str:
        return (f"{self.what} must be 0 ({self.zero}) or a number of {exact(self.least)} or "
                f"more, not {given(text)}{self.how(text)}")


def given(text: str) -> str:
    """An option's value as a message quotes it (a long one abridged)."""
    if not text.strip():
        return "an empty value"
    if len(text) > 60:
        return f"`{visible(text[:20])}...{visible(text[-10:])}` ({len(text):,} characters)"
    return f"`{visible(text)}`"


#: a whole number as an option takes it: ASCII digits, a sign, spaces around
_WHOLE = re.compile(r"\s*[-+]?[0-9]+\s*", re.ASCII)


def named(value: V) -> V:
    """A name given as an option (``-b ''``, ``--and ''``) is not empty: an empty one would
    quietly mean the default. Nor is a file named as an argument or option (``mitos simulate
    ''``, ``--lesson ''``, each of a list): ``Path('')`` is the current directory, so it was
    "`` is a directory", exit 1, where the same empty value of ``-b`` is a usage error."""
    values = value if isinstance(value, list) else [value]
    if any(v is not None and not v.strip() for v in values):
        raise typer.BadParameter("must name something, not be empty")
    return value


def file_arg(text: str) -> Path:
    """A file named on the command line, as a path: :func:`named`'s check for a
    ``Path``-typed option, which Click would otherwise turn from ``''`` into ``.`` (the
    current directory) before any callback sees it, so that ``-o ''`` said "`.` has no
    extension" or "cannot write `.`: it is a directory", exit 1."""
    named(text)
    return Path(not_a_directory_name(text))


class Positional(ParamType):
    """The type of a positional argument whose metavar says what it takes (``FILE``,
    ``[RULEBASE] NAME=VALUE...``): Typer's help prints the type's name beside it otherwise,
    ``<str>`` or ``<file_arg>``, which tells a user nothing. ``parse`` checks and converts.
    (Typer 0.26-0.28, the versions allowed, carry their own Click as ``typer._click``.)"""

    name = "text"

    def __init__(self, parse: Callable[[str], Any] | None = None) -> None:
        self.parse = parse

    def get_metavar(self, param: Parameter, ctx: Context | None = None) -> str:
        return ""

    def convert(self, value: Any, param: Parameter | None, ctx: Context | None) -> Any:
        return self.parse(value) if self.parse is not None and isinstance(value, str) else value


#: A positional argument of words or file names (kept as given).
WORDS = Positional()
#: A positional argument naming a file, as :func:`file_arg` reads it.
FILE = Positional(file_arg)


def not_a_directory_name(text: str) -> str:
    """A file's name does not end in a separator: ``Path('d.csv/')`` is ``d.csv``, so ``-o
    d.csv/`` wrote a file where the user named a directory."""
    if text.endswith(("/", os.sep)) and text.strip("/" + os.sep):
        raise typer.BadParameter(f"`{text}` ends in `{text[-1]}`, so it names a directory, not a "
                                 f"file: give the file's name (`{text.rstrip('/' + os.sep)}`, or "
                                 f"a name inside that directory)")
    return text


def target_of(kind: type[E], given: str | None, output: Path | None,
              suffixes: dict[E, str], what: str) -> E:
    """The member of ``kind`` that ``--to`` names, or, without ``--to``, the one whose file
    extension ``-o`` has (`mitos convert tipper.fis -o tipper.fll`): Click's "Missing option
    '--to'" said nothing of the extension given. Neither: a usage error naming both ways."""
    if given is not None:
        return choice(kind, given, what)
    if output is not None:
        for member, suffix in suffixes.items():
            if output.suffix.lower() == suffix:
                return member
    names = ", ".join(m.value for m in kind)
    told = (f"`{output}` has no extension that names one" if output is not None else
            "or give -o a file with the format's extension")
    raise typer.BadParameter(f"say which {what} to write: --to {names}; {told}",
                             param_hint="'--to'")


def choice(kind: type[E], value: str, what: str) -> E:
    """The member of ``kind`` named ``value`` (any case). An unknown name is a mistake in the
    command line, as an unknown planner or T-norm is: exit 2, the names, and "did you mean"."""
    for member in kind:
        if member.value == value.lower():
            return member
    raise unknown(what, value, [m.value for m in kind], cls=UsageError)


@contextmanager
def option_names() -> Iterator[None]:
    """Checks of options' names against fixed lists (``--planner``, ``--and``) made by code
    shared with Python callers, which raise a :class:`NameError_`: here the name came from the
    command line, so it is a usage error (exit 2), with the same words and hint."""
    try:
        yield
    except UsageError:
        raise
    except NameError_ as exc:
        raise UsageError(exc.message, span=exc.span, expected=exc.expected,
                         hint=exc.hint) from None


def choices(kind: type[Enum]) -> str:
    """The metavar of an option taking one of ``kind``'s names: ``[a|b|c]``."""
    return "[" + "|".join(m.value for m in kind) + "]"


def completer(kind: type[Enum]) -> Callable[[str], list[str]]:
    """Shell completion of one of ``kind``'s names."""
    return lambda incomplete: [m.value for m in kind if m.value.startswith(incomplete)]


class GivenTwice(typer.BadParameter):
    """A usage error (exit 2) that says itself, without Click's "Invalid value for"."""

    def format_message(self) -> str:
        return self.message


class OnceCommand(TyperCommand):
    """A command whose single-value options may each be given once. Click keeps the last of
    ``--x road --x size`` without a word, so what was asked for first was silently dropped;
    repeats are refused as ``--fix size=45 --fix size=50`` and ``road=78 road=80`` are.
    Every command is registered with this class (``cls=``), so each of its options is checked
    here rather than option by option."""

    def parse_args(self, ctx: Any, args: list[str]) -> list[str]:   # (Click's Context)
        # not while completing a command line, nor when help is asked for
        try:
            if not ctx.resilient_parsing and not set(args) & set(ctx.help_option_names):
                _, _, order = self.make_parser(ctx).parse_args(args=list(args))
                refuse_repeats(ctx, order)
            return super().parse_args(ctx, args)
        except NoSuchOption as exc:
            from .meant import option_meant

            raise option_meant(ctx, args, exc) from None

    def collect_usage_pieces(self, ctx: Any) -> list[str]:
        """The usage line's pieces, a required argument written as its bare name (``mitos
        convert [OPTIONS] FILE``), as Click and POSIX write it: Typer writes it in braces
        (``{FILE}``), which reads as a choice or shell brace expansion."""
        return [piece[1:-1] if piece.startswith("{") and piece.endswith("}") else piece
                for piece in super().collect_usage_pieces(ctx)]


def refuse_repeats(ctx: typer.Context, order: list) -> None:
    """A usage error (exit 2) for the first single-value option given twice in ``order``
    (the parameters as the parser met them, once per occurrence). Flags and options that
    take several values (``--fix``, ``--world``) may repeat."""
    seen: dict[str, Any] = {}
    for param in order:
        if not isinstance(param, TyperOption) or param.multiple or param.count \
                or param.is_flag or param.name is None:
            continue
        key = SPELLINGS.get(param.name, param.name)
        first = seen.get(key)
        if first is not None and first.name != param.name:
            raise GivenTwice(f"{first.get_error_hint(ctx)} and {param.get_error_hint(ctx)} are "
                             f"one option, given twice: give it once (one would be dropped "
                             f"without a word)", ctx=ctx, param=param)
        if first is not None:
            raise GivenTwice(f"{param.get_error_hint(ctx)} is given twice: give it once (the "
                             f"last would be kept without a word)", ctx=ctx, param=param)
        seen[key] = param


#: options that are one option under two names (``compare -n``, the old spelling of --runs:
#: ``--runs 3 -n 1`` ran one run a choice, with a word only on the spelling)
SPELLINGS = {"runs_n": "runs"}
