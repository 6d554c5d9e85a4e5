"""The ``mitos`` command: registers the commands and turns errors into messages.

Our own errors (:class:`MitosError`) print ``path:line:col: message`` and exit 1; usage errors
exit 2 (Click's convention); anything else is a bug and keeps its traceback.
"""

from __future__ import annotations

import sys

import typer

from ..errors import MitosError
from . import check_cmd, compare_cmd, convert_cmd, eval_cmd, export_cmd, operators_cmd, plot_cmd, teach_cmd
from . import simulate_cmd

app = typer.Typer(
    name="mitos",
    help="Instructible neurofuzzy motion planners: evaluate, check, simulate and teach "
         "fuzzy rule bases.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    context_settings={"help_option_names": ["-h", "--help"]},
)



@app.callback()
def _root() -> None:
    """Instructible neurofuzzy motion planners: evaluate, check, simulate and teach fuzzy rule
    bases. Rule files, term sets, worlds and lessons are documented in the README."""


# One line per command; each module holds one command function.
app.command("eval")(eval_cmd.eval_command)
app.command("convert")(convert_cmd.convert_command)
app.command("export")(export_cmd.export_command)
app.command("operators")(operators_cmd.operators_command)
app.command("check")(check_cmd.check_command)
app.command("teach")(teach_cmd.teach_command)
app.command("compare")(compare_cmd.compare_command)
app.command("simulate")(simulate_cmd.simulate_command)
app.add_typer(plot_cmd.plot_app, name="plot")


def main(argv: list[str] | None = None) -> None:
    """Entry point of the console script and ``python -m mitos_cli``."""
    try:
        app(args=argv, prog_name="mitos", standalone_mode=True)
    except MitosError as exc:
        from .output import report_error

        report_error(exc)
        sys.exit(1)
