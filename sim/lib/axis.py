"""cocotbext-axi around the AXI4-Stream video ports: pause generators and beat conversion for the benches.

The AXI side of the bridges is driven and checked by Alex Forencich's cocotbext-axi (``AxiStreamSource``,
``AxiStreamSink``; it works with cocotb 2.1). Each of its "frames" is one AXI packet, i.e. a run of
transfers ended by ``tlast``: for video that is one line. These helpers turn such packets into the
model's beats ``(tdata, tlast, tuser)`` and back, and make the random and stalling pause patterns.
"""

from __future__ import annotations

import itertools
import random

from cocotbext.axi import AxiStreamBus, AxiStreamFrame, AxiStreamSink, AxiStreamSource

__all__ = ["AxiStreamBus", "axis_sink", "axis_source", "beats_to_packets", "pauses", "packets_to_beats"]


def pauses(probability: float, seed: int = 0, stalls=()):
    """An endless pause pattern: each clock paused with ``probability``, and always within the
    ``stalls`` ``[(first_clock, clocks), ...]`` (clocks counted from the generator's start)."""
    if not 0.0 <= probability < 1.0:
        raise ValueError(f"pause probability must be in [0, 1), got {probability}")
    rng = random.Random(seed)
    for n in itertools.count():
        stalled = any(a <= n < a + length for a, length in stalls)
        yield stalled or (probability > 0 and rng.random() < probability)


def axis_sink(dut, prefix: str, clk, rst) -> AxiStreamSink:
    """An AxiStreamSink on ``<prefix>_t*`` whose beats are whole tdata words (no byte lanes)."""
    bus = AxiStreamBus.from_prefix(dut, prefix)
    return AxiStreamSink(bus, clk, rst, byte_size=len(bus.tdata))


def axis_source(dut, prefix: str, clk, rst) -> AxiStreamSource:
    bus = AxiStreamBus.from_prefix(dut, prefix)
    return AxiStreamSource(bus, clk, rst, byte_size=len(bus.tdata))


def packets_to_beats(packets) -> list[tuple[int, bool, bool]]:
    """cocotbext-axi frames (received with ``compact=False``) -> beats ``(tdata, tlast, tuser)``."""
    beats = []
    for f in packets:
        data = list(f.tdata)
        user = f.tuser if isinstance(f.tuser, list) else [f.tuser or 0] * len(data)
        for i, d in enumerate(data):
            beats.append((int(d), i == len(data) - 1, bool(user[i])))
    return beats


def beats_to_packets(beats) -> list[AxiStreamFrame]:
    """Beats ``(tdata, tlast, tuser)`` -> cocotbext-axi frames, one per run ending in ``tlast``.

    The last beat must have ``tlast`` (cocotbext-axi ends every frame with it).
    """
    if beats and not beats[-1][1]:
        raise ValueError("the last beat must carry tlast")
    out, data, user = [], [], []
    for d, last, u in beats:
        data.append(int(d))
        user.append(int(bool(u)))
        if last:
            out.append(AxiStreamFrame(tdata=data, tuser=user))
            data, user = [], []
    return out
