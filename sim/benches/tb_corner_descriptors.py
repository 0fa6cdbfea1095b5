"""cocotb bench: corner_descriptors against :func:`eyestereo.tools.models.corner_descriptors.corner_descriptors`.

Each frame (``frames``, one spec each) is a pair of grey images and a pair of flag images:

* ``"random:SEED:P"``: random grey levels, each pixel of each camera a corner with probability P (dense
  flags: corners next to each other, many in one row, the queue under load);
* ``"pair:LEFT:RIGHT:N"``: two grey images (paths; their centres at the frame size) and the strongest N
  Harris corners of each (:func:`eyestereo.tools.matching.sparse.detect_corners`) as flags.

The pixels go in as a stereo stream (left and right beat of each pixel, a random idle clock between beats
with probability ``idle``, ``frame_gap`` idle clocks between frames). The flags are the same beats, each
coming with the pixel beat ``lag`` beats later (as harris_stereo's flags come with a later input pixel) plus
``lag_clocks`` clocks (its pipeline, a crossing); the flags left after the last pixel come every
``tail_spacing`` clocks. ``lag`` is given in rows and pixels: ``lag_rows`` x width + ``lag_pixels``.

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
from eyestereo.sim.lib.queue import EdgeClock, drive_intervals, wait_until
from eyestereo.sim.lib.stream import UNKNOWN, resolved
from eyestereo.tools.models import corner_descriptors as model
from eyestereo.tools.models.async_fifo import ClockSpec

PERIOD_PS = 10_000
RESET_EDGES = (0, 4)
PORTS = ("data", "valid", "last", "cam", "x", "y", "row_end", "eof")


def frame_case(spec: str, w: int, h: int):
    """(left image, right image, left flags, right flags) of one frame spec."""
    kind, *args = spec.split(":")
    if kind == "random":
        rng = np.random.default_rng(int(args[0]))
        p = float(args[1])
        imgs = rng.integers(0, 256, (2, h, w)).astype(np.uint8)
        flags = rng.random((2, h, w)) < p
        return imgs[0], imgs[1], flags[0], flags[1]
    if kind == "pair":
        import cv2

        from eyestereo.tools.matching.sparse import detect_corners

        imgs = []
        for path in args[:2]:
            img = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
            if img is None:
                raise FileNotFoundError(f"cannot read {path}")
            y0, x0 = (img.shape[0] - h) // 2, (img.shape[1] - w) // 2
            imgs.append(np.ascontiguousarray(img[y0:y0 + h, x0:x0 + w]))
        flags = []
        for img in imgs:
            f = np.zeros((h, w), bool)
            xy = np.asarray(detect_corners(img, count=int(args[2])), np.int64).reshape(-1, 2)
            f[xy[:, 1], xy[:, 0]] = True
            flags.append(f)
        return imgs[0], imgs[1], flags[0], flags[1]
    raise ValueError(f"unknown frame spec {spec!r}")


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

    def schedule(self, cases, start: int) -> tuple[dict, list[int]]:
        """{edge: {handle: value}} of both streams' beats, and the edge of each frame's last flag beat."""
        w, h = self.p["width"], self.p["height"]
        idle, gap = self.cfg.get("idle", 0.0), self.cfg.get("frame_gap", 0)
        pix, flg = [], []  # (values) in beat order
        edges = []
        edge = start
        for left, right, fl, fr in cases:
            for y in range(h):
                for x in range(w):
                    for cam, img, f in ((0, left, fl), (1, right, fr)):
                        e = dict(eol=int(x == w - 1), eof=int(x == w - 1 and y == h - 1), cam=cam)
                        pix.append(dict(data=int(img[y, x]), **e))
                        flg.append(dict(data=int(f[y, x]), **e))
                        edges.append(edge)
                        edge += 1 + int(self.rng.random() < idle)
            edge += gap
        lag = 2 * (self.cfg.get("lag_rows", 0) * w + self.cfg.get("lag_pixels", 0))
        lag_clocks, tail = self.cfg.get("lag_clocks", 3), self.cfg.get("tail_spacing", 1)
        flag_edges = [(edges[j + lag] if j + lag < len(edges) else edges[-1] + tail * (j + lag - len(edges) + 1))
                      + lag_clocks for j in range(len(flg))]
        plan: dict[int, dict] = {}
        for handles, beats, at in ((self.sink, pix, edges), (self.flags, flg, flag_edges)):
            for i, (values, e) in enumerate(zip(beats, at)):
                slot = plan.setdefault(e, {})
                slot[handles["valid"]] = 1
                for n, v in values.items():
                    slot[handles[n]] = v
                if i + 1 == len(at) or at[i + 1] != e + 1:
                    plan.setdefault(e + 1, {}).setdefault(handles["valid"], 0)
        frame_beats = 2 * w * h
        last_flags = [flag_edges[(f + 1) * frame_beats - 1] for f in range(len(cases))]
        return plan, last_flags

    async def play(self, plan: dict) -> None:
        for e in sorted(plan):
            await wait_until(self.clock.before(e))
            for handle, v in plan[e].items():
                handle.value = v

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
    plan, last_flags = tb.schedule(cases, RESET_EDGES[1] + 3)
    cocotb.start_soon(tb.clock.start())
    cocotb.start_soon(drive_intervals(dut.rst, tb.clock, [RESET_EDGES]))
    cocotb.start_soon(tb.play(plan))
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
