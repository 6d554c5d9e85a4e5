"""YAML with source positions, so that every complaint about a term set or a world can name the
file, the line and the key.

Loading is ``yaml.SafeLoader`` underneath (nothing is ever evaluated as Python), with numbers
and booleans read as YAML 1.2 reads them (:class:`_Yaml12Scalars`); mappings come
back as :class:`YMap` and sequences as :class:`YList`, which remember where each key and value
stood. Checking helpers (:func:`check_keys`, :func:`require`) raise the caller's error class with
that position and a "did you mean" for unknown keys.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from typing import Any

import yaml

from ..errors import MitosError, Span, did_you_mean


class YMap(dict):
    """A mapping that remembers the span of itself, of each key and of each value."""

    span: Span
    end_span: Span               # just after the mapping (after the `}` of a flow mapping)
    key_spans: dict
    value_spans: dict

    def key_span(self, key: str) -> Span:
        return self.key_spans.get(key, self.span)

    def value_span(self, key: str) -> Span:
        return self.value_spans.get(key, self.key_span(key))


class YList(list):
    """A sequence that remembers the span of itself and of each item."""

    span: Span
    item_spans: list

    def item_span(self, index: int) -> Span:
        return self.item_spans[index] if index < len(self.item_spans) else self.span


#: what YAML counts as a line break (PyYAML's reader)
BREAKS = re.compile("\r\n|[\n\r\x85\u2028\u2029]")


def _span(mark: Any, text: str, path: str | None) -> Span:
    return Span.at(text, path, mark.index, mark.line + 1, mark.column + 1, breaks=BREAKS)


#: deeper nesting than any of our formats needs (and than Python's recursion allows)
MAX_DEPTH = 64
#: more values (scalars, lists and mappings) than a term set, world or map file holds: a 4 MB
#: list of 2,000,000 took a GB and over a minute to read; 100,000 take some 8 s. 500,000, not
#: 100,000: a world of 16,000 obstacles (a size the reliability page times) holds about 96,000
MAX_NODES = 500_000


def _refuse(problem: str, mark: Any) -> yaml.constructor.ConstructorError:
    return yaml.constructor.ConstructorError(None, None, problem, mark)


_INT, _FLOAT = "tag:yaml.org,2002:int", "tag:yaml.org,2002:float"
_BOOL = "tag:yaml.org,2002:bool"
#: ``yes``, ``no``, ``on``, ``off`` (any of their three cases): booleans in YAML 1.1 only
YAML11_BOOL = "tag:mitos:yaml11-bool"
_YAML11_MEANS = {spelt: means for word, means in (("yes", True), ("on", True), ("no", False),
                                                  ("off", False))
                 for spelt in (word, word.title(), word.upper())}


class _Yaml12Scalars(yaml.SafeLoader):
    """Numbers and booleans as YAML 1.2 (and every reader of it but PyYAML) reads them:
    ``010`` is ten, not octal eight; ``1:00`` is text, not sexagesimal sixty; ``1e3`` and
    ``5e-2`` are numbers without needing a dot; ``0o17`` and ``0x1F`` are octal and hexadecimal
    on purpose; only ``true`` and ``false`` are booleans. YAML 1.1's ``yes``, ``no``, ``on``
    and ``off`` come back as the text they are (:data:`YAML11_BOOL` while resolving, so that a
    key spelt so is refused): a flag given one is refused, as ``known: 1`` is, where it was
    silently true (``known: yes``)."""

    yaml_implicit_resolvers = {
        first: [(tag, regexp) for tag, regexp in resolvers if tag not in (_INT, _FLOAT, _BOOL)]
        for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()}


def yaml11_bool(value: Any) -> bool | None:
    """What YAML 1.1 would read ``value`` (a scalar as loaded here) as, when it is one of the
    booleans of YAML 1.1 alone (``yes`` -> True); else None. For hints: "write `true`"."""
    return _YAML11_MEANS.get(value) if isinstance(value, str) else None


_Yaml12Scalars.add_implicit_resolver(
    _BOOL, re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"), list("tTfF"))
_Yaml12Scalars.add_implicit_resolver(
    YAML11_BOOL, re.compile(r"^(?:yes|Yes|YES|no|No|NO|on|On|ON|off|Off|OFF)$"),
    list("yYnNoO"))
_Yaml12Scalars.add_implicit_resolver(
    _INT, re.compile(r"^(?:[-+]?[0-9]+|0o[0-7]+|0x[0-9a-fA-F]+)$"), list("-+0123456789"))
_Yaml12Scalars.add_implicit_resolver(
    _FLOAT, re.compile(r"^(?:[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?"
                       r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$"), list("-+.0123456789"))


def _construct_int(loader: yaml.SafeLoader, node: yaml.ScalarNode) -> int:
    value = str(node.value)
    if value.startswith(("0o", "0x")):
        return int(value[2:], 8 if value[1] == "o" else 16)
    return int(value, 10)


def _construct_float(loader: yaml.SafeLoader, node: yaml.ScalarNode) -> float:
    value = str(node.value).lower()
    if value.endswith(".inf"):
        return float("-inf") if value.startswith("-") else float("inf")
    return float("nan") if value == ".nan" else float(value)


def _construct_text(loader: yaml.SafeLoader, node: yaml.ScalarNode) -> str:
    return str(node.value)


_Yaml12Scalars.add_constructor(_INT, _construct_int)
_Yaml12Scalars.add_constructor(_FLOAT, _construct_float)
_Yaml12Scalars.add_constructor(YAML11_BOOL, _construct_text)


def _unsupported(event: yaml.Event) -> yaml.constructor.ConstructorError | None:
    """The refusal of an alias, an anchor or a tag at ``event`` (no format here has them, and
    an alias bomb expands a few lines into billions of values), or ``None``. A quoted string
    keeps the tag ``!!str`` the parser gives it, and ``!`` (a plain non-specific tag) is no
    tag."""
    if isinstance(event, yaml.AliasEvent):
        return _refuse(f"aliases (`*{event.anchor}`) are not supported here; write "
                       f"the value out", event.start_mark)
    anchor = getattr(event, "anchor", None)
    if anchor is not None:
        return _refuse(f"anchors (`&{anchor}`) are not supported here", event.start_mark)
    tag = getattr(event, "tag", None)
    if tag is not None and tag != "!" and not (
            isinstance(event, yaml.ScalarEvent) and not event.implicit[0]
            and tag == "tag:yaml.org,2002:str"):
        shown = tag.replace("tag:yaml.org,2002:", "!!")
        return _refuse(f"YAML tags (`{shown}`) are not supported here", event.start_mark)
    return None


def _key_refusal(key_node: yaml.Node) -> yaml.constructor.ConstructorError | None:
    """The refusal of a mapping key that is not a plain name: a list or mapping, a merge key
    (`<<`), or a word YAML 1.1 reads as a boolean, a number or null (``ON``, ``1e3``, ``~``:
    the key the user wrote would be lost); ``None`` for a plain name."""
    if not isinstance(key_node, yaml.ScalarNode):
        return _refuse("a mapping key must be a plain name", key_node.start_mark)
    if key_node.tag == "tag:yaml.org,2002:merge":
        return _refuse("merge keys (`<<`) are not supported here; write the keys out",
                       key_node.start_mark)
    if key_node.tag != "tag:yaml.org,2002:str":
        kind = key_node.tag.rsplit(":", 1)[-1]
        kind = {"bool": "true/false", "yaml11-bool": "true/false",
                "null": "null"}.get(kind, "a number")
        return _refuse(f"the key `{key_node.value}` reads as {kind} in YAML; "
                       f"write it in quotes: \"{key_node.value}\"", key_node.start_mark)
    return None


class _SafeLoader(_Yaml12Scalars):
    """Safe loading without aliases, anchors, merge keys or tags (no format here has
    them, and an alias bomb expands a few lines into billions of values), nested at most
    :data:`MAX_DEPTH` deep, of at most :data:`MAX_NODES` values, and with the
    constructors' own errors kept at their node."""

    depth = 0
    nodes = 0

    def compose_node(self, parent: yaml.Node | None, index: int) -> yaml.Node | None:
        event = self.peek_event()
        refused = _unsupported(event)
        if refused is not None:
            raise refused
        self.nodes += 1
        if self.nodes > MAX_NODES:
            raise _refuse(f"more than {MAX_NODES:,} values, far more than any term set, "
                          f"world or map file holds", event.start_mark)
        self.depth += 1
        try:
            if self.depth > MAX_DEPTH:
                raise _refuse(f"nested more than {MAX_DEPTH} levels deep",
                              event.start_mark)
            return super().compose_node(parent, index)
        finally:
            self.depth -= 1

    def construct_object(self, node: yaml.Node, deep: bool = False) -> Any:   # any YAML value
        try:
            return super().construct_object(node, deep)
        except yaml.YAMLError:
            raise
        except (ValueError, TypeError, KeyError, AttributeError, OverflowError):
            kind = node.tag.rsplit(":", 1)[-1]
            raise _refuse(f"`{node.value}` cannot be read as {kind}", node.start_mark
                          ) from None


def _build_loader(text: str, path: str | None) -> type:
    """A :class:`_SafeLoader` for ``text`` (read from ``path``) whose mappings and lists know
    where each of their keys and items is written (:class:`YMap`, :class:`YList`)."""
    def construct_mapping(loader: _SafeLoader, node: yaml.MappingNode) -> YMap:
        out = YMap()
        out.span = _span(node.start_mark, text, path)
        out.end_span = _span(node.end_mark, text, path)
        out.key_spans, out.value_spans = {}, {}
        for key_node, value_node in node.value:
            refused = _key_refusal(key_node)
            if refused is not None:
                raise refused
            key = loader.construct_object(key_node, deep=True)
            if key in out:
                raise yaml.constructor.ConstructorError(
                    None, None, f"duplicate key `{key}`", key_node.start_mark)
            out[key] = loader.construct_object(value_node, deep=True)
            out.key_spans[key] = _span(key_node.start_mark, text, path)
            out.value_spans[key] = _span(value_node.start_mark, text, path)
        return out

    def construct_sequence(loader: _SafeLoader, node: yaml.SequenceNode) -> YList:
        out = YList(loader.construct_object(child, deep=True) for child in node.value)
        out.span = _span(node.start_mark, text, path)
        out.item_spans = [_span(child.start_mark, text, path) for child in node.value]
        return out

    class Loader(_SafeLoader):
        pass

    Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, construct_mapping)
    Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_SEQUENCE_TAG, construct_sequence)
    return Loader


#: the longest YAML text read (characters): PyYAML scans some 3 MB a second here, and a 250 MB
#: term set (one long description) ran for minutes; the packaged files hold a few KB
MAX_CHARS = 16 << 20


def load(text: str, path: str | None, error: type[MitosError]) -> Any:
    """Parse YAML ``text`` (from ``path``) into positioned values, raising ``error`` when bad
    (or longer than :data:`MAX_CHARS`, refused before a character is scanned)."""
    if len(text) > MAX_CHARS:
        raise error(f"`{path}` holds {len(text):,} characters; a term set, world or map file "
                    f"may hold at most {MAX_CHARS:,} ({MAX_CHARS >> 20} MB)",
                    span=Span(path, 1, 1) if path else None)
    try:
        return yaml.load(text, Loader=_build_loader(text, path))  # noqa: S506 (SafeLoader)
    except yaml.MarkedYAMLError as exc:
        unclosed_flow(exc, text, path, error)
        unclosed = exc.problem == "found unexpected end of stream" and "quoted" in (exc.context or "")
        # a key without its `:` is found missing on the next line; a bare `*` or `&` after it
        at_start = unclosed or exc.problem == "could not find expected ':'" or \
            (exc.context or "") in ("while scanning an alias", "while scanning an anchor",
                                    "while parsing a tag", "while scanning a tag",
                                    "while scanning a directive")
        mark = (exc.context_mark if at_start else None) or exc.problem_mark or exc.context_mark
        span = _span(mark, text, path) if mark is not None else None
        problem, expected = _in_words(exc.problem or exc.context or "malformed YAML", exc.context)
        if mark is not None and exc.problem == _TAB:
            problem, expected = _tab_words(text, mark.index) or (problem, expected)
        hint = glued_hint(text, mark.line + 1) if mark is not None else None
        raise error(f"invalid YAML: {problem}", span=span, expected=expected, hint=hint) \
            from None
    except yaml.reader.ReaderError as exc:       # a character YAML does not allow
        pos = min(exc.position, len(text))
        line = text.count("\n", 0, pos) + 1
        column = pos - (text.rfind("\n", 0, pos) + 1) + 1
        char = chr(exc.character) if isinstance(exc.character, int) else exc.character
        raise error(f"invalid YAML: character {char!r} is not allowed",
                    span=Span.at(text, path, pos, line, column)) from None
    except yaml.YAMLError as exc:  # pragma: no cover - other YAML errors carry no mark
        raise error(f"invalid YAML: {exc}", span=Span(path, 1, 1)) from None


#: a key glued to its value (`seed:3`, `- radius:9`): YAML reads `seed:3` as one plain word
#: (matched on the line without its comment and trailing blanks: a lazy value before
#: `[ \t]*(?:#.*)?$` tried every end, quadratic in a line of blanks)
_GLUED_KEY = re.compile(r"[ \t]*(?:-[ \t]+)?([A-Za-z_][\w.-]*):([^\s:/\\#'\"].*)")
#: a list item's `-` glued to the item (`-points:`, `-{name: A}`): YAML reads a plain word
_GLUED_DASH = re.compile(r"[ \t]*-([\[{A-Za-z_].*)")


def glued_hint(text: str, line: int) -> str | None:
    """A hint for a YAML error at ``line`` (1-based) when that line or one of the two above
    glues a key to its value (``seed:3``: YAML reads one word, and the error falls where a key
    was due, or a line later) or a list's `-` to its item (``-points:``)."""
    lines = text.splitlines()
    for i in range(min(line, len(lines)) - 1, max(line - 4, -1), -1):
        code = lines[i].split("#", 1)[0].rstrip(" \t")
        key = _GLUED_KEY.fullmatch(code)
        if key:
            value = key.group(2) if len(key.group(2)) <= 24 else key.group(2).split()[0]
            return (f"`{key.group(1)}:{value}` (line {i + 1}) is one word to YAML: a key's "
                    f"`:` needs a space after it, `{key.group(1)}: {value}`")
        dash = _GLUED_DASH.fullmatch(code)
        if dash:
            word = dash.group(1).split()[0]
            return (f"`-{word}` (line {i + 1}) is one word to YAML: a list item's `-` needs a "
                    f"space after it, `- {word}`")
    return None


def _glued_key(key: object) -> str | None:
    """``length:24`` as a key (YAML's reading of ``{length:24}``): a hint to write the space."""
    match = re.fullmatch(r"([A-Za-z_][\w.-]*):(\S.*)", key) if isinstance(key, str) else None
    return (f"YAML reads `{key}` as one key: a key's `:` needs a space after it, "
            f"`{match.group(1)}: {match.group(2)}`") if match else None


def unclosed_flow(exc: yaml.MarkedYAMLError, text: str, path: str | None,
                  error: type[MitosError]) -> None:
    """A `[` list or `{` mapping not closed before a later line (`points: [[0, 0], [600, 0]`
    and the next key): PyYAML said "expected ',' or ']', but got '<scalar>'" at the next
    line's first word. Said at the bracket that is not closed."""
    flows = {"while parsing a flow sequence": ("[", "]"), "while parsing a flow mapping":
             ("{", "}")}
    brackets = flows.get(exc.context or "")
    opened, seen = exc.context_mark, exc.problem_mark
    if brackets is None or opened is None or seen is None or seen.line <= opened.line:
        return
    got = "the end of the file" if "<stream end>" in (exc.problem or "") else \
        f"line {seen.line + 1}"
    raise error(f"invalid YAML: this `{brackets[0]}` is not closed before {got}",
                span=_span(opened, text, path),
                expected=f"`{brackets[1]}` after its last item (its items apart with `,`)") \
        from None


#: PyYAML's words for a tab where a token would start
_TAB = "found character '\\t' that cannot start any token"
#: blanks to the line's end (or to a comment) from a tab on
_TRAILING = re.compile(r"\t[ \t]*(?:#[^\n]*)?(?:\r?\n|\r|$)")
#: a tab after the last thing on a line: YAML takes it there, as any blank, but PyYAML does
#: not, and "a tab, which YAML does not take as indentation" sent users looking at the indent
_TRAILING_TAB = ("a tab at the end of the line, after what it holds (the YAML reader takes "
                 "no tab there, though a space is fine)", "nothing after it on the line: delete "
                 "the tab, or make it a space")

#: a tab after a key's `:`, a list item's `-` or a flow list's `[`, `{` or `,`: where the
#: value starts (the indicator is the group)
_BEFORE_VALUE = re.compile(r"(?:^|.*[^\s])(:)$|(?:^|.*\s)([-?])$|.*[\[{].*([\[{,])$")


def _tab_words(text: str, at: int) -> tuple[str, str] | None:
    """What a tab PyYAML refuses (``at``, "found character '\\t' that cannot start any
    token") is, told by what stands before and after it on its line: at the line's end,
    after what the line holds; where a value starts (after a key's `:`, an item's `-`); or
    inside a value without quotes (`name: a<TAB>b`), which PyYAML said as a tab that YAML
    does not take as indentation or to start a value, and sent the user to the indentation.
    ``None`` in the indentation, which :data:`_WORDS` says (a tab between a key and its `:`
    is said as such)."""
    if _TRAILING.match(text, at):
        return _TRAILING_TAB
    start = max(text.rfind("\n", 0, at), text.rfind("\r", 0, at)) + 1
    before = text[start:at].rstrip(" \t")
    if not before:
        return None
    indicator = _BEFORE_VALUE.match(before)
    if indicator is not None:
        shown = next(g for g in indicator.groups() if g)
        return (f"a tab after `{shown}`, where the value starts (the YAML reader takes no tab "
                "there, though a space is fine)", "a space in place of the tab")
    word = _LAST_WORD.search(before)
    shown = word.group(0) if word is not None else before
    if _KEY_AFTER.match(text, at):
        return (f"a tab between the key `{shown}` and its `:`", "`key: value`, nothing between a "
                "key and its `:`")
    return (f"a tab inside a value, after `{shown}` (the YAML reader takes no tab in a value "
            "that is not in quotes)", "a space in place of the tab, or the whole value in "
            "quotes (`\"...\"`, which keeps the tab)")


#: the word before a tab inside a value (not the `[`, `{` or `,` before it in a flow)
_LAST_WORD = re.compile(r"[^\s\[{,]+$")
#: a tab between a key and its `:`
_KEY_AFTER = re.compile(r"\t[ \t]*:(?:[ \t\r\n]|$)")


#: PyYAML's words for the mistakes people make most, and what YAML expected there
_WORDS = {
    _TAB:
        ("a tab in the indentation, which YAML does not take",
         "spaces: YAML indents with spaces only"),
    "mapping values are not allowed here":
        ("a `:` where no new key can start",
         "one `key: value` a line, the keys of one mapping indented alike, and a value that "
         "holds `: ` in quotes"),
    "expected <block end>, but found '<block mapping start>'":
        ("this line's indentation matches no key above it",
         "the indentation of a key above it, or a key ending in `:` on the line above"),
}


#: what PyYAML's parser expected a block's end (its next key or item, or less indentation)
#: but found instead, in words: ``(problem, expected)``
_BLOCK_END = {
    "'?'": ("a key among the `- ` items of a list",
            "the key indented as the keys of the item above it (past its `- `), or as the keys "
            "above the list; or `- ` before it to begin an item"),
    "'-'": ("a `- ` list item among the keys of a mapping",
            "the list under a key of its own (`key:` on the line above, the items indented "
            "below it), or a `key: value` here"),
    "'<scalar>'": ("more after the value on this line",
                   "one value after `key:`; a text with quotes or brackets in it in one pair "
                   "of quotes"),
}

#: a character that starts something else in YAML (a key, an alias, an anchor, a tag, the
#: end of a bracket), met where a value starts
_VALUE_STARTS = re.compile(r"found character '(.)' that cannot start any token"
                           r"|expected the node content, but found '(.)'")


def _in_words(problem: str, context: str | None) -> tuple[str, str | None]:
    """PyYAML's problem in plain words, with what was expected where PyYAML does not say:
    its parser's own words ("expected <block end>, but found '?'", "but found another
    document") are never shown."""
    if problem in _WORDS:
        return _WORDS[problem]
    if problem == "found unexpected end of stream" and context and "quoted" in context:
        return "a quoted value is not closed before the end of the file", "its closing quote"
    if problem == "but found another document":
        return ("a second document (`---`) after the first",
                "one document in the file: remove this `---` and what follows it, or put that "
                "in a file of its own")
    if problem.startswith("expected '<document start>'"):
        return ("text after the end of the document (a `...` line, or a `%` directive without "
                "`---` after it)", "nothing after a `...` line: remove it")
    if problem == "could not find expected ':'":
        return ("a line that is neither `key: value` nor `- item` (no `:` after its key)",
                "`key: value`, or `- item` in a list; a text of several lines in quotes")
    if problem.startswith("expected <block end>, but found "):
        return _BLOCK_END.get(problem.rsplit(" ", 1)[-1], (
            "this line's indentation matches no key or list above it",
            "the indentation of a key or a `- ` item above it"))
    if problem == "sequence entries are not allowed here":
        return ("a `- ` list item on the line of its key",
                "the items on lines of their own below the key, indented (`- a`), or a list in "
                "brackets (`[a, b]`); a text that starts with `- ` in quotes")
    if context == "while scanning a directive":
        return ("`%` at the start of a line begins a YAML directive",
                "the key without `%`, or in quotes")
    if problem.startswith("expected the node content, but found '<stream end>'"):
        return ("the file ends where a value should start",
                "a value there, and each `[` and `{` closed")
    starts = _VALUE_STARTS.match(problem)
    char = (starts.group(1) or starts.group(2)) if starts else \
        {"while scanning an alias": "*", "while scanning an anchor": "&",
         "while parsing a tag": "!", "while scanning a tag": "!"}.get(context or "")
    if problem == "mapping keys are not allowed here":
        char = "?"
    if char is not None:
        shown = "`` ` ``" if char == "`" else f"`{char}`"
        return (f"{shown} cannot start a value in YAML",
                'the value in quotes: "?"' if char == "?" else f'the value in quotes: "{char}..."')
    if context == "while scanning a block scalar":
        return ("after `|` or `>` (a block of text) only `+`, `-` or a digit from 1 to 9 may "
                "follow on its line", "the text on the lines below, indented, or the value in "
                "quotes")
    return _TOKEN_NAMES.sub(lambda m: _TOKENS[m.group(0)], problem), None


#: PyYAML's names of its tokens, in words (for its messages not said otherwise above)
_TOKENS = {"'<stream end>'": "the end of the file", "'<scalar>'": "a value",
           "'<tag>'": "a tag (`!`)", "'<anchor>'": "an anchor (`&`)", "'<alias>'": "an alias (`*`)",
           "'<block mapping start>'": "a key", "'<block sequence start>'": "a `- ` item",
           "'<block end>'": "less indentation", "<block end>": "less indentation",
           "'<flow sequence start>'": "`[`", "'<flow mapping start>'": "`{`",
           "'<document start>'": "`---`", "'<document end>'": "`...`",
           "'<directive>'": "a `%` directive"}
_TOKEN_NAMES = re.compile("|".join(re.escape(t) for t in sorted(_TOKENS, key=len, reverse=True)))


def check_keys(mapping: YMap, allowed: Iterable[str], error: type[MitosError],
               what: str) -> None:
    """Refuse keys of ``mapping`` not in ``allowed``, suggesting the closest one."""
    allowed = list(allowed)
    for key in mapping:
        if key not in allowed:
            raise error(f"unknown key `{key}` in {what}", span=mapping.key_span(key),
                        expected="one of " + ", ".join(allowed),
                        hint=_glued_key(key) or did_you_mean(key, allowed))


def require(mapping: YMap, key: str, error: type[MitosError], what: str) -> Any:
    """The value of ``key``, or ``error`` naming the mapping's line when it is missing."""
    if key not in mapping:
        glued = next((k for k in mapping if isinstance(k, str) and k.startswith(f"{key}:")),
                     None)                         # `{shape:triangle, ...}`
        raise error(f"missing `{key}` in {what}", span=mapping.span,
                    hint=_glued_key(glued) or f"add `{key}: ...` to {what}")
    return mapping[key]


def expect_map(value: Any, span: Span, error: type[MitosError], what: str) -> YMap:
    if not isinstance(value, YMap):
        raise error(f"{what} must be a mapping (`key: value` lines)", span=span,
                    hint=_glued_key(value))         # `route:` and `  replan:never` below
    return value


def expect_number(value: Any, span: Span, error: type[MitosError], what: str, *,
                  units: str | None = None) -> float:
    """``value`` as a finite float, or ``error`` saying a number was expected. ``units`` says
    what the file's numbers are in, for a number written with a unit (``16in``, ``50ms``)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        shown = _quoted_number(value, span) or as_written(value, span)
        raise error(f"{what} must be a number, not {shown}", span=span,   # (YAML's `true`)
                    hint=_unit_hint(value, units))
    try:
        number = float(value)
    except OverflowError:
        raise error(f"{what} must be a finite number, not an integer of "
                    f"{len(str(abs(value)))} digits", span=span) from None
    if number != number:                            # `.nan`: not a number, of any range
        raise error(f"{what} must be a finite number, not `{_written(span) or 'nan'}`",
                    span=span)
    if number in (float("inf"), float("-inf")):
        text = _written(span)
        if text is not None and "inf" not in text.lower():    # 1.0e400: YAML read inf
            raise error(f"{what} must be a finite number: `{text}` is past a float's range",
                        span=span)
        raise error(f"{what} must be a finite number, not `{value}`", span=span)
    return number


#: A number followed by a unit: ``16in``, ``50 ms``, ``90deg``, ``-4.5 in/s``. The digits
#: before and after the point are one way to read (``\d+\.?\d*`` split a run of digits every
#: way: a fuzzed value of 200,000 digits took half an hour to be refused).
_WITH_UNIT = re.compile(r"\s*([-+]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?)\s*([^\d\s.+-][^\s]*)\s*")


def _unit_hint(value: Any, units: str | None) -> str | None:
    """What to write instead of a number with a unit (``dt: 50ms`` said only "must be a
    number, not `50ms`"): the number alone, in the file's units (which ``units`` names; the
    number is not repeated: `50` would be 50 s)."""
    found = _WITH_UNIT.fullmatch(value) if isinstance(value, str) else None
    if found is None:
        return None
    return (f"write the number alone, without `{found.group(2)}`"
            + (f": {units}" if units else ": a value takes no unit"))


def _quoted_number(value: Any, span: Span) -> str | None:
    """``the text `"0.05"` ...`` for a number written in quotes, which YAML reads as text:
    "resolution must be a number, not `0.05`" did not say what was wrong with 0.05."""
    text = _written(span)
    if not isinstance(value, str) or text is None or text[:1] not in ("'", '"'):
        return None
    try:
        float(value)
    except ValueError:
        return None
    return f"the text {text}: YAML reads a value in quotes as text; write the number without them"


#: how YAML writes nothing (``null``, ``Null``, ``NULL``, ``~``)
_NULLS = ("null", "Null", "NULL", "~")


def as_written(value: Any, span: Span) -> str:
    """``value`` (a value as loaded here) as the file wrote it, for "must be ..., not X":
    `null` and `~` as written, an empty value as "nothing (an empty value)", a boolean as
    `true`, a list or mapping as what it is (``give_way: null`` read "not `None`", Python's
    word for it, and ``give_way: [true]`` "not `[True]`")."""
    if value is None:
        written = _written(span)
        return f"`{written}`" if written in _NULLS else "nothing (an empty value)"
    if isinstance(value, bool):
        return f"`{str(value).lower()}`"
    if isinstance(value, str) and not value:
        return f"the empty text `{_written(span) or chr(34) * 2}`"
    if isinstance(value, list):
        return "a list"
    if isinstance(value, dict):
        return "a mapping"
    return f"`{value}`"


def _written(span: Span) -> str | None:
    """The scalar as written at ``span``, where the span holds its line."""
    if span.source_line is None:
        return None
    found = re.compile(r"[^\s,\]}#]+").match(span.source_line, span.column - span.source_start)
    return found.group() if found else None
