"""cocotb bench: async_fifo on its own, any stream into another clock, against its clock-accurate model.

The write side gets image-stream beats (random words of the configured width, frames back to back or with
idle clocks, reset tokens in the middle of frames) at edges drawn from a seeded generator; the reader
stalls in given windows; either side may be reset. The bench compares every word taken with
:func:`eyestereo.tools.models.async_fifo.async_fifo`, edge for edge, the complete frames with the words
sent, and the dropped-frame counter.

Config: ``params`` (data_width, depth), ``wclk``/``rclk`` ([period, phase] ps), ``width``/``height``
(frame geometry of the stimulus), ``frames`` (count), ``duty`` (fraction of write edges with a beat),
``seed``, ``tokens`` ({frame: words before the token}: that frame is cut and a token sent),
``stalls``, ``wresets``, ``rresets`` (edge intervals).
"""

from __future__ import annotations

import random

import cocotb
import numpy as np

from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.sim.lib.queue import BeatPlayer, EdgeClock, QueueMonitor, drive_intervals, wait_until
from eyestereo.tools.models.async_fifo import ClockSpec, async_fifo

INIT_RESET = (0, 3)


def stimulus(cfg: dict):
    """(beats [(data, eol, eof, edge, frame)], frames sent whole {frame: array})."""
    rng = np.random.default_rng(cfg.get("seed", 0))
    pick = random.Random(cfg.get("seed", 0))
    dw = cfg["params"]["data_width"]
    w, h = cfg["width"], cfg["height"]
    duty = float(cfg.get("duty", 1.0))
    tokens = {int(k): int(v) for k, v in cfg.get("tokens", {}).items()}
    beats, whole = [], {}
    k = int(cfg.get("first_edge", 8))
    for f in range(cfg["frames"]):
        words = rng.integers(0, 1 << dw, (h, w), dtype=np.int64)
        flat = words.reshape(-1).tolist()
        n = tokens.get(f, w * h)
        seq = [(flat[i], (i % w) == w - 1, i == w * h - 1) for i in range(n)]
        if f in tokens:
            seq.append((0, False, True))
        else:
            whole[f] = words
        for d, e, eof in seq:
            while duty < 1.0 and pick.random() >= duty:
                k += 1
            beats.append((d, e, eof, k, f))
            k += 1
        k += int(cfg.get("gap", 0))
    # The producer shares the write-domain reset: it sends nothing during a reset and drops the rest of
    # the frame it was sending (its next beat starts a frame), as camera_stream does.
    for a, b in sorted(tuple(r) for r in cfg.get("wresets", [])):
        hit = {f for _, _, _, e, f in beats if e >= a and any(e2 < a for _, _, _, e2, f2 in beats if f2 == f)}
        beats = [x for x in beats if not (a <= x[3] < b or (x[4] in hit and x[3] >= a))]
        for f in hit:
            whole.pop(f, None)
    return beats, whole


@cocotb.test()
async def fifo_frames(dut):
    cfg = load_config()
    p = cfg["params"]
    wclk, rclk = ClockSpec(*cfg["wclk"]), ClockSpec(*cfg["rclk"])
    wresets = [INIT_RESET] + [tuple(r) for r in cfg.get("wresets", [])]
    rresets = [INIT_RESET] + [tuple(r) for r in cfg.get("rresets", [])]
    stalls = [tuple(s) for s in cfg.get("stalls", [])]
    beats, whole = stimulus(cfg)
    model = async_fifo(beats, depth=p["depth"], wclk=wclk, rclk=rclk, wresets=wresets, rresets=rresets,
                       stalls=stalls)

    wc, rc = EdgeClock(dut.wclk, wclk), EdgeClock(dut.rclk, rclk)
    player = BeatPlayer(dut, "sink", wc)
    mon = QueueMonitor(dut, "source", rc, ignore=rresets)
    for c in (wc, rc):
        cocotb.start_soon(c.start())
    cocotb.start_soon(drive_intervals(dut.wrst, wc, wresets))
    cocotb.start_soon(drive_intervals(dut.rrst, rc, rresets))
    cocotb.start_soon(drive_intervals(dut.source_ready, rc, stalls, active=0))
    cocotb.start_soon(player.play([b[:4] for b in beats]))
    cocotb.start_soon(mon.run())
    end = max(wclk.time(beats[-1][3] + 4), rclk.time(max(model.last_edge, 0) + 1)) + 100 * rclk.period \
        + 20 * wclk.period
    await wait_until(end)

    assert not mon.undefined, f"undefined bits: {mon.undefined[:5]}"
    want = [(e.data, e.eol, e.eof, e.leave) for e in model.out]
    if mon.beats != want:
        i = next((i for i, (a, b) in enumerate(zip(mon.beats, want)) if a != b), min(len(mon.beats), len(want)))
        raise AssertionError(f"{len(mon.beats)} words out, model {len(want)}; first difference at word {i}: got "
                             f"{mon.beats[i] if i < len(mon.beats) else None}, "
                             f"want {want[i] if i < len(want) else None}")
    done = []
    w, h = cfg["width"], cfg["height"]
    for kind, tag, words in model.segments():
        if kind == "frame":
            assert np.array_equal(np.array(words).reshape(h, w), whole[tag]), f"frame {tag} differs from the one sent"
            done.append(tag)
    assert int(dut.dropped.value) == model.dropped, f"dropped {int(dut.dropped.value)}, model {model.dropped}"
    assert int(dut.empty.value) == 1, "the FIFO is not empty at the end"
    write_report(cfg, dict(words=len(mon.beats), frames=done, dropped=model.dropped, lost=model.lost,
                           max_level=model.max_level, tokens=sum(e.token for e in model.out)))
