"""Bit-true model of :func:`eyestereo.hdl.harris.harris_window.harris_window` (thesis 6.2.2).

Input: Sobel words (Iy, Ix as sfix[9,-3] codes). The products Ix^2, Iy^2, IxIy are formed per pixel
from the midpoints of the codes' floor intervals (a code c stands for gradients 8c .. 8c + 7, so the
product uses 2c + 1 in units of 4: one extra constant bit into the multiplier, and the floor bias of
the Sobel stage is gone), cut to 12 bits with rounding ((p + 16) >> 5) and saturation (ufix[12,-9],
ufix[12,-9], sfix[12,-9]; Sobel codes, -128..127, give at most 2032 and never saturate), packed into
one 36-bit word so one set of four line delays carries all three, and summed over the separable 5x5 window
[1 2 4 2 1] x [1 2 4 2 1]. The sums keep full precision: 19 bits each, the "/128" of the kernel is a
move of the binary point (fraction length 7 more), so the outputs are ufix[19,-2], ufix[19,-2],
sfix[19,-2] in real units of the gradient products.
"""

from __future__ import annotations

import numpy as np

from eyestereo.tools.fixed import sfix, ufix
from eyestereo.tools.packed import PackedWord
from eyestereo.tools.models.sobel import unpack as sobel_unpack
from eyestereo.tools.models.border import correlate_int, interior_mask

TAPS = np.array([1, 2, 4, 2, 1], dtype=np.int64)
KERNEL = np.outer(TAPS, TAPS)  # sum 100; normalised by 128 (a binary-point move, see module doc)
RADIUS = 2

PROD_SQ = ufix(12, -9)   # (2 Ix + 1)^2 / 32, i.e. the squared gradient midpoint in units of 512
PROD_XY = sfix(12, -9)   # (2 Ix + 1)(2 Iy + 1) / 32
SUM_SQ = ufix(19, -2)    # 100 * 4095 = 409500 < 2**19; fl = -9 + 7 for the /128
SUM_XY = sfix(19, -2)    # 100 * [-2048, 2047] fits 19 signed bits
#: The product word through the line delays: Pxx in bits 11..0, Pyy in 23..12, Pxy in 35..24.
PRODUCTS = PackedWord("harris_window products", [("pxx", PROD_SQ), ("pyy", PROD_SQ), ("pxy", PROD_XY)])
#: The output word: Sxx in bits 18..0, Syy in 37..19, Sxy in 56..38 (two's complement).
WORD = PackedWord("harris_window", [("sxx", SUM_SQ), ("syy", SUM_SQ), ("sxy", SUM_XY)])
PACK_BITS = PRODUCTS.width  # 36
OUT_BITS = WORD.width       # 57


def products(ix: np.ndarray, iy: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(pxx, pyy, pxy): rounded midpoint products (see the module doc), saturated to 12 bits."""
    # Each code c stands for the interval [8c, 8c + 8) of the floored gradient: use its midpoint
    # 8c + 4, i.e. (2c + 1) in units of 4, and round the product cut (+16 before >> 5).
    mx = 2 * np.asarray(ix, dtype=np.int64) + 1
    my = 2 * np.asarray(iy, dtype=np.int64) + 1
    pxx = np.clip((mx * mx + 16) >> 5, PROD_SQ.lo, PROD_SQ.hi)
    pyy = np.clip((my * my + 16) >> 5, PROD_SQ.lo, PROD_SQ.hi)
    pxy = np.clip((mx * my + 16) >> 5, PROD_XY.lo, PROD_XY.hi)
    return pxx, pyy, pxy


def harris_window_sums(ix: np.ndarray, iy: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(sxx, syy, sxy, interior mask): weighted 5x5 sums of the 12-bit products (exact integers)."""
    pxx, pyy, pxy = products(ix, iy)
    h, w = pxx.shape
    return (correlate_int(pxx, KERNEL), correlate_int(pyy, KERNEL), correlate_int(pxy, KERNEL),
            interior_mask(h, w, RADIUS))


def pack(sxx: np.ndarray, syy: np.ndarray, sxy: np.ndarray) -> np.ndarray:
    """The 57-bit output word (:data:`WORD`) from the three sums."""
    return WORD.pack(sxx=sxx, syy=syy, sxy=sxy)


def unpack(words: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(sxx, syy, sxy) from output words."""
    f = WORD.unpack(words)
    return f["sxx"], f["syy"], f["sxy"]


def harris_window(sobel_words: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(output words, interior mask) for a frame of Sobel words."""
    ix, iy = sobel_unpack(sobel_words)
    sxx, syy, sxy, mask = harris_window_sums(ix, iy)
    return pack(sxx, syy, sxy), mask
