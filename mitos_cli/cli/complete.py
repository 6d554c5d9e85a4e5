"""Shell completion beyond options (``mitos --install-completion``): packaged world names and
planners. A word no packaged name starts with completes as a file, the shell's default."""

from __future__ import annotations


def worlds(incomplete: str) -> list[str]:
    """The packaged worlds by the name the commands accept (``figure4``)."""
    from ..resources import packaged_names

    names = (n.removesuffix(".yaml") for n in packaged_names("worlds", ".yaml"))
    return [n for n in names if n.startswith(incomplete)]


def planners(incomplete: str) -> list[str]:
    from ..sim.planner import PLANNERS

    return [n for n in PLANNERS if n.startswith(incomplete)]
