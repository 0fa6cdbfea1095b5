"""cocotb driver behind ``eyestereo sim harris``: a stereo pair through harris_stereo, the flags saved.

Not a regression bench: it feeds one frame pair (a beat every ``share`` clocks), collects each camera's
output frame and saves them as ``flags.npy`` (2, H, W); every 4096 input beats it writes the count to
``progress`` (the command's bar reads it). Python wakes on clock edges only while beats go in and out.
"""

import cocotb
import numpy as np
from cocotb.triggers import ClockCycles

from eyestereo.sim.lib.bench import load_config
from eyestereo.sim.lib.harris_ports import split_cameras, start_run
from eyestereo.sim.lib.stream import UNKNOWN
from eyestereo.tools.models.stream_checker import frame_beats


@cocotb.test()
async def harris_cli(dut):
    cfg = load_config()
    p = cfg["params"]
    w, h, share = p["width"], p["height"], p["share"]
    pair = np.load(cfg["input"])
    source, monitor = await start_run(dut, share=share, k=cfg["k"], thresholds=cfg["thresholds"])
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
