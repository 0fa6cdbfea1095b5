"""cocotb bench: uart_bridge, random request sequences over the serial line against a Python AXI4-Lite slave.

The host side is a :class:`~eyestereo.sim.lib.uart.UartSender` on ``rx`` and a
:class:`~eyestereo.sim.lib.uart.UartReceiver` on ``tx``; the bus side a small AXI4-Lite slave
(:class:`AxilSlave`: a word memory with byte strobes, random ready and response delays, a few long
ones that make the receive FIFO fill, SLVERR and DECERR at some addresses) and the rule checker
:class:`eyestereo.sim.lib.axil.AxiLiteChecker`. Each request (identify, read and write bursts, unknown
bytes, requests cut off and left for longer than the timeout, bytes with a framing error) is fed to the
bridge's model (:class:`eyestereo.tools.models.uart_bridge.UartBridge`, on its own copy of the slave's
memory) and played on the line; the bench waits for the reply bytes the model says it gets. At the end
the reply bytes, the bus accesses in order and the error count must equal the model's, byte for byte
and access for access, and nothing may be left over (no byte in flight, the bus quiet).

``host_driver`` test: the host's own code, :class:`eyestereo.tools.board.serial_bus.SerialBus` on a
simulated serial port (:class:`~eyestereo.sim.lib.uart.SerialTransport`), identifies the bridge and
reads and writes words and bursts, checked against the slave's memory.

Config: ``params`` (the bridge's), ``period`` (ps), ``requests``, ``seed``, ``long_wait`` (clocks of the
slave's long delays).
"""

from __future__ import annotations

import json
import random
from pathlib import Path

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, First, RisingEdge, Timer

from eyestereo.sim.lib.axil import AxiLiteChecker
from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.uart import SerialTransport, UartReceiver, UartSender
from eyestereo.tools.board import protocol as P
from eyestereo.tools.board.serial_bus import READ_PIECE, SerialBus
from eyestereo.tools.models.uart_bridge import DROPPED, PAUSE, Access, UartBridge
from eyestereo.tools.models.register_bank import strobe_mask

OKAY, SLVERR, DECERR = 0, 2, 3


class WordMemory:
    """The slave's contents and responses, shared by the bench's slave and the model's bus: every word
    starts as a hash of its address; SLVERR where address bits 7..4 are all 1, DECERR at 0x...EC (writes
    there change nothing)."""

    def __init__(self):
        self.words: dict[int, int] = {}

    @staticmethod
    def resp(address: int) -> int:
        if address & 0xFF == 0xEC:
            return DECERR
        return SLVERR if address & 0xF0 == 0xF0 else OKAY

    def read(self, address: int) -> tuple[int, int]:
        a = address & ~3
        return self.words.get(a, (a * 2654435761 + 12345) & 0xFFFFFFFF), self.resp(address)

    def write(self, address: int, data: int, strb: int) -> int:
        resp = self.resp(address)
        if resp == OKAY:
            m = strobe_mask(strb)
            self.words[address & ~3] = (self.read(address)[0] & ~m) | (data & m)
        return resp


class AxilSlave:
    """An AXI4-Lite slave on ``bus_*`` over a :class:`WordMemory`: random delays before each ready and each
    response; records every access as the model's :class:`Access`."""

    def __init__(self, dut, clk, mem: WordMemory, rng: random.Random, *, long_wait: int):
        self.dut, self.clk, self.mem, self.rng, self.long_wait = dut, clk, mem, rng, long_wait
        self.accesses: list[Access] = []
        for name in ("awready", "wready", "bvalid", "arready", "rvalid"):
            getattr(dut, f"bus_{name}").value = 0
        dut.bus_bresp.value = 0
        dut.bus_rresp.value = 0
        dut.bus_rdata.value = 0
        self._task = cocotb.start_soon(self._run())

    def _delay(self) -> int:
        r = self.rng.random()
        return self.rng.randrange(self.long_wait) if r < 0.04 else (0 if r < 0.5 else self.rng.randrange(1, 6))

    async def _clocks(self, n: int) -> None:
        if n:
            await ClockCycles(self.clk, n, rising=False)

    async def _handshake(self, ready) -> None:
        """``ready`` high from this falling edge until a rising edge with its valid (already high) moves it."""
        await self._clocks(self._delay())
        ready.value = 1
        await RisingEdge(self.clk)
        await FallingEdge(self.clk)
        ready.value = 0

    async def _respond(self, valid, ready_name: str) -> None:
        await self._clocks(self._delay())
        valid.value = 1
        while True:
            await RisingEdge(self.clk)
            if int(getattr(self.dut, ready_name).value):
                break
        await FallingEdge(self.clk)
        valid.value = 0

    async def _run(self) -> None:
        d = self.dut
        while True:
            if not (int(d.bus_awvalid.value) or int(d.bus_arvalid.value)):
                await First(RisingEdge(d.bus_awvalid), RisingEdge(d.bus_arvalid))
            await FallingEdge(self.clk)
            if int(d.bus_arvalid.value):
                address = int(d.bus_araddr.value)
                await self._handshake(d.bus_arready)
                data, resp = self.mem.read(address)
                d.bus_rdata.value, d.bus_rresp.value = data, resp
                await self._respond(d.bus_rvalid, "bus_rready")
                self.accesses.append(Access("R", address, data, 0, resp))
            else:
                address, data, strb = int(d.bus_awaddr.value), int(d.bus_wdata.value), int(d.bus_wstrb.value)
                first, second = (d.bus_awready, d.bus_wready) if self.rng.random() < 0.5 else (d.bus_wready,
                                                                                              d.bus_awready)
                await self._handshake(first)
                await self._handshake(second)
                resp = self.mem.write(address, data, strb)
                d.bus_bresp.value = resp
                await self._respond(d.bus_bvalid, "bus_bready")
                self.accesses.append(Access("W", address, data, strb, resp))


class BridgeTB:
    """Clock, reset, the line agents, the slave and the bus checker around the bridge."""

    def __init__(self, dut, cfg):
        self.dut, self.cfg = dut, cfg
        p = cfg["params"]
        self.period = cfg["period"]
        self.cpb, self.timeout = p["clocks_per_bit"], p["timeout"]
        self.bit_ps = self.cpb * self.period
        self.rng = random.Random(cfg.get("seed", 1))
        Clock(dut.clk, self.period, unit="ps").start()
        dut.rst.value = 1
        self.sender = UartSender(dut.rx, self.bit_ps)
        self.receiver = UartReceiver(dut.tx, self.bit_ps)
        self.mem = WordMemory()
        self.model_mem = WordMemory()
        self.model = UartBridge(self.model_mem, addr_bits=p["addr_bits"])
        self.checker = AxiLiteChecker(dut, "bus", dut.clk, dut.rst, period_ns=self.period / 1000)

    async def reset(self):
        await ClockCycles(self.dut.clk, 4)
        self.dut.rst.value = 0
        await ClockCycles(self.dut.clk, 2)
        # the slave looks at the bus from here on (before the reset's edges the master's valids are U)
        self.slave = AxilSlave(self.dut, self.dut.clk, self.mem, self.rng, long_wait=self.cfg.get("long_wait", 40))

    async def play(self, items) -> None:
        """Items (bytes, PAUSE, DROPPED) on the line and into the model; waits for the reply the model gives."""
        for it in items:
            self.model.feed([it])
            if it == PAUSE:
                quiet = (self.timeout + 20 * self.cpb) * self.period + self.rng.randrange(self.bit_ps)
                await Timer(quiet, unit="ps")
            elif it == DROPPED:
                await self.sender.send([self.rng.randrange(256)], stop_bits=[0], gap_ps=2 * self.bit_ps)
            else:
                # inside a request: pauses far shorter than the timeout
                gap = self.rng.randrange(self.timeout // 8) * self.period if self.rng.random() < 0.1 else 0
                await self.sender.send([it], gap_ps=gap)
        n = len(self.model.reply)
        pending = n - len(self.receiver.received)
        long_wait = self.cfg.get("long_wait", 40)
        wait = (self.timeout + 20 * self.cpb * (pending + 2) + 2 * long_wait * (pending + 1)) * self.period
        ok = await self.receiver.wait_bytes(n, wait)
        assert ok, f"{len(self.receiver.received)} reply bytes, the model has {n} after {items[:8]}..."

    def request(self) -> list:
        """A random request (items), with an address range that hits the slave's error words now and then."""
        rng = self.rng
        base = rng.randrange(1 << 26) & ~3 if rng.random() < 0.3 else rng.randrange(0x400) & ~3
        n = rng.choice([1, 1, 2, 3, 5, 8]) if rng.random() < 0.9 else rng.randrange(9, 41)
        r = rng.random()
        if r < 0.12:
            return [P.IDENTIFY]
        if r < 0.45:
            return list(P.encode_read(base | rng.randrange(4) * (rng.random() < 0.1), n))
        if r < 0.8:
            strb = rng.choice([0xF, 0xF, 0x1, 0x3, 0xC, 0x0, 0xA])
            return list(P.encode_write(base, [rng.getrandbits(32) for _ in range(n)], strb))
        if r < 0.88:
            return [rng.choice([b for b in range(256) if b not in (P.IDENTIFY, P.READ, P.WRITE)])]
        if r < 0.95:  # cut off: part of a read or write, then a pause longer than the timeout
            req = (P.encode_read(base, n) if rng.random() < 0.4
                   else P.encode_write(base, [rng.getrandbits(32) for _ in range(n)], 0xF))
            return list(req[:rng.randrange(1, len(req))]) + [PAUSE]
        return [DROPPED]

    def finish_checks(self) -> None:
        self.checker.check()
        got, want = self.receiver.data(), bytes(self.model.reply)
        at = next((i for i, (a, b) in enumerate(zip(got, want)) if a != b), min(len(got), len(want)))
        assert got == want, f"reply differs at byte {at} ({len(got)} bytes, the model {len(want)})"
        assert not self.receiver.framing and not self.receiver.glitches
        hw, model = self.slave.accesses, self.model.accesses
        assert hw == model, f"bus accesses differ: first {next(((a, b) for a, b in zip(hw, model) if a != b), None)}"
        errors = int(self.dut.errors.value)
        assert errors == self.model.errors, f"errors {errors}, model {self.model.errors}"
        for name in ("awvalid", "wvalid", "arvalid"):
            assert int(getattr(self.dut, f"bus_{name}").value) == 0, f"bus_{name} still high at the end"
        assert int(self.dut.tx.value) == 1


def _report(cfg, **parts) -> None:
    """Adds ``parts`` to the report (each test of the module writes its own part)."""
    path = Path(cfg["report"])
    old = json.loads(path.read_text()) if path.exists() else {}
    write_report(cfg, {**old, **parts})


@cocotb.test()
async def random_requests(dut):
    cfg = load_config()
    tb = BridgeTB(dut, cfg)
    await tb.reset()
    kinds: dict[str, int] = {}
    for _ in range(cfg["requests"]):
        items = tb.request()
        kind = ("pause" if PAUSE in items else "dropped" if DROPPED in items
                else {P.IDENTIFY: "identify", P.READ: "read", P.WRITE: "write"}.get(items[0], "unknown"))
        kinds[kind] = kinds.get(kind, 0) + 1
        await tb.play(items)
        if tb.rng.random() < 0.3:
            await Timer(tb.rng.randrange(3 * tb.bit_ps), unit="ps")
    await Timer(20 * tb.bit_ps, unit="ps")
    tb.finish_checks()
    resps = [a.resp for a in tb.model.accesses]
    _report(cfg, random_requests=dict(kinds=kinds, reply_bytes=len(tb.model.reply), accesses=len(tb.model.accesses),
                           errors=tb.model.errors, slverr=resps.count(SLVERR), decerr=resps.count(DECERR),
                                      long_wait=tb.cfg.get("long_wait", 40)))


@cocotb.test()
async def host_driver(dut):
    """SerialBus (the host tool's bus) over a simulated serial port, against the slave's memory."""
    cfg = load_config()
    tb = BridgeTB(dut, cfg)
    await tb.reset()
    piece = (tb.timeout + 10 * (READ_PIECE + 10) * tb.cpb) * tb.period  # a piece of a reply and the bus's waits
    port = SerialTransport(tb.sender, tb.receiver, timeout_ps=piece)
    bus = SerialBus(port, clock_hz=1e12 / tb.period, sleep=lambda s: Timer(round(s * 1e12), unit="ps"))
    assert await bus.identify() == P.VERSION
    data, resp = await bus.read(0x100)
    assert (data, resp) == tb.mem.read(0x100)
    assert await bus.write(0x104, 0xDEADBEEF) == OKAY
    assert await bus.write(0x104, 0x00005500, strb=0x2) == OKAY
    assert tb.mem.read(0x104) == (0xDEAD55EF, OKAY)
    words = [tb.rng.getrandbits(32) for _ in range(300)]  # two requests: 256 + 44 words
    assert await bus.write_burst(0x200, words) == [tb.mem.resp(0x200 + 4 * i) for i in range(300)]
    got = await bus.read_burst(0x200, 300)
    assert got == [tb.mem.read(0x200 + 4 * i) for i in range(300)]
    assert [d for (d, r), w in zip(got, words) if r == OKAY] == [w for (d, r), w in zip(got, words) if r == OKAY]
    await bus.wait(10)
    assert bus.requests == 8
    tb.checker.check()
    assert int(dut.errors.value) == 0
    _report(cfg, host_driver=dict(requests=bus.requests, words=2 * len(words) + 4))
