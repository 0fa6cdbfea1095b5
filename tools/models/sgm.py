"""Bit-true model of the future ``sgm`` block (issue 28): semi-global matching of two census streams.

The block takes the census words of both cameras (:mod:`eyestereo.tools.models.census`) in raster order
and gives one disparity code per left pixel. Everything is integer; the stages, each in raster order:

1. **Matching costs.** ``C(x, y, d) = popcount(cL(x, y) XOR cR(x - d, y))`` for d = 0 .. D-1, saturated at
   ``2**cost_bits - 1``. Where ``x < d`` the right pixel lies outside the image and the cost is the
   saturated maximum ``cmax = min(window**2 - 1, 2**cost_bits - 1)``. A right-image delay line of D
   census words gives the D right words of a left pixel.
2. **Path costs** along ``paths`` directions r: 2 (left-to-right, top) or 4 (left-to-right, top-left,
   top, top-right); every one of them comes from the pixel to the left or from the previous row, so the
   block keeps the current row's left neighbour in registers and the previous row's path costs in block
   RAM. The standard recurrence::

       L(p, d) = C(p, d) + min(L(p-r, d), L(p-r, d-1) + P1, L(p-r, d+1) + P1, minL(p-r) + P2) - minL(p-r)

   with ``minL(p-r) = min over d of L(p-r, d)``; a path starts (``p - r`` outside the image) with
   ``L(p, d) = C(p, d)``; d-1 and d+1 outside 0..D-1 are left out of the minimum. The result is saturated
   at ``2**path_bits - 1``. P1 and P2 are run-time inputs, 8 bits each (0 <= P1 <= P2 <= 255).
3. **Sum** over the paths ``S(p, d) = (sum_r L_r(p, d)) >> sum_shift``.
4. **Winner take all** over the candidates d = 0 .. min(D-1, x) (a disparity beyond x would match
   outside the right image; the column counter masks it): ``dL`` = the d of the smallest S, ties to the
   smaller d. **Uniqueness** (percent, run-time 0..99): the pixel is valid when
   ``100 * S(dL) <= (100 - uniqueness) * second``, ``second`` = the smallest S over the candidates with
   ``|d - dL| > 1`` (no such candidate: valid). Two constant multiplications (100 as shifts and adds,
   ``100 - u`` a 7 x 8-bit multiplier), 15-bit products.
5. **Right disparity** by the diagonal of the same sums: ``dR(xr) = argmin over d of S(xr + d, d)``
   over d with ``xr + d <= W - 1`` (ties to the smaller d). In the stream the candidates of right pixel
   xr arrive with the left pixels xr .. xr + D - 1, in increasing d: D running minima (value and index)
   in registers; right pixel xr is complete when left pixel xr + D - 1 (or the row's end) has passed.
6. **Left-right check** (``lr_check``): valid only if ``|dL(x) - dR(x - dL(x))| <= 1``; the left results
   wait D pixels in a delay line for their dR.
7. **Sub-pixel** (``subpixel``): a parabola through the sums at dL - 1, dL, dL + 1 when both neighbours
   are candidates (1 <= dL <= min(D-1, x) - 1); otherwise the offset is 0. With ``num = S(d-1) - S(d+1)``
   and ``den = S(d-1) + S(d+1) - 2 S(d)`` (``|num| <= den`` because S(d) is the minimum), the offset
   ``num / (2 den)`` in units of ``2**-frac_bits`` px, rounded half away from zero, is
   ``q = sign(num) * ((floor(2**frac_bits * |num| / den) + 1) >> 1)`` (``den = 0``: q = 0). The quotient
   is at most ``2**frac_bits`` (5 bits for 4 fractional bits): **a radix-2 restoring divider of 5
   compare-and-subtract steps** (one pipeline stage each, 13-bit dividend, 9-bit divisor), no table and no rounding
   error beyond the final one.
8. **Output**: ``16 * dL + q * 2**(4 - frac_bits)`` as uint16 (disparity in 1/16 px, at most
   ``16 * 127``), or :data:`INVALID` (0xFFFF) where the uniqueness or the left-right check fails.

**PU**: the hardware may compute PU disparities per clock (a pixel in D/PU clocks); every minimum above is
defined with its tie rule (smallest d wins), which a tree of comparators over any grouping of the d's
reproduces, so the result never depends on PU -- it is a hardware parameter only, not a model parameter.

**Bit widths** (chosen by measurement, ``python -m eyestereo.tools.dense.accuracy``, docs/dense.md's
table of the cuts: each width cut alone; the rule: the smallest width whose bad-2 stays within 0.1 points
and whose RMS within 2 % of the full width's on Tsukuba, Venus and Motorcycle at 352 x 288, D = 64):

* cost: ``popcount`` of 24 (5 x 5) or 48 (7 x 7) bits: 5 or 6 bits (``cost_bits`` default: full; 4 bits
  cost 3 % of RMS on Tsukuba).
* path cost: ``L <= cmax + P2`` (the minimum in the recurrence is at most ``minL + P2``), so with
  8-bit P2 and a 6-bit cost 9 bits never saturate. Measured: the defaults (P2 = 30) never exceed 54
  (6 bits), and saturating at 6 bits changes nothing on the three pairs, 5 bits does. ``path_bits``
  default 7: exact up to P2 = 103 (5 x 5; 79 for 7 x 7), saturating above, a defined result for any P2.
  The previous row holds ``(paths - 1) * D * path_bits`` bits per pixel (4 paths, D = 64: 1344 bits,
  352 columns: 473 kbit; 9 bits would need 608 kbit) plus each path's minimum.
* sum: ``paths * (2**path_bits - 1)``: 9 bits for 4 paths (8 for 2), ``sum_shift`` LSBs dropped
  after the sum (default 1, 8 bits for 4 paths: dropping one costs at most 0.01 points of bad-2 and 1 %
  of RMS; two cost 4 % of RMS on Tsukuba).
* uniqueness products 15 bits (8-bit sums); divider: dividend ``16 |num|`` 13 bits, divisor 9 bits,
  5-bit quotient; output 16 bits.
"""

from __future__ import annotations

import numpy as np

from eyestereo.tools.models.census import census_bits

__all__ = ["INVALID", "D_RANGE", "PATHS", "PENALTY_MAX", "DIRECTIONS", "check_params", "matching_costs",
           "path_costs", "aggregate", "select", "sgm"]

#: The output code of a pixel without a disparity.
INVALID = 0xFFFF
#: The disparity counts D the block offers.
D_RANGE = (16, 128)
#: Aggregation path counts and their directions (dx, dy) of ``p - r``: where a path comes from.
PATHS = (2, 4)
DIRECTIONS = {2: ((-1, 0), (0, -1)), 4: ((-1, 0), (-1, -1), (0, -1), (1, -1))}
#: P1 and P2 are 8-bit run-time inputs.
PENALTY_MAX = 255


def _int(value, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise ValueError(f"{name} must be an int, got {value!r}")
    return int(value)


def check_params(*, disparities: int, paths: int, p1: int, p2: int, uniqueness: int, window: int,
                 cost_bits: int | None, path_bits: int, sum_shift: int, frac_bits: int) -> int:
    """Check the block's parameters (ValueError that says why); returns the cost's saturation value."""
    d = _int(disparities, "disparities")
    if not D_RANGE[0] <= d <= D_RANGE[1]:
        raise ValueError(f"disparities must be in {D_RANGE[0]}..{D_RANGE[1]}, got {d}")
    if _int(paths, "paths") not in PATHS:
        raise ValueError(f"paths must be one of {PATHS}, got {paths}")
    p1, p2 = _int(p1, "P1"), _int(p2, "P2")
    if not 0 <= p1 <= p2 <= PENALTY_MAX:
        raise ValueError(f"need 0 <= P1 <= P2 <= {PENALTY_MAX} (8-bit inputs), got P1={p1}, P2={p2}")
    if not 0 <= _int(uniqueness, "uniqueness") <= 99:
        raise ValueError(f"uniqueness is a percentage 0..99, got {uniqueness}")
    nbits = census_bits(window)
    full = int(nbits).bit_length()
    cb = full if cost_bits is None else _int(cost_bits, "cost_bits")
    if not 1 <= cb <= full:
        raise ValueError(f"cost_bits must be 1..{full} for a {window}x{window} census, got {cb}")
    if not 4 <= _int(path_bits, "path_bits") <= 12:
        raise ValueError(f"path_bits must be 4..12, got {path_bits}")
    if not 0 <= _int(sum_shift, "sum_shift") <= 6:
        raise ValueError(f"sum_shift must be 0..6, got {sum_shift}")
    if not 0 <= _int(frac_bits, "frac_bits") <= 4:
        raise ValueError(f"frac_bits must be 0..4 (the output has 4 fractional bits), got {frac_bits}")
    return min(nbits, (1 << cb) - 1)


def _popcount(words: np.ndarray) -> np.ndarray:
    return np.bitwise_count(words).astype(np.int32)


def matching_costs(census_left, census_right, disparities: int, cmax: int) -> np.ndarray:
    """The cost volume ``C[y, x, d]`` (int32): Hamming distances saturated at ``cmax``; ``cmax`` for x < d."""
    cl = np.asarray(census_left, np.uint64)
    cr = np.asarray(census_right, np.uint64)
    if cl.ndim != 2 or cl.shape != cr.shape:
        raise ValueError(f"census words of both cameras must be 2-D and of one size, got {cl.shape} and {cr.shape}")
    h, w = cl.shape
    if w <= 2:
        raise ValueError(f"image width {w} is too small for matching")
    cost = np.full((h, w, disparities), cmax, np.int32)
    for d in range(min(disparities, w)):
        cost[:, d:, d] = np.minimum(_popcount(cl[:, d:] ^ cr[:, :w - d]), cmax)
    return cost


def _step(c: np.ndarray, prev: np.ndarray, p1: int, p2: int, sat: int) -> np.ndarray:
    """One step of the recurrence on the last axis (the disparities)."""
    m = prev.min(axis=-1, keepdims=True)
    t = np.minimum(prev, m + p2)
    t[..., 1:] = np.minimum(t[..., 1:], prev[..., :-1] + p1)
    t[..., :-1] = np.minimum(t[..., :-1], prev[..., 1:] + p1)
    return np.minimum(c + t - m, sat)


def path_costs(cost: np.ndarray, direction: tuple[int, int], p1: int, p2: int, path_bits: int) -> np.ndarray:
    """The path costs ``L[y, x, d]`` along one direction ``(dx, dy)`` of ``p - r`` (dy = 0: from the
    left, dy = -1: from the previous row, dx = -1 / 0 / +1: its column to the left / the same / right)."""
    sat = (1 << path_bits) - 1
    c = np.asarray(cost, np.int32)
    h, w, _ = c.shape
    out = np.empty_like(c)
    dx, dy = direction
    if dy == 0:
        out[:, 0] = np.minimum(c[:, 0], sat)
        for x in range(1, w):
            out[:, x] = _step(c[:, x], out[:, x - 1], p1, p2, sat)
        return out
    out[0] = np.minimum(c[0], sat)
    lo, hi = max(0, -dx), w - max(0, dx)  # columns whose p - r lies in the previous row
    for y in range(1, h):
        row = np.minimum(c[y], sat)
        row[lo:hi] = _step(c[y, lo:hi], out[y - 1, lo + dx:hi + dx], p1, p2, sat)
        out[y] = row
    return out


def aggregate(cost: np.ndarray, *, paths: int, p1: int, p2: int, path_bits: int, sum_shift: int = 0,
              stats: dict | None = None) -> np.ndarray:
    """``S = (sum over the paths of L) >> sum_shift`` (int32). ``stats``, if given, gets the largest path
    cost seen (``max_path``) and the largest sum (``max_sum``): the widths actually used."""
    total = np.zeros(np.shape(cost), np.int32)
    peak = 0
    for direction in DIRECTIONS[paths]:
        lr = path_costs(cost, direction, p1, p2, path_bits)
        peak = max(peak, int(lr.max()))
        total += lr
    if stats is not None:
        stats["max_path"] = peak
        stats["max_sum"] = int(total.max())
    return total >> sum_shift


def _candidates(shape: tuple[int, int, int]) -> np.ndarray:
    """True where d is a candidate of the left pixel: d <= x."""
    _, w, dn = shape
    return np.arange(dn)[None, :] <= np.arange(w)[:, None]


def select(total: np.ndarray, *, uniqueness: int, lr_check: bool, subpixel: bool, frac_bits: int = 4
           ) -> np.ndarray:
    """Stages 4 to 8 on the sums ``S[y, x, d]``: uint16 disparity codes (1/16 px) or :data:`INVALID`."""
    s = np.asarray(total, np.int64)
    h, w, dn = s.shape
    big = np.int64(1) << 40
    cand = _candidates(s.shape)[None]
    sm = np.where(cand, s, big)
    dl = sm.argmin(axis=-1)                                       # first minimum: ties to the smaller d
    best = np.take_along_axis(sm, dl[..., None], -1)[..., 0]
    near = np.abs(np.arange(dn)[None, None, :] - dl[..., None]) <= 1
    second = np.where(near, big, sm).min(axis=-1)
    valid = (second == big) | (100 * best <= (100 - uniqueness) * second)
    if lr_check:
        diag = np.full((h, w, dn), big, np.int64)                 # diag[y, xr, d] = S[y, xr + d, d]
        for d in range(min(dn, w)):
            diag[:, :w - d, d] = s[:, d:, d]
        dr = diag.argmin(axis=-1)
        xr = np.arange(w)[None, :] - dl
        valid &= np.abs(dl - np.take_along_axis(dr, xr, axis=1)) <= 1
    code = 16 * dl
    if subpixel:
        lim = np.minimum(dn - 1, np.arange(w))[None, :]
        inner = (dl >= 1) & (dl <= lim - 1)
        dm = np.clip(dl - 1, 0, dn - 1)[..., None]
        dp = np.clip(dl + 1, 0, dn - 1)[..., None]
        cm = np.take_along_axis(s, dm, -1)[..., 0]
        cp = np.take_along_axis(s, dp, -1)[..., 0]
        num = cm - cp
        den = cm + cp - 2 * best
        inner &= den > 0
        quot = np.where(inner, (np.abs(num) << frac_bits) // np.where(inner, den, 1), 0)  # restoring divider
        q = np.sign(num) * ((quot + 1) >> 1)
        code = code + np.where(inner, q, 0) * (1 << (4 - frac_bits))
    return np.where(valid, code, INVALID).astype(np.uint16)


def sgm(census_left, census_right, *, disparities: int = 64, paths: int = 4, p1: int = 10, p2: int = 30,
        uniqueness: int = 10, lr_check: bool = True, subpixel: bool = True, window: int = 5,
        cost_bits: int | None = None, path_bits: int = 7, sum_shift: int = 1, frac_bits: int = 4,
        stats: dict | None = None) -> np.ndarray:
    """The block: census words of both cameras -> uint16 disparity codes (1/16 px, :data:`INVALID`)."""
    cmax = check_params(disparities=disparities, paths=paths, p1=p1, p2=p2, uniqueness=uniqueness,
                        window=window, cost_bits=cost_bits, path_bits=path_bits, sum_shift=sum_shift,
                        frac_bits=frac_bits)
    cost = matching_costs(census_left, census_right, disparities, cmax)
    total = aggregate(cost, paths=paths, p1=p1, p2=p2, path_bits=path_bits, sum_shift=sum_shift, stats=stats)
    return select(total, uniqueness=uniqueness, lr_check=bool(lr_check), subpixel=bool(subpixel),
                  frac_bits=frac_bits)
