"""Bit-true model of the ``corner_descriptors`` block (issue 29): the hardware matcher's first half.

The block sits on the rectified stereo stream and on the corner flags of the same frames (as
``harris_stereo`` gives them, any lag of up to a few rows) and sends, for every flagged corner at least
``border`` pixels from each edge, its position and its descriptor on the descriptor port
(:mod:`eyestereo.hdl.interfaces.descriptor`), which :func:`~eyestereo.tools.models.match_engine.match_engine`'s
block takes. This model gives the beats the block sends for one frame, in order:

* for each row y (0 .. height - 1): the corners of row y in the flags' order (x ascending, at equal x the
  left camera's first), each as its :func:`~eyestereo.tools.models.match_engine.descriptor_words` words (the
  last with ``last``), then the row's end (``row_end``, with ``eof`` on the frame's last row); rows without
  corners get their row end too.

A descriptor is :func:`eyestereo.tools.models.feature_matcher.descriptors`'s, packed by
:func:`~eyestereo.tools.models.match_engine.pack_descriptors` (SAD: a window column per word; census: one word of
``window**2 - 1`` bits). Since ``border >= window // 2`` (checked), every window lies inside the frame: the two
border rules of the feature matcher (SAD's edge replication, census's 0 bits) never apply, and the
descriptors are those of :func:`eyestereo.tools.models.feature_matcher.feature_matcher` on the corners.

A beat is a tuple :data:`BEAT` ``(row_end, eof, cam, x, y, last, data)``; a row end's cam, x, last and data
are 0.

Not modelled: the block's timing. A corner whose flag comes after its window has left the line buffers
(flags more than ``lead`` rows behind the pixels, or a pending queue that overflowed) is skipped and counted
by the block (its ``late`` and ``lost`` counts); the model is the block's output when both stay 0.
"""

from __future__ import annotations

import numpy as np

from eyestereo.tools.models.census import check_image
from eyestereo.tools.models.feature_matcher import descriptors
from eyestereo.tools.models.match_engine import COSTS, WINDOWS, pack_descriptors

__all__ = ["BEAT", "check_params", "corners", "corner_descriptors"]

#: The fields of a modelled beat, in tuple order.
BEAT = ("row_end", "eof", "cam", "x", "y", "last", "data")


def check_params(*, cost: str, window: int, border: int, width: int, height: int) -> None:
    """ValueError that says why, for a setting the block cannot take."""
    if cost not in COSTS:
        raise ValueError(f"parameter cost={cost!r}: must be one of {COSTS}")
    if isinstance(window, bool) or window not in WINDOWS:
        raise ValueError(f"parameter window={window!r}: must be one of {WINDOWS}")
    if isinstance(border, bool) or not isinstance(border, (int, np.integer)) or border < window // 2:
        raise ValueError(f"parameter border={border!r}: must be an integer >= window // 2 = {window // 2} (every "
                         "corner's window inside the frame)")
    if 2 * border + 1 > min(width, height):
        raise ValueError(f"parameter border={border}: a {width}x{height} frame has no pixel {border} from each edge")


def corners(flags: np.ndarray, border: int) -> np.ndarray:
    """(n, 2) (x, y) of the set flags at least ``border`` pixels from each edge, raster order."""
    f = np.asarray(flags).astype(bool)
    h, w = f.shape
    inside = np.zeros_like(f)
    inside[border:h - border, border:w - border] = True
    ys, xs = np.nonzero(f & inside)
    return np.stack([xs, ys], axis=1).astype(np.int64)


def corner_descriptors(left, right, left_flags, right_flags, *, cost: str = "sad", window: int = 9,
                       border: int = 4) -> dict:
    """The block's beats for one frame (see the module docstring).

    ``left``/``right``: rectified grey images (uint8, same shape); ``left_flags``/``right_flags``: corner flags
    of the same shape (nonzero = corner). Returns ``beats`` (list of :data:`BEAT` tuples), ``left_xy``,
    ``right_xy`` (the corners sent, raster order) and ``words`` (per camera, the corners' descriptor words).
    """
    left, right = check_image(left, "left image"), check_image(right, "right image")
    if left.shape != right.shape:
        raise ValueError(f"left and right images differ in size: {left.shape[1]}x{left.shape[0]} and "
                         f"{right.shape[1]}x{right.shape[0]}")
    h, w = left.shape
    for name, f in (("left flags", left_flags), ("right flags", right_flags)):
        if np.shape(f) != left.shape:
            raise ValueError(f"{name} must be {w}x{h} like the images, got shape {np.shape(f)}")
    check_params(cost=cost, window=window, border=border, width=w, height=h)
    xy = [corners(left_flags, border), corners(right_flags, border)]
    words = [pack_descriptors(descriptors(img, c, cost, window), cost, window) if len(c) else []
             for img, c in zip((left, right), xy)]
    beats = []
    nxt = [0, 0]
    for y in range(h):
        while True:
            # the flags' order: x ascending, the left camera first at equal x
            cand = [(int(xy[c][nxt[c], 0]), c) for c in (0, 1) if nxt[c] < len(xy[c]) and xy[c][nxt[c], 1] == y]
            if not cand:
                break
            x, c = min(cand)
            ws = words[c][nxt[c]]
            beats += [(0, 0, c, x, y, int(k == len(ws) - 1), wd) for k, wd in enumerate(ws)]
            nxt[c] += 1
        beats.append((1, int(y == h - 1), 0, 0, y, 0, 0))
    return dict(beats=beats, left_xy=xy[0], right_xy=xy[1], words=words)
