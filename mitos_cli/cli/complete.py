"""Shell completion beyond options (``mitos --install-completion``): packaged world names,
planners, executors and the documentation's pages. A word no packaged name starts with
completes as a file, the shell's default."""

from __future__ import annotations


def worlds(incomplete: str) -> list[str]:
    """The packaged worlds by the name the commands accept (``figure4``)."""
    from ..resources import packaged_names

    names = (n.removesuffix(".yaml") for n in packaged_names("worlds", ".yaml"))
    return [n for n in names if n.startswith(incomplete)]


def planners(incomplete: str) -> list[str]:
    from ..sim.planner import PLANNERS

    return [n for n in PLANNERS if n.startswith(incomplete)]


def planner_list(incomplete: str) -> list[str]:
    """``compare --planner fuzzy,d`` -> ``fuzzy,dwa``: the last name of a comma-separated list,
    among the planners not named yet (``planners`` completed only ``simulate``'s one name)."""
    from ..sim.planner import PLANNERS

    head, comma, last = incomplete.rpartition(",")
    named = set(head.split(",")) if comma else set()
    return [head + comma + n for n in PLANNERS if n.startswith(last) and n not in named]


def executors(incomplete: str) -> list[str]:
    from ..study.executors import EXECUTORS

    return [n for n in EXECUTORS if n.startswith(incomplete)]


def pages(incomplete: str) -> list[str]:
    """``mitos docs`` pages by name (``interop``, ``readme``)."""
    from ..resources import doc_pages

    return [n for n in doc_pages() if n.startswith(incomplete)]
