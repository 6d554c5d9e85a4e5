"""``pip install -e ".[bench]"`` installs everything the scripts in ``benchmarks/`` import.

Each third-party module a benchmark imports (at the top or inside a function) must come from
a distribution the ``bench`` extra names, directly or through the extras and dependencies it
pulls in, so that every figure in docs/benchmarks.md can be rerun from that one install."""

from __future__ import annotations

import ast
import re
import sys
from pathlib import Path

import pytest

tomllib = pytest.importorskip("tomllib")   # Python 3.11+; the extra is the same on 3.10

ROOT = Path(__file__).resolve().parents[1]
#: import name -> the distribution that provides it, where the two differ
DISTRIBUTION = {"fuzzylite": "pyfuzzylite", "skfuzzy": "scikit-fuzzy", "yaml": "pyyaml",
                "distributed": "dask", "PIL": "pillow"}
#: what scikit-fuzzy 0.5 imports without declaring it (it declares no dependencies)
UNDECLARED = {"scikit-fuzzy": {"scipy", "networkx"}}


def imported_modules() -> dict[str, set[str]]:
    """Top-level module -> the benchmark scripts that import it."""
    found: dict[str, set[str]] = {}
    for path in sorted((ROOT / "benchmarks").glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else \
                [node.module] if isinstance(node, ast.ImportFrom) and node.level == 0 and \
                node.module else []
            for name in names:
                found.setdefault(name.split(".")[0], set()).add(path.name)
    return found


def third_party(module: str) -> bool:
    local = {p.stem for p in (ROOT / "benchmarks").glob("*.py")}
    return module not in sys.stdlib_module_names and module not in local \
        and module != "mitos_cli"


def project_name(requirement: str) -> tuple[str, list[str]]:
    match = re.match(r"\s*([A-Za-z0-9_.-]+)\s*(?:\[([^\]]*)\])?", requirement)
    assert match, requirement
    extras = [e.strip() for e in (match.group(2) or "").split(",") if e.strip()]
    return match.group(1).lower().replace("_", "-"), extras


def bench_distributions() -> set[str]:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    extras = project["optional-dependencies"]
    names = {project_name(r)[0] for r in project["dependencies"]}
    todo, seen = ["bench"], set()
    while todo:
        extra = todo.pop()
        seen.add(extra)
        for requirement in extras[extra]:
            name, wanted = project_name(requirement)
            if name == project_name(project["name"])[0]:      # the extras it names of itself
                todo += [e for e in wanted if e not in seen]
            else:
                names.add(name)
    return names


def test_the_bench_extra_installs_every_import_of_the_benchmarks():
    provided = bench_distributions()
    missing = {}
    for module, scripts in imported_modules().items():
        if third_party(module) and DISTRIBUTION.get(module, module).lower() not in provided:
            missing[module] = sorted(scripts)
    assert not missing, f"add to the bench extra in pyproject.toml: {missing}"
    for dist, needs in UNDECLARED.items():
        assert dist in provided and needs <= provided, (dist, needs - provided)


def test_a_benchmark_names_a_missing_peer_and_how_to_install_it(monkeypatch, capsys):
    monkeypatch.syspath_prepend(str(ROOT / "benchmarks"))
    import peers

    peers.require("bench_x.py", "json")                      # present: nothing happens
    with pytest.raises(SystemExit) as exit_:
        peers.require("bench_x.py", "json", "skfuzzy_not_here", "fuzzylite_not_here")
    message = str(exit_.value.code)
    assert message.startswith("bench_x.py: the peers it is measured against are not installed")
    assert "skfuzzy_not_here, fuzzylite_not_here" in message and 'pip install -e ".[bench]"' in message


def script(name: str, monkeypatch):
    """A benchmark script imported as a module (its ``main`` is not run)."""
    monkeypatch.syspath_prepend(str(ROOT / "benchmarks"))
    import importlib

    return importlib.import_module(name)


@pytest.mark.parametrize("name, argv, said", [
    ("bench_drive", ["--barn", "-1"], "argument --barn: `-1`: must be at least 0"),
    ("bench_drive", ["--barn", "1", "--workers", "0"], "argument --workers: `0`: must be at least 1"),
    ("bench_drive", [], "nothing to run: give --barn N"),
    ("bench_sim", ["--only", "x"], "argument --only: `x`: give section numbers"),
    ("bench_sim", ["--only", "9"], "argument --only: `9`: the sections are 1 to 5"),
    ("bench_sim", ["--only", "5", "--runs", "0"], "argument --runs: `0`: must be at least 1"),
    ("bench_sim", ["--only", "2", "--against", "nosuchrev"], "unknown revision `nosuchrev`"),
    ("bench_sim", ["--only", "5,1", "--against", "HEAD"],
     "--against compares sections 2 and 4, and --only 1,5 has neither"),
    ("bench_sim", ["--only", "4", "--seconds", "x"], "argument --seconds: `x` is not a number of seconds"),
    ("bench_sim", ["--only", "4", "--seconds", "-1"], "argument --seconds: `-1`: give 0"),
    ("bench_sim", ["--only", "4", "--sizes", "16,0"], "argument --sizes: `16,0`: each batch size must be"),
    ("bench_sim", ["--only", "4", "--sizes", "16,x"], "argument --sizes: `16,x`: give batch sizes"),
    ("bench_bigmap", ["--sizes", "600"], "argument --sizes: `600`: each size from 1,700"),
    ("bench_check", ["--sizes", "20", "--against", "{tmp}/no-mitos"],
     "argument --against: `{tmp}/no-mitos` is not a command that runs"),
    ("bench_core", ["--against", "nosuchrev"], "unknown revision `nosuchrev`"),
    ("bench_core", ["--startup", "--against", "HEAD"], "--startup times this tree alone"),
    ("bench_norms", ["--quick", "--repeat", "0"], "argument --repeat: `0`: must be at least 1"),
    ("bench_compare", ["--runs", "0"], "argument --runs: `0`: must be at least 1"),
    ("bench_nav", ["--ticks-obstacles", "-5"], "`-5`: must be at least 1"),
    ("bench_nav", ["--worlds", "0"], "argument --worlds: `0`: must be at least 1"),
    ("bench_nav", ["--planners", ","], "no planner given"),
    ("bench_nav", ["--json", "{tmp}"], "cannot write `{tmp}`: it is a directory"),
    ("bench_nav", ["--rows", "{tmp}"], "cannot write `{tmp}`: it is a directory"),
    ("bench_nav", ["--json", "{tmp}/no/x.json"], "cannot write `{tmp}/no/x.json`: No such file or directory"),
    ("route_clearance", ["--json", "{tmp}"], "cannot write `{tmp}`: it is a directory"),
    ("bench_conformance", ["--quick", "--fcl-dir", "{tmp}/no"], "`{tmp}/no` is not a directory"),
    ("bench_conformance", ["--quick", "--jfuzzylogic", "{tmp}/no.jar"], "`{tmp}/no.jar` does not exist"),
    ("bench_conformance", ["--quick", "--jfuzzylogic", "{tmp}"], "give --fcl-dir DIR"),
    ("bench_teach", ["--only-fit", "--epochs", "-3"], "argument --epochs: `-3`: must be at least 1"),
    ("bench_teach", ["--only-fit", "--lesson", "{tmp}"], "`{tmp}` is a directory, not a lesson"),
    ("fuzz", ["--per-format", "-1"], "argument --per-format: `-1`: must be at least 1"),
    ("kill", ["--trials", "-1"], "argument --trials: `-1`: must be at least 1"),
    ("bench_export", ["--bogus"], "unrecognized arguments: --bogus"),
    ("bench_knowledge", ["--bogus"], "unrecognized arguments: --bogus"),
])
def test_a_wrong_option_value_is_a_usage_error_before_anything_runs(name, argv, said, tmp_path,
                                                                    monkeypatch, capsys):
    module = script(name, monkeypatch)
    monkeypatch.setattr(sys, "argv", [f"{name}.py", *(a.format(tmp=tmp_path) for a in argv)])
    with pytest.raises(SystemExit) as exit_:
        module.main()
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert said.format(tmp=tmp_path) in err and "Traceback" not in err


def test_export_and_knowledge_have_a_usage_text(monkeypatch, capsys):
    for name in ("bench_export", "bench_knowledge"):
        module = script(name, monkeypatch)
        monkeypatch.setattr(sys, "argv", [f"{name}.py", "--help"])
        with pytest.raises(SystemExit) as exit_:
            module.main()
        assert exit_.value.code == 0
        assert capsys.readouterr().out.startswith(f"usage: {name}.py [-h]")


@pytest.mark.parametrize("name, argv, said", [
    ("bench_drive", ["--barn", "1", "--rules", "old.rules"], "rule file `old.rules` not found"),
    ("bench_compare", ["--runs", "1", "--skip-dask", "--world", "nosuch.yaml"],
     "world file `nosuch.yaml` not found"),
])
def test_a_missing_file_is_said_in_one_line_not_a_traceback(name, argv, said, tmp_path,
                                                            monkeypatch, capsys):
    module = script(name, monkeypatch)
    monkeypatch.chdir(tmp_path)              # a short name: the message shortens long ones
    monkeypatch.setattr(sys, "argv", [f"{name}.py", *argv])
    assert module.main() == 1
    err = capsys.readouterr().err
    assert said in err.splitlines()[0] and "Traceback" not in err


def test_a_missing_peer_is_named_not_printed_as_nan(monkeypatch, capsys):
    import importlib.util

    for name, argv in (("bench_export", []), ("bench_conformance", ["--quick"])):
        module = script(name, monkeypatch)
        found = importlib.util.find_spec
        monkeypatch.setattr(importlib.util, "find_spec",
                            lambda m, *a, _found=found: None if m == "fuzzylite" else _found(m, *a))
        monkeypatch.setattr(sys, "argv", [f"{name}.py", *argv])
        with pytest.raises(SystemExit) as exit_:
            module.main()
        message = str(exit_.value.code)
        assert message.startswith(f"{name}.py: the peers it is measured against are not "
                                  f"installed (pyfuzzylite)")
        monkeypatch.undo()


def test_conformance_part_3_draws_each_file_s_inputs_from_a_stream_of_its_own(tmp_path,
                                                                             monkeypatch):
    """Part 3 drew every file's inputs from one stream: a file's sample, and so its figure,
    moved when the reader learned to load a file before it (docs/conformance.md)."""
    import shutil

    module = script("bench_conformance", monkeypatch)
    tipper = ROOT / "tests" / "data" / "interop" / "tipper.fis"
    debian = tmp_path / "debian"
    (debian / "b").mkdir(parents=True)
    shutil.copy(tipper, debian / "b" / "z.fis")
    monkeypatch.setattr(module, "DEBIAN", debian)
    monkeypatch.setattr(module, "OCTAVE", tmp_path / "no-octave")
    seen: dict[str, list] = {}
    monkeypatch.setattr(module, "octave_outputs",
                        lambda f, X, tmp: seen.setdefault(f.name, []).append(X.copy()))
    module.part_fis(tmp_path)
    (debian / "a").mkdir()
    shutil.copy(tipper, debian / "a" / "y.fis")           # a file before it, that loads
    module.part_fis(tmp_path)
    assert len(seen["z.fis"]) == 2 and (seen["z.fis"][0] == seen["z.fis"][1]).all()
    assert not (seen["y.fis"][0] == seen["z.fis"][0]).all()     # each file a stream of its own


def test_the_fuzz_table_has_as_many_cells_in_its_delimiter_row_as_in_its_header(monkeypatch):
    lines = script("fuzz", monkeypatch).table([]).splitlines()
    assert lines[0].count("|") == lines[1].count("|") == lines[2].count("|")


def test_an_error_from_the_other_tree_is_one_line_naming_the_revision(monkeypatch):
    revision = script("revision", monkeypatch)
    from mitos_cli.errors import MitosError

    theirs = type("RuleBaseError", (Exception,), {"__module__": "mitos_cli_rev.errors"})
    for raised, said in (
            (theirs("behavior `drive` reads input `nearest`\nexpected ..."),
             "RuleBaseError: behavior `drive` reads input `nearest`"),
            (AttributeError("module 'mitos_cli_rev.sim' has no attribute 'lockstep'"),
             "AttributeError: module 'mitos_cli_rev.sim' has no attribute 'lockstep'")):
        with pytest.raises(MitosError) as caught, revision.foreign("abc1234"):
            raise raised
        assert caught.value.message == ("revision `abc1234` cannot be measured by this "
                                        f"benchmark: {said}")
    for own in (ValueError("this tree's own"), MitosError("this tree's own")):
        with pytest.raises(type(own)) as caught, revision.foreign("abc1234"):
            raise own
        assert caught.value is own
    with pytest.raises(AttributeError), revision.foreign(None):     # no --against: unchanged
        raise AttributeError("module 'mitos_cli_rev.sim' has no attribute 'lockstep'")


def test_a_revision_whose_runs_differ_is_refused_before_any_figure(tmp_path, monkeypatch,
                                                                   capsys):
    """``--against`` times two trees on the same run: a tree whose run differs (here a
    stand-in whose last pose is an inch off) stops the section with one line, no figures."""
    sim = tmp_path / "otherrev" / "sim"
    sim.mkdir(parents=True)
    (sim.parent / "__init__.py").write_text("")
    (sim / "__init__.py").write_text("")
    (sim / "worldfile.py").write_text("from mitos_cli.sim.worldfile import load_world\n")
    (sim / "planner.py").write_text("from mitos_cli.sim.planner import FuzzyPlanner\n")
    (sim / "loop.py").write_text(
        "from mitos_cli.sim.loop import prepare, simulate as _simulate\n\n\n"
        "def simulate(*args, **kwargs):\n"
        "    res = _simulate(*args, **kwargs)\n"
        "    res.pose[-1, 0, 0] += 1.0\n"
        "    return res\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    import importlib

    bench_sim = script("bench_sim", monkeypatch)
    from mitos_cli.errors import MitosError

    with pytest.raises(MitosError) as caught:
        bench_sim.against_runs("otherrev", importlib.import_module("otherrev"), rounds=1)
    assert caught.value.message == "slalom.yaml's run differs between this tree and `otherrev`"
    assert "ticks/s" not in capsys.readouterr().out


def test_a_mean_time_to_goal_of_no_success_is_said_not_printed_as_nan(monkeypatch):
    rates = script("bench_drive", monkeypatch).rates
    line = rates([{"outcome": "collision", "time_s": 3.0}, {"outcome": "timeout", "time_s": 60.0}])
    assert "nan" not in line and line.endswith("mean time to goal   -   (no run reached it)")
    assert rates([{"outcome": "success", "time_s": 20.0}]).endswith("mean time to goal  20.0 s")


def test_section_1_of_bench_sim_runs_to_its_last_line(monkeypatch, capsys):
    """Section 1 takes the obstacle out of its corridor; the world check of 2026-12-05 refused
    the jitter left naming it, and the section stopped after its first figure."""
    bench_sim = script("bench_sim", monkeypatch)
    monkeypatch.setattr(bench_sim.time_runs, "__defaults__", (1,))
    bench_sim.single_robot(bench_sim.FuzzyPlanner(None, "drive"))
    out = capsys.readouterr().out
    assert "without the obstacle: fuzzy drive best" in out
    assert "ratio fuzzy / constant loop (no obstacle, CPU):" in out


def test_bench_knowledge_runs_every_row_to_its_last_line(monkeypatch, capsys):
    """Its hall of poles kept the corridor's jitter of `box`, which the world check of night 5
    refused: the script stopped after its first row, a traceback, for a week."""
    import dataclasses

    knowledge = script("bench_knowledge", monkeypatch)
    real = knowledge.simulate
    monkeypatch.setattr(knowledge.best_rate, "__defaults__", (1,))
    monkeypatch.setattr(knowledge, "simulate", lambda world, planner, scene: real(
        dataclasses.replace(world, time_limit=0.5), planner, scene=scene))
    knowledge.main([])
    out = capsys.readouterr().out
    for row in ("corridor.yaml (the map only", "300 unknown poles", "300 known poles",
                "detour.yaml (shut way", "detour.yaml with `given: none`", "route on office.yaml"):
        assert row in out, row


def test_a_ratio_far_below_one_keeps_its_digits_in_bench_export(monkeypatch):
    """pyfuzzylite on scalars, some 500 times slower than the engine, printed as 0.00x."""
    ratio_text = script("bench_export", monkeypatch).ratio_text
    assert ratio_text(2.2 / 1200) == "0.0018"
    assert (ratio_text(1.0), ratio_text(0.55), ratio_text(12.345)) == ("1.00", "0.55", "12.35")


def test_section_4_against_a_revision_gives_a_ratio_not_slower(tmp_path, monkeypatch, capsys):
    """Section 4 with ``--against``: the other tree's batch beside this one's, both the same
    runs; its ratio read "1.08x slower", and below 1 "0.93x slower" said the wrong way."""
    sim = tmp_path / "samerev" / "sim"
    sim.mkdir(parents=True)
    (sim.parent / "__init__.py").write_text("")
    (sim / "__init__.py").write_text("")
    for module, names in (("worldfile", "load_world"), ("planner", "FuzzyPlanner"),
                          ("loop", "prepare, simulate"), ("lockstep", "run_lockstep")):
        (sim / f"{module}.py").write_text(f"from mitos_cli.sim.{module} import {names}\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    import importlib

    bench_sim = script("bench_sim", monkeypatch)
    bench_sim.batch_sizes(bench_sim.FuzzyPlanner(None, "drive"), "samerev",
                          importlib.import_module("samerev"), seconds=0.25, sizes=[16])
    out = capsys.readouterr().out
    assert "batch    16 (16 runs):" in out and "x this tree's, same runs)" in out
    assert "slower" not in out


def test_bigmap_compares_two_trees_in_ratios_not_faster(monkeypatch):
    compared = script("bench_bigmap", monkeypatch).compared
    line = compared("abc1234", (2.0, 100.0), (1.0, 110.0))
    assert line.endswith("abc1234 / this tree: time 0.50x, peak memory 1.10x, same results")
    assert "faster" not in line and "less" not in line


@pytest.mark.parametrize("argv, said", [
    (["--drive", "fuzy", "--barn", "0"], "unknown planner `fuzy`"),
    (["--drive", "fuzzy", "--barn", "0", "--mrpb", "{tmp}/no"],
     "`--drive fuzzy` drives MRPB's tests, and MRPB 1.0's maps are not in `{tmp}/no`"),
])
def test_route_clearance_says_a_drive_it_cannot_do_before_any_route(argv, said, tmp_path,
                                                                   monkeypatch, capsys):
    """``--drive`` was met at MRPB's first test, after every world's route, as a traceback;
    without MRPB's maps it was dropped without a word."""
    module = script("route_clearance", monkeypatch)
    assert module.main([a.format(tmp=tmp_path) for a in argv]) == 1
    captured = capsys.readouterr()
    assert said.format(tmp=tmp_path) in captured.err and "Traceback" not in captured.err
    assert "routes" not in captured.out


class _Parsed(BaseException):
    """Raised in place of parsing: the script's own parser is what the test wanted."""


def benchmark_options(name: str, monkeypatch) -> set[str]:
    """The option strings the parser of ``benchmarks/{name}.py`` accepts (its ``main`` stopped
    at ``parse_args``, before anything runs)."""
    import argparse

    module = script(name, monkeypatch)
    seen: list[argparse.ArgumentParser] = []

    def parse_args(self, args=None, namespace=None):
        seen.append(self)
        raise _Parsed

    monkeypatch.setattr(argparse.ArgumentParser, "parse_args", parse_args)
    with pytest.raises(_Parsed):
        module.main([]) if "argv" in module.main.__code__.co_varnames else module.main()
    monkeypatch.undo()
    return set(seen[0]._option_string_actions)


def test_every_benchmark_command_in_the_docs_names_options_its_script_takes(monkeypatch):
    """A command a page gives (docs/*.md but the changelog's history, README.md) runs a
    script that exists, with options its parser takes: a renamed or dropped option is met
    here, not by the reader who copies the line."""
    pages = [p for p in sorted((ROOT / "docs").glob("*.md")) if p.name != "changelog.md"]
    commands = [(page.name, m.group(1), m.group(2))
                for page in [*pages, ROOT / "README.md"]
                for m in re.finditer(r"python3? benchmarks/(\w+)\.py([^`|#\n]*)",
                                     page.read_text(encoding="utf-8"))]
    assert len(commands) > 100
    options: dict[str, set[str]] = {}
    wrong = []
    for page, name, rest in commands:
        if not (ROOT / "benchmarks" / f"{name}.py").is_file():
            wrong.append(f"{page}: benchmarks/{name}.py does not exist")
            continue
        if name not in options:
            options[name] = benchmark_options(name, monkeypatch)
        wrong += [f"{page}: {name}.py {option}"
                  for option in re.findall(r"(?<!\S)--[a-z][\w-]*", rest)
                  if option not in options[name]]
    assert not wrong, wrong


def test_the_fuzz_help_gives_the_kinds_whose_count_is_a_share_of_per_format(monkeypatch,
                                                                            capsys):
    """``--per-format 20`` ran 1 lesson, 6 command lines and 28 CSVs; the help said "inputs
    per input kind" and ``--quick`` "150 per kind"."""
    fuzz = script("fuzz", monkeypatch)
    with pytest.raises(SystemExit):
        fuzz.main(["--help"])
    help_text = " ".join(capsys.readouterr().out.split())
    assert "(lessons 1/12, CLI arguments 1/3, eval --batch CSV 1.4x, teach journals 1.4x" in help_text
    assert "a short campaign (--per-format 150)" in help_text


def test_a_long_writer_refusal_is_cut_between_words_in_the_conformance_summary(monkeypatch):
    kind = script("bench_conformance", monkeypatch).refusal_kind
    cut = kind("input `x` has no terms (it only feeds linear consequents); a YAML term set "
               "needs at least one term per variable")
    assert cut == \
        "input `...` has no terms (it only feeds linear consequents); a YAML term set needs at ..."
    assert kind("term `a`: MATLAB has no `b` membership function") == \
        "term `...`: MATLAB has no `...` membership function"


@pytest.mark.parametrize("name", ["bench_conformance", "bench_export", "bench_knowledge",
                                  "bench_norms", "bench_plot", "bench_teach", "kill", "fuzz"])
def test_every_benchmark_says_a_failing_disk_in_one_line(name, monkeypatch, capsys):
    """Eight scripts' mains let an OSError out as a traceback, where the others say it in one
    line and exit 1 (``options.guarded``)."""
    import argparse

    module = script(name, monkeypatch)

    def full(self, args=None, namespace=None):
        raise OSError(28, "No space left on device", "out.csv")

    monkeypatch.setattr(argparse.ArgumentParser, "parse_args", full)
    assert module.main([]) == 1
    assert capsys.readouterr().err == "error: No space left on device: `out.csv`\n"


@pytest.mark.parametrize("argv, said", [
    (["--shipped", "--known"], "--known is for --barn N"),
    (["--shipped", "--show"], "--show is for --barn N"),
    (["--shipped", "--seed", "5"], "--seed is for --barn N"),
    (["--barn", "2", "--runs", "5"], "--runs is for --shipped"),
])
def test_bench_drive_refuses_an_option_it_would_drop(argv, said, monkeypatch, capsys):
    """`--runs` without `--shipped`, `--known`, `--show` or `--seed` without `--barn` ran as
    if not given."""
    with pytest.raises(SystemExit) as exc:
        script("bench_drive", monkeypatch).main(argv)
    assert exc.value.code == 2 and said in capsys.readouterr().err
