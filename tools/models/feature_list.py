"""Bit-true model of :func:`eyestereo.hdl.harris.feature_list.feature_list`: corner flags to feature lists and counts.

The feature words (the interface of the SRAM feature writer, ``sram_arbiter``'s ``feat`` queue port of
16-bit words, and of the host driver), declared once here:

* a feature is one :data:`FEATURE` word of 32 bits, sent as two 16-bit queue words, low half first:
  word 0 = x (bits 14..0) with cam in bit 15 (0 left, 1 right), word 1 = y;
* each frame's list ends with one :data:`TRAILER` (two words as well): word 0 = 0xFFFF (no feature has
  x = 0x7FFF and cam = 1: frames are at most 4096 wide), word 1 = the number of features in the list
  (bits 14..0) and the overflow flag (bit 15); ``eol`` and ``eof`` on that last word (one list per
  frame, as the feature writer's ``eof`` expects); an empty frame gives a trailer alone;
* a reset token on the flags aborts the list in progress: one queue word with ``eof`` high, ``eol`` low
  (the queue's reset token) ends it, and the next list starts with the next frame.

Timing on the queue port: two features, (x0, y0) of the left camera and (x1, y1) of the right one,
then the trailer of a list of 2 (``#`` high, ``_`` low, ``.`` don't care; a word moves on a rising
edge with ``valid`` and ``ready`` high, the consumer holds the word of cycle 2 back)::

    cycle   0       1     2       3       4     5       6      7
    valid   #       #     #       #       #     #       #      _
    ready   #       #     _       #       #     #       #      .
    data    x0|0    y0    x1|1<<15 x1|1<<15 y1  0xFFFF  2      .
    eol     _       _     _       _       _     _       #      .
    eof     _       _     _       _       _     _       #      .

Order: the stream order of the flags, raster order with left before right at each (x, y). Only pixels
at least ``border`` from every edge count (the detector's flags nearer the border are unspecified).
A list holds at most ``max_features`` features; the rest are counted but not listed, and the trailer's
overflow flag is set. Per frame the counts of every (camera, threshold block) and per camera are
published for an adaptive threshold controller; they count every feature, listed or not.
"""

from __future__ import annotations

import numpy as np

from eyestereo.tools.fixed import ufix
from eyestereo.tools.models.prethreshold import block_index
from eyestereo.tools.packed import PackedWord

#: One feature: two 16-bit queue words, (x | cam << 15) then y.
FEATURE = PackedWord("feature", [("x", ufix(15)), ("cam", ufix(1)), ("y", ufix(16))])
#: The end of a frame's list: 0xFFFF then (count | overflow << 15).
TRAILER = PackedWord("feature list trailer", [("marker", ufix(16)), ("count", ufix(15)), ("overflow", ufix(1))])
MARKER = 0xFFFF
MAX_FEATURES = (1 << 15) - 1
#: Queue word of a reset token (data, eol, eof).
TOKEN_WORD = (0, False, True)


def check_params(width: int, height: int, border: int, max_features: int) -> None:
    if not 1 <= border or 2 * border > min(width, height):
        raise ValueError(f"parameter border={border}: must be at least 1 and at most half of a {width}x{height} frame")
    if not 1 <= max_features <= MAX_FEATURES:
        raise ValueError(f"parameter max_features={max_features}: must be 1..{MAX_FEATURES} (15-bit count)")


def features(left: np.ndarray, right: np.ndarray, *, border: int) -> list[tuple[int, int, int]]:
    """(x, y, cam) of every set flag inside the border, in stream order."""
    fl = np.asarray(left).astype(bool)
    fr = np.asarray(right).astype(bool)
    h, w = fl.shape
    inside = np.zeros((h, w), bool)
    inside[border:h - border, border:w - border] = True
    both = np.stack([fl & inside, fr & inside], axis=-1)  # (h, w, cam)
    ys, xs, cams = np.nonzero(both)  # C order: y, then x, then cam: the stream order
    return list(zip(xs.tolist(), ys.tolist(), cams.tolist()))


def feature_list(left: np.ndarray, right: np.ndarray, *, blocks=(4, 4), border: int = 4,
                 max_features: int = 1023) -> dict:
    """The list words, counts and flags the block gives for one frame pair of corner flags.

    Returns ``words`` (list of (data, eol, eof) queue words: the features, then the trailer),
    ``features`` (listed (x, y, cam)), ``counts`` (2, BX*BY) per camera and block, ``totals`` (2,),
    ``overflow``.
    """
    h, w = np.asarray(left).shape
    check_params(w, h, border, max_features)
    feats = features(left, right, border=border)
    idx = block_index(h, w, tuple(blocks))
    counts = np.zeros((2, blocks[0] * blocks[1]), np.int64)
    for x, y, cam in feats:
        counts[cam, idx[y, x]] += 1
    listed = feats[:max_features]
    overflow = len(feats) > max_features
    words = []
    for x, y, cam in listed:
        word = int(FEATURE.pack(x=x, cam=cam, y=y))
        words += [(word & 0xFFFF, False, False), (word >> 16, False, False)]
    trailer = int(TRAILER.pack(marker=MARKER, count=len(listed), overflow=int(overflow)))
    words += [(trailer & 0xFFFF, False, False), (trailer >> 16, True, True)]
    return dict(words=words, features=listed, counts=counts, totals=counts.sum(axis=1), overflow=overflow)


def parse_words(words) -> list[dict]:
    """Lists from queue words (data, eol, eof), as a host driver reads them: one dict per list, with
    ``features`` [(x, y, cam)], ``count``, ``overflow``; an aborted list (reset token) is ``{"aborted": True}``."""
    out, cur, i = [], [], 0
    words = list(words)
    while i < len(words):
        d, eol, eof = words[i]
        if eof and not eol:
            out.append(dict(aborted=True, features=cur))
            cur, i = [], i + 1
            continue
        if i + 1 >= len(words):
            raise ValueError("a list ends in the middle of a two-word entry")
        d1, eol1, eof1 = words[i + 1]
        if eof1 and not eol1:  # token after the first half of an entry
            out.append(dict(aborted=True, features=cur))
            cur, i = [], i + 2
            continue
        word = int(d) | (int(d1) << 16)
        if int(d) == MARKER:
            t = TRAILER.unpack(np.array([word]))
            if not (eol1 and eof1):
                raise ValueError("a trailer without eol/eof")
            out.append(dict(features=cur, count=int(t["count"][0]), overflow=bool(t["overflow"][0])))
            cur = []
        else:
            f = FEATURE.unpack(np.array([word]))
            cur.append((int(f["x"][0]), int(f["y"][0]), int(f["cam"][0])))
        i += 2
    return out
