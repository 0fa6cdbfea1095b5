"""cocotb bench: median3 against :func:`eyestereo.tools.models.median3.median3`, bit for bit on every pixel.

Code maps (random with invalid codes, few levels full of ties, or a real disparity map) go in with idle
cycles (``duty``), optionally after a partial frame cut by a reset token, back to back. Checked: every
output frame equals the model's median map on every pixel, border pixels included; no output bit is
undefined; the token and exactly the frames that went in come out (before the token, the cut frame's
pixels whose windows were complete), nothing pending or extra after the last frame's tail; and each
output pixel outside a frame's tail comes :data:`eyestereo.hdl.dense.median3.LATENCY` clocks after its
input pixel (x + 1, y + 1), each tail pixel after the frame's last input beat.
"""

from pathlib import Path

import cocotb
import cv2
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge

from eyestereo.hdl.dense.median3 import LATENCY
from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.stream import UNKNOWN, BeatMonitor, BeatSource, IdleGenerator
from eyestereo.tools.io import centre_crop
from eyestereo.tools.models.dense_stereo import dense_stereo
from eyestereo.tools.models.median3 import median3
from eyestereo.tools.models.sgm import INVALID
from eyestereo.tools.models.stream_checker import frame_beats
from eyestereo.tools.stream import TOKEN, FrameAssembler

PERIOD_NS = 10
#: the crop of the stereo pair the real disparity map is computed on (its bottom-right corner is used:
#: the columns of the left image with all 16 disparities inside the right one)
DENSE_CROP = (96, 64)


def codes(spec: str, width: int, height: int) -> np.ndarray:
    """A code map: ``random:SEED`` (uniform 16-bit codes, a fifth of them INVALID), ``levels:SEED`` (codes
    of {0, 1, 2, 0xFFFE, INVALID}: mostly ties), ``dense:DIR`` (the bottom-right ``width`` x ``height``
    of the disparity codes, no median, of ``DIR``'s im3.png / im4.png, centre crop ``DENSE_CROP``, 16
    disparities) or ``npy:FILE`` (the bottom-right ``width`` x ``height`` of a code map saved with numpy: a
    full frame's, sim/measure/bench_dense.py)."""
    kind, _, arg = spec.partition(":")
    if kind == "random":
        rng = np.random.default_rng(int(arg))
        m = rng.integers(0, 1 << 16, (height, width), dtype=np.int64)
        m[rng.random((height, width)) < 0.2] = INVALID
        return m
    if kind == "levels":
        rng = np.random.default_rng(int(arg))
        return rng.choice(np.array([0, 1, 2, 0xFFFE, INVALID], np.int64), (height, width))
    if kind == "dense":
        grey = []
        for name in ("im3.png", "im4.png"):
            img = cv2.imread(str(Path(arg) / name), cv2.IMREAD_GRAYSCALE)
            if img is None:
                raise FileNotFoundError(f"cannot read {Path(arg) / name}")
            grey.append(centre_crop(img, *DENSE_CROP, name))
        full = dense_stereo(*grey, disparities=16, median=False)
        return full[-height:, -width:].astype(np.int64)
    if kind == "npy":
        m = np.load(arg)
        if m.ndim != 2 or m.shape[0] < height or m.shape[1] < width:
            raise ValueError(f"{arg}: a {m.shape} array holds no {height} x {width} code map")
        return m[-height:, -width:].astype(np.int64)
    raise ValueError(f"unknown code map {spec!r}")


class Median3TB:
    """Clock, reset, a beat source and monitor around ``median3``."""

    def __init__(self, dut, cfg: dict):
        self.dut, self.cfg = dut, cfg
        self.w, self.h = cfg["params"]["width"], cfg["params"]["height"]
        dut.rst.value = 1  # from the first clock: the block's flags are U until a reset
        Clock(dut.clk, PERIOD_NS, unit="ns").start()
        idle = IdleGenerator(cfg.get("duty", 1.0), cfg.get("seed", 0))
        self.source = BeatSource(dut, "sink", dut.clk, idle, period_ns=PERIOD_NS)
        self.monitor = None

    async def reset(self):
        """Ends the reset after three clocks and starts the monitor."""
        await ClockCycles(self.dut.clk, 3)
        self.dut.rst.value = 0
        await RisingEdge(self.dut.clk)
        self.monitor = BeatMonitor(self.dut, "source", self.dut.clk, period_ns=PERIOD_NS)

    def latencies(self, starts: list[int], outputs: list[list[tuple]]) -> int:
        """Assert each output's clock: ``LATENCY`` after input (x + 1, y + 1), or after the frame's last
        beat for the tail (the last line and pixel). Returns how many had the exact latency."""
        sent = self.source.sent_cycles
        npix = self.w * self.h
        lag = self.w + 1  # input pixels between an output pixel and the one completing its window
        exact = 0
        for f, first in enumerate(starts):
            end = sent[first + npix - 1]
            for i, beat in enumerate(outputs[f]):
                if i + lag >= npix:  # the tail: no input beat completes its window
                    assert beat[0] > end, f"frame {f}: tail pixel {i} before the frame's last beat"
                    continue
                clocks = beat[0] - sent[first + i + lag]
                assert clocks == LATENCY, (f"frame {f}, pixel ({i % self.w},{i // self.w}): out {clocks} "
                                           f"clocks after its input, want {LATENCY}")
                exact += 1
        return exact


@cocotb.test()
async def median3_frames(dut):
    tb = Median3TB(dut, load_config())
    cfg = tb.cfg
    await tb.reset()
    w, h = tb.w, tb.h
    maps = [codes(spec, w, h) for spec in cfg["frames"]]
    beats, tokens, cut = [], 0, None
    if cfg.get("token_after") is not None:
        cut = codes("random:97", w, h)
        beats += frame_beats(cut)[:cfg["token_after"]] + [TOKEN]
        tokens = 1
    starts = []
    for m in maps:
        starts.append(len(beats))
        beats += frame_beats(m)
    tb.source.send_beats(beats)
    while tb.source.queue:
        await ClockCycles(dut.clk, 64)
    # the last frame's tail (a line and a pixel, one per free clock), the pipeline, and a margin that
    # would show anything extra
    await ClockCycles(dut.clk, 2 * (w + 1) + 2 * LATENCY + 64)

    mon = tb.monitor
    assert not mon.undefined, f"undefined outputs: {mon.undefined[:4]}"
    out_tokens = [i for i, b in enumerate(mon.beats) if b[3] and not b[2]]
    assert len(out_tokens) == tokens, f"{len(out_tokens)} reset tokens out, {tokens} in"
    if tokens:
        # the cut frame's outputs before the token: those of its beats a line and a pixel after its
        # first, windows complete, so the model's pixels
        early = mon.beats[:out_tokens[0]]
        assert len(early) == max(0, cfg["token_after"] - (w + 1)), f"{len(early)} pixels before the token"
        want = median3(cut).ravel()[:len(early)]
        assert [b[1] for b in early] == want.tolist(), "the cut frame's pixels before the token differ"
    asm = FrameAssembler(w, h)
    outputs = [[] for _ in maps]
    for b in mon.beats[out_tokens[0] + 1 if tokens else 0:]:
        assert len(asm.frames) < len(maps), f"a beat after the {len(maps)} frames: {b}"
        outputs[len(asm.frames)].append(b)
        asm.push(b[1], bool(b[2]), bool(b[3]))
    assert len(asm.frames) == len(maps), f"{len(asm.frames)} frames out, {len(maps)} in"
    assert asm.pixels_pending == 0, f"{asm.pixels_pending} pixels of a frame pending"
    invalid = 0
    for f, m in enumerate(maps):
        got, want = asm.frames[f], median3(m)
        assert not (got == UNKNOWN).any(), f"frame {f}: undefined codes"
        wrong = [(int(x), int(y)) for y, x in np.argwhere(got != want)]
        assert not wrong, (f"frame {f}: {len(wrong)} of {want.size} codes differ, first: "
                           + ", ".join(f"({x},{y}) {int(got[y, x]):#x} for {int(want[y, x]):#x}" for x, y in wrong[:6]))
        invalid += int((want == INVALID).sum())
    exact = tb.latencies(starts, outputs)
    assert exact == len(maps) * (w * h - w - 1)
    write_report(cfg, dict(frames=len(maps), pixels_compared=len(maps) * w * h, invalid_out=invalid,
                           latency_checked=exact, latency=LATENCY, beats_out=len(mon.beats)))
