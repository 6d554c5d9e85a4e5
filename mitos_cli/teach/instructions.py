"""Corrections in words: a term for a number (``steering is very LM``) and relative
instructions over a window of a recorded run (``make a wider turn``).

Every instruction is a documented transformation (docs/teach.md) of what the behavior did at
each tick of the window into targets, in *term steps*: the crisp terms of an output sorted by
value are the steps of a scale (steering LB 30, LM 50, ..., RB 150), a value between two terms
lies between their steps, and "one term further" moves one step along it (from 67 deg, 0.15
of the way from LS to LM, to 47 deg, 0.15 of the way from LM to LB). The scale's centre is the
point the terms mirror about (steering ST, 90), else the middle of the universe; smaller
steering is to the left (the paper's "90 = straight, < 90 = left").

==============================  ==============================================================
instruction                     targets at each tick of the window
==============================  ==============================================================
``turn harder``                 steering one term further from straight, the way it turned
                                (ticks going straight give no example)
``turn less``                   steering one term back toward straight (never past it)
``make a wider turn``           every tick: the hardest steering of the window, one term
                                further (a sustained turn, not the drift back of Figure 4);
                                refused when ticks turn half a term or more the other way,
                                or when every tick goes straight (within 1 %)
``slow down`` / ``speed up``    speed one term lower / higher
``keep further from the wall``  steering one term away from the nearer side
                                (``gap_left`` / ``gap_right``; equal gaps give no example)
``keep right``                  steering one term to the right
==============================  ==============================================================

Hedges on a crisp term: ``very`` half a term further from the centre, ``extremely`` a whole
term, ``somewhat`` and ``more_or_less`` half a term toward it. Pure functions: the session
turns their targets into examples and shows them.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..errors import LessonError, Span, did_you_mean
from ..lang.interpretability import mirror_point
from ..lang.model import format_number
from ..lang.terms import Variable

#: Term steps each hedge moves a crisp target: + away from the scale's centre, - toward it.
HEDGE_STEPS = {"very": 0.5, "extremely": 1.0, "somewhat": -0.5, "more_or_less": -0.5}
#: Steering closer to the centre than this fraction of the universe counts as going straight.
STRAIGHT = 0.01


@dataclass(frozen=True)
class Scale:
    """The crisp terms of an output as steps: ``values`` increasing, ``centre`` in steps."""

    variable: str
    values: np.ndarray
    names: tuple[str, ...]
    centre: float

    def steps(self, y: np.ndarray) -> np.ndarray:
        return np.interp(y, self.values, np.arange(len(self.values), dtype=float))

    def value(self, u: np.ndarray) -> np.ndarray:
        u = np.clip(u, 0.0, len(self.values) - 1.0)
        return np.interp(u, np.arange(len(self.values), dtype=float), self.values)


def scale_of(var: Variable) -> Scale:
    """The scale of ``var``'s crisp terms (at least two are needed)."""
    pairs = sorted((t.center, t.name) for t in var.terms)
    if len(pairs) < 2:
        raise LessonError(f"`{var.name}` needs at least two terms to move along",
                          hint=f"give it terms, or say the number: `{var.name}=VALUE`")
    values = np.array([v for v, _ in pairs], dtype=float)
    point = mirror_point(var)
    mid = point if point is not None else 0.5 * (var.universe[0] + var.universe[1])
    s = Scale(var.name, values, tuple(n for _, n in pairs), 0.0)
    return Scale(var.name, values, s.names, float(s.steps(np.array(mid))))


def hedged(var: Variable, term: str, hedges: tuple[str, ...]) -> float:
    """The target ``var is HEDGES TERM`` stands for (at most the end of the scale: see
    :func:`past_the_end`)."""
    if not hedges:
        return var.term(term).center
    scale, u = _hedged_steps(var, term, hedges)
    return float(scale.value(np.array(u)))


def past_the_end(var: Variable, term: str, hedges: tuple[str, ...]) -> str | None:
    """The term at the end of the scale when ``HEDGES TERM`` would lie past it (``very LB``,
    ``extremely LB``: the target is LB's value, the furthest the scale goes), else None."""
    if not hedges:
        return None
    scale, u = _hedged_steps(var, term, hedges)
    last = len(scale.values) - 1
    if u < -1e-9:
        return scale.names[0]
    return scale.names[last] if u > last + 1e-9 else None


def at_the_middle(var: Variable, term: str) -> bool:
    """Whether ``term`` stands at the middle of ``var``'s scale, which a hedge moves a target
    away from: ``very ST`` is ST's own value."""
    scale = scale_of(var)
    return abs(float(scale.steps(np.array(var.term(term).center))) - scale.centre) < 1e-9


def not_a_target_hedge(hedge: str, term: str, span: Span | None = None) -> LessonError:
    """The error for a hedge of a rule's condition in a target (`seldom LB`), at ``span``."""
    return LessonError(f"`{hedge} {term}` has no meaning for a target value", span=span,
                       expected="very, extremely, somewhat or more_or_less")


def _hedged_steps(var: Variable, term: str, hedges: tuple[str, ...]) -> tuple[Scale, float]:
    """The scale of ``var`` and where ``HEDGES TERM`` lies on it, in steps (not clipped)."""
    value = var.term(term).center
    scale = scale_of(var)
    u = float(scale.steps(np.array(value)))
    for h in reversed(hedges):                         # the innermost hedge first
        if h not in HEDGE_STEPS:
            raise not_a_target_hedge(h, term)
        away = np.sign(u - scale.centre)
        if HEDGE_STEPS[h] > 0:
            u += away * HEDGE_STEPS[h]
        else:
            u -= away * min(-HEDGE_STEPS[h], abs(u - scale.centre))
    return scale, u


@dataclass(frozen=True)
class Window:
    """What the behavior did at each tick of a window: its outputs and its inputs."""

    outputs: dict            # name -> [n]
    inputs: dict             # name -> [n]
    variables: dict          # name -> Variable


@dataclass(frozen=True)
class Instruction:
    words: str
    output: str
    meaning: str
    targets: Callable[[Scale, Window], np.ndarray]   # [n], NaN: no example at that tick


def _turning(scale: Scale, w: Window) -> np.ndarray:
    var = w.variables[scale.variable]
    width = var.universe[1] - var.universe[0]
    y = w.outputs[scale.variable]
    centre = float(scale.value(np.array(scale.centre)))
    return np.where(np.abs(y - centre) < STRAIGHT * width, 0.0, np.sign(y - centre))


def _harder(scale: Scale, w: Window) -> np.ndarray:
    s = _turning(scale, w)
    u = scale.steps(w.outputs[scale.variable]) + s
    return np.where(s != 0, scale.value(u), np.nan)


def _less(scale: Scale, w: Window) -> np.ndarray:
    u = scale.steps(w.outputs[scale.variable])
    s = np.sign(u - scale.centre)
    return scale.value(u - s * np.minimum(1.0, np.abs(u - scale.centre)))


def _wider(scale: Scale, w: Window) -> np.ndarray:
    u = scale.steps(w.outputs[scale.variable]) - scale.centre
    side = np.sign(np.sum(u))
    if side == 0 or not np.any(_turning(scale, w)):     # straight (within 1 %) at every tick
        var = w.variables[scale.variable]
        tol = STRAIGHT * (var.universe[1] - var.universe[0])
        straight = float(scale.value(np.array(scale.centre)))
        raise LessonError(f"the robot did not turn in that window ({scale.variable} within "
                          f"{tol:g} of {straight:g} at every tick), so there is no turn to widen",
                          hint="name the window of the turn, or say `steering is LM`")
    against = int(np.sum(u * side < -0.5))       # half a term or more the other way
    if against:
        raise LessonError(f"the robot turned both ways in that window ({against} of {len(u)} "
                          f"ticks the other way, by half a term or more); `make a wider turn` "
                          f"widens one turn",
                          hint="name the window of one turn (`mitos simulate WORLD --trace` "
                               "shows the steering at each tick), or say `steering is LM`")
    hardest = float(np.max(u * side))
    return np.full(len(u), float(scale.value(np.array(scale.centre + side * (hardest + 1.0)))))


def _shift(steps: float) -> Callable[[Scale, Window], np.ndarray]:
    def move(scale: Scale, w: Window) -> np.ndarray:
        return scale.value(scale.steps(w.outputs[scale.variable]) + steps)
    return move


def _from_wall(scale: Scale, w: Window) -> np.ndarray:
    missing = [n for n in ("gap_left", "gap_right") if n not in w.inputs]
    if missing:
        raise LessonError("`keep further from the wall` reads the gaps beside the robot, "
                          "and this behavior has no input " + ", ".join(f"`{m}`" for m in missing),
                          hint="use a behavior with inputs gap_left and gap_right (drive)")
    # right: +; equal gaps (150 and 150: no wall in sight) have no nearer side, and gave an
    # example one term to the right
    away = np.sign(w.inputs["gap_right"] - w.inputs["gap_left"])
    if not np.any(away):
        gaps = sorted({format_number(float(g)) for g in w.inputs["gap_left"]})
        raise LessonError("`keep further from the wall`: the gaps beside the robot were equal "
                          "on both sides at every tick of the window (" + ", ".join(gaps[:3])
                          + (", ..." if len(gaps) > 3 else "") + " in), so no wall was nearer "
                          "on one side", hint="name a window where a wall is nearer on one side")
    target = scale.value(scale.steps(w.outputs[scale.variable]) + away)
    return np.where(away != 0, target, np.nan)


INSTRUCTIONS: dict[str, Instruction] = {i.words: i for i in (
    Instruction("turn harder", "steering", "steering one term further from straight, the way "
                "it turned", _harder),
    Instruction("turn less", "steering", "steering one term back toward straight", _less),
    Instruction("make a wider turn", "steering", "the hardest steering of the window, one term "
                "further, at every tick", _wider),
    Instruction("slow down", "speed", "speed one term lower", _shift(-1.0)),
    Instruction("speed up", "speed", "speed one term higher", _shift(1.0)),
    Instruction("keep further from the wall", "steering", "steering one term away from the "
                "nearer side", _from_wall),
    Instruction("keep right", "steering", "steering one term to the right", _shift(1.0)),
)}


def instruction(words: tuple[str, ...]) -> Instruction:
    """The instruction these words name, or a "did you mean" with the list."""
    text = " ".join(words)
    if text in INSTRUCTIONS:
        return INSTRUCTIONS[text]
    close = did_you_mean(text, list(INSTRUCTIONS))
    said = [part.strip() for part in f" {text} ".split(" and ")]
    if len(said) > 1 and all(part in INSTRUCTIONS for part in said):   # `... turn and slow down`
        close = ("one instruction per `at` line: " + ", then ".join(
            f"`at ... {part}`" for part in said) + " (same window)")
    raise LessonError(f"unknown instruction `{text}`",
                      expected="one of " + ", ".join(f"`{k}`" for k in INSTRUCTIONS)
                      + ", or `OUTPUT is TERM`, or `OUTPUT=VALUE`",
                      hint=close or "`help at` (at the prompt) and `mitos docs teach` say what "
                                    "each one does")


def targets(ins: Instruction, window: Window) -> np.ndarray:
    """The targets of ``ins`` at each tick of ``window`` (NaN: no example there)."""
    if ins.output not in window.outputs:
        raise LessonError(f"`{ins.words}` corrects `{ins.output}`, which this behavior does "
                          "not set", expected="outputs " + ", ".join(window.outputs))
    return ins.targets(scale_of(window.variables[ins.output]), window)


__all__ = ["HEDGE_STEPS", "INSTRUCTIONS", "Instruction", "Scale", "Window", "hedged",
           "instruction", "past_the_end", "scale_of", "targets"]
