"""docs/api.md runs as written: every example on the page is a doctest, from the repository
root."""

from __future__ import annotations

import doctest
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_api_page_examples_run(monkeypatch):
    monkeypatch.chdir(ROOT)
    failed, tried = doctest.testfile(
        str(ROOT / "docs" / "api.md"), module_relative=False, verbose=False, report=True,
        optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert tried > 40 and failed == 0


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
    robot started at x = 770 in a corridor that ends at 600. It loads, and both robots arrive,
    as the paragraph after it says."""
    import re

    from mitos_cli.sim import load_world, simulate

    text = (ROOT / "worlds" / "README.md").read_text(encoding="utf-8")
    world = tmp_path / "annotated.yaml"
    world.write_text(re.findall(r"```yaml\n(.*?)```", text, re.S)[0], encoding="utf-8")
    assert simulate(load_world(world)).outcome == "success"



def test_every_python_block_of_the_readme_runs_as_written(monkeypatch):
    """README.md's Python blocks, each pasted as it stands (one used arrays it never made),
    from the repository root; a line whose comment shows a result (``# {'steering': ...}``)
    gives that result."""
    import re

    monkeypatch.chdir(ROOT)
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    checker, shown = doctest.OutputChecker(), 0
    for block in re.findall(r"```python\n(.*?)```", text, re.S):
        namespace: dict = {}
        exec(compile(block, "README.md", "exec"), namespace)
        for line in block.splitlines():
            code, _, comment = line.partition("#")
            if comment.strip().startswith("{"):
                got = repr(eval(code.strip(), namespace))
                assert checker.check_output(comment.strip() + "\n", got + "\n",
                                            doctest.ELLIPSIS), (line, got)
                shown += 1
    assert shown


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


def test_every_link_between_the_pages_leads_somewhere():
    """docs/navigation.md linked `[The aims](#the-aims)`, a heading no page has: every relative
    link of the README, docs/ and worlds/README.md names a file that is there and, with a
    `#fragment`, a heading of that file (GitHub's slug: lower case, punctuation dropped,
    spaces as `-`)."""
    import re

    def slugs(page: Path) -> set[str]:
        heads = re.findall(r"^#+ (.*)$", page.read_text(encoding="utf-8"), re.M)
        return {re.sub(r"[^\w\- ]", "", h.strip().lower()).replace(" ", "-") for h in heads}

    pages = [ROOT / "README.md", ROOT / "worlds" / "README.md",
             *sorted((ROOT / "docs").glob("*.md"))]
    broken = []
    for page in pages:
        text = page.read_text(encoding="utf-8")
        for target, fragment in re.findall(r"\]\(([^)#\s]*)(?:#([^)\s]+))?\)", text):
            if target.startswith(("http://", "https://", "mailto:")):
                continue
            where = page.parent / target if target else page
            if not where.exists():
                broken.append(f"{page.relative_to(ROOT)}: {target}")
            elif fragment and where.suffix == ".md" and fragment not in slugs(where):
                broken.append(f"{page.relative_to(ROOT)}: {target}#{fragment}")
    assert broken == []
