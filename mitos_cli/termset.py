"""Reading term sets from YAML.

A term set file holds ``variables:``; each variable has ``role``, ``universe``, ``terms`` and
optionally ``description``, ``unit`` and (outputs) ``default``. A term is a mapping naming its
``shape`` and parameters, or a bare number for a crisp output value::

    variables:
      road:
        description: width of the road ahead (x1)
        unit: in
        role: input
        universe: [0, 160]
        terms:
          NARROW: {shape: left_shoulder, points: [40, 70]}
          MEDIUM: {shape: triangle, peak: 70, width: 30}     # the paper's eq. 15
          WIDE:   {shape: right_shoulder, points: [70, 100]}
      steering:
        role: output
        universe: [30, 150]
        default: 90
        terms: {LB: 30, LM: 50, LS: 70, ST: 90, RS: 110, RM: 130, RB: 150}
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from . import yamlpos
from .errors import Span, TermSetError, did_you_mean
from .shapes import SHAPES
from .terms import Term, TermSet, Variable, check_term
from .yamlpos import YList, YMap

VARIABLE_KEYS = ("description", "unit", "role", "universe", "terms", "default")
TRIANGLE_FORMS = {
    ("points",): "triangle",
    ("peak", "width"): "triangle_pw",
    ("left_width", "peak", "right_width"): "triangle_plr",
}
USER_SHAPES = sorted({"triangle", "trapezoid", "left_shoulder", "right_shoulder", "singleton"}
                     | {n for n in SHAPES if not n.startswith("triangle_")})


def load_termset(path: str | Path) -> TermSet:
    """Read and validate the term set at ``path``."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise TermSetError(f"cannot read term set `{path}`: {exc.__class__.__name__}: "
                           f"{getattr(exc, 'strerror', None) or exc}") from None
    return parse_termset(text, str(path))


def parse_termset(text: str, path: str | None = None) -> TermSet:
    """Build a :class:`TermSet` from YAML ``text``."""
    data = yamlpos.load(text, path, TermSetError)
    top = Span.in_text(text, path, 1, 1)
    if not isinstance(data, YMap):
        raise TermSetError("a term set must be a mapping with a `variables:` key", span=top)
    yamlpos.check_keys(data, ("variables",), TermSetError, "the term set")
    variables = yamlpos.require(data, "variables", TermSetError, "the term set")
    variables = yamlpos.expect_map(variables, data.value_span("variables"), TermSetError,
                                   "`variables`")
    out = tuple(_variable(name, spec, variables.key_span(name), variables.value_span(name))
                for name, spec in variables.items())
    if not out:
        raise TermSetError("the term set defines no variables", span=data.span)
    return TermSet(out, path)


def _variable(name: str, spec: Any, key_span: Span, value_span: Span) -> Variable:
    what = f"variable `{name}`"
    spec = yamlpos.expect_map(spec, value_span, TermSetError, what)
    yamlpos.check_keys(spec, VARIABLE_KEYS, TermSetError, what)
    role = yamlpos.require(spec, "role", TermSetError, what)
    if role not in ("input", "output"):
        raise TermSetError(f"{what}: role must be `input` or `output`, not `{role}`",
                           span=spec.value_span("role"), hint=did_you_mean(str(role),
                                                                         ["input", "output"]))
    universe = yamlpos.require(spec, "universe", TermSetError, what)
    uspan = spec.value_span("universe")
    if not isinstance(universe, YList) or len(universe) != 2:
        raise TermSetError(f"{what}: universe must be `[min, max]`", span=uspan)
    lo, hi = (yamlpos.expect_number(v, universe.item_span(i), TermSetError,
                                    f"{what}: universe bound") for i, v in enumerate(universe))
    if not lo < hi:
        raise TermSetError(f"{what}: universe [{lo:g}, {hi:g}] is empty", span=uspan,
                           hint="write `universe: [min, max]` with min < max")
    terms_spec = yamlpos.expect_map(yamlpos.require(spec, "terms", TermSetError, what),
                                    spec.value_span("terms"), TermSetError, f"{what}: terms")
    terms = tuple(_term(tname, tspec, terms_spec.key_span(tname), terms_spec.value_span(tname),
                        name) for tname, tspec in terms_spec.items())
    if not terms:
        raise TermSetError(f"{what} has no terms", span=spec.value_span("terms"))
    for term in terms:
        check_term(term, (lo, hi), name)
    default = None
    if "default" in spec:
        if role != "output":
            raise TermSetError(f"{what}: only outputs take a `default`",
                               span=spec.key_span("default"))
        default = yamlpos.expect_number(spec["default"], spec.value_span("default"),
                                        TermSetError, f"{what}: default")
        if not lo <= default <= hi:
            raise TermSetError(f"{what}: default {default:g} lies outside the universe "
                               f"[{lo:g}, {hi:g}]", span=spec.value_span("default"))
    text_of = {k: spec.get(k, "") for k in ("description", "unit")}
    for key, value in text_of.items():
        if not isinstance(value, (str, int, float)):
            raise TermSetError(f"{what}: {key} must be text", span=spec.value_span(key))
    return Variable(name, role, (lo, hi), terms, str(text_of["description"]),
                    str(text_of["unit"]), default, key_span)


def _term(name: str, spec: Any, key_span: Span, value_span: Span, variable: str) -> Term:
    what = f"term `{variable}.{name}`"
    if isinstance(spec, (int, float)) and not isinstance(spec, bool):
        value = yamlpos.expect_number(spec, value_span, TermSetError, what)
        return Term(name, "singleton", (value,), key_span)
    spec = yamlpos.expect_map(spec, value_span, TermSetError, what)
    shape = yamlpos.require(spec, "shape", TermSetError, what)
    if shape not in USER_SHAPES:
        raise TermSetError(f"{what}: unknown shape `{shape}`", span=spec.value_span("shape"),
                           expected="one of " + ", ".join(USER_SHAPES),
                           hint=did_you_mean(str(shape), USER_SHAPES))
    frozen = bool(spec.get("frozen", False))
    given = tuple(sorted(k for k in spec if k not in ("shape", "frozen")))
    if shape == "triangle":
        internal = TRIANGLE_FORMS.get(given)
        if internal is None:
            raise TermSetError(f"{what}: a triangle takes `points: [a, b, c]`, or `peak` and "
                               f"`width`, or `peak`, `left_width` and `right_width`",
                               span=spec.span)
    else:
        internal = shape
    kind = SHAPES[internal]
    if given == ("points",):
        points = spec["points"]
        pspan = spec.value_span("points")
        if not isinstance(points, YList) or len(points) != len(kind.params):
            raise TermSetError(f"{what}: `points` must list {len(kind.params)} numbers "
                               f"({', '.join(kind.params)})", span=pspan)
        params = tuple(yamlpos.expect_number(v, points.item_span(i), TermSetError,
                                             f"{what}: point") for i, v in enumerate(points))
    else:
        allowed = ("shape", "frozen", "points") + kind.params
        yamlpos.check_keys(spec, allowed, TermSetError, what)
        for p in kind.params:
            yamlpos.require(spec, p, TermSetError, what)
        params = tuple(yamlpos.expect_number(spec[p], spec.value_span(p), TermSetError,
                                             f"{what}: {p}") for p in kind.params)
    return Term(name, internal, params, key_span, frozen)
