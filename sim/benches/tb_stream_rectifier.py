"""cocotb bench: the stream rectifier (line cache + rectifier) against :mod:`eyestereo.tools.models.rectifier`.

Two camera queues play frames with a camera's timing (:class:`eyestereo.tools.camera.CameraTiming` and the
pixel clock, in memory clocks; the right camera ``skew`` lines behind the left), never held back; the
rectified stereo stream is recorded beat by beat. Checked: every frame's beats (data, cam, eol, eof) equal to
the rectification model of that frame's two camera images; ``overrun`` never pulses (or, with
``expect_overrun``, that it pulses once in each frame rectified: a cache too small for the calibration is
caught); the block idle and nothing left over at the end.

Configuration: ``images`` (a list of ``"random:SEED"`` / ``"file:NAME"`` specs, one per frame, or one for all),
``frames``, ``timing`` (CameraTiming fields; default: CIF blanking at the calibration's camera size),
``pclk_mhz`` (default 17.73), ``skew`` (lines, may be fractional), ``expect_overrun``.
"""

from __future__ import annotations

import math

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.simtime import get_sim_time
from cocotb.triggers import ClockCycles, FallingEdge, First, ReadOnly, RisingEdge, Timer

from eyestereo.sim.lib.bench import make_frame, write_report
from eyestereo.sim.lib.fetch_memory import compare_stream
from eyestereo.sim.lib.rectify_bench import PERIOD, rectify_config, reset
from eyestereo.tools.camera import CIF_PCLK_HZ, DEFAULT_TIMING, CameraTiming
from eyestereo.tools.models import rectifier as model


class StreamRectifierTB:
    """Cameras in, stereo stream out, the overrun pulses counted."""

    def __init__(self, dut, cfg, cal):
        self.dut, self.cfg, self.cal = dut, cfg, cal
        w, h = cal.source_width, cal.source_height
        t = dict(h_blank=DEFAULT_TIMING.h_blank, v_sync=DEFAULT_TIMING.v_sync, v_back=DEFAULT_TIMING.v_back,
                 v_front=DEFAULT_TIMING.v_front)
        t.update(cfg.get("timing", {}))
        self.timing = CameraTiming(width=w, height=h, **t)
        pclk = float(cfg.get("pclk_mhz", CIF_PCLK_HZ / 1e6))
        self.word_ns = 2 * 1000.0 / pclk  # a pixel is two PCLK
        self.line_ns = (2 * w + self.timing.h_blank) * 1000.0 / pclk
        t_ = self.timing
        self.frame_ns = (t_.height + t_.v_sync + t_.v_back + t_.v_front) * self.line_ns
        self.first_ns = (t_.v_sync + t_.v_back) * self.line_ns
        self.beats: list[tuple[int, int, int, int]] = []
        self.beat_ns: list[float] = []
        self.overruns = 0
        self.frame_starts: list[float] = []

    async def camera(self, cam: int, frames: list[np.ndarray], offset_ns: float) -> None:
        """Play the frames on ``cam<cam>_*``, each word at the falling edge before its time."""
        d = self.dut
        data, valid, eol, eof = (getattr(d, f"cam{cam}_{f}") for f in ("data", "valid", "eol", "eof"))
        h, w = self.cal.source_height, self.cal.source_width
        t0 = get_sim_time(unit="ns")
        for f, img in enumerate(frames):
            base = t0 + offset_ns + f * self.frame_ns + self.first_ns
            if cam == 0:
                self.frame_starts.append(base)
            flat = img.astype(np.int64).ravel() | (128 << 8)  # Y, and a grey chroma
            for y in range(h):
                for x in range(w):
                    when = base + y * self.line_ns + x * self.word_ns
                    edge = math.ceil(when / PERIOD) * PERIOD - PERIOD / 2  # the falling edge before it
                    now = get_sim_time(unit="ns")
                    if edge > now:
                        await Timer(edge - now, unit="ns")
                    data.value = int(flat[y * w + x])
                    eol.value = int(x == w - 1)
                    eof.value = int(x == w - 1 and y == h - 1)
                    valid.value = 1
                    await Timer(PERIOD, unit="ns")
                    valid.value = 0

    async def monitor(self) -> None:
        """Record every beat and count the overrun pulses, woken by ``source_valid`` and ``overrun`` (not
        by every clock: the rectifier is busy for a whole camera frame, beating a fraction of its clocks)."""
        d = self.dut
        valid, ovr = d.source_valid, d.overrun
        while True:
            await First(RisingEdge(valid), RisingEdge(ovr))
            await ReadOnly()
            while True:
                v, o = int(valid.value), int(ovr.value)
                if o:
                    self.overruns += 1
                if v:
                    self.beats.append((int(d.source_data.value), int(d.source_cam.value),
                                       int(d.source_eol.value), int(d.source_eof.value)))
                    self.beat_ns.append(get_sim_time(unit="ns"))
                if not (v or o):
                    break
                await RisingEdge(d.clk)
                await ReadOnly()


@cocotb.test()
async def stream_rectifier_frames(dut):
    cfg, cal, frac = rectify_config()
    Clock(dut.clk, PERIOD, unit="ns").start()
    for c in (0, 1):
        for f in ("valid", "eol", "eof", "data"):
            getattr(dut, f"cam{c}_{f}").value = 0
    dut.start.value = 0
    dut.arm.value = 0
    dut.rst.value = 0
    tb = StreamRectifierTB(dut, cfg, cal)
    frames = int(cfg.get("frames", 1))
    specs = cfg.get("images", ["random:1"])
    specs = [specs] if isinstance(specs, str) else list(specs)
    w, h = cal.source_width, cal.source_height
    pairs = []
    for f in range(frames):
        s = specs[f % len(specs)]
        left = make_frame(s, w, h).astype(np.uint8)
        if s.startswith("random:"):  # the right camera's noise of its own
            right = make_frame(f"random:{int(s[7:]) + 1000}", w, h).astype(np.uint8)
        else:  # a scene: the right camera sees it 3 px to the left (a disparity of 3)
            right = np.roll(left, -3, axis=1)
        pairs.append((left, right))
    await reset(dut, dut.clk)
    await FallingEdge(dut.clk)
    dut.start.value = 1  # every frame the rectifier is free for
    cocotb.start_soon(tb.monitor())
    skew_ns = float(cfg.get("skew", 0)) * tb.line_ns
    left_cam = cocotb.start_soon(tb.camera(0, [p[0] for p in pairs], 0.0))
    right_cam = cocotb.start_soon(tb.camera(1, [p[1] for p in pairs], skew_ns))
    await left_cam
    await right_cam
    npx = cal.width * cal.height
    # the last frame's rows after the cameras' last line: at most the whole frame at 8 clocks a pair
    for _ in range(npx * 8 // 1000 + 50):
        if len(tb.beats) >= 2 * npx * frames and not int(dut.busy.value):
            break
        await ClockCycles(dut.clk, 1000)
    expect_overrun = bool(cfg.get("expect_overrun"))
    report = dict(width=cal.width, height=cal.height, frames=frames, beats=len(tb.beats), overruns=tb.overruns,
                  line_ns=tb.line_ns, frame_ns=tb.frame_ns)
    if expect_overrun:
        # every frame overran (a cache too small for the calibration): one pulse per frame, not per read
        done = len(tb.beats) // (2 * npx)
        report["frames_rectified"] = done
        assert tb.overruns > 0, "the cache was too small for the calibration, and overrun never pulsed"
        assert tb.overruns == done, f"overrun pulsed {tb.overruns} times in {done} rectified frames (once a frame)"
        report["bit_exact"] = None
        write_report(cfg, report)
        return
    assert tb.overruns == 0, f"overrun pulsed {tb.overruns} times"
    assert len(tb.beats) == 2 * npx * frames, f"{len(tb.beats)} beats of {2 * npx * frames}"
    assert not int(dut.busy.value), "busy still high after the last frame"
    got = np.asarray(tb.beats, dtype=np.int64).reshape(-1, 4)
    got = {k: got[:, i] for i, k in enumerate(("data", "cam", "eol", "eof"))}
    want = [model.stream(cal, left, right, frac) for left, right in pairs]
    want = {k: np.concatenate([m[k] for m in want]) for k in ("data", "cam", "eol", "eof")}
    compare_stream(got, want, cal.width, f"{frames} frame(s)")
    n = len(tb.beats)
    await ClockCycles(dut.clk, 2000)
    assert len(tb.beats) == n, f"{len(tb.beats) - n} beats after the last frame"
    # per frame: from the left camera's first word to the first and the last beat
    first, last = [], []
    for f in range(frames):
        b0 = tb.beat_ns[2 * npx * f]
        b1 = tb.beat_ns[2 * npx * (f + 1) - 1]
        first.append(b0 - tb.frame_starts[f])
        last.append(b1 - tb.frame_starts[f])
    report.update(bit_exact=True, first_beat_lines=[x / tb.line_ns for x in first],
                  last_beat_lines=[x / tb.line_ns for x in last],
                  end_after_last_line=[(x - (h - 1) * tb.line_ns) / tb.line_ns for x in last])
    write_report(cfg, report)
