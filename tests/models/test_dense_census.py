"""Census model (tools/models/census.py): against a per-pixel brute force, the border rule, bad input."""

from __future__ import annotations

import numpy as np
import pytest

from eyestereo.tools.models import census as C


def brute(img: np.ndarray, window: int) -> np.ndarray:
    """Bits as a string per pixel, neighbours in raster order, out-of-image neighbours '0'."""
    h, w = img.shape
    r = window // 2
    out = np.zeros((h, w), np.uint64)
    for y in range(h):
        for x in range(w):
            bits = ""
            for yy in range(y - r, y + r + 1):
                for xx in range(x - r, x + r + 1):
                    if (yy, xx) == (y, x):
                        continue
                    inside = 0 <= yy < h and 0 <= xx < w
                    bits += "1" if inside and int(img[yy, xx]) < int(img[y, x]) else "0"
            out[y, x] = int(bits, 2)
    return out


@pytest.mark.parametrize("window", [5, 7])
def test_census_equals_brute_force(window):
    img = np.random.default_rng(window).integers(0, 256, (9, 12), dtype=np.uint8)
    img[2:5, 3:7] = 77  # equal neighbours give 0 bits
    assert np.array_equal(C.census(img, window=window), brute(img, window))


def test_bit_counts_and_border():
    assert C.census_bits(5) == 24 and C.census_bits(7) == 48
    img = np.zeros((8, 8), np.uint8)
    img[0, 0] = 200  # every neighbour darker: a bit for each in-image neighbour only
    word = int(C.census(img, window=5)[0, 0])
    assert bin(word).count("1") == 8
    assert word == int("00000" "00000" "0011" "00111" "00111", 2)  # rows -2, -1 outside; row 0 without centre
    assert int(C.census(np.full((6, 6), 9, np.uint8), window=7).max()) == 0


def test_stereo_gives_both_cameras():
    rng = np.random.default_rng(1)
    a, b = (rng.integers(0, 256, (7, 9), dtype=np.uint8) for _ in range(2))
    ca, cb = C.census_stereo(a, b, window=7)
    assert np.array_equal(ca, brute(a, 7)) and np.array_equal(cb, brute(b, 7))


@pytest.mark.parametrize("window", [3, 6, 9, True, "5"])
def test_bad_window(window):
    with pytest.raises(ValueError, match="census window must be one of"):
        C.census(np.zeros((8, 8), np.uint8), window=window)


@pytest.mark.parametrize("img, match", [(np.zeros((4, 4, 3), np.uint8), "2-D grey image"),
                                        (np.zeros((4, 4), float), "8-bit grey levels"),
                                        (np.full((4, 4), 300), "8-bit grey levels"),
                                        (np.zeros((0, 4), np.uint8), "empty")])
def test_bad_image(img, match):
    with pytest.raises(ValueError, match=match):
        C.census(img)


def test_stereo_sizes_must_agree():
    with pytest.raises(ValueError, match="differ in size: 9x7 and 8x7"):
        C.census_stereo(np.zeros((7, 9), np.uint8), np.zeros((7, 8), np.uint8))
