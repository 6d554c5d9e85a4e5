"""Reading and writing other fuzzy-logic formats: FCL (IEC 61131-7, jFuzzyLogic's and
fuzzylite's dialects), MATLAB ``.fis``, fuzzylite FLL, and the MITOS rule language itself.

``read_foreign(path)`` chooses the reader by extension and returns the same
:class:`~mitos_cli.lang.model.RuleBase` the rule language produces; ``write_foreign(rb, fmt)``
writes one behavior in a format. What a format can say but MITOS cannot compute is refused with
a :class:`~mitos_cli.errors.FormatError` at ``file:line`` naming the construct.
"""

from __future__ import annotations

from pathlib import Path

from ..errors import FormatError, RuleBaseError, did_you_mean
from ..lang.model import RuleBase

READERS = {".fcl": "fcl", ".fis": "fis", ".fll": "fll"}
FORMATS = ("fcl", "fis", "fll")


def read_foreign(path: str | Path) -> RuleBase:
    """Read an ``.fcl``, ``.fis`` or ``.fll`` file into a rule base."""
    path = Path(path)
    kind = READERS.get(path.suffix.lower())
    if kind is None:
        raise FormatError(f"`{path}`: unknown format `{path.suffix}`",
                          expected="a .fcl, .fis or .fll file")
    try:
        path.open("rb").close()
    except OSError as exc:
        raise RuleBaseError(f"cannot read rule file `{path}`: {exc.strerror or exc}",
                            hint=_nearby(path)) from None
    if kind == "fll":
        from .fll import read_fll

        return read_fll(path)
    if kind == "fis":
        from .fis import read_fis

        return read_fis(path)
    from .fcl import read_fcl

    return read_fcl(path)


def _nearby(path: Path) -> str | None:
    """``did you mean`` among the rule files beside ``path``, if one is close."""
    try:
        names = [p.name for p in (path.parent if str(path.parent) else Path(".")).iterdir()
                 if p.suffix.lower() in (*READERS, ".rules")]
    except OSError:
        return None
    return did_you_mean(path.name, names)


def write_foreign(rb: RuleBase, fmt: str, behavior: str | None = None) -> str:
    """One behavior of ``rb`` as ``fmt`` (``fcl``, ``fis`` or ``fll``) text."""
    if fmt == "fll":
        from .fll import write_fll

        return write_fll(rb, behavior)
    if fmt == "fis":
        from .fis import write_fis

        return write_fis(rb, behavior)
    if fmt == "fcl":
        from .fcl import write_fcl

        return write_fcl(rb, behavior)
    raise FormatError(f"unknown format `{fmt}`", expected="one of " + ", ".join(FORMATS))


def conversion_notes(rb: RuleBase, fmt: str, behavior: str | None = None) -> list[str]:
    """What writing ``rb`` as ``fmt`` (``rules`` included) leaves out or changes; the file is
    written anyway and ``mitos convert`` prints these as warnings."""
    from ..lang.operators import resolve

    b = rb.behavior(behavior)
    out = []
    written = _used(rb, b.name)
    left_out = [x.name for x in rb.behaviors if x.name not in written]
    if left_out:
        out.append(f"only behavior `{b.name}` is written (with the behaviors it uses); the "
                   f"others ({', '.join(left_out)}) are not: choose one with --behavior")
    if fmt == "fis":
        from .fis import notes

        return out + notes(rb, behavior)
    ops = resolve(b.operators, resolve(rb.operators))
    if fmt in ("fcl", "fll") and ops.inference == "mamdani" and ops.sampling != "midpoints":
        out.append(f"{fmt.upper()} Mamdani outputs are sampled at cell midpoints (fuzzylite's "
                   f"rule); this rule base samples at {ops.sampling} (MATLAB's), so results "
                   f"move by the discretisation")
    return out


def _used(rb: RuleBase, name: str) -> set[str]:
    """``name`` and every behavior it uses, directly or through others."""
    seen: set[str] = set()
    todo = [name]
    while todo:
        current = todo.pop()
        if current not in seen:
            seen.add(current)
            todo += [u.behavior for u in rb.behavior(current).uses]
    return seen


__all__ = ["FORMATS", "conversion_notes", "read_foreign", "write_foreign"]
