"""``mitos list``: the packaged worlds, rule bases, term sets and lessons, a line each.

A world is described by its ``name`` and the first sentence of its leading comment, a rule base
by its behaviors, a term set by its variables, a lesson by the first sentence of its leading
comment: whole in ``--json``, cut to a line (with ``...``) in the text listing.
Each is listed by the name the commands accept (``mitos simulate corridor``, ``--rulebase
mitos.rules``, ``mitos plot terms drive.terms.yaml``, ``--lesson wider-turn``).
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING, Annotated

import typer

from .output import emit, json_text
from .params import WORDS

if TYPE_CHECKING:
    from pathlib import Path

#: Each section: its title in the listing, where the files are and the suffix they end in.
SECTIONS = {
    "worlds": ("worlds (mitos simulate NAME)", "worlds", ".yaml"),
    "rulebases": ("rule bases (--rulebase NAME)", "rulebases", ".rules"),
    "termsets": ("term sets (mitos plot terms NAME, mitos check NAME)", "rulebases",
                 ".terms.yaml"),
    "lessons": ("lessons (mitos teach --lesson NAME)", "rulebases/lessons", ".lesson"),
}


def first_comment_line(text: str) -> str:
    """The first line of the comment a file starts with, without its ``#``; ``...`` marks a
    sentence that goes on in the next comment line, and a line whose first sentences end in
    it gives those alone. Empty when the file starts otherwise."""
    lines = [line.strip() for line in text.splitlines()]
    lines = [line for line in lines if line]
    for i, line in enumerate(lines):
        if not line.startswith("#"):
            return ""
        words = line.lstrip("#").strip()
        if not words:
            continue
        after = lines[i + 1].lstrip("#").strip() if i + 1 < len(lines) and \
            lines[i + 1].startswith("#") else ""
        if not after or words.endswith((".", "!", "?", ":")):
            return words
        # a sentence that ends in the line: that sentence, not the next one cut short
        # (detour's "... today's state of it. It is given the corridors (its ...")
        ends = [m.end() - 1 for m in re.finditer(r"[.!?](?=\s+[A-Z])", words)]
        return words[:ends[-1] + 1] if ends else words + " ..."
    return ""


#: The longest description the text listing prints whole; a longer one is cut at a word.
TEXT_WIDTH = 100


def first_sentence(text: str) -> str:
    """The first sentence of the comment a file starts with, whole, over as many comment
    lines as it takes (a blank ``#`` line ends it). Where the first line ends a sentence (or
    a line ending in ``:`` introduces a list), it is :func:`first_comment_line`."""
    line = first_comment_line(text)
    if not line.endswith(" ..."):
        return line
    words: list[str] = []
    for raw in text.splitlines():
        raw = raw.strip()
        if not raw:
            if words:
                break
            continue
        if not raw.startswith("#"):
            break
        part = raw.lstrip("#").strip()
        if not part and words:
            break
        if part:
            words.append(part)
    paragraph = " ".join(words)
    end = re.search(r"[.!?](?=\s+[A-Z])", paragraph)
    return paragraph[:end.end()] if end else paragraph


def shorten(description: str, width: int = TEXT_WIDTH) -> str:
    """A world's or lesson's ``description`` as the text listing prints it: whole up to
    ``width`` characters, else cut at the last word that fits, with `` ...``."""
    if len(description) <= width:
        return description
    cut = description[:width - 3].rsplit(" ", 1)[0].rstrip(",;:")
    return cut + " ..."


def _world(path: Path) -> dict:
    from ..errors import WorldError
    from ..lang import yamlpos

    text = path.read_text(encoding="utf-8")
    data = yamlpos.load(text, str(path), WorldError)
    name = data.get("name") if isinstance(data, dict) else None
    return {"name": path.stem, "world_name": None if name is None else str(name),
            "description": first_sentence(text)}


def _rulebase(path: Path) -> dict:
    from ..lang.resolve import load_rules_file

    rb = load_rules_file(path)
    return {"name": path.name, "behaviors": [b.name for b in rb.behaviors],
            "description": "behaviors: " + ", ".join(b.name for b in rb.behaviors)}


def _termset(path: Path) -> dict:
    from ..lang.termfile import load_termset

    names = [v.name for v in load_termset(path).variables]
    return {"name": path.name, "variables": names, "description": "variables: " + ", ".join(names)}


def _lesson(path: Path) -> dict:
    return {"name": path.stem,
            "description": first_sentence(path.read_text(encoding="utf-8"))}


def catalogue(only: str | None = None) -> dict[str, list[dict]]:
    """Every packaged world, rule base, term set and lesson, by section, in file-name order
    (of the section ``only``, if given)."""
    from ..resources import packaged_names, packaged_path

    describe = {"worlds": _world, "rulebases": _rulebase, "termsets": _termset,
                "lessons": _lesson}
    return {key: [describe[key](packaged_path(folder, filename))
                  for filename in packaged_names(folder, suffix)]
            for key, (_, folder, suffix) in SECTIONS.items() if only in (None, key)}


def render(cat: dict[str, list[dict]]) -> str:
    lines: list[str] = []
    width = max((len(e["name"]) for entries in cat.values() for e in entries), default=0)
    for key, entries in cat.items():
        if lines:
            lines.append("")
        lines.append(SECTIONS[key][0])
        for e in entries:
            description = e["description"]
            if key in ("worlds", "lessons"):            # a sentence; the names stay whole
                description = shorten(description)
            description = description or "(no description)"
            if key == "worlds" and e["world_name"] not in (None, e["name"]):
                description = f"`{e['world_name']}`: {description}"
            lines.append(f"  {e['name'].ljust(width)}  {description}")
        if not entries:
            lines.append("  (none)")
    return "\n".join(lines)


def section_of(kind: str) -> str:
    """The section ``kind`` names: ``worlds``, ``rulebases``, ``termsets`` or ``lessons``, or
    one of them in the singular, or with a space or dash (``rule-base``), in any case."""
    from ..errors import UsageError, unknown

    key = re.sub(r"[\s_-]+", "", kind.strip().lower())
    if key in SECTIONS:
        return key
    if key + "s" in SECTIONS:
        return key + "s"
    raise unknown("kind", kind, list(SECTIONS), cls=UsageError)


def list_command(
    kind: Annotated[str | None, typer.Argument(
        metavar="[KIND]", show_default=False, click_type=WORDS,
        help="Only one kind: worlds, rulebases, termsets or lessons.")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """List the packaged worlds, rule bases, term sets and lessons, a line each.

    Example: `mitos list`, then `mitos simulate slalom`; `mitos list worlds` for the worlds
    alone.
    """
    only = None if kind is None else section_of(kind)
    cat = catalogue(only)
    emit(json_text(cat) if as_json else render(cat))
