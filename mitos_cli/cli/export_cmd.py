"""``mitos export``: a rule base as a self-contained C99 file or a NumPy-only Python module."""

from __future__ import annotations

from enum import Enum
from pathlib import Path
from typing import Annotated, Optional

import typer

from .output import emit, err, warn, warn_notes
from .params import FILE, choices, completer, file_arg, named, target_of
from .targets import check_suffix, refuse_inputs, source_files


class Language(str, Enum):
    c = "c"
    python = "python"


SUFFIX = {Language.c: ".c", Language.python: ".py"}


def export_command(
    path: Annotated[Optional[Path], typer.Argument(
        click_type=FILE, metavar="[FILE]", help="Rule base to export (.rules, .fcl, .fis or .fll; "
                                                "default: the packaged MITOS rule base).")] = None,
    to_name: Annotated[Optional[str], typer.Option(
        "--to", metavar=choices(Language), autocompletion=completer(Language),
        help="c: one C99 file (no allocation, only libm); python: a NumPy-only module "
             "(default: the one -o's extension names, .c or .py).")] = None,
    output: Annotated[Optional[Path], typer.Option(
        "--output", "-o", parser=file_arg, metavar="OUT",
        help="File to write: a .c file for --to c, a .py file for --to python (default: "
             "stdout).")] = None,
    behavior: Annotated[Optional[str], typer.Option(
        "--behavior", "-b", metavar="NAME", callback=named,
        help="Behavior to export (default: the file's first).")] = None,
    prefix: Annotated[Optional[str], typer.Option(
        "--prefix", metavar="PREFIX",
        help="C names: PREFIX_eval, PREFIX_IN_<INPUT>, PREFIX_OUT_<OUTPUT> "
             "(default: mitos); --to c only.")] = None,
) -> None:
    """Export a rule base as code that computes its outputs from its inputs.

    The C function is `int PREFIX_eval(const double *in, double *out)`; the Python module
    has `evaluate(X)` for a batch X (one row per sample). Both agree with `mitos eval` to
    rounding.
    """
    from ..api import default_rulebase_path, load_rulebase
    from ..interop import left_out
    from ..interop.common import atomic_write
    from ..interop.export import ident, to_c, to_python

    to = target_of(Language, to_name, output, SUFFIX, "export language")
    if output is not None:
        check_suffix(output, SUFFIX[to], f"--to {to.value}")
    if prefix is not None and to is not Language.c:      # it was ignored without a word
        raise typer.BadParameter(f"--prefix names the C code's functions and macros; --to "
                                 f"{to.value} has none: leave --prefix out")
    prefix = "mitos" if prefix is None else prefix
    if ident(prefix) != prefix:
        close = ident(prefix)
        raise typer.BadParameter(f"--prefix `{prefix}` is not a C identifier (letters, digits "
                                 f"and `_`, not starting with a digit)"
                                 + (f"; did you mean `{close}`?" if close.strip("_") else ""))
    path = path if path is not None else default_rulebase_path()
    rb = load_rulebase(path, behavior)
    if output is not None:
        refuse_inputs([output], source_files(rb.rulebase, path))
    warn_notes(rb.rulebase)
    note = left_out(rb.rulebase, behavior, "exported")
    if note:
        warn(note)
    text = to_c(rb.compiled, prefix, path.name) if to is Language.c else \
        to_python(rb.compiled, path.name)
    if output is None:
        emit(text)
    else:
        atomic_write(output, text if text.endswith("\n") else text + "\n")
        err(f"wrote {output}")
