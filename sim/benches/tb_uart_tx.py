"""cocotb bench: uart_tx, random bytes offered with random pauses, the line edge for edge with the model.

The driver offers byte i ``gap_i`` clocks after byte i - 1 was taken (gap 0: already waiting, so the
frames follow back to back) and holds ``valid`` until the byte moves; it wakes at the offer and on
``sink_ready``, not per clock. A monitor records every change of ``tx`` with its edge. The bit-level model
(:func:`eyestereo.tools.models.uart_tx.uart_tx`) gives, from the same offers, the edge each byte is taken
and the line's transitions: both must be the VHDL's, edge for edge. An independent UART receiver
(:class:`eyestereo.sim.lib.uart.UartReceiver`, mid-bit samples in time) decodes the line: the bytes sent,
no framing error, nothing left over.

Config: ``params`` (clocks_per_bit), ``period`` (ps), ``bytes``, ``max_gap`` (clocks), ``seed``.
"""

from __future__ import annotations

import random

import cocotb
from cocotb.triggers import RisingEdge, Timer, ValueChange

from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.queue import EdgeClock, wait_until
from eyestereo.sim.lib.uart import UartReceiver
from eyestereo.tools.models.async_fifo import ClockSpec
from eyestereo.tools.models.uart_tx import uart_tx

RESET_EDGES = 4


class TxTB:
    """Clock, reset, the byte driver, the line monitor and the receiver."""

    def __init__(self, dut, cfg):
        self.dut, self.cfg = dut, cfg
        self.cpb = cfg["params"]["clocks_per_bit"]
        self.clock = EdgeClock(dut.clk, ClockSpec(cfg["period"], cfg["period"]))
        self.transitions: list[tuple[int, int]] = []
        self.takes: list[int] = []
        dut.sink_valid.value = 0
        dut.sink_data.value = 0
        dut.rst.value = 1

    async def start(self):
        cocotb.start_soon(self.clock.start())
        await wait_until(self.clock.before(RESET_EDGES))
        self.dut.rst.value = 0
        self.receiver = UartReceiver(self.dut.tx, self.cpb * self.cfg["period"])
        cocotb.start_soon(self._watch())

    async def _watch(self):
        while True:
            await ValueChange(self.dut.tx)
            v = self.dut.tx.value
            assert v.is_resolvable, f"tx is {v}"
            self.transitions.append((self.clock.edge_now() - RESET_EDGES, int(v)))

    async def play(self, offers):
        """Offers ``[(gap, byte), ...]`` as the model's :func:`uart_tx` describes; records the take edges."""
        c, dut = self.clock, self.dut
        edge = None
        for gap, byte in offers:
            offer = RESET_EDGES + gap if edge is None else edge + 1 + gap  # edges counted from time 0
            if edge is not None and gap:
                await wait_until(c.before(edge + 1))
                dut.sink_valid.value = 0
            await wait_until(c.before(offer))
            dut.sink_data.value = byte
            dut.sink_valid.value = 1
            if int(dut.sink_ready.value):
                edge = offer
            else:
                await RisingEdge(dut.sink_ready)
                edge = c.edge_now() + 1
            self.takes.append(edge - RESET_EDGES)
        if edge is not None:
            await wait_until(c.before(edge + 1))
            dut.sink_valid.value = 0


@cocotb.test()
async def uart_tx_bytes(dut):
    cfg = load_config()
    tb = TxTB(dut, cfg)
    rng = random.Random(cfg.get("seed", 1))
    await tb.start()
    # runs of back-to-back bytes (gap 0) and pauses, some shorter than a frame (the byte waits for ready)
    offers = [(0 if rng.random() < 0.5 else rng.randrange(1, cfg.get("max_gap", 40 * tb.cpb)), rng.randrange(256))
              for _ in range(cfg["bytes"])]
    await tb.play(offers)
    await Timer(12 * tb.cpb * cfg["period"], unit="ps")
    takes, transitions = uart_tx(offers, tb.cpb)
    assert tb.takes == takes, f"bytes taken at {tb.takes[:8]}..., the model takes them at {takes[:8]}..."
    assert tb.transitions == transitions, \
        f"line differs: first {next(((g, e) for g, e in zip(tb.transitions, transitions) if g != e), None)}, " \
        f"{len(tb.transitions)} vs {len(transitions)} transitions"
    assert tb.receiver.data() == bytes(b for _, b in offers), "the line does not decode to the bytes sent"
    assert not tb.receiver.framing and not tb.receiver.glitches
    assert int(dut.tx.value) == 1 and int(dut.sink_ready.value) == 1, "the transmitter is not idle at the end"
    gaps = [b - a for a, b in zip(takes, takes[1:])]
    write_report(cfg, dict(bytes=len(offers), transitions=len(transitions),
                           back_to_back=sum(g == 10 * tb.cpb for g in gaps)))
