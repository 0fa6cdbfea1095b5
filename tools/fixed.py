"""Fixed-point formats ``ufix[wl,fl]`` / ``sfix[wl,fl]`` and bit-true helpers.

The notation is MATLAB's, as used in chapter 2 of the thesis "FPGA-based Stereo
Vision System for the EyeBot M6": a format has a word length ``wl`` (bits,
>= 1) and a fraction length ``fl`` (any integer, may be negative or exceed
``wl``); an integer code ``c`` stands for the real value ``c * 2**-fl``.
Signed formats use two's complement.

Two calling conventions are supported everywhere:

* scalars (python ``int``/``float``/``Fraction`` and numpy scalars) are handled
  exactly with python integers, for any word length, and give python ``int``;
* numpy arrays are handled with int64 arithmetic and give int64 arrays; the
  destination format must then have ``wl <= 62`` (:data:`MAX_ARRAY_WL`).

This module is deliberately free of any HDL dependency so that the bit-true
software models can use it on their own; see ``eyestereo.hdl.common.fixed`` for the
MyHDL signal helpers.
"""

from __future__ import annotations

import math
import numbers
import re
from dataclasses import dataclass
from fractions import Fraction
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

__all__ = [
    "MAX_ARRAY_WL",
    "Fmt",
    "Overflow",
    "add_format",
    "fit_format",
    "intbv_bounds",
    "mul_format",
    "neg_format",
    "quantize",
    "requantize",
    "saturate",
    "sfix",
    "shift_between",
    "sub_format",
    "to_fraction",
    "to_real",
    "ufix",
    "wrap",
]

Overflow = Literal["wrap", "saturate"]

#: Largest word length accepted for numpy-array results.  Every code of such a
#: format, and 2**wl itself, fits an int64 with room to spare, so the
#: two's complement fix-ups below can never overflow.
MAX_ARRAY_WL = 62

# Shifting an int64 by 63 places already moves every bit out (or leaves only
# the sign), so larger shift amounts can be clamped to this without changing
# any result; it also keeps numpy shifts within their defined range.
_MAX_SHIFT = 63

_FMT_RE = re.compile(r"\s*([su])fix\s*\[\s*([+-]?\d+)\s*,\s*([+-]?\d+)\s*\]\s*")


@dataclass(frozen=True)
class Fmt:
    """A fixed-point format: sign mode, word length ``wl`` and fraction length ``fl``."""

    signed: bool
    wl: int
    fl: int

    def __post_init__(self) -> None:
        if not isinstance(self.signed, (bool, np.bool_)):
            raise ValueError(f"signed must be a bool, got {self.signed!r}")
        for name in ("wl", "fl"):
            value = getattr(self, name)
            # bool is an int subclass, but Fmt(True, True, 0) is surely a mistake
            if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
                raise ValueError(f"{name} must be an integer, got {value!r}")
        # Normalise numpy scalars so equality, hashing and str() match plain ints.
        object.__setattr__(self, "signed", bool(self.signed))
        object.__setattr__(self, "wl", int(self.wl))
        object.__setattr__(self, "fl", int(self.fl))
        if self.wl < 1:
            raise ValueError(f"word length must be at least 1 bit, got wl={self.wl}")

    @property
    def lo(self) -> int:
        """Smallest integer code (inclusive)."""
        return -(1 << (self.wl - 1)) if self.signed else 0

    @property
    def hi(self) -> int:
        """Largest integer code (inclusive)."""
        return (1 << (self.wl - 1)) - 1 if self.signed else (1 << self.wl) - 1

    @property
    def resolution(self) -> Fraction:
        """Real value of one LSB, ``2**-fl``."""
        return Fraction(1, 1 << self.fl) if self.fl >= 0 else Fraction(1 << -self.fl)

    @property
    def min(self) -> Fraction:
        """Smallest representable real value."""
        return self.lo * self.resolution

    @property
    def max(self) -> Fraction:
        """Largest representable real value."""
        return self.hi * self.resolution

    @property
    def iwl(self) -> int:
        """Integer word length ``wl - fl`` (including the sign bit when signed)."""
        return self.wl - self.fl

    def __str__(self) -> str:
        return f"{'s' if self.signed else 'u'}fix[{self.wl},{self.fl}]"

    @classmethod
    def parse(cls, text: str) -> Fmt:
        """Parse ``"sfix[wl,fl]"`` / ``"ufix[wl,fl]"`` (whitespace allowed)."""
        if not isinstance(text, str):
            raise ValueError(f"format text must be a str, got {text!r}")
        match = _FMT_RE.fullmatch(text)
        if match is None:
            raise ValueError(f"not a fixed-point format (expected e.g. 'sfix[9,-3]'): {text!r}")
        kind, wl, fl = match.groups()
        return cls(kind == "s", int(wl), int(fl))

    def contains(self, codes: Any) -> bool | npt.NDArray[np.bool_]:
        """Whether integer code(s) lie inside this format's code range."""
        if _is_int_scalar(codes):
            return self.lo <= int(codes) <= self.hi
        arr = _int_array(codes)
        # Clamp the bounds into int64 so wide formats compare without overflow;
        # clamping cannot change the outcome because no int64 lies beyond them.
        info = np.iinfo(np.int64)
        lo, hi = max(self.lo, int(info.min)), min(self.hi, int(info.max))
        return (arr >= lo) & (arr <= hi)


def sfix(wl: int, fl: int = 0) -> Fmt:
    """Signed format ``sfix[wl,fl]``."""
    return Fmt(True, wl, fl)


def ufix(wl: int, fl: int = 0) -> Fmt:
    """Unsigned format ``ufix[wl,fl]``."""
    return Fmt(False, wl, fl)


# ---------------------------------------------------------------------------
# input classification


def _is_int_scalar(x: Any) -> bool:
    return isinstance(x, (int, np.integer))


def _is_real_scalar(x: Any) -> bool:
    # covers int, float, Fraction, bool and numpy scalars (numpy registers them)
    return isinstance(x, numbers.Real)


def _check_overflow(overflow: str) -> None:
    if overflow not in ("wrap", "saturate"):
        raise ValueError(f"overflow must be 'wrap' or 'saturate', got {overflow!r}")


def _check_array_fmt(fmt: Fmt) -> None:
    if fmt.wl > MAX_ARRAY_WL:
        raise ValueError(
            f"{fmt} is too wide for int64 array results (wl <= {MAX_ARRAY_WL}); "
            "use python ints for wider formats"
        )


def _int_array(codes: Any) -> npt.NDArray[np.int64]:
    arr = np.asarray(codes)
    if arr.dtype.kind not in "iu":
        raise TypeError(f"integer codes expected, got an array of dtype {arr.dtype}")
    if arr.dtype == np.uint64 and arr.size and int(arr.max()) > np.iinfo(np.int64).max:
        raise ValueError("uint64 codes above 2**63-1 do not fit int64")
    return arr.astype(np.int64, copy=False)


def _exact(x: Any) -> Fraction:
    """Exact rational value of a real scalar (floats are exact binary fractions)."""
    if isinstance(x, Fraction):
        return x
    if _is_int_scalar(x):
        return Fraction(int(x))
    if isinstance(x, (float, np.floating)):
        if not math.isfinite(float(x)):
            raise ValueError(f"cannot quantize a non-finite value: {x!r}")
        # as_integer_ratio is exact for every numpy float width, longdouble included
        return Fraction(*x.as_integer_ratio())
    if isinstance(x, numbers.Rational):
        return Fraction(int(x.numerator), int(x.denominator))
    raise TypeError(f"unsupported value type {type(x).__name__}")


def _floor_code(v: Fraction, fl: int) -> int:
    """``floor(v * 2**fl)`` with python ints (``//`` floors toward minus infinity)."""
    if fl >= 0:
        return (v.numerator << fl) // v.denominator
    return v.numerator // (v.denominator << -fl)


# ---------------------------------------------------------------------------
# overflow handling


def _reduce_int(code: int, fmt: Fmt, overflow: str) -> int:
    if overflow == "wrap":
        return (code - fmt.lo) % (1 << fmt.wl) + fmt.lo
    return min(max(code, fmt.lo), fmt.hi)


def _floor_shift_reduce(
    m: npt.NDArray[np.int64], s: int | npt.NDArray[np.int64], fmt: Fmt, overflow: str
) -> npt.NDArray[np.int64]:
    """Exactly compute ``floor(m * 2**s)`` reduced into ``fmt``, using int64 only.

    ``s`` may be a python int or an int64 array broadcastable against ``m``.
    """
    if isinstance(s, int):
        s = max(-_MAX_SHIFT, min(_MAX_SHIFT, s))
    s = np.clip(np.asarray(s, dtype=np.int64), -_MAX_SHIFT, _MAX_SHIFT)
    left = np.maximum(s, 0)
    left_u = left.astype(np.uint64)
    # numpy's >> on int64 is an arithmetic shift, i.e. floor division by 2**k.
    m = np.asarray(m, dtype=np.int64) >> np.maximum(-s, 0)
    if overflow == "wrap":
        # Only the low wl bits survive a wrap, so shifting modulo 2**64 in
        # uint64 (where overflow is well defined) is exact.
        bits = (m.astype(np.uint64) << left_u) & np.uint64((1 << fmt.wl) - 1)
        res = bits.astype(np.int64)
        if fmt.signed:
            res = np.where(res > fmt.hi, res - (1 << fmt.wl), res)
    else:
        # Compare before shifting: m * 2**k > hi  <=>  m > floor(hi / 2**k), and
        # m * 2**k < lo  <=>  m < ceil(lo / 2**k); values in between shift safely.
        over = m > (np.int64(fmt.hi) >> left)
        under = m < -(np.int64(-fmt.lo) >> left)
        safe = np.where(over | under, 0, m)
        res = (safe.astype(np.uint64) << left_u).astype(np.int64)
        res = np.where(over, fmt.hi, np.where(under, fmt.lo, res))
    return np.asarray(res, dtype=np.int64)


def wrap(codes: Any, fmt: Fmt) -> Any:
    """Reduce integer codes modulo ``2**wl`` into ``fmt``'s range (two's complement wrap)."""
    if _is_int_scalar(codes):
        return _reduce_int(int(codes), fmt, "wrap")
    _check_array_fmt(fmt)
    return _floor_shift_reduce(_int_array(codes), 0, fmt, "wrap")


def saturate(codes: Any, fmt: Fmt) -> Any:
    """Clip integer codes into ``fmt``'s range."""
    if _is_int_scalar(codes):
        return _reduce_int(int(codes), fmt, "saturate")
    _check_array_fmt(fmt)
    return _floor_shift_reduce(_int_array(codes), 0, fmt, "saturate")


# ---------------------------------------------------------------------------
# conversions


def quantize(x: Any, fmt: Fmt, overflow: Overflow = "wrap") -> Any:
    """Real value(s) to codes of ``fmt``: ``floor(x * 2**fl)``, then wrap or saturate.

    Scalars are exact for any word length and give a python int.  Arrays
    (integer or float16/32/64) give int64 and need ``fmt.wl <= 62``; they are
    exact too, including subnormal and huge floats.
    """
    _check_overflow(overflow)
    if _is_real_scalar(x):
        return _reduce_int(_floor_code(_exact(x), fmt.fl), fmt, overflow)

    _check_array_fmt(fmt)
    arr = np.asarray(x)
    if arr.dtype.kind in "iu":
        return _floor_shift_reduce(_int_array(arr), fmt.fl, fmt, overflow)
    if arr.dtype.kind != "f" or arr.dtype.itemsize > 8:
        raise TypeError(f"cannot quantize an array of dtype {arr.dtype}")
    arr = arr.astype(np.float64)
    if not np.all(np.isfinite(arr)):
        raise ValueError("cannot quantize non-finite values")
    # Split x = m * 2**e exactly with an integer |m| < 2**53, so that
    # x * 2**fl = m * 2**(e + fl) becomes an integer shift.  Plain
    # floor(ldexp(x, fl)) would round once the result is subnormal and
    # overflow to inf for large values; this stays exact for every float.
    mant, exp = np.frexp(arr)
    m = np.ldexp(mant, 53).astype(np.int64)
    # Float exponents lie within +-1100, so fl beyond +-4096 yields shifts
    # past the clamp either way; clamping here keeps the sum inside int64.
    fl = max(-4096, min(4096, fmt.fl))
    return _floor_shift_reduce(m, exp.astype(np.int64) + (fl - 53), fmt, overflow)


def requantize(codes: Any, src: Fmt, dst: Fmt, overflow: Overflow = "wrap") -> Any:
    """Convert codes of ``src`` to codes of ``dst`` (floor rounding), then wrap or saturate.

    Codes are treated as plain integers, so values outside ``src``'s range are
    converted as they are rather than being wrapped first.
    """
    _check_overflow(overflow)
    shift = dst.fl - src.fl
    if _is_int_scalar(codes):
        c = int(codes)
        # python's >> on negative ints is also floor division by 2**k
        return _reduce_int(c << shift if shift >= 0 else c >> -shift, dst, overflow)
    _check_array_fmt(dst)
    return _floor_shift_reduce(_int_array(codes), shift, dst, overflow)


def to_real(codes: Any, fmt: Fmt) -> np.float64 | npt.NDArray[np.float64]:
    """Codes to float64 values ``code * 2**-fl`` (nearest float for codes beyond 2**53)."""
    # ldexp saturates to 0/inf well inside this range, so clamping is harmless
    # and keeps the exponent a valid C int for absurd fraction lengths.
    exponent = max(-2200, min(2200, -fmt.fl))
    return np.ldexp(np.asarray(codes, dtype=np.float64), exponent)


def to_fraction(code: int, fmt: Fmt) -> Fraction:
    """Exact real value of a single integer code."""
    if not _is_int_scalar(code):
        raise TypeError(f"integer code expected, got {type(code).__name__}")
    return int(code) * fmt.resolution


def shift_between(src_fl: int, dst_fl: int) -> int:
    """Right-shift amount converting codes from ``src_fl`` to ``dst_fl`` (negative = left)."""
    return int(src_fl) - int(dst_fl)


def intbv_bounds(fmt: Fmt) -> tuple[int, int]:
    """``(min, max)`` for MyHDL's ``intbv(min=, max=)`` (max exclusive), giving exactly ``wl`` bits."""
    return fmt.lo, fmt.hi + 1


# ---------------------------------------------------------------------------
# word-length growth


def _signed_bits(v: int) -> int:
    """Bits needed to hold ``v`` in two's complement, not counting the sign bit."""
    return v.bit_length() if v >= 0 else (~v).bit_length()


def _fit_codes(lo: int, hi: int, signed: bool, fl: int) -> Fmt:
    """Narrowest format of the given signedness and ``fl`` holding codes ``lo..hi``."""
    if signed:
        return Fmt(True, 1 + max(_signed_bits(lo), _signed_bits(hi)), fl)
    if lo < 0:
        raise ValueError(f"unsigned format cannot hold negative code {lo}")
    return Fmt(False, max(1, hi.bit_length()), fl)


def fit_format(lo: Any, hi: Any, fl: int = 0) -> Fmt:
    """Smallest format with fraction length ``fl`` covering the real interval ``[lo, hi]``.

    The format is unsigned when ``lo >= 0`` and signed otherwise; it is the
    narrowest one whose code range holds ``floor(lo * 2**fl) .. floor(hi * 2**fl)``,
    i.e. every value of the interval quantizes (floor rounding) without overflow.
    """
    if isinstance(fl, (bool, np.bool_)) or not isinstance(fl, numbers.Integral):
        raise ValueError(f"fl must be an integer, got {fl!r}")
    flo, fhi = _exact(lo), _exact(hi)
    if flo > fhi:
        raise ValueError(f"empty interval: lo={lo!r} > hi={hi!r}")
    fl = int(fl)
    return _fit_codes(_floor_code(flo, fl), _floor_code(fhi, fl), flo < 0, fl)


def _aligned(f: Fmt, fl: int) -> tuple[int, int]:
    """Code range of ``f`` expressed at the finer fraction length ``fl >= f.fl``."""
    return f.lo << (fl - f.fl), f.hi << (fl - f.fl)


def add_format(a: Fmt, b: Fmt) -> Fmt:
    """Full-precision format of ``a + b``: ``fl = max(fl_a, fl_b)``, narrowest sufficient ``wl``.

    Signed if either operand is; for equal formats this is the textbook
    ``ufix[n,f] + ufix[n,f] -> ufix[n+1,f]`` (likewise for sfix).
    """
    fl = max(a.fl, b.fl)
    (alo, ahi), (blo, bhi) = _aligned(a, fl), _aligned(b, fl)
    return _fit_codes(alo + blo, ahi + bhi, a.signed or b.signed, fl)


def sub_format(a: Fmt, b: Fmt) -> Fmt:
    """Full-precision format of ``a - b``; always signed, narrowest sufficient ``wl``."""
    fl = max(a.fl, b.fl)
    (alo, ahi), (blo, bhi) = _aligned(a, fl), _aligned(b, fl)
    return _fit_codes(alo - bhi, ahi - blo, True, fl)


def neg_format(a: Fmt) -> Fmt:
    """Format of ``-a``; always signed (``sfix[n]`` and ``ufix[n]`` both need ``n+1`` bits, n >= 2)."""
    return _fit_codes(-a.hi, -a.lo, True, a.fl)


def mul_format(a: Fmt, b: Fmt, no_min_product: bool = False) -> Fmt:
    """Full-precision format of ``a * b``: ``fl = fl_a + fl_b``, narrowest sufficient ``wl``.

    Signed if either operand is.  ``sfix[m]*sfix[n]`` needs ``m+n`` bits, not the
    ``m+n-1`` of the thesis's Table 2.2: the single product
    ``(-2**(m-1)) * (-2**(n-1)) = 2**(m+n-2)`` does not fit ``m+n-1`` bits.
    Pass ``no_min_product=True`` when that pair of codes can never meet (e.g.
    one operand never takes its most negative code) to get the ``m+n-1``
    width; the flag only matters when both operands are signed.
    ``ufix[m]*ufix[n]`` gives ``m+n`` bits except with a 1-bit operand, where
    the product is just the other operand and needs one bit less.
    """
    fl = a.fl + b.fl
    if no_min_product and a.signed and b.signed:
        # All pairs except (a.lo, b.lo): the union of the two rectangles
        # [a.lo+1, a.hi] x [b.lo, b.hi] and [a.lo, a.hi] x [b.lo+1, b.hi].
        # A product is bilinear, so its extremes sit at rectangle corners.
        products = [x * y for x in (a.lo + 1, a.hi) for y in (b.lo, b.hi)]
        products += [x * y for x in (a.lo, a.hi) for y in (b.lo + 1, b.hi)]
    else:
        products = [x * y for x in (a.lo, a.hi) for y in (b.lo, b.hi)]
    return _fit_codes(min(products), max(products), a.signed or b.signed, fl)
