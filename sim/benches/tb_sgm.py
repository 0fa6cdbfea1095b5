"""cocotb bench: sgm against :func:`eyestereo.tools.models.sgm.sgm` (and dense_stereo, the chain of census,
sgm and median3, against :func:`eyestereo.tools.models.dense_stereo.dense_stereo`), bit for bit on every pixel.

Stereo pairs (random, Tsukuba crops, or a shifted copy) go through the census model, and their census words
go in as a stereo stream at a given pixel rate (``pixel_clocks``: the average clocks between two pixels,
with random idle gaps) after an optional partial frame cut by a reset token, frames back to back. Checked:
each output frame equals the model's codes on every pixel; no beat has undefined bits; exactly the frames
(and the token) that went in come out, nothing pending or extra; ``overrun`` stays low (or, with
``expect_overrun``, goes high and stays high). ``save``: a .npy path for the output codes (frames x height x
width, int64; undefined bits as -1). Reported: the clocks from a row's last input pixel to its first
output and the output's beats per row.
"""

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge

from eyestereo.hdl.dense.dense_stereo import fifo_depth
from eyestereo.hdl.dense.sgm import spacing
from eyestereo.sim.lib.bench import grey_frame as stimulus
from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.stream import UNKNOWN, BeatMonitor, BeatSource, IdleGenerator
from eyestereo.tools.models import census as census_model
from eyestereo.tools.models import dense_stereo as chain_model
from eyestereo.tools.models import sgm as model
from eyestereo.tools.models.stream_checker import frame_beats
from eyestereo.tools.stream import TOKEN, FrameAssembler

PERIOD_NS = 10


def pair(specs: list[str], width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """A grey pair: two :func:`stimulus` specs, or ``["shift:SEED:D", ...]`` (a random left image and its
    copy moved D columns to the left as the right image: every pixel at disparity D)."""
    if specs[0].startswith("shift:"):
        _, seed, d = specs[0].split(":")
        wide = np.random.default_rng(int(seed)).integers(0, 256, (height, width + int(d)), dtype=np.int64)
        return wide[:, :width], wide[:, int(d):int(d) + width]
    return stimulus(specs[0], width, height), stimulus(specs[1], width, height)


class SgmTB:
    """Clock, reset, the run-time settings, a beat source and a monitor around ``sgm``."""

    def __init__(self, dut, cfg: dict):
        p = cfg["params"]
        self.dut, self.cfg, self.p = dut, cfg, p
        self.w, self.h = p["width"], p["height"]
        self.chain = cfg["block"] == "dense_stereo"  # grey pixels in, the whole chain's codes out
        self.settings = dict(p1=cfg.get("p1", 10), p2=cfg.get("p2", 30), uniqueness=cfg.get("uniqueness", 10),
                             lr_check=cfg.get("lr_check", True), subpixel=cfg.get("subpixel", True))
        Clock(dut.clk, PERIOD_NS, unit="ns").start()
        # two beats per pixel: a beat in a clock with probability 2 / pixel_clocks
        duty = min(1.0, 2.0 / cfg.get("pixel_clocks", 1.5 * spacing(p["disparities"], p["pu"])))
        self.source = BeatSource(dut, "sink", dut.clk, IdleGenerator(duty, cfg.get("seed", 0)), period_ns=PERIOD_NS)
        self.monitor = None

    async def reset(self):
        d, s = self.dut, self.settings
        d.p1.value, d.p2.value, d.uniqueness.value = s["p1"], s["p2"], s["uniqueness"]
        d.lr_check.value, d.subpixel.value = int(s["lr_check"]), int(s["subpixel"])
        d.rst.value = 1
        await ClockCycles(d.clk, 3)
        d.rst.value = 0
        await RisingEdge(d.clk)
        self.monitor = BeatMonitor(d, "source", d.clk, extra=("overrun",), period_ns=PERIOD_NS)

    def expected(self, left, right) -> np.ndarray:
        p = self.p
        if self.chain:
            return chain_model.dense_stereo(left, right, disparities=p["disparities"], paths=p["paths"],
                                            window=p["window"], median=p["median"], path_bits=p["path_bits"],
                                            sum_shift=p["sum_shift"], frac_bits=p["frac_bits"], **self.settings)
        cl, cr = census_model.census_stereo(left, right, window=p["window"])
        return model.sgm(cl, cr, disparities=p["disparities"], paths=p["paths"], window=p["window"],
                         path_bits=p["path_bits"], sum_shift=p["sum_shift"], frac_bits=p["frac_bits"],
                         **self.settings)

    def beats_of(self, left, right) -> list[tuple]:
        if self.chain:
            return frame_beats(left, stereo=True, right=right)
        cl, cr = census_model.census_stereo(left, right, window=self.p["window"])
        return frame_beats(cl.astype(np.int64), stereo=True, right=cr.astype(np.int64))


@cocotb.test()
async def sgm_frames(dut):
    cfg = load_config()
    tb = SgmTB(dut, cfg)
    w, h = tb.w, tb.h
    await tb.reset()
    pairs = [pair(specs, w, h) for specs in cfg["frames"]]
    beats, tokens = [], 0
    if cfg.get("token_after") is not None:
        left, right = pair(["random:99", "random:98"], w, h)
        beats += tb.beats_of(left, right)[:cfg["token_after"]] + [TOKEN + (0,)]
        tokens = 1
    starts = []
    for left, right in pairs:
        starts.append(len(beats))
        beats += tb.beats_of(left, right)
    tb.source.send_beats(beats)
    while tb.source.queue:
        await ClockCycles(dut.clk, 256)
    # the last row: its pixels still in the FIFO, then the pipeline, then the drain
    sp = spacing(tb.p["disparities"], tb.p["pu"])
    # (the chain: the census's and the median's last lines first)
    fifo = tb.p["fifo"] or fifo_depth(tb.p["window"], w)
    await ClockCycles(dut.clk, fifo * sp + 4 * sp + 3 * w + 200 + (8 * w + 100) * tb.chain)

    mon = tb.monitor
    assert not mon.undefined, f"undefined outputs: {mon.undefined[:4]}"
    over = mon.changes["overrun"]
    if cfg.get("expect_overrun"):
        assert over and over[-1][1] == 1, f"overrun never rose: {over}"
        write_report(cfg, dict(overrun=True, frames=0))
        return
    assert not any(v for _, v in over), f"overrun rose at cycle {[c for c, v in over if v][:1]}"
    got_tokens = [b for b in mon.beats if b[3] and not b[2]]
    assert len(got_tokens) == tokens, f"{len(got_tokens)} reset tokens out, {tokens} in"
    asm = FrameAssembler(w, h)
    rows_first = []  # cycle of each output row's first beat
    x = 0
    for b in mon.beats:
        if b[3] and not b[2]:
            asm.push(*TOKEN)
            rows_first, x = [], 0  # the cut frame's rows are gone with it
            continue
        assert len(asm.frames) < len(pairs), f"an extra beat after {len(pairs)} frames: {b}"
        if x == 0:
            rows_first.append(b[0])
        x = (x + 1) % w
        asm.push(b[1], bool(b[2]), bool(b[3]))
    assert len(asm.frames) == len(pairs), f"{len(asm.frames)} frames out, {len(pairs)} in"
    assert asm.pixels_pending == 0, f"{asm.pixels_pending} pixels of a frame pending"
    if cfg.get("save"):
        # the codes as they came out (for a command that shows them), before the comparison can fail
        np.save(cfg["save"], np.stack([asm.frames[f] for f in range(len(pairs))]).astype(np.int64))
    compared = valid = 0
    for f, (left, right) in enumerate(pairs):
        exp = tb.expected(left, right)
        got = asm.frames[f]
        assert not (got == UNKNOWN).any(), f"frame {f}: undefined codes"
        bad = got.astype(np.int64) != exp
        if bad.any():
            ys, xs = np.nonzero(bad)
            detail = ", ".join(f"({x},{y}) got {int(got[y, x]):#x} want {int(exp[y, x]):#x}"
                               for y, x in zip(ys[:6], xs[:6]))
            raise AssertionError(f"frame {f}: {bad.sum()} of {bad.size} codes differ: {detail}")
        compared += exp.size
        valid += int((exp != model.INVALID).sum())
    # a row's outputs follow its last input pixel (the right beat): rows in order
    sent = tb.source.sent_cycles
    lat = []
    for f, start in enumerate(starts):
        for y in range(h):
            last_in = sent[start + 2 * (y * w + w - 1) + 1]
            lat.append(rows_first[f * h + y] - last_in)
    assert min(lat) > 0, f"a row came out before its last pixel went in ({min(lat)} clocks)"
    pix = [b for b in mon.beats if not (b[3] and not b[2])]
    write_report(cfg, dict(frames=len(pairs), pixels_compared=compared, valid_codes=valid,
                           row_latency_min=min(lat), row_latency_max=max(lat), spacing=sp,
                           first_in=sent[starts[0]], last_in=sent[-1], first_out=pix[0][0], last_out=pix[-1][0]))
