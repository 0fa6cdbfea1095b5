"""cocotb bench: double_buffer (the frame handshake of one producer's two buffers) against its clock-true
model :class:`eyestereo.tools.models.sram_arbiter.DoubleBufferModel`.

A random producer (asks for a buffer, writes for a while, then publishes or aborts) and a random
consumer (wants a frame or not, holds it, releases it) drive the block; after every clock edge the
buffer states, the held buffer, the answers to the producer and the three event counters must equal the
model's. Inputs change at the falling edge, outputs are read in the read-only phase after the rising one.
"""

from __future__ import annotations

import random

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, ReadOnly, RisingEdge

from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.sram_model import read_int
from eyestereo.tools.models.sram_arbiter import DoubleBufferModel

INPUTS = ("p_start", "p_done", "p_done_buf", "p_abort", "p_abort_buf", "c_take", "c_release")


@cocotb.test()
async def double_buffer_random(dut):
    cfg = load_config()
    rng = random.Random(cfg.get("seed", 1))
    clk = dut.clk
    Clock(clk, 10, unit="ns").start()
    for n in INPUTS:
        getattr(dut, f"side_{n}").value = 0
    dut.rst.value = 1
    await ClockCycles(clk, 3)
    dut.rst.value = 0
    await FallingEdge(clk)
    model = DoubleBufferModel()
    prod, left, mybuf, held_for, want = "idle", 0, 0, 0, False
    events = dict(grants=0, denies=0, takes=0, aborts=0)
    for clock in range(cfg.get("clocks", 3000)):
        drive = {n: 0 for n in INPUTS}
        if prod == "idle" and rng.random() < cfg.get("frame_rate", 0.2):
            prod = "asking"
        if prod == "asking":
            drive["p_start"] = 1
        elif prod == "writing":
            left -= 1
            if left <= 0:
                if rng.random() < 0.1:
                    drive["p_abort"], drive["p_abort_buf"] = 1, mybuf
                    events["aborts"] += 1
                else:
                    drive["p_done"], drive["p_done_buf"] = 1, mybuf
                prod = "idle"
        if rng.random() < 0.05:
            want = not want
        drive["c_take"] = int(want)
        if model.held:
            held_for += 1
            if held_for > 5 and rng.random() < 0.05:
                drive["c_release"] = 1
                held_for = 0
        for n, v in drive.items():
            getattr(dut, f"side_{n}").value = v
        await RisingEdge(clk)
        was_held = model.held
        model.clock(**{n: (v if n.endswith("_buf") else bool(v)) for n, v in drive.items()})
        await ReadOnly()
        st = read_int(dut.side_state)
        got = dict(state=[st & 3, st >> 2], held=read_int(dut.side_c_held), grant=read_int(dut.side_p_grant),
                   deny=read_int(dut.side_p_deny), published=read_int(dut.side_published),
                   dropped=read_int(dut.side_dropped), overwritten=read_int(dut.side_overwritten))
        exp = dict(state=model.state, held=int(model.held), grant=int(model.p_grant), deny=int(model.p_deny),
                   published=model.published, dropped=model.dropped, overwritten=model.overwritten)
        assert got == exp, f"clock {clock}: the block has {got}, the model {exp}"
        if model.held:
            assert read_int(dut.side_c_buf) == model.buf, f"clock {clock}: held buffer differs"
            events["takes"] += int(not was_held)
        if model.p_grant:
            gbuf = read_int(dut.side_p_gbuf)
            assert gbuf == model.p_gbuf, f"clock {clock}: granted buffer {gbuf}, the model {model.p_gbuf}"
            mybuf, prod, left = gbuf, "writing", rng.randint(1, 40)
            events["grants"] += 1
        if model.p_deny:
            prod = "idle"
            events["denies"] += 1
        await FallingEdge(clk)
    events.update(published=model.published, dropped=model.dropped, overwritten=model.overwritten)
    write_report(cfg, events)
