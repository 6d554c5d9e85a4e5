"""The rule-base model: what a rule file means, as frozen dataclasses.

The parser produces these with names as written; :func:`mitos_cli.lang.resolve.build_rulebase`
checks every name against the term sets (with "did you mean") before a :class:`RuleBase` is
returned, so everything downstream may trust them. :func:`format_rule` writes a rule back in
the rule language (``parse(format_rule(r)) == r``).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

from ..errors import Span
from .terms import TermSet, Variable


@dataclass(frozen=True)
class Prop:
    """``var is [not] [hedge ...] TERM``: a membership, hedged then possibly negated."""

    var: str
    term: str
    hedges: tuple[str, ...] = ()
    negated: bool = False
    span: Span | None = field(default=None, compare=False)


@dataclass(frozen=True)
class Not:
    """``not (expr)``: the inhibitory input of eqs. 8-9, ``1 - x``."""

    expr: Expr
    span: Span | None = field(default=None, compare=False)


@dataclass(frozen=True)
class And:
    items: tuple[Expr, ...]
    span: Span | None = field(default=None, compare=False)


@dataclass(frozen=True)
class Or:
    items: tuple[Expr, ...]
    span: Span | None = field(default=None, compare=False)


Expr = Prop | Not | And | Or


@dataclass(frozen=True)
class Consequent:
    """``var is TERM`` (with optional hedges) or ``var is 70`` (a crisp value)."""

    var: str
    term: str | None = None
    value: float | None = None
    hedges: tuple[str, ...] = ()
    span: Span | None = field(default=None, compare=False)


@dataclass(frozen=True)
class Rule:
    label: str
    antecedent: Expr
    consequents: tuple[Consequent, ...]
    weight: float = 1.0
    span: Span | None = field(default=None, compare=False)
    weight_span: Span | None = field(default=None, compare=False, repr=False)   # `with W`


@dataclass(frozen=True)
class Use:
    """``use BEHAVIOR [when CONDITION] [with W]``: fuzzy behavior blending."""

    behavior: str
    condition: Expr | None = None
    weight: float = 1.0
    span: Span | None = field(default=None, compare=False)
    weight_span: Span | None = field(default=None, compare=False, repr=False)   # `with W`


@dataclass(frozen=True)
class Setting:
    """``key = value`` in an ``operators:`` line."""

    key: str
    value: str
    span: Span | None = field(default=None, compare=False)


@dataclass(frozen=True)
class Behavior:
    """A named group of rules (the paper's learned repertoire, recalled by name)."""

    name: str
    rules: tuple[Rule, ...] = ()
    uses: tuple[Use, ...] = ()
    operators: tuple[Setting, ...] = ()
    frozen: tuple[str, ...] = ()
    span: Span | None = field(default=None, compare=False)
    frozen_spans: tuple[Span | None, ...] = field(default=(), compare=False, repr=False)
    # where each of ``frozen`` is written (empty for a behavior not read from a file)


@dataclass(frozen=True)
class RuleBase:
    """A whole rule file: its term sets, file-level operators and behaviors.

    The default behavior is the first one in the file (top-level rules form a behavior named
    ``main``, which stands where the first of them, or of their ``use`` lines, is written).
    """

    path: str | None
    termsets: tuple[TermSet, ...]
    behaviors: tuple[Behavior, ...]
    operators: tuple[Setting, ...] = ()
    termset_paths: tuple[str, ...] = ()
    #: What a reader of a foreign format changed to make the file fit (``file:line:col: ...``:
    #: a renamed duplicate, a derived range); the CLI prints them as warnings.
    notes: tuple[str, ...] = field(default=(), compare=False)
    #: What a foreign file sets that MITOS's reading of it does not use, kept for the engines
    #: that do (a Sugeno ``.fis`` file's ``AggMethod``, as the file spells it, with its
    #: place: MATLAB ignores it, Octave's toolkit does not, ``--fidelity octave``).
    unused: tuple[Setting, ...] = field(default=(), compare=False)

    def __repr__(self) -> str:   # the generated one spells out every rule and term
        rules = sum(len(b.rules) for b in self.behaviors)
        return (f"<RuleBase {self.path or '(text)'}: {len(self.behaviors)} behaviors "
                f"({', '.join(b.name for b in self.behaviors)}), {rules} rules, "
                f"{len(self.variables)} variables>")

    @property
    def variables(self) -> dict[str, Variable]:
        return {v.name: v for ts in self.termsets for v in ts.variables}

    @property
    def default_behavior(self) -> str:
        return self.behaviors[0].name

    @functools.cached_property
    def _by_name(self) -> dict[str, Behavior]:
        """The behaviors by name, the first of a name (built once: a lookup per behavior by
        walking them all made a file of N behaviors N^2 to read)."""
        by_name: dict[str, Behavior] = {}
        for b in self.behaviors:
            by_name.setdefault(b.name, b)
        return by_name

    def behavior(self, name: str | None = None) -> Behavior:
        from ..errors import unknown

        name = name or self.default_behavior
        found = self._by_name.get(name)
        if found is not None:
            return found
        raise unknown("behavior", name, [b.name for b in self.behaviors])


def format_expr(expr: Expr, parent: str = "or") -> str:
    """``expr`` in the rule language, with parentheses only where precedence needs them."""
    if isinstance(expr, Prop):
        words = (["not"] if expr.negated else []) + list(expr.hedges) + [expr.term]
        return f"{expr.var} is {' '.join(words)}"
    if isinstance(expr, Not):
        inner = format_expr(expr.expr, "not")
        return f"not {inner}"
    op = "and" if isinstance(expr, And) else "or"
    text = f" {op} ".join(format_expr(item, op) for item in expr.items)
    needs = (parent == "and" and op == "or") or parent == "not"
    return f"({text})" if needs else text


def format_number(value: float) -> str:
    """A number as short as it round-trips: 70, 0.8, 33.333333333333336."""
    return repr(int(value)) if float(value).is_integer() and abs(value) < 1e15 else repr(value)


def format_consequent(c: Consequent) -> str:
    if c.term is None:
        assert c.value is not None  # a consequent names a term or a crisp value, never neither
        return f"{c.var} is {format_number(c.value)}"
    return f"{c.var} is {' '.join(list(c.hedges) + [c.term])}"


def format_rule(rule: Rule, label: bool = True) -> str:
    """One rule in the rule language, on one line."""
    head = f"{rule.label}: " if label and rule.label else ""
    text = (f"{head}if {format_expr(rule.antecedent)} then "
            + " and ".join(format_consequent(c) for c in rule.consequents))
    if rule.weight != 1.0:
        text += f" with {format_number(rule.weight)}"
    return text


def format_use(use: Use) -> str:
    text = f"use {use.behavior}"
    if use.condition is not None:
        text += f" when {format_expr(use.condition)}"
    if use.weight != 1.0:
        text += f" with {format_number(use.weight)}"
    return text


def flatten(rb: RuleBase, name: str | None = None) -> list[tuple[str, Rule, tuple[Use, ...]]]:
    """The rules a behavior evaluates: its own and those of the behaviors it uses.

    Each comes with its display label (``avoid_obstacle/r4`` for used behaviors) and the
    chain of ``use`` contexts that weight it.
    """
    out: list[tuple[str, Rule, tuple[Use, ...]]] = []

    def walk(bname: str, prefix: str, contexts: tuple[Use, ...]) -> None:
        b = rb.behavior(bname)
        for i, rule in enumerate(b.rules):
            label = rule.label or f"#{i + 1}"
            out.append((prefix + label, rule, contexts))
        for use in b.uses:
            walk(use.behavior, prefix + use.behavior + "/", contexts + (use,))

    walk(name or rb.default_behavior, "", ())
    return out
