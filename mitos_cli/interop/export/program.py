"""What the C and Python writers share: a compiled behavior as a straight-line program.

One membership per input term, one expression per rule (the AND / OR / NOT / hedge neurons
written out as calls of ``tnorm``, ``snorm`` and ``hedge_*``), then the output layer's
weighted sums. Names from the rule base reach the generated code only as identifiers made
here of ``[A-Za-z0-9_]`` (unique within their kind, so two names that sanitise alike cannot
share a variable) or, through the writers, as escaped text: a file never adds code.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ...engine.compile import CompiledRuleBase
from ...errors import FormatError
from ...fuzzy.shapes import kernel_params
from ...lang.model import And, Expr, Not, Prop, flatten
from ..common import setting_span

if TYPE_CHECKING:
    from collections.abc import Callable, Iterable

    from ...engine.compile import Accumulation

#: Text that may stand as it is in a C comment or a Python docstring.
PLAIN = re.compile(r"[A-Za-z0-9_ .,:;+=@%()\[\]<>~^!#&|{}-]*")


def num(value: float) -> str:
    """A float literal valid in C and Python that reads back to the same double."""
    value = float(value)
    if np.isnan(value) or np.isinf(value):
        raise ValueError(value)
    text = repr(value)
    return text if ("." in text or "e" in text or "n" in text) else text + ".0"


def finite_binary(params: tuple[float, ...]) -> tuple[float, ...]:
    """A ``binary`` term's direction as a finite number on the same side of its start: only
    which side counts, and ``Binary 3 inf`` (fuzzylite's way to write it) has no literal."""
    start, direction = params
    step = max(1.0, abs(start))
    return (start, start + step if direction > start else start - step if direction < start
            else start)


def ident(name: str) -> str:
    """``name`` as a C / Python identifier fragment: ``[A-Za-z0-9_]``, not starting with a
    digit."""
    out = re.sub(r"[^A-Za-z0-9_]", "_", name)
    return out if out and not out[0].isdigit() else "_" + out


def unique_idents(names: Iterable[str], fold: Callable[[str], str] = str) -> list[str]:
    """:func:`ident` of each name, ``_2``, ``_3`` ... appended where two would coincide
    (after ``fold``: ``str.upper`` for C macros)."""
    seen: set[str] = set()
    out = []
    for name in names:
        base = candidate = ident(name)
        n = 1
        while fold(candidate) in seen:
            n += 1
            candidate = f"{base}_{n}"
        seen.add(fold(candidate))
        out.append(candidate)
    return out


@dataclass(frozen=True)
class Program:
    """The straight-line form of a compiled behavior, shared by the C and Python writers."""

    compiled: CompiledRuleBase
    terms: tuple            # (var index, column name, shape, params, kernel or None)
    rules: tuple            # (column name, expression text, weight)
    shapes: tuple           # non-linear shapes used
    hedges: tuple           # hedges used
    norms: tuple            # "tnorm" / "snorm" where some rule uses them, "kernel"


def term_columns(compiled: CompiledRuleBase) -> dict[tuple[str, str], str]:
    """``mu_<variable>_<term>`` for every input term, unique however the names sanitise."""
    wanted = [f"{ident(var)}_{ident(term)}" for var, term in compiled.term_names]
    return {key: f"mu_{col}" for key, col in zip(compiled.term_names, unique_idents(wanted))}


def program(compiled: CompiledRuleBase) -> Program:
    """Build the straight-line program of ``compiled``."""
    if compiled.operators.inference == "tsukamoto":
        raise FormatError("`mitos export` has no code for Tsukamoto inference",
                          span=setting_span(compiled.rulebase, compiled.behavior, "inference"),
                          hint="export it with another inference, or convert it to FLL (`mitos "
                               "convert --to fll`) to run it in fuzzylite")
    if compiled.operators.inference == "mamdani" and compiled.operators.sampling == "trapezoid":
        raise FormatError("`mitos export` has no code for `sampling = trapezoid` (Octave's "
                          "centroid, the ends weighing half)",
                          span=setting_span(compiled.rulebase, compiled.behavior, "sampling"),
                          hint="export it with `sampling = endpoints` (MATLAB's) or "
                               "`midpoints`; the outputs move by the ends' half weight")
    names = term_columns(compiled)
    hedges: set[str] = set()
    used: set[str] = set()
    referenced: set[str] = set()

    def expr(e: Expr, negate: bool = False) -> str:
        """C / Python text of ``e``, or of ``not e``; ``not not x`` is ``x`` exactly, as the
        compiler has it (``1 - (1 - x)`` would round a tiny membership to 0)."""
        if isinstance(e, Prop):
            text = names[(e.var, e.term)]
            referenced.add(text)
            for h in reversed(e.hedges):
                hedges.add(h)
                text = f"hedge_{h}({text})"
            return f"(1.0 - {text})" if e.negated != negate else text
        if isinstance(e, Not):
            return expr(e.expr, not negate)
        fn = "tnorm" if isinstance(e, And) else "snorm"
        parts = [expr(i) for i in e.items]
        if len(parts) > 1:
            used.add(fn)
        acc = parts[0]
        for p in parts[1:]:
            acc = f"{fn}({acc}, {p})"
        return f"(1.0 - {acc})" if negate else acc

    for j in compiled.hedged_outputs:         # hedged Takagi-Sugeno consequents
        hedges.update(h for row in compiled.cons_hedges for h in row[j])
    rules = []
    for r, (_, rule, uses) in enumerate(flatten(compiled.rulebase, compiled.behavior)):
        text = expr(rule.antecedent)
        for use in uses:
            if use.condition is not None:
                text = f"{text} * {expr(use.condition)}"
        rules.append((f"dof_{r}", text, float(compiled.weight[r])))
    terms = []
    for i, key in enumerate(compiled.term_names):
        term = compiled.variables[key[0]].term(key[1])
        if names[key] in referenced:
            if term.formula is not None:
                raise FormatError(f"term `{key[0]}.{key[1]}`: `mitos export` has no code for "
                                  f"formula terms (`{term.formula.text}`)", span=term.span)
            kernel = kernel_params(term.corners) if term.corners is not None else None
            params = finite_binary(term.params) if term.shape == "binary" else term.params
            terms.append((int(compiled.term_var[i]), names[key], term.shape, params, kernel))
    shapes = {t[2] for t in terms if t[4] is None}
    if any(t[4] is not None for t in terms):
        used.add("kernel")
    return Program(compiled, tuple(terms), tuple(rules), tuple(sorted(shapes)),
                   tuple(sorted(hedges)), tuple(sorted(used)))


def weighted_sums(c: CompiledRuleBase, j: int, lang: str = "c") -> tuple[list[str], str, str]:
    """Output ``j``'s weighted sums as expressions over ``dof_<r>`` and ``x[i]``, the same
    text in C and in Python: ``sum(dof * y)`` (``y`` crisp or linear) and ``sum(dof)``, each
    ``dof`` hedged where the consequent is; under an ``accumulation`` S-norm one term per
    value, its weight ``accumulate(...)`` of the rules concluding it, in rule order. First,
    the statements (in ``lang``, ``c`` or ``python``) that join the values of different
    linear functions where they meet, as the engine does (:func:`_meeting_values`)."""
    terms = _weighted_terms(c, j)
    statements: list[str] = []
    if c.accumulated is not None and c.cons_linear is not None and len(terms) > 1:
        statements, terms = _meeting_values(terms, lang)
    numerator = " + ".join(f"{d} * {v}" for d, v in terms) or "0.0"
    denominator = " + ".join(d for d, _ in terms) or "0.0"
    return statements, numerator, denominator


def _meeting_values(terms: list[tuple[str, str]], lang: str) -> tuple[list[str], list]:
    """Each value's weight and value as a variable, then, for every pair ``h < g`` in order,
    ``g`` takes in ``h``'s weight where their values are equal (the same sign of zero too),
    which is the engine's fold of a run of equal values into its last member
    (``evaluation._join_equal_values``; ``accumulate(0, w)`` is ``w``)."""
    out = []
    for g, (w, v) in enumerate(terms):
        if lang == "c":
            out += [f"double w{g} = {w};", f"double v{g} = {v};"]
        else:
            out += [f"w{g} = {w} + np.zeros(X.shape[0])", f"v{g} = {v} + np.zeros(X.shape[0])"]
    for g in range(1, len(terms)):
        for h in range(g):
            if lang == "c":
                out.append(f"if (v{h} == v{g} && !signbit(v{h}) == !signbit(v{g})) "
                           f"{{ w{g} = accumulate(w{h}, w{g}); w{h} = 0.0; }}")
            else:
                out += [f"same = (v{h} == v{g}) & (np.signbit(v{h}) == np.signbit(v{g}))",
                        f"w{g} = np.where(same, accumulate(w{h}, w{g}), w{g})",
                        f"w{h} = np.where(same, 0.0, w{h})"]
    return out, [(f"w{g}", f"v{g}") for g in range(len(terms))]


def _weighted_terms(c: CompiledRuleBase, j: int) -> list[tuple[str, str]]:
    """``(weight, value)`` expressions of output ``j``: per rule, or per value under an
    ``accumulation`` S-norm."""
    terms = []
    for r in np.flatnonzero(c.cons_mask[:, j]):
        value = num(c.cons_value[r, j])
        if c.cons_linear is not None:
            parts = [num(c.cons_linear[r, j, -1])] + [
                f"{num(a)} * x[{i}]" for i, a in enumerate(c.cons_linear[r, j, :-1])
                if a != 0.0]
            value = "(" + " + ".join(parts) + ")"
        dof = f"dof_{r}"
        if j in c.hedged_outputs:             # the hedge weights the rule (evaluation.py)
            for h in reversed(c.cons_hedges[r][j]):
                dof = f"hedge_{h}({dof})"
            if "any" in c.cons_hedges[r][j]:  # 1 at a DOF of 0: only a rule that fires counts
                dof = f"(dof_{r} > 0.0) * {dof}"
        terms.append((dof, value))
    if c.accumulated is not None:             # one weight per value: the S-norm of its rules
        terms = _accumulated(c.accumulated[j], terms, np.flatnonzero(c.cons_mask[:, j]))
    return terms


def _accumulated(acc: Accumulation, terms: list[tuple[str, str]], rules: np.ndarray) -> list[tuple[str, str]]:
    """``terms`` (per rule setting the output, in ``rules`` order) joined per group of
    :class:`~mitos_cli.engine.compile.Accumulation`: ``accumulate(accumulate(d1, d2), d3)``."""
    at = {int(r): i for i, r in enumerate(rules)}
    weights = {int(g): terms[at[int(r)]][0] for g, r in enumerate(acc.first)}
    for groups, members in acc.steps:
        for g, r in zip(groups.tolist(), members.tolist()):
            weights[g] = f"accumulate({weights[g]}, {terms[at[r]][0]})"
    return [(weights[g], terms[at[int(r)]][1]) for g, r in enumerate(acc.first)]
