"""cocotb bench: the rectifier against :mod:`eyestereo.tools.models.rectifier`, with a fetch-port memory model.

The memory (:class:`eyestereo.sim.lib.fetch_memory.FetchMemory`) holds the two camera images, answers every
request with the timing of the configuration and checks the port's rules; the stereo output stream is
recorded beat by beat. Checked: every beat of every frame (data, cam, eol, eof) equal to the model's
stream; every request (x, y, cam, mask) equal to the model's (the reuse rule, so the reads counted are the
model's); ``busy`` low after the last frame, no beat, request or response left over, nothing after.

Configuration: ``params`` (the rectifier's), ``images`` ("random:SEED" or ``{"left": PATH.npy, "right":
PATH.npy}``), ``frames`` (back to back, same images), the memory's ``seed``, ``ready_p``, ``latency``,
``wait_p``, ``stall_p``, ``stall``; ``reset_after`` (abandon a first frame with ``rst`` after that many
beats, the memory reset with it, then run the frames); ``lenient`` (record ``bit_exact`` instead of failing on a data
difference: the ``eyestereo sim rectify`` command), ``dump`` (an .npz of the rectified images),
``progress`` (a file the bench updates with "beats total" now and then).
"""

from __future__ import annotations

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, RisingEdge

from eyestereo.sim.lib.bench import write_report
from eyestereo.sim.lib.fetch_memory import Clocked, StereoMonitor, compare_requests, compare_stream
from eyestereo.sim.lib.rectify_bench import PERIOD, memory, quiet, rectify_config, reset, wait_beats
from eyestereo.tools.models import fetch_interpolate as fi_model
from eyestereo.tools.models import rectifier as model
from eyestereo.tools.models.coordinate_warper import coordinate_warper


def load_images(spec, w: int, h: int) -> tuple[np.ndarray, np.ndarray]:
    if isinstance(spec, dict):
        return np.load(spec["left"]), np.load(spec["right"])
    kind, _, arg = str(spec).partition(":")
    if kind == "random":
        rng = np.random.default_rng(int(arg or 1))
        return (rng.integers(0, 256, (h, w), dtype=np.uint8), rng.integers(0, 256, (h, w), dtype=np.uint8))
    raise ValueError(f"unknown image spec {spec!r}")


def figures(cal, frac, mon, mem, frames, starts, pairs_oor) -> dict:
    npx = cal.width * cal.height
    first, last = starts[0], mon.clocks[-1] if mon.clocks else 0
    inrange = 2 * npx * frames - int(pairs_oor)
    return dict(width=cal.width, height=cal.height, frames=frames, beats=len(mon.beats),
                clocks=last - first, clocks_per_pixel=(last - first) / (npx * frames),
                requests=len(mem.requests), reads=mem.reads,
                reads_per_output_pixel=mem.reads / (2 * npx * frames),
                reads_per_inrange_pixel=mem.reads / max(1, inrange), oor_sides=int(pairs_oor), frac=frac)


@cocotb.test()
async def rectifier_frames(dut):
    cfg, cal, frac = rectify_config()
    clk = dut.clk
    Clock(clk, PERIOD, unit="ns").start()
    dut.start.value = 0
    dut.rst.value = 0
    left, right = load_images(cfg.get("images", "random:1"), cal.source_width, cal.source_height)
    left, right = model.check_images(cal, left, right)
    frames = int(cfg.get("frames", 1))
    npx = cal.width * cal.height
    mem = memory(dut, cfg, {0: left, 1: right})
    mon = StereoMonitor(dut)
    await reset(dut, clk)
    loop = Clocked(clk, [mem, mon], progress=cfg.get("progress"), total=2 * npx * frames, monitor=mon)
    cocotb.start_soon(loop.run())
    if cfg.get("reset_after"):  # a frame abandoned with rst (the memory side reset with it)
        await FallingEdge(clk)
        dut.start.value = 1
        await FallingEdge(clk)
        dut.start.value = 0
        await wait_beats(clk, mon, int(cfg["reset_after"]), 100 * npx + 5000, "frame before rst")
        await FallingEdge(clk)
        dut.rst.value = 1
        mem.clear()
        await ClockCycles(clk, 3)
        await FallingEdge(clk)
        dut.rst.value = 0
        mem.clear()
        mon.beats.clear()
        mon.clocks.clear()
        await ClockCycles(clk, 5)
        assert not int(dut.busy.value) and not mon.beats, "rst must end the frame"
    starts = []
    per = (8 + 400 * float(cfg.get("stall_p", 0)) * 100 + 20 * float(cfg.get("wait_p", 0))
           + 8 / float(cfg.get("ready_p", 1)))
    for f in range(frames):
        await FallingEdge(clk)
        dut.start.value = 1
        await RisingEdge(clk)
        starts.append(loop.clock)
        await FallingEdge(clk)
        dut.start.value = 0
        await wait_beats(clk, mon, 2 * npx * (f + 1), int(npx * per * 4) + 5000, f"frame {f}")
    await quiet(dut, clk, mem, mon)

    got = mon.arrays()
    want = model.stream(cal, left, right, frac)
    want = {k: np.tile(v, frames) for k, v in want.items()}
    bit_exact = True
    try:
        compare_stream(got, want, cal.width, f"{frames} frame(s)")
    except AssertionError:
        if not cfg.get("lenient"):
            raise
        bit_exact = False
    compare_requests(mem.request_arrays(), model.requests(cal, frac, frames), "fetch requests")
    pr = coordinate_warper(cal, frac)
    oor = (int(pr["oor_l"].sum()) + int(pr["oor_r"].sum())) * frames
    report = figures(cal, frac, mon, mem, frames, starts, oor)
    report.update(bit_exact=bit_exact, first_beat=mon.clocks[0] - starts[0],
                  reads_model=fi_model.reads(model.requests(cal, frac, frames)["mask"]))
    if cfg.get("dump"):
        d = got["data"][: 2 * npx].astype(np.uint8)
        np.savez(cfg["dump"], left=d[0::2].reshape(cal.height, cal.width), right=d[1::2].reshape(cal.height, cal.width))
    write_report(cfg, report)
