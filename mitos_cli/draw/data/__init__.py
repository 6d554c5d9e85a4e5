"""What the pictures show, as plain data: term curves (``curves``), control surfaces
(``surfaces``) and rule-viewer rows (``ruleviews``).

Every picture of :mod:`mitos_cli.draw` (and every terminal plot of :mod:`mitos_cli.draw.terminal`)
draws one of the dataclasses built here, so what a picture says can be tested without
matplotlib and without looking at pixels:

- :func:`variable_plot` -> :class:`VariablePlot`: every term of a variable sampled over its
  universe (corner points included, so piecewise-linear curves are drawn exactly), and the
  memberships of a marked value;
- :func:`surface` -> :class:`Surface`: one output over a grid of one or two inputs with the
  others fixed, computed by the engine in one batch;
- :func:`rule_view` -> :class:`RuleView`: for one input, the fired rules with the memberships
  of their propositions, their DOFs and consequents, and each output's aggregate and result;
- ``overlay.runs_overlay`` -> ``RunsOverlay``: many runs of one world, paths by outcome,
  counts and collisions (``simulate --runs N --plot``; imported from its module, since it
  reads the simulator's outcomes).

Nothing here imports matplotlib or prints.
"""

from __future__ import annotations

from .curves import (
                     CURVE_POINTS,
                     TermCurve,
                     VariablePlot,
                     curve_grid,
                     linear_formula,
                     sheet,
                     termset_inputs,
                     variable_plot,
                     visible,
)
from .ruleviews import (
                     ConsequentView,
                     InputValue,
                     OutputView,
                     PropView,
                     RuleRow,
                     RuleView,
                     props_of,
                     rule_view,
)
from .surfaces import Axis, Fixed, Surface, surface

__all__ = ["CURVE_POINTS", "Axis", "ConsequentView", "Fixed", "InputValue", "OutputView",
           "PropView", "RuleRow", "RuleView", "Surface", "TermCurve", "VariablePlot", "curve_grid",
           "linear_formula", "props_of", "rule_view", "sheet", "surface", "termset_inputs",
           "variable_plot", "visible"]
