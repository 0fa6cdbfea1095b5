"""Bit-true model of :func:`eyestereo.hdl.harris.cornerness.cornerness` (thesis 6.2.3).

c = det(G) - k trace(G)^2 from the window sums, fully pipelined, every multiplier input at most 18 bits
(two's complement, as the MULT18X18 takes them), no stage able to wrap:

=========  =====================================  =====================  ========================
stage      operation                              format (codes)         why it cannot wrap
=========  =====================================  =====================  ========================
1          a = Sxx >> 2, b = Syy >> 2             ufix[17] 0..102375     409500 >> 2
1          c = Sxy >> 2                           sfix[17]               [-204800, 204700] >> 2
1          t = (Sxx + Syy) >> 3                   ufix[17] 0..102375     trace / 2, same scale
2          ab = a * b, cc = c * c, kt = k * t     ufix[34], ufix[34],    products of the bounds
                                                  ufix[25]
3          det = ab - cc, kt8 = kt >> 8           sfix[35], ufix[17]     kt8 = floor(k t / 256)
4          ktt = kt8 * t                          ufix[34]
5          cr = det - 4 ktt                       sfix[37]               |det|, 4 ktt < 2**35
6          out = sat(cr >> 13, sfix[20])          sfix[20]               clamps instead of wrapping
=========  =====================================  =====================  ========================

Why the output shift is 13: with windows of Sobel gradients (|Ix|, |Iy| <= 128, products <= 2048,
sums <= 204800) ab <= 51200**2 and cr >> 13 <= 320000 < 2**19, so the positive side never saturates
and corners are ordered exactly as cr orders them; only edges (large negative cr) and window words
beyond what a Sobel can produce clamp. A larger shift would waste resolution on weak corners.
=========  =====================================  =====================  ========================

``k`` is a run-time port in ufix[8,8] (k = code / 256). Output units: with raw Sobel gradients g
(kernel [1 2 1] x [-1 0 1]) and M = sum w g g^T over the 5x5 window w normalised by 128, the output code
is (det M - k tr(M)^2) / 2**21 up to the quantization (see :func:`eyestereo.tools.models.harris_mono.harris_float`).
"""

from __future__ import annotations

import numpy as np

from eyestereo.tools.fixed import sfix, ufix
from eyestereo.tools.packed import PackedWord
from eyestereo.tools.models.harris_window import unpack as window_unpack

K = ufix(8, 8)
#: 20-bit signed output like the thesis's sfix[20,-16]; in this library's units (harris_float's c:
#: Sobel gradients in grey levels, window normalised by 128) the binary point sits at -21.
OUT = sfix(20, -21)
OUT_SHIFT = 13
#: The stream word: the cornerness code, two's complement.
WORD = PackedWord("cornerness", [("c", OUT)])
LATENCY = 6
STAGES = {
    "a": ufix(17), "b": ufix(17), "c": sfix(17), "t": ufix(17),
    "ab": ufix(34), "cc": ufix(34), "kt": ufix(25),
    "det": sfix(35), "kt8": ufix(17), "ktt": ufix(34), "cr": sfix(37),
}


def cornerness_stages(sxx, syy, sxy, k: int) -> dict[str, np.ndarray]:
    """Every intermediate of the pipeline (int64 arrays), for range checks and the output."""
    if not K.lo <= int(k) <= K.hi:
        raise ValueError(f"k code {k} outside ufix[8,8] (0..255)")
    sxx = np.asarray(sxx, np.int64)
    syy = np.asarray(syy, np.int64)
    sxy = np.asarray(sxy, np.int64)
    s = {}
    s["a"], s["b"], s["c"] = sxx >> 2, syy >> 2, sxy >> 2
    s["t"] = (sxx + syy) >> 3
    s["ab"], s["cc"], s["kt"] = s["a"] * s["b"], s["c"] * s["c"], int(k) * s["t"]
    s["det"], s["kt8"] = s["ab"] - s["cc"], s["kt"] >> 8
    s["ktt"] = s["kt8"] * s["t"]
    s["cr"] = s["det"] - 4 * s["ktt"]
    s["out"] = np.clip(s["cr"] >> OUT_SHIFT, OUT.lo, OUT.hi)
    return s


def cornerness_values(sxx, syy, sxy, k: int) -> np.ndarray:
    return cornerness_stages(sxx, syy, sxy, k)["out"]


def cornerness(window_words: np.ndarray, k: int) -> np.ndarray:
    """Output codes (signed) for a frame of window words; a point operation (no border)."""
    return cornerness_values(*window_unpack(window_words), k)


def to_word(values: np.ndarray) -> np.ndarray:
    """Stream words (:data:`WORD`) from cornerness codes."""
    return WORD.pack(c=values)


def from_word(words: np.ndarray) -> np.ndarray:
    """Cornerness codes from stream words."""
    return WORD.unpack(words)["c"]
