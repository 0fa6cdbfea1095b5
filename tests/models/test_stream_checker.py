"""The stream checker's model against an independent reference: the FrameAssembler of tools/stream.py.

The assembler (written for the benches' sinks) raises a ProtocolError at the first beat that breaks the
image-stream protocol; the checker must find the same fault at the same beat (a line that is too long
one beat earlier: at the line's last pixel, not after it), with the matching code, recover where its
docstring says, and in repair mode give a stream the assembler accepts whole, holding exactly the
frames that were sent intact.
"""

from __future__ import annotations

import numpy as np
import pytest

from eyestereo.tools.models import stream_checker as m
from eyestereo.tools.stream import TOKEN, FrameAssembler, ProtocolError

MONO_KINDS = ("long_line", "long_line_extra", "short_line", "short_last_line", "missing_eof", "early_eof")
STEREO_KINDS = ("cam_swap", "cam_missing", "pair_mismatch", "pair_eof")
CODE = m.KIND_CODES
#: The assembler's message for each code (it checks mono streams).
MESSAGE = {m.LONG_LINE: "eol missing", m.SHORT_LINE: "expected", m.MISSING_EOF: "ended without eof",
           m.EARLY_EOF: "eof on line"}


def good_frame(w, h, rng, stereo=False):
    left, right = rng.integers(0, 256, (2, h, w))
    return m.frame_beats(left, stereo=stereo, right=right), left, right


def reference_fault(beats, w, h):
    """(index, message) of the assembler's first ProtocolError on a mono stream, or None."""
    asm = FrameAssembler(w, h)
    for i, b in enumerate(beats):
        try:
            asm.push(*b[:3])
        except ProtocolError as e:
            return i, str(e)
    return None


@pytest.mark.parametrize("stereo", [False, True])
@pytest.mark.parametrize("repair", [False, True])
def test_good_streams_pass_unchanged(stereo, repair):
    rng = np.random.default_rng(1)
    for _ in range(40):
        w, h = (int(v) for v in rng.integers(1, 7, 2))
        beats = []
        for _ in range(int(rng.integers(1, 5))):
            f, _, _ = good_frame(w, h, rng, stereo)
            if rng.random() < 0.3:  # a frame cut by a reset token: legal
                cut = int(rng.integers(0, len(f)))
                beats += f[:cut] + [TOKEN + ((int(rng.integers(0, 2)),) if stereo else ())]
            beats += f
        steps = m.stream_checker(beats, w, h, stereo=stereo, repair=repair)
        assert not m.fault_positions(steps)
        assert all(not s.error and s.code == 0 for s in steps)
        norm = [tuple(b) + ((0,) if stereo and len(b) == 3 else ()) for b in beats]
        assert m.output_beats(steps) == norm


@pytest.mark.parametrize("kind", MONO_KINDS)
def test_mono_fault_found_where_the_reference_finds_it(kind):
    rng = np.random.default_rng(sorted(MONO_KINDS).index(kind))
    cases = 0
    for _ in range(60):
        w, h = (int(v) for v in rng.integers(2, 8, 2))
        good, _, _ = good_frame(w, h, rng)
        bad, at = m.faulty_frame(kind, w, h, rng)
        beats = good + bad
        steps = m.stream_checker(beats, w, h)
        first = m.fault_positions(steps)[0]
        assert first == (len(good) + at, CODE[kind])
        assert steps[first[0]].error and steps[first[0]].code == CODE[kind]
        assert not any(s.error for s in steps[:first[0]])
        ref = reference_fault(beats, w, h)
        assert ref is not None, "the reference must find the fault too"
        # The assembler finds a line that is too long only at its (width+1)-th pixel.
        assert ref[0] == first[0] + (1 if CODE[kind] == m.LONG_LINE else 0), (kind, ref, first)
        assert MESSAGE[CODE[kind]] in ref[1]
        cases += 1
    assert cases == 60


@pytest.mark.parametrize("kind", MONO_KINDS + STEREO_KINDS)
def test_stereo_fault_codes(kind):
    rng = np.random.default_rng(100 + (MONO_KINDS + STEREO_KINDS).index(kind))
    for _ in range(40):
        w, h = (int(v) for v in rng.integers(2, 7, 2))
        good, _, _ = good_frame(w, h, rng, stereo=True)
        bad, at = m.faulty_frame(kind, w, h, rng, stereo=True)
        steps = m.stream_checker(good + bad + good, w, h, stereo=True)
        assert m.fault_positions(steps)[0] == (len(good) + at, CODE[kind])
        if kind in MONO_KINDS:
            # Reference for the geometry faults: the left camera's beats alone, through the assembler.
            lefts = [(i, b) for i, b in enumerate(good + bad) if b[3] == 0]
            ref = reference_fault([b for _, b in lefts], w, h)
            idx = lefts[ref[0]][0]
            assert idx == len(good) + at + (2 if CODE[kind] == m.LONG_LINE else 0), (kind, idx, at)


@pytest.mark.parametrize("stereo", [False, True])
def test_repair_gives_whole_frames_only(stereo):
    """Random mixes of good frames, broken frames and tokens: the repaired stream assembles without a
    single protocol error, and its frames are exactly the good frames the checker was in sync for."""
    rng = np.random.default_rng(7 + stereo)
    kinds = MONO_KINDS + (STEREO_KINDS if stereo else ())
    for trial in range(30):
        w, h = (int(v) for v in rng.integers(2, 6, 2))
        beats, sent = [], []
        for _ in range(8):
            r = rng.random()
            if r < 0.45:
                b, left, right = good_frame(w, h, rng, stereo)
                beats += b
                sent.append((len(beats), left, right))
            elif r < 0.9:
                beats += m.faulty_frame(str(rng.choice(kinds)), w, h, rng, stereo=stereo)[0]
            else:
                beats.append(TOKEN + ((0,) if stereo else ()))
        steps = m.stream_checker(beats, w, h, stereo=stereo, repair=True)
        asm = assemble(m.output_beats(steps), w, h, stereo)  # raises on any protocol fault
        frames = [f.tolist() for f in asm.frames]
        for end, left, right in sent:
            s = steps[end - 1]
            if s.out is not None and s.fault == 0:  # the checker was in sync for this frame's end
                want = left * 256 + right if stereo else left
                assert want.tolist() in frames, f"trial {trial}: a good frame was dropped"
        assert len(frames) <= len(sent)


def assemble(out, w, h, stereo):
    """A FrameAssembler over the output; stereo: each (left, right) pair as one beat (left * 256 + right),
    after checking the interleaving (a token between the two beats of a pixel drops the left one)."""
    asm = FrameAssembler(w, h)
    pending = None
    for b in out:
        if not stereo:
            asm.push(*b[:3])
        elif b[2] and not b[1]:
            pending = None
            asm.push(*TOKEN)
        elif pending is None:
            assert b[3] == 0, f"a right beat where a left one is due: {b}"
            pending = b
        else:
            assert b[3] == 1 and b[1:3] == pending[1:3], f"right beat {b} does not match left {pending}"
            asm.push(pending[0] * 256 + b[0], b[1], b[2])
            pending = None
    return asm


def test_recovery_points():
    rng = np.random.default_rng(3)
    w, h = 4, 3
    good, _, _ = good_frame(w, h, rng)
    # A missing eof costs the frame after it: recovery at that frame's eof.
    bad, at = m.faulty_frame("missing_eof", w, h, rng)
    steps = m.stream_checker(bad + good + good, w, h, repair=True)
    assert m.fault_positions(steps) == [(at, m.MISSING_EOF)]
    assert all(s.out is None for s in steps[at + 1:len(bad) + len(good)])
    assert [s.out for s in steps[len(bad) + len(good):]] == good
    # ... unless a token comes first.
    steps = m.stream_checker(bad + [TOKEN] + good, w, h, repair=True)
    assert [s.out for s in steps[len(bad):]] == [TOKEN] + good
    assert steps[at].out == (bad[at][0], False, True)  # the faulty beat leaves as a token
    # A frame cut short (early eof) recovers at once: the next frame is checked and passed.
    bad, at = m.faulty_frame("early_eof", w, h, rng)
    steps = m.stream_checker(bad + good, w, h, repair=True)
    assert m.fault_positions(steps) == [(at, m.EARLY_EOF)]
    assert [s.out for s in steps[len(bad):]] == good
    # The code keeps the first fault; error stays high.
    bad2, _ = m.faulty_frame("short_line", w, h, rng)
    steps = m.stream_checker(bad + good + bad2 + good, w, h)
    assert [c for _, c in m.fault_positions(steps)] == [m.EARLY_EOF, m.SHORT_LINE]
    assert steps[-1].error and steps[-1].code == m.EARLY_EOF


def test_smallest_frame():
    # 1x1: every pixel is eol and eof; a beat without eof is a missing eof, without eol and eof too long.
    steps = m.stream_checker([(1, True, True), (2, True, False), (3, True, True), (4, False, False)], 1, 1)
    assert m.fault_positions(steps) == [(1, m.MISSING_EOF), (3, m.LONG_LINE)]


def test_fault_table_is_complete():
    assert set(m.FAULTS) == {m.OK, m.LONG_LINE, m.SHORT_LINE, m.MISSING_EOF, m.EARLY_EOF, m.STEREO}
    assert max(m.FAULTS) < 1 << m.CODE_BITS
    with pytest.raises(ValueError, match="unknown fault kind"):
        m.faulty_frame("nope", 4, 4, np.random.default_rng(0), stereo=True)
    with pytest.raises(ValueError, match="needs a stereo stream"):
        m.faulty_frame("cam_swap", 4, 4, np.random.default_rng(0))


def test_docstring_timing_example():
    """The timing diagram of hdl/streaming/stream_checker.py: a 3x2 frame whose second line is one pixel short."""
    beats = [(0, 0, 0), (1, 0, 0), (2, 1, 0), (3, 0, 0), (4, 1, 0), TOKEN, (5, 0, 0), (6, 0, 0)]
    steps = m.stream_checker(beats, 3, 2)
    assert m.fault_positions(steps) == [(4, m.SHORT_LINE)]
    assert [(s.error, s.code) for s in steps] == [(False, 0)] * 4 + [(True, 2)] * 4
    assert m.output_beats(steps) == beats
    repaired = m.stream_checker(beats, 3, 2, repair=True)
    assert repaired[4].out == (4, False, True)
    assert m.output_beats(repaired) == beats[:4] + [(4, False, True)] + beats[5:]
