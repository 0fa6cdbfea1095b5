"""The block catalogue: every block with its default configuration, for conversion, synthesis and benches.

Each entry knows how to build a fresh MyHDL instance with fresh ports for a set of parameters (MyHDL
needs a new instance per conversion) and the stream widths that parameter set implies.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from myhdl import ResetSignal, Signal, intbv

from eyestereo.hdl.convolve import convolve
from eyestereo.hdl.cornerness import cornerness
from eyestereo.hdl.harris_mono import harris_mono
from eyestereo.hdl.harris_window import harris_window
from eyestereo.hdl.nms import nms
from eyestereo.hdl.prethreshold import prethreshold
from eyestereo.hdl.line_delay import line_delay
from eyestereo.hdl.sobel import sobel
from eyestereo.hdl.fetch_port import FetchPort
from eyestereo.hdl.frame_buffers import BufferSide, FrameControl, double_buffer
from eyestereo.hdl.queue_port import QueuePort
from eyestereo.hdl.sram_arbiter import TAG_BITS, sram_arbiter
from eyestereo.hdl.sram_bus import HostPort, SramCmd, SramPins, SramRsp, StatPort
from eyestereo.hdl.sram_controller import sram_controller
from eyestereo.hdl.sram_subsystem import sram_subsystem
from eyestereo.hdl.stream import ImageStream
from eyestereo.tools.models import cornerness as corner_model
from eyestereo.tools.models import harris_window as window_model
from eyestereo.tools.models import nms as nms_model
from eyestereo.tools.models import sobel as sobel_model
from eyestereo.tools.models.convolve import check_kernel, output_width


@dataclass(frozen=True)
class BlockSpec:
    name: str
    summary: str
    func: Callable
    defaults: dict
    sink_width: Callable[[dict], int] | None = None
    source_width: Callable[[dict], int] | None = None
    hw_params: tuple[str, ...] = field(default=())  # parameters passed to the block function
    #: control ports after ``source``, in order: name -> function(params) -> fresh Signal
    control: tuple[tuple[str, Callable[[dict], object]], ...] = field(default=())
    #: blocks whose ports are not ``clk, rst, sink, source, control...``: function(params) -> ordered dict
    #: of every port (name -> fresh Signal or interface), passed to the block positionally in that order
    ports: Callable[[dict], dict] | None = None

    def params(self, **overrides) -> dict:
        unknown = set(overrides) - set(self.defaults)
        if unknown:
            raise ValueError(f"{self.name} has no parameter(s) {sorted(unknown)}; it has {sorted(self.defaults)}")
        p = dict(self.defaults)
        p.update(overrides)
        return p

    def elaborate(self, **overrides):
        """(instance, ports dict) of a fresh instance with the given parameters."""
        p = self.params(**overrides)
        if self.ports is not None:
            ports = self.ports(p)
            kw = {k: v for k, v in p.items() if k in self.hw_params}
            return self.func(*ports.values(), **kw), ports, p
        clk = Signal(bool(0))
        rst = ResetSignal(0, active=1, isasync=False)
        sink = ImageStream(self.sink_width(p))
        source = ImageStream(self.source_width(p))
        kw = {k: v for k, v in p.items() if k in self.hw_params}
        ctrl = {name: make(p) for name, make in self.control}
        inst = self.func(clk, rst, sink, source, *ctrl.values(), **kw)
        return inst, dict(clk=clk, rst=rst, sink=sink, source=source, **ctrl), p

    def entity(self, **overrides) -> str:
        return self.name


def _k_port(p):
    return Signal(intbv(0)[corner_model.K.wl:])


def _thr_ports():
    def addr(p):
        n = p["blocks"][0] * p["blocks"][1]
        return Signal(intbv(0)[max(1, (n - 1).bit_length()):])

    return (("thr_we", lambda p: Signal(bool(0))), ("thr_addr", addr),
            ("thr_data", lambda p: Signal(intbv(0)[corner_model.WORD.width:])))


def _conv_width(p):
    k, _ = check_kernel(p.get("kernel"), p.get("col"), p.get("row"))
    return output_width(k, p["data_width"], p["shift"])[0]


BLOCKS: dict[str, BlockSpec] = {
    "line_delay": BlockSpec(
        "line_delay", "one-line FIFO in block RAM: pixel (x, y-1) at (x, y)", line_delay,
        dict(width=352, height=288, data_width=8),
        sink_width=lambda p: p["data_width"], source_width=lambda p: p["data_width"],
        hw_params=("width", "height")),
    "convolve": BlockSpec(
        "convolve", "NxN integer-kernel convolution, separable or not (default: 3x3 binomial / 16)", convolve,
        dict(width=352, height=288, data_width=8, kernel=None, col=(1, 2, 1), row=(1, 2, 1), shift=4),
        sink_width=lambda p: p["data_width"], source_width=_conv_width,
        hw_params=("width", "height", "kernel", "col", "row", "shift")),
    "sobel": BlockSpec(
        "sobel", "separable 3x3 Sobel, Ix and Iy as sfix[9,-3]", sobel,
        dict(width=352, height=288),
        sink_width=lambda p: 8, source_width=lambda p: sobel_model.WORD.width, hw_params=("width", "height")),
    "harris_window": BlockSpec(
        "harris_window", "Ix^2, Iy^2, IxIy packed in 36 bits, summed over a 5x5 [1 2 4 2 1]^2 window",
        harris_window, dict(width=352, height=288),
        sink_width=lambda p: sobel_model.WORD.width, source_width=lambda p: window_model.WORD.width, hw_params=("width", "height")),
    "cornerness": BlockSpec(
        "cornerness", "det(G) - k trace(G)^2, 6-stage pipeline, 4 multipliers, 20-bit output", cornerness,
        dict(width=352, height=288),
        sink_width=lambda p: window_model.WORD.width, source_width=lambda p: corner_model.WORD.width,
        hw_params=("width", "height"), control=(("k", _k_port),)),
    "prethreshold": BlockSpec(
        "prethreshold", "cornerness > its block's run-time threshold, else 0 (BX x BY blocks)", prethreshold,
        dict(width=352, height=288, blocks=(4, 4)),
        sink_width=lambda p: corner_model.WORD.width, source_width=lambda p: corner_model.WORD.width,
        hw_params=("width", "height", "blocks"), control=_thr_ports()),
    "nms": BlockSpec(
        "nms", "separable non-maximum suppression 1x1/3x3/5x5 with a raster tie rule, 1-bit flags", nms,
        dict(width=352, height=288, size=3),
        sink_width=lambda p: corner_model.WORD.width, source_width=lambda p: nms_model.WORD.width,
        hw_params=("width", "height", "size")),
    "harris_mono": BlockSpec(
        "harris_mono", "Harris corners: Sobel -> window -> cornerness -> pre-threshold -> NMS", harris_mono,
        dict(width=352, height=288, blocks=(4, 4), nms=3),
        sink_width=lambda p: 8, source_width=lambda p: nms_model.WORD.width,
        hw_params=("width", "height", "blocks", "nms"),
        control=(("k", _k_port),) + _thr_ports()),
}


def _clk_rst():
    return dict(clk=Signal(bool(0)), rst=ResetSignal(0, active=1, isasync=False))


def _sram_controller_ports(p):
    return dict(_clk_rst(), cmd=SramCmd(tag_bits=p["tag_bits"]), rsp=SramRsp(tag_bits=p["tag_bits"]),
                sram=SramPins())


BLOCKS["sram_controller"] = BlockSpec(
    "sram_controller", "1M x 16 synchronous SRAM (NoBL or pipelined SyncBurst): pins <-> in-order word port",
    sram_controller, dict(kind="nobl", read_latency=2, tag_bits=5),
    hw_params=("kind", "read_latency"), ports=_sram_controller_ports)


def _masters(p):
    return dict(cam0=QueuePort(16), cam1=QueuePort(16), fetch=FetchPort(p["width"], p["height"]),
                rect=ImageStream(8, stereo=True), feat=QueuePort(16), host=HostPort(), ctl=FrameControl(),
                stat=StatPort())


_ARB = dict(width=352, height=288, feature_words=8192, depth=16, burst=8, fetch_burst=8, host_burst=1,
            counter_bits=32)

BLOCKS["sram_arbiter"] = BlockSpec(
    "sram_arbiter", "six SRAM masters (2 cameras, fetch port, rectified, features, host), double buffers",
    sram_arbiter, dict(_ARB), hw_params=tuple(_ARB),
    ports=lambda p: dict(_clk_rst(), **_masters(p), cmd=SramCmd(tag_bits=TAG_BITS), rsp=SramRsp(tag_bits=TAG_BITS)))

BLOCKS["sram_subsystem"] = BlockSpec(
    "sram_subsystem", "sram_arbiter + sram_controller: the SRAM's pins and the six masters' ports",
    sram_subsystem, dict(_ARB, kind="nobl", read_latency=2), hw_params=tuple(_ARB) + ("kind", "read_latency"),
    ports=lambda p: dict(_clk_rst(), **_masters(p), sram=SramPins()))

BLOCKS["double_buffer"] = BlockSpec(
    "double_buffer", "frame handshake of one producer's two SRAM buffers (FREE/WRITING/FULL/READING)",
    double_buffer, dict(), ports=lambda p: dict(_clk_rst(), side=BufferSide()))


def get(name: str) -> BlockSpec:
    try:
        return BLOCKS[name]
    except KeyError:
        raise ValueError(f"unknown block {name!r}; blocks are {sorted(BLOCKS)}") from None


def jsonable(p: dict) -> dict:
    """Parameters with numpy arrays turned into lists (for manifests and configs)."""
    return {k: (np.asarray(v).tolist() if isinstance(v, (np.ndarray, tuple)) else v) for k, v in p.items()}
