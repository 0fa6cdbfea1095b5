"""cocotb bench: a time-shared window filter keeps its beats ``share`` clocks apart, reset tokens included.

Regression of the formal proof's finding (docs/formal.md, job ``sobel_stereo_share2``): with ``share`` > 1
a reset token that reached ``window_control`` in the clock after it emitted a tail beat went out in the
next clock, two beats one clock apart. The trace, generalised: a whole stereo frame with its beats
``share`` clocks apart, then, ``gap`` clocks after its last beat, a reset token; ``gap`` runs over every
clock of the frame's tail (so the token meets the tail in every phase), one scenario after another.

Checked on every output beat: at least ``share`` clocks after the beat before; one token out per token in,
``latency`` to ``latency + share - 1`` clocks after it (the hold the fix adds); no frame end after a token
that cut its tail, exactly one per frame otherwise; nothing left over at the end.
"""

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge

from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.stream import resolved

PERIOD_NS = 10


class SpacingTB:
    """Drives the stereo sink beat by beat on a schedule and records every source beat with its clock."""

    def __init__(self, dut, share: int):
        self.dut, self.share = dut, share
        self.cycle = 0
        self.recording = False  # from the end of the reset (the outputs are undefined before it)
        self.out: list[tuple[int, int, int, int]] = []  # (clock, eol, eof, cam) of every source beat
        Clock(dut.clk, PERIOD_NS, unit="ns").start()
        cocotb.start_soon(self._monitor())

    async def _monitor(self):
        d = self.dut
        while True:
            await RisingEdge(d.clk)
            self.cycle += 1
            if self.recording and resolved(d.source_valid.value) == 1:
                self.out.append((self.cycle, resolved(d.source_eol.value), resolved(d.source_eof.value),
                                 resolved(d.source_cam.value)))

    async def reset(self):
        self.idle()
        self.dut.rst.value = 1
        await ClockCycles(self.dut.clk, 3)
        self.dut.rst.value = 0
        await RisingEdge(self.dut.clk)
        self.recording = True

    def idle(self):
        self.dut.sink_valid.value = 0
        self.dut.sink_eol.value = 0
        self.dut.sink_eof.value = 0
        self.dut.sink_cam.value = 0
        self.dut.sink_data.value = 0

    async def beat(self, eol: int, eof: int, cam: int, data: int = 0) -> int:
        """One beat in the next clock; returns the clock number the block samples it in."""
        d = self.dut
        d.sink_valid.value, d.sink_eol.value, d.sink_eof.value = 1, eol, eof
        d.sink_cam.value, d.sink_data.value = cam, data
        await RisingEdge(d.clk)
        self.idle()
        return self.cycle

    async def frame(self, width: int, height: int) -> list[int]:
        """A stereo frame, beats ``share`` clocks apart; the clocks of its beats."""
        clocks = []
        for y in range(height):
            for x in range(width):
                for cam in (0, 1):
                    eol = int(x == width - 1)
                    clocks.append(await self.beat(eol, int(eol and y == height - 1), cam, (x + 3 * y + cam) & 0xFF))
                    await ClockCycles(self.dut.clk, self.share - 1)
        return clocks


@cocotb.test()
async def window_spacing(dut):
    cfg = load_config()
    p = cfg["params"]
    w, h, share = p["width"], p["height"], p["share"]
    lead, latency = cfg["lead"], cfg["latency"]
    tail = 2 * lead * share  # clocks from a frame's last beat to its last tail beat
    # the token comes gap + share - 1 clocks after the frame's last beat (the frame's own spacing, then gap)
    tb = SpacingTB(dut, share)
    await tb.reset()
    tokens_in = []
    frames = cut = 0
    for gap in range(1, tail + share + 1):
        # the clock after the previous scenario's last output, so scenarios do not overlap
        await ClockCycles(dut.clk, latency + tail + 2 * share)
        first = len(tb.out)
        beats = await tb.frame(w, h)
        if frames == 0:
            start = (first, beats[2 * lead])
        frames += 1
        await ClockCycles(dut.clk, gap - 1)
        tokens_in.append(await tb.beat(0, 1, gap & 1))
        cut += gap + share - 1 <= tail  # the token came while the tail was still going out
    await ClockCycles(dut.clk, latency + tail + 2 * share)

    out = tb.out
    undefined = [b for b in out if -1 in b]
    assert not undefined, f"undefined flags on source beats: {undefined[:3]}"
    gaps = [b[0] - a[0] for a, b in zip(out, out[1:])]
    close = [(a, b) for a, b, g in zip(out, out[1:], gaps) if g < share]
    assert not close, f"beats closer than {share} clocks: {close[:3]} ({len(close)} pairs)"
    tokens_out = [b[0] for b in out if b[2] and not b[1]]
    assert len(tokens_out) == len(tokens_in), f"{len(tokens_out)} tokens out, {len(tokens_in)} in"
    # output pixel (0, 0) is decided at the sink beat of input pixel (r, r), beat 2 * lead of the frame
    pixel_delay = out[start[0]][0] - start[1]
    # (the bench's clock numbers: a beat's clock is the edge that samples it, an output's the edge after it)
    assert pixel_delay == latency + 1, f"pixel latency {pixel_delay - 1} clocks, {latency} documented"
    late = [(i, o) for i, o in zip(tokens_in, tokens_out) if not pixel_delay <= o - i <= pixel_delay + share - 1]
    assert not late, f"tokens out at the wrong time (in, out): {late[:3]}"
    ends = sum(1 for b in out if b[1] and b[2] and b[3])
    assert ends == frames - cut, f"{ends} frame ends out for {frames} frames, {cut} of them cut in the tail"
    write_report(cfg, dict(frames=frames, tokens=len(tokens_in), beats_out=len(out), frame_ends=ends,
                           min_gap=min(gaps)))
