"""Reading term sets from YAML.

A term set file holds ``variables:``; each variable has ``role``, ``universe``, ``terms`` and
optionally ``description``, ``unit`` and (outputs) ``default`` and ``resolution`` (a Mamdani
output's own sample points, where they differ from its behavior's). A term is a mapping naming its
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

Output terms may also be Takagi-Sugeno consequents: ``{shape: constant, value: 90}`` (the
same as a bare number) or ``{shape: linear, coefficients: {road: 0.5, size: -1}, constant:
90}``, i.e. ``y = 0.5 road - size + 90``; coefficients name input variables of this term set
(missing ones are 0) and are stored in the layout of :data:`mitos_cli.fuzzy.shapes.LINEAR_LAYOUT`.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

from ..errors import Span, TermSetError, did_you_mean
from ..fuzzy.formula import parse as parse_formula
from ..fuzzy.hedges import HEDGES
from ..fuzzy.shapes import SHAPES
from ..numbers import LARGEST, exact
from ..words import plural
from . import yamlpos
from .operators import RESOLUTION
from .terms import Term, TermSet, Variable, check_term, invisible_name, universe_problem
from .yamlpos import YList, YMap

VARIABLE_KEYS = ("description", "unit", "role", "universe", "terms", "default", "resolution")
TRIANGLE_FORMS = {
    ("points",): "triangle",
    ("peak", "width"): "triangle_pw",
    ("left_width", "peak", "right_width"): "triangle_plr",
}
USER_SHAPES = sorted({"triangle", "trapezoid", "left_shoulder", "right_shoulder", "singleton",
                      "constant", "linear"}
                     | {n for n in SHAPES if not n.startswith("triangle_")})
ALIASES = {"constant": "singleton"}     # Takagi-Sugeno's name for a crisp consequent


def load_termset(path: str | Path) -> TermSet:
    """Read and validate the term set at ``path``."""
    from ..fileio import bad_byte, not_text, read_text, text_encoding_hint, unreadable

    path = Path(path)
    try:
        text = read_text(path)
    except OSError as exc:
        raise TermSetError(unreadable("term set", path, exc)) from None
    except UnicodeDecodeError as exc:
        raise TermSetError(not_text(path, exc), span=bad_byte(path, exc),
                           hint=text_encoding_hint(exc)) from None
    return parse_termset(text, str(path))


def parse_termset(text: str, path: str | None = None) -> TermSet:
    """Build a :class:`TermSet` from YAML ``text``.

    A rule file names its term sets, and a rule file may come from someone else: until
    ``path`` is known to hold a term set (it is named ``.yaml`` / ``.yml``, or it is a YAML
    mapping with a ``variables:`` key) an error quotes nothing of it, so that ``terms
    "/etc/shadow"`` cannot print a line of a file the user can read (nor a link named
    ``x.yaml`` to it: the name its links lead to counts too).
    """
    from ..fileio import named_yaml

    named = path is None or named_yaml(path)
    try:
        data = yamlpos.load(text, path, TermSetError)
    except TermSetError:
        if named:
            raise
        data = None
    if not named and not (isinstance(data, YMap) and "variables" in data):
        raise TermSetError(f"`{path}` is not a term set", span=Span(path, 1, 1),
                           expected="a YAML file with a `variables:` key",
                           hint="term sets are named NAME.terms.yaml; check the `terms` line "
                                "of the rule file") from None
    top = Span.in_text(text, path, 1, 1)
    if not isinstance(data, YMap):
        raise TermSetError("a term set must be a mapping with a `variables:` key", span=top)
    other = _other_kind(data)
    if other is not None:
        raise TermSetError(f"`{path}` is {other[0]}, not a term set", span=top,
                           expected="a YAML file with a `variables:` key", hint=other[1])
    yamlpos.check_keys(data, ("variables",), TermSetError, "the term set")
    variables = yamlpos.require(data, "variables", TermSetError, "the term set")
    variables = yamlpos.expect_map(variables, data.value_span("variables"), TermSetError,
                                   "`variables`")
    inputs = tuple(name for name, spec in variables.items()
                   if isinstance(spec, YMap) and spec.get("role") == "input")
    out = tuple(_variable(name, spec, variables.key_span(name), variables.value_span(name),
                          inputs)
                for name, spec in variables.items())
    if not out:
        raise TermSetError("the term set defines no variables", span=data.span)
    return TermSet(out, path)


#: The keys that tell a world file or a map's YAML, named where a term set was expected.
_OTHER_KINDS = (
    (("q_init", "q_goal", "obstacles", "robots", "robot", "sensors"), "a world file",
     "`mitos simulate` reads worlds; a term set is a mapping with a `variables:` key"),
    (("image", "resolution", "origin", "occupied_thresh"), "a map's YAML (ROS map_server)",
     "a world names it under `map:`; a term set is a mapping with a `variables:` key"),
)


def _other_kind(data: YMap) -> tuple[str, str] | None:
    """What a YAML mapping without ``variables`` is instead (a world, a map), with a hint:
    "unknown key `name` in the term set" said nothing of what the file was."""
    if "variables" in data:
        return None
    for keys, what, hint in _OTHER_KINDS:
        if any(k in data for k in keys):
            return what, hint
    return None


#: a name a rule can write (the rule language's NAME)
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_\-]*[A-Za-z0-9_]|[A-Za-z_]")


def _writable(name: Any, span: Span, what: str) -> None:
    """Refuse a name no rule could write (docs/language.md, "Words and names"): characters
    the rule language's names do not take (`a.b`, `1x`), a hedge or `not` (`x is very` reads
    a hedge before a term). Such a name was read, and every rule naming it was a syntax error
    in the rule file."""
    text = str(name)
    if _NAME.fullmatch(text) and text not in HEDGES and text != "not":
        return
    invisible_name(text, span, what)          # said by its code point: it shows as nothing
    why = ("is a hedge word" if text in HEDGES else "is a keyword" if text == "not" else
           "holds what a name in a rule cannot (letters, digits, `_` and `-`, starting with a "
           "letter or `_`)")
    raise TermSetError(f"{what} {why}, so no rule could name it", span=span, hint="rename it")


def _variable(name: str, spec: Any, key_span: Span, value_span: Span,
              inputs: tuple[str, ...] = ()) -> Variable:
    what = f"variable `{name}`"
    _writable(name, key_span, what)
    spec = yamlpos.expect_map(spec, value_span, TermSetError, what)
    yamlpos.check_keys(spec, VARIABLE_KEYS, TermSetError, what)
    role = yamlpos.require(spec, "role", TermSetError, what)
    if role not in ("input", "output"):
        raise TermSetError(f"{what}: role must be `input` or `output`, not "
                           f"{yamlpos.as_written(role, spec.value_span('role'))}",
                           span=spec.value_span("role"), hint=did_you_mean(str(role),
                                                                         ["input", "output"]))
    universe = yamlpos.require(spec, "universe", TermSetError, what)
    uspan = spec.value_span("universe")
    if not isinstance(universe, YList) or len(universe) != 2:
        raise TermSetError(f"{what}: universe must be `[min, max]`", span=uspan)
    lo, hi = (_number(v, universe.item_span(i), f"{what}: universe bound")
              for i, v in enumerate(universe))
    problem = universe_problem(lo, hi)
    if problem:
        raise TermSetError(f"{what}: {problem[0]}", span=uspan, hint=problem[1])
    terms_spec = yamlpos.expect_map(yamlpos.require(spec, "terms", TermSetError, what),
                                    spec.value_span("terms"), TermSetError, f"{what}: terms")
    terms = tuple(_term(tname, tspec, terms_spec.key_span(tname), terms_spec.value_span(tname),
                        name, inputs) for tname, tspec in terms_spec.items())
    if not terms:
        raise TermSetError(f"{what} has no terms", span=spec.value_span("terms"))
    if role == "input":
        for term in terms:
            if term.shape == "linear":
                raise TermSetError(f"term `{name}.{term.name}`: a linear term is a Takagi-Sugeno "
                                   f"consequent and belongs to an output variable",
                                   span=term.span, hint="give input terms a membership shape "
                                   "(triangle, trapezoid, left_shoulder, ...)")
    for term in terms:
        # an input term may peak outside the universe (a shoulder seen from inside it, as
        # MATLAB and fuzzylite files often have); an output's crisp value may not
        check_term(term, (lo, hi), name, peak_inside=role == "output")
    default = None
    if "default" in spec:
        if role != "output":
            raise TermSetError(f"{what}: only outputs take a `default`",
                               span=spec.key_span("default"))
        value = spec["default"]
        if isinstance(value, float) and value != value:
            default = value            # `default: .nan`: no rule fired means NaN, as asked
        else:
            default = _number(value, spec.value_span("default"), f"{what}: default")
        if default == default and not lo <= default <= hi:
            raise TermSetError(f"{what}: default {exact(default)} lies outside the universe "
                               f"[{exact(lo)}, {exact(hi)}]", span=spec.value_span("default"))
    text_of = {k: spec.get(k, "") for k in ("description", "unit")}
    for key, value in text_of.items():
        if not isinstance(value, (str, int, float)):
            raise TermSetError(f"{what}: {key} must be text", span=spec.value_span(key))
    return Variable(name, role, (lo, hi), terms, str(text_of["description"]),
                    str(text_of["unit"]), default, key_span,
                    _resolution(spec, role, what) if "resolution" in spec else None)


def _resolution(spec: YMap, role: str, what: str) -> int:
    """An output's own ``resolution:`` (its Mamdani sample points), checked at its place."""
    if role != "output":
        raise TermSetError(f"{what}: only outputs take a `resolution` (an input is not "
                           f"sampled)", span=spec.key_span("resolution"))
    value, lo, hi = spec["resolution"], *RESOLUTION
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not (
            float(value).is_integer() and lo <= value <= hi):
        raise TermSetError(f"{what}: resolution must be a whole number from {lo} to {hi}, not "
                           f"{value!r}", span=spec.value_span("resolution"),
                           hint="the points its Mamdani output is sampled at, e.g. "
                                "`resolution: 1001`")
    return int(value)


def _term(name: str, spec: Any, key_span: Span, value_span: Span, variable: str,
          inputs: tuple[str, ...] = ()) -> Term:
    what = f"term `{variable}.{name}`"
    _writable(name, key_span, what)
    if isinstance(spec, (int, float)) and not isinstance(spec, bool):
        value = _number(spec, value_span, what)
        return Term(name, "singleton", (value,), key_span)
    spec = yamlpos.expect_map(spec, value_span, TermSetError, what)
    shape = yamlpos.require(spec, "shape", TermSetError, what)
    if shape not in USER_SHAPES:
        raise TermSetError(f"{what}: unknown shape `{shape}`", span=spec.value_span("shape"),
                           expected="one of " + ", ".join(USER_SHAPES),
                           hint=did_you_mean(str(shape), USER_SHAPES))
    frozen = _flag(spec, "frozen", False, what,
                   "`frozen: true` keeps adaptation from moving the term")
    held, held_at = _held(spec, what)
    if shape == "linear":
        return _linear_term(what, name, spec, key_span, frozen, inputs)
    if shape == "formula":
        return _formula_term(what, name, spec, key_span, frozen)
    given = tuple(sorted(k for k in spec if k not in ("shape", "frozen", "held")))
    if shape == "triangle":
        yamlpos.check_keys(spec, ("shape", "frozen", "held", "points", "peak", "width",
                                  "left_width", "right_width"), TermSetError, what)
        internal = TRIANGLE_FORMS.get(given)
        if internal is None:
            raise TermSetError(f"{what}: a triangle takes `points: [a, b, c]`, or `peak` and "
                               f"`width`, or `peak`, `left_width` and `right_width`",
                               span=spec.span)
    else:
        internal = ALIASES.get(shape, shape)
    kind = SHAPES[internal]
    if given == ("points",):
        points = spec["points"]
        pspan = spec.value_span("points")
        if kind.variadic and isinstance(points, YList):      # discrete: x1, y1, ..., xn, yn
            pass
        elif not isinstance(points, YList) or len(points) != len(kind.params):
            raise TermSetError(f"{what}: `points` must list {plural(len(kind.params), 'number')} "
                               f"({', '.join(kind.params)})", span=pspan)
        params = tuple(_number(v, points.item_span(i), f"{what}: point")
                       for i, v in enumerate(points))
    else:
        allowed = ("shape", "frozen", "held", "points") + kind.params
        yamlpos.check_keys(spec, allowed, TermSetError, what)
        for p in kind.params:
            yamlpos.require(spec, p, TermSetError, what)
        params = tuple(_number(spec[p], spec.value_span(p), f"{what}: {p}")
                       for p in kind.params)
    problem = kind.check(params)
    if problem:                 # at the value at fault, where the check names one
        at = next((spec.value_span(p) for p in kind.params
                   if p in spec and problem.startswith(f"{p} ")), None)
        if at is None and "points" in spec:
            at = spec.value_span("points")
        raise TermSetError(f"{what}: {problem}", span=at or key_span)
    return Term(name, internal, params, key_span, frozen, held, held_at)


def _number(value: Any, span: Span, what: str) -> float:
    """``value`` as a finite float within ±:data:`~mitos_cli.numbers.LARGEST`, as the foreign
    readers take numbers: beyond it a universe's width, a Mamdani grid's step or a weighted
    average's sum overflows to ``inf`` or ``nan`` with nothing said."""
    number = yamlpos.expect_number(value, span, TermSetError, what,
                                   units="a term set's numbers are in its variable's `unit`")
    if abs(number) > LARGEST:
        raise TermSetError(f"{what} is {exact(number)}: numbers beyond ±{LARGEST:g} cannot be "
                           "evaluated in floating point without overflow", span=span,
                           hint="measure the variable in a larger unit")
    return number


def _held(spec: YMap, what: str) -> tuple[bool, float | None]:
    """``held``: true (the default: a centre term stays on its point of symmetry), false (it
    may move), or the point it is held at (a number: ``held: 90``)."""
    value = spec.get("held", True)
    if isinstance(value, bool):
        return value, None
    if isinstance(value, (int, float)) and math.isfinite(value):
        return True, float(value)
    raise TermSetError(f"{what}: `held` must be true, false or the point the term is held at, "
                       f"not {yamlpos.as_written(value, spec.value_span('held'))}",
                       span=spec.value_span("held"),
                       hint="`held: false` lets adaptation move a centre term off its point")


def _flag(spec: YMap, key: str, default: bool, what: str, hint: str) -> bool:
    """A yes/no key of a term: YAML's `true`/`false` only, since `"no"` would be truthy."""
    value = spec.get(key, default)
    if not isinstance(value, bool):
        raise TermSetError(f"{what}: `{key}` must be true or false, not "
                           f"{yamlpos.as_written(value, spec.value_span(key))}",
                           span=spec.value_span(key), hint=hint)
    return value


def _linear_term(what: str, name: str, spec: YMap, key_span: Span, frozen: bool,
                 inputs: tuple[str, ...]) -> Term:
    """``{shape: linear, coefficients: {road: 0.5}, constant: 90}`` -> params
    ``(c_1, ..., c_k, constant)`` over ``inputs`` (the term set's input variables)."""
    yamlpos.check_keys(spec, ("shape", "frozen", "coefficients", "constant"), TermSetError, what)
    constant = _number(yamlpos.require(spec, "constant", TermSetError, what),
                       spec.value_span("constant"), f"{what}: constant")
    coefficients = dict.fromkeys(inputs, 0.0)
    if "coefficients" in spec:
        given = yamlpos.expect_map(spec["coefficients"], spec.value_span("coefficients"),
                                   TermSetError, f"{what}: coefficients")
        for var, value in given.items():
            if var not in coefficients:
                raise TermSetError(f"{what}: `{var}` is not an input variable of this term set",
                                   span=given.key_span(var),
                                   expected="one of " + ", ".join(inputs) if inputs else None,
                                   hint=did_you_mean(var, inputs))
            coefficients[var] = _number(value, given.value_span(var), f"{what}: coefficient")
    return Term(name, "linear", tuple(coefficients.values()) + (constant,), key_span, frozen)


def _formula_term(what: str, name: str, spec: YMap, key_span: Span, frozen: bool) -> Term:
    """``{shape: formula, formula: "1 / (1 + x^2)"}``: a membership function of ``x``."""
    yamlpos.check_keys(spec, ("shape", "formula", "frozen"), TermSetError, what)
    text = yamlpos.require(spec, "formula", TermSetError, what)
    if not isinstance(text, str):
        raise TermSetError(f"{what}: `formula` must be a text, e.g. \"1 / (1 + x^2)\"",
                           span=spec.value_span("formula"))
    formula = parse_formula(text, spec.value_span("formula"), TermSetError)
    return Term(name, "formula", (), key_span, frozen, formula=formula)

