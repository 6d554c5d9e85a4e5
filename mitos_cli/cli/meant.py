"""What a user meant by an option or a command this one does not have.

Click's own suggestions are spellings (``--worlds``: "Possible options: --or, --workers").
The mistakes users make are more often a habit from elsewhere:

- the rule base or the world given as an option to a command that takes it as an argument
  (``simulate`` and ``compare`` take ``--rulebase``; ``eval``, ``check``, ``teach``,
  ``convert``, ``export`` and ``plot`` take the rule base first; ``simulate`` and
  ``compare`` take their worlds as arguments): the answer is the command line as meant;
- a peer's name for an option (``--csv`` for ``eval --batch``, for ``simulate --out``);
- a command by another tool's name for it: MATLAB's ``gensurf``, ``plotmf`` and ``ruleview``
  for ``plot surface``, ``plot terms`` and ``plot rules``; ``train`` or ``run``.
"""

from __future__ import annotations

import shlex
from typing import Any

from typer._click import Context
from typer._click.exceptions import NoSuchOption, UsageError
from typer.core import TyperGroup

#: Options naming what these commands take as their first argument: the option -> what it is.
AS_ARGUMENT = {"--rulebase": "rule base", "--rules": "rule base", "-r": "rule base",
               "--world": "world", "--worlds": "world", "-w": "world"}

#: The commands that take each such thing as their first argument (by their last name).
FIRST_ARGUMENT = {
    "rule base": {"eval", "check", "teach", "convert", "export", "terms", "surface", "rules"},
    "world": {"simulate", "compare"},
}

#: Peers' names of options -> ours, offered where the command has ours.
OPTIONS = {"--csv": "--batch", "--input": "--batch", "--inputs": "--batch",
           "--in": "--batch", "--file": "--batch"}
#: The same for one command, where its option of that name means something else
#: (``simulate --csv``: Click offered `--fps`).
COMMAND_OPTIONS = {"simulate": {"--csv": "--out FILE.csv"}}

#: Other tools' names of commands -> ours, for each group (``""`` is ``mitos`` itself).
COMMANDS = {
    "": {"train": "teach", "learn": "teach", "adapt": "teach", "tell": "teach",
         "run": "simulate", "sim": "simulate", "drive": "simulate",
         "lint": "check", "validate": "check", "verify": "check",
         "ls": "list", "evaluate": "eval", "evalfis": "eval", "infer": "eval",
         "import": "convert", "save": "convert", "codegen": "export",
         "draw": "plot", "show": "plot", "gensurf": "plot surface", "plotmf": "plot terms",
         "ruleview": "plot rules", "bench": "compare", "benchmark": "compare", "study": "compare"},
    "plot": {"gensurf": "surface", "surf": "surface", "plotmf": "terms", "mf": "terms",
             "mfs": "terms", "membership": "terms", "memberships": "terms", "term": "terms",
             "ruleview": "rules", "viewer": "rules", "rule": "rules"},
}


def option_meant(ctx: Context, args: list[str], exc: NoSuchOption) -> UsageError:
    """``exc`` (an unknown option in ``args``, the command's own arguments), with what the user
    meant where we can tell: the command line without the option, or our name for it."""
    option = exc.option_name.partition("=")[0]
    command = ctx.command.name or ""
    what = AS_ARGUMENT.get(option)
    if what is not None and command in FIRST_ARGUMENT[what]:
        line = as_argument(ctx.command_path, args, option)
        example = f": did you mean `{line}`?" if line else ""
        takes = "the rule base as its first argument" if what == "rule base" \
            else "its worlds as arguments"
        return NoSuchOption(option, f"No such option: {option}. `{ctx.command_path}` takes "
                                    f"{takes}, not as an option{example}", ctx=ctx)
    ours = COMMAND_OPTIONS.get(command, {}).get(option) or OPTIONS.get(option)
    if ours is not None and ours.split()[0] in option_names(ctx):
        return NoSuchOption(option, f"No such option: {option}. Did you mean {ours}?", ctx=ctx)
    return exc


def as_argument(path: str, args: list[str], option: str) -> str | None:
    """``path args`` with ``option`` and its value (``--world x`` or ``--world=x``) taken out
    and the value put first among the arguments, quoted for a shell; ``None`` without a
    value."""
    at = next((i for i, a in enumerate(args) if a == option or a.startswith(option + "=")), -1)
    if at < 0:
        return None
    if args[at] != option:
        value, rest = args[at][len(option) + 1:], args[:at] + args[at + 1:]
    elif at + 1 < len(args) and not args[at + 1].startswith("-"):
        value, rest = args[at + 1], args[:at] + args[at + 2:]
    else:
        return None
    return " ".join([path, shlex.join([value, *rest])]) if value else None


def option_names(ctx: Context) -> set[str]:
    return {opt for param in ctx.command.params for opt in getattr(param, "opts", ())}


def command_meant(group: str, name: str, known: list[str]) -> str | None:
    """Our command for ``name`` in ``group`` (``""`` or ``"plot"``), if it is another tool's
    name for one of ``known``."""
    ours = COMMANDS.get(group, {}).get(name.lower())
    return ours if ours is not None and ours.split()[0] in known else None


class MeantGroup(TyperGroup):
    """A group of commands whose unknown command is answered with ours for it, where the
    name is another tool's (else with Typer's spelling suggestions)."""

    def resolve_command(self, ctx: Context, args: list[str]) -> Any:
        try:
            return super().resolve_command(ctx, args)
        except UsageError as exc:
            group = "" if ctx.parent is None else (ctx.command.name or "")
            ours = command_meant(group, args[0], list(self.commands)) if args else None
            if ours is not None:
                exc.message = f"No such command '{args[0]}'. Did you mean '{ours}'?"
            raise
