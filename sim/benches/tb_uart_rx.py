"""cocotb bench: uart_rx, a sender off in baud, glitches, framing errors and an overrun, edge for edge with the model.

A :class:`~eyestereo.sim.lib.uart.UartSender` plays, asynchronously to the clock: random bytes at the
nominal bit time and at the skews of the config (back to back and with idle gaps), glitches on the idle
line shorter than half a bit, bytes with a 0 stop bit followed by a good byte, and three bytes while the
consumer's ``ready`` is low. Every line transition falls between clock edges (the edges sit on even ps,
the transitions on odd ps), so the line each edge saw is defined; the bit-level model
(:func:`eyestereo.tools.models.uart_rx.uart_rx`) is run on those samples and its events, edge for edge,
must equal what the VHDL did: ``source.valid`` rising with the byte, ``frame_error`` and ``overrun`` pulses.
The bytes the model decodes must be the bytes sent (the independent reference). The monitors wake on
those three signals only.

Config: ``params`` (clocks_per_bit), ``period`` (clock, ps, even), ``bytes`` (per skew), ``skews``,
``glitches``, ``framing``, ``seed``.
"""

from __future__ import annotations

import random

import cocotb
from cocotb.simtime import get_sim_time
from cocotb.triggers import ReadOnly, RisingEdge, Timer

from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.queue import EdgeClock, wait_until
from eyestereo.sim.lib.uart import UartSender
from eyestereo.tools.models.async_fifo import ClockSpec
from eyestereo.tools.models.uart_rx import sample, uart_rx

RESET_EDGES = 4


class RxTB:
    """Clock, reset, the line's sender, the output monitors."""

    def __init__(self, dut, cfg):
        self.dut, self.cfg = dut, cfg
        self.cpb = cfg["params"]["clocks_per_bit"]
        self.clock = EdgeClock(dut.clk, ClockSpec(cfg["period"], cfg["period"]))
        self.bit_ps = self.cpb * cfg["period"]
        self.sender = UartSender(dut.rx, self.bit_ps)
        self.events: list[tuple[int, str, int | None]] = []  # (edge, kind, byte) as the VHDL did them
        self.undefined: list[str] = []
        dut.source_ready.value = 1
        dut.rst.value = 1

    async def start(self):
        cocotb.start_soon(self.clock.start())
        await wait_until(self.clock.before(RESET_EDGES))
        self.dut.rst.value = 0
        for name in ("source_valid", "frame_error", "overrun"):
            cocotb.start_soon(self._watch(name))

    async def _watch(self, name):
        sig = getattr(self.dut, name)
        while True:
            await RisingEdge(sig)
            k = self.clock.edge_now()
            await ReadOnly()
            if name == "source_valid":
                v = self.dut.source_data.value
                if not v.is_resolvable:
                    self.undefined.append(f"edge {k}: data {v}")
                    continue
                self.events.append((k - RESET_EDGES, "byte", int(v)))
            else:
                self.events.append((k - RESET_EDGES, "framing" if name == "frame_error" else "overrun", None))

    async def odd(self):
        """To an odd picosecond: the sender's transitions then never coincide with a clock edge (even ps)."""
        if int(get_sim_time(unit="ps")) % 2 == 0:
            await Timer(1, unit="ps")

    def next_edge(self) -> int:
        """The index of the first clock edge after now."""
        return self.clock.spec.first_after(int(get_sim_time(unit="ps")))

    def skewed(self, skew: float) -> int:
        """The bit time of a sender ``skew`` off (positive: slower), rounded to even ps."""
        return 2 * round(self.bit_ps * (1 + skew) / 2)


@cocotb.test()
async def uart_rx_bytes(dut):
    cfg = load_config()
    tb = RxTB(dut, cfg)
    rng = random.Random(cfg.get("seed", 1))
    await tb.start()
    await Timer(3 * tb.bit_ps, unit="ps")
    sent: list[int] = []
    overrun_window: list[tuple[int, int]] = []
    for skew in cfg.get("skews", [0.0]):
        bit = tb.skewed(skew)
        data = [rng.randrange(256) for _ in range(cfg["bytes"])]
        half = len(data) // 2
        await tb.odd()
        await tb.sender.send(data[:half], bit_ps=bit)  # back to back
        for b in data[half:]:
            await tb.odd()
            await tb.sender.send([b], bit_ps=bit, gap_ps=2 * rng.randrange(0, 2 * bit))
        sent += data
        await Timer(2 * tb.bit_ps, unit="ps")
    # glitches on the idle line, each shorter than half a bit (an even number of ps, from an odd time)
    for _ in range(cfg.get("glitches", 0)):
        await tb.odd()
        await tb.sender.glitch(2 * rng.randrange(1, tb.bit_ps // 4))
        await Timer(2 * tb.bit_ps + 2 * rng.randrange(tb.bit_ps), unit="ps")
    # framing errors: a 0 stop bit (the line then goes high), then a good byte
    for _ in range(cfg.get("framing", 0)):
        bad, good = rng.randrange(256), rng.randrange(256)
        await tb.odd()
        await tb.sender.send([bad], stop_bits=[0], gap_ps=2 * tb.bit_ps)
        await tb.odd()
        await tb.sender.send([good])
        sent.append(good)
        await Timer(tb.bit_ps, unit="ps")
    # an overrun: three bytes while the consumer does not take
    await wait_until(tb.clock.before(tb.next_edge()))
    dut.source_ready.value = 0
    first = tb.next_edge()
    await tb.odd()
    three = [rng.randrange(256) for _ in range(3)]
    await tb.sender.send(three)
    await Timer(tb.bit_ps, unit="ps")
    await wait_until(tb.clock.before(tb.next_edge()))
    dut.source_ready.value = 1
    overrun_window.append((first - RESET_EDGES, tb.next_edge() - RESET_EDGES))
    sent.append(three[0])
    await Timer(4 * tb.bit_ps, unit="ps")

    # the model on the line as the clock saw it
    end = tb.next_edge()
    edges = [tb.clock.spec.time(k) for k in range(RESET_EDGES, end)]
    expected = uart_rx(sample(tb.sender.transitions, edges), tb.cpb)
    for a, b in overrun_window:
        inside = [i for i, e in enumerate(expected) if a <= e[0] < b and e[1] == "byte"]
        for i in inside[1:]:
            expected[i] = (expected[i][0], "overrun", None)
    got = sorted(tb.events)
    assert not tb.undefined, tb.undefined[:5]
    first = next(((g, e) for g, e in zip(got, expected) if g != e), None)
    assert got == expected, f"VHDL and model differ: first {first}, {len(got)} vs {len(expected)} events"
    assert [e[2] for e in expected if e[1] == "byte"] == sent, "the model did not decode the bytes sent"
    assert int(dut.source_valid.value) == 0, "a byte left on source at the end"
    write_report(cfg, dict(bytes=sum(e[1] == "byte" for e in got), framing=sum(e[1] == "framing" for e in got),
                           overrun=sum(e[1] == "overrun" for e in got), clocks=end))
