"""Where conditions hold, exactly: box algebra over the atoms of the inputs' universes.

``mitos check`` asks where some rule of a composition sets an output, and where a behavior
that another one ``use``s is in use. Sampling the composed input space is out (``drive``
reads 13 inputs: every corner point of their terms would be 9.4e8 samples), but these are
questions about *where a degree is above 0*, and for the conditions the language writes they
have exact answers with no grid:

- Each input's universe is cut at the corner points of its terms (and its ends) into
  *atoms*: the corner points themselves and the open stretches between neighbours. A
  piecewise-linear membership is linear on each stretch, so there it is either 0 all over
  or above 0 all over, and either 1 all over or below 1 all over; a hedge (``very``,
  ``somewhat``, ...) keeps 0 at 0 and 1 at 1 and is monotone, so the same holds for a
  hedged term. A term's "above 0" and "below 1" sets are unions of atoms, read at one point
  of each atom.
- With a T-norm that has no zero divisors (``min``, ``product``, ``einstein``,
  ``hamacher``: ``T(a, b) > 0`` exactly where both are) an ``and`` is above 0 where all its
  items are, an ``or`` (any S-norm) where one is. ``not x`` is above 0 where ``x`` is below
  1; an ``and`` is below 1 where one item is (any T-norm), an ``or`` where all are (for
  S-norms that reach 1 only where an argument does: ``max``, ``probabilistic_sum``,
  ``einstein_sum``, ``hamacher_sum``). A rule's DOF is its condition times its ``use``
  conditions and weights (a product): above 0 where all of them are.

So the set where a condition is above 0 is a union of *cubes*, each a set of atoms per
input, and unions, intersections and differences of such sets are computed exactly
(:func:`subtract` splits a cube by another into at most one piece per input). The volume of
a cube is the product of its atoms' lengths. Only when the input terms are not
piecewise-linear, or the operators are others, or the cubes grow past :data:`MAX_CUBES` (or
the pairs of cubes looked at past :data:`MAX_WORK`), is there no exact answer
(:class:`NotExact`); the caller then samples as before.

Exact is meant of the formulas; in floating point a product of tiny degrees can underflow to 0
and ``a + b - a * b`` round to 1 on a set of no volume, as the engine's own numbers do there.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..fuzzy import hedges as hedge_fns
from ..lang.model import And, Expr, Not, Or, Prop

if TYPE_CHECKING:
    from collections.abc import Iterable, Sequence

    from ..lang.terms import Variable

#: T-norms with no zero divisors: ``T(a, b) > 0`` exactly where ``a > 0`` and ``b > 0``.
EXACT_TNORMS = frozenset({"min", "product", "einstein", "hamacher"})
#: S-norms that reach 1 only where an argument does: ``S(a, b) < 1`` where both are below 1.
EXACT_SNORMS = frozenset({"max", "probabilistic_sum", "einstein_sum", "hamacher_sum"})
#: Most cubes a set may hold before the answer is given up as too costly.
MAX_CUBES = 20_000

#: A set of atoms per input (bit ``a`` of ``cube[i]``: atom ``a`` of input ``i``).
Cube = tuple[int, ...]
#: A box in words: ``((name, lo, hi), ...)`` and which ends are left out, ``((lo?, hi?), ...)``
Ranges = tuple[tuple[tuple[str, float, float], ...], tuple[tuple[bool, bool], ...]]


class NotExact(Exception):
    """The question has no exact answer here (see the module's docstring): sample instead."""


@dataclass(frozen=True)
class Atoms:
    """One input's universe cut at its terms' corner points: atom ``2k`` is the point
    ``corners[k]``, atom ``2k + 1`` the open stretch between ``corners[k]`` and
    ``corners[k + 1]``."""

    name: str
    corners: np.ndarray

    @property
    def count(self) -> int:
        return 2 * len(self.corners) - 1

    @property
    def points(self) -> np.ndarray:
        """One value inside each atom: the corner points and the middles between them."""
        c = self.corners
        out = np.empty(self.count)
        out[0::2] = c
        out[1::2] = 0.5 * (c[:-1] + c[1:])
        return out

    @property
    def lengths(self) -> np.ndarray:
        """Each atom's share of the universe's length (a point's is 0)."""
        out = np.zeros(self.count)
        width = self.corners[-1] - self.corners[0]
        if width > 0:
            out[1::2] = np.diff(self.corners) / width
        elif self.count == 1:
            out[0] = 1.0                   # a universe of one point: all of it
        return out

    def index(self, x: np.ndarray) -> np.ndarray:
        """The atom each value of ``x`` (inside the universe) lies in."""
        right = np.searchsorted(self.corners, x, side="right")     # corners <= x
        on = (right > 0) & (self.corners[np.maximum(right - 1, 0)] == x)
        return np.where(on, 2 * (right - 1), 2 * right - 1).astype(np.intp)


class Space:
    """The input space of a set of variables as atoms, and the sets of its conditions."""

    def __init__(self, variables: Sequence[Variable], corners: Sequence[np.ndarray],
                 tnorm: str, snorm: str) -> None:
        if tnorm not in EXACT_TNORMS or snorm not in EXACT_SNORMS:
            raise NotExact(f"and = {tnorm}, or = {snorm}")
        self.names = tuple(v.name for v in variables)
        self.variables = {v.name: v for v in variables}
        self.atoms = tuple(Atoms(v.name, np.asarray(c, float)) for v, c in zip(variables, corners))
        self.full: Cube = tuple((1 << a.count) - 1 for a in self.atoms)
        self._where = {n: i for i, n in enumerate(self.names)}
        self._props: dict[tuple, tuple[int, int]] = {}

    # -- single propositions ----------------------------------------------------------------
    def _prop_bits(self, var: str, term: str, hedges: tuple[str, ...]) -> tuple[int, int]:
        """The atoms where ``var is [hedges] term`` is above 0, and where it is below 1."""
        key = (var, term, hedges)
        if key not in self._props:
            t = self.variables[var].term(term)
            if t.corners is None:
                raise NotExact(f"`{var}.{term}` is not piecewise linear")
            atoms = self.atoms[self._where[var]]
            with np.errstate(invalid="ignore", divide="ignore"):
                mu = hedge_fns.apply(hedges, np.asarray(t.membership(atoms.points), float))
            self._props[key] = (_bits(mu > 0.0), _bits(mu < 1.0))
        return self._props[key]

    def _cube(self, var: str, bits: int) -> list[Cube]:
        if not bits:
            return []
        i = self._where[var]
        return [self.full[:i] + (bits,) + self.full[i + 1:]]

    # -- conditions -------------------------------------------------------------------------
    def fires(self, expr: Expr | None) -> list[Cube]:
        """The set where ``expr``'s degree is above 0 (everywhere for no condition)."""
        return [self.full] if expr is None else self._set(expr, below_one=False)

    def _set(self, expr: Expr, below_one: bool) -> list[Cube]:
        """Where ``expr`` is above 0 (or, ``below_one``, below 1)."""
        if isinstance(expr, Prop):
            above, below = self._prop_bits(expr.var, expr.term, expr.hedges)
            # `x is not A` = 1 - A: above 0 where A is below 1, below 1 where A is above 0
            return self._cube(expr.var, below if below_one != expr.negated else above)
        if isinstance(expr, Not):
            return self._set(expr.expr, not below_one)
        parts = [self._set(item, below_one) for item in expr.items]
        if isinstance(expr, And) != below_one:       # and above 0, or below 1: all of them
            out = [self.full]
            for p in parts:
                out = intersect(out, p)
            return out
        assert isinstance(expr, And | Or)
        return simplify([c for p in parts for c in p])

    # -- measures and words -----------------------------------------------------------------
    def volume(self, cubes: Iterable[Cube]) -> float:
        """The share of the space's volume of disjoint ``cubes``."""
        lengths = [a.lengths for a in self.atoms]
        total = 0.0
        for cube in cubes:
            v = 1.0
            for bits, ln in zip(cube, lengths):
                v *= float(ln[_members(bits, len(ln))].sum())
            total += v
        return total

    def contains(self, cubes: Sequence[Cube], X: np.ndarray) -> np.ndarray:
        """Which rows of ``X[n, k]`` (values of the space's inputs, in order) lie in
        ``cubes``: one vectorized test per cube."""
        at = [a.index(X[:, i]) for i, a in enumerate(self.atoms)]
        inside = np.zeros(X.shape[0], bool)
        for cube in cubes:
            hit = np.ones(X.shape[0], bool)
            for i, (bits, a) in enumerate(zip(cube, self.atoms)):
                if bits != self.full[i]:
                    hit &= _members(bits, a.count)[at[i]]
            inside |= hit
        return inside

    def boxes(self, cubes: Sequence[Cube]) -> list[Ranges]:
        """``cubes`` as boxes of ranges (a cube whose atoms of one input are not one run
        is several boxes), the largest first; an input a box spans whole is left out. Each
        is ``((name, lo, hi), ...)`` and, range by range, whether each end is left out."""
        out: list[tuple[float, Ranges]] = []
        lengths = [a.lengths for a in self.atoms]
        for cube in merged(cubes):
            per_input = []
            for i, (bits, a) in enumerate(zip(cube, self.atoms)):
                if bits == self.full[i]:
                    continue
                per_input.append([(i, lo, hi) for lo, hi in _runs(bits, a.count)])
            for combo in _product(per_input):
                ranges, ends, v = [], [], 1.0
                for i, lo, hi in combo:
                    c = self.atoms[i].corners
                    ranges.append((self.names[i], float(c[lo // 2]), float(c[(hi + 1) // 2])))
                    ends.append((lo % 2 == 1, hi % 2 == 1))
                    v *= float(lengths[i][lo:hi + 1].sum())
                out.append((v, (tuple(ranges), tuple(ends))))
        out.sort(key=lambda vb: -vb[0])
        return [b for _, b in out]


def _bits(mask: np.ndarray) -> int:
    return sum(1 << int(a) for a in np.flatnonzero(mask))


def _members(bits: int, count: int) -> np.ndarray:
    return np.array([(bits >> a) & 1 for a in range(count)], dtype=bool)


def _runs(bits: int, count: int) -> list[tuple[int, int]]:
    """The runs of neighbouring atoms in ``bits``, as (first, last)."""
    runs, start = [], None
    for a in range(count + 1):
        on = a < count and (bits >> a) & 1
        if on and start is None:
            start = a
        elif not on and start is not None:
            runs.append((start, a - 1))
            start = None
    return runs


def _product(lists: list[list[tuple[int, int, int]]]) -> list[list[tuple[int, int, int]]]:
    out: list[list[tuple[int, int, int]]] = [[]]
    for options in lists:
        out = [prefix + [o] for prefix in out for o in options]
    return out


def _guard(cubes: list[Cube]) -> list[Cube]:
    if len(cubes) > MAX_CUBES:
        raise NotExact(f"more than {MAX_CUBES:,} boxes")
    return cubes


#: Most pairs of cubes one operation may look at (a rule base of thousands of rules in a
#: composition has no exact answer in reasonable time: it is sampled instead).
MAX_WORK = 100_000


def intersect(a: Sequence[Cube], b: Sequence[Cube]) -> list[Cube]:
    """The cubes of ``a`` and ``b``'s intersection (empty ones dropped)."""
    if len(a) * len(b) > MAX_WORK:
        raise NotExact(f"{len(a):,} x {len(b):,} boxes")
    out = []
    for x in a:
        for y in b:
            c = tuple(p & q for p, q in zip(x, y))
            if all(c):
                out.append(c)
    return _guard(simplify(out))


def _minus(e: Cube, d: Cube) -> list[Cube]:
    """``e`` without ``d``: at most one disjoint piece per input."""
    if not all(p & q for p, q in zip(e, d)):
        return [e]
    out = []
    prefix = list(e)
    for i, (p, q) in enumerate(zip(e, d)):
        rest = p & ~q
        if rest:
            piece = list(prefix)
            piece[i] = rest
            out.append(tuple(piece))
        prefix[i] = p & q
    return out


def subtract(a: Sequence[Cube], b: Sequence[Cube]) -> list[Cube]:
    """``a`` (disjoint cubes: :func:`disjoint`) without every cube of ``b``, as disjoint
    cubes."""
    out = list(a)
    work = 0
    joined = 32
    for d in sorted(b, key=_size, reverse=True):      # the large ones first: fewer pieces
        work += len(out)
        if work > MAX_WORK:
            raise NotExact(f"more than {MAX_WORK:,} box differences")
        out = [piece for e in out for piece in _minus(e, d)]
        if len(out) > 2 * joined:      # join pieces that differ in one input (still disjoint),
            out = merged(out, disjoint=True)         # each time they have doubled
            joined = max(32, len(out))
        _guard(out)
        if not out:
            break
    return out


def _size(c: Cube) -> int:
    return sum(bin(p).count("1") for p in c)


def disjoint(cubes: Sequence[Cube]) -> list[Cube]:
    """The same set as disjoint cubes (each cube without those before it)."""
    if len(cubes) ** 2 > MAX_WORK:
        raise NotExact(f"{len(cubes):,} boxes to make disjoint")
    out: list[Cube] = []
    for c in cubes:
        out += subtract([c], out)
        _guard(out)
    return out


def _inside(x: Cube, y: Cube) -> bool:
    return all(p & ~q == 0 for p, q in zip(x, y))


def simplify(cubes: Sequence[Cube]) -> list[Cube]:
    """``cubes`` without duplicates and without cubes inside another."""
    unique = sorted(set(cubes), key=lambda c: -sum(bin(p).count("1") for p in c))
    if len(unique) ** 2 > MAX_WORK:     # too many to compare every two: duplicates only
        return unique
    out: list[Cube] = []
    for c in unique:
        if not any(_inside(c, o) for o in out):
            out.append(c)
    return out


def merged(cubes: Sequence[Cube], disjoint: bool = False) -> list[Cube]:
    """Neighbouring cubes that differ in one input only joined into one (for the words: a
    difference's pieces are many small boxes otherwise). ``disjoint`` cubes stay disjoint,
    and none can lie inside another: no need to look for such."""
    tidy = (lambda c: list(dict.fromkeys(c))) if disjoint else simplify
    out = tidy(cubes)
    changed = True
    while changed:
        changed = False
        k = len(out[0]) if out else 0
        for i in range(k):
            groups: dict[tuple, int] = {}
            for c in out:
                key = c[:i] + c[i + 1:]
                groups[key] = groups.get(key, 0) | c[i]
            if len(groups) < len(out):
                out = tidy([key[:i] + (bits,) + key[i:] for key, bits in groups.items()])
                changed = True
    return out


def project(cubes: Sequence[Cube], keep: Sequence[int]) -> list[Cube]:
    """The cubes' shadow on the inputs ``keep`` (the others may take any value)."""
    return simplify([tuple(c[i] for i in keep) for c in cubes])
