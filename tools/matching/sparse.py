"""Sparse stereo: matching Harris corners between rectified left and right images (thesis 7.3.1-7.3.4).

For every left corner (xl, yl) the candidates are the right corners (xr, yr) with |yr - yl| <= ``rows``
and ``d_min <= xl - xr <= d_max`` (disparity d = xl - xr, left x minus right x). Each candidate pair is
scored by a window cost on the grey images and accepted when

* SAD: sum |l - r| over the W x H window  <  t_max * W * H       (thesis 7.3.3: t_max about 11),
* SSD: sum (l - r)^2                       <  t_max^2 * W * H     (t_max stays a mean grey-level difference),
* NCC: normalized cross-correlation        >= ``ncc_min``        (maximized; no t_max),

and the best accepted candidate wins (lowest cost; ties: smaller |dy|, then smaller disparity). With
``lr_check`` a pair is kept only if the left corner is also the best accepted match of its right corner.

Split correlation (thesis 7.3.4 after Hirschmueller, Fig. 7.6): ``split=5`` or ``split=9`` adds 4 or 8
W x H windows around the centre window C0, edge to edge (the 4 of the five-window set sit on the
diagonals, the 9 fill the 3 x 3 grid); the cost is C0 + the sum of the best (n - 1) / 2 of the others,
accepted below t_max * W * H * (1 + (n - 1) / 2). The thesis's best: 5 x 7 windows (W = 5, H = 7), 9 of them.

Windows that reach past the image border read the nearest edge pixel (edge replication), so the set of
corners that can be matched does not depend on the window size.

All of it is vectorized: the candidate pairs come from one sort of the right corners and two
``searchsorted`` calls per row offset, their costs from one gather of patches.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from eyestereo.tools.constants import K_DEFAULT, NMS_DEFAULT, THRESHOLD_BLOCKS
from eyestereo.tools.io import read_image, to_grey8
from eyestereo.tools.models import harris_mono as _hm

__all__ = ["COSTS", "SPLITS", "Matches", "as_grey", "load_grey", "load_pair", "check_pair", "check_features",
           "threshold_for_count", "detect_corners", "match_features", "split_offsets"]

COSTS = ("sad", "ssd", "ncc")
SPLITS = (1, 5, 9)
_CHUNK = 1 << 22  # pixel differences per chunk of candidate pairs (memory bound, ~16 MB of int32)


# --------------------------------------------------------------------------------------------------
# Images


def as_grey(img, *, order: str = "rgb") -> np.ndarray:
    """A 2-D uint8 grey image from a grey or colour (``order`` "rgb" or "bgr", 3 or 4 channels) array."""
    import cv2

    a = np.asarray(img)
    if a.ndim == 3 and a.shape[2] in (3, 4):
        if a.dtype != np.uint8:
            raise ValueError(f"colour images must be uint8, got {a.dtype}")
        if order not in ("rgb", "bgr"):
            raise ValueError(f"order must be 'rgb' or 'bgr', got {order!r}")
        code = {("rgb", 3): cv2.COLOR_RGB2GRAY, ("rgb", 4): cv2.COLOR_RGBA2GRAY,
                ("bgr", 3): cv2.COLOR_BGR2GRAY, ("bgr", 4): cv2.COLOR_BGRA2GRAY}[(order, a.shape[2])]
        a = cv2.cvtColor(np.ascontiguousarray(a), code)
    if a.ndim != 2:
        raise ValueError(f"an image must be 2-D grey or H x W x 3/4 colour, got shape {a.shape}")
    if a.dtype == np.uint8:
        return a
    if a.dtype == bool or not np.issubdtype(a.dtype, np.integer):
        raise ValueError(f"grey images must hold integers 0..255, got dtype {a.dtype}")
    if a.size and (a.min() < 0 or a.max() > 255):
        raise ValueError(f"grey values must lie in 0..255, got {a.min()}..{a.max()}")
    return a.astype(np.uint8)


def load_grey(path) -> np.ndarray:
    """Read an image file as 8-bit grey (:func:`eyestereo.tools.io.read_image` and
    :func:`~eyestereo.tools.io.to_grey8`: damaged files refused, colour to grey, 16-bit to its 8 most
    significant used bits, floating point refused); ValueError naming the file otherwise."""
    return to_grey8(read_image(path, grey=True), f"image {path}")


def load_pair(left_path, right_path) -> tuple[np.ndarray, np.ndarray]:
    """A stereo pair as 8-bit grey, like :func:`load_grey`; 16-bit images share one shift, so both
    views keep the same scale. ValueError unless both are readable and of the same size."""
    imgs = [read_image(left_path, what="left image", grey=True),
            read_image(right_path, what="right image", grey=True)]
    left, right = to_grey8(imgs, [f"left image {left_path}", f"right image {right_path}"])
    return check_pair(left, right)


def check_pair(left, right) -> tuple[np.ndarray, np.ndarray]:
    """Both images as grey uint8; ValueError unless they have the same size."""
    left, right = as_grey(left), as_grey(right)
    if left.shape != right.shape:
        raise ValueError(f"left and right images differ in size: {left.shape[1]}x{left.shape[0]} vs "
                         f"{right.shape[1]}x{right.shape[0]} (width x height)")
    if left.size == 0:
        raise ValueError("the images are empty")
    return left, right


def check_features(xy, shape, name: str = "features") -> np.ndarray:
    """Features as an (n, 2) int64 array of (x, y) inside an image of ``shape`` (h, w)."""
    a = np.asarray(xy)
    if a.size == 0:
        a = a.reshape(0, 2)
    if a.ndim != 2 or a.shape[1] != 2:
        raise ValueError(f"{name} must be an (n, 2) array of (x, y), got shape {a.shape}")
    if a.dtype.kind == "f":
        if not np.all(np.isfinite(a)) or not np.all(a == np.round(a)):
            raise ValueError(f"{name} must be integer pixel coordinates")
    elif a.dtype.kind not in "iu":
        raise ValueError(f"{name} must be integer pixel coordinates, got dtype {a.dtype}")
    a = a.astype(np.int64)
    h, w = shape
    if len(a) and (a[:, 0].min() < 0 or a[:, 0].max() >= w or a[:, 1].min() < 0 or a[:, 1].max() >= h):
        raise ValueError(f"{name} lie outside the {w}x{h} image")
    return a


# --------------------------------------------------------------------------------------------------
# Corners from the bit-true Harris model


def _corner_stages(img: np.ndarray, k: int):
    from eyestereo.tools.models import cornerness as _corner
    from eyestereo.tools.models import harris_window as _window
    from eyestereo.tools.models import sobel as _sobel

    frame = img.astype(np.int64)
    sob = _sobel.pack(*_sobel.sobel(frame)[:2])
    win, _ = _window.harris_window(sob)
    return _corner.cornerness(win, k)


def _flags_at(corner: np.ndarray, code, blocks, nms: int) -> np.ndarray:
    from eyestereo.tools.models import nms as _nms
    from eyestereo.tools.models import prethreshold as _pre

    n = blocks[0] * blocks[1]
    thr = np.broadcast_to(np.asarray(code, np.int64), (n,))
    pre = _pre.prethreshold(corner, thr, tuple(blocks))
    return _nms.nms(pre, nms)[0]


def threshold_for_count(img, count: int, *, k: float = K_DEFAULT, nms: int = NMS_DEFAULT) -> int:
    """The one threshold code (all blocks) whose bit-true corner count is closest to ``count``.

    Bisection over the code (the count falls as the code rises, up to NMS plateau effects); ties go to
    the higher code. Only the pre-threshold and NMS stages are rerun per step.
    """
    img = as_grey(img)
    if count < 1:
        raise ValueError(f"count must be >= 1, got {count}")
    kc = _hm.k_code(k)
    _hm.check_params(img.shape[1], img.shape[0], (1, 1), nms)
    corner = _corner_stages(img, kc)
    mask = _hm.interior_mask(*img.shape, _hm.radius(nms))
    n_at = {}

    def n(code: int) -> int:
        if code not in n_at:
            n_at[code] = int((_flags_at(corner, code, (1, 1), nms).astype(bool) & mask).sum())
        return n_at[code]

    lo, hi = 0, max(int(corner.max()), 0)  # n(hi) == 0
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if n(mid) > count:
            lo = mid
        else:
            hi = mid
    return lo if abs(n(lo) - count) < abs(n(hi) - count) else hi


def detect_corners(img, *, k: float = K_DEFAULT, threshold: int | None = None, count: int = 500,
                   blocks=THRESHOLD_BLOCKS, nms: int = NMS_DEFAULT) -> np.ndarray:
    """Corners (x, y), shape (n, 2), by the bit-true Harris model :func:`harris_mono`.

    ``threshold``: a code (int, all blocks) or one code per block; None picks the single code whose
    corner count is closest to ``count`` (:func:`threshold_for_count`). Only corners inside the
    model's specified area (``mask``) are returned.
    """
    img = as_grey(img)
    if min(img.shape) < 2 * _hm.radius(nms) + 1:
        raise ValueError(f"image {img.shape[1]}x{img.shape[0]} is too small for the Harris detector "
                         f"(needs at least {2 * _hm.radius(nms) + 1} pixels per side)")
    if threshold is None:
        threshold = threshold_for_count(img, count, k=k, nms=nms)
    thr = np.broadcast_to(np.asarray(threshold, np.int64), (blocks[0] * blocks[1],))
    flags, mask = _hm.harris_mono(img, _hm.k_code(k), thr, blocks=tuple(blocks), nms=nms)
    return _hm.features(flags, mask)


# --------------------------------------------------------------------------------------------------
# Matching


@dataclass
class Matches:
    """Accepted matches: corner i of the left list matched to corner j of the right list.

    ``left``/``right``: (n, 2) (x, y); ``disparity`` = left x - right x; ``cost``: the window cost (for NCC:
    1 - ncc); ``left_index``/``right_index`` into the feature lists; ``candidates``: pairs scored.
    """

    left: np.ndarray
    right: np.ndarray
    disparity: np.ndarray
    cost: np.ndarray
    left_index: np.ndarray
    right_index: np.ndarray
    candidates: int = 0
    params: dict = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.disparity)


def split_offsets(window, split: int) -> np.ndarray:
    """Centres (dx, dy) of the sub-windows, centre first: 1, 5 (diagonals) or 9 (3 x 3 grid)."""
    w, h = window
    if split == 1:
        cells = [(0, 0)]
    elif split == 5:
        cells = [(0, 0), (-1, -1), (1, -1), (-1, 1), (1, 1)]
    elif split == 9:
        cells = [(0, 0)] + [(i, j) for j in (-1, 0, 1) for i in (-1, 0, 1) if (i, j) != (0, 0)]
    else:
        raise ValueError(f"split must be one of {SPLITS}, got {split!r}")
    return np.array([(i * w, j * h) for i, j in cells], np.int64)


def _check_window(window) -> tuple[int, int]:
    if isinstance(window, int) and not isinstance(window, bool):
        window = (window, window)
    try:
        w, h = (int(v) for v in window)
    except (TypeError, ValueError):
        raise ValueError(f"window must be W x H (two odd ints), got {window!r}") from None
    if w < 1 or h < 1 or w % 2 == 0 or h % 2 == 0 or w > 255 or h > 255:
        raise ValueError(f"window sides must be odd, 1..255, got {w}x{h}")
    return w, h


def _patches(img: np.ndarray, xy: np.ndarray, rx: int, ry: int) -> np.ndarray:
    """(n, 2ry+1, 2rx+1) int32 patches centred on xy, edge replicated."""
    pad = np.pad(img, ((ry, ry), (rx, rx)), mode="edge").astype(np.int32)
    ys = xy[:, 1][:, None, None] + np.arange(2 * ry + 1)[None, :, None]
    xs = xy[:, 0][:, None, None] + np.arange(2 * rx + 1)[None, None, :]
    return pad[ys, xs]


def _candidates(fl: np.ndarray, fr: np.ndarray, width: int, d_min: int, d_max: int, rows: int):
    """(left index, right index) of every pair on rows |dy| <= rows with d_min <= xl - xr <= d_max."""
    keys = fr[:, 1] * width + fr[:, 0]
    order = np.argsort(keys, kind="stable")
    keys = keys[order]
    li_all, ri_all = [], []
    for dy in range(-rows, rows + 1):
        y = fl[:, 1] + dy
        xlo = np.maximum(fl[:, 0] - d_max, 0)
        xhi = np.minimum(fl[:, 0] - d_min, width - 1)
        ok = xlo <= xhi
        start = np.searchsorted(keys, y * width + xlo, side="left")
        stop = np.searchsorted(keys, y * width + xhi, side="right")
        cnt = np.where(ok, stop - start, 0)
        total = int(cnt.sum())
        if total == 0:
            continue
        li = np.repeat(np.arange(len(fl)), cnt)
        first = np.repeat(np.cumsum(cnt) - cnt, cnt)
        ri = order[np.repeat(start, cnt) + (np.arange(total) - first)]
        li_all.append(li)
        ri_all.append(ri)
    if not li_all:
        e = np.zeros(0, np.int64)
        return e, e
    return np.concatenate(li_all), np.concatenate(ri_all)


def _pair_costs(pl, pr, li, ri, cost: str, offsets, window) -> np.ndarray:
    """Cost (to minimize) of each pair; split windows summed as C0 + best half of the others."""
    n = len(li)
    w, h = window
    out = np.empty(n, np.float64)
    per = pl.shape[1] * pl.shape[2]
    step = max(1, _CHUNK // per)
    if cost == "ncc":
        a = pl.reshape(len(pl), -1).astype(np.float64)
        b = pr.reshape(len(pr), -1).astype(np.float64)
        a -= a.mean(1, keepdims=True)
        b -= b.mean(1, keepdims=True)
        na, nb = np.sqrt((a * a).sum(1)), np.sqrt((b * b).sum(1))
        for s in range(0, n, step):
            i, j = li[s:s + step], ri[s:s + step]
            num = np.einsum("ij,ij->i", a[i], b[j])
            den = na[i] * nb[j]
            ncc = np.divide(num, den, out=np.full(len(i), -1.0), where=den > 0)
            out[s:s + step] = 1.0 - ncc
        return out
    nwin = len(offsets)
    keep = (nwin - 1) // 2
    for s in range(0, n, step):
        d = pl[li[s:s + step]] - pr[ri[s:s + step]]
        d = np.abs(d) if cost == "sad" else d * d
        if nwin == 1:
            out[s:s + step] = d.reshape(len(d), -1).sum(1, dtype=np.int64)
            continue
        # sub-window sums: the patch is the 3x3 grid of W x H cells around the centre
        cells = d.reshape(len(d), 3, h, 3, w).sum((2, 4), dtype=np.int64)
        idx = [(1 + oy // h, 1 + ox // w) for ox, oy in offsets]
        c = np.stack([cells[:, j, i] for j, i in idx], 1)
        others = np.sort(c[:, 1:], axis=1)[:, :keep]
        out[s:s + step] = c[:, 0] + others.sum(1)
    return out


def match_features(left, right, left_xy, right_xy, *, window=(9, 9), t_max: float = 11.0,
                   cost: str = "sad", d_min: int = 0, d_max: int = 64, rows: int = 0, split: int = 1,
                   lr_check: bool = False, ncc_min: float = 0.8) -> Matches:
    """Match left corners to right corners on the same row (+-``rows``); see the module docstring.

    ``window``: (W, H) odd sides (or one int); ``d_min..d_max``: the disparity range (d = xl - xr).
    ValueError on images of different sizes, empty or malformed feature lists, bad parameters.
    """
    left, right = check_pair(left, right)
    wid = left.shape[1]
    fl = check_features(left_xy, left.shape, "left features")
    fr = check_features(right_xy, right.shape, "right features")
    if len(fl) == 0:
        raise ValueError("the left feature list is empty: nothing to match")
    if len(fr) == 0:
        raise ValueError("the right feature list is empty: nothing to match against")
    w, h = _check_window(window)
    if cost not in COSTS:
        raise ValueError(f"cost must be one of {COSTS}, got {cost!r}")
    offsets = split_offsets((w, h), split)
    if cost == "ncc" and split != 1:
        raise ValueError("split correlation is defined for the SAD and SSD costs only, not for NCC")
    if not (np.isfinite(t_max) and t_max > 0):
        raise ValueError(f"t_max must be a positive number, got {t_max}")
    if not -1 <= ncc_min <= 1:
        raise ValueError(f"ncc_min must lie in [-1, 1], got {ncc_min}")
    d_min, d_max, rows = int(d_min), int(d_max), int(rows)
    if d_min > d_max:
        raise ValueError(f"empty disparity range {d_min}..{d_max}")
    if rows < 0:
        raise ValueError(f"rows must be >= 0, got {rows}")
    params = dict(window=(w, h), t_max=float(t_max), cost=cost, d_min=d_min, d_max=d_max, rows=rows,
                  split=split, lr_check=bool(lr_check), ncc_min=float(ncc_min))

    li, ri = _candidates(fl, fr, wid, d_min, d_max, rows)
    if split == 1:
        rx, ry = w // 2, h // 2
    else:
        rx, ry = w + w // 2, h + h // 2
    c = np.zeros(0)
    if len(li):
        pl, pr = _patches(left, fl, rx, ry), _patches(right, fr, rx, ry)
        c = _pair_costs(pl, pr, li, ri, cost, offsets, (w, h))
    if cost == "ncc":
        ok = c <= 1.0 - ncc_min
    else:
        nsum = 1 + (len(offsets) - 1) // 2
        limit = (t_max if cost == "sad" else t_max ** 2) * w * h * nsum
        ok = c < limit
    li_a, ri_a, c_a = li[ok], ri[ok], c[ok]
    dy = np.abs(fr[ri_a, 1] - fl[li_a, 1])
    disp = fl[li_a, 0] - fr[ri_a, 0]

    def best(group: np.ndarray) -> np.ndarray:
        """Index (into the accepted pairs) of the best pair of each group value."""
        if len(group) == 0:
            return np.zeros(0, np.int64)
        o = np.lexsort((disp, dy, c_a, group))
        g = group[o]
        first = np.ones(len(o), bool)
        first[1:] = g[1:] != g[:-1]
        return o[first]

    sel = best(li_a)
    if lr_check and len(sel):
        best_left_of_right = np.full(len(fr), -1, np.int64)
        rsel = best(ri_a)
        best_left_of_right[ri_a[rsel]] = li_a[rsel]
        sel = sel[best_left_of_right[ri_a[sel]] == li_a[sel]]
    sel = np.sort(sel)
    sel = sel[np.argsort(li_a[sel], kind="stable")]
    i, j = li_a[sel], ri_a[sel]
    return Matches(left=fl[i], right=fr[j], disparity=disp[sel].astype(np.int64), cost=c_a[sel],
                   left_index=i, right_index=j, candidates=int(len(li)), params=params)
