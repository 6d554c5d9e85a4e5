"""What every command's ``--help`` ends with: examples that run as written from the repository
root, and the exit codes. One registry (``EXAMPLES``, ``EXIT_CODES``) so the README's "Exit
codes" table, the help and the tests read the same words."""

from __future__ import annotations

import inspect

#: Every command (``plot`` subcommands as ``plot terms``): example command lines, each with
#: what it does. Tests parse each line with the command's own options and keep every line of
#: the epilog within 76 columns (an 80-column terminal, with the help's margins).
EXAMPLES: dict[str, tuple[tuple[str, str], ...]] = {
    "eval": (
        ("mitos eval road=78 size=45 position=4", "the paper's sample run"),
        ("mitos eval rulebases/mitos.rules road=78 size=45 position=4 --json", "as JSON"),
        ("mitos eval --batch tests/data/inputs.csv > outputs.csv", "every row of a CSV, one batch"),
        ("mitos eval tests/data/interop/tipper.fis service=2 food=1", "a MATLAB .fis"),
        ("mitos eval --network", "the compiled neurons, layer by layer"),
    ),
    "check": (
        ("mitos check", "the packaged rule base: gaps, conflicts, dead rules"),
        ("mitos check rulebases/mitos.rules -b drive --json", "one behavior, as JSON"),
    ),
    "convert": (
        ("mitos convert tests/data/interop/tipper.fis --to rules", "tipper.rules + terms"),
        ("mitos convert rulebases/mitos.rules --to fll -o mitos.fll", "or fcl, fis"),
    ),
    "export": (
        ("mitos export rulebases/mitos.rules --to c -o planner.c", "C99, no allocation"),
        ("mitos export rulebases/mitos.rules --to python -o planner.py", "NumPy only"),
    ),
    "operators": (
        ("mitos operators", "every norm, method, defuzzifier and hedge"),
        ("mitos operators --json", "as JSON"),
    ),
    "teach": (
        ("mitos teach rulebases/mitos.rules", "the teaching prompt"),
        ("mitos teach --lesson rulebases/lessons/wider-turn.lesson -o taught.rules",
         "a scripted lesson (Figure 4 -> 10)"),
        ("mitos teach --resume", "continue the last session from its journal"),
    ),
    "compare": (
        ("mitos compare corridor slalom --and min,product -o study",
         "two T-norms and the potential field, 20 runs each"),
        ("mitos compare corridor --planner fuzzy,dwa --runs 10 -j 2 -o study-dwa",
         "the fuzzy planner's four T-norms and DWA, two processes"),
        ("mitos compare corridor slalom --and min,product -o study --resume",
         "go on after Ctrl-C"),
    ),
    "simulate": (
        ("mitos simulate figure4", "the untaught Figure 4 run: collision at B"),
        ("mitos simulate slalom --live --speed 4", "watch it in the terminal, 4x real time"),
        ("mitos simulate moving --animate run.gif", "an animation of the run"),
        ("mitos simulate figure4 --runs 20 --plot runs.png", "20 randomised runs, one picture"),
        ("mitos simulate slalom --out run.csv --json", "every tick as CSV, the summary as JSON"),
        ("mitos simulate slalom --planner dwa", "a baseline drives instead"),
    ),
    "list": (
        ("mitos list", "the packaged worlds, rule bases, term sets and lessons"),
        ("mitos list worlds", "the worlds alone"),
        ("mitos list --json", "as JSON"),
    ),
    "docs": (
        ("mitos docs", "the pages of the documentation, installed with MITOS"),
        ("mitos docs interop", "a page, as Markdown"),
        ("mitos docs teach --path", "where the page's file is"),
    ),
    "plot terms": (
        ("mitos plot terms -b avoid_obstacle road=78 size=45 position=4", "in the terminal"),
        ("mitos plot terms --var road -o road.png", "one variable, as a PNG"),
    ),
    "plot surface": (
        ("mitos plot surface steering --x road --y position --fix size=45 -o s.png",
         "a control surface"),
        ("mitos plot surface speed --x road --fix size=45 --fix position=4", "a curve, as text"),
    ),
    "plot rules": (
        ("mitos plot rules road=78 size=45 position=4", "the rule viewer in the terminal"),
        ("mitos plot rules road=78 size=45 position=4 -o rules.svg", "as an SVG"),
    ),
}

#: Exit codes: the ones every command has, then each command's own.
EXIT_CODES: tuple[tuple[int, str], ...] = (
    (0, "done"),
    (1, "a mistake in a file or a value (the message says where and what)"),
    (2, "a usage error: an unknown option or value, a missing or bad argument"),
)
#: Stopped by a signal other than Ctrl-C, where a command answers it as Ctrl-C.
STOPPED: tuple[tuple[int, str], ...] = (
    (129, "SIGHUP (the terminal closed): as Ctrl-C"),
    (143, "SIGTERM (kill, a scheduler's time limit): as Ctrl-C"),
)
OWN_EXIT_CODES: dict[str, tuple[tuple[int, str], ...]] = {
    "check": ((1, "a mistake in a file or value, or an error in the rule base"),),
    "simulate": ((3, "with --require success: a run did not succeed"),
                 (130, "Ctrl-C: with --runs, the runs that finished are still reported"),
                 *STOPPED),
    "compare": ((130, "Ctrl-C: the finished runs stay in DIR/results.csv (--resume)"),
                *STOPPED),
    "teach": ((130, "Ctrl-C: the journal keeps every change (--resume)"), *STOPPED),
}


def exit_codes(command: str) -> tuple[tuple[int, str], ...]:
    """The exit codes of ``command``, in order; its own meaning replaces the common one."""
    codes = dict(EXIT_CODES) | dict(OWN_EXIT_CODES.get(command, ()))
    return tuple(sorted(codes.items()))


def examples(command: str) -> tuple[tuple[str, str], ...]:
    """The examples of ``command``; of a group (``plot``), the first of each of its commands."""
    if command in EXAMPLES:
        return EXAMPLES[command]
    return tuple(lines[0] for name, lines in EXAMPLES.items()
                 if name.startswith(f"{command} "))


def epilog(command: str) -> str:
    """The end of ``mitos COMMAND --help``: examples, then exit codes (rich markup escaped)."""
    from rich.markup import escape

    lines = ["Examples:"]
    for line, what in examples(command):          # as a shell session: copy, paste, run
        lines += [f"  # {what}", f"  {line}"]
    lines += ["", "Exit codes:"]
    lines += [f"  {code:<3}  {meaning}" for code, meaning in exit_codes(command)]
    return escape("\n".join(lines))


def paragraphs(doc: str | None) -> str:
    """A docstring with each paragraph on one line: Typer's rich help keeps the source's
    line breaks inside a paragraph (a word alone at the end of a line)."""
    return "\n\n".join(" ".join(p.split()) for p in inspect.cleandoc(doc or "").split("\n\n"))
