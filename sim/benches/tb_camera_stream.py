"""cocotb bench: camera_stream (camera bus -> image stream of 16-bit words) against its model, edge for edge.

A camera model plays a schedule (frames, blanking, polarities, byte order, faults, a start part-way); the
bench records every beat of ``source`` and of ``luma`` with its PCLK edge and compares them with
:func:`eyestereo.tools.models.camera_stream.camera_stream`: the same words, flags and edges, the same
reset tokens; the complete frames equal the camera's frames; ``luma`` carries their Y.

Config: ``params`` (width, height, order, vsync_active, href_active, luma), ``timing`` (blanking),
``pclk`` ([period, phase] ps), ``frames``, ``faults``, ``start``, ``preroll``, ``resets`` (PCLK edges).
"""

from __future__ import annotations

import cocotb
import numpy as np
from cocotb.triggers import RisingEdge

from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.camera import CameraModel
from eyestereo.sim.lib.camera_config import camera_schedule, resets_of, timing_of
from eyestereo.sim.lib.queue import EdgeClock, drive_intervals, wait_until
from eyestereo.tools.camera import run_length
from eyestereo.tools.models.async_fifo import ClockSpec
from eyestereo.tools.models.camera_stream import camera_stream, frames_of


class StreamRecorder:
    """Every valid beat of ``<prefix>_*`` (an image stream) with the edge that samples it."""

    def __init__(self, dut, prefix: str, clock: EdgeClock):
        self.valid = getattr(dut, f"{prefix}_valid")
        self.data = getattr(dut, f"{prefix}_data")
        self.eol = getattr(dut, f"{prefix}_eol")
        self.eof = getattr(dut, f"{prefix}_eof")
        self.clock = clock
        self.beats: list[tuple[int, bool, bool, int]] = []
        self.undefined: list[str] = []

    async def run(self):
        while True:
            await RisingEdge(self.clock.signal)
            v = self.valid.value
            if not v.is_resolvable:
                self.undefined.append(f"edge {self.clock.edge_now()}: valid {v}")
            elif int(v):
                raw = self.data.value
                if not (raw.is_resolvable and self.eol.value.is_resolvable and self.eof.value.is_resolvable):
                    self.undefined.append(f"edge {self.clock.edge_now()}: data {raw}")
                    d = -1
                else:
                    d = int(raw)
                self.beats.append((d, bool(int(self.eol.value)), bool(int(self.eof.value)), self.clock.edge_now()))
                continue
            await RisingEdge(self.valid)


@cocotb.test()
async def camera_stream_frames(dut):
    cfg = load_config()
    timing = timing_of(cfg)
    w, h = timing.width, timing.height
    frames, offset, runs = camera_schedule(cfg, timing)
    pclk = ClockSpec(*cfg["pclk"])
    resets = resets_of(cfg.get("resets"))
    model = camera_stream(runs, timing, resets=resets)

    cam = CameraModel(dut, "cam", timing, pclk.period, pclk.phase)
    clock = EdgeClock(dut.cam_pclk, pclk)
    rec = StreamRecorder(dut, "source", clock)
    luma = StreamRecorder(dut, "luma", clock) if cfg["params"].get("luma") else None
    cocotb.start_soon(cam.start_clock())
    cocotb.start_soon(drive_intervals(dut.rst, clock, resets))
    cocotb.start_soon(cam.play(runs))
    cocotb.start_soon(rec.run())
    if luma:
        cocotb.start_soon(luma.run())
    n = sum(run_length(r) for r in runs)
    await wait_until(pclk.time(n + 8))

    assert cam.done, "the camera model did not finish"
    assert not rec.undefined, f"undefined bits: {rec.undefined[:5]}"
    # The recorder sees a beat at the edge after the one that loads the output register. A token's data
    # bits are unspecified.
    want = [(0 if b.token else b.data, b.eol, b.eof, b.edge + 1) for b in model]
    rec.beats = [(0 if e and not l else d, l, e, k) for d, l, e, k in rec.beats]
    if rec.beats != want:
        i = next((i for i, (a, b) in enumerate(zip(rec.beats, want)) if a != b), min(len(rec.beats), len(want)))
        raise AssertionError(f"{len(rec.beats)} beats out, model {len(want)}; first difference at beat {i}: got "
                             f"{rec.beats[i] if i < len(rec.beats) else None}, "
                             f"want {want[i] if i < len(want) else None}")
    got_frames, ids, aborted = frames_of(model, w, h, resets=resets)
    for f, i in zip(got_frames, ids):
        assert np.array_equal(f, frames[i + offset]), f"frame {i + offset} differs from the camera's"
    if luma:
        assert not luma.undefined, f"luma: undefined bits: {luma.undefined[:5]}"
        luma.beats = [(0 if f and not e else d, e, f, k) for d, e, f, k in luma.beats]
        assert [(d & 0xFF, e, f, k) for d, e, f, k in rec.beats] == luma.beats, "luma differs from source's Y"
    write_report(cfg, dict(beats=len(rec.beats), frames=[i + offset for i in ids],
                           aborted=[[i + offset, k] for i, k in aborted], samples=cam.samples))
