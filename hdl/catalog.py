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
from eyestereo.hdl.coord_pair import CoordPair
from eyestereo.hdl.coordinate_warper import coordinate_warper
from eyestereo.hdl.line_delay import line_delay
from eyestereo.hdl.poly_unit import CoefPort, poly_unit
from eyestereo.hdl.sobel import sobel
from eyestereo.hdl.stream import ImageStream
from eyestereo.tools.models import cornerness as corner_model
from eyestereo.tools.models import harris_window as window_model
from eyestereo.tools.models import nms as nms_model
from eyestereo.tools.models import sobel as sobel_model
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
    #: Blocks without an image stream: function(params) -> {port name: fresh Signal or interface} in
    #: the block's order after clk and rst (then sink_width/source_width/control are unused).
    ports: Callable[[dict], dict] | None = None

    @property
    def is_stream(self) -> bool:
        """Whether the block has the stream ports sink and source (else its ports come from ``ports``)."""
        return self.ports is None

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
        clk = Signal(bool(0))
        rst = ResetSignal(0, active=1, isasync=False)
        kw = {k: v for k, v in p.items() if k in self.hw_params}
        if self.ports is not None:
            ports = self.ports(p)
            inst = self.func(clk, rst, *ports.values(), **kw)
            return inst, dict(clk=clk, rst=rst, **ports), p
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


#: Rectification blocks: ``quantizers`` is a calibration spec or a quantizers.json path
#: (:func:`eyestereo.tools.rectify.calibrations.load`; "rig" = the synthetic rig, 352x288).
_POLY_DEFAULTS = dict(quantizers="rig", frac=poly_model.DEFAULT_FRAC, source_width=None, source_height=None,
                      coefficients="constant")


def _calibration(p):
    from eyestereo.hdl.poly_unit import calibration_param

    return calibration_param(p["quantizers"], p["source_width"], p["source_height"])


def _coef_port(p, cal):
    if p["coefficients"] not in ("constant", "register"):
        raise ValueError(f"parameter coefficients must be 'constant' or 'register', got {p['coefficients']!r}")
    return {"coef": CoefPort(poly_model.coef_data_bits(cal.formats))} if p["coefficients"] == "register" else {}


def _poly_ports(p):
    cal = _calibration(p)
    nb = poly_model.coord_bits(cal, p["frac"])
    return dict(enable=Signal(bool(0)), x=Signal(intbv(0)[poly_model.int_bits(cal.width):]),
                y=Signal(intbv(0)[poly_model.int_bits(cal.height):]), select_coord=Signal(intbv(0)[3:]),
                coord=Signal(intbv(0)[nb:]), out_of_range=Signal(bool(0)), select_coord_out=Signal(intbv(0)[3:]),
                **_coef_port(p, cal))


def _warper_ports(p):
    cal = _calibration(p)
    return dict(start=Signal(bool(0)), enable=Signal(bool(0)), busy=Signal(bool(0)), done=Signal(bool(0)),
                coord=CoordPair(cal.source_width, cal.source_height, poly_model.resolve_frac(cal, p["frac"])),
                **_coef_port(p, cal))


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
    "poly_unit": BlockSpec(
        "poly_unit", "the four rectification polynomials, 8-stage pipeline, 9 multipliers, 1 coordinate/clock",
        poly_unit, _POLY_DEFAULTS,
        hw_params=("quantizers", "frac", "source_width", "source_height"), ports=_poly_ports),
    "coordinate_warper": BlockSpec(
        "coordinate_warper", "x/y counters, poly_unit and the double-buffered coordinate pair output (4 clocks/pair)",
        coordinate_warper, _POLY_DEFAULTS,
        hw_params=("quantizers", "frac", "source_width", "source_height"), ports=_warper_ports),
    "harris_mono": BlockSpec(
        "harris_mono", "Harris corners: Sobel -> window -> cornerness -> pre-threshold -> NMS", harris_mono,
        dict(width=352, height=288, blocks=(4, 4), nms=3),
        sink_width=lambda p: 8, source_width=lambda p: nms_model.WORD.width,
        hw_params=("width", "height", "blocks", "nms"),
        control=(("k", _k_port),) + _thr_ports()),
}


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
