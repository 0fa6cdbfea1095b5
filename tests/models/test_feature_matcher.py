"""Feature matcher model (tools/models/feature_matcher.py): against the software matcher on Tsukuba, on
hand-built pairs whose answer is known, the words, the census cost against the census model, bad input."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from eyestereo.tools.matching.sparse import detect_corners, load_pair, match_features
from eyestereo.tools.models import census as C
from eyestereo.tools.models import feature_matcher as F


def raster(points) -> np.ndarray:
    """(x, y) points as a raster-ordered (n, 2) int64 list without repeats (the feature list's order)."""
    pts = sorted(set(map(tuple, points)), key=lambda p: (p[1], p[0]))
    return np.array(pts, np.int64).reshape(-1, 2)


def shifted_texture(seed: int, h: int, w: int, d: int, top: int = 200):
    """A random texture (grey 0..top-1) and its right view: right[y, x - d] == left[y, x]."""
    t = np.random.default_rng(seed).integers(0, top, (h, w + d)).astype(np.uint8)
    return t[:, :w], t[:, d:d + w]


def triples(res: dict) -> set:
    m = res["matches"]
    return set(zip(res["left_index"].tolist(), res["right_index"].tolist(), m[:, 2].tolist(), m[:, 3].tolist()))


# --------------------------------------------------------------------------------------------------
# (a) the software matcher's results, exactly


@pytest.fixture
def tsukuba(tsukuba_pair):
    """A 300x160 Tsukuba crop and its right view 7 px further, made unlike a copy (noise of +-6 grey
    levels, a slight blur) so the costs spread and the threshold cuts; the corners of each view by the
    bit-true Harris model. ``up`` moves the right view's content one row up (matches at dy = -1)."""
    def make(up: int):
        lp, rp = tsukuba_pair(slice(40, 201), slice(0, 300), 7)
        left, right = load_pair(lp, rp)
        left, right = left[:160], right[up:160 + up]
        noise = np.random.default_rng(1).integers(-6, 7, right.shape)
        right = cv2.GaussianBlur(np.clip(right.astype(int) + noise, 0, 255).astype(np.uint8), (3, 3), 0.6)
        return left, right, detect_corners(left, count=150), detect_corners(right, count=150)
    return make


@pytest.mark.parametrize("window,t_max,rows,up,lr_check", [
    (9, 11, 0, 0, False), (9, 11, 0, 0, True), (9, 11, 1, 1, False), (9, 11, 1, 1, True),
    (5, 8, 1, 0, True), (11, 14, 0, 0, False),
])
def test_equals_software_matcher(tsukuba, window, t_max, rows, up, lr_check):
    left, right, fl, fr = tsukuba(up)
    kw = dict(t_max=t_max, d_min=2, d_max=40, rows=rows, lr_check=lr_check)
    soft = match_features(left, right, fl, fr, window=window, cost="sad", split=1, **kw)
    hard = F.feature_matcher(left, right, fl, fr, window=window, cost="sad", uniqueness=0, **kw)
    want = set(zip(soft.left_index.tolist(), soft.right_index.tolist(), soft.disparity.tolist(),
                   soft.cost.astype(np.int64).tolist()))
    assert len(want) >= 40  # a real test: many matches, and some corners refused by the threshold
    assert triples(hard) == want
    assert np.any(hard["status"] == F.OVER_THRESHOLD)
    assert hard["candidates"] == soft.candidates
    assert np.array_equal(hard["matches"][:, :2], fl[hard["left_index"]])
    assert np.array_equal(fr[hard["right_index"]][:, 1] - fl[hard["left_index"]][:, 1], hard["dy"])
    assert np.all(np.diff(hard["left_index"]) > 0)  # the order of the left corners
    if up:
        assert np.count_nonzero(hard["dy"] == -1) > len(want) // 2


def test_ties_like_software_matcher():
    """Equal costs (copies of the left window): |dy| first, then the smaller disparity, then the right
    corner above; the model and the software pick the same, and the one said here."""
    rng = np.random.default_rng(3)
    left = rng.integers(0, 200, (64, 80)).astype(np.uint8)
    right = rng.integers(0, 200, (64, 80)).astype(np.uint8)

    def copy(xl, yl, xr, yr):  # the left 5x5 window at (xl, yl) into the right image at (xr, yr)
        right[yr - 2:yr + 3, xr - 2:xr + 3] = left[yl - 2:yl + 3, xl - 2:xl + 3]

    copy(44, 10, 34, 10), copy(44, 10, 20, 10)  # same row: d = 10 beats d = 24
    copy(54, 30, 34, 27), copy(54, 30, 34, 33)  # same d, |dy| = 3: the one above (dy = -3) wins
    copy(60, 50, 30, 50), copy(60, 50, 50, 51)  # |dy| = 0 at d = 30 beats |dy| = 1 at d = 10
    fl = raster([(44, 10), (54, 30), (60, 50)])
    fr = raster([(34, 10), (20, 10), (34, 27), (34, 33), (30, 50), (50, 51)])
    kw = dict(window=5, t_max=11, d_min=0, d_max=40, rows=3)
    soft = match_features(left, right, fl, fr, **kw)
    hard = F.feature_matcher(left, right, fl, fr, **kw)
    assert triples(hard) == set(zip(soft.left_index.tolist(), soft.right_index.tolist(), soft.disparity.tolist(),
                                    soft.cost.astype(np.int64).tolist()))
    assert fr[hard["right_index"]].tolist() == [[34, 10], [34, 27], [30, 50]]
    assert hard["matches"][:, 3].tolist() == [0, 0, 0] and hard["second"].tolist() == [0, 0, 0]


# --------------------------------------------------------------------------------------------------
# (b) a known answer


def corners_and_distractors(d: int, xs=(40, 52, 66, 80), ys=(12, 25, 40)):
    """Left corners on a grid; their true right corners (x - d) and two wrong ones per left corner."""
    fl = raster([(x, y) for y in ys for x in xs])
    fr = raster([(x - d + off, y) for y in ys for x in xs for off in (0, -5, 3)])
    return fl, fr


def test_shifted_texture_matched_at_its_disparity():
    d = 9
    left, right = shifted_texture(5, 56, 100, d, top=60)  # low contrast: the wrong candidates pass t_max too
    fl, fr = corners_and_distractors(d)
    res = F.feature_matcher(left, right, fl, fr, window=9, t_max=50, d_min=0, d_max=30)
    assert res["count"] == len(fl) and res["total"] == len(fl) and not res["overflow"]
    assert res["matches"].tolist() == [[x, y, d, 0] for x, y in fl.tolist()]
    assert res["candidates"] == sum(yl == yr and 0 <= xl - xr <= 30 for xl, yl in fl.tolist() for xr, yr in fr.tolist())
    assert np.all(res["second"] > 0) and np.all(res["second"] < res["limit"])  # the wrong ones were accepted
    assert res["limit"] == 50 * 81


# --------------------------------------------------------------------------------------------------
# (c) uniqueness


def repeated_pattern(d: int, period: int = 16, h: int = 40, w: int = 100, offset: int = 2):
    """A texture repeating every ``period`` columns; the right view shifted by d and ``offset`` brighter,
    so the true and the next repeat cost exactly ``offset * 81`` each (9x9)."""
    block = np.random.default_rng(7).integers(0, 200, (h, period))
    t = np.tile(block, (1, (w + d) // period + 1))[:, :w + d]
    return t[:, :w].astype(np.uint8), (t[:, d:d + w] + offset).astype(np.uint8)


def test_uniqueness_rejects_two_equally_good_candidates():
    d, x, y = 6, 60, 20
    left, right = repeated_pattern(d)
    fl = raster([(x, y)])
    fr = raster([(x - d, y), (x - d - 16, y)])  # the true corner and the pattern's next repeat
    kw = dict(window=9, t_max=11, d_min=0, d_max=40)
    off = F.feature_matcher(left, right, fl, fr, uniqueness=0, **kw)
    assert off["matches"].tolist() == [[x, y, d, 162]]  # a tie: the smaller disparity, as the software
    assert off["second"].tolist() == [162]
    on = F.feature_matcher(left, right, fl, fr, uniqueness=1, **kw)
    assert on["count"] == 0 and on["status"].tolist() == [F.NOT_UNIQUE]
    alone = F.feature_matcher(left, right, fl, fr[:1] if fr[0, 0] == x - d else fr[1:], uniqueness=50, **kw)
    assert alone["matches"].tolist() == [[x, y, d, 162]]  # one candidate: nothing to be unique against


def test_uniqueness_boundary():
    d, x, y = 6, 60, 20
    left, right = repeated_pattern(d)
    right[y, x - d - 16] += 8  # the repeat's centre 10 grey levels off instead of 2: 162 + 8 = 170
    fl, fr = raster([(x, y)]), raster([(x - d, y), (x - d - 16, y)])
    kw = dict(window=9, t_max=11, d_min=0, d_max=40)
    # 162 * 104 = 16848 <= 17000; 162 * 105 = 17010 > 17000
    assert F.feature_matcher(left, right, fl, fr, uniqueness=4, **kw)["matches"].tolist() == [[x, y, d, 162]]
    res = F.feature_matcher(left, right, fl, fr, uniqueness=5, **kw)
    assert res["count"] == 0 and res["second"].tolist() == [170]


# --------------------------------------------------------------------------------------------------
# left-right check, list length, words


def test_lr_check_drops_the_right_corners_second_choice():
    rng = np.random.default_rng(11)
    left = rng.integers(0, 200, (40, 80)).astype(np.uint8)
    right = rng.integers(0, 200, (40, 80)).astype(np.uint8)
    y, xr, xa, xb = 20, 30, 40, 55
    rows = np.s_[y - 4:y + 5]
    right[rows, xr - 4:xr + 5] = left[rows, xa - 4:xa + 5]      # A matches R at cost 0
    left[rows, xb - 4:xb + 5] = left[rows, xa - 4:xa + 5] + 1   # B matches R at cost 81, R's second choice
    fl, fr = raster([(xa, y), (xb, y)]), raster([(xr, y)])
    kw = dict(window=9, t_max=11, d_min=0, d_max=40)
    both = F.feature_matcher(left, right, fl, fr, **kw)
    assert both["matches"].tolist() == [[xa, y, 10, 0], [xb, y, 25, 81]]
    checked = F.feature_matcher(left, right, fl, fr, lr_check=True, **kw)
    assert checked["matches"].tolist() == [[xa, y, 10, 0]]
    assert checked["status"].tolist() == [F.MATCHED, F.LR_FAILED]


def test_max_matches_cuts_the_list_and_sets_overflow():
    d = 9
    left, right = shifted_texture(5, 56, 100, d)
    fl, fr = corners_and_distractors(d)  # 12 left corners, all matched
    cut = F.feature_matcher(left, right, fl, fr, d_max=30, max_matches=5)
    assert cut["count"] == 5 and cut["total"] == 12 and cut["overflow"] is True
    assert cut["matches"].tolist() == [[x, y, d, 0] for x, y in fl[:5].tolist()]
    assert len(cut["words"]) == 3 * 5 + 3
    assert cut["words"][-2] == (5 | 1 << 15, False, False)  # count 5, overflow bit
    full = F.feature_matcher(left, right, fl, fr, d_max=30, max_matches=12)
    assert full["count"] == 12 and full["overflow"] is False and full["words"][-2] == (12, False, False)


def test_words_of_one_match_and_trailer():
    """x = 40, y = 30, dy = -1, d = 9, cost = 3 * 81 = 243, packed by hand."""
    rng = np.random.default_rng(2)
    t = rng.integers(0, 200, (62, 109)).astype(np.uint8)
    left, right = t[1:61, :100], t[2:62, 9:109] + 3  # right[y - 1, x - 9] == left[y, x] + 3
    res = F.feature_matcher(left, right, raster([(40, 30)]), raster([(31, 29)]), rows=1, d_max=30)
    assert res["matches"].tolist() == [[40, 30, 9, 243]] and res["dy"].tolist() == [-1]
    assert res["words"] == [
        (40 | 0xF << 12, False, False),           # x, dy = -1 (4-bit two's complement)
        (30 | (9 & 0xF) << 12, False, False),     # y, disparity bits 3..0
        (9 >> 4 | 243 << 4, False, False),        # disparity bits 7..4, cost
        (0x8000, False, False), (1, False, False), (1, True, True),  # marker, count 1, 1 candidate
    ]


def test_empty_lists_give_a_trailer_alone():
    left, right = shifted_texture(1, 20, 30, 0)
    res = F.feature_matcher(left, right, np.zeros((0, 2), int), raster([(5, 5)]))
    assert res["count"] == 0 and res["candidates"] == 0
    assert res["words"] == [(0x8000, False, False), (0, False, False), (0, True, True)]


# --------------------------------------------------------------------------------------------------
# (f) census


@pytest.mark.parametrize("window", [5, 7])
def test_census_cost_is_the_census_blocks_hamming_distance(tsukuba, window):
    """Every pair's cost = popcount of the XOR of the census model's words, corners at the border too."""
    left, right, fl, fr = tsukuba(0)
    h, w = left.shape
    edge = [(0, 0), (1, 0), (w - 1, 0), (0, h // 2), (w - 1, h // 2), (2, h - 1), (w - 1, h - 1)]
    fl, fr = raster(fl.tolist() + edge), raster(fr.tolist() + edge)
    res = F.feature_matcher(left, right, fl, fr, window=window, cost="census", h_max=100, d_max=40, rows=1)
    cl, cr = C.census(left, window=window), C.census(right, window=window)
    li, ri = res["pairs"]["left"], res["pairs"]["right"]
    xor = cl[fl[li, 1], fl[li, 0]] ^ cr[fr[ri, 1], fr[ri, 0]]
    want = np.array([bin(int(v)).count("1") for v in xor])
    assert len(li) > 200
    assert np.array_equal(res["pairs"]["cost"], want)


def test_census_finds_the_shifted_texture():
    d = 9
    left, right = shifted_texture(5, 56, 100, d, top=60)
    fl, fr = corners_and_distractors(d)
    res = F.feature_matcher(left, right, fl, fr, window=7, cost="census", h_max=100, d_max=30)
    assert res["matches"].tolist() == [[x, y, d, 0] for x, y in fl.tolist()]
    assert np.all(res["second"] > 0)
    assert res["limit"] == 48  # ceil(100 * 48 / 100)


def test_census_ignores_a_brightness_offset_sad_does_not():
    """What census buys: the right camera 40 grey levels brighter (another exposure) -- every SAD cost
    is at least 40 * 81, far over t_max * 81, and nothing matches; the census words do not change."""
    d = 9
    left, right = shifted_texture(5, 56, 100, d)
    right = right + np.uint8(40)  # 0..199 + 40: no clipping, the order of the grey levels is kept
    fl, fr = corners_and_distractors(d)
    sad = F.feature_matcher(left, right, fl, fr, window=9, cost="sad", t_max=11, d_max=30)
    assert sad["count"] == 0 and np.all(sad["status"] == F.OVER_THRESHOLD) and np.all(sad["best"] >= 40 * 81)
    cen = F.feature_matcher(left, right, fl, fr, window=9, cost="census", h_max=25, d_max=30)
    assert cen["matches"].tolist() == [[x, y, d, 0] for x, y in fl.tolist()]


# --------------------------------------------------------------------------------------------------
# (e) bad input


GOOD = dict(window=9, cost="sad", t_max=11, d_min=0, d_max=64, rows=0, uniqueness=0, lr_check=False, max_matches=1023)


@pytest.mark.parametrize("change,match", [
    (dict(window=8), r"window=8: must be odd"),
    (dict(window=13), r"window=13: must be odd and one of \(5, 7, 9, 11\)"),
    (dict(window=3), r"window=3"),
    (dict(cost="ncc"), r"cost='ncc': must be one of \('sad', 'census'\)"),
    (dict(t_max=0), r"t_max=0: must be 1..50"),
    (dict(t_max=51), r"t_max=51: must be 1..50 .*12-bit cost field"),
    (dict(t_max=11.0), r"t_max=11.0: must be an integer"),
    (dict(cost="census", h_max=0), r"h_max=0: must be 1..100"),
    (dict(cost="census", h_max=101), r"h_max=101"),
    (dict(d_min=-1), r"d_min=-1: must be >= 0"),
    (dict(d_min=10, d_max=5), r"disparity range is empty"),
    (dict(d_max=256), r"d_max=256: must be <= 255"),
    (dict(rows=-1), r"rows=-1: must be 0..7"),
    (dict(rows=8), r"rows=8: must be 0..7"),
    (dict(uniqueness=100), r"uniqueness=100: must be 0..99"),
    (dict(uniqueness=-1), r"uniqueness=-1"),
    (dict(max_matches=0), r"max_matches=0: must be 1..32767"),
    (dict(max_matches=1 << 15), r"max_matches=32768"),
    (dict(lr_check="yes"), r"lr_check='yes': must be True or False"),
])
def test_parameter_errors(change, match):
    left, right = shifted_texture(1, 20, 30, 0)
    with pytest.raises(ValueError, match=match):
        F.feature_matcher(left, right, raster([(5, 5)]), raster([(4, 5)]), **{**GOOD, **change})


@pytest.mark.parametrize("what,match", [
    ("shape", r"left and right images differ in size: 30x20 and 31x20"),
    ("outside", r"right features lie outside the 30x20 image"),
    ("negative", r"left features lie outside"),
    ("order", r"left features must be in raster order without repeats"),
    ("repeat", r"right features must be in raster order without repeats"),
    ("columns", r"left features must be an \(n, 2\) array"),
    ("float", r"right features must be integer pixel coordinates"),
    ("image", r"left image must be a 2-D grey image"),
])
def test_input_errors(what, match):
    left, right = shifted_texture(1, 20, 30, 0)
    fl, fr = raster([(5, 5), (9, 7)]), raster([(4, 5)])
    if what == "shape":
        right = np.zeros((20, 31), np.uint8)
    elif what == "outside":
        fr = np.array([[30, 5]])
    elif what == "negative":
        fl = np.array([[-1, 5]])
    elif what == "order":
        fl = fl[::-1]
    elif what == "repeat":
        fr = np.array([[4, 5], [4, 5]])
    elif what == "columns":
        fl = np.array([[5, 5, 0]])
    elif what == "float":
        fr = fr.astype(float)
    elif what == "image":
        left = np.zeros((20, 30, 3), np.uint8)
    with pytest.raises(ValueError, match=match):
        F.feature_matcher(left, right, fl, fr)
