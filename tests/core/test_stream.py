"""Unit tests of eyestereo.tools.stream: frames <-> beats, the protocol checker, frame geometry checks.

Expected beat sequences are written out by hand or built by plain loops from the protocol's definition
in :mod:`eyestereo.hdl.interfaces.stream`, never by the code under test.
"""

from __future__ import annotations

import numpy as np
import pytest

from eyestereo.tools.stream import (
    TOKEN,
    FrameAssembler,
    ProtocolError,
    beats_to_frames,
    check_geometry,
    frame_to_beats,
)

SIZES = [(1, 1), (1, 5), (5, 1), (2, 3), (3, 2), (4, 4), (7, 13), (16, 9)]  # (height, width)


def random_frame(h: int, w: int, seed: int = 0, top: int = 256) -> np.ndarray:
    return np.random.default_rng(seed).integers(0, top, size=(h, w), dtype=np.int64)


def ramp(h: int, w: int) -> np.ndarray:
    """Pixel (x, y) holds 10 * y + x, so a beat's position can be read off its data."""
    return np.array([[10 * y + x for x in range(w)] for y in range(h)], dtype=np.int64)


# --------------------------------------------------------------------------------------------------
# frame_to_beats


def test_frame_to_beats_hand_written_2x3():
    frame = np.array([[1, 2, 3], [4, 5, 6]], dtype=np.uint8)
    assert frame_to_beats(frame) == [
        (1, False, False), (2, False, False), (3, True, False),
        (4, False, False), (5, False, False), (6, True, True),
    ]


@pytest.mark.parametrize("h,w", SIZES)
def test_frame_to_beats_flags_count_and_raster_order(h, w):
    frame = ramp(h, w)
    beats = frame_to_beats(frame)
    assert len(beats) == w * h
    i = 0
    for y in range(h):
        for x in range(w):
            data, eol, eof = beats[i]
            assert data == 10 * y + x, f"beat {i} is not pixel ({x}, {y})"
            assert eol == (x == w - 1), f"eol wrong at ({x}, {y})"
            assert eof == (x == w - 1 and y == h - 1), f"eof wrong at ({x}, {y})"
            i += 1
    assert sum(b[1] for b in beats) == h  # one eol per line
    assert sum(b[2] for b in beats) == 1  # one eof per frame


def test_frame_to_beats_yields_plain_python_types():
    beats = frame_to_beats(np.array([[7, 255]], dtype=np.uint8))
    for data, eol, eof in beats:
        assert type(data) is int
        assert type(eol) is bool and type(eof) is bool
    assert beats[1][0] == 255


@pytest.mark.parametrize(
    "bad",
    [
        pytest.param(np.arange(5), id="1-D"),
        pytest.param(np.zeros((2, 2, 2), dtype=np.int64), id="3-D"),
        pytest.param(np.int64(3), id="0-D"),
        pytest.param(np.zeros((0, 4), dtype=np.int64), id="empty-0-rows"),
        pytest.param(np.zeros((3, 0), dtype=np.int64), id="empty-0-cols"),
        pytest.param(np.zeros((2, 2), dtype=np.float64), id="float"),
        pytest.param(np.array([[0, 1], [-1, 2]], dtype=np.int64), id="negative"),
    ],
)
def test_frame_to_beats_rejects_bad_frames(bad):
    with pytest.raises(ValueError):
        frame_to_beats(bad)


# --------------------------------------------------------------------------------------------------
# Round trip


@pytest.mark.parametrize("h,w", SIZES)
def test_round_trip_single_frame(h, w):
    frame = random_frame(h, w, seed=h * 100 + w)
    frames = beats_to_frames(frame_to_beats(frame), w, h)
    assert len(frames) == 1
    np.testing.assert_array_equal(frames[0], frame)


@pytest.mark.parametrize("h,w", SIZES)
def test_round_trip_several_frames_back_to_back(h, w):
    originals = [random_frame(h, w, seed=s, top=1 << 18) for s in range(3)]
    beats = [b for f in originals for b in frame_to_beats(f)]
    frames = beats_to_frames(beats, w, h)
    assert len(frames) == 3
    for got, want in zip(frames, originals):
        np.testing.assert_array_equal(got, want)


def test_assembler_events_and_pending_count():
    asm = FrameAssembler(3, 2)
    beats = frame_to_beats(ramp(2, 3))
    for i, b in enumerate(beats[:-1]):
        asm.push(*b)
        assert asm.pixels_pending == i + 1
        assert asm.frames == []
    asm.push(*beats[-1])
    assert asm.pixels_pending == 0
    assert asm.events == [("frame", 0)]
    assert len(asm.frames) == 1


# --------------------------------------------------------------------------------------------------
# Reset tokens


def test_token_is_the_documented_beat():
    data, eol, eof = TOKEN
    assert eof and not eol


@pytest.mark.parametrize("cut", [1, 2, 3, 4, 5, 11])
def test_token_mid_frame_drops_partial_frame(cut):
    h, w = 3, 4
    first, second = ramp(h, w), ramp(h, w) + 100
    beats = frame_to_beats(first)[:cut] + [TOKEN] + frame_to_beats(second)
    asm = FrameAssembler(w, h)
    asm.push_all(beats)
    assert asm.events == [("token", cut), ("frame", 0)]
    assert len(asm.frames) == 1
    np.testing.assert_array_equal(asm.frames[0], second)
    assert asm.pixels_pending == 0
    # beats_to_frames agrees and does not complain about the aborted frame
    frames = beats_to_frames(beats, w, h)
    assert len(frames) == 1
    np.testing.assert_array_equal(frames[0], second)


def test_token_pending_count_resets_to_zero():
    asm = FrameAssembler(4, 3)
    asm.push_all(frame_to_beats(ramp(3, 4))[:6])
    assert asm.pixels_pending == 6
    asm.push(*TOKEN)
    assert asm.pixels_pending == 0


def test_token_between_frames_drops_nothing():
    h, w = 2, 3
    a, b = random_frame(h, w, seed=1), random_frame(h, w, seed=2)
    beats = [TOKEN] + frame_to_beats(a) + [TOKEN, TOKEN] + frame_to_beats(b)
    asm = FrameAssembler(w, h)
    asm.push_all(beats)
    assert asm.events == [("token", 0), ("frame", 0), ("token", 0), ("token", 0), ("frame", 1)]
    np.testing.assert_array_equal(asm.frames[0], a)
    np.testing.assert_array_equal(asm.frames[1], b)


def test_token_data_is_ignored():
    asm = FrameAssembler(2, 1)
    asm.push(123, False, True)  # a token with junk data still carries no pixel
    assert asm.events == [("token", 0)]
    asm.push_all(frame_to_beats(np.array([[5, 6]])))
    np.testing.assert_array_equal(asm.frames[0], [[5, 6]])


# --------------------------------------------------------------------------------------------------
# Protocol faults


def test_line_one_pixel_too_long_raises():
    h, w = 2, 3
    beats = frame_to_beats(ramp(h, w))
    # line 0 gets a fourth pixel; its eol moves to that pixel
    bad = [(0, False, False), (1, False, False), (2, False, False), (3, True, False)] + beats[3:]
    with pytest.raises(ProtocolError, match="longer|eol missing"):
        beats_to_frames(bad, w, h)


def test_line_one_pixel_short_raises():
    h, w = 2, 3
    bad = [(0, False, False), (1, True, False)] + frame_to_beats(ramp(h, w))[3:]
    with pytest.raises(ProtocolError, match="eol after 2 pixels"):
        beats_to_frames(bad, w, h)


def test_missing_eol_on_middle_line_raises():
    h, w = 3, 2
    beats = frame_to_beats(ramp(h, w))
    data, _, eof = beats[3]  # last pixel of line 1
    beats[3] = (data, False, eof)
    with pytest.raises(ProtocolError):
        beats_to_frames(beats, w, h)


FAULT_SIZES = [(1, 2), (2, 1), (1, 4), (4, 1), (2, 2), (2, 3), (3, 2), (3, 4)]  # (h, w), w*h >= 2


@pytest.mark.parametrize("nframes", [1, 2, 3])
@pytest.mark.parametrize("h,w", FAULT_SIZES)
def test_any_single_lost_beat_is_detected(h, w, nframes):
    """Dropping any one beat of a stream of whole frames must raise or leave pixels pending."""
    beats = [b for s in range(nframes) for b in frame_to_beats(random_frame(h, w, seed=s))]
    for i in range(len(beats)):
        lossy = beats[:i] + beats[i + 1:]
        asm = FrameAssembler(w, h)
        try:
            asm.push_all(lossy)
        except ProtocolError:
            pass
        else:
            assert asm.pixels_pending > 0, f"losing beat {i} of {len(beats)} went unnoticed"
        with pytest.raises(ProtocolError):
            beats_to_frames(lossy, w, h)


def test_eof_on_wrong_line_raises():
    h, w = 3, 2
    beats = frame_to_beats(ramp(h, w))
    beats[1] = (beats[1][0], True, True)  # eof already on line 0
    with pytest.raises(ProtocolError, match="eof on line 0"):
        beats_to_frames(beats, w, h)


def test_eof_on_second_to_last_line_raises():
    h, w = 3, 2
    beats = frame_to_beats(ramp(h, w))
    beats[3] = (beats[3][0], True, True)
    with pytest.raises(ProtocolError, match="eof on line 1"):
        beats_to_frames(beats, w, h)


def test_last_line_without_eof_raises():
    h, w = 3, 2
    beats = frame_to_beats(ramp(h, w))
    beats[-1] = (beats[-1][0], True, False)
    with pytest.raises(ProtocolError, match="without eof"):
        beats_to_frames(beats, w, h)


@pytest.mark.parametrize("keep", [1, 2, 3, 5])
def test_stream_ending_mid_frame_raises(keep):
    h, w = 2, 3
    beats = frame_to_beats(ramp(h, w))[:keep]
    with pytest.raises(ProtocolError, match="inside a frame"):
        beats_to_frames(beats, w, h)


def test_stream_ending_mid_second_frame_raises():
    h, w = 2, 2
    beats = frame_to_beats(ramp(h, w)) * 2
    with pytest.raises(ProtocolError, match="inside a frame"):
        beats_to_frames(beats[:-1], w, h)


def test_empty_stream_is_no_frames():
    assert beats_to_frames([], 3, 2) == []


def test_token_only_stream_is_no_frames():
    assert beats_to_frames([TOKEN, TOKEN], 3, 2) == []


def test_wrong_geometry_raises():
    beats = frame_to_beats(ramp(2, 3))
    with pytest.raises(ProtocolError):
        beats_to_frames(beats, 2, 3)  # transposed geometry
    with pytest.raises(ProtocolError):
        beats_to_frames(beats, 3, 3)  # one line too many expected


# --------------------------------------------------------------------------------------------------
# check_geometry


@pytest.mark.parametrize("w,h", [(1, 1), (352, 288), (4096, 4096), (1, 4096), (np.int64(5), np.int32(7))])
def test_check_geometry_accepts_ints_in_range(w, h):
    assert check_geometry(w, h) is None


def test_check_geometry_min_and_max_size_bounds():
    check_geometry(3, 3, min_size=3)
    check_geometry(100, 100, max_size=100)
    with pytest.raises(ValueError, match="width=2 is too small"):
        check_geometry(2, 3, min_size=3)
    with pytest.raises(ValueError, match="height=101 is too large"):
        check_geometry(100, 101, max_size=100)


@pytest.mark.parametrize(
    "value,what",
    [
        (0, "too small"),
        (-1, "too small"),
        (-4096, "too small"),
        (4097, "too large"),
        (10**9, "too large"),
        (3.0, "must be an int"),
        (3.5, "must be an int"),
        (True, "must be an int"),
        (False, "must be an int"),
        ("8", "must be an int"),
        (None, "must be an int"),
        (np.float64(8), "must be an int"),
        (np.bool_(True), "must be an int"),
    ],
)
@pytest.mark.parametrize("name", ["width", "height"])
def test_check_geometry_rejects_and_names_the_parameter(name, value, what):
    args = {"width": 8, "height": 8}
    args[name] = value
    with pytest.raises(ValueError) as info:
        check_geometry(**args)
    msg = str(info.value)
    assert name in msg, f"message does not name {name!r}: {msg}"
    assert what in msg, msg
    other = "height" if name == "width" else "width"
    assert other not in msg, f"message blames the wrong parameter: {msg}"
