"""Linguistic variables and their terms (the model side of a term set).

A :class:`Variable` has a universe, a role (input or output) and terms; a :class:`Term` is a
named membership function from :mod:`mitos_cli.fuzzy.shapes`. Both are frozen and validated when
built, so a compiled rule base never meets a malformed one.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import TYPE_CHECKING, Literal

import numpy as np

from ..errors import Span, TermSetError, control_character, invisible_character, unknown
from ..fuzzy.formula import Formula
from ..fuzzy.shapes import SHAPES, STEEP, Shape
from ..numbers import exact

if TYPE_CHECKING:
    from collections.abc import Callable

    from numpy.typing import ArrayLike

Role = Literal["input", "output"]

#: Shapes a term set spells differently from the registry: every triangle is ``shape:
#: triangle``, told apart by its parameters (docs/language.md); by its corners it takes
#: ``points: [a, b, c]`` only.
TERM_SET_SHAPES = {"triangle": "triangle", "triangle_pw": "triangle",
                   "triangle_plr": "triangle"}


def _number(value: float) -> str:
    return f"{value:g}"


@dataclass(frozen=True)
class Term:
    """A named fuzzy set: a shape and its parameters (in the shape's own order)."""

    name: str
    shape: str
    params: tuple[float, ...]
    span: Span | None = field(default=None, compare=False)
    frozen: bool = False
    #: ``held: false`` in the YAML: a centre term adaptation may move off its point of symmetry
    held: bool = True
    #: ``held: POINT`` in the YAML: the point a centre term is held at, written where its
    #: neighbours no longer mirror each other about it (``mitos teach`` saves it after an
    #: adaptation moved them); ``None``: the point of symmetry, if the terms have one
    held_at: float | None = None
    #: the membership function of a ``formula`` term (its params are empty)
    formula: Formula | None = None

    @property
    def kind(self) -> Shape:
        return SHAPES[self.shape]

    @property
    def corners(self) -> tuple[float, float, float, float] | None:
        """``(a, b, c, d)`` for piecewise-linear shapes, else ``None``."""
        return self.kind.corners(self.params) if self.kind.corners else None

    @property
    def center(self) -> float:
        """The crisp value the term stands for in a weighted-average consequent."""
        return float(self.kind.center(self.params))

    @property
    def shape_name(self) -> str:
        """The shape as the term set writes it: ``triangle``, never ``triangle_pw``."""
        return TERM_SET_SHAPES.get(self.shape, self.shape)

    def params_text(self, number: Callable[[float], str] = _number) -> str:
        """The parameters as the term set names them, for people: ``peak 70, width 30``,
        ``a 40, b 70``, ``points [10, 40, 70]`` (a triangle by its corners or a ``discrete``
        term), a singleton's value alone. ``number`` formats each value."""
        p = self.params
        if self.formula is not None:
            return f"formula {self.formula.text}"
        if self.shape == "singleton":
            return number(p[0])
        if self.shape == "linear":                 # LINEAR_LAYOUT: coefficients..., constant
            return (f"coefficients [{', '.join(number(v) for v in p[:-1])}], "
                    f"constant {number(p[-1])}")
        if self.shape == "triangle" or self.kind.variadic or len(p) != len(self.kind.params):
            return f"points [{', '.join(number(v) for v in p)}]"
        return ", ".join(f"{n} {number(v)}" for n, v in zip(self.kind.params, p))

    def membership(self, x: ArrayLike) -> np.ndarray:
        if self.formula is not None:
            return self.formula(x)
        return self.kind.membership(x, self.params)

    def with_params(self, params: tuple[float, ...]) -> Term:
        return replace(self, params=tuple(float(p) for p in params))


def _control_in(text: str, one_line: bool) -> str | None:
    """The first control character of ``text`` as its escape; in a ``one_line`` text a line
    break counts too (a tab does not: a .fis name may hold one, and it writes no line)."""
    found = control_character(text)
    if found is None and one_line and "\n" in text:
        found = "\\n"
    return found


def invisible_name(name: str, span: Span | None, what: str) -> None:
    """Refuse a format character in a name (a zero-width space, LRM, a BOM inside it): it
    prints as nothing, so `road` and `ro\\u200bad` look alike and are two names. Texts
    (descriptions, units) may hold them: Persian writes a zero-width non-joiner, mixed
    scripts an LRM."""
    char = invisible_character(name)
    if char is not None:
        raise TermSetError(f"{what} holds the invisible character {char}", span=span,
                           hint="it prints as nothing, so the name looks like another it is "
                                "not: write it without")


def first_at(span: Span | None) -> str:
    """`` (first at line N)``, said of a name given twice, at the second; empty without a
    position."""
    return f" (first at line {span.line})" if span is not None else ""


@dataclass(frozen=True)
class Variable:
    """A linguistic variable: x1 road width, y1 steering, ..."""

    name: str
    role: Role
    universe: tuple[float, float]
    terms: tuple[Term, ...]
    description: str = ""
    unit: str = ""
    default: float | None = None
    span: Span | None = field(default=None, compare=False)
    #: A Mamdani output's own number of sample points, where it differs from its behavior's
    #: ``resolution`` (fuzzylite gives each output its defuzzifier's); None: the behavior's.
    resolution: int | None = None

    def __post_init__(self) -> None:
        lo, hi = self.universe
        problem = universe_problem(lo, hi)
        if problem:
            raise TermSetError(f"variable `{self.name}`: {problem[0]}", span=self.span,
                               hint=problem[1])
        if self.resolution is not None:
            self._check_resolution()
        self._check_plain()
        seen: dict[str, Term] = {}
        for term in self.terms:
            first = seen.setdefault(term.name, term)
            if first is not term:
                raise TermSetError(f"variable `{self.name}`: duplicate term `{term.name}`"
                                   + first_at(first.span), span=term.span)

    def _check_resolution(self) -> None:
        from .operators import RESOLUTION

        if self.role != "output":
            raise TermSetError(f"variable `{self.name}`: only outputs take a `resolution` (an "
                               f"input is not sampled)", span=self.span)
        lo, hi = RESOLUTION
        if not (isinstance(self.resolution, int) and lo <= self.resolution <= hi):
            raise TermSetError(f"variable `{self.name}`: resolution must be a whole number "
                               f"from {lo} to {hi}, not {self.resolution}", span=self.span)

    def _check_plain(self) -> None:
        """Refuse a control character in a name, description or unit (a .fis name may hold
        any character, a YAML text any escape): `eval`, `check` and `teach` print them, and
        an ESC there was sent to the terminal as written (``\\x1b]0;...`` set its title).
        A name or unit is one line besides: `eval` prints the unit within its lines, and a
        line break in it wrote lines of output of its own (``outputs: steering = 150``)."""
        texts = [(f"variable `{self.name}`", "its name", self.name, self.span, True),
                 (f"variable `{self.name}`", "its description", self.description, self.span,
                  False),
                 (f"variable `{self.name}`", "its unit", self.unit, self.span, True)]
        texts += [(f"term `{self.name}.{t.name}`", "its name", t.name, t.span or self.span, True)
                  for t in self.terms]
        for what, part, text, span, one_line in texts:
            char = _control_in(text, one_line)
            if char is not None:
                raise TermSetError(f"{what}: {part} holds the control character `{char}`",
                                   span=span, hint="names and texts are printed to the "
                                   "terminal: write them without control characters")
        for what, part, text, span, _ in texts:
            if part == "its name":
                invisible_name(text, span, f"{what}: its name")


    @property
    def term_names(self) -> tuple[str, ...]:
        return tuple(t.name for t in self.terms)

    @cached_property
    def _by_name(self) -> dict[str, Term]:
        """The terms by name, the first of a name first (a search of the tuple per rule was
        quadratic in the terms: 20,000 took 8 s)."""
        out: dict[str, Term] = {}
        for t in self.terms:
            out.setdefault(t.name, t)
        return out

    def term(self, name: str, span: Span | None = None) -> Term:
        found = self._by_name.get(name)
        if found is None:
            error = unknown("term", name, self.term_names, span=span, owner=self.name)
            error.hint = self._modifier_glued(name) or error.hint
            raise error
        return found

    def _modifier_glued(self, name: str) -> str | None:
        """``notTIGHT``, ``veryWIDE``: `not` or a hedge glued to a term is one name; "did you
        mean `TIGHT`?" would drop the `not` (and turn the condition over)."""
        from ..fuzzy.hedges import HEDGES, fuzzylite_names

        lowered = name.lower()
        for word in sorted({"not", *HEDGES, *fuzzylite_names()}, key=len, reverse=True):
            rest = name[len(word):]
            if lowered.startswith(word) and rest in self._by_name:
                said = name[:len(word)]
                return f"`{said}` and `{rest}` are two words: `{self.name} is {said} {rest}`"
        return None

    def index(self, name: str) -> int:
        return self.term_names.index(name)

    def with_terms(self, terms: tuple[Term, ...]) -> Variable:
        return replace(self, terms=terms)


@dataclass(frozen=True)
class TermSet:
    """The variables of one YAML file."""

    variables: tuple[Variable, ...]
    path: str | None = None

    def variable(self, name: str, span: Span | None = None) -> Variable:
        for v in self.variables:
            if v.name == name:
                return v
        raise unknown("variable", name, [v.name for v in self.variables], span=span)


#: The least width of a universe: across a narrower one every edge is steeper than the
#: kernel's vertical edge (:data:`~mitos_cli.fuzzy.shapes.STEEP`), so every term is 1 on both
#: sides of it. (A term's own edge may be that narrow: it is a vertical edge, evaluated as one.)
TINY = 1.0 / STEEP


def universe_problem(lo: float, hi: float) -> tuple[str, str] | None:
    """What is wrong with a universe ``[lo, hi]`` and what to do, if anything: empty, or too
    narrow to compute with (a subnormal width: every slope across it overflows)."""
    if not lo < hi:
        return (f"universe [{lo:g}, {hi:g}] is empty",
                "write `universe: [min, max]` with min < max")
    if hi - lo < TINY:
        return (f"universe [{lo:g}, {hi:g}] is too narrow to compute with (at least {TINY:g} "
                "wide)", "measure the variable in a smaller unit")
    return None


def check_term(term: Term, universe: tuple[float, float], variable: str,
               peak_inside: bool = True) -> None:
    """Raise :class:`TermSetError` when ``term`` is malformed for its variable.

    A piecewise-linear term must reach 1 somewhere inside the universe (its core may stick
    out, as MATLAB's shower example's shoulders do); with ``peak_inside`` (outputs) its crisp
    value must lie inside too. Smooth shapes (bells, sigmoids) may peak outside.
    """
    problem = term.kind.check(term.params)
    if problem:
        raise TermSetError(f"term `{variable}.{term.name}`: {problem}", span=term.span)
    lo, hi = universe
    corners = term.corners
    if corners is not None and (corners[2] < lo or corners[1] > hi):
        where = (f"its peak {exact(corners[1])}" if corners[1] == corners[2]
                 else f"its core [{exact(corners[1])}, {exact(corners[2])}]")
        raise TermSetError(
            f"term `{variable}.{term.name}`: {where} lies outside the universe "
            f"[{exact(lo)}, {exact(hi)}]", span=term.span,
            hint="move the term or widen the variable's universe")
    if not peak_inside:
        return
    center = term.center          # NaN for a linear (Takagi-Sugeno) consequent: no peak
    if not np.isnan(center) and not lo <= center <= hi:
        raise TermSetError(
            f"term `{variable}.{term.name}`: its peak {exact(center)} lies outside the "
            f"universe [{exact(lo)}, {exact(hi)}]", span=term.span,
            hint="move the term or widen the variable's universe")
