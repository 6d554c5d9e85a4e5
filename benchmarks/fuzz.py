"""Fuzzing campaign: every input kind MITOS reads, mutated, fed to the library's own readers.

Run from the repository root (one command each)::

    python benchmarks/fuzz.py --quick                       # a short campaign: --per-format 150
    python benchmarks/fuzz.py --per-format 9000 --out fuzz-found      # 100,950 inputs
    python benchmarks/fuzz.py --per-format 9000 --jobs 2 --out fuzz-found  # on 2 cores
    python benchmarks/fuzz.py --per-format 9000 --shard 0/4           # a quarter of them
    python benchmarks/fuzz.py --via cli --per-format 1000   # through `mitos`'s main, in process
    python benchmarks/fuzz.py --via subprocess --per-format 30        # spot checks

Each input kind (rule files, term-set YAML, world YAML, map YAML + PGM, FCL, ``.fis``, FLL,
teach commands, lessons, ``eval --batch`` CSV, teach journals, command-line arguments) is
seeded from the shipped files and ``tests/data``, mutated by grammar-aware mutators (tokens
inserted, deleted, swapped and duplicated; keywords swapped; numbers replaced by ``nan``,
``inf``, ``-0``, ``1e308``, huge integers; truncation at a line; Unicode junk, CRLF, tabs, BOM;
deep nesting; long lines; YAML anchors, aliases, tags and duplicate keys; PGM header and pixel
bytes) and run in this process under a time limit (``SIGPROF`` after ``--limit`` CPU seconds: a
hang is cut off and counted, never waited for; a worker stuck where the signal cannot reach is
killed by the campaign). Every input is classified as

- ``loaded``: read (and, for rule bases, evaluated) without complaint;
- ``refused+pos``: a :class:`~mitos_cli.errors.MitosError` with ``file:line:col``;
- ``refused``: a ``MitosError`` without a position (acceptable only where the input has no
  lines: a command-line argument);
- ``foreign``: any other exception, a bug; its signature is the type and the raising frame;
- ``slow``: more than ``--slow`` CPU seconds (plus 0.01 s per KB of input), or cut off;
- ``nonfinite``: a rule base that loads but gives ``inf`` or an undeclared ``NaN``, or an
  output outside its universe;
- ``warning``: a ``RuntimeWarning`` or ``UserWarning`` (NumPy's "invalid value") that would
  reach the user's terminal.

For each new foreign / slow / non-finite signature a minimal reproducer (lines, then
characters, removed while the signature stays) is written to ``--out``. The table printed at
the end is the one in ``docs/reliability.md``.
"""

from __future__ import annotations

import argparse
import contextlib
import hashlib
import io
import json
import math
import os
import random
import re
import resource
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import traceback
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))          # this tree's mitos_cli, not an installed one
from options import guarded, positive_int  # noqa: E402

SEED = 20261201

OUTCOMES = ("loaded", "refused+pos", "refused", "foreign", "slow", "nonfinite", "warning")
#: outcomes that are defects (the campaign exits 1 if any input has one)
BAD = ("foreign", "slow", "nonfinite", "warning")


class Timeout(BaseException):
    """Raised by the alarm inside an input that ran past the limit (not an ``Exception``, so
    no ``except Exception`` in the code under test swallows it)."""


class NonFinite(Exception):
    """A loaded rule base evaluated to a non-finite number it did not declare."""


# ---------------------------------------------------------------------------------------------
# mutators

NUMBERS = ("nan", "NaN", "inf", "-inf", "Infinity", "-0", "0", "1e308", "-1e308", "1e400",
           "1e-320", "99999999999999999999999999999999999999", "1_000", "0x1F", "0b2", ".5",
           "5.", "1e5.5", "-", "+", "1__e5")
JUNK = ("\ufeff", "\u00e9", "\u2028", "\x00", "\x0b", "\x1c", "\t", "\r\n", "\r", "\u0301",
        "\U0001F600", "\\", '"', "'", "#", ":", "{", "[", "]", "}", "&a", "*a", "!!python/name:os.system",
        "<<: *a", "%", "@", "`")
TOKEN = re.compile(r"[A-Za-z_][\w\-]*|[-+]?\d[\d_.eE+\-xXbB]*|\s+|.", re.S)


def tokens(text: str) -> list[str]:
    return TOKEN.findall(text)


@dataclass
class Mutator:
    """Text mutations shared by all kinds, with a kind's vocabulary and nesting forms."""

    words: tuple[str, ...]
    nest: tuple[Callable[[int], str], ...] = ()
    #: whether a line may be repeated thousands of times (:meth:`repeat`): for kinds whose
    #: lines declare (rules, terms, CSV rows), not for lessons, where each line is work
    many: bool = False

    def __call__(self, rng: random.Random, text: str) -> str:
        ops = self.ops + (Mutator.repeat,) if self.many else self.ops
        for _ in range(rng.choice((1, 1, 1, 2, 3))):
            text = rng.choice(ops)(self, rng, text)
        return text

    def _tokens(self, rng, text):
        toks = tokens(text) or [""]
        return toks, rng.randrange(len(toks))

    def insert(self, rng, text):
        toks, i = self._tokens(rng, text)
        toks.insert(i, rng.choice(self.words + NUMBERS + JUNK) + rng.choice(("", " ")))
        return "".join(toks)

    def delete(self, rng, text):
        toks, i = self._tokens(rng, text)
        del toks[i:i + rng.choice((1, 1, 2, 5))]
        return "".join(toks)

    def swap(self, rng, text):
        toks, i = self._tokens(rng, text)
        j = rng.randrange(len(toks))
        toks[i], toks[j] = toks[j], toks[i]
        return "".join(toks)

    def duplicate(self, rng, text):
        toks, i = self._tokens(rng, text)
        n = rng.choice((1, 3, 20))
        return "".join(toks[:i] + toks[i:i + n] * rng.choice((2, 3, 50)) + toks[i:])

    @staticmethod
    def size(rng, common: tuple[int, ...], large: int) -> int:
        """A repeat count: one of ``common``, or ``large`` one time in 20 (large inputs test
        time per KB; as often as small ones they would be most of the campaign's time)."""
        return large if rng.random() < 0.05 else rng.choice(common)

    def keyword(self, rng, text):
        toks = tokens(text)
        words = [i for i, t in enumerate(toks) if t[:1].isalpha()]
        if not words:
            return text
        toks[rng.choice(words)] = rng.choice(self.words)
        return "".join(toks)

    def number(self, rng, text):
        toks = tokens(text)
        nums = [i for i, t in enumerate(toks) if t[:1].isdigit() or t[:1] in "+-" and len(t) > 1]
        if not nums:
            return text
        toks[rng.choice(nums)] = rng.choice(NUMBERS)
        return "".join(toks)

    def truncate(self, rng, text):
        lines = text.splitlines(keepends=True)
        if not lines:
            return text
        cut = rng.randrange(len(lines))
        head = "".join(lines[:cut])
        return head + lines[cut][:rng.randrange(len(lines[cut]) + 1)]

    def junk(self, rng, text):
        i = rng.randrange(len(text) + 1)
        return text[:i] + rng.choice(JUNK) + text[i:]

    def whitespace(self, rng, text):
        choice = rng.randrange(4)
        if choice == 0:
            return text.replace("\n", "\r\n")
        if choice == 1:
            return "\ufeff" + text
        if choice == 2:
            return text.replace("    ", "\t")
        return text.replace("\n", "\r")

    def nesting(self, rng, text):
        if not self.nest:
            return text
        depth = self.size(rng, (50, 500, 3000), 20000)
        deep = rng.choice(self.nest)(depth)
        lines = text.splitlines(keepends=True)
        i = rng.randrange(len(lines) + 1)
        return "".join(lines[:i]) + deep + "\n" + "".join(lines[i:])

    def long_line(self, rng, text):
        toks, i = self._tokens(rng, text)
        toks.insert(i, rng.choice(("x", "a" * 40 + " ", "9")) * self.size(rng, (300, 5000),
                                                                          200000))
        return "".join(toks)

    def lines(self, rng, text):
        lines = text.splitlines(keepends=True)
        if len(lines) < 2:
            return text
        i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
        if rng.random() < 0.5:
            lines[i], lines[j] = lines[j], lines[i]
        else:
            lines.insert(i, lines[j])
        return "".join(lines)

    def repeat(self, rng, text):
        """One line repeated up to 20,000 times: a file of many rules (readers that did
        per-line work over the whole text were quadratic in it)."""
        lines = text.splitlines(keepends=True)
        if not lines:
            return text
        i = rng.randrange(len(lines))
        line = lines[i] if lines[i].endswith(("\n", "\r")) else lines[i] + "\n"
        n = min(self.size(rng, (10, 200, 2000), 20000), REPEATED // len(line))
        return "".join(lines[:i] + [line] * max(n, 1) + lines[i + 1:])

    ops = (insert, delete, swap, duplicate, keyword, number, truncate, junk, whitespace,
           nesting, long_line, lines)


#: a number as written in YAML (a token of :data:`TOKEN` that float() reads)
NUMBER = re.compile(r"[-+]?\d+(\.\d*)?([eE][-+]?\d+)?")


@dataclass
class NumberMutator(Mutator):
    """Numbers only, each pushed near or far: most inputs still load and run, so that what
    reads them later (a simulation) gets odd figures, not only the reader's refusals."""

    def __call__(self, rng: random.Random, text: str) -> str:
        toks = tokens(text)
        nums = [i for i, t in enumerate(toks) if NUMBER.fullmatch(t)]
        if not nums:
            return text
        for _ in range(rng.choice((1, 1, 2, 3))):
            i = rng.choice(nums)
            if NUMBER.fullmatch(toks[i]):         # (not one pushed already to `0x1F`)
                toks[i] = self.pushed(rng, float(toks[i]))
        return "".join(toks)

    @staticmethod
    def pushed(rng: random.Random, x: float) -> str:
        choice = rng.randrange(9)
        if choice == 0 or not math.isfinite(x):
            return rng.choice(NUMBERS)
        pushed = (lambda: x * rng.uniform(0.5, 1.5), lambda: -x, lambda: 0.0, lambda: x * 10,
                  lambda: x / 10, lambda: x + 1e-9, lambda: x - 1e-9,
                  lambda: float(round(x * rng.uniform(0.8, 1.2))))
        return repr(pushed[choice - 1]())


def yaml_mutator(words: tuple[str, ...]) -> Mutator:
    """YAML: the text mutators plus anchors, aliases, merge keys, tags and duplicate keys."""
    def alias_bomb(depth: int) -> str:
        n = min(depth, 12)
        rows = ["a0: &a0 [x, x, x, x, x, x, x, x, x, x]"]
        rows += [f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 10) + "]" for i in range(1, n)]
        return "\n".join(rows)

    return Mutator(words + ("&a", "*a", "<<", "!!str", "!!int", "!!float", "!!binary",
                            "!!timestamp", "!!set", "!!omap", "!!python/tuple", "~", "null",
                            "yes", "No", "ON", "0o17", "0b2", "1_e5", "2001-12-14", "? "),
                   (lambda d: "x: " + "[" * d + "]" * d,
                    lambda d: "x: " + "{a: " * d + "1" + "}" * d,
                    lambda d: "\n".join(" " * i + f"k{i}:" for i in range(min(d, 300))),
                    lambda d: "\n".join("  " * i + "- " for i in range(min(d, 200))),
                    alias_bomb,
                    lambda d: "b: &b {x: 1}\nc:\n  <<: *b\n  y: 2",
                    lambda d: "x: 1\nx: 2"))


#: the most characters :meth:`Mutator.repeat` makes of one line (a long line repeated
#: 20,000 times would be gigabytes; other large inputs are up to about 8 MB)
REPEATED = 8_000_000

#: a fuzzylite chained engine (rules testing outputs), which the readers restate
CHAIN_FLL = "\n".join((
    "Engine: chain", "InputVariable: x", "  range: 0 1", "  term: A Triangle 0 0.5 1",
    "  term: B Triangle 0.5 1 1.5", *(line for i in range(3) for line in (
        f"OutputVariable: y{i}", "  range: 0 1", "  aggregation: Maximum",
        "  defuzzifier: Centroid 100", "  default: 0.5", "  term: A Triangle 0 0.5 1",
        "  term: B Triangle 0.5 1 1.5")),
    "RuleBlock: main", "  conjunction: Minimum", "  disjunction: Maximum",
    "  implication: Minimum", "  activation: General", "  rule: if x is A then y0 is A",
    "  rule: if x is B then y0 is B", "  rule: if y0 is A and x is B then y1 is A",
    "  rule: if y0 is B or y0 is A then y1 is B", "  rule: if y1 is A and y0 is A then y2 is B",
    "  rule: if y1 is very B then y2 is A with 0.5")) + "\n"


RULE_WORDS = ("if", "then", "and", "or", "not", "is", "with", "use", "when", "end", "behavior",
              "terms", "operators", "frozen", "very", "somewhat", "any", "road", "size",
              "position", "steering", "speed", "WIDE", "NARROW", "SMALL_SZ", "LEFT", "RS",
              "MEDIUM", "min", "product", "and", "=", ":", ",", "(", ")", '"x.yaml"',
              "inference", "defuzzify", "centroid", "mamdani", "r1:")
RULE_NEST = (lambda d: "if " + "not " * d + "road is WIDE then speed is FAST",
             lambda d: "if " + "(" * d + "road is WIDE" + ")" * d + " then speed is FAST",
             lambda d: "if " + " and ".join(["road is WIDE"] * d) + " then speed is FAST",
             lambda d: "\n".join(f"z{i}: if road is WIDE and size is SMALL_SZ then speed is SLOW"
                                 for i in range(d)))


# ---------------------------------------------------------------------------------------------
# the command line: in this process (fast), or as a subprocess (spot checks)

#: ``path:line:col: `` starting a line of stderr: a positioned message
POSITIONED = re.compile(r"\S[^\n]{0,4000}?:\d{1,9}:\d{1,9}: ")


def cli_in_process(argv: list[str], work: Path) -> tuple[int, str, str]:
    """``mitos ARGV`` through the CLI's own ``main`` in this process, run in ``work``: the exit
    code, stderr and stdout. An exception escaping ``main`` propagates: it is what a user would
    see as a traceback."""
    from mitos_cli.cli.app import main

    out, err = io.StringIO(), io.StringIO()
    cwd, stdin = os.getcwd(), sys.stdin
    os.chdir(work)
    sys.stdin = io.StringIO("")         # the prompt, `--lesson -`, `--batch -`: end of input
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                main(argv)
                code = 0
            except SystemExit as exc:
                code = exc.code if isinstance(exc.code, int) else int(exc.code is not None)
    finally:
        os.chdir(cwd)
        sys.stdin = stdin
    return code, err.getvalue(), out.getvalue()


def cli_subprocess(argv: list[str], work: Path, timeout: float) -> tuple[int, str, str]:
    """``python -m mitos_cli ARGV`` in ``work``: what a user runs, for spot checks."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    try:
        r = subprocess.run([sys.executable, "-m", "mitos_cli", *argv], cwd=work, env=env,
                           capture_output=True, text=True, errors="replace", timeout=timeout)
    except subprocess.TimeoutExpired:
        raise Timeout() from None
    return r.returncode, r.stderr, r.stdout


#: how much of stdout is read for a refusal printed there (``mitos check`` prints its errors
#: first; a batch's outputs may be megabytes)
STDOUT_READ = 64_000


def cli_outcome(code: int, err: str, out: str = "") -> tuple[str, str]:
    """The outcome of one ``mitos`` run from its exit code and stderr, and its stdout where an
    exit 1 says no error on stderr, only warnings or nothing (``mitos check`` prints the errors
    it finds in a rule base, positioned, with its report on stdout, and what the reader warned
    of on stderr)."""
    if "Traceback (most recent call last)" in err:
        return "foreign", "traceback: " + err.strip().splitlines()[-1][:70]
    if "Warning: " in err:              # plain searches: a message may quote 200 KB of input
        line = next(x for x in err.splitlines() if "Warning: " in x)
        return "warning", line[max(0, line.index("Warning: ") - 20):][:80]
    if code in (0, 3):                 # 3: `simulate --require success` not met
        return "loaded", ""
    if code == 1:
        if "error: " not in err:
            found = refusal_on_stdout(out[:STDOUT_READ])
            if found[0] == "refused+pos" or not err.strip():
                return found
        first = err.strip().splitlines()[0][:60]
        positioned = any(POSITIONED.match(x) for x in err.splitlines()[:3])
        return ("refused+pos", "") if positioned else ("refused", first)
    if code == 2:
        return "refused", "usage error"
    return "foreign", f"exit {code}"


def refusal_on_stdout(out: str) -> tuple[str, str]:
    """An exit 1 whose answer is on stdout: the first error of ``mitos check``'s report (text,
    or ``--json``), positioned or not; ``(no message)`` when stdout holds none either."""
    if out.lstrip().startswith("{"):
        try:
            report = json.loads(out)
        except ValueError:
            report = {}
        errors = [f for f in report.get("findings", ()) if isinstance(f, dict)
                  and f.get("severity") == "error"] if isinstance(report, dict) else []
        if errors:
            positioned = isinstance(errors[0].get("span"), dict)
            return ("refused+pos", "") if positioned else \
                ("refused", "error: " + str(errors[0].get("message"))[:53])
        return "refused", "(no message)"
    line = next((x for x in out.splitlines() if "error: " in x and not x[:1].isspace()), None)
    if line is None:
        return "refused", "(no message)"
    return ("refused+pos", "") if POSITIONED.match(line) else ("refused", line[:60])


class _NonFiniteJSON(ValueError):
    pass


def _no_constant(name: str) -> float:
    raise _NonFiniteJSON(name)


def finite_outcome(code: int, err: str, out: str) -> tuple[str, str]:
    """:func:`cli_outcome`, and for a run that printed JSON: a `NaN` or `Infinity` in it is
    non-finite (no option of `simulate` or `compare` asks for one)."""
    outcome = cli_outcome(code, err, out)
    if outcome[0] == "loaded" and out.lstrip().startswith(("{", "[")):
        try:
            json.loads(out, parse_constant=_no_constant)
        except _NonFiniteJSON as exc:
            return "nonfinite", f"{exc} in --json"
        except ValueError:
            return "foreign", "--json printed what is not JSON"
    return outcome


#: runs (`--runs` times the worlds and choices) past which a mutated `simulate` or `compare`
#: command line is not run: a long run the user asked for, not a hang
MOST_RUNS = 12


def not_run(argv: list[str]) -> tuple[str, str] | None:
    """The outcome of a command line the harness does not run: one the system would refuse,
    or a long run the user asked for."""
    if not possible(argv):
        return "refused", "argument list too long (the system refuses to run it)"
    asked = long_run(argv)
    if asked:
        return "refused", f"not run: {asked} (a long run the user asked for)"
    return None


def long_run(argv: list[str]) -> str:
    """What a `simulate` or `compare` command line asks for that is too long for a campaign
    ('' if nothing): more than :data:`MOST_RUNS` runs (`compare`: runs times worlds times
    choices, with its defaults of 20 runs, four T-norms and two planners), or a live view
    paced in real time."""
    if argv[:1] not in (["simulate"], ["compare"]):
        return ""
    given = dict(zip(argv, argv[1:]))
    runs = given.get("--runs", "20" if argv[0] == "compare" else "1")
    n = int(runs) if runs.isascii() and runs.isdigit() and len(runs) <= 6 else 1
    total = n if 1 <= n <= 100_000 else 1      # (past 100,000, `--runs` is refused)
    if argv[0] == "compare":
        for flag, default in (("--and", 4), ("--or", 1), ("--inference", 1), ("--planner", 2)):
            total *= len(given[flag].split(",")) if flag in given else default
        total *= max(1, sum(1 for a in argv[1:] if a.endswith(".yaml")))
    if total > MOST_RUNS:
        return f"{total} runs"
    if ("--live" in argv or "--speed" in argv) and given.get("--speed") != "0":
        return "a live view in real time"
    return ""


def via_cli(kind: Kind, how: str, limit: float) -> Callable:
    """``kind.run`` replaced by the ``mitos`` command that reads the input."""
    def run(data, work: Path):
        argv = kind.argv(data, work)
        refused = not_run(argv)
        if refused is not None:
            return refused
        if how == "subprocess":
            return finite_outcome(*cli_subprocess(argv, work, timeout=3 * limit + 10))
        return finite_outcome(*cli_in_process(argv, work))
    return run


def possible(argv: list[str]) -> bool:
    """Whether the system would start a program with ``argv``: ``execve`` refuses (E2BIG) an
    argument over 128 KB or a list over ``ARG_MAX``, so no user can give ``mitos`` one."""
    return all(len(a.encode(errors="surrogatepass")) < 131072 for a in argv) and \
        sum(len(a) + 1 for a in argv) < os.sysconf("SC_ARG_MAX")


def command_line(text: str) -> list[str]:
    """A mutated command line as the shell would split it (NUL cannot be in an argument)."""
    text = text.replace("\x00", "")
    if len(text) >= os.sysconf("SC_ARG_MAX"):
        return text.split()             # too long to run anyway; shlex takes minutes on it
    try:
        return shlex.split(text)
    except ValueError:                  # an unclosed quote: the shell would wait for more
        return text.split()


# ---------------------------------------------------------------------------------------------
# input kinds: seeds and the run of one input

@dataclass
class Kind:
    name: str
    seeds: list[tuple[str, str | bytes]]
    mutate: Callable
    run: Callable                      # (data, workdir) -> None or an outcome; raises what it raises
    ext: str = ".txt"
    #: with ``--via cli``: (data, workdir) -> the ``mitos`` arguments that read the input
    #: (after writing it where they look); None where no command reads this kind alone
    argv: Callable | None = None
    tried: int = 0
    seconds: float = 0.0                          # wall clock, the kind's whole run
    cpu: float = 0.0                              # CPU seconds inside the inputs
    large: list = field(default_factory=list)     # (bytes, CPU seconds) of inputs >= LARGE
    counts: dict = field(default_factory=lambda: dict.fromkeys(OUTCOMES, 0))


def _shipped(*patterns: str) -> list[tuple[str, str]]:
    out = []
    for pattern in patterns:
        for p in sorted(ROOT.glob(pattern)):
            out.append((str(p.relative_to(ROOT)), p.read_text(encoding="utf-8")))
    return out


def check_finite(compiled) -> None:
    """Evaluate ``compiled`` at the universe's corners, middle and random points: outputs must
    be finite (NaN only where no rule fired and no default is declared) and inside the
    output's universe."""
    from mitos_cli.engine.evaluation import evaluate
    from mitos_cli.errors import MitosError

    lo, hi = compiled.universe[:, 0], compiled.universe[:, 1]
    rng = np.random.default_rng(0)
    X = np.vstack([lo, hi, (lo + hi) / 2, lo + (hi - lo) * rng.random((8, len(lo)))])
    try:
        res = evaluate(compiled, X, strict=False)
    except MitosError:
        return
    Y = np.asarray(res.outputs, dtype=float)
    Y = Y.reshape(len(X), -1)
    for j, name in enumerate(compiled.outputs):
        y = Y[:, j]
        if np.isinf(y).any():
            raise NonFinite(f"output `{name}` is infinite")
        v = compiled.variables[name]
        if np.isnan(y).any() and v.default is not None and not math.isnan(v.default):
            raise NonFinite(f"output `{name}` is NaN though it declares a default")
        lo_o, hi_o = v.universe
        fin = y[np.isfinite(y)]
        span = max(1.0, abs(hi_o - lo_o))
        outside = fin.size and ((fin < lo_o - 1e-9 * span).any()
                                or (fin > hi_o + 1e-9 * span).any())
        if outside and compiled.cons_linear is None and not _crisp_outside(compiled, j):
            raise NonFinite(f"output `{name}` = {fin.min():g}..{fin.max():g} lies outside "
                            f"its universe {lo_o:g}..{hi_o:g}")


def _crisp_outside(compiled, j: int) -> bool:
    """A crisp consequent or a default outside the universe was written by the user: an output
    there is what the rule base says, not a wrong number."""
    lo, hi = compiled.variables[compiled.outputs[j]].universe
    vals = compiled.cons_value[compiled.cons_mask[:, j], j]
    d = compiled.default[j]
    return bool(((vals < lo) | (vals > hi)).any() or (not math.isnan(d) and not lo <= d <= hi))


def evaluate_all(rb) -> None:
    from mitos_cli.engine.compile import compile_rulebase

    for b in rb.behaviors:
        if b.rules or b.uses:
            check_finite(compile_rulebase(rb, b.name))


class Kinds:
    """Builds the input kinds once (seeds, term sets, a teaching session)."""

    def __init__(self, work: Path, fresh: bool = True) -> None:
        self.work = work
        self.fresh = fresh
        rb_dir = work / "rb"
        if fresh:
            shutil.copytree(ROOT / "rulebases", rb_dir)
            shutil.copytree(ROOT / "worlds", work / "worlds")
            # the world of two robots that the lessons in words simulate
            shutil.copyfile(ROOT / "tests" / "data" / "fleet_tiny.yaml", work / "fleet.yaml")
        self.rb_dir = rb_dir
        self._termsets: dict[str, object] = {}
        self._session = None
        self._compiled = None

    # -- rule files ---------------------------------------------------------------------------
    def run_rules(self, text: str, _work: Path) -> None:
        from mitos_cli.errors import TermSetError
        from mitos_cli.lang.parse import parse_rules
        from mitos_cli.lang.resolve import build_rulebase
        from mitos_cli.lang.termfile import load_termset

        path = str(self.rb_dir / "fuzz.rules")
        parsed = parse_rules(text, path)
        termsets = []
        for name, span in parsed.terms:
            target = self.rb_dir / name
            if name not in ("mitos.terms.yaml", "drive.terms.yaml"):
                raise TermSetError(f"term set `{name}` not found", span=span)
            if name not in self._termsets:
                self._termsets[name] = load_termset(target)
            termsets.append(self._termsets[name])
        rb = build_rulebase(parsed, tuple(termsets), tuple(n for n, _ in parsed.terms))
        evaluate_all(rb)

    def run_termset(self, text: str, _work: Path) -> None:
        from mitos_cli.lang.parse import parse_rules
        from mitos_cli.lang.resolve import build_rulebase
        from mitos_cli.lang.termfile import load_termset, parse_termset

        ts = parse_termset(text, str(self.rb_dir / "fuzz.terms.yaml"))
        names = {v.name for v in ts.variables}
        other = "drive.terms.yaml" if "road" in names else "mitos.terms.yaml"
        if other not in self._termsets:
            self._termsets[other] = load_termset(self.rb_dir / other)
        rules = (self.rb_dir / "mitos.rules").read_text()
        parsed = parse_rules(rules, str(self.rb_dir / "mitos.rules"))
        evaluate_all(build_rulebase(parsed, (ts, self._termsets[other]),
                                    ("fuzz.terms.yaml", other)))

    def run_world(self, text: str, _work: Path) -> None:
        from mitos_cli.sim.worldfile import parse_world

        parse_world(text, str(self.work / "worlds" / "fuzz.yaml"))

    def run_map(self, data: str | bytes, work: Path) -> None:
        from mitos_cli.sim.gridmap import load_map_yaml

        maps = self.work / "worlds" / "maps"
        if isinstance(data, bytes):
            (work / "m.pgm").write_bytes(data)
            (work / "m.yaml").write_text("image: m.pgm\nresolution: 0.05\n"
                                         "origin: [0.0, 0.0, 0.0]\n")
            load_map_yaml(work / "m.yaml")
        else:
            (maps / "fuzz.yaml").write_text(data, encoding="utf-8", errors="surrogatepass")
            load_map_yaml(maps / "fuzz.yaml")

    def run_foreign(self, reader: str):
        def run(text: str, _work: Path) -> None:
            from mitos_cli.interop import fcl, fis, fll

            parse = {"fcl": fcl.parse_fcl, "fis": fis.parse_fis, "fll": fll.parse_fll}[reader]
            evaluate_all(parse(text, f"fuzz.{reader}"))
        return run

    def run_command(self, text: str, _work: Path) -> None:
        from mitos_cli.teach.commands import parse_command

        parse_command(text, "<prompt>")

    def session(self, journal=None):
        from mitos_cli.teach.session import Session

        return Session(self.rb_dir / "mitos.rules", journal=journal, out=lambda s: None)

    def run_lesson(self, text: str, _work: Path) -> None:
        from mitos_cli.teach.lesson import run_lesson

        session = self.session()
        session.base = self.work
        run_lesson(session, text, "fuzz.lesson")

    def run_batch(self, text: str, _work: Path) -> None:
        from mitos_cli.engine.csvio import read_batch

        X = read_batch(text, "fuzz.csv", ("road", "size", "position"))
        if len(X):                     # what `mitos eval --batch` does next
            from mitos_cli.api import load_rulebase
            from mitos_cli.engine.evaluation import evaluate

            if self._compiled is None:
                self._compiled = load_rulebase(self.rb_dir / "mitos.rules").compiled
            evaluate(self._compiled, X, detail=False, strict=False)


    def run_journal(self, text: str, work: Path) -> None:
        from mitos_cli.teach.journal import Journal
        from mitos_cli.teach.session import Session

        d = work / "session"
        d.mkdir(exist_ok=True)
        (d / "journal.jsonl").write_text(text, encoding="utf-8", errors="surrogatepass")
        Session.resume(Journal.open(d), out=lambda s: None)

    # -- the same inputs through the command line (``--via cli``) -------------------------------
    def _file(self, where: Path, name: str, data) -> str:
        path = where / name
        if isinstance(data, bytes):
            path.write_bytes(data)
        else:
            path.write_text(data, encoding="utf-8", errors="surrogatepass")
        return str(path)

    def argv_rules(self, text: str, _work: Path) -> list[str]:
        # beside the shipped term sets, which a rule file names relative to itself
        return ["check", self._file(self.rb_dir, "fuzz.rules", text), "-n", "5"]

    def argv_termset(self, text: str, work: Path) -> list[str]:
        # `mitos check` reads a term set alone (plot terms reads it the same way)
        return ["check", self._file(work, "fuzz.terms.yaml", text)]

    def argv_foreign(self, ext: str) -> Callable:
        def argv(text: str, work: Path) -> list[str]:
            return ["check", self._file(work, "fuzz" + ext, text), "-n", "5"]
        return argv

    def argv_batch(self, text: str, work: Path) -> list[str]:
        return ["eval", str(self.rb_dir / "mitos.rules"), "--batch",
                self._file(work, "fuzz.csv", text)]

    def argv_lesson(self, text: str, work: Path) -> list[str]:
        # beside `worlds/`, which a lesson names relative to itself
        return ["teach", str(self.rb_dir / "mitos.rules"), "--lesson",
                self._file(self.work, "fuzz.lesson", text), "--save-as", str(work / "out.rules")]

    def argv_journal(self, text: str, work: Path) -> list[str]:
        d = work / ".mitos" / "teach" / "fuzz"
        d.mkdir(parents=True)
        self._file(d, "journal.jsonl", text)
        return ["teach", "--resume", "--lesson", self._file(work, "end.lesson", "quit\n")]

    # -- command-line arguments ---------------------------------------------------------------
    #: the files a command line may name, copied into each input's own directory (a mutated
    #: `-o` may overwrite any of them)
    ARG_FILES = ("mitos.rules", "mitos.terms.yaml", "drive.terms.yaml")

    def argv_args(self, text: str, work: Path) -> list[str]:
        for name in self.ARG_FILES:
            shutil.copyfile(self.rb_dir / name, work / name)
        interop = ROOT / "tests" / "data" / "interop"
        shutil.copyfile(interop / "robot_jfuzzylogic.fcl", work / "robot.fcl")
        shutil.copyfile(interop / "tipper.fis", work / "tipper.fis")
        (work / "batch.csv").write_text("road,size,position\n78,45,4\n10,5,-3\n")
        (work / "small.lesson").write_text("correct road=78 size=45 position=4 -> steering=100\n"
                                           "adapt epochs 2\nsave\n")
        return command_line(text)

    def run_args(self, text: str, work: Path) -> tuple[str, str]:
        argv = self.argv_args(text, work)
        if not possible(argv):
            return "refused", "argument list too long (the system refuses to run it)"
        return cli_outcome(*cli_in_process(argv, work))

    # -- fleets, lessons in words, simulate and compare (2026-12-07, night 24) -----------------
    def argv_fleet(self, text: str, work: Path) -> list[str]:
        """`mitos simulate WORLD --json` of a mutated world of several robots (or moving
        obstacles): read, checked and driven; what it prints must be finite."""
        return ["simulate", self._file(work, "fleet.yaml", text), "--json"]

    def run_fleet(self, text: str, work: Path) -> tuple[str, str]:
        return finite_outcome(*cli_in_process(self.argv_fleet(text, work), work))

    #: the files a `simulate` or `compare` command line may name, copied into each input's
    #: own directory
    RUN_FILES = {"tiny.yaml": "tests/data/tiny.yaml", "fleet.yaml": "tests/data/fleet_tiny.yaml",
                 "mitos.rules": "rulebases/mitos.rules",
                 "mitos.terms.yaml": "rulebases/mitos.terms.yaml",
                 "drive.terms.yaml": "rulebases/drive.terms.yaml"}

    def argv_runs(self, text: str, work: Path) -> list[str]:
        for name, source in self.RUN_FILES.items():
            shutil.copyfile(ROOT / source, work / name)
        return command_line(text)

    def run_runs(self, text: str, work: Path) -> tuple[str, str]:
        argv = self.argv_runs(text, work)
        refused = not_run(argv)
        if refused is not None:
            return refused
        return finite_outcome(*cli_in_process(argv, work))

    # -- seeds --------------------------------------------------------------------------------
    def journal_seeds(self) -> list[tuple[str, str]]:
        from mitos_cli.teach.journal import Journal

        d = self.work / "seed-session"
        if not self.fresh:
            return [("journal.jsonl", (d / "journal.jsonl").read_text())]
        session = self.session(Journal.create(d))
        for line in ("correct road=78 size=45 position=4 -> steering=100",
                     "r28: if road is NARROW and position is RIGHT then steering is LS",
                     "behavior turn:", "if road is WIDE then steering is RS", "end", "use avoid_obstacle",
                     "operators: and = product", "undo",
                     "correct road=20 size=10 position=-8 -> steering=40 speed=10"):
            session.run(line)
        return [("journal.jsonl", (d / "journal.jsonl").read_text())]

    def build(self) -> list[Kind]:
        rules = _shipped("rulebases/*.rules")
        rules.append(("small.rules", 'terms "mitos.terms.yaml"\noperators: and = product\n'
                      "behavior b:\n  r1: if (road is WIDE or not size is SMALL_SZ) and position"
                      " is very LEFT\n     then steering is RS and speed is 20 with 0.5\nend\n"
                      "use b when road is NARROW\n"))
        termsets = _shipped("rulebases/*.terms.yaml")
        worlds = _shipped("worlds/*.yaml")
        maps = _shipped("worlds/maps/*.yaml")
        pgm = (ROOT / "worlds" / "maps" / "mrpb_office02.pgm").read_bytes()
        small_pgms = [("p5.pgm", b"P5\n# c\n4 3\n255\n" + bytes(range(0, 240, 20))),
                      ("p2.pgm", b"P2\n3 2\n100\n0 50 100\n100 0 7\n"),
                      ("p5-16.pgm", b"P5 2 2 65535\n" + bytes(8)),
                      ("office.pgm", pgm)]
        # the shipped lesson simulates twice and adapts for 60 epochs (seconds of real work
        # that every mutation repeats): its commands are seeds of the command kind instead
        lessons = []
        lessons.append(("small.lesson", "correct road=78 size=45 position=4 -> steering=100\n"
                        "r28: if road is NARROW and position is RIGHT\n  then steering is LS\n"
                        "eval road=10 size=5 position=0\nshow rules\nadapt epochs 2\nundo\n"))
        lessons.append(("drive.lesson", "use drive\nsimulate worlds/corridor.yaml\n"
                        "at 1s to 2s steering=90\nadapt epochs 3\n"))
        commands = [(f"cmd{i}", line) for i, line in enumerate((
            "r28: if road is NARROW and position is RIGHT then steering is LS",
            "correct road=78 size=45 position=4 -> steering=100 speed=20",
            "eval road=10 size=5 position=0", "adapt epochs 60 rate 0.5", "undo",
            "at 9s to 12.75s steering=90", "simulate worlds/figure4.yaml", "show rules",
            "use drive when not road is WIDE with 0.5", "frozen r1, r2", "save x.rules",
            "operators: and = product, or = max", "behavior turn:", "end", "help adapt",
            "quit"))]
        csvs = [("batch.csv", "road,size,position\n78,45,4\n10,5,-3\n 0.5 , 1e2 , -8\n"),
                ("order.csv", "position,road,size\n4,78,45\n")]
        fcl = _shipped("tests/data/interop/*.fcl")
        fis = _shipped("tests/data/interop/*.fis")
        fll = self.fll_seeds()
        rule_mut = Mutator(RULE_WORDS, RULE_NEST, many=True)
        ymut = yaml_mutator(("name", "inputs", "outputs", "terms", "universe", "default",
                             "triangle", "trapezoid", "gaussian", "robot", "obstacles",
                             "image", "resolution", "origin", "negate", "occupied_thresh",
                             "free_thresh", "mode", "start", "goal", "map", "seed"))
        fmut = Mutator(("VAR_INPUT", "VAR_OUTPUT", "END_VAR", "FUZZIFY", "END_FUZZIFY",
                        "DEFUZZIFY", "TERM", ":=", "RULEBLOCK", "RULE", "IF", "THEN", "AND",
                        "OR", "NOT", "Range", "NumMFs", "trimf", "trapmf", "gaussmf",
                        "[Input1]", "[Rules]", "InputVariable:", "OutputVariable:", "term:",
                        "Triangle", "Trapezoid", "range:", "default:", "rule:", "if", "then",
                        "is", "and", "(", ")", ";", ",", "NaN", "inf"),
                       (lambda d: "RULE 1 : IF " + "(" * d + "x IS a" + ")" * d + " THEN y IS b;",
                        lambda d: "rule: if " + "not " * d + "x is a then y is b"), many=True)
        tmut = Mutator(RULE_WORDS + ("correct", "eval", "adapt", "epochs", "rate", "undo",
                                     "at", "s", "to", "simulate", "show", "save", "as", "help",
                                     "quit", "=", "1e400s", "-1s", "nan"), RULE_NEST[:3])
        cmut = Mutator(("road", "size", "position", ",", "\"", "\x00", "nan", "inf"),
                       (lambda d: '"' + "x" * (200 * d) + '"',), many=True)
        jmut = Mutator(("seq", "op", "rule", "examples", "undo", "of", "start", "text",
                        "behavior", "inputs", "targets", "null", "true", "{", "}", "[", "]",
                        ":", ",", '"', "adapt", "terms", "crisp"),
                       (lambda d: '{"seq": 99, "op": "examples", "examples": ' + "[" * d
                        + "]" * d + "}",))
        args = [(f"args{i}", line) for i, line in enumerate((
            "eval mitos.rules road=78 size=45 position=4 --digits 2",
            "eval mitos.rules --batch batch.csv --on-no-rule default --json",
            "eval mitos.rules road=20 size=10 position=-8 --network",
            "eval mitos.rules --fidelity matlab -b avoid road=78 size=45 position=4",
            "check mitos.rules --threshold 0.2 --resolution 8 --json",
            "convert robot.fcl --to rules -o out.rules",
            "convert mitos.rules --to fll", "convert tipper.fis --to fcl -o out.fcl",
            "export mitos.rules --to c -o out.c --prefix m", "export mitos.rules --to python",
            "teach mitos.rules --lesson small.lesson --save-as out.rules",
            "teach --resume --session x --recover", "operators", "list", "--version",
            "eval --help"))]
        amut = Mutator(("eval", "check", "convert", "export", "teach", "operators", "list",
                        "--batch", "--json", "--digits", "--network", "--on-no-rule",
                        "--fidelity", "--threshold", "-t", "--resolution", "-n", "--to", "-o",
                        "--output", "--behavior", "-b", "--prefix", "--lesson", "--save-as",
                        "--resume", "--recover", "--session", "-", "--", "road=", "size=1e400",
                        "position=nan", "=", "mitos.rules", "batch.csv", "robot.fcl",
                        "tipper.fis", "small.lesson", "fll", "fcl", "fis", "rules", "c",
                        "python", "matlab", "fuzzylite", "nan", "skip", "default", "error",
                        "x" * 300 + ".rules", "--help", "-h", "--version"))
        fleets = [(f"{name}", text) for name, text in _shipped(
            "tests/data/fleet_tiny.yaml", "tests/data/crossroads4.yaml",
            "tests/data/crossroads_carts.yaml", "tests/data/traffic/narrow_pass.yaml",
            "tests/data/traffic/merge.yaml", "worlds/multirobot.yaml", "worlds/moving.yaml")]
        fleet_mut = yaml_mutator(("robots", "robot", "name", "q_init", "q_goal", "x", "y",
                                  "heading", "tolerance", "give_way", "footprint", "length",
                                  "width", "wheelbase", "max_speed", "acceleration",
                                  "safety_margin", "steering", "behavior", "obstacles",
                                  "shape", "circle", "rectangle", "at", "radius", "velocity",
                                  "waypoints", "speed", "mode", "ping-pong", "loop",
                                  "randomise", "dx", "dy", "sensor_noise", "corridors",
                                  "points", "time_limit", "dt", "substeps", "seed", "oncoming",
                                  "all robots", "robot 2", "true", "false"))
        words_lessons = [
            ("fleet.lesson", "use drive\nsimulate fleet.yaml seed 2 robot oncoming\n"
             "at 1s to 2s steering is very LS\nat 4s to 5s speed is SLOW\n"
             "frozen heading.AHEAD, steering.LS\nunfrozen steering.ST\n"
             "adapt epochs 3 rate 0.5\nshow terms\nat 6s to 7s turn harder\nat 6s to 7s slow down\n"
             "at 7s to 8s make a wider turn\nshow history\nsave out/taught.rules\n"),
            ("words.lesson", "correct road=78 size=45 position=4 -> steering is very LM and "
             "speed is SLOW\ncorrect road=20 size=10 position=-8 -> steering=40 speed=10\n"
             "frozen r1, r2\nfrozen steering.RS\nadapt epochs 2\nundo\nunfrozen steering.RS\n"
             "show examples\nbehavior turn:\n  if road is WIDE then steering is RS\n"
             "  frozen r1\nend\nuse avoid_obstacle\nsave\n"),
            ("robot.lesson", "use drive\nsimulate fleet.yaml robot \"robot\"\n"
             "at 1.5s steering=60\nat 3s to 3.5s turn less\nat 8s speed up\n"
             "adapt epochs 2 unconstrained\nunfrozen heading.AHEAD\nshow terms\n")]
        lesson_mut = Mutator(RULE_WORDS + (
            "correct", "eval", "adapt", "epochs", "rate", "undo", "at", "s", "to", "simulate",
            "show", "save", "frozen", "unfrozen", "heading.AHEAD", "steering.LS", "speed.SLOW",
            ".", "robot", "seed", "oncoming", '"', "make a wider turn", "turn harder",
            "turn less", "slow down", "speed up", "and", "very", "somewhat", "is", "LM", "ST",
            "terms", "history", "examples", "unconstrained", "1e400s", "-1s", "nan"),
            RULE_NEST[:3])
        runs_lines = [(f"runs{i}", line) for i, line in enumerate((
            "simulate tiny.yaml --json --seed 3",
            "simulate fleet.yaml --runs 3 -j 1 --seed 2 --json",
            "simulate tiny.yaml --randomise --seed 4 -o out.csv",
            "simulate fleet.yaml --trace --every 50 --planner dwa",
            "simulate tiny.yaml -b drive --require success --planner potential_field",
            "simulate fleet.yaml -r mitos.rules --live --speed 0",
            "simulate tiny.yaml --plot run.png --seed 1",
            "compare tiny.yaml --and min,product --planner fuzzy --runs 2 -j 1 -o study "
            "--no-plots",
            "compare fleet.yaml --planner fuzzy,dwa --and min --runs 1 -j 1 -o s2 --no-plots "
            "--json",
            "compare tiny.yaml --and product --or dual --inference mamdani,weighted_average "
            "--planner fuzzy --runs 1 -j 1 --no-plots -o s3",
            "compare tiny.yaml --and min --planner fuzzy --runs 2 -j 1 --no-plots -o study "
            "--resume --seed 7 -b drive"))]
        runs_mut = Mutator((
            "simulate", "compare", "--json", "--seed", "--runs", "--randomise", "-o", "--out",
            "--trace", "--every", "--plot", "--live", "--speed", "--require", "success",
            "--workers", "-j", "--planner", "fuzzy", "dwa", "potential_field", "--rulebase",
            "-r", "--behavior", "-b", "drive", "--and", "--or", "--inference", "min",
            "product", "lukasiewicz", "einstein", "dual", "mamdani", "tsukamoto",
            "weighted_sum", "--resume", "--plots", "--no-plots", "--scheduler", "--executor",
            "local", "tiny.yaml", "fleet.yaml", "mitos.rules", "study", "out.csv", "run.png",
            ",", "-", "--", "0", "1", "nan", "x" * 300 + ".yaml", "--help", "-h"))
        k = self
        return [
            Kind("rule files", rules, rule_mut, k.run_rules, ".rules", k.argv_rules),
            Kind("term-set YAML", termsets, ymut, k.run_termset, ".terms.yaml",
                 k.argv_termset),
            Kind("world YAML", worlds, ymut, k.run_world, ".yaml"),
            Kind("map YAML + PGM", maps + small_pgms, ymut, k.run_map, ".yaml"),
            Kind("FCL", fcl, fmut, k.run_foreign("fcl"), ".fcl", k.argv_foreign(".fcl")),
            Kind(".fis", fis, fmut, k.run_foreign("fis"), ".fis", k.argv_foreign(".fis")),
            Kind("FLL", fll, fmut, k.run_foreign("fll"), ".fll", k.argv_foreign(".fll")),
            Kind("teach commands", commands, tmut, k.run_command, ".txt"),
            Kind("lessons", lessons, tmut, k.run_lesson, ".lesson", k.argv_lesson),
            Kind("eval --batch CSV", csvs, cmut, k.run_batch, ".csv", k.argv_batch),
            Kind("teach journals", self.journal_seeds(), jmut, k.run_journal, ".jsonl",
                 k.argv_journal),
            Kind("CLI arguments", args, amut, k.run_args, ".args", k.argv_args),
            # night 24: appended, so the kinds above make the same inputs as before
            Kind("fleet worlds", fleets, fleet_mut, k.run_fleet, ".yaml", k.argv_fleet),
            Kind("lessons in words", words_lessons, lesson_mut, k.run_lesson, ".lesson",
                 k.argv_lesson),
            Kind("simulate and compare arguments", runs_lines, runs_mut, k.run_runs, ".args",
                 k.argv_runs),
            Kind("fleet numbers", fleets, NumberMutator(()), k.run_fleet, ".yaml",
                 k.argv_fleet),
        ]

    def fll_seeds(self) -> list[tuple[str, str]]:
        from mitos_cli.api import read_rulebase
        from mitos_cli.interop import fcl, fll

        out = [("mitos.fll", fll.write_fll(read_rulebase(self.rb_dir / "mitos.rules"))),
               ("chain.fll", CHAIN_FLL)]
        for name, text in _shipped("tests/data/interop/*.fcl")[:2]:
            # a seed the writer cannot express is simply not a seed
            with contextlib.suppress(Exception):
                out.append((name + ".fll", fll.write_fll(fcl.parse_fcl(text, name))))
        return out


def mutate_bytes(rng: random.Random, data: bytes) -> bytes:
    """PGM: header numbers replaced (huge, zero, negative), bytes flipped, cut short."""
    choice = rng.randrange(5)
    if choice == 0:
        head, _, rest = data.partition(b"\n")
        fields = re.split(rb"(\s+)", data[:40])
        nums = [i for i, f in enumerate(fields) if f.isdigit()]
        if nums:
            fields[rng.choice(nums)] = rng.choice((b"0", b"99999999999", b"4294967297",
                                                   b"65536", b"1" * 40, b"-3", b"x"))
        return b"".join(fields) + data[40:]
    if choice == 1:
        return data[:rng.randrange(len(data) + 1)]
    if choice == 2:
        b = bytearray(data)
        for _ in range(rng.choice((1, 5, 50))):
            b[rng.randrange(len(b))] = rng.randrange(256)
        return bytes(b)
    if choice == 3:
        return data[:2] + rng.choice((b" # \n", b"\t", b"#", b"\r\n")) + data[2:]
    return data + bytes(rng.randrange(256) for _ in range(rng.choice((1, 100))))


# ---------------------------------------------------------------------------------------------
# running and classifying

def _alarm(signum, frame):
    raise Timeout()


def signature(exc: BaseException) -> str:
    """Exception type and the innermost frame of the project (or of anything) that raised it."""
    tb = traceback.extract_tb(exc.__traceback__)
    ours = [f for f in tb if "mitos_cli" in f.filename] or list(tb)
    f = ours[-1] if ours else None
    where = f"{Path(f.filename).name}:{f.name}:{f.lineno}" if f else "?"
    return f"{type(exc).__name__} at {where}"


#: seconds a large input may take per KB beyond ``--slow`` (its size explains that much)
PER_KB = 0.01
#: inputs of at least this many bytes are "large": the table gives their CPU time per KB
LARGE = 64 * 1024


def _cpu() -> float:
    """CPU seconds of this process and of its finished children (``--via subprocess``)."""
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + children.ru_utime + children.ru_stime


def classify(kind: Kind, data, work: Path, limit: float, slow: float,
             times: list[float] | None = None) -> tuple[str, str]:
    """The outcome of one input and its signature; its CPU seconds are appended to ``times``."""
    from mitos_cli.errors import MitosError

    allowance = len(data) / 1024 * PER_KB
    limit, slow = limit + allowance, slow + allowance
    # CPU time, not wall time: on a shared machine the wall clock measures the neighbours
    signal.signal(signal.SIGPROF, _alarm)
    t0 = _cpu()
    caught: list[warnings.WarningMessage] = []
    signal.setitimer(signal.ITIMER_PROF, limit)
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            result = kind.run(data, work)
        outcome, sig = result if result is not None else ("loaded", "")
    except Timeout:
        return "slow", "past the limit"
    except MitosError as exc:
        span = exc.span
        outcome = "refused+pos" if span is not None and span.line >= 1 else "refused"
        sig = exc.message[:60] if outcome == "refused" else ""
    except NonFinite as exc:
        outcome, sig = "nonfinite", str(exc).split("=")[0]
    except RecursionError as exc:
        outcome, sig = "foreign", signature(exc)
    except Exception as exc:              # noqa: BLE001 - exactly what a campaign looks for
        outcome, sig = "foreign", signature(exc)
    except MemoryError as exc:
        outcome, sig = "foreign", signature(exc)
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0)
    elapsed = _cpu() - t0
    if times is not None:
        times.append(elapsed)
    if elapsed > slow and outcome != "foreign":
        return "slow", "slower than allowed"
    # a warning the user would see (NumPy's "invalid value", a deprecation): a defect too
    leaked = [w for w in caught if issubclass(w.category, (RuntimeWarning, UserWarning))]
    if leaked and outcome != "foreign":
        w = leaked[0]
        return "warning", f"{w.category.__name__} at {Path(w.filename).name}:{w.lineno}"
    return outcome, sig


def minimise(kind: Kind, data, work: Path, want: tuple[str, str], limit: float, slow: float,
             budget: int = 150):
    """Delta debugging by lines, then by characters, while the outcome and signature stay."""
    if want[0] == "slow":
        return data                    # shrinking a slow input is itself slow: keep it whole
    tries = 0
    deadline = time.perf_counter() + 30.0

    def same(candidate) -> bool:
        nonlocal tries
        tries += 1
        if time.perf_counter() > deadline:
            tries = budget
            return False
        return classify(kind, candidate, work, limit, slow) == want

    unit = b"\n" if isinstance(data, bytes) else "\n"
    for sep in (unit, None):
        parts = data.split(unit) if sep is not None else list(data)
        n = 2
        while len(parts) >= 2 and tries < budget:
            chunk = max(1, len(parts) // n)
            for start in range(0, len(parts), chunk):
                cand_parts = parts[:start] + parts[start + chunk:]
                join = (sep if sep is not None else unit[:0]).join(cand_parts)
                if tries < budget and same(join):
                    parts, n = cand_parts, max(n - 1, 2)
                    break
            else:
                if chunk == 1:
                    break
                n = min(len(parts), n * 2)
        data = (sep if sep is not None else unit[:0]).join(parts)
    return data


def make_input(kind: Kind, i: int, seed: int):
    """Input ``i`` of ``kind``: the seeds first, then mutations; each from its own generator,
    so any input can be made again alone (the watchdog does, for an input that hung)."""
    name, base = kind.seeds[i % len(kind.seeds)]
    if i < len(kind.seeds):
        return name, base
    rng = random.Random(f"{seed}-{kind.name}-{i}")
    return name, (mutate_bytes(rng, base) if isinstance(base, bytes) else kind.mutate(rng, base))


def _allowance(kind: Kind, i: int, seed: int) -> float:
    return len(make_input(kind, i, seed)[1]) / 1024 * PER_KB


#: kinds whose inputs always go through the command line's ``main`` (a command line, or a
#: world that only ``simulate`` reads and drives): ``--via cli`` changes nothing for them
THROUGH_MAIN = ("CLI arguments", "fleet worlds", "simulate and compare arguments",
                "fleet numbers")


def routed(kinds: list[Kind], via: str, limit: float) -> list[Kind]:
    """The kinds as ``--via`` runs them: ``reader`` calls the library's readers, ``cli`` the
    command line's ``main`` in this process, ``subprocess`` ``python -m mitos_cli``. A kind no
    command reads alone (term sets, worlds, maps, single commands) keeps its reader."""
    if via == "reader":
        return kinds
    for kind in kinds:
        if kind.argv is not None and (via == "subprocess" or kind.name not in THROUGH_MAIN):
            kind.run = via_cli(kind, via, limit)
    return kinds


def share_rule_base(rb_dir: Path) -> None:
    """Every teaching session of the campaign starts from the shipped rule base: read it once
    per process, not once per input (its model is frozen; a changed file is read again)."""
    from mitos_cli.teach import session as module

    read = module.load_rules_file
    shared = str((rb_dir / "mitos.rules").resolve())
    cache: dict[tuple, object] = {}

    def load(path):
        p = Path(path)
        if str(p.resolve()) != shared:
            return read(path)
        st = p.stat()
        key = (st.st_mtime_ns, st.st_size)
        if key not in cache:
            cache.clear()
            cache[key] = read(path)
        return cache[key]

    module.load_rules_file = load


#: inputs per kind, as a fraction of ``--per-format``: a lesson simulates and adapts (about
#: 0.2 CPU s of real work) and a command line runs a whole command (about 30 ms), so they get
#: fewer; batch CSVs and journals (about 1 and 3 ms) more
SHARE = {"lessons": 1 / 12, "CLI arguments": 1 / 3, "eval --batch CSV": 1.4,
         "teach journals": 1.4, "fleet worlds": 1 / 6, "lessons in words": 1 / 6,
         "simulate and compare arguments": 1 / 6, "fleet numbers": 1 / 6}


def count_of(kind: Kind, per_format: int) -> int:
    return max(1, int(per_format * SHARE.get(kind.name, 1.0)))


def _worker(conn, kind_index: int, start: int, stop: int, step: int, seed: int,
            limit: float, slow: float, work: Path, via: str) -> None:
    """Runs inputs ``start, start + step, ... < stop`` of one kind, announcing each first."""
    import multiprocessing as mp

    resource.setrlimit(resource.RLIMIT_AS, (4 << 30, resource.RLIM_INFINITY))
    # the worker is daemonic so that it ends with the campaign; but `compare`, and `simulate
    # --runs` without `-j 1`, start a process pool, which a daemonic process may not (an
    # AssertionError no user meets): the pool's workers end with this one (sim/runs.py)
    mp.current_process().daemon = False
    os.chdir(work)                      # teaching writes `.mitos/` and saves here
    kinds = Kinds(work, fresh=False)
    share_rule_base(kinds.rb_dir)
    kind = routed(kinds.build(), via, limit)[kind_index]
    scratch = work / f"scratch-{os.getpid()}"
    for i in range(start, stop, step):
        _, data = make_input(kind, i, seed)
        conn.send(("start", i))
        scratch.mkdir(exist_ok=True)
        times: list[float] = []
        outcome, sig = classify(kind, data, scratch, limit, slow, times)
        shutil.rmtree(scratch, ignore_errors=True)
        conn.send(("done", i, outcome, sig, times[0] if times else limit, len(data)))
    conn.send(("end",))


def _cpu_of(pid: int) -> float | None:
    """CPU seconds process ``pid`` has used (Linux ``/proc``; None elsewhere)."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    except (OSError, IndexError, ValueError):
        return None


def _answers(conn, pid: int, budget: float) -> bool:
    """Whether the worker answers before it spends ``budget`` more CPU seconds (past its own
    alarm: stuck in C code), or, where it spends none (blocked), 30 times that in wall time.
    CPU, not wall time: on a loaded machine a niced worker gets a few percent of a core, and a
    wall-clock watchdog counted a 20,000-rule file that loads in 8 CPU s as hung."""
    start, began = _cpu_of(pid), time.monotonic()
    while not conn.poll(2.0):
        used = _cpu_of(pid)
        if start is not None and used is not None and used - start > budget:
            return False
        if time.monotonic() - began > 30 * budget + 60:
            return False
    return True


def campaign(per_format: int, out: Path | None, limit: float, slow: float, only: str | None,
             seed: int, log=print, via: str = "reader",
             shard: tuple[int, int] = (0, 1)) -> list[Kind]:
    """Run every kind's inputs in a worker process; a worker stuck in one input past twice
    the limit (a hang the alarm cannot reach, inside C code) is killed, the input counted as
    slow, and a new worker carries on after it."""
    import multiprocessing as mp

    ctx = mp.get_context("fork")
    resource.setrlimit(resource.RLIMIT_AS, (4 << 30, resource.RLIM_INFINITY))
    work = Path(tempfile.mkdtemp(prefix="mitos-fuzz-"))
    cwd = os.getcwd()
    os.chdir(work)
    try:
        built = Kinds(work)
        share_rule_base(built.rb_dir)
        kinds = routed(built.build(), via, limit)
        seen: set[tuple[str, str, str]] = set()
        for index, kind in enumerate(kinds):
            if only and not any(o.strip().lower() in kind.name.lower()
                                for o in only.split(",")):
                continue
            if via != "reader" and kind.argv is None:
                log(f"{kind.name}: no command reads it alone (run with --via reader)")
                continue
            t0 = time.perf_counter()
            (i, step), count = shard, count_of(kind, per_format)
            while i < count:
                parent, child = ctx.Pipe()
                proc = ctx.Process(target=_worker, args=(child, index, i, count, step, seed,
                                                         limit, slow, work, via), daemon=True)
                proc.start()
                child.close()
                current = i
                while True:
                    if not _answers(parent, proc.pid, 2 * (limit + _allowance(kind, current,
                                                                            seed))):
                        proc.kill()
                        proc.join()
                        result = ("slow", "hung (no answer from the worker)")
                        i = current + step
                        break
                    try:
                        msg = parent.recv()
                    except EOFError:             # the worker died (out of memory, a signal)
                        proc.join()
                        result = ("foreign", f"worker died (exit {proc.exitcode})")
                        i = current + step
                        break
                    if msg[0] == "start":
                        current = msg[1]
                        continue
                    if msg[0] == "end":
                        result = None
                        i = count
                        break
                    _, n, outcome, sig, cpu, size = msg
                    kind.cpu += cpu
                    if size >= LARGE:
                        kind.large.append((size, cpu))
                    _count(kind, n, outcome, sig, seen, out, seed, work, limit, slow, log)
                if result is not None:
                    _count(kind, current, *result, seen, out, seed, work, limit, slow, log)
                proc.join()
            kind.seconds = time.perf_counter() - t0
            LOADS.append(os.getloadavg()[0])
            log(f"{kind.name}: {kind.tried} inputs in {kind.seconds:.1f} s "
                + ", ".join(f"{k} {v}" for k, v in kind.counts.items() if v)
                + f" (load average {LOADS[-1]:.1f})")
        return kinds
    finally:
        os.chdir(cwd)
        shutil.rmtree(work, ignore_errors=True)


def _count(kind: Kind, i: int, outcome: str, sig: str, seen: set, out: Path | None, seed: int,
           work: Path, limit: float, slow: float, log) -> None:
    kind.tried += 1
    kind.counts[outcome] += 1
    key = (kind.name, outcome, sig)
    if outcome == "refused" and key not in seen and kind.name != "CLI arguments":
        seen.add(key)                   # without a position: right only for input without lines
        log(f"  {kind.name}: refused without a position: {sig} (input {i})")
    if outcome in BAD and key not in seen:
        seen.add(key)
        name, data = make_input(kind, i, seed)
        log(f"  {kind.name}: {outcome} {sig} (input {i}, from {name})")
        if out is not None:
            hung = sig.startswith(("hung", "worker"))
            scratch = work / "scratch-min"
            scratch.mkdir(exist_ok=True)
            _write(out, kind, data, (outcome, sig), scratch, limit, slow, shrink=not hung)
            shutil.rmtree(scratch, ignore_errors=True)


def _write(out: Path, kind: Kind, data, want, scratch: Path, limit: float, slow: float,
           shrink: bool = True) -> None:
    small = minimise(kind, data, scratch, want, limit, slow) if shrink else data
    out.mkdir(parents=True, exist_ok=True)
    tag = hashlib.sha1(f"{kind.name}{want}".encode()).hexdigest()[:10]
    stem = re.sub(r"\W+", "-", kind.name).strip("-")
    ext = ".pgm" if isinstance(small, bytes) else kind.ext
    target = out / f"{stem}-{tag}{ext}"
    raw = small if isinstance(small, bytes) else small.encode("utf-8", "surrogatepass")
    meta = json.dumps({"kind": kind.name, "outcome": want[0], "signature": want[1],
                       "bytes": len(small)}, indent=1) + "\n"
    # whole files only: the shards of `--jobs` may find the same signature at once
    for path, content in ((target, raw), (target.with_suffix(target.suffix + ".json"),
                                          meta.encode())):
        tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
        tmp.write_bytes(content)
        os.replace(tmp, path)


def table(kinds: list[Kind]) -> str:
    rows = ["| input | tried | loaded | refused with a position | refused without one | "
            "foreign exception | slow | non-finite | warning | CPU s | large inputs: n, "
            "largest, ms per KB (max) |", "|---|" + "---:|" * 10]
    total = dict.fromkeys(OUTCOMES, 0)
    tried, cpu = 0, 0.0
    for k in kinds:
        if not k.tried:
            continue
        tried += k.tried
        cpu += k.cpu
        for o in OUTCOMES:
            total[o] += k.counts[o]
        rows.append(f"| {k.name} | {k.tried:,} | " + " | ".join(f"{k.counts[o]:,}"
                                                                for o in OUTCOMES)
                    + f" | {k.cpu:,.0f} | {_large(k.large)} |")
    rows.append(f"| **all** | {tried:,} | " + " | ".join(f"{total[o]:,}" for o in OUTCOMES)
                + f" | {cpu:,.0f} | |")
    return "\n".join(rows)


def _large(large: list[tuple[int, float]]) -> str:
    if not large:
        return "0"
    biggest = max(size for size, _ in large)
    per_kb = max(cpu / (size / 1024) for size, cpu in large)
    return f"{len(large):,}, {biggest / 1024:,.0f} KB, {per_kb * 1000:.2f}"


#: the 1-minute load average at the start and at each kind's end (the table's "load")
LOADS: list[float] = []
#: shards of ``--jobs`` that died without their table (the campaign then fails)
LOST: list[int] = []


def shard_of(text: str) -> tuple[int, int]:
    """``K/N`` with 0 <= K < N (``2/2`` would silently skip input 0 and run half of shard 0)."""
    k, sep, n = text.partition("/")
    try:
        pair = (int(k), int(n) if sep else 1)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected K/N, found {text!r}") from None
    if not 0 <= pair[0] < pair[1]:
        raise argparse.ArgumentTypeError(f"expected K/N with 0 <= K < N, found {text!r} "
                                         f"(shards are numbered from 0)")
    return pair


def summary(kinds: list[Kind]) -> list[dict]:
    """What a shard sends back to ``--jobs``: each kind's counts and times."""
    return [{"name": k.name, "tried": k.tried, "counts": k.counts, "cpu": k.cpu,
             "seconds": k.seconds, "large": k.large} for k in kinds]


def merged(parts: list[list[dict]]) -> list[Kind]:
    """The shards' summaries as one campaign's kinds (in the kinds' order)."""
    kinds: dict[str, Kind] = {}
    for part in parts:
        for d in part:
            k = kinds.setdefault(d["name"], Kind(d["name"], [], None, None))
            k.tried += d["tried"]
            k.cpu += d["cpu"]
            k.seconds = max(k.seconds, d["seconds"])
            k.large.extend(tuple(x) for x in d["large"])
            for o, v in d["counts"].items():
                k.counts[o] += v
    return list(kinds.values())


def _shard(conn, k: int, n: int, args) -> None:
    """One shard of ``--jobs``: its campaign, its log lines prefixed with ``[K/N]``."""
    def log(line: str) -> None:
        print(f"[{k}/{n}] {line}", flush=True)

    kinds = campaign(args.n, args.out, args.limit, args.slow, args.only, args.seed, log=log,
                     via=args.via, shard=(k, n))
    conn.send((summary(kinds), LOADS))
    conn.close()


def run_jobs(args) -> list[Kind]:
    """``--jobs N``: shards 0/N .. N-1/N in N processes at once, their tables summed."""
    import multiprocessing as mp

    ctx = mp.get_context("fork")
    procs = []
    for k in range(args.jobs):
        parent, child = ctx.Pipe(duplex=False)
        proc = ctx.Process(target=_shard, args=(child, k, args.jobs, args))
        proc.start()
        child.close()
        procs.append((proc, parent))
    parts = []
    for k, (proc, parent) in enumerate(procs):
        try:
            part, loads = parent.recv()
        except EOFError:                 # the shard died: the table says it is short
            proc.join()
            print(f"[{k}/{args.jobs}] ended without its table (exit {proc.exitcode}); the "
                  "table below lacks its inputs", flush=True)
            LOST.append(k)
            continue
        parts.append(part)
        LOADS.extend(loads)
        proc.join()
    return merged(parts)


@guarded
def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--per-format", type=positive_int, default=2000,
                    help="inputs per input kind (" + ", ".join(
                        f"{kind} " + (f"1/{round(1 / share)}" if share < 1 else f"{share:g}x")
                        for kind, share in SHARE.items()) + " of it: docs/reliability.md)")
    ap.add_argument("--quick", action="store_true", help="a short campaign (--per-format 150)")
    ap.add_argument("--out", type=Path, default=None,
                    help="directory for minimal reproducers of new signatures")
    ap.add_argument("--only", default=None,
                    help="run only the kinds whose name contains this (comma-separated: any)")
    ap.add_argument("--limit", type=float, default=10.0, help="per-input time limit, seconds")
    ap.add_argument("--slow", type=float, default=5.0, help="slower than this counts as slow")
    ap.add_argument("--seed", type=int, default=SEED)
    ap.add_argument("--shard", type=shard_of, default=(0, 1), metavar="K/N",
                    help="run only inputs K, K + N, K + 2N, ... of each kind, 0 <= K < N (N "
                         "campaigns in parallel cover them all)")
    ap.add_argument("--jobs", type=positive_int, default=1, metavar="N",
                    help="run the N shards 0/N .. N-1/N at once in N processes and print their "
                         "summed table (one worker each: N cores)")
    ap.add_argument("--via", choices=("reader", "cli", "subprocess"), default="reader",
                    help="reader: the library's readers; cli: `mitos`'s main in this process "
                         "(stdout and stderr captured); subprocess: `python -m mitos_cli`, for "
                         "spot checks")
    args = ap.parse_args(argv)
    if args.jobs > 1 and args.shard != (0, 1):
        ap.error("--jobs runs every shard itself: give --jobs or --shard, not both")
    args.n = 150 if args.quick else args.per_format
    t0 = time.perf_counter()
    LOADS.append(os.getloadavg()[0])
    if args.jobs > 1:
        kinds = run_jobs(args)
        shard = f"{args.jobs} shards at once"
    else:
        kinds = campaign(args.n, args.out, args.limit, args.slow, args.only, args.seed,
                         via=args.via, shard=args.shard)
        shard = "shard {}/{}".format(*args.shard)
    LOADS.append(os.getloadavg()[0])
    if not any(k.tried for k in kinds) and not LOST:
        ap.error("nothing was run: no input kind"
                 + (f" matches `--only {args.only}`" if args.only else "")
                 + (f" that `--via {args.via}` reads" if args.via != "reader" else ""))
    wall = time.perf_counter() - t0
    own = resource.getrusage(resource.RUSAGE_SELF)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime
    print()
    print(table(kinds))
    bad = {o: sum(k.counts[o] for k in kinds) for o in BAD}
    print(f"\n{sum(k.tried for k in kinds):,} inputs in {wall:.0f} s of wall time, "
          f"{cpu:.0f} CPU s in all ({sum(k.cpu for k in kinds):.0f} inside the inputs); "
          + ", ".join(f"{o} {v}" for o, v in bad.items())
          + f"\n(seed {args.seed}, via {args.via}, {shard}, limit {args.limit:g} s, slow above "
          f"{args.slow:g} s; 1-minute load average {min(LOADS):.1f} to {max(LOADS):.1f} at the "
          f"start, the kinds' ends and the end)")
    return 1 if any(bad.values()) or LOST else 0

if __name__ == "__main__":
    sys.exit(main())
