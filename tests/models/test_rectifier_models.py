"""The rectification hardware's models (poly_unit, coordinate_warper) against independent references.

References: the float64 polynomials (the fit before the float-to-fixed conversion), the exact maps of
the rig, a scalar ``fractions.Fraction`` re-implementation of the range check and the cut, and plain
Python loops for the pair order. Nothing expected is produced by the code under test.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

from eyestereo.tools.fixed import Fmt, ufix
from eyestereo.tools.models import coordinate_warper as warp_model
from eyestereo.tools.models import poly_unit as unit
from eyestereo.tools.rectify import calibrations
from eyestereo.tools.rectify.ffc import POLY_NAMES, FFCError, fixed_stages_codes, fixed_stages, float_eval
from eyestereo.tools.reports.bench_ffc import synthetic_rig_polynomials
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH

SMALL = "seed:3:2@40x20"


@pytest.fixture(scope="module")
def small():
    return unit.Calibration.load(SMALL)


@pytest.fixture(scope="module")
def rig_doc():
    return calibrations.load("rig")


def test_fixed_stages_codes_is_fixed_stages_with_the_codes(rig_doc):
    polys = synthetic_rig_polynomials(FRAME_WIDTH, FRAME_HEIGHT)
    fm = rig_doc["_formats"]
    for n in POLY_NAMES:
        a = fixed_stages(polys[n], fm, FRAME_WIDTH, FRAME_HEIGHT)
        b = fixed_stages_codes(rig_doc["polynomials"][n]["codes"], fm, FRAME_WIDTH, FRAME_HEIGHT)
        assert all(np.array_equal(np.asarray(a[q]), np.asarray(b[q])) for q in range(1, 27))


def test_fixed_stages_codes_rejects_codes_that_do_not_fit(rig_doc):
    codes = list(rig_doc["polynomials"]["left_x"]["codes"])
    codes[0] = rig_doc["_formats"][0].hi + 1
    with pytest.raises(FFCError, match="code .* of p1 does not fit q1"):
        fixed_stages_codes(codes, rig_doc["_formats"], 4, 4)
    with pytest.raises(FFCError, match="p1..p10"):
        fixed_stages_codes(codes[:9], rig_doc["_formats"], 4, 4)


def test_default_calibration_is_the_synthetic_rig(rig_doc):
    cal = unit.Calibration.from_doc(rig_doc)
    assert (cal.width, cal.height, cal.source_width, cal.source_height) == (352, 288, 352, 288)
    assert unit.resolve_frac(cal) == cal.out_format.fl == 5  # coordinates ufix[14,5], as the thesis's
    assert unit.coord_format(5, 352) == ufix(14, 5)
    polys = synthetic_rig_polynomials(FRAME_WIDTH, FRAME_HEIGHT)
    assert rig_doc["float_polynomials"] == polys


def test_model_follows_the_float_polynomials_within_the_ffc_bound(rig_doc):
    """q24 against the float64 polynomial: the FFC's bound (mse 0.01 px^2 per polynomial) holds."""
    cal = unit.Calibration.from_doc(rig_doc)
    ev = unit.evaluate(cal)
    for n in POLY_NAMES:
        v = ev[n]["q24"] * 2.0 ** -cal.out_format.fl
        ref = float_eval(rig_doc["float_polynomials"][n], FRAME_WIDTH, FRAME_HEIGHT)
        assert np.mean((v - ref) ** 2) <= 0.01
        assert np.max(np.abs(v - ref)) < 0.25


def test_model_follows_the_exact_maps_of_a_seeded_rig():
    """End to end: the warper's coordinates against the rig's exact maps (fit + quantization error)."""
    from eyestereo.tools.rectify.maps import ground_truth_maps

    cal = unit.Calibration.load("seed:1")
    maps = ground_truth_maps(calibrations.seeded_rig(1, 1.0))
    pairs = warp_model.coordinate_warper(cal)
    frac = unit.resolve_frac(cal)
    inside = (pairs["oor_l"] == 0) & (pairs["oor_r"] == 0)
    for key, field in (("left_x", "xl"), ("left_y", "yl"), ("right_x", "xr"), ("right_y", "yr")):
        err = pairs[field][inside] / 2 ** frac - getattr(maps, key)[inside]
        assert np.sqrt(np.mean(err ** 2)) < 0.15, key
        assert np.max(np.abs(err)) < 0.5, key


def _ref_cut_and_flag(code: int, f24: Fmt, frac: int, size: int, nbits: int) -> tuple[int, int]:
    v = Fraction(code, 1) * Fraction(2) ** -f24.fl
    oor = int(v < 0 or v > size - 2)
    cut = math.floor(v * 2 ** frac) % (1 << nbits)
    return cut, oor


@pytest.mark.parametrize("fl", [-2, 0, 3, 5, 9])
@pytest.mark.parametrize("frac", [0, 4, 7])
def test_cut_and_range_check_against_fractions(fl, frac):
    f24 = Fmt(True, 14, fl)
    size = 37
    nbits = unit.int_bits(size) + frac
    codes = np.arange(f24.lo, f24.hi + 1, 37 if fl > 3 else 1)
    lim = unit.range_limit(f24, size)
    got_cut = unit.cut(codes, f24, frac, nbits)
    got_oor = (codes < 0) | (codes > lim)
    for c, gc, go in zip(codes, got_cut, got_oor):
        assert (int(gc), int(go)) == _ref_cut_and_flag(int(c), f24, frac, size, nbits), c
    # the limit is the exact boundary: its code is in range, the next one out (when the format reaches it)
    if lim < f24.hi:
        assert _ref_cut_and_flag(lim, f24, frac, size, nbits)[1] == 0
        assert _ref_cut_and_flag(lim + 1, f24, frac, size, nbits)[1] == 1


def test_pairs_in_raster_order_with_stream_flags(small):
    frac = unit.resolve_frac(small)
    p = warp_model.pairs(small, frac, frames=2)
    ev = unit.evaluate(small, frac)
    w, h = small.width, small.height
    k = 0
    for _frame in range(2):
        for y in range(h):
            for x in range(w):
                assert p["xl"][k] == ev["left_x"]["coord"][y, x] and p["yr"][k] == ev["right_y"]["coord"][y, x]
                assert p["oor_l"][k] == (ev["left_x"]["oor"][y, x] | ev["left_y"]["oor"][y, x])
                assert p["oor_r"][k] == (ev["right_x"]["oor"][y, x] | ev["right_y"]["oor"][y, x])
                assert p["eol"][k] == (x == w - 1) and p["eof"][k] == (x == w - 1 and y == h - 1)
                k += 1
    assert k == len(p["xl"])


def test_pair_word_round_trip(small):
    frac = unit.resolve_frac(small)
    word = warp_model.pair_word(small, frac)
    assert word.names == warp_model.PAIR_FIELDS
    assert word.field("xl").fmt == unit.coord_format(frac, small.source_width)
    p = warp_model.pairs(small, frac)
    codes = word.pack(p)
    bits = ((codes[:, None] >> np.arange(word.width)) & 1).astype(np.uint8)
    back = warp_model.decode_words(bits, word)
    assert all(np.array_equal(back[f], p[f]) for f in word.names)


def test_poly_unit_model_sequence_matches_the_grid(small):
    rng = np.random.default_rng(2)
    x = rng.integers(0, small.width, 300)
    y = rng.integers(0, small.height, 300)
    sel = rng.integers(0, 8, 300)
    coord, oor = unit.poly_unit(small, x, y, sel, 4)
    ev = unit.evaluate(small, 4)
    nb = unit.coord_bits(small, 4)
    for k in range(300):
        name = POLY_NAMES[sel[k] & 3]
        q24 = int(ev[name]["q24"][y[k], x[k]])
        size = small.source_height if sel[k] & 1 else small.source_width
        assert (int(coord[k]), int(oor[k])) == _ref_cut_and_flag(q24, small.out_format, 4, size, nb)


def test_register_writes_and_their_checks(small):
    w = unit.register_writes(small.codes, small.formats)
    assert len(w) == 40 and len({a for a, _ in w}) == 40 and max(a for a, _ in w) == 39
    for addr, data in w:
        i, idx = addr >> 2, addr & 3
        f = small.formats[i]
        assert data == small.codes[idx][i] & ((1 << f.wl) - 1) and 0 <= data < 1 << unit.coef_data_bits(small.formats)
    bad = [list(r) for r in small.codes]
    bad[2][4] = small.formats[4].hi + 1
    with pytest.raises(ValueError, match="right_x: code .* of p5 does not fit"):
        unit.register_writes(bad, small.formats)
    with pytest.raises(ValueError, match="p5 does not fit"):
        small.with_codes(bad)


@pytest.mark.parametrize("spec,match", [
    ("nope", "unknown calibration spec"), ("seed:x", "seed:N"), ("seed:1:-2", "spread"),
    ("rig:1x5", "bad size"), ("seed:1@40", "bad size")])
def test_calibration_specs_refused(spec, match):
    with pytest.raises(ValueError, match=match):
        calibrations.load(spec)


def test_calibration_file_errors(tmp_path):
    with pytest.raises(ValueError, match="does not exist"):
        calibrations.load(tmp_path / "missing.json")
    (tmp_path / "bad.json").write_text("{")
    with pytest.raises(ValueError, match="not valid JSON"):
        calibrations.load(str(tmp_path / "bad.json"))


def test_resolve_frac():
    cal = unit.Calibration.load(SMALL)
    assert unit.resolve_frac(cal, 0) == 0 and unit.resolve_frac(cal, 16) == 16
    for bad in (-1, 17, 2.0, True, "5"):
        with pytest.raises(ValueError, match="frac"):
            unit.resolve_frac(cal, bad)
