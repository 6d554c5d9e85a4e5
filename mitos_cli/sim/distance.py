"""Exact Euclidean distance transform of a boolean grid, in pure NumPy.

Felzenszwalb and Huttenlocher, "Distance Transforms of Sampled Functions" (Theory of
Computing 8, 2012): the squared distance is separable, so one pass of the 1-D lower envelope of
parabolas along the columns and one along the rows give the exact distance from every cell
centre to the nearest set cell's centre. Each pass runs the envelope over all lines of the grid
at once (the Python loop is over the cells of one line, not over lines). Routes need
distances only up to a few feet: :func:`distance_transform` with a ``cap`` takes the exact
column distances and the minimum over the row offsets within the cap, all array operations
(a 600 x 600 map in tens of milliseconds).
"""

from __future__ import annotations

import math

import numpy as np

_FAR = 1e20     # squared distance standing for "no set cell on this line"


def _envelope(f: np.ndarray) -> np.ndarray:
    """1-D squared-distance transform of every row of ``f[L, n]`` (FH's algorithm, vectorised
    over the rows): ``d[l, q] = min_p (q - p)^2 + f[l, p]``."""
    L, n = f.shape
    rows = np.arange(L)
    v = np.zeros((L, n), dtype=np.int64)          # parabola apexes of the lower envelope
    z = np.full((L, n + 1), np.inf)               # boundaries between them
    z[:, 0] = -np.inf
    k = np.zeros(L, dtype=np.int64)
    for q in range(1, n):
        fq = f[:, q]
        while True:
            p = v[rows, k]
            s = ((fq + q * q) - (f[rows, p] + p * p)) / (2.0 * (q - p))
            pop = (s <= z[rows, k]) & (k > 0)
            if not pop.any():
                break
            k = np.where(pop, k - 1, k)
        p = v[rows, k]
        s = ((fq + q * q) - (f[rows, p] + p * p)) / (2.0 * (q - p))
        k = k + 1
        v[rows, k] = q
        z[rows, k] = s
        z[rows, k + 1] = np.inf
    d = np.empty((L, n))
    k = np.zeros(L, dtype=np.int64)
    for q in range(n):
        while True:
            step = z[rows, k + 1] < q
            if not step.any():
                break
            k = k + step
        p = v[rows, k]
        d[:, q] = (q - p) ** 2 + f[rows, p]
    return d


def _capped(blocked: np.ndarray, cap: int,
            part: tuple[int, int, int, int] | None = None) -> np.ndarray:
    """:func:`_capped_squares` as float64 (the same numbers)."""
    return _capped_squares(blocked, cap, part).astype(np.float64)


def _capped_squares(blocked: np.ndarray, cap: int,
                    part: tuple[int, int, int, int] | None = None) -> np.ndarray:
    """Exact squared distances up to ``cap`` cells (larger ones read ``cap**2`` or more): the
    column distances, then the minimum over row offsets within the cap, all as array shifts.
    ``part``: only rows ``r0:r1`` and columns ``c0:c1`` of the answer (each cell's minimum is
    its own, so the bits of the whole). The squares are small whole numbers, worked out and
    given in the narrowest integers that hold them (uint16 up to a cap of 180 cells: a
    quarter of float64's memory and traffic on a large map). The shifts stop once ``dc**2``
    reaches the largest square left (looked at every few shifts): a shifted square is at
    least ``dc**2``, so no further one lowers a cell (in a corridor some 20 cells from its
    walls, a cap of 28 cells is done after 20 shifts)."""
    far = cap + 1
    kind = np.uint16 if far * far + cap * cap <= np.iinfo(np.uint16).max else np.int64
    g = np.minimum(_column_steps(blocked, far), far).astype(kind)
    g *= g
    rows, cols = g.shape
    r0, r1, c0, c1 = (0, rows, 0, cols) if part is None else part
    padded = np.full((r1 - r0, cols + 2 * cap), far * far, dtype=kind)
    padded[:, cap:cap + cols] = g[r0:r1]
    d = g[r0:r1, c0:c1].copy()
    shifted = np.empty_like(d)
    most = int(np.maximum.reduce(d, axis=None)) if d.size else 0
    for dc in range(1, cap + 1):
        if dc * dc >= most:
            break
        for start in (cap + dc, cap - dc):
            np.add(padded[:, start + c0:start + c1], kind(dc * dc), out=shifted)
            np.minimum(d, shifted, out=d)
        if dc % 4 == 0:
            most = int(np.maximum.reduce(d, axis=None))
    return d


def _column_steps(blocked: np.ndarray, far: int) -> np.ndarray:
    """Cells along each column to the nearest blocked cell, as whole numbers (``far`` or
    more where it is ``far`` or more away, or there is none)."""
    n = blocked.shape[0]
    kind = np.int32 if n + far < np.iinfo(np.int32).max else np.int64
    idx = np.arange(n, dtype=kind)[:, None]
    above = np.maximum.accumulate(np.where(blocked, idx, kind(-far)), axis=0)
    below = np.minimum.accumulate(np.where(blocked, idx, kind(n + far))[::-1], axis=0)[::-1]
    return np.minimum(idx - above, below - idx)


def distance_transform(blocked: np.ndarray, spacing: float = 1.0,
                       cap: float | None = None) -> np.ndarray:
    """Euclidean distance from each cell centre to the nearest ``blocked`` cell centre, times
    ``spacing`` (0 on blocked cells; ``inf`` everywhere when nothing is blocked). With ``cap``
    (same unit), distances are exact up to the cap and read at least the cap beyond it: a
    route needs no more, and the capped transform is all array operations."""
    return from_squares(squared_distances(blocked, spacing, cap), spacing)


def squared_distances(blocked: np.ndarray, spacing: float = 1.0,
                      cap: float | None = None) -> np.ndarray:
    """What :func:`distance_transform` takes the square root of: squared distances in cells,
    whole numbers (narrow integers when capped, float64 otherwise; ``inf`` everywhere when
    nothing is blocked). A field kept as these takes 2 bytes a cell, not 8."""
    blocked = np.asarray(blocked, dtype=bool)
    if not blocked.any():
        return np.full(blocked.shape, np.inf)
    if cap is not None:
        n = int(math.ceil(cap / spacing))
        if n < max(blocked.shape):
            return _capped_squares(blocked, n)
    f = np.where(blocked, 0.0, _FAR)
    return np.minimum(_envelope(_envelope(f.T).T), _FAR)       # columns, then rows


def from_squares(squares: np.ndarray, spacing: float) -> np.ndarray:
    """The distances of :func:`squared_distances`' ``squares`` (any part of them), times
    ``spacing``: ``sqrt(s) * spacing`` in float64. It never falls as ``s`` grows, so the
    distance of the least square is the least distance, bit for bit."""
    return np.sqrt(np.asarray(squares, dtype=np.float64)) * spacing
