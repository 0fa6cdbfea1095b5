"""Elaboration checks of fetch_interpolate and rectifier: bad ports and parameters give one ValueError that
names the block and the port or parameter; the catalogue entries are sized from the calibration; the
models' interpolation against a float bilinear reference and the reuse rule against a brute-force one."""

import numpy as np
import pytest
from myhdl import ResetSignal, Signal, intbv

from eyestereo.hdl.flow.catalog import BLOCKS
from eyestereo.hdl.interfaces.coord_pair import CoordPair
from eyestereo.hdl.interfaces.fetch_port import FetchPort
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.hdl.rectify.calibration import calibration_param
from eyestereo.hdl.rectify.fetch_interpolate import fetch_interpolate
from eyestereo.hdl.rectify.rectifier import rectifier
from eyestereo.tools.models import fetch_interpolate as fi

SPEC = "seed:3:2@40x20"


def fi_ports(**over):
    p = dict(clk=Signal(bool(0)), rst=ResetSignal(0, active=1, isasync=False), coord=CoordPair(352, 288, 5),
             fetch=FetchPort(352, 288), source=ImageStream(8, stereo=True), busy=Signal(bool(0)))
    p.update(over)
    return p


def test_fetch_interpolate_elaborates():
    assert fetch_interpolate(*fi_ports().values()) is not None
    assert fetch_interpolate(*fi_ports(coord=CoordPair(64, 48, 0), fetch=FetchPort(64, 48)).values(), depth=1)


@pytest.mark.parametrize("over,kw,match", [
    (dict(rst=Signal(bool(0))), {}, "fetch_interpolate: port rst"),
    (dict(clk=ResetSignal(0, active=1, isasync=False)), {}, "port clk must be the clock"),
    (dict(coord=Signal(bool(0))), {}, "port coord must be a CoordPair"),
    (dict(fetch=ImageStream(8)), {}, "port fetch must be a FetchPort"),
    (dict(fetch=FetchPort(320, 240)), {}, "port fetch is sized for 320x240 images, port coord for 352x288"),
    (dict(source=ImageStream(8)), {}, "port source must be a stereo stream"),
    (dict(source=ImageStream(9, stereo=True)), {}, "port source must carry 8-bit data"),
    (dict(busy=Signal(intbv(0)[2:])), {}, "port busy must be 1 bit wide"),
    (dict(coord=CoordPair(352, 288, 9)), {}, "frac=9; the interpolation takes at most 8"),
    ({}, dict(depth=0), "parameter depth=0 is too small"),
    ({}, dict(depth=17), "parameter depth=17 is too large"),
    ({}, dict(depth=2.0), "parameter depth must be an integer"),
    ({}, dict(depth=True), "parameter depth must be an integer"),
])
def test_fetch_interpolate_rejects(over, kw, match):
    with pytest.raises(ValueError, match=match) as e:
        fetch_interpolate(*fi_ports(**over).values(), **kw)
    assert "\n" not in str(e.value)


def test_fetch_interpolate_outputs_need_their_own_signals():
    p = fi_ports()
    p["busy"] = p["coord"].valid
    with pytest.raises(ValueError, match="share a signal"):
        fetch_interpolate(*p.values())


def rect_ports(**over):
    p = dict(clk=Signal(bool(0)), rst=ResetSignal(0, active=1, isasync=False), start=Signal(bool(0)),
             fetch=FetchPort(352, 288), source=ImageStream(8, stereo=True), busy=Signal(bool(0)))
    p.update(over)
    return p


@pytest.mark.parametrize("over,kw,match", [
    (dict(start=Signal(intbv(0)[3:])), dict(quantizers=SPEC), "rectifier: port start must be 1 bit wide"),
    (dict(fetch=FetchPort(40, 20)), dict(quantizers=SPEC), "camera images are 352x288"),
    (dict(source=ImageStream(8)), dict(quantizers=SPEC), "port source must be a stereo stream"),
    ({}, dict(quantizers=SPEC, frac=9), "parameter frac=9: the interpolation takes at most 8"),
    ({}, dict(quantizers="nope"), "rectifier: parameter quantizers: unknown calibration spec"),
    ({}, dict(quantizers=SPEC, depth=99), "parameter depth=99 is too large"),
])
def test_rectifier_rejects(over, kw, match):
    with pytest.raises(ValueError, match=match) as e:
        rectifier(*rect_ports(**over).values(), **kw)
    assert "\n" not in str(e.value)


def test_catalogue_entries():
    for name in ("fetch_interpolate", "rectifier"):
        spec = BLOCKS[name]
        assert spec.params()["quantizers"] == "rig" and spec.params()["depth"] == 4
        _, ports, _ = spec.elaborate(quantizers=SPEC)
        assert ports["fetch"].width == 352 and ports["source"].stereo and ports["source"].data_width == 8
    _, ports, _ = BLOCKS["rectifier"].elaborate(quantizers=SPEC, coefficients="register")
    assert list(ports) == ["clk", "rst", "start", "fetch", "source", "busy", "coef"]
    _, ports, _ = BLOCKS["fetch_interpolate"].elaborate(quantizers=SPEC, frac=3)
    assert list(ports) == ["clk", "rst", "coord", "fetch", "source", "busy"] and ports["coord"].frac == 3


# ------------------------------------------------------------------ the models


@pytest.mark.parametrize("frac", [0, 1, 5, 8])
def test_interpolation_is_rounded_bilinear(frac):
    """The hardware's integer arithmetic against a float bilinear interpolation: within 0.5 grey levels
    (only the final rounding), ties rounded up."""
    rng = np.random.default_rng(frac)
    img = rng.integers(0, 256, (30, 40), dtype=np.uint8)
    n = 5000
    x = rng.integers(0, 39 << frac, n)
    y = rng.integers(0, 29 << frac, n)
    oor = (rng.random(n) < 0.1).astype(np.int64)
    got = fi.interpolate(img, x, y, oor, frac).astype(np.float64)
    s = 1 << frac
    fx, fy = x / s, y / s
    x0, y0 = np.floor(fx).astype(int), np.floor(fy).astype(int)
    ax, ay = fx - x0, fy - y0
    f = img.astype(np.float64)
    ref = ((1 - ax) * (1 - ay) * f[y0, x0] + ax * (1 - ay) * f[y0, x0 + 1] + (1 - ax) * ay * f[y0 + 1, x0]
           + ax * ay * f[y0 + 1, x0 + 1])
    ok = oor == 0
    assert np.all(got[~ok] == 0)
    d = got[ok] - ref[ok]
    assert np.all((d > -0.5 - 1e-9) & (d <= 0.5 + 1e-9))
    assert np.array_equal(got[ok], np.floor(ref[ok] + 0.5))


def test_weights_sum_and_order():
    w = fi.weights(np.array([3]), np.array([5]), 3)[:, 0]
    assert list(w) == [15, 5 * 5, 3 * 3, 5 * 3] and w.sum() == 64


def test_reuse_rule_brute_force():
    """Each (ddx, ddy): the pixels not requested are exactly those of the previous 2x2."""
    for (ddx, ddy), (mask, src) in fi.REUSE.items():
        prev = {(ox, oy) for ox in (0, 1) for oy in (0, 1)}
        for i, (ox, oy) in enumerate(fi.OFFSETS):
            p = (ox + ddx, oy + ddy)
            assert bool((mask >> i) & 1) == (p not in prev)
            if p in prev:
                assert fi.OFFSETS[src[i]] == p


def test_requests_reuse_and_frames():
    """A left side moving right by one pixel asks for the right column; the neighbourhood is emptied after
    eof; black sides send nothing."""
    f = 2
    xl = np.array([10, 11, 11, 11, 30, 12]) << f
    yl = np.array([5, 5, 5, 6, 2, 6]) << f
    pairs = dict(xl=xl, yl=yl, xr=xl, yr=yl, oor_l=np.array([0, 0, 0, 0, 0, 0]), oor_r=np.array([1, 1, 1, 1, 1, 0]),
                 eof=np.array([0, 0, 1, 0, 0, 0]))
    r = fi.requests(pairs, f)
    assert list(r["mask"]) == [15, 0b0101, 15, 15, 15, 15]  # pair 2 repeats pair 1 (no request); eof empties
    assert list(r["cam"]) == [0, 0, 0, 0, 0, 1]
    assert list(r["x"]) == [10, 11, 11, 30, 12, 12] and fi.reads(r["mask"]) == 22


def test_rectifier_model_checks_images():
    from eyestereo.tools.models.rectifier import rectifier as model

    cal = calibration_param(SPEC)
    with pytest.raises(ValueError, match="left image is 40x20; the calibration was made for 352x288"):
        model(cal, np.zeros((20, 40), np.uint8), np.zeros((288, 352), np.uint8))
    with pytest.raises(ValueError, match="right image must be a 2-D uint8"):
        model(cal, np.zeros((288, 352), np.uint8), np.zeros((288, 352), np.float32))
