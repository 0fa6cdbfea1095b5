"""Bit-true model of :func:`eyestereo.hdl.harris.sobel.sobel`: Ix, Iy as sfix[9,-3] (floor of G/8)."""

import numpy as np

from eyestereo.tools.fixed import requantize, sfix
from eyestereo.tools.packed import PackedWord
from eyestereo.tools.models.border import correlate_int, interior_mask

#: Ix kernel (right minus left, as OpenCV's Sobel with dx=1); Iy is its transpose (down minus up).
KX = np.array([[-1, 0, 1], [-2, 0, 2], [-1, 0, 1]], dtype=np.int64)
KY = KX.T.copy()
#: Full-precision gradient: |G| <= 4 * 255 = 1020 needs sfix[11,0].
GRAD = sfix(11, 0)
#: Output format of each component (thesis 6.2.1): the gradient floored to a multiple of 8.
OUT = sfix(9, -3)
OUT_BITS = OUT.wl
#: The stream word: Ix in bits 8..0, Iy in bits 17..9, two's complement codes of sfix[9,-3].
WORD = PackedWord("sobel", [("ix", OUT), ("iy", OUT)])


def sobel(frame: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(ix, iy, interior mask) as integer codes of sfix[9,-3]: floor(G / 8)."""
    frame = np.asarray(frame, dtype=np.int64)
    if frame.ndim != 2:
        raise ValueError(f"sobel wants a 2-D grey image, got shape {frame.shape}")
    ix = requantize(correlate_int(frame, KX), GRAD, OUT)
    iy = requantize(correlate_int(frame, KY), GRAD, OUT)
    return ix, iy, interior_mask(*frame.shape, 1)


def pack(ix: np.ndarray, iy: np.ndarray) -> np.ndarray:
    """The 18-bit stream word (:data:`WORD`) from Ix and Iy codes."""
    return WORD.pack(ix=ix, iy=iy)


def unpack(words: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(ix, iy) signed codes from 18-bit stream words."""
    f = WORD.unpack(words)
    return f["ix"], f["iy"]
