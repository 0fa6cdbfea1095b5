"""cocotb model of an SDR SDRAM: the part's pins on the DUT, its rules checked at every rising edge.

The rules, the parts and the timing convention are :mod:`eyestereo.tools.sdram` (pure Python, unit-tested
there); this module connects :class:`~eyestereo.tools.sdram.SdramChip` to the DUT's ``<prefix>_*`` ports
(:class:`~eyestereo.hdl.interfaces.sdram_bus.SdramPins`): it samples the pins at each rising edge and
drives ``<prefix>_dq_i`` with the part's read data for the following cycle (``Z`` where the part does not
drive, e.g. bytes masked by DQM). Broken rules are collected in :attr:`SdramModel.violations` (each with
its edge, time and rule); the bench fails on any. ``record=True`` keeps every access in the chip's
``write_log`` and ``read_log`` (:class:`~eyestereo.tools.sdram.SdramChip`), as the SRAM model's ``log``.

The model's clock period (``period_ns``) is the one the ns rules are checked against: the bench gives the
period of the clock it runs, so a controller that counted its clocks for a faster clock is caught.
While the command is inhibited and nothing is in flight the model sleeps until ``cs_n`` falls or ``dq_oe``
changes (no Python during the power-up wait or idle stretches); edges are counted from simulation time,
and the refresh rules are brought up to date at the next command and by :meth:`SdramModel.finish`.
"""

from __future__ import annotations

import cocotb
from cocotb.triggers import FallingEdge, First, RisingEdge, ValueChange
from cocotb.types import LogicArray
from cocotb.utils import get_sim_time

from eyestereo.sim.lib.sram_model import read_int
from eyestereo.tools.sdram import Pins, SdramChip, part as sdram_part


class SdramModel:
    """The SDRAM part on ``<prefix>_*`` of ``dut``; :meth:`start` it before the controller leaves reset."""

    def __init__(self, dut, clk, part, *, prefix: str = "pins", period_ns: float = 10.0,
                 cas_latency: int | None = None, sleep: bool = True, log: int = 0, record: bool = False):
        self.clk = clk
        self.part = sdram_part(part)
        self.period_ns = period_ns
        self.chip = SdramChip(self.part, period_ns=period_ns, cas_latency=cas_latency, strict=False, log=log,
                              record=record)
        self.sleep = sleep
        g = lambda f: getattr(dut, f"{prefix}_{f}")  # noqa: E731
        self.h_cke, self.h_cs_n, self.h_ras_n, self.h_cas_n, self.h_we_n = (g(f) for f in (
            "cke", "cs_n", "ras_n", "cas_n", "we_n"))
        self.h_ba, self.h_a, self.h_dqm, self.h_dq_o, self.h_dq_oe, self.h_dq_i = (g(f) for f in (
            "ba", "a", "dqm", "dq_o", "dq_oe", "dq_i"))
        bits = self.part.data_bits
        self._z = LogicArray("Z" * bits)
        self._full = (1 << bits) - 1
        self.h_dq_i.value = self._z
        self._driving = False
        self._task = None
        self._stopped = False

    @property
    def violations(self) -> list:
        return self.chip.violations

    @property
    def stats(self):
        return self.chip.stats

    def start(self) -> None:
        self._task = cocotb.start_soon(self._run())

    def stop(self) -> None:
        """Stop watching: the model's task ends at its next wake-up, without touching the pins."""
        self._stopped = True
        self.h_dq_i.value = self._z

    def edge_now(self) -> int:
        return round(get_sim_time("ps") / (self.period_ns * 1000.0))

    def finish(self) -> None:
        """Bring the refresh and open-row rules up to the current edge (call at the end of a run)."""
        self.chip.finish(self.edge_now())

    def _sample(self, t: int) -> Pins:
        p = Pins(cke=read_int(self.h_cke), cs_n=read_int(self.h_cs_n), dq_oe=read_int(self.h_dq_oe))
        if p.cs_n == 0:
            p.ras_n, p.cas_n, p.we_n = read_int(self.h_ras_n), read_int(self.h_cas_n), read_int(self.h_we_n)
            p.ba, p.a = read_int(self.h_ba), read_int(self.h_a)
        if p.cs_n == 0 or p.dq_oe or self.chip.wants_dqm(t):
            p.dqm = read_int(self.h_dqm)
        if p.dq_oe:
            p.dq_o = read_int(self.h_dq_o)
        return p

    def _drive(self, out) -> None:
        if out is None:
            if self._driving:
                self.h_dq_i.value = self._z
                self._driving = False
            return
        value, mask = out
        if mask == self._full:
            self.h_dq_i.value = value
        else:
            bits = self.part.data_bits
            s = "".join(("1" if (value >> i) & 1 else "0") if (mask >> i) & 1 else "Z" for i in range(bits - 1, -1, -1))
            self.h_dq_i.value = LogicArray(s)
        self._driving = True

    async def _run(self):
        chip = self.chip
        while True:
            await RisingEdge(self.clk)
            if self._stopped:
                return
            t = self.edge_now()
            p = self._sample(t)
            self._drive(chip.edge(t, p))
            if self.sleep and chip.idle and p.cs_n == 1 and not p.dq_oe:
                await First(FallingEdge(self.h_cs_n), ValueChange(self.h_dq_oe))
                if self._stopped:
                    return
