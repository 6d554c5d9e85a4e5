"""PGM images and ROS map_server maps: rows flipped, origin, thresholds, negate, unknown."""

from __future__ import annotations

import struct
import warnings
import zlib
from pathlib import Path

import numpy as np
import pytest

from mitos_cli.errors import WorldError
from mitos_cli.sim.gridmap import INCH_PER_M, classify, load_map_yaml
from mitos_cli.sim.pgm import parse_pgm
from mitos_cli.sim.worldfile import load_world

# a 3 x 2 image, top row first: white (free), grey (unknown), black (occupied)
PIXELS = [254, 254, 205, 205, 0, 0]


def test_binary_pgm_with_a_comment():
    data = b"P5\n# made by hand\n2 3\n255\n" + bytes(PIXELS)
    px, maxval = parse_pgm(data)
    assert maxval == 255 and px.tolist() == [[254, 254], [205, 205], [0, 0]]


def test_ascii_pgm():
    px, _ = parse_pgm(b"P2 2 3 255 " + " ".join(map(str, PIXELS)).encode())
    assert px[2].tolist() == [0, 0]



def test_an_ascii_pgm_with_comments_in_its_raster_reads_as_map_server_reads_it():
    """map_server's image readers skip a `#` comment among an ASCII PGM's pixels; it was
    "something that is not a number", and a word that is none is now named."""
    px, _ = parse_pgm(b"P2\n2 3\n255\n254 254\n# the grey row\n205 205 # unknown\n0 0\n")
    assert px.tolist() == [[254, 254], [205, 205], [0, 0]]
    with pytest.raises(ValueError, match="holds `x` as its pixel 3, which is not a whole number"):
        parse_pgm(b"P2 2 3 255 254 254 x 205 0 0")


def test_a_comment_after_an_ascii_pgms_maximum_value_is_skipped_as_in_its_raster():
    """Only a binary PGM's pixels start at the byte after the maximum value."""
    px, _ = parse_pgm(b"P2\n2 1\n255# made by hand\n0 255\n")
    assert px.tolist() == [[0, 255]]


def test_sixteen_bit_pgm():
    px, maxval = parse_pgm(b"P5 1 2 65535\n" + bytes([0xFF, 0xFF, 0x00, 0x01]))
    assert maxval == 65535 and px.ravel().tolist() == [65535, 1]



def test_a_sixteen_bit_pgm_followed_by_a_newline_reads_as_an_eight_bit_one_does():
    """An 8-bit PGM with a byte after its pixels (a writer's last newline) read; a 16-bit one
    was refused with NumPy's "buffer size must be a multiple of element size"."""
    px, maxval = parse_pgm(b"P5 1 2 65535\n" + bytes([0xFF, 0xFF, 0x00, 0x01]) + b"\n")
    assert maxval == 65535 and px.ravel().tolist() == [65535, 1]


def test_a_binary_pgm_whose_header_ends_in_cr_lf_is_refused_not_shifted():
    """A header written with CR LF line ends: one whitespace byte ends it, so its LF was read
    as the first pixel, every pixel one place late, the last one left over, and the map
    loaded shifted without a word. The same pixels after an LF header read as they are."""
    with pytest.raises(ValueError, match="its header ends in CR LF .* one place late"):
        parse_pgm(b"P5\r\n2 3\r\n255\r\n" + bytes(PIXELS))
    px, _ = parse_pgm(b"P5\n2 3\n255\n" + bytes(PIXELS))
    assert px.ravel().tolist() == PIXELS


@pytest.mark.parametrize("data, words", [
    (b"P6 1 1 255\n\x00\x00\x00", "not a PGM"),
    (b"P5 2 2 255\n\x00", "holds 1 of its 4 pixels"),
    (b"P5 2", "cut short"),
    (b"P2 1 1 255 300", "outside 0..255"),
    # a binary pixel above the header's maximum was read as it stood: an occupancy below 0
    (b"P5 2 1 100\n\x00\xfe", r"column 2, row 1 \(counted from 1 at the top left\) is 254, "
                                 "outside 0..100"),
    (b"P5\n" + b"9" * 5000 + b" 1\n255\n\x00", "a number of 5,000 digits"),
    # the byte after the maximum value was skipped whatever it was: a comment's text became
    # the first pixels (here 0x63 `c`, 0x0A), the map shifted; nothing there, "holds -1"
    (b"P5\n2 1\n255#c\n\x00\xff", "255 is followed by a `#` comment, where one whitespace "
                                     "byte ends the header"),
    (b"P5\n2 1\n255x\x00\xff", "followed by the byte 0x78"),
    (b"P5\n2 1\n255", "cut short: nothing follows its maximum value"),
])
def test_broken_pgms_are_refused_in_words(data, words):
    with pytest.raises(ValueError, match=words):
        parse_pgm(data)


def test_rows_are_flipped_and_thresholds_applied():
    px = np.array(PIXELS).reshape(3, 2)
    blocked = classify(px, 255, negate=False, occupied_thresh=0.65, free_thresh=0.196)
    # row 0 is now the BOTTOM of the map: the black row
    assert blocked.tolist() == [[True, True], [True, True], [False, False]]
    lenient = classify(px, 255, negate=False, occupied_thresh=0.65, free_thresh=0.196,
                       unknown_occupied=False)
    assert lenient.tolist() == [[True, True], [False, False], [False, False]]


@pytest.mark.parametrize("mode", ["trinary", "scale", "raw"])
@pytest.mark.parametrize("maxval", [255, 1000, 65535])
def test_a_large_image_classified_through_a_table_is_classified_pixel_by_pixel(mode, maxval):
    """A large image's pixels are classified through a table of their values (the float
    occupancies took 18 bytes a pixel): the same cells as each pixel's own reading."""
    from mitos_cli.sim.gridmap import _blocked

    rng = np.random.default_rng(maxval)
    px = rng.integers(0, maxval + 1, (60, 70)).astype(np.uint16)
    px[0, :4] = (0, maxval, 100, 101)
    for negate, unknown in ((False, True), (True, False)):
        for occ_t, free_t in ((0.65, 0.196), (0.5, 0.5), (1.0, 0.0)):
            got = classify(px, maxval, negate=negate, occupied_thresh=occ_t,
                           free_thresh=free_t, unknown_occupied=unknown, mode=mode)
            want = _blocked(px, maxval, negate, occ_t, free_t, unknown, mode)[::-1]
            assert got.dtype == bool and got.flags.c_contiguous
            assert np.array_equal(got, want)


@pytest.mark.parametrize("pixel, maxval, free_thresh", [(204, 255, 0.2), (804, 1000, 0.196)])
def test_a_pixel_at_the_free_threshold_is_unknown_not_free(pixel, maxval, free_thresh):
    """map_server's occupancy is ``(255 - v) / 255``: a grey 204 is 0.2, not below a
    ``free_thresh`` of 0.2, so unknown (a wall here by default). Computed as ``1 - v / 255``
    it was 0.19999999999999996, and free."""
    px = np.array([[pixel, maxval]])
    blocked = classify(px, maxval, negate=False, occupied_thresh=0.65, free_thresh=free_thresh)
    assert blocked.tolist() == [[True, False]]
    lenient = classify(px, maxval, negate=False, occupied_thresh=0.65, free_thresh=free_thresh,
                       unknown_occupied=False)
    assert lenient.tolist() == [[False, False]]
    big = np.full((40, 40), pixel, dtype=np.uint16)        # classified through a table
    assert classify(big, maxval, negate=False, occupied_thresh=0.65,
                    free_thresh=free_thresh).all()


def test_negate_swaps_black_and_white():
    px = np.array(PIXELS).reshape(3, 2)
    blocked = classify(px, 255, negate=True, occupied_thresh=0.65, free_thresh=0.196,
                       unknown_occupied=False)
    # occupancy is now v / 255: black (bottom) free, grey 205 (0.80) and white occupied
    assert blocked.tolist() == [[False, False], [True, True], [True, True]]


def test_map_yaml_resolution_and_origin_in_inches(tmp_path: Path):
    (tmp_path / "m.pgm").write_bytes(b"P5 2 3 255\n" + bytes(PIXELS))
    (tmp_path / "m.yaml").write_text("image: m.pgm\nresolution: 0.05\n"
                                     "origin: [-1.0, 2.0, 0.0]\nnegate: 0\n"
                                     "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
    g = load_map_yaml(tmp_path / "m.yaml")
    assert g.resolution == pytest.approx(0.05 * INCH_PER_M)
    assert g.origin == pytest.approx((-INCH_PER_M, 2 * INCH_PER_M))
    assert g.occupied[0].all() and not g.occupied[2].any()


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize("res", ["1e-320", "1e-300", "1e-30"])
def test_a_resolution_finer_than_a_micrometre_is_refused_at_its_line(tmp_path: Path, res):
    """The fuzz audit: at 1e-320 m the cell lookup printed NumPy's overflow warnings, and at
    1e-30 a 600-pixel map was one point, the start reported outside a map of width 0."""
    (tmp_path / "m.pgm").write_bytes(b"P5 2 3 255\n" + bytes(PIXELS))
    (tmp_path / "m.yaml").write_text(f"image: m.pgm\nresolution: {res}\norigin: [-15, -15, 0]\n")
    world = "\n".join(("name: m", "dt: 0.05", "time_limit: 1",
                       "robot: {model: tricycle, wheelbase: 16, footprint: {length: 24, width: 18}}",
                       "q_init: {x: 0, y: 0, heading: 0}", "q_goal: {x: 100, y: 0}",
                       "map: {grid: m.yaml}", ""))
    (tmp_path / "w.yaml").write_text(world)
    with pytest.raises(WorldError) as info:
        load_world(tmp_path / "w.yaml")
    text = info.value.render()
    assert text.startswith(f"{tmp_path / 'm.yaml'}:2:13: world error: resolution {res} m per "
                           "pixel is finer than a micrometre")
    assert "hint: the resolution is in metres per pixel: 0.05 is 5 cm" in text
    (tmp_path / "m.yaml").write_text("image: m.pgm\nresolution: 1e-6\norigin: [0, 0, 0]\n")
    assert load_map_yaml(tmp_path / "m.yaml").resolution == pytest.approx(1e-6 * INCH_PER_M)


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize("res, origin, where, said", [
    ("1e308", "[-15, -15, 0]", "2:13", "resolution 1e+308 m per pixel puts the map's far edge beyond"),
    ("1e5", "[-15, -15, 0]", "2:13", "resolution 100000 m per pixel puts the map's far edge beyond"),
    ("0.05", "[-1e300, -15, 0]", "3:9", "the map's origin lies 3.94e+301 in away, beyond"),
])
def test_a_map_beyond_a_worlds_reach_is_refused_at_its_line(tmp_path: Path, res, origin, where, said):
    """The fuzz audit: a resolution of 1e308 m made every cell infinitely wide, and the start
    was "inside a wall"; a world's numbers lie within ±1e7 in, and so does its map now."""
    (tmp_path / "m.pgm").write_bytes(b"P5 2 3 255\n" + bytes(PIXELS))
    (tmp_path / "m.yaml").write_text(f"image: m.pgm\nresolution: {res}\norigin: {origin}\n")
    with pytest.raises(WorldError) as info:
        load_map_yaml(tmp_path / "m.yaml")
    text = info.value.render()
    assert text.startswith(f"{tmp_path / 'm.yaml'}:{where}: world error: {said}")
    (tmp_path / "m.yaml").write_text("image: m.pgm\nresolution: 1e3\norigin: [-1e3, 0, 0]\n")
    assert load_map_yaml(tmp_path / "m.yaml").resolution == pytest.approx(1e3 * INCH_PER_M)


def test_a_map_file_that_is_not_utf8_is_placed_at_its_byte(tmp_path: Path):
    (tmp_path / "m.yaml").write_bytes(b"image: m.pgm\nresolution: 0.05 # \xff\norigin: [0, 0, 0]\n")
    with pytest.raises(WorldError) as info:
        load_map_yaml(tmp_path / "m.yaml")
    assert info.value.render().startswith(f"{tmp_path / 'm.yaml'}:2:20: world error: cannot read "
                                          "map file")


def test_bad_thresholds(tmp_path: Path):
    (tmp_path / "m.yaml").write_text("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n"
                                     "occupied_thresh: 0.1\nfree_thresh: 0.5\n")
    with pytest.raises(WorldError, match="free_thresh <= occupied_thresh"):
        load_map_yaml(tmp_path / "m.yaml")



@pytest.mark.parametrize("thresholds, said, line", [
    ("occupied_thresh: 1.5\nfree_thresh: 0.196\n", "occupied_thresh must lie between 0 and 1, "
                                                    "not 1.5", 4),
    ("occupied_thresh: 0.65\nfree_thresh: -0.1\n", "free_thresh must lie between 0 and 1, "
                                                    "not -0.1", 5),
    ("occupied_thresh: 0.1\n", "free_thresh 0.196 lies above occupied_thresh 0.1", 4),
])
def test_a_bad_threshold_is_pointed_at_itself(tmp_path: Path, thresholds, said, line):
    """`occupied_thresh: 1.5` was refused at the `free_thresh` line (or at none)."""
    (tmp_path / "m.yaml").write_text("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n"
                                     + thresholds)
    with pytest.raises(WorldError) as info:
        load_map_yaml(tmp_path / "m.yaml")
    assert info.value.message == said and info.value.span.line == line


def test_the_shipped_real_map_loads():
    from mitos_cli.resources import packaged_path

    g = load_map_yaml(packaged_path("worlds", "maps/mrpb_office02.yaml"))
    assert g.occupied.shape == (600, 600)
    assert 0.2 < g.occupied.mean() < 0.6


# --- images Pillow reads, rotated origins ------------------------------------------------

def _map(tmp_path: Path, image: str, origin: str = "[0.0, 0.0, 0.0]") -> Path:
    y = tmp_path / "m.yaml"
    y.write_text(f"image: {image}\nresolution: 0.0254\norigin: {origin}\nnegate: 0\n"
                 "occupied_thresh: 0.65\nfree_thresh: 0.196\n", encoding="utf-8")
    return y


def test_a_png_map_reads_as_the_same_pgm(tmp_path):
    Image = pytest.importorskip("PIL.Image")
    px = np.array(PIXELS, dtype=np.uint8).reshape(3, 2)
    Image.fromarray(px).save(tmp_path / "m.png")
    (tmp_path / "m.pgm").write_bytes(b"P5 2 3 255\n" + px.tobytes())
    png = load_map_yaml(_map(tmp_path, "m.png"))
    pgm = load_map_yaml(_map(tmp_path, "m.pgm"))
    assert png.occupied.tolist() == pgm.occupied.tolist()
    Image.fromarray(np.stack([px] * 3, axis=-1)).save(tmp_path / "c.png")
    assert load_map_yaml(_map(tmp_path, "c.png")).occupied.tolist() == pgm.occupied.tolist()




def test_a_pixel_out_of_range_is_said_at_the_maps_image_line_counted_from_1(tmp_path):
    """The pixel was said from 0 (`column 1, row 0` for the second pixel of the first row),
    where every other position MITOS gives, the ASCII image's `pixel 1` among them, counts
    from 1."""
    (tmp_path / "m.pgm").write_bytes(b"P5 3 2 100\n" + bytes([0, 0, 0, 0, 0, 254]))
    with pytest.raises(WorldError) as info:
        load_map_yaml(_map(tmp_path, "m.pgm"))
    assert info.value.span.line == 1
    assert "the pixel in column 3, row 2 (counted from 1 at the top left) is 254, outside " \
           "0..100" in str(info.value)


def test_a_png_named_pgm_is_read_by_its_content_as_map_server_reads_it(tmp_path):
    """map_server's readers tell an image by its content: a PNG saved as `map.pgm` was
    refused as "not a PGM image". A file that is neither still is."""
    Image = pytest.importorskip("PIL.Image")
    px = np.array(PIXELS, dtype=np.uint8).reshape(3, 2)
    Image.fromarray(px).save(tmp_path / "png.pgm", format="PNG")
    (tmp_path / "m.pgm").write_bytes(b"P5 2 3 255\n" + px.tobytes())
    assert load_map_yaml(_map(tmp_path, "png.pgm")).occupied.tolist() == \
        load_map_yaml(_map(tmp_path, "m.pgm")).occupied.tolist()
    (tmp_path / "junk.pgm").write_bytes(b"\x89PNG not a pgm")
    with pytest.raises(WorldError, match="not a PGM image"):
        load_map_yaml(_map(tmp_path, "junk.pgm"))


def test_a_png_named_pgm_too_large_for_pillow_is_too_large_not_no_pgm(tmp_path):
    """A PNG named `.pgm` of 200 million pixels, past Pillow's own limit, was "not a PGM
    image" once such a file went to Pillow; it is refused as too large, at its line."""
    pytest.importorskip("PIL.Image")
    (tmp_path / "big.pgm").write_bytes(_png_header(20_000, 10_000))
    with pytest.raises(WorldError, match="exceeds limit") as info:
        load_map_yaml(_map(tmp_path, "big.pgm"))
    assert info.value.hint == "crop the image to the part the robot drives in"


def test_a_damaged_png_is_said_to_be_damaged_not_looked_for_elsewhere(tmp_path):
    """A truncated PNG ("image file is truncated") got the hint that the image path is
    relative to the map's YAML file, as if it had not been found."""
    Image = pytest.importorskip("PIL.Image")
    Image.fromarray(np.full((40, 60), 254, dtype=np.uint8)).save(tmp_path / "m.png")
    (tmp_path / "m.png").write_bytes((tmp_path / "m.png").read_bytes()[:60])
    with pytest.raises(WorldError, match="cannot read map image .*m.png") as info:
        load_map_yaml(_map(tmp_path, "m.png"))
    assert "damaged" in info.value.hint and "relative" not in info.value.hint
    with pytest.raises(WorldError) as info:
        load_map_yaml(_map(tmp_path, "gone.png"))
    assert info.value.hint == "the image path is relative to the map's YAML file"


def test_a_colour_map_reads_as_the_mean_of_its_channels_as_map_server_does(tmp_path):
    """map_server averages a pixel's channels: yellow (255, 255, 0) is 170, occupancy 0.33,
    unknown; green (0, 255, 0) is 85, occupancy 0.67, a wall. Read as luminance (226 and
    150), yellow was free and green unknown: free space with `unknown: free`."""
    Image = pytest.importorskip("PIL.Image")
    px = np.array([[[255, 255, 0], [0, 255, 0], [254, 254, 254]]], dtype=np.uint8)
    Image.fromarray(px, "RGB").save(tmp_path / "c.png")
    assert load_map_yaml(_map(tmp_path, "c.png")).occupied.tolist() == [[True, True, False]]
    lenient = load_map_yaml(_map(tmp_path, "c.png"), unknown_occupied=False)
    assert lenient.occupied.tolist() == [[False, True, False]]


def test_an_alpha_channel_is_averaged_in_in_trinary_mode_as_map_server_does(tmp_path):
    """map_server's trinary mode averages alpha in with the colours ("to preserve existing
    behavior"): an opaque grey 205 (unknown in a grey image) is (3 x 205 + 255) / 4 = 217.5,
    occupancy 0.15, free; black stays a wall. Scale mode leaves alpha out."""
    Image = pytest.importorskip("PIL.Image")
    grey = np.array([[205, 0, 254]], dtype=np.uint8)
    Image.fromarray(np.stack([grey] * 3, axis=-1)).convert("RGBA").save(tmp_path / "c.png")
    assert load_map_yaml(_map(tmp_path, "c.png")).occupied.tolist() == [[False, True, False]]
    scale = _map(tmp_path, "c.png")
    scale.write_text(scale.read_text() + "mode: scale\n", encoding="utf-8")
    assert load_map_yaml(scale).occupied.tolist() == [[True, True, False]]


def test_without_pillow_a_png_is_refused_with_what_to_install(tmp_path, monkeypatch):
    import sys

    (tmp_path / "m.png").write_bytes(b"\x89PNG\r\n\x1a\n")
    monkeypatch.setitem(sys.modules, "PIL", None)
    with pytest.raises(WorldError, match=r"needs Pillow: pip install 'Pillow>=9' \(the `maps` extra") as exc:
        load_map_yaml(_map(tmp_path, "m.png"))
    assert exc.value.span.line == 1


def test_a_file_that_is_no_image_is_refused_at_the_image_line(tmp_path):
    pytest.importorskip("PIL")
    (tmp_path / "m.png").write_bytes(b"not an image")
    with pytest.raises(WorldError, match="does not recognise it as an image"):
        load_map_yaml(_map(tmp_path, "m.png"))


def _png_header(width: int, height: int) -> bytes:
    """A PNG's signature and header for an 8-bit grey image, then a scrap of its data (a
    decoder that goes on reads past the end)."""
    def chunk(kind: bytes, data: bytes) -> bytes:
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 0, 0,
                                                                 0, 0))
            + chunk(b"IDAT", zlib.compress(b"\0" * 64)))


@pytest.mark.parametrize("name, data", [
    ("m.png", _png_header(10_000, 9_500)),
    ("m.pgm", b"P5\n10000 9500\n255\n"),
], ids=["png", "pgm"])
def test_an_image_of_too_many_pixels_is_refused_before_it_is_read(tmp_path, name, data):
    """A 114 KB PNG of 10,000 x 9,500 pixels: Pillow's own warning on stderr, then 9.7 GB and
    a minute before the first tick. Any map image is held to 8,000 x 8,000 pixels, far beyond
    a building, and refused at its `image:` line before a pixel is decoded."""
    if name.endswith(".png"):
        pytest.importorskip("PIL")
    (tmp_path / name).write_bytes(data)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(WorldError, match=r"it has 95,000,000 pixels \(10,000 x 9,500\); a "
                                             r"map image may have at most 64,000,000") as exc:
            load_map_yaml(_map(tmp_path, name))
    assert (exc.value.span.line, exc.value.span.column) == (1, 8)
    assert exc.value.hint == "crop the image to the part the robot drives in"


def test_a_half_turned_origin_puts_the_map_on_the_other_side(tmp_path):
    # 2 x 3 pixels, one black pixel at the top left; turned half round about the origin (1 m, 2 m)
    (tmp_path / "m.pgm").write_bytes(b"P5 2 3 255\n" + bytes([0, 254, 254, 254, 254, 254]))
    g = load_map_yaml(_map(tmp_path, "m.pgm", f"[1.0, 2.0, {np.pi!r}]"))
    assert g.origin == pytest.approx((1 / 0.0254 - 2, 2 / 0.0254 - 3))
    # the black pixel was the top-left cell (x 0..1, y 2..3 in): now it covers x -1..0, y -3..-2
    # relative to the origin, the bottom-right cell of the turned grid
    assert np.argwhere(g.occupied).tolist() == [[0, 1]]


def test_any_yaw_is_honoured_and_matches_the_exact_quarter_turn(tmp_path):
    from mitos_cli.sim.gridmap import rotate

    rng = np.random.default_rng(3)
    blocked = rng.random((9, 13)) < 0.3
    exact, o1 = rotate(blocked, 2.0, (10.0, -4.0), np.pi / 2)
    resampled, o2 = rotate(blocked, 2.0, (10.0, -4.0), np.pi / 2 + 1e-7)
    assert exact.shape == (13, 9) and o1 == pytest.approx(o2)
    assert (resampled[:13, :9] == exact).all()
    # a quarter turn to the left sends the map's +x axis to +y: its bottom row becomes the
    # grid's right-hand column, read upward
    assert (exact[:, -1] == blocked[0]).all()


def test_a_yaw_of_3_14_as_in_the_stata_basement_map_is_turned_not_refused(tmp_path):
    # 40 x 30 pixels of 1 in, one black pixel at image column 5, row 9 from the top
    px = np.full((30, 40), 254, dtype=np.uint8)
    px[9, 5] = 0
    (tmp_path / "m.pgm").write_bytes(b"P5 40 30 255\n" + px.tobytes())
    g = load_map_yaml(_map(tmp_path, "m.pgm", "[0.0, 0.0, 3.14]"))
    c, s = np.cos(3.14), np.sin(3.14)
    # the pixel's centre in the map's frame (in), turned by the yaw about the origin
    mx, my = 5.5, 30 - 9 - 0.5
    x, y = c * mx - s * my, s * mx + c * my
    rows, cols = np.argwhere(g.occupied[1:-1, 1:-1]).T + 1       # inside the cover's edge
    centres = np.stack([g.origin[0] + (cols + 0.5), g.origin[1] + (rows + 0.5)], axis=1)
    assert len(centres) >= 1
    assert np.hypot(centres[:, 0] - x, centres[:, 1] - y).min() < 0.71



def test_a_turned_map_is_resampled_a_block_of_rows_at_a_time():
    """A map turned by a yaw that is no quarter turn was resampled all at once, about 75
    bytes a cell of the turned map (10 GB for an 8,000 x 8,000 image at 45 degrees, which the
    size limit lets through); a block of rows at a time now, with the same cells."""
    import tracemalloc

    from mitos_cli.sim.gridmap import rotate

    rng = np.random.default_rng(3)
    blocked = rng.random((600, 600)) < 0.3
    tracemalloc.start()
    try:
        turned, corner = rotate(blocked, 2.0, (5.0, -7.0), 0.785)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 12 * turned.size
    c, s = np.cos(0.785), np.sin(0.785)                    # each cell as the map holds it
    rows, cols = turned.shape
    for r, k in rng.integers(0, (rows, cols), (200, 2)):
        px, py = corner[0] - 5.0 + (k + 0.5) * 2.0, corner[1] + 7.0 + (r + 0.5) * 2.0
        mc, mr = int(np.floor((c * px + s * py) / 2.0)), int(np.floor((-s * px + c * py) / 2.0))
        inside = 0 <= mr < 600 and 0 <= mc < 600
        assert turned[r, k] == (blocked[mr, mc] if inside else True)


def test_map_modes_raw_and_an_unknown_one(tmp_path: Path):
    """`mode: raw` reads pixel values as occupancy percent (0 free, 100 occupied, above 100
    unknown), as map_server does; an unknown mode was silently read as trinary."""
    (tmp_path / "r.pgm").write_bytes(b"P5 3 1 255\n" + bytes([0, 100, 255]))
    (tmp_path / "r.yaml").write_text("image: r.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n"
                                     "mode: raw\n")
    g = load_map_yaml(tmp_path / "r.yaml", unknown_occupied=False)
    assert g.occupied.tolist() == [[False, True, False]]
    assert load_map_yaml(tmp_path / "r.yaml").occupied.tolist() == [[False, True, True]]
    (tmp_path / "r.yaml").write_text("image: r.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n"
                                     "mode: rw\n")
    with pytest.raises(WorldError, match="unknown map_server mode `rw`") as info:
        load_map_yaml(tmp_path / "r.yaml")
    assert info.value.span.line == 4 and info.value.hint == "did you mean `raw`?"



def test_raw_pixels_are_read_on_the_scale_of_0_to_255_as_map_server_reads_them(tmp_path):
    """`mode: raw` took the pixel value as it stood: a 16-bit map's 100 % (25,700 of 65,535)
    was unknown, a PGM of maximum 100 read 100 as occupied (map_server: 255, unknown) and a
    colour pixel's mean of 100.33 unknown (map_server rounds it: 100, occupied)."""
    from mitos_cli.sim.gridmap import shade

    (tmp_path / "r.pgm").write_bytes(b"P5 3 1 65535\n" + np.array([0, 25700, 65535], ">u2")
                                     .tobytes())
    (tmp_path / "r.yaml").write_text("image: r.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n"
                                     "mode: raw\n")
    assert load_map_yaml(tmp_path / "r.yaml", unknown_occupied=False).occupied.tolist() == \
        [[False, True, False]]
    (tmp_path / "r.pgm").write_bytes(b"P2 3 1 100\n0 10 100\n")   # 0, 26 and 255 of 255
    assert load_map_yaml(tmp_path / "r.yaml", unknown_occupied=False).occupied.tolist() == \
        [[False, False, False]]
    assert load_map_yaml(tmp_path / "r.yaml").occupied.tolist() == [[False, True, True]]
    colour = np.array([[[100, 100, 101], [100, 101, 101]]])        # means 100.33 and 100.67
    assert classify(shade(colour, "raw"), 255, negate=False, occupied_thresh=0.65,
                    free_thresh=0.196, unknown_occupied=False, mode="raw").tolist() == \
        [[True, False]]


@pytest.mark.parametrize("line, said, column", [
    ("image:", "`image` in a map file is empty", 7),
    ("image: ''", "`image` in a map file is empty", 8),
    ("image: [m.pgm]", "`image` in a map file must be a path, not a list", 8),
    ("image: m.pgm\nmode:", "`mode` in a map file is empty", 6),
])
def test_an_empty_image_or_mode_is_said_so_not_none(tmp_path: Path, line, said, column):
    """An empty `image:` was "map image `None` not found", and an empty `mode:` an "unknown
    map_server mode `None`"."""
    (tmp_path / "m.pgm").write_bytes(b"P5 2 3 255\n" + bytes(PIXELS))
    (tmp_path / "m.yaml").write_text("resolution: 0.05\norigin: [0, 0, 0]\n" + line + "\n")
    with pytest.raises(WorldError) as info:
        load_map_yaml(tmp_path / "m.yaml")
    assert info.value.message == said and "None" not in info.value.render()
    assert (info.value.span.line, info.value.span.column) == (line.count("\n") + 3, column)


def test_a_map_named_by_its_image_points_at_its_yaml(tmp_path: Path):
    (tmp_path / "m.pgm").write_bytes(b"P5 2 3 255\n" + bytes(PIXELS))
    (tmp_path / "m.yaml").write_text("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n")
    with pytest.raises(WorldError, match="`m.pgm` is a map image") as info:
        load_map_yaml(tmp_path / "m.pgm")
    assert info.value.hint == f"did you mean `{tmp_path / 'm.yaml'}`?"


def test_a_misspelt_map_or_image_gets_a_did_you_mean_as_it_is_written(tmp_path: Path):
    """A misspelt `grid:` / `given:` path (or `image:`) was "not found" and no more, where a
    misspelt world file name gets the file beside it."""
    from mitos_cli.sim.worldfile import load_world

    maps = tmp_path / "maps"
    maps.mkdir()
    (maps / "hall.pgm").write_bytes(b"P5 2 3 255\n" + bytes(PIXELS))
    (maps / "hall.yaml").write_text("image: hall.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n")
    world = (Path(__file__).parent.parent / "worlds" / "corridor.yaml").read_text()
    for key in ("grid", "given"):
        w = tmp_path / f"w_{key}.yaml"
        w.write_text(world.replace("map:\n", "map:\n  grid: maps/hall.yaml\n  given: none\n")
                     .replace(f"{key}: " + ("maps/hall.yaml" if key == "grid" else "none"),
                              f"{key}: maps/hal.yaml"))
        with pytest.raises(WorldError) as info:
            load_world(w)
        assert info.value.message == f"map file `{maps / 'hal.yaml'}` not found"
        assert info.value.hint == "did you mean `maps/hall.yaml`?"
    (maps / "hall.yaml").write_text("image: hal.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n")
    with pytest.raises(WorldError) as info:
        load_map_yaml(maps / "hall.yaml")
    assert info.value.hint == ("did you mean `hall.pgm`? (the image path is relative to the "
                               "map's YAML file)")
    (maps / "hall.yaml").write_text("image: nothing.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n")
    with pytest.raises(WorldError) as info:
        load_map_yaml(maps / "hall.yaml")
    assert info.value.hint == "the image path is relative to the map's YAML file"



def test_an_absolute_image_path_from_another_machine_points_beside_the_yaml(tmp_path: Path):
    """ROS 1's map_saver given an absolute name writes the image's absolute path; moved to
    another machine, the map was told "the image path is relative to the map's YAML file"."""
    (tmp_path / "office.pgm").write_bytes(b"P5 2 3 255\n" + bytes(PIXELS))
    gone = tmp_path / "another" / "machine" / "office.pgm"
    (tmp_path / "m.yaml").write_text(f"image: {gone}\nresolution: 0.05\norigin: [0, 0, 0]\n")
    with pytest.raises(WorldError, match="map image .* not found") as info:
        load_map_yaml(tmp_path / "m.yaml")
    assert info.value.hint == ("did you mean `office.pgm`, beside the map's YAML? It names its "
                               "image by an absolute path, as map_saver writes one: write "
                               "`image: office.pgm`")
    (tmp_path / "office.pgm").unlink()
    with pytest.raises(WorldError) as info:
        load_map_yaml(tmp_path / "m.yaml")
    assert info.value.hint == ("the image path is absolute: it is looked for there, not beside "
                               "the map's YAML")


def test_a_number_in_quotes_is_said_to_be_text_in_quotes(tmp_path: Path):
    """`resolution: "0.05"` was "resolution must be a number, not `0.05`", which did not say
    what is wrong with 0.05: YAML reads it in quotes as text."""
    (tmp_path / "m.yaml").write_text('image: m.pgm\nresolution: "0.05"\norigin: [0, 0, 0]\n')
    with pytest.raises(WorldError) as info:
        load_map_yaml(tmp_path / "m.yaml")
    assert info.value.message == ('resolution must be a number, not the text "0.05": YAML reads '
                                  "a value in quotes as text; write the number without them")
    (tmp_path / "m.yaml").write_text("image: m.pgm\nresolution: 0.05\norigin: [0, 0, half]\n")
    with pytest.raises(WorldError, match="origin must be a number, not `half`\n"):
        load_map_yaml(tmp_path / "m.yaml")


def test_a_bad_origin_number_is_pointed_at_itself(tmp_path: Path):
    """`origin: [0, 0, half]` put the caret on the `[`."""
    (tmp_path / "m.yaml").write_text("image: m.pgm\nresolution: 0.05\norigin: [0, 0, half]\n")
    with pytest.raises(WorldError) as info:
        load_map_yaml(tmp_path / "m.yaml")
    text = info.value.render()
    assert text.startswith(f"{tmp_path / 'm.yaml'}:3:16: world error: origin must be a number, "
                           "not `half`")
    assert text.splitlines()[2] == " " * 19 + "^"


@pytest.mark.parametrize("yaw", ["1e300", "-1e17"])
def test_a_yaw_beyond_a_worlds_numbers_is_refused_at_itself(tmp_path: Path, yaw):
    """`origin: [0, 0, 1e300]` loaded as no turn at all: past 2**53 quarter turns every yaw
    is a whole number of them in floating point. Every number of a world lies within ±1e7."""
    (tmp_path / "m.pgm").write_bytes(b"P2\n2 2\n255\n254 254 254 254\n")
    (tmp_path / "m.yaml").write_text(f"image: m.pgm\nresolution: 0.05\norigin: [0, 0, {yaw}]\n")
    with pytest.raises(WorldError) as info:
        load_map_yaml(tmp_path / "m.yaml")
    text = info.value.render()
    assert text.startswith(f"{tmp_path / 'm.yaml'}:3:16: world error: the origin's yaw must be "
                           "within ±1e+07 (radians)")
    (tmp_path / "m.yaml").write_text("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 1e6]\n")
    assert load_map_yaml(tmp_path / "m.yaml").occupied.any()


def test_a_packaged_world_copied_elsewhere_is_told_where_its_map_is(tmp_path: Path):
    """`cp worlds/office.yaml mine.yaml; mitos simulate mine.yaml` said "map file
    `maps/mrpb_office02.yaml` not found" and no more: the map lies beside the packaged worlds.
    The hint names its full path, which the copy then loads from."""
    from mitos_cli.resources import packaged_path

    office = packaged_path("worlds", "office.yaml").read_text(encoding="utf-8")
    (tmp_path / "mine.yaml").write_text(office, encoding="utf-8")
    with pytest.raises(WorldError) as info:
        load_world(tmp_path / "mine.yaml")
    full = packaged_path("worlds", "maps/mrpb_office02.yaml").as_posix()
    assert info.value.message.endswith("/maps/mrpb_office02.yaml` not found")
    assert info.value.hint == (
        "a map path is relative to the world file, and `maps/mrpb_office02.yaml` lies beside "
        f"the packaged worlds: write its full path, `{full}`, or copy that `maps/` folder "
        "beside this world file")
    (tmp_path / "mine.yaml").write_text(office.replace("grid: maps/mrpb_office02.yaml",
                                                       f"grid: {full}"), encoding="utf-8")
    assert load_world(tmp_path / "mine.yaml").name == "office"
