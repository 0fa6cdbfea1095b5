"""Automatic float-to-fixed conversion (FFC) of the rectification polynomials (Rectification Toolbox, part B).

The coordinate warper evaluates four degree-3 polynomials (``left_x``, ``left_y``, ``right_x``,
``right_y``; thesis eq. 4.1) for every rectified pixel, in the Horner form of thesis 4.2.1::

    p1 + y(p3 + p6 x + y(p5 + p8 y + p10 x)) + x(p2 + x(p4 + p7 x + p9 y))

levelized into single operations with one quantizer (floor rounding, two's complement wrap) after
each, numbered as in the thesis's levelized listing (section 2.5) and Fig. 4.4::

    q1..q10  coefficients p1..p10          q25, q26  inputs X, Y
    stage 1  q11 = p8*Y   q12 = p10*X   q13 = p7*X   q14 = p9*Y
    stage 2  q20 = p5 + q11 + q12       q21 = p4 + q13 + q14
    stage 3  q15 = q20*Y  q16 = p6*X    q17 = q21*X
    stage 4  q22 = q15 + p3 + q16       q23 = q17 + p2
    stage 5  q18 = q22*Y  q19 = q23*X
    output   q24 = p1 + q18 + q19

Each quantizer quantizes the *exact* result of its operation on its (already quantized) operands, which
is what a hardware multiplier/adder followed by a truncating, wrapping resize computes.

The conversion follows thesis 2.5:

1. **ranges** of every node over all ``width * height`` pixels in float64 (:func:`value_ranges`);
2. **worst-case formats** (:func:`worst_case_format`): ``ufix[1, fl]`` / ``sfix[2, fl]`` with
   ``fl = ceil(-log2(max|v|))``, computed exactly with ``frexp`` so exact powers of two are right;
   these never overflow on the float ranges; nodes that are identically zero get ``ufix[1,0]`` and
   take no further part;
3. **coarse** search (:func:`coarse_search`): every format ``[wl+p, fl+p]`` with one common ``p``,
   the smallest ``p`` in ``[L, H]`` meeting the bound found by bisection;
4. **greedy** fine tuning (:func:`greedy_tune`): repeatedly try ``[wl-1, fl-1]`` on every quantizer
   on its own, keep the one with the smallest error, stop when even that one breaks the bound;
5. **merge** (:func:`merge_quantizers`) of the four polynomials' formats into one list for the
   merged, pipelined calculation unit (thesis 4.2.1, Table A.2 "merged"), then verified.

The inputs q25/q26 are *not* optimised: X and Y are integer pixel counters, kept exact as
``ufix[bits(W-1), 0]`` and ``ufix[bits(H-1), 0]`` (the thesis's tool sometimes dropped their LSB,
e.g. ``ufix[8,-1]``; an exact counter costs at most one bit and removes an error source that no
other quantizer can compensate).

The error bound applies to **each polynomial separately** (as the thesis's ``calc_best_quantizers``
ran per coordinate): with the default measure ``"mse"`` it is the mean over all pixels of
``(fixed - float)**2`` in px**2 for that one coordinate; the side's mean square *distance*
``mean(dx**2 + dy**2)`` is then at most twice the bound and is reported as well.  ``"max"`` bounds
``max |fixed - float|`` in px.  Any callable ``diff -> float`` works as a measure.

Everything is bit-true: :func:`fixed_eval` computes integer codes with int64/uint64 numpy arithmetic,
exactly (modular arithmetic where only the low bits survive the wrap), and raises :class:`FFCError`
where a format combination would need more than 64-bit intermediates.
"""

from __future__ import annotations

import json
import math
import numbers
import os
import time
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from eyestereo.tools.io import atomic_write_text
from eyestereo.tools.fixed import MAX_ARRAY_WL, Fmt, quantize, to_real

__all__ = [
    "DEGREE",
    "MEASURES",
    "MULT_INPUT_BITS",
    "N_QUANTIZERS",
    "POLY_NAMES",
    "PRODUCTS",
    "QUANTIZER_EXPR",
    "TERMS",
    "ErrorMeasure",
    "FFCError",
    "FFCResult",
    "PolyFFC",
    "PolyFile",
    "WideInput",
    "coarse_search",
    "dumps_json",
    "count_overflows",
    "covers",
    "fixed_eval",
    "fixed_stages",
    "fixed_stages_codes",
    "float_eval",
    "float_stages",
    "ffc_polynomial",
    "get_measure",
    "greedy_tune",
    "initial_formats",
    "merge_quantizers",
    "quantizers_dict",
    "read_poly_json",
    "read_quantizers_json",
    "run_ffc",
    "side_errors",
    "value_ranges",
    "wide_multiplier_inputs",
    "worst_case_format",
    "write_quantizers_json",
]

DEGREE = 3
TERMS = ("1", "x", "y", "x^2", "y^2", "xy", "x^3", "y^3", "x^2y", "xy^2")
POLY_NAMES = ("left_x", "left_y", "right_x", "right_y")
N_QUANTIZERS = 26
QX, QY = 25, 26  # the input quantizers

#: The levelized operations: quantizer -> (kind, operand quantizers), in evaluation order.
_OPS: dict[int, tuple[str, tuple[int, ...]]] = {
    11: ("mul", (8, QY)),
    12: ("mul", (10, QX)),
    13: ("mul", (7, QX)),
    14: ("mul", (9, QY)),
    20: ("add", (5, 11, 12)),
    21: ("add", (4, 13, 14)),
    15: ("mul", (20, QY)),
    16: ("mul", (6, QX)),
    17: ("mul", (21, QX)),
    22: ("add", (15, 3, 16)),
    23: ("add", (17, 2)),
    18: ("mul", (22, QY)),
    19: ("mul", (23, QX)),
    24: ("add", (1, 18, 19)),
}
_ORDER = tuple(_OPS)  # dict order is the levelized order above

#: Human-readable definition of every quantizer (q1..q26).
QUANTIZER_EXPR: dict[int, str] = {i: f"p{i}" for i in range(1, 11)}
QUANTIZER_EXPR.update({QX: "X", QY: "Y"})
for _q, (_kind, _ops) in _OPS.items():
    _names = [QUANTIZER_EXPR[o] if o <= 10 or o >= QX else f"q{o}" for o in _ops]
    QUANTIZER_EXPR[_q] = (" * " if _kind == "mul" else " + ").join(_names)

#: The nine products of the calculation unit: product quantizer -> (operand, operand).
PRODUCTS = {q: ops for q, (kind, ops) in _OPS.items() if kind == "mul"}

#: Input width of the Spartan-3E hardware multiplier MULT18X18 (signed two's complement).
MULT_INPUT_BITS = 18


def _downstream(q: int) -> tuple[int, ...]:
    """Stages (in evaluation order) whose value depends on quantizer ``q``."""
    dirty = {q}
    out = []
    for s in _ORDER:
        if any(o in dirty for o in _OPS[s][1]):
            dirty.add(s)
            out.append(s)
    return tuple(out)


_DOWNSTREAM = {q: _downstream(q) for q in range(1, N_QUANTIZERS + 1)}


class FFCError(ValueError):
    """The conversion cannot be done (bound unreachable, formats too wide, bad input)."""


# ---------------------------------------------------------------------------
# input: poly.json


@dataclass(frozen=True)
class PolyFile:
    """Contents of a ``poly.json`` (part A's contract) as far as the FFC needs them."""

    width: int
    height: int
    polynomials: dict[str, list[float]]


#: Largest image side the conversion accepts (the maps' limit), and the largest |fl| of a quantizer.
MAX_SIDE = 16384
MAX_PIXELS = 1 << 24
MAX_FRACTION_BITS = 256


def _check_pixels(width: int, height: int) -> None:
    if width * height > MAX_PIXELS:
        raise FFCError(f"{width}x{height} has {width * height} pixels; at most {MAX_PIXELS} (e.g. 4096x4096)")


def _check_size(name: str, v: Any) -> int:
    if isinstance(v, bool) or not isinstance(v, numbers.Integral) or int(v) < 1:
        raise FFCError(f"{name} must be a positive integer, got {v!r}")
    if int(v) > MAX_SIDE:
        raise FFCError(f"{name} {v} is implausible (at most {MAX_SIDE} pixels)")
    return int(v)


def _check_coeffs(name: str, coeffs: Any) -> list[float]:
    if not isinstance(coeffs, (list, tuple)):
        raise FFCError(f"polynomial {name!r} must be a list of {len(TERMS)} numbers")
    if len(coeffs) != len(TERMS):
        raise FFCError(f"polynomial {name!r} has {len(coeffs)} coefficients, a degree-3 polynomial has {len(TERMS)}")
    out = []
    for i, c in enumerate(coeffs, 1):
        if isinstance(c, bool) or not isinstance(c, numbers.Real):
            raise FFCError(f"polynomial {name!r}: p{i} is not a number: {c!r}")
        if not math.isfinite(float(c)):
            raise FFCError(f"polynomial {name!r}: p{i} is not finite: {c!r}")
        out.append(float(c))
    return out


def read_poly_json(path: str | os.PathLike[str]) -> PolyFile:
    """Read and check a ``poly.json``; :class:`FFCError` (a ``ValueError``) with one line if it is bad."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise FFCError(f"file {path} does not exist") from None
    except OSError as exc:
        raise FFCError(f"{path}: cannot read: {exc.strerror or exc}") from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise FFCError(f"{path}: not valid JSON (line {exc.lineno}, column {exc.colno}: {exc.msg})") from None
    if not isinstance(data, dict):
        raise FFCError(f"{path}: expected a JSON object at the top level")
    for key in ("width", "height", "degree", "polynomials"):
        if key not in data:
            raise FFCError(f"{path}: missing key {key!r}")
    try:
        width = _check_size("width", data["width"])
        height = _check_size("height", data["height"])
        _check_pixels(width, height)
    except FFCError as exc:
        raise FFCError(f"{path}: {exc}") from None
    if data["degree"] != DEGREE or isinstance(data["degree"], bool):
        raise FFCError(f"{path}: the FFC handles degree-3 polynomials only, got degree {data['degree']!r}")
    if "terms" in data and list(data["terms"]) != list(TERMS):
        raise FFCError(f"{path}: terms must be {list(TERMS)}, got {data['terms']!r}")
    polys = data["polynomials"]
    if not isinstance(polys, dict):
        raise FFCError(f"{path}: 'polynomials' must be an object with keys {', '.join(POLY_NAMES)}")
    out = {}
    for name in POLY_NAMES:
        if name not in polys:
            raise FFCError(f"{path}: missing polynomial {name!r}")
        try:
            out[name] = _check_coeffs(name, polys[name])
        except FFCError as exc:
            raise FFCError(f"{path}: {exc}") from None
    return PolyFile(width, height, out)


# ---------------------------------------------------------------------------
# float model and ranges


def _grid(width: int, height: int) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]:
    """X as a (1, W) row and Y as an (H, 1) column: every stage broadcasts to (H, W)."""
    width, height = _check_size("width", width), _check_size("height", height)
    return (np.arange(width, dtype=np.int64).reshape(1, width),
            np.arange(height, dtype=np.int64).reshape(height, 1))


def _coeff_list(p: Sequence[float]) -> list[float]:
    return _check_coeffs("p", list(p))


def float_stages(p: Sequence[float], width: int, height: int) -> dict[int, Any]:
    """Float64 value of every node q1..q26 (scalars, (1,W) rows, (H,1) columns or (H,W) grids)."""
    p = _coeff_list(p)
    xs, ys = _grid(width, height)
    v: dict[int, Any] = {i: p[i - 1] for i in range(1, 11)}
    v[QX], v[QY] = xs.astype(np.float64), ys.astype(np.float64)
    for q, (kind, ops) in _OPS.items():
        if kind == "mul":
            v[q] = v[ops[0]] * v[ops[1]]
        else:
            v[q] = sum((v[o] for o in ops[1:]), v[ops[0]])
    return v


def float_eval(p: Sequence[float], width: int, height: int) -> npt.NDArray[np.float64]:
    """The polynomial in float64 at every pixel, shape ``(height, width)`` (row y, column x)."""
    out = float_stages(p, width, height)[24]
    return np.ascontiguousarray(np.broadcast_to(out, (height, width)), dtype=np.float64)


def value_ranges(p: Sequence[float], width: int, height: int) -> list[tuple[float, float]]:
    """``(min, max)`` of every node q1..q26 over all pixels (float model; index 0 is q1)."""
    v = float_stages(p, width, height)
    return [(float(np.min(v[q])), float(np.max(v[q]))) for q in range(1, N_QUANTIZERS + 1)]


def worst_case_format(lo: float, hi: float) -> Fmt | None:
    """Thesis 2.5's worst-case format for the range ``[lo, hi]``; ``None`` when it is ``[0, 0]``.

    ``ufix[1, fl]`` (or ``sfix[2, fl]`` when ``lo < 0``) with ``fl = ceil(-log2(max(|lo|, |hi|)))``.
    With ``m = max|v| = f * 2**e`` (``frexp``: ``0.5 <= f < 1``) that is exactly ``fl = 1 - e``,
    so ``m * 2**fl`` lies in ``[1, 2)`` and floor-quantizes to code 1 at most (-2 at least when
    signed): no value of the range overflows, also for exact powers of two, and adding ``p`` bits to
    both ``wl`` and ``fl`` keeps it so.
    """
    lo, hi = float(lo), float(hi)
    if not (math.isfinite(lo) and math.isfinite(hi)) or lo > hi:
        raise FFCError(f"bad range [{lo}, {hi}]")
    m = max(abs(lo), abs(hi))
    if m == 0.0:
        return None
    e = math.frexp(m)[1]
    return Fmt(lo < 0, 2 if lo < 0 else 1, 1 - e)


def _input_format(n: int) -> Fmt:
    """Exact format of an integer counter 0..n-1: ``ufix[bits(n-1), 0]``."""
    return Fmt(False, max(1, (n - 1).bit_length()), 0)


def initial_formats(p: Sequence[float], width: int, height: int
                    ) -> tuple[list[Fmt], list[bool], list[tuple[float, float]]]:
    """Worst-case formats of q1..q26, the "zero" flags (identically-zero nodes) and the ranges.

    q25/q26 get the exact counter formats; zero nodes get ``ufix[1,0]``.
    """
    ranges = value_ranges(p, width, height)
    formats, zero = [], []
    for q in range(1, N_QUANTIZERS + 1):
        if q == QX:
            formats.append(_input_format(width)), zero.append(False)
            continue
        if q == QY:
            formats.append(_input_format(height)), zero.append(False)
            continue
        f = worst_case_format(*ranges[q - 1])
        zero.append(f is None)
        formats.append(Fmt(False, 1, 0) if f is None else f)
    return formats, zero, ranges


# ---------------------------------------------------------------------------
# bit-true fixed-point evaluation
#
# Codes are int64 numpy arrays (or python ints for the coefficients).  A quantizer computes
# wrap_wl(floor(v * 2**g)) of the exact operation result v.  Because the wrap keeps only the low
# wl bits, it suffices to know the exact integer S = v * 2**F (F = finest operand fraction length)
# modulo 2**(s + wl) with s = F - g; whenever s + wl <= 64 that is plain uint64 arithmetic modulo
# 2**64, which never loses anything that matters.  The result is then one left shift bringing the
# wl-bit window to the top of the word and one (arithmetic, if signed) right shift: in code,
# sum(a_i << k_i) >> (64 - wl) with k_i = 64 - wl + g - f_i.  Wider cases (a very coarse
# destination fed by very fine operands) take the slower exact paths below or raise FFCError.

_MASK64 = (1 << 64) - 1


def _u64(c: Any) -> Any:
    if isinstance(c, np.ndarray):
        return c.view(np.uint64)
    return int(c) & _MASK64  # python int modulo 2**64


class _Pool:
    """Recycles full-grid int64 buffers: allocating fresh 0.8 MB arrays for every stage costs more
    (page faults) than the arithmetic itself."""

    def __init__(self, shape: tuple[int, ...]) -> None:
        self.shape = shape
        self.free: list[npt.NDArray[np.int64]] = []

    def get(self, shape: tuple[int, ...]) -> npt.NDArray[np.int64]:
        if shape == self.shape and self.free:
            return self.free.pop()
        return np.empty(shape, dtype=np.int64)

    def put(self, arr: Any) -> None:
        if isinstance(arr, np.ndarray) and arr.shape == self.shape and arr.dtype == np.int64 \
                and arr.flags.c_contiguous and arr.base is None:
            self.free.append(arr)


def _buf(pool: _Pool | None, shape: tuple[int, ...]) -> npt.NDArray[np.int64]:
    return np.empty(shape, dtype=np.int64) if pool is None else pool.get(shape)


def _top_to_codes(out: npt.NDArray[np.int64], dst: Fmt) -> npt.NDArray[np.int64]:
    """In place: codes from words holding the destination's wl bits at their top (bits 63..64-wl)."""
    sh = 64 - dst.wl
    if dst.signed:
        np.right_shift(out, sh, out=out)
    else:
        ou = out.view(np.uint64)
        np.right_shift(ou, np.uint64(sh), out=ou)
    return out


def _wrap_i64(v: npt.NDArray[np.int64], dst: Fmt) -> npt.NDArray[np.int64]:
    """Two's complement wrap of exact int64 values into ``dst`` (a new array)."""
    out = np.asarray(v, dtype=np.int64).copy()
    ou = out.view(np.uint64)
    np.left_shift(ou, np.uint64(64 - dst.wl), out=ou)
    return _top_to_codes(out, dst)


def _shape(*arrays: Any) -> tuple[int, ...]:
    return np.broadcast_shapes(*(np.shape(a) for a in arrays))


def _mul_q(a: Any, fa: Fmt, b: Any, fb: Fmt, dst: Fmt, name: str,
           pool: _Pool | None = None) -> npt.NDArray[np.int64]:
    """Bit-true ``quantize(dst, a*b)`` of two code arrays (at least one is an array)."""
    shape = _shape(a, b)
    k = 64 - dst.wl + dst.fl - fa.fl - fb.fl
    if k >= 64:  # destination >= wl bits finer than the product: every code is a multiple of 2**wl
        out = _buf(pool, shape)
        out.fill(0)
        return out
    if k >= 0:
        # pre-shift the smaller operand (a python int stays a python int modulo 2**64)
        if np.size(a) < np.size(b):
            a, b = b, a
        ua, ub = _u64(a), _u64(b)
        ub = np.uint64((ub << k) & _MASK64) if isinstance(ub, int) else ub << np.uint64(k)
        out = _buf(pool, shape)
        np.multiply(ua, ub, out=out.view(np.uint64))
        return _top_to_codes(out, dst)
    # The destination is very coarse: floor needs the exact product.
    if fa.wl + fb.wl > 63:
        raise FFCError(f"{name}: exact product of {fa} and {fb} needs {fa.wl + fb.wl} bits, more than int64 holds")
    s = min(fa.fl + fb.fl - dst.fl, 63)  # > 0 here; |product| < 2**63 so >> 63 already gives floor
    prod = np.asarray(a, dtype=np.int64) * np.asarray(b, dtype=np.int64)
    return _wrap_i64(prod >> s, dst)


def _add_q(terms: Sequence[tuple[Any, Fmt]], dst: Fmt, name: str,
           pool: _Pool | None = None) -> npt.NDArray[np.int64]:
    """Bit-true ``quantize(dst, sum of terms)``; every term is (codes, format)."""
    shape = _shape(*(c for c, _ in terms))
    ks = [64 - dst.wl + dst.fl - f.fl for _, f in terms]
    if min(ks) >= 0:
        scalar = 0
        parts: list[tuple[npt.NDArray[np.uint64], int]] = []
        for (c, _f), k in zip(terms, ks):
            if k >= 64:
                continue  # contributes a multiple of 2**64: nothing
            if isinstance(c, np.ndarray):
                parts.append((c.view(np.uint64), k))
            else:
                scalar = (scalar + (_u64(c) << k)) & _MASK64
        out = _buf(pool, shape)
        acc = out.view(np.uint64)
        if not parts:
            acc.fill(scalar)
            return _top_to_codes(out, dst)
        parts.sort(key=lambda t: t[0].size, reverse=True)
        if scalar and parts[-1][0].size < acc.size:
            # fold the constant into the smallest (row or column) operand: one full pass less
            arr, k = parts.pop()
            parts.append(((arr << np.uint64(k)) + np.uint64(scalar), 0))
            scalar = 0
        arr, k = parts[0]
        if k:
            np.left_shift(arr, np.uint64(k), out=acc)
        else:
            np.copyto(acc, arr)
        for arr, k in parts[1:]:
            if not k:
                np.add(acc, arr, out=acc)
            elif arr.size < acc.size:
                np.add(acc, arr << np.uint64(k), out=acc)
            else:
                tmp = _buf(pool, shape)
                tu = tmp.view(np.uint64)
                np.left_shift(arr, np.uint64(k), out=tu)
                np.add(acc, tu, out=acc)
                if pool is not None:
                    pool.put(tmp)
        if scalar:
            np.add(acc, np.uint64(scalar), out=acc)
        return _top_to_codes(out, dst)
    # Slow path: split every finer-than-destination term into its integer part (floor) and its
    # fraction; the integer parts add modulo 2**64, the fractions exactly (they only carry).
    g = dst.fl
    d_max = max(f.fl - g for _, f in terms)
    carry_bits = max(1, (len(terms) - 1).bit_length())
    if d_max + carry_bits > 62:
        raise FFCError(f"{name}: destination {dst} is {d_max} fraction bits coarser than an operand; "
                       "exact floor needs more than 64 bits")
    ints = np.zeros(shape, dtype=np.uint64)
    fracs = np.zeros(shape, dtype=np.int64)
    for c, f in terms:
        d = f.fl - g
        if d <= 0:
            if -d < 64:
                if isinstance(c, np.ndarray):
                    ints += c.view(np.uint64) << np.uint64(-d)
                else:
                    ints += np.uint64((_u64(c) << -d) & _MASK64)
            continue
        if isinstance(c, np.ndarray):
            hi = c >> d
            lo = c - (hi << d)
            ints += hi.view(np.uint64)
            fracs += lo << (d_max - d)
        else:
            c = int(c)
            hi, lo = c >> d, c & ((1 << d) - 1)
            ints += np.uint64(hi & _MASK64)
            fracs += lo << (d_max - d)
    ints += (fracs >> d_max).view(np.uint64)
    return _wrap_i64(ints.view(np.int64), dst)


def _check_formats(formats: Sequence[Fmt]) -> list[Fmt]:
    formats = list(formats)
    if len(formats) != N_QUANTIZERS:
        raise FFCError(f"need {N_QUANTIZERS} formats (q1..q26), got {len(formats)}")
    for i, f in enumerate(formats, 1):
        if not isinstance(f, Fmt):
            raise FFCError(f"q{i}: not a Fmt: {f!r}")
        if f.wl > MAX_ARRAY_WL:
            raise FFCError(f"q{i}: {f} is wider than {MAX_ARRAY_WL} bits (int64 evaluation)")
    return formats


def _stage(q: int, fmts: Sequence[Fmt], val: Mapping[int, Any], pool: _Pool | None = None
           ) -> npt.NDArray[np.int64]:
    kind, ops = _OPS[q]
    if kind == "mul":
        a, b = ops
        return _mul_q(val[a], fmts[a - 1], val[b], fmts[b - 1], fmts[q - 1], f"q{q} = {QUANTIZER_EXPR[q]}", pool)
    return _add_q([(val[o], fmts[o - 1]) for o in ops], fmts[q - 1], f"q{q} = {QUANTIZER_EXPR[q]}", pool)


def _coef_code(c: float, fmt: Fmt) -> int:
    return int(quantize(float(c), fmt))


def fixed_stages(p: Sequence[float], formats: Sequence[Fmt], width: int, height: int) -> dict[int, Any]:
    """Integer codes of every node q1..q26 (python ints for q1..q10, broadcastable int64 arrays else)."""
    p = _coeff_list(p)
    fmts = _check_formats(formats)
    return fixed_stages_codes([_coef_code(p[i - 1], fmts[i - 1]) for i in range(1, 11)], fmts, width, height)


def _check_codes(codes: Sequence[int], fmts: Sequence[Fmt]) -> list[int]:
    codes = list(codes)
    if len(codes) != 10:
        raise FFCError(f"need the codes of p1..p10, got {len(codes)} codes")
    out = []
    for i, (c, f) in enumerate(zip(codes, fmts), 1):
        if isinstance(c, (bool, np.bool_)) or not isinstance(c, numbers.Integral):
            raise FFCError(f"code of p{i} must be an integer, got {c!r}")
        if not f.contains(int(c)):
            raise FFCError(f"code {int(c)} of p{i} does not fit q{i} {f}")
        out.append(int(c))
    return out


def fixed_stages_codes(codes: Sequence[int], formats: Sequence[Fmt], width: int, height: int) -> dict[int, Any]:
    """:func:`fixed_stages` from the coefficients' integer codes (q1..q10, as ``quantizers.json`` holds
    them) instead of their real values: what the hardware calculation unit computes at every pixel."""
    fmts = _check_formats(formats)
    xs, ys = _grid(width, height)
    val: dict[int, Any] = dict(enumerate(_check_codes(codes, fmts), 1))
    val[QX] = np.asarray(quantize(xs, fmts[QX - 1]), dtype=np.int64)
    val[QY] = np.asarray(quantize(ys, fmts[QY - 1]), dtype=np.int64)
    for q in _ORDER:
        val[q] = _stage(q, fmts, val)
    return val


def fixed_eval(p: Sequence[float], formats: Sequence[Fmt], width: int, height: int
               ) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.float64]]:
    """Bit-true evaluation at every pixel: output codes (q24) and their real values, shape (H, W)."""
    fmts = _check_formats(formats)
    out = fixed_stages(p, fmts, width, height)[24]
    codes = np.ascontiguousarray(np.broadcast_to(out, (height, width)), dtype=np.int64)
    return codes, np.asarray(to_real(codes, fmts[23]), dtype=np.float64)


def count_overflows(p: Sequence[float], formats: Sequence[Fmt], width: int, height: int) -> list[int]:
    """Per quantizer q1..q26: how many pixels wrapped (value outside the format before the wrap).

    A diagnostic: the exact operation result is recomputed in float64 from the operands' codes and
    compared with the wrapped code; a wrap moves the code by at least ``2**wl - 1`` LSBs, an
    honest floor by less than one, so the test (``diff < -0.5 or diff > 1.5`` LSB) is exact while
    the values stay below about 2**50 LSBs.  Coefficients count 1 when they do not fit.
    """
    pl = _coeff_list(p)
    fmts = _check_formats(formats)
    val = fixed_stages(pl, fmts, width, height)
    xs, ys = _grid(width, height)
    real = {q: to_real(val[q], fmts[q - 1]) for q in val}
    exact: dict[int, Any] = {i: pl[i - 1] for i in range(1, 11)}
    exact[QX], exact[QY] = xs.astype(np.float64), ys.astype(np.float64)
    for q, (kind, ops) in _OPS.items():
        exact[q] = real[ops[0]] * real[ops[1]] if kind == "mul" else sum((real[o] for o in ops[1:]), real[ops[0]])
    counts = []
    for q in range(1, N_QUANTIZERS + 1):
        f = fmts[q - 1]
        diff = np.ldexp(np.asarray(exact[q], dtype=np.float64), f.fl) - np.asarray(val[q], dtype=np.float64)
        bad = (diff < -0.5) | (diff > 1.5)
        n = int(np.count_nonzero(np.broadcast_to(bad, (height, width)))) if q > 10 else int(np.any(bad))
        counts.append(n)
    return counts


# ---------------------------------------------------------------------------
# error measures


@dataclass(frozen=True)
class ErrorMeasure:
    """An error measure: ``func(diff)`` of the array ``fixed - float`` (px) gives the error.

    ``scratch_func``, if given, computes the same value but may overwrite its argument; the
    search loops use it on their scratch buffer.
    """

    name: str
    func: Callable[[npt.NDArray[np.float64]], float]
    unit: str = ""
    description: str = ""
    scratch_func: Callable[[npt.NDArray[np.float64]], float] | None = None

    def __call__(self, diff: npt.NDArray[np.float64]) -> float:
        return float(self.func(diff))

    def on_scratch(self, diff: npt.NDArray[np.float64]) -> float:
        return float((self.scratch_func or self.func)(diff))


# No BLAS (np.dot) here: OpenBLAS threads its dot product and, with the optimisation's own
# threads or any other load on the machine, waits for cores far longer than the sum takes.
def _mse(diff: npt.NDArray[np.float64]) -> float:
    return float(np.sum(np.square(diff))) / diff.size


def _mse_scratch(diff: npt.NDArray[np.float64]) -> float:
    np.square(diff, out=diff)
    return float(np.sum(diff)) / diff.size


def _maxabs(diff: npt.NDArray[np.float64]) -> float:
    return float(max(np.max(diff), -np.min(diff)))


MEASURES: dict[str, ErrorMeasure] = {
    "mse": ErrorMeasure("mse", _mse, "px^2", "mean over all pixels of (fixed - float)^2 of one coordinate",
                        _mse_scratch),
    "max": ErrorMeasure("max", _maxabs, "px", "maximum over all pixels of |fixed - float| of one coordinate"),
}


def get_measure(measure: str | ErrorMeasure | Callable[[npt.NDArray[np.float64]], float]) -> ErrorMeasure:
    """A measure by name (``"mse"``, ``"max"``), or wrap a callable ``diff -> float``."""
    if isinstance(measure, ErrorMeasure):
        return measure
    if isinstance(measure, str):
        try:
            return MEASURES[measure]
        except KeyError:
            raise FFCError(f"unknown error measure {measure!r} (choose from {', '.join(MEASURES)})") from None
    if callable(measure):
        return ErrorMeasure(getattr(measure, "__name__", "custom"), measure)
    raise FFCError(f"not an error measure: {measure!r}")


# ---------------------------------------------------------------------------
# optimisation


class _Engine:
    """Bit-true evaluation of one polynomial with cached stages and recycled buffers, for the searches."""

    def __init__(self, p: Sequence[float], width: int, height: int, measure: ErrorMeasure) -> None:
        self.p = _coeff_list(p)
        self.width, self.height = width, height
        self.ref = float_eval(self.p, width, height)
        self.measure = measure
        self.evaluations = 0
        self.pool = _Pool((height, width))
        self._diff = np.empty((height, width), dtype=np.float64)

    def full(self, fmts: Sequence[Fmt]) -> dict[int, Any]:
        self.evaluations += 1
        return fixed_stages(self.p, fmts, self.width, self.height)

    def error(self, out: npt.NDArray[np.int64], fmt: Fmt) -> float:
        d = self._diff
        np.multiply(out, math.ldexp(1.0, -fmt.fl), out=d)
        np.subtract(d, self.ref, out=d)
        return self.measure.on_scratch(d)

    def release(self, arrays: Mapping[int, Any]) -> None:
        for a in arrays.values():
            self.pool.put(a)

    def trial(self, fmts: list[Fmt], val: Mapping[int, Any], q: int, new: Fmt
              ) -> tuple[float, dict[int, Any]]:
        """Error with quantizer q changed to ``new`` (only q and its downstream stages recomputed).

        The returned stage arrays come from the buffer pool: give them back with :meth:`release`
        or adopt them into the cached state."""
        self.evaluations += 1
        old = fmts[q - 1]
        tf = list(fmts)
        tf[q - 1] = new
        over: dict[int, Any] = {}
        if q <= 10:
            over[q] = _coef_code(self.p[q - 1], new)
        elif q in _OPS and new.wl == old.wl - 1 and new.fl == old.fl - 1 and new.signed == old.signed:
            # quantize(v, [wl-1, fl-1]) == quantize(v, [wl, fl]) >> 1 for floor rounding and wrap
            out = _buf(self.pool, np.shape(val[q]))
            np.right_shift(val[q], 1, out=out)
            over[q] = out
        elif q in _OPS:
            over[q] = _stage(q, tf, val, self.pool)
        else:
            raise FFCError(f"q{q} (an input) is not tuned")
        view = _Overlay(over, val)
        for s in _DOWNSTREAM[q]:
            over[s] = _stage(s, tf, view, self.pool)
        return self.error(np.broadcast_to(view[24], self.ref.shape), tf[23]), over


class _Overlay(Mapping[int, Any]):
    def __init__(self, top: dict[int, Any], base: Mapping[int, Any]) -> None:
        self.top, self.base = top, base

    def __getitem__(self, k: int) -> Any:
        return self.top[k] if k in self.top else self.base[k]

    def __iter__(self):  # pragma: no cover - not needed by the stages
        return iter(set(self.top) | set(self.base))

    def __len__(self) -> int:  # pragma: no cover
        return len(set(self.top) | set(self.base))


def _widen(fmts: Sequence[Fmt], fixed: Sequence[bool], p: int) -> list[Fmt]:
    return [f if fx else Fmt(f.signed, f.wl + p, f.fl + p) for f, fx in zip(fmts, fixed)]


def _frozen(zero: Sequence[bool]) -> list[bool]:
    """Quantizers the search leaves alone: the inputs and identically-zero nodes."""
    return [z or q in (QX, QY) for q, z in enumerate(zero, 1)]


def coarse_search(engine: _Engine, base: Sequence[Fmt], zero: Sequence[bool], bound: float,
                  L: int = 0, H: int = 32) -> tuple[int, float, list[tuple[int, float]]]:
    """Smallest common extra precision ``p`` in ``[L, H]`` meeting the bound, by bisection.

    Returns ``(p, error at p, trace of (p, error))``.  Guarantee: ``error(p) <= bound`` and, when
    ``p > L``, ``error(p - 1) > bound`` (both were evaluated).  The error is not monotone in ``p``
    in general, so a smaller ``p`` further down *may* also meet the bound; bisection does not look.
    """
    if isinstance(L, bool) or isinstance(H, bool) or not isinstance(L, numbers.Integral) \
            or not isinstance(H, numbers.Integral):
        raise FFCError(f"L and H must be integers, got L={L!r}, H={H!r}")
    if not 0 <= L <= H:
        raise FFCError(f"need 0 <= L <= H, got L={L}, H={H}")
    fixed = _frozen(zero)
    widest = max(f.wl for f, fx in zip(base, fixed) if not fx) if not all(fixed) else 0
    if widest + H > MAX_ARRAY_WL:
        raise FFCError(f"H={H} would make quantizers {widest + H} bits wide (at most {MAX_ARRAY_WL})")
    trace: list[tuple[int, float]] = []
    cache: dict[int, float] = {}

    def err(p: int) -> float:
        if p not in cache:
            fm = _widen(base, fixed, p)
            cache[p] = engine.error(engine.full(fm)[24], fm[23])
            trace.append((p, cache[p]))
        return cache[p]

    if not err(H) <= bound:
        raise FFCError(f"the error bound {bound:g} cannot be met with up to H={H} extra bits "
                       f"(error {err(H):.3g} at p={H}); raise H or the bound")
    if err(L) <= bound:
        return L, err(L), trace
    lo, hi = L, H  # invariant: err(lo) > bound >= err(hi)
    while hi - lo > 1:
        m = (lo + hi + 1) // 2
        if err(m) > bound:
            lo = m
        else:
            hi = m
    return hi, err(hi), trace


def greedy_tune(engine: _Engine, fmts: Sequence[Fmt], zero: Sequence[bool], bound: float
                ) -> tuple[list[Fmt], float, int]:
    """Thesis 2.5's greedy fine tuning; returns ``(formats, error, number of reductions)``.

    Each round tries ``[wl-1, fl-1]`` (same integer bits, one fraction bit less) on every tunable
    quantizer with ``wl >= 2`` on its own and keeps the one with the smallest error (ties: lowest
    q number); it stops when that smallest error exceeds the bound.  Guarantees: the result meets
    the bound, and no single further ``[wl-1, fl-1]`` reduction does.  It is a local optimum only
    (greedy never revisits a decision).
    """
    fmts = list(fmts)
    fixed = _frozen(zero)
    val = engine.full(fmts)
    err = engine.error(val[24], fmts[23])
    if not err <= bound:
        raise FFCError(f"greedy start does not meet the bound ({err:.3g} > {bound:g})")
    steps = 0
    while True:
        best_q, best_err = 0, math.inf
        for q in range(1, N_QUANTIZERS + 1):
            f = fmts[q - 1]
            if fixed[q - 1] or f.wl < 2:
                continue
            e, over = engine.trial(fmts, val, q, Fmt(f.signed, f.wl - 1, f.fl - 1))
            engine.release(over)
            if e < best_err:
                best_q, best_err = q, e
        if best_q == 0 or not best_err <= bound:
            return fmts, err, steps
        f = fmts[best_q - 1]
        new = Fmt(f.signed, f.wl - 1, f.fl - 1)
        err, over = engine.trial(fmts, val, best_q, new)
        fmts[best_q - 1] = new
        engine.release({q: val[q] for q in over})
        val = {**val, **over}
        steps += 1


@dataclass
class PolyFFC:
    """The conversion of one polynomial."""

    name: str
    coefficients: list[float]
    ranges: list[tuple[float, float]]
    zero: list[bool]
    initial: list[Fmt]
    coarse_p: int
    coarse_error: float
    coarse_trace: list[tuple[int, float]]
    formats: list[Fmt]
    error: float
    greedy_steps: int
    evaluations: int
    seconds: dict[str, float] = field(default_factory=dict)


def ffc_polynomial(p: Sequence[float], width: int, height: int, max_error: float = 0.01,
                   measure: str | ErrorMeasure | Callable[..., float] = "mse", L: int = 0, H: int = 32,
                   name: str = "poly") -> PolyFFC:
    """Ranges, worst-case formats, coarse search and greedy tuning for one polynomial."""
    m = get_measure(measure)
    bound = _check_bound(max_error)
    t0 = time.perf_counter()
    engine = _Engine(p, width, height, m)
    initial, zero, ranges = initial_formats(engine.p, width, height)
    t1 = time.perf_counter()
    try:
        pc, ec, trace = coarse_search(engine, initial, zero, bound, L, H)
    except FFCError as exc:
        raise FFCError(f"{name}: {exc}") from None
    t2 = time.perf_counter()
    fmts, err, steps = greedy_tune(engine, _widen(initial, _frozen(zero), pc), zero, bound)
    t3 = time.perf_counter()
    return PolyFFC(name, engine.p, ranges, zero, initial, pc, ec, trace, fmts, err, steps,
                   engine.evaluations, {"ranges": t1 - t0, "coarse": t2 - t1, "greedy": t3 - t2})


def _check_bound(max_error: Any) -> float:
    if isinstance(max_error, bool) or not isinstance(max_error, numbers.Real) \
            or not math.isfinite(float(max_error)) or float(max_error) <= 0:
        raise FFCError(f"max_error must be a positive finite number, got {max_error!r}")
    return float(max_error)


# ---------------------------------------------------------------------------
# merging


def covers(big: Fmt, small: Fmt) -> bool:
    """Whether every value of ``small`` is representable in ``big`` (so quantizing is exact)."""
    return big.fl >= small.fl and big.min <= small.min and big.max >= small.max


def merge_quantizers(results: Sequence[PolyFFC | Sequence[Fmt | None]]) -> list[Fmt]:
    """One format per quantizer covering all polynomials' formats (Table A.2's "merged" column).

    ``results`` are :class:`PolyFFC` (their identically-zero nodes impose nothing) or lists of 26
    formats with ``None`` for "don't care".  Per quantizer: the largest fraction length, signed if
    any is signed, and the fewest integer bits holding every format's range, an unsigned one
    needing one more integer bit in a signed result.  This is the smallest format covering them
    all (:func:`covers`).  The thesis's merge added that extra bit whenever signs were mixed, even
    when a signed format already needed more; it thus has 7 bits more than this rule on Table A.2.
    A quantizer that is don't-care everywhere becomes ``ufix[1,0]``.
    """
    lists: list[list[Fmt | None]] = []
    for r in results:
        if isinstance(r, PolyFFC):
            lists.append([None if z else f for f, z in zip(r.formats, r.zero)])
        else:
            lists.append(list(r))
    if not lists:
        raise FFCError("nothing to merge")
    for fl_list in lists:
        if len(fl_list) != N_QUANTIZERS:
            raise FFCError(f"every quantizer list needs {N_QUANTIZERS} entries, got {len(fl_list)}")
    merged = []
    for i in range(N_QUANTIZERS):
        fs = [fl_list[i] for fl_list in lists if fl_list[i] is not None]
        if not fs:
            merged.append(Fmt(False, 1, 0))
            continue
        signed = any(f.signed for f in fs)
        fl = max(f.fl for f in fs)
        iwl = max(f.iwl + (1 if signed and not f.signed else 0) for f in fs)
        merged.append(Fmt(signed, max(1, iwl + fl), fl))
    return merged


@dataclass(frozen=True)
class WideInput:
    """A multiplier operand wider than the MULT18X18 input."""

    product: int  # quantizer of the product
    operand: int  # quantizer of the operand
    fmt: Fmt
    bits: int  # width as a signed operand: wl, or wl + 1 for an unsigned one

    def __str__(self) -> str:
        return (f"q{self.product} = {QUANTIZER_EXPR[self.product]}: operand q{self.operand} {self.fmt} "
                f"needs {self.bits} signed bits > {MULT_INPUT_BITS}")


def wide_multiplier_inputs(formats: Sequence[Fmt], limit: int = MULT_INPUT_BITS,
                           zero: Sequence[bool] | None = None) -> list[WideInput]:
    """Multiplier operands that do not fit a ``limit``-bit signed multiplier input.

    The Spartan-3E MULT18X18 multiplies 18-bit two's complement numbers, so an unsigned operand
    of ``wl`` bits needs ``wl + 1``; an operand above ``limit`` costs a second multiplier (and
    clock rate).  Products whose operand is identically zero (``zero``) are left out.
    """
    fmts = _check_formats(formats)
    out = []
    for q, ops in PRODUCTS.items():
        if zero is not None and any(zero[o - 1] for o in ops):
            continue
        for o in ops:
            f = fmts[o - 1]
            bits = f.wl + (0 if f.signed else 1)
            if bits > limit:
                out.append(WideInput(q, o, f, bits))
    return out


# ---------------------------------------------------------------------------
# the whole run


@dataclass
class FFCResult:
    """Result of :func:`run_ffc`."""

    width: int
    height: int
    max_error: float
    measure: ErrorMeasure
    L: int
    H: int
    per_polynomial: dict[str, PolyFFC]
    merged: list[Fmt]
    merged_zero: list[bool]
    merged_errors: dict[str, float]
    merge_extra_bits: int
    codes: dict[str, list[int]]
    sides: dict[str, dict[str, float]]
    overflows: dict[str, list[int]]
    wide_inputs: list[WideInput]
    timings: dict[str, float]

    @property
    def total_bits(self) -> int:
        """Sum of the merged word lengths of q1..q26."""
        return sum(f.wl for f in self.merged)

    def values(self, name: str) -> list[float]:
        """Real coefficients p1..p10 that polynomial ``name``'s codes stand for under the merged formats."""
        return [float(to_real(c, f)) for c, f in zip(self.codes[name], self.merged[:10])]


def side_errors(fixed: Mapping[str, npt.NDArray[np.float64]], ref: Mapping[str, npt.NDArray[np.float64]]
                ) -> dict[str, dict[str, float]]:
    """Per side (``left``/``right`` with both ``_x`` and ``_y``): distance between two mappings.

    ``mean_square_distance`` = mean(dx**2 + dy**2) (px**2), ``mean_distance`` and ``max_distance``
    of sqrt(dx**2 + dy**2) (px).
    """
    out = {}
    for side in ("left", "right"):
        kx, ky = f"{side}_x", f"{side}_y"
        if kx in fixed and ky in fixed:
            d2 = (fixed[kx] - ref[kx]) ** 2 + (fixed[ky] - ref[ky]) ** 2
            dist = np.sqrt(d2)
            out[side] = {"mean_square_distance": float(np.mean(d2)), "mean_distance": float(np.mean(dist)),
                         "max_distance": float(np.max(dist))}
    return out


def run_ffc(polys: Mapping[str, Sequence[float]], width: int, height: int, max_error: float = 0.01,
            measure: str | ErrorMeasure | Callable[..., float] = "mse", L: int = 0, H: int = 32,
            workers: int | None = None) -> FFCResult:
    """Convert every polynomial (in parallel threads), merge their formats and verify the merge.

    The merged formats are checked on all pixels for every polynomial; should a merged error ever
    exceed the bound (merging only adds bits, but floor-rounding errors are not strictly monotone
    in the precision), one more fraction bit is given to every tunable quantizer until all meet it
    (``merge_extra_bits``, normally 0).
    """
    t0 = time.perf_counter()
    width, height = _check_size("width", width), _check_size("height", height)
    bound = _check_bound(max_error)
    m = get_measure(measure)
    if not polys:
        raise FFCError("no polynomials given")
    polys = {str(k): _check_coeffs(str(k), v) for k, v in polys.items()}
    if workers is None:
        workers = min(len(polys), os.cpu_count() or 1)

    def one(item: tuple[str, list[float]]) -> PolyFFC:
        return ffc_polynomial(item[1], width, height, bound, m, L, H, name=item[0])

    if workers > 1 and len(polys) > 1:
        pool = ThreadPoolExecutor(max_workers=workers)
        try:
            results = list(pool.map(one, polys.items()))
        except BaseException:  # an error or a signal: drop the queued polynomials, do not wait for them
            pool.shutdown(wait=False, cancel_futures=True)
            raise
        pool.shutdown()
    else:
        results = [one(it) for it in polys.items()]
    per = {r.name: r for r in results}
    t1 = time.perf_counter()

    merged = merge_quantizers(results)
    merged_zero = [all(r.zero[i] for r in results) for i in range(N_QUANTIZERS)]
    frozen = _frozen(merged_zero)
    refs = {n: float_eval(p, width, height) for n, p in polys.items()}
    extra = 0
    while True:
        fm = _widen(merged, frozen, extra)
        if max(f.wl for f in fm) > MAX_ARRAY_WL:
            raise FFCError("the merged formats cannot meet the bound within 62-bit words")
        fixed_vals = {n: fixed_eval(p, fm, width, height)[1] for n, p in polys.items()}
        errs = {n: m(fixed_vals[n] - refs[n]) for n in polys}
        if all(e <= bound for e in errs.values()):
            break
        extra += 1
    merged = fm
    codes = {n: [_coef_code(p[i], merged[i]) for i in range(10)] for n, p in polys.items()}
    overflows = {n: count_overflows(p, merged, width, height) for n, p in polys.items()}
    t2 = time.perf_counter()
    timings = {"optimise": t1 - t0, "merge": t2 - t1, "total": t2 - t0, "threads": workers}
    for r in results:
        for k, v in r.seconds.items():
            timings[f"{r.name}.{k}"] = v
    return FFCResult(width, height, bound, m, L, H, per, merged, merged_zero, errs, extra, codes,
                     side_errors(fixed_vals, refs), overflows,
                     wide_multiplier_inputs(merged, zero=merged_zero), timings)


# ---------------------------------------------------------------------------
# output: quantizers.json


def _fmt_json(q: int, f: Fmt, **extra: Any) -> dict[str, Any]:
    return {"name": f"q{q}", "signed": f.signed, "wl": f.wl, "fl": f.fl, **extra}


def quantizers_dict(result: FFCResult) -> dict[str, Any]:
    """The ``quantizers.json`` document of a result (see docs/ffc.md for the schema)."""
    m = result.measure
    return {
        "format": "eyestereo-quantizers",
        "version": 1,
        "width": result.width,
        "height": result.height,
        "degree": DEGREE,
        "terms": list(TERMS),
        "max_error": result.max_error,
        "measure": m.name,
        "quantizers": [_fmt_json(q, f, expr=QUANTIZER_EXPR[q]) for q, f in enumerate(result.merged, 1)],
        "polynomials": {n: {"codes": list(result.codes[n]), "values": result.values(n)} for n in result.codes},
        "per_polynomial_formats": {
            n: [_fmt_json(q, f, zero=z) for q, (f, z) in enumerate(zip(r.formats, r.zero), 1)]
            for n, r in result.per_polynomial.items()},
        "errors": {
            "measure": m.name,
            "unit": m.unit,
            "bound": result.max_error,
            "applies_to": "each polynomial separately",
            "per_polynomial": {n: r.error for n, r in result.per_polynomial.items()},
            "merged": dict(result.merged_errors),
            "sides_merged": result.sides,
        },
        "coarse_p": {n: r.coarse_p for n, r in result.per_polynomial.items()},
        "merge_extra_bits": result.merge_extra_bits,
        "total_bits": result.total_bits,
        "overflows_merged": {n: sum(v) for n, v in result.overflows.items()},
        "wide_multiplier_inputs": [
            {"product": f"q{w.product}", "operand": f"q{w.operand}", "signed": w.fmt.signed, "wl": w.fmt.wl,
             "fl": w.fmt.fl, "signed_bits": w.bits} for w in result.wide_inputs],
    }


def dumps_json(doc: Any, indent: int = 2, width: int = 110, _level: int = 0) -> str:
    """JSON text with every container that fits on one line of ``width`` written inline."""
    flat = json.dumps(doc, allow_nan=False)
    if not isinstance(doc, (dict, list)) or len(flat) + indent * _level <= width:
        return flat
    pad, inner = " " * (indent * _level), " " * (indent * (_level + 1))
    if isinstance(doc, dict):
        items = [f"{inner}{json.dumps(str(k))}: {dumps_json(v, indent, width, _level + 1)}" for k, v in doc.items()]
        return "{\n" + ",\n".join(items) + f"\n{pad}}}"
    items = [f"{inner}{dumps_json(v, indent, width, _level + 1)}" for v in doc]
    return "[\n" + ",\n".join(items) + f"\n{pad}]"


def write_quantizers_json(result: FFCResult, path: str | os.PathLike[str]) -> dict[str, Any]:
    """Write ``quantizers.json`` atomically; returns the document written."""
    doc = quantizers_dict(result)
    atomic_write_text(path, dumps_json(doc) + "\n")
    return doc


def read_quantizers_json(path: str | os.PathLike[str]) -> dict[str, Any]:
    """Read and check a ``quantizers.json``: the keys the VHDL package needs, 26 formats in order,
    ten codes per polynomial that fit their formats.  :class:`FFCError` with one line otherwise."""
    path = Path(path)
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise FFCError(f"file {path} does not exist") from None
    except OSError as exc:
        raise FFCError(f"{path}: cannot read: {exc.strerror or exc}") from None
    except json.JSONDecodeError as exc:
        raise FFCError(f"{path}: not valid JSON (line {exc.lineno}, column {exc.colno}: {exc.msg})") from None
    if not isinstance(doc, dict):
        raise FFCError(f"{path}: expected a JSON object at the top level")
    for key in ("width", "height", "degree", "quantizers", "polynomials"):
        if key not in doc:
            raise FFCError(f"{path}: missing key {key!r}")
    try:
        _check_pixels(_check_size("width", doc["width"]), _check_size("height", doc["height"]))
    except FFCError as exc:
        raise FFCError(f"{path}: {exc}") from None
    if doc["degree"] != DEGREE:
        raise FFCError(f"{path}: degree must be {DEGREE}, got {doc['degree']!r}")
    qs = doc["quantizers"]
    if not isinstance(qs, list) or len(qs) != N_QUANTIZERS:
        raise FFCError(f"{path}: 'quantizers' must list {N_QUANTIZERS} formats q1..q26")
    fmts = []
    for i, q in enumerate(qs, 1):
        try:
            if not isinstance(q, dict) or q.get("name") != f"q{i}":
                raise ValueError(f"entry {i} must be named 'q{i}'")
            if not isinstance(q.get("signed"), bool):
                raise ValueError("'signed' must be true or false")
            for k in ("wl", "fl"):
                if isinstance(q.get(k), bool) or not isinstance(q.get(k), int):
                    raise ValueError(f"'{k}' must be an integer")
            if not 1 <= q["wl"] <= MAX_ARRAY_WL:
                raise ValueError(f"word length {q['wl']} is implausible (the conversion makes 1..{MAX_ARRAY_WL} bits)")
            if abs(q["fl"]) > MAX_FRACTION_BITS:
                raise ValueError(f"fraction length {q['fl']} is implausible (|fl| <= {MAX_FRACTION_BITS})")
            fmts.append(Fmt(q["signed"], q["wl"], q["fl"]))
        except ValueError as exc:
            raise FFCError(f"{path}: quantizer q{i}: {exc}") from None
    polys = doc["polynomials"]
    if not isinstance(polys, dict) or not polys:
        raise FFCError(f"{path}: 'polynomials' must be a non-empty object")
    if sorted(polys) != sorted(POLY_NAMES):
        missing = [n for n in POLY_NAMES if n not in polys]
        extra = [n for n in polys if n not in POLY_NAMES]
        what = (f"lacks {', '.join(missing)}" if missing else "") + ("; " if missing and extra else "") + \
            (f"has unknown {', '.join(map(str, extra))}" if extra else "")
        raise FFCError(f"{path}: 'polynomials' must hold the four {', '.join(POLY_NAMES)}; it {what}")
    for name, entry in polys.items():
        codes = entry.get("codes") if isinstance(entry, dict) else None
        if not isinstance(codes, list) or len(codes) != 10 or \
                any(isinstance(c, bool) or not isinstance(c, int) for c in codes):
            raise FFCError(f"{path}: polynomial {name!r} needs 'codes': ten integers")
        for i, (c, f) in enumerate(zip(codes, fmts), 1):
            if not f.contains(c):
                raise FFCError(f"{path}: polynomial {name!r}: code {c} of p{i} does not fit q{i} {f}")
    doc = dict(doc)
    doc["_formats"] = fmts
    return doc
