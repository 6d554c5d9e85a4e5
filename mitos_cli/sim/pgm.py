"""A small reader for PGM images (binary ``P5`` and ASCII ``P2``), enough for ROS maps.

``read_pgm(path)`` returns the pixels as ``uint16`` ``[rows, cols]`` (row 0 = top of the image,
as stored) and the maximum value. Errors are :class:`ValueError` with a plain message; the
world loader turns them into a :class:`~mitos_cli.errors.WorldError` at the ``image:`` line.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np

from ..resources import exists
from ..words import plural


def _header(data: bytes, count: int) -> tuple[list[int], int]:
    """The first ``count`` integers after the magic number, skipping ``#`` comments; returns
    them and the offset just past the single whitespace byte that ends the header."""
    values: list[int] = []
    i = 2
    while len(values) < count:
        if i >= len(data):
            raise ValueError("the PGM header is cut short")
        c = data[i:i + 1]
        if c == b"#":
            while i < len(data) and data[i:i + 1] not in (b"\n", b"\r"):
                i += 1
        elif c.isspace():
            i += 1
        else:
            start = i
            while i < len(data) and data[i:i + 1].isdigit():
                i += 1
            if start == i:
                raise ValueError(f"unexpected byte {c!r} in the PGM header")
            if i - start > 18:              # (far past any image read; int() has a limit)
                raise ValueError(f"a number of {i - start:,} digits in the PGM header")
            values.append(int(data[start:i]))
    return values, i + 1


#: the most pixels a map image may have (8,000 x 8,000, far beyond any building): a run peaks at
#: about 50 bytes for each (it was 100 when a 114 KB PNG of 10,000 x 9,500 pixels took 9.7 GB
#: and over a minute before its first tick)
MAX_PIXELS = 8000 * 8000


class TooLarge(ValueError):
    """A map image of more than :data:`MAX_PIXELS` pixels."""


def check_size(width: int, height: int) -> None:
    """Refuse an image of more than :data:`MAX_PIXELS` pixels, before any is decoded."""
    if width * height > MAX_PIXELS:
        raise TooLarge(f"it has {width * height:,} pixels ({width:,} x {height:,}); a map "
                       f"image may have at most {MAX_PIXELS:,}")


class NotPGM(ValueError):
    """A file that does not start as a PGM does (``P5`` or ``P2``)."""


def parse_pgm(data: bytes) -> tuple[np.ndarray, int]:
    magic = data[:2]
    if magic not in (b"P5", b"P2"):
        raise NotPGM("not a PGM image (it does not start with P5 or P2)")
    (width, height, maxval), offset = _header(data, 3)
    if width <= 0 or height <= 0 or not 0 < maxval < 65536:
        raise ValueError(f"bad PGM size {width} x {height} or maximum value {maxval}")
    check_size(width, height)
    if magic == b"P5":
        _check_header_end(data, offset, maxval)
    n = width * height
    depth = 2 if maxval > 255 else 1
    if magic == b"P5" and len(data) - offset < n * depth:   # before allocating anything
        raise ValueError(f"the PGM image holds {(len(data) - offset) // depth:,} of its "
                         f"{plural(n, 'pixel')}")
    if magic == b"P5":
        _check_line_end(data, offset, n * depth)
    if magic == b"P2" and (len(data) - offset + 2) // 2 < n:  # at least "0 " per pixel
        raise ValueError(f"the PGM image is too short for its {plural(n, 'pixel')}")
    if magic == b"P5":
        dtype = np.dtype(">u2") if maxval > 255 else np.dtype("u1")
        # its n pixels only: all the bytes to the end made a 16-bit image followed by a
        # newline NumPy's "buffer size must be a multiple of element size"
        body = np.frombuffer(data, dtype=dtype, count=n, offset=offset)
        if body.size < n:
            raise ValueError(f"the PGM image holds {body.size} of its {plural(n, 'pixel')}")
        pixels = body[:n].astype(np.uint16)
        _within(pixels, maxval, width)
    else:
        pixels = _ascii_pixels(data[offset - 1:])
        if pixels.size < n:
            raise ValueError(f"the PGM image holds {pixels.size} of its {plural(n, 'pixel')}")
        pixels = pixels[:n]
        _within(pixels, maxval, width)
        pixels = pixels.astype(np.uint16)
    return pixels.reshape(height, width), maxval


def _check_header_end(data: bytes, offset: int, maxval: int) -> None:
    """Refuse a binary PGM whose maximum value is followed by anything but the one whitespace
    byte that ends the header: that byte was skipped whatever it was, so a `#` comment right
    after it (``255# made by hand``) had its text read as the first pixels, the map shifted
    without a word (map_server's SDL_image reads it so too; netpbm skips the comment: the file
    is mended, not guessed at); and nothing after it at all was "the image holds -1 of its
    pixels". An ASCII (``P2``) raster skips comments and whitespace: it needs no check."""
    if offset > len(data):
        raise ValueError("the PGM header is cut short: nothing follows its maximum value")
    end = data[offset - 1:offset]
    if end.isspace():
        return
    if end == b"#":
        raise ValueError(f"its maximum value {maxval} is followed by a `#` comment, where one "
                         "whitespace byte ends the header and the pixels begin: put the "
                         "comment on a line of its own, before the maximum value")
    raise ValueError(f"its maximum value {maxval} is followed by the byte 0x{end[0]:02X}, "
                     "where one whitespace byte ends the header and the pixels begin")


def _check_line_end(data: bytes, offset: int, size: int) -> None:
    """Refuse a binary PGM whose header ends in CR LF and whose image holds one byte more
    than its pixels: one whitespace byte ends the header, so its LF was read as the first
    pixel and every pixel came one place late, the map shifted without a word (map_server
    reads it so too: the file is mended, not guessed at)."""
    if data[offset - 1:offset + 1] == b"\r\n" and len(data) - offset == size + 1:
        raise ValueError("its header ends in CR LF (a Windows line end) and its image holds "
                         "one byte more than its pixels: read as the format says, every pixel "
                         "would come one place late, as map_server reads it; write the "
                         "header's line ends as LF")


def _ascii_pixels(raster: bytes) -> np.ndarray:
    """The numbers of an ASCII (``P2``) raster, ``#`` comments skipped as map_server's image
    readers skip them (a comment line in the raster was "something that is not a number");
    the first word that is no number is named."""
    if b"#" in raster:
        raster = re.sub(rb"#[^\r\n]*", b" ", raster)
    words = raster.split()
    try:
        return np.array(words, dtype=np.int64)
    except (ValueError, OverflowError):
        bad = next((i for i, w in enumerate(words) if not w.isdigit() or len(w) > 18), 0)
        shown = words[bad][:20].decode("ascii", "replace") if words else ""
        raise ValueError(f"the ASCII PGM image holds `{shown}` as its pixel {bad + 1:,}, "
                         "which is not a whole number from 0 to its maximum value") from None


def _within(pixels: np.ndarray, maxval: int, width: int) -> None:
    """Refuse a pixel outside ``0..maxval`` (binary or ASCII alike: read as it stands, a
    pixel above the maximum is an occupancy below 0, free, or with ``negate`` a wall). The
    extremes first: the masks of a large image are three of its size."""
    if not pixels.size or pixels.min() >= 0 and pixels.max() <= maxval:
        return
    bad = np.flatnonzero((pixels < 0) | (pixels > maxval))
    if len(bad):
        row, col = divmod(int(bad[0]), width)     # said from 1, as every position is
        raise ValueError(f"the pixel in column {col + 1:,}, row {row + 1:,} (counted from 1 at "
                         f"the top left) is "
                         f"{int(pixels[bad[0]])}, outside 0..{maxval}, the range its header "
                         f"gives ({plural(len(bad), 'such pixel')})")


#: the largest image read (bytes): a 16-bit 8,000 x 8,000 map, far beyond any building
MAX_BYTES = 128 << 20


def read_pgm(path: str | Path) -> tuple[np.ndarray, int]:
    """Pixels ``[rows, cols]`` (top row first, as stored) and the image's maximum value.

    Only regular files are read, and at most :data:`MAX_BYTES` of them (``image: /dev/zero``
    or a FIFO would otherwise be read without end)."""
    path = Path(path)
    if exists(path) and not path.is_file():
        raise ValueError("it is not a regular file")
    with open(path, "rb") as fh:            # (read(n) takes n bytes first: ask for the size)
        data = fh.read(min(os.fstat(fh.fileno()).st_size, MAX_BYTES) + 1)
    if len(data) > MAX_BYTES:
        raise ValueError(f"it is larger than {MAX_BYTES >> 20} MB")
    return parse_pgm(data)
