"""Where a figure goes: a PNG or SVG file (the Agg canvas, no window, no pyplot state) or a
window (``show``), and the one place that imports matplotlib for that.

Figures for files are plain :class:`matplotlib.figure.Figure` objects on an Agg canvas, so
drawing never touches pyplot's global figure list or backend; only :func:`new_figure` with
``show=True`` imports pyplot, and it refuses with a clear message where no window can open.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import MitosError, install_hint

if TYPE_CHECKING:
    from types import ModuleType

    from matplotlib.figure import Figure

#: The file formats a picture can be written in, by extension.
FORMATS = ("png", "svg")
#: matplotlib backends that cannot open a window
NON_INTERACTIVE = {"agg", "cairo", "pdf", "pgf", "ps", "svg", "template"}


class DrawError(MitosError):
    """A picture that cannot be drawn here (no matplotlib, no display); a file that cannot be
    written is a :class:`~mitos_cli.errors.WriteError`, as for every command."""

    kind = "error"


def file_path(path: object, what: str = "a picture") -> Path:
    """``path`` as a :class:`Path`, else a :class:`DrawError` saying what is taken
    (``draw_run(result, 3)`` met pathlib's "expected str, bytes or os.PathLike object"). A
    name ending in a separator names a directory, as on the command line: ``Path('run.gif/')``
    is ``run.gif``, which was written."""
    if isinstance(path, str) and path.endswith(("/", os.sep)) and path.strip("/" + os.sep):
        raise DrawError(f"`{path}` ends in `{path[-1]}`, so it names a directory, not a file",
                        hint=f"give the file's name (`{path.rstrip('/' + os.sep)}`, or a name "
                             f"inside that directory)")
    if isinstance(path, (str, os.PathLike)):
        return Path(path)
    raise DrawError(f"{what} is written to a file: expected a path, not "
                    f"{type(path).__name__} `{path!r:.40}`",
                    hint="give the file's name, such as 'run.png'")


def check_format(path: str | Path) -> str:
    """The format of ``path`` by its extension; :class:`DrawError` unless png or svg."""
    suffix = file_path(path).suffix.lower().lstrip(".")
    if suffix not in FORMATS:
        raise DrawError(f"cannot write `{path}`: unknown picture format "
                        f"`{suffix or '(no extension)'}`",
                        expected="a file name ending in " + " or ".join(f".{f}" for f in FORMATS))
    return suffix


def _matplotlib() -> ModuleType:
    try:
        import matplotlib
    except ImportError:
        raise DrawError("drawing pictures needs matplotlib, which is not installed",
                        hint=install_hint("plot")) from None
    except ValueError:              # its import reads MPLBACKEND, and refuses a name it lacks
        raise _bad_backend(os.environ.get("MPLBACKEND", "")) from None
    return matplotlib


def _bad_backend(name: str, why: str = "not a backend matplotlib has") -> DrawError:
    """The refusal of the backend the environment variable ``MPLBACKEND`` names (matplotlib
    met it with a ValueError on import, or an ImportError when a window was asked for)."""
    return DrawError(f"matplotlib cannot use the backend `{name:.60}` that MPLBACKEND names: "
                     f"{why}", hint="unset MPLBACKEND, or set it to agg (files only) or a GUI "
                                    "backend such as tkagg or qtagg")


def require_matplotlib() -> None:
    """:class:`DrawError` unless matplotlib can be imported: for a command that draws only
    after long work (``simulate --runs 1000 --plot``), to refuse before the work, not after."""
    _matplotlib()


def no_window() -> str | None:
    """Why no window can open here (no display, a backend that draws only files), or None."""
    _matplotlib()
    import matplotlib.pyplot as plt

    backend = plt.get_backend().lower()
    if backend not in NON_INTERACTIVE:
        return None
    if (os.name == "posix" and not os.environ.get("DISPLAY")
            and not os.environ.get("WAYLAND_DISPLAY") and os.uname().sysname == "Linux"):
        return "no display (DISPLAY is not set)"
    return f"matplotlib's backend `{backend}` cannot open windows"


def new_figure(figsize: tuple[float, float], show: bool = False, **kwargs: Any) -> Figure:  # Figure's own
    """A new figure: managed by pyplot (and an interactive backend) when ``show``, else a
    bare Figure on an Agg canvas."""
    _matplotlib()
    if show:
        import matplotlib.pyplot as plt

        why = no_window()
        if why is not None:
            raise DrawError(f"cannot open a window: {why}",
                            hint="write a file instead with -o FILE.png or -o FILE.svg")
        try:
            return plt.figure(figsize=figsize, **kwargs)
        except ImportError as exc:      # the backend's module is loaded with the first window
            raise DrawError(f"cannot open a window: "
                            f"{_bad_backend(os.environ.get('MPLBACKEND', ''), str(exc)).message}",
                            hint="unset MPLBACKEND, or write a file with -o FILE.png") from None
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, **kwargs)
    FigureCanvasAgg(fig)
    return fig


def literal_text(fig: Figure) -> None:
    """Every text of ``fig`` drawn as it is written: a ``$`` in a title, a world's name or a
    unit is a dollar sign, not the start of matplotlib's mathtext (which stops on ``$x^$``
    with a traceback when the figure is drawn)."""
    from matplotlib.text import Text

    for text in fig.findobj(Text):
        text.set_parse_math(False)


def finish(fig: Figure, path: str | Path | None = None, show: bool = False, dpi: int = 150,
           tight: bool = True) -> Figure:
    """Save ``fig`` to ``path`` (atomically: a temporary file renamed into place), then show
    it when asked; ``tight`` trims the margins (one more layout pass). Returns the figure."""
    literal_text(fig)
    if path is not None:
        path = file_path(path)
        fmt = check_format(path)
        import matplotlib

        from ..fileio import atomic_file

        with atomic_file(path, binary=True) as fh, \
                matplotlib.rc_context({"svg.hashsalt": "mitos"}):
            fig.savefig(fh, format=fmt, dpi=dpi, bbox_inches="tight" if tight else None,
                        metadata=_metadata(fmt))
    if show:
        import matplotlib.pyplot as plt

        plt.show()
    return fig


def _metadata(fmt: str) -> dict:
    """No creation dates in the files, so the same picture is the same bytes."""
    if fmt == "svg":
        return {"Date": None}
    return {"Software": None}
