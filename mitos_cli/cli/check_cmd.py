"""``mitos check``: static analysis of a rule base; exit 1 when it finds an error."""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Annotated, Optional

import typer

from ..words import plural
from .output import emit, json_text, warn, warn_notes
from .params import WORDS, Number, named

if TYPE_CHECKING:
    from ..engine.check import GridInfo, Report
    from ..lang.terms import TermSet


def show_path(path: str | None) -> str:
    """A span's path as users should read it: relative when below the current directory."""
    if not path:
        return "<rules>"
    try:
        rel = os.path.relpath(path)
    except ValueError:
        return path
    return path if rel.startswith("..") else rel


def render(report: Report, trace_path: str) -> str:
    """The report for people: one ``path:line:col: severity: message`` block per finding, with
    the line it points into and a caret, each path as the user gave it, a packaged file as
    the summary's ``checked PATH`` names it (``rulebases/...``, not its place in
    site-packages)."""
    from ..errors import excerpt
    from ..resources import packaged_name

    shown_as: dict[str | None, str] = {}     # each file once (20,000 findings took 10 s)
    lines = []
    for f in report.findings:
        where = ""
        if f.span:
            if f.span.path not in shown_as:
                shown_as[f.span.path] = ((f.span.path and packaged_name(f.span.path))
                                         or show_path(f.span.path))
            where = f"{shown_as[f.span.path]}:{f.span.line}:{f.span.column}: "
        shown = "note" if f.severity == "info" else f.severity     # as the summary counts it
        lines.append(f"{where}{shown}: {f.message} [{f.code}]")
        lines += excerpt(f.span, whole_lines=False)      # the line it points into
        for box in f.regions:
            lines.append(f"    {box.describe()}")
        if f.more_regions:
            lines.append(f"    ... and {plural(f.more_regions, 'more region')}")
        if f.uncovered:
            lines.append(f"    ... and {plural(f.uncovered, 'scattered sample')}")
        if f.hint:
            lines.append(f"    hint: {f.hint}")
    grids = "; ".join(
        f"`{g.behavior}` on " + " x ".join(f"{n} {name}" for name, n in g.points)
        + f" = {plural(g.samples, 'sample')}" for g in report.grids)
    counts = [plural(report.count(s), word) for s, word in
              (("error", "error"), ("warning", "warning"), ("info", "note"))]
    if lines:
        lines.append("")
    if report.rulebase.behaviors:
        lines.append(f"checked {trace_path}: {grids}")
    else:                                   # a term set alone: its terms, no rules
        lines.append(f"checked {trace_path}: the term set's "
                     f"{plural(len(report.rulebase.variables), 'variable')} (no rules)")
    for g in report.grids:
        if g.skipped:
            lines.append(skipped_note(g))
    lines.append(", ".join(counts) + (" - OK" if report.ok else ""))
    return "\n".join(lines)


def _check_termset(termset: TermSet, path: str | None, behavior: str | None) -> Report:
    """A term set's own findings (:func:`..engine.check.check_termset`), of a YAML term set or
    of a foreign file that has no rules (said so); ``-b`` needs rules."""
    from ..api import is_termset_name
    from ..engine.check import check_termset
    from ..errors import UsageError

    if behavior is not None:
        raise UsageError(f"`{path}` has no behaviors (its terms only): -b {behavior} needs "
                         "a rule file that reads them")
    if not is_termset_name(path):
        warn(f"`{path}` has no rules: its terms alone are checked")
    return check_termset(termset)


def skipped_note(grid: GridInfo) -> str:
    """Says that a behavior's grid is coarser than its terms (too many inputs), so that its
    `no-rule-fires` and `low-dof` findings, or their absence, claim no more than was seen."""
    from ..engine.check import MAX_SAMPLES, listed_names

    missed = ("places where the DOF is low may be missed between them (where no rule fires "
              "was decided exactly, with no grid)" if grid.exact else
              "places where no rule fires, or the DOF is low, may be missed between them")
    return (f"note: `{grid.behavior}`'s grid skipped corner points of {listed_names(grid.skipped)} "
            f"(all of them would take {grid.corner_samples:.3g} samples, the grid at most "
            f"{MAX_SAMPLES:,}): {missed}")


def to_json(report: Report, trace_path: str) -> dict:
    return {
        ("rulebase" if report.rulebase.behaviors else "termset"): trace_path,
        "ok": report.ok,
        "threshold": report.threshold,
        "behaviors": [{"name": g.behavior, "samples": g.samples,
                       "grid": {name: n for name, n in g.points},
                       "skipped_corners": list(g.skipped),
                       "exact_gaps": g.exact} for g in report.grids],
        "summary": {s: report.count(s) for s in ("error", "warning", "info")},
        "findings": [_shown(f.to_json()) for f in report.findings],
    }


def _shown(finding: dict) -> dict:
    if finding["span"] is not None:
        finding["span"]["path"] = show_path(finding["span"]["path"])
    return finding


def check_command(
    rulebase: Annotated[Optional[str], typer.Argument(
        click_type=WORDS, metavar="[RULEBASE]", callback=named,
        help="Rule file (default: the packaged MITOS rule base), or a term set "
             "(FILE.terms.yaml) checked alone.")] = None,
    behavior: Annotated[Optional[str], typer.Option(
        "--behavior", "-b", metavar="NAME", callback=named,
        help="Check only this behavior, and the term sets' variables it reads or sets "
             "(default: every behavior and variable).")] = None,
    threshold: Annotated[float, typer.Option(
        "--threshold", "-t", metavar="DOF", click_type=Number("the DOF threshold", 0.0, whole=False),
        help="Report regions where the total DOF of an output's rules is below this.")] = 0.1,
    resolution: Annotated[int, typer.Option(
        "--resolution", "-n", metavar="N",
        click_type=Number("the number of grid points per input", 2, 10_000),
        help="Grid points per input (plus the terms' corners; lowered to keep the grid at "
             "most 300,000 samples).")] = 41,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """Check a rule base: coverage gaps, conflicts, duplicates, dead rules, unused terms.

    Also low total DOF, contradictions, and gaps between the terms of an input. Exits 1 on
    an error: inputs where no rule sets an output that has no default, or rules with the
    same condition and different actions."""
    from ..api import read_terms
    from ..engine.check import check_rulebase
    from ..lang.model import RuleBase
    from ..resources import display_path

    source = read_terms(rulebase)
    if isinstance(source, RuleBase):
        warn_notes(source)
        report = check_rulebase(source, behavior, threshold=threshold, resolution=resolution)
    else:
        report = _check_termset(source, rulebase, behavior)
    name = display_path(report.rulebase.path)
    if as_json:
        emit(json_text(to_json(report, name)))
    else:
        emit(render(report, name))
    if not report.ok:
        raise typer.Exit(1)

