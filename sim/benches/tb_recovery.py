"""cocotb bench: a block recovers at the first reset token after a broken frame.

The config names the block's own bench class (``tb: "tb_sobel:SobelTB"``) and a fault kind of
:func:`eyestereo.tools.models.stream_checker.inject_fault`. The bench sends a good frame broken by that
fault, a reset token, and good frames; whatever the block makes of the broken frame is not looked at
(its output there is unspecified), but the token must come out, and every frame after it must equal the
block's bit-true model on every specified pixel with no undefined bit.
"""

import importlib

import cocotb
import numpy as np
from cocotb.triggers import ClockCycles

from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.stream import UNKNOWN, BeatMonitor
from eyestereo.tools.models.stream_checker import inject_fault
from eyestereo.tools.stream import FrameAssembler, frame_to_beats


@cocotb.test()
async def recovery_after_token(dut):
    cfg = load_config()
    p = cfg["params"]
    w, h = p["width"], p["height"]
    module, _, cls = cfg["tb"].partition(":")
    tb_class = getattr(importlib.import_module(f"eyestereo.sim.benches.{module}"), cls)
    tb = tb_class(dut, cfg, out_width=w, out_height=h)
    monitor = BeatMonitor(dut, "source", dut.clk, period_ns=tb.period_ns)
    await tb.reset()
    await tb.configure()
    monitor.beats.clear()

    rng = np.random.default_rng(cfg.get("seed", 0))
    broken, _ = inject_fault(frame_to_beats(tb.make_input(cfg["frames"][0], w, h)), cfg["fault"], w, h, rng)
    frames = [tb.make_input(spec, w, h) for spec in cfg["frames"][1:]]
    tb.source.send_beats(broken)
    tb.source.send_token()
    for f in frames:
        tb.source.send_frame(f)
    while tb.source.queue:
        await ClockCycles(dut.clk, 64)
    await ClockCycles(dut.clk, 4 * w + 200)  # the window blocks' self-emitted tails

    beats = monitor.beats
    tokens = [i for i, b in enumerate(beats) if b[3] == 1 and b[2] == 0]
    assert tokens, "the reset token did not come out"
    asm = FrameAssembler(w, h)
    for b in beats[tokens[0] + 1:]:
        asm.push(b[1], bool(b[2]), bool(b[3]))  # raises on any protocol fault after the token
    assert len(asm.frames) == len(frames), f"{len(asm.frames)} frames after the token, {len(frames)} sent"
    assert asm.pixels_pending == 0
    compared = 0
    for i, (f, got) in enumerate(zip(frames, asm.frames)):
        exp, mask = tb.expected(f)
        assert not (got == UNKNOWN).any(), f"frame {i}: undefined data on a valid beat"
        bad = (got != exp) & mask
        assert not bad.any(), f"frame {i} after the token: {bad.sum()} of {mask.sum()} pixels differ"
        compared += int(mask.sum())
    write_report(cfg, dict(frames=len(frames), pixels_compared=compared, beats_before_token=tokens[0]))
