"""cocotb bench: the coordinate warper against :func:`eyestereo.tools.models.coordinate_warper.pairs`.

Runs on the harness :mod:`eyestereo.sim.harnesses.warper_harness` (consumer, enable pattern and recorder in HDL),
so Python wakes once per ``batch`` pairs. Every pair of every frame is compared, all fields, with the
model: none lost, repeated or reordered. Also checked: the harness's protocol checks (outputs frozen
while ``enable`` is low, an offered pair held until taken), one ``done`` per frame with ``busy`` low
after it, and nothing taken after the last frame.

Configuration (from the runner): ``params`` (the harness's: the warper's and ``batch``), ``frames``,
``ack_p`` (0..256: per-clock probability x 256 of acknowledging an offered pair), ``ack_reg`` (registered
one-clock pulses), ``burst`` (long stretches without acknowledgement), ``en_p`` (0..256: enable),
``seed``; ``reset_after`` (abandon a first frame with ``rst`` after that many pairs, then run the
frames), ``start_while_busy`` (pulse ``start`` during each frame: ignored), ``coefficients: "random"``
(load random codes through the coefficient port first and expect them).
"""

from __future__ import annotations

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, First, ReadOnly, RisingEdge, Timer
from cocotb.utils import get_sim_time

from eyestereo.sim.lib.bench import write_report
from eyestereo.sim.lib.rectify_bench import PERIOD, random_codes, rectify_config, reset, write_coefficients
from eyestereo.tools.models import coordinate_warper as model
from eyestereo.tools.models import poly_unit as unit_model


class WarperTB:
    def __init__(self, dut):
        self.dut = dut
        cfg, self.cal, self.frac = rectify_config()
        self.cfg = cfg
        p = cfg["params"]
        self.batch = int(p.get("batch", 16))
        self.word = model.pair_word(self.cal, self.frac)
        self.clk = dut.clk
        self.rows: list[np.ndarray] = []  # recorded pairs as bit rows, in order
        self.already = 0  # pairs of the batch in progress read already (at a done)
        self.frame_clocks: list[int] = []
        Clock(self.clk, PERIOD, unit="ns").start()
        dut.start.value = 0
        dut.ack_p.value = int(cfg.get("ack_p", 256))
        dut.ack_reg.value = int(bool(cfg.get("ack_reg", False)))
        dut.burst.value = int(bool(cfg.get("burst", False)))
        dut.en_p.value = int(cfg.get("en_p", 256))
        dut.seed.value = int(cfg.get("seed", 1)) & 0xFFFFFFFF
        if p.get("coefficients") == "register":
            dut.coef_we.value = 0
            dut.coef_addr.value = 0
            dut.coef_data.value = 0

    async def reset(self):
        await reset(self.dut, self.clk)
        self.already = 0

    def _bits(self, value, n: int) -> np.ndarray:
        try:
            v = int(value)
        except ValueError:
            raise AssertionError(f"undefined (X/U) bits in recorded pairs: {value}") from None
        raw = np.frombuffer(v.to_bytes((self.batch * self.word.width + 7) // 8, "little"), dtype=np.uint8)
        bits = np.unpackbits(raw, bitorder="little")[: self.batch * self.word.width]
        return bits.reshape(self.batch, self.word.width)[self.batch - n:] if n else bits[:0].reshape(0, self.word.width)

    async def pulse_start(self, *, until_busy: bool = True) -> int:
        """``start`` high until the warper takes it (``busy`` rises; ``enable`` may be low for a while);
        returns the number of the clock it was taken in (the harness's ``cycle``)."""
        await FallingEdge(self.clk)
        self.dut.start.value = 1
        while True:
            await RisingEdge(self.clk)
            await ReadOnly()
            if not until_busy or int(self.dut.busy.value):
                break
        cycle = int(self.dut.cycle.value) - 1
        await FallingEdge(self.clk)
        self.dut.start.value = 0
        return cycle

    async def collect(self, *, until_pairs: int | None = None, poke_start: bool = False) -> bool:
        """Read batches until ``done`` (True) or until ``until_pairs`` recorded pairs (False)."""
        dut = self.dut
        per_pair = 4 * 256 * 256 // max(1, int(self.cfg.get("ack_p", 256))) // max(1, int(self.cfg.get("en_p", 256)))
        timeout = 200_000 + self.batch * (per_pair + 40) * PERIOD * (40 if self.cfg.get("burst") else 2)
        poked = False
        while True:
            t0 = get_sim_time("ns")
            await First(RisingEdge(dut.rec_strobe), RisingEdge(dut.done), Timer(timeout, "ns"))
            await ReadOnly()
            strobe, done = int(dut.rec_strobe.value), int(dut.done.value)
            if not (strobe or done):
                raise AssertionError(f"no pair batch and no done for {get_sim_time('ns') - t0:.0f} ns "
                                     f"({len(self.rows)} pairs recorded)")
            if strobe:
                self.rows.append(self._bits(dut.rec_data.value, self.batch)[self.already:])
                self.already = 0
            if done:
                c = int(dut.rec_count.value)
                self.rows.append(self._bits(dut.rec_shift.value, c)[self.already:])
                self.already = c
                self.done_cycle = int(dut.cycle.value)
                return True
            if poke_start and not poked and sum(len(r) for r in self.rows) >= self.batch:
                poked = True
                await self.pulse_start(until_busy=False)  # a start while busy must be ignored
            if until_pairs is not None and sum(len(r) for r in self.rows) >= until_pairs:
                return False

    def recorded(self) -> dict[str, np.ndarray]:
        rows = np.concatenate(self.rows) if self.rows else np.zeros((0, self.word.width), dtype=np.uint8)
        return model.decode_words(rows, self.word)

    def compare(self, got: dict[str, np.ndarray], want: dict[str, np.ndarray], what: str) -> int:
        n_got, n_want = len(got["xl"]), len(want["xl"])
        n = min(n_got, n_want)
        w = self.cal.width * self.cal.height
        for f in model.PAIR_FIELDS:
            bad = np.nonzero(got[f][:n] != want[f][:n])[0]
            if len(bad):
                k = int(bad[0])
                raise AssertionError(
                    f"{what}: {len(bad)} pairs differ in {f}; first: pair {k} (frame {k // w}, pixel "
                    f"({k % w % self.cal.width}, {k % w // self.cal.width})): got {int(got[f][k]):#x}, "
                    f"expected {int(want[f][k]):#x}")
        assert n_got == n_want, f"{what}: {n_got} pairs recorded, {n_want} expected"
        return n


@cocotb.test()
async def coordinate_warper_frames(dut):
    tb = WarperTB(dut)
    cfg = tb.cfg
    await tb.reset()
    cal = tb.cal
    if cfg.get("coefficients") == "random":
        codes = random_codes(cal, np.random.default_rng(int(cfg.get("seed", 1))))
        cal = tb.cal = cal.with_codes(codes)
        await write_coefficients(dut, tb.clk, unit_model.register_writes(codes, cal.formats))
    elif cfg["params"].get("coefficients") == "register":
        await write_coefficients(dut, tb.clk, unit_model.register_writes(cal.codes, cal.formats))
    frames = int(cfg.get("frames", 1))
    one = model.pairs(cal, tb.frac, 1)
    report: dict = {}

    if cfg.get("reset_after"):
        k = int(cfg["reset_after"])
        await tb.pulse_start()
        finished = await tb.collect(until_pairs=k)
        assert not finished, "the frame ended before the reset"
        got = tb.recorded()
        n = tb.compare(got, {f: v[:len(got["xl"])] for f, v in one.items()}, "frame cut by rst")
        report["pairs_before_reset"] = n
        await tb.reset()
        assert int(dut.busy.value) == 0 and int(dut.takes.value) == 0, "rst must end the frame"
        tb.rows = []

    for _ in range(frames):
        c_start = await tb.pulse_start()
        await tb.collect(poke_start=bool(cfg.get("start_while_busy")))
        tb.frame_clocks.append(tb.done_cycle - c_start)  # from the start clock to the done clock
        await FallingEdge(tb.clk)
        assert int(dut.busy.value) == 0, "busy still high after done"

    # Nothing may follow: no pair, no done, the output empty.
    takes = int(dut.takes.value)
    await ClockCycles(tb.clk, 200)
    await ReadOnly()
    assert int(dut.takes.value) == takes, "pairs were taken after the last frame"
    assert int(dut.busy.value) == 0 and int(dut.done.value) == 0
    err = int(dut.err.value)
    assert err & 1 == 0, "an output changed while enable was low"
    assert err & 2 == 0, "an offered pair vanished or changed before it was taken"
    got = tb.recorded()
    n = tb.compare(got, model.pairs(cal, tb.frac, frames), f"{frames} frame(s)")
    assert takes == n, f"{takes} pairs taken, {n} recorded"
    first, last = int(dut.first_take.value), int(dut.last_take.value)
    report.update(pairs=n, frames=frames, frame_clocks=tb.frame_clocks, first_take=first, last_take=last,
                  clocks_per_pair=(last - first) / max(1, n - 1), oor_l=int(got["oor_l"].sum()),
                  oor_r=int(got["oor_r"].sum()), width=cal.width, height=cal.height)
    write_report(cfg, report)
