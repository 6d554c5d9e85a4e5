"""Occupancy grids in the ROS map_server convention (``map.yaml`` + an image).

The YAML names the ``image`` (relative to the YAML), its ``resolution`` in metres per pixel, the
``origin`` ``[x, y, yaw]`` of the lower-left pixel in metres and radians, ``negate``,
``occupied_thresh`` and ``free_thresh``. A pixel's occupancy is ``(255 - v) / 255`` (``v / 255``
with ``negate: 1``); above ``occupied_thresh`` it is occupied, below ``free_thresh`` free, in
between unknown. Unknown counts as occupied unless the world says ``unknown: free``: real SLAM
maps often draw walls in unknown grey. Image rows run top to bottom, so they are flipped to put
row 0 at the bottom. Metres become inches.

The image is a PGM (read here, no dependency) or anything Pillow reads (PNG, BMP, TIFF, ...;
Pillow is the optional extra ``maps``, which matplotlib already brings): a colour
pixel is the mean of its channels, as map_server reads it (:func:`shade`; an alpha channel
averaged in with the colours in the default ``trinary`` mode, as map_server does);
``mode: raw`` reads pixel values (0 to 255) as occupancy percentages (:data:`MODES`).
An origin with a yaw rotates the map about its origin: the grid the simulator keeps is
axis-aligned, so a rotated map is resampled (nearest cell, same resolution) onto the
axis-aligned cells covering it; a quarter, half or three-quarter turn is exact (no
resampling), any other yaw moves walls by at most half a cell's diagonal.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np

from ..errors import MitosError, Span, WorldError, install_hint, unknown
from ..fileio import unreadable
from ..lang import yamlpos
from ..resources import exists
from .pgm import NotPGM, TooLarge, check_size, read_pgm
from .world import Grid
from .worldfile import LARGEST

INCH_PER_M = 1.0 / 0.0254
IMAGE_SUFFIXES = (".pgm", ".png", ".bmp", ".tif", ".tiff", ".jpg", ".jpeg", ".gif", ".ppm")
MAP_KEYS = ("image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh", "mode")
#: m per pixel: the finest resolution taken, a micrometre (ROS maps are centimetres: 0.05).
#: At 1e-30 m a 600-pixel map was narrower than floats tell apart at its origin (its cells
#: all one point, the start "outside the map"), and at 1e-320 the cell lookup overflowed.
FINEST = 1e-6


def _check_extent(spec: yamlpos.YMap, origin: tuple[float, float], res_m: float,
                  shape: tuple[int, ...]) -> None:
    """A map lies where a world's numbers may (within ±``LARGEST`` in): a resolution of
    1e308 m made its cells infinitely wide and the start "inside a wall", and an origin
    beyond it put every point of the world off the map by a number with 300 digits."""
    far = max(abs(v) for v in origin) * INCH_PER_M
    if far > LARGEST:
        raise WorldError(f"the map's origin lies {far:.3g} in away, beyond ±{LARGEST:g} in, "
                         "where a world lies", span=spec.value_span("origin"),
                         hint="the origin is in metres: [-15, -15, 0] puts the map's corner "
                              "15 m left of and below the world's (0, 0)")
    if far + res_m * INCH_PER_M * max(shape) > LARGEST:
        raise WorldError(f"resolution {res_m:g} m per pixel puts the map's far edge beyond "
                         f"±{LARGEST:g} in, where a world lies", span=spec.value_span("resolution"),
                         expected=f"at most {(LARGEST - far) / INCH_PER_M / max(shape):.3g} "
                                  f"(metres per pixel) for this {max(shape)}-pixel image",
                         hint="the resolution is in metres per pixel: 0.05 is 5 cm, as ROS "
                              "maps usually are")


def occupancy(pixels: np.ndarray, maxval: int, negate: bool) -> np.ndarray:
    """Occupancy probability of each pixel in [0, 1] (map_server's trinary reading), as
    map_server computes it: ``(255 - v) / 255``, one rounding. ``1 - v / 255`` rounds twice,
    and a grey 204 read 0.19999999999999996, below a ``free_thresh`` of 0.2 it equals: free
    where map_server's wiki and ``image_loader.cpp`` make it unknown."""
    p = pixels.astype(float)
    return (p if negate else float(maxval) - p) / float(maxval)


#: map_server's modes: ``trinary`` and ``scale`` read a pixel as above (``scale`` grades the
#: cells between the thresholds, which a grid of free and blocked cells cannot hold: they are
#: unknown in both); ``raw`` takes the pixel value, on the scale of 0 to 255 and rounded, as
#: the occupancy in percent (0 free, 100 occupied, above 100 unknown; ``negate`` does not
#: apply), as map_server writes and reads it (:func:`raw_percent`)
MODES = ("trinary", "scale", "raw")


def raw_percent(pixels: np.ndarray, maxval: int) -> np.ndarray:
    """A ``raw`` pixel's occupancy in percent, as ROS 2's map_server reads it
    (``round(shade * 255)``): the value on the scale of 0 to 255, rounded half up. The value
    as it stood made a 16-bit map's 100 % (25,700 of 65,535) unknown, a PGM of maximum 100
    read 100 as occupied where map_server reads 255, unknown, and a colour pixel's mean of
    100.33 was unknown where map_server has 100."""
    return np.floor(pixels / float(maxval) * 255.0 + 0.5)


def classify(pixels: np.ndarray, maxval: int, *, negate: bool, occupied_thresh: float,
             free_thresh: float, unknown_occupied: bool = True,
             mode: str = "trinary") -> np.ndarray:
    """Blocked cells ``[rows, cols]`` with row 0 at the BOTTOM of the map (rows flipped).
    Each pixel value is classified once, in a table looked up for every pixel: a pixel's
    class depends on its value alone, and the float occupancies of a 4,000 x 4,000 image
    took 18 bytes a pixel."""
    pixels = np.asarray(pixels)
    if pixels.dtype.kind == "u" and pixels.size > 1024:
        values = np.arange(int(pixels.max()) + 1, dtype=pixels.dtype)
        table = _blocked(values, maxval, negate, occupied_thresh, free_thresh,
                         unknown_occupied, mode)
        return np.ascontiguousarray(table[pixels[::-1]])
    blocked = _blocked(pixels, maxval, negate, occupied_thresh, free_thresh,
                       unknown_occupied, mode)
    return np.ascontiguousarray(blocked[::-1])


def _blocked(pixels: np.ndarray, maxval: int, negate: bool, occupied_thresh: float,
             free_thresh: float, unknown_occupied: bool, mode: str) -> np.ndarray:
    """Whether each of ``pixels`` is a blocked cell (see :func:`classify`)."""
    if mode == "raw":
        percent = raw_percent(pixels, maxval)
        occ = np.where(percent > 100, np.nan, percent / 100.0)    # NaN: unknown
    else:
        occ = occupancy(pixels, maxval, negate)
    occupied = occ > occupied_thresh
    free = occ < free_thresh
    return occupied | (~free if unknown_occupied else np.zeros_like(occupied))


def _check_thresholds(spec: yamlpos.YMap, occ_t: float, free_t: float) -> None:
    """``0 <= free_thresh <= occupied_thresh <= 1``, refused at the threshold that breaks it
    (an ``occupied_thresh`` of 1.5 was pointed at the ``free_thresh`` line)."""
    for key, value in (("occupied_thresh", occ_t), ("free_thresh", free_t)):
        if not 0 <= value <= 1:
            raise WorldError(f"{key} must lie between 0 and 1, not {value:g}",
                             span=spec.value_span(key),
                             hint="it is an occupancy: 0.65 and 0.196 are map_server's usual")
    if free_t > occ_t:
        key = "free_thresh" if "free_thresh" in spec else "occupied_thresh"
        raise WorldError(f"free_thresh {free_t:g} lies above occupied_thresh {occ_t:g}",
                         span=spec.value_span(key),
                         expected="0 <= free_thresh <= occupied_thresh <= 1")


def _negate(spec: yamlpos.YMap) -> bool:
    """``negate`` as map_server reads it: 0 or 1 (``false``/``true`` too). A quoted ``"0"``
    is a string, which Python would take for true and silently invert the map: refused."""
    value = spec.get("negate", 0)
    if value in (0, 1) and not isinstance(value, float) or isinstance(value, bool):
        return bool(value)
    raise WorldError(f"negate must be 0 or 1, not "
                     f"{yamlpos.as_written(value, spec.value_span('negate'))}",
                     span=spec.value_span("negate"),
                     hint="write `negate: 0` (dark pixels are walls) or `negate: 1`, unquoted")


def shade(pixels: np.ndarray, mode: str = "trinary") -> np.ndarray:
    """Each pixel's value ``[rows, cols]`` as map_server reads it: a grey image's as it is, a
    colour image's (``[rows, cols, channels]``, red, green, blue and alpha) the mean of its
    channels, alpha included in ``trinary`` mode and left out in the others (ROS 1's
    ``image_loader.cpp`` and ROS 2's ``map_io.cpp`` alike). Luminance, as read before, took
    a yellow pixel (occupancy 0.33 there, unknown) for free and a green one (0.67, a wall)
    for unknown."""
    if pixels.ndim == 2:
        return pixels
    if mode != "trinary" and pixels.shape[-1] == 4:
        pixels = pixels[..., :3]
    return pixels.mean(axis=-1)


def _pillow_knows(path: Path) -> bool:
    """Whether Pillow is there and recognises ``path`` as an image (one too large for it
    too: :func:`read_image` refuses it as too large, not as "not a PGM image")."""
    try:
        from PIL import Image
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            Image.open(path).close()
    except ImportError:
        return False
    except Image.DecompressionBombError:
        return True
    except Exception:               # (not an image Pillow knows: the PGM's message)
        return False
    return True


def read_image(path: Path) -> tuple[np.ndarray, int]:
    """Pixels ``[rows, cols]`` (top row first) of a grey map image, ``[rows, cols, channels]``
    of a colour one (red, green, blue, and alpha where it has one: :func:`shade` averages
    them), and the maximum value."""
    if exists(path) and not path.is_file():     # /dev/zero, a FIFO: would read without end
        raise ValueError("it is not a regular file")
    if path.suffix.lower() in (".pgm", ".pnm"):
        try:
            return read_pgm(path)
        except NotPGM:              # a PNG (or a colour PNM) named .pgm, which map_server's
            if not _pillow_knows(path):     # readers tell by its content, not its name
                raise
    try:
        from PIL import Image, UnidentifiedImageError
    except ImportError:
        raise ImportError("reading a map image other than PGM needs Pillow: "
                          f"{install_hint('maps')}, or convert the image to PGM") from None
    try:
        with warnings.catch_warnings():     # (Pillow's own warning of a large image: refused)
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            im = Image.open(path)
        with im:
            check_size(*im.size)
            if im.mode in ("I;16", "I;16B", "I;16L", "I"):
                px = np.asarray(im, dtype=np.int64)
                return px.clip(0, 65535).astype(np.uint16), 65535
            if im.mode in ("1", "L"):
                return np.asarray(im.convert("L"), dtype=np.uint16), 255
            alpha = "A" in im.getbands() or "transparency" in im.info
            return np.asarray(im.convert("RGBA" if alpha else "RGB"), dtype=np.uint16), 255
    except UnidentifiedImageError:
        raise ValueError("Pillow does not recognise it as an image") from None
    except Image.DecompressionBombError as exc:
        raise TooLarge(str(exc)) from None


#: the most cells of a turned map resampled at once (a block of its rows): all at once took
#: about 80 bytes a cell, 10 GB for an 8,000 x 8,000 image turned by 45 degrees
TURN_BLOCK = 1 << 16


def rotate(blocked: np.ndarray, res: float, origin: tuple[float, float],
           yaw: float) -> tuple[np.ndarray, tuple[float, float]]:
    """A map whose lower-left pixel sits at ``origin``, turned by ``yaw`` (rad) about it, as
    axis-aligned cells of the same size: the blocked cells and the new lower-left corner.
    Cells the turned map does not cover are blocked (nothing is known there)."""
    quarter = yaw / (math.pi / 2)
    rows, cols = blocked.shape
    corners = np.array([[0, 0], [cols, 0], [0, rows], [cols, rows]], float) * res
    c, s = math.cos(yaw), math.sin(yaw)
    if abs(quarter - round(quarter)) < 1e-9:
        turns = int(round(quarter)) % 4
        c, s = [(1, 0), (0, 1), (-1, 0), (0, -1)][turns]
        turned = np.rot90(blocked, -turns)      # row 0 at the bottom: a turn to the left
        lo = (corners @ np.array([[c, s], [-s, c]])).min(axis=0)
        return np.ascontiguousarray(turned), (origin[0] + lo[0], origin[1] + lo[1])
    placed = corners @ np.array([[c, s], [-s, c]])
    lo, hi = placed.min(axis=0), placed.max(axis=0)
    ncols, nrows = (int(math.ceil(v / res - 1e-6)) for v in hi - lo)
    out = np.ones((nrows, ncols), dtype=bool)
    px = lo[0] + (np.arange(ncols) + 0.5) * res      # cell centres relative to the origin
    step = max(1, TURN_BLOCK // ncols)
    for r0 in range(0, nrows, step):
        py = lo[1] + (np.arange(r0, min(r0 + step, nrows))[:, None] + 0.5) * res
        mx, my = c * px + s * py, -s * px + c * py     # back into the map's own frame
        col = np.floor(mx / res).astype(np.int64)
        row = np.floor(my / res).astype(np.int64)
        inside = (row >= 0) & (row < rows) & (col >= 0) & (col < cols)
        out[r0:r0 + len(py)][inside] = blocked[row[inside], col[inside]]
    return out, (origin[0] + lo[0], origin[1] + lo[1])


def not_a_path(value: object) -> str:
    """What a YAML value that is no path is, in words: ``a list``, ``a mapping``, ``true``."""
    if isinstance(value, bool):
        return "`true`" if value else "`false`"
    return "a list" if isinstance(value, list) else "a mapping"


def _item_span(value: list, index: int, span: Span) -> Span:
    """Where item ``index`` of a YAML list is written (``half`` of ``[0, 0, half]``, not its
    ``[``); ``span`` where that is not known."""
    return value.item_span(index) if isinstance(value, yamlpos.YList) else span


def _beside(path: Path, written: str | None, exc: OSError | UnicodeDecodeError,
            suffixes: tuple[str, ...]) -> str | None:
    """"did you mean `X`?" for a file that is not there, where one beside it has a name
    close to its own (as a world file's name gets: :func:`.fileio.nearby`), written as the
    file that names it writes the path."""
    from ..fileio import nearby_name

    if not isinstance(exc, FileNotFoundError):
        return None
    name = nearby_name(path, suffixes)
    if name is None:
        return None
    return f"did you mean `{(Path(written).parent if written else path.parent) / name}`?"


def _packaged_map(written: str | None, exc: OSError | UnicodeDecodeError) -> str | None:
    """A packaged world copied elsewhere (`cp worlds/office.yaml mine.yaml`) names its map
    as `maps/mrpb_office02.yaml`, beside the packaged world: said "not found" and no more."""
    from ..resources import data_dir, packaged_path

    if not isinstance(exc, FileNotFoundError) or not written or Path(written).is_absolute():
        return None
    try:
        if not (data_dir("worlds") / written).is_file():
            return None
        full = packaged_path("worlds", written).as_posix()
    except OSError:
        return None
    return (f"a map path is relative to the world file, and `{written}` lies beside the "
            f"packaged worlds: write its full path, `{full}`, or copy that "
            f"`{Path(written).parts[0]}/` folder beside this world file")


def unknown_at(source: str, x: float, y: float) -> bool:
    """Whether the point (in) lies in an unknown cell (grey, between the thresholds) of the
    map file ``source``: blocked as read with unknown cells occupied, free with them free.
    The map is read twice, so only for a refusal's words (a cell of a robot's map may be
    blocked by what is drawn on it, which the map file does not say)."""
    if not source:
        return False
    try:
        strict, lenient = (load_map_yaml(Path(source), unknown_occupied=u) for u in (True, False))
    except MitosError:
        return False
    return _blocked_at(strict, x, y) and not _blocked_at(lenient, x, y)


def _blocked_at(g: Grid, x: float, y: float) -> bool:
    """Whether the point (in) lies in a blocked cell of ``g`` (off it counts as blocked)."""
    col, row = math.floor((x - g.origin[0]) / g.resolution), \
        math.floor((y - g.origin[1]) / g.resolution)
    rows, cols = g.occupied.shape
    return not (0 <= row < rows and 0 <= col < cols) or bool(g.occupied[row, col])


def unknown_words(mapped: str) -> str:
    """How a refusal says a point lies in an unknown cell of ``mapped`` (``the map `m.yaml```)."""
    return (f"lies in an unknown cell of {mapped} (grey, between its free_thresh and "
            "occupied_thresh), which counts as a wall")


def _moved_hint(path: Path, written: str, yaml_dir: Path) -> str:
    """The hint of an absolute image path that is not there: ROS 1's map_saver writes the
    name it was given (``-f`` with an absolute name writes an absolute ``image:``), so a map
    moved to another machine names an image that now lies beside its YAML. It was told the
    path "is relative to the map's YAML file", which it is not."""
    if exists(yaml_dir / path.name) and (yaml_dir / path.name).is_file():
        return (f"did you mean `{path.name}`, beside the map's YAML? It names its image by an "
                f"absolute path, as map_saver writes one: write `image: {path.name}`")
    return "the image path is absolute: it is looked for there, not beside the map's YAML"


def _unread_hint(path: Path, written: str, exc: OSError, yaml_dir: Path) -> str | None:
    """The hint of a map image that could not be read: where it is looked for, where it is
    not there; that it is damaged, where Pillow could not decode it whole (a truncated PNG
    was told "the image path is relative to the map's YAML file")."""
    if isinstance(exc, PermissionError):
        return None
    if exists(path) and path.is_file():
        return "the file is there but its image could not be decoded whole: is it damaged? " \
               "(save it again, as PGM or PNG)"
    if Path(written).is_absolute():
        return _moved_hint(path, written, yaml_dir)
    close = _beside(path, written, exc, IMAGE_SUFFIXES)
    return f"{close} (the image path is relative to the map's YAML file)" if close else \
        "the image path is relative to the map's YAML file"


def load_map_yaml(path: Path, *, unknown_occupied: bool = True,
                  where: Span | None = None, written: str | None = None) -> Grid:
    """Read a map_server ``map.yaml`` and its image into a :class:`Grid` in inches
    (``written``: the path as the world file writes it, for a "did you mean" as it would be
    written there)."""
    spec = _map_spec(path, where, written)
    image = _image_name(spec, f"map file `{path.name}`")
    res_m = _resolution(spec, f"map file `{path.name}`")
    origin_written, (ox, oy, yaw) = _origin(spec, f"map file `{path.name}`")
    negate = _negate(spec)
    mode = _mode(spec)
    occ_t, free_t = (yamlpos.expect_number(spec.get(key, default), spec.value_span(key),
                                           WorldError, key)
                     for key, default in (("occupied_thresh", 0.65), ("free_thresh", 0.196)))
    _check_thresholds(spec, occ_t, free_t)
    pixels, maxval = _map_image(path, spec, image)
    blocked = classify(shade(pixels, mode), maxval, negate=negate, occupied_thresh=occ_t,
                       free_thresh=free_t, unknown_occupied=unknown_occupied, mode=mode)
    _check_extent(spec, (ox, oy), res_m, blocked.shape)
    res, origin = res_m * INCH_PER_M, (ox * INCH_PER_M, oy * INCH_PER_M)
    if abs(math.remainder(yaw, 2 * math.pi)) > 1e-12:
        blocked, origin = rotate(blocked, res, origin, yaw)
    note = _yaw_note(yaw, _item_span(origin_written, 2, spec.value_span("origin")))
    return Grid(blocked, res, origin, str(path), notes=(note,) if note else ())


def _map_spec(path: Path, where: Span | None, written: str | None) -> yamlpos.YMap:
    """The map file's YAML mapping, its keys checked; an image named where the YAML goes, a
    pipe or a device, and a file that is no map_server map are refused (until the file is
    known to be a map file, an error quotes nothing of it: docs/security.md)."""
    from ..fileio import bad_byte, named_yaml, read_text, text_encoding_hint

    if path.suffix.lower() in IMAGE_SUFFIXES:        # the image named where its YAML goes
        beside = [p for p in (path.with_suffix(".yaml"), path.parent / "map.yaml") if exists(p)]
        raise WorldError(f"`{path.name}` is a map image; a map is named by its map_server YAML "
                         f"file (which names the image, its resolution and origin)", span=where,
                         expected="PATH.yaml",
                         hint=f"did you mean `{beside[0]}`?" if beside else
                         "write a YAML beside it: `image: " + path.name + "`, `resolution: 0.05`, "
                         "`origin: [0, 0, 0]`")
    if exists(path) and not path.is_file() and not path.is_dir():
        # a FIFO waited for a writer without end (a world file may name any path)
        raise WorldError(f"map file `{written or path}` is not a regular file (a pipe or a "
                         "device)", span=where, expected="PATH.yaml, a map_server map file")
    try:
        text = read_text(path)
    except (OSError, UnicodeDecodeError) as exc:
        raise WorldError(unreadable("map file", path, exc), span=bad_byte(path, exc) or where,
                         hint=text_encoding_hint(exc)
                         or _beside(path, written, exc, (".yaml", ".yml"))
                         or _packaged_map(written, exc)) from None
    named = named_yaml(path)
    try:
        spec = yamlpos.load(text, str(path), WorldError)
    except WorldError:
        if named:
            raise
        spec = None
    if not named and not (isinstance(spec, dict) and "image" in spec):
        raise WorldError(f"`{path}` is not a map_server map file", span=Span(str(path), 1, 1),
                         expected="a YAML file with `image:` and `resolution:`") from None
    spec = yamlpos.expect_map(spec, Span(str(path), 1, 1), WorldError, "a map file")
    yamlpos.check_keys(spec, MAP_KEYS, WorldError, "a map_server map file")
    return spec


def _image_name(spec: yamlpos.YMap, what: str) -> object:     # the YAML value, a path's text
    """The image's path as the map file writes it (an empty `image:` was "map image `None`
    not found")."""
    image = yamlpos.require(spec, "image", WorldError, what)
    if image is None or isinstance(image, (list, dict, bool)) or not str(image).strip():
        raise WorldError("`image` in a map file " + ("is empty" if image is None or
                                                      isinstance(image, str) else
                                                      f"must be a path, not {not_a_path(image)}"),
                         span=spec.value_span("image"), expected="the image's path, such as "
                         "map.pgm (relative to this YAML file)")
    return image


def _resolution(spec: yamlpos.YMap, what: str) -> float:
    """Metres per pixel: positive, and no finer than :data:`FINEST`."""
    res_m = yamlpos.expect_number(yamlpos.require(spec, "resolution", WorldError, what),
                                  spec.value_span("resolution"), WorldError, "resolution")
    if res_m <= 0:
        raise WorldError("resolution must be positive (metres per pixel)",
                         span=spec.value_span("resolution"))
    if res_m < FINEST:
        raise WorldError(f"resolution {res_m:.3g} m per pixel is finer than a micrometre",
                         span=spec.value_span("resolution"),
                         expected=f"at least {FINEST:g} (metres per pixel)",
                         hint="the resolution is in metres per pixel: 0.05 is 5 cm, as ROS "
                              "maps usually are")
    return res_m


def _origin(spec: yamlpos.YMap, what: str) -> tuple[list, tuple[float, float, float]]:
    """The origin as written and as ``(x, y, yaw)`` (metres, metres, radians)."""
    written = yamlpos.require(spec, "origin", WorldError, what)
    if not isinstance(written, list) or len(written) != 3:
        raise WorldError("origin must be [x, y, yaw] (metres, metres, radians)",
                         span=spec.value_span("origin"))
    ox, oy, yaw = (yamlpos.expect_number(v, _item_span(written, i, spec.value_span("origin")),
                                         WorldError, "origin")
                   for i, v in enumerate(written))
    if abs(yaw) > LARGEST:                          # 1e300 read as an exact quarter turn, 0
        raise WorldError(f"the origin's yaw must be within ±{LARGEST:g} (radians), not {yaw:g}",
                         span=_item_span(written, 2, spec.value_span("origin")),
                         hint="the yaw is in radians: 3.14 is a half turn")
    return written, (ox, oy, yaw)


def _mode(spec: yamlpos.YMap) -> str:
    """map_server's ``mode`` (trinary when left out)."""
    mode = spec.get("mode", "trinary")
    if mode is None:                                         # read "unknown mode `None`"
        raise WorldError("`mode` in a map file is empty", span=spec.value_span("mode"),
                         expected="one of " + ", ".join(MODES),
                         hint="leave `mode` out for trinary, map_server's default")
    if mode not in MODES:
        raise unknown("map_server mode", str(mode), MODES, span=spec.value_span("mode"),
                      cls=WorldError)
    return mode


def _map_image(path: Path, spec: yamlpos.YMap, image: object) -> tuple[np.ndarray, int]:
    """The image's pixels and maxval, each way of failing said at the map file's `image:`."""
    image_path = path.parent / str(image)
    try:
        return read_image(image_path)
    except ImportError as exc:
        raise WorldError(f"cannot read map image `{image_path}`: {exc}",
                         span=spec.value_span("image")) from None
    except OSError as exc:
        raise WorldError(unreadable("map image", image_path, exc), span=spec.value_span("image"),
                         hint=_unread_hint(image_path, str(image), exc, path.parent)) from None
    except TooLarge as exc:
        raise WorldError(f"cannot read map image `{image_path}`: {exc}",
                         span=spec.value_span("image"),
                         hint="crop the image to the part the robot drives in") from None
    except ValueError as exc:
        raise WorldError(f"cannot read map image `{image_path}`: {exc}",
                         span=spec.value_span("image"),
                         hint="give a PGM (P5 or P2) or an image Pillow reads (PNG)") from None


def _yaw_note(yaw: float, span: Span) -> str | None:
    """A warning for a yaw past a whole turn: map_server's is in radians (map_saver writes
    it within ±pi), so ``origin: [0, 0, 90]`` is likely 90 degrees, and turned the map by
    90 rad (5,157 degrees: 116.6 past 14 turns) without a word."""
    if abs(yaw) <= 2 * math.pi:
        return None
    return (f"{span}: the origin's yaw {yaw:g} is in radians and turns the map by "
            f"{math.degrees(math.remainder(yaw, 2 * math.pi)):.4g} degrees (a yaw past a whole "
            f"turn is likely degrees: {yaw:g} degrees is {math.radians(yaw):.6g} rad)")
