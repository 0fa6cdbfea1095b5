"""cocotb bench: video_timing against :func:`eyestereo.tools.models.video_timing.signals`, every output, every clock.

After the reset, the outputs after clock edge k (the first edge with ``rst`` low being edge 0) must be the
model's counter state k, for ``clocks`` clocks (two whole frames of a small mode, or the first lines of
640x480, vertical sync and back porch included). Then a reset in the middle of a line: while it is high
the outputs are idle (syncs at the mode's idle levels, the rest 0), and after it the block starts again at
state 0, compared for ``restart`` clocks more. The outputs are flip-flops, so they are read at the falling
edge (stable there; nothing is written in the read-only phase).

Config: ``params`` (the block's: ``mode``), ``clocks``, ``restart``, ``gap`` (clocks of running before the
second reset).
"""

from __future__ import annotations

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, RisingEdge

from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.tools.models.video_timing import OUTPUTS, mode_of, signals


class TimingTB:
    """Clock, reset and a recorder of the seven outputs."""

    def __init__(self, dut, mode):
        self.dut = dut
        self.mode = mode
        self.ports = [getattr(dut, name) for name in OUTPUTS]
        Clock(dut.clk, 40, unit="ns").start()  # 25 MHz

    def read(self) -> list[int]:
        out = []
        for name, p in zip(OUTPUTS, self.ports, strict=True):
            v = p.value
            assert v.is_resolvable, f"{name} is {v}"
            out.append(int(v))
        return out

    async def reset(self, clocks: int = 3) -> None:
        """Reset for ``clocks`` edges, checking the idle outputs; returns at the falling edge after edge 0."""
        self.dut.rst.value = 1
        await ClockCycles(self.dut.clk, clocks)
        await FallingEdge(self.dut.clk)
        idle = dict(zip(OUTPUTS, self.read(), strict=True))
        want = dict(hsync=int(not self.mode.h_pol), vsync=int(not self.mode.v_pol), de=0, x=0, y=0, line_start=0,
                    frame_start=0)
        assert idle == want, f"outputs during the reset {idle}, idle levels {want}"
        self.dut.rst.value = 0
        await RisingEdge(self.dut.clk)  # edge 0
        await FallingEdge(self.dut.clk)

    async def record(self, n: int) -> np.ndarray:
        """The outputs after ``n`` consecutive edges (the caller is at the falling edge after the first)."""
        rows = []
        for i in range(n):
            if i:
                await FallingEdge(self.dut.clk)
            rows.append(self.read())
        return np.array(rows, dtype=np.int64)


def compare(got: np.ndarray, mode, what: str) -> None:
    want = signals(mode, len(got))
    for j, name in enumerate(OUTPUTS):
        bad = np.nonzero(got[:, j] != want[name])[0]
        if len(bad):
            k = int(bad[0])
            h, v = k % mode.h_total, k // mode.h_total % mode.v_total
            raise AssertionError(f"{what}: {name} = {got[k, j]} after edge {k} (h {h}, v {v}), the model says "
                                 f"{want[name][k]} ({len(bad)} clocks differ)")


@cocotb.test()
async def timing_matches_model(dut):
    cfg = load_config()
    mode = mode_of(cfg["params"].get("mode", "640x480@60"))
    tb = TimingTB(dut, mode)
    await tb.reset()
    n = int(cfg.get("clocks", 2 * mode.frame_clocks))
    compare(await tb.record(n), mode, "after the first reset")
    await ClockCycles(dut.clk, int(cfg.get("gap", mode.h_total // 3)))
    await tb.reset(clocks=2)
    m = int(cfg.get("restart", mode.h_total + 5))
    compare(await tb.record(m), mode, "after the reset mid-line")
    write_report(cfg, dict(clocks=n, restart=m, frames=n / mode.frame_clocks, mode=mode.name))
