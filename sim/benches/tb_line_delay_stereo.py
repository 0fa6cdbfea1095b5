"""cocotb bench: line_delay on a stereo stream (left and right pixel of each (x, y) in turn).

Each camera's output frame must equal :func:`eyestereo.tools.models.line_delay.line_delay` of that
camera's input frame on every specified pixel; every beat (reset tokens included) must come out one
clock after it went in with the same eol, eof and cam.
"""

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge

from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.stream import UNKNOWN, BeatMonitor, BeatSource, IdleGenerator
from eyestereo.tools.models import line_delay as model
from eyestereo.tools.models.stream_checker import frame_beats
from eyestereo.tools.stream import TOKEN, FrameAssembler

PERIOD_NS = 10


@cocotb.test()
async def line_delay_stereo_frames(dut):
    cfg = load_config()
    p = cfg["params"]
    w, h, bits = p["width"], p["height"], p["data_width"]
    rng = np.random.default_rng(cfg.get("seed", 0))
    Clock(dut.clk, PERIOD_NS, unit="ns").start()
    source = BeatSource(dut, "sink", dut.clk, IdleGenerator(cfg.get("duty", 1.0), cfg.get("seed", 0)),
                        period_ns=PERIOD_NS)
    monitor = BeatMonitor(dut, "source", dut.clk, period_ns=PERIOD_NS)
    dut.rst.value = 1
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    await RisingEdge(dut.clk)
    monitor.beats.clear()

    frames = [rng.integers(0, 1 << bits, (2, h, w)) for _ in range(cfg.get("frames", 2))]
    beats = []
    cut = frame_beats(rng.integers(0, 1 << bits, (h, w)), stereo=True,
                      right=rng.integers(0, 1 << bits, (h, w)))
    # a token with cam = 1 resets both sides
    beats += cut[:min(cfg.get("token_after", 7), len(cut) - 2)] + [TOKEN + (1,)]
    for left, right in frames:
        beats += frame_beats(left, stereo=True, right=right)
    source.send_beats(beats)
    while source.queue:
        await ClockCycles(dut.clk, 16)
    await ClockCycles(dut.clk, 8)

    got = monitor.beats
    assert len(got) == len(beats), f"{len(got)} beats out, {len(beats)} in"
    for i, (b, g, t) in enumerate(zip(beats, got, source.sent_cycles)):
        assert g[0] == t + 1, f"beat {i}: out in cycle {g[0]}, in at {t}: latency must be 1"
        assert (g[2], g[3], g[4]) == (int(b[1]), int(b[2]), int(b[3])), f"beat {i}: flags {g[2:5]} for {b[1:]}"
        assert UNKNOWN not in (g[1], g[2], g[3], g[4]), f"beat {i}: undefined bits {g[1:5]}"
    asm = [FrameAssembler(w, h), FrameAssembler(w, h)]
    for g in got:
        if g[3] and not g[2]:
            for a in asm:
                a.push(*TOKEN)
        else:
            asm[g[4]].push(g[1], bool(g[2]), bool(g[3]))
    compared = 0
    for cam in (0, 1):
        assert len(asm[cam].frames) == len(frames) and asm[cam].pixels_pending == 0
        for f, (pair, out) in enumerate(zip(frames, asm[cam].frames)):
            exp, mask = model.line_delay(pair[cam])
            bad = (out != exp) & mask
            assert not bad.any(), f"camera {cam}, frame {f}: {bad.sum()} pixels differ, first at " \
                                  f"{np.argwhere(bad)[0].tolist()}"
            compared += int(mask.sum())
    assert compared > 0
    write_report(cfg, dict(frames=len(frames), pixels_compared=compared, beats_out=len(got)))
