"""Elaboration checks of the SRAM blocks: bad ports and parameters end in one ValueError that names the block
and the port or parameter; the blocks' VHDL ports (the interfaces flatten to ``<arg>_<field>``)."""

from __future__ import annotations

import shutil

import numpy as np
import pytest
from myhdl import ResetSignal, Signal, intbv

from eyestereo.hdl.flow.catalog import BLOCKS
from eyestereo.hdl.flow.convert import analyse, convert, vhdl_ports
from eyestereo.hdl.interfaces.fetch_port import FetchPort
from eyestereo.hdl.interfaces.queue import QueuePort
from eyestereo.hdl.interfaces.sram_bus import HostPort, SramCmd, SramPins, SramRsp, StatPort
from eyestereo.hdl.interfaces.stream import ImageStream

SRAM_BLOCKS = ["sram_controller", "sram_arbiter", "sram_subsystem", "double_buffer"]
SMALL = dict(width=16, height=8, feature_words=64)


def _ports(name, **kw):
    spec = BLOCKS[name]
    small = {k: v for k, v in SMALL.items() if k in spec.defaults}
    return spec.ports(**{**small, **kw})


def _expect(name, match, ports, kw):
    with pytest.raises(ValueError) as e:
        BLOCKS[name].func(*ports.values(), **kw)
    msg = str(e.value)
    assert msg.startswith(f"{name}: "), msg
    assert "\n" not in msg
    import re
    assert re.search(match, msg), f"{msg!r} does not match {match!r}"


@pytest.mark.parametrize("name", SRAM_BLOCKS)
@pytest.mark.parametrize("bad", [None, 1, "x"])
def test_every_port_refuses_none_int_str(name, bad):
    ports0, _, _ = _ports(name)
    for port in ports0:
        ports, kw, _ = _ports(name)
        ports[port] = bad
        _expect(name, rf"port {port} .*got (None|int 1|str 'x')|port {port} must be", ports, kw)


@pytest.mark.parametrize("name", SRAM_BLOCKS)
def test_reset_and_clock(name):
    ports, kw, _ = _ports(name)
    ports["rst"] = ResetSignal(0, active=1, isasync=True)
    _expect(name, r"port rst is an asynchronous reset", ports, kw)
    ports, kw, _ = _ports(name)
    ports["clk"] = Signal(intbv(0)[1:])
    _expect(name, r"port clk must be a 1-bit Signal\(bool\(0\)\)", ports, kw)


@pytest.mark.parametrize("name,port,value,match", [
    ("sram_controller", "cmd", SramCmd(addr_bits=19, tag_bits=5), r"port cmd has 19 address bits, the SRAM pins 20"),
    ("sram_controller", "rsp", SramRsp(tag_bits=4), r"port rsp has 4 tag bits, cmd 5"),
    ("sram_controller", "sram", SramCmd(), r"port sram must be a SramPins"),
    ("sram_arbiter", "cam0", QueuePort(8), r"port cam0 must carry 16-bit data"),
    ("sram_arbiter", "cam1", ImageStream(16), r"port cam1 must be a QueuePort"),
    ("sram_arbiter", "rect", ImageStream(8), r"port rect must be a stereo stream"),
    ("sram_arbiter", "fetch", FetchPort(32, 8), r"port fetch is for 32x8 frames, the frame buffers for 16x8"),
    ("sram_arbiter", "host", QueuePort(16), r"port host must be a HostPort"),
    ("sram_arbiter", "stat", StatPort(addr_bits=4), r"port stat needs at least 5 address bits"),
    ("sram_arbiter", "cmd", SramCmd(tag_bits=5), r"ports cmd and rsp need 3 tag bits"),
    ("sram_subsystem", "feat", QueuePort(12), r"port feat must carry 16-bit data"),
    ("sram_subsystem", "sram", SramPins(addr_bits=19), None),
    ("sram_subsystem", "ctl", HostPort(), r"port ctl must be a FrameControl"),
])
def test_port_kinds_and_widths(name, port, value, match):
    ports, kw, _ = _ports(name)
    ports[port] = value
    if match is None:  # a 19-bit address bus: the controller inside refuses it, named as the subsystem
        with pytest.raises(ValueError, match=r"address bits"):
            BLOCKS[name].func(*ports.values(), **kw)
        return
    _expect(name, match, ports, kw)


@pytest.mark.parametrize("name,kw,match", [
    ("sram_controller", dict(kind="ddr"), r"parameter kind must be one of \['pipelined', 'nobl'\]"),
    ("sram_controller", dict(read_latency=4), r"parameter read_latency=4 is too large: at most 3"),
    ("sram_controller", dict(read_latency=2.0), r"parameter read_latency must be an integer, got float"),
    ("sram_controller", dict(read_latency=True), r"parameter read_latency must be an integer"),
    ("sram_arbiter", dict(depth=12), r"parameter depth must be one of \[8, 16, 32\]"),
    ("sram_arbiter", dict(burst=9), r"parameter burst=9 is too large: at most 8"),
    ("sram_arbiter", dict(feature_words=1), r"parameter feature_words=1 is too small"),
    ("sram_arbiter", dict(counter_bits=33), r"parameter counter_bits=33 is too large"),
    ("sram_arbiter", dict(host_burst="2"), r"parameter host_burst must be an integer, got str"),
    ("sram_subsystem", dict(kind="pipelined", read_latency=0), r"parameter read_latency=0 is too small"),
    ("sram_subsystem", dict(fetch_burst=3.0), r"parameter fetch_burst must be an integer, got float"),
])
def test_parameters(name, kw, match):
    ports, base, _ = _ports(name)
    base.update(kw)
    _expect(name, match, ports, base)


def test_a_map_that_does_not_fit_names_the_parameters():
    spec = BLOCKS["sram_arbiter"]
    ports, kw, _ = spec.ports(width=640, height=480)
    _expect("sram_arbiter", r"parameters width, height, feature_words: 640x480 frames", ports, kw)


@pytest.mark.parametrize("name", ["sram_controller", "sram_arbiter", "sram_subsystem"])
def test_numpy_integer_parameters_accepted(name):
    spec = BLOCKS[name]
    ports, kw, _ = _ports(name)
    for k, v in list(kw.items()):
        if isinstance(v, int) and not isinstance(v, bool):
            kw[k] = np.int64(v)
    assert spec.func(*ports.values(), **kw) is not None


PORTS = {
    "sram_controller": ["clk", "rst", "cmd_valid", "cmd_ready", "cmd_we", "cmd_addr", "cmd_wdata", "cmd_be",
                        "cmd_tag", "rsp_valid", "rsp_data", "rsp_tag", "sram_addr", "sram_ce_n", "sram_ld_n",
                        "sram_we_n", "sram_bw_n", "sram_oe_n", "sram_dq_o", "sram_dq_oe", "sram_dq_i"],
}


@pytest.mark.skipif(shutil.which("ghdl") is None, reason="GHDL not installed")
def test_controller_vhdl_ports_and_analysis(tmp_path):
    files = convert("sram_controller", tmp_path)
    ports = vhdl_ports(files[-1])
    assert [p["name"] for p in ports] == PORTS["sram_controller"]
    dirs = {p["name"]: p["dir"] for p in ports}
    assert dirs["sram_dq_i"] == "in" and dirs["sram_dq_o"] == "out" and dirs["cmd_ready"] == "out"
    for std in ("93c", "08"):
        analyse(files, std, tmp_path / std)


@pytest.mark.skipif(shutil.which("ghdl") is None, reason="GHDL not installed")
def test_subsystem_ports_are_the_documented_interfaces(tmp_path):
    files = convert("sram_subsystem", tmp_path, width=16, height=8, feature_words=64)
    names = [p["name"] for p in vhdl_ports(files[-1])]
    for prefix, fields in (("cam0", QueuePort(16).fields()), ("fetch", FetchPort(16, 8).fields()),
                           ("host", HostPort().fields()), ("stat", StatPort().fields()),
                           ("sram", SramPins().fields())):
        assert [f"{prefix}_{f}" for f in fields if f"{prefix}_{f}" in names] == [f"{prefix}_{f}" for f in fields]
    for f in ("cam_want", "cam_held", "cam_buf", "cam_release", "rect_buf", "feat_release", "avail"):
        assert f"ctl_{f}" in names
