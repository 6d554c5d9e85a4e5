"""``mitos eval``: one-shot inference with the paper's DOF trace, JSON, or a CSV batch."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Annotated, Optional

import typer

from ..errors import InputError
from .output import emit, warn
from ..words import plural


def split_args(args: list[str]) -> tuple[Optional[str], dict[str, str]]:
    """``[RULEBASE] NAME=VALUE ...`` -> (rule-base path or None, {name: text})."""
    path: Optional[str] = None
    values: dict[str, str] = {}
    for arg in args:
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


def parse_values(values: dict[str, str]) -> dict[str, float]:
    out = {}
    for name, text in values.items():
        try:
            out[name] = float(text)
        except ValueError:
            raise InputError(f"input `{name}` must be a number, not `{text}`") from None
    return out


def warn_clamped(result) -> None:
    c = result.compiled
    for k, count in enumerate(result.clamped):
        if count:
            lo, hi = c.universe[k]
            many = f" ({plural(int(count), 'sample')})" if result.inputs.shape[0] > 1 else ""
            warn(f"`{c.inputs[k]}` outside its universe [{lo:g}, {hi:g}] was clamped{many}")


def eval_command(
    args: Annotated[Optional[list[str]], typer.Argument(
        metavar="[RULEBASE] NAME=VALUE...",
        help="Rule file (.rules, .fcl, .fis, .fll; default: the packaged MITOS rule base), "
             "then one NAME=VALUE per input.")] = None,
    behavior: Annotated[Optional[str], typer.Option(
        "--behavior", "-b", help="Evaluate this behavior (default: the file's first).")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
    batch: Annotated[Optional[str], typer.Option(
        "--batch", metavar="FILE.csv|-",
        help="Evaluate every row of a CSV whose header names the inputs; write a CSV.")] = None,
    digits: Annotated[int, typer.Option(
        "--digits", min=0, max=12, help="Decimals in the trace (the paper prints 1).")] = 1,
    network: Annotated[bool, typer.Option(
        "--network", help="Print the compiled network of fuzzy neurons instead.")] = False,
) -> None:
    """Evaluate a rule base: fuzzified inputs, fired rules with DOFs, crisp outputs."""
    from ..api import load_rulebase

    path, values = split_args(args or [])
    if path is not None and Path(path).suffix.lower() not in (".rules", ".fcl", ".fis", ".fll") \
            and not Path(path).exists():    # `mitos eval road78 size=45`: a lost `=`
        raise typer.BadParameter(f"`{path}` is neither a rule file nor NAME=VALUE (no file "
                                 f"of that name; write each input as NAME=VALUE)")
    rb = load_rulebase(path, behavior)
    if network:
        from ..engine.describe import describe_network

        emit(describe_network(rb.compiled))
        return
    if batch is not None:
        if values:
            raise typer.BadParameter("give either NAME=VALUE inputs or --batch, not both")
        if as_json:
            raise typer.BadParameter("--batch writes a CSV; --json is for one evaluation "
                                     "(leave one of them out)")
        run_batch(rb, batch)
        return
    if not values:
        raise typer.BadParameter(
            "give one NAME=VALUE per input: " + " ".join(f"{k}=..." for k in rb.inputs))
    from ..engine.evaluation import as_batch, evaluate
    from ..engine.trace import trace_of

    result = evaluate(rb.compiled, as_batch(rb.compiled, parse_values(values)))
    warn_clamped(result)
    trace = trace_of(result)
    if as_json:
        emit(json.dumps(trace.to_json(), indent=2))
    else:
        emit(trace.render(digits))


def run_batch(rb, source: str) -> None:
    """Read the CSV, evaluate all rows as one batch, write inputs and outputs as CSV."""
    import numpy as np

    from ..engine.csvio import read_batch, write_batch

    if source == "-":
        text, name = sys.stdin.read(), "<stdin>"
    else:
        try:
            text, name = Path(source).read_text(encoding="utf-8"), source
        except (OSError, UnicodeDecodeError) as exc:
            raise InputError(f"cannot read batch file `{source}`: "
                             f"{getattr(exc, 'strerror', None) or exc}") from None
    X = read_batch(text, name, rb.compiled.inputs)
    result = rb.run(X)
    warn_clamped(result)
    write_batch(sys.stdout, rb.compiled.inputs, np.asarray(X), rb.compiled.outputs,
                result.outputs)
