"""Bit-true model of :func:`eyestereo.hdl.streaming.stream_checker.stream_checker`: the image-stream protocol checker.

The checker follows the stream beat by beat with the position (x, y) the next pixel must have (and, for
stereo streams, which camera's beat is due) and classifies the first beat that breaks the protocol of
:mod:`eyestereo.hdl.interfaces.stream` into one of the fault codes below. A *beat* is a tuple ``(data, eol, eof)``
or ``(data, eol, eof, cam)``; idle cycles are not beats (they change nothing).

Recovery: after a fault the checker no longer knows where it is in the frame. It resumes checking at the
next reset token (the next beat is pixel (0, 0)) or after the next end-of-frame beat (``eof`` with
``eol``; stereo: the right camera's), whichever comes first; a fault on an end-of-frame beat (a frame
cut short) resumes right after that beat. ``error`` and ``code`` stay as they are until ``rst``:
``code`` is the first fault since the reset.

Repair (``repair=True``): the faulty beat leaves as a reset token (``eof`` high, ``eol`` low, data and
cam passed) and every beat until the checker has recovered is dropped, so the source carries only whole
frames and reset tokens.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

OK = 0
LONG_LINE = 1    # the line's last pixel (x = width-1) without eol: a line too long
SHORT_LINE = 2   # eol before x = width-1: a line too short
MISSING_EOF = 3  # the frame's last pixel (eol on line height-1) without eof: a frame too long
EARLY_EOF = 4    # eof on a line before height-1: a frame too short
STEREO = 5       # stereo: a beat of the wrong camera, or the two beats of a pixel disagree on eol/eof

#: One-line description of each fault code.
FAULTS = {
    OK: "no fault",
    LONG_LINE: "line too long: no eol on pixel width-1",
    SHORT_LINE: "line too short: eol before pixel width-1",
    MISSING_EOF: "frame too long: no eof on the last line's eol",
    EARLY_EOF: "frame too short: eof before the last line",
    STEREO: "stereo interleaving broken: wrong cam, or eol/eof differ between the two beats of a pixel",
}
CODE_BITS = 3


@dataclass(frozen=True)
class Step:
    """What the checker does with one input beat: the output beat (None: dropped) and the flags with it."""

    out: tuple | None
    error: bool
    code: int
    fault: int  # the fault found on this beat (0: none)


def classify(beat, x: int, y: int, phase: int, left: tuple, width: int, height: int, stereo: bool) -> int:
    """Fault code of a pixel beat (not a token) expected at (x, y); ``phase`` 1 = the right camera's beat."""
    _, eol, eof = beat[:3]
    cam = int(beat[3]) if len(beat) > 3 else 0
    if stereo and phase:
        return STEREO if (cam != 1 or (bool(eol), bool(eof)) != left) else OK
    if stereo and cam != 0:
        return STEREO
    if x != width - 1:
        return SHORT_LINE if eol else OK
    if not eol:
        return LONG_LINE
    if y != height - 1:
        return EARLY_EOF if eof else OK
    return OK if eof else MISSING_EOF


def stream_checker(beats, width: int, height: int, *, stereo: bool = False, repair: bool = False) -> list[Step]:
    """One :class:`Step` per input beat, from the reset state (position (0, 0), no error)."""
    x = y = phase = 0
    left = (False, False)
    sync = True
    error, code = False, OK
    steps = []
    for beat in beats:
        data, eol, eof = beat[0], bool(beat[1]), bool(beat[2])
        cam = int(beat[3]) if len(beat) > 3 else 0
        out = tuple(beat) if len(beat) > 3 or not stereo else (data, eol, eof, 0)
        fault = OK
        if eof and not eol:  # reset token: always legal, always resynchronises
            x = y = phase = 0
            sync = True
        elif sync:
            fault = classify(beat, x, y, phase, left, width, height, stereo)
            if fault == OK:
                if stereo and not phase:
                    phase, left = 1, (eol, eof)
                else:
                    phase = 0
                    if eol:
                        x, y = 0, (0 if eof else y + 1)
                    else:
                        x += 1
            else:
                if not error:
                    code = fault
                error = True
                sync = False
                if repair:
                    out = (data, False, True) + out[3:]
        elif repair:
            out = None
        # Out of sync (also on the faulty beat itself): an end-of-frame beat ends the broken frame.
        if not sync and eof and eol and (not stereo or cam == 1):
            x = y = phase = 0
            sync = True
        steps.append(Step(out, error, code, fault))
    return steps


def fault_positions(steps: list[Step]) -> list[tuple[int, int]]:
    """(beat index, code) of every fault the checker reports."""
    return [(i, s.fault) for i, s in enumerate(steps) if s.fault]


def output_beats(steps: list[Step]) -> list[tuple]:
    """The beats that leave the checker (dropped ones left out)."""
    return [s.out for s in steps if s.out is not None]


# ---------------------------------------------------------------------------------------------------
# Faulty streams for the bench and the tests.

#: The fault code each kind of broken frame (:func:`faulty_frame`) must produce.
KIND_CODES = dict(long_line=LONG_LINE, long_line_extra=LONG_LINE, short_line=SHORT_LINE,
                  short_last_line=SHORT_LINE, missing_eof=MISSING_EOF, early_eof=EARLY_EOF,
                  cam_swap=STEREO, cam_missing=STEREO, pair_mismatch=STEREO, pair_eof=STEREO)
FAULT_KINDS = tuple(KIND_CODES)


def frame_beats(frame: np.ndarray, *, stereo: bool = False, right: np.ndarray | None = None) -> list[tuple]:
    """Beats of one frame (stereo: left and right pixel of each (x, y) in turn, eol/eof on both)."""
    frame = np.asarray(frame)
    h, w = frame.shape
    beats = []
    for yy in range(h):
        for xx in range(w):
            eol = xx == w - 1
            eof = eol and yy == h - 1
            if stereo:
                beats.append((int(frame[yy, xx]), eol, eof, 0))
                beats.append((int(right[yy, xx]), eol, eof, 1))
            else:
                beats.append((int(frame[yy, xx]), eol, eof))
    return beats


def faulty_frame(kind: str, width: int, height: int, rng: np.random.Generator, *, bits: int = 8,
                 stereo: bool = False) -> tuple[list[tuple], int]:
    """(beats of one frame broken by ``kind``, index of the beat where the fault must be found).

    Kinds (:data:`FAULT_KINDS`): ``long_line`` (a line's eol removed), ``long_line_extra`` (a line one
    pixel too long), ``short_line`` (a pixel of a line removed), ``short_last_line`` (the last line one
    pixel short, so eol/eof come early), ``missing_eof`` (the frame's last beat without eof),
    ``early_eof`` (the last line(s) dropped, eof on an earlier line), stereo only: ``cam_swap`` (one beat
    with the other camera's cam), ``cam_missing`` (a right-camera beat left out), ``pair_mismatch`` (a
    right beat's eol differs from its left beat's), ``pair_eof`` (the right beat of the frame's last
    pixel without eof).
    """
    left = rng.integers(0, 1 << bits, (height, width))
    right = rng.integers(0, 1 << bits, (height, width))
    return inject_fault(frame_beats(left, stereo=stereo, right=right), kind, width, height, rng, stereo=stereo)


def inject_fault(beats: list[tuple], kind: str, width: int, height: int, rng: np.random.Generator, *,
                 stereo: bool = False) -> tuple[list[tuple], int]:
    """:func:`faulty_frame` for the beats of a given (whole, width x height) frame."""
    beats = list(beats)
    if len(beats) != width * height * (2 if stereo else 1):
        raise ValueError(f"inject_fault needs the beats of one whole {width}x{height} frame, got {len(beats)}")
    n = 2 if stereo else 1  # beats per pixel
    line = width * n

    def flags(b, eol=None, eof=None, cam=None):
        b = list(b)
        if eol is not None:
            b[1] = eol
        if eof is not None:
            b[2] = eof
        if cam is not None:
            b[3] = cam
        return tuple(b)

    if kind in ("long_line", "long_line_extra", "short_line") and height < 2 and kind != "short_line":
        raise ValueError(f"{kind} needs a frame of at least 2 lines")
    if kind == "long_line":
        j = int(rng.integers(0, height - 1))
        at = j * line + (width - 1) * n
        for k in range(n):
            beats[at + k] = flags(beats[at + k], eol=False)
        return beats, at
    if kind == "long_line_extra":
        j = int(rng.integers(0, height - 1))
        at = j * line + (width - 1) * n
        extra = [flags(beats[at + k]) for k in range(n)]
        for k in range(n):
            beats[at + k] = flags(beats[at + k], eol=False)
        beats[at + n:at + n] = extra
        return beats, at
    if kind == "short_line":
        if width < 2:
            raise ValueError("short_line needs width >= 2")
        j = int(rng.integers(0, height))
        xx = int(rng.integers(0, width - 1))  # this pixel goes
        at = j * line + xx * n
        del beats[at:at + n]
        return beats, j * line + (width - 2) * n  # the line's eol now comes on pixel width-2
    if kind == "short_last_line":
        if width < 2:
            raise ValueError("short_last_line needs width >= 2")
        at = (height - 1) * line + (width - 2) * n
        del beats[at:at + n]  # pixel width-2 goes: eol/eof on what is now pixel width-2
        return beats, at
    if kind == "missing_eof":
        at = len(beats) - n
        for k in range(n):
            beats[at + k] = flags(beats[at + k], eof=False)
        return beats, at
    if kind == "early_eof":
        if height < 2:
            raise ValueError("early_eof needs height >= 2")
        keep = int(rng.integers(1, height))  # lines kept
        beats = beats[:keep * line]
        for k in range(n):
            beats[-n + k] = flags(beats[-n + k], eof=True)
        return beats, keep * line - n
    if not stereo:
        raise ValueError(f"fault kind {kind!r} needs a stereo stream")
    pixels = len(beats) // 2
    i = int(rng.integers(0, pixels - 1 if kind == "cam_missing" and pixels > 1 else pixels))  # a pixel
    if kind == "cam_swap":
        k = int(rng.integers(0, 2))
        beats[2 * i + k] = flags(beats[2 * i + k], cam=1 - k)
        return beats, 2 * i + k
    if kind == "cam_missing":
        del beats[2 * i + 1]
        # the next beat is a left beat (cam 0) where the right one is due (the next frame's first, if the
        # frame has one pixel)
        return beats, 2 * i + 1
    if kind == "pair_mismatch":
        b = beats[2 * i + 1]
        beats[2 * i + 1] = flags(b, eol=not b[1], eof=False)
        return beats, 2 * i + 1
    if kind == "pair_eof":
        at = len(beats) - 1
        beats[at] = flags(beats[at], eof=False)
        return beats, at
    raise ValueError(f"unknown fault kind {kind!r}; kinds are {FAULT_KINDS}")
