"""cocotb bench: word_cdc, random words in the source clock, what the destination shows, against the contract.

The source word changes at random source edges (runs of changes on consecutive edges, and pauses long
enough for a transfer); the monitor records every change of ``q`` (it wakes on ``q``, not on every
clock) with its time. :func:`eyestereo.tools.models.word_cdc.check` then holds the record to the block's
contract: only whole values ``d`` had, in order, none earlier than two destination clocks after it, and
the last one within the settle time.

Config: ``params`` (width), ``sclk``/``dclk`` ([period, phase] ps), ``changes``, ``seed``.
"""

from __future__ import annotations

import random

import cocotb
from cocotb.simtime import get_sim_time
from cocotb.triggers import ValueChange

from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.queue import EdgeClock, wait_until
from eyestereo.tools.models.async_fifo import ClockSpec
from eyestereo.tools.models.word_cdc import check, settle_time


@cocotb.test()
async def words_cross(dut):
    cfg = load_config()
    n = cfg["params"]["width"]
    rng = random.Random(cfg.get("seed", 1))
    sclk, dclk = ClockSpec(*cfg["sclk"]), ClockSpec(*cfg["dclk"])
    sc, dc = EdgeClock(dut.sclk, sclk), EdgeClock(dut.dclk, dclk)
    dut.d.value = 0
    d_changes = [(0, 0)]
    q_changes = []

    async def monitor():
        while True:
            await ValueChange(dut.q)
            v = dut.q.value
            assert v.is_resolvable, f"q is {v} at {get_sim_time(unit='ps')} ps"
            q_changes.append((get_sim_time(unit="ps"), int(v)))

    for c in (sc, dc):
        cocotb.start_soon(c.start())
    cocotb.start_soon(monitor())
    k = 4
    for _ in range(cfg.get("changes", 300)):
        k += 1 if rng.random() < 0.5 else rng.randrange(2, 40)
        await wait_until(sc.before(k))
        v = rng.getrandbits(n)
        dut.d.value = v
        d_changes.append((get_sim_time(unit="ps"), v))
    end = get_sim_time(unit="ps") + 2 * settle_time(sclk.period, dclk.period)
    await wait_until(end)
    errors = check(d_changes, q_changes, s_period=sclk.period, d_period=dclk.period, end=end)
    assert not errors, f"{len(errors)} breaches: {errors[:5]}"
    assert q_changes and q_changes[-1][1] == d_changes[-1][1]
    write_report(cfg, dict(d_changes=len(d_changes) - 1, q_changes=len(q_changes)))
