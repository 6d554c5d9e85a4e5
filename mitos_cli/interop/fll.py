"""fuzzylite Language (FLL): reader and writer.

An FLL file is a list of ``key: value`` lines in sections (``Engine``, ``InputVariable``,
``OutputVariable``, ``RuleBlock``); ``#`` starts a comment. The structure is read line by line;
the ``rule:`` lines are fuzzylite's rule language, parsed with ``grammar/fll_rule.lark``.

Mapping (details and refusals in ``docs/interop.md``):

- terms: every fuzzylite term type except ``Function`` (a free formula); a height other than 1
  is refused; ``Constant`` -> ``singleton``, ``Linear`` -> ``linear`` (coefficients over the
  engine's inputs, in order, as MITOS's ``linear`` layout).
- ``default: nan`` -> no default (an output no rule sets is NaN / :class:`NoRuleFiredError`);
  a number -> ``Variable.default``.
- ``lock-previous: true`` (keep the last output when no rule fires: state between evaluations)
  is refused. ``lock-range`` on inputs: ``true`` on every input is MITOS's default (clamped to
  the range), ``false`` or unwritten on every input (fuzzylite's default) is ``inputs =
  as_given`` (the terms evaluated at the value given), and a mixture is clamped with a note;
  the writer says ``true`` or ``false`` by ``inputs``. On an output ``true`` is accepted for
  Mamdani defuzzifiers, whose result lies in the range anyway, and refused for weighted
  (Takagi-Sugeno) ones.
- several rule blocks are merged when their operators agree, else refused; ``enabled: false``
  is refused (MITOS has no disabled parts); activation ``General`` only.
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from lark import Lark, Tree
from lark.exceptions import UnexpectedInput, UnexpectedToken

from ..errors import FormatError, Span, did_you_mean, lines_of
from ..fuzzy.formula import parse as parse_formula
from ..fuzzy.shapes import TSUKAMOTO
from ..lang.bulk import without_cyclic_gc
from ..lang.cache import lark_parser
from ..lang.lexing import Glued, accepted_before, parse_apart, read_as_one_name
from ..lang.model import Rule, RuleBase, Setting
from ..lang.model import format_number as _fmt_weight
from ..lang.terms import Role, Term, Variable
from . import common
from .common import FLL, Settings, fmt_number
from .ruletree import conclusions as conclusions_of
from .ruletree import expression
from .text import read_foreign_file

if TYPE_CHECKING:
    from collections.abc import Iterable

    from ..lang.operators import Operators
    from .ruletree import Node, SpanOf

#: fuzzylite's monotonic terms, which its weighted defuzzifiers invert (Tsukamoto inference)
TSUKAMOTO_KINDS = ("Ramp", "Sigmoid", "SShape", "ZShape", "Concave", "Arc")
SECTIONS = ("Engine", "InputVariable", "OutputVariable", "RuleBlock")
KEYS = {
    "Engine": ("description",),
    "InputVariable": ("description", "enabled", "range", "lock-range", "term"),
    "OutputVariable": ("description", "enabled", "range", "lock-range", "aggregation",
                       "accumulation", "defuzzifier", "default", "lock-previous", "lock-valid",
                       "term"),
    "RuleBlock": ("description", "enabled", "conjunction", "disjunction", "implication",
                  "activation", "rule"),
}
DEFAULT_RESOLUTION = 1000     # fuzzylite's IntegralDefuzzifier.default_resolution


@functools.cache
def rule_parser() -> Lark:
    from ..resources import grammar_text

    return lark_parser(grammar_text("fll_rule.lark"), propagate_positions=True,
                       maybe_placeholders=True)       # analysis kept in the private cache


@dataclass
class _Var:
    role: Role
    name: str
    span: Span
    range: tuple[float, float] | None = None
    range_span: Span | None = None      # where the range is written
    default_span: Span | None = None    # where the default is written
    terms: list = field(default_factory=list)          # (name, kind, values, span)
    default: float | None = None
    description: str = ""
    lock_range: Span | None = None      # `lock-range: true` on an output
    #: an input's `lock-range` as written (value, where); unwritten is fuzzylite's `false`
    input_lock: tuple[bool, Span] | None = None
    record: common.Record = field(default_factory=common.Record)
    weighted_type: tuple[str, Span] | None = None   # a weighted defuzzifier's type, where
    resolution: int | None = None       # its own, where outputs' resolutions differ


def _tsukamoto(v: _Var, notes: list[str]) -> None:
    """A weighted defuzzifier over monotonic terms is Tsukamoto inference: said so
    (``WeightedAverage Tsukamoto``), or inferred from the terms as fuzzylite does
    (``Automatic``, the default)."""
    if v.weighted_type is None:
        return
    kind, span = v.weighted_type
    monotonic = bool(v.terms) and all(k in TSUKAMOTO_KINDS for _, k, _, _ in v.terms)
    if kind != "Tsukamoto" and not (kind == "Automatic" and monotonic):
        return
    for i, (key, value, where, what) in enumerate(v.record):
        if key == "defuzzify":
            if value == "weighted_sum":
                raise FormatError("Tsukamoto inference with a weighted sum is not supported "
                                  "(MITOS's Tsukamoto takes the weighted average)", span=where)
            v.record[i] = (key, "tsukamoto", where, what)
    if any(k == "Sigmoid" for _, k, _, _ in v.terms):
        notes.append(f"{span}: `{v.name}` inverts Sigmoid terms (Tsukamoto inference); a sigmoid "
                     f"reaches 1 only at infinity, so where a rule fires fully the output is "
                     f"+-inf, as in fuzzylite")


@dataclass
class _Block:
    name: str
    span: Span
    record: common.Record = field(default_factory=common.Record)
    conj: dict = field(default_factory=lambda: {"conjunction": None, "disjunction": None})
    lines: list = field(default_factory=list)           # (rule text, line, column)
    rules: list = field(default_factory=list)


def read_fll(path: str | Path) -> RuleBase:
    return read_foreign_file(Path(path), parse_fll)


@without_cyclic_gc
def parse_fll(text: str, path: str | None = None) -> RuleBase:
    """Read FLL ``text`` into a rule base: one behavior ``main``, or, when rule blocks need
    different operators (fuzzylite's hybrid engines), one behavior per block."""
    variables, blocks, engine_span = _sections(text, path)
    notes: list[str] = []
    for v in variables:
        _tsukamoto(v, notes)
    _own_resolutions(variables)
    inputs = [x.name for x in variables if x.role == "input"]     # once: per variable, N^2
    built = [_build_variable(v, inputs, notes) for v in variables]
    by_name = {v.name: v for v in built}
    outputs = {v.name: v for v in variables if v.role == "output"}
    for b in blocks:
        b.rules = [_rule(value, text, path, lineno, vcol, by_name, b.conj, i)
                   for i, (value, lineno, vcol) in enumerate(b.lines)]
    blocks = [b for b in blocks if b.rules] or blocks[:1]
    groups = common.rule_blocks([(b.name, b.record, b.rules) for b in blocks],
                                {n: v.record for n, v in outputs.items()},
                                renumber=len(blocks) > 1)
    for _, rules, settings in groups:
        concluded = {c.var for r in rules for c in r.consequents}
        mine = [v for v in variables if v.role == "input" or v.name in concluded or
                len(groups) == 1]
        _check_outputs(mine, rules, settings)
    places: common.Places = {(v.name, what): at for v in variables
                             for what, at in (("range", v.range_span), ("default", v.default_span))
                             if at is not None}
    rb = common.assemble_blocks(path, built, groups, DEFAULT_RESOLUTION, engine_span, notes,
                                places)
    for _, rules, settings in groups:      # after the errors that say more (a term's, ...)
        if not settings.sugeno:
            _check_unset(variables, rules, settings)
    return _input_ranges(dataclasses.replace(rb, notes=tuple(notes)), variables)


def _input_ranges(rb: RuleBase, variables: list[_Var]) -> RuleBase:
    """fuzzylite clamps an input to its range only under ``lock-range: true`` (its default is
    ``false``: the terms evaluated at the value given). MITOS has one setting for all inputs:
    when no input is locked, ``inputs = as_given``; when some are and some are not, they are
    all clamped, with a note naming the others (they differ only outside their ranges)."""
    inputs = [v for v in variables if v.role == "input"]
    free = [v for v in inputs if not (v.input_lock and v.input_lock[0])]
    if not free:
        return rb
    if len(free) < len(inputs):
        names = ", ".join(f"`{v.name}`" for v in free)
        first = free[0].input_lock[1] if free[0].input_lock else free[0].span
        note = (f"{first}: {names} not locked to {'its' if len(free) == 1 else 'their'} range "
                f"(`lock-range: false`, fuzzylite's default) beside inputs that are: MITOS "
                f"clamps every input of a rule base or none, so these are clamped too (the "
                f"outputs differ from fuzzylite's only for inputs outside their ranges)")
        return dataclasses.replace(rb, notes=(*rb.notes, note))
    where = next((v.input_lock[1] for v in free if v.input_lock), None)
    return dataclasses.replace(rb, operators=(*rb.operators, Setting("inputs", "as_given", where)))


def _sections(text: str, path: str | None) -> tuple[list[_Var], list[_Block], Span]:
    """The FLL ``text``'s variables and rule blocks as written, line by line (each key checked
    against its section's), and where the ``Engine:`` line is (else the file's start)."""
    variables: list[_Var] = []
    blocks: list[_Block] = []
    section: str | None = None
    current: _Var | None = None
    engine_span = Span.in_text(text, path, 1, 1)

    for lineno, raw in enumerate(lines_of(text), 1):
        line = raw.split("#", 1)[0].rstrip()
        if not line.strip():
            continue
        indent = len(line) - len(line.lstrip())
        written, sep, value = line.strip().partition(":")
        key = written.rstrip()       # `range : 0 1`, as fuzzylite 6 and pyfuzzylite read it
        col = indent + 1
        span = Span.in_text(text, path, lineno, col, col + len(key))
        vcol = indent + len(written) + 2 + (len(value) - len(value.lstrip()))
        value = value.strip()
        vspan = Span.in_text(text, path, lineno, vcol, vcol + max(1, len(value)))
        if not sep:
            raise FormatError(f"expected `key: value`, not `{line.strip()}`", span=span)
        if key in SECTIONS:
            section = key
            current = None
            if key == "Engine":
                engine_span = span
            elif key in ("InputVariable", "OutputVariable"):
                if not value:
                    raise FormatError(f"{key} needs a name", span=span)
                current = _Var("input" if key == "InputVariable" else "output", value, vspan)
                variables.append(current)
            else:
                blocks.append(_Block(value, span))
            continue
        if section is None:
            raise FormatError(f"`{key}` before any section", span=span,
                              expected="Engine:, InputVariable:, OutputVariable: or RuleBlock:")
        if key not in KEYS[section]:
            joined = "".join(key.split())
            split = next((k for k in (*SECTIONS, *KEYS[section]) if k in (joined, "-".join(
                key.split()))), None) if joined != key else None      # `Input Variable`
            raise FormatError(f"unknown {section} key `{key}`", span=span,
                              expected="one of " + ", ".join(KEYS[section]),
                              hint=f"`{key}` is one word: `{split}`" if split else
                              did_you_mean(key, KEYS[section]))
        if key == "description":
            if current is not None:
                current.description = value
            continue
        if key == "enabled":
            if value != "true":
                raise FormatError(f"`enabled: {value}`: MITOS has no disabled variables or rule "
                                  f"blocks", span=vspan, hint="delete the part or enable it")
            continue
        if section in ("InputVariable", "OutputVariable"):
            assert current is not None          # set by its section's header line
            _variable_key(current, key, value, span, vspan, current.record)
        elif key == "rule":
            blocks[-1].lines.append((value, lineno, vcol))
        else:
            _block_key(key, value, vspan, blocks[-1].record, blocks[-1].conj)

    return variables, blocks, engine_span


def _own_resolutions(variables: list[_Var]) -> None:
    """fuzzylite samples each Mamdani output at its own defuzzifier's resolution (1000 where
    it writes none): where they differ each becomes its variable's own
    (:func:`.common.own_resolutions`)."""
    outputs = {v.name: v for v in variables if v.role == "output"}
    for name, points in common.own_resolutions({n: v.record for n, v in outputs.items()}).items():
        outputs[name].resolution = points


def _check_outputs(variables: list[_Var], rules: list[Rule], settings: Settings) -> None:
    if not settings.sugeno:
        for v in variables:
            for name, kind, _, span in v.terms:
                if v.role == "output" and kind == "Constant":
                    raise FormatError(
                        f"term `{v.name}.{name}`: in a Mamdani output fuzzylite's `Constant` is "
                        f"a flat membership of that height everywhere, which MITOS does not "
                        f"support", span=span, hint="use a Rectangle or Triangle term, or a "
                        "weighted-average defuzzifier for crisp consequents")
        return
    _check_grouping(variables, rules, settings)
    for v in variables:
        if v.lock_range is not None:
            raise FormatError(f"`lock-range: true` on the Takagi-Sugeno output `{v.name}` "
                              f"(clipping the output to its range) is not supported",
                              span=v.lock_range, hint="set `lock-range: false`")


def _check_unset(variables: list[_Var], rules: list[Rule], settings: Settings) -> None:
    """A Mamdani rule block without an `implication` (or `implication: none`), an output its
    rules set without a `defuzzifier`, and one two of its rules set without an `aggregation`:
    fuzzylite stops there ("implication operator needed", "defuzzifier needed", "expected an
    aggregation operator"), as the .fis reader does for `ImpMethod=''` and `AggMethod=''`.
    They were read as MITOS's defaults (min, centroid, max) without a word. One rule's set
    joined with nothing is itself under any S-norm."""
    if settings.implication is None and rules:
        rule = rules[0]
        raise FormatError(f"the rule block has no implication, but rule {rule.label} concludes "
                          f"`{rule.consequents[0].var}`: a Mamdani rule's set is cut by the "
                          f"implication, and fuzzylite stops without one", span=rule.span,
                          hint="add `implication: Minimum` (or another T-norm) to the "
                               "RuleBlock")
    first: dict[str, Rule] = {}
    by_name = {v.name: v for v in variables}          # (a search per rule was quadratic)
    keys = {v.name: {entry[0] for entry in v.record} for v in variables}
    for rule in rules:
        for c in rule.consequents:
            v, written = by_name[c.var], keys[c.var]
            if "defuzzify" not in written:
                raise FormatError(f"output `{c.var}` has no defuzzifier, but rule {rule.label} "
                                  f"sets it: fuzzylite stops without one", span=v.span,
                                  hint="add `defuzzifier: Centroid` (or another) to the "
                                       "OutputVariable")
            if c.var in first and first[c.var] is not rule and "aggregation" not in written:
                raise FormatError(
                    f"output `{c.var}` has no aggregation, but rules {first[c.var].label} "
                    f"and {rule.label} both set it: a Mamdani output joins their sets "
                    f"with its aggregation, and fuzzylite stops without one", span=v.span,
                    hint="add `aggregation: Maximum` (or another S-norm) to the "
                         "OutputVariable")
            first.setdefault(c.var, rule)


def _variable_key(v: _Var, key: str, value: str, span: Span, vspan: Span,
                  settings: common.Record) -> None:
    words = value.split()
    if key == "range":
        if len(words) != 2:
            raise FormatError("`range` takes two numbers: minimum and maximum", span=vspan)
        lo, hi = (common.number(w, vspan) for w in words)
        common.check_range(lo, hi, vspan, point=True)
        v.range = (lo, hi)
        v.range_span = vspan
    elif key == "term":
        if len(words) < 2:
            raise FormatError("`term` takes a name, a type and its parameters", span=vspan)
        if words[1] == "Function":            # the rest of the line is the formula
            start = value.index("Function", len(words[0])) + len("Function")
            text = value[start:]
            fspan = dataclasses.replace(vspan, column=vspan.column + start
                                        + len(text) - len(text.lstrip()), end_column=None)
            formula = parse_formula(text.lstrip(), fspan, FormatError)
            v.terms.append((words[0], "Function", formula, fspan))
            return
        v.terms.append((words[0], words[1], [common.number(w, vspan) for w in words[2:]], vspan))
    elif key in ("lock-range", "lock-previous", "lock-valid") and value not in ("true", "false"):
        raise FormatError(f"`{key}` is `true` or `false`, not `{value}`", span=vspan,
                          expected="true or false")
    elif key == "lock-range":
        if value == "true" and v.role == "output":
            v.lock_range = vspan
        elif v.role == "input":
            v.input_lock = (value == "true", vspan)
    elif key in ("lock-previous", "lock-valid"):
        if value == "true":
            raise FormatError(f"`{key}: true` (keep the previous output when no rule fires) "
                              f"needs state between evaluations, which MITOS does not keep",
                              span=vspan, hint="set `default:` to the value to use instead")
    elif key == "default":
        v.default = common.number(value, vspan)     # nan: NaN when no rule fires, as asked
        v.default_span = vspan
    elif key in ("aggregation", "accumulation"):
        if value != "none":
            settings.set("aggregation", common.table_lookup(common.AGGREGATIONS, FLL, value,
                                                            "aggregation", vspan), vspan,
                          "aggregation")
    elif key == "defuzzifier":
        if not words:
            raise FormatError("`defuzzifier` needs a name", span=vspan)
        name = common.table_lookup(common.DEFUZZIFIERS, FLL, words[0], "defuzzifier", vspan)
        if name in ("weighted_average", "weighted_sum"):
            v.weighted_type = (words[1:2] or ["Automatic"])[0], vspan
        settings.set("defuzzify", name, vspan, "defuzzifier")
        if len(words) > 1:
            if name in ("weighted_average", "weighted_sum"):
                if words[1] not in ("TakagiSugeno", "Automatic", "Tsukamoto"):
                    raise FormatError(f"unknown weighted defuzzifier type `{words[1]}`",
                                      span=vspan, expected="TakagiSugeno, Tsukamoto or Automatic")
            else:
                res = common.resolution(common.number(words[1], vspan, "a resolution"),
                                        words[1], vspan)
                settings.set("resolution", res, vspan, "resolution")


def _block_key(key: str, value: str, vspan: Span, settings: common.Record,
               conj: dict) -> None:
    if key == "conjunction":
        if value != "none":
            settings.set("and_", common.table_lookup(common.TNORMS, FLL, value, "conjunction",
                                                     vspan), vspan, "conjunction")
            conj["conjunction"] = value
    elif key == "disjunction":
        if value != "none":
            settings.set("or_", common.table_lookup(common.SNORMS, FLL, value, "disjunction",
                                                    vspan), vspan, "disjunction")
            conj["disjunction"] = value
    elif key == "implication":
        if value != "none":
            settings.set("implication", common.check_implication(
                common.table_lookup(common.TNORMS, FLL, value, "implication", vspan), vspan),
                vspan, "implication")
    elif key == "activation":
        name = value.split()[0] if value else ""
        if name == "General":
            return
        if name in {n[FLL] for n in common.TNORMS.values()}:     # fuzzylite 5: the implication
            _block_key("implication", name, vspan, settings, conj)
            return
        raise FormatError(f"activation `{value}` is not supported: MITOS activates every rule "
                          f"(fuzzylite's `General`)", span=vspan,
                          hint="First, Last, Highest, Lowest, Proportional and Threshold "
                               "activations select rules; rewrite the rules instead")


def _build_variable(v: _Var, inputs: list[str], notes: list[str]) -> Variable:
    if v.range is None:
        raise FormatError(f"variable `{v.name}` has no `range`", span=v.span)
    universe = v.range
    if universe[0] == universe[1]:
        if not (v.role == "output" and v.terms and all(
                kind in ("Constant", "Linear") for _, kind, _, _ in v.terms)):
            raise FormatError(f"range [{universe[0]:g}, {universe[1]:g}] is empty",
                              span=v.range_span or v.span,
                              hint="write the minimum, then a larger maximum")
        universe = (-float("inf"), float("inf"))     # a Takagi-Sugeno output's range is unused
    terms = []
    for name, kind, values, span in v.terms:
        if kind == "Linear" and v.role == "input":
            raise FormatError(f"term `{v.name}.{name}`: Linear terms belong to outputs",
                              span=span)
        if kind == "Function":
            terms.append(common.formula_term(name, values, span))
            continue
        terms.append(common.fuzzylite_term(name, kind, list(values), len(inputs), span))
    if not terms and v.role == "output":
        raise FormatError(f"output variable `{v.name}` has no terms", span=v.span)
    terms = common.distinct_names(terms, v.name, notes, "rules naming it mean the last term "
                                  "of that name, as in fuzzylite 8", keep_last=True)
    if not universe[0] < universe[1]:
        raise FormatError(f"variable `{v.name}`: range [{universe[0]:g}, {universe[1]:g}] is "
                          f"empty", span=v.span)
    try:
        return Variable(v.name, v.role, universe, tuple(terms), v.description, "", v.default,
                        v.span, v.resolution)
    except Exception as exc:                     # duplicate terms: TermSetError with a span
        raise FormatError(getattr(exc, "message", str(exc)),
                          span=getattr(exc, "span", None) or v.span) from None


def _rule(value: str, text: str, path: str | None, lineno: int, vcol: int,
          variables: dict[str, Variable], conj: dict, index: int) -> Rule:
    def span_of(node: object) -> Span:
        meta = getattr(node, "meta", None)
        column = getattr(node, "column", None) or (meta.column if meta and not meta.empty
                                                   else 1)
        end = getattr(node, "end_column", None) or (meta.end_column if meta and not meta.empty
                                                    else column + 1)
        return Span.in_text(text, path, lineno, vcol + column - 1, vcol + end - 1)

    try:
        tree = parse_apart(rule_parser(), value)
    except Glued as glued:
        # `if a isLow`, `then b is HIGHwith 0.5`: fuzzylite splits a rule at its blanks
        first, second = glued.first, glued.second
        word = value[first.start_pos:second.end_pos]
        keyword = first.type not in ("NAME", "NUMBER", "WORD")
        hint = f"`{first}` and `{second}` are two words: `{first} {second}`" \
            if keyword and glued.fits else None
        column = first.column or 1
        raise FormatError(f"unexpected `{word}`", span=Span.in_text(
            text, path, lineno, vcol + column - 1, vcol + column - 1 + len(word)),
            expected=_rule_words(accepted_before(rule_parser(), value, first)),
            hint=hint) from None
    except UnexpectedInput as exc:
        column = getattr(exc, "column", 1) or 1
        expected = getattr(exc, "expected", None) or getattr(exc, "allowed", None)
        hint = None
        if isinstance(exc, UnexpectedToken):
            if exc.interactive_parser is not None:  # `expected` may hold LALR's merged states
                expected = set(exc.interactive_parser.accepts()) or expected
            if exc.token.type == "$END":          # said after the rule, not at its last word
                column = len(value.rstrip()) + 1
            before = (exc.token_history or [None])[-1]
            if before is not None and before.type == "NAME":     # `is HIGHwith 0.5`
                hint = read_as_one_name(str(before), {str(e).lower() for e in expected or ()},
                                        _RULE_KEYWORDS)
        raise FormatError("cannot read this rule", span=Span.in_text(
            text, path, lineno, vcol + column - 1), expected=_rule_words(expected),
            hint=hint) from None
    antecedent_tree, *rest = tree.children
    weight_token = rest[-1]
    conclusions = [c for c in rest[:-1] if isinstance(c, Tree)]   # all are (the grammar)
    antecedent = expression(antecedent_tree, span_of, variables)
    _check_operators(antecedent_tree, conj, span_of)
    weight = common.number(str(weight_token), span_of(weight_token)) if weight_token else 1.0
    span = Span.in_text(text, path, lineno, vcol, vcol + len(value))
    return Rule(f"r{index + 1}", antecedent, conclusions_of(conclusions, span_of),
                weight, span)


#: the keywords of fuzzylite's rules (the hedges are names checked after parsing)
_RULE_KEYWORDS = {"if", "is", "then", "and", "or", "with"}
#: how a rule's terminals are named where they are expected (keywords: as written)
_RULE_WORDS = {"NAME": "a name", "NUMBER": "a number", "WORD": "a hedge", "LPAR": "`(`",
               "RPAR": "`)`", "$END": "the end of the rule", "<END-OF-FILE>": "the end of the rule"}


def _rule_words(terminals: Iterable[str] | None) -> str | None:
    words = sorted({_RULE_WORDS.get(str(t), str(t).lower()) for t in terminals or ()})
    if len(words) == 1:
        return words[0]                       # "a number", not "one of a number"
    return "one of " + ", ".join(words) if words else None


def _check_operators(tree: Node, conj: dict, span_of: SpanOf) -> None:
    """fuzzylite refuses `and` / `or` when the block's conjunction / disjunction is none."""
    from lark import Tree

    for sub in tree.iter_subtrees() if isinstance(tree, Tree) else ():
        if sub.data == "and_expr" and conj.get("conjunction") is None:
            raise FormatError("the rule uses `and` but its rule block's conjunction is none",
                              span=span_of(sub), hint="set `conjunction:` in the RuleBlock")
        if sub.data == "or_expr" and conj.get("disjunction") is None:
            raise FormatError("the rule uses `or` but its rule block's disjunction is none",
                              span=span_of(sub), hint="set `disjunction:` in the RuleBlock")


def _check_grouping(variables: list[_Var], rules: list[Rule], settings: Settings) -> None:
    """fuzzylite 8 aggregates the activations of one output term (weighted defuzzifiers) with
    the output's aggregation; without one (``none``) or with ``UnboundedSum`` it sums them, as
    MITOS does per rule."""
    if settings.aggregation in (None, "sum"):
        return
    seen: dict[tuple[str, str | None], Span | None] = {}
    for r in rules:
        for c in r.consequents:
            if (c.var, c.term) in seen:
                raise FormatError(
                    f"`{c.var} is {c.term}` is concluded by several rules while the output's "
                    f"aggregation is `{settings.aggregation}`: fuzzylite then aggregates their "
                    f"weights, MITOS sums them (as with `aggregation: none`)", span=c.span,
                    hint="set `aggregation: none` for a Takagi-Sugeno output")
            seen[(c.var, c.term)] = c.span


# ---------------------------------------------------------------------------------------------
# Writer


def write_fll(rb: RuleBase, behavior: str | None = None) -> str:
    """FLL text for one behavior of ``rb`` (reading it back gives the same outputs)."""
    flat = common.flatten_for_export(rb, behavior)
    common.refuse_accumulation(rb, behavior, flat, "FLL")
    ops = flat.operators
    at = functools.partial(common.setting_span, rb, behavior)       # where an operator was chosen
    tsukamoto = ops.inference == "tsukamoto"
    sugeno = ops.inference in ("weighted_average", "weighted_sum") or tsukamoto
    inputs = common.all_inputs(rb, flat)
    lock = "false" if ops.inputs == "as_given" else "true"     # clamped: fuzzylite's `true`
    out = [f"Engine: {flat.name}"]
    for v in inputs:
        out += [f"InputVariable: {v.name}"]
        if v.description:
            out.append(f"  description: {_one_line(v.description)}")
        out += ["  enabled: true", f"  range: {fmt_number(v.universe[0])} "
                f"{fmt_number(v.universe[1])}", f"  lock-range: {lock}"]
        out += [f"  term: {t.name} {common.fuzzylite_term_text(t, v.name)}" for t in v.terms]
    for v in flat.outputs:
        out += [f"OutputVariable: {v.name}"]
        if v.description:
            out.append(f"  description: {_one_line(v.description)}")
        out += ["  enabled: true", f"  range: {fmt_number(v.universe[0])} "
                f"{fmt_number(v.universe[1])}", "  lock-range: false"]
        if sugeno:
            out.append("  aggregation: none")
            if tsukamoto:
                out.append("  defuzzifier: WeightedAverage Tsukamoto")
            else:
                kind = common.DEFUZZIFIERS[ops.inference][FLL]
                out.append(f"  defuzzifier: {kind} TakagiSugeno")
        else:
            aggregation = common.foreign_name(common.AGGREGATIONS, FLL, ops.aggregation, "S-norm",
                                              span=at("aggregation"))
            out.append(f"  aggregation: {aggregation}")
            kind = common.foreign_name(common.DEFUZZIFIERS, FLL, ops.defuzzify, "defuzzifier",
                                       span=at("defuzzify"))
            points = v.resolution or ops.resolution
            res = "" if points == DEFAULT_RESOLUTION else f" {points}"
            out.append(f"  defuzzifier: {kind}{res}")
        out.append(f"  default: {'nan' if v.default is None else fmt_number(v.default)}")
        out.append("  lock-previous: false")
        for t in v.terms:
            if tsukamoto:
                _invertible(t, v)
            text = common.fuzzylite_term_text(t, v.name) if tsukamoto else \
                _output_term(rb, t, v, sugeno, inputs)
            out.append(f"  term: {t.name} {text}")
    and_ = common.foreign_name(common.TNORMS, FLL, ops.and_, "T-norm", span=at("and"))
    or_ = common.foreign_name(common.SNORMS, FLL, ops.or_, "S-norm", span=at("or"))
    out += [f"RuleBlock: {flat.name}", "  enabled: true", f"  conjunction: {and_}",
            f"  disjunction: {or_}"]
    if sugeno:
        out.append("  implication: none")
    else:
        imp = common.foreign_name(common.TNORMS, FLL, ops.implication, "implication",
                                  span=at("implication"))
        out.append(f"  implication: {imp}")
    out.append("  activation: General")
    for r in flat.rules:
        out.append(f"  rule: {fuzzylite_rule_text(r, ops, 'fll')}")
    return "\n".join(out) + "\n"


def _one_line(text: str) -> str:
    return " ".join(text.replace("#", "").split())


def _invertible(t: Term, v: Variable) -> None:
    """Refuse, at the term, a Tsukamoto output's term that has no inverse: FLL's
    ``WeightedAverage Tsukamoto`` holds monotonic terms only (the reader refuses the others),
    and a concluded one was refused already, so this one no rule concludes."""
    if t.shape not in TSUKAMOTO:
        raise FormatError(f"output term `{v.name}.{t.name}`: an FLL Tsukamoto output holds "
                          f"monotonic terms only ({', '.join(TSUKAMOTO)}), not a "
                          f"`{t.shape}` term", span=t.span,
                          hint=f"no rule concludes `{t.name}`: remove it from `{v.name}`'s "
                               f"terms (no output changes), or use another inference")


def _output_term(rb: RuleBase, t: Term, v: Variable, sugeno: bool,
                 inputs: tuple[Variable, ...]) -> str:
    if sugeno:
        if t.shape == "linear":
            coefficients = common.linear_coefficients(rb, v.name, t)
            values = [coefficients.get(i.name, 0.0) for i in inputs] + [t.params[-1]]
            return "Linear " + " ".join(fmt_number(c) for c in values)
        return f"Constant {fmt_number(t.center)}"     # weighted average uses the centre only
    if t.shape == "singleton":
        raise FormatError(f"term `{v.name}.{t.name}`: fuzzylite has no singleton set for a "
                          f"Mamdani output (its `Constant` is a flat membership)",
                          span=t.span, hint="use inference = weighted_average, or give the "
                                            "output membership-shaped terms")
    return common.fuzzylite_term_text(t, v.name)


def fuzzylite_rule_text(rule: Rule, ops: Operators, dialect: str) -> str:
    """A rule in fuzzylite's language (``dialect`` ``fll``: lower case; ``fcl``: upper-case
    keywords). ``not (...)`` groups are pushed onto propositions when the operators are duals."""
    from ..lang.model import And, Not, Prop

    antecedent = common.simple_nots(rule.antecedent, rule, ops)
    kw = (lambda w: w.upper()) if dialect == "fcl" else (lambda w: w)

    def expr(e: Any, parent: str) -> str:      # an Expr without Not (simple_nots pushed them in)
        if isinstance(e, Prop):
            words = (["not"] if e.negated else []) + [common.to_fuzzylite_hedge(h, e.span)
                                                       for h in e.hedges] + [e.term]
            return f"{e.var} {kw('is')} " + " ".join(kw(w) if w == "not" else w for w in words)
        op = "and" if isinstance(e, And) else "or"
        text = f" {kw(op)} ".join(expr(i, op) for i in e.items)
        return f"({text})" if parent != op and parent != "top" else text

    assert not isinstance(antecedent, Not)
    cons = f" {kw('and')} ".join(
        f"{c.var} {kw('is')} " + " ".join([common.to_fuzzylite_hedge(h, c.span) for h in hedges]
                                          + [common.concluded_term(c)])
        for c, hedges in common.written_consequents(rule, ops.inference))
    text = f"{kw('if')} {expr(antecedent, 'top')} {kw('then')} {cons}"
    if rule.weight != 1.0:
        text += f" {kw('with')} {_fmt_weight(rule.weight)}"
    return text
