"""The paper's fuzzy neuron (Sec. 3, eqs. 1-11) as a small vectorized function.

A neuron with inputs ``x_1 .. x_n`` in [0, 1]:

1. **synapses** (eqs. 4-6): each input is weighted by ``w_i`` in [0, 1], either by product,
   ``d_i = x_i * w_i`` (identity weight 1), or by max, ``d_i = x_i v w_i`` (identity weight 0);
2. **excitatory or inhibitory inputs** (eqs. 8-9): an inhibitory input enters as ``1 - d_i``;
3. **aggregation** (eq. 7): a T-norm (an AND neuron) or an S-norm (an OR neuron) folds the
   inputs, ``I = T(d_1, ..., d_n)``;
4. **activation** (eqs. 10-11): a linguistic modifier, ``y = Phi(I)``: identity (the simplified
   neuron), VERY = ``I^2``, MORE-OR-LESS = ``sqrt(I)`` (the hedges of :mod:`mitos_cli.fuzzy.hedges`).

Inputs stack on the last axis, so one call evaluates a neuron for a whole batch, and
``neuron(X[:, None, :], weights=W)`` with ``W[units, n]`` a whole layer. The compiled rule base
(:mod:`mitos_cli.engine.compile`) is a network of exactly these neurons with unit weights: membership
neurons, hedge neurons (activations), ``not`` (inhibitory inputs), AND and OR neurons; the
folds run in the same order, so the values agree bit for bit (tests/test_neurons.py).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from . import hedges as hedge_mod
from . import norms

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

SYNAPSES: dict[str, tuple[Callable[..., np.ndarray], float, str]] = {
    "product": (np.multiply, 1.0, "d = x * w (eq. 5)"),
    "max": (np.maximum, 0.0, "d = x v w = max(x, w) (eq. 6)"),
}
ACTIVATIONS = {"identity": ()} | {name: (name,) for name in hedge_mod.HEDGES}


def aggregation_norm(name: str | norms.Norm) -> norms.Norm:
    """A T-norm or S-norm by name or alias (their names do not overlap)."""
    if isinstance(name, norms.Norm):
        return name
    for kind in ("tnorm", "snorm"):
        try:
            return norms.lookup(kind, name)
        except KeyError:
            pass
    raise KeyError(name)


def activation_hedges(activation: str | tuple[str, ...]) -> tuple[str, ...]:
    """``"identity"``, a hedge name (``"very"``) or hedges left to right (``("very", "very")``)."""
    if isinstance(activation, str):
        if activation not in ACTIVATIONS:
            raise KeyError(activation)
        return ACTIVATIONS[activation]
    for h in activation:
        if h not in hedge_mod.HEDGES:
            raise KeyError(h)
    return tuple(activation)


def synapse(x: ArrayLike, w: ArrayLike, kind: str = "product") -> np.ndarray:
    """Synaptic weighting ``d = w(x)`` (eqs. 4-6): product ``x * w`` or max ``x v w``."""
    fn, _, _ = SYNAPSES[kind]
    return fn(np.asarray(x, dtype=float), np.asarray(w, dtype=float))


def neuron(x: ArrayLike, *, norm: str | norms.Norm = "min", weights: ArrayLike | None = None,
           synapse_kind: str = "product", inhibitory: ArrayLike | None = None,
           activation: str | tuple[str, ...] = "identity") -> np.ndarray:
    """One fuzzy neuron (or a layer, by broadcasting) on inputs ``x[..., n]``.

    ``norm`` names the aggregation: a T-norm makes an AND neuron, an S-norm an OR neuron.
    ``weights`` broadcast against ``x`` (default: the synapse's identity, so inputs pass
    unchanged); ``inhibitory[n]`` marks inputs that enter as ``1 - d``; ``activation`` is the
    linguistic modifier applied to the aggregate. Returns ``y[...]``.
    """
    x = np.asarray(x, dtype=float)
    aggregation = aggregation_norm(norm)
    if weights is not None:
        x = synapse(x, weights, synapse_kind)
    elif synapse_kind not in SYNAPSES:
        raise KeyError(synapse_kind)
    if inhibitory is not None:
        mask = np.asarray(inhibitory, dtype=bool)
        x = np.where(mask, 1.0 - x, x)
    total = norms.reduce(aggregation, x, axis=-1)
    return hedge_mod.apply(activation_hedges(activation), total)


def negation(x: ArrayLike) -> np.ndarray:
    """The negating neuron of Fig. 3(b): one inhibitory input, identity activation."""
    x = np.asarray(x, dtype=float)
    return neuron(x[..., None], norm="min", inhibitory=[True])


def snorm_from_tnorm(x: ArrayLike, tnorm: str | norms.Norm) -> np.ndarray:
    """Fig. 3(b): an OR neuron built from AND neurons, ``S(x) = 1 - T(1 - x_1, ..., 1 - x_n)``:
    a T-norm neuron whose inputs are all inhibitory, followed by a negating neuron."""
    x = np.asarray(x, dtype=float)
    inner = neuron(x, norm=tnorm, inhibitory=np.ones(x.shape[-1], dtype=bool))
    return negation(inner)
