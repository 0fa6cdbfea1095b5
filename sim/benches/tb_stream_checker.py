"""cocotb bench: stream_checker against :func:`eyestereo.tools.models.stream_checker.stream_checker`, beat for beat.

One simulation runs many scenarios, each from a fresh ``rst``: good frames with a reset token, every
fault class the configuration allows (a good frame, the broken one, two good ones: detection and
recovery), a missing eof followed by a token, and a random mix of good frames, broken frames and tokens
without a reset in between (the code keeps the first fault). For every scenario the output beats
(cycle, data, eol, eof, cam), the ``error`` and ``code`` outputs on each beat, and every change of
``error`` and ``code`` (watched by edge, not per clock) must equal the model's; no output bit may be
undefined.
"""

from __future__ import annotations

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge

from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.stream import BeatMonitor, BeatSource, IdleGenerator
from eyestereo.tools.models import stream_checker as model
from eyestereo.tools.stream import TOKEN

PERIOD_NS = 10


def fault_kinds(width: int, height: int, stereo: bool) -> list[str]:
    """The fault kinds a width x height frame can show."""
    kinds = ["missing_eof"]
    if height >= 2:
        kinds += ["long_line", "long_line_extra", "early_eof"]
    if width >= 2:
        kinds += ["short_line", "short_last_line"]
    if stereo:
        kinds += ["cam_swap", "cam_missing", "pair_mismatch", "pair_eof"]
    return kinds


def scenarios(width: int, height: int, stereo: bool, seed: int) -> list[tuple[str, list[tuple]]]:
    """(name, beats) of every scenario, each to be run from a reset."""
    rng = np.random.default_rng(seed)
    tok = TOKEN + ((0,) if stereo else ())

    def good():
        left, right = rng.integers(0, 256, (2, height, width))
        return model.frame_beats(left, stereo=stereo, right=right)

    def bad(kind):
        return model.faulty_frame(kind, width, height, rng, stereo=stereo)[0]

    kinds = fault_kinds(width, height, stereo)
    g = good()
    out = [("good", good() + g[:len(g) // 2] + [tok] + good() + good())]
    out += [(kind, good() + bad(kind) + good() + good()) for kind in kinds]
    out.append(("missing_eof+token", bad("missing_eof") + [tok] + good()))
    mixed = []
    for _ in range(12):
        r = rng.random()
        mixed += good() if r < 0.5 else bad(str(rng.choice(kinds))) if r < 0.9 else [tok]
    out.append(("mixed", mixed + good()))
    return out


class CheckerTB:
    def __init__(self, dut, cfg: dict):
        self.dut = dut
        self.cfg = cfg
        p = cfg["params"]
        self.width, self.height = p["width"], p["height"]
        self.stereo, self.repair = bool(p.get("stereo", False)), bool(p.get("repair", False))
        Clock(dut.clk, PERIOD_NS, unit="ns").start()
        dut.rst.value = 0
        self.source = BeatSource(dut, "sink", dut.clk, IdleGenerator(cfg.get("duty", 1.0), cfg.get("seed", 0)),
                                 period_ns=PERIOD_NS)
        self.monitor = BeatMonitor(dut, "source", dut.clk, extra=("error", "code"), period_ns=PERIOD_NS)

    async def reset(self):
        self.dut.rst.value = 1
        await ClockCycles(self.dut.clk, 3)
        self.dut.rst.value = 0
        await RisingEdge(self.dut.clk)
        self.monitor.beats.clear()
        self.monitor.undefined.clear()
        for c in self.monitor.changes.values():
            c.clear()
        self.source.sent_cycles.clear()

    async def run(self, name: str, beats: list[tuple]) -> dict:
        await self.reset()
        self.source.send_beats(beats)
        while self.source.queue:
            await ClockCycles(self.dut.clk, 16)
        await ClockCycles(self.dut.clk, 4)  # the last beat's output, and anything that should not come
        steps = model.stream_checker(beats, self.width, self.height, stereo=self.stereo, repair=self.repair)
        sent = self.source.sent_cycles
        assert len(sent) == len(beats), f"{name}: {len(sent)} beats sent of {len(beats)}"
        want = []
        for cyc, s in zip(sent, steps):
            if s.out is not None:
                out = tuple(int(v) for v in s.out) + ((0,) if len(s.out) == 3 else ())
                want.append((cyc + 1,) + out + (int(s.error), s.code))
        got = self.monitor.beats
        assert not self.monitor.undefined, f"{name}: undefined output bits: {self.monitor.undefined[:3]}"
        if got != want:
            bad = next(i for i, (a, b) in enumerate(zip(got + [None] * len(want), want + [None] * len(got)))
                       if a != b)
            raise AssertionError(f"{name}: output beat {bad} (cycle, data, eol, eof, cam, error, code) is "
                                 f"{got[bad] if bad < len(got) else None}, the model says "
                                 f"{want[bad] if bad < len(want) else None} "
                                 f"({len(got)} beats out, {len(want)} expected)")
        first = next((i for i, s in enumerate(steps) if s.error), None)
        changes = self.monitor.changes
        if first is None:
            assert changes["error"] == [] and changes["code"] == [], f"{name}: {changes}"
        else:
            at = sent[first] + 1
            assert changes["error"] == [(at, 1)], f"{name}: error changed {changes['error']}, expected [({at}, 1)]"
            assert changes["code"] == [(at, steps[first].code)], f"{name}: code changed {changes['code']}"
        faults = model.fault_positions(steps)
        return dict(name=name, beats_in=len(beats), beats_out=len(got), faults=len(faults),
                    first_code=steps[first].code if first is not None else 0,
                    dropped=sum(s.out is None for s in steps))


@cocotb.test()
async def stream_checker_scenarios(dut):
    cfg = load_config()
    tb = CheckerTB(dut, cfg)
    results = []
    for name, beats in scenarios(tb.width, tb.height, tb.stereo, cfg.get("seed", 0)):
        results.append(await tb.run(name, beats))
    codes = {r["first_code"] for r in results}
    kinds = fault_kinds(tb.width, tb.height, tb.stereo)
    expected_codes = {0} | {model.KIND_CODES[k] for k in kinds}
    assert codes == expected_codes, f"fault codes seen {sorted(codes)}, expected {sorted(expected_codes)}"
    if tb.repair:
        assert sum(r["dropped"] for r in results) > 0, "repair mode dropped no beat"
    write_report(cfg, dict(scenarios=results, frames=len(results),
                           pixels_compared=sum(r["beats_out"] for r in results)))
