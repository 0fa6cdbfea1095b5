"""cocotb bench: axil_split, one cocotbext-axi master onto two slaves that answer OKAY, SLVERR and DECERR.

The master (AxiLiteMaster) runs its writes and its reads as two lines at once, with random gaps; the
addresses come from a pool of words with random high bits on both sides of bit ``split_bit``; writes
carry random contiguous strobes, data and ``awprot``. Each slave
(:class:`~eyestereo.sim.lib.axil_watch.CodedSlave`) keeps its own words and answers every access with a
code that depends on the address it sees (most OKAY, some SLVERR, some DECERR). Random pauses on every
channel of all three ports, so a write's W comes before, with or after its AW.

What the bench checks (expected values from :mod:`eyestereo.tools.models.axil_split` and the accesses the
bench issued, never from the block):

1. the order: which access the split serves when, the edge its address moves, by the model's rule
   given the arrival and response edges the master port's watch saw;
2. routing: each slave saw exactly the model's accesses, in order, each with bit ``split_bit`` cleared
   and cut to the slave's address bits, prot, data and strobes unchanged;
3. the responses: every answer the master got (code, read data) is the answer the slave gave to that
   access, and the model's memories replayed give the same answers;
4. the AXI4-Lite rules on all three ports, nothing left over, and writes with W before and after AW seen.

Config: ``params`` (addr_bits, s0_bits, s1_bits, split_bit), ``accesses`` (per line), ``pause``, ``gap``,
``words``, ``seed``.
"""

from __future__ import annotations

import random

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles
from cocotbext.axi import AxiProt

from eyestereo.sim.lib.axil import AxiLiteChecker, AxiLiteHost
from eyestereo.sim.lib.axil_watch import CodedSlave, PortWatch, transactions
from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.tools.models.axil_arbiter import Access, Grant, WordMemory
from eyestereo.tools.models.axil_split import serve, split_order

#: a slave's answer by the word it sees: (address >> 2) % 8 -> code (OKAY 0, SLVERR 2, DECERR 3)
CODES = ((0, 0, 0, 2, 0, 0, 3, 0), (0, 3, 0, 0, 0, 2, 0, 0))


def code_of(port: int):
    return lambda addr: CODES[port][addr >> 2 & 7]


class TB:
    def __init__(self, dut, cfg):
        self.dut, self.cfg = dut, cfg
        self.rng = random.Random(cfg.get("seed", 1))
        p = cfg["params"]
        self.bits, self.split = p["addr_bits"], p["split_bit"]
        self.slave_bits = (p["s0_bits"], p["s1_bits"])
        Clock(dut.clk, 10, unit="ns").start()
        self.host = AxiLiteHost(dut, "m", dut.clk, dut.rst)
        pause = cfg.get("pause", 0.3)
        self.slaves = [CodedSlave(dut, f"s{k}", dut.clk, dut.rst, code_of(k), pause=pause,
                                  rng=random.Random(self.rng.random())) for k in (0, 1)]
        self.checkers = [AxiLiteChecker(dut, f"s{k}", dut.clk, dut.rst) for k in (0, 1)] + [self.host.checker]
        self.watch = PortWatch(dut, "m", dut.clk)
        self.slave_watch = [PortWatch(dut, f"s{k}", dut.clk) for k in (0, 1)]
        # a pool of words, random high bits; half of them on each side of the split bit, each half with
        # every one of the 8 answer codes' word indices (bits 4..2)
        self.words = []
        for i in range(cfg.get("words", 16)):
            a = self.rng.getrandbits(self.bits) & ~0x1F | (i % 8) << 2
            self.words.append(a & ~(1 << self.split) | (i // 8 & 1) << self.split)
        self.requests = {True: [], False: []}
        self.answers = {True: [], False: []}

    async def reset(self):
        self.dut.rst.value = 1
        await ClockCycles(self.dut.clk, 4)
        self.dut.rst.value = 0
        await ClockCycles(self.dut.clk, 2)

    async def line(self, write: bool, n: int):
        master, rng = self.host.master, self.rng
        for _ in range(n):
            if rng.random() < 0.6:
                await ClockCycles(self.dut.clk, rng.randrange(1, self.cfg.get("gap", 12) + 1))
            base, prot = rng.choice(self.words), rng.randrange(8)
            if write:
                off = rng.randrange(4)
                data = bytes(rng.randrange(256) for _ in range(rng.randrange(1, 5 - off)))
                word = int.from_bytes(bytes(off) + data + bytes(4 - off - len(data)), "little")
                self.requests[True].append(Access(True, base + off, prot, word, ((1 << len(data)) - 1) << off))
                r = await master.write(base + off, data, prot=AxiProt(prot))
                self.answers[True].append((int(r.resp), 0))
            else:
                self.requests[False].append(Access(False, base, prot))
                r = await master.read(base, 4, prot=AxiProt(prot))
                self.answers[False].append((int(r.resp), int.from_bytes(bytes(r.data), "little")))


@cocotb.test()
async def one_master_two_slaves(dut):
    cfg = load_config()
    tb = TB(dut, cfg)
    await tb.reset()
    tb.host.pauses(cfg.get("pause", 0.3), seed=tb.rng.randrange(1 << 30))
    n = cfg.get("accesses", 80)
    tasks = [cocotb.start_soon(tb.line(w, n)) for w in (True, False)]
    for t in tasks:
        await t
    await ClockCycles(dut.clk, 20)

    # 1. the order and its timing
    mv = tb.watch.moves
    arrivals = {True: [m.arrival for m in mv["aw"]], False: [m.arrival for m in mv["ar"]]}
    done = {True: [m.edge for m in mv["b"]], False: [m.edge for m in mv["r"]]}
    order = split_order(arrivals, done)
    seen = sorted([Grant(0, True, k, m.edge) for k, m in enumerate(mv["aw"])] +
                  [Grant(0, False, k, m.edge) for k, m in enumerate(mv["ar"])], key=lambda g: g.accept)
    assert order == seen, next(f"access {i}: model {a}, seen {b}" for i, (a, b) in enumerate(zip(order, seen))
                               if a != b)
    # 2. routing: what each slave saw (its own record and its port's watch)
    memories = tuple(WordMemory(1 << tb.slave_bits[k], code_of(k)) for k in (0, 1))
    expect, answers = serve(order, tb.requests, tb.split, tb.slave_bits, memories)
    for k in (0, 1):
        logged = [a for a, _, _ in tb.slaves[k].log]
        assert logged == expect[k], f"slave s{k}: saw {len(logged)} accesses, model {len(expect[k])}; first " \
            f"difference {next(((g, e) for g, e in zip(logged, expect[k]) if g != e), None)}"
        assert [a for _, a in transactions(tb.slave_watch[k])] == expect[k], f"slave s{k}'s port watch"
    assert sum(map(len, expect)) == 2 * n and all(expect), "both slaves must be reached"
    # 3. responses unchanged: the slaves' answers, in the order served, are the master's answers
    given = {True: [], False: []}
    logs = [iter(s.log) for s in tb.slaves]
    for g in order:
        port = tb.requests[g.write][g.index].addr >> tb.split & 1
        _, resp, data = next(logs[port])
        given[g.write].append((resp, data))
    assert tb.answers == given, "the master's answers are not the slaves'"
    assert tb.answers == answers, "the master's answers differ from the model's memories"
    codes = {r for w in (True, False) for r, _ in tb.answers[w]}
    assert codes == {0, 2, 3}, f"response codes seen: {codes}"
    # 4. rules, leftovers, W before and after its AW
    for c in tb.checkers:
        c.check()
    for w in [tb.watch] + tb.slave_watch:
        assert w.idle()
    assert {ch: len(m) for ch, m in mv.items()} == dict(aw=n, w=n, b=n, ar=n, r=n)
    w_first = sum(w.arrival < a.arrival for a, w in zip(mv["aw"], mv["w"]))
    w_later = sum(w.arrival > a.arrival for a, w in zip(mv["aw"], mv["w"]))
    assert w_first and w_later, f"W before its AW {w_first} times, after {w_later}"
    write_report(cfg, dict(accesses=2 * n, s0=len(expect[0]), s1=len(expect[1]), w_first=w_first, w_later=w_later,
                           errors=sum(r != 0 for w in (True, False) for r, _ in tb.answers[w])))
