"""cocotb bench: harris_stereo against the harris_mono model of each camera, bit for bit.

The stimulus: stereo frame pairs (left and right pixel of each (x, y) in turn) with beats at least
``share`` clocks apart (``duty`` 1.0: exactly every ``share`` clocks; lower: random extra idle clocks),
optionally a partial pair of frames cut by a reset token first (after a left beat, so the token breaks
a pixel pair), then the frames back to back. Checked: each camera's frames equal the mono model of that
camera's frame with that camera's k and thresholds on every specified pixel; no undefined bit on any
valid beat; left and right beats alternate; output beats at least ``share`` clocks apart; one token
out for the token in, before the frames; no pixel left over, no extra beat; the latency of every
specified flag equals :func:`eyestereo.hdl.harris.harris_stereo.latency`.
"""

from __future__ import annotations

import cocotb
import numpy as np
from cocotb.triggers import ClockCycles

from eyestereo.sim.lib.bench import load_config, make_frame, write_report
from eyestereo.sim.lib.harris_ports import split_cameras, start_run
from eyestereo.tools.constants import K_CODE_DEFAULT, NMS_DEFAULT, THRESHOLD_BLOCKS
from eyestereo.tools.models import harris_stereo as model
from eyestereo.tools.models.harris_mono import radius
from eyestereo.tools.models.stream_checker import frame_beats
from eyestereo.tools.stream import TOKEN


def stereo_pair(spec: str, w: int, h: int):
    """(left, right) for a spec: ``A|B`` two frame specs (see :func:`make_frame`), or ``npy:PATH`` (2, h, w)."""
    if spec.startswith("npy:"):
        pair = np.load(spec[4:])
        return pair[0].astype(np.int64), pair[1].astype(np.int64)
    a, _, b = spec.partition("|")
    return make_frame(a, w, h), make_frame(b or a, w, h)


@cocotb.test()
async def harris_stereo_frames(dut):
    cfg = load_config()
    p = cfg["params"]
    w, h = p["width"], p["height"]
    share, nms = p.get("share", 3), p.get("nms", NMS_DEFAULT)
    blocks = tuple(p.get("blocks", THRESHOLD_BLOCKS))
    n = blocks[0] * blocks[1]
    k = tuple(cfg.get("k", (K_CODE_DEFAULT, K_CODE_DEFAULT)))
    thr = cfg.get("thresholds", [[0] * n, [0] * n])
    source, monitor = await start_run(dut, share=share, k=k, thresholds=thr, duty=cfg.get("duty", 1.0),
                                      seed=cfg.get("seed", 0))

    pairs = [stereo_pair(s, w, h) for s in cfg.get("frames", ["random:1|random:2"])]
    beats = []
    tokens = 0
    if cfg.get("token_after") is not None:
        cut = frame_beats(make_frame("random:99", w, h), stereo=True, right=make_frame("random:98", w, h))
        t = int(cfg["token_after"]) | 1  # odd: the token follows a left beat and breaks the pair
        beats += cut[:min(t, len(cut) - 2)] + [TOKEN + (cfg.get("token_cam", 1),)]
        tokens = 1
    first_frame_beat = len(beats)
    for left, right in pairs:
        beats += frame_beats(left, stereo=True, right=right)
    source.send_beats(beats)
    total = len(beats)
    limit = int(total * share / cfg.get("duty", 1.0) * 1.6) + 40 * w * share + 4000
    waited = 0
    while source.queue and waited < limit:
        await ClockCycles(dut.clk, 256)
        waited += 256
    lat, ll, lp = __import__("eyestereo.hdl.harris.harris_stereo", fromlist=["latency"]).latency(nms, share)
    r = radius(nms)
    # the tail of the last frame: ll lines + lp pixels per camera at one beat every share clocks
    await ClockCycles(dut.clk, lat + 2 * (ll * w + lp) * share + 200)
    assert not source.queue, "the source still holds beats (timeout)"

    got = monitor.beats
    assert not monitor.undefined, f"undefined bits on valid beats: {monitor.undefined[:4]}"
    asm, order = split_cameras(got, w, h)
    assert order.count("token") == tokens, f"{order.count('token')} tokens out, {tokens} in"
    start = 0
    if tokens:
        for a in asm:
            assert a.events and a.events[0][0] == "token", "the reset token must come out before the first frame"
        start = next(i for i, b in enumerate(got) if b[3] and not b[2]) + 1
    pix = [b for b in got[start:] if not (b[3] and not b[2])]
    cams = [b[4] for b in pix]
    assert cams == [0, 1] * (len(pix) // 2) and len(pix) % 2 == 0, "left and right beats do not alternate"
    gaps = np.diff([b[0] for b in got])
    assert len(gaps) == 0 or gaps.min() >= share, f"output beats {gaps.min()} clocks apart, share is {share}"
    compared = 0
    for cam in (0, 1):
        assert len(asm[cam].frames) == len(pairs), f"camera {cam}: {len(asm[cam].frames)} frames out, {len(pairs)} in"
        assert asm[cam].pixels_pending == 0, f"camera {cam}: {asm[cam].pixels_pending} pixels of an unfinished frame"
    for i, (left, right) in enumerate(pairs):
        fl, fr, mask = model.harris_stereo(left, right, k, thr, blocks=blocks, nms=nms)
        for cam, exp in ((0, fl), (1, fr)):
            out = asm[cam].frames[i]
            bad = (out != exp) & mask
            if bad.any():
                ys, xs = np.nonzero(bad)
                raise AssertionError(f"frame {i} camera {cam}: {bad.sum()} of {mask.sum()} flags differ, first at "
                                     f"{list(zip(xs[:6].tolist(), ys[:6].tolist()))}")
            compared += int(mask.sum())
    assert compared > 0

    # Latency of every specified flag: its beat against the input beat of (x + lp, y + ll) of its camera.
    sent = source.sent_cycles[first_frame_beat:]
    outs = pix
    lats = set()
    per_frame = 2 * w * h
    for f in range(len(pairs)):
        for y in range(r, h - r):
            for x in range(r, w - r):
                for cam in (0, 1):
                    o = outs[f * per_frame + 2 * (y * w + x) + cam][0]
                    if y + ll >= h or x + lp >= w:
                        continue  # decided by the tail, after the frame's last input
                    i = sent[f * per_frame + 2 * ((y + ll) * w + x + lp) + cam]
                    lats.add(o - i)
    assert lats == {lat}, f"latencies {sorted(lats)[:6]}, expected {lat}"
    first_in = sent[0]
    last_out = outs[-1][0]
    write_report(cfg, dict(frames=len(pairs), pixels_compared=compared, beats_out=len(got), frame_beats_out=len(pix),
                           latency=lat, lead=[ll, lp],
                           first_in=first_in, last_out=last_out, beats_in=len(sent),
                           features=[int(asm[c].frames[i].astype(bool).sum()) for i in range(len(pairs))
                                     for c in (0, 1)]))
