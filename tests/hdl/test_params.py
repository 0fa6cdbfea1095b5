"""Elaboration-time parameter checks of the MyHDL blocks and the block catalogue (no simulation)."""

from __future__ import annotations

import numbers
import re
import warnings

import numpy as np
import pytest
from myhdl import ResetSignal, Signal, intbv

from eyestereo.hdl.flow.catalog import BLOCKS, get
from eyestereo.hdl.streaming.convolve import convolve
from eyestereo.hdl.streaming.line_delay import line_delay
from eyestereo.hdl.harris.sobel import sobel
from eyestereo.hdl.interfaces.stream import ImageStream

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
        (dict(kernel=BINOMIAL3, shift=-1), r"parameter shift=-1 is too small: at least 0"),
        (dict(kernel=BINOMIAL3, shift=1.5), r"parameter shift must be an integer, got float 1.5"),
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
        (dict(sink_dw=7), r"port sink must carry 8-bit data, got an ImageStream of 7 bits"),
        (dict(sink_dw=9), r"port sink must carry 8-bit data.*9 bits"),
        (dict(source_dw=16), r"port source must carry 18-bit data.*16 bits"),
        (dict(source_dw=19), r"port source must carry 18-bit data.*19 bits"),
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
    if spec.build is not None:  # multi-clock and camera blocks: their ports are checked in test_camera_params
        return
    assert set(ports_) == {"clk", "rst", "sink", "source"} | set(spec.control_names())
    # ImageStream and AxiStream both carry data_width (an AxiStream pads tdata to whole bytes)
    assert ports_["sink"].data_width == spec.sink_width(spec.params())
    assert ports_["source"].data_width == spec.source_width(spec.params())


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


# --------------------------------------------------------------------------------------------------
# Bad block input, every catalogue block (docs/bad_input.md, "Blocks"): each class of mistake a user can
# make when instantiating a block ends in one ValueError that starts with the block's name and names the
# port or parameter, never in a MyHDL or Python internal error. New catalogue blocks are covered too.


SMALL_FRAME = dict(width=16, height=8, lines=4)  # lines: the line cache's (at most the height)


#: Blocks with the standard ports (clk, rst, sink, source, control); the others (several clocks, other
#: interfaces) have their own port tests next to their benches.
STANDARD = sorted(n for n, s in BLOCKS.items() if s.build is None)


def _small(spec):
    small = {k: v for k, v in SMALL_FRAME.items() if k in spec.defaults}
    if "disparities" in spec.defaults and "width" in spec.defaults:
        small.update(width=24, disparities=16)  # the dense blocks' frame must be wider than D
    if "lead" in spec.defaults and "border" in spec.defaults:
        small.update(height=16)  # corner_descriptors: a corner 4 (the border) from each edge needs 9 rows
    return small


def _call(spec, ports, kw):
    return spec.func(*ports.values(), **kw)


def _port_names(spec):
    return ["clk", "rst", "sink", "source"] + spec.control_names(**_small(spec))


def _expect(name, match, spec, ports, kw):
    with pytest.raises(ValueError) as e:
        _call(spec, ports, kw)
    msg = str(e.value)
    assert msg.startswith(f"{name}: "), f"the message does not start with the block's name: {msg!r}"
    assert "\n" not in msg, f"not one line: {msg!r}"
    assert re.search(match, msg), f"{msg!r} does not match {match!r}"
    return msg


def _expect_port(name, port, value, match):
    """Block ``name`` in its small configuration with ``value`` on ``port`` (the other ports as the catalog
    makes them): refused with a message matching ``match``."""
    spec = BLOCKS[name]
    ports, kw, _ = spec.ports(**_small(spec))
    ports[port] = value
    _expect(name, match, spec, ports, kw)


BAD_PORT_VALUES = {
    "None": (lambda port: None, r"got None"),
    "int": (lambda port: 1, r"got int 1"),
    "str": (lambda port: port, r"got str"),
}


@pytest.mark.parametrize("bad", sorted(BAD_PORT_VALUES))
@pytest.mark.parametrize("name", STANDARD)
def test_every_port_refuses_none_int_str(name, bad):
    make, match = BAD_PORT_VALUES[bad]
    for port in _port_names(BLOCKS[name]):
        _expect_port(name, port, make(port), rf"port {port} .*{match}")


@pytest.mark.parametrize("name", STANDARD)
def test_reset_must_be_synchronous_active_high_reset_signal(name):
    for rst, match in ((Signal(bool(0)), r"port rst must be a ResetSignal\(0, active=1, isasync=False\), got a Signal"),
                       (ResetSignal(0, active=1, isasync=True), r"port rst is an asynchronous reset"),
                       (ResetSignal(1, active=0, isasync=False), r"port rst is an active-low reset"),
                       (ResetSignal(1, active=0, isasync=True), r"port rst is an asynchronous active-low reset")):
        _expect_port(name, "rst", rst, match)


@pytest.mark.parametrize("name", STANDARD)
def test_clock_must_be_a_bool_signal(name):
    for clk, match in ((Signal(intbv(0)[1:]), r"port clk must be a 1-bit Signal\(bool\(0\)\), got a 1-bit unsigned"),
                       (ResetSignal(0, active=1, isasync=False), r"port clk must be the clock.*swapped")):
        _expect_port(name, "clk", clk, match)


@pytest.mark.parametrize("name", STANDARD)
def test_streams_and_control_ports_swapped(name):
    """A Signal where a stream belongs and a stream where a Signal belongs (ports out of order)."""
    spec = BLOCKS[name]
    for port in ("sink", "source"):
        ports, kw, _ = spec.ports(**_small(spec))
        kind = type(ports[port]).__name__  # ImageStream, or AxiStream for the bridges' AXI side
        ports[port] = Signal(intbv(0)[8:])
        _expect(name, rf"port {port} must be an {kind}, got an 8-bit unsigned Signal", spec, ports, kw)
    for port in spec.control_names(**_small(spec)):
        _expect_port(name, port, ImageStream(8), rf"port {port} must be a MyHDL Signal, got an ImageStream")


@pytest.mark.parametrize("name", STANDARD)
def test_wrong_stream_widths(name):
    spec = BLOCKS[name]
    for port in ("sink", "source"):
        ports, kw, _ = spec.ports(**_small(spec))
        n = ports[port].data_width
        ports[port] = type(ports[port])(n + 1)  # the same kind of interface (ImageStream or AxiStream)
        # Blocks that take any sink width (line_delay, convolve, stream_checker) blame the source.
        _expect(name, rf"port (sink|source) .*({n}.*{n + 1}|{n + 1}.*{n})", spec, ports, kw)


@pytest.mark.parametrize("name", STANDARD)
def test_control_port_widths_and_kinds(name):
    spec = BLOCKS[name]
    for port in spec.control_names(**_small(spec)):
        ports, kw, _ = spec.ports(**_small(spec))
        n = 1 if isinstance(ports[port].val, bool) else len(ports[port])
        if port == "thr_addr":  # at least log2(blocks) bits: more are fine, fewer are not
            ports[port] = Signal(intbv(0)[1:])
            kw = dict(kw, blocks=(4, 4))
            _expect(name, r"port thr_addr needs 4 bits for 16 blocks, has 1", spec, ports, kw)
            continue
        ports[port] = Signal(intbv(0)[n + 1:])
        _expect(name, rf"port {port} must be {n} bits? wide, got {n + 1}", spec, ports, kw)
        ports, kw, _ = spec.ports(**_small(spec))
        ports[port] = Signal(intbv(0))
        _expect(name, rf"port {port} has no bit width", spec, ports, kw)
        if n > 1 and port in ("k", "thr_data"):  # code bits: a signed Signal would be read as a number
            ports, kw, _ = spec.ports(**_small(spec))
            ports[port] = Signal(intbv(0, min=-(1 << (n - 1)), max=1 << (n - 1)))
            _expect(name, rf"port {port} must be unsigned, got an? {n}-bit signed", spec, ports, kw)


@pytest.mark.parametrize("name", STANDARD)
def test_an_output_port_needs_signals_of_its_own(name):
    spec = BLOCKS[name]
    ports, kw, _ = spec.ports(**_small(spec))
    same_kind = type(ports["sink"]) is type(ports["source"])
    if same_kind and ports["sink"].data_width == ports["source"].data_width:
        ports["source"] = ports["sink"]
        _expect(name, r"ports source and sink share a signal; the output port source", spec, ports, kw)
    ports, kw, _ = spec.ports(**_small(spec))
    # one field shared: the valid of each side (tvalid on an AXI4-Stream port)
    src_valid = "valid" if hasattr(ports["source"], "valid") else "tvalid"
    snk_valid = "valid" if hasattr(ports["sink"], "valid") else "tvalid"
    setattr(ports["source"], src_valid, getattr(ports["sink"], snk_valid))
    _expect(name, r"ports source and sink share a signal", spec, ports, kw)


@pytest.mark.parametrize("name", STANDARD)
def test_stereo_streams_forwarded_or_refused(name):
    """The stereo rule: a block with a ``stereo`` parameter takes stereo streams (and forwards cam);
    every other block refuses a stereo sink, and a stereo source, with the same message."""
    spec = BLOCKS[name]
    if "stereo" in spec.defaults:
        inst, ports, _ = spec.elaborate(stereo=True, **_small(spec))
        assert inst is not None and ports["sink"].stereo and ports["source"].stereo
        ports, kw, _ = spec.ports(stereo=True, **_small(spec))
        ports["source"] = ImageStream(ports["source"].data_width)
        _expect(name, r"port source must be a stereo stream", spec, ports, kw)
        return
    for port in ("sink", "source"):
        ports, kw, _ = spec.ports(**_small(spec))
        if not isinstance(ports[port], ImageStream):
            continue  # an AXI4-Stream port has no stereo form (the bridges take mono streams)
        ports[port] = ImageStream(ports[port].data_width, stereo=True)
        _expect(name, rf"port {port} is a stereo stream \(with cam\); this block takes mono streams only", spec,
                ports, kw)


def _int_params(spec):
    return [k for k in spec.hw_params if isinstance(spec.defaults.get(k), int)
            and not isinstance(spec.defaults.get(k), bool)]


@pytest.mark.parametrize("name", sorted(BLOCKS))
def test_float_parameters_refused(name):
    spec = BLOCKS[name]
    for p in _int_params(spec):
        ports, kw, params = spec.ports(**_small(spec))
        kw[p] = float(params[p])
        _expect(name, rf"parameter {p} must be (an integer|one of .*), got float", spec, ports, kw)
    for p in spec.hw_params:
        v = spec.defaults.get(p)
        ports, kw, params = spec.ports(**_small(spec))
        if isinstance(v, tuple) and len(v) == 2 and all(isinstance(x, int) for x in v):  # (BX, BY)
            kw[p] = (float(v[0]),) + tuple(v[1:])
            _expect(name, rf"parameter {p} must be a pair of ints", spec, ports, kw)
        elif isinstance(v, bool):
            kw[p] = 1
            _expect(name, rf"parameter {p} must be True or False, got int 1", spec, ports, kw)


@pytest.mark.parametrize("name", sorted(BLOCKS))
def test_bool_and_string_parameters_refused(name):
    spec = BLOCKS[name]
    for p in _int_params(spec):
        for bad in (True, "8"):
            ports, kw, _ = spec.ports(**_small(spec))
            kw[p] = bad
            _expect(name, rf"parameter {p} must be", spec, ports, kw)


@pytest.mark.parametrize("name", sorted(BLOCKS))
def test_numpy_integer_parameters_accepted(name):
    """numpy integers for every integer parameter elaborate (and are ints from there on)."""
    spec = BLOCKS[name]
    ports, kw, params = spec.ports(**_small(spec))
    for p in _int_params(spec):
        kw[p] = np.int64(params[p])
    for p in spec.hw_params:
        v = params.get(p)
        if isinstance(v, tuple) and all(isinstance(x, numbers.Integral) for x in v):
            kw[p] = tuple(np.int32(x) for x in v)
    assert _call(spec, ports, kw) is not None


@pytest.mark.parametrize("name", ["line_delay", "nms", "prethreshold", "stream_checker"])
def test_numpy_integer_parameters_convert(name, tmp_path):
    """... and convert: MyHDL's intbv refuses numpy integers, so the blocks must pass on Python ints."""
    spec = BLOCKS[name]
    ports, kw, params = spec.ports(**_small(spec))
    kw = {k: (np.int64(v) if k in _int_params(spec) else v) for k, v in kw.items()}
    if "blocks" in kw:
        kw["blocks"] = (np.int64(2), np.int64(2))
    inst = _call(spec, ports, kw)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # unread outputs of inner blocks
        inst.convert(hdl="VHDL", name=f"np_{name}", path=str(tmp_path), initial_values=False)
    assert (tmp_path / f"np_{name}.vhd").exists()


@pytest.mark.parametrize("name,kw,match", [
    ("nms", dict(size=3.0), r"parameter size must be one of \[1, 3, 5\], got float 3.0"),
    ("nms", dict(size=np.int64(5)), None),
    ("nms", dict(size=4), r"parameter size must be one of \[1, 3, 5\], got int 4"),
    ("harris_mono", dict(nms=3.0), r"parameter nms must be one of \[1, 3, 5\], got float 3.0"),
    ("harris_mono", dict(blocks=(2.0, 2)), r"parameter blocks must be a pair of ints"),
    ("harris_mono", dict(blocks=(np.int64(2), np.int64(3))), None),
    ("harris_mono", dict(blocks=(17, 1)), r"parameter blocks=\(17, 1\): BX and BY must be 1..16"),
    ("prethreshold", dict(blocks=4), r"parameter blocks must be a pair of ints"),
    ("convolve", dict(shift=np.int64(4)), None),
    ("convolve", dict(shift=4.0), r"parameter shift must be an integer, got float 4.0"),
    ("stream_checker", dict(repair="yes"), r"parameter repair must be True or False, got str"),
    ("stream_checker", dict(repair=np.bool_(True)), None),
    ("sobel", dict(width=np.int32(8), height=np.uint16(6)), None),
    ("sobel", dict(width=np.float64(8)), r"parameter width must be an integer, got float64"),
    ("line_delay", dict(width=0), r"parameter width=0 is too small: at least 1"),
    ("line_delay", dict(height=4097), r"parameter height=4097 is too large: at most 4096"),
])
def test_parameter_cases(name, kw, match):
    spec = BLOCKS[name]
    ports, base, _ = spec.ports(**_small(spec))
    base.update(kw)
    if match is None:
        assert _call(spec, ports, base) is not None
    else:
        _expect(name, match, spec, ports, base)


def test_composite_block_names_itself_not_an_inner_block():
    """harris_mono checks every port and parameter itself: no message comes from sobel, nms, ..."""
    spec = BLOCKS["harris_mono"]
    for mutate in (lambda p, k: p.update(sink=ImageStream(8, stereo=True)),
                   lambda p, k: p.update(k=Signal(intbv(0)[7:])),
                   lambda p, k: k.update(nms=7),
                   lambda p, k: p.update(thr_data=None)):
        ports, kw, _ = spec.ports(**_small(spec))
        mutate(ports, kw)
        _expect("harris_mono", r".", spec, ports, kw)


def test_window_machinery_checks_its_arguments():
    from eyestereo.hdl.common import delay
    from eyestereo.hdl.streaming.window import column_taps, window_control

    clk, rst = ports()
    with pytest.raises(ValueError, match=r"column_taps: taps must be a list of at least 2 Signals"):
        column_taps(clk, rst, ImageStream(8), [Signal(intbv(0)[8:])], Signal(bool(0)), width=8, height=4)
    with pytest.raises(ValueError, match=r"column_taps: port taps\[1\] must be 8 bits wide, got 9"):
        column_taps(clk, rst, ImageStream(8), [Signal(intbv(0)[8:]), Signal(intbv(0)[9:])], Signal(bool(0)),
                    width=8, height=4)
    # one machinery for both kinds of stream: the source must be of the sink's kind, share needs stereo
    with pytest.raises(ValueError, match=r"window_control: port source must be a stereo stream"):
        window_control(clk, rst, ImageStream(8, stereo=True), ImageStream(8), width=8, height=4, radius=1,
                       latency=3)
    with pytest.raises(ValueError, match=r"window_control: .*share.*stereo"):
        window_control(clk, rst, ImageStream(8), ImageStream(8), width=8, height=4, radius=1, latency=3, share=2)
    with pytest.raises(ValueError, match=r"window_control: parameter radius must be an integer, got float"):
        window_control(clk, rst, ImageStream(8), ImageStream(8), width=8, height=4, radius=1.0, latency=3)
    with pytest.raises(ValueError, match=r"window_control: parameter latency=0 is too small: at least 1"):
        window_control(clk, rst, ImageStream(8), ImageStream(8), width=8, height=4, radius=1, latency=0)
    with pytest.raises(ValueError, match=r"window_control: a 5x5 window needs a frame larger than 4x2"):
        window_control(clk, rst, ImageStream(8), ImageStream(8), width=4, height=2, radius=2, latency=3)
    with pytest.raises(ValueError, match=r"delay: parameter clocks must be an integer, got float 2.0"):
        delay(clk, Signal(bool(0)), Signal(bool(0)), clocks=2.0)
    assert window_control(clk, rst, ImageStream(8), ImageStream(8), width=np.int64(8), height=np.int64(4),
                          radius=np.int64(1), latency=np.int64(3)) is not None


def test_catalog_defaults_are_the_blocks_own():
    """Every block parameter's catalogue default is the block function's keyword default, except the ones
    the catalogue states on purpose (written out here)."""
    import inspect

    stated = {("convolve", "col"), ("convolve", "row"), ("convolve", "shift"), ("harris_stereo", "share"),
              ("poly_unit", "quantizers"), ("coordinate_warper", "quantizers"), ("rectifier", "quantizers"),
              ("stream_rectifier", "quantizers")}
    for name, spec in BLOCKS.items():
        sig = inspect.signature(spec.func).parameters
        own = {k: v.default for k, v in sig.items() if v.kind is v.KEYWORD_ONLY}
        assert set(spec.hw_params) == set(own), name
        for k, v in own.items():
            if (name, k) not in stated:
                assert spec.defaults[k] == v, (name, k)
        # the port list is the block's positional parameters, in order (optional ones may be left out)
        ports, _, _ = spec.ports()
        positional = [k for k, v in sig.items() if v.kind is not v.KEYWORD_ONLY]
        assert list(ports) == positional[:len(ports)], name
    assert BLOCKS["harris_stereo"].defaults["share"] == 3 and BLOCKS["convolve"].defaults["shift"] == 4
