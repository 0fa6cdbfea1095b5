"""Bit-true model of :func:`eyestereo.hdl.rectify.poly_unit.poly_unit`, the merged calculation unit (thesis 4.2.1).

The unit evaluates the four rectification polynomials (``left_x``, ``left_y``, ``right_x``, ``right_y``)
in the levelized Horner form of the float-to-fixed conversion with its 26 quantizers; the arithmetic is
:func:`eyestereo.tools.rectify.ffc.fixed_stages_codes` -- the toolbox's own bit-true evaluator, not a copy.
This module adds what the hardware does after the output quantizer q24:

* the **range check** on the full-precision q24 code ``c`` (value ``v = c * 2**-fl24``): the coordinate
  is *out of range* when ``v < 0`` or ``v > S - 2``, S = the camera image's width for an x coordinate and
  its height for a y coordinate (the pixel at the coordinate and the one after it must exist for the
  bilinear interpolation); exactly, ``c < 0`` or ``c > floor((S - 2) * 2**fl24)``;
* the **cut** to the interpolation precision: ``floor(v * 2**frac)`` kept modulo ``2**n`` (two's
  complement wrap, i.e. its low ``n`` bits), ``n = int_bits(S) + frac`` with
  ``int_bits(S) = bits(S - 1)``: an unsigned number with ``frac`` fraction bits, ufix[n, frac]. In range,
  this is exactly ``floor(v * 2**frac)`` (integer part ``0 .. S - 2``); out of range it is what the low bits
  happen to be (defined, so the hardware is compared bit for bit everywhere, but meaningless).

``select`` codes (thesis Table 4.3): bit 2 = valid, bit 1 = right camera, bit 0 = y coordinate; the
polynomial index ``select & 3`` is 0 ``left_x``, 1 ``left_y``, 2 ``right_x``, 3 ``right_y``.

Coefficient register port (the unit's run-time option): address ``4 * (i - 1) + index`` for coefficient
``p_i`` (i = 1..10) of polynomial ``index``; data = the code's two's complement bits, in the low
``wl_i`` bits of a :func:`coef_data_bits`-bit word (:func:`register_writes`).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from eyestereo.tools.fixed import Fmt, ufix
from eyestereo.tools.rectify.ffc import POLY_NAMES, FFCError, fixed_stages_codes

__all__ = ["DEFAULT_FRAC", "LATENCY", "SELECT", "VALID", "Calibration", "coef_addr_bits", "coef_data_bits",
           "coord_bits", "coord_format", "cut", "evaluate", "int_bits", "poly_unit", "q24_codes", "range_limit",
           "register_writes", "resolve_frac"]

#: Pipeline depth of the hardware unit: input register, the six arithmetic stages of the levelized
#: listing (products, sums, products, sums, products, output sum) with the last products over two
#: stages (partial products, then their sum), and the range check / cut.
LATENCY = 9
#: Default fraction bits of the output coordinate: ``None`` = q24's own fraction length (clamped to
#: 0..MAX_FRAC), which the interpolation study (docs/rectifier.md) picks on every calibration: fewer bits
#: add error, more add only zeros. The synthetic rig (352x288) gets 5, the OpenCV calibration (640x480) 6.
DEFAULT_FRAC = None
#: Polynomial index (= select & 3) of each polynomial.
SELECT = {name: i for i, name in enumerate(POLY_NAMES)}
VALID = 0b100
#: Largest ``frac`` the blocks accept.
MAX_FRAC = 16


def resolve_frac(cal: Calibration, frac: int | None = DEFAULT_FRAC) -> int:
    """``frac``, or for ``None`` the default: q24's fraction length, clamped to 0..MAX_FRAC."""
    if frac is None:
        return min(max(cal.out_format.fl, 0), MAX_FRAC)
    if isinstance(frac, bool) or not isinstance(frac, (int, np.integer)) or not 0 <= int(frac) <= MAX_FRAC:
        raise ValueError(f"frac must be an integer 0..{MAX_FRAC} or None, got {frac!r}")
    return int(frac)


def int_bits(size: int) -> int:
    """Integer bits of a coordinate into an image dimension of ``size`` pixels: ``bits(size - 1)``."""
    return max(1, (int(size) - 1).bit_length())


def coord_format(frac: int, size: int) -> Fmt:
    """ufix[int_bits(size) + frac, frac]: a coordinate register (X-L ...) into a dimension of ``size``."""
    return ufix(int_bits(size) + frac, frac)


@dataclass(frozen=True)
class Calibration:
    """What the hardware is elaborated from: a checked ``quantizers.json``, in select order.

    ``width``/``height``: the rectified image (the x/y counters); ``source_width``/``source_height``:
    the camera images (the range checks); ``formats``: q1..q26; ``codes[index]``: p1..p10 of polynomial
    ``index`` (:data:`SELECT`).
    """

    width: int
    height: int
    source_width: int
    source_height: int
    formats: tuple[Fmt, ...]
    codes: tuple[tuple[int, ...], ...]
    origin: str = ""

    @classmethod
    def from_doc(cls, doc: dict[str, Any], *, source_width: int | None = None,
                 source_height: int | None = None) -> Calibration:
        """From a document of :func:`eyestereo.tools.rectify.ffc.read_quantizers_json` (or
        :func:`eyestereo.tools.rectify.calibrations.load`); it must hold all four polynomials."""
        fmts = tuple(doc["_formats"])
        missing = [n for n in POLY_NAMES if n not in doc["polynomials"]]
        if missing:
            raise FFCError(f"quantizers.json lacks polynomial(s) {missing}; the unit needs {list(POLY_NAMES)}")
        codes = tuple(tuple(int(c) for c in doc["polynomials"][n]["codes"]) for n in POLY_NAMES)
        sw = int(source_width if source_width is not None else doc.get("source_width", doc["width"]))
        sh = int(source_height if source_height is not None else doc.get("source_height", doc["height"]))
        return cls(int(doc["width"]), int(doc["height"]), sw, sh, fmts, codes, str(doc.get("origin", "")))

    @classmethod
    def load(cls, spec: str | os.PathLike[str] | dict[str, Any] | None = None, **kw: Any) -> Calibration:
        """From a calibration spec or path (:func:`eyestereo.tools.rectify.calibrations.load`)."""
        from eyestereo.tools.rectify.calibrations import load

        return cls.from_doc(load(spec), **kw)

    def with_codes(self, codes: Sequence[Sequence[int]]) -> Calibration:
        """The same formats with other coefficient codes (what a run-time load gives)."""
        codes = tuple(tuple(int(c) for c in row) for row in codes)
        if len(codes) != 4 or any(len(r) != 10 for r in codes):
            raise ValueError("need 4 x 10 coefficient codes")
        for row in codes:
            for i, (c, f) in enumerate(zip(row, self.formats), 1):
                if not f.contains(c):
                    raise ValueError(f"code {c} of p{i} does not fit q{i} {f}")
        return Calibration(self.width, self.height, self.source_width, self.source_height, self.formats,
                           codes, self.origin)

    @property
    def out_format(self) -> Fmt:
        """q24, the full-precision output."""
        return self.formats[23]


def coef_data_bits(formats: Sequence[Fmt]) -> int:
    """Width of the coefficient register port's data: the widest of q1..q10."""
    return max(f.wl for f in formats[:10])


def coef_addr_bits() -> int:
    """Width of the coefficient register port's address (40 coefficients: 6 bits)."""
    return 6


def register_writes(codes: Sequence[Sequence[int]], formats: Sequence[Fmt]) -> list[tuple[int, int]]:
    """(address, data) of the 40 register writes that load ``codes`` (4 x 10, select order).

    Raises ValueError when a code does not fit its format (a calibration whose coefficients need other
    formats needs a new elaboration)."""
    out = []
    for i in range(10):
        f = formats[i]
        for idx, row in enumerate(codes):
            c = int(row[i])
            if not f.contains(c):
                raise ValueError(f"{POLY_NAMES[idx]}: code {c} of p{i + 1} does not fit q{i + 1} {f}")
            out.append(((i << 2) | idx, c & ((1 << f.wl) - 1)))
    return out


def range_limit(fmt: Fmt, size: int) -> int:
    """Largest in-range q24 code for a dimension of ``size`` pixels: ``floor((size - 2) * 2**fl)``."""
    if size < 2:
        raise ValueError(f"an image dimension for interpolation needs >= 2 pixels, got {size}")
    lim = (size - 2) << fmt.fl if fmt.fl >= 0 else (size - 2) >> -fmt.fl
    return min(lim, fmt.hi)


def cut(codes: npt.ArrayLike, fmt: Fmt, frac: int, nbits: int) -> npt.NDArray[np.int64]:
    """``floor(code * 2**(frac - fl))`` modulo ``2**nbits`` (what the coordinate register holds)."""
    c = np.asarray(codes, dtype=np.int64)
    d = frac - fmt.fl
    v = c << d if d >= 0 else c >> -d
    return v & ((1 << nbits) - 1)


def q24_codes(cal: Calibration, index: int, width: int, height: int) -> npt.NDArray[np.int64]:
    """Full-precision output codes (q24) of polynomial ``index`` at x < width, y < height: (height, width)."""
    out = fixed_stages_codes(cal.codes[index], cal.formats, width, height)[24]
    return np.ascontiguousarray(np.broadcast_to(out, (height, width)), dtype=np.int64)


def _limits(cal: Calibration) -> tuple[int, int]:
    return range_limit(cal.out_format, cal.source_width), range_limit(cal.out_format, cal.source_height)


def evaluate(cal: Calibration, frac: int | None = DEFAULT_FRAC) -> dict[str, dict[str, npt.NDArray[np.int64]]]:
    """Every polynomial at every rectified pixel, as the coordinate warper's registers hold them.

    ``{name: {"q24": codes, "coord": cut codes, "oor": 0/1}}``, each ``(height, width)``; ``coord`` has
    ``coord_format(frac, S).wl`` bits, S = source width for x, source height for y.
    """
    frac = resolve_frac(cal, frac)
    lim_x, lim_y = _limits(cal)
    out = {}
    for index, name in enumerate(POLY_NAMES):
        q24 = q24_codes(cal, index, cal.width, cal.height)
        is_y = index & 1
        size = cal.source_height if is_y else cal.source_width
        lim = lim_y if is_y else lim_x
        oor = ((q24 < 0) | (q24 > lim)).astype(np.int64)
        out[name] = {"q24": q24, "coord": cut(q24, cal.out_format, frac, coord_format(frac, size).wl), "oor": oor}
    return out


def coord_bits(cal: Calibration, frac: int | None = DEFAULT_FRAC) -> int:
    """Width of the unit's ``coord`` output: enough for x and y coordinates."""
    return max(int_bits(cal.source_width), int_bits(cal.source_height)) + resolve_frac(cal, frac)


def poly_unit(cal: Calibration, x: npt.ArrayLike, y: npt.ArrayLike, select: npt.ArrayLike,
              frac: int | None = DEFAULT_FRAC) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]:
    """(coord, out_of_range) for a sequence of unit inputs (x, y counter values, select codes).

    The output for input ``k`` leaves the unit ``LATENCY`` enabled clocks later with ``select[k]``; the
    values of invalid inputs (select bit 2 clear) are returned too (what the hardware computes for them).
    ``coord`` has :func:`coord_bits` bits. x may be any value of ``bits(width - 1)`` bits, y of
    ``bits(height - 1)``.
    """
    x = np.asarray(x, dtype=np.int64)
    y = np.asarray(y, dtype=np.int64)
    sel = np.asarray(select, dtype=np.int64)
    if x.shape != y.shape or x.shape != sel.shape:
        raise ValueError("x, y and select need one shape")
    gw, gh = 1 << int_bits(cal.width), 1 << int_bits(cal.height)
    if x.size and (x.min() < 0 or x.max() >= gw or y.min() < 0 or y.max() >= gh):
        raise ValueError(f"x must fit {int_bits(cal.width)} bits and y {int_bits(cal.height)} bits")
    frac = resolve_frac(cal, frac)
    nb = coord_bits(cal, frac)
    lim_x, lim_y = _limits(cal)
    coord = np.zeros(x.shape, dtype=np.int64)
    oor = np.zeros(x.shape, dtype=np.int64)
    for index in range(4):
        m = (sel & 3) == index
        if not m.any():
            continue
        q24 = q24_codes(cal, index, gw, gh)[y[m], x[m]]
        lim = lim_y if index & 1 else lim_x
        coord[m] = cut(q24, cal.out_format, frac, nb)
        oor[m] = (q24 < 0) | (q24 > lim)
    return coord, oor
