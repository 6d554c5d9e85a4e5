"""Saving a taught rule base so that it stays linguistic and ``git diff`` shows what was learned.

The rule file and its YAML term sets are written back by *text surgery* on the originals:
every label, comment and line break stays where it was; only the numbers that changed are
replaced, at the positions the parsers recorded (Lark tokens for the rule file, ``yamlpos``
spans for the YAML). Rules told again under an existing label replace that rule's text; new
rules, ``use`` and ``frozen`` lines go before their behavior's ``end``; new behaviors are
appended in the rule language. The rule file and its term sets are written as one set
(:func:`~mitos_cli.fileio.atomic_write_set`): after a crash they are the old files or the new
ones, never a rule file of one save beside the term set of another.

Saving under another name writes ``OUT.rules`` and its term set beside it as
``OUT.terms.yaml`` (with several term sets, ``OUT.<original name>``), with the ``terms`` line
updated; saving over the original rule file rewrites its term sets in place.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from lark import Token, Tree

from ..errors import LessonError, MitosError, TermSetError
from ..fileio import atomic_write, atomic_write_set, finish_saves  # noqa: F401 (re-exported)
from ..fuzzy.shapes import SHAPES
from ..lang import yamlpos
from ..lang.model import Behavior, Rule, RuleBase, format_number, format_rule, format_use
from ..lang.parse import _unquote
from ..lang.parse import parser as rule_parser
from ..lang.terms import Term
from ..words import plural

if TYPE_CHECKING:
    from collections.abc import Iterable, Iterator

    from ..errors import Span
    from ..lang.model import Setting
    from ..lang.terms import TermSet

NUMBER = re.compile(r"[-+]?(?:\d[\d_]*\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
#: a plain YAML scalar such as ``true`` (up to a space, comma, ``}`` or comment)
SCALAR = re.compile(r"[^\s,}#]*")


@dataclass(frozen=True)
class Sources:
    """The texts a session's rule base was read from: the rule file and its term sets (in the
    order it names them), as they were, byte-order mark and line breaks kept.

    ``save`` edits these, not the files as they are when it runs: a first `save` over the
    original rule file put its new rules in the file, and the next save, editing that file
    against the rule base read before, wrote them twice (refused as "a bug in MITOS": the
    session could not save again). Kept in the journal's start, they let ``--resume`` read
    the rule base as the session began, so that `undo` takes back what a save wrote."""

    rules: str
    terms: tuple[str, ...]

    @classmethod
    def read(cls, rb: RuleBase) -> Sources:
        """The files of ``rb`` (read from its path) as they are now."""
        src = Path(rb.path or "")
        return cls(src.read_bytes().decode("utf-8"),
                   tuple((src.parent / rel).read_bytes().decode("utf-8")
                         for rel in rb.termset_paths))

    @classmethod
    def from_json(cls, data: object) -> Sources | None:
        """The sources a journal's start holds (``None``: an older journal keeps none)."""
        if not isinstance(data, dict) or not isinstance(data.get("rules"), str) \
                or not isinstance(data.get("terms"), list) \
                or not all(isinstance(t, str) for t in data["terms"]):
            return None
        return cls(data["rules"], tuple(data["terms"]))

    def to_json(self) -> dict:
        return {"rules": self.rules, "terms": list(self.terms)}

    def rulebase(self, path: Path) -> RuleBase:
        """The rule base these texts hold, read as if from ``path`` (where the rule file is)."""
        from ..lang.parse import parse_rules
        from ..lang.resolve import build_rulebase
        from ..lang.termfile import parse_termset

        parsed = parse_rules(self.rules.removeprefix("\ufeff"), str(path))
        names = tuple(n for n, _ in parsed.terms)
        if len(names) != len(self.terms):
            raise LessonError(f"the session's copy of {path} names {len(names)} term sets, "
                              f"and holds {len(self.terms)}")
        return build_rulebase(parsed, tuple(
            parse_termset(t.removeprefix("\ufeff"), str(path.parent / n))
            for n, t in zip(names, self.terms)), names)

    def digest(self) -> str:
        """As :func:`~mitos_cli.teach.state.files_digest` of the files these were read from."""
        import hashlib

        h = hashlib.sha256()
        for text in (self.rules, *self.terms):
            h.update(text.encode("utf-8"))
        return h.hexdigest()[:16]


def _as_read(text: str) -> str:
    """``text`` as ``Path.read_text(encoding="utf-8-sig")`` reads a file of it: no byte-order
    mark, every line break a ``\\n``."""
    return text.removeprefix("\ufeff").replace("\r\n", "\n").replace("\r", "\n")


@dataclass(frozen=True)
class Saved:
    """What :func:`save_rulebase` wrote."""

    rules: Path
    termsets: tuple[Path, ...]
    changes: tuple[str, ...]          # one line per change, for people
    created: Path | None = None       # the directory the save made (`save taught/new.rules`)


def termset_targets(rules_target: Path, original_rules: Path,
                    termset_paths: tuple[str, ...]) -> tuple[Path, ...]:
    """Where the term sets go when the rule file is saved as ``rules_target``."""
    if rules_target.resolve() == original_rules.resolve():
        return tuple(original_rules.parent / p for p in termset_paths)
    stem = rules_target.name[:-len(".rules")] if rules_target.name.endswith(".rules") \
        else rules_target.stem
    if len(termset_paths) == 1:
        return (rules_target.parent / f"{stem}.terms.yaml",)
    return tuple(rules_target.parent / f"{stem}.{name}" for name in distinct_names(termset_paths))


def distinct_names(termset_paths: tuple[str, ...]) -> list[str]:
    """Each term set's file name, with its directories where two term sets share one
    (`a/x.terms.yaml` and `b/x.terms.yaml`: `a.x.terms.yaml` and `b.x.terms.yaml`): by file
    name alone both were written to one `OUT.x.terms.yaml`, the second over the first, and
    the saved rule base named it twice, so that it did not load."""
    names = [Path(p).name for p in termset_paths]
    out = [".".join([d for d in Path(p).parent.parts if d not in (".", "..", "/")] + [name])
           if names.count(name) > 1 else name for p, name in zip(termset_paths, names)]
    for i, name in enumerate(out):          # `../a/x` beside `a/x`: numbered
        if name in out[:i]:
            out[i] = next(f"{n}.{name}" for n in range(2, len(out) + 2)
                          if f"{n}.{name}" not in out)
    return out


def save_rulebase(original: RuleBase, current: RuleBase, target: Path,
                  sources: Sources | None = None, elsewhere: str | None = None) -> Saved:
    """Write ``current`` to ``target`` (and its term sets), as edits of the texts ``original``
    was read from: ``sources``, else its files as they are now. A file that cannot be written
    is an error whose hint is ``elsewhere`` (default: save at another place, `save ~/...`)."""
    if original.path is None:
        raise LessonError("this rule base has no file to save from")
    src = Path(original.path)
    if src.suffix.lower() in (".fcl", ".fis", ".fll"):
        raise LessonError(f"`{src.name}` is not in the rule language; saving keeps the rule "
                          f"language only", hint="save to a `.rules` file after converting it")
    elsewhere = elsewhere or (f"save where you can write files (`save ~/{target.name}`); the "
                              f"session keeps every change")
    try:
        files, changes = saved_files(original, current, target, sources)
    except LessonError as exc:          # a place it cannot write, found before writing
        exc.hint = exc.hint or elsewhere
        raise
    created = _directory_for(target)
    try:
        finish_saves(target, error=LessonError)        # one a crash left half done
        atomic_write_set(files, target, error=LessonError)
    except LessonError as exc:          # it names the file it failed on: often a term set
        if created is not None:
            with contextlib.suppress(OSError):
                created.rmdir()                         # made for this save: nothing in it
        raise LessonError(f"cannot save `{target}`: {exc.message}", hint=elsewhere) from None
    return Saved(target, tuple(d for d, _ in files[:-1]), changes, created)


def saved_files(original: RuleBase, current: RuleBase, target: Path,
                sources: Sources | None = None
                ) -> tuple[list[tuple[Path, str | bytes]], tuple[str, ...]]:
    """What a save of ``current`` as ``target`` writes, not yet written: the term sets, then
    the rule file (each with its text, read back as ``current``), and the changes in words."""
    src = Path(original.path or target)
    targets = check_save_target(original, target)
    if sources is None:
        sources = Sources.read(original)
    changes: list[str] = []
    texts: list[tuple[Path, str]] = []
    for ts_old, ts_new, rel, dest, raw in zip(original.termsets, current.termsets,
                                             original.termset_paths, targets, sources.terms):
        new_text, changed = edit_termset(_as_read(raw), str(src.parent / rel), ts_old, ts_new)
        changes += changed
        texts.append((dest, new_text))
    names = tuple(os.path.relpath(dest, target.parent).replace(os.sep, "/") for dest in targets)
    # a BOM is no token of the rule language
    new_rules, changed = edit_rules(_as_read(sources.rules), str(src), original, current, names)
    changes += changed
    _check_reads_back(current, new_rules, texts, target, names)
    written = [(dest, _breaks_as(text, raw)) for (dest, text), raw in zip(texts, sources.terms)]
    return written + [(target, _breaks_as(new_rules, sources.rules))], tuple(changes)


def _breaks_as(text: str | bytes, raw: str) -> str | bytes:
    """``text`` (read with universal newlines, a BOM dropped) with the line breaks and the BOM
    of ``raw``, the file it was read from: a rule base written on Windows (``\\r\\n``) was
    saved with ``\\n``, so that `git diff` showed every line changed where only numbers were
    learned."""
    if isinstance(text, bytes):
        return text
    first = raw.find("\n")
    if first > 0 and raw[first - 1:first] == "\r":
        text = text.replace("\n", "\r\n")
    return "\ufeff" + text if raw.startswith("\ufeff") else text


def check_save_target(original: RuleBase, target: Path) -> tuple[Path, ...]:
    """The term-set files a save of ``original`` as ``target`` writes, after refusing a save
    that would replace a file it must not (:func:`_check_targets`); ``mitos teach
    --save-as`` asks before a session starts, ``save`` again when it writes."""
    from ..fileio import LOOP_HINT, link_loop

    loop = link_loop(target)
    if loop is not None:            # (`Path.resolve` of it raised a RuntimeError)
        raise LessonError(f"cannot save `{target}`: {loop}", hint=LOOP_HINT)
    src = Path(original.path or target)
    targets = termset_targets(target, src, original.termset_paths)
    try:
        _check_directory(target)    # (`--save-as /nonexistent/dir/x.rules` ran the whole
        _check_targets(target, src, original, targets)     # lesson, then failed to save)
    except OSError as exc:          # a name the system cannot look up
        raise _cannot_look_up(target, exc) from None
    return targets


def _cannot_look_up(target: Path, exc: OSError) -> LessonError:
    """A save whose files the system cannot look up: a term set's name of over 255
    characters (`OUT.mitos.terms.yaml` of a long `OUT`) raised an ``OSError`` that ended the
    teaching prompt, with no place."""
    name = Path(exc.filename).name if isinstance(exc.filename, str) else ""
    too_long = exc.errno == errno.ENAMETOOLONG
    shown = f"`{name[:40]}...` ({len(name):,} characters)" if len(name) > 60 else f"`{name}`"
    return LessonError(f"cannot save `{target}`: {exc.strerror or exc}"
                       + (f": {shown}" if name else ""),
                       hint="each part of a path may have at most 255 characters: save under a "
                            "shorter name" if too_long else None)


def _check_targets(target: Path, src: Path, original: RuleBase, targets: tuple[Path, ...]) -> None:
    """Refuse a save that would write over a file the session reads: an original term set
    saved under another rule file's name (`save b.rules` beside a rule file that reads
    `b.terms.yaml`), or a term set onto the rule file itself; or over a file the user did not
    name: a term set there that the rule file saved over does not read (a term set of an
    earlier save as ``target`` is its own, and is replaced)."""
    if nameless(target):
        raise LessonError(f"`{target}` names no rule file: `.rules` is the ending, and the name "
                          "before it is missing",
                          hint=f"give it a name: `save {(target.parent / 'taught.rules').as_posix()}`")
    if target.suffix != ".rules":
        raise LessonError(f"`{target}` does not end in `.rules`; save writes a rule file"
                          + (" (and its term sets beside it)" if target.suffix in YAML else ""),
                          hint=f"save {_rules_name(target, src).as_posix()}")
    if target.resolve() == src.resolve():
        return                            # over the original: its term sets in place
    _check_link_elsewhere(target)
    originals = {(src.parent / rel).resolve(): rel for rel in original.termset_paths}
    for dest in targets:
        rel = originals.get(dest.resolve())
        if rel is not None:
            raise LessonError(
                f"saving as `{target.name}` would write its term set over `{dest.name}`, the "
                f"term set `{src.name}` reads (`terms \"{rel}\"`), which would change what it "
                f"means",
                hint="save under another name, or over the original rule file itself "
                     f"(`save {src}`)")
    from ..lang.resolve import strays

    for dest in strays(target, targets):
        raise LessonError(
            f"`{dest}` is already there and no term set of `{target}`; saving as "
            f"`{target.name}` would write its term set over it",
            hint="remove it, or save under another name")


def _check_link_elsewhere(target: Path) -> None:
    """Refuse a save onto a symbolic link into another directory: the rule file is written
    where the link leads, its term sets beside the link (where the link's name looks for
    them), so the file the link leads to would not load."""
    if not target.is_symlink() or target.resolve().parent == target.parent.resolve():
        return
    real = target.resolve()
    raise LessonError(f"`{target}` is a link to `{real}`, in another directory: the rule file "
                      "would be written there and its term sets beside the link, so "
                      f"`{real.name}` would not find them",
                      hint=f"save to `{real}` itself, or under a name that is no link")


def nameless(target: str | Path) -> bool:
    """Whether ``target`` is only the ending, `.rules` (`dir/.rules`): ``Path.suffix`` of a
    dot-file is empty, so "`.rules` does not end in `.rules`" was said of it."""
    return Path(target).name.lower() == ".rules"


#: The endings of a term-set file's name (`mitos.terms.yaml`), stripped from a hint's name.
YAML = (".yaml", ".yml")


def _rules_name(target: Path, src: Path) -> Path:
    """The rule file a save given ``target`` most likely meant: ``mitos.terms.yaml`` ->
    ``mitos.rules`` (not ``mitos.terms.rules``), ``x.txt`` -> ``x.rules``; never the original
    (a hint must not suggest writing over it): ``taught.rules`` then."""
    name = target.name
    for suffix in (".terms.yaml", ".terms.yml") + YAML:
        if name.endswith(suffix) and len(name) > len(suffix):
            name = name[:-len(suffix)]
            break
    else:
        name = target.stem
    out = target.with_name(f"{name}.rules")
    with contextlib.suppress(OSError):
        if out.resolve() == src.resolve():
            out = target.with_name("taught.rules")
    return out


def _check_reads_back(current: RuleBase, rules_text: str, texts: list[tuple[Path, str]], target: Path,
                      names: tuple[str, ...]) -> None:
    """The texts about to be written, read back, must be ``current``: a save never reports
    success for a file that does not load or that means something else."""
    from ..lang.operators import resolve
    from ..lang.parse import parse_rules
    from ..lang.resolve import build_rulebase
    from ..lang.termfile import parse_termset

    try:
        back = build_rulebase(parse_rules(rules_text, str(target)),
                              tuple(parse_termset(text, str(dest)) for dest, text in texts),
                              names)
        same = _terms(back) == _terms(current) and [
            (b.name, b.rules, b.uses, b.frozen) for b in back.behaviors] == [
            (b.name, b.rules, b.uses, b.frozen) for b in current.behaviors] and all(
            resolve(x.operators, resolve(back.operators))
            == resolve(y.operators, resolve(current.operators))
            for x, y in zip(back.behaviors, current.behaviors))
        why = "it reads back as another rule base"
    except MitosError as exc:
        same, why = False, f"it would not read back: {exc.message}"
    if not same:
        raise LessonError(f"`save` made a text that does not hold the session's rule base "
                          f"({why}); nothing was written",
                          hint="this is a bug in MITOS: the session and its journal are "
                               "intact; please report the lesson that led here")


def _terms(rb: RuleBase) -> dict:
    """Every variable as a file states it (a released term's point is not written:
    ``held: false`` says all)."""
    import dataclasses

    return {name: v.with_terms(tuple(dataclasses.replace(t, held_at=None) if not t.held else t
                                     for t in v.terms))
            for name, v in rb.variables.items()}


def _check_directory(target: Path) -> None:
    """Refuse a save whose directory cannot be had: a file where a directory goes, or a
    missing directory whose parent is missing too (only the last one is made)."""
    parent = target.parent
    if parent.is_dir():
        _check_writable(target, parent)
        return
    for up in (parent, parent.parent):  # `save notes.txt/x.rules`: said "File exists"
        if up.exists() and not up.is_dir():
            raise LessonError(f"cannot save `{target}`: `{up}` is a file, not a directory",
                              hint="name a directory, or a new one to be made")
    if not parent.parent.is_dir():
        raise LessonError(f"cannot save `{target}`: the directory `{parent.parent}` does not "
                          f"exist", hint="check the path, or create the directory first")
    _check_writable(target, parent.parent)          # where the missing one would be made


def _check_writable(target: Path, directory: Path) -> None:
    """Refuse a save into a directory this process may not write (a read-only file system,
    another user's directory): `--save-as ro/x.rules` ran the whole lesson, then failed."""
    if os.access(directory, os.W_OK | os.X_OK):
        return
    try:
        read_only = bool(os.statvfs(directory).f_flag & os.ST_RDONLY)
    except (OSError, AttributeError):   # (no statvfs: Windows)
        read_only = False
    raise LessonError(f"cannot save `{target}`: cannot write in `{directory}`: "
                      f"{'Read-only file system' if read_only else 'Permission denied'}")


def _directory_for(target: Path) -> Path | None:
    """Make the directory ``target`` goes in when only that last one is missing (`save
    taught/new.rules`), and return it (the session says so); a path whose parents are
    missing too is most likely a typo, refused as every other writer refuses a missing
    directory."""
    parent = target.parent
    if parent.is_dir():
        return None
    _check_directory(target)
    try:
        parent.mkdir()
    except OSError as exc:
        raise LessonError(f"cannot create `{parent}`: {exc.strerror or exc}") from None
    return parent


# ---- term sets ----------------------------------------------------------------------------------

def _offsets(text: str) -> list[int]:
    starts = [0]
    for line in text.splitlines(keepends=True):
        starts.append(starts[-1] + len(line))
    return starts


#: What a save adds to a comment on a line whose numbers it changed, so that the comment
#: stays true: `MEDIUM: {shape: triangle, peak: 70, width: 17.71}  # eq. 15: width 30 in`
#: said of the taught width what was true of the paper's.
BEFORE_TEACHING = " (before teaching)"


def _comment_after(text: str, at: int, yaml: bool = True) -> tuple[int, int] | None:
    """The comment that ends the line of offset ``at``, after it (a ``#`` outside quotes, in
    YAML after a blank): its start and its end, trailing blanks left out; ``None`` without
    one."""
    end = text.find("\n", at)
    end = len(text) if end < 0 else end
    quote = None
    i = at
    while i < end:
        c = text[i]
        if quote is not None:
            if c == "\\" and quote == '"':
                i += 1                          # an escaped character in double quotes
            elif c == quote:
                quote = None
        elif c in "'\"":
            quote = c
        elif c == "#" and (not yaml or i == 0 or text[i - 1] in " \t"):
            return i, len(text[:end].rstrip(" \t"))
        i += 1
    return None


def edit_termset(text: str, path: str, old: TermSet, new: TermSet) -> tuple[str, list[str]]:
    """``text`` with the parameters of every term that differs between ``old`` and ``new``
    (term sets of the same variables and terms) replaced in place. A comment on the line of a
    number that changed spoke of the number before: it is marked ``(before teaching)``
    (:data:`BEFORE_TEACHING`); every other comment stays as it is."""
    data = yamlpos.load(text, path, TermSetError)
    starts = _offsets(text)
    edits: list[tuple[int, int, str]] = []
    changes: list[str] = []
    marked: set[tuple[int, int]] = set()        # comments marked: one line, several terms
    variables = data["variables"]
    for v_old, v_new in zip(old.variables, new.variables):
        spec = variables[v_old.name]
        terms = spec["terms"]
        for t_old, t_new in zip(v_old.terms, v_new.terms):
            was, now = _flags(t_old), _flags(t_new)
            said: list[str] = []             # one line per term, whatever changed in it
            t_params_changed = t_old.params != t_new.params
            if was != now:
                edits += _flag_edits(text, starts, terms, t_old, t_new)
            if t_params_changed:
                said.append(f"{_params(t_old)} -> {_params(t_new)}")
            if t_old.frozen != t_new.frozen:
                said.append("frozen" if t_new.frozen else "no longer frozen")
            if was["held"] != now["held"]:
                said.append(
                    "free to move off its point (held: false)" if not t_new.held else
                    "held at its point" if t_new.held_at is None else
                    f"`held: {now['held']}` written (its neighbours no longer mirror each "
                    f"other about it)")
            spans = _param_spans(terms, t_old) if t_params_changed else []
            for span, a, b in zip(spans, t_old.params, t_new.params):
                comment = None if a == b else \
                    _comment_after(text, starts[span.line - 1] + span.column - 1)
                if comment is not None and comment not in marked:
                    marked.add(comment)
                    if not text[:comment[1]].endswith(BEFORE_TEACHING):
                        edits.append((comment[1], comment[1], BEFORE_TEACHING))
                        said.append(f"its comment marked `{BEFORE_TEACHING.strip()}`")
            if said:
                changes.append(f"{v_old.name}.{t_old.name}: " + "; ".join(said))
            bare = not isinstance(terms[t_old.name], yamlpos.YMap)
            if not t_params_changed or (bare and was != now):   # (the flags' edit wrote it)
                continue
            for span, a, b in zip(spans, t_old.params, t_new.params):
                if a == b:
                    continue
                at = starts[span.line - 1] + span.column - 1
                match = NUMBER.match(text, at)
                if match is None:            # pragma: no cover - yamlpos pointed at a number
                    raise LessonError(f"cannot find the number for `{v_old.name}."
                                      f"{t_old.name}` in {path}:{span.line}")
                edits.append((match.start(), match.end(), format_number(b)))
    return _apply(text, edits), changes


def _flags(term: Term) -> dict[str, str]:
    """A term's ``frozen`` and ``held`` keys as its YAML writes them (``held``: true, false
    or the point it is held at)."""
    held = "false" if not term.held else \
        "true" if term.held_at is None else format_number(term.held_at)
    return {"frozen": "true" if term.frozen else "false", "held": held}


def _flag_edits(text: str, starts: list[int], terms: yamlpos.YMap, old: Term,
                new: Term) -> list[tuple[int, int, str]]:
    """The edits that write ``new``'s ``frozen`` and ``held`` keys where they differ from
    ``old``'s into its YAML: a key's value replaced where it is written, else the keys added
    (to a flow mapping before its ``}``, to a block mapping as its first lines; a bare crisp
    value becomes ``{shape: singleton, value: V, frozen: true}``, V its new value)."""
    was = _flags(old)
    flags = {key: value for key, value in _flags(new).items() if was[key] != value}

    def offset(span: Span) -> int:
        return starts[span.line - 1] + span.column - 1

    spec = terms[old.name]
    if not isinstance(spec, yamlpos.YMap):            # `LM: 50`
        at = offset(terms.value_span(old.name))
        match = NUMBER.match(text, at)
        end = match.end() if match else at
        pairs = "".join(f", {k}: {v}" for k, v in flags.items())
        value = text[at:end] if old.params == new.params else format_number(new.params[0])
        return [(at, end, f"{{shape: singleton, value: {value}{pairs}}}")]
    edits = []
    for key in [k for k in flags if k in spec]:
        at = offset(spec.value_span(key))
        scalar = SCALAR.match(text, at)
        edits.append((at, scalar.end() if scalar else at, flags.pop(key)))
    if not flags:
        return edits
    end = offset(spec.end_span)
    if text[:end].rstrip().endswith("}"):             # a flow mapping
        close = text.rindex("}", 0, end)
        return edits + [(close, close, "".join(f", {k}: {v}" for k, v in flags.items()))]
    first = offset(spec.key_span(next(iter(spec))))
    line_start = text.rfind("\n", 0, first) + 1
    indent = text[line_start:first]
    return edits + [(line_start, line_start,
                     "".join(f"{indent}{k}: {v}\n" for k, v in flags.items()))]


def _params(term: Term) -> str:
    return "(" + ", ".join(format_number(p) for p in term.params) + ")"


def _param_spans(terms: yamlpos.YMap, term: Term) -> list:
    """The YAML positions of ``term``'s parameters, in the shape's parameter order."""
    spec = terms[term.name]
    if not isinstance(spec, yamlpos.YMap):            # a bare number: a crisp output value
        return [terms.value_span(term.name)]
    if "points" in spec:
        points = spec["points"]
        return [points.item_span(i) for i in range(len(points))]
    if "value" in spec and term.shape == "singleton":
        return [spec.value_span("value")]
    return [spec.value_span(p) for p in SHAPES[term.shape].params]


def _apply(text: str, edits: list[tuple[int, int, str]]) -> str:
    for start, end, new in sorted(edits, reverse=True):
        text = text[:start] + new + text[end:]
    return text


# ---- the rule file --------------------------------------------------------------------------------

@dataclass
class _Place:
    """Where a behavior's parts stand in the rule file."""

    rules: list                 # in order: (label or "", (start, end, crisp number tokens
                                # by variable)); a session keeps its rules' places
    end_line_start: int | None  # offset of the line holding `end` (None: top level)
    indent: str
    #: where each operator is last set on an `operators:` line (start, end): the file's
    #: top level, or the behavior's own lines
    settings: dict[str, tuple[int, int]] = field(default_factory=dict)


def _tokens(tree: Tree) -> Iterator[tuple[Tree, Token]]:
    for node in tree.iter_subtrees_topdown():
        for child in node.children:
            if isinstance(child, Token):
                yield node, child


def _rule_place(tree: Tree) -> tuple[str, tuple[int, int, dict]]:
    label = ""
    crisp = {}
    for child in tree.children:
        if isinstance(child, Tree) and child.data == "label":
            label = str(child.children[0])
        if isinstance(child, Tree) and child.data == "crisp_consequent":
            var = str(child.children[0])
            number = child.children[1]
            assert isinstance(number, Tree)        # the grammar: `NAME "is" number`
            tok = number.children[0]
            assert isinstance(tok, Token)          # the grammar: `number: SIGNED_NUMBER`
            crisp[var] = (tok.start_pos, tok.end_pos)
    return label, (tree.meta.start_pos, tree.meta.end_pos, crisp)


def _places(text: str) -> tuple[dict[str, _Place], list[Token]]:
    tree = rule_parser().parse(text, start="start")
    places: dict[str, _Place] = {}
    top = _Place([], None, "")
    terms_tokens: list[Token] = []
    for item in tree.children:
        if not isinstance(item, Tree):
            continue
        if item.data == "rule":
            top.rules.append(_rule_place(item))
        elif item.data == "terms_stmt":
            terms_tokens += [t for t in item.children if isinstance(t, Token)]
        elif item.data == "operators_stmt":
            top.settings.update(_settings_at(item))
        elif item.data == "behavior":
            name = str(item.children[0])
            rules = []
            indent = "    "
            settings: dict[str, tuple[int, int]] = {}
            for sub in item.children[1:]:
                if isinstance(sub, Tree) and sub.data == "operators_stmt":
                    settings.update(_settings_at(sub))
                if isinstance(sub, Tree) and sub.data == "rule":
                    rules.append(_rule_place(sub))
                    line_start = text.rfind("\n", 0, sub.meta.start_pos) + 1
                    indent = text[line_start:sub.meta.start_pos]
                    if indent.strip():
                        indent = "    "
            end_kw = item.meta.end_pos - len("end")
            line_start = text.rfind("\n", 0, end_kw) + 1
            if text[line_start:end_kw].strip():          # `end` shares its line: insert before it
                line_start = end_kw
            places[name] = _Place(rules, line_start, indent, settings)
    if top.rules:
        places["main"] = top
    return places, terms_tokens


def _settings_at(stmt: Tree) -> dict[str, tuple[int, int]]:
    """Where an ``operators:`` line sets each operator (start, end of ``key = value``)."""
    return {str(a.children[0]): (a.meta.start_pos, a.meta.end_pos) for a in stmt.children
            if isinstance(a, Tree) and a.data == "op_assign"}


def edit_rules(text: str, path: str, original: RuleBase, current: RuleBase,
               termset_names: tuple[str, ...]) -> tuple[str, list[str]]:
    """The rule file ``text`` with ``current``'s differences from ``original`` written in."""
    places, terms_tokens = _places(text)
    edits: list[tuple[int, int, str]] = []
    changes: list[str] = []
    for tok, name in zip(terms_tokens, termset_names):
        # read as the rule parser reads it (`"sets\\x.terms.yaml"`: a JSON-unknown escape is
        # kept as written, where `json.loads` raised), written escaped (a `"` in the name)
        if _unquote(tok) != name:
            assert tok.start_pos is not None and tok.end_pos is not None  # the lexer's tokens
            edits.append((tok.start_pos, tok.end_pos, json.dumps(name, ensure_ascii=False)))
    appended: list[str] = []
    old_behaviors = {b.name: b for b in original.behaviors}
    restore = _kept_from_the_top(original, current, places)
    for b in current.behaviors:
        old = old_behaviors.get(b.name)
        keep = {} if b.name == "main" else {
            key: value for key, value in restore.items() if key not in _last_values(b.operators)}
        if old is None:
            appended.append(_behavior_text(b, keep))
            changes.append(f"new behavior {b.name} ({plural(len(b.rules), 'rule')})")
            continue
        place = places.get(b.name)
        inserted = _edited_behavior(b, old, place, keep, text, path, edits, changes)
        if inserted:
            if place is None or place.end_line_start is None:
                appended += inserted                      # top-level rules: at the end
            else:
                block = "".join(place.indent + line + "\n" for line in inserted)
                if text[place.end_line_start - 1:place.end_line_start] not in ("\n", ""):
                    block = "\n" + block
                edits.append((place.end_line_start, place.end_line_start, block))
    out = _apply(text, edits)
    if appended:
        if not out.endswith("\n"):
            out += "\n"
        out += "\n# told in `mitos teach`\n" + "\n".join(appended) + "\n"
    return out, changes


def _edited_behavior(b: Behavior, old: Behavior, place: _Place | None, keep: dict[str, str],
                     text: str, path: str, edits: list[tuple[int, int, str]],
                     changes: list[str]) -> list[str]:
    """The edits (into ``edits``) of behavior ``b``'s rules, uses, operators and freezes
    since ``old``, where the file ``text`` at ``place`` writes it; returns the lines to
    insert at its end (new rules, uses, operators and freezes)."""
    inserted: list[str] = []
    if keep:
        inserted.append("operators: " + ", ".join(f"{k} = {v}" for k, v in keep.items()))
        changes.append(f"{b.name}: operators {inserted[-1][len('operators: '):]} (as before: "
                       f"the file's own `operators:` line now sets what `main` was told)")
    for i, rule in enumerate(b.rules):
        # a rule told again under its label stays in its place, a new one is added at
        # the end (`state._put_rule`): the first rules are the file's, in its order,
        # labelled or not
        before = old.rules[i] if i < len(old.rules) else None
        if before is None:
            inserted.append(format_rule(rule))
            changes.append(f"{b.name}: new rule {format_rule(rule)}")
            continue
        if before == rule:
            continue
        if place is None or i >= len(place.rules) or place.rules[i][0] != before.label:
            raise LessonError(f"{path} changed since the lesson began: rule "    # since
                              f"`{before.label or f'#{i + 1}'}` of behavior {b.name} is no "
                              f"longer there",
                              hint="start the lesson again on the file as it is now")
        rule_edits, marked = _rule_edits(text, before, rule, *place.rules[i][1])
        edits += rule_edits
        changes.append(f"{b.name}: {format_rule(rule)}"
                       + (f"; its comment marked `{BEFORE_TEACHING.strip()}`" if marked else ""))
    for use in b.uses[len(old.uses):]:
        inserted.append(format_use(use))
        changes.append(f"{b.name}: {format_use(use)}")
    told = b.operators[len(old.operators):]
    if told:
        changes.append(f"{b.name}: operators {_operators_text(told)}")
        kept = [s for s in told if place is None or s.key not in place.settings]
        if place is not None:
            # set where the file (or the behavior) already sets it: a second line
            # setting the same key is read with a warning
            for key, value in _last_values(told).items():
                if key in place.settings:
                    edits.append((*place.settings[key], f"{key} = {value}"))
        if kept:
            inserted.append("operators: " + _operators_text(kept))
    new_frozen = [label for label in b.frozen if label not in old.frozen]
    if new_frozen:
        inserted.append("frozen " + ", ".join(new_frozen))
        changes.append(f"{b.name}: frozen {', '.join(new_frozen)}")
    return inserted


def _rule_edits(text: str, before: Rule, rule: Rule, start: int, end: int,
                crisp: dict[str, tuple[int, int]]) -> tuple[list[tuple[int, int, str]], bool]:
    """``before``, written at ``start:end`` of ``text``, changed into ``rule``: where only
    crisp values changed (learned), those numbers (at ``crisp``, by output) and the rest of
    the line as the instructor wrote it, a comment on a changed number's line marked
    ``(before teaching)``; else the whole rule (told again: the comment after it is the
    instructor's). The edits, and whether a comment was marked."""
    if not (_only_crisp_changed(before, rule)
            and all(c.var in crisp for c in rule.consequents if c.term is None)):
        return [(start, end, format_rule(rule))], False
    edits = []
    marked: set[tuple[int, int]] = set()
    said = False
    for c_old, c_new in zip(before.consequents, rule.consequents):
        if c_old.value != c_new.value:
            assert c_new.value is not None   # same terms, so a crisp value changed
            s, e = crisp[c_new.var]
            edits.append((s, e, format_number(c_new.value)))
            comment = _comment_after(text, e, yaml=False)
            if comment is not None and comment not in marked:
                marked.add(comment)
                if not text[:comment[1]].endswith(BEFORE_TEACHING):
                    edits.append((comment[1], comment[1], BEFORE_TEACHING))
                    said = True
    return edits, said


def _operators_text(settings: Iterable[Setting]) -> str:
    """``settings`` as one ``operators:`` line's text, each key once with the value told last
    (one line may not set a key twice; two `operators:` lines at the prompt may)."""
    return ", ".join(f"{key} = {value}" for key, value in _last_values(settings).items())


def _last_values(settings: Iterable[Setting]) -> dict[str, str]:
    """Each key of ``settings`` with the value told last."""
    return {setting.key: setting.value for setting in settings}


def _only_crisp_changed(before: Rule, after: Rule) -> bool:
    if before.label != after.label or before.antecedent != after.antecedent \
            or before.weight != after.weight or len(before.consequents) != len(after.consequents):
        return False
    for a, b in zip(before.consequents, after.consequents):
        if (a.var, a.term, a.hedges) != (b.var, b.term, b.hedges):
            return False
    return True


def _kept_from_the_top(original: RuleBase, current: RuleBase, places: dict) -> dict[str, str]:
    """The operators told for the rules outside any behavior (`main`), each with the value
    the file set for every behavior before. The file has no block of `main`'s own: they are
    written on its top-level `operators:` line, the default of every behavior, so each other
    behavior that does not set them itself is written with the value it had. Without that a
    save of `operators: and = product` told for `main` beside any behavior read back as
    another rule base and was refused as "a bug in MITOS"."""
    from ..lang.operators import KEYS, resolve

    now = next((b for b in current.behaviors if b.name == "main"), None)
    was = next((b for b in original.behaviors if b.name == "main"), None)
    place = places.get("main")
    if now is None or was is None or place is None or place.end_line_start is not None:
        return {}
    before = resolve(original.operators)
    return {key: str(getattr(before, KEYS[key]))
            for key in _last_values(now.operators[len(was.operators):])}


def _behavior_text(b: Behavior, keep: dict[str, str] | None = None) -> str:
    lines = [f"behavior {b.name}:"]
    settings = {**(keep or {}), **_last_values(b.operators)}
    if settings:
        lines.append("    operators: " + ", ".join(f"{k} = {v}" for k, v in settings.items()))
    lines += ["    " + format_rule(r) for r in b.rules]
    lines += ["    " + format_use(u) for u in b.uses]
    if b.frozen:
        lines.append("    frozen " + ", ".join(b.frozen))
    lines.append("end")
    return "\n".join(lines)
