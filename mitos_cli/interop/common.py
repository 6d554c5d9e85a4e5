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
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import FormatError, MitosError, NoRulesError, Span, did_you_mean
from ..fuzzy import norms as norm_registry
from ..fuzzy.formula import Formula
from ..fuzzy.hedges import HEDGES, fuzzylite_names
from ..fuzzy.shapes import SHAPES, TSUKAMOTO
from ..lang import operators as ops_mod
from ..lang.model import And, Behavior, Consequent, Expr, Not, Or, Prop, Rule, RuleBase, Setting, format_expr
from ..lang.resolve import MAIN, check_rule
from ..lang.terms import Term, TermSet, Variable, first_at, universe_problem
from ..numbers import LARGEST, parse_value
from ..words import plural
from . import rewrite

if TYPE_CHECKING:
    from collections.abc import Iterable, Iterator

# ---------------------------------------------------------------------------------------------
# Operators: MITOS name -> (FLL, FIS, FCL). None = the format has no name for it.

TNORMS = {n.name: (n.fll, n.fis, n.fcl) for n in norm_registry.TNORMS.values()}
SNORMS = {n.name: (n.fll, n.fis, n.fcl) for n in norm_registry.SNORMS.values()}
#: Mamdani aggregations: the S-norms and the unbounded sum (an aggregation only, not for OR).
_SUM = norm_registry.UNBOUNDED_SUM
AGGREGATIONS = {**SNORMS, _SUM.name: (_SUM.fll, _SUM.fis, _SUM.fcl)}
#: Defuzzifiers of Mamdani inference; the two weighted ones are MITOS inferences.
DEFUZZIFIERS = {
    "centroid": ("Centroid", "centroid", "COG"),
    "bisector": ("Bisector", "bisector", "COA"),
    "mom": ("MeanOfMaximum", "mom", "MM"),
    "som": ("SmallestOfMaximum", "som", "LM"),
    "lom": ("LargestOfMaximum", "lom", "RM"),
    # MATLAB's (read from .fis); FLL and FCL get fuzzylite's, and `convert` measures the change
    "matlab_bisector": ("Bisector", "bisector", "COA"),
    "matlab_som": ("SmallestOfMaximum", "som", "LM"),
    "matlab_lom": ("LargestOfMaximum", "lom", "RM"),
    # jFuzzyLogic's COA (``--fidelity jfuzzylogic``); FCL files' COA is read as fuzzylite's
    "jfuzzylogic_bisector": ("Bisector", "bisector", "COA"),
    "weighted_average": ("WeightedAverage", "wtaver", "COGS"),
    "weighted_sum": ("WeightedSum", "wtsum", "COGSS"),
}
#: Extra spellings readers accept (older fuzzylite, jFuzzyLogic), upper-cased for FCL.
FCL_ALIASES = {"BIS": "bisector", "MOM": "mom", "SOM": "som", "LOM": "lom",
               # jFuzzyLogic's centre of gravity of FUNCTION terms: the same weighted average
               # of singletons as its COGS (DefuzzifierCenterOfGravityFunctions)
               "COGF": "weighted_average",
               "ALGEBRAIC_PRODUCT": "product", "PROBOR": "probabilistic_sum",
               "UNSUM": "sum",                  # the unbounded sum's other abbreviation
               "DMIN": "drastic", "DMAX": "drastic_sum", "NIPMIN": "nilpotent_minimum",
               "NIPMAX": "nilpotent_maximum", "EINSTEIN": "einstein", "HAMACHER": "hamacher"}
#: The names Octave's fuzzy-logic-toolkit (and fuzzylite's .fis exporter) give the norms
#: MATLAB has no name for.
FIS_ALIASES = {"algebraic_product": "product", "bounded_difference": "lukasiewicz",
               "drastic_product": "drastic", "einstein_product": "einstein",
               "hamacher_product": "hamacher", "nilpotent_minimum": "nilpotent_minimum",
               "algebraic_sum": "probabilistic_sum", "bounded_sum": "bounded_sum",
               "drastic_sum": "drastic_sum", "einstein_sum": "einstein_sum",
               "hamacher_sum": "hamacher_sum", "nilpotent_maximum": "nilpotent_maximum"}
_ONLY_AGGREGATION = ("the unbounded sum is a Mamdani aggregation only (`aggregation = sum`), "
                     "not an S-norm joining conditions")
#: Names formats use for operators MITOS does not have (refused with this explanation).
UNSUPPORTED_NORMS = {
    "NormalizedSum": "fuzzylite 8's normalized sum, (a + b) / max(1, a + b), is the bounded sum "
                     "exactly, but fuzzylite 6's is a + b / max(1, max(a, b)), which depends on "
                     "the order of the rules past 1, and the file does not say which wrote it; "
                     "write `BoundedSum` for fuzzylite 8's",
    "UnboundedSum": _ONLY_AGGREGATION,
    "NSUM": "jFuzzyLogic's normalized sum is an accumulation (`ACCU : NSUM`, read as the "
            "bounded sum, which it equals), not a connective; write `BSUM`",
    "UNSUM": _ONLY_AGGREGATION,
    "SUM": _ONLY_AGGREGATION,
    "sum": _ONLY_AGGREGATION,
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
    if fmt == FIS and FIS_ALIASES.get(name) in table:
        return FIS_ALIASES[name]
    # (each once: MATLAB's and jFuzzyLogic's bisectors are FCL's `COA` as fuzzylite's is)
    pool = list(dict.fromkeys(n[fmt] for n in table.values() if n[fmt] is not None))
    why = UNSUPPORTED_NORMS.get(name) or (UNSUPPORTED_NORMS.get(name.upper()) if fmt == FCL
                                          else None)
    if why:
        raise FormatError(f"{what} `{name}` is not supported: {why}", span=span,
                          expected="one of " + ", ".join(pool))
    raise FormatError(f"unknown {what} `{name}`", span=span, expected="one of " + ", ".join(pool),
                      hint=did_you_mean(name, pool))


def foreign_name(table: dict, fmt: int, mitos: str, what: str,
                 span: Span | None = None) -> str:
    """The format's name for MITOS's operator ``mitos`` (writers), else a FormatError at
    ``span``, where the rule base chose it (:func:`setting_span`)."""
    names = table.get(mitos)
    if names is None or names[fmt] is None:
        raise FormatError(f"{FORMAT_NAMES[fmt]} has no {what} `{mitos}`", span=span,
                          hint="choose an operator the format has where this one is set")
    return names[fmt]


def setting_span(rb: RuleBase, behavior: str | None, key: str) -> Span | None:
    """Where the operator ``key`` (``and``, ``implication``, ...) that ``behavior`` uses was
    set: the behavior's own ``operators:`` line, else the file's; ``None`` for a default."""
    for settings in (rb.behavior(behavior).operators, rb.operators):
        for s in reversed(settings):
            if s.key == key:
                return s.span
    return None


# ---------------------------------------------------------------------------------------------
# Hedges: fuzzylite's names (FLL and its FCL dialect) -> MITOS's.

FUZZYLITE_HEDGES = fuzzylite_names()                     # fuzzylite's name -> MITOS's
MITOS_TO_FUZZYLITE_HEDGES = {h.name: h.fuzzylite for h in HEDGES.values() if h.fuzzylite}


def fuzzylite_hedge(name: str, span: Span | None) -> str:
    if name in FUZZYLITE_HEDGES:
        return FUZZYLITE_HEDGES[name]
    raise FormatError(f"unknown hedge `{name}`", span=span,
                      expected="one of " + ", ".join(FUZZYLITE_HEDGES),
                      hint=did_you_mean(name, FUZZYLITE_HEDGES))


def to_fuzzylite_hedge(name: str, span: Span | None = None) -> str:
    """fuzzylite's name for hedge ``name``; refused at ``span`` (the proposition or consequent
    using it) when fuzzylite has none."""
    if name not in MITOS_TO_FUZZYLITE_HEDGES:
        raise FormatError(f"fuzzylite has no hedge like MITOS's `{name}` (x^3)", span=span,
                          hint="use `very` (x^2) or `intensely` (fuzzylite's `extremely`)")
    return MITOS_TO_FUZZYLITE_HEDGES[name]


def written_consequents(rule: Rule, inference: str | None = None
                        ) -> list[tuple[Consequent, tuple[str, ...]]]:
    """A rule's consequents as fuzzylite's rule text must list them, each with the hedges to
    write before its term: fuzzylite carries a consequent's hedges on to the ones after it
    (:func:`.ruletree.conclusions`), so less-hedged consequents come first and each writes
    only the hedges it adds. Hedges that cannot be carried that way are refused by name, and
    so is any hedge on a consequent under ``inference`` ``mamdani``: fuzzylite would hedge the
    rule's activation degree where MITOS hedges the output set."""
    hedged = next((c for c in rule.consequents if c.hedges), None)
    if inference == "mamdani" and hedged is not None:
        raise FormatError(f"rule `{rule.label}`: `{hedged_text(hedged)}` hedges a Mamdani "
                          f"consequent's set, which fuzzylite would read as the hedged "
                          f"activation degree of the rule, computing other outputs",
                          span=hedged.span or rule.span,
                          hint="move the hedge onto the condition (`if x is very A`), or give "
                               "the output a term shaped as the hedged one")
    ordered = sorted(rule.consequents, key=lambda c: len(c.hedges))
    out = []
    carried: tuple[str, ...] = ()
    for c in ordered:
        own = len(c.hedges) - len(carried)
        if c.hedges[own:] != carried:
            raise FormatError(f"rule `{rule.label}`: hedges `{' '.join(c.hedges)}` on `{c.var}` "
                              f"and `{' '.join(carried)}` on another consequent cannot be "
                              f"written in fuzzylite's rules, which carry a consequent's hedges "
                              f"on to the consequents after it", span=rule.span,
                              hint="split the rule in two")
        out.append((c, c.hedges[:own]))
        carried = c.hedges
    return out


def hedged_text(c: Consequent) -> str:
    """``y is very lo``: a hedged consequent as messages quote it."""
    return f"{c.var} is {' '.join(c.hedges)} {c.term}"


def concluded_term(c: Consequent) -> str:
    """The output term an exported consequent names (:func:`flatten_for_export` has turned
    crisp values into terms; the formats have no crisp consequents)."""
    if c.term is None:
        raise FormatError(f"`{c.var} is {c.value:g}`: the format has no crisp consequents",
                          span=c.span)
    return c.term


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
    """A number as the formats write them (``nan``, ``inf``, ``-inf`` included); one past a
    float's range (``1e400``) is refused as written, not read as the ``inf`` it was not."""
    try:
        return parse_value(text)
    except OverflowError:
        raise past_range(text, span) from None
    except ValueError:
        raise FormatError(f"expected {what}, not `{text}`", span=span) from None


def past_range(text: str, span: Span | None) -> FormatError:
    """The error of a number written past a float's range, such as ``1e400`` (a long one
    shown by its ends and length)."""
    shown = f"`{text}`" if len(text) <= 24 else f"`{text[:10]}...{text[-6:]}` ({len(text)} characters)"
    return FormatError(f"{shown} is past a float's range: numbers beyond ±{LARGEST:g} cannot "
                       "be evaluated in floating point without overflow", span=span)


def fuzzylite_term(name: str, kind: str, values: list[float], n_inputs: int,
                   span: Span | None) -> Term:
    """A term from fuzzylite's ``NAME Kind p1 p2 ... [height]``."""
    if kind in FORMULA_TERMS:
        raise FormatError(f"term `{name}`: `{kind}` terms ({FORMULA_TERMS[kind]}) are not "
                          f"supported", span=span,
                          hint="replace it by one of the shapes: " + ", ".join(FUZZYLITE_SHAPES))
    if kind not in FUZZYLITE_SHAPES:
        glued = [k for k in FUZZYLITE_SHAPES if name.endswith(k) and len(name) > len(k)]
        hint = did_you_mean(kind, FUZZYLITE_SHAPES) or (
            f"`{name}` is read as the term's name: `{name[:-len(glued[0])]}` and `{glued[0]}` "
            f"are two words" if glued else None)        # `term: lowTriangle 0 1 2`
        raise FormatError(f"term `{name}`: unknown term type `{kind}`", span=span,
                          expected="one of " + ", ".join(FUZZYLITE_SHAPES), hint=hint)
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
    return make_term(name, *shoulder(shape, tuple(values)), span)


def shoulder(shape: str, values: tuple[float, ...]) -> tuple[str, tuple[float, ...]]:
    """A trapezoid with both feet at -inf (or +inf) is the shoulder it draws (``Trapezoid
    -inf -inf c d``, ``trapmf [-inf -inf c d]``): a term set takes shoulders, not infinite
    corners."""
    if shape == "trapezoid" and values[0] == values[1] == -math.inf:
        return "left_shoulder", values[2:]
    if shape == "trapezoid" and values[2] == values[3] == math.inf:
        return "right_shoulder", values[:2]
    return shape, values


def distinct_names(terms: list[Term], variable: str, notes: list[str], why: str,
                   keep_last: bool = False) -> list[Term]:
    """A variable's terms with a repeated name suffixed (``low``, ``low_2``) and a note:
    MITOS names must differ, while a .fis file (rules name MFs by index) and fuzzylite 8
    (whose rules take the last term of a name) allow repeats. ``keep_last`` leaves the name to
    the last of its terms, else to the first."""
    seen: set[str] = set()
    taken = {x.name for x in terms}       # the file's names and each new one (once: per
    tried: dict[str, int] = {}            # repeat, N^2; 20,000 repeats of a .fis MF took 60 s)
    out = []
    order = list(reversed(terms)) if keep_last else list(terms)
    for t in order:
        if t.name in seen:
            new = unique_name(f"{t.name}_2", taken, tried)
            taken.add(new)
            notes.append(f"{t.span}: `{variable}` has more than one term named `{t.name}`; "
                         f"this one is read as `{new}` ({why})")
            t = replace(t, name=new)    # (a new Term lost a formula term's formula: a traceback)
        seen.add(t.name)
        out.append(t)
    return list(reversed(out)) if keep_last else out


def make_term(name: str, shape: str, params: tuple[float, ...], span: Span | None) -> Term:
    problem = SHAPES[shape].check(params)
    if problem:
        raise FormatError(f"term `{name}`: {problem}", span=span)
    return Term(name, shape, tuple(float(p) for p in params), span)


def formula_term(name: str, formula: Formula, span: Span | None) -> Term:
    """fuzzylite's ``Function`` term: a membership given by a formula of ``x``."""
    return Term(name, "formula", (), span, formula=formula)


def fuzzylite_term_text(term: Term, variable: str) -> str:
    """``Kind p1 p2 ...`` for a MITOS term (FLL and fuzzylite's FCL)."""
    shape, p = term.shape, term.params
    if term.formula is not None:
        return f"Function {term.formula.text}"
    if shape in ("left_shoulder", "right_shoulder", "triangle_pw", "triangle_plr"):
        corners = term.corners
        assert corners is not None             # these four shapes are piecewise linear
        a, b, c, d = corners
        return "Trapezoid " + " ".join(fmt_number(v) for v in (a, b, c, d)) if shape in (
            "left_shoulder", "right_shoulder") else "Triangle " + " ".join(
            fmt_number(v) for v in (a, b, d))
    if shape not in MITOS_TO_FUZZYLITE_SHAPES:
        raise FormatError(f"term `{variable}.{term.name}`: fuzzylite has no `{shape}` term",
                          span=term.span)
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
    #: weighted inference's S-norm over the rules of one value (FCL's ACCU under COGS)
    accumulation: str | None = None
    spans: dict | None = None

    def set(self, key: str, value: str | int, span: Span | None, what: str) -> None:
        """Set ``key``; a second, different value (another output or block) is refused."""
        if self.spans is None:
            self.spans = {}
        old = getattr(self, key)
        if old is not None and old != value:
            raise FormatError(f"{what} `{value}` differs from `{old}` set at "
                              f"{self.spans.get(key)}: MITOS uses one {what} per rule base",
                              span=span, hint=_same_hint(key))
        setattr(self, key, value)
        self.spans.setdefault(key, span)

    def operators(self, default_resolution: int) -> tuple[Setting, ...]:
        out = []
        spans = self.spans or {}
        if self.and_:
            out.append(Setting("and", self.and_, spans.get("and_")))
        if self.or_:
            out.append(Setting("or", self.or_, spans.get("or_")))
        defuzz = self.defuzzify or "centroid"
        if defuzz in ("weighted_average", "weighted_sum", "tsukamoto"):
            out.append(Setting("inference", defuzz, spans.get("defuzzify")))
            if self.accumulation and defuzz != "tsukamoto":
                out.append(Setting("accumulation", self.accumulation,
                                   spans.get("aggregation")))
        else:
            out.append(Setting("inference", "mamdani"))
            out.append(Setting("implication", self.implication or "min",
                               spans.get("implication")))
            out.append(Setting("aggregation", self.aggregation or "max",
                               spans.get("aggregation")))
            out.append(Setting("defuzzify", defuzz, spans.get("defuzzify")))
            # the span says the file wrote it (``--fidelity fuzzylite6`` keeps only those)
            out.append(Setting("resolution", str(self.resolution or default_resolution),
                               spans.get("resolution")))
            if self.sampling:
                out.append(Setting("sampling", self.sampling))
        return tuple(out)

    @property
    def sugeno(self) -> bool:
        """Weighted inference (Takagi-Sugeno or Tsukamoto): no Mamdani settings."""
        return self.defuzzify in ("weighted_average", "weighted_sum", "tsukamoto")


def own_resolutions(records: dict[str, Record]) -> dict[str, int]:
    """Each Mamdani output's own resolution, taken out of its ``records`` (the settings its
    format writes per output: fuzzylite's ``defuzzifier: Centroid 200``), where the outputs'
    resolutions are not all one written number; else none, and the one number stays the
    behavior's. An output that writes none is left to the behavior's (the reader's default,
    which ``--fidelity`` may replace: fuzzylite 8 takes 1000 there, fuzzylite 6 100)."""
    mamdani = {n: r for n, r in records.items() if any(
        key == "defuzzify" and value not in ("weighted_average", "weighted_sum", "tsukamoto")
        for key, value, _, _ in r)}
    written = {n: [e for e in r if e[0] == "resolution"] for n, r in mamdani.items()}
    values = {e[1] for entries in written.values() for e in entries}
    if len(values) < 2 and (not values or all(written.values())):
        return {}
    own = {}
    for n, entries in written.items():
        for entry in entries:
            own[n] = entry[1]
            mamdani[n].remove(entry)
    return own


def _same_hint(key: str) -> str:
    """What to do when two outputs or rule blocks set ``key`` differently."""
    if key == "resolution":
        return "give the rule block one resolution (the larger samples finer)"
    if key == "sampling":
        return "give every output the same sampling"
    return "use the same operator for every output and rule block"


class Record(list):
    """Operator choices as written, ``(key, value, span, what)``, kept per output and per rule
    block and replayed into a :class:`Settings` once it is known which of them form one
    behavior (see :func:`replay`)."""

    def set(self, key: str, value: str | int, span: Span | None, what: str) -> None:
        self.append((key, value, span, what))


def replay(records: Iterable[Record]) -> Settings:
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


def rule_blocks(blocks: list[tuple[str, Record, list[Rule]]], outputs: dict[str, Record],
                renumber: bool) -> list[tuple[str, list[Rule], Settings]]:
    """The behaviors of a file's rule blocks (name, operators, rules), with each output's own
    settings in ``outputs``: one, ``main``, holding every rule (numbered ``r1``... through when
    ``renumber``), or, where the blocks' operators conflict and no output is concluded by two
    of them (fuzzylite's hybrid engines), one per block, named after it."""
    rules = [r for _, _, block in blocks for r in block]
    try:
        settings = replay([record for _, record, _ in blocks] + list(outputs.values()))
    except FormatError as conflict:
        if len(blocks) < 2 or not disjoint_outputs([block for _, _, block in blocks]):
            raise conflict
    else:
        if renumber:
            rules = [Rule(f"r{i + 1}", r.antecedent, r.consequents, r.weight, r.span)
                     for i, r in enumerate(rules)]
        return [(MAIN, rules, settings)]
    behaviors = []
    for i, (name, record, block) in enumerate(blocks):
        concluded = {c.var for r in block for c in r.consequents}
        behaviors.append((name or f"block{i + 1}", block,
                          replay([record] + [outputs[n] for n in outputs if n in concluded])))
    return behaviors



#: Where an infinite parameter is meaningful, as (index, sign): the open end of a shoulder
#: (fuzzylite writes ``Trapezoid -inf -inf c d``, ``Triangle -inf b c``) and the direction of
#: a ``Binary`` term (``Binary 0.5 inf``).
INFINITE_OK = {"trapezoid": {(0, -1), (1, -1), (2, 1), (3, 1)},
               "triangle": {(0, -1), (2, 1)}, "binary": {(1, -1), (1, 1)}}


def check_range(lo: float, hi: float, span: Span, what: str = "range",
                point: bool = False) -> None:
    """Refuse, at the range as written, one with a NaN end, one that is empty (a single
    point too, unless ``point``: FLL's unused Takagi-Sugeno range) or too narrow to compute
    with (infinities are refused by :func:`check_numbers`, which knows the terms)."""
    if math.isnan(lo) or math.isnan(hi):
        raise FormatError(f"the {what} is [{lo:g}, {hi:g}]: its ends must be numbers",
                          span=span, hint="write the minimum, then a larger maximum")
    if point and lo == hi:
        return
    problem = universe_problem(lo, hi)
    if problem:
        raise FormatError(problem[0].replace("universe", what, 1), span=span,
                          hint=problem[1] if lo < hi else "write the minimum, then a larger "
                                                          "maximum")


def resolution(value: float, text: str, span: Span) -> int:
    """A defuzzifier's resolution as written (``text``), within what MITOS evaluates."""
    if not value.is_integer() or not ops_mod.RESOLUTION[0] <= value <= ops_mod.RESOLUTION[1]:
        lo, hi = ops_mod.RESOLUTION
        raise FormatError(f"resolution must be a whole number from {lo} to {hi}, not {text}",
                          span=span)
    return int(value)


#: where a reader found each variable's range and default: ``(variable, "range" | "default")``
Places = dict[tuple[str, str], Span]


def check_numbers(variables: list[Variable], places: Places | None = None) -> None:
    """Refuse, with the position, what floating point cannot evaluate: NaN or infinite
    parameters (but a shoulder's open end), ranges and defaults, numbers beyond
    :data:`LARGEST`, and a default outside its output's range. So no NaN or infinity leaves
    the engine unless the file asked for one (``default: nan``). ``places``: where each
    variable's range and default are written (else the variable is named)."""
    places = places or {}
    for v in variables:
        lo, hi = v.universe
        open_range = (lo, hi) == (-math.inf, math.inf) and v.role == "output" and all(
            t.shape in ("singleton", "linear") for t in v.terms)   # an unused Sugeno range
        if not open_range:
            for end in (lo, hi):
                _finite(end, f"variable `{v.name}`: the range",
                        places.get((v.name, "range"), v.span))
        for t in v.terms:
            allowed = INFINITE_OK.get(t.shape, set())
            for i, p in enumerate(t.params):
                if math.isinf(p) and (i, 1 if p > 0 else -1) in allowed:
                    continue
                _finite(p, f"term `{v.name}.{t.name}`: parameter {i + 1}", t.span or v.span)
        d = v.default
        if d is not None and d == d:
            at = places.get((v.name, "default"), v.span)
            _finite(d, f"output `{v.name}`: the default", at)
            if not open_range and not lo <= d <= hi:
                raise FormatError(f"output `{v.name}`: the default {d:g} lies outside its "
                                  f"range [{lo:g}, {hi:g}]", span=at,
                                  hint="give a default inside the range, or nan for none")


def _finite(value: float, what: str, span: Span | None) -> None:
    if not math.isfinite(value):
        raise FormatError(f"{what} is {fmt_number(value)}: it must be a finite number",
                          span=span)
    if abs(value) > LARGEST:
        raise FormatError(f"{what} is {fmt_number(value)}: numbers beyond ±{LARGEST:g} cannot be "
                          f"evaluated in floating point without overflow", span=span)


def check_implication(name: str, span: Span | None) -> str:
    if name not in ops_mod.IMPLICATIONS:
        raise FormatError(f"implication `{name}` is not supported", span=span,
                          expected="one of " + ", ".join(ops_mod.IMPLICATIONS))
    return name


def assemble(path: str | None, variables: list[Variable], rules: list[Rule], settings: Settings,
             default_resolution: int, span: Span | None = None,
             notes: list[str] | None = None,
             places: Places | None = None) -> RuleBase:
    """Check what a reader gathered and return the rule base (one behavior, ``main``)."""
    return assemble_blocks(path, variables, [(MAIN, rules, settings)], default_resolution, span,
                           notes, places)


def assemble_blocks(path: str | None, variables: list[Variable],
                    blocks: list[tuple[str, list[Rule], Settings]], default_resolution: int,
                    span: Span | None = None, notes: list[str] | None = None,
                    places: Places | None = None) -> RuleBase:
    """The rule base of one or more rule blocks: one block gives behavior ``main`` with the
    operators on the file; several (whose operators differ) give one behavior each, with its
    own operators, the first being the default. Chained outputs are restated first
    (:func:`.rewrite.unchain`), with a line in ``notes``; ``places``: where each
    variable's range and default are written."""
    first: dict[str, Variable] = {}
    for v in variables:                             # at the second definition, as rules do
        if first.setdefault(v.name, v) is not v:
            raise FormatError(f"variable `{v.name}` is defined twice"
                              + first_at(first[v.name].span), span=v.span)
    if not any(v.role == "input" for v in variables):
        raise FormatError("the file defines no input variable", span=span)
    check_numbers(variables, places)
    if not any(rules for _, rules, _ in blocks):
        raise NoRulesError("the file has no rules", span=span,
                           termset=TermSet(tuple(variables), path))     # its terms: for plot, check
    by_name = {v.name: v for v in variables}
    behaviors = []
    outputs = {v.name for v in variables if v.role == "output"}
    for name, rules, settings in blocks:
        and_, or_ = settings.and_ or "min", settings.or_ or "max"
        aggregation = settings.aggregation or (None if settings.sugeno else "max")
        rules = rewrite.unchain(rules, outputs, and_, or_, aggregation,
                                notes if notes is not None else [])
        if not settings.sugeno:
            rules = _hedges_moved(rules, notes if notes is not None else [])
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
            if sugeno and t.formula is not None:
                raise FormatError(
                    f"output term `{v.name}.{t.name}`: a formula as a weighted-average "
                    f"consequent (a function of the engine's variables) is not supported",
                    span=t.span, hint="use Constant or Linear terms")
            if settings.defuzzify == "tsukamoto":
                if t.shape not in TSUKAMOTO:
                    raise FormatError(f"output term `{v.name}.{t.name}`: Tsukamoto inference "
                                      f"inverts monotonic terms ({', '.join(TSUKAMOTO)}), not "
                                      f"a `{t.shape}` term", span=t.span)
                continue
            if sugeno and t.shape not in ("singleton", "linear"):
                raise FormatError(
                    f"output term `{v.name}.{t.name}`: a weighted-average output needs constant "
                    f"or linear terms (Takagi-Sugeno) or monotonic ones (Tsukamoto: "
                    f"{', '.join(TSUKAMOTO)}), not a `{t.shape}` term", span=t.span)
            if not sugeno and t.shape == "linear":
                raise FormatError(f"output term `{v.name}.{t.name}`: linear terms need a "
                                  f"weighted-average (Takagi-Sugeno) defuzzifier", span=t.span)
    for rule in rules:
        try:
            check_rule(rule, by_name)
        except MitosError as exc:
            raise FormatError(exc.message, span=exc.span or rule.span, expected=exc.expected,
                              hint=exc.hint) from None


def _hedges_moved(rules: list[Rule], notes: list[str]) -> list[Rule]:
    """Mamdani rules whose consequents fuzzylite hedges, restated so that MITOS computes what
    fuzzylite does (:func:`_hedge_moved`), with a note; a rule that cannot be is refused."""
    out = [_hedge_moved(r) for r in rules]
    moved = [(r, new) for r, new in zip(rules, out) if new is not r]
    if moved:
        (first, read), verb = moved[0], "hedges" if len(moved) == 1 else "hedge"
        notes.append(f"{first.span or first.label}: {plural(len(moved), 'rule')} {verb} a "
                     f"Mamdani consequent, which fuzzylite computes as the hedged degree of the "
                     f"rule: the hedge is read on the condition ({_moved_text(first, read)}), "
                     f"the same there")
    return out


def _moved_text(rule: Rule, read: Rule) -> str:
    """The first moved rule as the note quotes it, in its own names (a fixed example, `y is
    very lo` as `x is very A`, read as if about the user's rule)."""
    c = next(c for c in rule.consequents if c.hedges)
    return f"`then {hedged_text(c)}` as `if {format_expr(read.antecedent)} then {c.var} is {c.term}`"


def _hedge_moved(rule: Rule) -> Rule:
    """``if x is A then y is very B`` as ``if x is very A then y is B``: fuzzylite hedges a
    Mamdani consequent's activation degree (``Consequent.modify``), MITOS's rules would hedge
    the output set. The same where the condition is one proposition without ``not``, the
    weight 1 (fuzzylite hedges ``w * dof``), every consequent carries the same hedges and none
    is ``any`` (fuzzylite skips a rule of degree 0 before hedging); otherwise refused by name."""
    c = next((c for c in rule.consequents if c.hedges), None)
    if c is None:
        return rule
    e = rule.antecedent
    if (isinstance(e, Prop) and not e.negated and rule.weight == 1.0 and "any" not in c.hedges
            and all(k.hedges == c.hedges for k in rule.consequents)):
        return replace(rule, antecedent=replace(e, hedges=c.hedges + e.hedges),
                       consequents=tuple(replace(k, hedges=()) for k in rule.consequents))
    raise FormatError(
        f"rule `{rule.label}`: `{hedged_text(c)}` hedges a Mamdani consequent, which fuzzylite "
        f"computes as the hedged activation degree of the rule and MITOS as the hedged output "
        f"set: not supported here", span=c.span,
        hint="move the hedge onto the condition (`if x is very A`), the same where the "
             "condition is one proposition without `not` and the rule's weight is 1 (such a "
             "rule is read so)")


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
    operators = ops_mod.of_behavior(rb, b)
    rules = []
    for label, rule, uses in flatten(rb, name):
        w = rule.weight
        for use in uses:
            if use.condition is not None:
                raise FormatError(f"rule `{label}` comes from `use {use.behavior} when ...`: "
                                  f"a conditional include cannot be written in FCL, FIS or FLL",
                                  span=use.span,
                                  hint=f"convert `{use.behavior}` alone (--behavior "
                                       f"{use.behavior}), or write the condition into its "
                                       f"rules; `mitos export` (C, Python) keeps `{name}` "
                                       f"whole")
            w *= use.weight
        rules.append(Rule(label, rule.antecedent, rule.consequents, w, rule.span))
    variables = rb.variables
    used_in = {p.var for r in rules for p in props(r.antecedent)}
    used_out = {c.var for r in rules for c in r.consequents}
    inputs = tuple(v for v in variables.values() if v.role == "input" and v.name in used_in)
    outputs = [v for v in variables.values() if v.role == "output" and v.name in used_out]
    if crisp_terms:
        extra: dict[str, dict[float, str]] = {}
        crisp_taken: dict[str, set[str]] = {}     # a variable's term names and new ones
        new_rules = []
        for r in rules:
            cons = []
            for c in r.consequents:
                if c.term is None:
                    assert c.value is not None   # a consequent names a term or a crisp value
                    var = variables[c.var]
                    names = extra.setdefault(c.var, {})
                    if c.value not in names:
                        taken = crisp_taken.setdefault(c.var, set(var.term_names))
                        names[c.value] = unique_name(crisp_name(c.value), taken)
                        taken.add(names[c.value])
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
    linear consequent of the rules weighs (its coefficients are rewritten over these).
    Terms are looked up in ``flat``'s outputs: they hold the ``crisp_80`` terms that stand for
    crisp consequents, which ``rb`` does not."""
    needed = {v.name for v in flat.inputs}
    outputs = {v.name: v for v in flat.outputs}
    for r in flat.rules:
        for c in r.consequents:
            term = outputs[c.var].term(c.term) if c.term is not None else None
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


def unique_name(name: str, taken: Iterable[str], tried: dict[str, int] | None = None) -> str:
    """``name``, else the first of ``name_2``, ``name_3``, ... not in ``taken`` (a set is used
    as it is; anything else is made one). ``tried`` remembers, per ``name``, the suffix
    reached: a caller that only adds to ``taken`` gets its next name without trying again
    every suffix an earlier call tried."""
    if not isinstance(taken, (set, frozenset, dict)):
        taken = set(taken)
    i = tried.get(name, 1) if tried is not None else 1
    out = name if i == 1 else f"{name}_{i}"
    while out in taken:
        i += 1
        out = f"{name}_{i}"
    if tried is not None:
        tried[name] = i
    return out


def props(expr: Expr) -> Iterator[Prop]:
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
    """Write ``text`` to ``path`` atomically (:func:`mitos_cli.fileio.atomic_write`; a
    failure is a :class:`~mitos_cli.errors.WriteError`, as every command's is)."""
    from ..fileio import atomic_write as write

    write(path, text)



# ---------------------------------------------------------------------------------------------
# Names each format can hold

#: A legal name per target format, and the words its rules reserve.
NAME_PATTERNS = {
    "fll": r"[A-Za-z_][A-Za-z0-9_.]*",
    "fcl": r"[A-Za-z_][A-Za-z0-9_.]*",
    "rules": r"[A-Za-z_]([A-Za-z0-9_\-]*[A-Za-z0-9_])?",
    "fis": r"[^'\n]+",
}
_RULE_WORDS = {"if", "then", "and", "or", "not", "is", "with"} | set(FUZZYLITE_HEDGES)
RESERVED_NAMES = {
    "fll": _RULE_WORDS,
    "fcl": _RULE_WORDS | {"rule", "term", "range", "method", "default", "accu", "act",
                          "lock", "end_var", "var_input", "var_output", "fuzzify",
                          "defuzzify", "end_fuzzify", "end_defuzzify", "ruleblock",
                          "end_ruleblock", "function_block", "end_function_block", "real"},
    "rules": _RULE_WORDS | {"use", "when", "behavior", "end", "terms", "operators", "frozen"}
             | set(HEDGES),
    "fis": set(),
}


FORMAT_TITLES = {"fll": "FLL", "fcl": "FCL", "fis": "a .fis file", "rules": "the rule language"}


def legal_names(rb: RuleBase, fmt: str) -> tuple[RuleBase, list[str]]:
    """``rb`` with every variable and term name the format ``fmt`` cannot hold (``LDL-Level``
    in FLL, ``service level`` in the rule language, a term named ``very``) mapped to a legal
    one (``LDL_Level``), and a note per renamed name."""
    var_map, term_map, notes = _legal_renames(rb, fmt)
    if not notes:
        return rb, []
    return _renamed(rb, var_map, term_map), notes


def _legal_renames(rb: RuleBase, fmt: str
                   ) -> tuple[dict[str, str], dict[tuple[str, str], str], list[str]]:
    """The new names of the variables and of each variable's terms that ``fmt`` cannot hold
    (each new name unlike every other of its kind, so no two names merge), and a note per
    renamed name saying why."""
    import re

    pattern = re.compile(NAME_PATTERNS.get(fmt, NAME_PATTERNS["fll"]))
    reserved = RESERVED_NAMES.get(fmt, set())

    def legal(name: str, taken: set[str]) -> str:
        """``name``, or a legal one none of ``taken`` (but ``name``) has."""
        if pattern.fullmatch(name) and name.lower() not in reserved:
            return name
        taken = taken - {name}      # only here: a copy per name was quadratic in the terms
        new = re.sub(r"[^A-Za-z0-9_]", "_", name) if fmt != "fis" else name.replace("'", "_")
        if not new or not (new[0].isalpha() or new[0] == "_") and fmt != "fis":
            new = "_" + new
        if new.lower() in reserved:
            new += "_"
        return unique_name(new, taken)

    notes: list[str] = []
    var_map: dict[str, str] = {}
    term_map: dict[tuple[str, str], str] = {}
    all_vars = [v for ts in rb.termsets for v in ts.variables]
    taken_vars = {v.name for v in all_vars}
    for v in all_vars:
        new = legal(v.name, taken_vars)
        if new != v.name:
            var_map[v.name] = new
            taken_vars.add(new)
            notes.append(f"variable `{v.name}` is written as `{new}` ({FORMAT_TITLES[fmt]} "
                         f"cannot name it `{v.name}`)")
        taken_terms = set(v.term_names)
        for t in v.terms:
            new_t = legal(t.name, taken_terms)
            if new_t != t.name:
                term_map[(v.name, t.name)] = new_t
                taken_terms.add(new_t)
                notes.append(f"term `{v.name}.{t.name}` is written as `{new_t}` "
                             f"({FORMAT_TITLES[fmt]} cannot name it `{t.name}`)")
    return var_map, term_map, notes


def _renamed(rb: RuleBase, var_map: dict[str, str],
             term_map: dict[tuple[str, str], str]) -> RuleBase:
    """``rb`` with its variables and terms renamed (``var_map``; ``term_map``, keyed by the
    old variable and term names) wherever they are named: term sets, rules, `use`
    conditions."""
    def var(name: str) -> str:
        return var_map.get(name, name)

    def term(v: str, t: str) -> str:
        return term_map.get((v, t), t)

    def expr(e: Expr) -> Expr:
        if isinstance(e, Prop):
            return replace(e, var=var(e.var), term=term(e.var, e.term))
        if isinstance(e, Not):
            return replace(e, expr=expr(e.expr))
        return replace(e, items=tuple(expr(i) for i in e.items))

    def rule(r: Rule) -> Rule:
        return replace(r, antecedent=expr(r.antecedent), consequents=tuple(
            replace(c, var=var(c.var), term=None if c.term is None else term(c.var, c.term))
            for c in r.consequents))

    termsets = tuple(TermSet(tuple(replace(
        v, name=var(v.name), terms=tuple(replace(t, name=term(v.name, t.name))
                                         for t in v.terms)) for v in ts.variables), ts.path)
        for ts in rb.termsets)
    behaviors = tuple(replace(
        b, rules=tuple(rule(r) for r in b.rules),
        uses=tuple(replace(u, condition=None if u.condition is None else expr(u.condition))
                   for u in b.uses))
        for b in rb.behaviors)
    return replace(rb, termsets=termsets, behaviors=behaviors)


# ---------------------------------------------------------------------------------------------
# Fidelity to a format's reference engine

#: How each reference engine samples a Mamdani output: (resolution, sampling); ``None`` keeps
#: the file's resolution, a number replaces only a resolution the file does not write.
#: MATLAB's ``evalfis``: 101 points including both ends; jFuzzyLogic: 1000 left cell ends;
#: fuzzylite 8 (pyfuzzylite 8.0.6, which reads FLL only): the file's resolution, 1000 by
#: default, at cell midpoints; fuzzylite 6 (Debian's ``fuzzylite`` binary, which reads FLL,
#: FCL and .fis): the same with 100 by default (``IntegralDefuzzifier::_defaultResolution``),
#: which is every FCL ``METHOD : COG;`` and every .fis ``centroid``.
FIDELITY = {"matlab": (101, "endpoints"), "jfuzzylogic": (1000, "left"),
            "fuzzylite": (None, "midpoints"), "fuzzylite6": (None, "midpoints"),
            "octave": (101, "trapezoid")}
UNWRITTEN_RESOLUTION = {"fuzzylite": 1000, "fuzzylite6": 100}
#: Engines that evaluate an input outside its universe as given (``inputs = as_given``):
#: jFuzzyLogic's ``Variable.setValue`` only warns; fuzzylite clamps only an input whose
#: ``lock-range`` is true, which no FCL or ``.fis`` file can say (an FLL file's is read).
UNCLAMPED = {"jfuzzylogic": None, "fuzzylite": (".fcl", ".fis"), "fuzzylite6": (".fcl", ".fis")}


def fidelity_settings(rb: RuleBase, engine: str, behavior: str | None = None
                      ) -> tuple[Setting, ...]:
    """Operator overrides that make ``rb``'s Mamdani outputs sample as ``engine`` does (none
    for a weighted-average rule base, whose outputs are not sampled). An output's own
    ``resolution`` beats them: compile :func:`fidelity_rulebase` ``(rb, engine)`` with them."""
    if engine not in FIDELITY:
        raise FormatError(f"unknown engine `{engine}`", expected="one of " + ", ".join(FIDELITY),
                          hint=did_you_mean(engine, FIDELITY))
    b = rb.behavior(behavior)
    ops = ops_mod.of_behavior(rb, b)
    files = UNCLAMPED.get(engine, ())       # None: every file
    unclamped = files is None or (rb.path or "").lower().endswith(files)
    given = (Setting("inputs", "as_given"),) if unclamped else ()
    if engine == "octave" and ops.inference in ("weighted_average", "weighted_sum"):
        return _octave_accumulation(rb)
    if ops.inference != "mamdani":
        return given
    resolution, sampling = FIDELITY[engine]
    if resolution is None:
        foreign = (rb.path or "").lower().endswith((".fll", ".fcl", ".fis"))
        # the rule language's default (101) is its own and the FLL writer writes it; a
        # foreign reader's default (FLL, FCL: 1000) is not in the file; .fis has none
        written = not foreign or (setting_span(rb, behavior, "resolution") is not None
                                  and ops.sampling != "endpoints")
        resolution = ops.resolution if written else UNWRITTEN_RESOLUTION[engine]
    return (*given, Setting("resolution", str(resolution)), Setting("sampling", sampling),
            *_engines_defuzzifier(ops.defuzzify, engine))


def _octave_accumulation(rb: RuleBase) -> tuple[Setting, ...]:
    """Octave's toolkit joins the rules of one Sugeno output value with the file's
    ``AggMethod`` before the weighted average (``aggregate_fis_output``: the rules' values
    sorted, equal ones joined), which is ``accumulation = AggMethod``; MATLAB, and MITOS's
    reading of a ``.fis``, count every rule. Only a ``.fis`` file says it, and its reader
    keeps it (:attr:`.RuleBase.unused`)."""
    given = next((s for s in rb.unused if s.key == "AggMethod"), None)
    if given is None:
        return ()
    method = table_lookup(AGGREGATIONS, FIS, given.value, "aggregation method", given.span)
    return () if method == "sum" else (Setting("accumulation", method),)


def engine_defaults(rb: RuleBase, engine: str) -> dict[str, str]:
    """The outputs for which ``engine`` has no number where no rule sets them, though ``rb``'s
    reading gives its default there, each with what the engine does, to be said beside the
    NaN the fidelity gives instead. MATLAB returns the middle of the output's range, which
    the ``.fis`` reader makes the default; Octave's toolkit (0.4.6) returns NaN for a Mamdani
    output and stops with an error for a Sugeno one (``defuzzify_output_sugeno`` indexes an
    empty aggregate). Octave reads no fuzzylite ``Default=`` line (``readfis`` stops there),
    so a written default other than the middle stays the file's."""
    if engine != "octave" or not (rb.path or "").lower().endswith(".fis"):
        return {}
    mamdani = ops_mod.of_behavior(rb, rb.behavior(None)).inference == "mamdani"
    said = "Octave gives NaN" if mamdani else "Octave's evalfis stops with an error"
    return {v.name: said for v in rb.variables.values()
            if v.role == "output" and v.default == (v.universe[0] + v.universe[1]) / 2}


def fidelity_rulebase(rb: RuleBase, engine: str) -> RuleBase:
    """``rb`` as ``engine`` samples its outputs: fuzzylite (8 and 6) gives each Mamdani output
    its defuzzifier's resolution, so the outputs' own ``resolution`` stays; MATLAB, Octave and
    jFuzzyLogic sample every output alike (:data:`FIDELITY`), so it goes, and the behavior's
    (:func:`fidelity_settings`) is every output's. The outputs of :func:`engine_defaults`
    declare NaN, the engine's value where no rule sets them."""
    nan = engine_defaults(rb, engine)
    alike = FIDELITY.get(engine, (None,))[0] is not None and any(
        v.resolution is not None for v in rb.variables.values())
    if not nan and not alike:
        return rb

    def as_engine(v: Variable) -> Variable:
        return replace(v, resolution=None if alike else v.resolution,
                       default=math.nan if v.name in nan else v.default)

    termsets = tuple(replace(ts, variables=tuple(as_engine(v) for v in ts.variables))
                     for ts in rb.termsets)
    return replace(rb, termsets=termsets)


def _engines_defuzzifier(method: str, engine: str) -> tuple[Setting, ...]:
    """``engine``'s own bisector, som or lom: MATLAB defines them otherwise than fuzzylite
    (:data:`.fis.MATLAB_DEFUZZIFIERS`), jFuzzyLogic its bisector (COA) otherwise than both
    (``jfuzzylogic_bisector``), and a fidelity computes as its engine."""
    plain = method.removeprefix("matlab_").removeprefix("jfuzzylogic_")
    if plain not in ("bisector", "som", "lom"):
        return ()
    if engine == "matlab":
        return (Setting("defuzzify", f"matlab_{plain}"),)
    if engine == "jfuzzylogic" and plain == "bisector":
        return (Setting("defuzzify", "jfuzzylogic_bisector"),)
    return (Setting("defuzzify", plain),)


def refuse_accumulation(rb: RuleBase, behavior: str | None, flat: Flat, fmt: str,
                        hint: str = "write it to FCL (ACCU) or a rule file") -> None:
    """Refuse to write a behavior whose ``accumulation`` S-norm joins several rules of one
    value to a format that cannot say so (fuzzylite and MATLAB average every rule): two rules
    of one value, or a linear function among an output's values (they meet at some inputs,
    where the engine joins them). Where neither happens the S-norm changes nothing and the
    file is written."""
    if not flat.operators.accumulated:
        return
    seen: dict[tuple, str] = {}
    outputs = {v.name: v for v in flat.outputs}
    for r in flat.rules:
        for c in r.consequents:
            term = outputs[c.var].term(c.term) if c.term is not None else None
            key = (c.var, term.params if term is not None and term.shape == "linear"
                   else term.center if term is not None else c.value)
            if key in seen:
                value = (f"the linear function of `{c.term}`" if isinstance(key[1], tuple)
                         else fmt_number(float(key[1] or 0.0)))
                raise FormatError(
                    f"{fmt} has no accumulation of the rules that conclude one value: "
                    f"`{seen[key]}` and `{r.label}` both set `{c.var}` to {value}, which "
                    f"`accumulation = {flat.operators.accumulation}` joins",
                    span=setting_span(rb, behavior, "accumulation"),
                    hint=f"{hint}, or merge the rules")
            seen[key] = r.label
    for var in dict.fromkeys(k[0] for k in seen):
        keys = [k for k in seen if k[0] == var]
        linear = [k for k in keys if isinstance(k[1], tuple)]
        if linear and len(keys) > 1:         # the engine joins two values where they meet
            raise FormatError(
                f"{fmt} has no accumulation of the rules that conclude one value: `{var}`'s "
                f"linear function (`{seen[linear[0]]}`) meets its other values at some inputs, "
                f"where `accumulation = {flat.operators.accumulation}` joins their rules",
                span=setting_span(rb, behavior, "accumulation"), hint=hint)
