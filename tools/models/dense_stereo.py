"""Bit-true model of :func:`eyestereo.hdl.dense.dense_stereo.dense_stereo`: census, SGM and the optional median.

The chain: a stereo image stream (8-bit left and right, rectified) in; the census words of both cameras
(:mod:`~eyestereo.tools.models.census`); semi-global matching with winner take all, uniqueness, left-right
check and sub-pixel refinement (:mod:`~eyestereo.tools.models.sgm`); optionally the 3 x 3 median
(:mod:`~eyestereo.tools.models.median3`); a disparity stream out: uint16 per pixel, the disparity in
1/16 px, :data:`INVALID` (0xFFFF) where there is none. Everything integer and in raster order; the bit
widths and what each stage keeps in line buffers are in the stages' docstrings.

Parameters (the elaboration ones: ``window``, ``disparities``, ``paths``, the widths; the run-time ones:
``p1``, ``p2``, ``uniqueness``, ``lr_check``, ``subpixel``, ``median``). :data:`DEFAULTS` were tuned on
Tsukuba, Venus and Motorcycle at 352 x 288 with D = 64 (docs/dense.md). The number of disparities the
hardware computes per clock (PU) is not a parameter: the result does not depend on it.
"""

from __future__ import annotations

import numpy as np

from eyestereo.tools.constants import DENSE_DEFAULTS
from eyestereo.tools.models.census import census_stereo
from eyestereo.tools.models.median3 import median3
from eyestereo.tools.models.sgm import INVALID, sgm

__all__ = ["DEFAULTS", "WIDTHS", "INVALID", "dense_stereo", "to_float"]

#: The chain's defaults (tuned, docs/dense.md; the DENSE register's reset values); the float reference takes the
#: same names.
DEFAULTS = dict(DENSE_DEFAULTS)
#: The widths chosen by measurement (docs/dense.md, the table of the cuts): full Hamming costs, path costs of
#: 7 bits (exact up to P2 = 103 with the 5 x 5 census; the defaults need 6), one LSB dropped from the sums
#: of the paths, 4 fractional bits.
WIDTHS = dict(cost_bits=None, path_bits=7, sum_shift=1, frac_bits=4)


def dense_stereo(left, right, *, window: int = DEFAULTS["window"], disparities: int = DEFAULTS["disparities"],
                 paths: int = DEFAULTS["paths"], p1: int = DEFAULTS["p1"], p2: int = DEFAULTS["p2"],
                 uniqueness: int = DEFAULTS["uniqueness"], lr_check: bool = DEFAULTS["lr_check"],
                 subpixel: bool = DEFAULTS["subpixel"], median: bool = DEFAULTS["median"],
                 cost_bits: int | None = WIDTHS["cost_bits"], path_bits: int = WIDTHS["path_bits"],
                 sum_shift: int = WIDTHS["sum_shift"], frac_bits: int = WIDTHS["frac_bits"],
                 stats: dict | None = None) -> np.ndarray:
    """Disparity codes (uint16, 1/16 px, :data:`INVALID`) of the left image of a rectified grey pair."""
    cl, cr = census_stereo(left, right, window=window)
    if cl.shape[1] <= disparities:
        raise ValueError(f"image width {cl.shape[1]} must exceed the {disparities} disparities")
    codes = sgm(cl, cr, disparities=disparities, paths=paths, p1=p1, p2=p2, uniqueness=uniqueness,
                lr_check=lr_check, subpixel=subpixel, window=window, cost_bits=cost_bits, path_bits=path_bits,
                sum_shift=sum_shift, frac_bits=frac_bits, stats=stats)
    return median3(codes) if median else codes


def to_float(codes) -> np.ndarray:
    """Float disparities (px) of a code map, NaN where :data:`INVALID`."""
    c = np.asarray(codes)
    return np.where(c == INVALID, np.nan, c / 16.0)
