"""Fuzzy Control Language (IEC 61131-7): reader (jFuzzyLogic's and fuzzylite's dialects) and
writer.

The whole file is parsed with ``grammar/fcl.lark`` (LALR); this module turns the tree into
MITOS's model. Both dialects are read:

- terms: the standard point lists ``(x, y) ...`` (a list that is exactly a triangle, trapezoid
  or shoulder becomes that shape, else ``discrete``), singletons ``TERM t := 5;``,
  jFuzzyLogic's ``trian trape gauss gauss2 gbell sigm dsigm cosine`` (any case) and
  fuzzylite's class names
  (``Triangle``, ``Gaussian``, ``Linear``, ...; every one but ``Function``);
- ``ACCU`` in the RULEBLOCK (IEC, jFuzzyLogic) or in DEFUZZIFY (fuzzylite); ``ACT`` is the
  implication; with only ``AND`` (or only ``OR``) given the other is its De Morgan dual, as
  IEC 61131-7 says (jFuzzyLogic's ``HAMACHER`` and ``EINSTEIN``: each other, as it pairs them);
- ``METHOD``: COG, COA (BIS), MM (MOM), LM (SOM), RM (LOM) for Mamdani; COGS (weighted
  average of singletons), COGF (jFuzzyLogic's, the same over ``FUNCTION`` terms, read as
  linear terms where they are linear) and COGSS (weighted sum) for Takagi-Sugeno, where an
  ``ACCU`` is the behavior's ``accumulation`` (jFuzzyLogic joins the rules of one singleton
  value with it);
- a rule concluding several terms of one output: one rule per term (jFuzzyLogic fires each);
- ``DEFAULT := v`` -> ``Variable.default``; ``DEFAULT := nan`` -> none; ``| NC`` (no change:
  keep the previous output) and ``LOCK : PREVIOUS`` need state and are refused; ``LOCK : RANGE``
  is accepted for Mamdani outputs (a no-op there) and refused for Takagi-Sugeno ones;
- hedges (fuzzylite's dialect) as in FLL; ``NOT (...)`` over groups.

Without a ``RANGE``, a variable's range is the extent of its piecewise-linear terms.
The writer writes one of two dialects (:data:`DIALECTS`): fuzzylite 6's (the default) or IEC
61131-7 as jFuzzyLogic reads it (an input's RANGE after its declaration, no ``DEFAULT := nan``,
jFuzzyLogic's names for its shapes); both have lower-case rule keywords, point lists for
piecewise-linear terms and no resolution after METHOD. Shapes IEC has no notation for use
jFuzzyLogic's or fuzzylite's names, which this reader reads back.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import re
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, cast

import numpy as np
from lark import Lark, Token, Tree
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken

from ..errors import (
    FormatError,
    NoRulesError,
    Span,
    did_you_mean,
    invisible_character,
    lines_of,
    lone_cr_as_lf,
)
from ..fuzzy import norms
from ..fuzzy.shapes import TSUKAMOTO
from ..lang.bulk import without_cyclic_gc
from ..lang.cache import lark_parser
from ..lang.lexing import Glued, accepted_before, parse_apart, read_as_one_name
from ..lang.model import And, Behavior, Expr, Not, Or, Prop, Rule, RuleBase, format_consequent
from ..lang.terms import Role, Term, TermSet, Variable, first_at
from ..words import plural
from . import common
from .common import FCL, FLL, fmt_number
from .fclfunction import linear_function
from .ruletree import check_depth, conclusions, expression
from .text import read_foreign_file

if TYPE_CHECKING:
    from collections.abc import Callable, Iterable

    from ..lang.operators import Operators
    from .ruletree import Node, SpanOf

DEFAULT_RESOLUTION = 1000

#: jFuzzyLogic's shape names (lower case) -> (MITOS shape, count, FCL params -> MITOS params)
JFUZZY_SHAPES = {
    "trian": ("triangle", 3, lambda p: p),
    "trape": ("trapezoid", 4, lambda p: p),
    "gauss": ("gaussian", 2, lambda p: p),                            # mean stdev
    "gauss2": ("gaussian2", 4, lambda p: p),                          # meanl stdevl meanr stdevr
    "gbell": ("bell", 3, lambda p: (p[2], p[0], p[1])),              # a b mean
    "sigm": ("sigmoid", 2, lambda p: (p[1], p[0])),                   # gain center
    # g1 c1 g2 c2: max(s1 - s2, 0), not fuzzylite's |s1 - s2|
    "dsigm": ("clipped_sigmoid_difference", 4, lambda p: (p[1], p[0], p[2], p[3])),
    # net_max offset: (1 + cos(pi (x - offset) / net_max)) / 2 on offset +- net_max
    "cosine": ("cosine", 2, lambda p: (p[1], 2.0 * p[0])),
}


@functools.cache
def parser() -> Lark:
    from ..resources import grammar_text

    return lark_parser(grammar_text("fcl.lark"), propagate_positions=True,
                       maybe_placeholders=True)       # analysis kept in the private cache


def read_fcl(path: str | Path) -> RuleBase:
    return read_foreign_file(Path(path), parse_fcl)


def _syntax_error(exc: UnexpectedInput, text: str, path: str | None) -> FormatError:
    """Lark's exception in FCL's own words: keywords as FCL writes them (``END_FUZZIFY``),
    "did you mean" for a word that is a misspelt keyword (``TREM``, ``END_FUZIFY``), and
    "two words" for the word before the error read as one name (``poorTHEN``)."""
    line, column = getattr(exc, "line", 1) or 1, getattr(exc, "column", 1) or 1
    end_column = None
    hint = None
    expected = set(getattr(exc, "expected", None) or getattr(exc, "allowed", None) or ())
    if isinstance(exc, UnexpectedEOF) or (isinstance(exc, UnexpectedToken)
                                          and exc.token.type == "$END"):
        lines = lines_of(text) or [""]
        line, column = len(lines), len(lines[-1]) + 1
        what = "unexpected end of file"
    elif isinstance(exc, UnexpectedToken):
        # (a FUNCTION term's formula runs to the next `;`: `FUNCTION BLOCK` took lines)
        shown = str(exc.token).split()[0] if exc.token.type == "FORMULA" else str(exc.token)
        what = f"unexpected `{shown}`"
        end_column = column + len(shown)
        if exc.interactive_parser is not None:      # `expected` may hold LALR's merged states
            expected = set(exc.interactive_parser.accepts()) or expected
        keywords = set(_keywords(t.name for t in parser().terminals))
        end = exc.token.end_pos
        hidden = invisible_character(text[end:end + 1]) if end is not None else None
        if hidden is not None:          # (`ACT` and a zero-width space: "did you mean `ACT`?")
            hint = f"`{shown}` is followed by the invisible character {hidden}: delete it"
        if hint is None and exc.token.type in ("NAME", "FORMULA"):   # `END RULEBLOCK`: one word
            after = re.match(r"[ \t]+([A-Za-z_]\w*)", text[exc.token.start_pos + len(shown):]
                             if exc.token.start_pos is not None else "")
            joined = f"{shown}_{after.group(1)}".upper() if after else ""
            if joined in keywords:
                hint = f"`{shown} {after.group(1)}` is one word: `{joined}`" if after else None
        if hint is None and exc.token.type == "NAME":   # a word where a keyword stands
            hint = did_you_mean(str(exc.token), _keywords(expected))
        before = (exc.token_history or [None])[-1]
        if hint is None and before is not None and before.type == "NAME" \
                and f"{before}_{shown}".upper() in keywords:      # `END VAR`, `END` a name
            hint = f"`{before} {shown}` is one word: `{f'{before}_{shown}'.upper()}`"
        if hint is None and before is not None and before.type == "NAME":
            hint = read_as_one_name(str(before), set(_keywords(expected)), keywords,
                                    fold=str.upper) or _underscore_dropped(str(before),
                                                                           keywords)
    elif isinstance(exc, UnexpectedCharacters):
        pos: int = exc.pos_in_stream  # type: ignore[assignment]  # lark declares None; the lexer sets an int
        char = text[pos] if pos < len(text) else ""
        what = f"unexpected character `{char}`"
    else:
        what = "cannot read this"
    return FormatError(what, span=Span.in_text(text, path, line, column, end_column),
                       expected=_expected(expected), hint=hint)


def _underscore_dropped(name: str, keywords: set[str]) -> str | None:
    """``ENDVAR`` read as a variable's name before the error: a keyword without its `_`."""
    written = next((k for k in keywords if "_" in k and k.replace("_", "") == name.upper()),
                   None)
    return f"`{name}` is read as a name: did you mean `{written}`?" if written else None


#: option keys (one terminal, OPTION_KEY) as FCL writes them
OPTION_KEYS = ("METHOD", "ACCU", "AND", "OR", "ACT", "ACTIVATION", "IMPLICATION")


def _keywords(terminals: Iterable[str]) -> list[str]:
    """The keywords among ``terminals``, as FCL writes them (for "did you mean")."""
    words: list[str] = []
    for t in terminals:
        if t == "OPTION_KEY":
            words.extend(OPTION_KEYS)
        elif (literal := _literal(t)) is not None and literal.replace("_", "").isalpha():
            words.append(literal)
    return words


def _literal(terminal: str) -> str | None:
    """The text of a keyword or punctuation terminal (``END_FUZZIFY``, ``:=``), or None for
    a terminal that is a pattern (a name, a number)."""
    from lark.lexer import PatternStr

    for t in parser().terminals:
        if t.name == terminal:
            return t.pattern.value.upper() if isinstance(t.pattern, PatternStr) else None
    return None


def _word(terminal: str) -> str:
    """A terminal as a reader of FCL knows it: ``END_FUZZIFY``, `` `:=` ``, a name."""
    names = {"NAME": "a name", "SIGNED_NUMBER": "a number", "NAN": "nan", "INF": "inf",
             "INT": "a number", "WORD": "a hedge", "OPTION_KEY": "/".join(OPTION_KEYS[:5]),
             "SINGLETONS": "SINGLETONS", "FORMULA": "FUNCTION", "$END": "the end of the file"}
    if terminal in names:
        return names[terminal]
    literal = _literal(terminal)
    if literal is None:
        return terminal
    return literal if literal.replace("_", "").isalpha() else f"`{literal}`"


def _parse(text: str, path: str | None) -> Tree:
    """``text``'s parse tree, or its syntax error; a keyword glued to the next word
    (``IF dist ISlo``, ``WITH0.5``) is refused at the word, as jFuzzyLogic refuses it."""
    try:
        return parse_apart(parser(), text)
    except Glued as glued:
        raise _glued_error(glued, text, path) from None
    except UnexpectedInput as exc:
        raise _syntax_error(exc, text, path) from None


def _glued_error(glued: Glued, text: str, path: str | None) -> FormatError:
    """A keyword glued to the next word (``ISlo``) said at the word: what could stand there,
    and "two words" when what follows the keyword may follow it, else "did you mean" the
    keyword (``END_RULEBLOCKx``)."""
    first, second = glued.first, glued.second
    word = text[first.start_pos:second.end_pos]
    expected = accepted_before(parser(), text, first)
    keyword = first.type == "OPTION_KEY" or (_literal(first.type) or "1").replace("_", "")\
        .isalpha()
    hint = None
    if keyword and glued.fits:
        hint = f"`{first}` and `{second}` are two words: `{first} {second}`"
    elif keyword:
        hint = did_you_mean(word, _keywords(expected))
    line, column = first.line or 1, first.column or 1
    end = column + len(word) if "\n" not in word else None
    return FormatError(f"unexpected `{word}`", span=Span.in_text(text, path, line, column, end),
                       expected=_expected(expected), hint=hint)


def _expected(terminals: set[str]) -> str | None:
    words = sorted({_word(e) for e in terminals})
    if len(words) == 1:
        return words[0]                       # "a name", not "one of a name"
    return ("one of " + ", ".join(words)) if words else None


@without_cyclic_gc
def parse_fcl(text: str, path: str | None = None) -> RuleBase:
    """Read FCL ``text`` into a rule base (one behavior, ``main``)."""
    text = lone_cr_as_lf(text)
    tree = _parse(text, path)

    def span_of(node: Node) -> Span:
        if isinstance(node, Token):
            return Span.in_text(text, path, node.line or 1, node.column or 1, node.end_column)
        meta = node.meta
        if meta.empty:
            return Span.in_text(text, path, 1, 1)
        end = meta.end_column if meta.end_line == meta.line else None
        return Span.in_text(text, path, meta.line, meta.column, end)

    check_depth(tree, span_of)                  # before scan_values, which recurses
    for token in tree.scan_values(lambda v: isinstance(v, Token) and v.type == "SIGNED_NUMBER"):
        if math.isinf(float(token)):
            raise common.past_range(str(token), span_of(token))
    blocks = [b for b in tree.children if isinstance(b, Tree)]     # the grammar's blocks
    if len(blocks) == 1:
        return _function_block(blocks[0], span_of)
    return _blocks_as_behaviors(blocks, span_of)


def _blocks_as_behaviors(blocks: list[Tree], span_of: SpanOf) -> RuleBase:
    """Several FUNCTION_BLOCKs (jFuzzyLogic reads each by its name): a behavior each, named
    after its block, over the variables of all of them. A variable two blocks define
    differently, and two blocks of one name, are refused: a rule base has one of each."""
    parts: list[tuple[str, RuleBase | None, TermSet]] = []
    for i, fb in enumerate(blocks):
        token = fb.children[0]
        name = str(token) if isinstance(token, Token) else f"block{i + 1}"
        if any(name == n for n, _, _ in parts):
            raise FormatError(f"two function blocks are named `{name}`", span=span_of(fb),
                              hint="rename one: each becomes a behavior of that name")
        try:
            rb = _function_block(fb, span_of)
        except NoRulesError as exc:          # a block of terms only: its variables count
            parts.append((name, None, cast(TermSet, exc.termset)))
            continue
        parts.append((name, rb, rb.termsets[0]))
    termset = TermSet(tuple(_shared_variables(parts)), span_of(blocks[0]).path)
    behaviors = [Behavior(name if len(rb.behaviors) == 1 else f"{name}_{b.name}", b.rules,
                          b.uses, b.operators or rb.operators)
                 for name, rb, _ in parts if rb is not None for b in rb.behaviors]
    if not behaviors:
        raise NoRulesError("the file has no rules", span=span_of(blocks[0]), termset=termset)
    notes = tuple(n for _, rb, _ in parts if rb is not None for n in rb.notes)
    return RuleBase(termset.path, (termset,), tuple(behaviors), (), notes=notes)


def _shared_variables(parts: list[tuple[str, RuleBase | None, TermSet]]) -> list[Variable]:
    """The variables of every block, each once: one two blocks define alike is shared."""
    variables: dict[str, Variable] = {}
    for _, _, ts in parts:
        for v in ts.variables:
            first = variables.setdefault(v.name, v)
            if first != v:
                raise FormatError(f"variable `{v.name}` is defined in two function blocks, "
                                  f"differently" + first_at(first.span), span=v.span,
                                  hint="rename it in one of them: the blocks' behaviors share "
                                       "one set of variables")
    return list(variables.values())


def _num(tree: Node) -> float:
    token = tree.children[0] if isinstance(tree, Tree) else tree
    return float(str(token))


def _function_block(fb: Tree, span_of: SpanOf) -> RuleBase:
    """The rule base of one FUNCTION_BLOCK: its declared variables, their FUZZIFY and
    DEFUZZIFY blocks, and its RULEBLOCKs (one behavior, or one per block where their
    operators differ and their outputs do not meet)."""
    declared, fuzzify, defuzzify, blocks = _declarations(fb, span_of)
    n_inputs = sum(1 for role, _, _ in declared.values() if role == "input")
    records: dict[str, common.Record] = {}           # per output: METHOD, ACCU
    notes: list[str] = []
    locks: dict[str, Span] = {}
    constants: list[tuple[str, Term]] = []
    variables: dict[str, Variable] = {}
    ranges: common.Places = {}                        # where each RANGE and DEFAULT is written
    for node in fuzzify + defuzzify:
        role: Role = "input" if node.data == "fuzzify" else "output"
        record = records.setdefault(str(node.children[0]), common.Record())
        v = _variable(node, role, declared, record, locks, constants, n_inputs, span_of, notes,
                      ranges, variables)
        if v.name in variables:
            raise FormatError(f"variable `{v.name}` is defined twice"
                              + first_at(variables[v.name].span), span=v.span)
        variables[v.name] = v
    for name, (role, span, _) in declared.items():
        if name in variables:
            continue
        if variables and not any(isinstance(r, Tree) and r.data == "rule"
                                 for b in blocks for r in b.children):
            raise NoRulesError("the file has no rules", span=span_of(fb),   # terms only (tests
                               termset=TermSet(tuple(variables.values()),   # of jFuzzyLogic's)
                                               span_of(fb).path))
        kind = "FUZZIFY" if role == "input" else "DEFUZZIFY"
        raise FormatError(f"variable `{name}` is declared but has no {kind} block", span=span)
    outputs_written = {n: records[n] for n in declared if declared[n][0] == "output"}
    for name, points in common.own_resolutions(outputs_written).items():   # `COG 200`, MITOS's
        variables[name] = dataclasses.replace(variables[name], resolution=points)
    parsed = [_rule_block(block, variables, span_of, notes) for block in blocks]
    parsed = [p for p in parsed if p[2]] or parsed[:1]
    outputs = [n for n in declared if declared[n][0] == "output"]
    for n in outputs:
        _tsukamoto(records[n], variables[n], notes)
    all_rules = [r for _, _, rules in parsed for r in rules]
    for n in outputs:
        _singletons_note(records[n], variables[n], all_rules, notes)
    groups = common.rule_blocks(parsed, {n: records[n] for n in outputs},
                                renumber=len({r.label for r in all_rules}) < len(all_rules))
    _check_outputs(groups, locks, constants)
    in_defuzzify = {(e[2].line, e[2].column) for n in outputs for e in records[n]
                    if e[0] == "aggregation" and e[2] is not None}
    _accumulation(groups, in_defuzzify, notes)
    ordered = [variables[n] for n in declared]
    rb = common.assemble_blocks(span_of(fb).path, ordered, groups, DEFAULT_RESOLUTION,
                                span_of(fb), notes, ranges)
    return dataclasses.replace(rb, notes=tuple(notes))


Declared = dict[str, tuple[Role, Span, tuple[float, float] | None]]


def _declarations(fb: Tree, span_of: SpanOf) -> tuple[Declared, list[Tree], list[Tree], list[Tree]]:
    """The VAR_INPUT / VAR_OUTPUT declarations by name (role, place, RANGE), and the
    FUZZIFY, DEFUZZIFY and RULEBLOCK blocks in the order written."""
    declared: Declared = {}
    fuzzify, defuzzify, blocks = [], [], []
    for item in fb.children[1:]:
        if item.data in ("var_input", "var_output"):
            role: Role = "input" if item.data == "var_input" else "output"
            for decl in item.children:
                name, typ, rng, after = decl.children
                rng = rng if rng is not None else after
                if str(name) in declared:
                    raise FormatError(f"variable `{name}` is declared twice"
                                      + first_at(declared[str(name)][1]), span=span_of(name))
                if str(typ).upper() != "REAL":
                    raise FormatError(f"variable `{name}`: type `{typ}` is not supported",
                                      span=span_of(typ), expected="REAL")
                r = (_num(rng.children[0]), _num(rng.children[1])) if rng is not None else None
                declared[str(name)] = (role, span_of(name), r)
        elif item.data == "fuzzify":
            fuzzify.append(item)
        elif item.data == "defuzzify":
            defuzzify.append(item)
        else:
            blocks.append(item)
    return declared, fuzzify, defuzzify, blocks


def _rule_block(block: Tree, variables: dict[str, Variable], span_of: SpanOf,
                notes: list[str]) -> tuple[str, common.Record, list[Rule]]:
    """One RULEBLOCK's name, operators and rules. IEC 61131-7 names one of AND and OR: the
    other one is its dual."""
    record = common.Record()
    for item in block.children[1:]:
        if item.data == "option":
            _option(item, record, span_of, {}, notes)
    keys = {key for key, *_ in record}
    pair = _jfl_pair(block)
    if "and_" in keys and "or_" not in keys:
        and_ = next(v for k, v, *_ in record if k == "and_")
        record.set("or_", pair or norms.lookup("tnorm", and_).dual, None, "OR")
    elif "or_" in keys and "and_" not in keys:
        or_ = next(v for k, v, *_ in record if k == "or_")
        record.set("and_", pair or norms.lookup("snorm", or_).dual, None, "AND")
    else:
        _both_note(block, record, span_of, notes)
    rule_items = [x for x in block.children[1:] if x.data == "rule"]
    rules = [part for i, item in enumerate(rule_items)
             for part in _split(_rule(item, variables, span_of, i), notes)]
    _grouping_note(rule_items, span_of, notes)
    name = str(block.children[0]) if block.children[0] is not None else ""
    return name, record, rules


#: jFuzzyLogic's own names that set the other connective too, to a pair that is not De
#: Morgan's (`RuleBlock.fclTree`: HAMACHER goes with the Einstein sum, not the Hamacher sum)
JFL_PAIRS = {("AND", "HAMACHER"): "einstein_sum", ("OR", "EINSTEIN"): "hamacher"}


def _jfl_pair(block: Tree) -> str | None:
    """The other connective a RULEBLOCK's `AND : HAMACHER` or `OR : EINSTEIN` sets."""
    for item in block.children[1:]:
        if item.data == "option":
            key, value = (str(t).upper() for t in item.children[:2])
            if (key, value) in JFL_PAIRS:
                return JFL_PAIRS[key, value]
    return None


#: jFuzzyLogic's names of the connectives (``Fcl.g``)
JFL_NAMES = {"AND": {"MIN", "PROD", "BDIF", "DMIN", "NIPMIN", "HAMACHER"},
             "OR": {"MAX", "ASUM", "BSUM", "DMAX", "NIPMAX", "EINSTEIN"}}


def _both_note(block: Tree, record: common.Record, span_of: SpanOf, notes: list[str]) -> None:
    """Say where a RULEBLOCK gives both AND and OR in jFuzzyLogic's names, not as the pair its
    last line sets: MITOS uses each, as fuzzylite does; jFuzzyLogic sets both connectives from
    each line, so the last one decides both (`RuleBlock.fclTree`)."""
    lines = [(k, v, item) for item in block.children[1:] if item.data == "option"
             for k, v in [(str(t).upper() for t in item.children[:2])] if k in JFL_NAMES]
    if {k for k, _, _ in lines} != {"AND", "OR"} or any(v not in JFL_NAMES[k]
                                                         for k, v, _ in lines):
        return
    ops = {k: v for k, v, *_ in record}
    key, value, item = lines[-1]
    other = JFL_PAIRS.get((key, value))
    theirs = (ops["and_"], other or norms.lookup("tnorm", ops["and_"]).dual) if key == "AND" \
        else (other or norms.lookup("snorm", ops["or_"]).dual, ops["or_"])
    if theirs != (ops["and_"], ops["or_"]):
        notes.append(f"{span_of(item)}: both AND (`{ops['and_']}`) and OR (`{ops['or_']}`) are "
                     f"given, not as a pair: MITOS uses each, as fuzzylite does; jFuzzyLogic "
                     f"sets both from each line, so its last, `{key} : {value}`, gives AND "
                     f"`{theirs[0]}` and OR `{theirs[1]}`: give one of them, or their pair")


def _check_outputs(groups: list, locks: dict[str, Span],
                   constants: list[tuple[str, Term]]) -> None:
    """Refuse what a behavior's inference cannot mean: `LOCK : RANGE` on a Takagi-Sugeno
    output, and fuzzylite's `Constant` term in a Mamdani one."""
    for _, rules, settings in groups:
        concluded = {c.var for r in rules for c in r.consequents}

        def mine(n: str, concluded: set = concluded) -> bool:
            return n in concluded or len(groups) == 1
        if settings.sugeno:
            for name, span in locks.items():
                if mine(name):
                    raise FormatError(f"`LOCK : RANGE` on the Takagi-Sugeno output `{name}` "
                                      f"(clipping the output to its range) is not supported",
                                      span=span)
        else:
            for name, term in constants:
                if mine(name):
                    raise FormatError(
                        f"term `{name}.{term.name}`: in a Mamdani output fuzzylite's "
                        f"`Constant` is a flat membership of that height everywhere, which "
                        f"MITOS does not support", span=term.span,
                        hint=f"for a singleton write `TERM {term.name} := value;`")


def _tsukamoto(record: common.Record, v: Variable, notes: list[str]) -> None:
    """`METHOD : COGS;` over monotonic terms is Tsukamoto inference, as fuzzylite's FCL
    importer infers it (its weighted defuzzifiers' `Automatic` type)."""
    if not v.terms or any(t.shape not in TSUKAMOTO for t in v.terms):
        return
    for i, (key, value, where, what) in enumerate(record):
        if key == "defuzzify" and value == "weighted_average":
            record[i] = (key, "tsukamoto", where, what)
            if any(t.shape == "sigmoid" for t in v.terms):
                notes.append(f"{where}: `{v.name}` inverts sigmoid terms (Tsukamoto inference); "
                             f"a sigmoid reaches 1 only at infinity, so where a rule fires "
                             f"fully the output is +-inf, as in fuzzylite")


def _singletons_note(record: common.Record, v: Variable, rules: list[Rule],
                     notes: list[str]) -> None:
    """A singleton term concluded under a continuous METHOD (COG, also where none is written):
    jFuzzyLogic throws on every evaluation (`RuleActivationMethod.imply`: a discrete term under
    a continuous defuzzifier), MITOS computes its centroid of spikes (engine/mamdani.py)."""
    method, where = next(((value, span) for key, value, span, _ in record
                          if key == "defuzzify"), ("centroid", None))
    singles = {t.name for t in v.terms if t.shape == "singleton"}
    used = [c.term for r in rules for c in r.consequents if c.var == v.name and c.term in singles]
    if not used or method in ("weighted_average", "weighted_sum", "tsukamoto"):
        return
    written = f"`METHOD : {common.DEFUZZIFIERS[method][FCL]}`" if where else "no METHOD (COG)"
    notes.append(f"{where or v.span}: `{v.name} IS {used[0]}` concludes a singleton under "
                 f"{written}: jFuzzyLogic throws on every evaluation (a discrete term under a "
                 f"continuous defuzzifier); MITOS averages the singletons, each snapped to "
                 f"its nearest sample, weighted by their aggregated degrees")


def _variable(node: Tree, role: Role, declared: Declared, settings: common.Record, locks: dict,
              constants: list, n_inputs: int, span_of: SpanOf, notes: list[str],
              ranges: common.Places | None = None,
              known: dict[str, Variable] | None = None) -> Variable:
    """A FUZZIFY or DEFUZZIFY block as a :class:`Variable`, checked against its declaration
    (``declared``); its output settings go to ``settings``, its `LOCK : RANGE` to ``locks``,
    its constant output terms to ``constants`` and where it writes RANGE and DEFAULT to
    ``ranges``."""
    name_token = node.children[0]
    name = str(name_token)
    if name not in declared:
        raise FormatError(f"`{name}` is not declared in VAR_INPUT / VAR_OUTPUT",
                          span=span_of(name_token), hint=did_you_mean(name, declared))
    declared_role, _, universe = declared[name]
    if declared_role != role:
        raise FormatError(f"`{name}` is declared as an {declared_role} but has a "
                          f"{'FUZZIFY' if role == 'input' else 'DEFUZZIFY'} block",
                          span=span_of(name_token))
    terms: list[Term] = []
    default = None
    default_span: Span | None = None
    for item in node.children[1:]:
        kind = item.data
        if kind == "term":
            inputs = tuple(n for n, (r, _, _) in declared.items() if r == "input")
            terms.append(_term(item, role, n_inputs, span_of, inputs))
            definition = item.children[1]
            if role == "output" and definition.data == "shape_def" and \
                    str(definition.children[0]).lower() == "constant":
                constants.append((name, terms[-1]))
        elif kind == "range_item":
            universe = (_num(item.children[0]), _num(item.children[1]))
            common.check_range(*universe, span_of(item), "RANGE")
            if ranges is not None:
                ranges[name, "range"] = span_of(item)
        elif kind == "option":
            key = str(item.children[0]).upper()
            if role == "input":
                raise FormatError(f"`{key}` has no meaning in FUZZIFY", span=span_of(item))
            _option(item, settings, span_of, {}, notes)
        elif kind == "default_item":
            default = _default(item, span_of)   # nan: NaN when no rule fires, as asked
            default_span = span_of(item)
            if ranges is not None:
                ranges[name, "default"] = default_span
        elif kind == "lock_item":
            for word in item.children:
                locks[name] = _lock_range(word, span_of)
    weighted = any(entry[0] == "defuzzify" and entry[1] in ("weighted_average", "weighted_sum")
                   for entry in settings)
    lo, hi = _universe(node, name, role, universe, terms, declared, default, span_of, notes,
                       known, weighted, default_span)
    try:
        return Variable(name, role, (lo, hi), tuple(terms), "", "", default, span_of(name_token))
    except Exception as exc:                     # duplicate terms: TermSetError with a span
        raise FormatError(getattr(exc, "message", str(exc)),
                          span=getattr(exc, "span", None) or span_of(node)) from None


def _default(item: Tree, span_of: SpanOf) -> float:
    """A `DEFAULT := value;` item's value; `NC` and the `| NC` flag are refused: keeping the
    previous output needs state between evaluations, which MITOS does not keep."""
    value, flag = item.children
    if flag is not None:
        if str(flag).upper() == "NC":
            raise FormatError("`| NC` (no change: keep the previous output when no rule "
                              "fires) needs state between evaluations, which MITOS does "
                              "not keep", span=span_of(flag),
                              hint="give a plain `DEFAULT := value;`")
        raise FormatError(f"unknown DEFAULT flag `{flag}`", span=span_of(flag),
                          expected="NC")
    if isinstance(value, Token) and value.type == "NAME":
        if str(value).upper() == "NC":
            raise FormatError("`DEFAULT := NC` (no change: keep the previous output "
                              "when no rule fires) needs state between evaluations, "
                              "which MITOS does not keep", span=span_of(value),
                              hint="give a number: `DEFAULT := value;`")
        raise FormatError(f"DEFAULT must be a number, not `{value}`", span=span_of(value))
    return _num(value)


def _lock_range(word: Node, span_of: SpanOf) -> Span:
    """Where a `LOCK` word says RANGE (the output is clipped to its range); `PREVIOUS` is
    refused (it needs state between evaluations, which MITOS does not keep), as is any
    other word."""
    w = str(word).upper()
    if w == "PREVIOUS":
        raise FormatError("`LOCK : PREVIOUS` (keep the previous output when no rule "
                          "fires) needs state between evaluations, which MITOS does "
                          "not keep", span=span_of(word))
    if w != "RANGE":
        raise FormatError(f"unknown LOCK `{word}`", span=span_of(word),
                          expected="PREVIOUS or RANGE")
    return span_of(word)


def _universe(node: Tree, name: str, role: Role, universe: tuple[float, float] | None,
              terms: list[Term], declared: Declared, default: float | None, span_of: SpanOf,
              notes: list[str], known: dict[str, Variable] | None, weighted: bool = False,
              default_span: Span | None = None) -> tuple[float, float]:
    """The variable's range: as declared or written (RANGE), else where jFuzzyLogic puts it,
    from its terms (:func:`_linear_extent` for linear output terms, :func:`_extent`); a
    variable without terms or with an empty range is refused. An output without RANGE whose
    DEFAULT lies beyond its terms' extent: under COGS / COGSS (``weighted``), which average its
    singletons and sample no range, the range is widened to hold the default, as for linear
    terms; otherwise (a sampled output) it is refused, saying that the range was derived."""
    if not terms and (role == "output" or universe is None):
        raise FormatError(f"variable `{name}` has no terms", span=span_of(node),
                          hint=None if role == "output" else "an input without terms (it only "
                          "feeds linear consequents) needs `RANGE := (min .. max);`")
    if universe is None and any(t.shape == "linear" for t in terms):
        names = [n for n, (r, _, _) in declared.items() if r == "input"]
        universe = _linear_extent(terms, names, known or {}, default, name, span_of(node),
                                  notes)
    d = default if role == "output" and default is not None and default == default else None
    if universe is None and d is not None and weighted and terms and \
            all(t.shape == "singleton" for t in terms):
        xs = [t.params[0] for t in terms]
        if not min(xs) <= d <= max(xs):
            universe = (min(*xs, d), max(*xs, d))
            notes.append(f"{span_of(node)}: `{name}` has no RANGE; its universe [{universe[0]:g}, "
                         f"{universe[1]:g}] holds its terms' values and its DEFAULT "
                         f"{fmt_number(d)} (the weighted average samples no range)")
    if universe is None:
        lo, hi = universe = _extent(terms, name, span_of(node), notes)
        if d is not None and not lo <= d <= hi:
            raise FormatError(
                f"output `{name}` has no RANGE, and its DEFAULT {fmt_number(d)} lies outside "
                f"[{lo:g}, {hi:g}], the extent of its terms, which jFuzzyLogic takes for its "
                f"universe (`Variable.estimateUniverse`) and samples; a MITOS output's default "
                f"lies inside its universe", span=default_span or span_of(node),
                hint=f"add `RANGE := ({min(lo, d):g} .. {max(hi, d):g});` (the output is then "
                     f"sampled there), or give a DEFAULT inside [{lo:g}, {hi:g}]")
    lo, hi = universe
    if not lo < hi:
        raise FormatError(f"variable `{name}`: range [{lo:g}, {hi:g}] is empty",
                          span=span_of(node))
    return lo, hi


#: Where jFuzzyLogic's ``estimateUniverse`` puts the ends of a term with unbounded support,
#: on MITOS's parameters: the Gaussians' mean -+ 4 sigma, a bell's centre -+ width *
#: 999^(1 / (2 slope)) (membership 0.001), a sigmoid's inflection -+ 9 / |slope|.
UNIVERSE_ESTIMATES = {
    "gaussian": lambda p: (p[0] - 4 * abs(p[1]), p[0] + 4 * abs(p[1])),
    "gaussian2": lambda p: (p[0] - 4 * abs(p[1]), p[2] + 4 * abs(p[3])),
    "bell": lambda p: (p[0] - abs(p[1]) * 999 ** (1 / (2 * p[2])),
                       p[0] + abs(p[1]) * 999 ** (1 / (2 * p[2]))),
    "sigmoid": lambda p: (p[0] - 9 / abs(p[1]), p[0] + 9 / abs(p[1])),
    "sigmoid_difference": lambda p: (min(p[0] - 9 / abs(p[1]), p[3] - 9 / abs(p[2])),
                                     max(p[0] + 9 / abs(p[1]), p[3] + 9 / abs(p[2]))),
    "cosine": lambda p: (p[0] - abs(p[1]) / 2, p[0] + abs(p[1]) / 2),
    "s_shape": lambda p: (p[0], p[1]), "z_shape": lambda p: (p[0], p[1]),
    "pi_shape": lambda p: (p[0], p[3]),
}
UNIVERSE_ESTIMATES["clipped_sigmoid_difference"] = UNIVERSE_ESTIMATES["sigmoid_difference"]
UNIVERSE_ESTIMATES["sigmoid_product"] = UNIVERSE_ESTIMATES["sigmoid_difference"]


def _extent(terms: list[Term], name: str, span: Span,
            notes: list[str] | None = None) -> tuple[float, float]:
    """A variable's range from its terms when the file gives none, as jFuzzyLogic derives it:
    the smallest interval holding every term's estimated support."""
    xs = []
    estimated = []
    for t in terms:
        if t.shape == "discrete":
            xs += list(t.params[0::2])
        elif t.corners is not None:
            xs += [c for c in t.corners if abs(c) != float("inf")]
        elif t.shape == "singleton":
            xs.append(t.params[0])
        elif t.shape in UNIVERSE_ESTIMATES:
            with np.errstate(all="ignore"):
                xs += list(UNIVERSE_ESTIMATES[t.shape](t.params))
            estimated.append(t.name)
        else:
            raise FormatError(f"variable `{name}` has no RANGE and its `{t.name}` term "
                              f"({t.shape}) has no bounded support", span=span,
                              hint="add `RANGE := (min .. max);`")
    if not all(math.isfinite(x) for x in xs):
        raise FormatError(f"variable `{name}` has no RANGE and its terms give no finite one",
                          span=span, hint="add `RANGE := (min .. max);`")
    if estimated and notes is not None and xs and min(xs) < max(xs):
        notes.append(f"{span}: `{name}` has no RANGE; its universe [{min(xs):g}, {max(xs):g}] "
                     f"is derived from its terms ({', '.join(estimated)} unbounded) as "
                     f"jFuzzyLogic estimates one")
    if xs and min(xs) == max(xs):
        raise FormatError(
            f"variable `{name}` has no RANGE and its terms lie at the one point "
            f"{fmt_number(xs[0])}: jFuzzyLogic takes [{fmt_number(xs[0])}, {fmt_number(xs[0])}] "
            f"for its universe (`Variable.estimateUniverse`: the extent of the terms), where an "
            f"output can be nothing but {fmt_number(xs[0])} and an input is out of range at any "
            f"other value; MITOS needs a universe with two ends", span=span,
            hint="add `RANGE := (min .. max);` with the values the variable takes")
    if not xs:
        raise FormatError(f"variable `{name}` has no RANGE and its terms do not span one",
                          span=span, hint="add `RANGE := (min .. max);`")
    return min(xs), max(xs)


def _linear_extent(terms: list[Term], inputs: list[str], known: dict[str, Variable],
                   default: float | None, name: str, span: Span,
                   notes: list[str]) -> tuple[float, float]:
    """The range of a Takagi-Sugeno output without a RANGE (jFuzzyLogic's FUNCTION terms):
    every value its terms take over the inputs' ranges, its default included. jFuzzyLogic
    averages the functions' values wherever they lie, so the range only has to hold them."""
    missing = [x for x in inputs if x not in known]
    if missing:
        raise FormatError(f"variable `{name}` has no RANGE, and its linear terms' values "
                          f"cannot be bounded before `{missing[0]}`'s FUZZIFY block", span=span,
                          hint="add `RANGE := (min .. max);`, or move the FUZZIFY blocks first")
    xs = [] if default is None or default != default else [default]
    others = [t for t in terms if t.shape != "linear"]
    if others:
        xs += list(_extent(others, name, span) if len(others) > 1 or others[0].shape != "singleton"
                   else (others[0].params[0],))
    for t in terms:
        if t.shape != "linear":
            continue
        lo = hi = t.params[-1]
        for x, a in zip(inputs, t.params[:-1]):
            ends = (a * known[x].universe[0], a * known[x].universe[1])
            lo, hi = lo + min(ends), hi + max(ends)
        xs += [lo, hi]
    if not all(math.isfinite(x) for x in xs) or min(xs) == max(xs):
        raise FormatError(f"variable `{name}` has no RANGE and its terms do not span one",
                          span=span, hint="add `RANGE := (min .. max);`")
    notes.append(f"{span}: `{name}` has no RANGE; its universe [{min(xs):g}, {max(xs):g}] holds "
                 f"every value of its linear terms over the inputs' ranges")
    return min(xs), max(xs)


def _no_variable(term: str, node: Node, span_of: SpanOf) -> None:
    """jFuzzyLogic lets a membership parameter be a variable's name (optimised by its
    learning code); MITOS's terms have numbers."""
    if isinstance(node, Token) and node.type == "NAME":
        raise FormatError(f"term `{term}`: a parameter given by a variable (`{node}`) is not "
                          f"supported", span=span_of(node), hint="write the number")


def _point_values(term: str, points: list[Tree], span_of: SpanOf) -> list[Tree]:
    for p in points:
        for v in p.children:
            _no_variable(term, v, span_of)
    return points


def _term(item: Tree, role: str, n_inputs: int, span_of: SpanOf, inputs: tuple[str, ...] = ()) -> Term:
    name_token, definition = item.children
    name, span = str(name_token), span_of(item)
    if definition.data == "singleton_def":
        return common.make_term(name, "singleton", (_num(definition.children[0]),), span)
    if definition.data == "formula_def" and role == "output":
        # jFuzzyLogic's Takagi-Sugeno consequent: a singleton at the function's value
        token = definition.children[0]
        coefficients = list(linear_function(str(token), span_of(token), inputs))
        return common.fuzzylite_term(name, "Linear", coefficients, n_inputs, span)
    if definition.data == "formula_def":
        raise _formula_term(name, role, definition.children[0], span_of)
    if definition.data == "singletons_def":
        raise FormatError(f"term `{name}`: SINGLETONS terms (several weighted singletons in one "
                          f"term) are not supported", span=span_of(definition.children[0]),
                          hint="give each singleton its own term (`TERM t := value;`)")
    if definition.data == "points":
        pts = [(_num(p.children[0]), _num(p.children[1])) for p in _point_values(
            name, definition.children, span_of)]
        return _points_term(name, pts, span)
    kind_token, *value_nodes = definition.children
    for v in value_nodes:
        _no_variable(name, v, span_of)
    kind = str(kind_token)
    values = [_num(v) for v in value_nodes]
    # fuzzylite's class names in their own spelling first: `Cosine c w` is fuzzylite's
    # (center, width), `COSINE t c` jFuzzyLogic's (net_max, offset)
    if kind.lower() in JFUZZY_SHAPES and kind not in common.FUZZYLITE_SHAPES:
        shape, count, convert = JFUZZY_SHAPES[kind.lower()]
        if len(values) != count:
            raise FormatError(f"term `{name}`: {kind} takes {plural(count, 'number')}, "
                              f"not {len(values)}",
                              span=span)
        return common.make_term(name, shape, tuple(convert(tuple(values))), span)
    by_lower = {k.lower(): k for k in common.FUZZYLITE_SHAPES} | {
        k.lower(): k for k in common.FORMULA_TERMS}
    if kind.lower() in by_lower:
        fl_kind = by_lower[kind.lower()]
        if fl_kind == "Linear" and role != "output":
            raise FormatError(f"term `{name}`: Linear terms belong to outputs", span=span)
        return common.fuzzylite_term(name, fl_kind, values, n_inputs, span)
    known = sorted(JFUZZY_SHAPES) + sorted(common.FUZZYLITE_SHAPES)
    raise FormatError(f"term `{name}`: unknown membership function `{kind}`", span=span,
                      expected="a point list (x, y) ..., a number, or one of " + ", ".join(known),
                      hint=did_you_mean(kind, known))


def _formula_term(name: str, role: str, token: Node, span_of: SpanOf) -> FormatError:
    """The refusal of an input's membership given by a formula (an output's ``FUNCTION`` is
    a Takagi-Sugeno consequent: :func:`.fclfunction.linear_function`)."""
    word = str(token).split()[0].split("(")[0]
    return FormatError(f"term `{name}`: {word} terms (a membership given by a formula) are "
                       f"not supported", span=span_of(token),
                       hint="replace the formula by one of the shapes (trian, trape, gauss, "
                            "gbell, sigm, ...) or a point list")


def _points_term(name: str, pts: list[tuple[float, float]], span: Span) -> Term:
    """A point list, as the simplest MITOS shape that draws exactly the same polyline."""
    xs = [p[0] for p in pts]
    ys = [p[1] for p in pts]
    if any(a > b for a, b in zip(xs, xs[1:])):
        raise FormatError(f"term `{name}`: the points' x values must ascend", span=span)
    if len(set(xs)) == len(xs):
        if ys == [0, 1, 0]:
            return common.make_term(name, "triangle", tuple(xs), span)
        if ys == [0, 1, 1, 0]:
            return common.make_term(name, "trapezoid", tuple(xs), span)
        if ys == [1, 0]:
            return common.make_term(name, "left_shoulder", tuple(xs), span)
        if ys == [0, 1]:
            return common.make_term(name, "right_shoulder", tuple(xs), span)
    if len(pts) == 1:
        raise FormatError(f"term `{name}`: a point list needs at least two points", span=span,
                          hint=f"for a singleton write `TERM {name} := {fmt_number(xs[0])};`")
    return common.make_term(name, "discrete", tuple(v for p in pts for v in p), span)


#: Names that mean an S-norm after `OR :` (the same word after `AND :` is the T-norm).
OR_ALIASES = {"EINSTEIN": "einstein_sum", "HAMACHER": "hamacher_sum"}


#: jFuzzyLogic's ``ACCU : NSUM`` (``RuleAccumulationMethodNormedSum``): ``(a + b) / max(1, a +
#: b)``, which is ``a + b`` up to 1 and ``(a + b) / (a + b)``, exactly 1, above: the bounded sum
#: ``min(1, a + b)`` bit for bit (and pyfuzzylite 8's ``NormalizedSum``). fuzzylite 6's
#: ``NormalizedSum``, which its FCL reader makes of ``NSUM``, is ``a + b / max(1, max(a, b))``.
NSUM_MEANS = ("jFuzzyLogic's normalized sum, (a + b) / max(1, a + b), which is the bounded "
              "sum min(1, a + b) exactly")


def _option(item: Tree, settings: common.Record, span_of: SpanOf, conj: dict,
            notes: list[str] | None = None) -> None:
    key_token, value_token, number = item.children
    key, value, span = str(key_token).upper(), str(value_token), span_of(value_token)
    if key == "AND":
        settings.set("and_", _norm(common.TNORMS, value, "AND", span), span, "AND")
    elif key == "OR":
        # jFuzzyLogic's `OR : EINSTEIN;` is the Einstein sum (RuleConnectionMethodOrEinstein)
        name = OR_ALIASES.get(value.upper()) or _norm(common.SNORMS, value, "OR", span)
        settings.set("or_", name, span, "OR")
    elif key in ("ACT", "IMPLICATION"):
        settings.set("implication", common.check_implication(
            _norm(common.TNORMS, value, "ACT", span), span), span, "ACT")
    elif key == "ACTIVATION":
        if value.lower() != "general":
            raise FormatError(f"activation `{value}` is not supported: MITOS activates every "
                              f"rule", span=span)
    elif key == "ACCU" and value.upper() == "NSUM":
        settings.set("aggregation", "bounded_sum", span, "ACCU")
        if notes is not None:
            notes.append(f"{span}: `ACCU : NSUM` is read as {NSUM_MEANS} (`bounded_sum`); "
                         f"fuzzylite 6 reads it as its `NormalizedSum`, a + b / max(1, max(a, "
                         f"b)), the plain sum while both are at most 1")
    elif key == "ACCU":
        # SUM: jFuzzyLogic's default, the unbounded sum (under COGS the accumulation, below)
        settings.set("aggregation", _norm(common.AGGREGATIONS, value, "ACCU", span), span, "ACCU")
    elif key == "METHOD":
        method = _norm(common.DEFUZZIFIERS, value, "METHOD", span)
        settings.set("defuzzify", method, span, "METHOD")
        if number is not None:
            res = _num(number)
            settings.set("resolution", common.resolution(res, fmt_number(res), span_of(number)),
                         span_of(number), "resolution")


def _norm(table: dict, value: str, what: str, span: Span) -> str:
    """FCL's abbreviations (any case), or fuzzylite's class names."""
    try:
        return common.table_lookup(table, FCL, value, what, span, case=False)
    except FormatError:
        for mitos, names in table.items():
            if names[FLL] == value:
                return mitos
        raise


def _accumulation(groups: list[tuple[str, list[Rule], common.Settings]],
                  in_defuzzify: set[tuple[int, int]], notes: list[str]) -> None:
    """``ACCU`` under ``METHOD : COGS`` (or COGSS, COGF) is the behavior's ``accumulation``:
    jFuzzyLogic (and IEC 61131-7) join the rules that conclude one singleton value with the
    ACCU norm (`RuleActivationMethod.imply` at the defuzzifier's point of that value) before
    the weighted average; without ACCU (or with ``ACCU : SUM``) it sums them, which is
    MITOS's default. A Mamdani output without ACCU sums its rules' sets, jFuzzyLogic's
    default (`RuleBlock.fclTree`), ``aggregation = sum``.

    An ``ACCU`` inside DEFUZZIFY (its place at ``(line, column)`` in ``in_defuzzify``) is
    fuzzylite's dialect: jFuzzyLogic's grammar has none there, and fuzzylite 6, the engine
    that reads it, does not use the aggregation under a weighted defuzzifier (each rule is
    counted: its binary gives 0.32 where joining by MAX gives 0.4,
    ``tests/test_accumulation.py``), so it is read as the sum, and said where two rules
    conclude one term."""
    for _, rules, settings in groups:
        weighted = settings.defuzzify in ("weighted_average", "weighted_sum")
        if not weighted and not settings.sugeno and settings.aggregation is None:
            settings.aggregation = "sum"
        if not (weighted and settings.aggregation):
            continue
        span = (settings.spans or {}).get("aggregation")
        if span is not None and (span.line, span.column) in in_defuzzify:
            _fuzzylite_accu(rules, settings, span, notes)
            settings.aggregation = None
            continue
        settings.accumulation = settings.aggregation
        if settings.aggregation == "sum":
            settings.aggregation = None


def _fuzzylite_accu(rules: list[Rule], settings: common.Settings, span: Span,
                    notes: list[str]) -> None:
    """Say where fuzzylite's reading of a DEFUZZIFY ``ACCU`` under COGS (every rule counted)
    gives another number than jFuzzyLogic's would (the rules of one term joined)."""
    aggregation = settings.aggregation
    if aggregation is None or aggregation == "sum":
        return
    seen: dict[tuple[str, str | None, float | None], str] = {}
    for r in rules:
        for c in r.consequents:
            key = (c.var, c.term, c.value if c.term is None else None)
            if key in seen:
                what = f"`{format_consequent(c)}`"
                name = common.AGGREGATIONS[aggregation][FCL] or aggregation
                notes.append(f"{span}: `ACCU : {name}` in DEFUZZIFY under a weighted `METHOD` "
                             f"is fuzzylite's dialect, whose engine (fuzzylite 6) counts every "
                             f"rule there: read so, `{seen[key]}` and `{r.label}` both adding "
                             f"{what}; jFuzzyLogic would join them with {name} (write the ACCU "
                             f"in the RULEBLOCK for that)")
                return
            seen[key] = r.label


def _grouping_note(rule_items: list[Tree], span_of: SpanOf, notes: list[str]) -> None:
    """Say where a condition reads ``a OR b AND c`` without parentheses around the AND: MITOS
    (as fuzzylite) reads AND first, jFuzzyLogic's grammar (``condition : subcondition ((AND |
    OR) subcondition)*``) left to right, ``(a OR b) AND c``, and the file does not say which
    engine wrote it."""
    found = [span for item in rule_items if (span := _or_before_and(item.children[1], span_of))]
    if found:
        notes.append(f"{found[0]}: `OR` before an `AND` without parentheses "
                     f"({plural(len(found), 'rule')}): read with AND first (`a OR (b AND c)`), "
                     f"as fuzzylite reads it; jFuzzyLogic reads AND and OR left to right "
                     f"(`(a OR b) AND c`): add parentheses to say which")


def _or_before_and(tree: Node, span_of: SpanOf) -> Span | None:
    """Where an AND group follows an OR without parentheses of its own, else None."""
    if not isinstance(tree, Tree):
        return None
    for node in tree.iter_subtrees_topdown():
        if node.data != "or_expr":
            continue
        for child in node.children[1:]:
            if isinstance(child, Tree) and child.data == "and_expr":
                span = span_of(child)
                line = span.source_line or ""
                before = line[:max(span.column - span.source_start, 0)].rstrip()
                if before and not before.endswith("("):
                    return span
    return None


def _split(rule: Rule, notes: list[str]) -> list[Rule]:
    """A rule concluding several terms of one output (``THEN v IS a, v IS b``), as rules with
    its condition and weight, one per term (``r5``, ``r5_2``, ...): jFuzzyLogic implies each
    conclusion at the rule's degree and accumulates it like another rule's, so this is exact
    under every ACCU and METHOD."""
    layers: list[list] = []
    for c in rule.consequents:              # the k-th conclusion of an output: rule k
        layer = next((lay for lay in layers if all(d.var != c.var for d in lay)), None)
        if layer is None:
            layers.append([c])
        else:
            layer.append(c)
    if len(layers) == 1:
        return [rule]
    labels = [rule.label] + [f"{rule.label}_{i + 1}" for i in range(1, len(layers))]
    notes.append(f"{rule.span}: rule `{rule.label}` concludes {plural(len(layers), 'term')} of "
                 f"one output: read as the rules {', '.join(f'`{x}`' for x in labels)} with its "
                 f"condition and weight, each concluding one (jFuzzyLogic fires every "
                 f"conclusion); `mitos check` reports them as a conflict")
    return [Rule(label, rule.antecedent, tuple(layer), rule.weight, rule.span)
            for label, layer in zip(labels, layers)]


def _rule(item: Tree, variables: dict[str, Variable], span_of: SpanOf, index: int) -> Rule:
    label_tree, antecedent_tree, *rest = item.children
    weight_tree = rest[-1]
    label = str(label_tree.children[0])
    label = label if not label.isdigit() else f"r{label}"
    antecedent = expression(antecedent_tree, span_of, variables)
    weight = _num(weight_tree) if weight_tree is not None else 1.0
    return Rule(label, antecedent, conclusions(rest[:-1], span_of), weight,
                span_of(item))


# ---------------------------------------------------------------------------------------------
# Writer


#: The FCL dialects the writer writes, as ``mitos convert --dialect`` names them. The readers
#: disagree on two things only (checked on fuzzylite 6's ``FclImporter`` and jFuzzyLogic's
#: ``Fcl.g``): where ``ACCU`` stands (fuzzylite 6 refuses it in the RULEBLOCK and needs it in
#: DEFUZZIFY; IEC 61131-7 and jFuzzyLogic read it only in the RULEBLOCK, and jFuzzyLogic takes
#: SUM without it) and what joins two conclusions (fuzzylite 6: ``and``; IEC and jFuzzyLogic:
#: ``,``). Everything else is written in the form all three read.
DIALECTS = {
    "fuzzylite": "fuzzylite 6's FclImporter (ACCU in DEFUZZIFY, `and` between conclusions)",
    "iec": "IEC 61131-7 as jFuzzyLogic reads it (ACCU in the RULEBLOCK, `,` between "
           "conclusions)",
}
DEFAULT_DIALECT = "fuzzylite"


def write_fcl(rb: RuleBase, behavior: str | None = None, dialect: str = DEFAULT_DIALECT) -> str:
    """FCL text for one behavior of ``rb`` in ``dialect`` (:data:`DIALECTS`).

    Rule keywords are lower case (fuzzylite 6 reads only ``if is and or not then with``; IEC
    and jFuzzyLogic read keywords in any case) and ``METHOD`` carries no resolution (none of
    the three reads ``COG 200``; :func:`.conversion_notes` says what that changes)."""
    if dialect not in DIALECTS:
        raise FormatError(f"unknown FCL dialect `{dialect}`",
                          expected="one of " + ", ".join(DIALECTS),
                          hint=did_you_mean(dialect, DIALECTS))
    flat = common.flatten_for_export(rb, behavior)
    ops = flat.operators
    at = functools.partial(common.setting_span, rb, behavior)       # where an operator was chosen
    if ops.inference == "tsukamoto":
        raise FormatError("FCL has no Tsukamoto inference; write it to FLL or a rule file",
                          span=at("inference"))
    sugeno = ops.inference in ("weighted_average", "weighted_sum")
    inputs = common.all_inputs(rb, flat)
    accu = None if sugeno else common.foreign_name(
        common.AGGREGATIONS, FCL, ops.aggregation, "S-norm", span=at("aggregation"))
    if accu is not None and ops.aggregation == "sum" and dialect == "fuzzylite":
        # fuzzylite 6's FCL reader has no abbreviation for it (`SUM` fails the whole import)
        accu = common.AGGREGATIONS["sum"][FLL]
    if ops.accumulated and dialect == "fuzzylite":
        # fuzzylite 6 counts every rule under COGS whatever the ACCU (and so reads MITOS)
        common.refuse_accumulation(rb, behavior, flat, "fuzzylite's FCL",
                                   hint="write `--dialect iec` (jFuzzyLogic's ACCU) or a rule "
                                        "file")
    if ops.accumulated:                 # ACCU under COGS: jFuzzyLogic's join at a singleton
        accu = common.foreign_name(common.SNORMS, FCL, ops.accumulation, "S-norm",
                                   span=at("accumulation"))
    out = [f"// {DIALECTS[dialect]}; written by MITOS", "", f"FUNCTION_BLOCK {flat.name}", "",
           "VAR_INPUT"]
    # jFuzzyLogic's grammar has an input's RANGE after its declaration (`var_def`), not in
    # FUZZIFY, which holds terms only; fuzzylite 6 reads it in FUZZIFY
    iec = dialect == "iec"
    out += [f"    {v.name} : REAL;" + (f" {_range(v)}" if iec else "") for v in inputs]
    out += ["END_VAR", "", "VAR_OUTPUT"]
    out += [f"    {v.name} : REAL;" for v in flat.outputs] + ["END_VAR", ""]
    for v in inputs:
        out.append(f"FUZZIFY {v.name}")
        out += [] if iec else [f"    {_range(v)}"]
        out += [f"    TERM {t.name} := {_term_text(t, v, dialect)};" for t in v.terms]
        out += ["END_FUZZIFY", ""]
    for v in flat.outputs:
        out += _defuzzify(rb, v, ops, inputs, at, dialect, accu)
        out += ["END_DEFUZZIFY", ""]
    out.append(f"RULEBLOCK {flat.name}")
    and_ = common.foreign_name(common.TNORMS, FCL, ops.and_, "T-norm", span=at("and"))
    or_ = common.foreign_name(common.SNORMS, FCL, ops.or_, "S-norm", span=at("or"))
    out += [f"    AND : {and_};", f"    OR : {or_};"]
    if not sugeno:
        act = common.foreign_name(common.TNORMS, FCL, ops.implication, "T-norm",
                                  span=at("implication"))
        out.append(f"    ACT : {act};")
    if accu is not None and dialect == "iec":
        out.append(f"    ACCU : {accu};")
    for i, r in zip(_rule_numbers(flat.rules), flat.rules):
        out.append(f"    RULE {i} : {_rule_text(r, dialect, ops)};")
    out += ["END_RULEBLOCK", "", "END_FUNCTION_BLOCK"]
    return "\n".join(out) + "\n"


def _rule_numbers(rules: Sequence[Rule]) -> list[int]:
    """The number after each ``RULE``: a rule labelled ``rN`` keeps N, which the reader reads
    back as ``rN``, where every label is of that form and none repeats (the packaged rule base
    counts from r0: written 1, 2, ... its r4 came back as r5); else 1, 2, ... by position (IEC
    61131-7 numbers its rules, so other labels are not written)."""
    numbers = [int(m.group(1)) if (m := re.fullmatch(r"r(0|[1-9][0-9]*)", r.label)) else None
               for r in rules]
    if None in numbers or len(set(numbers)) < len(numbers):
        return list(range(1, len(rules) + 1))
    return [n for n in numbers if n is not None]


def _range(v: Variable) -> str:
    return f"RANGE := ({fmt_number(v.universe[0])} .. {fmt_number(v.universe[1])});"


def _defuzzify(rb: RuleBase, v: Variable, ops: Operators, inputs: Sequence[Variable],
               at: Callable[[str], Span | None], dialect: str,
               accu: str | None) -> list[str]:
    """An output's DEFUZZIFY block up to its END; ``accu``: the ACCU line fuzzylite's dialect
    writes after METHOD, where fuzzylite's own exporter writes it."""
    sugeno = ops.inference in ("weighted_average", "weighted_sum")
    out = [f"DEFUZZIFY {v.name}", f"    {_range(v)}"]
    for t in v.terms:
        if sugeno and t.shape == "linear":
            coefficients = common.linear_coefficients(rb, v.name, t)
            values = [coefficients.get(x.name, 0.0) for x in inputs] + [t.params[-1]]
            text = "Linear " + " ".join(fmt_number(c) for c in values)
        elif sugeno:
            text = fmt_number(t.center)
        else:
            text = _term_text(t, v, dialect)
        out.append(f"    TERM {t.name} := {text};")
    if sugeno:
        out.append(f"    METHOD : {common.DEFUZZIFIERS[ops.inference][FCL]};")
    else:
        method = common.foreign_name(common.DEFUZZIFIERS, FCL, ops.defuzzify, "defuzzifier",
                                     span=at("defuzzify"))
        out.append(f"    METHOD : {method};")
    if accu is not None and dialect == "fuzzylite":
        out.append(f"    ACCU : {accu};")
    # none: no DEFAULT line (the output is NaN); jFuzzyLogic's DEFAULT takes a number or NC,
    # and NaN is its default when no line gives one
    if v.default is not None and not (dialect == "iec" and math.isnan(v.default)):
        out.append(f"    DEFAULT := {fmt_number(v.default)};")
    return out


#: MITOS shapes jFuzzyLogic names (the IEC dialect writes them so): MITOS params -> its own
JFUZZY_NAMES = {
    "gaussian": ("GAUSS", lambda p: p),
    "gaussian2": ("GAUSS2", lambda p: p),
    "bell": ("GBELL", lambda p: (p[1], p[2], p[0])),
    "sigmoid": ("SIGM", lambda p: (p[1], p[0])),
    "cosine": ("COSINE", lambda p: (p[1] / 2.0, p[0])),
}


def _term_text(t: Term, v: Variable, dialect: str = DEFAULT_DIALECT) -> str:
    if t.formula is not None:
        raise FormatError(f"term `{v.name}.{t.name}`: FCL has no formula terms (fuzzylite's "
                          f"`Function`); write it to FLL or a term set", span=t.span)
    if t.shape == "singleton":
        return fmt_number(t.params[0])
    if t.shape == "clipped_sigmoid_difference":          # jFuzzyLogic's DSIGM g1 c1 g2 c2
        left, rising, falling, right = t.params
        return "DSIGM " + " ".join(fmt_number(x) for x in (rising, left, falling, right))
    if t.shape == "discrete":
        p = t.params
        return " ".join(f"({fmt_number(x)}, {fmt_number(y)})" for x, y in zip(p[0::2], p[1::2]))
    if t.corners is not None and t.shape not in ("rectangle", "ramp"):
        pts = _corner_points(t.corners)
        if pts is not None:
            return " ".join(f"({fmt_number(x)}, {fmt_number(y)})" for x, y in pts)
    if dialect == "iec" and t.shape in JFUZZY_NAMES:
        name, order = JFUZZY_NAMES[t.shape]
        return f"{name} " + " ".join(fmt_number(x) for x in order(t.params))
    return common.fuzzylite_term_text(t, v.name)


def _corner_points(corners: tuple[float, float, float, float]) -> list[tuple[float, float]] | None:
    """The IEC point list drawing a trapezoid-family term exactly, or None (vertical edges)."""
    a, b, c, d = corners
    inf = float("inf")
    if a == b == -inf and -inf < c < d < inf:
        return [(c, 1.0), (d, 0.0)]
    if c == d == inf and -inf < a < b < inf:
        return [(a, 0.0), (b, 1.0)]
    if -inf < a < b <= c < d < inf:
        return [(a, 0.0), (b, 1.0), (d, 0.0)] if b == c else \
            [(a, 0.0), (b, 1.0), (c, 1.0), (d, 0.0)]
    return None


def _rule_text(r: Rule, dialect: str = DEFAULT_DIALECT, ops: Operators | None = None) -> str:
    """A rule in lower-case keywords; conclusions joined as ``dialect`` reads them. fuzzylite's
    ``not`` is a hedge on one proposition, so for it a ``not`` over a group is moved onto the
    propositions (De Morgan), which is exact when the rule block's `and` and `or` are duals
    (min and max, ...); otherwise it is refused by name."""
    def expr(e: Expr, parent: str) -> str:
        if isinstance(e, Prop):
            words = (["not"] if e.negated else []) + [common.to_fuzzylite_hedge(h, e.span)
                                                       for h in e.hedges] + [e.term]
            return f"{e.var} is " + " ".join(words)
        if isinstance(e, Not):
            if dialect == "fuzzylite":
                return expr(_de_morgan(e, r, ops), parent)
            return f"not ({expr(e.expr, 'not')})"
        op = "and" if isinstance(e, And) else "or"
        text = f" {op} ".join(expr(i, op) for i in e.items)
        return f"({text})" if parent not in ("top", op, "not") else text

    joint = " and " if dialect == "fuzzylite" else ", "
    cons = joint.join(f"{c.var} is " + " ".join(
        [common.to_fuzzylite_hedge(h, c.span) for h in hedges] + [common.concluded_term(c)])
        for c, hedges in common.written_consequents(r, ops.inference if ops is not None else None))
    text = f"if {expr(r.antecedent, 'top')} then {cons}"
    if r.weight != 1.0:
        text += f" with {fmt_number(r.weight)}"
    return text


def _de_morgan(e: Not, r: Rule, ops: Operators | None) -> Expr:
    """``not (a or b)`` as ``not a and not b`` (and the dual), down to the propositions."""
    if ops is None or norms.lookup("tnorm", ops.and_).dual != ops.or_:
        raise FormatError(f"rule `{r.label}`: fuzzylite's FCL has no `not` over a group (its "
                          f"`not` is a hedge on one proposition), and with `and = {ops and ops.and_}`, "
                          f"`or = {ops and ops.or_}` (not duals) it cannot be moved onto the "
                          f"propositions", span=e.span or r.span,
                          hint="write `--dialect iec` (IEC 61131-7, jFuzzyLogic)")

    def negate(x: Expr) -> Expr:
        if isinstance(x, Prop):
            return dataclasses.replace(x, negated=not x.negated)
        if isinstance(x, Not):
            return push(x.expr)
        items = tuple(negate(i) for i in x.items)
        return Or(items, x.span) if isinstance(x, And) else And(items, x.span)

    def push(x: Expr) -> Expr:
        if isinstance(x, Prop):
            return x
        if isinstance(x, Not):
            return negate(x.expr)
        return type(x)(tuple(push(i) for i in x.items), x.span)

    return negate(e.expr)
