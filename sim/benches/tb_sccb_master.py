"""cocotb bench: sccb_master writing its table into SCCB slave models, one per camera bus, edge for edge.

Each bus has an OV7670 slave model (:mod:`eyestereo.sim.lib.sccb`) that checks every timing rule while it
records the writes and answers the ID reads; a camera marked absent has a model that only watches (its
SIO_D stays pulled up: reads give 0xFF). The bench checks that

* every present model recorded exactly the table's writes, and the reads of PID and VER;
* every change of ``sio_c`` / ``sio_d_oe`` happened at the clock edge :func:`eyestereo.tools.models.sccb_master.changes`
  predicts, and ``done`` pulsed at the predicted edge, ``busy`` high until then;
* ``present`` has the bits of the answering cameras;
* optionally a ``start`` pulse while busy is ignored, and one after ``done`` writes the table again (the
  same level sequence, shifted to the quarter where the start was taken);
* at the end nothing is left over: no open transmission, no pending slave drive, ``busy`` low.

Python wakes on the bus's edges, ``done`` and the few clock edges of the reset and the start pulses.

Config: ``params`` (table, clk_hz, sccb_hz, cameras), ``answer`` (per camera), ``present`` (expected
bits), ``restart``, ``start_while_busy``.
"""

from __future__ import annotations

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, First, RisingEdge, Timer
from cocotb.utils import get_sim_time

from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.sccb import SccbBus, SccbSlave
from eyestereo.tools.models.sccb_master import changes, writes
from eyestereo.tools.ov7670 import PID, PID_VALUE, TABLE, VER, VER_VALUE


class SccbTB:
    """The master, its clock and the slave models of its buses."""

    def __init__(self, dut, cfg: dict):
        self.dut, self.cfg = dut, cfg
        p = cfg["params"]
        self.table = [tuple(e) for e in p.get("table", TABLE)]
        self.clk_hz, self.sccb_hz = p.get("clk_hz", 100e6), p.get("sccb_hz", 100e3)
        self.cameras = p.get("cameras", 2)
        self.period = round(1e12 / self.clk_hz)
        answer = cfg.get("answer", [True] * self.cameras)
        self.slaves = [SccbSlave(f"{k}", answer=bool(a)) for k, a in enumerate(answer)]
        self.bus = SccbBus(dut, self.slaves)
        self.expected, self.done_edge = changes(self.table, clk_hz=self.clk_hz, sccb_hz=self.sccb_hz)
        self.t1 = None

    def edge(self, t_ps: int) -> int:
        """The clock edge (1 = the first with the reset low) a change at ``t_ps`` came with."""
        k, r = divmod(t_ps - self.t1, self.period)
        assert r == 0, f"a change at {t_ps} ps, off the clock edges"
        return k + 1

    async def reset(self):
        d = self.dut
        cocotb.start_soon(Clock(d.clk, self.period, unit="ps").start())
        d.rst.value, d.start.value = 1, 0
        cocotb.start_soon(self.bus.run())
        await ClockCycles(d.clk, 3)
        await FallingEdge(d.clk)
        d.rst.value = 0
        await RisingEdge(d.clk)
        self.t1 = get_sim_time(unit="ps")

    async def pulse_start(self):
        await FallingEdge(self.dut.clk)
        self.dut.start.value = 1
        await FallingEdge(self.dut.clk)
        self.dut.start.value = 0

    async def wait_done(self) -> int:
        """Wait for ``done``; its edge number."""
        limit = (self.done_edge + 100) * self.period
        r = await First(RisingEdge(self.dut.done), Timer(limit, unit="ps"))
        assert isinstance(r, RisingEdge) or int(self.dut.done.value), "done never came"
        return self.edge(get_sim_time(unit="ps"))

    def check_writes(self, runs: int):
        want = writes(self.table) * runs
        for s in self.slaves:
            assert not s.errors, s.errors
            if s.answer:
                first = next((i for i, (a, b) in enumerate(zip(s.writes, want)) if a != b), None)
                assert s.writes == want, f"camera {s.name}: {len(s.writes)} writes, first differing {first}"
                assert s.reads == [(PID, PID_VALUE), (VER, VER_VALUE)] * runs, s.reads
            else:
                assert s.reads == [(PID, 0xFF), (VER, 0xFF)] * runs, s.reads

    def levels(self, changes_: list) -> list[tuple[int, int, int]]:
        return [(self.edge(t), c, 1 - oe) for t, c, oe in changes_]


@cocotb.test()
async def table_written(dut):
    cfg = load_config()
    tb = SccbTB(dut, cfg)
    await tb.reset()
    assert int(dut.busy.value) == 1, "busy low after reset"
    if cfg.get("start_while_busy"):
        await ClockCycles(dut.clk, tb.done_edge // 3)
        await tb.pulse_start()
    done = await tb.wait_done()
    assert done == tb.done_edge, f"done after edge {done}, the model says {tb.done_edge}"
    got = tb.levels(tb.bus.changes)
    assert got == tb.expected, (f"{len(got)} level changes, the model has {len(tb.expected)}; first difference: "
                                f"{next(((a, b) for a, b in zip(got, tb.expected) if a != b), None)}")
    await FallingEdge(dut.clk)
    assert int(dut.busy.value) == 0 and int(dut.done.value) == 1
    await FallingEdge(dut.clk)  # a one-clock pulse
    assert int(dut.busy.value) == 0 and int(dut.done.value) == 0
    assert int(dut.present.value) == cfg["present"], f"present {int(dut.present.value):#b}, want {cfg['present']:#b}"
    tb.check_writes(1)
    runs = 1
    # a start while busy is ignored: the bus stays quiet after done
    await ClockCycles(dut.clk, 40)
    assert len(tb.bus.changes) == len(got) and int(dut.busy.value) == 0, "activity after done without a start"
    if cfg.get("restart"):
        n0 = len(tb.bus.changes)
        await tb.pulse_start()
        assert int(dut.busy.value) == 1, "start not taken"
        await tb.wait_done()
        again = tb.levels(tb.bus.changes[n0:])
        shift = again[0][0] - tb.expected[0][0]
        assert [(e - shift, c, d) for e, c, d in again] == tb.expected, "the second run's levels differ"
        runs = 2
        assert int(dut.present.value) == cfg["present"]
        tb.check_writes(2)
    await Timer(2 * tb.slaves[0].rules.ps("t_aa"), unit="ps")
    assert tb.bus.pending == 0 and all(s.idle() for s in tb.slaves), "a slave is left inside a transmission"
    write_report(cfg, dict(runs=runs, changes=len(tb.bus.changes), done_edge=tb.done_edge,
                           writes=[len(s.writes) for s in tb.slaves]))
