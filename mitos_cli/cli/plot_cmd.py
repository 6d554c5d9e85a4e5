"""``mitos plot``: membership plots, control surfaces and the rule viewer.

With ``-o FILE.png`` or ``-o FILE.svg`` a picture is written (matplotlib, Agg canvas); with
``--show`` a window opens where one can. Without either, the picture goes to the terminal:
``plot terms`` draws the memberships in Unicode Braille, ``plot surface`` prints the surface as
a table of output values, ``plot rules`` prints the rule viewer with bars. matplotlib is
imported only when a picture file or window is asked for.
"""

from __future__ import annotations

import os
import sys
from enum import Enum
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Optional

import typer

from ..errors import InputError, UsageError
from ..numbers import parse_value
from .eval_cmd import parse_values, refuse_nan, split_args, unused_inputs
from .help import epilog
from .meant import MeantGroup
from .output import emit, err, warn
from .params import (
    WORDS,
    Number,
    OnceCommand,
    choice,
    choices,
    completer,
    named,
    not_a_directory_name,
)

if TYPE_CHECKING:
    from collections.abc import Sequence

    from ..api import LoadedRuleBase
    from ..draw.data.curves import VariablePlot

FORMATS = ("png", "svg")
RULE_SUFFIXES = (".rules", ".fcl", ".fis", ".fll")

plot_app = typer.Typer(
    name="plot",
    help="Draw a rule base: membership plots, control surfaces, the rule viewer "
         "(PNG/SVG with -o, a window with --show, else in the terminal).",
    epilog=epilog("plot"),
    no_args_is_help=True,
    context_settings={"help_option_names": ["-h", "--help"]},
    cls=MeantGroup,
)


class Style(str, Enum):
    surface = "surface"
    heatmap = "heatmap"


def check_output(path: Optional[str]) -> Optional[str]:
    """``-o`` must name a .png or .svg file (usage error otherwise)."""
    return picture_path(path, "'-o' / '--output'")


def picture_path(path: Optional[str], option: str) -> Optional[str]:
    """The picture file an ``option`` names, a .png or .svg one (usage error otherwise)."""
    if path is None:
        return None
    named(path)                        # (`-o ''` said "`` has no extension")
    suffix = Path(not_a_directory_name(path)).suffix.lower().lstrip(".")
    if suffix not in FORMATS:
        raise typer.BadParameter(
            f"`{path}` has {'extension .' + suffix if suffix else 'no extension'}; "
            f"the picture formats are " + " and ".join(f".{f}" for f in FORMATS),
            param_hint=option)
    return path


OutputOpt = Annotated[Optional[str], typer.Option(
    "--output", "-o", metavar="FILE.png|FILE.svg", callback=check_output,
    help="Write the picture to this file (format by extension: .png or .svg).")]
ShowOpt = Annotated[bool, typer.Option(
    "--show", help="Open the picture in a window (where a display is available).")]
BehaviorOpt = Annotated[Optional[str], typer.Option(
    "--behavior", "-b", metavar="NAME", callback=named,
    help="Use this behavior (default: the file's first).")]
TitleOpt = Annotated[Optional[str], typer.Option(
    "--title", metavar="TEXT", help="The picture's title (default: says what is drawn).")]


def _warn_undrawn(values: dict[str, float], plots: Sequence[VariablePlot], chose: str) -> None:
    """A value given for a variable that ``--var`` or ``-b`` leaves off the sheet marks
    nothing: say so, where it was dropped without a word."""
    drawn = {p.name for p in plots}
    left = [name for name in values if name not in drawn]
    if left:
        names = ", ".join(f"`{n}`" for n in left)
        warn(f"{names} {'is' if len(left) == 1 else 'are'} given a value but not drawn: "
             f"{chose} leaves {'it' if len(left) == 1 else 'them'} off the sheet "
             f"(add {' '.join('--var ' + n for n in left)} to draw {'it' if len(left) == 1 else 'them'})")


def _wants_picture(output: Optional[str], show: bool) -> bool:
    return output is not None or show


def _one_way(output: Optional[str], show: bool, *, title: Optional[str] = None,
             width: Optional[int] = None, color: Optional[bool] = None) -> None:
    """An option of the other way of drawing is a usage error: `--title` in the terminal, or
    `--width` / `--color` with a picture, was ignored without a word."""
    if _wants_picture(output, show):
        for name, given in (("--width", width), ("--color/--no-color", color)):
            if given is not None:
                raise typer.BadParameter(f"{name} shapes the terminal drawing; -o and --show "
                                         f"draw a picture: leave {name} out")
    elif title is not None:
        raise typer.BadParameter("--title names the picture: add -o FILE.png (or --show), or "
                                 "leave --title out")


def _done(output: Optional[str], no_window: Optional[str] = None) -> None:
    if output is not None:
        err(f"wrote {output}")
    if no_window is not None:
        from ..draw.output import DrawError

        raise DrawError(f"cannot open a window: {no_window}",
                        hint=f"the picture is in {output}" if output else None)


def _window(output: Optional[str], show: bool) -> tuple[bool, Optional[str]]:
    """``--show`` as it can be honoured, and why not: with ``-o`` where no window can open the
    file is still written, then the window refused (it was refused before the file)."""
    if show and output is not None:
        from ..draw.output import no_window

        why = no_window()
        if why is not None:
            return False, why
    return show, None


def _use_color(color: Optional[bool]) -> bool:
    """``--color/--no-color``, else colour on a terminal that shows it: not with NO_COLOR, nor
    on TERM=dumb, which printed the escape codes as text (as Rich does not colour there)."""
    if color is not None:
        return color
    return (sys.stdout.isatty() and not os.environ.get("NO_COLOR")
            and os.environ.get("TERM") != "dumb")


#: the terminal drawing's options
WIDTH = Number("the plot's width in characters", 30, 400)
WidthOpt = Annotated[Optional[int], typer.Option(
    "--width", metavar="N", click_type=WIDTH,
    help="Terminal plot width in characters (default: the terminal's, at most 100).")]
ColorOpt = Annotated[Optional[bool], typer.Option(
    "--color/--no-color", help="Colour the terminal plot (default: when stdout is a "
                               "terminal, TERM is not dumb and NO_COLOR is unset).")]


def _terminal_width(width: Optional[int]) -> int:
    """``--width``, else the terminal's width, at most 100."""
    if width is not None:
        return width
    import shutil

    return min(shutil.get_terminal_size((80, 24)).columns, 100)


def terms_command(
    args: Annotated[Optional[list[str]], typer.Argument(
        click_type=WORDS, metavar="[RULEBASE] [NAME=VALUE]...", callback=named,
        help="Rule file (default: the packaged MITOS rule base) or a term set "
             "(FILE.terms.yaml), then values to mark, "
             "e.g. road=78.")] = None,
    var: Annotated[Optional[list[str]], typer.Option(
        "--var", "-v", metavar="NAME", callback=named,
        help="Draw only this variable (repeat for more).")] = None,
    behavior: Annotated[Optional[str], typer.Option(
        "--behavior", "-b", metavar="NAME", callback=named,
        help="Draw only the variables this behavior uses.")] = None,
    output: OutputOpt = None,
    show: ShowOpt = False,
    title: TitleOpt = None,
    width: WidthOpt = None,
    color: ColorOpt = None,
) -> None:
    """Membership plots: every term of each variable, with given values marked.

    All variables on one sheet (the paper's Figures 5-9) unless --var picks some. Without -o or
    --show the plot is drawn in the terminal with Unicode characters."""
    from ..api import is_termset_name, read_terms
    from ..draw.data import sheet
    from ..lang.model import RuleBase
    from ..resources import display_path

    _one_way(output, show, title=title, width=width, color=color)
    path, texts = split_args(args or [])
    rulebase = read_terms(path)
    if not isinstance(rulebase, RuleBase):
        if behavior is not None:
            raise UsageError(f"`{path}` has no behaviors (its terms only): -b {behavior} needs "
                             "a rule file that reads them")
        if not is_termset_name(path):
            warn(f"`{path}` has no rules: its terms alone are drawn")
    values = parse_values(texts)
    plots = sheet(rulebase, var, values, behavior)
    _warn_undrawn(values, plots, "--var" if var else "-b")
    for p in plots:
        if p.clamped:
            lo, hi = p.universe
            warn(f"`{p.name}` outside its universe [{lo:g}, {hi:g}] was clamped")
        _warn_no_degree(p)
    if not _wants_picture(output, show):
        from ..draw.terminal import render_sheet

        emit(render_sheet(plots, width=_terminal_width(width), color=_use_color(color)))
        return
    from ..draw.terms import draw_sheet

    if title is None:
        where = display_path(rulebase.path)
        if len(plots) == 1:
            title = f"{plots[0].name}: {where}"
        elif behavior and not var:
            title = f"Term sets of behavior {behavior}: {where}"
        else:
            title = f"Term sets of {where}"
    show, why = _window(output, show)
    draw_sheet(plots, output, title=title, show=show)
    _done(output, why)


def _warn_no_degree(plot: VariablePlot) -> None:
    """Say where a drawn term (a formula) leaves [0, 1], which `eval` and `check` refuse: the
    picture shows it, and without a word it looked like a term that works."""
    import numpy as np

    for c in plot.curves:
        if c.kind != "curve":
            continue
        bad = np.flatnonzero(~((c.y >= 0.0) & (c.y <= 1.0)))
        if len(bad):
            at = int(bad[0])
            warn(f"term `{plot.name}.{c.name}` gives {float(c.y[at]):g} at {plot.name} = "
                 f"{float(c.x[at]):g}: a membership degree lies in [0, 1] (`eval` and `check` "
                 f"refuse it)")


def _axis(text: str, option: str) -> tuple[str, Optional[tuple[float, float]]]:
    """``road`` or ``road=40:100`` -> (name, range or None)."""
    name, sep, rng = text.partition("=")
    if not sep:
        return name, None
    lo, colon, hi = rng.partition(":")
    try:
        if not colon:
            raise ValueError
        return name, (parse_value(lo), parse_value(hi))
    except OverflowError:           # (`1e400` read as inf was said as `inf`, never written)
        big = next(t for t in (lo, hi) if not _fits(t))
        raise InputError(f"range {rng} of `{name}` has a number too large for a float: `{big}`",
                         expected="numbers of magnitude at most 1.8e308") from None
    except ValueError:
        raise typer.BadParameter(f"`{text}`: write NAME or NAME=LOW:HIGH, e.g. {name}=40:100",
                                 param_hint=option) from None


def _fits(text: str) -> bool:
    """Whether ``text`` reads as a number inside a float's range (or as written, ``inf``)."""
    try:
        parse_value(text)
    except OverflowError:
        return False
    except ValueError:
        pass
    return True


def _fixed(items: list[str]) -> dict[str, str]:
    out: dict[str, str] = {}
    for item in items:
        name, sep, value = item.partition("=")
        if not sep or not name:
            raise typer.BadParameter(f"`{item}`: write NAME=VALUE, e.g. size=45",
                                     param_hint="'--fix'")
        if name in out:
            raise typer.BadParameter(f"`{name}` is fixed twice", param_hint="'--fix'")
        out[name] = value
    return out


def _surface_args(args: list[str]) -> tuple[Optional[str], Optional[str]]:
    """``[RULEBASE] [OUTPUT]`` -> (rule-base path, output name); a lone argument that names a
    rule file is the rule base."""
    for arg in args:
        if "=" in arg:          # `--fix size=45 position=4`: the second value fell out of --fix
            raise typer.BadParameter(
                f"`{arg}` is not a rule base or an output; to hold several inputs, repeat "
                f"--fix: --fix {arg} (one --fix NAME=VALUE per input)")
    if len(args) > 2:
        raise typer.BadParameter(f"expected [RULEBASE] [OUTPUT], got {len(args)} arguments: "
                                 + " ".join(args))
    if len(args) == 2:
        return args[0], args[1]
    if len(args) == 1:
        arg = args[0]
        if Path(arg).suffix.lower() in RULE_SUFFIXES or Path(arg).is_file():
            return arg, None
        return None, arg
    return None, None


STYLE_NEEDS = ("--style chooses how a picture of two inputs is drawn: add --y and -o FILE.png "
               "(or --show), or leave --style out")


def _surface_defaults(rb: LoadedRuleBase, out_name: str | None, x: str | None,
                      y: str | None) -> tuple[str, str, str | None, list[str]]:
    """What `mitos plot surface` draws when told less, as MATLAB's ``gensurf(fis)``: the
    behavior's first output over its first two inputs, and the note that says each default
    (printed once the surface is made: before an error it spoke of a drawing never made)."""
    chose = []
    if out_name is None:
        out_name = rb.outputs[0]
        if len(rb.outputs) > 1:
            chose.append(f"`{out_name}`, the first output (name another: "
                         + ", ".join(rb.outputs[1:]) + ")")
    if x is None:
        x, y = rb.inputs[0], rb.inputs[1] if len(rb.inputs) > 1 else None
        over = f"`{x}`" + (f" and `{y}`" if y is not None else "")
        chose.append(f"over {over}, the first inputs (--x and --y choose others)")
    return out_name, x, y, ["drawing " + "; ".join(chose)] if chose else []


def surface_command(
    args: Annotated[Optional[list[str]], typer.Argument(
        click_type=WORDS, metavar="[RULEBASE] [OUTPUT]", callback=named,
        help="Rule file (default: the packaged MITOS rule base), then the output to draw "
             "(default: the behavior's first, with a note).")] = None,
    x: Annotated[Optional[str], typer.Option(
        "--x", metavar="INPUT[=LOW:HIGH]", callback=named,
        help="Input on the x axis, optionally zoomed to LOW:HIGH (default: the behavior's "
             "first input, and its second on the y axis, as MATLAB's gensurf).")] = None,
    y: Annotated[Optional[str], typer.Option(
        "--y", metavar="INPUT[=LOW:HIGH]", callback=named,
        help="Input on the y axis (with --x alone: a curve over --x).")] = None,
    fix: Annotated[Optional[list[str]], typer.Option(
        "--fix", metavar="NAME=VALUE",
        help="Hold another input at a value (repeat; inputs not fixed are held at the "
             "midpoint of their universe, with a note).")] = None,
    resolution: Annotated[int, typer.Option(
        "--resolution", "-n", metavar="N",
        click_type=Number("the number of grid points per axis", 2, 1000),
        help="Grid points per axis.")] = 61,
    style_name: Annotated[Optional[str], typer.Option(
        "--style", metavar=choices(Style), autocompletion=completer(Style),
        help="surface: a 3-D surface (the default); heatmap: a heat map with contour lines. "
             "For a picture of two inputs (--y, with -o or --show).")] = None,
    output: OutputOpt = None,
    show: ShowOpt = False,
    title: TitleOpt = None,
    behavior: BehaviorOpt = None,
) -> None:
    """Control surface: an output over one or two inputs, the others fixed.

    The grid is computed in one batch. Without -o or --show the surface is printed as a table
    of output values ("-" where no rule fires and the output has no default)."""
    from ..api import load_rulebase
    from ..draw.data import surface

    style = choice(Style, style_name or Style.surface.value, "style")
    _one_way(output, show, title=title)
    if x is None and y is not None:
        raise typer.BadParameter("--y needs --x: name the input on the x axis too")
    if style_name is not None and ((x is not None and y is None)
                                   or not _wants_picture(output, show)):
        raise typer.BadParameter(STYLE_NEEDS)
    path, out_name = _surface_args(args or [])
    held = _fixed(fix or [])            # (a malformed --fix followed a note on the axes)
    rb = load_rulebase(path, behavior)
    out_name, x, y, chosen = _surface_defaults(rb, out_name, x, y)
    if style_name is not None and y is None:          # a behavior of one input: a curve
        raise typer.BadParameter(STYLE_NEEDS)
    x_name, x_range = _axis(x, "'--x'")
    y_name, y_range = _axis(y, "'--y'") if y is not None else (None, None)
    fixed = parse_values(held)
    s = surface(rb.compiled, out_name, x_name, y_name, fixed, resolution, x_range, y_range)
    for note in [*chosen, *s.notes()]:
        err(f"note: {note}")
    if not _wants_picture(output, show):
        from ..draw.terminal import render_surface

        emit(render_surface(s))
        return
    from ..draw.surface import draw_surface

    show, why = _window(output, show)
    draw_surface(s, output, style=style.value, show=show, title=title)
    _done(output, why)


def _used_values(rb: LoadedRuleBase, texts: dict[str, str]) -> dict[str, float]:
    """The ``NAME=VALUE`` inputs as `mitos eval` takes them: an input of the file that the
    behavior does not test is taken and dropped (``eval -b main road=78 size=5`` ran, the same
    words here said "does not use input"), NaN refused for every input."""
    numbers = parse_values(texts)
    refuse_nan(numbers)
    unused = unused_inputs(rb)
    return {k: v for k, v in numbers.items() if k not in unused}


def rules_command(
    args: Annotated[Optional[list[str]], typer.Argument(
        click_type=WORDS, metavar="[RULEBASE] NAME=VALUE...", callback=named,
        help="Rule file (default: the packaged MITOS rule base), then one NAME=VALUE per "
             "input.")] = None,
    output: OutputOpt = None,
    show: ShowOpt = False,
    title: TitleOpt = None,
    behavior: BehaviorOpt = None,
    max_rules: Annotated[int, typer.Option(
        "--max-rules", metavar="N", click_type=Number("the number of fired rules to draw", 1, 500),
        help="Draw at most this many fired rules (the strongest).")] = 30,
    width: Annotated[Optional[int], typer.Option(
        "--width", metavar="N", click_type=WIDTH,
        help="Width in characters of a Mamdani output's plot in the text viewer "
             "(default 72).")] = None,
    color: ColorOpt = None,
) -> None:
    """Rule viewer: each fired rule with its memberships, DOF and consequent.

    For one input: every fired rule as a row, each output's aggregate and crisp result. Without
    -o or --show the viewer is printed as text with bars."""
    from ..api import load_rulebase
    from ..draw.data import rule_view

    _one_way(output, show, title=title, width=width, color=color)
    path, texts = split_args(args or [])
    rb = load_rulebase(path, behavior)
    if not texts:
        raise typer.BadParameter(
            "give one NAME=VALUE per input: " + " ".join(f"{k}=..." for k in rb.inputs))
    view = rule_view(rb.compiled, _used_values(rb, texts))
    for i in view.inputs:
        if i.clamped:
            lo, hi = i.universe
            warn(f"`{i.name}` outside its universe [{lo:g}, {hi:g}] was clamped")
    if not _wants_picture(output, show):
        from ..draw.terminal import render_rule_view

        emit(render_rule_view(view, width=width or 72, color=_use_color(color)))
        return
    from ..draw.rules import draw_rules

    show, why = _window(output, show)
    draw_rules(view, output, show=show, max_rows=max_rules, title=title)
    _done(output, why)


def reflow(doc: str | None) -> str:
    """A docstring as help text: paragraphs kept, the lines inside each joined (Typer's rich
    help would otherwise keep the source's line breaks)."""
    import inspect

    paragraphs = inspect.cleandoc(doc or "").split("\n\n")
    return "\n\n".join(" ".join(p.split()) for p in paragraphs)


plot_app.command("terms", cls=OnceCommand, help=reflow(terms_command.__doc__),
                 epilog=epilog("plot terms"))(terms_command)
plot_app.command("surface", cls=OnceCommand, help=reflow(surface_command.__doc__),
                 epilog=epilog("plot surface"))(surface_command)
plot_app.command("rules", cls=OnceCommand, help=reflow(rules_command.__doc__),
                 epilog=epilog("plot rules"))(rules_command)

__all__ = ["plot_app"]
