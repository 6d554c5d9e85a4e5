"""Reading and writing other fuzzy-logic formats: FCL (IEC 61131-7, jFuzzyLogic's and
fuzzylite's dialects), MATLAB ``.fis``, fuzzylite FLL, and the MITOS rule language itself.

``read_foreign(path)`` chooses the reader by extension and returns the same
:class:`~mitos_cli.lang.model.RuleBase` the rule language produces; ``write_foreign(rb, fmt)``
writes one behavior in a format. What a format can say but MITOS cannot compute is refused with
a :class:`~mitos_cli.errors.FormatError` at ``file:line`` naming the construct.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import FormatError, MitosError
from ..lang.model import RuleBase

if TYPE_CHECKING:
    from ..lang.operators import Operators

READERS = {".fcl": "fcl", ".fis": "fis", ".fll": "fll"}
FORMATS = ("fcl", "fis", "fll")


def read_foreign(path: str | Path) -> RuleBase:
    """Read an ``.fcl``, ``.fis`` or ``.fll`` file into a rule base."""
    path = Path(path)
    kind = READERS.get(path.suffix.lower())
    if kind is None:
        raise FormatError(f"`{path}`: unknown format `{path.suffix}`",
                          expected="a .fcl, .fis or .fll file")
    if kind == "fll":             # (each reader opens the file once: it may be a pipe)
        from .fll import read_fll

        return read_fll(path)
    if kind == "fis":
        from .fis import read_fis

        return read_fis(path)
    from .fcl import read_fcl

    return read_fcl(path)


#: each format by how its files begin (its first statement), and what it is called
SIGNATURES = {
    "fis": ("a MATLAB .fis file", re.compile(r"(?im)^[ \t]*(\[System\])[ \t]*\r?$")),
    "fcl": ("an FCL file", re.compile(r"(?im)^[ \t]*(FUNCTION_BLOCK)\b")),
    "fll": ("a fuzzylite FLL file", re.compile(r"(?m)^[ \t]*(Engine[ \t]*:)")),
    "rules": ("a MITOS rule file",
              re.compile(r'(?m)^[ \t]*(terms[ \t]+"|behavior[ \t]+[A-Za-z_][\w\-]*[ \t]*:)')),
    # not a rule base at all, but what a rule file's `terms` line names
    "termset": ("a YAML term set", re.compile(r"(?m)^(variables[ \t]*:)[ \t]*(?:#.*)?\r?$")),
}


#: what each reader reads
LANGUAGES = {"fis": "MATLAB .fis", "fcl": "FCL", "fll": "FLL",
             "rules": "the MITOS rule language"}


def reader_of(path: str | Path) -> str:
    """The reader :func:`mitos_cli.api.read_rulebase` chooses for ``path``: by extension,
    the rule language for any extension but .fcl, .fis and .fll."""
    return READERS.get(Path(path).suffix.lower(), "rules")


def looks_like(path: str | Path, head: int = 4096) -> tuple[str, str, int] | None:
    """The format ``path``'s first statement belongs to (``[System]``: fis; ``FUNCTION_BLOCK``:
    fcl; ``Engine:``: fll; ``terms "..."``: rules), with that statement and its line; ``None``
    when none does or the file cannot be read. Only a regular file is opened again: a named
    pipe, read already, would wait for a writer that is gone."""
    try:
        if not Path(path).is_file():
            return None
        with open(path, encoding="utf-8", errors="replace") as f:
            text = f.read(head)
    except OSError:
        return None
    found = [(m.start(), fmt, m) for fmt, (_, pattern) in SIGNATURES.items()
             if (m := pattern.search(text))]
    if not found:
        return None
    at, fmt, match = min(found, key=lambda f: f[0])
    return fmt, match.group(1).strip(), text.count("\n", 0, at) + 1


def wrong_reader_hint(path: str | Path, reader: str, command: str | None = None) -> str | None:
    """What to do when ``path``, read as ``reader``, failed and looks like another format:
    the reader goes by extension (there is no option to choose it). ``command``: a command
    that reads the rule language whatever the extension (``mitos teach``)."""
    path = Path(path)
    if reader == "rules":
        other = _not_a_rulebase(path, command)
        if other is not None:
            return other
    looks = looks_like(path)
    if looks is None or looks[0] == reader:
        return None
    fmt, statement, line = looks
    what = SIGNATURES[fmt][0]
    seen = f"`{path.name}` looks like {what} (`{statement}` on line {line})"
    if fmt == "termset":
        return (f"{seen}, not a rule base: a term set is read through the `terms` line of "
                f"its .rules file: give that file")
    named = path if path.suffix.lower() == f".{fmt}" else path.with_suffix(f".{fmt}")
    rename = "" if named == path else f"rename it to `{named.name}`, then "
    if command is not None and fmt != "rules":
        return (f"{seen}, but `{command}` reads the MITOS rule language only: {rename}convert "
                f"it with `mitos convert {named} --to rules`")
    return (f"{seen} but is read as {LANGUAGES[reader]}: the reader is chosen by the file's "
            f"extension (.fcl, .fis, .fll, anything else the rule language; no option chooses "
            f"another): rename it to `{named.name}`")


def _not_a_rulebase(path: Path, command: str | None) -> str | None:
    """What to do with a file of another of MITOS's kinds, named where a rule base goes and
    read (by its extension) as the rule language: a batch CSV (`mitos eval inputs.csv`, the
    `--batch` left out) or a lesson (`mitos teach wider-turn.lesson`, the `--lesson` left
    out). Lark's "`road` is read as a rule's label" said nothing of either."""
    suffix = path.suffix.lower()
    if suffix == ".csv":
        return (f"`{path.name}` is a CSV file, not a rule base: to evaluate each of its rows, "
                f"give it to --batch (`mitos eval [RULEBASE] --batch {path.as_posix()}`)")
    if suffix == ".lesson":
        return (f"`{path.name}` is a lesson, not a rule base: a lesson is run with --lesson "
                f"(`mitos teach [RULEBASE] --lesson {path.as_posix()}`)")
    return None


def hint_wrong_reader(exc: MitosError, path: str | Path, command: str | None = None) -> None:
    """Give ``exc``, an error in the file at ``path``, the hint of :func:`wrong_reader_hint`
    when the file looks like another format (a ``.fis`` saved as ``.txt``)."""
    if exc.span is None or exc.span.path != str(path):
        return                      # not in the file itself (its term set, a missing file)
    hint = wrong_reader_hint(path, reader_of(path) if command is None else "rules", command)
    if hint is not None:
        exc.hint = hint


def write_foreign(rb: RuleBase, fmt: str, behavior: str | None = None,
                  dialect: str | None = None) -> str:
    """One behavior of ``rb`` as ``fmt`` (``fcl``, ``fis`` or ``fll``) text; names the format
    cannot hold are written as legal ones (:func:`conversion_notes` lists them). ``dialect``:
    FCL's (:data:`.fcl.DIALECTS`; the default is fuzzylite's)."""
    from .common import legal_names

    rb, _ = legal_names(rb, fmt)
    if fmt == "fll":
        from .fll import write_fll

        return write_fll(rb, behavior)
    if fmt == "fis":
        from .fis import write_fis

        return write_fis(rb, behavior)
    if fmt == "fcl":
        from .fcl import DEFAULT_DIALECT, write_fcl

        return write_fcl(rb, behavior, dialect or DEFAULT_DIALECT)
    raise FormatError(f"unknown format `{fmt}`", expected="one of " + ", ".join(FORMATS))


def left_out(rb: RuleBase, behavior: str | None, done: str) -> str | None:
    """The note that only one behavior (and those it uses) is ``done`` (written, exported):
    ``None`` when that is all the rule base has."""
    b = rb.behavior(behavior)
    written = _used(rb, b.name)
    others = [x.name for x in rb.behaviors if x.name not in written]
    if not others:
        return None
    return (f"only behavior `{b.name}` is {done} (with the behaviors it uses); the others "
            f"({', '.join(others)}) are not: choose one with --behavior")


#: Where a sampling other than fuzzylite's midpoints takes its points, and whose rule it is.
SAMPLED_AT = {"endpoints": "evenly spaced points including both ends (MATLAB's)",
              "left": "the cells' left ends (jFuzzyLogic's)",
              "trapezoid": "evenly spaced points including both ends, the ends weighing half "
                           "(Octave's)"}


#: MATLAB's defuzzifiers that fuzzylite (FLL, FCL) defines otherwise, and what each means
MATLAB_MEANS = {"bisector": "the first sample whose running area reaches half the total",
                "som": "the maximum's sample smallest in absolute value",
                "lom": "the maximum's sample largest in absolute value"}
FUZZYLITE_MEANS = {"bisector": "the sample whose running area is closest to half the total",
                   "som": "the maximum's smallest sample", "lom": "the maximum's largest sample"}
JFUZZYLOGIC_COA = "where two running areas walking in from both ends meet"


def _defuzzifier_notes(ops: Operators, fmt: str) -> list[str]:
    """A bisector, som or lom written where the target defines it otherwise: MATLAB's into FLL
    or FCL, fuzzylite's (MITOS's own) into a .fis file."""
    if ops.inference != "mamdani":
        return []
    if ops.defuzzify == "jfuzzylogic_bisector":
        if fmt == "fcl":
            return ["FCL's `COA` is written, which jFuzzyLogic computes as this rule base does "
                    f"({JFUZZYLOGIC_COA}), but which MITOS and fuzzylite read as fuzzylite's "
                    f"bisector ({FUZZYLITE_MEANS['bisector']}): evaluate the file with "
                    f"`--fidelity jfuzzylogic` to get this rule base's numbers"]
        if fmt in ("fll", "fis"):
            means = FUZZYLITE_MEANS if fmt == "fll" else MATLAB_MEANS
            return [f"{fmt.upper() if fmt == 'fll' else 'a .fis file'} has no jFuzzyLogic "
                    f"`bisector` ({JFUZZYLOGIC_COA}): {'fuzzylite' if fmt == 'fll' else 'MATLAB'}"
                    f"'s is written ({means['bisector']}), so results move where the two differ"]
        return []
    name = ops.defuzzify.removeprefix("matlab_")
    if name not in MATLAB_MEANS:
        return []
    if fmt in ("fll", "fcl") and ops.defuzzify.startswith("matlab_"):
        return [f"{fmt.upper()} has no MATLAB `{name}` ({MATLAB_MEANS[name]}): fuzzylite's is "
                f"written ({FUZZYLITE_MEANS[name]}), so results move where the two differ"]
    if fmt == "fis" and not ops.defuzzify.startswith("matlab_"):
        return [f"a .fis file's `{name}` is MATLAB's ({MATLAB_MEANS[name]}), not this rule "
                f"base's ({FUZZYLITE_MEANS[name]}), so results move where the two differ"]
    return []


def conversion_notes(rb: RuleBase, fmt: str, behavior: str | None = None) -> list[str]:
    """What writing ``rb`` as ``fmt`` (``rules`` included) leaves out or changes; the file is
    written anyway and ``mitos convert`` prints these as warnings."""
    from ..lang.operators import of_behavior
    from .common import legal_names

    b = rb.behavior(behavior)
    left = left_out(rb, behavior, "written")
    rb, out = legal_names(rb, fmt)
    if left:
        out.append(left)
    ops = of_behavior(rb, b)
    out += _defuzzifier_notes(ops, fmt)
    if ops.inputs == "as_given" and fmt not in ("rules", "fll"):     # FLL: `lock-range: false`
        out.append(f"`inputs = as_given` is not written: {fmt.upper()} has no word for it, and "
                   f"the file is read back with inputs clamped to their universes (fuzzylite and "
                   f"jFuzzyLogic evaluate its inputs as given: `--fidelity fuzzylite` or "
                   f"`jfuzzylogic`)")
    if fmt == "fis":
        from .fis import notes

        return out + notes(rb, behavior)
    if fmt in ("fcl", "fll") and ops.inference == "mamdani" and ops.sampling != "midpoints":
        out.append(f"{fmt.upper()} Mamdani outputs are sampled at cell midpoints (fuzzylite's "
                   f"rule); this rule base samples at {SAMPLED_AT[ops.sampling]}, so results "
                   f"move by the discretisation")
    points = sampled_at(rb, behavior) if ops.inference == "mamdani" else []
    if fmt == "fcl" and ops.inference == "mamdani" and points != [1000]:
        from .common import DEFUZZIFIERS

        method = DEFUZZIFIERS.get(ops.defuzzify, ("", "", "COG"))[2]
        out.append(f"FCL has no resolution that fuzzylite 6, jFuzzyLogic and IEC 61131-7 read: "
                   f"`METHOD : {method};` is written without this rule base's "
                   f"{' and '.join(map(str, points))} points, and read as 1000 (MITOS, "
                   f"jFuzzyLogic) or 100 (fuzzylite 6)")
    return out


def sampled_at(rb: RuleBase, behavior: str | None = None) -> list[int]:
    """The resolutions a Mamdani behavior's outputs are sampled at (its own, then its outputs'
    own), each once, in that order."""
    from ..lang.model import flatten
    from ..lang.operators import of_behavior

    name = behavior or rb.default_behavior
    ops = of_behavior(rb, rb.behavior(name))
    concluded = dict.fromkeys(c.var for _, r, _ in flatten(rb, name) for c in r.consequents)
    own = [rb.variables[n].resolution for n in concluded]
    every = bool(own) and all(own)
    return list(dict.fromkeys(([] if every else [ops.resolution]) + [r for r in own if r]))





def round_trip_difference(rb: RuleBase, written: RuleBase, fmt: str,
                          behavior: str | None = None, samples: int = 2000) -> list[str]:
    """How far the outputs of ``written`` (``rb`` written as ``fmt`` and read back) lie from
    ``rb``'s, measured on ``samples`` seeded random inputs inside the universes and at the
    universes' ends and middles: one note per output that moves by more than 1e-9 of its
    range, with the largest difference and where."""
    import numpy as np

    from ..engine.compile import compile_rulebase
    from ..engine.evaluation import evaluate
    from .common import legal_names

    renamed, _ = legal_names(rb, fmt)
    before = compile_rulebase(renamed, behavior)
    after = compile_rulebase(written)
    if set(after.inputs) - set(before.inputs) or set(after.outputs) - set(before.outputs):
        return [f"the written {fmt.upper()} file has other inputs or outputs than the rule "
                f"base; its outputs were not compared"]
    rng = np.random.default_rng(np.random.SeedSequence(2024))
    lo, hi = np.array(before.universe, dtype=float).T
    k = len(before.inputs)
    # and every input at its universe's ends and middle (all combinations up to 6 inputs): a
    # term that is 1 at one point only (`trimf [0 0 0]` for a 0/1 input) no draw meets
    levels = np.stack([lo, (lo + hi) / 2, hi], axis=1)
    grid = (np.array(np.meshgrid(*levels, indexing="ij")).reshape(k, -1).T if 3 ** k <= 729
            else levels.T.copy())
    X = np.vstack([rng.uniform(lo, hi, size=(samples, k)), grid])
    on = f"{samples:,} seeded inputs and {len(grid):,} at the universes' ends and middles"
    Y0 = evaluate(before, X, detail=False, strict=False).outputs
    cols = [before.inputs.index(name) for name in after.inputs]
    Y1 = evaluate(after, X[:, cols], detail=False, strict=False).outputs
    notes = []

    def where(row: int) -> str:
        return ", ".join(f"{k}={X[row, i]:.4g}" for i, k in enumerate(before.inputs))

    for j1, name in enumerate(after.outputs):
        j0 = before.outputs.index(name)
        a, b = Y0[:, j0], Y1[:, j1]
        one_sided = np.isnan(a) != np.isnan(b)               # a default NaN against a number
        if one_sided.any():
            row = int(np.argmax(one_sided))
            notes.append(f"reading the written {fmt.upper()} back, `{name}` is {b[row]:.6g} "
                         f"where the rule base gives {a[row]:.6g}, on "
                         f"{int(one_sided.sum()):,} of {on} (first at {where(row)})")
        same = (np.isnan(a) & np.isnan(b)) | (a == b) | one_sided   # NaN = NaN, inf = inf
        with np.errstate(invalid="ignore"):                   # inf - inf, masked out
            diff = np.where(same, 0.0, np.abs(a - b))
        diff = np.where(np.isnan(diff), np.inf, diff)
        worst = int(np.argmax(diff))
        v = renamed.variables[name]
        width = v.universe[1] - v.universe[0]
        scale = width if np.isfinite(width) and width > 0 else max(1.0, float(np.nanmax(
            np.abs(a), initial=1.0)))
        if diff[worst] <= 1e-9 * scale:
            continue
        share = (f" ({100 * diff[worst] / width:.2g}% of its range)" if np.isfinite(width)
                 and np.isfinite(diff[worst]) else "")
        notes.append(f"reading the written {fmt.upper()} back, `{name}` moves by up to "
                     f"{diff[worst]:.3g}{share} on {on} (largest at {where(worst)})")
    return notes


def parse_foreign(text: str, fmt: str, path: str | None = None) -> RuleBase:
    """Read ``fmt`` (``fcl``, ``fis`` or ``fll``) text into a rule base."""
    if fmt == "fll":
        from .fll import parse_fll

        return parse_fll(text, path)
    if fmt == "fis":
        from .fis import parse_fis

        return parse_fis(text, path)
    from .fcl import parse_fcl

    return parse_fcl(text, path)


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


__all__ = ["FORMATS", "conversion_notes", "hint_wrong_reader", "looks_like", "parse_foreign", "read_foreign",
           "reader_of", "round_trip_difference", "write_foreign", "wrong_reader_hint"]
