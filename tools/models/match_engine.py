"""Bit-true model of the ``match_engine`` block (issue 29): corner descriptors of both cameras to a match list.

The engine is the second half of the hardware matcher (:mod:`eyestereo.tools.models.feature_matcher` is the
whole): it takes, per camera, the corners of a frame in raster order with one **descriptor** each, and
writes the frame's match list. The descriptor is what the cost needs of the window around the corner:

* ``"sad"``: the ``window`` x ``window`` grey levels, ``window`` words of ``8 * window`` bits, word k the
  window's column k (left to right), the pixel of row i in bits ``8 i + 7 .. 8 i`` (the top row lowest): a
  column per word because the front half reads a window from its line buffers a column per clock (all rows
  at one address); the cost is a sum over the pixels, so the layout only has to be the same for both cameras;
* ``"census"``: one word of ``window**2 - 1`` bits, the census bits in the window's raster order, the
  top-left neighbour the most significant (the census block's word).

A pair's cost is the sum of ``|l - r|`` over the window, or the number of differing bits; every step after
that (candidates, best and second best with their tie rule, threshold, uniqueness, left-right check, the
list, its words) is the one the feature matcher's docstring describes, and this module computes it.
:func:`match_engine` is that computation; :func:`eyestereo.tools.models.feature_matcher.feature_matcher`
builds the descriptors from the images and calls it.

**The order key.** Candidates of a corner are ranked by (cost, |dy|, disparity, dy), smallest first: the
block compares one unsigned :data:`KEY` word, so the rule is one comparator. Two candidates of one left
corner never have equal keys (equal dy and disparity make them the same right corner), nor two of one
right corner; the left-right check ranks a right corner's left candidates by the same key.

**The threshold** is the ``limit`` the block gets at run time (accepted: ``best < limit``), the feature
matcher's :func:`~eyestereo.tools.models.feature_matcher.cost_limit` of ``t_max`` or ``h_max``.
"""

from __future__ import annotations

import numpy as np

from eyestereo.tools.constants import MATCH_MARKER
from eyestereo.tools.fixed import sfix, ufix
from eyestereo.tools.packed import PackedWord

__all__ = ["COSTS", "WINDOWS", "MATCH", "TRAILER", "MARKER", "KEY", "MAX_MATCHES", "MAX_ROWS", "MAX_DISPARITY",
           "MAX_LIMIT", "MATCHED", "NO_CANDIDATE", "OVER_THRESHOLD", "NOT_UNIQUE", "LR_FAILED", "descriptor_words",
           "word_bits", "cost_bits", "pack_descriptors", "order_key", "candidates", "check_engine", "match_engine",
           "parse_list"]

COSTS = ("sad", "census")
#: The window sizes the matcher offers (odd, so the corner is the centre).
WINDOWS = (5, 7, 9, 11)
#: One match: three 16-bit queue words, low first (see the feature matcher's docstring).
MATCH = PackedWord("match", [("x", ufix(12)), ("dy", sfix(4)), ("y", ufix(12)), ("disparity", ufix(8)),
                             ("cost", ufix(12))])
#: The end of a frame's list: MARKER, then count | overflow << 15, then the candidates (saturated).
TRAILER = PackedWord("match list trailer", [("marker", ufix(16)), ("count", ufix(15)), ("overflow", ufix(1)),
                                            ("candidates", ufix(16))])
MARKER = MATCH_MARKER
MAX_MATCHES = (1 << 15) - 1
MAX_ROWS = 7
MAX_DISPARITY = 255
#: The largest threshold: the listed costs must fit MATCH's 12-bit cost field.
MAX_LIMIT = 1 << 12
#: What became of a left corner (``status``).
MATCHED, NO_CANDIDATE, OVER_THRESHOLD, NOT_UNIQUE, LR_FAILED = range(5)
#: The order of two candidates, one unsigned word, least significant field first: dy + 8 (dy -7..7),
#: the disparity, |dy|, the cost (15 bits: an 11 x 11 SAD is at most 121 * 255 = 30855).
KEY = PackedWord("match order key", [("dy", ufix(4)), ("disparity", ufix(8)), ("abs_dy", ufix(3)),
                                     ("cost", ufix(15))])
_CHUNK = 1 << 21  # pixel differences per chunk of pairs (memory bound, a few MB)


def descriptor_words(cost: str, window: int) -> int:
    """Words per descriptor: ``window`` for SAD (a column each), 1 for census."""
    return window if cost == "sad" else 1


def word_bits(cost: str, window: int) -> int:
    """Bits of a descriptor word: ``8 * window`` (SAD: a column of grey levels) or ``window**2 - 1`` (census)."""
    return 8 * window if cost == "sad" else window * window - 1


def cost_bits(cost: str, window: int) -> int:
    """Bits of a pair's cost: the largest SAD (``window**2 * 255``) or Hamming distance (``window**2 - 1``)."""
    return (window * window * 255 if cost == "sad" else window * window - 1).bit_length()


def pack_descriptors(desc: np.ndarray, cost: str, window: int) -> list[list[int]]:
    """The block's descriptor words of each corner: ``desc`` is (n, window**2) grey levels (SAD) or (n,
    window**2 - 1) census bits (bool, the window's raster order); returns n lists of
    :func:`descriptor_words` ints."""
    d = np.asarray(desc)
    if cost == "sad":
        cols = d.reshape(len(d), window, window).transpose(0, 2, 1).astype(np.int64)  # [corner, column, row]
        weights = [1 << (8 * i) for i in range(window)]
        return [[int(sum(int(p) * w for p, w in zip(col, weights))) for col in corner] for corner in cols]
    nb = window * window - 1
    # Python ints: a word of 9 x 9 or 11 x 11 bits is wider than numpy's int64
    return [[sum(1 << (nb - 1 - int(i)) for i in np.flatnonzero(bits))] for bits in d.astype(bool)]


def order_key(cost, dy, disparity):
    """The :data:`KEY` word of candidates (numpy arrays or ints)."""
    return KEY.pack(dy=np.asarray(dy) + 8, disparity=disparity, abs_dy=np.abs(dy), cost=cost)


def candidates(left_xy: np.ndarray, right_xy: np.ndarray, width: int, d_min: int, d_max: int,
               rows: int) -> tuple[np.ndarray, np.ndarray]:
    """(left index, right index) of every pair, in the block's order (checked, raster-ordered lists):
    left corners in raster order, for each its right corners in raster order (row yl - rows first)."""
    keys = right_xy[:, 1] * width + right_xy[:, 0]  # increasing: the right list is in raster order
    dys = np.arange(-rows, rows + 1)
    y = left_xy[:, 1:2] + dys[None, :]  # (n, 2 rows + 1): one key range per row, row yl - rows first
    xlo = np.maximum(left_xy[:, 0] - d_max, 0)[:, None]
    xhi = np.minimum(left_xy[:, 0] - d_min, width - 1)[:, None]
    start = np.searchsorted(keys, y * width + xlo, side="left")
    stop = np.searchsorted(keys, y * width + xhi, side="right")
    cnt = np.where(xlo <= xhi, stop - start, 0).ravel()  # rows off the image find no key: empty ranges
    total = int(cnt.sum())
    first = np.repeat(np.cumsum(cnt) - cnt, cnt)
    ri = np.repeat(start.ravel(), cnt) + (np.arange(total) - first)
    li = np.repeat(np.repeat(np.arange(len(left_xy)), len(dys)), cnt)
    return li.astype(np.int64), ri.astype(np.int64)


def check_engine(*, cost: str, window: int, limit: int, d_min: int, d_max: int, rows: int, uniqueness: int,
                 max_matches: int) -> None:
    """ValueError that says why, for any setting the engine cannot take."""
    for name, v in dict(window=window, limit=limit, d_min=d_min, d_max=d_max, rows=rows, uniqueness=uniqueness,
                        max_matches=max_matches).items():
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer)):
            raise ValueError(f"parameter {name}={v!r}: must be an integer")
    if cost not in COSTS:
        raise ValueError(f"parameter cost={cost!r}: must be one of {COSTS}")
    if window not in WINDOWS:
        raise ValueError(f"parameter window={window!r}: must be odd and one of {WINDOWS}")
    if not 1 <= limit <= MAX_LIMIT:
        raise ValueError(f"parameter limit={limit}: must be 1..{MAX_LIMIT} (accepted costs are below it and "
                         f"fit the 12-bit cost field)")
    if d_min < 0:
        raise ValueError(f"parameter d_min={d_min}: must be >= 0 (d = xl - xr; negative disparities lie "
                         f"behind the cameras)")
    if d_max > MAX_DISPARITY:
        raise ValueError(f"parameter d_max={d_max}: must be <= {MAX_DISPARITY} (8-bit disparity field)")
    if d_min > d_max:
        raise ValueError(f"parameters d_min={d_min}, d_max={d_max}: the disparity range is empty")
    if not 0 <= rows <= MAX_ROWS:
        raise ValueError(f"parameter rows={rows}: must be 0..{MAX_ROWS} (4-bit signed dy field)")
    if not 0 <= uniqueness <= 99:
        raise ValueError(f"parameter uniqueness={uniqueness}: must be 0..99 (percent; 0 = off)")
    if not 1 <= max_matches <= MAX_MATCHES:
        raise ValueError(f"parameter max_matches={max_matches}: must be 1..{MAX_MATCHES} (15-bit count)")


def _pair_costs(a: np.ndarray, b: np.ndarray, li: np.ndarray, ri: np.ndarray, cost: str) -> np.ndarray:
    out = np.empty(len(li), np.int64)
    step = max(1, _CHUNK // max(1, a.shape[1]))
    for s in range(0, len(li), step):
        pa, pb = a[li[s:s + step]], b[ri[s:s + step]]
        diff = np.abs(pa.astype(np.int16) - pb.astype(np.int16)) if cost == "sad" else pa != pb
        out[s:s + step] = diff.sum(axis=1, dtype=np.int64)
    return out


def _first_of_groups(key: np.ndarray, group: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pairs sorted by group, then by ``key``; the start of each group in it."""
    order = np.lexsort((key, group))
    g = group[order]
    first = np.ones(len(order), bool)
    first[1:] = g[1:] != g[:-1]
    return order, first


def match_engine(left_xy: np.ndarray, right_xy: np.ndarray, left_desc: np.ndarray, right_desc: np.ndarray, *,
                 width: int, cost: str = "sad", window: int = 9, limit: int = 11 * 81, d_min: int = 0,
                 d_max: int = 64, rows: int = 0, uniqueness: int = 0, lr_check: bool = False,
                 max_matches: int = 1023) -> dict:
    """The match list of one frame from checked inputs: corners (n, 2) (x, y) in raster order without
    repeats, descriptors (n, window**2) grey levels (SAD) or (n, window**2 - 1) census bits, ``width`` the
    frame's (the candidates' search bound). Returns what
    :func:`~eyestereo.tools.models.feature_matcher.feature_matcher` documents."""
    check_engine(cost=cost, window=window, limit=limit, d_min=d_min, d_max=d_max, rows=rows,
                 uniqueness=uniqueness, max_matches=max_matches)
    fl = np.asarray(left_xy, np.int64).reshape(-1, 2)
    fr = np.asarray(right_xy, np.int64).reshape(-1, 2)
    a, b = np.asarray(left_desc), np.asarray(right_desc)
    nl = len(fl)
    li, ri = candidates(fl, fr, int(width), int(d_min), int(d_max), int(rows))
    c = _pair_costs(a, b, li, ri, cost)
    dyr = fr[ri, 1] - fl[li, 1]
    disp = fl[li, 0] - fr[ri, 0]
    key = order_key(c, dyr, disp)

    best = np.full(nl, -1, np.int64)
    second = np.full(nl, -1, np.int64)
    choice = np.full(nl, -1, np.int64)
    status = np.full(nl, NO_CANDIDATE, np.int64)
    if len(li):
        order, first = _first_of_groups(key, li)
        win = order[first]
        best[li[win]], choice[li[win]] = c[win], ri[win]
        # the pair after a group's first, when in the same group, holds its second-lowest cost
        nxt = np.flatnonzero(first) + 1
        nxt = nxt[nxt < len(order)]
        nxt = nxt[li[order[nxt]] == li[order[nxt - 1]]]
        second[li[order[nxt]]] = c[order[nxt]]
        has = choice >= 0
        status[has] = MATCHED
        status[has & (best >= limit)] = OVER_THRESHOLD
        unique = (second < 0) | (best * (100 + int(uniqueness)) <= second * 100)
        status[(status == MATCHED) & ~unique] = NOT_UNIQUE
        if lr_check:
            # the right corner's best left corner, over all its pairs: if that best is over the
            # threshold, so are all its pairs, and no left corner can be matched to it anyway
            order_r, first_r = _first_of_groups(key, ri)
            best_left = np.full(len(fr), -1, np.int64)
            best_left[ri[order_r[first_r]]] = li[order_r[first_r]]
            mutual = np.zeros(nl, bool)
            mutual[has] = best_left[choice[has]] == np.flatnonzero(has)
            status[(status == MATCHED) & ~mutual] = LR_FAILED

    found = np.flatnonzero(status == MATCHED)  # increasing: the order of the left corners
    listed = found[:max_matches]
    j = choice[listed]
    matches = np.stack([fl[listed, 0], fl[listed, 1], fl[listed, 0] - fr[j, 0], best[listed]], axis=1)
    dy = fr[j, 1] - fl[listed, 1]
    overflow = len(found) > max_matches
    words = []
    packed = MATCH.pack(x=matches[:, 0], dy=dy, y=matches[:, 1], disparity=matches[:, 2], cost=matches[:, 3])
    for word in packed.tolist():
        words += [(word & 0xFFFF, False, False), ((word >> 16) & 0xFFFF, False, False), (word >> 32, False, False)]
    trailer = int(TRAILER.pack(marker=MARKER, count=len(listed), overflow=int(overflow),
                               candidates=min(len(li), 0xFFFF)))
    words += [(trailer & 0xFFFF, False, False), ((trailer >> 16) & 0xFFFF, False, False), (trailer >> 32, True, True)]
    return dict(matches=matches.reshape(-1, 4).astype(np.int64), left_index=listed, right_index=j, dy=dy,
                count=len(listed), total=len(found), overflow=bool(overflow), candidates=int(len(li)), limit=limit,
                words=words, best=best, second=second, choice=choice, status=status,
                pairs=dict(left=li, right=ri, cost=c))


def parse_list(words) -> dict:
    """A match list's words (ints, or ``(data, eol, eof)``; the trailer last) back to ``matches`` ((n, 4) x, y,
    disparity, cost), ``dy``, ``count``, ``overflow``, ``candidates``; ValueError when the words are not a list."""
    w = [int(v[0]) if isinstance(v, (tuple, list)) else int(v) for v in words]
    if len(w) < 3 or len(w) % 3 or w[-3] != MARKER:
        raise ValueError(f"not a match list: {len(w)} words, want 3 per match and a trailer starting {MARKER:#06x}")
    n = len(w) // 3 - 1
    tr = TRAILER.unpack(w[-3] | w[-2] << 16 | w[-1] << 32)
    if int(tr["count"]) != n:
        raise ValueError(f"match list of {n} matches, its trailer counts {int(tr['count'])}")
    packed = np.array([w[3 * i] | w[3 * i + 1] << 16 | w[3 * i + 2] << 32 for i in range(n)], np.int64)
    f = MATCH.unpack(packed)
    matches = np.stack([f["x"], f["y"], f["disparity"], f["cost"]], axis=1).reshape(-1, 4).astype(np.int64)
    return dict(matches=matches, dy=np.asarray(f["dy"], np.int64), count=n, overflow=bool(tr["overflow"]),
                candidates=int(tr["candidates"]))
