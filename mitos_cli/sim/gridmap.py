"""Occupancy grids in the ROS map_server convention (``map.yaml`` + PGM image).

The YAML names the ``image`` (relative to the YAML), its ``resolution`` in metres per pixel, the
``origin`` ``[x, y, yaw]`` of the lower-left pixel in metres and radians, ``negate``,
``occupied_thresh`` and ``free_thresh``. A pixel's occupancy is ``(255 - v) / 255`` (``v / 255``
with ``negate: 1``); above ``occupied_thresh`` it is occupied, below ``free_thresh`` free, in
between unknown. Unknown counts as occupied unless the world says ``unknown: free``: real SLAM
maps often draw walls in unknown grey. Image rows run top to bottom, so they are flipped to put
row 0 at the bottom. Metres become inches. A rotated origin (yaw not 0) is refused: turn the
image instead.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..lang import yamlpos
from ..errors import Span, WorldError
from .pgm import read_pgm
from .world import Grid

INCH_PER_M = 1.0 / 0.0254
MAP_KEYS = ("image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh", "mode")


def occupancy(pixels: np.ndarray, maxval: int, negate: bool) -> np.ndarray:
    """Occupancy probability of each pixel in [0, 1] (map_server's trinary reading)."""
    p = pixels.astype(float) / float(maxval)
    return p if negate else 1.0 - p


def classify(pixels: np.ndarray, maxval: int, *, negate: bool, occupied_thresh: float,
             free_thresh: float, unknown_occupied: bool = True) -> np.ndarray:
    """Blocked cells ``[rows, cols]`` with row 0 at the BOTTOM of the map (rows flipped)."""
    occ = occupancy(pixels, maxval, negate)
    occupied = occ > occupied_thresh
    free = occ < free_thresh
    blocked = occupied | (~free if unknown_occupied else np.zeros_like(occupied))
    return np.ascontiguousarray(blocked[::-1])


def load_map_yaml(path: Path, *, unknown_occupied: bool = True,
                  where: Span | None = None) -> Grid:
    """Read a map_server ``map.yaml`` and its image into a :class:`Grid` in inches."""
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise WorldError(f"cannot read map file `{path}`: "
                         f"{getattr(exc, 'strerror', None) or exc}", span=where) from None
    spec = yamlpos.load(text, str(path), WorldError)
    spec = yamlpos.expect_map(spec, Span(str(path), 1, 1), WorldError, "a map file")
    yamlpos.check_keys(spec, MAP_KEYS, WorldError, "a map_server map file")
    what = f"map file `{path.name}`"
    image = yamlpos.require(spec, "image", WorldError, what)
    res_m = yamlpos.expect_number(yamlpos.require(spec, "resolution", WorldError, what),
                                  spec.value_span("resolution"), WorldError, "resolution")
    if res_m <= 0:
        raise WorldError("resolution must be positive (metres per pixel)",
                         span=spec.value_span("resolution"))
    origin = yamlpos.require(spec, "origin", WorldError, what)
    if not isinstance(origin, list) or len(origin) != 3:
        raise WorldError("origin must be [x, y, yaw] (metres, metres, radians)",
                         span=spec.value_span("origin"))
    ox, oy, yaw = (yamlpos.expect_number(v, spec.value_span("origin"), WorldError, "origin")
                   for v in origin)
    if abs(math.remainder(yaw, 2 * math.pi)) > 1e-9:
        raise WorldError(f"the map's origin is rotated (yaw {yaw:g} rad); rotated maps are not "
                         f"supported", span=spec.value_span("origin"),
                         hint="rotate the image so that the yaw is 0, and adjust x and y")
    negate = bool(spec.get("negate", 0))
    occ_t = float(spec.get("occupied_thresh", 0.65))
    free_t = float(spec.get("free_thresh", 0.196))
    if not 0 <= free_t <= occ_t <= 1:
        raise WorldError("need 0 <= free_thresh <= occupied_thresh <= 1",
                         span=spec.value_span("free_thresh"))
    image_path = path.parent / str(image)
    try:
        pixels, maxval = read_pgm(image_path)
    except OSError as exc:
        raise WorldError(f"cannot read map image `{image_path}`: {exc.strerror or exc}",
                         span=spec.value_span("image"),
                         hint="the image path is relative to the map's YAML file") from None
    except ValueError as exc:
        raise WorldError(f"cannot read map image `{image_path}`: {exc}",
                         span=spec.value_span("image"),
                         hint="give a PGM image (P5 or P2)") from None
    blocked = classify(pixels, maxval, negate=negate, occupied_thresh=occ_t,
                       free_thresh=free_t, unknown_occupied=unknown_occupied)
    return Grid(blocked, res_m * INCH_PER_M, (ox * INCH_PER_M, oy * INCH_PER_M), str(path))
