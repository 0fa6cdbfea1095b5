"""cocotb bench: camera_interface / camera_pair (camera bus -> async FIFO -> system clock) against the model.

One or two camera models, each with its own PCLK (period and phase in ps), play frame schedules (from
images, with blanking, faults, a start part-way into a frame) while a reader takes the words in the
system clock, stalling in given windows; either domain can be reset at given edges. The bench runs the
model (:func:`eyestereo.tools.models.camera_interface.camera_interface`) on the same schedule, clocks,
stalls and resets, and checks:

* every word taken equals the model's, in order (data, eol, eof): complete frames, aborted prefixes and
  reset tokens alike, and that nothing more comes out;
* every complete frame equals the camera frame it came from (the stimulus, not the model);
* the dropped-frame counter equals the model's; no undefined bit on the port.

The config (JSON, from :func:`eyestereo.sim.lib.runner.run_bench`)::

    params:   the block's parameters (width, height, order, vsync_active, href_active, depth)
    timing:   h_blank, v_sync, v_back, v_front (camera blanking; the block's parameters give the rest)
    rclk:     [period_ps, phase_ps]
    rresets:  [[first, end], ...] read-clock edges with rrst high (after the initial reset)
    cameras:  one per camera port (camera_interface: 1, camera_pair: 2), each
              prefix (cam | cam_l | cam_r), pclk: [period_ps, phase_ps], frames: [spec, ...]
              (see :func:`eyestereo.sim.lib.camera.camera_frame`), faults: {frame: {lines, line_bytes}},
              start (first sample played), preroll (idle samples before it), wresets, stalls
"""

from __future__ import annotations

import time

import cocotb
import numpy as np

from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.camera import CameraModel
from eyestereo.sim.lib.camera_config import camera_schedule, resets_of, timing_of
from eyestereo.sim.lib.queue import EdgeClock, QueueMonitor, drive_intervals, wait_until
from eyestereo.tools.camera import CameraTiming, run_length
from eyestereo.tools.models.async_fifo import ClockSpec
from eyestereo.tools.models.camera_interface import camera_interface


class Side:
    """One camera: its model, its port names, the model's prediction."""

    def __init__(self, dut, cfg: dict, cam: dict, timing: CameraTiming, rclk: ClockSpec, rresets):
        self.name = cam["prefix"]
        suffix = self.name[len("cam"):]  # "" or "_l" / "_r"
        self.frames, self.offset, self.runs = camera_schedule(cam, timing)
        self.pclk = ClockSpec(*cam["pclk"])
        self.wresets = resets_of(cam.get("wresets"))
        self.stalls = [tuple(s) for s in cam.get("stalls", [])]
        t0 = time.time()
        self.model = camera_interface(self.runs, timing, depth=cfg["params"]["depth"], pclk=self.pclk, rclk=rclk,
                                      wresets=self.wresets, rresets=rresets, stalls=self.stalls)
        self.model_seconds = time.time() - t0
        self.camera = CameraModel(dut, self.name, timing, self.pclk.period, self.pclk.phase)
        self.clock = EdgeClock(getattr(dut, f"{self.name}_pclk"), self.pclk)
        self.wrst = getattr(dut, f"wrst{suffix}")
        self.dropped = getattr(dut, f"dropped{suffix}")
        self.source = f"source{suffix}"
        self.ready = getattr(dut, f"{self.source}_ready")

    def end_time(self, rclk: ClockSpec) -> int:
        n = sum(run_length(r) for r in self.runs)
        t_cam = self.pclk.time(n + 4)
        t_read = rclk.time(self.model.last_edge + 1) if self.model.last_edge >= 0 else 0
        return max(t_cam, t_read)


@cocotb.test()
async def camera_frames(dut):
    cfg = load_config()
    timing = timing_of(cfg)
    rclk = ClockSpec(*cfg["rclk"])
    rresets = resets_of(cfg.get("rresets"))
    sides = [Side(dut, cfg, cam, timing, rclk, rresets) for cam in cfg["cameras"]]
    rclock = EdgeClock(dut.rclk, rclk)
    wall = time.time()

    cocotb.start_soon(rclock.start())
    cocotb.start_soon(drive_intervals(dut.rrst, rclock, rresets))
    monitors = []
    for s in sides:
        # The reader: ready high except in the stall windows.
        cocotb.start_soon(drive_intervals(s.ready, rclock, s.stalls, active=0))
        cocotb.start_soon(drive_intervals(s.wrst, s.clock, s.wresets))
        cocotb.start_soon(s.camera.start_clock())
        cocotb.start_soon(s.camera.play(s.runs))
        mon = QueueMonitor(dut, s.source, rclock, ignore=rresets)
        cocotb.start_soon(mon.run())
        monitors.append(mon)

    end = max(s.end_time(rclk) for s in sides) + 200 * rclk.period + 20 * max(s.pclk.period for s in sides)
    await wait_until(end)
    wall = time.time() - wall

    report = dict(sides=[], sim_ps=end, wall_seconds=wall)
    for s, mon in zip(sides, monitors):
        assert s.camera.done, f"{s.name}: the camera model did not finish its schedule"
        assert not mon.undefined, f"{s.name}: undefined bits on the port: {mon.undefined[:5]}"
        got = [(d, e, f) for d, e, f, _ in mon.beats]
        want = [(d, e, f) for d, e, f, _ in s.model.beats]
        if got != want:
            i = next((i for i, (a, b) in enumerate(zip(got, want)) if a != b), min(len(got), len(want)))
            raise AssertionError(
                f"{s.name}: {len(got)} words out, model {len(want)}; first difference at word {i}: "
                f"got {got[i] if i < len(got) else None} (edge {mon.beats[i][3] if i < len(got) else None}), "
                f"want {want[i] if i < len(want) else None} (edge {s.model.beats[i][3] if i < len(want) else None}); "
                f"model frames {s.model.frame_ids}, aborted {s.model.aborted}, dropped {s.model.dropped}")
        same_edge = sum(a[3] == b[3] for a, b in zip(mon.beats, s.model.beats))
        # Latency of each word taken: from the bus sample that completed it (the pair's 4th byte for an
        # even pixel, the next sample for an odd one) to the read edge that moved it.
        lat = [rclk.time(b[3]) - s.pclk.time(e.wedge - 2)
               for b, e in zip(mon.beats, s.model.fifo.out) if not e.token]
        # The delivered frames are the camera's frames (checked against the stimulus, not the model).
        for f, fid in zip(s.model.frames, s.model.frame_ids):
            src = s.frames[fid + s.offset]
            assert np.array_equal(f, src), f"{s.name}: frame {fid + s.offset} came out different from the camera's"
        dropped = int(s.dropped.value)
        assert dropped == s.model.dropped, f"{s.name}: dropped counter {dropped}, model {s.model.dropped}"
        report["sides"].append(dict(
            name=s.name, words=len(got), frames=[fid + s.offset for fid in s.model.frame_ids],
            aborted=[[fid + s.offset, n] for fid, n in s.model.aborted],
            cut_by_rrst=[[fid + s.offset, n] for fid, n in s.model.cut_off], dropped=dropped,
            edges_equal=same_edge, max_level=s.model.fifo.max_level, lost=s.model.fifo.lost,
            monitor_wakes=mon.wakes, model_seconds=s.model_seconds,
            latency_ps=[min(lat), max(lat), sum(lat) / len(lat)] if lat else None,
            camera_samples=s.camera.samples))
    write_report(cfg, report)
