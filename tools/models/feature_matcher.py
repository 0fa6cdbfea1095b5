"""Bit-true model of the ``feature_matcher`` block (issue 29): Harris corners of both cameras to matches.

The block takes the two feature lists of a frame (:mod:`eyestereo.tools.models.feature_list`, raster
order) and the rectified pixels around every corner, and writes one match list per frame. Everything is
integer; the steps:

1. **Candidates.** For left corner (xl, yl) the right corners (xr, yr) with ``|yr - yl| <= rows`` and
   ``d_min <= d <= d_max``, d = xl - xr. They are scored in the block's order: left corners in raster
   order, for each its right corners in raster order (row yl - rows first). ``candidates`` counts them.
2. **Cost** of a pair over the ``window`` x ``window`` square around both corners:

   * ``"sad"``: sum of |l - r| over the window; pixels past the image border are the nearest edge
     pixel (edge replication, as the software matcher reads them).
   * ``"census"``: the Hamming distance of the two corners' census words, one bit per neighbour of the
     window (``window**2 - 1`` bits, the centre left out): 1 when the neighbour is strictly darker than
     the centre. A neighbour past the border gives a 0 bit, the rule of :mod:`~eyestereo.tools.models.census`,
     so for windows 5 and 7 the word is the census block's word at the corner (the dense and sparse
     matchers can share that block). Why this census and not a sum of per-pixel Hamming distances over
     the window: it needs the same window of pixels the SAD needs, ``window**2 - 1`` comparators against
     the centre once per corner, and one stored word per corner (80 bits for 9 x 9 instead of 81 pixels
     of 8 bits), and a pair costs an XOR and a popcount instead of 81 subtractions and an adder tree.
     It is invariant to any strictly increasing change of the grey levels (an offset, a gain), SAD is not.
3. **Best and second best** per left corner: the lowest cost wins; ties to the smaller |dy|, then the
   smaller disparity, then the smaller yr - yl (the right corner above). ``second`` is the lowest cost
   of the corner's other candidates.
4. **Threshold**: the best is accepted when its cost is below ``limit``: ``t_max * window**2`` for SAD
   (t_max a mean grey-level difference, integer), ``ceil(h_max * (window**2 - 1) / 100)`` for census
   (h_max a percentage of differing bits). The block gets ``limit`` from a register the host writes.
5. **Uniqueness** (percent u, 0 = off): accepted when ``best * (100 + u) <= second * 100``; a corner
   with one candidate passes. Two constant multiplications; with u = 0 it always passes.
6. **Left-right check** (``lr_check``): the pair is kept only if the left corner is also the best of its
   right corner's candidates (same order of costs and ties, seen from the right corner). The block keeps
   a running best (cost, |dy|, d, left corner) per right corner while it scores, and emits the list after
   the last pair (the right corner's last candidate may come with a later left corner).
7. **List**: the matches in the order of their left corners, at most ``max_matches``; the rest are
   counted (``total``), not listed, and the trailer's overflow flag is set (as the feature list does).

Steps 1 and 3-7 are :func:`~eyestereo.tools.models.match_engine.match_engine`, the model of the block's
second half, on the corners' descriptors (:func:`descriptors`: the window's grey levels or its census bits).

Per left corner ``status`` says what became of it: :data:`MATCHED`, :data:`NO_CANDIDATE`,
:data:`OVER_THRESHOLD`, :data:`NOT_UNIQUE`, :data:`LR_FAILED` (the first test it failed, in that order).

**The words** (the match writer's queue port of 16-bit words, like the feature list's, and the host driver's),
declared once in :mod:`~eyestereo.tools.models.match_engine`: a match is one :data:`MATCH` word of 48 bits,
three queue words, low first: bits 11..0 x, 15..12 dy = yr - yl (signed), 27..16 y, 35..28 disparity, 47..36
cost. Widths from the parameter ranges: x and y 12 bits (frames up to
:data:`~eyestereo.tools.constants.FRAME_MAX` = 4096), dy 4 bits signed (rows <= 7), disparity 8 bits (d_max <=
255), cost 12 bits because only accepted matches are listed and the limit is at most 4096 (t_max * window**2
<= 4096: t_max up to 33 with 11 x 11, 163 with 5 x 5, the thesis uses 11; census costs are at most 120). The
list ends with one :data:`TRAILER` (three words): :data:`MARKER` (0x8000: dy = -8, which no match has), then
the count (bits 14..0) with the overflow flag (bit 15), then ``candidates`` saturated at 0xFFFF; ``eol`` and
``eof`` on its last word.

**Differences from** :func:`eyestereo.tools.matching.sparse.match_features`, which this model equals for
SAD, a square window of 5..11, split = 1, an integer t_max, uniqueness 0 and either lr_check (the tests
compare them): no SSD and no NCC (multipliers and a division per pair); no split windows (they need a
window three times as wide and high); square windows only; t_max an integer; the census cost and the
uniqueness ratio are new; the feature lists must be in raster order without repeats (the feature list
block's order; the software takes any order) and may be empty (the software refuses an empty list);
the list is cut at ``max_matches``; disparities 0..255, rows 0..7 (the word's fields).
"""

from __future__ import annotations

import numpy as np

from eyestereo.tools.constants import FRAME_MAX, FRAME_MIN
from eyestereo.tools.models.census import check_image
from eyestereo.tools.models.match_engine import (COSTS, LR_FAILED, MARKER, MATCH, MATCHED, MAX_DISPARITY, MAX_LIMIT,
                                                 MAX_MATCHES, MAX_ROWS, NO_CANDIDATE, NOT_UNIQUE, OVER_THRESHOLD,
                                                 TRAILER, WINDOWS, candidates, check_engine, match_engine)

__all__ = ["COSTS", "WINDOWS", "MATCH", "TRAILER", "MARKER", "MAX_MATCHES", "MAX_ROWS", "MAX_DISPARITY",
           "MAX_LIMIT", "MATCHED", "NO_CANDIDATE", "OVER_THRESHOLD", "NOT_UNIQUE", "LR_FAILED", "check_params",
           "cost_limit", "candidates", "descriptors", "feature_matcher"]


def _int(value, name: str) -> int:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise ValueError(f"parameter {name}={value!r}: must be an integer")
    return int(value)


def cost_limit(cost: str, window: int, t_max: int, h_max: int) -> int:
    """The accepted costs are those below this: ``t_max * window**2`` (SAD) or ``ceil(h_max * (window**2 - 1)
    / 100)`` (census)."""
    if cost == "sad":
        return t_max * window * window
    return -(-h_max * (window * window - 1) // 100)


def check_params(*, window: int, cost: str, t_max: int, h_max: int, d_min: int, d_max: int, rows: int,
                 uniqueness: int, max_matches: int) -> None:
    """ValueError that says why, for any parameter the block cannot take."""
    if isinstance(window, bool) or window not in WINDOWS:
        raise ValueError(f"parameter window={window!r}: must be odd and one of {WINDOWS}")
    if cost not in COSTS:
        raise ValueError(f"parameter cost={cost!r}: must be one of {COSTS}")
    t_max, h_max = _int(t_max, "t_max"), _int(h_max, "h_max")
    if cost == "sad" and not 1 <= t_max <= MAX_LIMIT // (window * window):
        raise ValueError(f"parameter t_max={t_max}: must be 1..{MAX_LIMIT // (window * window)} for a {window}x"
                         f"{window} SAD window (t_max * window**2 <= {MAX_LIMIT}: the 12-bit cost field)")
    if cost == "census" and not 1 <= h_max <= 100:
        raise ValueError(f"parameter h_max={h_max}: must be 1..100 (percent of the census bits)")
    check_engine(cost=cost, window=window, limit=cost_limit(cost, window, t_max, h_max), d_min=d_min, d_max=d_max,
                 rows=rows, uniqueness=uniqueness, max_matches=max_matches)


def _check_features(xy, shape, what: str) -> np.ndarray:
    a = np.asarray(xy)
    if a.size == 0:
        return np.zeros((0, 2), np.int64)
    if a.ndim != 2 or a.shape[1] != 2:
        raise ValueError(f"{what} must be an (n, 2) array of (x, y), got shape {a.shape}")
    if a.dtype.kind not in "iu":
        raise ValueError(f"{what} must be integer pixel coordinates, got dtype {a.dtype}")
    a = a.astype(np.int64)
    h, w = shape
    if a[:, 0].min() < 0 or a[:, 0].max() >= w or a[:, 1].min() < 0 or a[:, 1].max() >= h:
        raise ValueError(f"{what} lie outside the {w}x{h} image")
    key = a[:, 1] * w + a[:, 0]
    if np.any(np.diff(key) <= 0):
        raise ValueError(f"{what} must be in raster order without repeats (the feature list's order)")
    return a


def _windows(pad: np.ndarray, xy: np.ndarray, r: int) -> np.ndarray:
    """(n, (2r+1)**2) windows of an image padded by r on every side, around the corners xy (raster order)."""
    off = np.arange(2 * r + 1)
    win = pad[xy[:, 1, None, None] + off[None, :, None], xy[:, 0, None, None] + off[None, None, :]]
    return win.reshape(len(xy), (2 * r + 1) ** 2)


def _sad_windows(img: np.ndarray, xy: np.ndarray, r: int) -> np.ndarray:
    """int16 windows, pixels past the border replaced by the nearest edge pixel (the software's rule)."""
    return _windows(np.pad(img, r, mode="edge").astype(np.int16), xy, r)


def _census_words(img: np.ndarray, xy: np.ndarray, r: int) -> np.ndarray:
    """(n, (2r+1)**2 - 1) bool census bits of the corners, neighbours in raster order, 0 past the border."""
    pad = np.pad(img.astype(np.int16), r, constant_values=256)  # never darker than a centre: a 0 bit
    win = _windows(pad, xy, r)
    centre = (2 * r + 1) ** 2 // 2
    return np.delete(win < win[:, centre:centre + 1], centre, axis=1)


def descriptors(img: np.ndarray, xy: np.ndarray, cost: str, window: int) -> np.ndarray:
    """The corners' descriptors the engine compares (:mod:`eyestereo.tools.models.match_engine`): (n, window**2)
    grey levels, edge pixels repeated past the border (SAD), or (n, window**2 - 1) census bits (census)."""
    r = window // 2
    return _sad_windows(img, xy, r) if cost == "sad" else _census_words(img, xy, r)


def feature_matcher(left, right, left_xy, right_xy, *, window: int = 9, cost: str = "sad", t_max: int = 11,
                    h_max: int = 15, d_min: int = 0, d_max: int = 64, rows: int = 0, uniqueness: int = 0,
                    lr_check: bool = False, max_matches: int = 1023) -> dict:
    """The match list the block gives for one frame: see the module docstring.

    ``left``/``right``: rectified grey images (uint8, same shape); ``left_xy``/``right_xy``: (n, 2) (x, y)
    corners in raster order. ``t_max`` counts for SAD, ``h_max`` for census (default 15 %, measured on
    Tsukuba, Venus and Motorcycle at 352 x 288, 500 corners, 9 x 9, lr_check: bad (|error| > 1 px) 15, 4
    and 11 % of the matches; 25 % gives 18, 6 and 16 %; SAD with t_max 11 gives 8, 2 and 6 %).

    Returns ``matches`` ((count, 4) int64: x, y, disparity, cost, in the order of the left corners),
    ``left_index``/``right_index`` and ``dy`` of the listed matches, ``count`` (listed), ``total`` (all
    matches), ``overflow``, ``candidates``, ``limit``, ``words`` (queue words (data, eol, eof): the
    matches, then the trailer), and per left corner ``best``, ``second`` (costs, -1 = none), ``choice``
    (right index of the best, -1 = none), ``status``; ``pairs`` (``left``, ``right``, ``cost`` of every
    pair in the block's order).
    """
    left, right = check_image(left, "left image"), check_image(right, "right image")
    if left.shape != right.shape:
        raise ValueError(f"left and right images differ in size: {left.shape[1]}x{left.shape[0]} and "
                         f"{right.shape[1]}x{right.shape[0]}")
    h, w = left.shape
    if not (FRAME_MIN <= w <= FRAME_MAX and FRAME_MIN <= h <= FRAME_MAX):
        raise ValueError(f"images of {w}x{h}: each side must be {FRAME_MIN}..{FRAME_MAX} (12-bit x and y fields)")
    check_params(window=window, cost=cost, t_max=t_max, h_max=h_max, d_min=d_min, d_max=d_max, rows=rows,
                 uniqueness=uniqueness, max_matches=max_matches)
    if not isinstance(lr_check, (bool, np.bool_)):
        raise ValueError(f"parameter lr_check={lr_check!r}: must be True or False")
    fl = _check_features(left_xy, left.shape, "left features")
    fr = _check_features(right_xy, right.shape, "right features")
    limit = cost_limit(cost, window, int(t_max), int(h_max))
    return match_engine(fl, fr, descriptors(left, fl, cost, window), descriptors(right, fr, cost, window), width=w,
                        cost=cost, window=window, limit=limit, d_min=int(d_min), d_max=int(d_max), rows=int(rows),
                        uniqueness=int(uniqueness), lr_check=bool(lr_check), max_matches=int(max_matches))
