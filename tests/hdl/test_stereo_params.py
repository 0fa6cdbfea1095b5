"""Elaboration-time checks of harris_stereo and feature_list (ports and parameters; no simulation).

The catalogue-wide checks (tests/hdl/test_params.py) cover harris_stereo's standard ports; these are
the parameters and ports particular to the two blocks, and feature_list's own ports (it has a queue
port and statistics outputs, so it is built by its catalogue entry's ``build``).
"""

import re

import pytest
from myhdl import Signal, intbv

from eyestereo.hdl.flow.catalog import BLOCKS
from eyestereo.hdl.interfaces.queue import QueuePort
from eyestereo.hdl.interfaces.stream import ImageStream


def _expect(spec, ports, kw, match):
    with pytest.raises(ValueError) as e:
        spec.func(*ports.values(), **kw)
    msg = str(e.value)
    assert msg.startswith(f"{spec.name}: ") and "\n" not in msg, msg
    assert re.search(match, msg), f"{msg!r} does not match {match!r}"


@pytest.mark.parametrize("kw,match", [
    (dict(share=4), r"parameter share must be one of \[1, 2, 3\], got int 4"),
    (dict(share=0), r"parameter share must be one of \[1, 2, 3\]"),
    (dict(share=2.0), r"parameter share must be one of \[1, 2, 3\], got float 2.0"),
    (dict(share=True), r"parameter share must be one of \[1, 2, 3\], got bool"),
    (dict(nms=7), r"parameter nms must be one of \[1, 3, 5\]"),
    (dict(blocks=(17, 1)), r"parameter blocks=\(17, 1\)"),
    (dict(width=4), r"parameter width=4 is too small"),
])
def test_harris_stereo_parameters(kw, match):
    spec = BLOCKS["harris_stereo"]
    ports, base, _ = spec.ports(width=16, height=8)
    base.update(kw)
    _expect(spec, ports, base, match)


@pytest.mark.parametrize("port,value,match", [
    ("sink", ImageStream(8), r"port sink must be a stereo stream"),
    ("source", ImageStream(1), r"port source must be a stereo stream"),
    ("thr_cam", Signal(intbv(0)[2:]), r"port thr_cam must be 1 bit wide, got 2"),
    ("k_right", Signal(intbv(0)[9:]), r"port k_right must be 8 bits wide, got 9"),
    ("k_left", None, r"port k_left .*got None"),
])
def test_harris_stereo_ports(port, value, match):
    spec = BLOCKS["harris_stereo"]
    ports, kw, _ = spec.ports(width=16, height=8)
    ports[port] = value
    _expect(spec, ports, kw, match)


def test_harris_stereo_shares_elaborate():
    spec = BLOCKS["harris_stereo"]
    for share in (1, 2, 3):
        inst, _, _ = spec.elaborate(width=16, height=8, share=share, blocks=(2, 2))
        assert inst is not None


@pytest.mark.parametrize("kw,match", [
    (dict(border=0), r"parameter border=0 is too small"),
    (dict(border=5), r"parameter border=5 is more than half of a 23x9 frame"),
    (dict(border=2.0), r"parameter border must be an integer, got float"),
    (dict(max_features=0), r"parameter max_features=0 is too small"),
    (dict(max_features=40000), r"parameter max_features=40000 is too large"),
    (dict(depth=12), r"parameter depth=12 must be a power of two"),
    (dict(depth=2), r"parameter depth=2 is too small"),
    (dict(blocks=(2, 10)), r"parameter blocks=\(2, 10\)"),
])
def test_feature_list_parameters(kw, match):
    spec = BLOCKS["feature_list"]
    p = spec.params(width=23, height=9)
    ports = spec.build(p)
    base = {k: v for k, v in p.items() if k in spec.hw_params}
    base.update(kw)
    _expect(spec, ports, base, match)


@pytest.mark.parametrize("port,value,match", [
    ("sink", ImageStream(1), r"port sink must be a stereo stream"),
    ("sink", ImageStream(2, stereo=True), r"port sink must carry 1-bit data"),
    ("source", ImageStream(16), r"port source must be a QueuePort"),
    ("source", QueuePort(18), r"port source must carry 16-bit data, got a QueuePort of 18 bits"),
    ("count_addr", Signal(intbv(0)[3:]), r"port count_addr must be 5 bits wide, got 3"),
    ("total_left", Signal(intbv(0)[8:]), r"port total_left must be 17 bits wide, got 8"),
    ("overflow", None, r"port overflow .*got None"),
    ("clk", None, r"port clk .*got None"),
])
def test_feature_list_ports(port, value, match):
    spec = BLOCKS["feature_list"]
    p = spec.params()
    ports = spec.build(p)
    ports[port] = value
    _expect(spec, ports, {k: v for k, v in p.items() if k in spec.hw_params}, match)


def test_feature_list_outputs_need_signals_of_their_own():
    spec = BLOCKS["feature_list"]
    p = spec.params()
    ports = spec.build(p)
    ports["total_right"] = ports["total_left"]
    _expect(spec, ports, {k: v for k, v in p.items() if k in spec.hw_params}, r"share a signal")
