"""Accuracy of a dense disparity map against ground truth (Middlebury's measures, our conventions).

Conventions (the page docs/dense.md repeats them):

* Ground truth is float px of the left view; **unknown pixels** (NaN) are left out of every measure.
* **Regions**: ``all`` = the pixels with known ground truth; ``noc`` = those of them that are visible in
  the right image. The data carry no occlusion masks; :func:`visible_mask` derives one from the ground
  truth itself by a left-right check of the ground truth: each left pixel is sent to ``x - d`` in the right
  view, where the largest disparity arriving at a column is the surface the right camera sees; a pixel
  whose disparity is more than 1 px below that (a nearer surface hides it), or that lands outside the
  right image, is occluded.
* An estimate is **valid** when finite. ``bad-t`` = share of the valid estimates of the region with
  ``|d - d_gt| > t`` (in %); ``density`` = share of the region's pixels with a valid estimate (in %);
  ``rms`` = root mean square error over the region's valid estimates (px); ``bad-2 filled`` counts every
  pixel of the region without an estimate as bad too (in %), so a method cannot gain by leaving holes.
* ``bad-2 interpolated`` is the benchmarks' way: the holes are filled first by :func:`fill_background`
  (KITTI's devkit, ``DisparityImage::interpolateBackground``, before it scores a submission at full
  density), then bad-2 is counted over every pixel of the region (density 100 %).
"""

from __future__ import annotations

import numpy as np

__all__ = ["THRESHOLDS", "visible_mask", "fill_background", "scores"]

#: The bad-pixel thresholds (px).
THRESHOLDS = (1.0, 2.0, 4.0)


def _check_gt(gt) -> np.ndarray:
    g = np.asarray(gt, np.float64)
    if g.ndim != 2:
        raise ValueError(f"ground truth must be a 2-D disparity map, got shape {g.shape}")
    if np.any(g[np.isfinite(g)] < 0):
        raise ValueError("ground truth holds negative disparities")
    return g


def visible_mask(gt, tolerance: float = 1.0) -> np.ndarray:
    """True where the ground truth is known and the pixel is visible in the right view (see above)."""
    g = _check_gt(gt)
    h, w = g.shape
    known = np.isfinite(g)
    ys, xs = np.nonzero(known)
    d = g[ys, xs]
    xr = np.rint(xs - d).astype(np.int64)
    inside = xr >= 0
    seen = np.full((h, w), -np.inf)
    np.maximum.at(seen, (ys[inside], xr[inside]), d[inside])
    out = np.zeros((h, w), bool)
    ok = inside.copy()
    ok[inside] = d[inside] >= seen[ys[inside], xr[inside]] - tolerance
    out[ys[ok], xs[ok]] = True
    return out


def _fill_rows(d: np.ndarray) -> np.ndarray:
    """Each row's holes: the smaller of the two valid values around a gap, the nearest one at a row's ends."""
    h, w = d.shape
    valid = np.isfinite(d)
    idx = np.broadcast_to(np.arange(w), (h, w))
    left = np.maximum.accumulate(np.where(valid, idx, -1), axis=1)             # last valid at or before x
    right = np.minimum.accumulate(np.where(valid, idx, w)[:, ::-1], axis=1)[:, ::-1]  # first at or after x
    rows = np.arange(h)[:, None]
    lv = np.where(left >= 0, d[rows, np.clip(left, 0, w - 1)], np.nan)
    rv = np.where(right < w, d[rows, np.clip(right, 0, w - 1)], np.nan)
    # fmin: the smaller where both exist (the farther surface: a hole is most often what a nearer object
    # hides), the one that exists at a row's ends; NaN where the row has nothing valid
    return np.where(valid, d, np.fmin(lv, rv))


def fill_background(disparity) -> np.ndarray:
    """A full map from one with holes (NaN), the way KITTI's devkit fills a submission before scoring it.

    Along each row, a gap between two valid pixels takes the smaller (farther) of their two disparities and
    a gap at a row's end the nearest valid value of the row. A row with nothing valid is then filled the same
    way along its column from the filled rows: above the first or below the last filled row the nearest one's
    value (KITTI's extrapolation to the top and bottom); between two filled rows the smaller of the two (KITTI
    leaves such a row invalid; ours is the row rule turned by 90 degrees). Only a map with no valid pixel at
    all stays NaN."""
    d = np.asarray(disparity, np.float64)
    if d.ndim != 2:
        raise ValueError(f"disparity map must be 2-D, got shape {d.shape}")
    # after the row pass every row is full or empty: the column pass changes the empty rows only
    return _fill_rows(_fill_rows(d).T).T


def scores(disparity, gt, *, visible=None) -> dict[str, float]:
    """The measures of a float map (NaN = no estimate): ``bad1/bad2/bad4_noc``, ``..._all``, ``density``
    (all), ``rms`` (noc), ``bad2_filled`` (noc), ``bad2_interp`` (noc, on :func:`fill_background`'s map).
    ``visible``: the noc mask (default :func:`visible_mask`)."""
    d = np.asarray(disparity, np.float64)
    g = _check_gt(gt)
    if d.shape != g.shape:
        raise ValueError(f"disparity map {d.shape[::-1]} and ground truth {g.shape[::-1]} differ in size")
    noc = visible_mask(g) if visible is None else np.asarray(visible, bool) & np.isfinite(g)
    regions = {"noc": noc, "all": np.isfinite(g)}
    valid = np.isfinite(d)
    err = np.abs(np.where(valid, d, 0.0) - np.where(np.isfinite(g), g, 0.0))
    out: dict[str, float] = {}
    for region, sel in regions.items():
        est = sel & valid
        n = int(np.count_nonzero(est))
        for t in THRESHOLDS:
            out[f"bad{t:g}_{region}"] = 100.0 * np.count_nonzero(est & (err > t)) / n if n else float("nan")
        if region == "noc":
            out["rms"] = float(np.sqrt(np.mean(err[est] ** 2))) if n else float("nan")
            total = int(np.count_nonzero(sel))
            out["bad2_filled"] = 100.0 * (np.count_nonzero(est & (err > 2.0)) + total - n) / total if total \
                else float("nan")
            filled = np.abs(fill_background(d) - np.where(np.isfinite(g), g, 0.0))
            # NaN (a map with nothing valid) compares False: counted bad by counting the good ones
            out["bad2_interp"] = 100.0 * (total - np.count_nonzero(sel & (filled <= 2.0))) / total if total \
                else float("nan")
        else:
            out["density"] = 100.0 * n / max(1, int(np.count_nonzero(sel)))
    return out
