"""Disparity metrics (tools/metrics.py) on constructed cases whose answers are worked out by hand."""

from __future__ import annotations

import os
import math
from pathlib import Path

import cv2
import numpy as np
import pytest

import eyestereo.tools
from eyestereo.tools.matching import metrics as Q

SHARED = Path(os.environ.get("EYESTEREO_SHARED", Path(eyestereo.tools.__file__).resolve().parents[1].parent / "shared"))
DATA = SHARED / "data" / "middlebury"
needs_middlebury = pytest.mark.skipif(not (DATA / "tsukuba" / "disp3.pgm").is_file(),
                                      reason=f"Middlebury ground truth not found at {DATA}")


def test_sparse_scores_by_hand():
    gt = np.full((10, 20), 4.0)
    gt[0, :] = np.nan                                   # unknown row
    pts = np.array([[x, 5] for x in range(10)] + [[3, 0]])
    d = np.array([4, 4, 4, 4, 5, 3, 6, 2, 7, 4.5, 9])    # errors 0 0 0 0 1 -1 2 -2 3 0.5, unknown
    s = Q.sparse_scores(pts, d, gt)
    assert (s.evaluated, s.good, s.bad, s.unknown) == (10, 7, 3, 1)
    assert s.bad_percent == 30.0
    assert s.rms == pytest.approx(math.sqrt((1 + 1 + 4 + 4 + 9 + 0.25) / 10), abs=1e-15)


def test_bad_threshold_is_strictly_greater_than_one():
    gt = np.zeros((1, 3))
    gt[:] = 10.0
    s = Q.sparse_scores([[0, 0], [1, 0], [2, 0]], [11.0, 9.0, 11.000001], gt)
    assert (s.good, s.bad) == (2, 1)
    s = Q.sparse_scores([[0, 0]], [12.0], gt, bad_threshold=2.0)
    assert (s.good, s.bad) == (1, 0)


def test_perfect_and_empty_cases():
    gt = np.arange(12, dtype=float).reshape(3, 4)
    ys, xs = np.mgrid[0:3, 0:4]
    pts = np.stack([xs.ravel(), ys.ravel()], 1)
    s = Q.sparse_scores(pts, gt.ravel(), gt)
    assert (s.evaluated, s.bad, s.rms, s.bad_percent) == (12, 0, 0.0, 0.0)
    e = Q.sparse_scores(np.zeros((0, 2)), [], gt)
    assert (e.evaluated, e.good, e.bad) == (0, 0, 0) and math.isnan(e.rms) and math.isnan(e.bad_percent)
    assert e.as_dict()["rms"] is None and e.as_dict()["bad_percent"] is None


def test_dense_scores_count_missing_and_unknown():
    gt = np.full((4, 5), 2.0)
    gt[0, 0] = np.nan
    est = np.full((4, 5), 2.0)
    est[1, 1] = 4.0          # bad, error 2
    est[2, 2] = np.nan       # no estimate
    est[3, 3] = 2.5          # good, error 0.5
    s = Q.dense_scores(est, gt)
    assert (s.evaluated, s.good, s.bad, s.unknown, s.missing) == (18, 17, 1, 1, 1)
    assert s.bad_percent == pytest.approx(100 / 18, abs=1e-12)
    assert s.rms == pytest.approx(math.sqrt((4 + 0.25) / 18), abs=1e-15)
    mask = np.zeros((4, 5), bool)
    mask[1, :] = True
    s = Q.dense_scores(est, gt, mask=mask)
    assert (s.evaluated, s.bad, s.rms) == (5, 1, pytest.approx(math.sqrt(4 / 5)))


def test_shifted_image_disparity_is_exact():
    # the dense "estimate" of a plane shifted by 7 px is 7 everywhere: no bad pixel, RMS 0 exactly
    gt = np.full((30, 40), 7.0)
    s = Q.dense_scores(np.full((30, 40), 7.0), gt)
    assert (s.bad, s.rms, s.evaluated) == (0, 0.0, 1200)
    s = Q.dense_scores(np.full((30, 40), 9.0), gt)
    assert (s.bad, s.rms, s.bad_percent) == (1200, 2.0, 100.0)


def test_gt_from_array_units_and_unknowns():
    raw = np.array([[0, 16, 32], [160, 0, 8]], np.uint8)
    g = Q.gt_from_array(raw, scale=16)
    assert np.isnan(g[0, 0]) and np.isnan(g[1, 1])
    assert g[0, 1] == 1.0 and g[0, 2] == 2.0 and g[1, 0] == 10.0 and g[1, 2] == 0.5
    f = Q.gt_from_array(np.array([[np.inf, 3.5], [np.nan, 0.0]], np.float32))
    assert np.isnan(f[0, 0]) and f[0, 1] == 3.5 and np.isnan(f[1, 0]) and np.isnan(f[1, 1])
    with pytest.raises(ValueError, match="negative"):
        Q.gt_from_array(np.array([[-1.0, 2.0]]))
    with pytest.raises(ValueError, match="scale"):
        Q.gt_from_array(raw, scale=0)
    with pytest.raises(ValueError, match="2-D"):
        Q.gt_from_array(np.zeros(5))


def write_pfm(path, a):
    with open(path, "wb") as fh:
        fh.write(b"Pf\n%d %d\n-1.0\n" % (a.shape[1], a.shape[0]))
        fh.write(np.ascontiguousarray(a[::-1], "<f4").tobytes())


def test_load_disparity_formats(tmp_path):
    raw = (np.arange(24, dtype=np.uint16).reshape(4, 6) * 100)
    cv2.imwrite(str(tmp_path / "d16.png"), raw)
    g = Q.load_disparity(tmp_path / "d16.png", 100)
    assert np.isnan(g[0, 0]) and g[3, 5] == 23.0 and g[1, 2] == 8.0
    f = np.array([[1.5, np.inf], [0, 4.25]], np.float32)
    write_pfm(tmp_path / "d.pfm", f)
    g = Q.load_disparity(tmp_path / "d.pfm")
    assert g[0, 0] == 1.5 and np.isnan(g[0, 1]) and np.isnan(g[1, 0]) and g[1, 1] == 4.25
    np.save(tmp_path / "d.npy", f)
    assert np.array_equal(Q.load_disparity(tmp_path / "d.npy", 0.5), g * 2, equal_nan=True)
    with pytest.raises(ValueError, match="does not exist"):
        Q.load_disparity(tmp_path / "missing.pgm")
    (tmp_path / "junk.png").write_bytes(b"not an image")
    with pytest.raises(ValueError, match="cannot read"):
        Q.load_disparity(tmp_path / "junk.png")


def test_ground_truth_of_the_wrong_size_is_a_clear_error():
    with pytest.raises(ValueError, match="ground truth is 5x4 but the images are 6x4"):
        Q.check_gt(np.zeros((4, 5)), (4, 6))
    with pytest.raises(ValueError, match="ground truth is"):
        Q.dense_scores(np.zeros((4, 6)), np.zeros((4, 5)))
    with pytest.raises(ValueError, match="outside"):
        Q.sparse_scores([[5, 0]], [1.0], np.zeros((4, 5)))
    with pytest.raises(ValueError, match=r"\(n, 2\) points and n disparities"):
        Q.sparse_scores([[1, 0], [2, 0]], [1.0], np.zeros((4, 5)))


@needs_middlebury
def test_tsukuba_and_venus_ground_truth():
    t = Q.load_disparity(DATA / "tsukuba" / "disp3.pgm", 16)
    assert t.shape == (288, 384) and np.nanmin(t) == 5 and np.nanmax(t) == 14
    assert np.isnan(t[:18]).all() and np.isnan(t[:, :18]).all()      # Tsukuba's unknown border
    v = Q.load_disparity(DATA / "venus" / "disp2.pgm", 8)
    assert v.shape == (383, 434) and 19 < np.nanmax(v) <= 20
