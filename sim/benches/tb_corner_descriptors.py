"""cocotb bench: corner_descriptors against :func:`eyestereo.tools.models.corner_descriptors.corner_descriptors`.

Each frame (``frames``, one spec each: :func:`eyestereo.sim.lib.corner_frames.frame_case`, random flags or
Harris corners) is a pair of grey images and a pair of flag images. The pixels go in as a stereo stream (a
random idle clock between beats with probability ``idle``, ``frame_gap`` idle clocks between frames), the
flags as the same beats, each with the pixel beat ``lag_rows`` rows and ``lag_pixels`` pixels later (as
harris_stereo's flags come with a later input pixel) plus ``lag_clocks`` clocks (its pipeline, a crossing),
those left after the last pixel every ``tail_spacing`` clocks
(:func:`~eyestereo.sim.lib.corner_frames.stream_plan`).

Checked: the descriptor port's beats equal the model's (corners: camera, x, y, last, data; row ends: y and
eof), no beat has undefined bits, nothing comes after the last frame's last row end, ``late`` and ``lost``
are 0. With ``expect_late`` (flags far too late): the beats are the model's with whole corners left out,
every row end comes, and ``late`` counts the corners left out. Reported: corners, beats, the clocks from each
frame's last flag to its last row end.
"""

import cocotb
import numpy as np
from cocotb.triggers import ReadOnly, RisingEdge, Timer

from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.corner_frames import frame_case, play_plan, stream_plan
from eyestereo.sim.lib.queue import EdgeClock, drive_intervals, wait_until
from eyestereo.sim.lib.stream import UNKNOWN, resolved
from eyestereo.tools.models import corner_descriptors as model
from eyestereo.tools.models.async_fifo import ClockSpec

PERIOD_PS = 10_000
RESET_EDGES = (0, 4)
PORTS = ("data", "valid", "last", "cam", "x", "y", "row_end", "eof")


class CornerDescriptorsTB:
    """The clock, reset, the pixel and flag beats' player and the descriptor port's monitor."""

    def __init__(self, dut, cfg: dict):
        self.dut, self.cfg, self.p = dut, cfg, cfg["params"]
        self.clock = EdgeClock(dut.clk, ClockSpec(PERIOD_PS))
        self.rng = np.random.default_rng(cfg.get("seed", 0))
        self.sink = {n: getattr(dut, f"sink_{n}") for n in ("data", "valid", "cam", "eol", "eof")}
        self.flags = {n: getattr(dut, f"flags_{n}") for n in ("data", "valid", "cam", "eol", "eof")}
        self.source = {n: getattr(dut, f"source_{n}") for n in PORTS}
        self.beats: list[tuple] = []
        self.undefined: list[str] = []

    async def monitor(self) -> None:
        clk, src = self.dut.clk, self.source
        while True:
            await RisingEdge(clk)
            await ReadOnly()
            v = src["valid"].value
            if not v.is_resolvable:
                self.undefined.append(f"edge {self.clock.edge_now()}: valid is {v}")
                continue
            if not int(v):
                continue
            b = {n: resolved(src[n].value) for n in PORTS}
            edge = self.clock.edge_now()
            if b["row_end"]:
                beat = (1, b["eof"], 0, 0, b["y"], 0, 0)
                if UNKNOWN in (b["eof"], b["y"]):
                    self.undefined.append(f"edge {edge}: row end {b}")
            else:
                beat = (0, 0, b["cam"], b["x"], b["y"], b["last"], b["data"])
                if UNKNOWN in beat:
                    self.undefined.append(f"edge {edge}: beat {b} has undefined bits")
            self.beats.append(beat + (edge,))


@cocotb.test()
async def corner_descriptors_frames(dut):
    cfg = load_config()
    tb = CornerDescriptorsTB(dut, cfg)
    p = tb.p
    cases = [frame_case(spec, p["width"], p["height"]) for spec in cfg["frames"]]
    expected = [model.corner_descriptors(*c, cost=p["cost"], window=p["window"], border=p["border"]) for c in cases]
    for handles in (tb.sink, tb.flags):
        for h in handles.values():
            h.value = 0
    plan, last_flags = stream_plan(tb.sink, tb.flags, cases, RESET_EDGES[1] + 3, cfg, tb.rng)
    cocotb.start_soon(tb.clock.start())
    cocotb.start_soon(drive_intervals(dut.rst, tb.clock, [RESET_EDGES]))
    cocotb.start_soon(play_plan(tb.clock, plan))
    await wait_until(tb.clock.spec.time(RESET_EDGES[1]) + 1)  # the outputs are defined from the reset on
    cocotb.start_soon(tb.monitor())
    await wait_until(tb.clock.spec.time(max(plan) + 50 * p["width"]))
    await Timer(300 * PERIOD_PS, unit="ps")  # then nothing more may come
    assert not tb.undefined, f"undefined bits on the descriptor port: {tb.undefined[:4]}"
    late, lost = resolved(dut.late.value), resolved(dut.lost.value)
    got = [b[:7] for b in tb.beats]
    corners = sum(len(e["left_xy"]) + len(e["right_xy"]) for e in expected)
    if cfg.get("expect_late"):
        # flags after their windows left the buffers: those corners are skipped and counted, every row end
        # comes, and each corner that does come is the model's (same words): the beats are the model's with
        # whole corners left out
        want = [b for e in expected for b in e["beats"]]
        groups, cur = [], []
        for b in want:
            cur.append(b)
            if b[0] or b[5]:
                groups.append(cur)
                cur = []
        pos, skipped = 0, 0
        for g in groups:
            if got[pos:pos + len(g)] == g:
                pos += len(g)
            elif g[0][0]:
                raise AssertionError(f"row end {g[0]} missing at beat {pos}: got {got[pos:pos + 3]}")
            else:
                skipped += 1
        assert pos == len(got), f"beats {got[pos:pos + 3]} at {pos} are not the model's"
        assert (late, lost) == (skipped, 0), f"late {late}, lost {lost}: want {skipped} (the corners not sent), 0"
        write_report(cfg, dict(frames=len(cases), corners=corners, late=late, lost=lost, beats=len(got)))
        return
    assert (late, lost) == (0, 0), f"late {late}, lost {lost}: corners were dropped"
    pos, ends = 0, []
    for f, e in enumerate(expected):
        want = e["beats"]
        part = got[pos:pos + len(want)]
        if part != want:
            i = next((i for i, (a, b) in enumerate(zip(part, want)) if a != b), min(len(part), len(want)))
            raise AssertionError(f"frame {f}: {len(part)} beats out, the model's {len(want)}; first difference at "
                                 f"beat {i}: got {part[i] if i < len(part) else None}, want "
                                 f"{want[i] if i < len(want) else None} (fields {model.BEAT})")
        pos += len(want)
        ends.append(tb.beats[pos - 1][7])
    assert pos == len(got), f"{len(got) - pos} beats after the last frame's last row end: {got[pos:pos + 3]}"
    write_report(cfg, dict(frames=len(cases), beats=pos, late=late, lost=lost,
                           corners=[[len(e["left_xy"]), len(e["right_xy"])] for e in expected],
                           last_flag=last_flags, last_row_end=ends,
                           end_latency=[a - b for a, b in zip(ends, last_flags)]))
