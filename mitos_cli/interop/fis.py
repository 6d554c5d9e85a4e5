"""MATLAB Fuzzy Logic Toolbox ``.fis`` files: reader and writer.

A ``.fis`` file is INI-like: ``[System]``, ``[Input1]`` ... ``[Output1]`` ... sections of
``Key=value`` lines, then ``[Rules]`` with one line per rule in index form::

    1 1, 1 (1) : 1      # input MF indices, output MF indices (weight) : 1 = AND, 2 = OR

Index 0 means "not in this rule"; a negative input index means NOT (``1 - mu``). The format is
not a language, so it is read line by line; every line keeps its number for errors.

Mapping: ``trimf trapmf gaussmf gauss2mf gbellmf sigmf dsigmf psigmf pimf smf zmf linsmf linzmf
constant linear``, and the types fuzzylite's exporter adds (``rampmf cosinemf discretemf spikemf
concavemf rectmf binarymf``, read as its terms); ``and``: min, prod; ``or``: max, probor;
``imp``: min, prod; ``agg``: max, probor (``sum`` is refused); defuzzifiers centroid, bisector,
mom, som, lom (Mamdani; bisector, som and lom as MATLAB defines them, ``matlab_*``) and
wtaver, wtsum (Sugeno). When no rule fires MATLAB returns the middle
of the output range (with a warning); the reader makes that the output's ``default``. An
antecedent's fractional MF index is Octave's hedge (``-2.3``: not extremely MF 2; ``.05 .2 .3
.4``: somewhat, very, extremely, very very). Custom MF functions, other fractions, and negative
or fractional output indices (complemented or hedged consequents) are refused.

Resolution: MATLAB's ``evalfis`` samples a Mamdani output at 101 evenly spaced points from the
range's minimum to its maximum; the reader sets ``resolution = 101, sampling = endpoints``, which
reproduces MATLAB's documented outputs (``docs/conformance.md``). The writer cannot record
another resolution or sampling: a ``.fis`` file always means MATLAB's.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections import Counter
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, cast

from ..errors import FormatError, Span, did_you_mean, lines_of
from ..fuzzy.shapes import TSUKAMOTO
from ..lang.bulk import without_cyclic_gc
from ..lang.model import And, Consequent, Or, Prop, Rule, RuleBase, Setting
from ..lang.terms import Role, Term, Variable
from ..words import plural
from . import common
from .common import FIS, Settings, fmt_number
from .text import read_foreign_file

if TYPE_CHECKING:
    from collections.abc import Sequence

    #: a ``key=value`` line of a section: key, value, the line's span and the value's
    Item = tuple[str, str, Span, Span]
    #: a ``[Section]``: its name, its span and its lines
    Section = tuple[str, Span, list[Item]]

DEFAULT_RESOLUTION = 101

#: MATLAB MF type -> (MITOS shape, param count, MATLAB order -> MITOS order)
MF_TYPES = {
    "trimf": ("triangle", 3, (0, 1, 2)),
    "trapmf": ("trapezoid", 4, (0, 1, 2, 3)),
    "gaussmf": ("gaussian", 2, (1, 0)),                   # [sigma c]
    "gauss2mf": ("gaussian2", 4, (1, 0, 3, 2)),           # [sig1 c1 sig2 c2]
    "gbellmf": ("bell", 3, (2, 0, 1)),                    # [a b c] = width, slope, center
    "sigmf": ("sigmoid", 2, (1, 0)),                      # [a c] = slope, inflection
    "dsigmf": ("sigmoid_difference", 4, (1, 0, 2, 3)),    # [a1 c1 a2 c2]
    "psigmf": ("sigmoid_product", 4, (1, 0, 2, 3)),
    "pimf": ("pi_shape", 4, (0, 1, 2, 3)),
    "smf": ("s_shape", 2, (0, 1)),
    "zmf": ("z_shape", 2, (0, 1)),
    "linsmf": ("ramp", 2, (0, 1)),
    "linzmf": ("ramp", 2, (1, 0)),
    "constant": ("singleton", 1, (0,)),
}
#: fuzzylite's own MF types in the ``.fis`` files it writes (its ``FisExporter``): its terms,
#: with the parameters in the order of its ``.fll`` (``FisImporter``)
FUZZYLITE_MF_TYPES = {"binarymf": "Binary", "concavemf": "Concave", "cosinemf": "Cosine",
                      "discretemf": "Discrete", "rampmf": "Ramp", "rectmf": "Rectangle",
                      "spikemf": "Spike"}
#: the weighted systems: MATLAB's Sugeno, and fuzzylite's exporter's name for Tsukamoto
WEIGHTED_TYPES = ("sugeno", "tsukamoto")
#: output MFs Tsukamoto inference inverts, as fuzzylite names them in a .fis file
MONOTONIC_MFS = ("rampmf", "sigmf", "smf", "zmf", "concavemf")
#: MATLAB's evalfis defines these its own way (its bisector is the first sample whose running
#: area reaches half, its som and lom are by absolute value): a .fis file means MATLAB's
MATLAB_DEFUZZIFIERS = {"bisector": "matlab_bisector", "som": "matlab_som", "lom": "matlab_lom"}
SYSTEM_KEYS = ("Name", "Type", "Version", "NumInputs", "NumOutputs", "NumRules", "AndMethod",
               "OrMethod", "ImpMethod", "AggMethod", "DefuzzMethod",
               "DisableStructuralChecks")     # MATLAB R2018b+; only affects MATLAB's editor
#: fuzzylite's exporter adds Enabled=1, and on outputs Default=, LockPrevious=, LockRange=
VAR_KEYS = ("Name", "Range", "NumMFs", "Enabled", "Default", "LockPrevious", "LockRange")


def read_fis(path: str | Path) -> RuleBase:
    return read_foreign_file(Path(path), parse_fis)


def _sections(text: str, path: str | None) -> tuple[list[Section], list[tuple[str, int, Span]]]:
    """``[(name, span, [(key, value, span, vspan), ...]), ...]`` and the rule lines."""
    sections: list = []
    rules: list = []
    for lineno, raw in enumerate(lines_of(text), 1):
        line = raw.strip()
        if not line or line[0] in "%#":         # MATLAB's readfis skips % and # comment lines
            continue
        span = Span.in_text(text, path, lineno, len(raw) - len(raw.lstrip()) + 1,
                            len(raw.rstrip()) + 1)
        if line.startswith("[") and line.endswith("]"):
            name = line[1:-1].strip()
            if name not in ("System", "Rules") and not re.fullmatch(r"(Input|Output)\d{1,9}",
                                                                    name):
                raise FormatError(f"unknown section [{name}]", span=span,
                                  expected="[System], [InputN], [OutputN] or [Rules]",
                                  hint=did_you_mean(name, ("System", "Rules", "Input1",
                                                           "Output1")))
            sections.append((name, span, []))
            continue
        if not sections:
            raise FormatError("expected a section header such as `[System]`", span=span)
        if sections[-1][0] == "Rules":
            rules.append((line, lineno, span))
            continue
        key, sep, value = line.partition("=")
        if not sep:
            raise FormatError(f"expected `Key=value`, not `{line}`", span=span)
        col = raw.index("=") + 2
        vspan = Span.in_text(text, path, lineno, col, len(raw.rstrip()) + 1)
        sections[-1][2].append((key.strip(), value.strip(), span, vspan))
    return sections, rules


def _string(value: str, vspan: Span) -> str:
    if len(value) >= 2 and value[0] == value[-1] == "'":
        return value[1:-1]
    raise FormatError(f"expected a quoted text ('...'), not `{value}`", span=vspan)


def _vector(value: str, vspan: Span) -> list[float]:
    value = value.strip()
    if not (value.startswith("[") and value.endswith("]")):
        raise FormatError(f"expected numbers in brackets ([a b c]), not `{value}`", span=vspan)
    return [common.number(w, vspan) for w in value[1:-1].replace(",", " ").split()]


#: fuzzylite writes an engine of Mamdani and Takagi-Sugeno outputs as `Type='hybrid'`, which
#: MATLAB refuses and which keeps one defuzzifier for both kinds (fuzzylite 6 reads it back with
#: a centroid over the constant terms too, and so writes it to FLL); the FLL the engine was
#: written from keeps each output's, and MITOS reads that as one behavior per rule block.
HYBRID_HINT = ("a .fis keeps one defuzzifier for both kinds of output; read the engine from "
               "the FLL it was written from (fuzzylite's examples ship one beside each .fis), "
               "whose rule blocks MITOS reads as behaviors")


@without_cyclic_gc
def parse_fis(text: str, path: str | None = None) -> RuleBase:
    """Read ``.fis`` text into a rule base (one behavior, ``main``)."""
    sections, rule_lines = _sections(text, path)
    by_kind = {name: (span, items) for name, span, items in sections}
    if "System" not in by_kind:
        raise FormatError("the file has no [System] section",
                          span=Span.in_text(text, path, 1, 1))
    sys_span, sys_items = by_kind["System"]
    system = _system(sys_items)
    kind = _string(*system.get("Type", ("'mamdani'", sys_span))).lower()
    if kind not in ("mamdani", "sugeno", "tsukamoto"):
        hint = HYBRID_HINT if kind == "hybrid" else None
        raise FormatError(f"FIS type `{kind}` is not supported", span=system["Type"][1],
                          expected="mamdani or sugeno (or fuzzylite's tsukamoto)", hint=hint)
    settings, unset, sugeno = _settings(system, sys_span, kind)
    notes: list[str] = []
    ranges: common.Places = {}
    inputs = _variables(sections, "Input", "input", kind, notes, 0, ranges)
    n_inputs = len(inputs)
    outputs = _variables(sections, "Output", "output", kind, notes, n_inputs, ranges)
    _check_count(system, "NumInputs", len(inputs), sys_span)
    _check_count(system, "NumOutputs", len(outputs), sys_span)
    variables = inputs + outputs
    fuzzylites = bool(FUZZYLITE_EXPORT.match(text))
    read = [_rule(line, lineno, span, inputs, outputs, text, path, i, fuzzylites)
            for i, (line, lineno, span) in enumerate(rule_lines)]
    _check_count(system, "NumRules", len(read), sys_span)
    rules = [r for r in read if isinstance(r, Rule)]
    _unloaded_note([r for r in read if not isinstance(r, Rule)], rules, outputs, notes)
    _check_unset(unset, rules)
    if sugeno:
        _sugeno_aggregation(system, rules, notes)
        _tsukamoto(kind, outputs, settings, system, sys_span, notes)
    rb = common.assemble(path, variables, rules, settings, DEFAULT_RESOLUTION, sys_span, notes,
                         ranges)
    agg = system.get("AggMethod")                # Octave's toolkit uses it: RuleBase.unused
    unused = (Setting("AggMethod", name, agg[1]),) if sugeno and agg and (
        name := _string(*agg)) else ()
    return dataclasses.replace(rb, notes=tuple(notes), unused=unused)


def _system(items: list[Item]) -> dict[str, tuple[str, Span]]:
    """The [System] section's values (and their places) by key; an unknown key is refused."""
    system = {}
    for key, value, span, vspan in items:
        if key not in SYSTEM_KEYS:
            raise FormatError(f"unknown [System] key `{key}`", span=span,
                              expected="one of " + ", ".join(SYSTEM_KEYS),
                              hint=did_you_mean(key, SYSTEM_KEYS))
        system[key] = (value, vspan)
    return system


def _settings(system: dict[str, tuple[str, Span]], sys_span: Span,
              kind: str) -> tuple[Settings, dict[str, Span], bool]:
    """The operators the [System] section names (MATLAB's defaults for those it leaves out),
    where a method is written as ``''`` (fuzzylite writes that for an operator its rules
    never use), and whether the system is Takagi-Sugeno."""
    settings = Settings()
    unset: dict[str, Span] = {}

    def method(key: str, table: dict, what: str, default: str) -> str:
        value, vspan = system.get(key, (f"'{default}'", sys_span))
        name = _string(value, vspan)
        if not name:
            unset[key] = vspan
            return default
        return common.table_lookup(table, FIS, name, what, vspan)

    settings.set("and_", method("AndMethod", common.TNORMS, "AND method", "min"), None, "and")
    settings.set("or_", method("OrMethod", common.SNORMS, "OR method", "max"), None, "or")
    defuzz = method("DefuzzMethod", common.DEFUZZIFIERS, "defuzzification method",
                    "centroid" if kind == "mamdani" else "wtaver")
    sugeno = defuzz in ("weighted_average", "weighted_sum")
    if sugeno != (kind in WEIGHTED_TYPES):
        raise FormatError(f"defuzzification `{_string(*system['DefuzzMethod'])}` does not fit a "
                          f"{kind} system", span=system["DefuzzMethod"][1])
    settings.set("defuzzify", MATLAB_DEFUZZIFIERS.get(defuzz, defuzz), None, "defuzzifier")
    if not sugeno:        # MATLAB ignores ImpMethod / AggMethod for Sugeno systems
        settings.set("implication", common.check_implication(
            method("ImpMethod", common.TNORMS, "implication method", "min"),
            system.get("ImpMethod", ("", sys_span))[1]), None, "implication")
        settings.set("aggregation", method("AggMethod", common.AGGREGATIONS, "aggregation method",
                                           "max"), None, "aggregation")
        settings.set("resolution", DEFAULT_RESOLUTION, None, "resolution")
        settings.set("sampling", "endpoints", None, "sampling")
    return settings, unset, sugeno


def _tsukamoto(kind: str, outputs: list[Variable], settings: Settings,
               system: dict[str, tuple[str, Span]], sys_span: Span, notes: list[str]) -> None:
    """fuzzylite's reading of a weighted system whose outputs hold only monotonic terms
    (``rampmf``, ``sigmf``, ``smf``, ``zmf``, ``concavemf``): Tsukamoto inference, each term
    inverted at its activation. fuzzylite ignores ``Type`` and infers it from the terms; its
    exporter writes ``Type='tsukamoto'``. MATLAB has no such system."""
    monotonic = {v.name: all(t.shape in TSUKAMOTO for t in v.terms) for v in outputs}
    if kind != "tsukamoto" and not (outputs and all(monotonic.values())):
        if any(monotonic.values()):
            tsuk = next(n for n, m in monotonic.items() if m)
            other = next(v for v in outputs if not monotonic[v.name])
            term = next(t for t in other.terms if t.shape not in TSUKAMOTO)
            raise FormatError(f"output `{other.name}`'s MF `{term.name}` is a `{term.shape}` "
                              f"term, where `{tsuk}`'s are all monotonic (Tsukamoto): MITOS "
                              f"takes one inference per rule base", span=term.span,
                              hint="give every output monotonic MFs (rampmf, sigmf, smf, zmf, "
                                   "concavemf) or constant and linear ones")
        return                                    # Takagi-Sugeno
    if settings.defuzzify == "weighted_sum":
        raise FormatError("Tsukamoto inference with a weighted sum is not supported (MITOS's "
                          "Tsukamoto takes the weighted average)",
                          span=system.get("DefuzzMethod", ("", sys_span))[1],
                          hint="write DefuzzMethod='wtaver'")
    settings.defuzzify = "tsukamoto"
    if kind == "sugeno":                         # `Type='tsukamoto'` says so itself
        notes.append(f"{system['Type'][1]}: a Sugeno system whose outputs hold only monotonic "
                     f"MFs, read as fuzzylite reads it: Tsukamoto inference, each MF inverted "
                     f"where its rules' activation meets it (MATLAB refuses such a system)")
    for v in outputs:
        if any(t.shape == "sigmoid" for t in v.terms):
            notes.append(f"{v.span}: `{v.name}` inverts sigmf terms (Tsukamoto inference); a "
                         f"sigmoid reaches 1 only at infinity, so where a rule fires fully "
                         f"the output is +-inf, as in fuzzylite")


def _check_unset(unset: dict[str, Span], rules: list[Rule]) -> None:
    """``AndMethod=''`` (or ``OrMethod``) with a rule that joins its conditions so; in a
    Mamdani system, ``ImpMethod=''`` with any rule and ``AggMethod=''`` with two rules that
    set one output (where the method changes the number: one set joined with nothing is
    itself under any S-norm). Those two were read as MATLAB's defaults, min and max, without
    a word, where fuzzylite refuses to run an engine without them."""
    for key, connective in (("AndMethod", And), ("OrMethod", Or)):
        used = next((r for r in rules if isinstance(r.antecedent, connective)), None)
        if key in unset and used is not None:
            raise FormatError(f"{key}='' but rule {used.label} joins its conditions with "
                              f"{'AND' if connective is And else 'OR'}", span=used.span,
                              hint=f"give {key} a method, e.g. "
                                   f"'{'min' if connective is And else 'max'}'")
    if "ImpMethod" in unset and rules:
        rule = rules[0]
        raise FormatError(f"ImpMethod='' but rule {rule.label} concludes "
                          f"`{rule.consequents[0].var}`: a Mamdani system cuts each rule's set "
                          f"with its implication", span=unset["ImpMethod"],
                          hint="give ImpMethod a method, e.g. 'min' (MATLAB's default)")
    if "AggMethod" in unset:
        first: dict[str, Rule] = {}
        for rule in rules:
            for c in rule.consequents:
                if c.var in first and first[c.var] is not rule:
                    raise FormatError(
                        f"AggMethod='' but rules {first[c.var].label} and {rule.label} both set "
                        f"`{c.var}`: a Mamdani system joins their sets with its aggregation",
                        span=unset["AggMethod"],
                        hint="give AggMethod a method, e.g. 'max' (MATLAB's default)")
                first.setdefault(c.var, rule)


def _sugeno_aggregation(system: dict, rules: list[Rule], notes: list[str]) -> None:
    """A note where a Sugeno file's ``AggMethod`` changes its outputs in other engines: MATLAB
    (and MITOS) average every rule, Octave's toolkit and fuzzylite first take ``AggMethod``
    over the rules concluding one output term (docs/conformance.md, part 3)."""
    if "AggMethod" not in system:
        return
    value, vspan = system["AggMethod"]
    agg = _string(value, vspan)
    concluded = Counter((c.var, c.term) for r in rules for c in r.consequents)
    shared = [f"{v}.{t}" for (v, t), n in concluded.items() if n > 1]
    if agg in ("", "sum") or not shared:
        return
    notes.append(f"{vspan}: AggMethod='{agg}' in a Sugeno system: MITOS averages every rule's "
                 f"output as MATLAB does; Octave's toolkit and fuzzylite take the {agg} over "
                 f"the rules concluding one term first, so they differ where several do "
                 f"({', '.join(shared[:3])}{', ...' if len(shared) > 3 else ''})")



def _check_count(system: dict, key: str, found: int, span: Span) -> None:
    if key in system:
        value, vspan = system[key]
        if common.number(value, vspan) != found:
            raise FormatError(f"{key}={value} but the file has {found}", span=vspan)


def _variables(sections: list[Section], prefix: str, role: Role, kind: str, notes: list[str],
               n_inputs: int = 0, ranges: common.Places | None = None) -> list[Variable]:
    """The ``[PrefixN]`` sections' variables, in order; ``ranges``: gets where each one's
    range (and fuzzylite's ``Default``) is written."""
    found = [(int(name[len(prefix):]), span, items) for name, span, items in sections
             if re.fullmatch(prefix + r"\d{1,9}", name)]
    found.sort(key=lambda f: f[0])
    for i, (number, span, _) in enumerate(found, 1):
        if number != i:
            raise FormatError(f"expected [{prefix}{i}], found [{prefix}{number}]", span=span)
    return [_variable(span, items, role, kind, n_inputs, notes, ranges)
            for _, span, items in found]


def _variable(span: Span, items: list[Item], role: Role, kind: str, n_inputs: int,
              notes: list[str], ranges: common.Places | None = None) -> Variable:
    values = {}
    terms: list[Term] = []
    for key, value, kspan, vspan in items:
        if re.fullmatch(r"MF\d+", key):
            terms.append(_mf(value, vspan, role, kind, n_inputs))
        elif key == "Enabled":
            if value.strip() != "1":
                raise FormatError(f"`Enabled={value}`: MITOS has no disabled variables",
                                  span=vspan, hint="delete the variable or enable it")
        elif key == "LockPrevious" and value.strip() != "0":
            raise FormatError(f"`LockPrevious={value}` (keep the previous output when no rule "
                              f"fires) needs state between evaluations, which MITOS does not "
                              f"keep", span=vspan, hint="set `Default=` to the value to use")
        elif key in ("Default", "LockRange") and role != "output":
            raise FormatError(f"`{key}` belongs to outputs", span=kspan)
        elif key == "LockRange" and value.strip() != "0" and kind in WEIGHTED_TYPES:
            raise FormatError("`LockRange=1` on a Sugeno output (clipping the output to its "
                              "range) is not supported", span=vspan, hint="set LockRange=0")
        elif key in VAR_KEYS:
            values[key] = (value, vspan)
        else:
            raise FormatError(f"unknown key `{key}`", span=kspan,
                              expected="Name, Range, NumMFs or MFn",
                              hint=did_you_mean(key, VAR_KEYS))
    if "Name" not in values or "Range" not in values:
        raise FormatError("a variable needs `Name` and `Range`", span=span)
    name = _string(*values["Name"]).strip()   # `'User '` is `User`, as fuzzylite reads it
    terms = common.distinct_names(terms, name, notes, "rules refer to MFs by index, so "
                                  "nothing else changes")
    rng = _vector(*values["Range"])
    if len(rng) != 2 or not rng[0] < rng[1]:
        raise FormatError("`Range` must be [min max] with min < max", span=values["Range"][1])
    common.check_range(rng[0], rng[1], values["Range"][1], "Range")
    if ranges is not None:
        ranges[name, "range"] = values["Range"][1]
    if "NumMFs" in values and common.number(*values["NumMFs"]) != len(terms):
        raise FormatError(f"NumMFs={values['NumMFs'][0]} but the variable has {len(terms)} MFs",
                          span=values["NumMFs"][1])
    if not terms and role == "output":
        raise FormatError(f"output `{name}` has no membership functions", span=span)
    default = (rng[0] + rng[1]) / 2 if role == "output" else None     # MATLAB's choice
    if "Default" in values:                      # fuzzylite's: nan when the file says so
        default = common.number(*values["Default"])
        if ranges is not None:
            ranges[name, "default"] = values["Default"][1]
    try:
        return Variable(name, role, (rng[0], rng[1]), tuple(terms), "", "", default,
                        values["Name"][1])
    except Exception as exc:                     # duplicate terms: TermSetError with a span
        raise FormatError(getattr(exc, "message", str(exc)),
                          span=getattr(exc, "span", None) or span) from None


def _mf(value: str, vspan: Span, role: str, kind: str, n_inputs: int) -> Term:
    m = re.fullmatch(r"'([^']*)'\s*:\s*'([^']*)'\s*,\s*(\[.*\])", value.strip())
    if not m:
        raise FormatError("expected 'name':'type',[params]", span=vspan)
    if m.group(2) == "function":          # fuzzylite's .fis extension: a formula
        raise FormatError(f"MF `{m.group(1)}`: `function` MFs (fuzzylite's formula of the "
                          f"engine's variables, `{m.group(3)[1:-1].strip()}`) are not supported",
                          span=vspan)
    name, mf, params = m.group(1).strip(), m.group(2), _vector(m.group(3), vspan)
    if mf == "linear":
        if role != "output" or kind != "sugeno":
            raise FormatError(f"MF `{name}`: `linear` belongs to Sugeno outputs", span=vspan)
        if len(params) != n_inputs + 1:
            raise FormatError(f"MF `{name}`: linear takes {plural(n_inputs + 1, 'number')} (one "
                              f"per input and a constant), not {len(params)}", span=vspan)
        return common.make_term(name, "linear", tuple(params), vspan)
    if role == "output" and kind in WEIGHTED_TYPES and mf not in ("constant", *MONOTONIC_MFS):
        takes = ("only monotonic MFs" if kind == "tsukamoto" else
                 "`constant` or `linear` MFs, or only monotonic ones")
        raise FormatError(f"MF `{name}`: the outputs of a {kind.capitalize()}-type .fis take "
                          f"{takes} ({', '.join(MONOTONIC_MFS)}: fuzzylite's Tsukamoto "
                          f"inference), not `{mf}`", span=vspan)
    if mf in FUZZYLITE_MF_TYPES:
        return common.fuzzylite_term(name, FUZZYLITE_MF_TYPES[mf], params, n_inputs, vspan)
    if mf not in MF_TYPES:
        known = [*MF_TYPES, "linear", *FUZZYLITE_MF_TYPES]
        raise FormatError(f"MF `{name}`: membership function type `{mf}` is not supported",
                          span=vspan, expected="one of " + ", ".join(known),
                          hint=did_you_mean(mf, known))
    shape, count, order = MF_TYPES[mf]
    if len(params) > count and not any(params[count:]):
        params = params[:count]        # old MATLAB files pad every list with zeros to one length
    if len(params) != count:
        raise FormatError(f"MF `{name}`: {mf} takes {plural(count, 'number')}, not {len(params)}",
                          span=vspan)
    _check_linear_saturation(name, mf, params, vspan)
    step = _step(mf, params)
    if step is not None:
        return common.make_term(name, *step, vspan)
    return common.make_term(name, *common.shoulder(shape, tuple(params[i] for i in order)),
                            vspan)


def _check_linear_saturation(name: str, mf: str, params: list[float], span: Span) -> None:
    """MATLAB's ``linsmf [a b]`` rises from its foot ``a`` to its shoulder ``b`` and ``linzmf
    [a b]`` falls from ``a`` to ``b``, both defined for ``a <= b``. With ``a > b`` they were
    read as fuzzylite's ``Ramp``, whose direction is the order of its ends: a ``linsmf`` that
    falls, a ``linzmf`` that rises. ``linzmf [a a]``, MATLAB's step 1 below ``a`` and 0 from
    ``a`` on, has no MITOS shape (``binary`` is 1 at its own point)."""
    if mf not in ("linsmf", "linzmf"):
        return
    a, b = params
    if a > b:
        raise FormatError(f"MF `{name}`: {mf} takes [a b] with a <= b (it "
                          f"{'rises' if mf == 'linsmf' else 'falls'} from a to b), not "
                          f"[{fmt_number(a)} {fmt_number(b)}]", span=span,
                          hint=f"write the smaller end first: `linsmf [{fmt_number(b)} "
                               f"{fmt_number(a)}]` rises from {fmt_number(b)} to "
                               f"{fmt_number(a)}, `linzmf [{fmt_number(b)} {fmt_number(a)}]` "
                               f"falls")
    if mf == "linzmf" and a == b:
        raise FormatError(f"MF `{name}`: `linzmf [{fmt_number(a)} {fmt_number(b)}]` is MATLAB's "
                          f"step 1 below {fmt_number(a)} and 0 from {fmt_number(a)} on, which no "
                          f"MITOS shape computes exactly (a `binary` step is 1 at its own point)",
                          span=span, hint=f"write `zmf [{fmt_number(a)} {fmt_number(a)}]`, the "
                                          f"step 1 up to and at {fmt_number(a)}, if that is meant")


def _step(mf: str, params: list[float]) -> tuple[str, tuple[float, ...]] | None:
    """MATLAB's ``smf`` and ``zmf`` whose feet meet or cross (``a >= b``) are a step at their
    midpoint, ``x >= (a + b) / 2`` and ``x <= (a + b) / 2`` (its ``fisSMf``, ``fisZMf``): 1 at
    the midpoint itself, where fuzzylite's S and Z shapes give 0 and 1. ``pimf`` is their
    product, a closed rectangle when both are steps. ``linsmf [a a]`` is the step ``x >= a``
    (MATLAB's documentation). None for the other MFs."""
    if mf == "linsmf" and params[0] == params[1]:
        return "binary", (params[0], math.inf)
    if mf in ("smf", "zmf") and params[0] >= params[1]:
        return "binary", ((params[0] + params[1]) / 2, math.inf if mf == "smf" else -math.inf)
    if mf == "pimf" and params[0] >= params[1] and params[2] >= params[3]:
        return "rectangle", ((params[0] + params[1]) / 2, (params[2] + params[3]) / 2)
    return None


#: Octave's fuzzy-logic-toolkit: the fraction of an antecedent's MF index is a hedge, the
#: power ``round(100 * fraction) / 10`` applied before ``not`` (get_mf_index_and_hedge.m,
#: evalmf_private.m); the four it names, as MITOS's hedges
OCTAVE_HEDGES = {0.5: ("somewhat",), 2.0: ("very",), 3.0: ("extremely",),
                 4.0: ("very", "very")}


def _hedges(idx: float, k: int, span: Span) -> tuple[str, ...]:
    """The hedges Octave reads in the antecedent's MF index ``idx`` (``k`` its MF number)."""
    power = round(100 * (abs(idx) - k)) / 10
    if power == 0:
        return ()
    if power not in OCTAVE_HEDGES:
        raise FormatError(f"MF index {fmt_number(idx)}: Octave's hedge x^{power:g} (the "
                          f"fraction .{round(100 * (abs(idx) - k)):02d}) has no MITOS hedge",
                          span=span, expected=".05 (somewhat), .2 (very), .3 (extremely) or .4 "
                                              "(very very)")
    return OCTAVE_HEDGES[power]


#: The first line fuzzylite's ``FisExporter`` writes: the file is fuzzylite's, and fuzzylite 6
#: is the engine that reads it as its writer meant it.
FUZZYLITE_EXPORT = re.compile(r"\s*#\s*Code automatically generated with fuzzylite")


def _unloaded_note(dropped: list[Span], rules: list[Rule], outputs: list[Variable],
                   notes: list[str]) -> None:
    """Say which rules of a fuzzylite export were left out as fuzzylite 6 leaves them out (a
    rule with no condition, the exporter's 0 for a condition on an output), and which outputs
    no rule sets then."""
    if not dropped:
        return
    unset = [v.name for v in outputs if not any(c.var == v.name for r in rules
                                                for c in r.consequents)]
    notes.append(f"{dropped[0]}: {plural(len(dropped), 'rule')} with no condition (fuzzylite's "
                 f"exporter writes 0 for a condition on an output, a chained engine's, which a "
                 f".fis file cannot say): left out, as fuzzylite 6 leaves them out (it does not "
                 f"load them, so they never fire)"
                 + (f"; no rule sets {', '.join(f'`{n}`' for n in unset)} then, so MITOS "
                    f"computes no value for it (fuzzylite 6: NaN on every row)" if unset else "")
                 + "; the engine's FLL or FCL keeps the conditions")


def _rule(line: str, lineno: int, span: Span, inputs: list[Variable], outputs: list[Variable],
          text: str, path: str | None, index: int, fuzzylites: bool = False) -> Rule | Span:
    """Rule ``index`` of the [Rules] section; in fuzzylite's export (``fuzzylites``) a rule with
    no condition, which fuzzylite 6 does not load, is its place instead (left out)."""
    m = re.fullmatch(r"([-\d.\s]+),([-\d.\s]+)\(\s*([-+\d.eE]+)\s*\)\s*:\s*(\d+)", line)
    if not m:
        raise FormatError("expected a rule `in1 in2 ..., out1 ... (weight) : 1|2`", span=span)
    ins = [common.number(w, span) for w in m.group(1).split()]
    outs = [common.number(w, span) for w in m.group(2).split()]
    weight = common.number(m.group(3), span)
    connection = int(m.group(4)) if len(m.group(4)) < 10 else 0     # else refused below
    if len(ins) != len(inputs) or len(outs) != len(outputs):
        raise FormatError(f"the rule lists {plural(len(ins), 'input')} and "
                          f"{plural(len(outs), 'output')}; the system has {len(inputs)} and "
                          f"{len(outputs)}", span=span)
    if connection not in (1, 2):
        raise FormatError(f"connection {connection}: expected 1 (AND) or 2 (OR)", span=span)
    for idx in ins + outs:
        if not math.isfinite(idx) or abs(idx) > 1e9:
            raise FormatError(f"MF index {fmt_number(idx)} is not an MF number", span=span)
    props = []
    for v, idx in zip(inputs, ins):
        k = int(abs(idx))
        if k == 0:                      # Octave ignores a fraction after 0 too
            continue
        if k > len(v.terms):
            raise FormatError(f"`{v.name}` has {len(v.terms)} MFs, not {k}", span=span)
        props.append(Prop(v.name, v.terms[k - 1].name, _hedges(idx, k, span), idx < 0, span))
    cons = []
    for v, idx in zip(outputs, outs):
        if idx != int(idx) or idx < 0:
            raise FormatError(f"output MF index {idx:g}: negative (complemented) or fractional "
                              f"(hedged) consequents are not supported", span=span,
                              hint="Octave's toolkit reads a hedge there as a power of the "
                                   "rule's strength (1 / power for a Sugeno output), which "
                                   "MITOS's rules do not express: write the consequent's "
                                   "whole MF number")
        if idx == 0:
            continue
        if idx > len(v.terms):
            raise FormatError(f"`{v.name}` has {len(v.terms)} MFs, not {int(idx)}", span=span)
        cons.append(Consequent(v.name, v.terms[int(idx) - 1].name, None, (), span))
    if not props and cons and fuzzylites:
        return span
    if not props or not cons:
        raise FormatError("the rule has no " + ("condition" if not props else "consequent"),
                          span=span)
    antecedent = props[0] if len(props) == 1 else (And if connection == 1 else Or)(
        tuple(props), span)
    return Rule(f"r{index + 1}", antecedent, tuple(cons), weight, span)


# ---------------------------------------------------------------------------------------------
# Writer


def write_fis(rb: RuleBase, behavior: str | None = None) -> str:
    """``.fis`` text for one behavior of ``rb``. Rules must be flat: propositions (possibly
    negated, without hedges) joined all by AND or all by OR, as MATLAB's rule list is."""
    flat = common.flatten_for_export(rb, behavior)
    common.refuse_accumulation(rb, behavior, flat, "MATLAB's .fis")
    ops = flat.operators
    at = partial(common.setting_span, rb, behavior)       # where an operator was chosen
    if ops.inference == "tsukamoto":
        raise FormatError("MATLAB's .fis has no Tsukamoto inference; write it to FLL or a "
                          "rule file", span=at("inference"))
    sugeno = ops.inference in ("weighted_average", "weighted_sum")
    inputs = common.all_inputs(rb, flat)
    name = flat.name
    and_ = common.foreign_name(common.TNORMS, FIS, ops.and_, "AND method", span=at("and"))
    or_ = common.foreign_name(common.SNORMS, FIS, ops.or_, "OR method", span=at("or"))
    lines = ["[System]", f"Name='{name}'", f"Type='{'sugeno' if sugeno else 'mamdani'}'",
             "Version=2.0", f"NumInputs={len(inputs)}", f"NumOutputs={len(flat.outputs)}",
             f"NumRules={len(flat.rules)}",
             f"AndMethod='{and_}'", f"OrMethod='{or_}'"]
    if sugeno:
        lines += ["ImpMethod='prod'", "AggMethod='sum'",
                  f"DefuzzMethod='{common.DEFUZZIFIERS[ops.inference][FIS]}'"]
    else:
        imp = common.foreign_name(common.TNORMS, FIS, ops.implication, "implication",
                                  span=at("implication"))
        agg = common.foreign_name(common.AGGREGATIONS, FIS, ops.aggregation, "aggregation",
                                  span=at("aggregation"))
        defuzz = common.foreign_name(common.DEFUZZIFIERS, FIS, ops.defuzzify, "defuzzifier",
                                     span=at("defuzzify"))
        lines += [f"ImpMethod='{imp}'", f"AggMethod='{agg}'", f"DefuzzMethod='{defuzz}'"]
    for i, v in enumerate(inputs, 1):
        lines += ["", f"[Input{i}]"] + _var_lines(v, [_mf_text(t, v) for t in v.terms])
    for i, v in enumerate(flat.outputs, 1):
        if sugeno:
            mfs = []
            for t in v.terms:
                if t.shape == "linear":
                    coefficients = common.linear_coefficients(rb, v.name, t)
                    values = [coefficients.get(x.name, 0.0) for x in inputs] + [t.params[-1]]
                    mfs.append(f"'{t.name}':'linear',[{' '.join(fmt_number(c) for c in values)}]")
                else:
                    mfs.append(f"'{t.name}':'constant',[{fmt_number(t.center)}]")
        else:
            mfs = [_mf_text(t, v) for t in v.terms]
        lines += ["", f"[Output{i}]"] + _var_lines(v, mfs)
    lines += ["", "[Rules]"]
    for r in flat.rules:
        r = Rule(r.label, common.simple_nots(r.antecedent, r, ops), r.consequents, r.weight,
                 r.span)
        lines.append(_rule_text(r, inputs, flat.outputs))
    return "\n".join(lines) + "\n"


def notes(rb: RuleBase, behavior: str | None = None) -> list[str]:
    """What a .fis file cannot record about ``rb`` (printed as warnings by ``mitos convert``)."""
    flat = common.flatten_for_export(rb, behavior)
    ops = flat.operators
    out = []
    for v in flat.outputs:
        mid = (v.universe[0] + v.universe[1]) / 2
        if v.default != mid:
            now = "NaN / an error" if v.default is None else f"{v.default:g}"
            out.append(f"output `{v.name}`: when no rule fires MATLAB returns the middle of the "
                       f"range ({mid:g}), not {now}")
    points = list(dict.fromkeys(v.resolution or ops.resolution for v in flat.outputs))
    if ops.inference == "mamdani" and (points, ops.sampling) != ([DEFAULT_RESOLUTION],
                                                                 "endpoints"):
        out.append(f"MATLAB samples Mamdani outputs at 101 points including the ends; this rule "
                   f"base uses {' and '.join(map(str, points))} {ops.sampling}, so results "
                   f"move by the discretisation")
    return out


def _var_lines(v: Variable, mfs: list[str]) -> list[str]:
    lo, hi = v.universe
    return [f"Name='{v.name}'", f"Range=[{fmt_number(lo)} {fmt_number(hi)}]",
            f"NumMFs={len(mfs)}"] + [f"MF{i}={m}" for i, m in enumerate(mfs, 1)]


INVERSE = {shape: (mf, order) for mf, (shape, _, order) in MF_TYPES.items()
           if mf not in ("linsmf", "linzmf")}        # a ramp is written as a trapmf


def _mf_text(t: Term, v: Variable) -> str:
    shape, p = t.shape, t.params
    if shape in ("left_shoulder", "right_shoulder", "ramp", "triangle_pw", "triangle_plr",
                 "rectangle"):
        corners = t.corners
        assert corners is not None             # these six shapes are piecewise linear
        a, b, c, d = corners
        lo, hi = v.universe
        # an open end (a shoulder's, a ramp's): feet outside the universe, 1 and 2 past it
        # (inputs are clamped to it and outputs sampled inside it, so nothing computed
        # changes). Apart, since Octave's toolkit refuses a trapmf whose feet meet (`[-1 -1 40
        # 70]`: "trapmf's second argument must be a parameter vector"); a ramp went out as
        # `linsmf` / `linzmf`, which only MATLAB R2022a on reads (not fuzzylite 6, Octave)
        if a == b == -math.inf:
            a, b = min(lo, c) - 2.0, min(lo, c) - 1.0
        if c == d == math.inf:
            c, d = max(hi, b) + 1.0, max(hi, b) + 2.0
        if shape in ("triangle_pw", "triangle_plr"):
            return f"'{t.name}':'trimf',[{fmt_number(a)} {fmt_number(b)} {fmt_number(d)}]"
        return f"'{t.name}':'trapmf',[{' '.join(fmt_number(x) for x in (a, b, c, d))}]"
    if shape == "binary" and math.isinf(p[1]):      # MATLAB's step: smf or zmf [s s]
        mf = "smf" if p[1] > 0 else "zmf"
        return f"'{t.name}':'{mf}',[{fmt_number(p[0])} {fmt_number(p[0])}]"
    if shape not in INVERSE:
        raise FormatError(f"term `{v.name}.{t.name}`: MATLAB has no `{shape}` membership "
                          f"function", span=t.span)
    mf, order = INVERSE[shape]
    values = [0.0] * len(order)
    for mitos_i, matlab_i in enumerate(order):
        values[matlab_i] = p[mitos_i]
    return f"'{t.name}':'{mf}',[{' '.join(fmt_number(x) for x in values)}]"


def _rule_text(r: Rule, inputs: Sequence[Variable], outputs: Sequence[Variable]) -> str:
    e = r.antecedent
    if isinstance(e, Prop):
        props, connection = [e], 1
    elif isinstance(e, (And, Or)) and all(isinstance(i, Prop) for i in e.items):
        props = [i for i in e.items if isinstance(i, Prop)]     # all of them (checked above)
        connection = 1 if isinstance(e, And) else 2
    else:
        raise FormatError(f"rule `{r.label}`: MATLAB rules join propositions all by AND or all "
                          f"by OR; nested expressions cannot be written to .fis", span=r.span,
                          hint="split the rule into several simpler rules")
    index = {}
    for p in props:
        if p.hedges:
            raise FormatError(f"rule `{r.label}`: hedges cannot be written to .fis", span=r.span)
        if p.var in index:
            raise FormatError(f"rule `{r.label}` tests `{p.var}` twice, which .fis cannot say",
                              span=r.span)
        v = next(v for v in inputs if v.name == p.var)
        index[p.var] = (v.index(p.term) + 1) * (-1 if p.negated else 1)
    outs = {}
    for c in r.consequents:
        if c.hedges:
            raise FormatError(f"rule `{r.label}`: hedges cannot be written to .fis", span=r.span)
        v = next(v for v in outputs if v.name == c.var)
        outs[c.var] = v.index(cast(str, c.term)) + 1     # (flatten_for_export: crisp values are terms)
    ins = " ".join(str(index.get(v.name, 0)) for v in inputs)
    outs_text = " ".join(str(outs.get(v.name, 0)) for v in outputs)
    return f"{ins}, {outs_text} ({fmt_number(r.weight)}) : {connection}"
