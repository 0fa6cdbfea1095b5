"""Elaboration-time parameter checks of the MyHDL blocks and the block catalogue (no simulation)."""

from __future__ import annotations

import numpy as np
import pytest
from myhdl import ResetSignal, Signal

from eyestereo.hdl.catalog import BLOCKS, get
from eyestereo.hdl.convolve import convolve
from eyestereo.hdl.line_delay import line_delay
from eyestereo.hdl.sobel import sobel
from eyestereo.hdl.stream import ImageStream

BINOMIAL3 = np.outer([1, 2, 1], [1, 2, 1])  # sum <= 16 * 255: 8 bits after shift=4, 12 bits with shift=0
BINOMIAL5 = np.outer([1, 4, 6, 4, 1], [1, 4, 6, 4, 1])  # sum <= 256 * 255: 8 bits after shift=8


def ports():
    return Signal(bool(0)), ResetSignal(0, active=1, isasync=False)


def build_line_delay(*, dw=8, source_dw=None, **kw):
    clk, rst = ports()
    return line_delay(clk, rst, ImageStream(dw), ImageStream(dw if source_dw is None else source_dw), **kw)


def build_convolve(*, dw=8, source_dw=8, **kw):
    clk, rst = ports()
    return convolve(clk, rst, ImageStream(dw), ImageStream(source_dw), **kw)


def build_sobel(*, sink_dw=8, source_dw=18, **kw):
    clk, rst = ports()
    return sobel(clk, rst, ImageStream(sink_dw), ImageStream(source_dw), **kw)


# --------------------------------------------------------------------------------------------------
# line_delay


@pytest.mark.parametrize(
    "kw,match",
    [
        (dict(width=0), r"width=0 is too small"),
        (dict(width=-1), r"width=-1 is too small"),
        (dict(width=5000), r"width=5000 is too large"),
        (dict(width=3.5), r"width must be an int"),
        (dict(width=True), r"width must be an int"),
        (dict(height=0), r"height=0 is too small"),
        (dict(height=4097), r"height=4097 is too large"),
        (dict(dw=37), r"37 bits.*at most 36"),
        (dict(dw=8, source_dw=9), r"source data width 9 differs from sink's 8"),
        (dict(dw=18, source_dw=9), r"differs"),
    ],
)
def test_line_delay_rejects(kw, match):
    with pytest.raises(ValueError, match=match):
        build_line_delay(**kw)


@pytest.mark.parametrize("kw", [dict(width=1, height=1), dict(width=4096, height=4096), dict(dw=1),
                                dict(dw=36), dict(width=352, height=288)])
def test_line_delay_accepts(kw):
    kw = {"width": 16, "height": 4, **kw}
    assert build_line_delay(**kw) is not None


# --------------------------------------------------------------------------------------------------
# convolve


@pytest.mark.parametrize(
    "kw,match",
    [
        (dict(kernel=np.ones((4, 4), dtype=int)), r"3x3 or 5x5"),
        (dict(kernel=np.ones((7, 7), dtype=int)), r"3x3 or 5x5"),
        (dict(kernel=np.ones((3, 5), dtype=int)), r"3x3 or 5x5"),
        (dict(kernel=np.ones(3, dtype=int)), r"3x3 or 5x5"),
        (dict(col=[1, 2, 1, 1], row=[1, 2, 1, 1]), r"3x3 or 5x5"),
        (dict(kernel=BINOMIAL3, col=[1, 2, 1], row=[1, 2, 1]), r"not both"),
        (dict(kernel=BINOMIAL3, col=[1, 2, 1]), r"not both"),
        (dict(col=[1, 2, 1]), r"needs both col= and row="),
        (dict(row=[1, 2, 1]), r"needs both col= and row="),
        (dict(), r"needs both col= and row="),
        (dict(col=[1, 2, 1], row=[1, 2]), r"equal length"),
        (dict(kernel=[[1, 0.5, 1], [1, 1, 1], [1, 1, 1]]), r"integers"),
        (dict(kernel=np.full((3, 3), 0.5)), r"integers"),
        (dict(kernel=np.full((3, 3), 1 << 16)), r"2\*\*16"),
        (dict(kernel=BINOMIAL3, shift=-1), r"shift must be an int >= 0"),
        (dict(kernel=BINOMIAL3, shift=1.5), r"shift must be an int"),
        (dict(kernel=BINOMIAL3, width=2, height=8), r"width=2 is too small"),
        (dict(kernel=BINOMIAL3, width=8, height=2), r"height=2 is too small"),
        (dict(kernel=BINOMIAL5, shift=8, width=8, height=4), r"height=4 is too small"),
        (dict(kernel=BINOMIAL5, shift=8, width=4, height=8), r"width=4 is too small"),
        (dict(col=[1, 4, 6, 4, 1], row=[1, 4, 6, 4, 1], shift=8, width=4, height=8), r"width=4 is too small"),
        (dict(kernel=BINOMIAL3, shift=4, width=5000), r"width=5000 is too large"),
        (dict(kernel=BINOMIAL3, shift=0, source_dw=8), r"needs 12 data bits.*has 8"),
        (dict(kernel=BINOMIAL3, shift=4, source_dw=9), r"needs 8 data bits.*has 9"),
        (dict(col=[1, 0, -1], row=[1, 2, 1], shift=0, source_dw=10), r"needs 11 data bits"),
    ],
)
def test_convolve_rejects(kw, match):
    kw = {"width": 8, "height": 8, "shift": 4, **kw}
    with pytest.raises(ValueError, match=match):
        build_convolve(**kw)


@pytest.mark.parametrize(
    "kw,source_dw",
    [
        # Elaboration is slow (MyHDL inspects the call stack for every block), so only a few cases.
        pytest.param(dict(kernel=BINOMIAL3, shift=4, width=3, height=3), 8, id="3x3-in-3x3-frame"),
        pytest.param(dict(kernel=BINOMIAL5, shift=8, width=5, height=5), 8, id="5x5-in-5x5-frame"),
        pytest.param(dict(col=[1, 4, 6, 4, 1], row=[1, 4, 6, 4, 1], shift=8, width=5, height=5), 8,
                     id="separable-5x5-in-5x5-frame"),
        pytest.param(dict(kernel=[[-1, 0, 1], [-2, 0, 2], [-1, 0, 1]], shift=0, width=7, height=3), 11,
                     id="signed-output"),
        pytest.param(dict(kernel=np.zeros((3, 3), dtype=int), shift=0, width=3, height=3), 1,
                     id="zero-kernel-1-bit"),
    ],
)
def test_convolve_accepts(kw, source_dw):
    assert build_convolve(source_dw=source_dw, **kw) is not None


def test_convolve_rejects_non_integer_separable_factors():
    # outer([0.5, 1, 0.5], [2, 4, 2]) is the integer binomial kernel, but a 0.5 cannot be a shift-add
    # coefficient: each factor must be integral on its own.
    with pytest.raises(ValueError, match="integer"):
        build_convolve(col=[0.5, 1, 0.5], row=[2, 4, 2], shift=4, width=8, height=8, source_dw=8)


# --------------------------------------------------------------------------------------------------
# sobel


@pytest.mark.parametrize(
    "kw,match",
    [
        (dict(sink_dw=7), r"8-bit pixels.*7"),
        (dict(sink_dw=9), r"8-bit pixels.*9"),
        (dict(source_dw=16), r"18 bits.*16"),
        (dict(source_dw=19), r"18 bits.*19"),
        (dict(width=2), r"width=2 is too small"),
        (dict(height=2), r"height=2 is too small"),
        (dict(width=4097), r"width=4097 is too large"),
        (dict(width=8.0), r"width must be an int"),
    ],
)
def test_sobel_rejects(kw, match):
    kw = {"width": 8, "height": 8, **kw}
    with pytest.raises(ValueError, match=match):
        build_sobel(**kw)


@pytest.mark.parametrize("w,h", [(3, 3)])  # the catalogue test elaborates the default 352x288
def test_sobel_accepts(w, h):
    assert build_sobel(width=w, height=h) is not None


# --------------------------------------------------------------------------------------------------
# ImageStream


@pytest.mark.parametrize("dw", [0, -3, 2.0, "8", None])
def test_image_stream_rejects_bad_width(dw):
    with pytest.raises(ValueError, match="data_width"):
        ImageStream(dw)


def test_image_stream_fields():
    s = ImageStream(18)
    assert len(s.data) == 18
    assert s.fields() == ["data", "valid", "eol", "eof"]
    st = ImageStream(8, stereo=True)
    assert st.fields()[-1] == "cam" and hasattr(st, "cam")


# --------------------------------------------------------------------------------------------------
# Catalogue


def test_catalog_unknown_block():
    with pytest.raises(ValueError, match=r"unknown block 'nope'.*sobel"):
        get("nope")


def test_catalog_unknown_parameter():
    with pytest.raises(ValueError, match=r"sobel has no parameter.*bogus"):
        BLOCKS["sobel"].params(bogus=1)


def test_catalog_get_returns_the_entry():
    for name, spec in BLOCKS.items():
        assert get(name) is spec
        assert spec.name == name


def test_catalog_params_override_and_keep_defaults():
    p = BLOCKS["line_delay"].params(width=64)
    assert p["width"] == 64 and p["height"] == BLOCKS["line_delay"].defaults["height"]
    assert BLOCKS["line_delay"].defaults["width"] == 352  # the override did not leak into the defaults


def test_catalog_has_the_expected_blocks():
    assert {"line_delay", "convolve", "sobel"} <= set(BLOCKS)


@pytest.mark.parametrize("name", sorted(BLOCKS))
def test_catalog_default_configuration_elaborates(name):
    spec = BLOCKS[name]
    inst, ports_, p = spec.elaborate()
    assert inst is not None
    assert p == spec.params()
    if spec.ports is not None:  # a block with its own interfaces: the ports its spec declares
        assert list(ports_) == list(spec.ports(p)) and list(ports_)[:2] == ["clk", "rst"]
        return
    assert set(ports_) == {"clk", "rst", "sink", "source"} | {n for n, _ in spec.control}
    assert len(ports_["sink"].data) == spec.sink_width(spec.params())
    assert len(ports_["source"].data) == spec.source_width(spec.params())


@pytest.mark.parametrize(
    "name,sink,source",
    [("line_delay", 8, 8), ("sobel", 8, 18), ("convolve", 8, 8),  # convolve default: 3x3 binomial / 16
     ("harris_window", 18, 57), ("cornerness", 57, 20), ("prethreshold", 20, 20), ("nms", 20, 1),
     ("harris_mono", 8, 1)],
)
def test_catalog_default_widths_hand_computed(name, sink, source):
    spec = BLOCKS[name]
    p = spec.params()
    assert spec.sink_width(p) == sink
    assert spec.source_width(p) == source


def test_catalog_overrides_reach_the_block():
    spec = BLOCKS["convolve"]
    _, ports_, p = spec.elaborate(shift=0, width=16, height=8)
    assert len(ports_["source"].data) == 12  # 16 * 255 needs 12 bits without the shift
    with pytest.raises(ValueError, match="too small"):
        BLOCKS["sobel"].elaborate(width=2)
