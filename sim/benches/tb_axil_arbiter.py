"""cocotb bench: axil_arbiter, two cocotbext-axi masters with random reads and writes into one AxiLiteRam.

Each master has two lines (its writes and its reads, each one access at a time with random gaps), so
the arbiter sees both masters and both kinds of one master at once. Writes carry random contiguous byte
strobes (1..4 bytes at any offset: what AxiLiteMaster writes), random data and ``awprot``; reads random
``arprot``. Addresses come from a small pool of words spread over the whole address space (the memory
wraps at ``ram_bits``; the model wraps the same), so the masters overwrite each other's words and every
read's value depends on the order of the grants.

What the bench checks against :mod:`eyestereo.tools.models.axil_arbiter` (expected values from the model
and the accesses the bench issued, never from the block):

1. a quiet phase (no pauses, one access at a time): each master port's response latency is the slave
   port's + 2 clocks (the block's documented latency);
2. the grants: which master and kind, in which order, and the edge each address moves on its master's
   port, equal to the model's rule given the arrival edges and the responses' edges the watches saw;
3. the slave's view: every access the slave saw (address, prot, data, strobes), in the model's order;
4. every master's answers (response code, read data) from the model's memory replayed in that order,
   and the memory's final words;
5. the bound on waiting: a request waits for at most 2 grants of the other master and 1 of its own
   other kind; no master loses two decisions in a row while it waits; both masters contend often;
6. the AXI4-Lite rules on all three ports (:class:`~eyestereo.sim.lib.axil.AxiLiteChecker`) and nothing
   left over: no valid high at the end, every channel's transfer count as issued.

Config: ``params`` (addr_bits), ``accesses`` (per line), ``pause`` (probability of a pause on every
channel of both masters and the memory), ``gap`` (largest idle gap in clocks), ``words`` (pool size),
``ram_bits``, ``seed``.
"""

from __future__ import annotations

import random

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles
from cocotbext.axi import AxiLiteBus, AxiLiteRam, AxiProt

from eyestereo.sim.lib.axil import AxiLiteChecker, AxiLiteHost
from eyestereo.sim.lib.axil_watch import PortWatch, set_pauses, transactions
from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.tools.models.axil_arbiter import Access, Grant, WordMemory, grant_order, passed_over, replay, waits

LINES = [(m, w) for m in (0, 1) for w in (True, False)]


class TB:
    def __init__(self, dut, cfg):
        self.dut, self.cfg = dut, cfg
        self.rng = random.Random(cfg.get("seed", 1))
        self.bits = cfg["params"]["addr_bits"]
        self.ram_bits = min(cfg.get("ram_bits", 16), self.bits)
        Clock(dut.clk, 10, unit="ns").start()
        self.hosts = [AxiLiteHost(dut, f"m{i}", dut.clk, dut.rst) for i in (0, 1)]
        self.ram = AxiLiteRam(AxiLiteBus.from_prefix(dut, "s"), dut.clk, dut.rst, size=1 << self.ram_bits)
        for side in (self.ram.write_if, self.ram.read_if):
            side.log.setLevel("WARNING")
        self.s_checker = AxiLiteChecker(dut, "s", dut.clk, dut.rst)
        self.watch = {p: PortWatch(dut, p, dut.clk) for p in ("m0", "m1", "s")}
        n = cfg.get("words", 12)
        self.words = [self.rng.getrandbits(self.bits) & ~3 for _ in range(n)]
        self.requests = {ln: [] for ln in LINES}
        self.answers = {ln: [] for ln in LINES}

    async def reset(self):
        self.dut.rst.value = 1
        await ClockCycles(self.dut.clk, 4)
        self.dut.rst.value = 0
        await ClockCycles(self.dut.clk, 2)

    async def access(self, m: int, write: bool):
        """One random access of master ``m``; recorded with its answer."""
        master, rng = self.hosts[m].master, self.rng
        base, prot = rng.choice(self.words), rng.randrange(8)
        if write:
            off = rng.randrange(4)
            data = bytes(rng.randrange(256) for _ in range(rng.randrange(1, 5 - off)))
            word = int.from_bytes(bytes(off) + data + bytes(4 - off - len(data)), "little")
            self.requests[(m, True)].append(Access(True, base + off, prot, word, ((1 << len(data)) - 1) << off))
            r = await master.write(base + off, data, prot=AxiProt(prot))
            self.answers[(m, True)].append((int(r.resp), 0))
        else:
            self.requests[(m, False)].append(Access(False, base, prot))
            r = await master.read(base, 4, prot=AxiProt(prot))
            self.answers[(m, False)].append((int(r.resp), int.from_bytes(bytes(r.data), "little")))

    async def line(self, m: int, write: bool, n: int):
        for _ in range(n):
            if self.rng.random() < 0.6:
                await ClockCycles(self.dut.clk, self.rng.randrange(1, self.cfg.get("gap", 12) + 1))
            await self.access(m, write)

    def observed_grants(self) -> list[Grant]:
        out = []
        for m in (0, 1):
            w = self.watch[f"m{m}"]
            out += [Grant(m, True, k, mv.edge) for k, mv in enumerate(w.moves["aw"])]
            out += [Grant(m, False, k, mv.edge) for k, mv in enumerate(w.moves["ar"])]
        return sorted(out, key=lambda g: g.accept)

    def edges(self) -> tuple[dict, dict]:
        """(arrival edges, response edges) of every line, as the master ports' watches saw them."""
        arrivals, done = {}, {}
        for m in (0, 1):
            w = self.watch[f"m{m}"].moves
            arrivals[(m, True)], arrivals[(m, False)] = [mv.arrival for mv in w["aw"]], [mv.arrival for mv in w["ar"]]
            done[(m, True)], done[(m, False)] = [mv.edge for mv in w["b"]], [mv.edge for mv in w["r"]]
        return arrivals, done


@cocotb.test()
async def two_masters_share_one_slave(dut):
    cfg = load_config()
    tb = TB(dut, cfg)
    await tb.reset()

    # 1. quiet: one access at a time, no pauses; latency on the master ports = the slave port's + 2
    for m in (0, 1):
        await tb.access(m, True)
        await tb.access(m, False)
    for kind in ("write_latency", "read_latency"):
        s_lat = getattr(tb.s_checker, kind)
        m_lat = [getattr(tb.hosts[m].checker, kind)[0] for m in (0, 1)]
        assert m_lat == [s_lat[0] + 2, s_lat[1] + 2], f"{kind}: masters {m_lat}, slave {s_lat}"

    # 2. random traffic with random pauses on every channel of every port
    pause = cfg.get("pause", 0.3)
    for i, h in enumerate(tb.hosts):
        h.pauses(pause, seed=tb.rng.randrange(1 << 30) + i)
    ram = tb.ram
    set_pauses((ram.write_if.aw_channel, ram.write_if.w_channel, ram.write_if.b_channel, ram.read_if.ar_channel,
                ram.read_if.r_channel), pause, tb.rng)
    n = cfg.get("accesses", 60)
    tasks = [cocotb.start_soon(tb.line(m, w, n)) for m, w in LINES]
    for t in tasks:
        await t
    await ClockCycles(dut.clk, 20)

    # the grants and their timing against the rule
    arrivals, done = tb.edges()
    model = grant_order(arrivals, done)
    seen = tb.observed_grants()
    bad = next((i for i, (a, b) in enumerate(zip(model, seen)) if a != b), min(len(model), len(seen)))
    assert model == seen, f"grant {bad}: model {model[max(bad - 2, 0):bad + 2]}, seen {seen[max(bad - 2, 0):bad + 2]}"
    # what the slave saw and what the masters got
    memory = WordMemory(1 << tb.ram_bits)
    slave_view, answers = replay(model, tb.requests, memory)
    got = [a for _, a in transactions(tb.watch["s"])]
    assert got == slave_view, next(f"slave access {i}: {g} != model {e}" for i, (g, e) in
                                   enumerate(zip(got + [None] * 9, slave_view)) if g != e)
    for ln in LINES:
        assert tb.answers[ln] == answers[ln], f"line {ln}: answers differ from the model's"
    for word, value in memory.words.items():
        assert int.from_bytes(ram.read(word, 4), "little") == value, f"memory word {word:#x}"
    # the bound on waiting, and contention that makes it mean something
    ws = waits(model, arrivals)
    worst_others, worst_own = max(w.others for w in ws), max(w.own for w in ws)
    assert worst_others <= 2 and worst_own <= 1, f"a request waited for {worst_others} / {worst_own} grants"
    lost, contended = passed_over(model, arrivals)
    assert max(lost) <= 1, f"a master lost {max(lost)} decisions in a row"
    assert contended >= n // 4, f"only {contended} decisions with both masters waiting"
    assert all(sum(g.master == m for g in model) == 2 * n + 2 for m in (0, 1))
    # rules and leftovers
    for c in [h.checker for h in tb.hosts] + [tb.s_checker]:
        c.check()
    for name, w in tb.watch.items():
        assert w.idle(), f"port {name}: a valid is still high"
        writes = 2 * (n + 1) if name == "s" else n + 1  # per master and kind: 1 quiet + n random
        counts = {ch: len(mv) for ch, mv in w.moves.items()}
        assert counts == dict(aw=writes, w=writes, b=writes, ar=writes, r=writes), f"port {name}: {counts}"
    write_report(cfg, dict(grants=len(model), contended=contended, worst_others=worst_others, worst_own=worst_own,
                           worst_wait_clocks=max(w.clocks for w in ws), lost_in_a_row=max(lost),
                           reads_checked=sum(len(tb.answers[(m, False)]) for m in (0, 1))))
