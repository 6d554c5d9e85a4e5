"""The degree-of-fulfilment trace of one evaluation, as the paper's sample run prints it.

A :class:`Trace` is plain data (inputs with their memberships, the rules that fired with their
DOFs, the crisp outputs); :meth:`Trace.render` writes it for people and :meth:`Trace.to_json`
for machines (the ``mitos eval --json`` contract).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..numbers import exact, whole_number
from ..resources import display_path
from ..words import plural, with_unit
from .evaluation import Result, declares_nan

#: the decimals :meth:`Trace.render` gives, as ``mitos eval --digits`` allows them
DIGITS = (0, 12)

#: From this magnitude the trace shows a number as ``1.69158e+148``: a float's 17 digits end
#: there, and the fixed form's further digits say nothing.
LONG = 1e15


@dataclass(frozen=True)
class InputTrace:
    name: str
    value: float
    unit: str
    memberships: tuple[tuple[str, float], ...]
    clamped: bool = False
    #: the value as given, before clamping (``value`` is what the rules saw); ``None`` when
    #: the trace was made without it
    given: float | None = None


@dataclass(frozen=True)
class RuleTrace:
    label: str
    text: str
    dof: float


@dataclass(frozen=True)
class Trace:
    rulebase: str
    behavior: str
    operators: str
    n_rules: int
    inputs: tuple[InputTrace, ...]
    rules: tuple[RuleTrace, ...]          # fired rules only, in rule-base order
    outputs: tuple[tuple[str, float, str], ...]
    defaulted: tuple[str, ...] = ()       # outputs no rule set: their `default` applies
    #: of ``defaulted``, those whose rules fire but give them no value (a Mamdani set 0 at
    #: every sample, Tsukamoto inverses at +inf and -inf): their `default` applies too
    unvalued: tuple[str, ...] = ()
    #: of ``defaulted``, those whose NaN there stands for what an engine does (``eval
    #: --fidelity octave``: "Octave gives NaN" where MATLAB gives the middle of the range)
    engine_nan: tuple[tuple[str, str], ...] = ()

    def __repr__(self) -> str:
        """A line: the behavior, the inputs as given, the outputs and how many rules fired
        (the generated one was 2,000-2,700 characters of nested dataclasses);
        ``print(trace.render())`` shows the trace, and a notebook shows it itself."""
        given = ", ".join(f"{i.name}={i.value if i.given is None else i.given:g}"
                          for i in self.inputs[:4]) + (", ..." if len(self.inputs) > 4 else "")
        outputs = ", ".join(f"{name} {with_unit(f'{value:.4g}', unit)}".rstrip()
                            for name, value, unit in self.outputs)
        return (f"<Trace of {self.behavior!r} at {given}: {outputs}; {len(self.rules)} of "
                f"{plural(self.n_rules, 'rule')} fired>")

    def _repr_html_(self) -> str:
        """A notebook shows the trace as the terminal does."""
        import html

        return f"<pre>{html.escape(self.render())}</pre>"

    def to_json(self) -> dict:
        return {
            "rulebase": self.rulebase,
            "behavior": self.behavior,
            "operators": self.operators,
            "inputs": {i.name: {"value": i.value,
                                "given": i.value if i.given is None else i.given,
                                "clamped": i.clamped, "memberships": dict(i.memberships)}
                       for i in self.inputs},
            "rules": [{"label": r.label, "text": r.text, "dof": r.dof} for r in self.rules],
            "outputs": {name: value for name, value, _ in self.outputs},
            # the outputs that no rule sets here, each its `default` (the text trace says
            # "its default: no rule sets it here"); added in 0.2, empty when rules set all
            "defaulted": list(self.defaulted),
        }

    def render(self, digits: int = 1) -> str:
        """The paper's layout: fuzzified inputs, fired rules with DOFs, crisp outputs."""
        digits = _digits(digits)

        def num(x: float) -> str:
            if abs(x) >= LONG:                  # not 150 digits, most of them noise
                return f"{x:.{max(digits, 6)}g}"
            text = f"{x:.{digits}f}"
            if x != 0 and float(text) == 0:     # a rule that fired, if only a little
                text = f"{x:.{max(digits, 1)}g}"
            return text

        lines = [f"rule base {self.rulebase}, behavior {self.behavior} "
                 f"({plural(self.n_rules, 'rule')}; {self.operators})", "", "fuzzified inputs:"]
        fuzzified = []
        for i in self.inputs:
            # every term above 0, as every rule above 0: a term the digits round to 0 is one
            # the fired rules may read (`CENTER/0.04` beside `RIGHT/1.0`)
            shown = [f"{t}/{num(mu)}" for t, mu in i.memberships if mu > 0]
            fuzzified.append(f"{i.name} = ({', '.join(shown)})")
        width = max(len(f) for f in fuzzified) if fuzzified else 0
        for text, i in zip(fuzzified, self.inputs):
            note = "" if not i.clamped else " (clamped to its universe)" if i.given is None \
                else f" (given {exact(i.given)}, clamped to its universe)"
            lines.append(f"  {text.ljust(width)}   {i.name} = "
                         f"{with_unit(f'{i.value:g}', i.unit)}".rstrip() + note)
        lines += ["", f"rules fired ({len(self.rules)} of {self.n_rules}):"]
        for r in self.rules:
            lines.append(f"  {r.label}: {r.text}, DOF = {num(r.dof)}")
        if not self.rules:
            lines.append("  (none)")
        lines += ["", "outputs:"]
        engines = dict(self.engine_nan)
        for name, value, unit in self.outputs:
            why = ("the rules that fire give it no value here" if name in self.unvalued
                   else "no rule sets it here")
            note = "" if name not in self.defaulted else \
                f"   ({why}; {engines[name]})" if name in engines else \
                f"   (its default: {why})"
            lines.append(f"  {name} = {with_unit(num(value), unit)}".rstrip() + note)
        return "\n".join(lines)


def _digits(value: object) -> int:
    """``value`` as a number of decimals, else an :class:`InputError` (-1 and ``True`` met
    "Format specifier missing precision", 1.5 a TypeError, and 99 was taken)."""
    n = whole_number(value)
    if n is None or not DIGITS[0] <= n <= DIGITS[1]:
        raise InputError(f"digits is a whole number from {DIGITS[0]} to {DIGITS[1]} "
                         f"(as `mitos eval --digits`), not `{value!r:.40}`")
    return n


def trace_of(result: Result, row: int = 0, given: np.ndarray | None = None) -> Trace:
    """The trace of sample ``row`` of an evaluation; ``given``, the ``X[n, k]`` it was given,
    keeps the value of an input that was clamped."""
    if result.memberships is None or result.dof is None:
        raise ValueError("a trace needs the memberships and DOFs: evaluate(..., detail=True)")
    c = result.compiled
    inputs = []
    t = 0
    for k, name in enumerate(c.inputs):
        var = c.variables[name]
        mus = []
        for term in var.terms:
            mus.append((term.name, float(result.memberships[row, t])))
            t += 1
        lo, hi = var.universe
        value = float(result.inputs[row, k])
        original = None if given is None else float(given[row, k])
        clamped = bool(result.clamped[k]) and value in (lo, hi) and (
            original is None or original != value)
        inputs.append(InputTrace(name, value, var.unit, tuple(mus), clamped, original))
    rules = tuple(RuleTrace(c.labels[r], c.rule_text(r), float(result.dof[row, r]))
                  for r in range(c.n_rules) if result.dof[row, r] > 0)
    outputs = tuple((name, float(result.outputs[row, j]), c.variables[name].unit)
                    for j, name in enumerate(c.outputs))
    fired = result.dof[row] > 0
    declared = [not np.isnan(c.default[j]) or declares_nan(c, name)
                for j, name in enumerate(c.outputs)]
    # rules that fire may give an output no value too (NaN before the default): its value is
    # the default all the same (a Tsukamoto output of +inf and -inf printed the default as
    # the rules' value, and `--json` listed it as set)
    unvalued = tuple(name for j, name in enumerate(c.outputs)
                     if declared[j] and fired[c.cons_mask[:, j]].any()
                     and result.no_rule is not None and bool(result.no_rule[row, j]))
    defaulted = tuple(name for j, name in enumerate(c.outputs)
                      if declared[j] and (not fired[c.cons_mask[:, j]].any() or name in unvalued))
    path = display_path(c.rulebase.path)
    return Trace(path, c.behavior, c.describe_operators(), c.n_rules, tuple(inputs), rules,
                 outputs, defaulted, unvalued)
