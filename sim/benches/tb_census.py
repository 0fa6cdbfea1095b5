"""cocotb bench: census against :func:`eyestereo.tools.models.census.census_stereo`, bit for bit on every pixel.

Stereo (or mono) frames go in with idle cycles (``duty``), optionally after a partial frame cut by a reset
token, back to back. Checked: each camera's output frames equal the model's census words on every pixel,
border pixels included (their rule is defined); no beat has undefined bits; exactly the frames (and the
token) that went in come out, nothing pending or extra after the tail; and every output pixel that is
not in a frame's tail comes :func:`eyestereo.hdl.dense.census.latency` clocks after its camera's input
pixel (x + r, y + r), the tail pixels after their frame's last input beat.
"""

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge

from eyestereo.hdl.dense.census import latency
from eyestereo.sim.lib.bench import grey_frame as stimulus
from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.stream import UNKNOWN, BeatMonitor, BeatSource, IdleGenerator
from eyestereo.tools.models import census as model
from eyestereo.tools.models.stream_checker import frame_beats
from eyestereo.tools.stream import TOKEN, FrameAssembler

PERIOD_NS = 10


class CensusTB:
    """Clock, reset, a beat source and monitor around ``census``; the expected words from the model."""

    def __init__(self, dut, cfg: dict):
        p = cfg["params"]
        self.dut, self.cfg = dut, cfg
        self.w, self.h, self.window = p["width"], p["height"], p["window"]
        self.stereo = bool(p.get("stereo", True))
        self.cams = 2 if self.stereo else 1
        Clock(dut.clk, PERIOD_NS, unit="ns").start()
        self.source = BeatSource(dut, "sink", dut.clk, IdleGenerator(cfg.get("duty", 1.0), cfg.get("seed", 0)),
                                 period_ns=PERIOD_NS)
        self.monitor = None

    async def reset(self):
        """Three clocks of reset; the monitor starts after it (before it the flags are U)."""
        self.dut.rst.value = 1
        await ClockCycles(self.dut.clk, 3)
        self.dut.rst.value = 0
        await RisingEdge(self.dut.clk)
        self.monitor = BeatMonitor(self.dut, "source", self.dut.clk, period_ns=PERIOD_NS)

    def beats_of(self, left, right) -> list[tuple]:
        return frame_beats(left, stereo=True, right=right) if self.stereo else frame_beats(left)

    def expected(self, left, right) -> list[np.ndarray]:
        if self.stereo:
            return list(model.census_stereo(left, right, window=self.window))
        return [model.census(left, window=self.window)]

    def check_latency(self, frame_start: list[int], got_frames: list[list[list[tuple]]]) -> int:
        """Every non-tail output pixel ``latency`` clocks after its input beat; tail pixels after the
        frame's last beat. Returns the number of pixels checked for the exact latency."""
        sent = self.source.sent_cycles
        r = self.window // 2
        lead = r * self.w + r
        npix = self.w * self.h
        want = latency(self.window)
        exact = 0
        for f, start in enumerate(frame_start):
            last_in = sent[start + npix * self.cams - 1]
            for cam in range(self.cams):
                for i, beat in enumerate(got_frames[f][cam]):
                    p = i + lead  # the input pixel whose beat completes this output's window
                    if p < npix:
                        t_in = sent[start + p * self.cams + cam]
                        assert beat[0] - t_in == want, (f"frame {f}, camera {cam}, pixel {i % self.w},{i // self.w}: "
                                                        f"out {beat[0] - t_in} clocks after its input, want {want}")
                        exact += 1
                    else:
                        assert beat[0] > last_in, f"frame {f}, camera {cam}: tail pixel {i} before the frame's end"
        return exact


@cocotb.test()
async def census_frames(dut):
    cfg = load_config()
    tb = CensusTB(dut, cfg)
    w, h = tb.w, tb.h
    await tb.reset()
    pairs = [tuple(stimulus(s, w, h) for s in specs) for specs in cfg["frames"]]
    beats, tokens = [], 0
    if cfg.get("token_after") is not None:
        cut = tb.beats_of(stimulus("random:99", w, h), stimulus("random:98", w, h))
        beats += cut[:cfg["token_after"]] + [TOKEN + ((1,) if tb.stereo else ())]
        tokens = 1
    frame_start = []
    for left, right in pairs:
        frame_start.append(len(beats))
        beats += tb.beats_of(left, right)
    tb.source.send_beats(beats)
    while tb.source.queue:
        await ClockCycles(dut.clk, 64)
    # the last frame's tail: lead pixels of each camera, a flush beat per free clock, then the pipeline
    r = tb.window // 2
    await ClockCycles(dut.clk, 2 * tb.cams * (r * w + r) + 2 * latency(tb.window) + 64)

    mon = tb.monitor
    assert not mon.undefined, f"undefined outputs: {mon.undefined[:4]}"
    got_tokens = [b for b in mon.beats if b[3] and not b[2]]
    assert len(got_tokens) == tokens, f"{len(got_tokens)} reset tokens out, {tokens} in"
    if tokens:
        assert mon.beats[0][3] and not mon.beats[0][2], "the reset token must come out before any pixel"
    asm = [FrameAssembler(w, h) for _ in range(tb.cams)]
    per_frame = [[[] for _ in range(tb.cams)] for _ in pairs]
    for b in mon.beats:
        if b[3] and not b[2]:
            for a in asm:
                a.push(*TOKEN)
            continue
        cam = b[4] if tb.stereo else 0
        f = len(asm[cam].frames)
        assert f < len(pairs), f"an extra beat after {len(pairs)} frames: {b}"
        per_frame[f][cam].append(b)
        asm[cam].push(b[1], bool(b[2]), bool(b[3]))
    compared = 0
    for cam in range(tb.cams):
        assert len(asm[cam].frames) == len(pairs), f"camera {cam}: {len(asm[cam].frames)} frames out, {len(pairs)} in"
        assert asm[cam].pixels_pending == 0, f"camera {cam}: {asm[cam].pixels_pending} pixels of a frame pending"
    for f, (left, right) in enumerate(pairs):
        for cam, exp in enumerate(tb.expected(left, right)):
            got = asm[cam].frames[f]
            assert not (got == UNKNOWN).any(), f"frame {f}, camera {cam}: undefined words"
            bad = got.astype(np.uint64) != exp
            if bad.any():
                ys, xs = np.nonzero(bad)
                detail = ", ".join(f"({x},{y}) got {int(got[y, x]):#x} want {int(exp[y, x]):#x}"
                                   for y, x in zip(ys[:6], xs[:6]))
                raise AssertionError(f"frame {f}, camera {cam}: {bad.sum()} of {bad.size} words differ: {detail}")
            compared += exp.size
    exact = tb.check_latency(frame_start, per_frame)
    assert exact > 0
    write_report(cfg, dict(frames=len(pairs), pixels_compared=compared, latency_checked=exact,
                           latency=latency(tb.window), beats_out=len(mon.beats)))
