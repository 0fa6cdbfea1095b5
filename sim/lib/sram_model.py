"""cocotb model of the board's SRAM: the part's pins on the DUT, its rules checked at every rising edge.

The rules, the two kinds of part and the timing convention are :mod:`eyestereo.tools.sram` (pure Python,
unit-tested there); this module only connects :class:`~eyestereo.tools.sram.SramChip` to the DUT's
``<prefix>_*`` ports (:class:`~eyestereo.hdl.interfaces.sram_bus.SramPins`): it samples the pins at each rising edge
and drives ``<prefix>_dq_i`` with the part's read data for the following cycle (``Z`` when the part does
not drive). A broken rule raises :class:`~eyestereo.tools.sram.SramViolation` in the model's task, which
fails the test with the rule, the edge and the time.

While the part is deselected with nothing in flight, the model sleeps until ``ce_n`` falls, ``ld_n``
changes or ``dq_oe`` rises (no Python on idle clocks); edges are counted from simulation time.
"""

from __future__ import annotations

import cocotb
from cocotb.triggers import FallingEdge, First, RisingEdge, ValueChange
from cocotb.types import LogicArray
from cocotb.utils import get_sim_time

from eyestereo.tools.sram import Pins, SramChip, SramPart


def read_int(handle):
    """A port's value as an int, or None if any bit is X, U or Z."""
    v = handle.value
    return int(v) if v.is_resolvable else None


def _bytes(handle, nbytes: int) -> tuple:
    s = str(handle.value)
    out = []
    n = len(s)
    for b in range(nbytes):
        chunk = s[n - 8 * (b + 1):n - 8 * b]
        out.append(int(chunk, 2) if chunk and all(c in "01" for c in chunk) else None)
    return tuple(out)


class SramModel:
    """The SRAM part on ``<prefix>_*`` of ``dut``; call :meth:`start` once the DUT is out of reset."""

    def __init__(self, dut, clk, part: SramPart, *, prefix: str = "sram", period_ns: float = 10.0,
                 strict: bool = True, sleep: bool = True, log: bool = False):
        self.clk = clk
        self.part = part
        self.chip = SramChip(part, strict=strict, period_ns=period_ns, log=log)
        self.period_ns = period_ns
        self.sleep = sleep
        g = lambda f: getattr(dut, f"{prefix}_{f}")  # noqa: E731
        self.h_addr, self.h_ce_n, self.h_ld_n = g("addr"), g("ce_n"), g("ld_n")
        self.h_we_n, self.h_bw_n, self.h_oe_n = g("we_n"), g("bw_n"), g("oe_n")
        self.h_dq_o, self.h_dq_oe, self.h_dq_i = g("dq_o"), g("dq_oe"), g("dq_i")
        self._z = LogicArray("Z" * part.data_bits)
        self.h_dq_i.value = self._z
        self._driving = False
        self._task = None
        self.error: BaseException | None = None

    @property
    def mem(self) -> dict:
        return self.chip.mem

    def start(self) -> None:
        self._task = cocotb.start_soon(self._run())

    def _edge_number(self) -> int:
        return round(get_sim_time("ns") / self.period_ns)

    def _sample(self) -> Pins:
        p = Pins()
        p.ld_n = read_int(self.h_ld_n)
        p.ce_n = read_int(self.h_ce_n)
        p.dq_oe = read_int(self.h_dq_oe)
        p.oe_n = read_int(self.h_oe_n)
        if p.ce_n == 0:
            p.addr = read_int(self.h_addr)
            p.we_n = read_int(self.h_we_n)
            if p.we_n == 0:
                p.bw_n = read_int(self.h_bw_n)
        if p.dq_oe:
            p.dq_o = _bytes(self.h_dq_o, self.part.nbytes)
        return p

    async def _run(self):
        chip = self.chip
        while True:
            await RisingEdge(self.clk)
            p = self._sample()
            out = chip.edge(self._edge_number(), p)
            if out is not None:
                self.h_dq_i.value = out
                self._driving = True
            elif self._driving:
                self.h_dq_i.value = self._z
                self._driving = False
            if self.sleep and chip.idle and p.ce_n == 1 and p.ld_n == 0 and not p.dq_oe:
                # Nothing in flight and deselected: wait for the next access (or a rule-relevant pin).
                await First(FallingEdge(self.h_ce_n), ValueChange(self.h_ld_n), ValueChange(self.h_dq_oe))
