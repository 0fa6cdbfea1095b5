"""cocotb bench: sdram_controller against the SDRAM model, with a scoreboard.

One simulation runs several seeds in turn: for each, the controller is reset (so the model, fresh, sees
the whole power-up sequence again), random bursts are offered on the burst port, and the model
(:mod:`eyestereo.sim.lib.sdram_model`) checks the part's rules at every edge. Traffic (``pattern``):

``random``  (the regression) sequential runs of bursts of random length across rows and banks, bursts at
            random places in a few rows per bank (row hits, misses and bank conflicts), random single words,
            now and then anywhere in the part; reads and writes mixed, byte masks, idle gaps, long pauses.
``seq8``, ``row``, ``mixed``, ``single``, ``seq1``, ``wseq1``  (bandwidth,
            :mod:`eyestereo.sim.measure.bench_sdram`) reads in sequential bursts of 8, reads of whole rows,
            write and read bursts of 8 taking turns (two sequential streams, the reader one bank ahead), reads
            of single words at random addresses, reads and writes of single words at sequential addresses
            (the SRAM arbiter's words through ``sdram_bridge``); offered without pause for ``clocks`` clocks
            after the power-up sequence.
``latency``  single words far apart (:func:`latency_traffic`): a write to an idle bank, reads on an open row,
            an idle bank and a row miss, a write on an open row; each one's clocks from the command taken to
            its first word (``rd_valid``) or ``wr_ready`` asserted equal to the documented latency.

``patterns`` (a list) and ``seeds`` (a list) say what to run, every pattern with every seed.

Checks: every read word equals what the scoreboard says was written there (the power-up pattern where
nothing was), in order, with no extra word; every command and write word taken, every read answered; the
model saw the power-up sequence, no rule broken, no refresh late, and at least the refreshes the run's
length asks for. The report gives each burst's latency (clocks from its command taken to its first word).
"""

from __future__ import annotations

import math
import random
from collections import deque

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, First, RisingEdge, Timer

from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.sdram_model import SdramModel
from eyestereo.sim.lib.sram_model import read_int
from eyestereo.tools.sdram import join, part as sdram_part, power_up_word, split


class Burst:
    __slots__ = ("we", "addr", "n", "words", "bes", "gap")

    def __init__(self, we, addr, n, words=(), bes=(), gap=0):
        self.we, self.addr, self.n, self.words, self.bes, self.gap = we, addr, n, list(words), list(bes), gap


def burst_addrs(p, addr: int, n: int) -> list[int]:
    """The word addresses of a burst: its row's columns from the first one on (wrapping in the row)."""
    base = addr & ~(p.columns - 1)
    col = addr & (p.columns - 1)
    return [base | ((col + j) & (p.columns - 1)) for j in range(n)]


def random_traffic(rng: random.Random, p, n: int, max_burst: int) -> list[Burst]:
    """``n`` random bursts (see the module docstring): a few hot rows per bank, runs, singles, pauses."""
    hot = [(b, rng.randrange(p.rows)) for b in range(p.banks) for _ in range(2)]
    out: list[Burst] = []

    def data(we, k):
        if not we:
            return [], []
        return ([rng.randrange(1 << p.data_bits) for _ in range(k)],
                [rng.choice((3, 3, 3, 3, 1, 2, 0)) for _ in range(k)])

    def gap():
        r = rng.random()
        return 0 if r < 0.7 else rng.randint(1, 6) if r < 0.97 else rng.randint(40, 400)

    while len(out) < n:
        kind = rng.random()
        we = rng.random() < 0.5
        if kind < 0.3:  # a sequential run: bursts one after the other, across the row's end into the next bank
            bank, row = rng.choice(hot)
            addr = join(p, bank, row, rng.randrange(p.columns - 2 * max_burst, p.columns))
            for _ in range(rng.randint(2, 5)):
                col = addr & (p.columns - 1)
                k = min(rng.randint(1, max_burst), p.columns - col)
                out.append(Burst(we, addr, k, *data(we, k), gap=0))
                addr = (addr + k) % p.words
            out[-1].gap = gap()
        elif kind < 0.75:  # a burst somewhere in a hot row (hits, misses, conflicts)
            bank, row = rng.choice(hot)
            col = rng.randrange(64)
            k = rng.randint(1, max_burst)
            out.append(Burst(we, join(p, bank, row, col), k, *data(we, k), gap=gap()))
        else:  # single words, mostly in hot rows, sometimes anywhere
            if rng.random() < 0.15:
                addr = rng.randrange(p.words)
            else:
                bank, row = rng.choice(hot)
                addr = join(p, bank, row, rng.randrange(64))
            out.append(Burst(we, addr, 1, *data(we, 1), gap=gap()))
    return out[:n]


def latency_traffic(p, ck, cas_latency: int) -> tuple[list[Burst], list[tuple[bool, int]]]:
    """Single words far apart, each finding the controller idle and its bank in a known state, and what each
    should take from the clock its command is taken to its first word (``rd_valid``) or ``wr_ready``, as the
    controller's docstring and the port's timing diagram give it, in the part's clocks ``ck``: a read on an
    open row CL + 3, on an idle bank tRCD more, on a row miss tRP + tRCD more; a write on an open row 1."""
    gap = 4 * max(ck.rc, ck.rfc, ck.ras + ck.rp, ck.wr + ck.rp) + cas_latency + 8  # every bank timer runs out
    rd = cas_latency + 3
    plan = ((True, 0, 5, 0, 1 + ck.rcd),           # write, idle bank: ACTIVATE, tRCD, WRITE
            (False, 0, 5, 1, rd),                  # read, open row
            (False, 1, 7, 0, rd + ck.rcd),         # read, idle bank
            (False, 0, 9, 0, rd + ck.rp + ck.rcd),  # read, row miss: PRECHARGE, tRP, ACTIVATE, tRCD
            (True, 0, 9, 2, 1))                    # write, open row
    bursts = [Burst(we, join(p, bank, row, col), 1, [0x1234 + col] if we else [], [3] if we else [], gap=gap)
              for we, bank, row, col, _ in plan]
    return bursts, [(not we, n) for we, _, _, _, n in plan]


def pattern_traffic(rng: random.Random, p, pattern: str, n: int) -> list[Burst]:
    """The bandwidth patterns: ``n`` bursts of ``seq8``, ``row``, ``mixed`` or ``single``."""
    out = []
    if pattern == "seq8":
        return [Burst(False, (8 * i) % p.words, 8) for i in range(n)]
    if pattern == "row":
        return [Burst(False, (p.columns * i) % p.words, p.columns) for i in range(n)]
    if pattern == "mixed":
        # a writer and a reader taking turns, each sequential; the reader one bank ahead of the writer
        half = p.words // 2
        for i in range(n):
            we = i % 2 == 0
            addr = (8 * (i // 2)) % half + (0 if we else half + p.columns)
            out.append(Burst(we, addr, 8, [rng.randrange(1 << p.data_bits) for _ in range(8)] if we else [],
                             [3] * 8 if we else []))
        return out
    if pattern == "single":
        return [Burst(False, rng.randrange(p.words), 1) for _ in range(n)]
    if pattern == "seq1":
        return [Burst(False, i % p.words, 1) for i in range(n)]
    if pattern == "wseq1":
        return [Burst(True, i % p.words, 1, [rng.randrange(1 << p.data_bits)], [3]) for i in range(n)]
    raise ValueError(f"unknown pattern {pattern!r}: random, seq8, row, mixed, single, seq1 or wseq1")


def merge(old: int, data: int, be: int) -> int:
    for b in range(2):
        if (be >> b) & 1:
            m = 0xFF << (8 * b)
            old = (old & ~m) | (data & m)
    return old


class SdramTB:
    """Clock, reset and the burst port's drivers around the controller; the model is made per run."""

    def __init__(self, dut, cfg: dict):
        self.dut, self.cfg = dut, cfg
        prm = cfg["params"]
        # model_part: a board whose part differs from the one the controller was built for (the negative test)
        self.part = sdram_part(cfg.get("model_part", prm.get("part", "AS4C32M16SB-7")))
        self.cl = prm.get("cas_latency", 2)
        self.max_burst = prm.get("max_burst", 8)
        # the clock's period rounded up to whole ps: never faster than the controller counted for
        self.period_ps = math.ceil(1e6 / prm.get("clock_mhz", 100.0))
        self.period = self.period_ps / 1000.0
        Clock(dut.clk, self.period_ps, unit="ps").start()
        for name in ("cmd_valid", "cmd_we", "cmd_addr", "cmd_len", "wr_data", "wr_be"):
            getattr(dut, f"port_{name}").value = 0

    async def run(self, bursts: list[Burst], *, measure_clocks: int | None = None, tail_clocks: int = 0) -> dict:
        dut, p = self.dut, self.part
        model = SdramModel(dut, dut.clk, p, period_ns=self.period, cas_latency=self.cl, log=24)
        dut.rst.value = 1
        await ClockCycles(dut.clk, 2)  # (the output ports are undefined until the first edge in reset)
        model.start()
        await ClockCycles(dut.clk, 2)
        dut.rst.value = 0
        ck = p.clocks(1000.0 / self.period)
        limit = ck.powerup + 64 * (ck.rfc + ck.rp) + 200
        await First(RisingEdge(dut.port_cmd_ready), Timer(limit * self.period_ps, unit="ps"))
        await RisingEdge(dut.clk)
        assert read_int(dut.port_cmd_ready) == 1, f"cmd_ready not high {limit} clocks after reset"
        assert model.chip.ready, "the controller takes commands before the power-up sequence is complete"
        start_edge = model.edge_now()

        image: dict[int, int] = {}
        wq: deque = deque()         # write words still to be pulled: (data, be, burst index of a first word)
        expq: deque = deque()       # read words still to come: (address, value, burst index of a first word)
        taken: dict[int, int] = {}  # burst index -> the clock its command was taken in
        latency: list[tuple] = []   # (burst index, read?, clocks from taken to its first word)
        h_valid, h_we, h_addr, h_len = dut.port_cmd_valid, dut.port_cmd_we, dut.port_cmd_addr, dut.port_cmd_len
        h_ready, h_wready = dut.port_cmd_ready, dut.port_wr_ready
        h_rvalid, h_rdata = dut.port_rd_valid, dut.port_rd_data
        h_wdata, h_wbe = dut.port_wr_data, dut.port_wr_be
        i, clock, offer_from = 0, 0, 0
        words_read = words_written = 0
        offered = None  # the burst whose command is on the port
        head = None
        end = measure_clocks if measure_clocks is not None else 50 * len(bursts) + 20 * sum(b.n for b in bursts) + 5000
        while clock < end:
            offering = i < len(bursts) and clock >= offer_from
            if offering:
                if offered != i:
                    b = bursts[i]
                    h_valid.value = 1
                    h_we.value = int(b.we)
                    h_addr.value = b.addr
                    h_len.value = b.n
                    offered = i
            elif offered is not None:
                h_valid.value = 0
                offered = None
            if wq and wq[0] is not head:
                head = wq[0]
                h_wdata.value, h_wbe.value = head[0], head[1]
            await RisingEdge(dut.clk)
            # the values of clock `clock`, sampled at the edge that ends it
            if wq and read_int(h_wready):
                if wq[0][2] is not None:
                    latency.append((wq[0][2], False, clock - taken[wq[0][2]]))
                wq.popleft()
                words_written += 1
            rv = read_int(h_rvalid)
            if rv is None:
                raise AssertionError(f"clock {clock}: rd_valid undefined")
            if rv:
                got = read_int(h_rdata)
                assert expq, f"clock {clock}: a read word nobody asked for ({h_rdata.value})"
                addr, want, first = expq.popleft()
                if first is not None:
                    latency.append((first, True, clock - taken[first]))
                assert got == want, (f"clock {clock}: read of {addr:#09x} (bank, row, column {split(p, addr)}) gave "
                                     f"{h_rdata.value}, expected {want:#06x} (the part holds "
                                     f"{model.chip.word(addr):#06x}); "
                                     f"rules broken so far: "
                                     f"{model.violations[:3]}; the part's last commands (edge, command, bank, a): "
                                     f"{model.chip.command_log} at edge {model.edge_now()}")
                words_read += 1
            if offering:
                ready = read_int(h_ready)
                assert ready is not None, f"clock {clock}: cmd_ready undefined"
                if ready:
                    b = bursts[i]
                    addrs = burst_addrs(p, b.addr, b.n)
                    taken[i] = clock
                    if b.we:
                        for j, (a, w, be) in enumerate(zip(addrs, b.words, b.bes)):
                            image[a] = merge(image.get(a, power_up_word(a, p.data_bits)), w, be)
                            wq.append((w, be, i if j == 0 else None))
                    else:
                        expq.extend((a, image.get(a, power_up_word(a, p.data_bits)), i if j == 0 else None)
                                    for j, a in enumerate(addrs))
                    i += 1
                    offer_from = clock + 1 + b.gap
            clock += 1
            if measure_clocks is None and i == len(bursts) and not wq and not expq:
                break
        h_valid.value = 0
        if measure_clocks is None:
            assert i == len(bursts), f"only {i} of {len(bursts)} bursts taken in {clock} clocks"
            assert not wq and not expq, f"{len(wq)} write words not pulled, {len(expq)} read words not returned"
        else:
            await ClockCycles(dut.clk, 40)  # let the last reads come back (not counted)
            while expq and read_int(h_rvalid):
                expq.popleft()
        if tail_clocks:
            await Timer(tail_clocks * self.period_ps, unit="ps")
        await ClockCycles(dut.clk, self.cl + 4)  # the last commands reach the part
        model.finish()
        model.stop()
        st = model.stats
        return dict(bursts=i, words_read=words_read, words_written=words_written, clocks=clock,
                    run_clocks=model.edge_now() - start_edge, refreshes=st.refreshes, late=st.late_refreshes,
                    max_owed=st.max_owed, max_gap_ns=st.max_refresh_gap_ns, commands=dict(st.commands),
                    part_reads=st.read_words, part_writes=st.write_words,
                    ready_edge=st.ready_edge, violations=list(model.violations), latency=latency)


@cocotb.test()
async def controller_random(dut):
    cfg = load_config()
    tb = SdramTB(dut, cfg)
    p = tb.part
    runs = []
    jobs = [(pattern, seed) for pattern in cfg.get("patterns", ["random"]) for seed in cfg.get("seeds", [1])]
    for pattern, seed in jobs:
        rng = random.Random(seed)
        if pattern == "latency":
            ck = p.clocks(cfg["params"].get("clock_mhz", 100.0))
            bursts, want = latency_traffic(p, ck, tb.cl)
            assert ck.refi > 2 * sum(b.gap + 2 * tb.cl + 20 for b in bursts), \
                "the latency pattern needs a tREFI longer than its run (no refresh in the way)"
            rep = await tb.run(bursts)
            got = [(rd, n) for _, rd, n in sorted(rep["latency"])]
            assert got == want, f"seed {seed}: (read?, clocks from the command taken to the first word): " \
                f"{got}, expected {want}"
        elif pattern == "random":
            bursts = random_traffic(rng, p, cfg.get("bursts", 60), tb.max_burst)
            rep = await tb.run(bursts, tail_clocks=cfg.get("tail_clocks", 0))
            # every word the port moved crossed the pins once: no read or write repeated or lost
            assert (rep["part_reads"], rep["part_writes"]) == (rep["words_read"], rep["words_written"]), rep
        else:
            clocks = cfg["clocks"]
            bursts = pattern_traffic(rng, p, pattern, clocks + 10)
            rep = await tb.run(bursts, measure_clocks=clocks)
        rep["seed"], rep["pattern"] = seed, pattern
        runs.append(rep)
        write_report(cfg, dict(runs=runs, period_ns=tb.period, part=p.name))
        assert not rep["violations"], f"seed {seed}: {len(rep['violations'])} rules broken, first: " + \
            "; ".join(rep["violations"][:5])
        assert rep["late"] == 0, f"seed {seed}: {rep['late']} refreshes late"
        due = int(rep["run_clocks"] * tb.period // p.t_refi)
        assert rep["refreshes"] >= due - 1, f"seed {seed}: {rep['refreshes']} refreshes in a run that needs {due}"
    write_report(cfg, dict(runs=runs, period_ns=tb.period, part=p.name))
