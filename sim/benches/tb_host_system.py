"""cocotb bench: the host driver through the register bank on the real SRAM subsystem and the SRAM model.

On :mod:`eyestereo.sim.harnesses.host_harness` (register_bank + sram_subsystem, wired as docs/registers.md says),
with cocotbext-axi's AxiLiteMaster and the bus checker, the SRAM model checking the part's rules:

1. the host writes words into the host area of the SRAM and reads them back (the arbiter's host port,
   the controller, the part);
2. camera 0 sends one frame (the queue-port agent of the SRAM benches); the host waits for it by polling
   the arbiter's published-frame count (``ARB``), finds the FULL buffer in the buffer-state word, and
   reads the frame back through the SRAM window: every word as sent (the address map of
   :class:`~eyestereo.tools.models.sram_arbiter.AddressMap`);
   (the report gives the clocks per word of that read-out, on a quiet bus);
3. the arbiter's counters seen through the bank: words moved by camera 0 and by the host equal what the
   bench counted; clocks since reset grow; STATUS.avail shows camera 0's FULL frame (the wiring).
"""

from __future__ import annotations

import random

import cocotb
from cocotb.clock import Clock
from cocotb.simtime import get_sim_time
from cocotb.triggers import ClockCycles, RisingEdge

from eyestereo.sim.lib.axil import AxiLiteHost
from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.sram_agents import CameraSource
from eyestereo.sim.lib.sram_model import SramModel
from eyestereo.tools.host_driver import HostDriver
from eyestereo.tools.models.sram_arbiter import FULL, AddressMap
from eyestereo.tools.regmap import REGMAP
from eyestereo.tools.sram import SramPart


@cocotb.test()
async def host_reads_a_camera_frame(dut):
    cfg = load_config()
    p = cfg["params"]
    w, h = p.get("width", 16), p.get("height", 4)
    amap = AddressMap(w, h, p.get("feature_words", 64))
    rng = random.Random(cfg.get("seed", 1))
    clk = dut.clk
    Clock(clk, 10, unit="ns").start()
    idle = ["cam0_valid", "cam1_valid", "fetch_req_valid", "rect_valid", "feat_valid", "ctl_cam_run", "ctl_cam_arm",
            "ctl_cam_want", "ctl_cam_release", "fcount_data"]
    idle += [f"regs_{f}" for r in REGMAP.of_kind("status") for f in (x.name for x in r.fields)
             if f not in ("avail", "rect_held", "feat_held", "rect_buf", "feat_buf")]
    for n in idle:
        getattr(dut, n).value = 0
    dut.rst.value = 1
    bus = AxiLiteHost(dut, "bus", clk, dut.rst)
    bus.pauses(cfg.get("pause", 0.2), cfg.get("seed", 1))
    await ClockCycles(clk, 4)
    dut.rst.value = 0
    await RisingEdge(clk)
    sram = SramModel(dut, clk, SramPart("nobl", 2))
    sram.start()
    drv = HostDriver(bus)
    await drv.check_id()
    assert await drv.geometry() == (w, h)

    # 1. the host area
    base = amap.host_base
    words = [rng.randrange(1 << 16) for _ in range(12)]
    await drv.write_sram_words(base, words)
    assert await drv.read_sram_words(base, len(words)) == words, "host area read back differs"
    host_moves = 2 * len(words)

    # 2. one camera frame
    cam = CameraSource(dut, "cam0", random.Random(7), width=w, height=h, rate=0.5, depth=64)
    cam.limit = 1
    dut.ctl_cam_run.value = 1  # camera 0 captures every frame it can

    async def camera():
        k = 0
        while True:
            await RisingEdge(clk)
            cam.sample(k)
            cam.drive(k)
            k += 1

    cocotb.start_soon(camera())
    for _ in range(200):  # (window reads are not SRAM accesses: only the host area and the frame count)
        if (await drv.read("ARB", 13)) & 0xFFFF >= 1:  # camera 0 frames published
            break
        await bus.wait(20)
    else:
        raise AssertionError("camera 0's frame was never published")
    states = await drv.read("ARB", 19)
    cam0 = states & 0xF
    full = [b for b in (0, 1) if (cam0 >> (2 * b)) & 3 == FULL]
    assert len(full) == 1, f"camera 0 buffer states {cam0:#x}: one FULL buffer expected"
    bus.pauses(0)  # the read-out rate of a frame through the bus, master without pauses
    t0 = get_sim_time(unit="ns")
    got = await drv.read_sram_words(amap.camera(0, full[0]), w * h)
    clocks_per_word = (get_sim_time(unit="ns") - t0) / 10 / (w * h)
    host_moves += w * h
    assert got == cam.frames[0], "the frame read through the bus differs from the one camera 0 sent"
    st = await drv.status()
    assert st["avail"] & 1 == 1, f"STATUS.avail {st['avail']:#x}: camera 0's FULL frame not shown"

    # 3. the arbiter's counters through the bank
    arb = await drv.arbiter()
    assert arb["moved_cam0"] == w * h == cam.moved, (arb["moved_cam0"], cam.moved)
    assert arb["moved_host"] == host_moves, (arb["moved_host"], host_moves)
    assert arb["moved_cam1"] == arb["moved_fetch"] == arb["moved_rect"] == arb["moved_feat"] == 0
    c1 = arb["clocks"]
    await bus.wait(100)
    assert (await drv.read("ARB", 12)) - c1 >= 100
    bus.checker.check()
    assert sram.error is None
    write_report(cfg, dict(host_moves=host_moves, arb=arb, axi=bus.checker.counts,
                           sram_read_clocks_per_word=round(clocks_per_word, 2)))
