"""The block catalogue: every block with its default configuration, for conversion, synthesis and benches.

Each entry knows how to build a fresh MyHDL instance with fresh ports for a set of parameters (MyHDL
needs a new instance per conversion) and the stream widths that parameter set implies.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from myhdl import ResetSignal, Signal, intbv

from eyestereo.hdl.streaming.async_fifo import async_fifo
from eyestereo.hdl.interfaces.axil import AxiLite
from eyestereo.hdl.interfaces.camera_bus import CameraBus
from eyestereo.hdl.camera.camera_interface import camera_interface, camera_pair
from eyestereo.hdl.camera.camera_stream import camera_stream
from eyestereo.hdl.interfaces.axis import AxiStream
from eyestereo.hdl.axi.axis_to_stream import axis_to_stream
from eyestereo.hdl.streaming.convolve import convolve
from eyestereo.hdl.harris.cornerness import cornerness
from eyestereo.hdl.harris.harris_mono import harris_mono
from eyestereo.hdl.harris.harris_stereo import harris_stereo
from eyestereo.hdl.harris.feature_list import addr_bits, count_bits, feature_list
from eyestereo.hdl.harris.harris_window import harris_window
from eyestereo.hdl.harris.nms import nms
from eyestereo.hdl.harris.prethreshold import prethreshold
from eyestereo.hdl.system.register_bank import RegisterPorts, register_bank
from eyestereo.hdl.interfaces.coord_pair import CoordPair
from eyestereo.hdl.rectify.coordinate_warper import coordinate_warper
from eyestereo.hdl.rectify.fetch_interpolate import DEFAULT_DEPTH, fetch_interpolate
from eyestereo.hdl.streaming.line_delay import line_delay
from eyestereo.hdl.rectify.poly_unit import CoefPort, poly_unit
from eyestereo.hdl.rectify.rectifier import rectifier
from eyestereo.hdl.system.stereo_frontend import stereo_frontend
from eyestereo.hdl.harris.sobel import sobel
from eyestereo.hdl.streaming.stream_checker import stream_checker
from eyestereo.hdl.interfaces.queue import QueuePort
from eyestereo.hdl.interfaces.fetch_port import FetchPort
from eyestereo.hdl.memory.frame_buffers import BufferSide, FrameControl, double_buffer
from eyestereo.hdl.memory.sram_arbiter import TAG_BITS, sram_arbiter
from eyestereo.hdl.interfaces.sram_bus import HostPort, SramCmd, SramPins, SramRsp, StatPort
from eyestereo.hdl.memory.sram_controller import sram_controller
from eyestereo.hdl.memory.sram_subsystem import sram_subsystem
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.hdl.streaming.stream_cdc import stream_cdc
from eyestereo.hdl.streaming.word_cdc import word_cdc
from eyestereo.tools.camera import WORD as CAMERA_WORD
from eyestereo.hdl.axi.stream_to_axis import stream_to_axis
from eyestereo.tools.models import cornerness as corner_model
from eyestereo.tools.models import harris_window as window_model
from eyestereo.tools.models import nms as nms_model
from eyestereo.tools.models import sobel as sobel_model
from eyestereo.tools.models import stream_checker as checker_model
from eyestereo.tools.models.convolve import check_kernel, output_width
from eyestereo.tools.models import poly_unit as poly_model


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
    #: blocks whose ports are not ``clk, rst, sink, source, <control>`` (several clocks, a camera bus,
    #: a queue port): function(params) -> (instance, ports dict) of a fresh instance
    build: Callable[[dict], tuple[object, dict]] | None = None
    #: interface classes of ``sink`` and ``source`` (built with the stream width)
    sink_type: type = ImageStream
    source_type: type = ImageStream
    #: clock ports with the thesis's goal in MHz (None: none, or the default of eyestereo.hdl.flow.synth)
    clocks: tuple[tuple[str, float | None], ...] = (("clk", None),)

    def params(self, **overrides) -> dict:
        unknown = set(overrides) - set(self.defaults)
        if unknown:
            raise ValueError(f"{self.name} has no parameter(s) {sorted(unknown)}; it has {sorted(self.defaults)}")
        p = dict(self.defaults)
        p.update(overrides)
        return p

    def ports(self, **overrides) -> tuple[dict, dict, dict]:
        """(fresh ports in call order, the block function's keyword parameters, all parameters).

        A ``stereo`` parameter (blocks that take stereo streams have one) makes both streams stereo.
        Blocks whose ports are not ``clk, rst, sink, source, <control>`` (several clocks, other
        interfaces) make their ports with their ``build`` function.
        """
        p = self.params(**overrides)
        kw = {k: v for k, v in p.items() if k in self.hw_params}
        if self.build is not None:
            return self.build(p), kw, p
        stereo = bool(p.get("stereo", False))

        def stream(kind, width):
            return kind(width, stereo=stereo) if kind is ImageStream else kind(width)

        ports = dict(clk=Signal(bool(0)), rst=ResetSignal(0, active=1, isasync=False),
                     sink=stream(self.sink_type, self.sink_width(p)),
                     source=stream(self.source_type, self.source_width(p)))
        ports.update((name, make(p)) for name, make in self.control)
        return ports, kw, p

    def elaborate(self, **overrides):
        """(instance, ports dict, parameters) of a fresh instance with the given parameters."""
        ports, kw, p = self.ports(**overrides)
        inst = self.func(*ports.values(), **kw)
        return inst, ports, p

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


def _rst():
    return ResetSignal(0, active=1, isasync=False)


_CAMERA = dict(width=352, height=288, order="YUYV", vsync_active=1, href_active=1)


def _build_camera_stream(p):
    ports = dict(cam=CameraBus(), rst=_rst(), source=ImageStream(CAMERA_WORD),
                 luma=ImageStream(8) if p["luma"] else None)
    return ports


def _build_async_fifo(p):
    ports = dict(wclk=Signal(bool(0)), wrst=_rst(), sink=ImageStream(p["data_width"]), rclk=Signal(bool(0)),
                 rrst=_rst(), source=QueuePort(p["data_width"]), dropped=Signal(intbv(0)[16:]),
                 full=Signal(bool(0)), empty=Signal(bool(0)))
    return ports


def _build_camera_interface(p):
    ports = dict(cam=CameraBus(), wrst=_rst(), rclk=Signal(bool(0)), rrst=_rst(),
                 source=QueuePort(CAMERA_WORD), dropped=Signal(intbv(0)[16:]))
    return ports


def _build_camera_pair(p):
    ports = dict(cam_l=CameraBus(), wrst_l=_rst(), cam_r=CameraBus(), wrst_r=_rst(), rclk=Signal(bool(0)),
                 rrst=_rst(), source_l=QueuePort(CAMERA_WORD), source_r=QueuePort(CAMERA_WORD),
                 dropped_l=Signal(intbv(0)[16:]), dropped_r=Signal(intbv(0)[16:]))
    return ports


#: Rectification blocks: ``quantizers`` is a calibration spec or a quantizers.json path
#: (:func:`eyestereo.tools.rectify.calibrations.load`; "rig" = the synthetic rig, 352x288).
_POLY_DEFAULTS = dict(quantizers="rig", frac=poly_model.DEFAULT_FRAC, source_width=None, source_height=None,
                      coefficients="constant")


def _calibration(p):
    from eyestereo.hdl.rectify.poly_unit import calibration_param

    return calibration_param(p["quantizers"], p["source_width"], p["source_height"])


def _coef_port(p, cal):
    if p["coefficients"] not in ("constant", "register"):
        raise ValueError(f"parameter coefficients must be 'constant' or 'register', got {p['coefficients']!r}")
    return {"coef": CoefPort(poly_model.coef_data_bits(cal.formats))} if p["coefficients"] == "register" else {}


def _build_poly_unit(p):
    cal = _calibration(p)
    nb = poly_model.coord_bits(cal, p["frac"])
    return dict(clk=Signal(bool(0)), rst=_rst(), enable=Signal(bool(0)), x=Signal(intbv(0)[poly_model.int_bits(cal.width):]),
                y=Signal(intbv(0)[poly_model.int_bits(cal.height):]), select_coord=Signal(intbv(0)[3:]),
                coord=Signal(intbv(0)[nb:]), out_of_range=Signal(bool(0)), select_coord_out=Signal(intbv(0)[3:]),
                **_coef_port(p, cal))


def _build_coordinate_warper(p):
    cal = _calibration(p)
    return dict(clk=Signal(bool(0)), rst=_rst(), start=Signal(bool(0)), enable=Signal(bool(0)), busy=Signal(bool(0)), done=Signal(bool(0)),
                coord=CoordPair(cal.source_width, cal.source_height, poly_model.resolve_frac(cal, p["frac"])),
                **_coef_port(p, cal))


def _build_fetch_interpolate(p):
    cal = _calibration(p)
    return dict(clk=Signal(bool(0)), rst=_rst(),
                coord=CoordPair(cal.source_width, cal.source_height, poly_model.resolve_frac(cal, p["frac"])),
                fetch=FetchPort(cal.source_width, cal.source_height), source=ImageStream(8, stereo=True),
                busy=Signal(bool(0)))


def _build_rectifier(p):
    cal = _calibration(p)
    return dict(clk=Signal(bool(0)), rst=_rst(), start=Signal(bool(0)),
                fetch=FetchPort(cal.source_width, cal.source_height), source=ImageStream(8, stereo=True),
                busy=Signal(bool(0)), **_coef_port(p, cal))


_RECT_DEFAULTS = dict(_POLY_DEFAULTS, depth=DEFAULT_DEPTH)

def _build_feature_list(p):
    cb = count_bits(p["width"], p["height"])
    return dict(clk=Signal(bool(0)), rst=_rst(), sink=ImageStream(1, stereo=True), source=QueuePort(16),
                count_addr=Signal(intbv(0)[addr_bits(p["blocks"]):]), count_data=Signal(intbv(0)[cb:]),
                total_left=Signal(intbv(0)[cb:]), total_right=Signal(intbv(0)[cb:]), overflow=Signal(bool(0)),
                frame_done=Signal(bool(0)))


BLOCKS: dict[str, BlockSpec] = {
    "line_delay": BlockSpec(
        "line_delay", "one-line FIFO in block RAM: pixel (x, y-1) at (x, y)", line_delay,
        dict(width=352, height=288, data_width=8, stereo=False),
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
    "poly_unit": BlockSpec(
        "poly_unit", "the four rectification polynomials, 8-stage pipeline, 9 multipliers, 1 coordinate/clock",
        poly_unit, _POLY_DEFAULTS,
        hw_params=("quantizers", "frac", "source_width", "source_height"), build=_build_poly_unit),
    "coordinate_warper": BlockSpec(
        "coordinate_warper", "x/y counters, poly_unit and the double-buffered coordinate pair output (4 clocks/pair)",
        coordinate_warper, _POLY_DEFAULTS,
        hw_params=("quantizers", "frac", "source_width", "source_height"), build=_build_coordinate_warper),
    "fetch_interpolate": BlockSpec(
        "fetch_interpolate", "coordinate pairs -> fetch port (previous 2x2 reused) -> bilinear MAC -> 8-bit stereo stream",
        fetch_interpolate, {k: v for k, v in _RECT_DEFAULTS.items() if k != "coefficients"},
        source_width=lambda p: 8, hw_params=("depth",), build=_build_fetch_interpolate),
    "rectifier": BlockSpec(
        "rectifier", "coordinate_warper + fetch_interpolate: calibration in, rectified 8-bit stereo stream out",
        rectifier, _RECT_DEFAULTS, source_width=lambda p: 8,
        hw_params=("quantizers", "frac", "source_width", "source_height", "depth"), build=_build_rectifier),
    "harris_mono": BlockSpec(
        "harris_mono", "Harris corners: Sobel -> window -> cornerness -> pre-threshold -> NMS", harris_mono,
        dict(width=352, height=288, blocks=(4, 4), nms=3),
        sink_width=lambda p: 8, source_width=lambda p: nms_model.WORD.width,
        hw_params=("width", "height", "blocks", "nms"),
        control=(("k", _k_port),) + _thr_ports()),
    "harris_stereo": BlockSpec(
        "harris_stereo", "stereo Harris corners: one datapath for both cameras, shared line delays and "
        "multipliers (share 1/2/3), k and block thresholds per camera", harris_stereo,
        dict(width=352, height=288, blocks=(4, 4), nms=3, share=3, stereo=True),
        sink_width=lambda p: 8, source_width=lambda p: nms_model.WORD.width,
        hw_params=("width", "height", "blocks", "nms", "share"),
        control=(("k_left", _k_port), ("k_right", _k_port), _thr_ports()[0],
                 ("thr_cam", lambda p: Signal(bool(0))), *_thr_ports()[1:])),
    "feature_list": BlockSpec(
        "feature_list", "stereo corner flags -> feature words (x, y, cam) on a 16-bit queue port, counts per "
        "camera and threshold block, a maximum per frame with an overflow flag", feature_list,
        dict(width=352, height=288, blocks=(4, 4), border=4, max_features=1023, depth=16),
        sink_width=lambda p: 1, source_width=lambda p: 16,
        hw_params=("width", "height", "blocks", "border", "max_features", "depth"), build=_build_feature_list),
    "stream_checker": BlockSpec(
        "stream_checker", "protocol checker: lines/frames of the wrong size, stereo interleaving; sticky error "
        "and fault code; optional repair (broken frames become reset tokens)", stream_checker,
        dict(width=352, height=288, data_width=8, stereo=False, repair=False),
        sink_width=lambda p: p["data_width"], source_width=lambda p: p["data_width"],
        hw_params=("width", "height", "repair"),
        control=(("error", lambda p: Signal(bool(0))),
                 ("code", lambda p: Signal(intbv(0)[checker_model.CODE_BITS:])))),
    "camera_stream": BlockSpec(
        "camera_stream", "camera bus (PCLK, VSYNC, HREF, 8-bit YUV 4:2:2) to 16-bit words, whole frames only",
        camera_stream, dict(_CAMERA, luma=True), sink_width=lambda p: 8, source_width=lambda p: CAMERA_WORD.width,
        hw_params=tuple(_CAMERA), build=_build_camera_stream, clocks=(("cam_pclk", 18.0),)),
    "async_fifo": BlockSpec(
        "async_fifo", "dual-clock frame FIFO: Gray pointers, a reset per domain, broken frames dropped and counted",
        async_fifo, dict(data_width=CAMERA_WORD.width, depth=1024), sink_width=lambda p: p["data_width"],
        source_width=lambda p: p["data_width"], hw_params=("depth",), build=_build_async_fifo,
        clocks=(("wclk", 18.0), ("rclk", 100.0))),
    "camera_interface": BlockSpec(
        "camera_interface", "camera_stream + async_fifo: a camera bus in, whole frames in the system clock out",
        camera_interface, dict(_CAMERA, depth=1024), sink_width=lambda p: 8,
        source_width=lambda p: CAMERA_WORD.width, hw_params=(*_CAMERA, "depth"), build=_build_camera_interface,
        clocks=(("cam_pclk", 18.0), ("rclk", 100.0))),
    "camera_pair": BlockSpec(
        "camera_pair", "two camera_interfaces, each with its own camera clock, into one system clock",
        camera_pair, dict(_CAMERA, depth=1024), sink_width=lambda p: 8, source_width=lambda p: CAMERA_WORD.width,
        hw_params=(*_CAMERA, "depth"), build=_build_camera_pair,
        clocks=(("cam_l_pclk", 18.0), ("cam_r_pclk", 18.0), ("rclk", 100.0))),
    "stream_to_axis": BlockSpec(
        "stream_to_axis", "image stream -> AXI4-Stream video (UG934), FIFO for tready, cut frames on overflow",
        stream_to_axis, dict(width=352, height=288, data_width=8, depth=1024, commit="line"),
        sink_width=lambda p: p["data_width"], source_width=lambda p: p["data_width"],
        hw_params=("width", "height", "depth", "commit"), source_type=AxiStream,
        control=(("overflow", lambda p: Signal(bool(0))),)),
    "axis_to_stream": BlockSpec(
        "axis_to_stream", "AXI4-Stream video (UG934) -> image stream of a fixed geometry, tokens for faults",
        axis_to_stream, dict(width=352, height=288, data_width=8),
        sink_width=lambda p: p["data_width"], source_width=lambda p: p["data_width"],
        hw_params=("width", "height"), sink_type=AxiStream,
        control=(("error", lambda p: Signal(bool(0))),)),
}


# --- the SRAM subsystem (issue 12): blocks with interfaces of their own, ports made by ``build`` --------
def _clk_rst():
    return dict(clk=Signal(bool(0)), rst=_rst())


def _build_sram_controller(p):
    return dict(_clk_rst(), cmd=SramCmd(tag_bits=p["tag_bits"]), rsp=SramRsp(tag_bits=p["tag_bits"]),
                sram=SramPins())


def _masters(p):
    return dict(cam0=QueuePort(CAMERA_WORD), cam1=QueuePort(CAMERA_WORD), fetch=FetchPort(p["width"], p["height"]),
                rect=ImageStream(8, stereo=True), feat=QueuePort(16), host=HostPort(), ctl=FrameControl(),
                stat=StatPort())


_ARB = dict(width=352, height=288, feature_words=8192, depth=16, burst=8, fetch_burst=8, host_burst=1,
            counter_bits=32)

BLOCKS["sram_controller"] = BlockSpec(
    "sram_controller", "1M x 16 synchronous SRAM (NoBL or pipelined SyncBurst): pins <-> in-order word port",
    sram_controller, dict(kind="nobl", read_latency=2, tag_bits=5), sink_width=lambda p: 16,
    source_width=lambda p: 16, hw_params=("kind", "read_latency"), build=_build_sram_controller,
    clocks=(("clk", 100.0),))
BLOCKS["double_buffer"] = BlockSpec(
    "double_buffer", "frame handshake of one producer's two SRAM buffers (FREE/WRITING/FULL/READING)",
    double_buffer, dict(), sink_width=lambda p: 1, source_width=lambda p: 1,
    build=lambda p: dict(_clk_rst(), side=BufferSide()), clocks=(("clk", 100.0),))
BLOCKS["sram_arbiter"] = BlockSpec(
    "sram_arbiter", "six SRAM masters (2 cameras, fetch port, rectified, features, host), double buffers",
    sram_arbiter, dict(_ARB), sink_width=lambda p: 16, source_width=lambda p: 8, hw_params=tuple(_ARB),
    build=lambda p: dict(_clk_rst(), **_masters(p), cmd=SramCmd(tag_bits=TAG_BITS), rsp=SramRsp(tag_bits=TAG_BITS)),
    clocks=(("clk", 100.0),))
BLOCKS["sram_subsystem"] = BlockSpec(
    "sram_subsystem", "sram_arbiter + sram_controller: the SRAM's pins and the six masters' ports",
    sram_subsystem, dict(_ARB, kind="nobl", read_latency=2), sink_width=lambda p: 16, source_width=lambda p: 8,
    hw_params=tuple(_ARB) + ("kind", "read_latency"), build=lambda p: dict(_clk_rst(), **_masters(p), sram=SramPins()),
    clocks=(("clk", 100.0),))


# --- the complete system (issue 15): the register bank on the AXI4-Lite register bus ---------------------
def _build_register_bank(p):
    from eyestereo.tools.regmap import REGMAP

    return dict(_clk_rst(), bus=AxiLite(REGMAP.addr_bits), regs=RegisterPorts(REGMAP), arb=StatPort(),
                fcount=StatPort(5, 16), host=HostPort())


BLOCKS["register_bank"] = BlockSpec(
    "register_bank", "the register map (tools/regmap.py) on an AXI4-Lite slave: control, k, thresholds, status, "
    "arbiter counters, SRAM window", register_bank, dict(width=352, height=288), sink_width=lambda p: 32,
    source_width=lambda p: 32, hw_params=("width", "height"), build=_build_register_bank, clocks=(("clk", 100.0),))


def _build_stream_cdc(p):
    return dict(wclk=Signal(bool(0)), wrst=_rst(), sink=ImageStream(p["data_width"], stereo=p["stereo"]),
                rclk=Signal(bool(0)), rrst=_rst(), source=ImageStream(p["data_width"], stereo=p["stereo"]),
                dropped=Signal(intbv(0)[16:]))


BLOCKS["stream_cdc"] = BlockSpec(
    "stream_cdc", "an image stream, mono or stereo, into another clock (async_fifo inside; whole stereo frames "
    "or a reset token): the rectifier's stream into the Harris clock", stream_cdc,
    dict(data_width=8, stereo=True, depth=16), sink_width=lambda p: p["data_width"],
    source_width=lambda p: p["data_width"], hw_params=("depth",), build=_build_stream_cdc,
    clocks=(("wclk", 100.0), ("rclk", 50.0)))
BLOCKS["word_cdc"] = BlockSpec(
    "word_cdc", "a multi-bit value into another clock by a toggle handshake, never torn (k codes, counts)",
    word_cdc, dict(width=16), sink_width=lambda p: p["width"], source_width=lambda p: p["width"],
    build=lambda p: dict(sclk=Signal(bool(0)), d=Signal(intbv(0)[p["width"]:]), dclk=Signal(bool(0)),
                         q=Signal(intbv(0)[p["width"]:])),
    clocks=(("sclk", 100.0), ("dclk", 50.0)))

def _build_stereo_frontend(p):
    from eyestereo.hdl.interfaces.axil import AxiLite
    from eyestereo.hdl.interfaces.camera_bus import CameraBus
    from eyestereo.hdl.interfaces.sram_bus import SramPins
    from eyestereo.tools.regmap import REGMAP

    return dict(clk=Signal(bool(0)), rst=_rst(), hclk=Signal(bool(0)), hrst=_rst(), cam_l=CameraBus(), wrst_l=_rst(),
                cam_r=CameraBus(), wrst_r=_rst(), bus=AxiLite(REGMAP.addr_bits), sram=SramPins())


_FRONTEND = dict(quantizers="rig", frac=poly_model.DEFAULT_FRAC, nms=3, share=1, border=None, max_features=1023,
                 feature_words=2048, cam_depth=1024, kind="nobl", read_latency=2)
BLOCKS["stereo_frontend"] = BlockSpec(
    "stereo_frontend", "the complete stereo front end: two camera buses -> SRAM -> rectifier -> stereo Harris -> "
    "feature lists, AXI4-Lite registers, sequential and overlapped modes", stereo_frontend, dict(_FRONTEND),
    sink_width=lambda p: 8, source_width=lambda p: 16, hw_params=tuple(_FRONTEND), build=_build_stereo_frontend,
    clocks=(("clk", 100.0), ("hclk", 50.0), ("cam_l_pclk", 18.0), ("cam_r_pclk", 18.0)))

#: Simulation-only top levels (a bench harness around a block, registered by its module in
#: ``eyestereo.sim``): :func:`get` finds them, ``make vhdl`` / ``make synth`` do not build them.
BENCH_TOPS: dict[str, BlockSpec] = {}


def get(name: str) -> BlockSpec:
    if name in BLOCKS:
        return BLOCKS[name]
    if name in BENCH_TOPS:
        return BENCH_TOPS[name]
    raise ValueError(f"unknown block {name!r}; blocks are {sorted(BLOCKS)}")


def jsonable(p: dict) -> dict:
    """Parameters with numpy arrays turned into lists (for manifests and configs)."""
    return {k: (np.asarray(v).tolist() if isinstance(v, (np.ndarray, tuple)) else v) for k, v in p.items()}
