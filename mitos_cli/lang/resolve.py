"""From a parsed rule file to a checked :class:`RuleBase`.

Here every name is resolved against the term sets: unknown variables, terms, hedges and
behaviors get a "did you mean"; inputs may only appear in conditions and outputs only in
actions; labels are unique within a behavior; ``use`` has no cycles; operator settings exist.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import MitosError, RuleBaseError, Span, TermSetError, unknown
from ..fuzzy.hedges import HEDGES
from ..numbers import exact
from ..resources import exists, is_dir, is_file
from . import operators as ops_mod
from .bulk import without_cyclic_gc
from .model import And, Behavior, Consequent, Expr, Not, Or, Prop, Rule, RuleBase, Setting
from .parse import ParsedFile, parse_rules
from .termfile import load_termset
from .terms import TermSet, Variable

if TYPE_CHECKING:
    from collections.abc import Iterable

    from .operators import Operators

MAIN = "main"


def rule_file_hint(path: str | Path) -> str | None:
    """"did you mean" for a rule file that is not there: the closest of the files beside it
    (:func:`..fileio.nearby`) and, where the packaged rule bases would be looked for
    (``mitos.rule``, ``rulebases/mitoss.rules`` from anywhere), the packaged ones, as a world
    file's name gets the packaged worlds: a `mitos.fll` here was suggested for `mitos.rule`,
    which every command reads as the packaged `mitos.rules` once spelt right."""
    from ..fileio import RULE_SUFFIXES, nearby, repository_only
    from ..resources import packaged_names, packaged_place

    packaged = ([n for suffix in RULE_SUFFIXES for n in packaged_names("rulebases", suffix)]
                if packaged_place(Path(path).parent.as_posix(), "rulebases") else [])
    return nearby(path, RULE_SUFFIXES, packaged) or repository_only(path)


def rule_file_not_found_hint(path: str | Path) -> str | None:
    """The hint of "rule file `X` not found": :func:`rule_file_hint`, else, for a name the
    packaged rule bases are looked up by, where to see them (`mitos eval nope.rules` said
    "not found" and no more, where a world's name gets `mitos list`)."""
    from ..resources import packaged_place

    return rule_file_hint(path) or (
        "`mitos list` shows the packaged rule bases, which are found by name (`mitos.rules`)"
        if packaged_place(Path(path).parent.as_posix(), "rulebases") else None)


def termset_hint(target: Path, name: str) -> str:
    """What to write in the ``terms`` line for a term set that is not there: the YAML file
    beside it whose name is close (`mitos.terms.yaml` for `mitos.term.yaml`), as the line
    names it, else how the line's paths are read."""
    from ..fileio import nearby_name

    close = nearby_name(target, (".yaml", ".yml")) if not exists(target) else None
    if close is not None:
        return f"did you mean `{(Path(name).parent / close).as_posix()}`?"
    return "term-set paths are relative to the rule file, and name a YAML file"


@without_cyclic_gc
def load_rules_file(path: str | Path) -> RuleBase:
    """Read, parse and check the rule file at ``path`` and the term sets it names."""
    from ..fileio import (
        bad_byte,
        broken_link,
        finish_saves,
        not_text,
        read_text,
        text_encoding_hint,
        unreadable,
    )

    path = Path(path)
    finish_saves(path)              # a set save a crash left half done
    try:
        text = read_text(path)
    except UnicodeDecodeError as exc:
        raise RuleBaseError(not_text(path, exc), span=bad_byte(path, exc),
                            hint=text_encoding_hint(exc)) from None
    except OSError as exc:
        raise RuleBaseError(unreadable("rule file", path, exc),
                            hint=rule_file_not_found_hint(path)) from None
    parsed = parse_rules(text, str(path))
    termsets = []
    seen: dict[Path, str] = {}
    for name, span in parsed.terms:
        target = path.parent / name
        _named_once(target, name, span, seen)
        if not is_file(target):
            link = broken_link("term set", target)
            if link is not None:
                raise TermSetError(link, span=span)
            found = ("not found" if not exists(target) else "is a directory" if is_dir(target)
                     else "is not a regular file")          # a device, a pipe
            raise TermSetError(f"term set `{name}` {found} (looked for `{target}`)", span=span,
                               hint=termset_hint(target, name))
        termsets.append(load_termset(target))
    return build_rulebase(parsed, tuple(termsets), tuple(n for n, _ in parsed.terms))


def termsets_read(path: str | Path) -> set[Path]:
    """The term sets (resolved paths) that the rule file at ``path`` names, when it is there
    and parses; else none. A writer that puts a term set beside ``path`` may replace one of
    these (it belongs to the rule file being replaced), never another file."""
    from ..fileio import read_text

    path = Path(path)
    try:
        parsed = parse_rules(read_text(path), str(path))
        return {(path.parent / name).resolve() for name, _ in parsed.terms}
    except (MitosError, OSError, UnicodeDecodeError, ValueError):
        return set()


def strays(rules_target: str | Path, companions: Iterable[str | Path]) -> list[Path]:
    """The files among ``companions`` (written beside ``rules_target``, which the user named)
    that are already there and that the rule file at ``rules_target`` does not read: files
    the user did not name, which writing would replace."""
    there = [Path(p) for p in companions if _present(Path(p))]
    if not there:
        return []
    own = termsets_read(rules_target)
    return [p for p in there if p.resolve() not in own]


def _present(path: Path) -> bool:
    """Whether something is at ``path`` (a link to nothing included); a path in a directory
    this user cannot enter is not known to be (its write is refused in words: `convert -o`
    into such a directory was a `PermissionError` traceback here). Any other failure, a name
    too long to look up, is the caller's to say."""
    try:
        return path.exists() or path.is_symlink()
    except PermissionError:
        return False


def _named_once(target: Path, name: str, span: Span | None, seen: dict[Path, str]) -> None:
    """Refuse a term set the rule file names twice (its variables would be "defined in two term
    sets", which sends the user looking for a second definition that is not there)."""
    import os

    key = Path(os.path.normpath(target))
    if key in seen:
        raise TermSetError(f"term set `{name}` is named twice"
                           + (f" (also as `{seen[key]}`)" if seen[key] != name else ""),
                           span=span, hint="name each term set once")
    seen[key] = name


def build_rulebase(parsed: ParsedFile, termsets: tuple[TermSet, ...],
                   termset_paths: tuple[str, ...] = ()) -> RuleBase:
    """Check ``parsed`` against ``termsets`` and return the rule base."""
    if not termsets:
        raise RuleBaseError("the rule file names no term set",
                            span=Span.in_text(parsed.text, parsed.path, 1, 1),
                            hint='add a line `terms "NAME.terms.yaml"` naming its YAML term set')
    variables: dict[str, Variable] = {}
    for ts in termsets:
        for v in ts.variables:
            if v.name in variables:
                raise TermSetError(f"variable `{v.name}` is defined in two term sets", span=v.span)
            variables[v.name] = v
    behaviors = list(parsed.behaviors)
    if parsed.rules or parsed.uses:
        behaviors.insert(_main_place(parsed), Behavior(MAIN, parsed.rules, parsed.uses, (),
                                                       parsed.frozen,
                                                       None, parsed.frozen_spans))
    elif parsed.frozen:
        import re

        found = re.search(r"(?m)^[ \t]*(frozen)\b", parsed.text)
        at = found.start(1) if found else 0
        line = parsed.text.count("\n", 0, at) + 1
        span = parsed.frozen_spans[0] if parsed.frozen_spans else None
        raise RuleBaseError("`frozen` outside a behavior names rules that do not exist",
                            span=span or Span.at(parsed.text, parsed.path, at, line,
                                                 at - (parsed.text.rfind("\n", 0, at) + 1) + 1),
                            hint="put `frozen LABEL, ...` inside the behavior of those rules")
    if not behaviors:
        raise RuleBaseError("the rule file has no rules",
                            span=Span.in_text(parsed.text, parsed.path, 1, 1),
                            hint="write a rule: `if road is WIDE then speed is FAST`")
    names = [b.name for b in behaviors]
    first: dict[str, Behavior] = {}
    for b in behaviors:
        if b.name in first:                 # reported at the second: the first was right
            raise _defined_twice(b, first[b.name])
        first[b.name] = b
        if b.name in HEDGES or b.name == "not":     # `use very when ...` could not name it
            raise RuleBaseError(f"`{b.name}` is a reserved word (a hedge), not a name",
                                span=b.span, hint="name the behavior something else")
    base_ops = ops_mod.resolve(parsed.operators)
    labels = {b.name: {r.label for r in b.rules if r.label} for b in behaviors}
    for b in behaviors:
        ops_mod.resolve(b.operators, base_ops)
        _check_behavior(b, variables, names, labels)
    rb = RuleBase(parsed.path, termsets, tuple(behaviors), parsed.operators, termset_paths,
                  notes=set_again(parsed.operators)
                  + tuple(n for b in behaviors for n in set_again(b.operators, b.name))
                  + infinite_inverses(behaviors, variables, base_ops))
    _check_uses(rb)
    return rb


def set_again(settings: tuple[Setting, ...], behavior: str | None = None) -> tuple[str, ...]:
    """A note for each operator a later ``operators:`` line of the file's top level (or of
    ``behavior``) sets again: the lines merge, key by key, the last one winning, which was
    done without a word (one line setting a key twice is an error)."""
    first: dict[str, Setting] = {}
    notes = []
    scope = f"behavior `{behavior}`" if behavior else "the whole file"
    aside = "" if behavior else " (a behavior's own `operators:` line sets it for that behavior)"
    for s in settings:
        before = first.setdefault(s.key, s)
        if before is s or before.span is None or s.span is None:
            continue
        notes.append(f"{s.span}: `{s.key}` is set again (`{s.value}`; line {before.span.line} "
                     f"set `{before.value}`): the later line wins for {scope}; keep one "
                     f"`{s.key}`{aside}")
    return tuple(notes)


def infinite_inverses(behaviors: Iterable[Behavior], variables: dict[str, Variable],
                      base_ops: Operators) -> tuple[str, ...]:
    """A note for each sigmoid a Tsukamoto behavior's rule concludes: a sigmoid reaches 1 only
    at infinity, so where the rule fires fully its inverse, and the output, is +-inf (as in
    fuzzylite, whose reader's note this is); nothing else said so."""
    notes, seen = [], set()
    for b in behaviors:
        if ops_mod.resolve(b.operators, base_ops).inference != "tsukamoto":
            continue
        for rule in b.rules:
            for c in rule.consequents:
                if c.term is None or variables[c.var].term(c.term).shape != "sigmoid" \
                        or (c.var, c.term) in seen:
                    continue
                seen.add((c.var, c.term))
                notes.append(f"{c.span or rule.span}: `{c.var} is {c.term}` inverts a sigmoid "
                             f"(Tsukamoto inference); a sigmoid reaches 1 only at infinity, so "
                             f"where the rule fires fully `{c.var}` is +-inf, as in fuzzylite")
    return tuple(notes)


def _main_place(parsed: ParsedFile) -> int:
    """Where ``main`` (the rules outside any behavior) stands among the file's behaviors: at
    its first rule or ``use``, so that the first behavior of the file is the default one, as
    docs/language.md says, wherever the top-level rules are written."""
    spans = [r.span for r in parsed.rules] + [u.span for u in parsed.uses]
    starts = [(span.line, span.column) for span in spans if span is not None]
    if not starts:
        return 0
    first = min(starts)
    return sum(1 for b in parsed.behaviors
               if b.span is not None and (b.span.line, b.span.column) < first)


def _defined_twice(second: Behavior, first: Behavior) -> RuleBaseError:
    """A behavior defined again, at the second definition, saying where the first is."""
    where = f" (first at line {first.span.line})" if first.span else ""
    if second.name == MAIN and None in (first.span, second.span):   # the top-level rules
        where = " (also by the rules outside any behavior)"           # are the other one
    span = second.span and second.span.naming(second.name)
    if second.span is None:         # the top-level rules after `behavior main:`: at the first
        span = min((x.span for x in second.rules + second.uses if x.span is not None),
                   key=lambda x: (x.line, x.column), default=None)
    return RuleBaseError(f"behavior `{second.name}` is defined twice{where}", span=span,
                         hint="rename one of them, or move its rules into the other")


def _check_behavior(b: Behavior, variables: dict[str, Variable], behaviors: list[str],
                    labels_of: dict[str, set[str]] | None = None) -> None:
    labels: set[str] = set()
    for rule in b.rules:
        if rule.label:
            if rule.label in labels:
                raise RuleBaseError(f"rule label `{rule.label}` is used twice in behavior "
                                    f"`{b.name}`", span=rule.span,
                                    hint="give each rule its own label")
            labels.add(rule.label)
        check_rule(rule, variables)
    for use in b.uses:
        if use.behavior not in behaviors:
            raise unknown("behavior", use.behavior, behaviors,
                          span=use.span and use.span.naming(use.behavior))
        if use.condition is not None:
            check_expr(use.condition, variables)
        _check_weight(use.weight, use.weight_span or use.span)
    for i, label in enumerate(b.frozen):
        if label not in labels:
            at = b.frozen_spans[i] if i < len(b.frozen_spans) else None
            exc = unknown("rule label", label, labels, span=at or b.span)
            exc.message = f"unknown rule label `{label}` in behavior `{b.name}`" + \
                (" (the rules outside any behavior)" if b.name == MAIN else "")
            exc.hint = exc.hint or _frozen_elsewhere(label, b.name, labels_of or {})
            raise exc


def _frozen_elsewhere(label: str, behavior: str, labels_of: dict[str, set[str]]) -> str | None:
    """A hint for ``frozen LABEL`` where LABEL is a rule of another behavior: `frozen` names
    rules of the behavior it stands in (`main` for a line outside any behavior)."""
    owners = [name for name, labels in labels_of.items() if label in labels and name != behavior]
    if not owners:
        return None
    where = "outside any behavior" if owners[0] == MAIN else f"in behavior `{owners[0]}`"
    return (f"`{label}` is a rule {where}: `frozen` names rules of the behavior it is written "
            f"in, so write `frozen {label}` there")


def check_rule(rule: Rule, variables: dict[str, Variable]) -> None:
    """Raise when ``rule`` names something the term sets do not define."""
    check_expr(rule.antecedent, variables)
    seen: set[str] = set()
    for c in rule.consequents:
        _check_consequent(c, variables)
        if c.var in seen:
            raise RuleBaseError(f"the rule sets `{c.var}` twice", span=c.span)
        seen.add(c.var)
    _check_weight(rule.weight, rule.weight_span or rule.span)


def _check_weight(weight: float, span: Span | None) -> None:
    if not 0.0 <= weight <= 1.0:
        raise RuleBaseError(f"a rule weight must lie in [0, 1], not {exact(weight)}", span=span)


def _variable(name: str, role: str, variables: dict[str, Variable], span: Span | None) -> Variable:
    span = span and span.naming(name)          # the name, not `name is TERM`
    v = variables.get(name)
    if v is None:
        pool = [n for n, var in variables.items() if var.role == role]
        error = unknown(f"{role} variable", name, pool, span=span)
        if role == "input" and name[:3].lower() == "not" and name[3:] in pool:
            # `if notroad is WIDE`: "did you mean `road`?" dropped the `not`
            error.hint = f"`{name[:3]}` and `{name[3:]}` are two words"
        raise error
    if v.role != role:
        where = "a condition" if role == "input" else "an action"
        raise RuleBaseError(f"`{name}` is an {v.role} variable and cannot appear in {where}",
                            span=span)
    return v


def _check_hedges(hedges: tuple[str, ...], span: Span | None) -> None:
    for h in hedges:
        if h not in HEDGES:
            raise unknown("hedge", h, HEDGES, span=span and span.naming(h))


def check_expr(expr: Expr, variables: dict[str, Variable]) -> None:
    if isinstance(expr, Prop):
        v = _variable(expr.var, "input", variables, expr.span)
        v.term(expr.term, expr.span and expr.span.ending(expr.term))
        _check_hedges(expr.hedges, expr.span)
    elif isinstance(expr, Not):
        check_expr(expr.expr, variables)
    elif isinstance(expr, (And, Or)):
        for item in expr.items:
            check_expr(item, variables)


def _check_consequent(c: Consequent, variables: dict[str, Variable]) -> None:
    v = _variable(c.var, "output", variables, c.span)
    if c.term is not None:
        v.term(c.term, c.span and c.span.ending(c.term))
        _check_hedges(c.hedges, c.span)
    elif c.value is not None:
        lo, hi = v.universe
        if not lo <= c.value <= hi:
            raise RuleBaseError(f"{c.var} = {exact(c.value)} lies outside its universe "
                                f"[{exact(lo)}, {exact(hi)}]", span=c.span)


#: The longest chain of behaviors each using the next (a rule's conditions may nest 100 deep
#: too): evaluation writes used behaviors out level by level.
MAX_USE_DEPTH = 100
#: The most rules a behavior may hold once the behaviors it uses are written out: each `use`
#: writes the used behavior out again, so behaviors that use two others, which use the same
#: two again, double at each level (18 levels: 262,143 rules, minutes and gigabytes).
MAX_WRITTEN_RULES = 20_000


def _check_uses(rb: RuleBase) -> None:
    """Refuse, at the ``use`` that does it, behaviors that use each other in a cycle, a chain
    of uses deeper than :data:`MAX_USE_DEPTH`, and a behavior of more than
    :data:`MAX_WRITTEN_RULES` rules written out. One walk over the file's uses, each once
    (the file's top level, ``main``, has no position of its own: a cycle is reported at the
    ``use`` closing it)."""
    done: dict[str, tuple[int, int]] = {}       # name -> (chain of uses below, rules written out)
    for root in rb.behaviors:
        if root.name in done:
            continue
        path, todo = [root.name], [iter(root.uses)]
        while todo:
            use = next(todo[-1], None)
            if use is None:                      # every behavior it uses is done
                done[path[-1]] = _written(rb.behavior(path[-1]), done)
                path.pop()
                todo.pop()
            elif use.behavior in path:
                cycle = " -> ".join(path[path.index(use.behavior):] + [use.behavior])
                raise RuleBaseError(f"behaviors use each other in a cycle: {cycle}",
                                    span=use.span)
            elif use.behavior not in done:
                path.append(use.behavior)
                todo.append(iter(rb.behavior(use.behavior).uses))


def _written(b: Behavior, done: dict[str, tuple[int, int]]) -> tuple[int, int]:
    """``b``'s chain of uses and its rules written out, from those of the behaviors it uses
    (``done``); refused, at its use that makes them, beyond the limits."""
    depth, rules = 0, len(b.rules)
    for use in b.uses:
        below, written = done[use.behavior]
        if below + 1 > MAX_USE_DEPTH:
            raise RuleBaseError(f"behaviors use each other more than {MAX_USE_DEPTH} deep: "
                                f"`{b.name}` uses `{use.behavior}`, which starts a chain of "
                                f"{below} uses", span=use.span or b.span,
                                hint="use the behaviors from fewer levels: a behavior may "
                                     "use several others directly")
        depth, rules = max(depth, below + 1), rules + written
        if rules > MAX_WRITTEN_RULES:
            raise RuleBaseError(f"behavior `{b.name}` would hold more than "
                                f"{MAX_WRITTEN_RULES:,} rules once the behaviors it uses are "
                                f"written out ({rules:,} with `{use.behavior}`)",
                                span=use.span or b.span,
                                hint="each `use` writes the used behavior's rules out again: "
                                     "a behavior used from several places counts once for each")
    return depth, rules


