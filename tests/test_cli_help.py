"""Every command's ``--help``: examples that parse with the command's own options and name
files that exist, the exit codes, one meaning per short option, and shell completion."""

from __future__ import annotations

import os
import shlex
import subprocess
import sys
from pathlib import Path

import pytest
import typer.main

from mitos_cli.cli.app import COMMANDS, build_app
from mitos_cli.cli.help import EXAMPLES, exit_codes

ROOT = Path(__file__).resolve().parent.parent


def commands() -> dict:
    """Every command by its name after ``mitos`` (``plot terms`` for a subcommand)."""
    group = typer.main.get_group(build_app())
    out = {}
    for name, cmd in group.commands.items():
        if hasattr(cmd, "commands"):           # a group (Typer's own Click)
            out.update({f"{name} {sub}": c for sub, c in cmd.commands.items()})
        else:
            out[name] = cmd
    return out


def test_every_command_has_examples_and_exit_codes():
    every = commands()
    assert set(every) == set(EXAMPLES)
    assert {name.split()[0] for name in every} == set(COMMANDS)
    for name, cmd in every.items():
        assert "Examples:" in cmd.epilog and "Exit codes:" in cmd.epilog, name
        assert [c for c, _ in exit_codes(name)][:3] == [0, 1, 2]


def test_a_group_s_help_ends_with_its_commands_examples_and_exit_codes():
    """`mitos plot --help` listed its three commands and ended there, where the README says
    every `mitos COMMAND --help` ends with examples and the exit codes."""
    from mitos_cli.cli.help import epilog

    group = typer.main.get_group(build_app())
    groups = {name: cmd for name, cmd in group.commands.items() if hasattr(cmd, "commands")}
    assert sorted(groups) == ["plot"]
    for name, cmd in groups.items():
        assert cmd.epilog == epilog(name)
        for sub in cmd.commands:                    # the first example of each subcommand
            assert f"  {EXAMPLES[f'{name} {sub}'][0][0]}" in cmd.epilog.splitlines()
        assert max(len(line) for line in cmd.epilog.splitlines()) <= 76
    env = {**os.environ, "COLUMNS": "100", "PYTHONPATH": str(ROOT)}
    out = subprocess.run([sys.executable, "-m", "mitos_cli", "plot", "--help"],
                         capture_output=True, text=True, env=env, cwd=ROOT).stdout
    assert "mitos plot surface steering --x road --y position --fix size=45 -o s.png" in out
    assert "2    a usage error" in out


@pytest.mark.parametrize("name", sorted(EXAMPLES))
def test_examples_parse_and_name_files_that_exist(name):
    cmd = commands()[name]
    for line, _ in EXAMPLES[name]:
        words = shlex.split(line.split(">")[0])
        assert words[:1 + name.count(" ") + 1] == ["mitos", *name.split()], line
        args = words[1 + name.count(" ") + 1:]
        cmd.make_context(f"mitos {name}", list(args))          # a usage error raises here
        for word in args:
            if "/" in word and not word.startswith("-") and "=" not in word:
                assert (ROOT / word).exists(), f"{line}: {word} does not exist"


#: Options whose value is a file an example writes, not one it reads.
WRITES = {"-o", "--out", "--output", "--save-as", "--plot", "--animate"}


@pytest.mark.parametrize("name", sorted(EXAMPLES))
def test_examples_read_only_files_of_the_repository(name):
    """`mitos eval --batch inputs.csv` ran from the repository root only to say that
    `inputs.csv` was not found: a file named without a directory was never checked."""
    for line, _ in EXAMPLES[name]:
        words = shlex.split(line.split(">")[0])
        for before, word in zip(words, words[1:]):
            if before in WRITES or word.startswith("-") or "=" in word:
                continue
            if Path(word).suffix:
                assert (ROOT / word).exists(), f"{line}: {word} does not exist"


def test_compare_examples_run_one_after_another():
    """Run in their order, the second was refused ("study/results.csv already holds 120
    results"): the first had made its study in the same directory."""
    fresh = [shlex.split(line) for line, _ in EXAMPLES["compare"] if "--resume" not in line]
    outs = [words[words.index("-o") + 1] for words in fresh]
    assert len(set(outs)) == len(outs), outs


def test_help_ends_with_the_examples_and_exit_codes():
    env = {**os.environ, "COLUMNS": "120", "PYTHONPATH": str(ROOT)}
    out = subprocess.run([sys.executable, "-m", "mitos_cli", "simulate", "--help"],
                         capture_output=True, text=True, env=env, cwd=ROOT).stdout
    assert "mitos simulate slalom --live --speed 4" in out
    assert "130  Ctrl-C: with --runs, the runs that finished are still reported" in out


def test_a_short_option_means_one_thing_in_every_command():
    meaning: dict[str, set[str]] = {}
    for cmd in commands().values():
        for param in cmd.params:
            if param.param_type_name != "option" or param.hidden:
                continue
            longs = [o for o in param.opts if o.startswith("--")]
            for short in (o for o in param.opts if not o.startswith("--")):
                meaning.setdefault(short, set()).update(longs)
    clashes = {s: m for s, m in meaning.items() if len(m) > 1}
    assert clashes == {"-o": {"--out", "--output", "--save-as"}}   # -o: where it writes
    assert meaning["-n"] == {"--resolution"} and meaning["-j"] == {"--workers"}
    assert meaning["-r"] == {"--rulebase"} and meaning["-b"] == {"--behavior"}


def test_every_option_that_takes_a_value_names_it_in_words():
    """The help showed Click's type names for 27 options (`--behavior <str>`, `--seed <int
    range> [x>=0]`, `--fps <float range>`): each now names what it takes (NAME, N, SEED, DOF,
    ...), as the options with a metavar did (`--out FILE.csv`)."""
    bare = []
    for name, cmd in commands().items():
        for param in cmd.params:
            if param.param_type_name != "option" or param.is_flag or param.hidden:
                continue
            if param.metavar is None:
                bare.append(f"{name} {param.opts[0]}")
    assert bare == []
    help_text = subprocess.run([sys.executable, "-m", "mitos_cli", "simulate", "--help"],
                               capture_output=True, text=True,
                               env={**os.environ, "COLUMNS": "200"}).stdout
    assert "--seed               SEED [x>=0]" in help_text
    assert "<int range>" not in help_text and "<float range>" not in help_text


def test_no_option_value_is_wider_than_its_help_column_leaves_it():
    """`eval --fidelity [matlab|jfuzzylogic|fuzzylite|fuzzylite6|octave]` (48 characters)
    was split mid-word by the help's table at 80 and 120 columns (`fuzzyl ite6`, `octav e`):
    every option's value is a word short enough to stay whole, and where it names choices
    the help lists them."""
    wide = [f"{name} {p.opts[0]} {p.metavar}" for name, cmd in commands().items()
            for p in cmd.params if p.param_type_name == "option"
            and len(getattr(p, "metavar", None) or "") > 24]
    assert wide == []
    help_text = subprocess.run([sys.executable, "-m", "mitos_cli", "eval", "--help"],
                               capture_output=True, text=True,
                               env={**os.environ, "COLUMNS": "80"}).stdout
    assert "ENGINE: matlab, jfuzzylogic, fuzzylite, fuzzylite6, octave" in " ".join(
        line.strip("│ ") for line in help_text.splitlines())


def test_every_choice_an_option_lists_is_said_in_its_help():
    """`eval --fidelity [matlab|jfuzzylogic|fuzzylite|fuzzylite6|octave]` said what four of
    its five engines do and nothing of `octave`: an option whose metavar lists its choices
    names each of them in its help."""
    import re

    unsaid = []
    for name, cmd in commands().items():
        for param in cmd.params:
            metavar = getattr(param, "metavar", None) or ""
            if param.param_type_name != "option" or not re.fullmatch(r"\[[\w|]+\]", metavar):
                continue
            for value in metavar[1:-1].split("|"):
                if not re.search(rf"\b{value}\b", param.help or ""):
                    unsaid.append(f"{name} {param.opts[0]} {value}")
    assert unsaid == []


def test_an_option_whose_value_is_a_list_says_it_is_comma_separated():
    """`compare --planner` said "Planners to compare: fuzzy, potential_field, dwa." and not
    how to give several (`--planner fuzzy dwa` read `dwa` as a world): every option whose
    value `compare` splits at commas (`split_list`) says "comma-separated"."""
    import ast

    from mitos_cli.cli import compare_cmd

    tree = ast.parse(Path(compare_cmd.__file__).read_text(encoding="utf-8"))
    split = {arg.id for node in ast.walk(tree) if isinstance(node, ast.Call)
             and getattr(node.func, "id", None) == "split_list"
             for arg in node.args if isinstance(arg, ast.Name)}
    params = {p.name: p for p in commands()["compare"].params}
    lists = split & set(params)
    assert lists == {"and_", "or_", "inference", "planner"}
    unsaid = [params[n].opts[0] for n in sorted(lists) if "comma-separated" not in params[n].help]
    assert unsaid == []


def test_simulate_given_compare_s_list_of_planners_names_compare(capsys):
    """`simulate --planner fuzzy,dwa` was "unknown planner `fuzzy,dwa`", did you mean
    `fuzzy`?": simulate drives with one, and compare takes the list."""
    from mitos_cli.cli.app import main

    with pytest.raises(SystemExit) as info:
        main(["simulate", "--planner", "fuzzy,DWA"])
    err = " ".join(capsys.readouterr().err.replace("│", " ").split())
    assert info.value.code == 2
    assert ("Invalid value for --planner: simulate drives with one planner (--planner NAME); "
            "`mitos compare --planner fuzzy,dwa` compares them") in err


def test_an_option_mitos_list_names_says_it_takes_a_packaged_name():
    """`mitos list` heads its rule bases `(--rulebase NAME)` and its lessons `(mitos teach
    --lesson NAME)`, and both options take such a name, but their help said only `PATH`,
    "Rule base", and "a lesson file"."""
    every = commands()
    for name, option in (("simulate", "--rulebase"), ("compare", "--rulebase"),
                         ("teach", "--lesson")):
        param = next(p for p in every[name].params if option in p.opts)
        assert "NAME" in param.metavar and "mitos list" in param.help, (name, option)


def test_a_rule_base_argument_is_called_the_same_in_every_command():
    """`teach` called its rule file `[RULES]` where eval, check and plot say `[RULEBASE]`."""
    for name, cmd in commands().items():
        args = [p.metavar for p in cmd.params if p.param_type_name == "argument"]
        if name in ("eval", "check", "teach") or name.startswith("plot"):
            assert args[0].startswith("[RULEBASE]"), (name, args)


def test_the_old_spelling_of_compare_runs_still_works(tmp_path, capsys):
    cmd = commands()["compare"]
    ctx = cmd.make_context("mitos compare", ["corridor", "-n", "3", "-o", str(tmp_path)])
    assert ctx.params["runs_n"] == 3


def test_completion_offers_packaged_worlds_and_planners():
    env = {**os.environ, "PYTHONPATH": str(ROOT), "_MITOS_COMPLETE": "complete_bash",
           "COMP_WORDS": "mitos simulate fig", "COMP_CWORD": "2"}
    run = [sys.executable, "-m", "mitos_cli"]
    assert subprocess.run(run, env=env, capture_output=True, text=True).stdout.split() == \
        ["figure4"]
    env.update(COMP_WORDS="mitos simulate --planner d", COMP_CWORD="3")
    assert subprocess.run(run, env=env, capture_output=True, text=True).stdout.split() == \
        ["dwa"]
    # compare's --planner takes a list: the README promises planners there too
    env.update(COMP_WORDS="mitos compare corridor --planner fuzzy,", COMP_CWORD="4")
    assert subprocess.run(run, env=env, capture_output=True, text=True).stdout.split() == \
        ["fuzzy,potential_field", "fuzzy,dwa"]
    env.update(COMP_WORDS="mitos compare corridor --executor d", COMP_CWORD="4")
    assert subprocess.run(run, env=env, capture_output=True, text=True).stdout.split() == \
        ["dask"]


def test_the_readme_lists_the_exit_codes_of_the_help():
    readme = (ROOT / "README.md").read_text()
    table = readme.split("| exit code | meaning |")[1].split("\n\n")[0]
    codes = {int(row.split("|")[1]) for row in table.strip().splitlines()[1:]}
    helped = {c for name in EXAMPLES for c, _ in exit_codes(name)}
    assert codes == helped


def test_the_epilog_fits_an_80_column_terminal():
    from mitos_cli.cli.help import epilog

    for name in EXAMPLES:
        assert max(len(line) for line in epilog(name).splitlines()) <= 76, name


def test_the_completion_script_is_shown_for_bash(capsys, monkeypatch):
    from mitos_cli.cli.app import main

    # with shellingham installed Typer detects the shell from the process tree, which a pytest
    # worker may not show (the test failed as the first of a worker: "Shell  not supported")
    monkeypatch.setattr("typer.completion._get_shell_name", lambda: "bash")
    with pytest.raises(SystemExit) as info:
        main(["--show-completion", "bash"])
    assert info.value.code == 0
    assert "complete -o default -F _mitos_completion mitos" in capsys.readouterr().out


@pytest.mark.parametrize("words", [[], ["simulate"], ["plot", "terms"]])
def test_mitos_help_is_the_help_of_the_command_named(words):
    """`mitos help` (as `git help`, `pip help`) said "No such command 'help'", exit 2: it
    prints what `--help` prints, of `mitos` or of the command named."""
    def run(*args):
        return subprocess.run([sys.executable, "-m", "mitos_cli", *args], capture_output=True,
                              text=True, env={**os.environ, "COLUMNS": "100"})
    helped, asked = run("help", *words), run(*words, "--help")
    assert helped.returncode == asked.returncode == 0
    assert helped.stdout == asked.stdout and "Usage: mitos" in helped.stdout
    wrong = run("help", "simulat")
    assert wrong.returncode == 2 and "Did you mean 'simulate'?" in wrong.stderr


@pytest.mark.parametrize("name", sorted(EXAMPLES))
def test_usage_writes_a_required_argument_by_its_bare_name(name):
    """Typer wrote `mitos convert [OPTIONS] {FILE}` and `mitos compare [OPTIONS] {WORLDS...}`:
    braces read as a choice, or as the shell's brace expansion. Click and POSIX write FILE."""
    cmd = commands()[name]
    ctx = cmd.make_context(f"mitos {name}", ["--help"], resilient_parsing=True)
    usage = " ".join(cmd.collect_usage_pieces(ctx))
    assert "{" not in usage and "}" not in usage, usage
    assert usage.startswith("[OPTIONS]")


def test_usage_of_convert_and_compare():
    every = commands()
    for name, expected in [("convert", "[OPTIONS] [FILE]"), ("export", "[OPTIONS] [FILE]"),
                           ("compare", "[OPTIONS] WORLDS...")]:
        cmd = every[name]
        ctx = cmd.make_context(f"mitos {name}", ["--help"], resilient_parsing=True)
        assert " ".join(cmd.collect_usage_pieces(ctx)) == expected


def test_the_commands_that_answer_sigterm_and_sighup_list_their_codes():
    """`simulate`, `compare` and `teach` stop on a SIGTERM or a SIGHUP as on Ctrl-C, exiting
    143 or 129 (docs/reliability.md), and their help listed 130 alone."""
    from mitos_cli.cli.help import exit_codes

    for command in ("simulate", "compare", "teach"):
        codes = dict(exit_codes(command))
        assert {129, 130, 143} <= set(codes), command
        assert "SIGTERM" in codes[143] and "SIGHUP" in codes[129]
    assert 143 not in dict(exit_codes("eval"))
