"""The block catalogue: every block with its default configuration, for conversion, synthesis and benches.

Each entry knows how to build a fresh MyHDL instance with fresh ports for a set of parameters (MyHDL
needs a new instance per conversion) and the stream widths that parameter set implies.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from myhdl import ResetSignal, Signal

from eyestereo.hdl.convolve import convolve
from eyestereo.hdl.line_delay import line_delay
from eyestereo.hdl.sobel import sobel
from eyestereo.hdl.stream import ImageStream
from eyestereo.tools.convolve import check_kernel, output_width


@dataclass(frozen=True)
class BlockSpec:
    name: str
    summary: str
    func: Callable
    defaults: dict
    sink_width: Callable[[dict], int]
    source_width: Callable[[dict], int]
    hw_params: tuple[str, ...] = field(default=())  # parameters passed to the block function

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
        sink = ImageStream(self.sink_width(p))
        source = ImageStream(self.source_width(p))
        kw = {k: v for k, v in p.items() if k in self.hw_params}
        inst = self.func(clk, rst, sink, source, **kw)
        return inst, dict(clk=clk, rst=rst, sink=sink, source=source), p

    def entity(self, **overrides) -> str:
        return self.name


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
        sink_width=lambda p: 8, source_width=lambda p: 18, hw_params=("width", "height")),
}


def get(name: str) -> BlockSpec:
    try:
        return BLOCKS[name]
    except KeyError:
        raise ValueError(f"unknown block {name!r}; blocks are {sorted(BLOCKS)}") from None


def jsonable(p: dict) -> dict:
    """Parameters with numpy arrays turned into lists (for manifests and configs)."""
    return {k: (np.asarray(v).tolist() if isinstance(v, (np.ndarray, tuple)) else v) for k, v in p.items()}
