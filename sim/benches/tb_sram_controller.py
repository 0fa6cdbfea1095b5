"""cocotb bench: sram_controller against the SRAM model and the controller's cycle-true model.

Random reads and writes (byte enables, a small address pool so reads hit fresh writes, idle gaps) are
offered on the word port; the SRAM model (:mod:`eyestereo.sim.lib.sram_model`) checks the part's rules on
every edge. Checks: every read returns the last word written to its address (scoreboard), with its tag,
in order; each command is taken in exactly the clock :func:`eyestereo.tools.models.sram_controller.schedule`
says, and each response comes in the clock it says; nothing is left in flight at the end.
"""

from __future__ import annotations

import random

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge

from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.sram_model import SramModel, read_int
from eyestereo.tools.models.sram_controller import Command, schedule
from eyestereo.tools.sram import SramPart, power_up_word


def random_commands(rng: random.Random, n: int, *, write_share: float, duty: float, tag_bits: int,
                    pool: int = 8) -> list[Command]:
    addrs = [rng.randrange(1 << 20) for _ in range(pool)]
    out = []
    for _ in range(n):
        addr = rng.choice(addrs) if rng.random() < 0.8 else rng.randrange(1 << 20)
        we = rng.random() < write_share
        be = rng.choice([3, 3, 3, 1, 2]) if we else 3
        gap = 0 if rng.random() < duty else rng.randint(1, 4)
        out.append(Command(we, addr, rng.randrange(1 << 16), be, rng.randrange(1 << tag_bits), gap))
    return out


def merge(old: int, data: int, be: int) -> int:
    for b in range(2):
        if (be >> b) & 1:
            m = 0xFF << (8 * b)
            old = (old & ~m) | (data & m)
    return old


@cocotb.test()
async def controller_random(dut):
    cfg = load_config()
    p = cfg["params"]
    # part_kind / part_latency: a board whose part differs from what the controller was built for (the
    # negative tests: the model or the scoreboard must catch it)
    part = SramPart(cfg.get("part_kind", p.get("kind", "nobl")), cfg.get("part_latency", p.get("read_latency", 2)))
    tag_bits = p.get("tag_bits", 5)
    rng = random.Random(cfg.get("seed", 1))
    cmds = random_commands(rng, cfg.get("commands", 300), write_share=cfg.get("write_share", 0.5),
                           duty=cfg.get("duty", 1.0), tag_bits=tag_bits)

    Clock(dut.clk, 10, unit="ns").start()
    for name in ("cmd_valid", "cmd_we", "cmd_addr", "cmd_wdata", "cmd_be", "cmd_tag"):
        getattr(dut, name).value = 0
    dut.rst.value = 1
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    await RisingEdge(dut.clk)
    model = SramModel(dut, dut.clk, part)
    model.start()

    start = 10
    exp_taken, exp_rsp = schedule(cmds, p.get("kind", "nobl"), p.get("read_latency", 2), start=start)
    mem: dict[int, int] = {}
    expected = []  # (value, tag) of reads taken, in order
    taken, rsp_clocks = [], []
    i = 0
    offer_from = start + (cmds[0].gap if cmds else 0)
    clock = 0  # the clock (cycle) we are in: after edge `clock`
    last = exp_rsp[-1] if exp_rsp else (exp_taken[-1] if exp_taken else start)
    while clock <= last + 8:
        offering = i < len(cmds) and clock >= offer_from
        if offering:
            c = cmds[i]
            dut.cmd_valid.value = 1
            dut.cmd_we.value = int(c.we)
            dut.cmd_addr.value = c.addr
            dut.cmd_wdata.value = c.data
            dut.cmd_be.value = c.be
            dut.cmd_tag.value = c.tag
        else:
            dut.cmd_valid.value = 0
        await RisingEdge(dut.clk)
        # values during `clock`, sampled at the edge that ends it
        if read_int(dut.rsp_valid) is None:
            raise AssertionError(f"clock {clock}: rsp_valid is undefined")
        if read_int(dut.rsp_valid):
            data, tag = read_int(dut.rsp_data), read_int(dut.rsp_tag)
            assert expected, f"clock {clock}: a response nobody asked for (data {data}, tag {tag})"
            want, want_tag = expected.pop(0)
            assert data is not None, f"clock {clock}: response data undefined ({dut.rsp_data.value})"
            assert (data, tag) == (want, want_tag), (
                f"clock {clock}: response {len(rsp_clocks)} is data {data:#06x} tag {tag}, expected "
                f"{want:#06x} tag {want_tag}")
            rsp_clocks.append(clock)
        if offering:
            ready = read_int(dut.cmd_ready)
            assert ready is not None, f"clock {clock}: cmd_ready undefined"
            if ready:
                c = cmds[i]
                old = mem.get(c.addr, power_up_word(c.addr))
                if c.we:
                    mem[c.addr] = merge(old, c.data, c.be)
                else:
                    expected.append((old, c.tag))
                taken.append(clock)
                i += 1
                if i < len(cmds):
                    offer_from = clock + 1 + cmds[i].gap
        clock += 1

    assert i == len(cmds), f"only {i} of {len(cmds)} commands taken"
    assert not expected, f"{len(expected)} reads never answered"
    assert taken == exp_taken, next(f"command {k} ({'write' if cmds[k].we else 'read'}) taken in clock {a}, "
                                    f"the model says {b}" for k, (a, b) in enumerate(zip(taken, exp_taken)) if a != b)
    assert rsp_clocks == exp_rsp, next(f"response {k} in clock {a}, the model says {b}"
                                       for k, (a, b) in enumerate(zip(rsp_clocks, exp_rsp)) if a != b)
    assert model.chip.idle, f"the SRAM model still has {model.chip.pending()}"
    assert not model.chip.violations
    st = model.chip.stats
    reads = sum(not c.we for c in cmds)
    assert st.reads == reads and st.writes == len(cmds) - reads, (st, reads)
    write_report(cfg, dict(commands=len(cmds), reads=reads, writes=len(cmds) - reads,
                           clocks=taken[-1] - taken[0] + 1 if taken else 0,
                           stall_clocks=sum(t - (taken[k - 1] + 1 + cmds[k].gap) for k, t in enumerate(taken) if k),
                           sram=vars(st)))
