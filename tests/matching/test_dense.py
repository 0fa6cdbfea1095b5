"""Dense SAD block matching (tools/dense.py): exact on constructed pairs, a loop reference, StereoBM, Tsukuba."""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np
import pytest

import eyestereo.tools
from eyestereo.tools.matching import dense as D
from eyestereo.tools.matching import sparse as M
from eyestereo.tools.matching import metrics as Q

SHARED = Path(os.environ.get("EYESTEREO_SHARED", Path(eyestereo.tools.__file__).resolve().parents[1].parent / "shared"))
DATA = SHARED / "data" / "middlebury"
needs_middlebury = pytest.mark.skipif(not (DATA / "tsukuba" / "im3.png").is_file(),
                                      reason=f"Middlebury images not found at {DATA}")


def dots(h, w, seed, dot=2):
    rng = np.random.default_rng(seed)
    cells = rng.integers(30, 221, size=(-(-h // dot), -(-w // dot)))
    return np.kron(cells, np.ones((dot, dot), np.int64))[:h, :w].astype(np.uint8)


def test_box_sum_equals_loops():
    a = np.random.default_rng(0).integers(0, 255, (11, 13))
    for rx, ry in [(0, 0), (1, 2), (3, 1)]:
        got = D.box_sum(a, rx, ry)
        exp = np.array([[a[y - ry:y + ry + 1, x - rx:x + rx + 1].sum() for x in range(rx, 13 - rx)]
                        for y in range(ry, 11 - ry)])
        assert np.array_equal(got, exp)


@pytest.mark.parametrize("d", [0, 4, 13])
def test_shifted_pair_gives_the_shift_exactly(d):
    h, w, r = 48, 80, 4
    base = dots(h, w + d, d)
    left, right = base[:, :w], base[:, d:d + w]
    disp = D.sad_disparity(left, right, 16, window=9)
    # every pixel whose true right window lies inside the image: exactly d
    inner = np.zeros((h, w), bool)
    inner[r:h - r, d + r:w - r] = True
    assert np.all(disp[inner] == d)
    assert np.all(np.isnan(disp[:r])) and np.all(np.isnan(disp[:, -r:]))
    s = Q.dense_scores(np.where(inner, disp, np.nan), np.full((h, w), float(d)))
    assert (s.bad, s.rms, s.evaluated) == (0, 0.0, inner.sum())


def test_equals_a_loop_reference():
    rng = np.random.default_rng(3)
    L = rng.integers(0, 256, (20, 30)).astype(np.uint8)
    R = rng.integers(0, 256, (20, 30)).astype(np.uint8)
    r, dmin, dmax = 2, 1, 6
    got = D.sad_disparity(L, R, dmax, window=5, d_min=dmin)
    Li, Ri = L.astype(int), R.astype(int)
    for y in range(r, 20 - r):
        for x in range(r, 30 - r):
            costs = [(np.abs(Li[y - r:y + r + 1, x - r:x + r + 1]
                             - Ri[y - r:y + r + 1, x - d - r:x - d + r + 1]).sum(), d)
                     for d in range(dmin, dmax + 1) if x - d - r >= 0]
            exp = min(costs)[1] if costs else np.nan
            assert (np.isnan(exp) and np.isnan(got[y, x])) or got[y, x] == exp, (x, y)


def test_stereo_bm_agrees_on_a_random_dot_pair():
    h, w, d = 64, 128, 9
    base = dots(h, w + d, 5)
    left, right = base[:, :w], base[:, d:d + w]
    bm = D.stereo_bm(left, right, 16, window=9)
    ok = np.isfinite(bm)
    assert ok.sum() > 0.5 * h * w
    assert np.mean(np.abs(bm[ok] - d) <= 0.25) > 0.95     # StereoBM interpolates to 1/16 px


def test_bad_input():
    a = np.zeros((20, 30), np.uint8)
    with pytest.raises(ValueError, match="differ in size"):
        D.sad_disparity(a, a[:, :-2], 5)
    with pytest.raises(ValueError, match="odd"):
        D.sad_disparity(a, a, 5, window=4)
    with pytest.raises(ValueError, match="below the image width"):
        D.sad_disparity(a, a, 30)
    with pytest.raises(ValueError, match="d_min"):
        D.sad_disparity(a, a, 3, d_min=5)
    with pytest.raises(ValueError, match="smaller than"):
        D.sad_disparity(a[:5], a[:5], 3, window=9)
    with pytest.raises(ValueError, match="StereoBM"):
        D.stereo_bm(a, a, 5, window=3)


@needs_middlebury
def test_tsukuba_dense_9x9():
    L = M.load_grey(DATA / "tsukuba" / "im3.png")
    R = M.load_grey(DATA / "tsukuba" / "im4.png")
    gt = Q.load_disparity(DATA / "tsukuba" / "disp3.pgm", 16)
    t0 = time.perf_counter()
    disp = D.sad_disparity(L, R, 15, window=9)
    dt = time.perf_counter() - t0
    assert dt < 2.0                               # a few seconds at most, on any machine
    s = Q.dense_scores(disp, gt)
    assert s.evaluated > 80000 and 3 < s.bad_percent < 20
    bm = D.stereo_bm(L, R, 15, window=9)
    both = np.isfinite(bm) & np.isfinite(disp)
    assert both.mean() > 0.8 and np.mean(np.abs(bm[both] - disp[both]) <= 1) > 0.8
