"""``mitos docs``: the documentation's pages, which a wheel carries: a page's text, or where it is.

The help texts and hints that point to a page say ``mitos docs NAME`` (``docs/NAME.md`` in the
repository), so that a user who installed MITOS with pip, whose copy has no ``docs/`` folder
of its own, reads the same page. A page's links to ``docs/NAME.md`` or ``NAME.md`` are
``mitos docs NAME``.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING, Annotated

import typer

from .complete import pages
from .output import emit
from .params import WORDS

if TYPE_CHECKING:
    from importlib.abc import Traversable


def page_name(given: str) -> str:
    """The page ``given`` names: its name (``interop``), as a file (``interop.md``,
    ``docs/interop.md``) or in any case; ``README.md`` is ``readme``, ``worlds/README.md``
    ``worlds``."""
    key = given.strip().replace("\\", "/").lower()
    key = re.sub(r"^(\./)?(docs/)?", "", key).removesuffix(".md")
    return "worlds" if key == "worlds/readme" else key


def find_page(given: str) -> tuple[str, Traversable]:
    """``(name, file)`` of the page ``given`` names, else a usage error with the pages and
    "did you mean"; a page its copy of MITOS lacks is an error that says so."""
    from ..errors import MitosError, UsageError, did_you_mean
    from ..resources import doc_pages, is_file

    pages = doc_pages()
    name = page_name(given)
    if name not in pages:                # every name: `unknown` cuts a list at 12
        raise UsageError(f"unknown page `{given}`", expected="one of " + ", ".join(pages),
                         hint=did_you_mean(name, pages) or "`mitos docs` lists them")
    if not is_file(pages[name]):
        raise MitosError(f"page `{name}` is not installed with this copy of MITOS",
                         hint="reinstall it from its wheel (`pip install mitos-planner`)")
    return name, pages[name]


def title(text: str) -> str:
    """A page's first ``# `` heading, without its marks."""
    for line in text.splitlines():
        if line.startswith("# "):
            return line[2:].replace("`", "").strip()
    return ""


def listing() -> str:
    from ..resources import doc_pages, is_file

    rows = [(name, title(page.read_text(encoding="utf-8")))
            for name, page in doc_pages().items() if is_file(page)]
    width = max((len(n) for n, _ in rows), default=0)
    return "\n".join(["pages (mitos docs NAME prints one; --path says where its file is):",
                      *(f"  {n.ljust(width)}  {t}".rstrip() for n, t in rows)])


def docs_command(
    page: Annotated[str | None, typer.Argument(
        metavar="[PAGE]", show_default=False, click_type=WORDS, autocompletion=pages,
        help="The page to print: interop, teach, language, ..., readme or worlds (as "
             "docs/interop.md and README.md are named in the repository). Without it, the "
             "list of pages.")] = None,
    path: Annotated[bool, typer.Option(
        "--path", help="Print where the page's file is (without PAGE: the folder of the "
                       "pages) instead of its text.")] = False,
) -> None:
    """Print a page of the documentation, which is installed with MITOS, or list the pages.

    Example: `mitos docs interop | less`; `mitos docs teach --path` for its file.
    """
    from ..resources import data_dir, real_path

    if page is None:
        emit(str(real_path(data_dir("docs"))) if path else listing())
        return
    _, file = find_page(page)
    emit(str(real_path(file)) if path else file.read_text(encoding="utf-8"))
