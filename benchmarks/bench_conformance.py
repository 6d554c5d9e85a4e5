"""Conformance benchmark: the example controllers other tools ship, read as they are.

    python benchmarks/bench_conformance.py            # everything (a few minutes)
    python benchmarks/bench_conformance.py --quick    # pyfuzzylite's examples only
    python benchmarks/bench_conformance.py --quick --fcl-dir DIR   # and every .fcl under DIR
    python benchmarks/bench_conformance.py --quick --fcl-dir DIR --jfuzzylogic JAR   # and 5.

1. pyfuzzylite's example engines (inside the installed package) through the command line,
   ``mitos eval X.fll --batch IN.csv [-b BEHAVIOR]``, against their ``.fld`` tables to 1e-6,
   rows where no rule fired (NaN) included.
2. Debian's ``fuzzylite`` examples (``/usr/share/doc/fuzzylite/examples``, comments and all):
   every ``.fis``, ``.fcl`` and ``.fll`` loads or is refused by construct; each one that
   loads is compared with the table the ``fuzzylite`` 6 binary writes for it, sampled as
   fuzzylite 6 samples (its default resolution is 100 cells, midpoints).
3. ``.fis`` files (Debian's ``octave-fuzzy-logic-toolkit`` and the fuzzylite ones): compared
   with Octave's ``evalfis`` where Octave reads them (MATLAB's semantics: 101 points
   including both ends) on 200 inputs drawn from each file's own stream (keyed on its path
   under its folder, so no file's figure moves when another one loads), and MATLAB's
   documented tipper values; each also with ``--fidelity octave`` (Octave's trapezoid centroid
   and its Sugeno join of the rules of one value by ``AggMethod``).
4. Every file that loads is converted to every other format and read back: outputs unchanged
   (1e-9 of the output's range), or the converter's warning gives the measured difference.
5. With ``--jfuzzylogic JAR`` (a jFuzzyLogic jar; needs Java): every ``.fcl`` under
   ``--fcl-dir`` evaluated on a grid of inputs by jFuzzyLogic itself and by MITOS, as MITOS
   reads it and with ``--fidelity jfuzzylogic``; the largest difference per file and output,
   with its cause where it is known (``jfl_oracle.py``); then the same on the construct-by-
   construct cases of ``tests/test_interop_fcl_grammar.py``.

Missing Debian packages are installed with ``apt-get`` when it is available (and said so);
without them parts 2 and 3 are skipped, saying why. CI does not run this.
"""

from __future__ import annotations

import argparse
import glob
import os
import re
import shutil
import subprocess
import sys
import tempfile
from collections import Counter
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import jfl_oracle  # noqa: E402
from options import directory, guarded  # noqa: E402
from peers import require  # noqa: E402

from mitos_cli.api import LoadedRuleBase, read_rulebase  # noqa: E402
from mitos_cli.engine.compile import compile_rulebase  # noqa: E402
from mitos_cli.engine.evaluation import evaluate  # noqa: E402
from mitos_cli.errors import MitosError  # noqa: E402
from mitos_cli.interop import parse_foreign, round_trip_difference, write_foreign  # noqa: E402
from mitos_cli.interop.common import fidelity_rulebase, fidelity_settings  # noqa: E402

TOLERANCE = 1e-6
DEBIAN = Path("/usr/share/doc/fuzzylite/examples")
OCTAVE = Path("/usr/share/octave/packages")
PACKAGES = {"fuzzylite": DEBIAN, "octave-fuzzy-logic-toolkit": OCTAVE}


def read_fld(path: Path) -> tuple[list[str], np.ndarray]:
    lines = [ln for ln in path.read_text().splitlines() if ln.strip()]
    return lines[0].split(), np.array([[float(v) for v in ln.split()] for ln in lines[1:]])


def worst(got: np.ndarray, ref: np.ndarray) -> float:
    """Largest |difference|, NaN = NaN (no rule fired), equal infinities equal (Tsukamoto),
    NaN against a number = inf."""
    both = (np.isnan(got) & np.isnan(ref)) | (got == ref)     # NaN = NaN, inf = inf
    with np.errstate(invalid="ignore"):                      # inf - inf
        diff = np.abs(np.where(both, 0.0, got - ref))
    return float(np.where(np.isnan(diff), np.inf, diff).max(initial=0.0))


def refusal_kind(message: str) -> str:
    """A writer's refusal with its names left out, so that refusals of one kind count
    together, at most 90 characters, cut between words (it read "a YAML term set needs at
    leas")."""
    import textwrap

    return textwrap.shorten(re.sub(r"`[^`]*`", "`...`", message), 90, placeholder=" ...")


def refusal(exc: MitosError) -> str:
    where = f"{Path(exc.span.path or '').name}:{exc.span.line}" if exc.span else "?"
    return f"{where}: {exc.message}"


# ---------------------------------------------------------------------------------------------
# 1. pyfuzzylite's examples through the CLI


def pyfuzzylite_examples() -> Path | None:
    import importlib.util

    spec = importlib.util.find_spec("fuzzylite")
    if spec is None or not spec.submodule_search_locations:
        return None
    path = Path(list(spec.submodule_search_locations)[0]) / "examples"
    return path if path.is_dir() else None


def cli_batch(fll: Path, header: list[str], table: np.ndarray, behavior: str | None,
              tmp: Path) -> dict[str, np.ndarray]:
    """``mitos eval FLL --batch CSV [-b B]`` in a subprocess: its outputs by column name."""
    csv = tmp / f"{fll.stem}-{behavior or 'main'}.csv"
    np.savetxt(csv, table, delimiter=",", header=",".join(header), comments="", fmt="%.17g")
    args = [sys.executable, "-m", "mitos_cli", "eval", str(fll), "--batch", str(csv)]
    if behavior:
        args += ["-b", behavior]
    env = {**os.environ, "PYTHONPATH": str(ROOT)}       # this checkout's MITOS, not another
    proc = subprocess.run(args, capture_output=True, text=True, cwd=tmp, env=env)
    if proc.returncode != 0:
        raise RuntimeError(proc.stderr.strip().splitlines()[-1] if proc.stderr else "failed")
    lines = proc.stdout.splitlines()
    names = lines[0].split(",")
    rows = np.array([[float(c) for c in ln.split(",")] for ln in lines[1:]], dtype=float)
    return {n: rows[:, i] for i, n in enumerate(names)}


def part_pyfuzzylite(examples: Path, tmp: Path) -> dict:
    files = sorted(p for p in examples.rglob("*.fll"))
    rows = []

    def one(fll: Path):
        name = str(fll.relative_to(examples))
        try:
            rb = read_rulebase(fll)
        except MitosError as exc:
            return name, "refused", refusal(exc), None
        header, table = read_fld(fll.with_suffix(".fld"))
        inputs = [v.name for v in rb.variables.values() if v.role == "input"]
        cols = [header.index(n) for n in inputs]
        error = 0.0
        try:
            for b in rb.behaviors:
                got = cli_batch(fll, inputs, table[:, cols],
                                b.name if len(rb.behaviors) > 1 else None, tmp)
                for out, values in got.items():
                    if out in header and out not in inputs:
                        error = max(error, worst(values, table[:, header.index(out)]))
        except RuntimeError as exc:
            return name, "cli error", str(exc), None
        return name, "match" if error <= TOLERANCE else "differs", "", error

    with ThreadPoolExecutor(2) as pool:
        rows = list(pool.map(one, files))
    return {"files": len(files), "rows": rows}


# ---------------------------------------------------------------------------------------------
# 2. Debian's fuzzylite examples against the fuzzylite 6 binary


def ensure_packages() -> list[str]:
    """Install the Debian packages this needs when they are missing; what is still missing."""
    missing = [p for p, where in PACKAGES.items() if not where.exists()]
    if missing and shutil.which("apt-get"):
        print(f"installing {', '.join(missing)} with apt-get (needed for parts 2 and 3)")
        subprocess.run(["apt-get", "install", "-y", "-q", *missing], capture_output=True)
    return [p for p, where in PACKAGES.items() if not where.exists()]


def fuzzylite6_table(path: Path, tmp: Path) -> tuple[list[str], np.ndarray] | None:
    out = tmp / (path.stem + "-" + path.suffix[1:] + ".fld")
    proc = subprocess.run(["fuzzylite", "-i", str(path), "-if", path.suffix[1:], "-o", str(out),
                           "-of", "fld", "-values", "1024", "-scope", "AllVariables",
                           "-dheader", "true", "-dinputs", "true", "-decimals", "9"],
                          capture_output=True, text=True)
    if proc.returncode != 0 or not out.exists() or out.stat().st_size == 0:
        return None
    return read_fld(out)


def plain(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_]", "", name)


def part_debian(tmp: Path) -> dict:
    files = sorted(p for ext in ("fis", "fcl", "fll") for p in DEBIAN.rglob(f"*.{ext}"))
    rows = []
    for path in files:
        name = str(path.relative_to(DEBIAN))
        try:
            rb = read_rulebase(path)
        except MitosError as exc:
            rows.append((name, "refused", refusal(exc), None))
            continue
        ref = fuzzylite6_table(path, tmp)
        if ref is None:
            rows.append((name, "loaded", "the fuzzylite binary writes no table for it", None))
            continue
        header, table = ref
        col = {plain(h): i for i, h in enumerate(header)}     # fuzzylite drops `-` from names
        error, defaulted = 0.0, 0
        for b in rb.behaviors:
            c = LoadedRuleBase(rb, b.name, fidelity_settings(rb, "fuzzylite6", b.name)).compiled
            X = table[:, [col[plain(n)] for n in c.inputs]]
            Y = evaluate(c, X, strict=False, detail=False).outputs
            for j, out in enumerate(c.outputs):
                if plain(out) not in col:
                    continue
                ref_j = table[:, col[plain(out)]]
                if path.suffix == ".fis":     # no rule fired: MATLAB's mid-range, not NaN
                    mid = np.isnan(ref_j) & (Y[:, j] == c.default[j])
                    defaulted += int(mid.sum())
                    ref_j = np.where(mid, Y[:, j], ref_j)
                error = max(error, worst(Y[:, j], ref_j))
        why = (f"{defaulted} rows where no rule fires give MATLAB's mid-range default "
               f"(fuzzylite: NaN)") if defaulted else ""
        rows.append((name, "match" if error <= TOLERANCE else "differs", why, error))
    return {"files": len(files), "rows": rows}


# ---------------------------------------------------------------------------------------------
# 3. .fis files against Octave's evalfis (MATLAB's semantics) and MATLAB's tipper

OCTAVE_SCRIPT = """
pkg load fuzzy-logic-toolkit;
fis = readfis('{fis}');
X = dlmread('{inputs}', ',');
Y = evalfis(X, fis);
dlmwrite('{outputs}', Y, 'precision', '%.12g');
"""


def octave_outputs(fis: Path, X: np.ndarray, tmp: Path) -> np.ndarray | None:
    if not shutil.which("octave-cli"):
        return None
    inputs, outputs = tmp / (fis.stem + "-in.csv"), tmp / (fis.stem + "-oct.csv")
    np.savetxt(inputs, X, delimiter=",", fmt="%.17g")
    outputs.unlink(missing_ok=True)
    script = OCTAVE_SCRIPT.format(fis=fis, inputs=inputs, outputs=outputs)
    subprocess.run(["octave-cli", "--no-gui", "-q", "--eval", script], capture_output=True,
                   text=True, timeout=300)
    if not outputs.exists():
        return None
    return np.loadtxt(outputs, delimiter=",", ndmin=2)


def file_rng(path: Path, root: Path) -> np.random.Generator:
    """A stream of its own for each file, keyed on its path under its root, so one file's
    inputs do not move when the reader learns to load another file before it."""
    return np.random.default_rng(np.random.SeedSequence([7, *path.relative_to(root).as_posix()
                                                          .encode()]))


def part_fis(tmp: Path) -> dict:
    files = [(Path(f), Path(f).parent)        # the toolkit's folder: its version is not the key
             for f in sorted(glob.glob(str(OCTAVE / "fuzzy-logic-toolkit*" / "*.fis")))]
    files += [(p, DEBIAN) for p in sorted(DEBIAN.rglob("*.fis"))]
    rows = []
    for f, root in files:
        name = f"{f.parent.name}/{f.name}" if root != DEBIAN else str(f.relative_to(DEBIAN))
        rng = file_rng(f, root)
        try:
            rb = read_rulebase(f)
        except MitosError as exc:
            rows.append((name, "refused", refusal(exc), None))
            continue
        c = compile_rulebase(rb)
        lo, hi = np.array(c.universe, dtype=float).T
        X = rng.uniform(lo, hi, size=(200, len(c.inputs)))
        order = [v.name for v in rb.variables.values() if v.role == "input"]
        X_file = X[:, [c.inputs.index(n) if n in c.inputs else 0 for n in order]]
        theirs = octave_outputs(f, X_file, tmp)
        if theirs is None:
            rows.append((name, "loaded", "Octave's readfis/evalfis cannot read it", None))
            continue
        outs = [v.name for v in rb.variables.values() if v.role == "output"]
        octave = LoadedRuleBase(fidelity_rulebase(rb, "octave"), None,
                                fidelity_settings(rb, "octave")).compiled
        error, error_octave = (max(worst(Y[:, c.outputs.index(o)], theirs[:, k])
                                   for k, o in enumerate(outs) if o in c.outputs)
                               for Y in (evaluate(cc, X, strict=False, detail=False).outputs
                                         for cc in (c, octave)))
        rows.append((name, "match" if error <= TOLERANCE else "differs",
                     f"with --fidelity octave: {error_octave:.2g}", error))
    tipper = read_rulebase(ROOT / "tests" / "data" / "interop" / "tipper.fis")
    documented = [((2, 1), 7.0169), ((4, 5), 14.4585), ((7, 8), 20.3414)]
    got = evaluate(compile_rulebase(tipper), np.array([x for x, _ in documented], float)
                   ).outputs[:, 0]
    return {"files": len(files), "rows": rows, "tipper": got.tolist(),
            "tipper_ok": bool(np.all(np.abs(got - [y for _, y in documented]) < 5e-5))}


# ---------------------------------------------------------------------------------------------
# 4. Round trips


def round_trips(paths: list[Path], tmp: Path) -> dict:
    counts: Counter = Counter()
    largest: dict[str, tuple[float, str]] = {}
    refusals: Counter = Counter()
    for path in paths:
        try:
            rb = read_rulebase(path)
        except MitosError:
            continue
        for behavior in [b.name for b in rb.behaviors]:
            for fmt in ("fcl", "fis", "fll", "rules"):
                if fmt == path.suffix[1:]:
                    continue
                try:
                    if fmt == "rules":
                        from mitos_cli.interop.rules_writer import write_rules

                        rules, terms = write_rules(rb, "rt.terms.yaml", behavior)
                        (tmp / "rt.rules").write_text(rules)
                        (tmp / "rt.terms.yaml").write_text(terms)
                        back = read_rulebase(tmp / "rt.rules")
                    else:
                        back = parse_foreign(write_foreign(rb, fmt, behavior), fmt, "rt." + fmt)
                except MitosError as exc:
                    counts[(fmt, "refused by the writer")] += 1
                    refusals[refusal_kind(exc.message)] += 1
                    continue
                notes = round_trip_difference(rb, back, fmt, behavior)
                if not notes:
                    counts[(fmt, "unchanged")] += 1
                    continue
                counts[(fmt, "warned")] += 1
                for note in notes:
                    m = re.search(r"moves by up to (\S+) \(([\d.e+-]+)% of its range\)", note)
                    if m is None:       # a value where the other gives nan (no rule fires):
                        counts[(fmt, "no rule")] += 1   # no percentage to rank
                        continue
                    pct = float(m.group(2))
                    if pct > largest.get(fmt, (-1.0, ""))[0]:
                        largest[fmt] = (pct, f"{path.name} [{behavior}]")
    return {"counts": counts, "largest": largest, "refusals": refusals}


# ---------------------------------------------------------------------------------------------


def part_fcl_dir(directory: Path) -> dict:
    """Every ``.fcl`` under ``directory`` (e.g. a jFuzzyLogic checkout): it loads, or the
    refusal names its construct (an "unexpected" token would be a reader's gap, not a refusal)."""
    files = sorted(directory.rglob("*.fcl"))
    rows = []
    for path in files:
        name = str(path.relative_to(directory))
        try:
            compile_rulebase(read_rulebase(path))
        except MitosError as exc:
            rows.append((name, "refused", refusal(exc), None))
            continue
        rows.append((name, "loaded", "", None))
    return {"files": len(files), "rows": rows}


def report_rows(title: str, part: dict) -> None:
    status = Counter(s for _, s, _, _ in part["rows"])
    print(f"\n## {title}: {part['files']} files")
    for key in ("match", "differs", "loaded", "refused", "cli error"):
        if status[key]:
            print(f"  {key:10s} {status[key]}")
    for name, s, why, error in part["rows"]:
        if s == "differs":
            print(f"  differs  {name}: largest difference {error:.3g}"
                  + (f" ({why})" if why else ""))
        elif s == "match" and why and not why.startswith("with --fidelity"):
            print(f"  match    {name} ({why})")
        elif s in ("refused", "loaded", "cli error") and why:
            print(f"  {s:8s} {name}: {why}")
    errors = [e for _, s, _, e in part["rows"] if s == "match"]
    if errors:
        print(f"  largest difference among the matching: {max(errors):.2g}")
    octave = [float(why.rsplit(" ", 1)[1]) for _, s, why, _ in part["rows"]
              if s in ("match", "differs") and why.startswith("with --fidelity octave")]
    if octave:
        print(f"  with --fidelity octave: {sum(e <= TOLERANCE for e in octave)} of "
              f"{len(octave)} match (largest difference {max(octave):.2g})")


def jar(text: str) -> Path:
    """A jFuzzyLogic jar (or a directory of its classes) that exists."""
    path = Path(text)
    if not path.exists():
        raise argparse.ArgumentTypeError(f"`{text}` does not exist")
    return path


@guarded
def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="pyfuzzylite's examples only")
    parser.add_argument("--fcl-dir", type=directory, metavar="DIR",
                        help="also read every .fcl under DIR (e.g. a jFuzzyLogic checkout)")
    parser.add_argument("--jfuzzylogic", type=jar, metavar="JAR",
                        help="compare every .fcl under --fcl-dir with this jFuzzyLogic jar's "
                             "outputs (needs java; javac for full precision)")
    args = parser.parse_args(argv)
    if args.jfuzzylogic and not args.fcl_dir:
        parser.error("--jfuzzylogic compares the files of --fcl-dir: give --fcl-dir DIR")
    if args.jfuzzylogic and not shutil.which("java"):
        sys.exit("bench_conformance.py: --jfuzzylogic runs the jar with `java`, which is not "
                 "on the PATH")
    all_files: list[Path] = []
    examples = pyfuzzylite_examples()
    if examples is None and args.quick and not args.fcl_dir:    # --quick: part 1 alone
        require("bench_conformance.py", "fuzzylite")
        sys.exit("bench_conformance.py: pyfuzzylite's examples are not in its package: "
                 "--quick has nothing to measure")
    tmp = Path(tempfile.mkdtemp(prefix="mitos-conformance-"))
    if examples is None:
        print("pyfuzzylite is not installed (pip install -e \".[bench]\"): part 1 skipped")
    else:
        part = part_pyfuzzylite(examples, tmp)
        report_rows("1. pyfuzzylite examples through `mitos eval --batch`", part)
        all_files += sorted(examples.rglob("*.fll"))
    if not args.quick:
        missing = ensure_packages()
        if "fuzzylite" in missing or not shutil.which("fuzzylite"):
            print("\nDebian's fuzzylite is not installed: part 2 skipped")
        else:
            report_rows("2. Debian fuzzylite examples against the fuzzylite 6 binary",
                        part_debian(tmp))
            all_files += sorted(p for e in ("fis", "fcl", "fll") for p in DEBIAN.rglob(f"*.{e}"))
        if "octave-fuzzy-logic-toolkit" in missing:
            print("\nDebian's octave-fuzzy-logic-toolkit is not installed: part 3 skipped")
        else:
            part = part_fis(tmp)
            report_rows("3. .fis files against Octave's evalfis", part)
            print(f"  MATLAB's documented tipper (7.0169, 14.4585, 20.3414): "
                  f"{', '.join(f'{y:.4f}' for y in part['tipper'])} "
                  f"({'matches' if part['tipper_ok'] else 'DIFFERS'})")
            all_files += sorted(map(Path, glob.glob(str(OCTAVE / "fuzzy-logic-toolkit*" /
                                                         "*.fis"))))
    if args.fcl_dir:
        part = part_fcl_dir(args.fcl_dir)
        report_rows(f"5. FCL files under {args.fcl_dir} (--fcl-dir; round trips in 4)", part)
        unexpected = [n for n, s, why, _ in part["rows"] if "unexpected" in why]
        print(f"  refused without naming a construct: {len(unexpected)}"
              + (f" ({', '.join(unexpected)})" if unexpected else ""))
        all_files += sorted(args.fcl_dir.rglob("*.fcl"))
        if args.jfuzzylogic:
            jfl_oracle.report(jfl_oracle.part_jfuzzylogic(args.fcl_dir, args.jfuzzylogic, tmp),
                              f"5a. jFuzzyLogic itself on {args.fcl_dir}")
            cases = jfl_oracle.grammar_cases(tmp / "grammar")
            jfl_oracle.report(jfl_oracle.part_jfuzzylogic(cases, args.jfuzzylogic, tmp),
                              "5b. jFuzzyLogic itself on tests/test_interop_fcl_grammar.py's cases")
    rt = round_trips(all_files, tmp)
    print("\n## 4. Round trips of every file that loads (each behavior, each other format)")
    for fmt in ("fcl", "fis", "fll", "rules"):
        c = {k[1]: v for k, v in rt["counts"].items() if k[0] == fmt}
        big = rt["largest"].get(fmt)
        extra = f"; largest warned difference {big[0]:.2g}% of the range ({big[1]})" if big \
            else ""
        if c.get("no rule"):
            extra += (f"; {c['no rule']} where no rule fires, a value on one side and nan on "
                      "the other (MATLAB's middle of the range)")
        print(f"  to {fmt:5s}: {c.get('unchanged', 0)} unchanged, {c.get('warned', 0)} warned "
              f"with the measured difference, {c.get('refused by the writer', 0)} refused by "
              f"the writer{extra}")
    for why, n in rt["refusals"].most_common(8):
        print(f"    writer refusal x{n}: {why}")
    shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    os.environ.setdefault("NO_COLOR", "1")
    sys.exit(main())
