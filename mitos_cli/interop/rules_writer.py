"""Writing a rule base as fresh MITOS files: ``NAME.rules`` and ``NAME.terms.yaml``.

This writes new files from the model (for ``mitos convert --to rules``); the teaching loop has
its own saver that keeps the comments of an existing file. One behavior is written, with its
``use`` includes inlined, as top-level rules; operators that differ from MITOS's defaults go on
an ``operators:`` line. Names the rule language cannot hold (reserved words, characters outside
``[A-Za-z0-9_-]``) are refused with the name.
"""

from __future__ import annotations

import json
import re
from typing import TYPE_CHECKING

import numpy as np
import yaml

from ..errors import FormatError
from ..lang.model import Rule, RuleBase, format_rule
from ..lang.terms import Term, Variable
from . import common

if TYPE_CHECKING:
    from collections.abc import Iterable, Sequence

NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_\-]*[A-Za-z0-9_]|[A-Za-z_]")
RESERVED = common.RESERVED_NAMES["rules"]       # the rule language's keywords and hedge words


def check_name(name: str, what: str) -> None:
    if not NAME.fullmatch(name) or name in RESERVED:
        why = "is a reserved word" if name in RESERVED else "has characters the rule language " \
                                                               "does not allow in names"
        raise FormatError(f"{what} `{name}` {why}",
                          hint="rename it in the source file (letters, digits, `_` and `-`)")


def check_readable(v: Variable, t: Term) -> None:
    """Refuse, at the source file's term, a term its format accepts but a term set refuses: a
    core (or an output's peak) outside the variable's range, which MATLAB and fuzzylite allow.
    Written as it is, the converted files could not be read back by any command."""
    from ..errors import TermSetError
    from ..lang.terms import check_term

    try:
        check_term(t, v.universe, v.name, peak_inside=v.role == "output")
    except TermSetError as exc:
        raise FormatError(f"{exc.message}: the rule language needs a term's core (an output "
                          f"term's peak) inside its variable's range", span=t.span,
                          hint="move the term inside the range, or widen the range, in the "
                               "source file") from None


def write_rules(rb: RuleBase, termset_name: str, behavior: str | None = None,
                source: str = "") -> tuple[str, str]:
    """``(rules text, term-set YAML text)``; the rules file names ``termset_name``.

    A behavior that uses no other is written as top-level rules; one that does is written with
    the behaviors it uses (recursively) as ``behavior`` blocks, itself first (the default)."""
    from ..lang.model import Use, flatten, format_use
    from ..lang.operators import of_behavior, resolve
    from .common import legal_names

    rb, _ = legal_names(rb, "rules")
    name = behavior or rb.default_behavior
    chosen = rb.behavior(name)
    order: list = []

    def visit(bname: str) -> None:
        if bname in [b.name for b in order]:
            return
        b = rb.behavior(bname)
        order.append(b)
        for use in b.uses:
            visit(use.behavior)

    visit(name)
    rules = [r for _, r, _ in flatten(rb, name)]
    conditions = [u.condition for b in order for u in b.uses if u.condition is not None]
    used_in = {p.var for r in rules for p in common.props(r.antecedent)}
    used_in |= {p.var for c in conditions for p in common.props(c)}
    used_out = {c.var for r in rules for c in r.consequents}
    flat = common.Flat(name, tuple(v for v in rb.variables.values()
                                   if v.role == "input" and v.name in used_in),
                       tuple(v for v in rb.variables.values()
                             if v.role == "output" and v.name in used_out),
                       tuple(rules), of_behavior(rb, chosen))
    inputs = common.all_inputs(rb, flat)
    for v in inputs + flat.outputs:
        check_name(v.name, "variable")
        for t in v.terms:
            check_name(t.name, f"term of `{v.name}`")
            check_readable(v, t)
    head = [f"# {name}: written by `mitos convert`" + (f" from {source}" if source else ""),
            "", f"terms {_quote(termset_name)}"]
    file_settings = resolve(rb.operators).settings()
    if len(order) == 1:                  # one behavior: its settings on the file's line
        file_settings = flat.operators.settings()
    if file_settings:
        head.append("operators: " + ", ".join(f"{k} = {v}" for k, v in file_settings.items()))
    head.append("")
    if len(order) == 1:
        body = _rule_lines(chosen.rules, "")
        if chosen.frozen:
            body.append("frozen " + ", ".join(chosen.frozen))
    else:
        body = []
        for b in order:
            check_name(b.name, "behavior")
            body.append(f"behavior {b.name}:")
            if b.operators:
                body.append("    operators: " + ", ".join(f"{s.key} = {s.value}"
                                                          for s in b.operators))
            body += ["    " + format_use(Use(u.behavior, u.condition, u.weight))
                     for u in b.uses]
            body += _rule_lines(b.rules, "    ")
            if b.frozen:
                body.append("    frozen " + ", ".join(b.frozen))
            body += ["end", ""]
    return "\n".join(head + body).rstrip("\n") + "\n", write_termset(rb, inputs, flat.outputs,
                                                                      source)


def _rule_lines(rules: Iterable[Rule], indent: str) -> list[str]:
    labels: set[str] = set()
    lines = []
    for i, r in enumerate(rules):
        label = r.label if NAME.fullmatch(r.label or "") and r.label not in RESERVED else ""
        if not label or label in labels:
            label = common.unique_name(f"r{i + 1}", labels)
        labels.add(label)
        lines.append(indent + format_rule(Rule(label, r.antecedent, r.consequents, r.weight),
                                          label=True))
    return lines


def _quote(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _scalar(value: str | float) -> str:
    if isinstance(value, str):
        return yaml.safe_dump(value, default_flow_style=True, width=1 << 16).strip() \
            .removesuffix("...").strip()
    value = float(value)
    if np.isnan(value):
        return ".nan"
    if np.isinf(value):
        return ".inf" if value > 0 else "-.inf"
    return common.fmt_number(value)


def _written_universe(rb: RuleBase, v: Variable) -> tuple[float, float]:
    """``v``'s universe, or for a weighted-average output without one (fuzzylite's
    ``range: 0 0``) the interval its terms can reach over the inputs' universes, which a term
    set needs and the weighted average never uses."""
    lo, hi = v.universe
    if np.isfinite(lo) and np.isfinite(hi):
        return lo, hi
    ends = []
    for t in v.terms:
        if t.shape == "linear":
            coefficients = common.linear_coefficients(rb, v.name, t)
            low = high = t.params[-1]
            for name, a in coefficients.items():
                a_lo, a_hi = (a * x for x in rb.variables[name].universe)
                low, high = low + min(a_lo, a_hi), high + max(a_lo, a_hi)
            ends += [low, high]
        else:
            ends.append(t.center)
    lo, hi = min(ends), max(ends)
    return (lo, hi) if lo < hi else (lo - 0.5, hi + 0.5)


def write_termset(rb: RuleBase, inputs: Sequence[Variable], outputs: Sequence[Variable],
                  source: str = "") -> str:
    lines = ["# Term set written by `mitos convert`" + (f" from {source}" if source else ""),
             "variables:"]
    input_names = [v.name for v in inputs]
    for v in tuple(inputs) + tuple(outputs):
        if not v.terms:
            raise FormatError(f"input `{v.name}` has no terms (it only feeds linear "
                              f"consequents); a YAML term set needs at least one term",
                              hint="convert to FLL, FCL or FIS instead, which allow it")
        lines.append(f"  {_scalar(v.name)}:")
        if v.description:
            lines.append(f"    description: {_scalar(v.description)}")
        if v.unit:
            lines.append(f"    unit: {_scalar(v.unit)}")
        lines.append(f"    role: {v.role}")
        lo, hi = _written_universe(rb, v)
        lines.append(f"    universe: [{_scalar(lo)}, {_scalar(hi)}]")
        if v.default is not None:
            lines.append(f"    default: {_scalar(v.default)}")
        if v.resolution is not None:
            lines.append(f"    resolution: {v.resolution}")
        lines.append("    terms:")
        for t in v.terms:
            lines.append(f"      {_scalar(t.name)}: {_term_spec(rb, v, t, input_names)}")
    return "\n".join(lines) + "\n"


def _term_spec(rb: RuleBase, v: Variable, t: Term, inputs: list[str]) -> str:
    p = t.params
    frozen = (", frozen: true" if t.frozen else "") + \
        (", held: false" if not t.held else "" if t.held_at is None else
         f", held: {_scalar(t.held_at)}")
    if t.shape == "singleton":
        return f"{{shape: singleton, value: {_scalar(p[0])}{frozen}}}" if frozen else _scalar(p[0])
    if t.shape == "linear":
        coefficients = common.linear_coefficients(rb, v.name, t)
        lo, hi = _written_universe(rb, v)
        if not any(coefficients.values()) and lo <= p[-1] <= hi:   # y = constant: a number
            return _scalar(p[-1])            # (beyond the universe a number is refused there)
        given = ", ".join(f"{_scalar(n)}: {_scalar(a)}" for n, a in coefficients.items()
                          if a != 0.0)
        return f"{{shape: linear, coefficients: {{{given}}}, constant: {_scalar(p[-1])}}}"
    if t.formula is not None:                      # a JSON string is a YAML string
        return (f"{{shape: formula, formula: {json.dumps(t.formula.text)}"
                f"{', frozen: true' if t.frozen else ''}}}")
    if t.shape == "triangle_pw":
        return f"{{shape: triangle, peak: {_scalar(p[0])}, width: {_scalar(p[1])}{frozen}}}"
    if t.shape == "triangle_plr":
        return (f"{{shape: triangle, peak: {_scalar(p[0])}, left_width: {_scalar(p[1])}, "
                f"right_width: {_scalar(p[2])}{frozen}}}")
    if t.shape == "binary" and np.isinf(p[1]):      # only the side matters: a finite one
        p = (p[0], p[0] + (1.0 if p[1] > 0 else -1.0))
    points = ", ".join(_scalar(x) for x in p)
    return f"{{shape: {t.shape}, points: [{points}]{frozen}}}"
