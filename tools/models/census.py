"""Bit-true model of the future ``census`` block (issue 28): the census transform of both cameras.

Every pixel gets one bit per neighbour of its ``window`` x ``window`` neighbourhood (the centre left out):
the bit is 1 when the neighbour's grey level is strictly below the centre's. The bits are packed in the
raster order of the window (top-left neighbour = most significant bit, bottom-right = bit 0), so a 5 x 5
census is a 24-bit word and a 7 x 7 census a 48-bit word. Matching compares two words by their Hamming
distance (:mod:`eyestereo.tools.models.sgm`), so only the order being the same in both cameras matters.

**Border** (defined, not "unspecified"): a neighbour outside the image contributes a 0 bit. A raster
line-delay window knows which of its taps lie outside the image (the row and column counters against
the radius) and ANDs those comparison bits with 0: one gate per bit, no multiplexed pixel data (a clamped
or mirrored window would need a multiplexer per tap). Both cameras get the same rule, so two border
pixels still match each other on the bits they have.

Ports of the block: a stereo image stream in (8-bit left and right), the two census words out per pixel.

Bit widths: 8-bit pixels in, comparisons of 8 bits; out ``window**2 - 1`` bits per camera (24 or 48).
Resources of the block: ``window - 1`` line delays of 2 x 8 bits (both cameras) and ``window**2 - 1``
8-bit comparators per camera.
"""

from __future__ import annotations

import numpy as np

__all__ = ["WINDOWS", "census", "census_bits", "census_stereo"]

#: The window sizes the block offers.
WINDOWS = (5, 7)


def census_bits(window: int) -> int:
    """The number of bits of a census word: one per neighbour of the window (``window**2 - 1``)."""
    if isinstance(window, bool) or window not in WINDOWS:
        raise ValueError(f"census window must be one of {WINDOWS}, got {window!r}")
    return window * window - 1


def check_image(img, what: str = "image") -> np.ndarray:
    """A 2-D uint8 (or integer 0..255) image as uint8; ValueError that says what is wrong otherwise."""
    a = np.asarray(img)
    if a.ndim != 2:
        raise ValueError(f"{what} must be a 2-D grey image, got shape {a.shape}")
    if a.shape[0] < 1 or a.shape[1] < 1:
        raise ValueError(f"{what} is empty ({a.shape[1]}x{a.shape[0]})")
    if a.dtype != np.uint8:
        if not np.issubdtype(a.dtype, np.integer) or a.min() < 0 or a.max() > 255:
            raise ValueError(f"{what} must hold 8-bit grey levels (uint8 or integers 0..255), got {a.dtype}")
        a = a.astype(np.uint8)
    return a


def census(img, *, window: int = 5) -> np.ndarray:
    """The census words (uint64, ``census_bits(window)`` bits used) of a grey image, same shape."""
    nbits = census_bits(window)
    a = check_image(img).astype(np.int16)
    h, w = a.shape
    r = window // 2
    # pad with a value that is never below the centre: the out-of-image bit is 0 by the rule above
    pad = np.full((h + 2 * r, w + 2 * r), 256, np.int16)
    pad[r:r + h, r:r + w] = a
    out = np.zeros((h, w), np.uint64)
    bit = nbits
    for dy in range(window):
        for dx in range(window):
            if dy == r and dx == r:
                continue
            bit -= 1
            below = pad[dy:dy + h, dx:dx + w] < a
            out |= below.astype(np.uint64) << np.uint64(bit)
    return out


def census_stereo(left, right, *, window: int = 5) -> tuple[np.ndarray, np.ndarray]:
    """Census words of both cameras of a stereo pair (the block takes a stereo stream: same size)."""
    left = check_image(left, "left image")
    right = check_image(right, "right image")
    if left.shape != right.shape:
        raise ValueError(f"left and right images differ in size: {left.shape[1]}x{left.shape[0]} and "
                         f"{right.shape[1]}x{right.shape[0]}")
    return census(left, window=window), census(right, window=window)
