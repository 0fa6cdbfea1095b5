"""The dense stereo chain (tools/models/dense_stereo.py, median3.py) against the float reference
(tools/dense/reference.py) on Tsukuba at 352 x 288, D = 64.

Tolerance: with the model's full widths (nothing saturates, no LSB dropped) the two differ only by the
sub-pixel rounding: the same pixels valid and at most 1/32 px apart. With the default widths (one LSB
dropped from the sums) at least 99 % of the pixels agree on validity and at least 99 % of those valid in
both are within 1/4 px.
"""

from __future__ import annotations

import numpy as np
import pytest

from eyestereo.tools.dense import datasets, reference as R
from eyestereo.tools.models import dense_stereo as M
from eyestereo.tools.models.median3 import median3

needs_data = pytest.mark.skipif(not (datasets.data_dir() / "middlebury" / "tsukuba" / "im3.png").is_file(),
                                reason="Middlebury pairs not in the shared data folder")
FULL = dict(cost_bits=None, path_bits=9, sum_shift=0, frac_bits=4)


@pytest.fixture(scope="module")
def tsukuba():
    pair = datasets.resize(datasets.load("tsukuba"))
    return pair, R.reference(pair.left, pair.right)


@needs_data
def test_full_widths_equal_the_reference_but_for_rounding(tsukuba):
    pair, ref = tsukuba
    got = M.to_float(M.dense_stereo(pair.left, pair.right, **FULL))
    assert np.array_equal(np.isfinite(got), np.isfinite(ref))
    both = np.isfinite(got)
    assert both.mean() > 0.8
    assert np.abs(got - ref)[both].max() <= 1 / 32


@needs_data
def test_default_widths_within_tolerance(tsukuba):
    pair, ref = tsukuba
    got = M.to_float(M.dense_stereo(pair.left, pair.right))
    assert np.mean(np.isfinite(got) == np.isfinite(ref)) >= 0.99
    both = np.isfinite(got) & np.isfinite(ref)
    assert np.mean(np.abs(got - ref)[both] <= 0.25) >= 0.99


def brute_median(a):
    out = a.copy()
    for y in range(1, a.shape[0] - 1):
        for x in range(1, a.shape[1] - 1):
            out[y, x] = sorted(a[y - 1:y + 2, x - 1:x + 2].ravel().tolist())[4]
    return out


def test_median_against_loops_and_its_border():
    rng = np.random.default_rng(4)
    a = rng.integers(0, 400, (7, 9)).astype(np.uint16)
    a[rng.random(a.shape) < 0.3] = M.INVALID
    got = median3(a)
    assert np.array_equal(got, brute_median(a))
    assert np.array_equal(got[0], a[0]) and np.array_equal(got[:, -1], a[:, -1])
    b = np.full((3, 3), 160, np.uint16)
    b.flat[:5] = M.INVALID  # five of nine invalid: invalid
    assert median3(b)[1, 1] == M.INVALID
    b.flat[0] = 7  # four invalid: the fifth smallest of the valid ones and the four largest
    assert median3(b)[1, 1] == 160
    with pytest.raises(ValueError, match="16-bit unsigned"):
        median3(np.full((3, 3), -1))
    with pytest.raises(ValueError, match="2-D map"):
        median3(np.zeros(5, np.uint16))


def test_chain_checks_its_input():
    img = np.zeros((20, 40), np.uint8)
    with pytest.raises(ValueError, match="must exceed the 64 disparities"):
        M.dense_stereo(img, img)
    with pytest.raises(ValueError, match="differ in size"):
        M.dense_stereo(img, img[:, :-1], disparities=16)
    with pytest.raises(ValueError, match="paths must be one of"):
        M.dense_stereo(img, img, disparities=16, paths=8)
    with pytest.raises(ValueError, match="must exceed the 64 disparities"):
        R.reference(img, img)


def test_to_float():
    got = M.to_float(np.array([[0, 24, M.INVALID]], np.uint16))
    assert got[0, 0] == 0 and got[0, 1] == 1.5 and np.isnan(got[0, 2])
