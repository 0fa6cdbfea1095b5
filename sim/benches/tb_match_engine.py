"""cocotb bench: match_engine against :func:`eyestereo.tools.models.match_engine.match_engine`, word for word.

Each frame is a set of corners of both cameras with their descriptors (``frames``, one spec each):

* ``"texture:SEED:N"``: a random texture and its right view ``shift`` columns further with grey-level noise;
  N left corners at random, the right corners their matches (moved by the shift, some by a row, some
  missing) and as many random ones more; descriptors from the images
  (:func:`eyestereo.tools.models.feature_matcher.descriptors`).
* ``"random:SEED:N"``: N random corners per camera with random descriptors of few levels (many ties).
* ``"pair:LEFT:RIGHT:N"``: two grey images (paths; their centres at the frame size), the strongest N Harris
  corners of each
  (:func:`eyestereo.tools.matching.sparse.detect_corners`), their descriptors.

The corners go in row by row on the descriptor port (each camera's in raster order, the two cameras'
interleaved by column, random idle clocks between corners), a row every ``row_clocks`` clocks at the
earliest, each row closed by its row-end beat; ``ready`` of the list port is held low in random
stretches. Checked: every frame's words equal the model's (data, eol, eof), no word has undefined bits,
``dropped`` stays low (with ``expect_dropped``: it is high at the end; the overload tests), nothing comes
out after the last frame's trailer. ``allow_dropped``: a run whose ``dropped`` rose reports it and is not
compared (the pace study of sim/measure/bench_matcher.py). Reported: words, matches,
candidates, the clocks from each frame's last row end to its trailer.
"""

import cocotb
import numpy as np
from cocotb.triggers import Timer

from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.corner_frames import check_match_lists
from eyestereo.sim.lib.queue import EdgeClock, QueueMonitor, drive_intervals, random_stalls, wait_until
from eyestereo.sim.lib.stream import resolved
from eyestereo.tools.models import match_engine as model
from eyestereo.tools.models.async_fifo import ClockSpec
from eyestereo.tools.models.feature_matcher import descriptors

PERIOD_PS = 10_000
RESET_EDGES = (0, 4)


def raster(points: np.ndarray, w: int, h: int) -> np.ndarray:
    """The points inside the frame, sorted in raster order without repeats."""
    p = points[(points[:, 0] >= 0) & (points[:, 0] < w) & (points[:, 1] >= 0) & (points[:, 1] < h)]
    keys = np.unique(p[:, 1] * w + p[:, 0])
    return np.stack([keys % w, keys // w], axis=1).astype(np.int64)


def frame_case(spec: str, p: dict, shift: int):
    """(left corners, right corners, left descriptors, right descriptors) of one frame spec."""
    w, h, cost, window = p["width"], p["height"], p["cost"], p["window"]
    kind, *args = spec.split(":")
    if kind == "random":
        seed, n = int(args[0]), int(args[1])
        rng = np.random.default_rng(seed)
        fl = raster(np.stack([rng.integers(0, w, n), rng.integers(0, h, n)], axis=1), w, h)
        fr = raster(np.stack([rng.integers(0, w, n), rng.integers(0, h, n)], axis=1), w, h)
        size = window * window - (cost == "census")
        if cost == "sad":
            return fl, fr, rng.integers(0, 3, (len(fl), size)) * 100, rng.integers(0, 3, (len(fr), size)) * 100
        return fl, fr, rng.integers(0, 2, (len(fl), size)) == 1, rng.integers(0, 2, (len(fr), size)) == 1
    if kind == "texture":
        seed, n = int(args[0]), int(args[1])
        rng = np.random.default_rng(seed)
        tex = rng.integers(0, 200, (h, w + shift))
        left = tex[:, :w].astype(np.uint8)  # right[y, x - shift] == left[y, x] up to the noise
        right = np.clip(tex[:, shift:] + rng.integers(-8, 9, (h, w)), 0, 255).astype(np.uint8)
        fl = raster(np.stack([rng.integers(shift, w, n), rng.integers(0, h, n)], axis=1), w, h)
        keep = fl[rng.random(len(fl)) < 0.8]
        moved = keep - [shift, 0] + np.stack([np.zeros(len(keep), int), rng.integers(-1, 2, len(keep))], axis=1)
        extra = np.stack([rng.integers(0, w, n), rng.integers(0, h, n)], axis=1)
        fr = raster(np.concatenate([moved, extra]), w, h)
        return fl, fr, descriptors(left, fl, cost, window), descriptors(right, fr, cost, window)
    if kind == "pair":
        import cv2

        from eyestereo.tools.io import centre_crop
        from eyestereo.tools.matching.sparse import detect_corners

        lp, rp, n = args[0], args[1], int(args[2])
        imgs = [cv2.imread(f, cv2.IMREAD_GRAYSCALE) for f in (lp, rp)]
        if any(i is None for i in imgs):
            raise ValueError(f"cannot read the pair {lp}, {rp}")
        imgs = [centre_crop(i, w, h, f) for i, f in zip(imgs, (lp, rp))]
        fl, fr = (raster(np.asarray(detect_corners(i, count=n), np.int64), w, h) for i in imgs)
        return fl, fr, descriptors(imgs[0], fl, cost, window), descriptors(imgs[1], fr, cost, window)
    raise ValueError(f"unknown frame spec {spec!r}")


class MatchEngineTB:
    """The clock, reset, settings, the descriptor beats' player and the list's monitor around match_engine."""

    PORTS = ("data", "valid", "last", "cam", "x", "y", "row_end", "eof")

    def __init__(self, dut, cfg: dict):
        self.dut, self.cfg, self.p = dut, cfg, cfg["params"]
        self.clock = EdgeClock(dut.clk, ClockSpec(PERIOD_PS))
        self.settings = dict(limit=cfg["limit"], uniqueness=cfg.get("uniqueness", 0),
                             lr_check=cfg.get("lr_check", False))
        self.monitor = QueueMonitor(dut, "source", self.clock, ignore=[RESET_EDGES])
        self.handles = {n: getattr(dut, f"sink_{n}") for n in self.PORTS}
        self.rng = np.random.default_rng(cfg.get("seed", 0))

    def expected(self, case) -> dict:
        p = self.p
        return model.match_engine(*case, width=p["width"], cost=p["cost"], window=p["window"], d_min=p["d_min"],
                                  d_max=p["d_max"], rows=p["rows"], max_matches=p["max_matches"], **self.settings)

    def schedule(self, cases, start: int) -> tuple[list[tuple[int, dict]], list[int]]:
        """(edge, port values) of every beat of the frames, and the edge of each frame's last row end."""
        p = self.p
        row_clocks, gap = self.cfg.get("row_clocks", 64), self.cfg.get("gap", 2)
        beats, ends = [], []
        edge = start
        for fl, fr, a, b in cases:
            words = [model.pack_descriptors(d, p["cost"], p["window"]) for d in (a, b)]
            for y in range(p["height"]):
                row_start = edge
                items = [(int(x), 0, i) for i, (x, yy) in enumerate(fl) if yy == y]
                items += [(int(x), 1, i) for i, (x, yy) in enumerate(fr) if yy == y]
                items.sort()  # by column; each camera's stay in raster order
                for x, cam, i in items:
                    ws = words[cam][i]
                    for k, word in enumerate(ws):
                        beats.append((edge, dict(data=word, valid=1, last=int(k == len(ws) - 1), cam=cam, x=x, y=y,
                                                 row_end=0, eof=0)))
                        edge += 1
                    edge += int(self.rng.integers(0, gap + 1))
                edge = max(edge, row_start + row_clocks - 1)
                beats.append((edge, dict(data=0, valid=1, last=0, cam=0, x=0, y=y, row_end=1,
                                         eof=int(y == p["height"] - 1))))
                edge += 1
            ends.append(edge - 1)
            edge += self.cfg.get("frame_gap", 0)
        return beats, ends

    async def play(self, beats) -> None:
        idle = True
        for i, (edge, values) in enumerate(beats):
            await wait_until(self.clock.before(edge))
            for n, v in values.items():
                self.handles[n].value = v
            idle = i + 1 < len(beats) and beats[i + 1][0] != edge + 1
            if idle:
                await wait_until(self.clock.before(edge + 1))
                self.handles["valid"].value = 0
        if not idle:
            await wait_until(self.clock.before(beats[-1][0] + 1))
            self.handles["valid"].value = 0

    def stalls(self, until: int) -> list[tuple[int, int]]:
        """Random (first, end) edge intervals with ``ready`` low (config ``stall``: the share of edges)."""
        return random_stalls(self.rng, self.cfg.get("stall", 0.0), RESET_EDGES[1] + 2, until)


@cocotb.test()
async def match_engine_frames(dut):
    cfg = load_config()
    tb = MatchEngineTB(dut, cfg)
    cases = [frame_case(spec, tb.p, cfg.get("shift", 7)) for spec in cfg["frames"]]
    expected = [tb.expected(c) for c in cases]
    for n in tb.PORTS:
        tb.handles[n].value = 0
    for k, v in tb.settings.items():
        getattr(dut, k).value = int(v)
    beats, ends = tb.schedule(cases, RESET_EDGES[1] + 3)
    budget = cfg.get("budget", 4000)
    horizon = beats[-1][0] + budget * len(cases) + 64 * sum(len(c[0]) for c in cases)
    cocotb.start_soon(tb.clock.start())
    cocotb.start_soon(drive_intervals(dut.rst, tb.clock, [RESET_EDGES]))
    cocotb.start_soon(drive_intervals(dut.source_ready, tb.clock, tb.stalls(horizon), active=0))
    cocotb.start_soon(tb.play(beats))
    await wait_until(tb.clock.spec.time(RESET_EDGES[1]) + 1)  # the outputs are defined from the reset on
    cocotb.start_soon(tb.monitor.run())

    want_words = sum(len(e["words"]) for e in expected)
    mon = tb.monitor
    t = tb.clock.spec.time(beats[-1][0])
    while len(mon.beats) < want_words and t < tb.clock.spec.time(horizon):
        t += 500 * PERIOD_PS
        await wait_until(t)
    await Timer(300 * PERIOD_PS, unit="ps")  # then nothing more may come
    assert not mon.undefined, f"undefined bits on the list port: {mon.undefined[:4]}"
    if cfg.get("allow_dropped") and resolved(dut.dropped.value) == 1:
        # a pace study (sim/measure/bench_matcher.py): the rows came faster than the engine matches them
        write_report(cfg, dict(frames=len(cases), dropped=True, words=len(mon.beats)))
        return
    if cfg.get("expect_dropped"):
        # more than the engine can keep: the flag must say so (the lists are not the model's then)
        assert resolved(dut.dropped.value) == 1, "dropped stayed low, but the stores could not hold the corners"
        write_report(cfg, dict(frames=len(cases), dropped=True, words=len(mon.beats)))
        return
    assert resolved(dut.dropped.value) == 0, "dropped rose: a store, the event queue or the result table overflowed"
    got = [(d, eol, eof) for d, eol, eof, _ in mon.beats]
    if cfg.get("dump"):
        import json
        with open(cfg["dump"], "w") as fh:
            json.dump(dict(got=[w for w, _, _ in got], want=[[int(d) for d, _, _ in e["words"]] for e in expected]), fh)
    trailer_edges = check_match_lists(mon.beats, expected)
    pos = len(got)
    lat = [t - e for t, e in zip(trailer_edges, ends)]
    write_report(cfg, dict(frames=len(cases), words=pos, dropped=False, matches=[e["count"] for e in expected],
                           candidates=[e["candidates"] for e in expected],
                           corners=[[len(c[0]), len(c[1])] for c in cases], list_latency=lat,
                           last_row_end=ends, trailer_edge=trailer_edges))
