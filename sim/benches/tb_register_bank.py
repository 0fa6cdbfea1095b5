"""cocotb bench: register_bank on GHDL through the AXI4-Lite bus model, checked against the register table.

The bus: cocotbext-axi's AxiLiteMaster with random pauses on all five channels, and the rule checker
(:class:`eyestereo.sim.lib.axil.AxiLiteChecker`). What every access must return, and what it must do to
the ports, comes from the table through the bank's transaction model
(:class:`eyestereo.tools.models.register_bank.RegisterBank`), never from the block itself:

1. after reset: every register's and every array word's value; every rw output port at its reset value;
2. rw registers: random words with random byte strobes, read back; the output ports follow;
3. pulses (CMD) and the arrays' write ports: every 1 written is one pulse of one clock, every array write
   one write-port write of the merged word, in order, nothing else;
4. status registers: random values on the input ports read back;
5. windows: every word through emulated read ports of exactly the table's latency (the data of an
   address appears ``latency`` clocks after it), the unused words SLVERR;
6. the SRAM window on an emulated host port (the arbiter's req_ready pattern, random read latency);
7. bad addresses (every gap of the map) and writes to read-only registers: SLVERR, read data 0, nothing
   changes (all registers, outputs and port events compared afterwards);
8. the host driver on top (configure, start, status, counters, wait for a frame, SRAM);
9. a second reset in the middle: back to the reset values (arrays read 0 again).
"""

from __future__ import annotations

import random

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge

from eyestereo.sim.lib.axil import AxiLiteHost
from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.tools.host_driver import BusError, HostDriver
from eyestereo.tools.models.register_bank import RegisterBank
from eyestereo.tools.regmap import ARB_WORDS, REGMAP

CONTIGUOUS = (0x1, 0x2, 0x4, 0x8, 0x3, 0x6, 0xC, 0x7, 0xE, 0xF)


def window_word(port: str, index: int, salt: int) -> int:
    """What the emulated read port answers for an index (differs per index and per salt)."""
    return (0x9E3779B1 * (index + 1) + 0x7F4A7C15 * salt + (0x1234 if port == "fcount" else 0)) & 0xFFFFFFFF


class TB:
    def __init__(self, dut, cfg):
        self.dut, self.cfg = dut, cfg
        self.rng = random.Random(cfg.get("seed", 1))
        self.clk = dut.clk
        Clock(dut.clk, 10, unit="ns").start()
        p = cfg["params"]
        # the bank's frame size, else the model's defaults (the block's)
        self.model = RegisterBank(**{k: p[k] for k in ("width", "height") if k in p})
        self.salt = 0
        for w in REGMAP.of_kind("window"):
            self.model.windows[w.port] = (lambda i, _p=w.port: window_word(_p, i, self.salt))
        self.events: list[tuple] = []
        self.host_reqs = 0
        self.model_sram_hw: dict[int, int] = {}  # what the emulated host port's SRAM holds
        for f in self.model.inputs:
            getattr(dut, f"regs_{f}").value = 0
        dut.host_req_ready.value = 0
        dut.host_rsp_valid.value = 0
        dut.host_rsp_data.value = 0
        self.bus = AxiLiteHost(dut, "bus", dut.clk, dut.rst)
        self.drv = HostDriver(self.bus)
        cocotb.start_soon(self._ports())
        cocotb.start_soon(self._host_port())

    async def reset(self):
        self.dut.rst.value = 1
        await ClockCycles(self.clk, 4)
        self.dut.rst.value = 0
        self.model.reset()
        await ClockCycles(self.clk, 2)

    # ---- emulated neighbours ---------------------------------------------------------------------------
    async def _ports(self):
        """Each window's read port with the table's latency; the pulse and array-write monitor."""
        wins = [(w.port, w.latency, getattr(self.dut, f"{w.port}_addr"), getattr(self.dut, f"{w.port}_data"),
                 (1 << w.fields[0].width) - 1) for w in REGMAP.of_kind("window")]
        hist = {p: [0] * (lat - 1) for p, lat, *_ in wins}  # the addresses of the last lat - 1 clocks
        pulses = [(f.name, getattr(self.dut, f"regs_{f.name}")) for r in REGMAP.of_kind("pulse") for f in r.fields]
        arrays = [(r.port, getattr(self.dut, f"regs_{r.port}_we"), getattr(self.dut, f"regs_{r.port}_addr"),
                   getattr(self.dut, f"regs_{r.port}_data")) for r in REGMAP.of_kind("array")]
        while True:
            await RisingEdge(self.clk)
            for p, _lat, addr, data, mask in wins:
                h = hist[p]
                try:
                    a = int(addr.value)
                except ValueError:
                    a = 0
                h.append(a)
                # what we drive now is seen in the next clock: the data of the address of lat - 1 clocks ago
                data.value = window_word(p, h.pop(0), self.salt) & mask
            for name, sig in pulses:
                if str(sig.value) == "1":
                    self.events.append(("pulse", name))
            for port, we, addr, data in arrays:
                if str(we.value) == "1":
                    self.events.append(("write", port, int(addr.value), int(data.value)))

    async def _host_port(self):
        """The arbiter's host port: req_ready from a register, high every other clock at most (and held
        low at random), a read's word 3..12 clocks after it moved."""
        d = self.dut
        pending = []  # (due cycle, data)
        cycle = 0
        ready = 0
        while True:
            await RisingEdge(self.clk)
            cycle += 1
            if ready and str(d.host_req_valid.value) == "1":  # moved at this edge
                self.host_reqs += 1
                a = int(d.host_req_addr.value)
                if str(d.host_req_we.value) == "1":
                    be = int(d.host_req_be.value)
                    old = self.model_sram_hw.get(a, 0)
                    keep = (0xFF if be & 1 else 0) | (0xFF00 if be & 2 else 0)
                    self.model_sram_hw[a] = (old & ~keep) | (int(d.host_req_wdata.value) & keep)
                else:
                    pending.append((cycle + self.rng.randint(3, 12), self.model_sram_hw.get(a, 0)))
                ready = 0
            else:
                ready = int(self.rng.random() < 0.7)
            d.host_req_ready.value = ready
            if pending and pending[0][0] <= cycle:
                d.host_rsp_valid.value = 1
                d.host_rsp_data.value = pending.pop(0)[1]
            else:
                d.host_rsp_valid.value = 0

    # ---- checks ----------------------------------------------------------------------------------------
    async def expect_read(self, address: int, what: str = ""):
        data, resp = await self.bus.read(address)
        want, want_resp = self.model.read(address)
        assert (data, resp) == (want, want_resp), (
            f"read {what or hex(address)} at {address:#x}: got {data:#x} resp {resp}, the table says {want:#x} "
            f"resp {want_resp}")
        return data

    async def expect_write(self, address: int, data: int, strb: int = 0xF, what: str = ""):
        resp = await self.bus.write(address, data, strb)
        want = self.model.write(address, data, strb)
        assert resp == want, f"write {what or hex(address)} at {address:#x}: resp {resp}, the table says {want}"

    def check_outputs(self, when: str):
        for name, want in self.model.outputs().items():
            got = int(getattr(self.dut, f"regs_{name}").value)
            assert got == want, f"{when}: output regs_{name} is {got:#x}, the table says {want:#x}"

    async def check_events(self, when: str):
        await ClockCycles(self.clk, 2)
        assert self.events == self.model.events, (
            f"{when}: port events {self.events[-6:]} (of {len(self.events)}), the table says "
            f"{self.model.events[-6:]} (of {len(self.model.events)})")

    def local_addresses(self):
        """Every word of the local space with its register (None: a gap)."""
        return [(a, REGMAP.decode(a)) for a in range(0, REGMAP.local_bytes, 4)]

    async def dump(self, when: str):
        """Every local word read and compared (windows: their whole region)."""
        for a, hit in self.local_addresses():
            await self.expect_read(a, f"{hit[0].name}[{hit[1]}] {when}" if hit else f"gap {when}")


@cocotb.test()
async def register_bank_against_table(dut):
    cfg = load_config()
    tb = TB(dut, cfg)
    rng = tb.rng
    tb.bus.pauses(cfg.get("pause", 0.3), cfg.get("seed", 1))
    await tb.reset()
    report = {}

    # 1. reset values
    tb.check_outputs("after reset")
    await tb.dump("after reset")

    # 2. rw registers, random words and strobes
    rws = REGMAP.of_kind("rw")
    for _ in range(cfg.get("rw_writes", 40)):
        r = rng.choice(rws)
        await tb.expect_write(r.offset, rng.getrandbits(32), rng.choice(CONTIGUOUS), r.name)
        tb.check_outputs(f"after a write of {r.name}")
        await tb.expect_read(r.offset, r.name)

    # 3. pulses and arrays
    cmd = REGMAP["CMD"]
    for _ in range(12):
        await tb.expect_write(cmd.offset, rng.getrandbits(32), rng.choice(CONTIGUOUS), "CMD")
        await tb.expect_read(cmd.offset, "CMD")
    for r in REGMAP.of_kind("array"):
        for i in rng.sample(range(r.count), r.count):
            await tb.expect_write(r.address(i), rng.getrandbits(32), 0xF, f"{r.name}[{i}]")
        for _ in range(8):  # partial strobes on the stored copy
            i = rng.randrange(r.count)
            await tb.expect_write(r.address(i), rng.getrandbits(32), rng.choice(CONTIGUOUS), f"{r.name}[{i}]")
        for i in range(r.count):
            await tb.expect_read(r.address(i), f"{r.name}[{i}]")
    await tb.check_events("pulses and array writes")
    assert len([e for e in tb.events if e[0] == "pulse"]) > 5 and len(tb.events) > 40

    # 4. status inputs
    for _round in range(3):
        for f in list(tb.model.inputs):
            v = rng.getrandbits(tb.model.regmap.field(f)[1].width)
            getattr(dut, f"regs_{f}").value = v
            tb.model.set_input(f, v)
        for r in REGMAP.of_kind("status"):
            await tb.expect_read(r.offset, r.name)

    # 5. windows (every word, in random order, twice with different contents)
    for salt in range(1, 1 + cfg.get("salts", 2)):
        tb.salt = salt
        for r in REGMAP.of_kind("window"):
            words = list(range(r.span // 4))
            rng.shuffle(words)
            for i in words:
                await tb.expect_read(r.offset + 4 * i, f"{r.name}[{i}]")

    # 6. SRAM window
    sram = REGMAP["SRAM"]
    addrs = [0, 1, 2, sram.count - 1, sram.count // 2] + [rng.randrange(sram.count) for _ in range(10)]
    n0, want = tb.host_reqs, 0
    for a in addrs:
        strobe = rng.choice(CONTIGUOUS)
        want += bool(strobe & 0x3)  # an SRAM word is bits 15..0: a write of the upper bytes alone reaches no word
        await tb.expect_write(sram.address(a), rng.getrandbits(32), strobe, f"SRAM[{a}]")
    for a in addrs + [7]:
        want += 1
        await tb.expect_read(sram.address(a), f"SRAM[{a}]")
    assert tb.model_sram_hw == {k: v for k, v in tb.model.sram.items()}, "host port writes differ from the table"
    assert tb.host_reqs - n0 == want, \
        f"{tb.host_reqs - n0} host port requests for the SRAM window's accesses, want {want}"

    # 7. bad addresses and read-only registers
    n_events = len(tb.events)
    gaps = [a for a, hit in tb.local_addresses() if hit is None]
    beyond = [REGMAP.local_bytes, 0x1000, 0x3FFFFC, rng.randrange(REGMAP.local_bytes, 0x400000) & ~3]
    for a in gaps + beyond:
        await tb.expect_read(a, "bad address")
    for a in rng.sample(gaps, min(12, len(gaps))) + beyond:
        await tb.expect_write(a, 0xFFFFFFFF, 0xF, "bad address")
    for r in REGMAP.of_kind("const", "status", "window"):
        await tb.expect_write(r.offset, 0xFFFFFFFF, 0xF, f"read-only {r.name}")
    await tb.check_events("bad writes")
    assert len(tb.events) == n_events
    tb.check_outputs("after the bad writes")
    if cfg.get("full", True):
        await tb.dump("after the bad writes")
    else:  # every register's first and last word
        for r in REGMAP:
            if r.kind != "memory":
                for i in sorted({0, r.count - 1}):
                    await tb.expect_read(r.address(i), f"{r.name}[{i}] after the bad writes")
    report["gaps"] = len(gaps)

    # 8. the host driver on top
    drv = tb.drv
    await drv.check_id()
    assert await drv.geometry() == (tb.model.params["width"], tb.model.params["height"])
    thr = [rng.getrandbits(20) for _ in range(16)]
    await drv.configure(mode="overlapped", continuous=True, k_left=17, k_right=33, thresholds_left=thr)
    assert int(dut.regs_mode.value) == 1 and int(dut.regs_continuous.value) == 1
    assert int(dut.regs_k_left.value) == 17 and int(dut.regs_k_right.value) == 33
    assert await drv.read_thresholds("THR_LEFT") == thr
    await ClockCycles(tb.clk, 2)
    assert [e for e in tb.events if e[0] == "write"][-16:] == [("write", "thr_left", i, t) for i, t in enumerate(thr)]
    before = len(tb.events)
    await drv.start()
    await drv.pulse("rect_release", "feat_release")
    await ClockCycles(tb.clk, 2)
    assert tb.events[before:] == [("pulse", "start"), ("pulse", "rect_release"), ("pulse", "feat_release")]
    assert await drv.get("CTRL.mode") == 1 and await drv.get("k_right") == 33
    st = await drv.status()
    assert st == tb.model.inputs | {}, f"driver status {st} != driven {tb.model.inputs}"
    arb = await drv.arbiter()
    assert arb == {w: window_word("arb", i, tb.salt) for i, w in enumerate(ARB_WORDS)}
    left, right = await drv.feature_counts()
    assert left + right == [window_word("fcount", i, tb.salt) & 0xFFFF for i in range(32)]
    await drv.write_sram_words(100, [0x1111, 0x2222, 0x3333])
    assert await drv.read_sram_words(100, 3) == [0x1111, 0x2222, 0x3333]
    try:
        await drv.write("ID", 0)
        raise AssertionError("a write to ID must raise BusError (SLVERR)")
    except BusError:
        pass
    frames0 = int(dut.regs_frames.value)

    async def frame_later():
        await ClockCycles(tb.clk, 500)
        dut.regs_frames.value = (frames0 + 1) & 0xFFFFFFFF

    cocotb.start_soon(frame_later())
    got = await drv.wait_frame(poll_clocks=50, timeout_clocks=5000)
    assert got == (frames0 + 1) & 0xFFFFFFFF

    # 9. reset in the middle
    await tb.reset()
    tb.events.clear()
    tb.check_outputs("after the second reset")
    for r in REGMAP.of_kind("const", "rw", "array", "pulse"):
        for i in range(r.count):
            await tb.expect_read(r.address(i), f"{r.name}[{i}] after the second reset")
    assert await drv.read_thresholds("THR_LEFT") == [0] * 16
    assert await drv.read_thresholds("THR_RIGHT") == [0] * 16

    tb.bus.checker.check()
    c = tb.bus.checker
    assert c.counts["aw"] == c.counts["w"] == c.counts["b"] > 100, c.counts
    assert c.counts["ar"] == c.counts["r"] > (300 if cfg.get("full", True) else 150), c.counts
    report.update(counts=c.counts, write_latency=sorted(set(c.write_latency)),
                  read_latency=sorted(set(c.read_latency)), host_requests=tb.host_reqs)
    write_report(cfg, report)


@cocotb.test()
async def register_bank_latency(dut):
    """No pauses: the clocks from address to response of a register write, a register read and a window
    read (the figures of the bus's timing diagram)."""
    cfg = load_config()
    tb = TB(dut, cfg)
    await tb.reset()
    c = tb.bus.checker
    await tb.expect_write(REGMAP["K_LEFT"].offset, 0x55)
    await tb.expect_read(REGMAP["K_LEFT"].offset)
    await tb.expect_read(REGMAP["ARB"].offset)
    await tb.expect_read(0x3FC)  # a gap: SLVERR after the same wait
    c.check()
    assert c.write_latency == [3], f"register write: response {c.write_latency} clocks after the transfer"
    assert c.read_latency == [5, 5, 5], f"register reads: data {c.read_latency} clocks after the address"


@cocotb.test()
async def checker_catches_master_faults(dut):
    """The bus checker itself: a master that drops awvalid before its transfer and one that changes araddr
    while arvalid waits are reported (the bank is correct here; the faults are the master's)."""
    from eyestereo.sim.lib.axil import AxiLiteChecker

    clk = dut.clk
    Clock(clk, 10, unit="ns").start()
    for n in ("awvalid", "wvalid", "arvalid", "bready", "rready", "awaddr", "araddr", "wdata", "wstrb", "awprot",
              "arprot"):
        getattr(dut, f"bus_{n}").value = 0
    for n in ("host_req_ready", "host_rsp_valid", "host_rsp_data"):
        getattr(dut, n).value = 0
    dut.rst.value = 1
    await ClockCycles(clk, 3)
    dut.rst.value = 0
    checker = AxiLiteChecker(dut, "bus", clk, dut.rst)
    await ClockCycles(clk, 2)
    assert not checker.errors
    dut.bus_awvalid.value = 1  # no wvalid: the bank waits for both, so the address does not move
    await ClockCycles(clk, 2)
    dut.bus_awvalid.value = 0
    await ClockCycles(clk, 2)
    assert any("awvalid dropped" in e for e in checker.errors), checker.errors
    n = len(checker.errors)
    await RisingEdge(clk)
    dut.bus_araddr.value = 0x014
    dut.bus_arvalid.value = 1
    dut.bus_rready.value = 1
    await RisingEdge(clk)
    dut.bus_araddr.value = 0x018  # arready comes one clock after arvalid: this change is before the transfer
    await ClockCycles(clk, 12)
    dut.bus_arvalid.value = 0
    await ClockCycles(clk, 4)
    assert any("ar payload" in e for e in checker.errors[n:]), checker.errors
