"""Camera side in pure Python: YUV words and byte orders, bus schedules, the camera_stream and FIFO models.

References: the camera frames themselves (what a good frame must come out as), OpenCV's BT.601 YCrCb
conversion for the colour helper, and a fluid (rate-only) picture of the FIFO for the overflow boundary.
"""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from eyestereo.tools.camera import (ORDERS, WORD, CameraTiming, Fault, cut, frame_schedule, line_bytes,
                                    schedule_length, vsyncs_before, yuv_frame, yuv_from_bgr)
from eyestereo.tools.models.async_fifo import ClockSpec, async_fifo
from eyestereo.tools.models.camera_interface import AmbiguousSchedule, camera_interface
from eyestereo.tools.models.camera_stream import camera_stream, frames_of

SMALL = CameraTiming(width=8, height=4, h_blank=6, v_sync=1, v_back=1, v_front=1)
P18, R100 = ClockSpec(55556, 40000), ClockSpec(10000, 3000)


def frames(n, t=SMALL, seed=0):
    rng = np.random.default_rng(seed)
    w, h = t.width, t.height
    return [yuv_frame(rng.integers(0, 256, (h, w)), rng.integers(0, 256, (h, w // 2)),
                      rng.integers(0, 256, (h, w // 2))) for _ in range(n)]


# --- words and bytes ---------------------------------------------------------------------------------
def test_word_layout_is_the_interface_contract():
    assert WORD.width == 16 and WORD.bits("y") == (8, 0) and WORD.bits("c") == (16, 8)
    w = yuv_frame(np.array([[10, 11, 12, 13]]), u=np.array([[100, 102]]), v=np.array([[200, 202]]))
    assert w.tolist() == [[100 << 8 | 10, 200 << 8 | 11, 102 << 8 | 12, 202 << 8 | 13]]


@pytest.mark.parametrize("order", ORDERS)
def test_line_bytes_orders(order):
    w = yuv_frame(np.array([[1, 2, 3, 4]]), u=np.array([[5, 6]]), v=np.array([[7, 8]]))[0]
    pairs = [dict(Y=[1, 2], U=[5], V=[7]), dict(Y=[3, 4], U=[6], V=[8])]  # Y0 before Y1 in every order
    want = [pair[ch].pop(0) for pair in pairs for ch in order]
    assert line_bytes(w, order).tolist() == want


def test_full_resolution_chroma_is_averaged_per_pair():
    y = np.zeros((1, 4), int)
    u = np.array([[10, 13, 200, 201]])
    w = yuv_frame(y, u=u, v=7)
    c = WORD.unpack(w)["c"]
    assert c.tolist() == [[11, 7, 200, 7]]


def test_yuv_from_bgr_matches_opencv():
    rng = np.random.default_rng(3)
    bgr = rng.integers(0, 256, (6, 8, 3), dtype=np.uint8)
    ycc = cv2.cvtColor(bgr, cv2.COLOR_BGR2YCrCb).astype(int)
    f = WORD.unpack(yuv_from_bgr(bgr))
    assert np.array_equal(f["y"], ycc[..., 0])
    assert np.array_equal(f["c"][:, 0::2], (ycc[:, 0::2, 2] + ycc[:, 1::2, 2]) // 2)  # U = Cb
    assert np.array_equal(f["c"][:, 1::2], (ycc[:, 0::2, 1] + ycc[:, 1::2, 1]) // 2)  # V = Cr


@pytest.mark.parametrize("kw,match", [
    (dict(width=7), "even"), (dict(width=0), "even"), (dict(height=0), "height"), (dict(h_blank=0), "h_blank"),
    (dict(v_sync=0), "v_sync"), (dict(order="YYUV"), "order"), (dict(vsync_active=2), "0 or 1"),
    (dict(width=8.0), "must be an int"),
])
def test_timing_rejects(kw, match):
    with pytest.raises(ValueError, match=match):
        CameraTiming(**kw)


def test_default_timing_is_cif_at_50_fps():
    t = CameraTiming()
    assert (t.width, t.height, t.line_pclk, t.lines) == (352, 288, 896, 396)
    assert abs(t.fps(17.73e6) - 50.0) < 0.05
    assert abs(t.word_rate(17.73e6) - 5.07e6) < 0.01e6  # 9 M words/s while HREF is active, 5 on average


# --- schedules ---------------------------------------------------------------------------------------
def test_schedule_length_and_cut():
    fr = frames(3)
    runs = frame_schedule(fr, SMALL)
    assert schedule_length(runs) == 3 * SMALL.frame_pclk
    for start in (0, 1, 37, 100, SMALL.frame_pclk):
        c = cut(runs, start, preroll=5)
        assert schedule_length(c) == 3 * SMALL.frame_pclk - start + 5
    with pytest.raises(ValueError, match="frame 0 is 4x2"):
        frame_schedule([np.zeros((2, 4), int)], SMALL)
    with pytest.raises(ValueError, match="faults for frames"):
        frame_schedule(fr, SMALL, faults={5: Fault(lines=1)})


# --- camera_stream model -----------------------------------------------------------------------------
@pytest.mark.parametrize("order", ORDERS)
@pytest.mark.parametrize("pol", [(1, 1), (0, 0)])
def test_clean_schedule_gives_the_frames(order, pol):
    t = CameraTiming(width=8, height=4, h_blank=6, v_sync=1, v_back=1, v_front=1, order=order,
                     vsync_active=pol[0], href_active=pol[1])
    fr = frames(3, t)
    out, ids, aborted = frames_of(camera_stream(frame_schedule(fr, t), t), 8, 4)
    assert ids == [0, 1, 2] and aborted == []
    assert all(np.array_equal(a, b) for a, b in zip(out, fr))


def test_beats_come_every_other_clock_with_one_clock_latency():
    fr = frames(1)
    beats = camera_stream(frame_schedule(fr, SMALL), SMALL)
    first_byte = (SMALL.v_sync + SMALL.v_back) * SMALL.line_pclk
    assert [b.edge - first_byte for b in beats[:4]] == [4, 5, 8, 9]  # 4th byte at edge 3, word at edge 4
    # the line's last word comes with the first blanking sample (edge 16), when HREF is known to be down
    assert [b.edge - first_byte for b in beats[6:8]] == [16, 17]
    assert beats[7].eol and not any(b.eol for b in beats[:7])


@pytest.mark.parametrize("fault,aborted", [
    (Fault(line_bytes={0: 3}), []),  # broken before its first word: dropped without a token
    (Fault(line_bytes={0: 4}), [(0, 1)]),  # one word out, then the token
    (Fault(line_bytes={2: 15}), [(0, 22)]),  # two lines, then 6 words of line 2 (3 whole pairs)
    (Fault(line_bytes={3: 17}), [(0, 31)]),  # too long: the last word is not sent, the token is
    (Fault(lines=3), [(0, 24)]),  # VSYNC after three lines
    (Fault(lines=0), []),
])
def test_broken_frames_never_end_with_eof(fault, aborted):
    fr = frames(2)
    out, ids, ab = frames_of(camera_stream(frame_schedule(fr, SMALL, faults={0: fault}), SMALL), 8, 4)
    assert ids == [1] and ab == aborted
    assert np.array_equal(out[0], fr[1])


def test_mid_frame_start_waits_for_vsync():
    fr = frames(3)
    runs = frame_schedule(fr, SMALL)
    for start in range(1, SMALL.frame_pclk + 1, 7):
        ids = [i + vsyncs_before(runs, start) for i in frames_of(camera_stream(cut(runs, start), SMALL), 8, 4)[1]]
        # a frame whose VSYNC is (partly) still to come is taken; one whose lines have begun is not
        first = 0 if start < SMALL.v_sync * SMALL.line_pclk else 1
        if start >= SMALL.frame_pclk:
            first = 1 + (start - SMALL.frame_pclk >= SMALL.v_sync * SMALL.line_pclk)
        assert ids == list(range(first, 3)), start


def test_reset_forgets_the_frame():
    fr = frames(3)
    runs = frame_schedule(fr, SMALL)
    mid = SMALL.frame_pclk + SMALL.first_line_pclk + 30  # inside frame 1
    out, ids, ab = frames_of(camera_stream(runs, SMALL, resets=[(mid, mid + 2)]), 8, 4, resets=[(mid, mid + 2)])
    assert ids == [0, 2] and ab == []  # no token from the block itself: the FIFO is reset with it


# --- FIFO and camera_interface models ----------------------------------------------------------------
def run_ci(fr, **kw):
    kw = dict(dict(depth=16, pclk=P18, rclk=R100), **kw)
    return camera_interface(frame_schedule(fr, SMALL), SMALL, **kw)


@pytest.mark.parametrize("rclk", [ClockSpec(10000, 3000), ClockSpec(20000, 1), ClockSpec(37037, 5000),
                                  ClockSpec(60000, 777)])
def test_no_stall_no_drop_when_the_reader_keeps_up(rclk):
    fr = frames(3)
    r = run_ci(fr, rclk=rclk)
    assert r.frame_ids == [0, 1, 2] and r.dropped == 0 and r.fifo.lost == 0
    assert all(np.array_equal(a, b) for a, b in zip(r.frames, fr))


def test_a_slow_reader_drops_frames_and_counts_them():
    fr = frames(4)
    r = run_ci(fr, rclk=ClockSpec(400000, 0), depth=4)  # 2.5 MHz: slower than the camera's words
    assert r.dropped >= 1 and len(r.frames) + r.dropped == 4
    assert all(np.array_equal(f, fr[i]) for f, i in zip(r.frames, r.frame_ids))


def word_edges(fr):
    return [b.edge + 1 for b in camera_stream(frame_schedule(fr, SMALL), SMALL)]


@pytest.mark.parametrize("depth", [4, 8, 16])
def test_overflow_boundary_against_a_fluid_picture(depth):
    """A stall starting right after a frame's first word: words written while the reader waits fill the
    FIFO; the frame is dropped iff more than depth + 1 (the output register) arrive, within a word
    either way for the synchronisers."""
    fr = frames(2)
    edges = word_edges(fr)[:32]
    t_first = P18.time(edges[0])
    s0 = R100.first_after(t_first) + 4  # the first word is taken before the stall
    results = {}
    for n in range(depth - 2, depth + 5):
        # stall until just after word (1 + n) of the frame has been written
        t_end = P18.time(edges[n]) + 1
        s1 = R100.first_after(t_end)
        try:
            r = run_ci(fr, depth=depth, stalls=[(s0, s1)])
        except AmbiguousSchedule:
            continue
        results[n] = 0 in r.frame_ids
    assert results, "every stall was ambiguous"
    kept = [n for n, ok in results.items() if ok]
    lost = [n for n, ok in results.items() if not ok]
    assert kept and lost and max(kept) < min(lost)
    assert abs(min(lost) - (depth + 1)) <= 1, results


def test_overflow_aborts_with_a_token_and_the_next_frame_is_whole():
    fr = frames(3)
    first_line = SMALL.first_line_pclk + SMALL.frame_pclk  # frame 1's first byte
    s0 = R100.first_after(P18.time(first_line + 12))
    s1 = R100.first_after(P18.time(first_line + 3 * SMALL.line_pclk))
    r = run_ci(fr, depth=4, stalls=[(s0, s1)])
    assert r.frame_ids == [0, 2] and r.dropped == 1
    assert len(r.aborted) == 1 and r.aborted[0][0] == 1
    n = r.aborted[0][1]
    assert 0 < n < 32
    # the aborted words are the frame's first n words, in order
    flat = [b[0] for b in r.beats]
    start = 32  # after frame 0
    assert flat[start:start + n] == fr[1].reshape(-1)[:n].tolist()


def test_write_reset_mid_frame_is_counted_and_read_reset_skips_to_the_next_frame():
    fr = frames(3)
    mid = SMALL.frame_pclk + SMALL.first_line_pclk + 30
    r = run_ci(fr, wresets=[(mid, mid + 2)])
    assert r.frame_ids == [0, 2] and r.dropped == 1 and r.aborted and r.aborted[0][0] == 1
    t = P18.time(mid)
    rm = R100.first_after(t)
    r = run_ci(fr, rresets=[(rm, rm + 3)])
    assert r.frame_ids == [0, 2] and r.dropped == 0 and r.cut_off and r.cut_off[0][0] == 1


def test_ambiguous_schedules_are_refused():
    fr = frames(2)
    edges = word_edges(fr)
    # a stall ending exactly when the FIFO is about to overflow at a frame's last word is ambiguous for
    # some end edge near the boundary: the model must refuse at least one of them, never guess
    t_last = P18.time(edges[31])
    s0 = R100.first_after(P18.time(edges[31 - 18]))
    refused = 0
    for d in range(-30, 30):
        try:
            run_ci(fr, depth=16, stalls=[(s0, R100.first_after(t_last) + d)])
        except AmbiguousSchedule:
            refused += 1
    assert refused >= 1


def test_fifo_model_rejects_bad_intervals():
    with pytest.raises(ValueError, match="empty"):
        async_fifo([], depth=4, wclk=P18, rclk=R100, stalls=[(5, 5)])
    with pytest.raises(ValueError, match="period > 0"):
        ClockSpec(0)
