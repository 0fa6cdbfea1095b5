"""Float reference of the dense stereo chain (:mod:`eyestereo.tools.models.dense_stereo`).

The same algorithm as the bit-true model, written without its hardware choices: no saturation of any
cost (the path costs and their sums are unbounded float64), the uniqueness test as a real ratio
(``best <= (1 - u/100) * second``), the sub-pixel offset as the exact quotient
``(S(d-1) - S(d+1)) / (2 (S(d-1) + S(d+1) - 2 S(d)))``, the median over float disparities. What the
hardware's widths cost is the difference between the two (docs/dense.md). Rules the model defines and the
reference keeps, because they are part of the algorithm, not of its arithmetic: census bits of neighbours
outside the image are 0; the cost of ``x < d`` is the census length; candidates ``d <= x``; ties go to
the smaller d; the median's border passes through and an invalid pixel counts as +infinity in it.

Written apart from the model (census as a stack of comparison planes, Hamming distances as plane sums,
paths by one generic scan) so that the test comparing them compares two codes.
"""

from __future__ import annotations

import numpy as np

from eyestereo.tools.models.census import census_bits, check_image
from eyestereo.tools.models.dense_stereo import DEFAULTS
from eyestereo.tools.models.sgm import DIRECTIONS, check_params

__all__ = ["census_planes", "costs", "aggregate", "disparity", "reference"]


def census_planes(img, window: int) -> np.ndarray:
    """(bits, h, w) bool: plane k is "neighbour k (raster order of the window, centre skipped) < centre";
    False where the neighbour lies outside the image."""
    a = check_image(img).astype(np.float64)
    h, w = a.shape
    r = window // 2
    planes = []
    for oy in range(-r, r + 1):
        for ox in range(-r, r + 1):
            if (oy, ox) == (0, 0):
                continue
            nb = np.full((h, w), np.inf)
            ys, xs = slice(max(0, -oy), h - max(0, oy)), slice(max(0, -ox), w - max(0, ox))
            nb[ys, xs] = a[max(0, oy):h + min(0, oy), max(0, ox):w + min(0, ox)]
            planes.append(nb < a)
    return np.array(planes)


def costs(left, right, window: int, disparities: int) -> np.ndarray:
    """Hamming costs (h, w, D) float64; the census length where x < d."""
    pl, pr = census_planes(left, window), census_planes(right, window)
    _, h, w = pl.shape
    out = np.full((h, w, disparities), float(census_bits(window)))
    for d in range(min(disparities, w)):
        out[:, d:, d] = np.count_nonzero(pl[:, :, d:] != pr[:, :, :w - d], axis=0)
    return out


def _scan(cost: np.ndarray, dx: int, dy: int, p1: float, p2: float) -> np.ndarray:
    """Path costs along one direction: every pixel after its predecessor ``(x + dx, y + dy)``."""
    h, w, dn = cost.shape
    out = np.array(cost, np.float64)
    inf = np.full((1,), np.inf)

    def update(cur: np.ndarray, prev: np.ndarray) -> np.ndarray:
        # cur, prev: (n, D); the four terms of the recurrence, out-of-range d's as +inf
        m = prev.min(axis=1, keepdims=True)
        lower = np.concatenate([np.broadcast_to(inf, (len(prev), 1)), prev[:, :-1]], axis=1) + p1
        upper = np.concatenate([prev[:, 1:], np.broadcast_to(inf, (len(prev), 1))], axis=1) + p1
        return cur + np.minimum.reduce([prev, lower, upper, np.broadcast_to(m + p2, prev.shape)]) - m

    if dy == 0:
        for x in range(1, w):
            out[:, x] = update(cost[:, x], out[:, x - 1])
        return out
    cols = np.arange(w)
    has = (cols + dx >= 0) & (cols + dx < w)
    for y in range(1, h):
        out[y, has] = update(cost[y, has], out[y - 1, cols[has] + dx])
    return out


def aggregate(cost: np.ndarray, paths: int, p1: float, p2: float) -> np.ndarray:
    """Sum of the path costs over the ``paths`` directions (float64, unbounded)."""
    return sum(_scan(cost, dx, dy, p1, p2) for dx, dy in DIRECTIONS[paths])


def disparity(total: np.ndarray, *, uniqueness: float, lr_check: bool, subpixel: bool) -> np.ndarray:
    """Winner take all, uniqueness, left-right check, exact sub-pixel: float px, NaN = invalid."""
    h, w, dn = total.shape
    out = np.full((h, w), np.nan)
    ratio = 1.0 - uniqueness / 100.0
    # the right view's winners along the diagonals, first minimum
    right = np.zeros((h, w), np.int64)
    for xr in range(w):
        ds = np.arange(min(dn, w - xr))
        right[:, xr] = np.argmin(total[:, xr + ds, ds], axis=1)
    for x in range(w):
        s = total[:, x, :min(dn, x + 1)]
        d = np.argmin(s, axis=1)
        rows = np.arange(h)
        best = s[rows, d]
        far = np.abs(np.arange(s.shape[1])[None, :] - d[:, None]) > 1
        second = np.where(far, s, np.inf).min(axis=1)
        ok = best <= ratio * second
        if lr_check:
            ok &= np.abs(d - right[rows, x - d]) <= 1
        val = d.astype(np.float64)
        if subpixel:
            inner = (d >= 1) & (d + 1 < s.shape[1])
            cm = total[rows, x, np.clip(d - 1, 0, dn - 1)]
            cp = total[rows, x, np.clip(d + 1, 0, dn - 1)]
            den = cm + cp - 2 * best
            inner &= den > 0
            val = val + np.where(inner, (cm - cp) / (2 * np.where(inner, den, 1.0)), 0.0)
        out[:, x] = np.where(ok, val, np.nan)
    return out


def _median(disp: np.ndarray) -> np.ndarray:
    h, w = disp.shape
    if h < 3 or w < 3:
        return disp.copy()
    a = np.where(np.isnan(disp), np.inf, disp)
    win = np.lib.stride_tricks.sliding_window_view(a, (3, 3)).reshape(h - 2, w - 2, 9)
    out = disp.copy()
    med = np.sort(win, axis=-1)[..., 4]
    out[1:-1, 1:-1] = np.where(np.isinf(med), np.nan, med)
    return out


def reference(left, right, *, window: int = DEFAULTS["window"], disparities: int = DEFAULTS["disparities"],
              paths: int = DEFAULTS["paths"], p1: float = DEFAULTS["p1"], p2: float = DEFAULTS["p2"],
              uniqueness: float = DEFAULTS["uniqueness"], lr_check: bool = DEFAULTS["lr_check"],
              subpixel: bool = DEFAULTS["subpixel"], median: bool = DEFAULTS["median"]) -> np.ndarray:
    """Float disparities (px, NaN = none) of the left image: the model's algorithm in exact arithmetic."""
    check_params(disparities=disparities, paths=paths, p1=int(p1), p2=int(p2), uniqueness=int(uniqueness),
                 window=window, cost_bits=None, path_bits=9, sum_shift=0, frac_bits=4)
    left, right = check_image(left, "left image"), check_image(right, "right image")
    if left.shape != right.shape:
        raise ValueError(f"left and right images differ in size: {left.shape} and {right.shape}")
    if left.shape[1] <= disparities:
        raise ValueError(f"image width {left.shape[1]} must exceed the {disparities} disparities")
    total = aggregate(costs(left, right, window, disparities), paths, float(p1), float(p2))
    d = disparity(total, uniqueness=float(uniqueness), lr_check=lr_check, subpixel=subpixel)
    return _median(d) if median else d
