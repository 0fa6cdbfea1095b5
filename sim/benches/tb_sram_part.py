"""cocotb bench: the HDL SRAM part of the fast harness against the Python part model, pin for pin.

The same random pin sequence goes to the HDL ``sram_part`` (:mod:`eyestereo.sim.harnesses.frontend_harness`) and
to :class:`~eyestereo.tools.sram.SramChip` (NoBL, the same read latency, ``strict=False``): mostly legal single
reads and writes (random addresses in a small window, so reads hit written, forwarded and never-written words;
random byte enables), and, with probability ``fault_rate`` per cycle, one broken rule of the config's ``faults``
(``ld_n`` high, a write with no byte enabled, a stray DQ drive, a drive during read data, ``oe_n`` high during
read data). Every word the part drives must equal the Python model's, and the violations must agree: the same
count, the same rules, the same first edge. Then the backdoor: a dump of the window equals the Python model's
words (power-up pattern for the never-written ones).
"""

from __future__ import annotations

import random

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ReadOnly, RisingEdge

from eyestereo.sim.lib.harness_files import SRAM_RULES
from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.fast_system import Backdoor, sram_rules
from eyestereo.tools.sram import Pins, SramChip, SramPart

FAULTS = ("ld_n", "no_bytes", "stray", "contention", "oe")


@cocotb.test()
async def part_matches_model(dut):
    cfg = load_config()
    rl = int(cfg["params"].get("read_latency", 2))
    cycles, rate = int(cfg.get("cycles", 3000)), float(cfg.get("fault_rate", 0.0))
    faults = tuple(cfg.get("faults", FAULTS))
    unknown = set(faults) - set(FAULTS)
    if unknown:
        raise ValueError(f"unknown fault kinds {sorted(unknown)}: {', '.join(FAULTS)}")
    rng = random.Random(cfg.get("seed", 1))
    chip = SramChip(SramPart("nobl", rl), strict=False)
    Clock(dut.clk, 10, unit="ns").start(start_high=False)
    dut.ce_n.value, dut.ld_n.value, dut.we_n.value, dut.bw_n.value = 1, 0, 1, 3
    dut.oe_n.value, dut.addr.value, dut.dq_o.value, dut.dq_oe.value = 0, 0, 0, 0
    dut.dump_stb.value = 0
    base = 0x1F000
    data_due: dict[int, int] = {}   # cycle -> the data word the FPGA drives in it (a write's)
    read_due: set[int] = set()      # cycles in which the part drives read data
    injected = dict.fromkeys(faults, 0)
    compared = 0
    await RisingEdge(dut.clk)  # the part's edge 1 (the clock starts low: its first edge is a rising one)
    await _leave_readonly(dut)
    for c in range(cycles + rl + 1):  # the last rl + 1 cycles drain: no new access, the writes' data still due
        # pins for cycle c (sampled at edge c + 1): one access, registered at edge c + 1, its data in cycle c + rl
        p = Pins(ce_n=1, ld_n=0, we_n=1, bw_n=3, oe_n=0, addr=0, dq_oe=0, dq_o=(0, 0))
        op = rng.random() if c < cycles else 1.0
        fault = rng.choice(faults) if faults and c < cycles and rng.random() < rate else None
        if op < 0.4:
            p.ce_n, p.we_n, p.addr = 0, 0, base + rng.randrange(64)
            p.bw_n = 3 if fault == "no_bytes" else rng.choice((0, 0, 1, 2))
            data_due[c + rl] = rng.randrange(1 << 16)
        elif op < 0.8:
            p.ce_n, p.addr = 0, base + rng.randrange(64)
            read_due.add(c + rl)
        if c in data_due:
            d = data_due.pop(c)
            p.dq_oe, p.dq_o = 1, (d & 0xFF, d >> 8)
        if fault == "ld_n":
            p.ld_n = 1
        elif fault == "stray" and not p.dq_oe and c not in read_due:
            p.dq_oe, p.dq_o = 1, (0x5A, 0xA5)
        elif fault == "contention" and c in read_due and not p.dq_oe:
            p.dq_oe, p.dq_o = 1, (0x3C, 0xC3)
        elif fault == "oe" and c in read_due:
            p.oe_n = 1
        elif fault == "no_bytes" and p.ce_n == 0 and p.we_n == 0:
            pass  # the write above enables no byte
        elif fault is not None:
            fault = None  # not applicable in this cycle
        if fault is not None:
            injected[fault] += 1
        read_due.discard(c)
        dut.ce_n.value, dut.ld_n.value, dut.we_n.value, dut.bw_n.value = p.ce_n, p.ld_n, p.we_n, p.bw_n
        dut.oe_n.value, dut.addr.value, dut.dq_oe.value = p.oe_n, p.addr, p.dq_oe
        dut.dq_o.value = p.dq_o[0] | p.dq_o[1] << 8
        await RisingEdge(dut.clk)  # the part's edge c + 2
        out = chip.edge(c + 2, p)
        await ReadOnly()
        if out is not None:
            got = int(dut.dq_i.value)
            assert got == out, f"edge {c + 2}: the HDL part drives {got:#06x}, the Python model {out:#06x}"
            compared += 1
        await _leave_readonly(dut)  # the next iteration drives the pins of the next cycle
    # the violations: the Python model's messages name the rule ("...: <rule>: ...")
    py_rules = [next(r for r in SRAM_RULES if f": {r}: " in v) for v in chip.violations]
    first_edge = int(chip.violations[0].split("edge ")[1].split()[0]) if chip.violations else None
    await RisingEdge(dut.clk)
    hdl = sram_rules(dut, prefix="")
    assert hdl["violations"] == len(py_rules), (hdl, len(py_rules), chip.violations[:4])
    assert set(hdl["rules"]) == set(py_rules), (hdl["rules"], sorted(set(py_rules)))
    if first_edge is not None:
        assert hdl["first"]["edge"] == first_edge, (hdl["first"], first_edge)
        assert hdl["first"]["rule"] == py_rules[0], (hdl["first"], py_rules[0])
    assert hdl["reads"] == chip.stats.reads and hdl["writes"] == chip.stats.writes, (hdl, chip.stats)
    dump = await Backdoor(dut, dut.clk, prefix="").read(base, 64)
    want = np.array([chip.word(base + a) for a in range(64)], np.int64)
    assert np.array_equal(dump, want), f"backdoor: {np.flatnonzero(dump != want)[:4]} differ"
    assert compared > cycles // 4, f"only {compared} read words compared"
    if rate > 0:
        assert all(injected.values()), f"a fault kind was never injected: {injected}"
    write_report(cfg, dict(cycles=cycles, compared=compared, injected=injected, violations=len(py_rules),
                           rules=sorted(set(py_rules)), reads=hdl["reads"], writes=hdl["writes"]))


async def _leave_readonly(dut):
    from cocotb.triggers import Timer

    await Timer(1, unit="ns")
