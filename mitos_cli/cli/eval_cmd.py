"""``mitos eval``: one-shot inference with the paper's DOF trace, JSON, or a CSV batch."""

from __future__ import annotations

import enum
import re
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Optional

import typer

from ..errors import InputError
from ..numbers import exact
from ..words import plural
from .output import emit, json_text, warn, warn_notes
from .params import WORDS, Number, choice, choices, completer, named

if TYPE_CHECKING:
    from collections.abc import Callable

    import numpy as np
    from numpy.typing import ArrayLike

    from ..api import LoadedRuleBase
    from ..engine.compile import CompiledRuleBase
    from ..engine.evaluation import Result
    from ..errors import Span


class Engine(str, enum.Enum):
    """A reference engine whose sampling of Mamdani outputs ``--fidelity`` reproduces."""

    matlab = "matlab"
    jfuzzylogic = "jfuzzylogic"
    fuzzylite = "fuzzylite"       # fuzzylite 8 (pyfuzzylite): 1000 where the file says none
    fuzzylite6 = "fuzzylite6"     # fuzzylite 6 (Debian's binary): 100 where the file says none
    octave = "octave"             # Octave's fuzzy-logic-toolkit: trapezoid centroid, AggMethod


class NoRule(str, enum.Enum):
    """What ``eval --batch`` writes where no rule sets an output (see docs/interop.md)."""

    error = "error"          # stop, naming the first such row
    default = "default"      # the output's declared default (a number or nan); else stop
    nan = "nan"              # NaN, whatever the default
    skip = "skip"            # leave the row out


def split_args(args: list[str]) -> tuple[Optional[str], dict[str, str]]:
    """``[RULEBASE] NAME=VALUE ...`` -> (rule-base path or None, {name: text})."""
    path: Optional[str] = None
    values: dict[str, str] = {}
    for i, arg in enumerate(args):
        meant = _apart(args[i:i + 2])
        if meant is not None:
            raise typer.BadParameter(f"`{arg} {args[i + 1]}`: write each input as NAME=VALUE, "
                                     f"in one word; did you mean `{meant}`?")
        if "=" in arg:
            name, _, value = arg.partition("=")
            if not name:
                raise typer.BadParameter(f"`{arg}` has no input name (write NAME=VALUE)")
            if name in values:
                raise typer.BadParameter(f"input `{name}` is given twice")
            values[name] = value
        elif path is None and not values:
            path = arg
        else:
            raise typer.BadParameter(
                f"`{arg}` is neither the rule base (which comes first) nor NAME=VALUE")
    return path, values


def _apart(pair: list[str]) -> str | None:
    """``road=78`` for an input name and its number given as two words (``road 78``, ``road=
    78``, ``road =78``), which the shell split; else None."""
    from ..numbers import parse_number

    if len(pair) != 2:
        return None
    name, value = pair[0].removesuffix("="), pair[1].removeprefix("=")
    if "=" in name or "=" in value or not name.isidentifier():
        return None
    try:
        parse_number(value)
    except ValueError:
        return None
    return f"{name}={value}"


def parse_values(values: dict[str, str]) -> dict[str, float]:
    """``NAME=VALUE`` texts as numbers, read as a batch CSV's cells are (``parse_value``):
    ``float`` alone would take ``1_000`` and other scripts' digits, which the batch refuses,
    and read ``1e400`` as ``inf``."""
    from ..numbers import parse_value

    out = {}
    for name, text in values.items():
        try:
            out[name] = parse_value(text)
        except OverflowError:
            raise InputError(f"input `{name}` has a number too large for a float: `{text}`",
                             expected="numbers of magnitude at most 1.8e308") from None
        except ValueError:
            shown = f"`{text}`" if text else "empty"               # `road=`: not "not ``"
            raise InputError(f"input `{name}` must be a number, not {shown}",
                             expected="a decimal number such as 78, -4.5 or 1e3",
                             hint=_glued(name, text) if text else
                             f"give it after the `=`, in the same word: `{name}=78`") from None
    return out


def _glued(name: str, text: str) -> str | None:
    """"give each input as a word of its own" for inputs run together with commas or
    semicolons (`road=78,size=45,position=4`), which read as one input whose value is
    `78,size=45,position=4`; the same for a separator left after a number (`road=78,`)."""
    import re

    from ..engine.csvio import comma_in_number
    from ..numbers import parse_value

    comma = comma_in_number(text, f"{name}=")      # `road=78,5`: a decimal comma
    if comma is not None:
        return comma
    if "=" not in text:                         # `road=78,` of `road=78, size=45`
        bare = text.rstrip(",; ")
        try:
            parse_value(bare)
        except (ValueError, OverflowError):
            return None
        return (f"inputs are apart with spaces only: write `{name}={bare}`, without "
                f"`{text[len(bare):].strip()}`") if bare != text else None
    # `road=78size=45`: the next input's name begins where the number ends
    spaced = re.sub(r"(?<=[\d.])(?=[A-Za-z_][\w\-]*=)", " ", f"{name}={text}")
    words = [w for w in re.split(r"[,;\s]+", spaced) if w]
    if len(words) < 2:
        return None
    return "give each input as a word of its own, apart with spaces: `" + " ".join(words) + "`"


def warn_clamped(result: Result) -> None:
    c = result.compiled
    if c.operators.inputs == "as_given":    # fuzzylite's, jFuzzyLogic's reading: said, not clamped
        lo, hi = c.universe[:, 0], c.universe[:, 1]
        outside = ((result.inputs < lo) | (result.inputs > hi)).sum(axis=0)
        for k, count in enumerate(outside):
            if count:
                many = (f" ({plural(int(count), 'sample')})" if result.inputs.shape[0] > 1
                        else f" ({exact(result.inputs[0, k])})")
                warn(f"`{c.inputs[k]}` lies outside its universe [{lo[k]:g}, {hi[k]:g}]{many}: "
                     f"its terms are evaluated there, not clamped (`inputs = as_given`, "
                     f"fuzzylite's and jFuzzyLogic's reading)")
        return
    for k, count in enumerate(result.clamped):
        if count:
            lo, hi = c.universe[k]
            many = f" ({plural(int(count), 'sample')})" if result.inputs.shape[0] > 1 else ""
            warn(f"`{c.inputs[k]}` outside its universe [{lo:g}, {hi:g}] was clamped{many}")


def warn_outside(compiled: CompiledRuleBase, Y: ArrayLike) -> None:
    """An output outside its universe, which a weighted sum or a linear consequent can give
    (the rules' values are what they are: said, not clamped)."""
    import numpy as np

    Y = np.atleast_2d(np.asarray(Y, dtype=float))
    for j, name in enumerate(compiled.outputs):
        lo, hi = compiled.variables[name].universe
        col = Y[:, j]
        out = np.isfinite(col) & ((col < lo - 1e-9 * max(1.0, abs(lo)))
                                  | (col > hi + 1e-9 * max(1.0, abs(hi))))
        if out.any():
            many = (f" in {plural(int(out.sum()), 'sample')}" if len(col) > 1
                    else f" ({exact(col[out][0])})")
            warn(f"output `{name}` lies outside its universe [{exact(lo)}, {exact(hi)}]{many}: "
                 f"the behavior's inference or a linear consequent can leave it")


def warn_undersampled(rb: LoadedRuleBase, dof: np.ndarray | None) -> None:
    """Once per term: a fired rule concludes a Mamdani output term that falls between its
    output's sample points (:func:`~mitos_cli.engine.mamdani.undersampled`), so the number
    printed hardly reflects it. The number is kept as it is (MATLAB samples the same way)."""
    if dof is None or rb.compiled.operators.inference != "mamdani":
        return                              # nothing imported for the common case
    import numpy as np

    from ..engine.check import undersampled_hint
    from ..engine.mamdani import undersampled

    for u in undersampled(rb.compiled):
        strongest = dof[:, u.rules].max(axis=0) if len(dof) else np.zeros(len(u.rules))
        fired = [rb.compiled.labels[r] for r, d in zip(u.rules, strongest) if d > 0]
        if fired:
            warn(f"{u.describe()}, though {', '.join(fired[:3])}"
                 f"{' ...' if len(fired) > 3 else ''} fired (DOF up to "
                 f"{float(strongest.max()):.2g})\n  hint: "
                 f"{undersampled_hint(rb.rulebase.path, u)}")


def eval_command(
    args: Annotated[Optional[list[str]], typer.Argument(
        click_type=WORDS, metavar="[RULEBASE] NAME=VALUE...", callback=named,
        help="Rule file (.rules, .fcl, .fis, .fll; default: the packaged MITOS rule base), "
             "then one NAME=VALUE per input.")] = None,
    behavior: Annotated[Optional[str], typer.Option(
        "--behavior", "-b", metavar="NAME", callback=named,
        help="Evaluate this behavior (default: the file's first).")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
    batch: Annotated[Optional[str], typer.Option(
        "--batch", metavar="FILE.csv|-", callback=named,
        help="Evaluate every row of a CSV whose header names the inputs; write a CSV of the "
             "inputs, the outputs and the CSV's other columns as they were.")] = None,
    digits: Annotated[Optional[int], typer.Option(
        "--digits", metavar="N", click_type=Number("the number of decimals", 0, 12),
        help="Decimals in the trace (default 1, as the paper prints) and, with --batch, in the "
             "outputs (default: every digit, the shortest text that reads back as the same "
             "number).")] = None,
    network: Annotated[bool, typer.Option(
        "--network", help="Print the compiled network of fuzzy neurons instead.")] = False,
    on_no_rule_name: Annotated[Optional[str], typer.Option(
        "--on-no-rule", metavar=choices(NoRule), autocompletion=completer(NoRule),
        help="With --batch, where no rule sets an output: error, default (the output's "
             "declared default, else an error; what happens without this option), nan, or "
             "skip the row. Given, it adds a `no_rule` column naming such outputs.")] = None,
    fidelity_name: Annotated[Optional[str], typer.Option(
        "--fidelity", metavar="ENGINE", autocompletion=completer(Engine),
        help="Sample Mamdani outputs as this engine does (ENGINE: "
             f"{', '.join(e.value for e in Engine)}), to reproduce its published tables: "
             "matlab (101 points with both ends), jfuzzylogic (1000 left cell ends, its COA, "
             "and inputs outside their ranges not clamped), "
             "fuzzylite (fuzzylite 8: cell midpoints at the file's resolution, 1000 where it "
             "gives none), fuzzylite6 (fuzzylite 6, Debian's `fuzzylite`: the same, 100 where "
             "it gives none, as in every FCL `METHOD : COG;` and .fis), both with an FCL or "
             ".fis file's inputs not clamped; octave (Octave's fuzzy-logic-toolkit on a .fis: "
             "101 points, the trapezoid rule, a Sugeno output's equal values joined by the "
             "file's AggMethod, and NaN, said as Octave's, where no rule sets an output and "
             "MATLAB gives the middle of its range).")] = None,
) -> None:
    """Evaluate a rule base: fuzzified inputs, fired rules with DOFs, crisp outputs."""
    on_no_rule = (None if on_no_rule_name is None
                  else choice(NoRule, on_no_rule_name, "--on-no-rule policy"))
    fidelity = None if fidelity_name is None else choice(Engine, fidelity_name, "engine")
    path, values = split_args(args or [])
    rb, engine_nan = _loaded(path, behavior, fidelity)
    if network:
        if batch is not None or values or as_json or digits is not None:
            raise typer.BadParameter("--network prints the rule base's network and evaluates "
                                     "nothing: leave out --batch, --json, --digits and "
                                     "NAME=VALUE")
        from ..engine.describe import describe_network

        emit(describe_network(rb.compiled))
        return
    if batch is not None:
        if values:
            raise typer.BadParameter("give either NAME=VALUE inputs or --batch, not both")
        if as_json:
            raise typer.BadParameter("--batch writes a CSV; --json is for one evaluation "
                                     "(leave one of them out)")
        run_batch(rb, batch, on_no_rule, digits, engine_nan)
        return
    if on_no_rule is not None:
        raise typer.BadParameter("--on-no-rule applies to --batch")
    if not values:
        raise typer.BadParameter(
            "give one NAME=VALUE per input: " + " ".join(f"{k}=..." for k in rb.inputs))
    if as_json and digits is not None:      # (it was taken and did nothing)
        raise typer.BadParameter("--json gives every digit (the shortest text that reads back "
                                 "as the same number); --digits rounds the trace and a "
                                 "--batch's outputs: leave one of them out")
    _evaluate_one(rb, values, as_json, digits, engine_nan)


def _loaded(path: str | None, behavior: str | None, fidelity: Engine | None
            ) -> tuple[LoadedRuleBase, dict[str, str]]:
    """The rule base (the packaged one without ``path``), its notes said, read as the engine
    ``fidelity`` names where one is asked for, and the outputs for which that engine has no
    number where no rule sets them (:func:`~mitos_cli.interop.common.engine_defaults`), each
    with what it does; a lone word that is no file is a lost ``=``."""
    from ..api import LoadedRuleBase, load_rulebase

    if path is not None and not _names_file(path):  # `mitos eval road78 size=45`: a lost `=`
        # the name ends in a letter and the digits read one way (a lazy name before
        # `\d+\.?\d*` split a run of digits every way: 2,000 digits took 20 s)
        lost = re.fullmatch(r"([^\W\d](?:\w*[^\W\d])?)([-+]?(?:\d+(?:\.\d*)?|\.\d+))", path)
        raise typer.BadParameter(f"`{path}` is neither a rule file nor NAME=VALUE (no file "
                                 f"of that name; write each input as NAME=VALUE)"
                                 + (f"; did you mean `{lost[1]}={lost[2]}`?" if lost else ""))
    rb = load_rulebase(path, behavior)
    warn_notes(rb.rulebase)
    if fidelity is None:
        return rb, {}
    from ..interop.common import engine_defaults, fidelity_rulebase, fidelity_settings

    settings = fidelity_settings(rb.rulebase, fidelity.value, behavior)
    ops = rb.compiled.operators
    if not settings and fidelity.value == "octave" and ops.inference != "mamdani":
        warn(f"--fidelity octave changes nothing here: behavior `{rb.compiled.behavior}` infers "
             f"by {ops.inference}, where Octave joins the rules of one value by a .fis file's "
             f"AggMethod, and this file is no .fis or its AggMethod is sum")
    elif not settings:                # it changed nothing, and nothing said so
        warn(f"--fidelity {fidelity.value} changes nothing here: behavior `{rb.compiled.behavior}` "
             f"infers by {ops.inference}, and only Mamdani outputs are sampled")
    if fidelity.value == "octave" and ops.inference == "mamdani" and "bisector" in ops.defuzzify:
        warn("Octave's bisector gives the index of its sample, not the sample (defuzz.m): "
             "--fidelity octave gives the sample, by the trapezoid rule's areas")
    return (LoadedRuleBase(fidelity_rulebase(rb.rulebase, fidelity.value), behavior, settings),
            engine_defaults(rb.rulebase, fidelity.value))


def _names_file(word: str) -> bool:
    """Whether ``word``, the first of eval's arguments and no NAME=VALUE, names a rule file,
    found or not, as ``check``, ``plot`` and ``simulate --rulebase`` read one: a file, a packaged
    rule base (``mitos``), or what looks like a file's name (an extension, a directory, a name
    close to a rule file's: ``mitos.rule``), which is then "not found" with a "did you mean"
    (exit 1). Anything else (``road78``) is an input that lost its ``=`` (exit 2)."""
    from ..lang.resolve import rule_file_hint
    from ..resources import exists, resolve

    given = Path(word)
    return (exists(given) or resolve("rulebases", word, ".rules") is not None
            or given.suffix[1:].isalpha() or len(given.parts) > 1
            or rule_file_hint(word) is not None)


def _evaluate_one(rb: LoadedRuleBase, values: dict[str, str], as_json: bool, digits: int | None,
                  engine_nan: dict[str, str] | None = None) -> None:
    """One sample from its ``NAME=VALUE`` texts: its trace (or JSON), and warnings on stderr for
    clamped inputs, outputs outside their universes and undersampled terms that fired; the
    trace says what the engine does for the outputs of ``engine_nan`` that no rule sets."""
    import dataclasses

    from ..engine.evaluation import as_batch, evaluate
    from ..engine.trace import trace_of

    unused = unused_inputs(rb)
    numbers = parse_values(values)
    refuse_nan(numbers)
    given: dict[str, object] = {k: v for k, v in numbers.items() if k not in unused}
    X = as_batch(rb.compiled, given)
    result = evaluate(rb.compiled, X)
    warn_clamped(result)
    warn_outside(rb.compiled, result.outputs)
    warn_undersampled(rb, result.dof)
    trace = trace_of(result, given=X)
    if engine_nan:
        trace = dataclasses.replace(trace, engine_nan=tuple(
            (name, engine_nan[name]) for name in trace.defaulted if name in engine_nan))
    if as_json:
        emit(json_text(trace.to_json(), infinity_as_text=True))
    else:
        emit(trace.render(1 if digits is None else digits))


def refuse_nan(numbers: dict[str, float]) -> None:
    """NaN inputs are an error, as the engine says for the inputs the rules test; an input
    they do not test is dropped before the engine, and took `unused=nan` where it refused
    `unused=abc`."""
    for name, x in numbers.items():
        if x != x:
            raise InputError(f"input `{name}` is not a number (NaN)",
                             hint="give every input a finite number")


def unused_inputs(rb: LoadedRuleBase) -> tuple[str, ...]:
    """Inputs the file declares but the behavior's rules never test: a table of the file's
    inputs may still give them (and their values change nothing)."""
    return tuple(v.name for v in rb.rulebase.variables.values()
                 if v.role == "input" and v.name not in rb.compiled.inputs)


def run_batch(rb: LoadedRuleBase, source: str, on_no_rule: NoRule | None = None,
              digits: int | None = None, engine_nan: dict[str, str] | None = None) -> None:
    """Read the CSV, evaluate all rows as one batch, write inputs and outputs as CSV;
    ``engine_nan``: the outputs whose default is NaN for an engine (``--fidelity``)."""
    from ..engine.csvio import flag_name, passed_names, read_table, row_span, write_batch
    from ..engine.evaluation import rule_dofs
    from ..engine.mamdani import undersampled

    if source == "-":                  # bytes: a text stream would turn `\r\n` into `\n`
        from ..fileio import bad_byte, decode_text, text_encoding_hint, why_unreadable

        stream = getattr(sys.stdin, "buffer", None)
        try:
            text = decode_text(stream.read()) if stream is not None else sys.stdin.read()
        except UnicodeDecodeError as exc:
            raise InputError(f"cannot read the batch from stdin: {why_unreadable(exc)}",
                             span=bad_byte("<stdin>", exc), hint=text_encoding_hint(exc)) from None
        name = "<stdin>"
    else:
        from ..fileio import (
            bad_byte,
            nearby,
            read_text,
            repository_only,
            text_encoding_hint,
            unreadable,
        )

        try:
            text, name = read_text(source), source
        except (OSError, UnicodeDecodeError) as exc:
            missing = isinstance(exc, FileNotFoundError)      # a mistyped name: did you mean
            raise InputError(unreadable("batch file", source, exc), span=bad_byte(source, exc),
                             hint=nearby(source, (".csv",)) or repository_only(source)
                             if missing else text_encoding_hint(exc)) from None
    batch = read_table(text, name, rb.compiled.inputs, unused_inputs(rb))
    X = batch.X
    result = rb.run(X, strict=False, detail=False)
    warn_clamped(result)
    if undersampled(rb.compiled):       # the rules' DOFs, only when there is a term to tell
        warn_undersampled(rb, rule_dofs(rb.compiled, X))
    Y, keep, flags = no_rule_policy(rb.compiled, result, on_no_rule or NoRule.default,
                                    lambda row: row_span(text, name, row), engine_nan)
    warn_outside(rb.compiled, Y[keep])
    flag = flag_name(rb.compiled.inputs, rb.compiled.outputs)
    taken = (*rb.compiled.inputs, *rb.compiled.outputs, *(() if on_no_rule is None
                                                         else (flag,)))
    extra = passed_names(batch.extra, taken)
    renamed = [f"`{a}` as `{b}`" for a, b in zip(batch.extra, extra) if a != b]
    if renamed:
        warn("passed-through " + plural(len(renamed), "column") + " renamed, the output CSV "
             "has columns of those names: " + ", ".join(renamed))
    everything = bool(keep.all())
    write_batch(sys.stdout, rb.compiled.inputs,
                [g if everything else g[keep] for g in batch.given],
                rb.compiled.outputs, Y[keep], None if on_no_rule is None else flags[keep],
                extra, [c if everything else c[keep] for c in batch.columns], digits)


def _no_rule_hint(output: str, declared: bool) -> str:
    """What writes the other rows: ``--on-no-rule default`` only where ``output`` declares a
    default (without one it is the choice that just failed)."""
    if declared:
        return "--on-no-rule default, nan or skip writes the other rows (`mitos docs interop`)"
    return (f"`{output}` declares no default: declare one, or give --on-no-rule nan or skip "
            "to write the other rows (`mitos docs interop`)")


def _fired_rows(compiled: CompiledRuleBase, result: Result, rows: np.ndarray,
                j: int) -> np.ndarray:
    """Of the rows where output ``j`` has no value (``rows``), those where a rule setting it
    fires all the same (a Mamdani set 0 at every sample, Tsukamoto inverses at +inf and
    -inf): "no rule sets it" there was untrue. Only those rows' DOFs are computed."""
    import numpy as np

    from ..engine.evaluation import rule_dofs

    fired = np.zeros(len(rows), dtype=bool)
    index = np.flatnonzero(rows)
    dof = rule_dofs(compiled, result.inputs[index])
    fired[index] = (dof[:, compiled.cons_mask[:, j]] > 0).any(axis=1)
    return fired


def _unset_words(out: str, count: int, fired: int, n: int) -> str:
    """Why ``out`` has no value in ``count`` rows of ``n``, ``fired`` of them rows where its
    rules fire."""
    if not fired:
        return f"no rule sets `{out}` in {plural(count, 'row')} of {n}"
    if fired == count:
        return f"the rules that fire give `{out}` no value in {plural(count, 'row')} of {n}"
    return (f"no rule sets `{out}` in {plural(count - fired, 'row')} of {n}, and the rules "
            f"that fire give it no value in {plural(fired, 'other')}")


def no_rule_policy(compiled: CompiledRuleBase, result: Result, policy: NoRule,
                   where: Callable[[int], Span | None] | None = None,
                   engine_nan: dict[str, str] | None = None
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(outputs, rows to keep, no_rule column)`` after applying ``policy`` to the rows where
    no rule set an output; a warning says how many rows each output's choice changed. An
    error stops at the first such row, at ``where(row)`` (its place in the batch file).
    ``engine_nan`` names the outputs whose default is NaN for an engine (``--fidelity
    octave``), each with what the engine does there, which the warning says."""
    import numpy as np

    from ..engine.evaluation import declares_nan
    from ..errors import EmptyOutputError, NoRuleFiredError

    Y = result.outputs.copy()
    unset = result.no_rule if result.no_rule is not None else np.zeros(Y.shape, dtype=bool)
    n = len(Y)
    keep = np.ones(n, dtype=bool)
    for j, out in enumerate(compiled.outputs):
        rows = unset[:, j]
        count = int(rows.sum())
        if not count:
            continue
        declared = not np.isnan(compiled.default[j]) or declares_nan(compiled, out)
        shown = "nan" if np.isnan(compiled.default[j]) else f"{compiled.default[j]:g}"
        fired = _fired_rows(compiled, result, rows, j)
        if policy is NoRule.error or (policy is NoRule.default and not declared):
            row = int(np.argmax(rows))
            values = ", ".join(f"{k}={exact(result.inputs[row, i])}"
                               for i, k in enumerate(compiled.inputs))
            error = EmptyOutputError if fired[row] else NoRuleFiredError
            what = (f"the rules that fire give `{out}` no value" if fired[row]
                    else f"no rule sets `{out}`")
            raise error(
                f"{what} for {values} (row {row + 1}; {count} of {n} rows)",
                span=None if where is None else where(row),
                hint=_no_rule_hint(out, declared))
        what = _unset_words(out, count, int(fired.sum()), n)
        if policy is NoRule.default and engine_nan and out in engine_nan:
            warn(f"{what}: {engine_nan[out]} there, and nan is written")
        elif policy is NoRule.default:
            warn(f"{what}: the file's default ({shown}) is written there")
        elif policy is NoRule.nan:
            Y[rows, j] = np.nan
            warn(f"{what}: nan is written there")
        else:
            keep &= ~rows
            warn(f"{what}: left out")
    flags = np.full(n, "", dtype=object)
    for j, out in enumerate(compiled.outputs):
        flags = np.where(unset[:, j], flags + (";" + out), flags)
    return Y, keep, np.char.lstrip(flags.astype(str), ";") if n else flags
