"""Bit-true model of :func:`eyestereo.hdl.harris_window.harris_window` (thesis 6.2.2).

Input: Sobel words (Iy, Ix as sfix[9,-3] codes). The products Ix^2, Iy^2, IxIy are formed per pixel,
floored by 8 and saturated to 12 bits (ufix[12,-9], ufix[12,-9], sfix[12,-9]; with the Sobel block's
codes, -128..127 and never both -128, saturation never triggers), packed into one 36-bit word so one
set of four line delays carries all three, and summed over the separable 5x5 window
[1 2 4 2 1] x [1 2 4 2 1]. The sums keep full precision: 19 bits each, the "/128" of the kernel is a
move of the binary point (fraction length 7 more), so the outputs are ufix[19,-2], ufix[19,-2],
sfix[19,-2] in real units of the gradient products.
"""

from __future__ import annotations

import numpy as np

from eyestereo.tools.fixed import sfix, ufix
from eyestereo.tools.sobel import unpack as sobel_unpack
from eyestereo.tools.window import correlate_int, interior_mask

TAPS = np.array([1, 2, 4, 2, 1], dtype=np.int64)
KERNEL = np.outer(TAPS, TAPS)  # sum 100; normalised by 128 (a binary-point move, see module doc)
RADIUS = 2

PROD_SQ = ufix(12, -9)   # Ix^2 / 8, Iy^2 / 8 (Ix code unit 8 -> square unit 64 -> /8 unit 512)
PROD_XY = sfix(12, -9)   # Ix Iy / 8
SUM_SQ = ufix(19, -2)    # 100 * 4095 = 409500 < 2**19; fl = -9 + 7 for the /128
SUM_XY = sfix(19, -2)    # 100 * [-2048, 2047] fits 19 signed bits
PACK_BITS = 36           # product word through the line delays: Ixy | Iyy | Ixx, 12 bits each
OUT_BITS = 3 * 19        # output word: Sxy (bits 56..38) | Syy (37..19) | Sxx (18..0)


def products(ix: np.ndarray, iy: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(pxx, pyy, pxy): floor(product / 8), saturated to the 12-bit formats."""
    ix = np.asarray(ix, dtype=np.int64)
    iy = np.asarray(iy, dtype=np.int64)
    pxx = np.clip((ix * ix) >> 3, PROD_SQ.lo, PROD_SQ.hi)
    pyy = np.clip((iy * iy) >> 3, PROD_SQ.lo, PROD_SQ.hi)
    pxy = np.clip((ix * iy) >> 3, PROD_XY.lo, PROD_XY.hi)
    return pxx, pyy, pxy


def harris_window_sums(ix: np.ndarray, iy: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(sxx, syy, sxy, interior mask): weighted 5x5 sums of the 12-bit products (exact integers)."""
    pxx, pyy, pxy = products(ix, iy)
    h, w = pxx.shape
    return (correlate_int(pxx, KERNEL), correlate_int(pyy, KERNEL), correlate_int(pxy, KERNEL),
            interior_mask(h, w, RADIUS))


def pack(sxx: np.ndarray, syy: np.ndarray, sxy: np.ndarray) -> np.ndarray:
    m = (1 << 19) - 1
    return (np.asarray(sxx, np.int64) & m) | ((np.asarray(syy, np.int64) & m) << 19) | \
        ((np.asarray(sxy, np.int64) & m) << 38)


def unpack(words: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    w = np.asarray(words, dtype=np.int64)
    m = (1 << 19) - 1
    sxy = (w >> 38) & m
    sxy = np.where(sxy >= 1 << 18, sxy - (1 << 19), sxy)
    return w & m, (w >> 19) & m, sxy


def harris_window(sobel_words: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(output words, interior mask) for a frame of Sobel words."""
    ix, iy = sobel_unpack(sobel_words)
    sxx, syy, sxy, mask = harris_window_sums(ix, iy)
    return pack(sxx, syy, sxy), mask
