"""Sparse feature matching (tools/matching.py): known-answer stereo pairs, a brute-force reference, bad input.

References are independent of the code under test: the disparity a pair was built with, corners of the
bit-true Harris model (tools/harris_mono.py) located by set intersection, and plain Python loops for the
window costs and the selection rules.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import cv2
import numpy as np
import pytest

import eyestereo.tools
from eyestereo.tools.models import harris_mono as hm
from eyestereo.tools.matching import sparse as M
from eyestereo.tools.matching import metrics as Q
from eyestereo.tools.constants import K_CODE_DEFAULT

SHARED = Path(os.environ.get("EYESTEREO_SHARED", Path(eyestereo.tools.__file__).resolve().parents[1].parent / "shared"))
DATA = SHARED / "data" / "middlebury"
needs_middlebury = pytest.mark.skipif(not (DATA / "tsukuba" / "im3.png").is_file(),
                                      reason=f"Middlebury images not found at {DATA}")


def dots(h: int, w: int, seed: int, dot: int = 2, lo: int = 30, hi: int = 220) -> np.ndarray:
    """Random-dot texture: dot x dot squares of uniform random grey lo..hi."""
    rng = np.random.default_rng(seed)
    cells = rng.integers(lo, hi + 1, size=(-(-h // dot), -(-w // dot)))
    return np.kron(cells, np.ones((dot, dot), np.int64))[:h, :w].astype(np.uint8)


def shifted_pair(h=64, w=96, d=6, seed=0, offset=0):
    """Left and right views of a fronto-parallel plane at disparity d: R(x) = L(x + d) (+ offset)."""
    base = dots(h, w + d, seed)
    left = base[:, :w]
    right = np.clip(base[:, d:d + w].astype(np.int64) + offset, 0, 255).astype(np.uint8)
    return left, right


def corners(img, code=0):
    flags, mask = hm.harris_mono(img, K_CODE_DEFAULT, [code] * 16)
    return hm.features(flags, mask)


def counterparts(fl, fr, d):
    """Indices of left corners whose partner (x - d, y) is a right corner."""
    right = {tuple(p) for p in fr.tolist()}
    return [i for i, (x, y) in enumerate(fl.tolist()) if (x - d, y) in right]


# --------------------------------------------------------------------------------------------------
# Known answers


@pytest.mark.parametrize("d", [0, 3, 11])
def test_shifted_random_dots_match_exactly(d):
    left, right = shifted_pair(d=d, seed=d)
    fl, fr = corners(left), corners(right)
    expect = counterparts(fl, fr, d)
    assert len(expect) > 30
    m = M.match_features(left, right, fl, fr, d_max=16, t_max=11)
    assert sorted(m.left_index.tolist()) == expect
    assert np.all(m.disparity == d) and np.all(m.cost == 0)
    assert np.array_equal(m.right, m.left - [d, 0])
    gt = np.full(left.shape, float(d))
    s = Q.sparse_scores(m.left, m.disparity, gt)
    assert (s.evaluated, s.good, s.bad, s.unknown, s.rms, s.bad_percent) == (len(expect), len(expect), 0, 0, 0.0, 0.0)


@pytest.mark.parametrize("cost", ["sad", "ssd", "ncc"])
def test_every_cost_finds_the_shift(cost):
    left, right = shifted_pair(d=5, seed=7)
    fl, fr = corners(left), corners(right)
    m = M.match_features(left, right, fl, fr, d_max=12, cost=cost, ncc_min=0.99)
    assert sorted(m.left_index.tolist()) == counterparts(fl, fr, 5)
    assert np.all(m.disparity == 5)
    np.testing.assert_allclose(m.cost, 0, atol=1e-12)


def test_acceptance_threshold_is_strict_and_scales_with_the_window():
    # right = left shifted + 5 grey levels: every true pair has SAD exactly 5 W H, SSD 25 W H, NCC 1
    left, right = shifted_pair(d=4, seed=3, offset=5)
    fl, fr = corners(left), corners(right)  # gradients (so corners) do not see the offset
    expect = counterparts(fl, fr, 4)
    assert len(expect) > 30
    for w, h in [(9, 9), (5, 7), (3, 3)]:
        m = M.match_features(left, right, fl, fr, window=(w, h), d_max=8, t_max=5.0)
        assert len(m) == 0                                   # 5 W H < 5 W H is false
        m = M.match_features(left, right, fl, fr, window=(w, h), d_max=8, t_max=5.001)
        assert sorted(m.left_index.tolist()) == expect and np.all(m.cost == 5 * w * h)
        m = M.match_features(left, right, fl, fr, window=(w, h), d_max=8, t_max=5.0, cost="ssd")
        assert len(m) == 0
        m = M.match_features(left, right, fl, fr, window=(w, h), d_max=8, t_max=5.001, cost="ssd")
        assert np.all(m.cost == 25 * w * h) and len(m) == len(expect)
        m = M.match_features(left, right, fl, fr, window=(w, h), d_max=8, cost="ncc", ncc_min=0.999)
        assert sorted(m.left_index.tolist()) == expect


def two_layer(h=96, w=128, db=3, df=9, box=(40, 24, 96, 72), seed=1):
    """Random-dot stereogram: background plane at db, a foreground rectangle (left x0..x1, y0..y1) at df.

    Returns left, right, the true left disparity map, and the mask of left pixels that are visible in
    the right view (not occluded)."""
    x0, y0, x1, y1 = box
    bg, fg = dots(h, w + db + df, seed, dot=2), dots(h, w + df, seed + 100, dot=2)
    ys, xs = np.mgrid[0:h, 0:w]
    in_box = (xs >= x0) & (xs < x1) & (ys >= y0) & (ys < y1)
    left = np.where(in_box, fg[:, :w], bg[:, :w])
    # right pixel x shows the foreground if x + df lies in the box (left coordinates), else background
    u = xs + df
    r_fg = (u >= x0) & (u < x1) & (ys >= y0) & (ys < y1)
    right = np.where(r_fg, fg[ys, np.minimum(u, w + df - 1)], bg[ys, xs + db])
    gt = np.where(in_box, float(df), float(db))
    visible = in_box | ~((xs - db + df >= x0) & (xs - db + df < x1) & (ys >= y0) & (ys < y1))
    return left.astype(np.uint8), right.astype(np.uint8), gt, visible


def test_random_dot_stereogram_exact_away_from_the_boundary():
    left, right, gt, visible = two_layer()
    fl, fr = corners(left), corners(right)
    m = M.match_features(left, right, fl, fr, d_max=16, window=(9, 9))
    s = Q.sparse_scores(m.left, m.disparity, gt)
    assert s.evaluated == len(m) > 100
    # a corner is "safe" when its Harris support and its 9x9 window stay within one visible layer
    r = 4 + hm.radius(3)
    safe = []
    for x, y in m.left.tolist():
        win = (slice(max(y - r, 0), y + r + 1), slice(max(x - r, 0), x + r + 1))
        same = gt[win].min() == gt[win].max()
        safe.append(same and visible[win].all())
    safe = np.array(safe)
    assert safe.sum() > 100
    assert np.all(m.disparity[safe] == gt[m.left[safe, 1], m.left[safe, 0]])
    assert np.all(m.cost[safe] == 0)
    # the foreground and the background are both found
    assert {3, 9} <= set(m.disparity[safe].tolist())
    assert s.bad <= (~safe).sum()


def test_split_correlation_ignores_a_disturbed_outer_window():
    # identical views except a bright square that covers one diagonal neighbour of a corner's window
    left, right = shifted_pair(h=80, w=120, d=4, seed=11)
    fl, fr = corners(left), corners(right)
    i = counterparts(fl, fr, 4)[len(fl) // 3]
    x, y = fl[i]
    w, h = 5, 7
    right = right.copy()
    # cell (+1, +1) of the 3x3 grid in the right image around (x - 4, y)
    cx, cy = x - 4 + w, y + h
    ys, xs = np.mgrid[cy - h // 2:cy + h // 2 + 1, cx - w // 2:cx + w // 2 + 1]
    ok = (ys >= 0) & (ys < right.shape[0]) & (xs >= 0) & (xs < right.shape[1])
    right[ys[ok], xs[ok]] = 255
    one = dict(window=(w, h), d_max=8, t_max=2.0)
    m1 = M.match_features(left, right, fl[i:i + 1], fr, split=1, **one)
    m9 = M.match_features(left, right, fl[i:i + 1], fr, split=9, **one)
    m5 = M.match_features(left, right, fl[i:i + 1], fr, split=5, **one)
    assert len(m1) == 1 and m1.cost[0] == 0          # the centre window alone is clean
    assert len(m9) == 1 and m9.cost[0] == 0 and m9.disparity[0] == 4   # best 4 of 8 skip the bright cell
    assert len(m5) == 1 and m5.cost[0] == 0 and m5.disparity[0] == 4   # best 2 of 4 diagonals too
    # a plain window of the whole 15 x 21 area sees the square
    big = M.match_features(left, right, fl[i:i + 1], fr, window=(3 * w, 3 * h), d_max=8, t_max=100)
    assert len(big) == 1 and big.cost[0] > 0


def test_split_offsets_geometry():
    assert M.split_offsets((5, 7), 1).tolist() == [[0, 0]]
    assert M.split_offsets((5, 7), 5).tolist() == [[0, 0], [-5, -7], [5, -7], [-5, 7], [5, 7]]
    nine = M.split_offsets((5, 7), 9).tolist()
    assert nine[0] == [0, 0] and sorted(nine) == sorted([dx, dy] for dx in (-5, 0, 5) for dy in (-7, 0, 7))


def test_left_right_check_removes_a_shared_right_corner():
    left, right = shifted_pair(d=6, seed=5)
    fl, fr = corners(left), corners(right)
    i = counterparts(fl, fr, 6)[5]
    j = int(np.flatnonzero((fr == fl[i] - [6, 0]).all(1))[0])
    # a second left feature, one pixel to the right of the true one, on the same row
    fl2 = np.array([fl[i], fl[i] + [1, 0]])
    plain = M.match_features(left, right, fl2, fr[j:j + 1], d_max=16, t_max=60)
    assert plain.right_index.tolist() == [0, 0]          # both take the only right corner
    lr = M.match_features(left, right, fl2, fr[j:j + 1], d_max=16, t_max=60, lr_check=True)
    assert lr.left_index.tolist() == [0] and lr.disparity.tolist() == [6] and lr.cost.tolist() == [0]


def test_rows_option_reaches_the_next_row():
    left, right = shifted_pair(d=6, seed=8)
    fl, fr = corners(left), corners(right)
    fr_up = fr + [0, 1]                                    # right corners listed one row too low
    fr_up = fr_up[fr_up[:, 1] < left.shape[0]]
    m0 = M.match_features(left, right, fl, fr_up, d_max=16, t_max=2)
    m1 = M.match_features(left, right, fl, fr, d_max=16, t_max=2, rows=1)
    m1b = M.match_features(left, right, fl, fr_up, d_max=16, t_max=40, rows=1)
    assert len(m0) == 0
    assert len(m1) == len(counterparts(fl, fr, 6))
    assert len(m1b) > 0 and np.all(np.abs(m1b.right[:, 1] - m1b.left[:, 1]) <= 1)


# --------------------------------------------------------------------------------------------------
# Brute-force reference


def ref_cost(L, R, xl, yl, xr, yr, w, h, cost, split):
    pad = 3 * max(w, h)
    Lp = np.pad(L.astype(np.int64), pad, mode="edge")
    Rp = np.pad(R.astype(np.int64), pad, mode="edge")

    def win(img, x, y):
        return img[pad + y - h // 2:pad + y + h // 2 + 1, pad + x - w // 2:pad + x + w // 2 + 1]

    if cost == "ncc":
        a, b = win(Lp, xl, yl).astype(float).ravel(), win(Rp, xr, yr).astype(float).ravel()
        a, b = a - a.mean(), b - b.mean()
        den = np.sqrt((a * a).sum() * (b * b).sum())
        return 1.0 - (float((a * b).sum() / den) if den > 0 else -1.0)
    cells = {1: [(0, 0)], 5: [(0, 0), (-1, -1), (1, -1), (-1, 1), (1, 1)],
             9: [(0, 0)] + [(i, j) for i in (-1, 0, 1) for j in (-1, 0, 1) if (i, j) != (0, 0)]}[split]
    cs = []
    for i, j in cells:
        diff = win(Lp, xl + i * w, yl + j * h) - win(Rp, xr + i * w, yr + j * h)
        cs.append(int(np.abs(diff).sum()) if cost == "sad" else int((diff * diff).sum()))
    return cs[0] + sum(sorted(cs[1:])[:(len(cs) - 1) // 2])


def ref_match(L, R, fl, fr, *, window, t_max, cost, d_max, rows, split, lr_check, ncc_min=0.8):
    w, h = window
    nsum = 1 + (split - 1) // 2
    acc = []
    for i, (xl, yl) in enumerate(fl.tolist()):
        for j, (xr, yr) in enumerate(fr.tolist()):
            if abs(yr - yl) <= rows and 0 <= xl - xr <= d_max:
                c = ref_cost(L, R, xl, yl, xr, yr, w, h, cost, split)
                ok = c <= 1 - ncc_min + 1e-12 if cost == "ncc" else \
                    c < (t_max if cost == "sad" else t_max ** 2) * w * h * nsum
                if ok:
                    acc.append((i, j, c, abs(yr - yl), xl - xr))
    best_l, best_r = {}, {}
    for a in acc:
        i, j, c, dy, d = a
        if i not in best_l or (c, dy, d) < best_l[i][2:]:
            best_l[i] = a
        if j not in best_r or (c, dy, d) < best_r[j][2:]:
            best_r[j] = a
    out = [best_l[i] for i in sorted(best_l)]
    if lr_check:
        out = [a for a in out if best_r[a[1]][0] == a[0]]
    return out


@pytest.mark.parametrize("case,cost,split,rows,lr,window", [
    (0, "sad", 1, 0, False, (9, 9)), (1, "sad", 1, 1, True, (5, 7)), (2, "ssd", 1, 1, False, (7, 5)),
    (3, "ncc", 1, 1, False, (5, 5)), (4, "sad", 5, 0, False, (5, 7)), (5, "sad", 9, 1, True, (5, 7)),
    (6, "ssd", 9, 0, False, (3, 3)), (7, "sad", 1, 2, True, (3, 9)),
])
def test_vectorized_matching_equals_brute_force(case, cost, split, rows, lr, window):
    rng = np.random.default_rng(100 + case)
    base = dots(40, 70, 50 + case, dot=3)
    L = base[:, :64]
    R = np.clip(base[:, 5:69].astype(int) + rng.integers(-25, 26, L.shape), 0, 255).astype(np.uint8)
    fl = np.unique(np.stack([rng.integers(0, 64, 60), rng.integers(0, 40, 60)], 1), axis=0)
    # right corners: most left corners moved by the true shift (some a row off), plus random ones
    fr = fl - [5, 0] + np.stack([np.zeros(len(fl), int), rng.integers(-1, 2, len(fl))], 1)
    fr = np.concatenate([fr, np.stack([rng.integers(0, 64, 60), rng.integers(0, 40, 60)], 1)])
    fr = np.unique(np.clip(fr, 0, [63, 39]), axis=0)
    kw = dict(window=window, t_max=14.0, cost=cost, d_max=20, rows=rows, split=split, lr_check=lr)
    m = M.match_features(L, R, fl, fr, ncc_min=0.3, **kw)
    ref = ref_match(L, R, fl, fr, ncc_min=0.3, **kw)
    assert len(ref) > 3
    assert m.left_index.tolist() == [a[0] for a in ref]
    assert m.right_index.tolist() == [a[1] for a in ref]
    assert m.disparity.tolist() == [a[4] for a in ref]
    np.testing.assert_allclose(m.cost, [a[2] for a in ref], rtol=1e-9, atol=1e-12)


# --------------------------------------------------------------------------------------------------
# Corners and images


def test_threshold_for_count_is_the_closest_code():
    img = dots(72, 96, 4, dot=3)
    for target in (50, 150):
        code = M.threshold_for_count(img, target)
        n = {c: len(corners(img, c)) for c in (max(code - 1, 0), code, code + 1)}
        assert abs(n[code] - target) <= min(abs(v - target) for v in n.values())
        assert np.array_equal(M.detect_corners(img, threshold=code), corners(img, code))
        assert np.array_equal(M.detect_corners(img, count=target), corners(img, code))


def test_as_grey_converts_colour_and_rejects_floats():
    rgb = np.zeros((4, 5, 3), np.uint8)
    rgb[..., 0] = 200
    assert M.as_grey(rgb).shape == (4, 5) and M.as_grey(rgb)[0, 0] == cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY)[0, 0]
    assert M.as_grey(rgb, order="bgr")[0, 0] == cv2.cvtColor(rgb, cv2.COLOR_BGR2GRAY)[0, 0]
    assert M.as_grey(np.full((3, 3), 7, np.int64)).dtype == np.uint8
    with pytest.raises(ValueError, match="integers 0..255"):
        M.as_grey(np.zeros((3, 3)))
    with pytest.raises(ValueError, match="0..255"):
        M.as_grey(np.full((3, 3), 300))
    with pytest.raises(ValueError, match="2-D"):
        M.as_grey(np.zeros((2, 3, 4, 5), np.uint8))


# --------------------------------------------------------------------------------------------------
# Bad input


def test_bad_input_gives_clear_errors():
    left, right = shifted_pair()
    fl, fr = corners(left), corners(right)
    with pytest.raises(ValueError, match="differ in size"):
        M.match_features(left, right[:, :-1], fl, fr)
    with pytest.raises(ValueError, match="left feature list is empty"):
        M.match_features(left, right, np.zeros((0, 2), int), fr)
    with pytest.raises(ValueError, match="right feature list is empty"):
        M.match_features(left, right, fl, [])
    with pytest.raises(ValueError, match=r"\(n, 2\)"):
        M.match_features(left, right, fl[:, :1], fr)
    with pytest.raises(ValueError, match="outside"):
        M.match_features(left, right, fl + [1000, 0], fr)
    with pytest.raises(ValueError, match="integer pixel"):
        M.match_features(left, right, fl + 0.5, fr)
    with pytest.raises(ValueError, match="odd"):
        M.match_features(left, right, fl, fr, window=(4, 5))
    with pytest.raises(ValueError, match="cost"):
        M.match_features(left, right, fl, fr, cost="census")
    with pytest.raises(ValueError, match="split"):
        M.match_features(left, right, fl, fr, split=3)
    with pytest.raises(ValueError, match="SAD and SSD"):
        M.match_features(left, right, fl, fr, split=9, cost="ncc")
    with pytest.raises(ValueError, match="disparity range"):
        M.match_features(left, right, fl, fr, d_min=5, d_max=2)
    with pytest.raises(ValueError, match="t_max"):
        M.match_features(left, right, fl, fr, t_max=0)
    with pytest.raises(ValueError, match="too small"):
        M.detect_corners(np.zeros((6, 40), np.uint8))


# --------------------------------------------------------------------------------------------------
# Real images


@needs_middlebury
def test_tsukuba_500_corners_match_fast_and_well():
    L = M.load_grey(DATA / "tsukuba" / "im3.png")
    R = M.load_grey(DATA / "tsukuba" / "im4.png")
    gt = Q.load_disparity(DATA / "tsukuba" / "disp3.pgm", 16)
    code = M.threshold_for_count(L, 500)
    fl, fr = M.detect_corners(L, threshold=code), M.detect_corners(R, threshold=code)
    assert 450 <= len(fl) <= 550 and 400 <= len(fr) <= 600
    t0 = time.perf_counter()
    m = M.match_features(L, R, fl, fr, d_max=15, window=(9, 9), t_max=11)
    dt = time.perf_counter() - t0
    assert dt < 0.5
    s = Q.sparse_scores(m.left, m.disparity, gt)
    assert len(m) > 200 and s.bad_percent < 10 and s.rms < 1.5
