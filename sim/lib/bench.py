"""The base test bench shared by the block benches: clock, reset, stream source and sink, checks.

A bench module subclasses :class:`StreamTB`, says how to compute the expected frames with the block's
bit-true model, and calls :func:`run_scenario` from a ``@cocotb.test()``.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import cv2
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, First, RisingEdge, Timer
from cocotb.utils import get_sim_time

from eyestereo.sim.lib.stream import (UNKNOWN, ClockedStreamSink, ClockedStreamSource, IdleGenerator, StreamSink,
                                  StreamSource)
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH
from eyestereo.tools.io import centre_crop
from eyestereo.tools.stream import frame_to_beats

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data"


def load_config() -> dict:
    return json.loads(os.environ["EYESTEREO_TB"])


def make_frame(spec: str, width: int, height: int, bits: int = 8) -> np.ndarray:
    """A stimulus frame of stream words.

    Images (8-bit): ``random:SEED``, ``ramp``, ``file:NAME`` (from tests/data, centre crop), ``pattern:SEED``
    and ``checker:SEED`` (the corner test patterns of :mod:`eyestereo.tools.testpattern`, blur 0.5). Random
    words of other widths: ``random:SEED`` uses ``bits``.
    Inputs for later stages, built with the bit-true models from an image spec after the colon:
    ``sobel:IMG`` (Sobel words), ``window:IMG`` (harris_window words), ``corner:K:IMG`` (cornerness
    words for k code K). Random inputs over a stage's full range: ``grad:SEED:LIM`` (Sobel words with
    codes in [-LIM, LIM)), ``rwindow:SEED`` (window words), ``rcorner:SEED:LO:HI`` (cornerness codes in
    [LO, HI]).
    """
    from eyestereo.tools.models import cornerness, harris_window, sobel

    kind, _, arg = spec.partition(":")
    if kind == "random":
        return np.random.default_rng(int(arg)).integers(0, 1 << bits, (height, width), dtype=np.int64)
    if kind == "ramp":
        y, x = np.mgrid[0:height, 0:width]
        return ((x * 7 + y * 13) % (1 << bits)).astype(np.int64)
    if kind == "file":
        img = cv2.imread(str(DATA / arg), cv2.IMREAD_GRAYSCALE)
        if img is None:
            raise FileNotFoundError(f"cannot read stimulus image {DATA / arg}")
        return centre_crop(img, width, height, arg).astype(np.int64)
    if kind in ("pattern", "checker"):
        from eyestereo.tools.testpattern import checkerboard_pattern, corner_pattern

        gen = corner_pattern if kind == "pattern" else checkerboard_pattern
        return gen(width, height, seed=int(arg), blur=0.5).image.astype(np.int64)
    if kind == "sobel":
        return sobel.pack(*sobel.sobel(make_frame(arg, width, height))[:2])
    if kind == "window":
        return harris_window.harris_window(make_frame(f"sobel:{arg}", width, height))[0]
    if kind == "corner":
        k, _, img = arg.partition(":")
        return cornerness.to_word(cornerness.cornerness(make_frame(f"window:{img}", width, height), int(k)))
    rng_seed, _, rest = arg.partition(":")
    rng = np.random.default_rng(int(rng_seed) if rng_seed else 0)
    if kind == "grad":
        lim = int(rest or 128)
        ix, iy = (rng.integers(-lim, lim, (height, width)) for _ in range(2))
        return sobel.pack(ix, iy)
    if kind == "rwindow":
        sq, xy = harris_window.SUM_SQ, harris_window.SUM_XY
        sxx, syy = (rng.integers(sq.lo, sq.hi + 1, (height, width)) for _ in range(2))
        return harris_window.pack(sxx, syy, rng.integers(xy.lo, xy.hi + 1, (height, width)))
    if kind == "rcorner":
        lo, _, hi = rest.partition(":")
        return cornerness.to_word(rng.integers(int(lo), int(hi) + 1, (height, width)))
    raise ValueError(f"unknown stimulus {spec!r}")


class StreamTB:
    """Clock, reset, source (with idle generator) and sink around a stream block."""

    period_ns = 10
    token_spec = "random:99"  # stimulus of the partial frame cut by the reset token

    def __init__(self, dut, cfg: dict, *, out_width: int, out_height: int):
        self.dut = dut
        self.cfg = cfg
        self.clk = dut.clk
        Clock(dut.clk, self.period_ns, unit="ns").start()
        # drivers="clocked": the per-clock drivers of before (make bench measures both in one run)
        self.clocked = cfg.get("drivers", "events") == "clocked"
        # drivers="hdl": a VHDL player and recorder around the block (eyestereo.sim.lib.hdl_drivers, GHDL)
        self.hdl = cfg.get("drivers", "events") == "hdl"
        idle = IdleGenerator(cfg.get("duty", 1.0), cfg.get("seed", 0))
        if self.hdl:
            from eyestereo.sim.lib.hdl_drivers import HdlStreamSink, HdlStreamSource

            self.source = HdlStreamSource(dut, dut.clk, idle)
            self.sink = HdlStreamSink(dut, dut.clk, out_width, out_height)
            return
        src, snk = (ClockedStreamSource, ClockedStreamSink) if self.clocked else (StreamSource, StreamSink)
        self.source = src(dut, "sink", dut.clk, idle)
        self.sink = snk(dut, "source", dut.clk, out_width, out_height)

    async def reset(self):
        self.dut.rst.value = 1
        await ClockCycles(self.clk, 3)
        self.dut.rst.value = 0
        self.sink.active = True
        await RisingEdge(self.clk)

    def make_input(self, spec: str, width: int, height: int) -> np.ndarray:
        """One input frame for a stimulus spec (see :func:`make_frame`)."""
        return make_frame(spec, width, height, self.cfg["params"].get("data_width", 8))

    async def configure(self) -> None:
        """Drive the block's control ports after reset (blocks with such ports override this)."""

    def expected(self, frame: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(expected output words, mask of the pixels whose data is specified) for one input frame."""
        raise NotImplementedError

    async def wait_frames(self, n: int, timeout_cycles: int):
        """Wait until ``n`` frames came out and the source is empty (or a protocol error, or the timeout).

        Python wakes only when a frame completes or the source runs empty, not on every clock.
        """
        if self.clocked:
            return await self._wait_frames_clocked(n, timeout_cycles)
        if self.hdl:
            from eyestereo.sim.lib.hdl_drivers import wait_frames_hdl

            return await wait_frames_hdl(self, n, timeout_cycles)
        sink, source = self.sink, self.source
        deadline = get_sim_time(unit="ns") + timeout_cycles * self.period_ns
        while not (len(sink.frames) >= n and source.idle_now) and sink.error is None:
            left = deadline - get_sim_time(unit="ns")
            if left <= 0:
                break
            sink.changed.clear()
            source.changed.clear()
            await First(sink.changed.wait(), source.changed.wait(), Timer(left, unit="ns"))
        sink.check()
        assert len(sink.frames) >= n, (
            f"timeout: {len(sink.frames)} of {n} frames after {timeout_cycles} cycles "
            f"({sink.asm.pixels_pending} pixels of a frame pending)")
        # Anything still coming out would be an extra beat; give the pipeline time to show it.
        await Timer(64 * self.period_ns, unit="ns")
        await RisingEdge(self.clk)
        sink.check()


    async def _wait_frames_clocked(self, n: int, timeout_cycles: int):
        for _ in range(timeout_cycles):
            await RisingEdge(self.clk)
            self.sink.check()
            if len(self.sink.frames) >= n and self.source.idle_now:
                break
        self.sink.check()
        assert len(self.sink.frames) >= n, (
            f"timeout: {len(self.sink.frames)} of {n} frames after {timeout_cycles} cycles "
            f"({self.sink.asm.pixels_pending} pixels of a frame pending)")
        await ClockCycles(self.clk, 64)
        self.sink.check()


async def write_thresholds(dut, clk, thresholds: dict[int, int], bits: int) -> None:
    """Write block thresholds through a ``thr_we/thr_addr/thr_data`` register port, one per clock."""
    for i, v in thresholds.items():
        dut.thr_we.value = 1
        dut.thr_addr.value = int(i)
        dut.thr_data.value = int(v) & ((1 << bits) - 1)
        await RisingEdge(clk)
    dut.thr_we.value = 0
    await RisingEdge(clk)


async def run_scenario(tb: StreamTB, frames: list[np.ndarray], *, token_after: int | None = None,
                       token_frame: np.ndarray | None = None) -> dict:
    """Send (optionally a partial frame and a reset token, then) ``frames`` back to back; check all.

    Checks: every output frame is rebuilt without protocol error and has the input's size; data equal
    to the model on every specified pixel; exactly one output frame per input frame and one token per
    token, nothing left pending, nothing extra.
    """
    await tb.reset()
    await tb.configure()
    tokens = 0
    if token_after is not None:
        tb.source.send_beats(frame_to_beats(token_frame)[:token_after])
        tb.source.send_token()
        tokens = 1
    for f in frames:
        tb.source.send_frame(f)
    total = sum(f.size for f in frames) + (token_after or 0)
    duty = tb.cfg.get("duty", 1.0)
    await tb.wait_frames(len(frames), timeout_cycles=int(total / duty * 1.5) + 20 * frames[0].shape[1] + 2000)

    sink = tb.sink
    assert len(sink.frames) == len(frames), f"{len(sink.frames)} frames out, {len(frames)} in"
    assert sink.asm.pixels_pending == 0, f"{sink.asm.pixels_pending} pixels of an unfinished frame came out"
    got_tokens = [e for e in sink.events if e[0] == "token"]
    assert len(got_tokens) == tokens, f"{len(got_tokens)} reset tokens out, {tokens} in"
    if tokens:
        assert sink.events[0][0] == "token", "the reset token must come out before the next frame"
    compared = 0
    for i, (f, got) in enumerate(zip(frames, sink.frames)):
        exp, mask = tb.expected(f)
        assert got.shape == exp.shape, f"frame {i}: {got.shape} out, {exp.shape} expected"
        # Border pixels are unspecified in value but must still be 0/1 on every valid beat (a real
        # FPGA never outputs U/X): check every pixel, not only the specified ones.
        unknown = got == UNKNOWN
        assert not unknown.any(), (f"frame {i}: {int(unknown.sum())} valid beats with X/U bits, first (y, x): "
                                   f"{np.argwhere(unknown)[:5].tolist()}")
        bad = (got != exp) & mask
        if bad.any():
            ys, xs = np.nonzero(bad)
            detail = ", ".join(f"({x},{y}) got {got[y, x]:#x} want {exp[y, x]:#x}" for y, x in zip(ys[:8], xs[:8]))
            raise AssertionError(f"frame {i}: {bad.sum()} of {mask.sum()} pixels differ: {detail}")
        compared += int(mask.sum())
    assert compared > 0, "no pixel was compared"
    assert not tb.source.queue, "source still holds beats"
    report = dict(frames=len(frames), pixels_compared=compared, beats_out=sink.beats,
                  cycles=tb.sink.cycle, sent=len(tb.source.sent_cycles))
    if tb.cfg.get("timing"):
        report["sent_cycles"] = list(tb.source.sent_cycles)
        report["received_cycles"] = list(tb.sink.received_cycles)
    if tb.cfg.get("dump"):
        np.save(tb.cfg["dump"], np.stack(sink.frames))
    return report


def write_report(cfg: dict, report: dict) -> None:
    if cfg.get("report"):
        Path(cfg["report"]).write_text(json.dumps(report, indent=2) + "\n")


def frame_params(cfg: dict) -> tuple[int, int, int]:
    """A bench config's frame width, height and data bits (the blocks' defaults where it gives none)."""
    p = cfg["params"]
    return p.get("width", FRAME_WIDTH), p.get("height", FRAME_HEIGHT), p.get("data_width", 8)


async def run_configured(dut, tb_class: type[StreamTB]) -> dict:
    """The body of a block bench: frames, duty, token and parameters from the runner's config."""
    import time

    cfg = load_config()
    # CPU time of the simulator process (the simulator and Python share it): on a shared machine the
    # wall-clock rate follows the load, the CPU-time rate much less (make bench reports both).
    cpu0 = time.process_time()
    w, h, _ = frame_params(cfg)
    tb = tb_class(dut, cfg, out_width=w, out_height=h)
    frames = [tb.make_input(spec, w, h) for spec in cfg.get("frames", ["random:1", "random:2"])]
    token_frame = tb.make_input(cfg.get("token_frame", tb.token_spec), w, h)
    report = await run_scenario(tb, frames, token_after=cfg.get("token_after"), token_frame=token_frame)
    report["cpu_seconds"] = time.process_time() - cpu0
    write_report(cfg, report)
    return report


def grey_frame(spec: str, width: int, height: int) -> np.ndarray:
    """A grey frame: ``random:SEED``, ``flat:V`` (every pixel V: ties give 0 bits) or ``image:PATH``
    (the centre ``width`` x ``height`` of an image file, converted to grey)."""
    kind, _, arg = spec.partition(":")
    if kind == "random":
        return np.random.default_rng(int(arg)).integers(0, 256, (height, width), dtype=np.int64)
    if kind == "flat":
        return np.full((height, width), int(arg), np.int64)
    if kind == "image":
        img = cv2.imread(arg, cv2.IMREAD_GRAYSCALE)
        if img is None:
            raise FileNotFoundError(f"cannot read stimulus image {arg}")
        return centre_crop(img, width, height, arg).astype(np.int64)
    raise ValueError(f"unknown stimulus {spec!r}")
