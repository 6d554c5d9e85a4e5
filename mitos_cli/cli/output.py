"""Where the CLI writes: data to stdout, diagnostics to stderr (user text never as markup)."""

from __future__ import annotations

import dataclasses
import sys

from ..errors import MitosError


def err(message: str) -> None:
    """A diagnostic line on stderr."""
    print(message, file=sys.stderr)


def warn(message: str) -> None:
    err(f"warning: {message}")


def warn_notes(rulebase: object) -> None:
    """What a foreign file's reader changed to make the file fit, one warning each."""
    for note in getattr(rulebase, "notes", ()):
        warn(note)


def report_error(exc: MitosError) -> None:
    """``exc`` on stderr, a place in a packaged rule base named as the user names it
    (``rulebases/mitos.rules:146:5``, as ``check`` does), not where pip put it."""
    span = exc.span
    if span is not None and span.path:
        from ..resources import packaged_name

        if (name := packaged_name(span.path)) is not None:
            exc.span = dataclasses.replace(span, path=name)
    err(exc.render())


def json_text(value: object, infinity_as_text: bool = False) -> str:
    """``value`` as strict JSON (indented): a NaN or an infinity, which ``json.dumps`` would
    write as the bare ``NaN``/``Infinity`` that strict parsers refuse, is ``null``; with
    ``infinity_as_text`` an infinity is the text ``"inf"`` or ``"-inf"`` (an input given as
    ``inf`` is a value, which ``null`` would deny)."""
    import json
    import math

    def strict(v: object) -> object:
        if isinstance(v, float) and not math.isfinite(v):
            if infinity_as_text and math.isinf(v):
                return "inf" if v > 0 else "-inf"
            return None
        if isinstance(v, dict):
            return {k: strict(x) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            return [strict(x) for x in v]
        return v

    return json.dumps(strict(value), indent=2, allow_nan=False)


def emit(text: str) -> None:
    """Data on stdout."""
    sys.stdout.write(text if text.endswith("\n") else text + "\n")
