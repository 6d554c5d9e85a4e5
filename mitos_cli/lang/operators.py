"""The operator settings of a rule base or behavior (``operators: and = min, or = max, ...``).

The default is the paper's: AND = min (eq. 17), OR = max, and the DOF-weighted average of crisp
consequents (eqs. 18-19). A behavior's settings override the file's, key by key.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
from typing import Any

from ..errors import NameError_, RuleBaseError, Span, did_you_mean, unknown
from ..fuzzy import norms
from ..lang.model import Behavior, RuleBase, Setting

INFERENCES = ("weighted_average", "weighted_sum", "mamdani", "tsukamoto")
#: Mamdani implications: any T-norm (min and product are the classic ones; FLL files also use
#: e.g. EinsteinProduct).
IMPLICATIONS = tuple(norms.TNORMS)
DEFUZZIFIERS = ("centroid", "bisector", "mom", "som", "lom",
                "matlab_bisector", "matlab_som", "matlab_lom",      # MATLAB's evalfis
                "jfuzzylogic_bisector")                             # jFuzzyLogic's COA
#: Where Mamdani outputs are sampled: cell midpoints (fuzzylite's rule, the default),
#: ``resolution`` evenly spaced points including both ends (MATLAB's ``evalfis``), or the
#: cells' left ends (jFuzzyLogic's, each reached from the one before: ``x += (max - min) / resolution``),
#: or the end points with the two ends weighing half in the centroid and bisector's areas: the
#: trapezoid rule of Octave's fuzzy-logic-toolkit (``trapz`` in its ``defuzz.m``).
SAMPLINGS = ("midpoints", "endpoints", "left", "trapezoid")
#: How weighted inference joins the rules that conclude one value of an output: ``sum`` counts
#: each rule in the average (fuzzylite 6, MATLAB); an S-norm first joins their DOFs into one
#: weight for that value (jFuzzyLogic's ``ACCU`` under ``METHOD : COGS``).
ACCUMULATIONS = ("sum",)
#: What an input outside its universe is evaluated at: the universe's nearer end (MITOS's and
#: fuzzylite's ``lock-range: true``, MATLAB's), or the value as given (jFuzzyLogic's, whose
#: ``Variable.setValue`` only warns).
INPUTS = ("clamped", "as_given")
#: The least and the most points a Mamdani output is sampled on.
RESOLUTION = (3, 100_000)


@dataclass(frozen=True)
class Operators:
    """Which operators the neurons of a compiled behavior use."""

    and_: str = "min"
    or_: str = "max"
    inference: str = "weighted_average"
    implication: str = "min"
    aggregation: str = "max"
    defuzzify: str = "centroid"
    resolution: int = 101
    sampling: str = "midpoints"
    accumulation: str = "sum"
    inputs: str = "clamped"

    @property
    def tnorm(self) -> norms.Norm:
        return norms.lookup("tnorm", self.and_)

    @property
    def snorm(self) -> norms.Norm:
        return norms.lookup("snorm", self.or_)

    def describe(self, own: dict[str, int] | None = None, every: bool = False) -> str:
        """The settings in an ``operators:`` line's words; ``own``: outputs sampled at a
        resolution of their own, ``every`` output (``resolution = 200 for Power, 500 for
        InversePower``) or some (``resolution = 1000, 200 for Power``)."""
        text = f"and = {self.and_}, or = {self.or_}, inference = {self.inference}"
        if self.inference == "mamdani":
            points = ", ".join(([] if own and every else [str(self.resolution)])
                               + [f"{r} for {n}" for n, r in (own or {}).items()])
            text += (f", implication = {self.implication}, aggregation = {self.aggregation}, "
                     f"defuzzify = {self.defuzzify}, resolution = {points}")
            if self.sampling != "midpoints":
                text += f", sampling = {self.sampling}"
        elif self.accumulated:
            text += f", accumulation = {self.accumulation}"
        if self.inputs != "clamped":
            text += f", inputs = {self.inputs}"
        return text

    @property
    def accumulated(self) -> bool:
        """Weighted inference that joins the rules concluding one value with an S-norm."""
        return (self.accumulation != "sum"
                and self.inference in ("weighted_average", "weighted_sum"))

    def settings(self) -> dict[str, str]:
        """The non-default settings as ``operators:`` keys (for writing a rule file back)."""
        default = Operators()
        out = {}
        for f in fields(self):
            value = getattr(self, f.name)
            if value != getattr(default, f.name):
                out[f.name.rstrip("_")] = str(value)
        return out


KEYS = {"and": "and_", "or": "or_", "inference": "inference", "implication": "implication",
        "aggregation": "aggregation", "defuzzify": "defuzzify", "resolution": "resolution",
        "sampling": "sampling", "accumulation": "accumulation", "inputs": "inputs"}


def _check(key: str, value: str, span: Span | None) -> str | int:
    if key in ("and", "implication"):       # an implication is any T-norm, by any of its names
        try:
            return norms.lookup("tnorm", value).name
        except KeyError:
            what = "T-norm" if key == "and" else "implication"
            raise unknown(what, value, norms.names("tnorm"), span=span) from None
    if key == "accumulation" and value in ACCUMULATIONS:
        return value
    if key == "aggregation" and value in ("sum",) + norms.UNBOUNDED_SUM.aliases:
        return "sum"
    if key == "or" and value in ("sum",) + norms.UNBOUNDED_SUM.aliases:
        raise RuleBaseError(f"`or = {value}`: the unbounded sum is a Mamdani aggregation only "
                            f"(`aggregation = sum`), not an S-norm: it leaves [0, 1]",
                            span=span, hint="did you mean `or = bounded_sum` (min(1, a + b)) "
                                            "or `or = probabilistic_sum` (a + b - a b)?")
    if key in ("or", "aggregation", "accumulation"):
        try:
            return norms.lookup("snorm", value).name
        except KeyError:
            if key == "or":
                raise unknown("S-norm", value, norms.names("snorm"), span=span) from None
            raise _unknown_join(key, value, span) from None
    among = {"inference": INFERENCES, "defuzzify": DEFUZZIFIERS,
             "sampling": SAMPLINGS, "inputs": INPUTS}.get(key)
    if among is not None:
        if value not in among:
            raise unknown(key, value, among, span=span)
        return value
    # resolution
    try:
        number = float(value)
    except ValueError:
        number = -1.0
    if not number.is_integer() or not RESOLUTION[0] <= number <= RESOLUTION[1]:
        raise RuleBaseError(f"resolution must be a whole number from {RESOLUTION[0]} to "
                            f"{RESOLUTION[1]}, not {value}", span=span)
    return int(number)


#: What ``sum`` means where it is not an S-norm, by setting.
SUM_MEANS = {"aggregation": "the unbounded sum of the rules' sets",
             "accumulation": "each rule counted in the average, the default"}
#: Other engines' names for one of the S-norms, said as a hint where they are written.
FOREIGN_JOINS = {"nsum": "bounded_sum", "normalized_sum": "bounded_sum",
                 "normalizedsum": "bounded_sum"}


def _unknown_join(key: str, value: str, span: Span | None) -> NameError_:
    """An unknown ``aggregation`` or ``accumulation``: ``sum`` first, then the S-norms by
    their names (each alias is still taken, and a did-you-mean looks among them too)."""
    sum_names = ["sum", *norms.UNBOUNDED_SUM.aliases] if key == "aggregation" else ["sum"]
    hint = (f"jFuzzyLogic's `NSUM` is `{FOREIGN_JOINS[value.lower()]}` (the two are equal)"
            if value.lower() in FOREIGN_JOINS
            else did_you_mean(value, sum_names + norms.names("snorm")))
    expected = (f"`sum` ({SUM_MEANS[key]}) or an S-norm: " + ", ".join(norms.SNORMS))
    return NameError_(f"unknown {key} `{value}`", span=span, expected=expected, hint=hint)


def resolve(settings: tuple[Setting, ...], base: Operators | None = None) -> Operators:
    """Apply ``operators:`` settings on top of ``base`` (the paper's defaults)."""
    ops = base or Operators()
    for s in settings:
        if s.key not in KEYS:
            raise unknown("operator setting", s.key, KEYS, span=s.span)
        change: dict[str, Any] = {KEYS[s.key]: _check(s.key, s.value, s.span)}  # field by name
        ops = replace(ops, **change)
    return ops


def of_behavior(rb: RuleBase, behavior: Behavior, overrides: tuple[Setting, ...] = ()) -> Operators:
    """A behavior's operators: the paper's defaults, then the file's ``operators:`` line, then
    the behavior's own, then ``overrides`` (a study's choices)."""
    return resolve(overrides, resolve(behavior.operators, resolve(rb.operators)))
