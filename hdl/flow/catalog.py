"""The block catalogue: every block with its default configuration, for conversion, synthesis and benches.

Each entry knows how to build a fresh MyHDL instance with fresh ports for a set of parameters (MyHDL
needs a new instance per conversion) and the stream widths that parameter set implies.

Nothing here restates what a block or a bundle declares: an entry's parameters and their defaults are the
block function's keyword-only parameters (:func:`block_defaults`), its port list (names and order) is the
block function's positional parameters (:func:`fresh_ports`), and each bundle port is made by its class
from its one declaration (:mod:`eyestereo.hdl.interfaces.bundle`). An entry states only the parameters
that shape its ports (``data_width``, ``stereo``, ...) and, with a comment, where the catalogue's
configuration deliberately differs from the block's default.
"""

from __future__ import annotations

import inspect
import re
from dataclasses import dataclass, field
from collections.abc import Callable

import numpy as np
from myhdl import ResetSignal, Signal, intbv

from eyestereo.hdl.streaming.async_fifo import async_fifo
from eyestereo.hdl.interfaces.axil import AxiLite
from eyestereo.hdl.interfaces.camera_bus import CameraBus
from eyestereo.hdl.camera.camera_interface import camera_interface, camera_pair
from eyestereo.hdl.camera.camera_stream import camera_stream
from eyestereo.hdl.camera.sccb_master import sccb_master
from eyestereo.hdl.interfaces.axis import AxiStream
from eyestereo.hdl.axi.axis_to_stream import axis_to_stream
from eyestereo.hdl.axi.axil_arbiter import axil_arbiter
from eyestereo.hdl.axi.axil_split import axil_split
from eyestereo.hdl.streaming.convolve import convolve
from eyestereo.hdl.dense.census import census
from eyestereo.hdl.dense.median3 import median3
from eyestereo.hdl.dense.sgm import sgm
from eyestereo.hdl.dense.dense_stereo import dense_stereo
from eyestereo.hdl.interfaces.descriptor import DescriptorPort
from eyestereo.hdl.matching.corner_descriptors import corner_descriptors
from eyestereo.hdl.matching.feature_matcher import feature_matcher
from eyestereo.hdl.system.list_append import list_append
from eyestereo.hdl.matching.match_engine import limit_bits, match_engine
from eyestereo.tools.models.match_engine import word_bits as match_word_bits
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
from eyestereo.hdl.rectify.fetch_interpolate import fetch_interpolate
from eyestereo.hdl.streaming.line_delay import line_delay
from eyestereo.hdl.rectify.poly_unit import CoefPort, poly_unit
from eyestereo.hdl.rectify.rectifier import rectifier
from eyestereo.hdl.rectify.line_cache import line_cache
from eyestereo.hdl.memory.sdram_controller import sdram_controller
from eyestereo.hdl.memory.sdram_bridge import sdram_bridge
from eyestereo.hdl.memory.sdram_subsystem import sdram_subsystem
from eyestereo.hdl.interfaces.sdram_bus import SdramPins, SdramPort
from eyestereo.tools.sdram import ULX3S
from eyestereo.tools.sdram import part as sdram_part
from eyestereo.hdl.rectify.stream_rectifier import stream_rectifier
from eyestereo.hdl.rectify.calibration import calibration_of
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
from eyestereo.hdl.serial.uart_bridge import uart_bridge
from eyestereo.hdl.serial.uart_rx import ByteStream, uart_rx
from eyestereo.hdl.serial.uart_tx import uart_tx
from eyestereo.hdl.video.tmds_encoder import tmds_encoder
from eyestereo.hdl.video.tmds_serializer import tmds_serializer
from eyestereo.hdl.video.video_timing import coord_bits, video_timing
from eyestereo.hdl.video.pair_display import pair_display
from eyestereo.hdl.boards.board_regs import board_regs
from eyestereo.tools.models.video_timing import mode_of
from eyestereo.tools.camera import WORD as CAMERA_WORD
from eyestereo.hdl.axi.stream_to_axis import stream_to_axis
from eyestereo.tools.models import cornerness as corner_model
from eyestereo.tools.models.census import census_bits
from eyestereo.tools.models import harris_window as window_model
from eyestereo.tools.models import nms as nms_model
from eyestereo.tools.models import sobel as sobel_model
from eyestereo.tools.models import stream_checker as checker_model
from eyestereo.tools.models.convolve import check_kernel, output_width
from eyestereo.tools.models import poly_unit as poly_model


_CLOCK = re.compile(r"^[a-z]?clk$")
_RESET = re.compile(r"^[a-z]?rst(_[lr])?$")


def _rst():
    return ResetSignal(0, active=1, isasync=False)


def block_defaults(func: Callable) -> dict:
    """The keyword-only parameters of a block function with their defaults (the block's own signature)."""
    return {k: v.default for k, v in inspect.signature(func).parameters.items() if v.kind is v.KEYWORD_ONLY}


def fresh_ports(func: Callable, **given) -> dict:
    """Fresh ports of ``func`` in its call order: the ``given`` ones, a ``Signal(bool(0))`` for each clock
    (``clk``, ``wclk``, ...), the library's reset for each reset (``rst``, ``wrst_l``, ...); an optional
    port (default None) that is not given is left out (it must come last, as the blocks write it)."""
    ports, skipped = {}, None
    for name, par in inspect.signature(func).parameters.items():
        if par.kind is par.KEYWORD_ONLY:
            break
        if name in given:
            port = given.pop(name)
        elif _CLOCK.match(name):
            port = Signal(bool(0))
        elif _RESET.match(name):
            port = _rst()
        elif par.default is None:
            skipped = name
            continue
        else:
            raise ValueError(f"{func.__name__}: the catalogue has no port {name}")
        if skipped is not None:
            raise ValueError(f"{func.__name__}: port {name} follows the optional port {skipped}, which is not given")
        ports[name] = port
    if given:
        raise ValueError(f"{func.__name__} has no port(s) {sorted(given)}")
    return ports


@dataclass(frozen=True)
class BlockSpec:
    name: str
    summary: str
    func: Callable
    defaults: dict
    sink_width: Callable[[dict], int] | None = None
    source_width: Callable[[dict], int] | None = None
    hw_params: tuple[str, ...] = field(default=())  # parameters passed to the block function
    #: control ports (after ``source`` in the block's signature): name -> function(params) -> fresh Signal
    control: tuple[tuple[str, Callable[[dict], object]], ...] = field(default=())
    #: blocks whose ports are not ``clk, rst, sink, source, <control>`` (several clocks, a camera bus,
    #: a queue port): function(params) -> ports dict of a fresh instance
    build: Callable[[dict], dict] | None = None
    #: interface classes of ``sink`` and ``source`` (built with the stream width)
    sink_type: type = ImageStream
    source_type: type = ImageStream
    #: clock ports with the thesis's goal in MHz (None: none, or the default of eyestereo.hdl.flow.synth)
    clocks: tuple[tuple[str, float | None], ...] = (("clk", None),)
    #: bench tops only: hand-written test models simulated beside the conversion, function(language: "vhdl" or
    #: "verilog") -> {file name: text} (written into the conversion's folder, compiled before the top)
    sources: Callable[[str], dict[str, str]] | None = None

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

        # a maker may return None: that port does not exist in this configuration (an optional port)
        control = {name: make(p) for name, make in self.control}
        ports = fresh_ports(self.func, sink=stream(self.sink_type, self.sink_width(p)),
                            source=stream(self.source_type, self.source_width(p)),
                            **{name: port for name, port in control.items() if port is not None})
        return ports, kw, p

    def control_names(self, **overrides) -> list[str]:
        """The control ports of a configuration, in call order (a maker returning None: no such port)."""
        p = self.params(**overrides)
        return [name for name, make in self.control if make(p) is not None]

    def elaborate(self, **overrides):
        """(instance, ports dict, parameters) of a fresh instance with the given parameters."""
        ports, kw, p = self.ports(**overrides)
        inst = self.func(*ports.values(), **kw)
        return inst, ports, p

    def entity(self, **overrides) -> str:
        return self.name


def block(name: str, summary: str, func: Callable, *, port_params: dict | None = None, differ: dict | None = None,
          **kw) -> BlockSpec:
    """A catalogue entry whose parameters are the block's own keyword-only parameters with the block's
    defaults (also its ``hw_params``), then ``port_params`` (parameters that only shape the catalogue's
    ports: ``data_width``, ``stereo``, a calibration), then ``differ`` (where the catalogue's configuration
    deliberately differs from the block's default; say why where it is given)."""
    own = block_defaults(func)
    kw.setdefault("hw_params", tuple(own))
    return BlockSpec(name, summary, func, {**own, **(port_params or {}), **(differ or {})}, **kw)


def k_right_port(p):
    """cornerness's second k port: the right camera's k on a stereo stream, no port on a mono one."""
    return k_port(p) if p.get("stereo") else None


def k_port(p):
    """A fresh k port: the ufix[8,8] code of k (cornerness_model.K)."""
    return Signal(intbv(0)[corner_model.K.wl:])


def thr_ports(*, cam_in_addr: bool = False):
    """(name, maker) of the threshold write ports ``thr_we``, ``thr_addr``, ``thr_data`` (blocks grid).

    ``cam_in_addr``: for a stereo configuration (``stereo`` parameter true) ``thr_addr`` is one bit wider,
    2 * block + cam (``prethreshold`` on a stereo stream; ``harris_stereo`` has a ``thr_cam`` port instead)."""
    def addr(p):
        n = p["blocks"][0] * p["blocks"][1]
        cam = cam_in_addr and bool(p.get("stereo"))
        return Signal(intbv(0)[max(1, (n - 1).bit_length()) + cam:])

    return (("thr_we", lambda p: Signal(bool(0))), ("thr_addr", addr),
            ("thr_data", lambda p: Signal(intbv(0)[corner_model.WORD.width:])))


def _bit(p):
    return Signal(bool(0))


def _count16(p):
    return Signal(intbv(0)[16:])


def _conv_width(p):
    k, _ = check_kernel(p.get("kernel"), p.get("col"), p.get("row"))
    return output_width(k, p["data_width"], p["shift"])[0]


def _build_camera_stream(p):
    return fresh_ports(camera_stream, cam=CameraBus(), source=ImageStream(CAMERA_WORD),
                       **({"luma": ImageStream(8)} if p["luma"] else {}))


def _build_async_fifo(p):
    return fresh_ports(async_fifo, sink=ImageStream(p["data_width"]), source=QueuePort(p["data_width"]),
                       dropped=_count16(p), full=_bit(p), empty=_bit(p))


def _build_camera_interface(p):
    return fresh_ports(camera_interface, cam=CameraBus(), source=QueuePort(CAMERA_WORD), dropped=_count16(p))


def _build_camera_pair(p):
    return fresh_ports(camera_pair, cam_l=CameraBus(), cam_r=CameraBus(), source_l=QueuePort(CAMERA_WORD),
                       source_r=QueuePort(CAMERA_WORD), dropped_l=_count16(p), dropped_r=_count16(p))


#: The rectification blocks' port-shaping parameters: ``quantizers`` is a calibration spec or a
#: quantizers.json path (:func:`eyestereo.tools.rectify.calibrations.load`; "rig" = the synthetic rig,
#: 352x288): named, where the blocks' own default (None) means the same rig, so that manifests and
#: labels say which calibration; ``coefficients``: "constant" (in the VHDL) or "register" (a coef port).
POLY_DEFAULTS = dict(block_defaults(poly_unit), quantizers="rig", coefficients="constant")


def calibration(p):
    """The calibration a rectification entry's parameters name (quantizers, source_width, source_height):
    resolved by the one function the blocks and the benches use (:mod:`eyestereo.hdl.rectify.calibration`)."""
    return calibration_of(p)


def _coef_port(p, cal):
    if p["coefficients"] not in ("constant", "register"):
        raise ValueError(f"parameter coefficients must be 'constant' or 'register', got {p['coefficients']!r}")
    return {"coef": CoefPort(poly_model.coef_data_bits(cal.formats))} if p["coefficients"] == "register" else {}


def _coord_pair(p, cal):
    return CoordPair(cal.source_width, cal.source_height, poly_model.resolve_frac(cal, p["frac"]))


def _build_poly_unit(p):
    cal = calibration(p)
    nb = poly_model.coord_bits(cal, p["frac"])
    return fresh_ports(poly_unit, enable=_bit(p), x=Signal(intbv(0)[poly_model.int_bits(cal.width):]),
                       y=Signal(intbv(0)[poly_model.int_bits(cal.height):]), select_coord=Signal(intbv(0)[3:]),
                       coord=Signal(intbv(0)[nb:]), out_of_range=_bit(p), select_coord_out=Signal(intbv(0)[3:]),
                       **_coef_port(p, cal))


def _dense_settings():
    return dict(p1=Signal(intbv(0)[8:]), p2=Signal(intbv(0)[8:]), uniqueness=Signal(intbv(0)[7:]),
                lr_check=Signal(bool(0)), subpixel=Signal(bool(0)), overrun=Signal(bool(0)))


def _build_sgm(p):
    # a stereo sink of census words, a mono source of 16-bit codes and the run-time settings
    return fresh_ports(sgm, sink=ImageStream(census_bits(p["window"]), stereo=True), source=ImageStream(16),
                       **_dense_settings())


def _build_dense_stereo(p):
    # a stereo sink of grey pixels, a mono source of 16-bit codes and the run-time settings
    return fresh_ports(dense_stereo, sink=ImageStream(8, stereo=True), source=ImageStream(16), **_dense_settings())


def _build_match_engine(p):
    # the descriptor port of the cost's words, the 16-bit list port, the run-time settings and the flag
    return fresh_ports(match_engine, sink=DescriptorPort(match_word_bits(p["cost"], p["window"]), width=p["width"],
                                                         height=p["height"]),
                       source=QueuePort(16), limit=Signal(intbv(0)[limit_bits():]), uniqueness=Signal(intbv(0)[7:]),
                       lr_check=Signal(bool(0)), dropped=Signal(bool(0)))


def _build_corner_descriptors(p):
    # a stereo sink of grey pixels, a stereo sink of flags, the descriptor port of the cost's words, two counts
    return fresh_ports(corner_descriptors, sink=ImageStream(8, stereo=True), flags=ImageStream(1, stereo=True),
                       source=DescriptorPort(match_word_bits(p["cost"], p["window"]), width=p["width"],
                                             height=p["height"]),
                       late=Signal(intbv(0)[16:]), lost=Signal(intbv(0)[16:]))


def _build_feature_matcher(p):
    # the pixels, the flags, the 16-bit list port, the engine's settings, its flag and the two counts
    return fresh_ports(feature_matcher, sink=ImageStream(8, stereo=True), flags=ImageStream(1, stereo=True),
                       source=QueuePort(16), limit=Signal(intbv(0)[limit_bits():]), uniqueness=Signal(intbv(0)[7:]),
                       lr_check=Signal(bool(0)), dropped=Signal(bool(0)), late=Signal(intbv(0)[16:]),
                       lost=Signal(intbv(0)[16:]))


def _build_list_append(p):
    # the feature lists, the match lists, the joined lists, the last list's count and overflow flag
    return fresh_ports(list_append, sink=QueuePort(16), matches=QueuePort(16), source=QueuePort(16),
                       count=Signal(intbv(0)[15:]), overflow=Signal(bool(0)))


def _build_coordinate_warper(p):
    cal = calibration(p)
    return fresh_ports(coordinate_warper, start=_bit(p), enable=_bit(p), busy=_bit(p), done=_bit(p),
                       coord=_coord_pair(p, cal), **_coef_port(p, cal))


def _build_fetch_interpolate(p):
    cal = calibration(p)
    return fresh_ports(fetch_interpolate, coord=_coord_pair(p, cal),
                       fetch=FetchPort(cal.source_width, cal.source_height),
                       source=ImageStream(8, stereo=True), busy=_bit(p))


def _build_rectifier(p):
    cal = calibration(p)
    return fresh_ports(rectifier, start=_bit(p), fetch=FetchPort(cal.source_width, cal.source_height),
                       source=ImageStream(8, stereo=True), busy=_bit(p), **_coef_port(p, cal))


def _build_line_cache(p):
    return fresh_ports(line_cache, cam0=QueuePort(CAMERA_WORD), cam1=QueuePort(CAMERA_WORD),
                       fetch=FetchPort(p["width"], p["height"]), start=_bit(p), run=_bit(p), arm=_bit(p),
                       begun=_bit(p),
                       overrun=_bit(p))


def _build_stream_rectifier(p):
    cal = calibration(p)
    return fresh_ports(stream_rectifier, cam0=QueuePort(CAMERA_WORD), cam1=QueuePort(CAMERA_WORD),
                       source=ImageStream(8, stereo=True), start=_bit(p), arm=_bit(p), begun=_bit(p), busy=_bit(p),
                       overrun=_bit(p),
                       **_coef_port(p, cal))


def _build_feature_list(p):
    cb = count_bits(p["width"], p["height"])
    return fresh_ports(feature_list, sink=ImageStream(1, stereo=True), source=QueuePort(16),
                       count_addr=Signal(intbv(0)[addr_bits(p["blocks"]):]), count_data=Signal(intbv(0)[cb:]),
                       total_left=Signal(intbv(0)[cb:]), total_right=Signal(intbv(0)[cb:]), overflow=_bit(p),
                       frame_done=_bit(p))


def _same(key):
    return lambda p: p[key]


def _fixed(width):
    return lambda p: width


BLOCKS: dict[str, BlockSpec] = {b.name: b for b in (
    block("line_delay", "one-line FIFO in block RAM: pixel (x, y-1) at (x, y)", line_delay,
          port_params=dict(data_width=8, stereo=False), sink_width=_same("data_width"),
          source_width=_same("data_width")),
    # The block has no default kernel; the catalogue's is the 3x3 binomial / 16 as two 1-D passes.
    block("convolve", "NxN integer-kernel convolution, separable or not (default: 3x3 binomial / 16)", convolve,
          port_params=dict(data_width=8), differ=dict(col=(1, 2, 1), row=(1, 2, 1), shift=4),
          sink_width=_same("data_width"), source_width=_conv_width),
    # the Harris stages take mono and stereo streams (the kind from the sink): the stereo parameter
    # shapes the catalogue's ports only
    block("sobel", "separable 3x3 Sobel, Ix and Iy as sfix[9,-3]", sobel, port_params=dict(stereo=False),
          sink_width=_fixed(8), source_width=_fixed(sobel_model.WORD.width)),
    block("harris_window", "Ix^2, Iy^2, IxIy packed in 36 bits, summed over a 5x5 [1 2 4 2 1]^2 window", harris_window,
          port_params=dict(stereo=False), sink_width=_fixed(sobel_model.WORD.width),
          source_width=_fixed(window_model.WORD.width)),
    block("cornerness", "det(G) - k trace(G)^2, 6-stage pipeline, 4 multipliers, 20-bit output", cornerness,
          port_params=dict(stereo=False), sink_width=_fixed(window_model.WORD.width),
          source_width=_fixed(corner_model.WORD.width), control=(("k", k_port), ("k_right", k_right_port))),
    block("prethreshold", "cornerness > its block's run-time threshold, else 0 (BX x BY blocks)", prethreshold,
          port_params=dict(stereo=False), sink_width=_fixed(corner_model.WORD.width),
          source_width=_fixed(corner_model.WORD.width), control=thr_ports(cam_in_addr=True)),
    block("nms", "separable non-maximum suppression 1x1/3x3/5x5 with a raster tie rule, 1-bit flags", nms,
          port_params=dict(stereo=False), sink_width=_fixed(corner_model.WORD.width),
          source_width=_fixed(nms_model.WORD.width)),
    # dense stereo (issue 28): both cameras of a stereo stream, as the rectifier delivers them
    block("census", "census transform 5x5 / 7x7 of both cameras, out-of-image neighbours 0, 24 / 48-bit words",
          census, port_params=dict(stereo=True), sink_width=_fixed(8),
          source_width=lambda p: census_bits(p["window"])),
    block("sgm", "semi-global matching of census words: D disparities, PU per clock, 2 / 4 paths, uniqueness, "
          "left-right check, sub-pixel; 16-bit codes", sgm, build=_build_sgm),
    block("dense_stereo", "census, sgm and the 3x3 median: a rectified stereo stream in, disparity codes out",
          dense_stereo, build=_build_dense_stereo),
    block("corner_descriptors", "rectified stereo pixels and corner flags -> every corner's window (SAD columns or "
          "a census word) on the descriptor port, row by row; flags joined by position", corner_descriptors,
          build=_build_corner_descriptors),
    block("match_engine", "corner descriptors of both cameras -> the frame's match list: candidates in a disparity "
          "range and +-R rows, SAD or census costs, best and second best, threshold, uniqueness, left-right check",
          match_engine, build=_build_match_engine),
    block("feature_matcher", "corner_descriptors + match_engine: rectified stereo pixels and corner flags in, each "
          "frame's match list (x, y, disparity, cost) out", feature_matcher, build=_build_feature_matcher),
    block("list_append", "a frame's feature list, filler up to a fixed word, then its match list: one list buffer "
          "for both (the front end's matcher option)", list_append, build=_build_list_append),
    block("median3", "3x3 median of 16-bit disparity codes (0xFFFF = invalid, the largest), border pixels passed "
          "through", median3, sink_width=_fixed(16), source_width=_fixed(16)),
    block("poly_unit", "the four rectification polynomials, 8-stage pipeline, 9 multipliers, 1 coordinate/clock",
          poly_unit, differ=POLY_DEFAULTS, build=_build_poly_unit),  # POLY_DEFAULTS says why
    block("coordinate_warper", "x/y counters, poly_unit and the double-buffered coordinate pair output (4 clocks/pair)",
          coordinate_warper, differ=POLY_DEFAULTS, build=_build_coordinate_warper),
    block("fetch_interpolate", "coordinate pairs -> fetch port (previous 2x2 reused) -> bilinear MAC -> 8-bit stereo "
          "stream", fetch_interpolate, port_params={k: v for k, v in POLY_DEFAULTS.items() if k != "coefficients"},
          source_width=_fixed(8), build=_build_fetch_interpolate),
    block("rectifier", "coordinate_warper + fetch_interpolate: calibration in, rectified 8-bit stereo stream out",
          rectifier, differ=POLY_DEFAULTS, source_width=_fixed(8), build=_build_rectifier),
    block("line_cache", "the last L lines of both cameras in block RAM behind a fetch port (rectify='stream')",
          line_cache, sink_width=_fixed(16),
          source_width=_fixed(8), build=_build_line_cache),
    block("stream_rectifier", "line_cache + rectifier: the cameras' streams in, the rectified stereo stream out, "
          "no frame store", stream_rectifier, differ=POLY_DEFAULTS, sink_width=_fixed(16), source_width=_fixed(8),
          build=_build_stream_rectifier),
    block("harris_mono", "Harris corners: Sobel -> window -> cornerness -> pre-threshold -> NMS", harris_mono,
          sink_width=_fixed(8), source_width=_fixed(nms_model.WORD.width), control=(("k", k_port),) + thr_ports()),
    # share 3 is stated, whatever the block's default: the catalogue's configuration is the thesis's
    # Table 6.4 design (make synth and the report measure it against the thesis's figures).
    block("harris_stereo", "stereo Harris corners: one datapath for both cameras, shared line delays and "
          "multipliers (share 1/2/3), k and block thresholds per camera", harris_stereo,
          port_params=dict(stereo=True), differ=dict(share=3),
          sink_width=_fixed(8), source_width=_fixed(nms_model.WORD.width),
          control=(("k_left", k_port), ("k_right", k_port), ("thr_cam", _bit)) + thr_ports()),
    block("feature_list", "stereo corner flags -> feature words (x, y, cam) on a 16-bit queue port, counts per "
          "camera and threshold block, a maximum per frame with an overflow flag", feature_list,
          sink_width=_fixed(1), source_width=_fixed(16), build=_build_feature_list),
    block("stream_checker", "protocol checker: lines/frames of the wrong size, stereo interleaving; sticky error "
          "and fault code; optional repair (broken frames become reset tokens)", stream_checker,
          port_params=dict(data_width=8, stereo=False), sink_width=_same("data_width"),
          source_width=_same("data_width"),
          control=(("error", _bit), ("code", lambda p: Signal(intbv(0)[checker_model.CODE_BITS:])))),
    block("camera_stream", "camera bus (PCLK, VSYNC, HREF, 8-bit YUV 4:2:2) to 16-bit words, whole frames only",
          camera_stream, port_params=dict(luma=True), sink_width=_fixed(8), source_width=_fixed(CAMERA_WORD.width),
          build=_build_camera_stream, clocks=(("cam_pclk", 18.0),)),
    block("async_fifo", "dual-clock frame FIFO: Gray pointers, a reset per domain, broken frames dropped and counted",
          async_fifo, port_params=dict(data_width=CAMERA_WORD.width), sink_width=_same("data_width"),
          source_width=_same("data_width"), build=_build_async_fifo, clocks=(("wclk", 18.0), ("rclk", 100.0))),
    block("camera_interface", "camera_stream + async_fifo: a camera bus in, whole frames in the system clock out",
          camera_interface, sink_width=_fixed(8), source_width=_fixed(CAMERA_WORD.width),
          build=_build_camera_interface, clocks=(("cam_pclk", 18.0), ("rclk", 100.0))),
    block("camera_pair", "two camera_interfaces, each with its own camera clock, into one system clock",
          camera_pair, sink_width=_fixed(8), source_width=_fixed(CAMERA_WORD.width), build=_build_camera_pair,
          clocks=(("cam_l_pclk", 18.0), ("cam_r_pclk", 18.0), ("rclk", 100.0))),
    block("stream_to_axis", "image stream -> AXI4-Stream video (UG934), FIFO for tready, cut frames on overflow",
          stream_to_axis, port_params=dict(data_width=8), sink_width=_same("data_width"),
          source_width=_same("data_width"), source_type=AxiStream, control=(("overflow", _bit),)),
    block("axis_to_stream", "AXI4-Stream video (UG934) -> image stream of a fixed geometry, tokens for faults",
          axis_to_stream, port_params=dict(data_width=8), sink_width=_same("data_width"),
          source_width=_same("data_width"), sink_type=AxiStream, control=(("error", _bit),)),
)}


def _build_sdram_controller(p):
    part = sdram_part(p["part"])
    return fresh_ports(sdram_controller, port=SdramPort(part.addr_bits, p["max_burst"], part.data_bits),
                       pins=SdramPins(part))


# --- the SRAM subsystem (issue 12): blocks with interfaces of their own, ports made by ``build`` --------
def masters(p):
    """Fresh ports of the six SRAM masters (and the frame handshake and status port) for ``p``'s frame."""
    return dict(cam0=QueuePort(CAMERA_WORD), cam1=QueuePort(CAMERA_WORD), fetch=FetchPort(p["width"], p["height"]),
                rect=ImageStream(8, stereo=True), feat=QueuePort(16), host=HostPort(), ctl=FrameControl(),
                stat=StatPort())


_CLOCK_100 = (("clk", 100.0),)

for _b in (
    block("sram_controller", "1M x 16 synchronous SRAM (NoBL or pipelined SyncBurst): pins <-> in-order word port",
          sram_controller, port_params=dict(tag_bits=5), sink_width=_fixed(16), source_width=_fixed(16),
          build=lambda p: fresh_ports(sram_controller, cmd=SramCmd(tag_bits=p["tag_bits"]),
                                      rsp=SramRsp(tag_bits=p["tag_bits"]), sram=SramPins()), clocks=_CLOCK_100),
    block("double_buffer", "frame handshake of one producer's two SRAM buffers (FREE/WRITING/FULL/READING)",
          double_buffer, sink_width=_fixed(1), source_width=_fixed(1),
          build=lambda p: fresh_ports(double_buffer, side=BufferSide()), clocks=_CLOCK_100),
    block("sram_arbiter", "six SRAM masters (2 cameras, fetch port, rectified, features, host), double buffers",
          sram_arbiter, sink_width=_fixed(16), source_width=_fixed(8),
          build=lambda p: fresh_ports(sram_arbiter, **masters(p), cmd=SramCmd(tag_bits=TAG_BITS),
                                      rsp=SramRsp(tag_bits=TAG_BITS)), clocks=_CLOCK_100),
    block("sdram_controller", "SDR SDRAM (the ULX3S's AS4C32M16SB): pins <-> in-order burst port, open rows, "
          "bank interleaving, auto refresh", sdram_controller, sink_width=_fixed(16), source_width=_fixed(16),
          build=_build_sdram_controller, clocks=_CLOCK_100),
    block("sdram_bridge", "the SRAM arbiter's word port as one-word bursts on the SDRAM controller's port, tags kept",
          sdram_bridge, sink_width=_fixed(16), source_width=_fixed(16),
          build=lambda p: fresh_ports(sdram_bridge, cmd=SramCmd(tag_bits=TAG_BITS), rsp=SramRsp(tag_bits=TAG_BITS),
                                      port=SdramPort(sdram_part(ULX3S).addr_bits, 1)), clocks=_CLOCK_100),
    block("sdram_subsystem", "sram_arbiter + sdram_bridge + sdram_controller: the six masters on an SDR SDRAM",
          sdram_subsystem, sink_width=_fixed(16), source_width=_fixed(8),
          build=lambda p: fresh_ports(sdram_subsystem, **masters(p), sdram=SdramPins(sdram_part(p["part"]))),
          clocks=_CLOCK_100),
    block("sram_subsystem", "sram_arbiter + sram_controller: the SRAM's pins and the six masters' ports",
          sram_subsystem, sink_width=_fixed(16), source_width=_fixed(8),
          build=lambda p: fresh_ports(sram_subsystem, **masters(p), sram=SramPins()), clocks=_CLOCK_100),
):
    BLOCKS[_b.name] = _b


# --- the complete system (issue 15): the register bank on the AXI4-Lite register bus ---------------------
def _build_register_bank(p):
    from eyestereo.tools.regmap import REGMAP

    return fresh_ports(register_bank, bus=AxiLite(REGMAP.addr_bits), regs=RegisterPorts(REGMAP), arb=StatPort(),
                       fcount=StatPort(5, 16), host=HostPort())


def _build_stream_cdc(p):
    return fresh_ports(stream_cdc, sink=ImageStream(p["data_width"], stereo=p["stereo"]),
                       source=ImageStream(p["data_width"], stereo=p["stereo"]), dropped=_count16(p))


def _build_stereo_frontend(p):
    from eyestereo.tools.regmap import REGMAP

    mem = SdramPins(sdram_part(p["sdram_part"])) if p.get("memory") == "sdram" else SramPins()
    return fresh_ports(stereo_frontend, cam_l=CameraBus(), cam_r=CameraBus(), bus=AxiLite(REGMAP.addr_bits),
                       sram=mem)


for _b in (
    block("register_bank", "the register map (tools/regmap.py) on an AXI4-Lite slave: control, k, thresholds, "
          "status, arbiter counters, SRAM window", register_bank, sink_width=_fixed(32), source_width=_fixed(32),
          build=_build_register_bank, clocks=_CLOCK_100),
    block("stream_cdc", "an image stream, mono or stereo, into another clock (async_fifo inside; whole stereo frames "
          "or a reset token): the rectifier's stream into the Harris clock", stream_cdc,
          port_params=dict(data_width=8, stereo=True), sink_width=_same("data_width"),
          source_width=_same("data_width"), build=_build_stream_cdc, clocks=(("wclk", 100.0), ("rclk", 50.0))),
    block("word_cdc", "a multi-bit value into another clock by a toggle handshake, never torn (k codes, counts)",
          word_cdc, port_params=dict(width=16), sink_width=_same("width"), source_width=_same("width"),
          build=lambda p: fresh_ports(word_cdc, d=Signal(intbv(0)[p["width"]:]), q=Signal(intbv(0)[p["width"]:])),
          clocks=(("sclk", 100.0), ("dclk", 50.0))),
    block("stereo_frontend", "the complete stereo front end: two camera buses -> SRAM -> rectifier -> stereo Harris "
          "-> feature lists, AXI4-Lite registers, sequential and overlapped modes", stereo_frontend,
          sink_width=_fixed(8), source_width=_fixed(16), build=_build_stereo_frontend,
          clocks=(("clk", 100.0), ("hclk", 50.0), ("cam_l_pclk", 18.0), ("cam_r_pclk", 18.0))),
):
    BLOCKS[_b.name] = _b

# --- the board's register bus (issue 27): two masters onto the bank, the bridge's space split in two ----------
for _b in (
    block("axil_arbiter", "two AXI4-Lite masters onto one slave, one transaction at a time, round robin (the UART "
          "bridge and the display engine onto the register bank)", axil_arbiter, sink_width=_fixed(32),
          source_width=_fixed(32), clocks=_CLOCK_100,
          build=lambda p: fresh_ports(axil_arbiter, **{k: AxiLite(p["addr_bits"]) for k in ("m0", "m1", "s")})),
    # addr_bits, s0_bits, s1_bits: the ports' widths (the board's: a 24-bit bridge, the 23-bit register map)
    block("axil_split", "one AXI4-Lite master onto two slaves by one address bit (cleared on the way), one "
          "transaction at a time", axil_split, port_params=dict(addr_bits=24, s0_bits=23, s1_bits=23),
          sink_width=_fixed(32), source_width=_fixed(32), clocks=_CLOCK_100,
          build=lambda p: fresh_ports(axil_split, m=AxiLite(p["addr_bits"]), s0=AxiLite(p["s0_bits"]),
                                      s1=AxiLite(p["s1_bits"]))),
):
    BLOCKS[_b.name] = _b

# --- the cameras' SCCB configuration at start-up (issue 27) ---------------------------------------------------
BLOCKS["sccb_master"] = block(
    "sccb_master", "SCCB master: the OV7670 register table into both cameras at start-up (and on start), then "
    "their PID/VER read back (present)", sccb_master, sink_width=_fixed(1), source_width=_fixed(1),
    clocks=_CLOCK_100,
    build=lambda p: fresh_ports(sccb_master, start=Signal(bool(0)), sio_c=Signal(bool(0)), sio_d_oe=Signal(bool(0)),
                                sio_d_i=Signal(intbv(0)[p["cameras"]:]), busy=Signal(bool(0)), done=Signal(bool(0)),
                                present=Signal(intbv(0)[p["cameras"]:])))


# --- the board's monitor output (issue 27): display timing, TMDS encoding, the DDR serializer ---------------------
def _build_video_timing(p):
    m = mode_of(p["mode"])
    return fresh_ports(video_timing, hsync=_bit(p), vsync=_bit(p), de=_bit(p),
                       x=Signal(intbv(0)[coord_bits(m.h_active):]), y=Signal(intbv(0)[coord_bits(m.v_active):]),
                       line_start=_bit(p), frame_start=_bit(p))


for _b in (
    block("video_timing", "display timing of a mode (640x480@60): hsync, vsync, de, x, y and line/frame pulses, "
          "all registered", video_timing, sink_width=_fixed(1), source_width=_fixed(1), build=_build_video_timing,
          clocks=(("clk", 25.0),)),
    block("tmds_encoder", "one DVI 1.0 TMDS channel: 8b/10b transition minimised and DC balanced, control codes "
          "while de is low", tmds_encoder, sink_width=_fixed(8), source_width=_fixed(10), clocks=(("clk", 25.0),),
          build=lambda p: fresh_ports(tmds_encoder, data=Signal(intbv(0)[8:]), c0=_bit(p), c1=_bit(p), de=_bit(p),
                                      q=Signal(intbv(0)[10:]))),
    block("tmds_serializer", "three TMDS characters and the clock channel per pixel clock -> 2 bits per channel "
          "per 5x clock for DDR output cells, a toggle crossing", tmds_serializer, sink_width=_fixed(10),
          source_width=_fixed(2), clocks=(("clk", 25.0), ("clk5", 125.0)),
          build=lambda p: fresh_ports(tmds_serializer, clk5=_bit(p),
                                      **{f"d{i}": Signal(intbv(0)[10:]) for i in range(3)},
                                      **{f"q{c}": Signal(intbv(0)[2:]) for c in "012c"})),
):
    BLOCKS[_b.name] = _b


# --- the host's serial link (issue 27): UART receiver, transmitter, the bridge to the register bus -------------

for _b in (
    block("uart_rx", "UART receiver (8N1): the serial line -> bytes on a valid/ready port; framing errors and "
          "overruns flagged", uart_rx, sink_width=_fixed(1), source_width=_fixed(8), clocks=_CLOCK_100,
          build=lambda p: fresh_ports(uart_rx, rx=Signal(bool(1)), source=ByteStream(), frame_error=_bit(p),
                                      overrun=_bit(p))),
    block("uart_tx", "UART transmitter (8N1): bytes from a valid/ready port -> the serial line, back to back",
          uart_tx, sink_width=_fixed(8), source_width=_fixed(1), clocks=_CLOCK_100,
          build=lambda p: fresh_ports(uart_tx, sink=ByteStream(), tx=Signal(bool(1)))),
    block("uart_bridge", "the host's serial link: identify, read and write bursts on an AXI4-Lite master, "
          "timeouts, error count", uart_bridge, sink_width=_fixed(8), source_width=_fixed(8),
          clocks=_CLOCK_100,
          build=lambda p: fresh_ports(uart_bridge, rx=Signal(bool(1)), tx=Signal(bool(1)), bus=AxiLite(p["addr_bits"]),
                                      errors=Signal(intbv(0)[16:]))),
):
    BLOCKS[_b.name] = _b

# --- the board's own blocks (issue 27): the monitor's picture, the board registers ------------------------------
def _build_pair_display(p):
    return fresh_ports(pair_display, pclk=_bit(p), prst=_rst(), bus=AxiLite(p["addr_bits"]), run=_bit(p),
                       copies=Signal(intbv(0)[16:]), idle=_bit(p), hsync=_bit(p), vsync=_bit(p), de=_bit(p),
                       red=Signal(intbv(0)[8:]), green=Signal(intbv(0)[8:]), blue=Signal(intbv(0)[8:]))


def _build_board_regs(p):
    return fresh_ports(board_regs, bus=AxiLite(p["addr_bits"]), display_run=_bit(p), sccb_restart=_bit(p),
                       pll_locked=_bit(p), sccb_busy=_bit(p), display_idle=_bit(p), cam_present=Signal(intbv(0)[2:]),
                       copies=Signal(intbv(0)[16:]), uart_errors=Signal(intbv(0)[16:]))


for _b in (
    block("pair_display", "the board's monitor picture: the newest rectified pair (taken over AXI4-Lite as a host "
          "does) side by side with its corners marked, their anaglyph below", pair_display,
          port_params=dict(addr_bits=23), sink_width=_fixed(32), source_width=_fixed(8),
          build=_build_pair_display, clocks=(("clk", 100.0), ("pclk", 25.0))),
    block("board_regs", "the board's own registers (tools/board/regmap.py) on an AXI4-Lite slave", board_regs,
          port_params=dict(addr_bits=8), sink_width=_fixed(32), source_width=_fixed(32), build=_build_board_regs,
          clocks=_CLOCK_100),
):
    BLOCKS[_b.name] = _b

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
