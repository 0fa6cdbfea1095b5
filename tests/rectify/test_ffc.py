"""Float-to-fixed conversion of the rectification polynomials (eyestereo.tools.rectify.ffc, cli_ffc).

The bit-true evaluator is checked against an independent scalar reference written here from the
thesis's levelized listing (section 2.5) with exact ``Fraction`` arithmetic and a hand-written floor
and wrap; the search results are re-checked with that evaluator or the reference, never with the
numbers the search reports about itself.
"""

from __future__ import annotations

import json
import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from eyestereo.tools.cli import ffc as cli_ffc
from eyestereo.tools.cli import main as cli_main
from eyestereo.tools.rectify import ffc
from eyestereo.tools.reports.bench_ffc import TABLE_A2, rig_maps, synthetic_rig_polynomials, table_a2_formats
from eyestereo.tools.fixed import Fmt

# ---------------------------------------------------------------------------
# independent reference

# (quantizer, operation, operands) transcribed from the thesis's calc_fixpoint listing:
# product1..9 and sum1..5 with their quant(n) indices; p(i) are quantizers 1..10, X = 25, Y = 26.
THESIS_LISTING = [
    (11, "*", (8, 26)), (12, "*", (10, 25)), (13, "*", (7, 25)), (14, "*", (9, 26)),
    (20, "+", (5, 11, 12)), (21, "+", (4, 13, 14)),
    (15, "*", (20, 26)), (16, "*", (6, 25)), (17, "*", (21, 25)),
    (22, "+", (15, 3, 16)), (23, "+", (17, 2)),
    (18, "*", (22, 26)), (19, "*", (23, 25)),
    (24, "+", (1, 18, 19)),
]


def ref_code(v: Fraction, f: Fmt) -> int:
    """floor(v * 2**fl), then two's complement wrap into wl bits (written out, not fixed.py)."""
    c = math.floor(Fraction(v) * Fraction(2) ** f.fl)
    lo = -(1 << (f.wl - 1)) if f.signed else 0
    return (c - lo) % (1 << f.wl) + lo


def ref_value(c: int, f: Fmt) -> Fraction:
    return Fraction(c) * Fraction(2) ** (-f.fl)


def ref_pixel(p, fm, x, y) -> tuple[int, dict[int, Fraction], dict[int, Fraction]]:
    """Output code at one pixel, plus every node's quantized value and its exact (pre-quantizer) value."""
    v = {i: ref_value(ref_code(Fraction(p[i - 1]), fm[i - 1]), fm[i - 1]) for i in range(1, 11)}
    v[25] = ref_value(ref_code(Fraction(x), fm[24]), fm[24])
    v[26] = ref_value(ref_code(Fraction(y), fm[25]), fm[25])
    exact = {}
    code = 0
    for q, op, ops in THESIS_LISTING:
        e = v[ops[0]] * v[ops[1]] if op == "*" else sum((v[o] for o in ops), Fraction(0))
        exact[q] = e
        code = ref_code(e, fm[q - 1])
        v[q] = ref_value(code, fm[q - 1])
    return code, v, exact


def ref_eval(p, fm, width, height) -> np.ndarray:
    out = np.zeros((height, width), dtype=object)
    for y in range(height):
        for x in range(width):
            out[y, x] = ref_pixel(p, fm, x, y)[0]
    return out


def horner_float(p, width, height) -> np.ndarray:
    """eq. 4.1 in plain powers, float64 (independent of the levelized form)."""
    y, x = np.mgrid[0:height, 0:width].astype(np.float64)
    return (p[0] + p[1] * x + p[2] * y + p[3] * x**2 + p[4] * y**2 + p[5] * x * y + p[6] * x**3 + p[7] * y**3
            + p[8] * x**2 * y + p[9] * x * y**2)


def mse(a, b) -> float:
    return float(np.mean((np.asarray(a, dtype=np.float64) - np.asarray(b, dtype=np.float64)) ** 2))


def fixed_real(p, fm, width, height) -> np.ndarray:
    codes, _ = ffc.fixed_eval(p, fm, width, height)
    return codes.astype(np.float64) * 2.0 ** -fm[23].fl


def widen(fmts, zero, p):
    """Every format but the inputs and zero nodes grows by p bits in wl and fl (the coarse step)."""
    return [f if (z or q in (25, 26)) else Fmt(f.signed, f.wl + p, f.fl + p)
            for q, (f, z) in enumerate(zip(fmts, zero), 1)]


# ---------------------------------------------------------------------------
# strategies

fmts_st = st.builds(Fmt, st.booleans(), st.integers(1, 24), st.integers(-8, 36))
input_fmt_st = st.builds(Fmt, st.booleans(), st.integers(1, 10), st.integers(-3, 3))
coef_st = st.builds(lambda m, e: m * 2.0**e, st.floats(-1, 1, allow_nan=False), st.integers(-30, 10))
SMALL = dict(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])

SMALL_W, SMALL_H = 48, 40
RIG_SMALL = synthetic_rig_polynomials(SMALL_W, SMALL_H)


@st.composite
def rig_like(draw, width=SMALL_W, height=SMALL_H):
    """A synthetic-rig polynomial with every coefficient scaled by 0.7..1.3 and p1 shifted."""
    name = draw(st.sampled_from(ffc.POLY_NAMES))
    base = synthetic_rig_polynomials(width, height)[name] if (width, height) != (SMALL_W, SMALL_H) else RIG_SMALL[name]
    scale = draw(st.lists(st.floats(0.7, 1.3), min_size=10, max_size=10))
    p = [c * s for c, s in zip(base, scale)]
    p[0] += draw(st.floats(-5, 5))
    return p


# ---------------------------------------------------------------------------
# structure


def test_quantizer_numbering_is_the_thesis_listing():
    expected = {11: "p8 * Y", 12: "p10 * X", 13: "p7 * X", 14: "p9 * Y", 15: "q20 * Y", 16: "p6 * X",
                17: "q21 * X", 18: "q22 * Y", 19: "q23 * X", 20: "p5 + q11 + q12", 21: "p4 + q13 + q14",
                22: "q15 + p3 + q16", 23: "q17 + p2", 24: "p1 + q18 + q19", 25: "X", 26: "Y"}
    expected.update({i: f"p{i}" for i in range(1, 11)})
    assert ffc.QUANTIZER_EXPR == expected
    assert ffc.PRODUCTS == {11: (8, 26), 12: (10, 25), 13: (7, 25), 14: (9, 26), 15: (20, 26), 16: (6, 25),
                            17: (21, 25), 18: (22, 26), 19: (23, 25)}


@given(st.lists(coef_st, min_size=10, max_size=10), st.integers(1, 7), st.integers(1, 7))
@settings(max_examples=40, deadline=None)
def test_float_eval_is_the_polynomial(p, w, h):
    np.testing.assert_allclose(ffc.float_eval(p, w, h), horner_float(p, w, h), rtol=1e-12,
                               atol=1e-12 * max(1.0, max(abs(c) for c in p)) * 7**3)


# ---------------------------------------------------------------------------
# bit-true evaluation


@given(st.lists(coef_st, min_size=10, max_size=10), st.lists(fmts_st, min_size=24, max_size=24),
       input_fmt_st, input_fmt_st, st.integers(1, 5), st.integers(1, 5))
@settings(max_examples=150, deadline=None)
def test_fixed_eval_equals_reference(p, fm, fx, fy, w, h):
    fm = fm + [fx, fy]
    codes, values = ffc.fixed_eval(p, fm, w, h)
    ref = ref_eval(p, fm, w, h)
    assert codes.shape == (h, w) and codes.dtype == np.int64
    assert [[int(c) for c in row] for row in codes] == [[int(c) for c in row] for row in ref]
    assert np.array_equal(values, codes.astype(np.float64) * 2.0 ** -fm[23].fl)


@given(st.lists(coef_st, min_size=10, max_size=10), st.lists(st.integers(20, 36), min_size=26, max_size=26),
       st.integers(30, 48), st.integers(-10, 0), st.integers(1, 4), st.integers(1, 4))
@settings(max_examples=60, deadline=None)
def test_fixed_eval_wide_coarse_destinations_equal_reference(p, fls, wl, fl_out, w, h):
    """Fine operands into wide, coarse adders and multipliers: the exact slow paths."""
    fm = [Fmt(i % 2 == 0, 24, fls[i]) for i in range(24)] + [Fmt(False, 4, 0), Fmt(False, 4, 0)]
    for q in (15, 17, 18, 19, 20, 21, 22, 23, 24):  # coarse results of fine operands
        fm[q - 1] = Fmt(True, wl, fl_out)
    codes, _ = ffc.fixed_eval(p, fm, w, h)
    assert [[int(c) for c in row] for row in codes] == [[int(c) for c in row] for row in ref_eval(p, fm, w, h)]


def test_fixed_eval_refuses_what_int64_cannot_do_exactly():
    p = [0.5] * 10
    fm = [Fmt(True, 40, 30)] * 24 + [Fmt(False, 30, 0), Fmt(False, 30, 0)]
    fm[10] = Fmt(True, 40, -20)  # q11 = p8*Y: 70-bit exact product needed for the floor
    with pytest.raises(ffc.FFCError, match=r"q11 = p8 \* Y: exact product .* 70 bits"):
        ffc.fixed_eval(p, fm, 3, 3)
    with pytest.raises(ffc.FFCError, match="wider than 62 bits"):
        ffc.fixed_eval(p, [Fmt(True, 63, 0)] * 26, 3, 3)
    with pytest.raises(ffc.FFCError, match="need 26 formats"):
        ffc.fixed_eval(p, [Fmt(True, 8, 0)] * 25, 3, 3)


def test_fixed_eval_exact_on_a_full_size_image_sample():
    """352x288 with realistic formats: spot-check 300 random pixels against the reference."""
    polys = synthetic_rig_polynomials()
    fm = table_a2_formats("merged")
    rng = np.random.default_rng(7)
    for name, p in polys.items():
        codes, _ = ffc.fixed_eval(p, fm, 352, 288)
        for x, y in zip(rng.integers(0, 352, 75), rng.integers(0, 288, 75)):
            assert int(codes[y, x]) == ref_pixel(p, fm, int(x), int(y))[0], (name, x, y)


@given(rig_like())
@settings(max_examples=25, deadline=None)
def test_huge_precision_fixed_is_float(p):
    fmts, zero, _ = ffc.initial_formats(p, SMALL_W, SMALL_H)
    fixed = fixed_real(p, widen(fmts, zero, 40), SMALL_W, SMALL_H)
    assert np.max(np.abs(fixed - horner_float(p, SMALL_W, SMALL_H))) < 1e-6


# ---------------------------------------------------------------------------
# ranges and worst-case formats


@given(st.floats(-1e6, 1e6, allow_nan=False), st.floats(-1e6, 1e6, allow_nan=False), st.integers(0, 8),
       st.sampled_from([None, 1.0, 2.0**-7, 2.0**5, 0.75, 2.0**-30]))
@settings(max_examples=300, deadline=None)
def test_worst_case_format_never_overflows(a, b, extra, power):
    lo, hi = min(a, b), max(a, b)
    if power is not None:  # exact powers of two (and their negatives) at the range ends
        lo, hi = min(lo, -power), max(hi, power) if a > 0 else hi
    f = ffc.worst_case_format(lo, hi)
    if lo == hi == 0:
        assert f is None
        return
    m = max(abs(Fraction(lo)), abs(Fraction(hi)))
    assert f.signed == (lo < 0) and f.wl == (2 if lo < 0 else 1)
    assert 1 <= m * Fraction(2) ** f.fl < 2  # fl = ceil(-log2(max|v|)), exactly
    g = Fmt(f.signed, f.wl + extra, f.fl + extra)
    for v in (lo, hi):
        code = math.floor(Fraction(v) * Fraction(2) ** g.fl)
        assert g.lo <= code <= g.hi


def test_worst_case_format_edge_cases():
    assert ffc.worst_case_format(0.0, 0.0) is None
    assert ffc.worst_case_format(0.5, 0.5) == Fmt(False, 1, 1)  # 0.5 -> code 1 of ufix[1,1]
    assert ffc.worst_case_format(-0.5, 0.0) == Fmt(True, 2, 1)  # -0.5 -> code -1 of sfix[2,1]
    assert ffc.worst_case_format(-1.0, 0.25) == Fmt(True, 2, 0)
    assert ffc.worst_case_format(0.0, 351.0) == Fmt(False, 1, -8)  # 351 -> code 1 of ufix[1,-8]
    assert ffc.worst_case_format(0.0, 256.0) == Fmt(False, 1, -8)
    assert ffc.worst_case_format(0.0, 255.9) == Fmt(False, 1, -7)
    with pytest.raises(ffc.FFCError):
        ffc.worst_case_format(1.0, float("nan"))


def test_initial_formats_inputs_exact_and_zero_nodes():
    p = [1.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]  # p3..p10 zero: whole branches vanish
    fmts, zero, ranges = ffc.initial_formats(p, 352, 288)
    assert fmts[24] == Fmt(False, 9, 0) and fmts[25] == Fmt(False, 9, 0)  # 351 and 287 exactly
    assert [q for q, z in enumerate(zero, 1) if z] == [3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16,
                                                       17, 18, 20, 21, 22]
    assert ranges[23] == (1.0, 1.0 + 0.5 * 351)
    fmts, _, _ = ffc.initial_formats(RIG_SMALL["left_x"], 1, 1)
    assert fmts[24] == fmts[25] == Fmt(False, 1, 0)
    fmts, _, _ = ffc.initial_formats(RIG_SMALL["left_x"], 257, 256)
    assert fmts[24] == Fmt(False, 9, 0) and fmts[25] == Fmt(False, 8, 0)


def test_zero_polynomial_branches_convert():
    """A polynomial with zero coefficients: zero nodes stay ufix[1,0], no overflow, bound met."""
    p = [10.0, 0.9, 0.05, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    r = ffc.ffc_polynomial(p, 40, 30, 0.01)
    # p3 and p2 keep q22 = q15 + p3 + q16 -> q18 and q23 = q17 + p2 -> q19 alive
    assert [q for q, z in enumerate(r.zero, 1) if z] == [4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 20, 21]
    assert all(r.formats[q - 1] == Fmt(False, 1, 0) for q in range(4, 18))
    assert mse(fixed_real(p, r.formats, 40, 30), horner_float(p, 40, 30)) <= 0.01


def test_ranges_cover_every_node_value():
    """value_ranges are the min/max of the exact (float) operation results at every pixel."""
    p = RIG_SMALL["right_y"]
    ranges = ffc.value_ranges(p, 9, 7)
    fm = [Fmt(True, 300, 200)] * 24 + [Fmt(False, 4, 0), Fmt(False, 3, 0)]  # exact for these values
    lo = {q: math.inf for q in range(11, 25)}
    hi = {q: -math.inf for q in range(11, 25)}
    for y in range(7):
        for x in range(9):
            _, _, exact = ref_pixel(p, fm, x, y)
            for q, e in exact.items():
                lo[q], hi[q] = min(lo[q], float(e)), max(hi[q], float(e))
    for q in range(11, 25):
        assert ranges[q - 1][0] == pytest.approx(lo[q], rel=1e-9, abs=1e-15)
        assert ranges[q - 1][1] == pytest.approx(hi[q], rel=1e-9, abs=1e-15)
    assert ranges[:10] == [(c, c) for c in p]
    assert ranges[24] == (0.0, 8.0) and ranges[25] == (0.0, 6.0)


# ---------------------------------------------------------------------------
# the search


@given(rig_like(), st.sampled_from([0.003, 0.01, 0.05]))
@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
def test_ffc_polynomial_meets_bound_and_its_guarantees(p, bound):
    r = ffc.ffc_polynomial(p, SMALL_W, SMALL_H, bound)
    flt = horner_float(p, SMALL_W, SMALL_H)
    # the result meets the bound (recomputed from the bit-true output)
    err = mse(fixed_real(p, r.formats, SMALL_W, SMALL_H), flt)
    assert err <= bound
    assert err == pytest.approx(r.error, rel=1e-9)
    # coarse: p_min meets the bound, p_min - 1 does not
    pc = r.coarse_p
    assert mse(fixed_real(p, widen(r.initial, r.zero, pc), SMALL_W, SMALL_H), flt) <= bound
    assert pc > 0
    assert mse(fixed_real(p, widen(r.initial, r.zero, pc - 1), SMALL_W, SMALL_H), flt) > bound
    # greedy: no single further [wl-1, fl-1] keeps the bound
    for q in range(1, 25):
        f = r.formats[q - 1]
        if r.zero[q - 1] or f.wl < 2:
            continue
        fm = list(r.formats)
        fm[q - 1] = Fmt(f.signed, f.wl - 1, f.fl - 1)
        assert mse(fixed_real(p, fm, SMALL_W, SMALL_H), flt) > bound, q
    # greedy only takes bits away, and keeps every quantizer's integer bits
    start = widen(r.initial, r.zero, pc)
    for f, g in zip(r.formats, start):
        assert f.signed == g.signed and f.iwl == g.iwl and f.wl <= g.wl
    # inputs stay exact
    assert r.formats[24] == Fmt(False, 6, 0) and r.formats[25] == Fmt(False, 6, 0)


def test_max_measure_and_custom_measure():
    p = RIG_SMALL["left_y"]
    flt = horner_float(p, SMALL_W, SMALL_H)
    r = ffc.ffc_polynomial(p, SMALL_W, SMALL_H, 0.05, measure="max")
    assert np.max(np.abs(fixed_real(p, r.formats, SMALL_W, SMALL_H) - flt)) <= 0.05
    calls = []

    def mean_abs(diff):
        calls.append(diff.shape)
        return float(np.mean(np.abs(diff)))

    r2 = ffc.ffc_polynomial(p, SMALL_W, SMALL_H, 0.02, measure=mean_abs)
    assert np.mean(np.abs(fixed_real(p, r2.formats, SMALL_W, SMALL_H) - flt)) <= 0.02
    assert calls and all(s == (SMALL_H, SMALL_W) for s in calls)
    with pytest.raises(ffc.FFCError, match="unknown error measure 'rms'"):
        ffc.ffc_polynomial(p, SMALL_W, SMALL_H, 0.02, measure="rms")


def test_unreachable_bound_is_a_clear_error():
    with pytest.raises(ffc.FFCError) as exc:
        ffc.run_ffc({"left_x": RIG_SMALL["left_x"]}, SMALL_W, SMALL_H, max_error=1e-30, H=4)
    msg = str(exc.value)
    assert "\n" not in msg
    assert msg.startswith("left_x: the error bound 1e-30 cannot be met with up to H=4 extra bits")
    for bad in (0, -1.0, float("nan"), float("inf")):
        with pytest.raises(ffc.FFCError, match="max_error must be a positive finite number"):
            ffc.run_ffc({"left_x": RIG_SMALL["left_x"]}, SMALL_W, SMALL_H, max_error=bad)
    with pytest.raises(ffc.FFCError, match="need 0 <= L <= H"):
        ffc.run_ffc({"left_x": RIG_SMALL["left_x"]}, SMALL_W, SMALL_H, L=5, H=4)


def test_low_bound_already_enough():
    """A generous bound is met at p = L: the coarse step returns L itself."""
    p = RIG_SMALL["left_x"]
    r = ffc.ffc_polynomial(p, SMALL_W, SMALL_H, 1e6, L=3, H=10)
    assert r.coarse_p == 3


# ---------------------------------------------------------------------------
# merging


def fmt_covers(big: Fmt, small: Fmt) -> bool:
    """Every code of small, as an exact value, is a code of big (checked on the range ends)."""
    if big.fl < small.fl:
        return False
    scale = 1 << (big.fl - small.fl)
    return big.lo <= small.lo * scale and small.hi * scale <= big.hi


def test_merge_reproduces_table_a2_up_to_the_mixed_sign_bit():
    """Merging the thesis's four columns gives its merged column, except that the thesis added a
    sign bit whenever signs were mixed, also where a signed format already had enough integer bits."""
    merged = ffc.merge_quantizers([table_a2_formats(n) for n in ("left_x", "left_y", "right_x", "right_y")])
    thesis = [Fmt.parse(s) for s in (
        "ufix[11,7] sfix[16,15] sfix[16,15] ufix[13,22] ufix[13,22] ufix[13,22] sfix[14,30] sfix[15,31] "
        "sfix[13,30] sfix[13,30] sfix[14,22] sfix[13,22] sfix[14,22] sfix[13,22] sfix[13,14] ufix[14,15] "
        "sfix[15,15] sfix[17,7] sfix[17,7] sfix[14,22] sfix[14,22] sfix[17,15] sfix[15,14] sfix[16,5] "
        "ufix[9,0] ufix[9,0]").split()]
    assert thesis == table_a2_formats("merged")
    one_bit_more = {7, 8, 11, 13, 15, 17, 24}
    for q, (m, t) in enumerate(zip(merged, thesis), 1):
        if q in one_bit_more:
            assert (t.signed, t.wl, t.fl) == (m.signed, m.wl + 1, m.fl), q
        else:
            assert t == m, q
    assert sum(f.wl for f in thesis) == 361


@given(st.lists(st.lists(st.one_of(st.none(), fmts_st), min_size=26, max_size=26), min_size=1, max_size=5))
@settings(max_examples=200, deadline=None)
def test_merge_is_the_smallest_cover(lists):
    merged = ffc.merge_quantizers(lists)
    for i in range(26):
        fs = [fl[i] for fl in lists if fl[i] is not None]
        m = merged[i]
        if not fs:
            assert m == Fmt(False, 1, 0)
            continue
        assert all(fmt_covers(m, f) for f in fs)
        assert m.fl == max(f.fl for f in fs) and m.signed == any(f.signed for f in fs)
        if m.wl > 1:  # one bit less covers not all of them
            assert not all(fmt_covers(Fmt(m.signed, m.wl - 1, m.fl), f) for f in fs)


@pytest.fixture(scope="module")
def full_run():
    """The realistic case: all four synthetic-rig polynomials at 352x288."""
    polys = synthetic_rig_polynomials()
    return polys, ffc.run_ffc(polys, 352, 288, max_error=0.01)


def test_full_size_run_merged(full_run):
    polys, res = full_run
    flt = {n: horner_float(p, 352, 288) for n, p in polys.items()}
    assert list(res.per_polynomial) == list(ffc.POLY_NAMES)
    for n, p in polys.items():
        r = res.per_polynomial[n]
        # per-polynomial formats meet the bound, and so do the merged ones (recomputed)
        assert mse(fixed_real(p, r.formats, 352, 288), flt[n]) <= 0.01
        e_merged = mse(fixed_real(p, res.merged, 352, 288), flt[n])
        assert e_merged <= 0.01
        assert e_merged == pytest.approx(res.merged_errors[n], rel=1e-9)
        # merging only added bits here, and the errors did not get worse (observed, see docs)
        assert e_merged <= r.error
        for q, (m, f, z) in enumerate(zip(res.merged, r.formats, r.zero), 1):
            assert z or fmt_covers(m, f), (n, q)
        # coefficients: codes are floor(p * 2**fl) and values are exactly code * 2**-fl
        for i in range(10):
            f = res.merged[i]
            assert res.codes[n][i] == math.floor(Fraction(p[i]) * Fraction(2) ** f.fl)
            assert Fraction(res.values(n)[i]) == Fraction(res.codes[n][i]) * Fraction(2) ** -f.fl
        assert res.overflows[n] == [0] * 26
    assert res.merge_extra_bits == 0
    assert res.merged[24] == Fmt(False, 9, 0) and res.merged[25] == Fmt(False, 9, 0)
    # side distances: mean of dx^2 + dy^2 is the sum of the two coordinates' mse
    for side in ("left", "right"):
        s = res.sides[side]
        assert s["mean_square_distance"] == pytest.approx(
            res.merged_errors[f"{side}_x"] + res.merged_errors[f"{side}_y"], rel=1e-9)
        assert s["mean_distance"] <= s["max_distance"]
    # wide multiplier inputs are exactly the product operands above 18 signed bits
    expect = sorted((q, o) for q, ops in ffc.PRODUCTS.items() for o in ops
                    if res.merged[o - 1].wl + (0 if res.merged[o - 1].signed else 1) > 18)
    assert sorted((w.product, w.operand) for w in res.wide_inputs) == expect
    assert res.total_bits == sum(f.wl for f in res.merged)


def test_rig_is_like_the_thesis():
    maps = rig_maps()
    y, x = np.mgrid[0:288, 0:352]
    shift = max(np.max(np.hypot(maps[f"{s}_x"] - x, maps[f"{s}_y"] - y)) for s in ("left", "right"))
    assert 20 < shift < 30
    polys = synthetic_rig_polynomials()
    for n, p in polys.items():  # degree 3 fits to ~0.1 px, as thesis Table 4.1
        assert np.max(np.abs(horner_float(p, 352, 288) - maps[n])) < 0.5


def test_wide_multiplier_inputs():
    fm = [Fmt(True, 10, 0)] * 26
    fm[21] = Fmt(True, 19, 17)  # q22 feeds q18 = q22*Y
    fm[22] = Fmt(False, 18, 0)  # q23 feeds q19: unsigned 18 bits need 19 signed
    fm[19] = Fmt(True, 18, 0)  # q20 feeds q15: exactly 18 signed bits fit
    fm[24] = Fmt(False, 17, 0)  # X: 17 unsigned = 18 signed, fits
    wide = ffc.wide_multiplier_inputs(fm)
    assert [(w.product, w.operand, w.bits) for w in wide] == [(18, 22, 19), (19, 23, 19)]
    assert "q18 = q22 * Y" in str(wide[0])


def test_count_overflows_matches_reference():
    p = RIG_SMALL["left_x"]
    fmts, zero, _ = ffc.initial_formats(p, 12, 10)
    fm = widen(fmts, zero, 8)
    fm[18] = Fmt(False, 5, 3)  # q19 = q23*X is up to ~12: needs 4 integer bits, give 2
    fm[0] = Fmt(True, 4, 2)  # p1 = 24.8 does not fit sfix[4,2]
    counts = ffc.count_overflows(p, fm, 12, 10)
    expect = [0] * 26
    for y in range(10):
        for x in range(12):
            _, _, exact = ref_pixel(p, fm, x, y)
            for q, e in exact.items():
                c = math.floor(e * Fraction(2) ** fm[q - 1].fl)
                expect[q - 1] += not (fm[q - 1].lo <= c <= fm[q - 1].hi)
    expect[0] = 1
    assert counts == expect
    assert counts[18] > 0


# ---------------------------------------------------------------------------
# files


def test_quantizers_json_schema(full_run, tmp_path):
    polys, res = full_run
    path = tmp_path / "quantizers.json"
    ffc.write_quantizers_json(res, path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["quantizers.json"]  # no temp file left
    doc = json.loads(path.read_text())
    for key in ("width", "height", "degree", "max_error", "quantizers", "polynomials", "per_polynomial_formats",
                "errors"):
        assert key in doc
    assert (doc["width"], doc["height"], doc["degree"], doc["max_error"]) == (352, 288, 3, 0.01)
    assert [q["name"] for q in doc["quantizers"]] == [f"q{i}" for i in range(1, 27)]
    assert all(set(q) >= {"name", "signed", "wl", "fl"} for q in doc["quantizers"])
    fm = [Fmt(q["signed"], q["wl"], q["fl"]) for q in doc["quantizers"]]
    assert fm == res.merged
    assert sorted(doc["polynomials"]) == sorted(ffc.POLY_NAMES)
    for n, entry in doc["polynomials"].items():
        assert len(entry["codes"]) == len(entry["values"]) == 10
        for i, (c, v) in enumerate(zip(entry["codes"], entry["values"])):
            assert isinstance(c, int) and fm[i].lo <= c <= fm[i].hi
            assert Fraction(v) == Fraction(c) * Fraction(2) ** -fm[i].fl  # exactly
            assert c == math.floor(Fraction(polys[n][i]) * Fraction(2) ** fm[i].fl)
    for n, lst in doc["per_polynomial_formats"].items():
        assert [q["name"] for q in lst] == [f"q{i}" for i in range(1, 27)]
        r = res.per_polynomial[n]
        assert [Fmt(q["signed"], q["wl"], q["fl"]) for q in lst] == r.formats
    errs = doc["errors"]
    assert errs["measure"] == "mse" and errs["bound"] == 0.01
    for n in ffc.POLY_NAMES:
        assert errs["merged"][n] <= 0.01 and errs["per_polynomial"][n] <= 0.01
    # read back through the checker used by the package command
    back = ffc.read_quantizers_json(path)
    assert back["_formats"] == res.merged


def poly_doc(**over):
    doc = {"width": SMALL_W, "height": SMALL_H, "degree": 3, "terms": list(ffc.TERMS),
           "polynomials": {n: list(RIG_SMALL[n]) for n in ffc.POLY_NAMES}}
    doc.update(over)
    return doc


@pytest.mark.parametrize("mutate, message", [
    (lambda d: d.pop("width"), "missing key 'width'"),
    (lambda d: d.pop("polynomials"), "missing key 'polynomials'"),
    (lambda d: d.update(degree=2), "degree-3 polynomials only, got degree 2"),
    (lambda d: d["polynomials"].pop("right_y"), "missing polynomial 'right_y'"),
    (lambda d: d["polynomials"]["left_y"].pop(), "'left_y' has 9 coefficients"),
    (lambda d: d["polynomials"]["left_x"].__setitem__(3, float("nan")), "'left_x': p4 is not finite"),
    (lambda d: d["polynomials"]["left_x"].__setitem__(0, "1"), "'left_x': p1 is not a number"),
    (lambda d: d.update(width=0), "width must be a positive integer"),
    (lambda d: d.update(terms=["1", "y", "x"] + list(ffc.TERMS[3:])), "terms must be"),
])
def test_read_poly_json_rejects_bad_content(tmp_path, mutate, message):
    doc = poly_doc()
    mutate(doc)
    path = tmp_path / "poly.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(ffc.FFCError) as exc:
        ffc.read_poly_json(path)
    assert message in str(exc.value) and "\n" not in str(exc.value)


def test_read_poly_json_good(tmp_path):
    path = tmp_path / "poly.json"
    path.write_text(json.dumps(poly_doc(extra="ignored")))
    pf = ffc.read_poly_json(path)
    assert (pf.width, pf.height) == (SMALL_W, SMALL_H)
    assert pf.polynomials == {n: list(RIG_SMALL[n]) for n in ffc.POLY_NAMES}


# ---------------------------------------------------------------------------
# command line


def run_cli(argv, capsys):
    code = cli_main.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_ffc_writes_quantizers(tmp_path, capsys):
    src = tmp_path / "poly.json"
    src.write_text(json.dumps(poly_doc()))
    out = tmp_path / "q.json"
    code, stdout, err = run_cli(["ffc", src, "-o", out, "--max-error", "0.02", "--measure", "max",
                                 "--low", "2", "--high", "20"], capsys)
    assert code == 0 and err == ""
    doc = json.loads(out.read_text())
    assert doc["measure"] == "max" and doc["max_error"] == 0.02
    fm = [Fmt(q["signed"], q["wl"], q["fl"]) for q in doc["quantizers"]]
    for p in RIG_SMALL.values():
        assert np.max(np.abs(fixed_real(p, fm, SMALL_W, SMALL_H) - horner_float(p, SMALL_W, SMALL_H))) <= 0.02
    assert str(out) in stdout


@pytest.mark.parametrize("case", ["missing", "badjson", "degree2", "unreachable", "nodir"])
def test_cli_ffc_bad_input(tmp_path, capsys, case):
    src = tmp_path / "poly.json"
    out = tmp_path / "q.json"
    extra: list[str] = []
    if case == "badjson":
        src.write_text('{"width": 48, "height": ')
    elif case == "degree2":
        src.write_text(json.dumps(poly_doc(degree=2)))
    elif case == "unreachable":
        src.write_text(json.dumps(poly_doc()))
        extra = ["--max-error", "1e-30", "--high", "4"]
    elif case == "nodir":
        src.write_text(json.dumps(poly_doc()))
        out = tmp_path / "no" / "such" / "q.json"
        extra = ["--max-error", "1"]
    code, stdout, err = run_cli(["ffc", src, "-o", out, *extra], capsys)
    assert code != 0
    assert err.startswith("eyestereo: error: ") and err.count("\n") == 1
    assert {"missing": "does not exist", "badjson": "not valid JSON", "degree2": "degree 2",
            "unreachable": "cannot be met", "nodir": "cannot write"}[case] in err
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ([] if case == "missing" else ["poly.json"])


def test_cli_register_adds_subcommands():
    import argparse

    parser = argparse.ArgumentParser(prog="eyestereo")
    sub = parser.add_subparsers(dest="command")
    cli_ffc.register(sub)
    args = parser.parse_args(["ffc", "p.json", "-o", "q.json"])
    assert (args.func, args.max_error, args.measure, args.low, args.high) == (cli_ffc.cmd_ffc, 0.01, "mse", 0, 32)
    args = parser.parse_args(["package", "q.json", "-o", "pkg.vhd"])
    assert args.func is cli_ffc.cmd_package and args.name == "stereo_calibration_pkg"
    with pytest.raises(SystemExit):
        parser.parse_args(["ffc", "p.json", "-o", "q.json", "--max-error", "-1"])


def test_table_a2_transcription_totals():
    """Column totals of Table A.2 (sum of word lengths), counted by hand from the thesis."""
    assert {n: sum(Fmt.parse(s).wl for s in col) for n, col in TABLE_A2.items()} == {
        "left_x": 282, "left_y": 301, "right_x": 290, "right_y": 286, "merged": 361}
