"""What the AXI4-Lite interconnect benches need beside :mod:`eyestereo.sim.lib.axil`: a port watch that records
every transfer with the edge its valid was first seen and the edge it moved, a slave that answers with
chosen response codes, and random pause patterns for cocotbext-axi's channels.

* :class:`PortWatch`: one port's five channels; per channel a list of :class:`Move` (arrival edge,
  transfer edge, payload). Edges are counted from time 0 (``round(time / period)``), the numbering
  :mod:`eyestereo.tools.models.axil_arbiter` works in. It sleeps while no valid is high and samples every
  clock while one is.
* :class:`CodedSlave`: an AXI4-Lite slave on cocotbext-axi's channel classes (``AxiLiteAWSink`` ...):
  its own word memory, a response code per address (OKAY, SLVERR, DECERR: cocotbext-axi's
  ``AxiLiteRam`` answers OKAY only), every access and answer recorded; random pauses on its channels.
* :func:`set_pauses`: random pauses (valid or ready held low) on a list of cocotbext-axi channels.
"""

from __future__ import annotations

import itertools
import random
from dataclasses import dataclass

import cocotb
from cocotb.triggers import First, RisingEdge
from cocotb.utils import get_sim_time
from cocotbext.axi import AxiLiteBus
from cocotbext.axi.axil_channels import (AxiLiteARSink, AxiLiteAWSink, AxiLiteBSource, AxiLiteBTransaction,
                                         AxiLiteRSource, AxiLiteRTransaction, AxiLiteWSink)

from eyestereo.sim.lib.axil import CHANNELS
from eyestereo.tools.models.axil_arbiter import Access

__all__ = ["CodedSlave", "Move", "PortWatch", "set_pauses", "transactions"]


@dataclass(frozen=True)
class Move:
    """One transfer: the edge its valid was first sampled high, the edge it moved, its payload."""

    arrival: int
    edge: int
    payload: dict


def _pauses(probability: float, rng: random.Random):
    for _ in itertools.count():
        yield rng.random() < probability


def set_pauses(channels, probability: float, rng: random.Random) -> None:
    """Random pauses on cocotbext-axi channels (each its own pattern); none for probability 0."""
    for ch in channels:
        if probability > 0:
            ch.set_pause_generator(_pauses(probability, random.Random(rng.random())))
        else:
            ch.clear_pause_generator()


class PortWatch:
    """Every transfer of one AXI4-Lite port ``<prefix>_*`` (module docstring): ``moves[channel]``."""

    def __init__(self, dut, prefix: str, clk, *, period_ns: float = 10.0):
        self.sig = {name: getattr(dut, f"{prefix}_{name}") for v, r, payload in CHANNELS.values()
                    for name in (v, r, *payload)}
        self.clk, self.period = clk, period_ns
        self.moves: dict[str, list[Move]] = {ch: [] for ch in CHANNELS}
        self.offered: dict[str, int | None] = dict.fromkeys(CHANNELS)  # arrival edge of a waiting offer
        cocotb.start_soon(self._run())

    def _high(self, name: str) -> bool:
        v = self.sig[name].value
        return v.is_resolvable and int(v) == 1

    async def _run(self):
        valids = [self.sig[v] for v, _, _ in CHANNELS.values()]
        while True:
            if not any(self._high(v) for v, _, _ in CHANNELS.values()):
                await First(*(RisingEdge(s) for s in valids))
            await RisingEdge(self.clk)
            edge = round(get_sim_time(unit="ns") / self.period)
            for ch, (v, r, payload) in CHANNELS.items():
                if not self._high(v):
                    continue
                if self.offered[ch] is None:
                    self.offered[ch] = edge
                if self._high(r):
                    self.moves[ch].append(Move(self.offered[ch], edge, {p: int(self.sig[p].value) for p in payload}))
                    self.offered[ch] = None

    def idle(self) -> bool:
        """No valid high and no offer waiting."""
        return all(o is None for o in self.offered.values()) and not any(
            self._high(v) for v, _, _ in CHANNELS.values())


def transactions(watch: PortWatch) -> list[tuple[int, Access]]:
    """The port's accesses in the order their addresses moved: (address edge, :class:`Access`); a write's
    data is its W (the k-th W belongs to the k-th AW)."""
    aw, w, ar = watch.moves["aw"], watch.moves["w"], watch.moves["ar"]
    out = [(a.edge, Access(True, a.payload["awaddr"], a.payload["awprot"], d.payload["wdata"], d.payload["wstrb"]))
           for a, d in zip(aw, w)]
    out += [(a.edge, Access(False, a.payload["araddr"], a.payload["arprot"])) for a in ar]
    return sorted(out, key=lambda t: t[0])


class CodedSlave:
    """An AXI4-Lite slave on port ``<prefix>_*`` (module docstring): ``code(addr)`` answers each access
    (a write answered with an error changes nothing, a read so answered returns 0);
    ``log`` lists (Access, resp, data) in the order served."""

    def __init__(self, dut, prefix: str, clk, rst, code, *, pause: float = 0.0, rng: random.Random | None = None):
        bus = AxiLiteBus.from_prefix(dut, prefix)
        self.aw = AxiLiteAWSink(bus.write.aw, clk, rst)
        self.w = AxiLiteWSink(bus.write.w, clk, rst)
        self.b = AxiLiteBSource(bus.write.b, clk, rst)
        self.ar = AxiLiteARSink(bus.read.ar, clk, rst)
        self.r = AxiLiteRSource(bus.read.r, clk, rst)
        self.code = code
        self.words: dict[int, int] = {}
        self.log: list[tuple[Access, int, int]] = []
        set_pauses((self.aw, self.w, self.b, self.ar, self.r), pause, rng or random.Random(1))
        cocotb.start_soon(self._writes())
        cocotb.start_soon(self._reads())

    def _answer(self, a: Access) -> tuple[int, int]:
        resp, word = self.code(a.addr), a.addr & ~3
        data = 0
        if resp == 0 and a.write:
            merged = self.words.get(word, 0)
            for i in range(4):
                if a.strb >> i & 1:
                    merged = merged & ~(0xFF << 8 * i) | a.data & (0xFF << 8 * i)
            self.words[word] = merged
        elif resp == 0:
            data = self.words.get(word, 0)
        self.log.append((a, resp, data))
        return resp, data

    async def _writes(self):
        while True:
            aw = await self.aw.recv()
            w = await self.w.recv()
            resp, _ = self._answer(Access(True, int(aw.awaddr), int(aw.awprot), int(w.wdata), int(w.wstrb)))
            await self.b.send(AxiLiteBTransaction(bresp=resp))

    async def _reads(self):
        while True:
            ar = await self.ar.recv()
            resp, data = self._answer(Access(False, int(ar.araddr), int(ar.arprot)))
            await self.r.send(AxiLiteRTransaction(rresp=resp, rdata=data))
