"""cocotb bench: feature_matcher against :func:`eyestereo.tools.models.feature_matcher.feature_matcher`, word for word.

Each frame (``frames``: :func:`eyestereo.sim.lib.corner_frames.frame_case`: random flags, a shifted texture
with its Harris corners, or a real pair's centre with its Harris corners) goes in as the rectified stereo
stream and its flag stream, the flags rows behind the pixels as harris_stereo's come
(:func:`~eyestereo.sim.lib.corner_frames.stream_plan`: ``idle``, ``frame_gap``, ``lag_rows``, ``lag_pixels``,
``lag_clocks``, ``tail_spacing``); the list port's ``ready`` is held low a share ``stall`` of the time in
random stretches. The model gets the corners of the flags inside the border
(:func:`eyestereo.tools.models.corner_descriptors.corners`) and the settings (``t_max`` or ``h_max``, ``uniqueness``,
``lr_check``); the block gets the model's ``limit``.

Checked: every frame's words equal the model's (data, eol, eof), no word has undefined bits, ``dropped``,
``late`` and ``lost`` stay 0, nothing comes after the last frame's trailer. Reported: corners, candidates,
matches, words, the clocks from each frame's last flag to its trailer, and the model's matches
(``matches_xy``: x, y, disparity, cost) for the accuracy figures.
"""

import cocotb
import numpy as np
from cocotb.triggers import Timer

from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.corner_frames import check_match_lists, frame_case, play_plan, stream_plan
from eyestereo.sim.lib.queue import EdgeClock, QueueMonitor, drive_intervals, random_stalls, wait_until
from eyestereo.sim.lib.stream import resolved
from eyestereo.tools.models.async_fifo import ClockSpec
from eyestereo.tools.models.corner_descriptors import corners
from eyestereo.tools.models.feature_matcher import feature_matcher

PERIOD_PS = 10_000
RESET_EDGES = (0, 4)


class FeatureMatcherTB:
    """The clock, reset, settings, the two streams' player and the list's monitor around feature_matcher."""

    def __init__(self, dut, cfg: dict):
        self.dut, self.cfg, self.p = dut, cfg, cfg["params"]
        self.clock = EdgeClock(dut.clk, ClockSpec(PERIOD_PS))
        self.rng = np.random.default_rng(cfg.get("seed", 0))
        self.sink = {n: getattr(dut, f"sink_{n}") for n in ("data", "valid", "cam", "eol", "eof")}
        self.flags = {n: getattr(dut, f"flags_{n}") for n in ("data", "valid", "cam", "eol", "eof")}
        self.monitor = QueueMonitor(dut, "source", self.clock, ignore=[RESET_EDGES])

    def expected(self, case) -> dict:
        p, c = self.p, self.cfg
        left, right, fl, fr = case
        return feature_matcher(left, right, corners(fl, p["border"]), corners(fr, p["border"]), window=p["window"],
                               cost=p["cost"], t_max=c.get("t_max", 11), h_max=c.get("h_max", 15), d_min=p["d_min"],
                               d_max=p["d_max"], rows=p["rows"], uniqueness=c.get("uniqueness", 0),
                               lr_check=c.get("lr_check", False), max_matches=p["max_matches"])

    def stalls(self, until: int) -> list[tuple[int, int]]:
        """Random (first, end) edge intervals with ``ready`` low (config ``stall``: the share of edges)."""
        return random_stalls(self.rng, self.cfg.get("stall", 0.0), RESET_EDGES[1] + 2, until)


@cocotb.test()
async def feature_matcher_frames(dut):
    cfg = load_config()
    tb = FeatureMatcherTB(dut, cfg)
    p = tb.p
    cases = [frame_case(spec, p["width"], p["height"]) for spec in cfg["frames"]]
    expected = [tb.expected(c) for c in cases]
    for handles in (tb.sink, tb.flags):
        for h in handles.values():
            h.value = 0
    dut.limit.value = int(expected[0]["limit"])
    dut.uniqueness.value = int(cfg.get("uniqueness", 0))
    dut.lr_check.value = int(bool(cfg.get("lr_check", False)))
    plan, last_flags = stream_plan(tb.sink, tb.flags, cases, RESET_EDGES[1] + 3, cfg, tb.rng)
    horizon = max(plan) + 4000 * len(cases) + 64 * sum(int(c[2].sum() + c[3].sum()) for c in cases)
    cocotb.start_soon(tb.clock.start())
    cocotb.start_soon(drive_intervals(dut.rst, tb.clock, [RESET_EDGES]))
    cocotb.start_soon(drive_intervals(dut.source_ready, tb.clock, tb.stalls(horizon), active=0))
    cocotb.start_soon(play_plan(tb.clock, plan))
    await wait_until(tb.clock.spec.time(RESET_EDGES[1]) + 1)  # the outputs are defined from the reset on
    cocotb.start_soon(tb.monitor.run())

    want_words = sum(len(e["words"]) for e in expected)
    mon = tb.monitor
    t = tb.clock.spec.time(max(plan))
    while len(mon.beats) < want_words and t < tb.clock.spec.time(horizon):
        t += 500 * PERIOD_PS
        await wait_until(t)
    await Timer(300 * PERIOD_PS, unit="ps")  # then nothing more may come
    assert not mon.undefined, f"undefined bits on the list port: {mon.undefined[:4]}"
    flags = {n: resolved(getattr(dut, n).value) for n in ("dropped", "late", "lost")}
    if flags != dict(dropped=0, late=0, lost=0):
        write_report(cfg, dict(frames=len(cases), flags=flags, words=len(mon.beats)))  # what a pace study reads
    assert flags == dict(dropped=0, late=0, lost=0), f"corners were dropped: {flags}"
    trailer_edges = check_match_lists(mon.beats, expected)
    pos = len(mon.beats)
    write_report(cfg, dict(frames=len(cases), words=pos, matches=[e["count"] for e in expected],
                           candidates=[e["candidates"] for e in expected],
                           corners=[[int(len(corners(c[2], p["border"]))), int(len(corners(c[3], p["border"])))]
                                    for c in cases],
                           last_flag=last_flags, trailer_edge=trailer_edges,
                           list_latency=[a - b for a, b in zip(trailer_edges, last_flags)],
                           matches_xy=[e["matches"].tolist() for e in expected],
                           left_index=[e["left_index"].tolist() for e in expected]))
