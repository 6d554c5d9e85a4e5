"""jFuzzyLogic itself as the oracle for its own ``.fcl`` files (``bench_conformance.py
--fcl-dir DIR --jfuzzylogic JAR``).

Every ``.fcl`` under DIR is evaluated on a grid of inputs (each input's universe, both ends
included, so points where no rule fires are in) by MITOS and by jFuzzyLogic, and the largest
difference is given per file and output, with its cause where it is known. jFuzzyLogic runs
through ``JflGrid.java`` (MITOS's driver of its public API: many points per JVM at full
precision, a fresh FIS per point as ``-e`` does), compiled against the jar with ``javac``;
without ``javac``, each point is one ``java -jar JAR -e FILE IN...``, which prints 6 decimals.
"""

from __future__ import annotations

import ast
import itertools
import os
import re
import shutil
import subprocess
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from mitos_cli.api import read_rulebase
from mitos_cli.engine.compile import compile_rulebase
from mitos_cli.engine.evaluation import evaluate
from mitos_cli.errors import MitosError
from mitos_cli.interop.common import fidelity_settings

DRIVER = Path(__file__).with_name("JflGrid.java")
GRAMMAR_CASES = Path(__file__).resolve().parents[1] / "tests" / "test_interop_fcl_grammar.py"
#: points per file at most (a grid of k points per input, k**n <= POINTS, 3 <= k <= 21)
POINTS = 300
#: points per file without javac (a JVM per point)
POINTS_E = 27
#: a difference above this has its cause said
EXACT = 1e-9
#: the same through ``-e``, which prints 6 decimals (``%6f``): half a unit of the last one
ROUNDED = 5e-7 + 1e-12

#: Causes read in jFuzzyLogic's source for differences :func:`cause_of` does not recognise, by
#: file name
KNOWN = {
    # the grammar cases (grammar_cases)
    "09_METHOD_COA.fcl": "jFuzzyLogic's COA walks in from both ends until they meet "
        "(DefuzzifierCenterOfArea), which in a gap of zeros between two areas need not stop "
        "in its middle (3.99 where MITOS's bisector gives 4.995): --fidelity jfuzzylogic computes "
        "it so (`defuzzify = jfuzzylogic_bisector`)",
}


@dataclass
class Grid:
    """What jFuzzyLogic said for one file: its inputs (``BLOCK.VAR``, in the order a point
    gives them), their universes, one row per point (outputs by ``BLOCK.VAR``, or the message
    of what it threw), or why it did not load."""

    inputs: list[str] = field(default_factory=list)
    universe: dict[str, tuple[float, float]] = field(default_factory=dict)
    rows: list[dict[str, float] | str] = field(default_factory=list)
    load_error: str | None = None
    syntax_errors: int = 0


def parse_grid(text: str) -> Grid:
    """``JflGrid``'s output (see ``JflGrid.java``)."""
    grid = Grid()
    for line in text.splitlines():
        word, _, rest = line.partition(" ")
        if word == "load-error":
            grid.load_error = " ".join(rest.split())
        elif word == "in":
            grid.inputs = rest.split()
        elif word == "universe":
            for item in rest.split():
                name, _, span = item.rpartition("=")
                lo, _, hi = span.partition(":")
                grid.universe[name] = (float(lo), float(hi))
        elif word == "out":
            grid.rows.append({k: float(v) for k, _, v in
                              (item.rpartition("=") for item in rest.split())})
        elif word == "error":
            grid.rows.append(" ".join(rest.split()))      # Java's messages hold tabs
    return grid


def parse_eval(text: str) -> dict[str, float]:
    """``java -jar JAR -e FILE IN...``'s outputs by ``BLOCK.VAR`` (printed with 6 decimals;
    ``FUNCITON_BLOCK`` is jFuzzyLogic's spelling)."""
    block, outputs = "", {}
    for line in text.splitlines():
        if m := re.match(r"FUNC\w*_BLOCK\s+(\S+)", line):
            block = m.group(1)
        elif m := re.match(r"\s*VAR_OUTPUT\s+(\S+)\s*=\s*(\S+)", line):
            outputs[f"{block}.{m.group(1)}"] = float(m.group(2))
    return outputs


def parse_missing(text: str) -> list[str]:
    """The inputs ``-e`` asks for when given none (``Missing argument 'BLOCK.VAR'``), in its
    order."""
    return re.findall(r"Missing argument '([^']+)'", text)


def syntax_errors(stderr: str) -> int:
    """ANTLR's recovered syntax errors (``line 27:4 missing SEMICOLON at 'TERM'``)."""
    return len(re.findall(r"^line \d+:\d+ ", stderr, re.M))


class Jfl:
    """A jFuzzyLogic jar, driven by ``JflGrid`` (compiled into ``tmp``) or by ``-e``."""

    def __init__(self, jar: Path, tmp: Path):
        self.jar = jar
        self.driver: list[str] | None = None
        if shutil.which("javac"):
            classes = tmp / "jflgrid"
            classes.mkdir(exist_ok=True)
            subprocess.run(["javac", "-nowarn", "-d", str(classes), "-cp", str(jar),
                            str(DRIVER)], check=True, capture_output=True, text=True)
            self.driver = ["java", "-cp", os.pathsep.join([str(classes), str(jar)]), "JflGrid"]

    @property
    def exact(self) -> bool:
        """Whether outputs come at full precision (else ``-e``'s 6 decimals)."""
        return self.driver is not None

    @property
    def tolerance(self) -> float:
        """The largest difference that is no difference at this precision."""
        return EXACT if self.exact else ROUNDED

    def run(self, fcl: Path, points: list[list[float]]) -> Grid:
        if self.driver is None:
            return self._run_e(fcl, points)
        # a file without inputs still gets a line per point (JflGrid skips empty lines)
        stdin = "".join((" ".join(repr(float(v)) for v in p) or "-") + "\n" for p in points)
        proc = subprocess.run([*self.driver, str(fcl)], input=stdin, capture_output=True,
                              text=True, timeout=600)
        grid = parse_grid(proc.stdout)
        grid.syntax_errors = syntax_errors(proc.stderr)
        if not grid.inputs and grid.load_error is None and proc.returncode:
            grid.load_error = (proc.stderr.strip().splitlines() or ["java failed"])[-1]
        return grid

    def _e(self, fcl: Path, values: list[float]) -> subprocess.CompletedProcess:
        return subprocess.run(["java", "-jar", str(self.jar), "-noCharts", "-e", str(fcl),
                               *map(repr, values)], capture_output=True, text=True, timeout=120)

    def _run_e(self, fcl: Path, points: list[list[float]]) -> Grid:
        asked = self._e(fcl, [])
        grid = Grid(inputs=parse_missing(asked.stderr), syntax_errors=syntax_errors(asked.stderr))
        if not grid.inputs and "Exception" in asked.stderr:
            grid.load_error = next(ln for ln in asked.stderr.splitlines() if "Exception" in ln)
            return grid
        for p in points[:POINTS_E]:
            proc = self._e(fcl, p)
            outputs = parse_eval(proc.stdout)
            said = proc.stderr.splitlines()
            grid.rows.append(outputs or " ".join(next(
                (ln for ln in said if "Exception" in ln), said[-1] if said else "no output").split()))
        return grid


def grid_points(universe: list[tuple[float, float]], budget: int = POINTS) -> list[list[float]]:
    """k evenly spaced points per input, ends included, k**n <= budget (3 to 21 a side)."""
    if not universe:
        return [[]]
    k = max(3, min(21, int(round(budget ** (1 / len(universe)) + 1e-9))))
    while k > 3 and k ** len(universe) > budget:
        k -= 1
    axes = [np.linspace(lo, hi, k) for lo, hi in universe]
    rows = [list(map(float, p)) for p in itertools.product(*axes)]
    return rows[:: max(1, len(rows) // budget)][:budget]


def universes(grid: Grid, mitos: dict[str, tuple[float, float]]) -> list[tuple[float, float]]:
    """Each jFuzzyLogic input's universe: MITOS's where it reads the file (matched by the
    variable's name), else jFuzzyLogic's estimate, else [0, 1]."""
    out = []
    for name in grid.inputs:
        span = mitos.get(name.rpartition(".")[2]) or grid.universe.get(name, (0.0, 1.0))
        out.append(span if all(np.isfinite(span)) and span[0] <= span[1] else (0.0, 1.0))
    return out


def difference(ours: np.ndarray, theirs: np.ndarray) -> float:
    """Largest |difference|; NaN against NaN (no rule fired, no DEFAULT) is equal, NaN against
    a number is infinite."""
    both = (np.isnan(ours) & np.isnan(theirs)) | (ours == theirs)
    with np.errstate(invalid="ignore"):
        diff = np.abs(np.where(both, 0.0, ours - theirs))
    return float(np.where(np.isnan(diff), np.inf, diff).max(initial=0.0))


@dataclass
class Row:
    """One line of the table: a file's output (or the file, when no output is compared)."""

    file: str
    mitos: str
    jfl: str
    output: str = ""
    diff: float | None = None
    fidelity: float | None = None
    cause: str = ""


def cause_of(name: str, diff: float, fidelity: float, notes: tuple[str, ...],
             tolerance: float = EXACT) -> str:
    """Why MITOS and jFuzzyLogic differ on an output, where it is known."""
    if diff <= tolerance:
        return ""
    if fidelity <= tolerance:
        known = KNOWN.get(Path(name).name)
        return known or "sampling (1000 midpoints; jFuzzyLogic: 1000 left ends): --fidelity closes it"
    said = [n.split(": ", 1)[-1] for n in notes
            if re.search(r"ACCU|OR` before|not as a pair|singleton under", n)]
    if said:
        return "MITOS warned: " + said[0][:160]
    return KNOWN.get(Path(name).name, "not explained")


def compare_file(jfl: Jfl, path: Path, root: Path) -> list[Row]:
    """Rows for one file: its outputs' largest differences, or why nothing is compared."""
    name = str(path.relative_to(root))
    try:
        rb = read_rulebase(path)
        compiled = {b.name: compile_rulebase(rb, b.name) for b in rb.behaviors}
    except MitosError as exc:
        rb, compiled, refused = None, {}, exc.message.splitlines()[0]
    mitos_span = {n: (float(lo), float(hi)) for c in compiled.values()
                  for n, (lo, hi) in zip(c.inputs, c.universe)}
    probe = jfl.run(path, [])
    if probe.load_error:
        return [Row(name, "loads" if rb else f"refuses: {refused}",
                    f"does not load: {probe.load_error[:160]}")]
    points = grid_points(universes(probe, mitos_span), POINTS if jfl.exact else POINTS_E)
    grid = jfl.run(path, points)
    said = f"reads it ({len(points)} points" + (
        f", {grid.syntax_errors} syntax errors recovered)" if grid.syntax_errors else ")")
    thrown = [r for r in grid.rows if isinstance(r, str)]
    if thrown:
        said += f"; throws on {len(thrown)}"
    if rb is None:
        return [Row(name, f"refuses: {refused}", said + "; " + outputs_said(grid))]
    rows = list(compare_outputs(name, rb, compiled, grid, points, said, jfl.tolerance))
    return rows + [Row(name, "loads", said, key.rpartition(".")[2] if len(compiled) == 1 else key,
                       cause=f"MITOS computes no such output (no rule concludes it); "
                             f"jFuzzyLogic: {outputs_said(grid, key)}")
                   for key in extra_outputs(grid, rows)]


def outputs_said(grid: Grid, key: str | None = None) -> str:
    """jFuzzyLogic's outputs in a few words: none, NaN everywhere, or one value everywhere."""
    values = [v for r in grid.rows if isinstance(r, dict) for k, v in r.items()
              if key is None or k == key]
    if not values:
        return "no output"
    finite = [v for v in values if np.isfinite(v)]
    if not finite:
        return "NaN at every point"
    if len(set(finite)) == 1 and len(finite) == len(values):
        return f"{finite[0]:g} at every point"
    return f"numbers at {len(finite)} of {len(values)} output values"


def extra_outputs(grid: Grid, rows: list[Row]) -> list[str]:
    """jFuzzyLogic's outputs (``BLOCK.VAR``) no row compares."""
    seen = {r.output.rpartition(".")[2] for r in rows}
    keys = {k for r in grid.rows if isinstance(r, dict) for k in r}
    return sorted(k for k in keys if k.rpartition(".")[2] not in seen)


def compare_outputs(name: str, rb, compiled: dict, grid: Grid, points: list[list[float]],
                    said: str, tolerance: float):
    """Each output of each behavior against jFuzzyLogic's ``BLOCK.VAR`` of that name."""
    X_all = np.array(points, dtype=float).reshape(len(points), len(grid.inputs))
    by_var = {n.rpartition(".")[2]: i for i, n in enumerate(grid.inputs)}
    ok = [i for i, r in enumerate(grid.rows) if isinstance(r, dict)]
    for behavior, c in compiled.items():
        X = X_all[:, [by_var[n] for n in c.inputs]] if all(n in by_var for n in c.inputs) \
            else None
        if X is None:
            yield Row(name, "loads", said, cause=f"inputs of `{behavior}` not in jFuzzyLogic's")
            continue
        plain = evaluate(c, X[ok], strict=False, detail=False).outputs
        faithful = evaluate(compile_rulebase(rb, behavior, fidelity_settings(
            rb, "jfuzzylogic", behavior)), X[ok], strict=False, detail=False).outputs
        for k, out in enumerate(c.outputs):
            key = next((key for key in grid.rows[ok[0]] if key.rpartition(".")[2] == out and
                        (len(compiled) == 1 or key.startswith(behavior + "."))), None) \
                if ok else None
            if key is None:
                thrown = next((r for r in grid.rows if isinstance(r, str)), None)
                yield Row(name, "loads", said, out if len(compiled) == 1 else f"{behavior}.{out}",
                          cause=f"jFuzzyLogic throws: {thrown[:160]}" if thrown
                          else "jFuzzyLogic has no such output")
                continue
            theirs = np.array([grid.rows[i][key] for i in ok])  # type: ignore[index]
            d, f = difference(plain[:, k], theirs), difference(faithful[:, k], theirs)
            yield Row(name, "loads", said, out if len(compiled) == 1 else f"{behavior}.{out}",
                      d, f, cause_of(name, d, f, rb.notes, tolerance))


def grammar_cases(dest: Path) -> Path:
    """The construct-by-construct files of ``tests/test_interop_fcl_grammar.py`` (its BASE and
    each of its LOADS cases) written to ``dest``, the input's RANGE moved from FUZZIFY to its
    declaration, where jFuzzyLogic's grammar has it (it does not load a RANGE in FUZZIFY)."""
    tree = ast.parse(GRAMMAR_CASES.read_text(encoding="utf-8"))
    wanted = [n for n in tree.body if isinstance(n, ast.Assign) and any(
        isinstance(t, ast.Name) and t.id in ("BASE", "HIGH", "LOADS") for t in n.targets)]
    space: dict = {}
    exec(compile(ast.Module(wanted, []), str(GRAMMAR_CASES), "exec"), space)
    base = space["BASE"].replace("    a : REAL;\n", "    a : REAL; RANGE := (0 .. 10);\n") \
        .replace("FUZZIFY a\n    RANGE := (0 .. 10);\n", "FUZZIFY a\n")
    dest.mkdir(parents=True, exist_ok=True)
    (dest / "00_base.fcl").write_text(base)
    for i, (old, new) in enumerate(space["LOADS"], 1):
        name = re.sub(r"[^A-Za-z0-9]+", "_", new.strip()).strip("_")[:40]
        (dest / f"{i:02d}_{name}.fcl").write_text(base.replace(old, new, 1))
    return dest


def part_jfuzzylogic(directory: Path, jar: Path, tmp: Path) -> dict:
    jfl = Jfl(jar, tmp)
    rows = [row for path in sorted(directory.rglob("*.fcl"))
            for row in compare_file(jfl, path, directory)]
    return {"rows": rows, "exact": jfl.exact, "tolerance": jfl.tolerance}


def report(part: dict, title: str) -> None:
    rows: list[Row] = part["rows"]
    files = sorted({r.file for r in rows})
    print(f"\n## {title}: {len(files)} files, "
          + ("full precision (JflGrid)" if part["exact"] else "6 decimals (-e; no javac)"))
    print("| file | MITOS | jFuzzyLogic | output | max abs diff | with --fidelity jfuzzylogic "
          "| cause |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for r in rows:
        nums = [f"{v:.3g}" if v is not None else "" for v in (r.diff, r.fidelity)]
        print(f"| {r.file} | {r.mitos} | {r.jfl} | {r.output} | {nums[0]} | {nums[1]} "
              f"| {r.cause} |")
    compared = [r for r in rows if r.diff is not None]
    tol = part["tolerance"]
    exact = sum(1 for r in compared if r.diff <= tol)
    faithful = sum(1 for r in compared if (r.fidelity or 0) <= tol)
    print(f"  outputs compared: {len(compared)}; equal to {tol:.1g}: {exact} as MITOS reads "
          f"them, {faithful} with --fidelity jfuzzylogic")
