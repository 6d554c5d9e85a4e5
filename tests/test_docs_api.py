"""The pages say what the code does: their Python runs as written (docs/api.md's examples are
doctests), their `mitos` commands parse, their links lead somewhere."""

from __future__ import annotations

import doctest
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def test_worlds_readme_python_example_says_what_it_prints(monkeypatch, capsys):
    """worlds/README.md's "Driving the simulator from Python": the block runs from the
    repository root and ends the way its comment says."""
    import re

    monkeypatch.chdir(ROOT)
    text = (ROOT / "worlds" / "README.md").read_text(encoding="utf-8")
    block = next(b for b in re.findall(r"```python\n(.*?)```", text, re.S) if "Simulation(" in b)
    said = re.search(r'print\(sim\.outcome\)\s+# "(\w+)"', block)
    assert said is not None
    exec(compile(block, "worlds/README.md", "exec"), {})
    printed = capsys.readouterr().out.split()
    assert printed[-1] == said.group(1)


def test_the_architecture_page_names_every_module():
    """docs/architecture.md's table left out 17 modules (numbers.py, sim/safety.py, ...): each
    module is named there, by its path or, inside a package's row, by its name in backticks."""
    import re

    page = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    named = set(re.findall(r"`([\w/.]+)`", page)) | set(re.findall(r"`(\w+)` \(", page))
    package = ROOT / "mitos_cli"
    missing = []
    for path in sorted(package.rglob("*.py")):
        rel = path.relative_to(package)
        if path.name in ("__init__.py", "__main__.py") or path.name.endswith("_cmd.py"):
            continue
        if len(rel.parts) > 2:                  # draw/data/..., interop/export/...: the package
            continue
        if str(rel) not in named and path.stem not in named:
            missing.append(str(rel))
    assert not missing, missing


def test_worlds_readme_annotated_world_runs_as_written(tmp_path):
    """worlds/README.md's "The format, annotated", saved as a file, was refused: its second
    robot started at x = 770 in a corridor that ends at 600. It loads, and runs as the
    paragraph after it says: `robot` waits for `oncoming` at the box, which leaves room for
    one, and the cart runs into it."""
    import re

    from mitos_cli.sim import load_world, simulate

    text = (ROOT / "worlds" / "README.md").read_text(encoding="utf-8")
    world = tmp_path / "annotated.yaml"
    world.write_text(re.findall(r"```yaml\n(.*?)```", text, re.S)[0], encoding="utf-8")
    res = simulate(load_world(world))
    assert res.robot_outcomes == ("collision", "stopped")
    assert f"after {res.t[-1]:.2f} s" in text



def test_the_counts_of_the_drive_behavior_the_benchmark_pages_give_are_its_own():
    """docs/benchmarks.md and bench_sim.py described `drive` as 44 rules on 9 inputs when it
    had grown to 55 on 13: each count they state is the packaged behavior's."""
    import re

    from mitos_cli import load_rulebase
    from mitos_cli.teach.adapt import parameterise

    compiled = load_rulebase(behavior="drive").compiled
    page = (ROOT / "docs" / "benchmarks.md").read_text(encoding="utf-8")
    script = (ROOT / "benchmarks" / "bench_sim.py").read_text(encoding="utf-8")
    p = parameterise(compiled)
    said = re.search(r"perception of the (\d+) rule inputs, the `drive` behavior of\s+the "
                     r"packaged rule base \((\d+) rules", page)
    assert said and (int(said[1]), int(said[2])) == (len(compiled.inputs), len(compiled.rules))
    said = re.search(r"on the `drive` behavior, (\d+) learnable numbers, (\d+) of them free", page)
    assert said and (int(said[1]), int(said[2])) == (len(p.values), p.n_free)
    said = re.search(r"behavior ``drive``, (\d+) rules", script)
    assert said and int(said[1]) == len(compiled.rules)


def test_the_readme_counts_debians_examples_as_the_conformance_page_does():
    """The README said 66 of Debian's 78 fuzzylite files load and 13 of those that do not
    match differ between fuzzylite's versions, and so did docs/conformance.md's part 2 prose,
    while its summary table (and `bench_conformance.py` on 2026-12-08: 51 match, 17 differ,
    10 refused) had 68 loading since night 14. The three give one count."""
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    page = (ROOT / "docs" / "conformance.md").read_text(encoding="utf-8")
    said = re.search(r"(\d+) of the (\d+) example files Debian ships\s+with fuzzylite 6 to its "
                     r"binary's tables \((\d+) load; (\d+) of the other (\d+) differ", readme)
    row = re.search(r"\| 2\. Debian `fuzzylite` 6 examples .*?\| (\d+) \| \*\*(\d+)\*\* .*?\| "
                    r"\*\*(\d+)\*\* .*?\| (\d+) ", page)
    prose = re.search(r"(\d+) of the (\d+) files load .*?and (\d+)\s+of them match.*?"
                      r"Of the other (\d+), (\d+) differ from fuzzylite 6", page, re.S)
    assert said and row and prose
    matched, files, loaded, versions, other = map(int, said.groups())
    assert (files, loaded, matched) == tuple(map(int, row.groups()[:3]))
    assert files == loaded + int(row[4]) and other == loaded - matched
    assert (loaded, files, matched, other, versions) == tuple(map(int, prose.groups()))


def test_the_readmes_unmet_speed_aims_are_its_tables_figures():
    """The README's table gave night 24's 1,345 and 1,499 ticks/s and 30.64 s, and the
    paragraph under it night 23's "3.5-3.8x short": the shortfalls it states are those of the
    figures in its table (5,000 ticks/s and 20 s aimed at)."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    ticks = re.search(r"\| ([\d,]+) and ([\d,]+) ticks/s \(EPYC", text)
    runs = re.search(r"in lockstep \| ([\d.]+) s, CPU", text)
    said = re.search(r"one run at 5,000 ticks/s \(([\d.]+)-([\d.]+)x short .*?1,000 runs in 20 s "
                     r"\(([\d.]+)x over", text)
    assert ticks and runs and said
    slow, fast = sorted(float(t.replace(",", "")) for t in ticks.groups())
    assert (float(said[1]), float(said[2])) == (round(5000 / fast, 1), round(5000 / slow, 1))
    assert float(said[3]) == round(float(runs[1]) / 20, 1)
    # the batch: "not on one" core of the Xeon, where its table gives 1.00-1.08x there
    batch = re.search(r"\| ([\d.]+)x a NumPy kernel hand-written for these 27 rules \(both on "
                      r"the 2 cores; ([\d.]+)x on one core each; on the Xeon ([\d.]+)-([\d.]+)x "
                      r"and ([\d.]+)-([\d.]+)x\)", text)
    assert batch and min(map(float, batch.groups())) >= 1.0
    assert "kernel's pace (>= 1.0x) is met on both machines, on two cores and on one" in text


def test_the_animation_plots_md_times_is_the_run_it_names():
    """docs/plots.md timed `mitos simulate moving --animate run.gif` as "the whole run, 26.85
    s and 269 frames"; the run ends after 26.80 s (its ticks times `dt`, as `simulate` says
    it). The time and the frame count it gives are the run's."""
    from mitos_cli.draw.animation import frame_ticks
    from mitos_cli.sim import load_world, simulate

    page = (ROOT / "docs" / "plots.md").read_text(encoding="utf-8")
    said = re.search(r"mitos simulate (\w+) --animate\s+run\.gif` \(the whole run, ([\d.]+) s "
                     r"and (\d+) frames", page)
    assert said
    res = simulate(load_world(said[1]))
    assert f"{res.t[-1]:.2f}" == said[2]
    assert len(frame_ticks(res.ticks, res.world.dt, 10.0)) == int(said[3])


def _mitos_commands() -> dict:
    """Every command by its name after ``mitos`` (``plot terms`` for a subcommand)."""
    import typer.main

    from mitos_cli.cli.app import build_app

    group = typer.main.get_group(build_app())
    out = {}
    for name, cmd in group.commands.items():
        subs = getattr(cmd, "commands", None)
        out.update({f"{name} {s}": c for s, c in subs.items()} if subs else {name: cmd})
    return out


def _shell_blocks(text: str) -> list[str]:
    """The fenced blocks of a Markdown page that hold commands (no language, or a shell's),
    fence by fence: a regular expression from one ``` to the next paired a block's closing
    fence with the next one's opening, and read the prose between as a block."""
    blocks, lines, language = [], None, None
    for line in text.splitlines():
        if line.lstrip().startswith("```"):
            if lines is None:
                lines, language = [], line.strip()[3:].strip()
            else:
                if language in ("", "sh", "bash", "console", "shell"):
                    blocks.append("\n".join(lines))
                lines = None
        elif lines is not None:
            lines.append(line)
    return blocks


def test_every_mitos_command_the_pages_show_parses_with_its_commands_options():
    """The README's and docs' shell blocks were run by no test (only the help's examples
    were): each `mitos ...` line of them (comments, pipes and redirections cut, `...` lines
    left out) parses with its command's own options and arguments, so an option renamed or
    dropped leaves no page showing it, and each file it names under the repository is there."""
    import re
    import shlex

    commands = _mitos_commands()
    pages = [ROOT / "README.md", ROOT / "worlds" / "README.md",
             *sorted(p for p in (ROOT / "docs").glob("*.md") if p.name != "changelog.md")]
    checked, wrong = 0, []
    for page in pages:
        for block in _shell_blocks(page.read_text(encoding="utf-8")):
            for line in block.replace("\\\n", " ").splitlines():
                line = line.strip().removeprefix("$ ")
                if not line.startswith("mitos ") or "..." in line:
                    continue
                code = re.split(r"\s#\s|\s[|>]\s|\s2?>|\s<\s", line)[0]
                words = shlex.split(code)[1:]
                name = " ".join(words[:2]) if " ".join(words[:2]) in commands else words[0]
                args = words[len(name.split()):]
                try:
                    commands[name].make_context(f"mitos {name}", list(args))
                except Exception as exc:  # noqa: BLE001 - any refusal is the page's mistake
                    wrong.append(f"{page.name}: {line}: {exc}")
                wrong += [f"{page.name}: {line}: {word} is not there" for word in args
                          if word.startswith(("tests/", "rulebases/", "worlds/"))
                          and "*" not in word and not (ROOT / word).exists()]
                checked += 1
    assert checked > 40 and wrong == [], wrong


# -- every Python block of the pages runs ---------------------------------------------------
#
# The rule: every block fenced ```python (or ```py, ```pycon) of README.md and docs/*.md is
# meant to run, and runs here. A block that is not (a fragment, a sketch of an API to come)
# is fenced with a word after the language, ```python no-run, which GitHub still colours as
# Python. A page's blocks run in order in one namespace (a reader's session: docs/api.md's
# first block loads the `rb` its later ones use), in a temporary directory that holds the
# repository root's `worlds/`, `rulebases/` and `tests/` (the files the examples name; what
# they write stays there). A block of `>>>` lines is a doctest (ELLIPSIS,
# NORMALIZE_WHITESPACE); in any other, a line whose comment shows a value
# (`rb.evaluate(...)   # {'steering': 65.41..., ...}`) gives that value, and a `print(...)`
# whose comment shows what it prints (`# success 17.9 15.33`) prints that.

PAGES = [ROOT / "README.md", *sorted(p for p in (ROOT / "docs").glob("*.md"))]
PYTHON = ("python", "py", "pycon")


def fenced_blocks(text: str) -> list[tuple[int, str, str]]:
    """Each fenced block of a Markdown page: the line its fence opens on (from 1), its info
    string and its text, fence by fence (an indented fence too, as in a list)."""
    blocks, body, info, start, fence = [], [], "", 0, ""
    for number, line in enumerate(text.splitlines(), 1):
        stripped = line.strip()
        if not fence and stripped.startswith(("```", "~~~")):
            fence = stripped[:3]
            info, start, body = stripped[3:].strip(), number, []
        elif fence and stripped.startswith(fence) and not stripped[3:].strip():
            blocks.append((start, info, "\n".join(body) + "\n"))
            fence = ""
        elif fence:
            body.append(line)
    return blocks


def python_blocks(page: Path) -> list[tuple[int, str]]:
    """The blocks of ``page`` meant to run (the rule above), with their first lines."""
    return [(line, code) for line, info, code in fenced_blocks(page.read_text(encoding="utf-8"))
            if info.split()[:1] and info.split()[0].lower() in PYTHON and len(info.split()) == 1]


def _checkout_like(directory: Path) -> None:
    for name in ("worlds", "rulebases", "tests"):
        (directory / name).symlink_to(ROOT / name, target_is_directory=True)


def _python_cases() -> list:
    """Each page with Python blocks, in a directory laid out as the repository's root and, where
    its blocks name no file of the repository that `pip install` does not copy (docs/api.md's
    `tests/data/tiny.yaml`), in an empty one too, as a user who installed MITOS runs them."""
    cases = []
    for page in [p for p in PAGES if python_blocks(p)]:
        name = str(page.relative_to(ROOT))
        cases.append(pytest.param(page, "repository", id=f"{name}-repository"))
        if not any(re.search(r"[\"'](tests|benchmarks)/", code) for _, code in python_blocks(page)):
            cases.append(pytest.param(page, "elsewhere", id=f"{name}-elsewhere"))
    return cases


@pytest.mark.parametrize("page, where", _python_cases())
def test_every_python_block_of_the_pages_runs_as_written(page, where, tmp_path, monkeypatch,
                                                         capsys):
    import textwrap

    if where == "repository":
        _checkout_like(tmp_path)
    monkeypatch.chdir(tmp_path)
    name = str(page.relative_to(ROOT))
    scope: dict = {"__name__": "__docs__"}
    checker, flags = doctest.OutputChecker(), doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE
    for line, code in python_blocks(page):
        code = textwrap.dedent(code)
        where = f"{name}:{line}"
        if code.lstrip().startswith(">>>"):
            test = doctest.DocTestParser().get_doctest(code, scope, where, name, line)
            runner, report = doctest.DocTestRunner(optionflags=flags), []
            runner.run(test, out=report.append, clear_globs=False)
            assert runner.failures == 0, "".join(report)
            scope.update(test.globs)
            continue
        capsys.readouterr()
        exec(compile(code, where, "exec"), scope)
        printed = capsys.readouterr().out
        for text in code.splitlines():
            statement, _, comment = text.partition("  #")
            comment = comment.strip()
            if comment.startswith("{"):
                got = repr(eval(statement.strip(), scope))
                assert checker.check_output(comment + "\n", got + "\n", flags), (where, text, got)
            elif statement.startswith("print(") and comment:
                assert checker.check_output(comment + "\n", printed.splitlines()[-1] + "\n",
                                            flags), (where, text, printed)


def test_the_block_rule_finds_the_blocks_the_pages_hold():
    """The rule above reads the blocks it is meant to: those of the README and of the API,
    Gymnasium and teaching pages, and a block fenced ``python no-run`` is left out."""
    found = {str(p.relative_to(ROOT)): len(python_blocks(p)) for p in PAGES if python_blocks(p)}
    assert found == {"README.md": 1, "docs/api.md": 11, "docs/gym.md": 1, "docs/plots.md": 1,
                     "docs/teach.md": 1}
    page = "```python no-run\nnot run\n```\n\n  ```python\n  x = 1\n  ```\n"
    assert [(n, i) for n, i, _ in fenced_blocks(page)] == [(1, "python no-run"), (5, "python")]


def test_every_option_the_pages_name_in_their_text_exists():
    """The shell blocks' options are parsed above; the prose names many more in `code`
    (`--fidelity octave`, `--on-no-rule`, `--dialect iec`): each is an option of a `mitos`
    command or of a script in benchmarks/, or one of the other tools' the pages name."""
    import typer.main

    from mitos_cli.cli.app import build_app

    known = {"--install-completion", "--show-completion",      # Typer's, on `mitos` itself
             "--hypothesis-profile",                           # pytest with hypothesis
             "--tool"}                                         # valgrind --tool=callgrind

    def walk(command) -> None:
        for param in command.params:
            known.update(o for o in [*param.opts, *param.secondary_opts] if o.startswith("--"))
        for sub in getattr(command, "commands", {}).values():
            walk(sub)

    walk(typer.main.get_group(build_app()))
    scripts = "".join(p.read_text(encoding="utf-8") for p in (ROOT / "benchmarks").glob("*.py"))
    unknown = []
    for page in [p for p in PAGES if p.name != "changelog.md"]:
        text = page.read_text(encoding="utf-8")
        for span in re.finditer(r"`([^`\n]+)`", text):
            for option in re.findall(r"(?<![\w-])(--[a-z][a-z0-9-]*)", span.group(1)):
                if option not in known and f'"{option}"' not in scripts:
                    line = text.count("\n", 0, span.start()) + 1
                    unknown.append(f"{page.relative_to(ROOT)}:{line}: {option}")
    assert unknown == [], unknown


def test_every_script_command_the_pages_show_takes_its_options():
    """The pages' shell blocks run `python benchmarks/NAME.py --option ...` (docs/reliability.md,
    navigation.md, benchmarks.md) and `python -m mitos_cli.sim.barn ...`: those lines were
    parsed by no test (the `mitos` lines are, above, and the prose's options against every
    script at once). Each names a script that is there, and each of its options is that
    script's own (`"--option"` in its source, as argparse is given it)."""
    import shlex

    checked, wrong = 0, []
    pages = [ROOT / "README.md", *sorted(p for p in (ROOT / "docs").glob("*.md")
                                         if p.name != "changelog.md")]
    for page in pages:
        for block in _shell_blocks(page.read_text(encoding="utf-8")):
            for line in block.replace("\\\n", " ").splitlines():
                if not line.strip().startswith(("python", "nice ")):
                    continue
                words = shlex.split(re.split(r"\s#\s", line.strip())[0])
                while words and words[0] in ("nice", "-n", "19"):
                    words = words[1:]
                if len(words) < 2 or words[0] not in ("python", "python3"):
                    continue
                if words[1] == "-m" and words[2].startswith("mitos_cli."):
                    script = ROOT / (words[2].replace(".", "/") + ".py")
                elif words[1].startswith("benchmarks/"):
                    script = ROOT / words[1]
                else:                                       # -m venv, -m pytest: not ours
                    continue
                if not script.is_file():
                    wrong.append(f"{page.name}: {line.strip()}: no {script.relative_to(ROOT)}")
                    continue
                source = script.read_text(encoding="utf-8")
                wrong += [f"{page.name}: {line.strip()}: {w} is no option of {script.name}"
                          for w in words if w.startswith("--") and f'"{w}"' not in source]
                checked += 1
    assert checked > 40 and wrong == [], wrong


def test_every_module_and_name_the_pages_give_is_there():
    """The pages name the code and files a reader opens or imports
    (`mitos_cli.gym.EnvOptionError`, `mitos_cli.sim.planner.PLANNERS`,
    `mitos_cli/teach/instructions.py`, `tests/data/tiny.yaml`): each dotted name imports and
    each path is a file, so a name moved or renamed leaves no page pointing at
    nothing (docs/architecture.md's own table is held above)."""
    import importlib

    checked, missing = 0, []
    for page in [p for p in PAGES if p.name != "changelog.md"]:
        text = page.read_text(encoding="utf-8")
        for found in re.finditer(r"`(mitos_cli(?:\.\w+)+)", text):
            parts, obj, rest = found[1].split("."), None, []
            for i in range(len(parts), 0, -1):
                try:
                    obj, rest = importlib.import_module(".".join(parts[:i])), parts[i:]
                    break
                except ImportError:
                    continue
            for name in rest:
                obj = getattr(obj, name, None)
            line = text.count("\n", 0, found.start()) + 1
            if obj is None:
                missing.append(f"{page.relative_to(ROOT)}:{line}: {found[1]}")
            checked += 1
        for found in re.finditer(r"`((?:mitos_cli|grammar|rulebases|worlds|tests|benchmarks)/"
                                 r"[\w/.-]+\.\w+)`", text):
            if "*" in found[1] or "of jFuzzyLogic's" in text[found.end():found.end() + 20]:
                continue                    # a pattern; another project's file
            if not (ROOT / found[1]).is_file():
                line = text.count("\n", 0, found.start()) + 1
                missing.append(f"{page.relative_to(ROOT)}:{line}: {found[1]}")
            checked += 1
    assert checked > 50 and missing == [], missing


# -- every page's quick commands run as written, in the repository and away from it ---------
#
# A page's `mitos` lines (of its shell blocks, `\\`-continued lines joined) run in the order a
# reader meets them, each page in a directory of its own: every one that makes no picture of a
# run and drives no more than one (no `--runs`, `--live`, `--speed`, `--plot`, `--animate`,
# `teach`, `compare`; nor `--planner`: DWA takes 4 s), its `> FILE` written. A block that the
# line before it names as a file (`corridor.rules`: in docs/language.md) is that file, written
# where the commands run, as a reader saves it; a line whose comment calls a file the reader's
# own (`# in.csv: your inputs`) is not run. A comment that gives a value (`# tip = 7.0`,
# `# 7.016879 (MATLAB: 7.0169)`, `# the paper's sample run from the FLL: 65.4, 32.4`) gives
# what the command prints.
#
# "repository": in a directory laid out as the repository's root, every line exits 0.
# "elsewhere": in an empty directory, as a user who installed MITOS runs them: a line naming
# a folder of the repository that `pip install` does not copy (`tests/`, `benchmarks/`,
# `docs/`) or a pattern (`worlds/*.yaml`) exits 1, with a hint where it says why; every
# other line (the packaged worlds and rule bases go by their names and paths from anywhere)
# runs as in the repository.

SLOW_OPTIONS = ("--runs", "--live", "--speed", "--plot", "--animate", "--planner")
REPOSITORY_ONLY = ("tests/", "benchmarks/", "docs/")


def page_files(text: str) -> dict[str, str]:
    """The blocks a page introduces as files, by the name on the line before their fence."""
    lines, found = text.splitlines(), {}
    for start, _, code in fenced_blocks(text):
        before = next((t.strip() for t in reversed(lines[:start - 1]) if t.strip()), "")
        named = re.fullmatch(r"`([\w.-]+\.(?:rules|ya?ml|fcl|fis|fll|csv|lesson))`:", before)
        if named:
            found[named[1]] = code
    return found


def page_commands(text: str) -> list[tuple[str, str]]:
    """The quick `mitos` lines of a page (the rule above), each with its comment."""
    found = []
    for block in _shell_blocks(text):
        for line in block.replace("\\\n", " ").splitlines():
            line = line.strip().removeprefix("$ ")
            if not line.startswith("mitos ") or "..." in line:
                continue
            code, _, comment = line.partition(" # ")
            words = code.split()
            if words[1] in ("teach", "compare") or any(w in SLOW_OPTIONS for w in words) \
                    or "your" in comment:
                continue
            found.append((code.strip(), comment.strip()))
    return found


def _said(comment: str) -> list[str]:
    """The values a command's comment says it prints."""
    said = re.match(r"(\w+ = [-\d.]+)(?:\s|$)", comment) or re.match(r"(-?\d[\d.]*)\b", comment)
    if said:
        return [said[1]]
    listed = re.search(r": (-?\d[\d.]*(?:, -?\d[\d.]*)+)$", comment)
    return listed[1].split(", ") if listed else []


COMMAND_PAGES = [p for p in PAGES if p.name != "changelog.md" and page_commands(
    p.read_text(encoding="utf-8"))]


@pytest.mark.parametrize("where", ["repository", "elsewhere"])
@pytest.mark.parametrize("page", COMMAND_PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_pages_quick_commands_run_as_written(page, where, tmp_path, monkeypatch, capsys):
    """The README's commands were run by a test, in a directory laid out as the repository's
    root, and no other page's: docs/interop.md's `# 7.016879` and docs/language.md's
    `mitos check corridor.rules` were held by no test, and none ran away from the repository,
    where a new user runs them. `mitos eval -b drive --batch run.csv` came before any command
    had written run.csv."""
    import shlex

    from mitos_cli.cli.app import main

    text = page.read_text(encoding="utf-8")
    if where == "repository":
        _checkout_like(tmp_path)
        (tmp_path / "docs" / "img").mkdir(parents=True)     # docs/plots.md's pictures go there
    for name, body in page_files(text).items():
        (tmp_path / name).write_text(body, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("COLUMNS", "100")
    ran, failed = [], []
    for code, comment in page_commands(text):
        words, target = shlex.split(code.split(" > ")[0]), None
        if " > " in code:
            target = code.split(" > ")[1].split()[0]
        capsys.readouterr()
        try:
            main(words[1:])
            status = 0
        except SystemExit as exc:
            status = exc.code or 0
        out, err = capsys.readouterr()
        if target:
            (tmp_path / target).write_text(out, encoding="utf-8")
        ran.append(code)
        if where == "elsewhere" and any(w.startswith(REPOSITORY_ONLY) or "*" in w
                                        for w in words):
            said = "`pip install` does not copy" if "*" not in code else "matches the pattern"
            if status != 1 or (said not in err and not any(
                    w.startswith("docs/") for w in words)):       # an -o there: no such folder
                failed.append(f"{code}: exit {status}: {err.strip()[:300]}")
            continue
        if status != 0:
            failed.append(f"{code}: exit {status}: {err.strip()[:300]}")
        failed += [f"{code}: printed no `{value}`" for value in _said(comment)
                   if not re.search(rf"(?<![\w.]){re.escape(value)}(?![\d])", out)]
    assert ran and failed == [], failed


# The README's exit-code table names its usage errors by example (`--seed 1_0`, `corridor
# corridor`, `--planner fuzzy dwa`, `mitos check --rulebase x.rules`, MATLAB's `gensurf`):
# each, as written there, and a command line that makes it, which exits 2.
README_USAGE_ERRORS = [
    ("`--seed 1_0`", ["simulate", "--seed", "1_0"]),
    ("10000, not `abc` ``", ["check", "-n", "abc"]),
    ("`-b ''`", ["eval", "-b", "", "road=78"]),
    ("`--var ''`", ["plot", "terms", "--var", ""]),
    ("`--x road --x size`", ["plot", "surface", "--x", "road", "--x", "size"]),
    ("`corridor corridor`", ["simulate", "corridor", "corridor"]),
    ("`corridor corridor`", ["compare", "corridor", "corridor"]),
    ("`a.yaml ./a.yaml`", ["simulate", "a.yaml", "./a.yaml"]),
    ("`--every` without `--trace`", ["simulate", "--every", "3"]),
    ("`--on-no-rule` without `--batch`", ["eval", "--on-no-rule", "nan", "road=78"]),
    ("`--planner dwb`", ["simulate", "--planner", "dwb"]),
    ("`--require succes`", ["simulate", "--require", "succes"]),
    ("`--and prodct`", ["compare", "corridor", "--and", "prodct"]),
    ("`--to fsl`", ["convert", "rulebases/mitos.rules", "--to", "fsl"]),
    ("`--planner fuzzy dwa`", ["compare", "corridor", "--planner", "fuzzy", "dwa"]),
    ("`simulate --planner fuzzy,dwa`", ["simulate", "--planner", "fuzzy,dwa"]),
    ("`mitos check --rulebase x.rules`", ["check", "--rulebase", "x.rules"]),
    ("a CSV option of `eval` answered with `--batch`", ["eval", "--csv", "x.csv"]),
    ("`gensurf`", ["gensurf"]),
    ("`plotmf`", ["plotmf"]),
    ("`ruleview`", ["ruleview"]),
]


def test_the_readmes_usage_errors_exit_2(tmp_path, monkeypatch, capsys):
    from mitos_cli.cli.app import main

    text = (ROOT / "README.md").read_text(encoding="utf-8")
    row = next(line for line in text.splitlines() if line.startswith("| 2 | a usage error"))
    monkeypatch.chdir(tmp_path)
    (tmp_path / "a.yaml").write_text((ROOT / "worlds" / "corridor.yaml").read_text("utf-8"),
                                     encoding="utf-8")
    wrong = []
    for said, argv in README_USAGE_ERRORS:
        if said not in row:
            wrong.append(f"the README's row 2 no longer says {said}")
            continue
        try:
            main(argv)
            code = 0
        except SystemExit as exc:
            code = exc.code
        if code != 2:
            wrong.append(f"mitos {' '.join(argv)}: exit {code}: {capsys.readouterr().err[:200]}")
        capsys.readouterr()
    assert wrong == []


def test_the_command_rule_finds_the_commands_the_pages_hold():
    """The rule above runs the commands it is meant to, and reads the files and values the
    pages give."""
    found = {str(p.relative_to(ROOT)): len(page_commands(p.read_text(encoding="utf-8")))
             for p in COMMAND_PAGES}
    assert found == {"README.md": 19, "docs/interop.md": 16, "docs/language.md": 3,
                     "docs/operators.md": 1, "docs/paper.md": 2, "docs/plots.md": 2}
    language = (ROOT / "docs" / "language.md").read_text(encoding="utf-8")
    assert sorted(page_files(language)) == ["corridor.rules", "corridor.terms.yaml"]
    assert _said("tip = 7.0 (MATLAB: 7.0169)") == ["tip = 7.0"]
    assert _said("7.016879 (MATLAB: 7.0169)") == ["7.016879"]
    assert _said("the paper's sample run from the FLL: 65.4, 32.4") == ["65.4", "32.4"]
    assert _said("a CSV, as one batch") == []


# -- a shown session prints what it shows ------------------------------------------------------
#
# A block (no language, or `console`) whose first line is `$ mitos ...` shows a session: the
# command runs (as above, in a directory laid out as the repository's root) and prints the
# rest of the block, `...` standing for any text (doctest's ELLIPSIS, NORMALIZE_WHITESPACE).

def shown_sessions(page: Path) -> list[tuple[int, str, str]]:
    return [(line, code.splitlines()[0][2:], code.split("\n", 1)[1])
            for line, info, code in fenced_blocks(page.read_text(encoding="utf-8"))
            if info in ("", "console") and code.startswith("$ mitos ")]


@pytest.mark.parametrize("page, line, command, shown", [
    pytest.param(p, *s, id=f"{p.relative_to(ROOT)}:{s[0]}") for p in PAGES
    for s in shown_sessions(p)])
def test_a_shown_session_prints_what_the_page_shows(page, line, command, shown, tmp_path,
                                                    monkeypatch, capsys):
    import shlex

    from mitos_cli.cli.app import main

    _checkout_like(tmp_path)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("COLUMNS", "100")
    try:
        main(shlex.split(command)[1:])
        code = 0
    except SystemExit as exc:
        code = exc.code or 0
    out = capsys.readouterr().out
    checker = doctest.OutputChecker()
    assert code == 0 and checker.check_output(
        shown, out, doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE), \
        f"{page.relative_to(ROOT)}:{line}: {command}\n{out}"


def test_the_pages_show_sessions():
    found = {str(p.relative_to(ROOT)): len(shown_sessions(p)) for p in PAGES if shown_sessions(p)}
    assert found == {"README.md": 1, "docs/operators.md": 1}


# -- every relative link leads somewhere ----------------------------------------------------

def github_anchors(text: str) -> set[str]:
    """The ``#fragment`` GitHub gives each heading of a page (outside its code blocks): the
    heading as it reads (links as their text, no backticks or tags), lower case, everything
    but letters, digits, `_`, `-` and spaces dropped, spaces as `-`; the second heading of one
    anchor gets `-1`, the third `-2`, ..."""
    fenced = {n for start, _, code in fenced_blocks(text)
              for n in range(start, start + code.count("\n") + 2)}
    anchors, seen = set(), {}
    for number, line in enumerate(text.splitlines(), 1):
        heading = re.match(r" {0,3}#{1,6}\s+(.*?)(?:\s+#+)?\s*$", line)
        if heading is None or number in fenced:
            continue
        words = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading.group(1))
        words = re.sub(r"<[^>]+>", "", words)
        anchor = re.sub(r"[^\w\- ]", "", words.lower()).replace(" ", "-")
        n = seen.get(anchor, 0)
        seen[anchor] = n + 1
        anchors.add(anchor if n == 0 else f"{anchor}-{n}")
    return anchors


def relative_links(text: str) -> list[tuple[int, str, str]]:
    """Each link of a page outside code (blocks and `spans`) to a file or a heading: its
    line, its target (empty for the page itself) and its fragment."""
    fenced = {n for start, _, code in fenced_blocks(text)
              for n in range(start, start + code.count("\n") + 2)}
    found = []
    for number, line in enumerate(text.splitlines(), 1):
        if number in fenced:
            continue
        line = re.sub(r"`[^`]*`", "", line)
        for target, fragment in re.findall(r"\]\(<?([^)#\s>]*)(?:#([^)\s>]+))?>?"
                                           r"(?:\s+\"[^\"]*\")?\)", line):
            if not target.startswith(("http://", "https://", "mailto:")):
                found.append((number, target, fragment))
    return found


def test_github_anchors_follow_githubs_rules():
    page = ("# The aims\n## `mitos eval`: the paper's sample run\n## Speed\n## Speed\n"
            "### Speed\n```\n# not a heading\n```\n## [Links](x.md) & <b>tags</b>\n")
    assert github_anchors(page) == {"the-aims", "mitos-eval-the-papers-sample-run", "speed",
                                    "speed-1", "speed-2", "links--tags"}
    assert relative_links("[a](b.md#c) `[d](e.md)`\n```\n[f](g.md)\n```\n[h](#i)") == [
        (1, "b.md", "c"), (5, "", "i")]


def test_every_link_between_the_pages_leads_somewhere():
    """docs/navigation.md linked `[The aims](#the-aims)`, a heading no page has: every relative
    link of the README, docs/ and worlds/README.md names a file that is there and, with a
    `#fragment`, a heading of that file by GitHub's anchor rules (:func:`github_anchors`)."""
    pages = [ROOT / "README.md", ROOT / "worlds" / "README.md", *PAGES[1:]]
    broken, checked = [], 0
    for page in pages:
        for line, target, fragment in relative_links(page.read_text(encoding="utf-8")):
            where = (page.parent / target) if target else page
            checked += 1
            if not where.exists():
                broken.append(f"{page.relative_to(ROOT)}:{line}: {target}")
            elif fragment and where.suffix == ".md" and fragment not in github_anchors(
                    where.read_text(encoding="utf-8")):
                broken.append(f"{page.relative_to(ROOT)}:{line}: {target}#{fragment}")
    assert checked > 50 and broken == [], broken
