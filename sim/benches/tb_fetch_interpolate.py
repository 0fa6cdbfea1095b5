"""cocotb bench: fetch_interpolate alone, pairs from Python, against :mod:`eyestereo.tools.models.fetch_interpolate`.

A :class:`PairSource` offers coordinate pairs over the CoordPair handshake (held until ``read_ack``, random
gaps) -- random walks of the integer position with steps -2..+2 (every case of the reuse rule and jumps
beyond it), random fractions, sides out of range with probability ``oor_p``, frames of ``width x height``
pairs with eol/eof; the memory model of :mod:`eyestereo.sim.lib.fetch_memory` answers. Checked: every output
beat (data, cam, eol, eof) and every request (x, y, cam, mask) equal to the model's; ``busy`` low at the
end, nothing left over or after.

Configuration: ``params`` (the block's: a calibration spec sizes the camera images and ``frac``),
``width``/``height`` (the pair frames), ``frames``, ``oor_p``, ``offer_p`` (probability per clock that
a pair is offered), the memory's ``seed``, ``ready_p``, ``latency``, ``wait_p``, ``stall_p``.
"""

from __future__ import annotations

import random

import cocotb
import numpy as np
from cocotb.clock import Clock

from eyestereo.sim.lib.bench import write_report
from eyestereo.sim.lib.fetch_memory import Clocked, StereoMonitor, compare_requests, compare_stream
from eyestereo.sim.lib.rectify_bench import PERIOD, memory, quiet, rectify_config, reset, wait_beats
from eyestereo.tools.models import fetch_interpolate as model
from eyestereo.tools.models.poly_unit import coord_format


def random_pairs(rng: np.random.Generator, n: int, sw: int, sh: int, frac: int, oor_p: float, nx: int,
                 ny: int) -> dict[str, np.ndarray]:
    out = {}
    steps = np.array([-2, -1, 0, 1, 1, 1, 2])
    for xk, yk, ok in (("xl", "yl", "oor_l"), ("xr", "yr", "oor_r")):
        sx = rng.choice(steps, n)
        sy = rng.choice(np.array([-1, 0, 0, 0, 0, 1, 2]), n)
        jump = rng.random(n) < 0.02
        x0 = np.zeros(n, dtype=np.int64)
        y0 = np.zeros(n, dtype=np.int64)
        x, y = int(rng.integers(0, sw - 1)), int(rng.integers(0, sh - 1))
        for k in range(n):
            if jump[k]:
                x, y = int(rng.integers(0, sw - 1)), int(rng.integers(0, sh - 1))
            else:
                x = min(max(x + int(sx[k]), 0), sw - 2)
                y = min(max(y + int(sy[k]), 0), sh - 2)
            x0[k], y0[k] = x, y
        oor = (rng.random(n) < oor_p).astype(np.int64)
        fx = rng.integers(0, 1 << frac, n) if frac else np.zeros(n, dtype=np.int64)
        fy = rng.integers(0, 1 << frac, n) if frac else np.zeros(n, dtype=np.int64)
        xs, ys = (x0 << frac) | fx, (y0 << frac) | fy
        # out of range: any bits (the block must not use them)
        xs = np.where(oor == 1, rng.integers(0, 1 << nx, n), xs)
        ys = np.where(oor == 1, rng.integers(0, 1 << ny, n), ys)
        out[xk], out[yk], out[ok] = xs, ys, oor
    return out


class PairSource:
    """Offers the pairs in order over ``coord_*``; a pair moves at an edge with valid and read_ack high."""

    def __init__(self, dut, pairs: dict[str, np.ndarray], *, offer_p: float, seed: int):
        self.dut = dut
        self.pairs = pairs
        self.n = len(pairs["xl"])
        self.k = 0
        self.offer_p = offer_p
        self.rng = random.Random(seed)
        self.offering = False
        self.h = {f: getattr(dut, f"coord_{f}") for f in ("valid", "read_ack", "xl", "yl", "xr", "yr", "oor_l",
                                                         "oor_r", "eol", "eof")}
        self.h["valid"].value = 0
        self.taken_clocks: list[int] = []

    def edge(self, clock: int) -> None:
        if self.offering and int(self.h["read_ack"].value):
            self.taken_clocks.append(clock)
            self.k += 1
            self.offering = False
        if not self.offering and self.k < self.n and (self.offer_p >= 1 or self.rng.random() < self.offer_p):
            for f in ("xl", "yl", "xr", "yr", "oor_l", "oor_r", "eol", "eof"):
                self.h[f].value = int(self.pairs[f][self.k])
            self.offering = True
        self.h["valid"].value = int(self.offering)


@cocotb.test()
async def fetch_interpolate_pairs(dut):
    cfg, cal, frac = rectify_config()
    sw, sh = cal.source_width, cal.source_height
    w, h, frames = int(cfg.get("width", 16)), int(cfg.get("height", 6)), int(cfg.get("frames", 2))
    n = w * h * frames
    rng = np.random.default_rng(int(cfg.get("seed", 1)))
    nx, ny = coord_format(frac, sw).wl, coord_format(frac, sh).wl
    pairs = random_pairs(rng, n, sw, sh, frac, float(cfg.get("oor_p", 0.1)), nx, ny)
    eol = np.zeros((frames, h, w), dtype=np.int64)
    eol[:, :, -1] = 1
    eof = np.zeros((frames, h, w), dtype=np.int64)
    eof[:, -1, -1] = 1
    pairs["eol"], pairs["eof"] = eol.ravel(), eof.ravel()
    if cfg.get("first_in_range"):  # the first pair's sides both fetched: its latency is FIRST_PIXEL's
        pairs["oor_l"][0] = pairs["oor_r"][0] = 0
    left = rng.integers(0, 256, (sh, sw), dtype=np.uint8)
    right = rng.integers(0, 256, (sh, sw), dtype=np.uint8)

    clk = dut.clk
    Clock(clk, PERIOD, unit="ns").start()
    dut.rst.value = 0
    mem = memory(dut, cfg, {0: left, 1: right})
    mon = StereoMonitor(dut)
    src = PairSource(dut, pairs, offer_p=float(cfg.get("offer_p", 1.0)), seed=int(cfg.get("seed", 1)) + 7)
    await reset(dut, clk)
    loop = Clocked(clk, [src, mem, mon])
    cocotb.start_soon(loop.run())
    await wait_beats(clk, mon, 2 * n, 200 * n + 5000, "pairs")
    await quiet(dut, clk, mem, mon)
    assert src.k == n, f"{src.k} of {n} pairs taken"

    got = mon.arrays()
    lo, ro = model.fetch_interpolate(left, right, pairs, frac)
    want = {"data": np.stack([lo, ro], axis=1).ravel().astype(np.int64), "cam": np.tile([0, 1], n),
            "eol": np.repeat(pairs["eol"], 2), "eof": np.repeat(pairs["eof"], 2)}
    compare_stream(got, want, w, f"{n} pairs")
    req = model.requests(pairs, frac)
    compare_requests(mem.request_arrays(), req, "fetch requests")
    masks = mem.request_arrays()["mask"]
    kinds = sorted({int(m) for m in masks})
    write_report(cfg, dict(pairs=n, beats=len(mon.beats), requests=len(mem.requests), reads=mem.reads,
                           masks=kinds, clocks=loop.clock, black=int(pairs["oor_l"].sum() + pairs["oor_r"].sum()),
                           first_pixel=mon.clocks[0] - src.taken_clocks[0],
                           first_in_range=bool(not pairs["oor_l"][0])))
