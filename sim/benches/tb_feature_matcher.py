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
from eyestereo.sim.lib.corner_frames import frame_case, stream_plan
from eyestereo.sim.lib.queue import EdgeClock, QueueMonitor, drive_intervals, wait_until
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

    async def play(self, plan: dict) -> None:
        for e in sorted(plan):
            await wait_until(self.clock.before(e))
            for handle, v in plan[e].items():
                handle.value = v

    def stalls(self, until: int) -> list[tuple[int, int]]:
        """Random (first, end) edge intervals with ``ready`` low (config ``stall``: the share of edges)."""
        share = self.cfg.get("stall", 0.0)
        out, e = [], RESET_EDGES[1] + 2
        while share and e < until:
            length = int(self.rng.integers(1, 12))
            gap = max(1, int(length * (1 - share) / share * self.rng.uniform(0.5, 1.5)))
            e += gap
            out.append((e, e + length))
            e += length + 1
        return out


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
    cocotb.start_soon(tb.play(plan))
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
    got = [(d, eol, eof) for d, eol, eof, _ in mon.beats]
    pos, trailer_edges = 0, []
    for f, e in enumerate(expected):
        want = [(int(d), bool(a), bool(b)) for d, a, b in e["words"]]
        part = got[pos:pos + len(want)]
        if part != want:
            i = next((i for i, (a, b) in enumerate(zip(part, want)) if a != b), min(len(part), len(want)))
            raise AssertionError(f"frame {f}: {len(part)} words out, the model's {len(want)}; first difference at "
                                 f"word {i}: got {part[i] if i < len(part) else None}, want "
                                 f"{want[i] if i < len(want) else None} (model: {e['count']} matches, "
                                 f"{e['candidates']} candidates)")
        pos += len(want)
        trailer_edges.append(mon.beats[pos - 1][3])
    assert pos == len(got), f"{len(got) - pos} words after the last frame's trailer: {got[pos:pos + 3]}"
    write_report(cfg, dict(frames=len(cases), words=pos, matches=[e["count"] for e in expected],
                           candidates=[e["candidates"] for e in expected],
                           corners=[[int(len(corners(c[2], p["border"]))), int(len(corners(c[3], p["border"])))]
                                    for c in cases],
                           last_flag=last_flags, trailer_edge=trailer_edges,
                           list_latency=[a - b for a, b in zip(trailer_edges, last_flags)],
                           matches_xy=[e["matches"].tolist() for e in expected],
                           left_index=[e["left_index"].tolist() for e in expected]))
