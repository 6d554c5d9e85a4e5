"""What the three foreign formats share: name tables, term construction, assembling a RuleBase.

Every reader turns its file into MITOS's own model (:class:`~mitos_cli.lang.model.RuleBase` with one
term set and one behavior ``main``), so ``eval``, ``check``, ``simulate`` and ``teach`` never
know where a rule base came from. The tables below are the single place where a foreign name
(``AlgebraicProduct``, ``prod``, ``PROD``) meets MITOS's (``product``); writers use them in the
other direction. Anything a format names that MITOS cannot compute exactly is refused with a
:class:`~mitos_cli.errors.FormatError` at ``file:line`` naming the construct.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from ..lang import operators as ops_mod
from ..lang.resolve import MAIN, check_rule
from ..errors import FormatError, MitosError, Span, did_you_mean
from ..lang.model import And, Behavior, Consequent, Expr, Not, Or, Prop, Rule, RuleBase, Setting
from ..fuzzy.shapes import SHAPES
from ..lang.terms import Term, TermSet, Variable
from ..words import plural

# ---------------------------------------------------------------------------------------------
# Operators: MITOS name -> (FLL, FIS, FCL). None = the format has no name for it.

TNORMS = {
    "min": ("Minimum", "min", "MIN"),
    "product": ("AlgebraicProduct", "prod", "PROD"),
    "lukasiewicz": ("BoundedDifference", None, "BDIF"),
    "drastic": ("DrasticProduct", None, "DPROD"),
    "einstein": ("EinsteinProduct", None, "EPROD"),
    "hamacher": ("HamacherProduct", None, "HPROD"),
    "nilpotent_minimum": ("NilpotentMinimum", None, "NMIN"),
}
SNORMS = {
    "max": ("Maximum", "max", "MAX"),
    "probabilistic_sum": ("AlgebraicSum", "probor", "ASUM"),
    "bounded_sum": ("BoundedSum", None, "BSUM"),
    "drastic_sum": ("DrasticSum", None, "DSUM"),
    "einstein_sum": ("EinsteinSum", None, "ESUM"),
    "hamacher_sum": ("HamacherSum", None, "HSUM"),
    "nilpotent_maximum": ("NilpotentMaximum", None, "NMAX"),
}
#: Defuzzifiers of Mamdani inference; the two weighted ones are MITOS inferences.
DEFUZZIFIERS = {
    "centroid": ("Centroid", "centroid", "COG"),
    "bisector": ("Bisector", "bisector", "COA"),
    "mom": ("MeanOfMaximum", "mom", "MM"),
    "som": ("SmallestOfMaximum", "som", "LM"),
    "lom": ("LargestOfMaximum", "lom", "RM"),
    "weighted_average": ("WeightedAverage", "wtaver", "COGS"),
    "weighted_sum": ("WeightedSum", "wtsum", "COGSS"),
}
#: Extra spellings readers accept (older fuzzylite, jFuzzyLogic), upper-cased for FCL.
FCL_ALIASES = {"BIS": "bisector", "MOM": "mom", "SOM": "som", "LOM": "lom",
               "ALGEBRAIC_PRODUCT": "product", "PROBOR": "probabilistic_sum",
               "DMIN": "drastic", "DMAX": "drastic_sum", "NIPMIN": "nilpotent_minimum",
               "NIPMAX": "nilpotent_maximum", "EINSTEIN": "einstein", "HAMACHER": "hamacher"}
#: Names formats use for operators MITOS does not have (refused with this explanation).
UNSUPPORTED_NORMS = {
    "NormalizedSum": "the normalized sum is not an S-norm MITOS computes",
    "UnboundedSum": "the unbounded sum is not an S-norm MITOS computes",
    "NSUM": "the normalized sum is not an S-norm MITOS computes",
    "UNSUM": "the unbounded sum is not an S-norm MITOS computes",
    "SUM": "the unbounded sum is not an S-norm MITOS computes",
    "sum": "MATLAB's `sum` aggregation (unbounded) is not an S-norm MITOS computes",
    "COGF": "jFuzzyLogic's fast centre of gravity (a coarser integration) is not supported; "
            "COG is the exact one",
}

FLL, FIS, FCL = 0, 1, 2
FORMAT_NAMES = ("FLL", "FIS", "FCL")


def table_lookup(table: dict, fmt: int, name: str, what: str, span: Span | None,
                 case: bool = True) -> str:
    """MITOS's name for ``name`` in column ``fmt`` of ``table``, else a FormatError."""
    for mitos, names in table.items():
        foreign = names[fmt]
        if foreign is not None and (foreign == name if case else foreign.upper() == name.upper()):
            return mitos
    if fmt == FCL and name.upper() in FCL_ALIASES and FCL_ALIASES[name.upper()] in table:
        return FCL_ALIASES[name.upper()]
    pool = [n[fmt] for n in table.values() if n[fmt] is not None]
    why = UNSUPPORTED_NORMS.get(name) or (UNSUPPORTED_NORMS.get(name.upper()) if fmt == FCL
                                          else None)
    if why:
        raise FormatError(f"{what} `{name}` is not supported: {why}", span=span,
                          expected="one of " + ", ".join(pool))
    raise FormatError(f"unknown {what} `{name}`", span=span, expected="one of " + ", ".join(pool),
                      hint=did_you_mean(name, pool))


def foreign_name(table: dict, fmt: int, mitos: str, what: str) -> str:
    """The format's name for MITOS's operator ``mitos`` (writers), else a FormatError."""
    names = table.get(mitos)
    if names is None or names[fmt] is None:
        raise FormatError(f"{FORMAT_NAMES[fmt]} has no {what} `{mitos}`",
                          hint="choose another operator in the rule file's `operators:` line")
    return names[fmt]


# ---------------------------------------------------------------------------------------------
# Hedges: fuzzylite's names (FLL and its FCL dialect) -> MITOS's.

FUZZYLITE_HEDGES = {"very": "very", "somewhat": "somewhat", "seldom": "seldom",
                    "extremely": "intensely", "any": "any"}
MITOS_TO_FUZZYLITE_HEDGES = {v: k for k, v in FUZZYLITE_HEDGES.items()}
MITOS_TO_FUZZYLITE_HEDGES["more_or_less"] = "somewhat"      # the same function, sqrt(x)


def fuzzylite_hedge(name: str, span: Span | None) -> str:
    if name in FUZZYLITE_HEDGES:
        return FUZZYLITE_HEDGES[name]
    raise FormatError(f"unknown hedge `{name}`", span=span,
                      expected="one of " + ", ".join(FUZZYLITE_HEDGES),
                      hint=did_you_mean(name, FUZZYLITE_HEDGES))


def to_fuzzylite_hedge(name: str) -> str:
    if name not in MITOS_TO_FUZZYLITE_HEDGES:
        raise FormatError(f"fuzzylite has no hedge like MITOS's `{name}` (x^3)",
                          hint="use `very` (x^2) or `intensely` (fuzzylite's `extremely`)")
    return MITOS_TO_FUZZYLITE_HEDGES[name]


# ---------------------------------------------------------------------------------------------
# Terms: one table of fuzzylite names (FLL and fuzzylite's FCL dialect), params in MITOS order.

#: fuzzylite class -> (MITOS shape, number of params or None = pairs)
FUZZYLITE_SHAPES = {
    "Triangle": ("triangle", 3), "Trapezoid": ("trapezoid", 4), "Rectangle": ("rectangle", 2),
    "Gaussian": ("gaussian", 2), "GaussianProduct": ("gaussian2", 4), "Bell": ("bell", 3),
    "Sigmoid": ("sigmoid", 2), "SigmoidDifference": ("sigmoid_difference", 4),
    "SigmoidProduct": ("sigmoid_product", 4), "PiShape": ("pi_shape", 4),
    "SShape": ("s_shape", 2), "ZShape": ("z_shape", 2), "Ramp": ("ramp", 2),
    "Cosine": ("cosine", 2), "Spike": ("spike", 2), "Concave": ("concave", 2),
    "Arc": ("arc", 2), "Binary": ("binary", 2), "SemiEllipse": ("semi_ellipse", 2),
    "Discrete": ("discrete", None), "Constant": ("singleton", 1), "Linear": ("linear", None),
}
MITOS_TO_FUZZYLITE_SHAPES = {v[0]: k for k, v in FUZZYLITE_SHAPES.items()}
MITOS_TO_FUZZYLITE_SHAPES.update({"left_shoulder": "Trapezoid", "right_shoulder": "Trapezoid",
                                  "triangle_pw": "Triangle", "triangle_plr": "Triangle"})
FORMULA_TERMS = {"Function": "a free formula"}


def number(text: str, span: Span | None, what: str = "a number") -> float:
    """A number as the formats write them (``nan``, ``inf``, ``-inf`` included)."""
    try:
        return float(text)
    except ValueError:
        raise FormatError(f"expected {what}, not `{text}`", span=span) from None


def fuzzylite_term(name: str, kind: str, values: list[float], n_inputs: int,
                   span: Span | None) -> Term:
    """A term from fuzzylite's ``NAME Kind p1 p2 ... [height]``."""
    if kind in FORMULA_TERMS:
        raise FormatError(f"term `{name}`: `{kind}` terms ({FORMULA_TERMS[kind]}) are not "
                          f"supported", span=span,
                          hint="replace it by one of the shapes: " + ", ".join(FUZZYLITE_SHAPES))
    if kind not in FUZZYLITE_SHAPES:
        raise FormatError(f"term `{name}`: unknown term type `{kind}`", span=span,
                          expected="one of " + ", ".join(FUZZYLITE_SHAPES),
                          hint=did_you_mean(kind, FUZZYLITE_SHAPES))
    shape, count = FUZZYLITE_SHAPES[kind]
    height = 1.0
    if shape == "linear":
        if len(values) != n_inputs + 1:
            raise FormatError(f"term `{name}`: Linear takes one coefficient per input variable "
                              f"({n_inputs}) and a constant, not {plural(len(values), 'number')}",
                              span=span)
    elif count is None:                       # Discrete: pairs, then an optional height
        if len(values) % 2:
            height = values.pop()
    elif len(values) == count + 1:
        height = values.pop()
    elif len(values) != count:
        raise FormatError(f"term `{name}`: {kind} takes {plural(count, 'number')}, "
                          f"not {len(values)}",
                          span=span, expected=", ".join(SHAPES[shape].params))
    if height != 1.0:
        raise FormatError(f"term `{name}`: a term height ({height:g}) other than 1 is not "
                          f"supported", span=span,
                          hint="MITOS terms reach 1; scale the rule weights instead")
    if shape == "rectangle":            # fuzzylite takes the ends in either order
        values = sorted(values)
    return make_term(name, shape, tuple(values), span)


def make_term(name: str, shape: str, params: tuple[float, ...], span: Span | None) -> Term:
    problem = SHAPES[shape].check(params)
    if problem:
        raise FormatError(f"term `{name}`: {problem}", span=span)
    return Term(name, shape, tuple(float(p) for p in params), span)


def fuzzylite_term_text(term: Term, variable: str) -> str:
    """``Kind p1 p2 ...`` for a MITOS term (FLL and fuzzylite's FCL)."""
    shape, p = term.shape, term.params
    if shape in ("left_shoulder", "right_shoulder", "triangle_pw", "triangle_plr"):
        a, b, c, d = term.corners
        return "Trapezoid " + " ".join(fmt_number(v) for v in (a, b, c, d)) if shape in (
            "left_shoulder", "right_shoulder") else "Triangle " + " ".join(
            fmt_number(v) for v in (a, b, d))
    if shape not in MITOS_TO_FUZZYLITE_SHAPES:
        raise FormatError(f"term `{variable}.{term.name}`: fuzzylite has no `{shape}` term")
    return MITOS_TO_FUZZYLITE_SHAPES[shape] + " " + " ".join(fmt_number(v) for v in p)


def fmt_number(value: float) -> str:
    """Shortest text that reads back to the same float (``nan``, ``inf``, ``-inf``)."""
    value = float(value)
    if math.isnan(value):
        return "nan"
    if math.isinf(value):
        return "inf" if value > 0 else "-inf"
    if value.is_integer() and abs(value) < 1e15:
        return str(int(value))
    return repr(value)


# ---------------------------------------------------------------------------------------------
# Settings gathered by a reader, checked and turned into `operators:` settings.


@dataclass
class Settings:
    """The operator choices of a foreign file, with where each was written."""

    and_: str | None = None
    or_: str | None = None
    implication: str | None = None
    aggregation: str | None = None
    defuzzify: str | None = None        # a DEFUZZIFIERS key
    resolution: int | None = None
    sampling: str | None = None         # "endpoints" for MATLAB, else MITOS's midpoints
    spans: dict | None = None

    def set(self, key: str, value: str | int, span: Span | None, what: str) -> None:
        """Set ``key``; a second, different value (another output or block) is refused."""
        if self.spans is None:
            self.spans = {}
        old = getattr(self, key)
        if old is not None and old != value:
            raise FormatError(f"{what} `{value}` differs from `{old}` set at "
                              f"{self.spans.get(key)}: MITOS uses one {what} per rule base",
                              span=span, hint="use the same operator for every output and "
                                              "rule block")
        setattr(self, key, value)
        self.spans.setdefault(key, span)

    def operators(self, default_resolution: int) -> tuple[Setting, ...]:
        out = []
        if self.and_:
            out.append(Setting("and", self.and_))
        if self.or_:
            out.append(Setting("or", self.or_))
        defuzz = self.defuzzify or "centroid"
        if defuzz in ("weighted_average", "weighted_sum"):
            out.append(Setting("inference", defuzz))
        else:
            out.append(Setting("inference", "mamdani"))
            out.append(Setting("implication", self.implication or "min"))
            out.append(Setting("aggregation", self.aggregation or "max"))
            out.append(Setting("defuzzify", defuzz))
            out.append(Setting("resolution", str(self.resolution or default_resolution)))
            if self.sampling:
                out.append(Setting("sampling", self.sampling))
        return tuple(out)

    @property
    def sugeno(self) -> bool:
        return self.defuzzify in ("weighted_average", "weighted_sum")


class Record(list):
    """Operator choices as written, ``(key, value, span, what)``, kept per output and per rule
    block and replayed into a :class:`Settings` once it is known which of them form one
    behavior (see :func:`replay`)."""

    def set(self, key: str, value, span: Span | None, what: str) -> None:
        self.append((key, value, span, what))


def replay(records) -> Settings:
    """One :class:`Settings` from several records; a conflict raises FormatError."""
    settings = Settings()
    for record in records:
        for entry in record:
            settings.set(*entry)
    return settings


def disjoint_outputs(blocks: list[list[Rule]]) -> bool:
    """Whether no output is concluded by two of the rule blocks (then blocks with different
    operators are independent and may become separate behaviors; otherwise their rules feed
    one output together, which one MITOS behavior with one set of operators cannot do)."""
    seen: set[str] = set()
    for rules in blocks:
        mine = {c.var for r in rules for c in r.consequents}
        if mine & seen:
            return False
        seen |= mine
    return True


def check_implication(name: str, span: Span | None) -> str:
    if name not in ops_mod.IMPLICATIONS:
        raise FormatError(f"implication `{name}` is not supported", span=span,
                          expected="one of " + ", ".join(ops_mod.IMPLICATIONS))
    return name


def assemble(path: str, variables: list[Variable], rules: list[Rule], settings: Settings,
             default_resolution: int, span: Span | None = None) -> RuleBase:
    """Check what a reader gathered and return the rule base (one behavior, ``main``)."""
    return assemble_blocks(path, variables, [(MAIN, rules, settings)], default_resolution, span)


def assemble_blocks(path: str, variables: list[Variable],
                    blocks: list[tuple[str, list[Rule], Settings]], default_resolution: int,
                    span: Span | None = None) -> RuleBase:
    """The rule base of one or more rule blocks: one block gives behavior ``main`` with the
    operators on the file; several (whose operators differ) give one behavior each, with its
    own operators, the first being the default."""
    names = [v.name for v in variables]
    for v in variables:
        if names.count(v.name) > 1:
            raise FormatError(f"variable `{v.name}` is defined twice", span=v.span)
    if not any(v.role == "input" for v in variables):
        raise FormatError("the file defines no input variable", span=span)
    if not any(rules for _, rules, _ in blocks):
        raise FormatError("the file has no rules", span=span)
    by_name = {v.name: v for v in variables}
    behaviors = []
    for name, rules, settings in blocks:
        _check_block(rules, settings, by_name, len(blocks) == 1)
        operators = settings.operators(default_resolution)
        try:
            ops_mod.resolve(operators)
        except MitosError as exc:
            raise FormatError(exc.message, span=span, expected=exc.expected,
                              hint=exc.hint) from None
        behaviors.append(Behavior(name, tuple(rules), (), operators))
    termset = TermSet(tuple(variables), path)
    if len(behaviors) == 1:
        b = behaviors[0]
        return RuleBase(path, (termset,), (Behavior(b.name, b.rules),), b.operators)
    return RuleBase(path, (termset,), tuple(behaviors), ())


def _check_block(rules: list[Rule], settings: Settings, by_name: dict[str, Variable],
                 every_output: bool) -> None:
    sugeno = settings.sugeno
    concluded = {c.var for r in rules for c in r.consequents}
    for v in by_name.values():
        if v.role != "output" or not (every_output or v.name in concluded):
            continue
        for t in v.terms:
            if sugeno and t.shape not in ("singleton", "linear"):
                raise FormatError(
                    f"output term `{v.name}.{t.name}`: a weighted-average output needs constant "
                    f"or linear terms; a `{t.shape}` term there is Tsukamoto inference, which "
                    f"MITOS does not support", span=t.span)
            if not sugeno and t.shape == "linear":
                raise FormatError(f"output term `{v.name}.{t.name}`: linear terms need a "
                                  f"weighted-average (Takagi-Sugeno) defuzzifier", span=t.span)
    for rule in rules:
        try:
            check_rule(rule, by_name)
        except MitosError as exc:
            raise FormatError(exc.message, span=exc.span or rule.span, expected=exc.expected,
                              hint=exc.hint) from None
        if sugeno:
            for c in rule.consequents:
                if c.hedges:
                    raise FormatError("hedges on a Takagi-Sugeno consequent are not supported",
                                      span=c.span)


# ---------------------------------------------------------------------------------------------
# Writers' helpers.


@dataclass(frozen=True)
class Flat:
    """A behavior flattened for writing: variables, rules, operators, extra crisp terms."""

    name: str
    inputs: tuple[Variable, ...]
    outputs: tuple[Variable, ...]
    rules: tuple[Rule, ...]
    operators: ops_mod.Operators


def flatten_for_export(rb: RuleBase, behavior: str | None = None, *,
                       crisp_terms: bool = True) -> Flat:
    """One behavior of ``rb`` as a single rule list over its variables.

    ``use`` includes are inlined (a constant ``use`` weight multiplies the rule weights; a
    ``use ... when`` condition has no equivalent in the foreign formats and is refused). With
    ``crisp_terms``, crisp consequents (``speed is 40``) become constant output terms named
    ``crisp_40`` (the formats have no crisp consequents).
    """
    from ..lang.model import flatten

    name = behavior or rb.default_behavior
    b = rb.behavior(name)
    operators = ops_mod.resolve(b.operators, ops_mod.resolve(rb.operators))
    rules = []
    for label, rule, uses in flatten(rb, name):
        w = rule.weight
        for use in uses:
            if use.condition is not None:
                raise FormatError(f"rule `{label}` comes from `use {use.behavior} when ...`: "
                                  f"a conditional include cannot be written in FCL, FIS or FLL",
                                  span=use.span, hint="convert the behavior it is used by alone "
                                                      "(--behavior), or write the condition "
                                                      "into the rules")
            w *= use.weight
        rules.append(Rule(label, rule.antecedent, rule.consequents, w, rule.span))
    variables = rb.variables
    used_in = {p.var for r in rules for p in props(r.antecedent)}
    used_out = {c.var for r in rules for c in r.consequents}
    inputs = tuple(v for v in variables.values() if v.role == "input" and v.name in used_in)
    outputs = [v for v in variables.values() if v.role == "output" and v.name in used_out]
    if crisp_terms:
        extra: dict[str, dict[float, str]] = {}
        new_rules = []
        for r in rules:
            cons = []
            for c in r.consequents:
                if c.term is None:
                    var = variables[c.var]
                    names = extra.setdefault(c.var, {})
                    if c.value not in names:
                        names[c.value] = unique_name(crisp_name(c.value), var.term_names +
                                                     tuple(names.values()))
                    c = Consequent(c.var, names[c.value], None, (), c.span)
                cons.append(c)
            new_rules.append(Rule(r.label, r.antecedent, tuple(cons), r.weight, r.span))
        rules = new_rules
        outputs = [v.with_terms(v.terms + tuple(Term(n, "singleton", (value,))
                                                for value, n in extra.get(v.name, {}).items()))
                   for v in outputs]
    return Flat(name, inputs, tuple(outputs), tuple(rules), operators)


def all_inputs(rb: RuleBase, flat: Flat) -> tuple[Variable, ...]:
    """The inputs a written file needs, in term-set order: those the rules test, and those a
    linear consequent of the rules weighs (its coefficients are rewritten over these)."""
    needed = {v.name for v in flat.inputs}
    for r in flat.rules:
        for c in r.consequents:
            term = rb.variables[c.var].term(c.term) if c.term is not None else None
            if term is not None and term.shape == "linear":
                needed.update(n for n, a in linear_coefficients(rb, c.var, term).items()
                              if a != 0.0)
    return tuple(v for v in rb.variables.values() if v.role == "input" and v.name in needed)


def linear_coefficients(rb: RuleBase, output: str, term: Term) -> dict[str, float]:
    """A ``linear`` term's coefficients by input name (its term set's inputs, in order)."""
    for ts in rb.termsets:
        if any(v.name == output for v in ts.variables):
            names = [v.name for v in ts.variables if v.role == "input"]
            return dict(zip(names, term.params[:-1]))
    return {}


def crisp_name(value: float) -> str:
    text = fmt_number(value).replace("-", "m").replace(".", "_").replace("+", "")
    return f"crisp_{text}"


def unique_name(name: str, taken) -> str:
    taken = set(taken)
    out, i = name, 2
    while out in taken:
        out, i = f"{name}_{i}", i + 1
    return out


def props(expr: Expr):
    """The propositions of an expression, left to right."""
    if isinstance(expr, Prop):
        yield expr
    elif isinstance(expr, Not):
        yield from props(expr.expr)
    else:
        for item in expr.items:
            yield from props(item)


def push_not(expr: Expr, negate: bool = False) -> Expr:
    """``expr`` with every ``not (...)`` pushed onto propositions (De Morgan), for formats whose
    ``not`` applies to a single proposition. Exact only for dual operator pairs; callers check."""
    if isinstance(expr, Prop):
        if not negate:
            return expr
        return Prop(expr.var, expr.term, expr.hedges, not expr.negated, expr.span)
    if isinstance(expr, Not):
        return push_not(expr.expr, not negate)
    items = tuple(push_not(i, negate) for i in expr.items)
    if negate:
        return Or(items, expr.span) if isinstance(expr, And) else And(items, expr.span)
    return type(expr)(items, expr.span)


def can_push_not(operators: ops_mod.Operators) -> bool:
    """Whether De Morgan (``push_not``) is exact: the AND and OR norms are a dual pair."""
    return operators.tnorm.dual == operators.snorm.name


def has_group_not(expr: Expr) -> bool:
    """Whether ``expr`` negates a compound (``not (a and b)``) anywhere, which needs De Morgan
    to be pushed onto propositions (``not (a)`` alone is just a negated proposition)."""
    if isinstance(expr, Not):
        inner = expr.expr
        while isinstance(inner, Not):
            inner = inner.expr
        return not isinstance(inner, Prop)
    if isinstance(expr, Prop):
        return False
    return any(has_group_not(i) for i in expr.items)


def simple_nots(expr: Expr, rule: Rule, ops: ops_mod.Operators) -> Expr:
    """``expr`` with every ``not`` on a proposition: direct for ``not (a)``, by De Morgan for
    groups when the AND and OR norms are duals, else a FormatError."""
    if has_group_not(expr) and not can_push_not(ops):
        raise FormatError(f"rule `{rule.label}`: `not (...)` over a group cannot be written "
                          f"with and = {ops.and_}, or = {ops.or_} (not De Morgan duals)",
                          span=rule.span)
    return push_not(expr)


def atomic_write(path: str | Path, text: str) -> None:
    """Write ``text`` to ``path`` atomically (:func:`mitos_cli.fileio.atomic_write`)."""
    from ..fileio import atomic_write as write

    write(path, text, error=FormatError)

