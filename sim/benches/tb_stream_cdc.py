"""cocotb bench: stream_cdc, stereo (or mono) frames from one clock into another, against its model.

The write side gets the frames' beats at the rectifier's pace (a left and a right pixel every
``pair_clocks`` write clocks, with random extra gaps) or at any ``duty``; the two clocks have their own
period and phase (ps). Every beat that comes out is compared, edge for edge, with
:func:`eyestereo.tools.models.stream_cdc.stream_cdc`; every frame that comes out whole with the frame
sent (bit-exact: data, cam, eol, eof), and the dropped-frame counter with the model's.

Config: ``params`` (data_width, stereo, depth), ``wclk``/``rclk`` ([period, phase] ps), ``width``/``height``,
``frames``, ``pair_clocks`` or ``duty``, ``gap`` (clocks between frames), ``tokens`` ({frame: beats
before a reset token}), ``seed``.
"""

from __future__ import annotations

import random

import cocotb
import numpy as np
from cocotb.triggers import RisingEdge

from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.queue import BeatPlayer, EdgeClock, drive_intervals, wait_until
from eyestereo.tools.models.stream_cdc import ClockSpec, stream_cdc
from eyestereo.tools.models.stream_checker import frame_beats

INIT_RESET = (0, 3)


def stimulus(cfg: dict):
    """(beats [(data, eol, eof[, cam], edge, frame)], frames sent whole {frame: beats without edges})."""
    p = cfg["params"]
    stereo = bool(p.get("stereo", True))
    rng = np.random.default_rng(cfg.get("seed", 0))
    pick = random.Random(cfg.get("seed", 0))
    w, h = cfg["width"], cfg["height"]
    tokens = {int(k): int(v) for k, v in cfg.get("tokens", {}).items()}
    beats, whole = [], {}
    k = int(cfg.get("first_edge", 8))
    for f in range(cfg["frames"]):
        left = rng.integers(0, 1 << p["data_width"], (h, w))
        right = rng.integers(0, 1 << p["data_width"], (h, w))
        seq = frame_beats(left, stereo=stereo, right=right if stereo else None)
        if f in tokens:
            seq = seq[:tokens[f]] + [(0, False, True) + ((1,) if stereo else ())]
        else:
            whole[f] = seq
        for i, b in enumerate(seq):
            if "duty" in cfg:
                while pick.random() >= cfg["duty"]:
                    k += 1
            elif i % 2 == 0 and i:  # the rectifier: a pair every pair_clocks clocks, sometimes later
                k += cfg.get("pair_clocks", 4) - 2 + (pick.randrange(3) if pick.random() < 0.2 else 0)
            beats.append((*b, k, f))
            k += 1
        k += int(cfg.get("gap", 0))
    return beats, whole


class StereoPlayer(BeatPlayer):
    """BeatPlayer with ``cam`` (beats ``(data, eol, eof, cam, edge)``)."""

    def __init__(self, dut, prefix, clock):
        super().__init__(dut, prefix, clock)
        self.cam = getattr(dut, f"{prefix}_cam")
        self.cam.value = 0

    async def play(self, beats) -> None:
        last = None
        for data, eol, eof, cam, k in beats:
            if last is not None and k != last + 1:
                await wait_until(self.clock.before(last + 1))
                self.valid.value = 0
            await wait_until(self.clock.before(k))
            self.data.value, self.eol.value, self.eof.value, self.cam.value = int(data), int(eol), int(eof), int(cam)
            self.valid.value = 1
            last = k
        if last is not None:
            await wait_until(self.clock.before(last + 1))
            self.valid.value = 0


class StreamMonitor:
    """Records the beats of an image stream (``valid`` at a rising edge), with the edge index; wakes on
    ``valid`` while the stream is idle."""

    def __init__(self, dut, prefix: str, clock: EdgeClock, stereo: bool, ignore=()):
        names = ("data", "eol", "eof") + (("cam",) if stereo else ())
        self.sigs = [getattr(dut, f"{prefix}_{n}") for n in names]
        self.valid = getattr(dut, f"{prefix}_valid")
        self.clock, self.ignore = clock, list(ignore)
        self.beats: list[tuple] = []
        self.undefined: list[str] = []

    async def run(self):
        while True:
            await RisingEdge(self.clock.signal)
            v = self.valid.value
            k = self.clock.edge_now()
            if not v.is_resolvable:
                self.undefined.append(f"edge {k}: valid {v}")
            elif int(v) and not any(a <= k < b for a, b in self.ignore):
                vals = [s.value for s in self.sigs]
                if not all(x.is_resolvable for x in vals):
                    self.undefined.append(f"edge {k}: {[str(x) for x in vals]}")
                    continue
                d, eol, eof, *cam = (int(x) for x in vals)
                self.beats.append((d, bool(eol), bool(eof), *(bool(c) for c in cam), k))
            if not (self.valid.value.is_resolvable and int(self.valid.value)):
                await RisingEdge(self.valid)


def frames_out(beats, stereo: bool):
    """The beats (without edges) cut into frames: ('frame', beats) at a right-camera eof, ('token', beats)."""
    cur = []
    for b in beats:
        data, eol, eof = b[:3]
        if eof and not eol:
            yield "token", cur
            cur = []
            continue
        cur.append(tuple(b[:4] if stereo else b[:3]))
        if eof and (not stereo or b[3]):
            yield "frame", cur
            cur = []


@cocotb.test()
async def cdc_frames(dut):
    cfg = load_config()
    p = cfg["params"]
    stereo = bool(p.get("stereo", True))
    wclk, rclk = ClockSpec(*cfg["wclk"]), ClockSpec(*cfg["rclk"])
    beats, whole = stimulus(cfg)
    out, res = stream_cdc(beats, data_width=p["data_width"], stereo=stereo, depth=p["depth"], wclk=wclk,
                          rclk=rclk, wresets=[INIT_RESET], rresets=[INIT_RESET])
    wc, rc = EdgeClock(dut.wclk, wclk), EdgeClock(dut.rclk, rclk)
    n = 4 if stereo else 3
    player = StereoPlayer(dut, "sink", wc) if stereo else BeatPlayer(dut, "sink", wc)
    mon = StreamMonitor(dut, "source", rc, stereo, ignore=[INIT_RESET])
    for c in (wc, rc):
        cocotb.start_soon(c.start())
    cocotb.start_soon(drive_intervals(dut.wrst, wc, [INIT_RESET]))
    cocotb.start_soon(drive_intervals(dut.rrst, rc, [INIT_RESET]))
    cocotb.start_soon(player.play([b[:n] + (b[n],) for b in beats]))
    cocotb.start_soon(mon.run())
    end = max(wclk.time(beats[-1][n] + 4), rclk.time(max(res.last_edge, 0) + 1)) + 50 * rclk.period \
        + 20 * wclk.period
    await wait_until(end)

    assert not mon.undefined, f"undefined bits: {mon.undefined[:5]}"
    if mon.beats != out:
        i = next((i for i, (a, b) in enumerate(zip(mon.beats, out)) if a != b), min(len(mon.beats), len(out)))
        raise AssertionError(f"{len(mon.beats)} beats out, model {len(out)}; first difference at beat {i}: got "
                             f"{mon.beats[i] if i < len(mon.beats) else None}, want {out[i] if i < len(out) else None}")
    # bit-exact frames: every frame that came out whole is one that was sent, in order
    got = [seg for kind, seg in frames_out(mon.beats, stereo) if kind == "frame"]
    sent = [whole[f] for f in sorted(whole)]
    tokens = sum(1 for kind, _ in frames_out(mon.beats, stereo) if kind == "token")
    assert got == [s for s in sent if s in got], "a frame came out that was not sent (or out of order)"
    if res.dropped == 0:
        assert got == sent, f"{len(got)} of {len(sent)} frames came through whole"
    assert int(dut.dropped.value) == res.dropped, f"dropped {int(dut.dropped.value)}, model {res.dropped}"
    write_report(cfg, dict(beats=len(mon.beats), frames=len(got), sent=len(sent), dropped=res.dropped,
                           lost=res.lost, max_level=res.max_level, tokens=tokens))
