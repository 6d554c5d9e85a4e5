"""Where the grammar, the packaged rule bases, worlds and the documentation live.

In a wheel they are package data under ``mitos_cli/_data/`` (read with ``importlib.resources``,
so they work from a zip too); in a source checkout they are the top-level ``grammar/``,
``rulebases/``, ``worlds/`` and ``docs/`` directories next to the package (and the README).
"""

from __future__ import annotations

import importlib.resources
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from importlib.abc import Traversable

DEFAULT_RULEBASE = "mitos.rules"
DEFAULT_WORLD = "corridor.yaml"


def data_dir(kind: str) -> Traversable:
    """The ``grammar``, ``rulebases``, ``worlds`` or ``docs`` directory as a Traversable."""
    packaged = importlib.resources.files("mitos_cli") / "_data" / kind
    if packaged.is_dir():
        return packaged
    return importlib.resources.files("mitos_cli") / ".." / kind


def grammar_text(name: str = "mitos.lark") -> str:
    return (data_dir("grammar") / name).read_text(encoding="utf-8")


def packaged_path(kind: str, name: str) -> Path:
    """A packaged file as a real filesystem path (extracted when the package is zipped)."""
    return real_path(data_dir(kind) / name)


def real_path(resource: Traversable) -> Path:
    """A packaged file or folder as a real filesystem path (extracted when zipped)."""
    if isinstance(resource, Path):
        return resource.resolve()
    stack = importlib.resources.as_file(resource)  # zip: extract to a temporary file
    return Path(stack.__enter__())


def packaged_names(kind: str, suffix: str) -> Iterator[str]:
    for entry in sorted(data_dir(kind).iterdir(), key=lambda e: e.name):
        if entry.name.endswith(suffix):
            yield entry.name


def resolve(kind: str, name: str | Path, suffix: str, base: Path | None = None) -> Path | None:
    """``name`` if it exists (first relative to ``base``, e.g. the lesson that names it, then
    to the working directory), else the packaged file of that name (``figure4`` ->
    ``worlds/figure4.yaml``, ``rulebases/mitos.rules`` from anywhere), else ``None``."""
    p = Path(name)
    for candidate in ([base / p] if base is not None else []) + [p]:
        if is_file(candidate):
            return candidate
    if not packaged_place(p.parent.as_posix(), kind):
        return None             # `nope/corridor.yaml`: a mistyped directory, not the packaged
    for filename in (p.name, p.name + suffix):
        if is_file(data_dir(kind) / filename):
            return packaged_path(kind, filename)
    return None


def doc_pages() -> dict[str, Traversable]:
    """The documentation's pages by the name ``mitos docs`` takes: each ``docs/NAME.md``,
    the README as ``readme`` and the worlds' README as ``worlds``. A wheel carries them under
    ``mitos_cli/_data/docs/`` (the README beside the pages); a checkout has them in place."""
    docs = data_dir("docs")
    pages: dict[str, Traversable] = {}
    if docs.is_dir():
        for entry in sorted(docs.iterdir(), key=lambda e: e.name):
            if entry.name.endswith(".md") and entry.name != "README.md":
                pages[entry.name.removesuffix(".md")] = entry
    readme = docs / "README.md"
    pages["readme"] = readme if is_file(readme) else \
        importlib.resources.files("mitos_cli") / ".." / "README.md"
    pages["worlds"] = data_dir("worlds") / "README.md"
    return pages


def packaged_place(directory: str, kind: str) -> bool:
    """Whether a file named in ``directory`` may be the packaged one: a bare name, or one
    under the directory it has in the repository (``worlds/``, ``rulebases/lessons/`` or
    ``lessons/``), as the docs and the README write them."""
    return directory == "." or directory == kind or kind.endswith("/" + directory)


def is_file(path: Path | Traversable) -> bool:
    """``path.is_file()``, False for a name the system cannot look up (longer than 255
    characters): such a name is simply not found, and the caller says so in words."""
    try:
        return path.is_file()
    except OSError:
        return False


def is_dir(path: Path) -> bool:
    """``path.is_dir()``, False for a name the system cannot look up (as :func:`is_file`)."""
    try:
        return path.is_dir()
    except OSError:
        return False


def exists(path: Path) -> bool:
    """``path.exists()``, False for a name the system cannot look up (as :func:`is_file`)."""
    try:
        return path.exists()
    except OSError:
        return False


def display_path(path: str | None) -> str:
    """A rule-base path as users should read it: relative to here, or marked as packaged; by
    the names given, not the place a symbolic link on the way leads to."""
    import os

    if not path:
        return "<rules>"
    packaged = packaged_name(path)
    if packaged is not None:
        return f"{packaged} (packaged)"
    try:
        return os.path.relpath(path)
    except ValueError:
        return str(path)


def display_world(path: str) -> str:
    """A world's path as a study's report shows it: a packaged world by its name, marked as
    packaged (`corridor (packaged)`, not where pip put it), any other as given."""
    name = packaged_world(world_file(path))
    return path if name is None else f"{name} (packaged)"


def world_file(name: str | Path) -> Path:
    """The file a world ``name`` of a study opens: the file as given, else the packaged world
    of that name (``corridor``, ``worlds/corridor.yaml``), else ``name`` as it is (said where
    it is read)."""
    found = resolve("worlds", name, ".yaml")
    return Path(name) if found is None else found


def packaged_world(path: str | Path) -> str | None:
    """The name a study gives the packaged world at ``path`` (``corridor``, not where pip put
    it), which opens that world from any directory; None for any other file (and for a
    packaged world that a file of the working directory of its name would hide)."""
    try:
        packaged = Path(str(data_dir("worlds"))).resolve()
        p = Path(path).resolve()
        if p.parent != packaged or p.suffix != ".yaml":
            return None
        found = resolve("worlds", p.stem, ".yaml")
        return p.stem if found is not None and Path(found).resolve() == p else None
    except (OSError, ValueError):
        return None


def packaged_name(path: str) -> str | None:
    """``rulebases/NAME`` for a file of the packaged rule bases (wherever pip put them),
    else None."""
    from pathlib import Path

    try:
        packaged = Path(str(data_dir("rulebases"))).resolve()
        p = Path(path).resolve()
        if p.is_relative_to(packaged):
            return f"rulebases/{p.relative_to(packaged).as_posix()}"
    except (OSError, ValueError):
        pass
    return None
