"""The register-bus model of the benches: cocotbext-axi's AxiLiteMaster, a rule checker, the host driver's bus.

* :class:`AxiLiteChecker` watches the five channels of an AXI4-Lite port (``<prefix>_awvalid`` ...) and
  records every breach of the rules in :mod:`eyestereo.hdl.interfaces.axil`: a valid dropped or a payload changed
  before its transfer, a write response before both the address and the data of its write moved, a read
  response before its address, a response code AXI4-Lite does not have, X/U on a handshake signal or
  a valid payload, a response valid during reset. It wakes on the valids' edges while the bus is quiet
  and on every clock only while a transfer is pending. It also times every access (clocks from the
  address transfer to the response's valid).
* :class:`AxiLiteHost` is the bus object of :class:`eyestereo.tools.host_driver.HostDriver` on
  cocotbext-axi's ``AxiLiteMaster`` (Alex Forencich's; works with cocotb 2.1): ``read``, ``write`` (with
  byte strobes: any contiguous run of bytes, as AxiLiteMaster writes them), ``wait``; random pauses on
  every channel with :meth:`AxiLiteHost.pauses`.
"""

from __future__ import annotations

import itertools
import logging
import random

from cocotb.triggers import ClockCycles, First, RisingEdge
from cocotbext.axi import AxiLiteBus, AxiLiteMaster

__all__ = ["AxiLiteChecker", "AxiLiteHost"]

CHANNELS = {
    "aw": ("awvalid", "awready", ("awaddr", "awprot")),
    "w": ("wvalid", "wready", ("wdata", "wstrb")),
    "b": ("bvalid", "bready", ("bresp",)),
    "ar": ("arvalid", "arready", ("araddr", "arprot")),
    "r": ("rvalid", "rready", ("rdata", "rresp")),
}


def _val(sig):
    """int value, or None for X/U/Z."""
    v = sig.value
    try:
        return int(v)
    except ValueError:
        return None


class AxiLiteChecker:
    """Rule checker of one AXI4-Lite port (see the module docstring); ``errors`` lists the breaches."""

    def __init__(self, dut, prefix: str, clk, rst, *, period_ns: float = 10.0):
        self.sig = {}
        for v, r, payload in CHANNELS.values():
            for name in (v, r) + payload:
                self.sig[name] = getattr(dut, f"{prefix}_{name}")
        self.clk, self.rst = clk, rst
        self.errors: list[str] = []
        self.counts = dict.fromkeys(CHANNELS, 0)
        self.write_latency: list[int] = []   # clocks from the AW+W transfer to bvalid
        self.read_latency: list[int] = []    # clocks from the AR transfer to rvalid
        self.cycle = 0
        self._prev = None
        self._aw_at: list[int] = []
        self._w_at: list[int] = []
        self._ar_at: list[int] = []
        self._b_seen = self._r_seen = False
        import cocotb

        self._task = cocotb.start_soon(self._run())

    def _error(self, msg: str) -> None:
        if len(self.errors) < 50:
            self.errors.append(f"clock {self.cycle}: {msg}")

    def check(self) -> None:
        assert not self.errors, "AXI4-Lite rules broken:\n" + "\n".join(self.errors[:20])

    def _pending(self) -> bool:
        return (self._prev is not None and any(self._prev[v] for v, _, _ in CHANNELS.values())) or \
            len(self._aw_at) > self.counts["b"] or len(self._ar_at) > self.counts["r"]

    async def _run(self):
        valids = [self.sig[v] for v, _, _ in CHANNELS.values()]
        while True:
            if not self._pending():
                # quiet bus: sleep until a valid rises (clocks meanwhile are counted from the time)
                await First(*(RisingEdge(s) for s in valids))
                self._prev = None
            await RisingEdge(self.clk)
            self.cycle += 1
            self._sample()

    def _sample(self):
        now = {n: _val(s) for n, s in self.sig.items()}
        in_reset = _val(self.rst) == 1
        if in_reset:
            for v in ("bvalid", "rvalid"):
                if now[v]:
                    self._error(f"{v} high during reset")
            self._prev = None
            return
        for ch, (v, r, payload) in CHANNELS.items():
            if now[v] is None or now[r] is None:
                self._error(f"{v}/{r} is X/U")
                continue
            if now[v]:
                bad = [p for p in payload if now[p] is None]
                if bad:
                    self._error(f"{ch} payload {bad} X/U while {v} is high")
            p = self._prev
            if p is not None and p[v] and not p[r]:  # offered, not taken at the last edge
                if not now[v]:
                    self._error(f"{v} dropped before its transfer")
                changed = [q for q in payload if now[q] != p[q]]
                if now[v] and changed:
                    self._error(f"{ch} payload {changed} changed before its transfer")
        # responses only after what they answer (counts of transfers at earlier edges)
        if now["bvalid"] and not self._b_seen:
            done = self.counts["b"]
            if len(self._aw_at) <= done or len(self._w_at) <= done:
                self._error("bvalid before the address and data of its write moved")
            else:
                self.write_latency.append(self.cycle - max(self._aw_at[done], self._w_at[done]))
        if now["rvalid"] and not self._r_seen:
            done = self.counts["r"]
            if len(self._ar_at) <= done:
                self._error("rvalid before its read address moved")
            else:
                self.read_latency.append(self.cycle - self._ar_at[done])
        for v, resp in (("bvalid", "bresp"), ("rvalid", "rresp")):
            if now[v] and now[resp] == 1:
                self._error(f"{resp} = 1 (EXOKAY): AXI4-Lite has no exclusive access")
        self._b_seen = bool(now["bvalid"]) and not now["bready"]
        self._r_seen = bool(now["rvalid"]) and not now["rready"]
        # transfers at this edge
        for ch, (v, r, _) in CHANNELS.items():
            if now[v] and now[r]:
                self.counts[ch] += 1
                if ch == "aw":
                    self._aw_at.append(self.cycle)
                elif ch == "w":
                    self._w_at.append(self.cycle)
                elif ch == "ar":
                    self._ar_at.append(self.cycle)
        self._prev = now


def _pause_gen(probability: float, rng: random.Random):
    for _ in itertools.count():
        yield probability > 0 and rng.random() < probability


class AxiLiteHost:
    """The host driver's bus on cocotbext-axi's AxiLiteMaster (and the checker) for port ``<prefix>_*``."""

    def __init__(self, dut, prefix: str, clk, rst):
        self.clk = clk
        self.master = AxiLiteMaster(AxiLiteBus.from_prefix(dut, prefix), clk, rst)
        for side in (self.master.write_if, self.master.read_if):  # not a log line per access
            side.log.setLevel(logging.WARNING)
        self.checker = AxiLiteChecker(dut, prefix, clk, rst)

    def pauses(self, probability: float, seed: int = 0) -> None:
        """Random pauses (valid or ready held low) on every channel, each with its own pattern."""
        rng = random.Random(seed)
        m = self.master
        for ch in (m.write_if.aw_channel, m.write_if.w_channel, m.write_if.b_channel, m.read_if.ar_channel,
                   m.read_if.r_channel):
            if probability > 0:
                ch.set_pause_generator(_pause_gen(probability, random.Random(rng.random())))
            else:
                ch.clear_pause_generator()

    async def read(self, address: int) -> tuple[int, int]:
        r = await self.master.read(int(address) & ~3, 4)
        return int.from_bytes(bytes(r.data), "little"), int(r.resp)

    async def write(self, address: int, data: int, strb: int = 0xF) -> int:
        """A write of the bytes ``strb`` selects (contiguous: 1, 3, 7, F, 2, 6, E, 4, C, 8)."""
        lanes = [i for i in range(4) if strb >> i & 1]
        if not lanes or lanes != list(range(lanes[0], lanes[-1] + 1)):
            raise ValueError(f"AxiLiteMaster writes contiguous bytes only, wstrb {strb:#x} is not")
        raw = (int(data) & 0xFFFFFFFF).to_bytes(4, "little")
        r = await self.master.write((int(address) & ~3) + lanes[0], raw[lanes[0]:lanes[-1] + 1])
        return int(r.resp)

    async def wait(self, clocks: int) -> None:
        await ClockCycles(self.clk, int(clocks))
