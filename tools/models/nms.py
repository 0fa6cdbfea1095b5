"""Bit-true model of :func:`eyestereo.hdl.harris.nms.nms`: non-maximum suppression with a raster tie rule.

A pixel is a feature when its value is > 0 and it beats every other pixel of the size x size window
centred on it, where "beats" means: strictly greater than the neighbours that come before it in raster
order (rows above; same row, to the left) and greater or equal to those after it. On a plateau of equal
values that fits in the window, exactly one pixel survives: the plateau's first in raster order.

The block takes mono and stereo streams; on a stereo stream each camera's flags are this function of
that camera's frame (:func:`eyestereo.tools.models.harris_stereo.harris_stereo` applies it per camera).
"""

from __future__ import annotations

import numpy as np

from eyestereo.tools.constants import NMS_SIZES
from eyestereo.tools.models.border import interior_mask
from eyestereo.tools.packed import PackedWord

#: The output word: one feature flag per pixel.
WORD = PackedWord("nms", [("corner", 1)])


def nms(values: np.ndarray, size: int) -> tuple[np.ndarray, np.ndarray]:
    """(feature flags 0/1, interior mask) for a frame of signed values."""
    if size not in NMS_SIZES:
        raise ValueError(f"nms size must be one of {NMS_SIZES}, got {size}")
    v = np.asarray(values, np.int64)
    h, w = v.shape
    r = size // 2
    flags = v > 0
    if r:
        pad = np.full((h + 2 * r, w + 2 * r), np.iinfo(np.int64).min, dtype=np.int64)
        pad[r:r + h, r:r + w] = v
        for dy in range(-r, r + 1):
            for dx in range(-r, r + 1):
                if dy == 0 and dx == 0:
                    continue
                n = pad[r + dy:r + dy + h, r + dx:r + dx + w]
                before = dy < 0 or (dy == 0 and dx < 0)
                flags &= (v > n) if before else (v >= n)
    return flags.astype(np.int64), interior_mask(h, w, r)
