"""Bit-true model of :func:`eyestereo.hdl.rectify.coordinate_warper.coordinate_warper` (thesis 4.2.3).

The warper offers one coordinate pair (Pl, Pr) per rectified pixel, in raster order (x fastest), each
exactly once: the four coordinates of the pixel from the calculation unit
(:mod:`eyestereo.tools.models.poly_unit`, registers X-L, Y-L, X-R, Y-R as ufix[int_bits + frac, frac]),
the out-of-range flag of each side (``oor_l = oor(X-L) | oor(Y-L)``, likewise right), and ``eol``/``eof``
of the image stream the pair's pixel belongs to (``eol`` on the last pixel of a line, ``eof`` with it on
the frame's last pixel). Timing is not part of the model: the order and values are the whole contract.

:data:`PAIR_FIELDS` / :func:`pair_word` declare the pair as one packed word (least significant field
first), the layout the benches record pairs in.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from eyestereo.tools.models.poly_unit import DEFAULT_FRAC, Calibration, coord_format, evaluate, resolve_frac
from eyestereo.tools.packed import PackedWord

__all__ = ["PAIR_FIELDS", "coordinate_warper", "decode_words", "pair_word", "pairs"]

#: Fields of a pair, least significant first.
PAIR_FIELDS = ("xl", "yl", "xr", "yr", "oor_l", "oor_r", "eol", "eof")


def pair_word(cal: Calibration, frac: int | None = DEFAULT_FRAC) -> PackedWord:
    """The pair as a packed word: X-L, Y-L, X-R, Y-R (ufix[n, frac]), then the four flags."""
    frac = resolve_frac(cal, frac)
    fx, fy = coord_format(frac, cal.source_width), coord_format(frac, cal.source_height)
    return PackedWord("coord_pair", [("xl", fx), ("yl", fy), ("xr", fx), ("yr", fy),
                                     ("oor_l", 1), ("oor_r", 1), ("eol", 1), ("eof", 1)])


def coordinate_warper(cal: Calibration, frac: int | None = DEFAULT_FRAC) -> dict[str, npt.NDArray[np.int64]]:
    """Every field of the pair of every rectified pixel, ``(height, width)`` int64 arrays."""
    ev = evaluate(cal, frac)
    h, w = cal.height, cal.width
    eol = np.zeros((h, w), dtype=np.int64)
    eol[:, -1] = 1
    eof = np.zeros((h, w), dtype=np.int64)
    eof[-1, -1] = 1
    return {"xl": ev["left_x"]["coord"], "yl": ev["left_y"]["coord"], "xr": ev["right_x"]["coord"],
            "yr": ev["right_y"]["coord"], "oor_l": ev["left_x"]["oor"] | ev["left_y"]["oor"],
            "oor_r": ev["right_x"]["oor"] | ev["right_y"]["oor"], "eol": eol, "eof": eof}


def pairs(cal: Calibration, frac: int | None = DEFAULT_FRAC, frames: int = 1) -> dict[str, npt.NDArray[np.int64]]:
    """The pairs in the order the warper offers them (``frames`` frames): flat arrays per field."""
    f = coordinate_warper(cal, frac)
    return {k: np.tile(v.ravel(), frames) for k, v in f.items()}


def decode_words(words: npt.NDArray[np.uint8], word: PackedWord) -> dict[str, npt.NDArray[np.int64]]:
    """Fields of packed words given as a ``(n, word.width)`` bit matrix (column 0 = bit 0).

    Works for words of any width (the pair word is wider than 63 bits for large images and ``frac``),
    unlike :meth:`PackedWord.unpack`; fields are unsigned here (the pair has no signed field).
    """
    bits = np.asarray(words, dtype=np.int64)
    if bits.ndim != 2 or bits.shape[1] != word.width:
        raise ValueError(f"want an (n, {word.width}) bit matrix, got shape {bits.shape}")
    out = {}
    for f in word.fields:
        if f.fmt.signed:
            raise ValueError(f"decode_words handles unsigned fields only ({f.name} is {f.fmt})")
        weights = np.left_shift(np.int64(1), np.arange(f.fmt.wl, dtype=np.int64))
        out[f.name] = bits[:, f.lsb:f.msb + 1] @ weights
    return out
