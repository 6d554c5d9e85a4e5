"""An option or a command MITOS does not have, answered with what the user meant: the rule base
or the worlds given as an option where the command takes them as arguments (with the command
line as meant), a peer's option name, another tool's command name (MATLAB's ``gensurf``)."""

from __future__ import annotations

import shlex

import pytest
from hypothesis import given
from hypothesis import strategies as st

from mitos_cli.cli.app import main
from mitos_cli.cli.meant import as_argument


def run_main(args, capsys):
    with pytest.raises(SystemExit) as info:
        main(args)
    out, err = capsys.readouterr()
    return info.value.code, out, " ".join(err.replace("│", " ").split())


@pytest.mark.parametrize("args, meant", [
    (["check", "--rulebase", "mitos.rules"], "did you mean `mitos check mitos.rules`?"),
    (["eval", "--rulebase", "mitos.rules", "road=78", "size=45"],
     "did you mean `mitos eval mitos.rules road=78 size=45`?"),
    (["eval", "road=78", "-r=my rules.rules"], "did you mean `mitos eval 'my rules.rules' road=78`?"),
    (["plot", "terms", "--rulebase", "x.rules", "-o", "t.png"],
     "did you mean `mitos plot terms x.rules -o t.png`?"),
    (["convert", "--rules", "x.fis", "--to", "fll"], "did you mean `mitos convert x.fis --to fll`?"),
    (["simulate", "--world", "slalom", "corridor", "--runs", "3"],
     "takes its worlds as arguments, not as an option: "
     "did you mean `mitos simulate slalom corridor --runs 3`?"),
    (["compare", "--worlds=slalom"], "did you mean `mitos compare slalom`?"),
])
def test_the_rule_base_or_worlds_as_an_option_gets_the_command_line_meant(args, meant, capsys):
    code, out, err = run_main(args, capsys)
    assert code == 2 and out == ""
    assert "No such option: -" in err and meant in err


def test_without_a_value_it_says_where_the_rule_base_goes(capsys):
    code, _, err = run_main(["teach", "--rulebase"], capsys)
    assert code == 2
    assert "`mitos teach` takes the rule base as its first argument, not as an option" in err
    assert "did you mean" not in err


@pytest.mark.parametrize("args, meant", [
    (["eval", "--csv", "in.csv"], "No such option: --csv. Did you mean --batch?"),
    (["eval", "--input=in.csv"], "No such option: --input. Did you mean --batch?"),
    (["gensurf"], "No such command 'gensurf'. Did you mean 'plot surface'?"),
    (["train"], "No such command 'train'. Did you mean 'teach'?"),
    (["run", "slalom"], "No such command 'run'. Did you mean 'simulate'?"),
    (["plot", "gensurf"], "No such command 'gensurf'. Did you mean 'surface'?"),
    (["plot", "plotmf"], "No such command 'plotmf'. Did you mean 'terms'?"),
    (["plot", "ruleview"], "No such command 'ruleview'. Did you mean 'rules'?"),
    # a misspelling keeps Typer's suggestion, an unknown option Click's answer
    (["simualte"], "No such command 'simualte'. Did you mean 'simulate'?"),
    (["simulate", "--output", "x.csv"], "No such option: --output (Possible options: --out)"),
    # Click offered `--fps`
    (["simulate", "slalom", "--csv"], "No such option: --csv. Did you mean --out FILE.csv?"),
    (["eval", "--frobnicate"], "No such option: --frobnicate"),
])
def test_other_tools_names_get_ours(args, meant, capsys):
    code, out, err = run_main(args, capsys)
    assert code == 2 and out == ""
    assert meant in err


def test_a_peers_option_name_is_offered_only_where_the_command_has_ours(capsys):
    code, _, err = run_main(["check", "--csv", "x.csv"], capsys)
    assert code == 2 and "No such option: --csv" in err and "--batch" not in err
    code, _, err = run_main(["compare", "slalom", "--csv"], capsys)     # its --out: a folder
    assert code == 2 and "No such option: --csv" in err and "Did you mean" not in err


words = st.text(st.characters(blacklist_categories=("Cs", "Cc")), min_size=1, max_size=12)


@given(value=words.filter(lambda w: not w.startswith("-")),
       rest=st.lists(words.filter(lambda w: not w.startswith("--rulebase")), max_size=4),
       at=st.integers(0, 4), inline=st.booleans())
def test_the_command_line_meant_reads_back_as_the_value_then_the_rest(value, rest, at, inline):
    at = min(at, len(rest))
    given_args = [*rest[:at], *([f"--rulebase={value}"] if inline else ["--rulebase", value]),
                  *rest[at:]]
    line = as_argument("mitos check", given_args, "--rulebase")
    assert line is not None and line.startswith("mitos check ")
    assert shlex.split(line[len("mitos check "):]) == [value, *rest]
