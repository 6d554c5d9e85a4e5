"""Plane geometry on arrays: segments, rectangles, rays and distances (inches, radians).

Segments are rows ``[x0, y0, x1, y1]``; every function takes whole arrays and loops over
nothing but a handful of fixed things (the four sides of a rectangle), never over beams, walls
or cells.
"""

from __future__ import annotations

import functools
import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

EPS = 1e-9

#: Elements (floats) in one of the largest arrays a batched stage works a block of rows on:
#: 512 kB, so a block's arrays stay in a core's cache (a lockstep batch of hundreds of
#: robots spills them out of it, which costs more than the calls the blocks repeat).
CACHED = 1 << 16


def _clip_ufunc() -> np.ufunc:
    """The ufunc ``np.clip`` calls, to call it without its Python wrapper (NumPy 2 keeps it in
    ``numpy._core.umath``, NumPy 1 in ``numpy.core.umath``)."""
    import importlib

    for name in ("numpy._core.umath", "numpy.core.umath"):
        try:
            return importlib.import_module(name).clip
        except (ImportError, AttributeError):
            continue
    raise ImportError("this NumPy has no clip ufunc")


clip_arrays: np.ufunc = _clip_ufunc()


def rect_corners(cx: ArrayLike, cy: ArrayLike, heading: ArrayLike, length: ArrayLike,
                 width: ArrayLike) -> np.ndarray:
    """Corners ``[..., 4, 2]`` of rectangles centred at (cx, cy), long side along ``heading``
    (rad), counter-clockwise from the rear right corner."""
    cx, cy, heading = np.broadcast_arrays(*(np.asarray(a, float) for a in (cx, cy, heading)))
    c, s = np.cos(heading), np.sin(heading)
    hl = np.asarray(length, float) / 2.0
    hw = np.asarray(width, float) / 2.0
    local = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
    lx = local[:, 0] * hl[..., None] if np.ndim(hl) else local[:, 0] * hl
    ly = local[:, 1] * hw[..., None] if np.ndim(hw) else local[:, 1] * hw
    x = cx[..., None] + c[..., None] * lx - s[..., None] * ly
    y = cy[..., None] + s[..., None] * lx + c[..., None] * ly
    return np.stack([x, y], axis=-1)


def polygon_segments(corners: np.ndarray) -> np.ndarray:
    """Closed polygons ``[..., P, 2]`` -> their sides ``[... * P, 4]``."""
    nxt = corners[..., _following(corners.shape[-2]), :]          # np.roll(-1), cheaper
    return np.concatenate([corners, nxt], axis=-1).reshape(-1, 4)


@functools.cache
def _following(k: int) -> np.ndarray:
    """Index of the next corner of a closed polygon of ``k`` corners."""
    out = (np.arange(k) + 1) % k
    out.flags.writeable = False
    return out


def point_segment_distance(p: np.ndarray, seg: np.ndarray) -> np.ndarray:
    """Distances ``[P, S]`` from points ``[P, 2]`` to segments ``[S, 4]``.

    The x and y arithmetic runs as one ``[..., 2]`` array (each entry is still
    ``dx * ex + dy * ey`` and ``hypot(dx - t ex, dy - t ey)``): half the NumPy calls, which is
    what a few points and segments cost."""
    a = seg[:, :2]
    e = seg[:, 2:] - a                                  # [S, 2] each side's run
    d = p[:, None] - a                                  # [P, S, 2] from its start to the point
    ee = e * e
    ee = np.maximum(ee[:, 0] + ee[:, 1], EPS)
    de = d * e
    t = (de[..., 0] + de[..., 1]) / ee
    clip_arrays(t, 0.0, 1.0, out=t)
    off = d - t[..., None] * e
    return np.hypot(off[..., 0], off[..., 1])


def cross(ax: np.ndarray, ay: np.ndarray, bx: np.ndarray, by: np.ndarray) -> np.ndarray:
    return ax * by - ay * bx


def segments_intersect(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """Whether segments ``A[M, 4]`` and ``B[N, 4]`` cross or touch: ``[M, N]`` booleans."""
    ax0, ay0, ax1, ay1 = (A[:, i, None] for i in range(4))
    bx0, by0, bx1, by1 = (B[None, :, i] for i in range(4))
    d1 = cross(ax1 - ax0, ay1 - ay0, bx0 - ax0, by0 - ay0)
    d2 = cross(ax1 - ax0, ay1 - ay0, bx1 - ax0, by1 - ay0)
    d3 = cross(bx1 - bx0, by1 - by0, ax0 - bx0, ay0 - by0)
    d4 = cross(bx1 - bx0, by1 - by0, ax1 - bx0, ay1 - by0)
    return (d1 * d2 <= 0) & (d3 * d4 <= 0) & ~((d1 == 0) & (d2 == 0) & (d3 == 0) & (d4 == 0))


def segment_distance(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """Distances ``[M, N]`` between segments ``A[M, 4]`` and ``B[N, 4]`` (0 when they cross)."""
    if len(A) == 0 or len(B) == 0:
        return np.full((len(A), len(B)), np.inf)
    d = np.minimum(
        np.minimum(point_segment_distance(A[:, 0:2], B), point_segment_distance(A[:, 2:4], B)),
        np.minimum(point_segment_distance(B[:, 0:2], A), point_segment_distance(B[:, 2:4], A)).T)
    return np.where(segments_intersect(A, B), 0.0, d)


def points_in_polygon(points: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """Whether points ``[P, 2]`` lie inside convex CCW polygons ``[Q, K, 2]``: ``[P, Q]``."""
    a = corners[None]                       # [1, Q, K, 2]
    e = np.roll(corners, -1, axis=1)[None] - a
    d = points[:, None, None, :] - a
    return (cross(e[..., 0], e[..., 1], d[..., 0], d[..., 1]) >= 0).all(axis=-1)  # type: ignore[return-value]


def ray_segments(origin: np.ndarray, dirs: np.ndarray, seg: np.ndarray,
                 max_range: float) -> np.ndarray:
    """Range ``[B]`` along unit directions ``dirs[B, 2]`` from ``origin[2]`` (or ``[B, 2]``) to
    the first of the segments ``seg[N, 4]``, ``max_range`` when none is hit closer."""
    if len(seg) == 0:
        return np.full(len(dirs), max_range)
    return np.minimum(ray_hits(origin, dirs, seg).min(axis=1), max_range)


def ray_hits(origin: np.ndarray, dirs: np.ndarray, seg: np.ndarray) -> np.ndarray:
    """``[B, N]``: how far along each ray segment ``seg[N, 4]`` is hit (``inf`` if not); each
    entry depends on its ray and segment alone."""
    o = np.asarray(origin, float)
    if o.ndim == 1:                 # one origin: [1, N] offsets, broadcast over the beams
        px = seg[None, :, 0] - o[0]
        py = seg[None, :, 1] - o[1]
    else:
        o = np.broadcast_to(o, (len(dirs), 2))
        px = seg[None, :, 0] - o[:, 0, None]
        py = seg[None, :, 1] - o[:, 1, None]
    ex = seg[None, :, 2] - seg[None, :, 0]
    ey = seg[None, :, 3] - seg[None, :, 1]
    dx, dy = dirs[:, 0, None], dirs[:, 1, None]
    denom = cross(dx, dy, ex, ey)
    ok = np.abs(denom) > EPS
    safe = np.where(ok, denom, 1.0)
    t = cross(px, py, ex, ey) / safe
    s = cross(px, py, dx, dy) / safe
    hit = ok & (t >= 0.0) & (s >= 0.0) & (s <= 1.0)
    return np.where(hit, t, np.inf)


def ray_circles(origin: np.ndarray, dirs: np.ndarray, centres: np.ndarray, radii: np.ndarray,
                max_range: float) -> np.ndarray:
    """Range ``[B]`` from ``origin`` (``[2]``, or one per beam ``[B, 2]``) along ``dirs[B, 2]``
    to the first circle it enters."""
    B = len(dirs)
    if len(centres) == 0:
        return np.full(B, max_range)
    o = np.asarray(origin, float)
    if o.ndim == 1:                 # one origin: its offsets from the centres, [C]
        mx, my = o[0] - centres[:, 0], o[1] - centres[:, 1]
    else:
        o = np.broadcast_to(o, (B, 2))
        mx = o[:, 0, None] - centres[None, :, 0]
        my = o[:, 1, None] - centres[None, :, 1]
    # the dot products as np.einsum sums them: from 0, so a sum of -0.0 reads +0.0
    b = mx * dirs[:, 0, None] + my * dirs[:, 1, None] + 0.0                # [B, C]
    c = mx * mx + my * my - radii ** 2
    disc = b * b - c
    root = np.sqrt(np.maximum(disc, 0.0))
    t = np.where(c <= 0.0, 0.0, -b - root)                   # inside: range 0
    hit = (disc >= 0.0) & (t >= 0.0)
    return np.minimum(np.where(hit, t, np.inf).min(axis=1), max_range)


def clip_segment_outside(seg: np.ndarray, rects: np.ndarray, shrink: float = 1e-6) -> list:
    """The pieces of one segment ``[4]`` that lie outside every rectangle ``[Q, 4, 2]``
    (a piece on a rectangle's border counts as outside, so shared walls stay). Each
    rectangle's span along the segment is found for all at once and the spans are merged:
    one rectangle at a time in Python made a polyline of 400 points that doubles back on
    itself (every rectangle meeting every side) take 38 s to load."""
    p0, p1 = seg[:2], seg[2:]
    t0, t1 = _inside_spans(p0, p1, np.asarray(rects, float).reshape(-1, 4, 2), shrink)
    order = np.argsort(t0, kind="stable")
    pieces, a = [], 0.0
    for lo, hi in zip(t0[order].tolist(), t1[order].tolist()):
        if lo > a:
            pieces.append((a, lo))
        a = max(a, hi)
    if a < 1.0:
        pieces.append((a, 1.0))
    length = float(np.hypot(*(p1 - p0)))
    return [np.concatenate([p0 + a * (p1 - p0), p0 + b * (p1 - p0)]) for a, b in pieces
            if (b - a) * length > 1e-6]


def _dots(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row by row ``np.dot(a[i], b[i])``, to the bit (as ``matmul``; a sum of products
    rounds differently, and the walls, so every run, would move in their last bits)."""
    return (a[:, None, :] @ b[:, :, None])[:, 0, 0]


def _inside_spans(p0: np.ndarray, p1: np.ndarray, rects: np.ndarray,
                  shrink: float) -> tuple[np.ndarray, np.ndarray]:
    """``(t0, t1)``: where the segment ``p0 -> p1`` (``t`` from 0 to 1) runs inside each
    rectangle (shrunk by ``shrink``), for those it enters with some length only."""
    centre = rects.mean(axis=1)
    u = rects[:, 1] - rects[:, 0]
    v = rects[:, 3] - rects[:, 0]
    nu, nv = np.sqrt(_dots(u, u)), np.sqrt(_dots(v, v))     # as np.linalg.norm of one
    some = (nu > 0) & (nv > 0)      # a side of no length (a corridor 1e-20 in wide): no inside
    t0, t1 = np.zeros(len(rects)), np.ones(len(rects))
    with np.errstate(divide="ignore", invalid="ignore"):
        for axis, half in ((u / nu[:, None], nu / 2 - shrink), (v / nv[:, None], nv / 2 - shrink)):
            a0 = _dots(p0 - centre, axis)
            da = _dots(np.broadcast_to(p1 - p0, axis.shape), axis)
            along = np.abs(da) >= EPS
            some &= along | (np.abs(a0) < half)
            ta, tb = (-half - a0) / da, (half - a0) / da
            t0 = np.where(along, np.maximum(t0, np.minimum(ta, tb)), t0)
            t1 = np.where(along, np.minimum(t1, np.maximum(ta, tb)), t1)
    some &= t1 > t0
    return t0[some], t1[some]


def box_segment_distance(hl: float, hw: float, seg: np.ndarray) -> np.ndarray:
    """Distances ``[S]`` from the box ``[-hl, hl] x [-hw, hw]`` to segments ``[S, 4]`` given in
    the box's frame (0 when a segment touches or crosses the box)."""
    if len(seg) == 0:
        return np.zeros(0)
    half, points, diagonal = _box(hl, hw)
    # the endpoints' distances to the box: (|x| - hl, |y| - hw) of both ends, at least 0
    q = np.abs(seg) - half
    np.maximum(q, 0.0, out=q)
    ends = np.hypot(q[:, 0::2], q[:, 1::2])                            # [S, 2]
    # the box's corners' distances to the segments, and its centre's
    near = point_segment_distance(points, seg)                          # [5, S]
    d = np.minimum(np.minimum(ends[:, 0], ends[:, 1]), np.minimum.reduce(near[:4], axis=0))
    # a segment can cross the box only if it passes within the box's half diagonal of its
    # centre; clip just those (Liang-Barsky)
    maybe = near[4] <= diagonal
    if not np.count_nonzero(maybe):
        return d
    out = d.copy()
    out[maybe] = _box_crossing(hl, hw, seg[maybe], d[maybe])
    return out


@functools.lru_cache(maxsize=64)
def _box(hl: float, hw: float) -> tuple[np.ndarray, np.ndarray, float]:
    """The box ``[-hl, hl] x [-hw, hw]``: its half sizes as a segment's ``[4]`` (hl, hw, hl,
    hw), its corners (counter-clockwise from the rear right) then its centre ``[5, 2]``, and
    its half diagonal."""
    half = np.array([hl, hw, hl, hw])
    points = np.array([[-hl, -hw], [hl, -hw], [hl, hw], [-hl, hw], [0.0, 0.0]])
    half.flags.writeable = points.flags.writeable = False
    return half, points, math.hypot(hl, hw)


def box_polygon_depth(hl: float, hw: float, poly: np.ndarray) -> np.ndarray:
    """How deep convex polygons ``[P, k, 2]`` (corners in order, in the box's frame; a segment
    when ``k == 2``) reach into the box ``[-hl, hl] x [-hw, hw]``: the length of the shortest
    move that separates them (separating axis theorem), 0 when they only touch or are apart.
    A circle's depth is its radius minus the box's signed distance to its centre, the same
    definition."""
    if len(poly) == 0:
        return np.zeros(0)
    edges = poly[:, _following(poly.shape[1])] - poly                   # [P, k, 2]
    length = np.hypot(edges[..., 0], edges[..., 1])
    normals = np.stack([-edges[..., 1], edges[..., 0]], axis=-1) \
        / np.maximum(length, EPS)[..., None]
    normals[length <= EPS] = (1.0, 0.0)              # a repeated corner adds no new axis
    box_axes = np.broadcast_to(np.eye(2), (len(poly), 2, 2))
    axes = np.concatenate([box_axes, normals], axis=1)                  # [P, A, 2]
    proj = np.einsum("pad,pkd->pak", axes, poly)                        # [P, A, k]
    radius = hl * np.abs(axes[..., 0]) + hw * np.abs(axes[..., 1])      # the box's, [P, A]
    overlap = np.minimum(radius - proj.min(axis=-1), proj.max(axis=-1) + radius)
    return np.maximum(overlap.min(axis=1), 0.0)


def box_polygon_distance(hl: float, hw: float, poly: np.ndarray,
                         side_gaps: np.ndarray | None = None) -> np.ndarray:
    """Signed distances ``[P]`` from the box ``[-hl, hl] x [-hw, hw]`` to convex polygons
    ``[P, k, 2]`` in its frame: the gap when apart, minus the penetration depth
    (:func:`box_polygon_depth`) when they overlap, also when one holds the other whole.

    Two convex shapes overlap only if their sides cross (gap 0) or one holds the other: then
    the box holds the polygon's first corner or the polygon holds the box's centre. Only those
    polygons get the depth computed (the simulator asks this every tick). ``side_gaps``: the
    box's distances to the polygons' sides (:func:`polygon_segments`), when already known."""
    if len(poly) == 0:
        return np.zeros(0)
    if side_gaps is None:
        side_gaps = box_segment_distance(hl, hw, polygon_segments(poly))
    gap = side_gaps.reshape(len(poly), -1).min(axis=1)
    over = polygon_overlaps(hl, hw, poly, gap)
    if not np.count_nonzero(over):
        return gap
    out = gap.copy()
    depth = box_polygon_depth(hl, hw, poly[over])
    out[over] = np.where(depth > 0.0, -depth, gap[over])
    return out
def polygon_overlaps(hl: float, hw: float, poly: np.ndarray, gap: np.ndarray) -> np.ndarray:
    """``[P]``: which convex polygons ``[P, k, 2]`` (in the box's frame, at ``gap [P]`` from
    it when apart) may overlap the box ``[-hl, hl] x [-hw, hw]``: their sides touch it, the
    box holds their first corner, or they hold its centre."""
    x, y = poly[..., 0], poly[..., 1]
    nxt = _following(x.shape[1])
    ex, ey = x[:, nxt] - x, y[:, nxt] - y
    side = x * ey - y * ex                                  # > 0: the centre left of a side
    return ((gap <= 0.0) | ((np.abs(x[:, 0]) <= hl) & (np.abs(y[:, 0]) <= hw))
            | (side >= 0.0).all(axis=1) | (side <= 0.0).all(axis=1))


def _box_crossing(hl: float, hw: float, seg: np.ndarray, d: np.ndarray) -> np.ndarray:
    """``d`` with 0 where the segment crosses the box (Liang-Barsky clipping)."""
    x0, y0, x1, y1 = seg[:, 0], seg[:, 1], seg[:, 2], seg[:, 3]
    dx, dy = x1 - x0, y1 - y0
    with np.errstate(divide="ignore", invalid="ignore"):
        t0 = np.zeros(len(seg))
        t1 = np.ones(len(seg))
        for p, q in ((-dx, x0 + hl), (dx, hl - x0), (-dy, y0 + hw), (dy, hw - y0)):
            r = q / p
            par = p == 0
            t0 = np.where(~par & (p < 0), np.maximum(t0, r), t0)
            t1 = np.where(~par & (p > 0), np.minimum(t1, r), t1)
            t1 = np.where(par & (q < 0), -1.0, t1)
    return np.where(t0 <= t1, 0.0, d)
