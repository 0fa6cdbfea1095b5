"""Drivers of harris_stereo's ports, shared by its benches (``tb_harris_stereo``, ``tb_harris_cli``).

The start of a run (clock, reset, the k and threshold registers, the source and the monitor), the source's
spacing of beats (at least ``share`` clocks apart) and the split of the interleaved output by camera. A
bench imports no other bench: what two of them share lives here.
"""

from __future__ import annotations

import random

from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge

from eyestereo.sim.lib.stream import BeatMonitor, BeatSource
from eyestereo.tools.models import cornerness as corner_model
from eyestereo.tools.stream import TOKEN, FrameAssembler

#: The bench clock's period.
PERIOD_NS = 10


class SpacedIdle:
    """Offers a beat at least ``share`` clocks after the previous one, then each clock with probability ``duty``."""

    def __init__(self, share: int, duty: float, seed: int):
        self.share = share
        self.duty = duty
        self.rng = random.Random(seed)
        self.since = share

    def __call__(self) -> bool:
        # called once per clock while beats wait: ``since`` = clocks since the last beat, this one included
        ok = self.since >= self.share and (self.duty >= 1.0 or self.rng.random() < self.duty)
        self.since = 1 if ok else self.since + 1
        return ok


async def write_registers(dut, clk, k, thresholds, bits: int) -> None:
    """Set ``k_left``/``k_right`` and write every camera's block thresholds (``bits`` wide) over ``thr_*``."""
    dut.k_left.value = int(k[0])
    dut.k_right.value = int(k[1])
    for cam in (0, 1):
        for i, v in enumerate(thresholds[cam]):
            dut.thr_we.value = 1
            dut.thr_cam.value = cam
            dut.thr_addr.value = i
            dut.thr_data.value = int(v) & ((1 << bits) - 1)
            await RisingEdge(clk)
    dut.thr_we.value = 0
    await RisingEdge(clk)


async def start_run(dut, *, share: int, k, thresholds, duty: float = 1.0,
                    seed: int = 0) -> tuple[BeatSource, BeatMonitor]:
    """Start the clock, reset the block for 3 clocks, write its registers; returns the ``sink``'s source
    (beats :class:`SpacedIdle`) and the ``source``'s monitor (recording from the first clock after the writes)."""
    Clock(dut.clk, PERIOD_NS, unit="ns").start()
    dut.thr_we.value = 0
    dut.thr_cam.value = 0
    dut.thr_addr.value = 0
    dut.thr_data.value = 0
    source = BeatSource(dut, "sink", dut.clk, SpacedIdle(share, duty, seed), period_ns=PERIOD_NS)
    dut.rst.value = 1
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    await RisingEdge(dut.clk)
    await write_registers(dut, dut.clk, k, thresholds, corner_model.OUT.wl)
    return source, BeatMonitor(dut, "source", dut.clk, period_ns=PERIOD_NS)


def split_cameras(beats, w: int, h: int) -> tuple[list[FrameAssembler], list[str]]:
    """Two FrameAssemblers fed from output beats (cycle, data, eol, eof, cam); tokens reach both. Also the
    order of what came out ("token" for each reset token)."""
    asm = [FrameAssembler(w, h), FrameAssembler(w, h)]
    order = []
    for b in beats:
        _, data, eol, eof, cam = b[:5]
        if eof and not eol:
            for a in asm:
                a.push(*TOKEN)
            order.append("token")
        else:
            asm[cam].push(data, bool(eol), bool(eof))
    return asm, order
