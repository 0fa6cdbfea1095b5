"""Elaboration checks of the camera blocks (bad ports and parameters name themselves) and their port lists."""

from __future__ import annotations

import shutil

import pytest
from myhdl import ResetSignal, Signal, intbv

from eyestereo.hdl.streaming.async_fifo import async_fifo
from eyestereo.hdl.interfaces.camera_bus import CameraBus
from eyestereo.hdl.camera.camera_interface import camera_interface
from eyestereo.hdl.camera.camera_stream import camera_stream
from eyestereo.hdl.flow.catalog import BLOCKS
from eyestereo.hdl.flow.convert import analyse, convert, vhdl_ports
from eyestereo.hdl.interfaces.queue import QueuePort
from eyestereo.hdl.interfaces.stream import ImageStream


def rst():
    return ResetSignal(0, active=1, isasync=False)


def build_cs(cam=None, reset=None, source=None, luma=None, **kw):
    return camera_stream(CameraBus() if cam is None else cam, rst() if reset is None else reset,
                         ImageStream(16) if source is None else source, luma,
                         **{"width": 8, "height": 4, **kw})


def build_fifo(sink=None, source=None, dropped=None, **kw):
    return async_fifo(Signal(bool(0)), rst(), ImageStream(16) if sink is None else sink, Signal(bool(0)), rst(),
                      QueuePort(16) if source is None else source,
                      Signal(intbv(0)[16:]) if dropped is None else dropped,
                      **{"depth": 16, **kw})


@pytest.mark.parametrize("kw,match", [
    (dict(width=7), "width=7 must be even"),
    (dict(width=0), "width=0 is too small"),
    (dict(height=0), "height=0 is too small"),
    (dict(width=8.0), "width must be an integer"),
    (dict(order="YYUV"), "parameter order must be one of"),
    (dict(vsync_active=2), "parameter vsync_active must be one of"),
    (dict(href_active=True), "parameter href_active must be one of"),
    (dict(cam=ImageStream(8)), "port cam must be a CameraBus"),
    (dict(cam=CameraBus(10)), "port cam must have 8 data bits"),
    (dict(reset=Signal(bool(0))), "port rst must be a ResetSignal"),
    (dict(source=ImageStream(8)), "port source must carry 16-bit data"),
    (dict(luma=ImageStream(16)), "port luma must carry 8-bit data"),
])
def test_camera_stream_rejects(kw, match):
    with pytest.raises(ValueError, match=match):
        build_cs(**kw)


@pytest.mark.parametrize("kw,match", [
    (dict(depth=12), "depth=12 must be a power of two"),
    (dict(depth=2), "depth=2 is too small"),
    (dict(depth=1 << 15), "too large"),
    (dict(source=ImageStream(16)), "port source must be a QueuePort"),
    (dict(source=QueuePort(8)), "port source must carry 16-bit data"),
    (dict(sink=QueuePort(16)), "port sink must be an ImageStream"),
    (dict(dropped=Signal(intbv(0)[8:])), "port dropped must be 16 bits"),
])
def test_async_fifo_rejects(kw, match):
    with pytest.raises(ValueError, match=match):
        build_fifo(**kw)


def test_async_fifo_rejects_bad_clocks():
    with pytest.raises(ValueError, match="port rclk must be a 1-bit Signal"):
        async_fifo(Signal(bool(0)), rst(), ImageStream(16), None, rst(), QueuePort(16), Signal(intbv(0)[16:]))
    with pytest.raises(ValueError, match="port wrst is an asynchronous"):
        async_fifo(Signal(bool(0)), ResetSignal(0, active=1, isasync=True), ImageStream(16), Signal(bool(0)),
                   rst(), QueuePort(16), Signal(intbv(0)[16:]))


def test_camera_interface_rejects():
    with pytest.raises(ValueError, match="port source must be a QueuePort"):
        camera_interface(CameraBus(), rst(), Signal(bool(0)), rst(), ImageStream(16), Signal(intbv(0)[16:]))
    with pytest.raises(ValueError, match="depth=100 must be a power of two"):
        camera_interface(CameraBus(), rst(), Signal(bool(0)), rst(), QueuePort(16), Signal(intbv(0)[16:]),
                         depth=100)


def test_interfaces_reject_bad_widths():
    for bad in (0, -1, 2.5, True):
        with pytest.raises(ValueError, match="data_width"):
            QueuePort(bad)
        with pytest.raises(ValueError, match="data_width"):
            CameraBus(bad)


PORTS = {
    "camera_stream": ["rst", "cam_pclk", "cam_vsync", "cam_href", "cam_data", "source_data", "source_valid",
                      "source_eol", "source_eof", "luma_data", "luma_valid", "luma_eol", "luma_eof"],
    "async_fifo": ["wclk", "wrst", "rclk", "rrst", "dropped", "full", "empty", "sink_data", "sink_valid",
                   "sink_eol", "sink_eof", "source_data", "source_valid", "source_ready", "source_eol",
                   "source_eof"],
    "camera_interface": ["wrst", "rclk", "rrst", "dropped", "cam_pclk", "cam_vsync", "cam_href", "cam_data",
                         "source_data", "source_valid", "source_ready", "source_eol", "source_eof"],
}


@pytest.mark.skipif(shutil.which("ghdl") is None, reason="GHDL not installed")
@pytest.mark.parametrize("name", sorted(PORTS))
def test_vhdl_ports_and_analysis(tmp_path, name):
    files = convert(name, tmp_path)
    ports = vhdl_ports(files[-1])
    assert [p["name"] for p in ports] == PORTS[name]
    dirs = {p["name"]: p["dir"] for p in ports}
    assert dirs.get("source_ready") in (None, "in") and dirs["source_valid"] == "out"
    for std in ("93c", "08"):
        analyse(files, std, tmp_path / std)
    assert BLOCKS[name].build is not None


def test_catalog_camera_pair_has_two_of_everything():
    _, ports, p = BLOCKS["camera_pair"].elaborate(width=8, height=4, depth=16)
    assert {"cam_l", "cam_r", "wrst_l", "wrst_r", "source_l", "source_r", "dropped_l", "dropped_r", "rclk",
            "rrst"} == set(ports)
