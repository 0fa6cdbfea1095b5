"""cocotb driver behind ``eyestereo sim harris``: a stereo pair through harris_stereo, the flags saved.

Not a regression bench: it feeds one frame pair (a beat every ``share`` clocks), collects each camera's
output frame and saves them as ``flags.npy`` (2, H, W); every 4096 input beats it writes the count to
``progress`` (the command's bar reads it). Python wakes on clock edges only while beats go in and out.
"""

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge

from eyestereo.sim.lib.bench import load_config
from eyestereo.sim.lib.stream import UNKNOWN, BeatMonitor, BeatSource
from eyestereo.sim.benches.tb_harris_stereo import SpacedIdle, split_cameras, write_registers
from eyestereo.tools.models import cornerness as corner_model
from eyestereo.tools.models.stream_checker import frame_beats


@cocotb.test()
async def harris_cli(dut):
    cfg = load_config()
    p = cfg["params"]
    w, h, share = p["width"], p["height"], p["share"]
    pair = np.load(cfg["input"])
    Clock(dut.clk, 10, unit="ns").start()
    dut.thr_we.value = 0
    dut.thr_cam.value = 0
    dut.thr_addr.value = 0
    dut.thr_data.value = 0
    source = BeatSource(dut, "sink", dut.clk, SpacedIdle(share, 1.0, 0), period_ns=10)
    dut.rst.value = 1
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    await RisingEdge(dut.clk)
    await write_registers(dut, dut.clk, cfg["k"], cfg["thresholds"], corner_model.OUT.wl)
    monitor = BeatMonitor(dut, "source", dut.clk, period_ns=10)
    beats = frame_beats(pair[0], stereo=True, right=pair[1])
    source.send_beats(beats)
    progress = cfg["progress"]
    total = len(beats)
    while source.queue:
        await ClockCycles(dut.clk, 4096)
        with open(progress, "w") as f:
            f.write(str(total - len(source.queue)))
    await ClockCycles(dut.clk, 2 * (8 * w + 8) * share + 400)  # more than any tail (5 lines + 5 pixels)
    with open(progress, "w") as f:
        f.write(str(total))
    asm, _ = split_cameras(monitor.beats, w, h)
    if any(len(a.frames) != 1 for a in asm) or monitor.undefined:
        raise AssertionError(f"harris_stereo gave {[len(a.frames) for a in asm]} frames, "
                             f"{len(monitor.undefined)} undefined beats")
    flags = np.stack([asm[0].frames[0], asm[1].frames[0]])
    if (flags == UNKNOWN).any():
        flags = np.where(flags == UNKNOWN, 0, flags)  # only where the flags are unspecified (the border)
    np.save(cfg["output"], flags.astype(np.uint8))
