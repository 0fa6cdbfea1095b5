"""SGM model (tools/models/sgm.py): hand-made cases with known answers, the recurrence by hand, bad input."""

from __future__ import annotations

import numpy as np
import pytest

from eyestereo.tools.models import sgm as S
from eyestereo.tools.models.census import census_stereo

PLAIN = dict(uniqueness=0, lr_check=False, subpixel=False)


def textured(h, w, seed):
    return np.random.default_rng(seed).integers(0, 256, (h, w), dtype=np.uint8)


def shifted_pair(h, w, shift, seed=0):
    """Right view = left view seen ``shift`` px further: left(x) = right(x - shift)."""
    big = textured(h, w + shift, seed)
    return big[:, :w], big[:, shift:shift + w]


@pytest.mark.parametrize("shift, paths", [(0, 4), (5, 4), (11, 2), (23, 4)])
def test_constant_shift_gives_that_disparity(shift, paths):
    left, right = shifted_pair(24, 64, shift)
    codes = S.sgm(*census_stereo(left, right), disparities=32, paths=paths, **PLAIN)
    inner = codes[3:-3, shift + 3:-3]
    assert np.all(inner == 16 * shift)
    full = S.sgm(*census_stereo(left, right), disparities=32, paths=paths)  # uniqueness, lr check, sub-pixel
    inner = full[3:-3, shift + 3:-3].astype(np.int64)
    assert np.all(np.abs(inner - 16 * shift) <= 8)


def test_textureless_region_fills_with_a_large_p2():
    shift = 6
    left, right = shifted_pair(40, 72, shift, seed=3)
    left, right = left.copy(), right.copy()
    left[10:30, 25:55] = 128                 # the same flat patch in both views, where it belongs
    right[10:30, 25 - shift:55 - shift] = 128
    cl, cr = census_stereo(left, right)
    region = (slice(14, 26), slice(29, 51))  # the patch without the census border
    smooth = S.sgm(cl, cr, disparities=16, p1=2, p2=255, **PLAIN)[region]
    assert np.mean(smooth == 16 * shift) > 0.95
    alone = S.sgm(cl, cr, disparities=16, p1=0, p2=0, **PLAIN)[region]  # no aggregation: ambiguous
    assert np.mean(alone == 16 * shift) < 0.5


def test_recurrence_by_hand():
    cost = np.array([[[0, 5, 5], [5, 0, 5], [9, 9, 0]]], np.int32)  # one row, 3 pixels, D = 3
    lr = S.path_costs(cost, (-1, 0), 1, 3, 9)
    # x1: d0 min(0, 5+1, 0+3) = 0 -> 5; d1 min(5, 0+1, 5+1, 3) = 1 -> 1; d2 min(5, 5+1, 3) = 3 -> 8
    # x2: min of x1 = 1; d0 min(5, 1+1, 4) - 1 = 1 -> 10; d1 min(1, 5+1, 8+1, 4) - 1 = 0 -> 9; d2 min(8, 2, 4) - 1 -> 1
    assert lr[0].tolist() == [[0, 5, 5], [5, 1, 8], [10, 9, 1]]
    top = S.path_costs(cost.transpose(1, 0, 2), (0, -1), 1, 3, 9)  # the same along a column
    assert top[:, 0].tolist() == lr[0].tolist()
    assert S.path_costs(cost, (-1, 0), 1, 3, 3).max() == 7  # saturated at 2**3 - 1
    diag = S.path_costs(np.repeat(cost, 2, axis=0), (1, -1), 1, 3, 9)  # from the previous row's right
    # (y1, x0) after (y0, x1) = [5, 0, 5], min 0: d0 min(5, 0+1, 3) -> 0+1; d1 min(0, 6, 6, 3) -> 5+0;
    # d2 min(5, 0+1, 3) -> 5+1; the last column has no predecessor: a new path
    assert diag[1, 0].tolist() == [1, 5, 6] and diag[1, 2].tolist() == [9, 9, 0]


def volume(w, dn, value=50):
    return np.full((1, w, dn), value, np.int64)


def test_winner_uniqueness_and_candidates():
    s = volume(30, 16)
    s[0, 20, 5] = 10
    assert S.select(s, **PLAIN)[0, 20] == 80
    s[0, 20, 9] = 11  # a rival 4 disparities away: 100 * 10 > 90 * 11
    assert S.select(s, uniqueness=10, lr_check=False, subpixel=False)[0, 20] == S.INVALID
    assert S.select(s, uniqueness=5, lr_check=False, subpixel=False)[0, 20] == 80
    s[0, 20, 9] = 50
    s[0, 20, 6] = 10  # a tie next door: the smaller d, and d +- 1 do not count as rivals
    assert S.select(s, uniqueness=50, lr_check=False, subpixel=False)[0, 20] == 80
    s[0, 2, 10] = 0  # d = 10 > x = 2 is no candidate
    assert S.select(s, **PLAIN)[0, 2] == 0


@pytest.mark.parametrize("cm, c0, cp, q", [(10, 4, 6, 4), (9, 4, 6, 3), (6, 4, 9, -3), (5, 4, 20, -7),
                                           (20, 4, 5, 7), (5, 4, 5, 0), (50, 4, 5, 8)])
def test_subpixel_by_hand(cm, c0, cp, q):
    # q = round(8 (cm - cp) / (cm + cp - 2 c0)) by hand: 32/8 = 4, 24/7 = 3.4, -24/7, -120/17 = -7.06,
    # 120/17, 0, 360/47 = 7.66
    s = volume(30, 16, 99)
    s[0, 20, 6:9] = (cm, c0, cp)
    assert int(S.select(s, uniqueness=0, lr_check=False, subpixel=True)[0, 20]) == 16 * 7 + q
    s[0, 20, 8] = 99  # d + 1 no candidate for x = 7: no offset
    s[0, 7, 6:9] = (cm, c0, cp)
    assert int(S.select(s, uniqueness=0, lr_check=False, subpixel=True)[0, 7]) == 16 * 7


def test_half_rounds_away_from_zero():
    s = volume(30, 16, 99)
    s[0, 20, 6:9] = (13, 4, 11)  # num 2, den 16: 8 * 2 / 16 = 1.0 exactly -> 1
    s[0, 21, 6:9] = (12, 4, 11)  # num 1, den 15: 0.533 -> 1
    s[0, 22, 6:9] = (27, 4, 26)  # num 1, den 45: 0.178 -> 0
    s[0, 23, 6:9] = (24, 4, 25)  # num -1, den 41: -0.195 -> 0; and den 16 num -1 below
    s[0, 24, 6:9] = (11, 4, 12)  # num -1, den 15: -0.533 -> -1
    got = S.select(s, uniqueness=0, lr_check=False, subpixel=True)[0, 20:25].astype(int).tolist()
    assert got == [113, 113, 112, 112, 111]


def test_left_right_check():
    s = volume(30, 8)
    s[0, 10, 4] = 0  # left pixel 10 -> d = 4, right pixel 6 sees it on its diagonal
    assert S.select(s, uniqueness=0, lr_check=True, subpixel=False)[0, 10] == 64
    s[0, 6, 0] = 0  # right pixel 6's diagonal now has a tie at d = 0: the smaller d wins, |4 - 0| > 1
    assert S.select(s, uniqueness=0, lr_check=True, subpixel=False)[0, 10] == S.INVALID
    assert S.select(s, uniqueness=0, lr_check=False, subpixel=False)[0, 10] == 64


def test_costs_outside_the_right_image_are_the_maximum():
    left, right = shifted_pair(8, 40, 3)
    cl, cr = census_stereo(left, right)
    cost = S.matching_costs(cl, cr, 16, 24)
    assert np.all(cost[:, 2, 3:] == 24) and cost[:, 10, 3].max() < 24
    assert S.matching_costs(cl, cr, 16, 15).max() == 15


def census_pair():
    return census_stereo(*shifted_pair(8, 40, 2))


@pytest.mark.parametrize("kw, match", [
    (dict(disparities=15), "disparities must be in 16..128"), (dict(disparities=129), "disparities must be in"),
    (dict(disparities=True), "disparities must be an int"), (dict(paths=3), "paths must be one of"),
    (dict(p1=40, p2=30), "P1 <= P2"), (dict(p2=256), "P2 <= 255"), (dict(p1=-1), "0 <= P1"),
    (dict(uniqueness=100), "uniqueness is a percentage"), (dict(window=3), "census window"),
    (dict(cost_bits=6), "cost_bits must be 1..5"), (dict(path_bits=3), "path_bits must be 4..12"),
    (dict(sum_shift=7), "sum_shift"), (dict(frac_bits=5), "frac_bits must be 0..4"),
    (dict(p1=1.5), "P1 must be an int")])
def test_bad_parameters(kw, match):
    with pytest.raises(ValueError, match=match):
        S.sgm(*census_pair(), **kw)


def test_census_words_must_agree():
    cl, cr = census_pair()
    with pytest.raises(ValueError, match="one size"):
        S.sgm(cl, cr[:, :-1])
