"""Bit-true model of the future ``median3`` block (issue 28): an optional 3 x 3 median of the disparity codes.

Each output is the median (the 5th smallest) of the nine 16-bit codes of the 3 x 3 window centred on the
pixel, the invalid code 0xFFFF taken as the largest value it is: a pixel ends invalid when five or more of
its nine are invalid, and invalid neighbours push a valid median up by at most their count's rank. The
hardware needs no special case for invalid pixels (a plain sorting network of unsigned comparators).

**Border** (defined): a pixel whose window leaves the image (first and last row and column) passes
through unchanged; the line-delay window selects the centre tap there, no padded data.

Bit widths: 16-bit codes in and out. Resources: two line delays of 16 bits and a 9-input median network
(19 compare-exchange cells in the usual arrangement). Latency: one row and one pixel plus the network.
"""

from __future__ import annotations

import numpy as np

__all__ = ["median3"]


def median3(codes) -> np.ndarray:
    """The 3 x 3 median of a uint16 code map, borders passed through (uint16, same shape)."""
    a = np.asarray(codes)
    if a.ndim != 2:
        raise ValueError(f"median3 takes a 2-D map of codes, got shape {a.shape}")
    if not np.issubdtype(a.dtype, np.integer) or (a.size and (a.min() < 0 or a.max() > 0xFFFF)):
        raise ValueError(f"median3 takes 16-bit unsigned codes, got {a.dtype}")
    a = a.astype(np.uint16)
    h, w = a.shape
    out = a.copy()
    if h < 3 or w < 3:
        return out
    stack = np.stack([a[dy:h - 2 + dy, dx:w - 2 + dx] for dy in range(3) for dx in range(3)])
    out[1:-1, 1:-1] = np.sort(stack, axis=0)[4]
    return out
