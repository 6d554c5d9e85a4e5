"""PGM images and ROS map_server maps: rows flipped, origin, thresholds, negate, unknown."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mitos_cli.errors import WorldError
from mitos_cli.sim.gridmap import INCH_PER_M, classify, load_map_yaml
from mitos_cli.sim.pgm import parse_pgm

# a 3 x 2 image, top row first: white (free), grey (unknown), black (occupied)
PIXELS = [254, 254, 205, 205, 0, 0]


def test_binary_pgm_with_a_comment():
    data = b"P5\n# made by hand\n2 3\n255\n" + bytes(PIXELS)
    px, maxval = parse_pgm(data)
    assert maxval == 255 and px.tolist() == [[254, 254], [205, 205], [0, 0]]


def test_ascii_pgm():
    px, _ = parse_pgm(b"P2 2 3 255 " + " ".join(map(str, PIXELS)).encode())
    assert px[2].tolist() == [0, 0]


def test_sixteen_bit_pgm():
    px, maxval = parse_pgm(b"P5 1 2 65535\n" + bytes([0xFF, 0xFF, 0x00, 0x01]))
    assert maxval == 65535 and px.ravel().tolist() == [65535, 1]


@pytest.mark.parametrize("data, words", [
    (b"P6 1 1 255\n\x00\x00\x00", "not a PGM"),
    (b"P5 2 2 255\n\x00", "holds 1 of its 4 pixels"),
    (b"P5 2", "cut short"),
    (b"P2 1 1 255 300", "outside 0..255"),
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


def test_bad_thresholds(tmp_path: Path):
    (tmp_path / "m.yaml").write_text("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n"
                                     "occupied_thresh: 0.1\nfree_thresh: 0.5\n")
    with pytest.raises(WorldError, match="free_thresh <= occupied_thresh"):
        load_map_yaml(tmp_path / "m.yaml")


def test_the_shipped_real_map_loads():
    from mitos_cli.resources import packaged_path

    g = load_map_yaml(packaged_path("worlds", "maps/mrpb_office02.yaml"))
    assert g.occupied.shape == (600, 600)
    assert 0.2 < g.occupied.mean() < 0.6
