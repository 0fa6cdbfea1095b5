"""Bit-true model of :func:`eyestereo.hdl.camera.camera_stream.camera_stream`: camera bus schedule -> stream beats.

The model follows the block's rules sample by sample (runs of blanking are handled at once: they change
nothing after their first sample):

* VSYNC active: a frame in progress (a line begun, or lines received) that is not complete is aborted;
  the block arms for a new frame (line counter 0). HREF is ignored while VSYNC is active.
* HREF active, armed: bytes are counted; the 4th byte of each pixel pair (Y, U, Y, V in the timing's
  order) emits the even pixel's word, the next sample emits the odd pixel's word. A byte beyond
  ``2 * width`` aborts the frame (line too long).
* HREF inactive after a line: a line of exactly ``2 * width`` bytes ends with its last word, flagged
  ``eol`` (and ``eof`` on the frame's last line; the frame is then complete and the block waits for the
  next VSYNC); any other length aborts the frame (line too short).
* An aborted frame ends with a reset token (``eof`` without ``eol``; its data bits are unspecified, 0
  here) if any of its words came out, and with nothing otherwise. A frame whose VSYNC the block did not
  see (it came out of reset, or the camera was switched on, after it) is never started: no word of it
  comes out.
* Reset (``rst`` high at an edge): the block forgets everything and waits for the next VSYNC.

Sample ``j`` of the schedule is on the bus at PCLK edge ``j``; the block registers its inputs there, acts
at edge ``j + 1`` (its output register holds the beat from then on), and the FIFO behind it writes the
beat at edge ``j + 2``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from eyestereo.tools.camera import DEFAULT_TIMING, WORD, CameraTiming, run_length

__all__ = ["Beat", "camera_stream", "frames_of", "OUT_DELAY", "WRITE_DELAY"]

#: Edges from a sample on the bus to the block's output register holding the beat it produced.
OUT_DELAY = 1
#: Edges from a sample on the bus to the FIFO write edge of its beat (camera_interface).
WRITE_DELAY = 2

#: Position of (Y0, U, Y1, V) within a pixel pair's four bytes, per byte order.
POSITIONS = {"YUYV": (0, 1, 2, 3), "YVYU": (0, 3, 2, 1), "UYVY": (1, 0, 3, 2), "VYUY": (1, 2, 3, 0)}


@dataclass(frozen=True)
class Beat:
    """One output beat: a word (``eof and not eol`` is a reset token), the PCLK edge at which the block's
    output register takes it, and the index of the VSYNC pulse (in the schedule) of its frame."""

    data: int
    eol: bool
    eof: bool
    edge: int
    frame: int

    @property
    def token(self) -> bool:
        return self.eof and not self.eol


def _in(intervals, e: int) -> bool:
    return any(a <= e < b for a, b in intervals)


def camera_stream(runs, timing: CameraTiming = DEFAULT_TIMING, *, resets=()) -> list[Beat]:
    """Beats of camera_stream for a bus schedule (see :mod:`eyestereo.tools.camera`).

    ``resets``: ``[(first, end), ...]`` PCLK edge intervals in which ``rst`` is high (edges first..end-1).
    """
    w2 = 2 * timing.width
    h = timing.height
    iy0, iu, iy1, iv = POSITIONS[timing.order]
    resets = [(int(a), int(b)) for a, b in resets]
    beats: list[Beat] = []
    st = dict(armed=False, started=False, y=0, n=0, pend=0, frame=-1, cur=-1)
    buf = [0, 0, 0, 0]

    def emit(j, data, eol, eof):
        beats.append(Beat(int(data), eol, eof, j + OUT_DELAY, st["cur"]))

    def abort(j):
        if st["started"]:
            emit(j, 0, False, True)
        st.update(armed=False, started=False, n=0)

    def step(j, vs, hr, d):
        if _in(resets, j + OUT_DELAY):  # the block acts on sample j at edge j + 1
            st.update(armed=False, started=False, y=0, n=0)
            return
        if vs:
            if st["armed"] and (st["y"] > 0 or st["n"] > 0):
                abort(j)
            st.update(armed=True, started=False, y=0, n=0, cur=st["frame"])
        elif hr:
            if not st["armed"]:
                return
            n = st["n"]
            if n == w2:
                abort(j)
                return
            buf[n % 4] = int(d)
            if n % 4 == 3:
                emit(j, (buf[iu] << 8) | buf[iy0], False, False)
                st["pend"] = (buf[iv] << 8) | buf[iy1]
                st["started"] = True
            elif n % 4 == 0 and n > 0:
                emit(j, st["pend"], False, False)
            st["n"] = n + 1
        elif st["armed"] and st["n"] > 0:
            if st["n"] == w2:
                last = st["y"] == h - 1
                emit(j, st["pend"], True, last)
                st["y"] += 1
                st["n"] = 0
                if last:
                    st.update(armed=False, started=False)
            else:
                abort(j)

    j = 0
    for kind, p in runs:
        n = run_length((kind, p))
        if kind == "line":
            for k, d in enumerate(np.asarray(p).tolist()):
                step(j + k, False, True, d)
        else:
            if kind == "vsync":
                st["frame"] += 1
            # A run of blanking acts on its first sample only, and again after a reset ends inside it.
            points = {j} | {b - OUT_DELAY for a, b in resets if j < b - OUT_DELAY < j + n} \
                | {a - OUT_DELAY for a, b in resets if j < a - OUT_DELAY < j + n}
            for q in sorted(points):
                step(q, kind == "vsync", False, 0)
        j += n
    return beats


def frames_of(beats, width: int, height: int, resets=()) -> tuple[list[np.ndarray], list[int], list[tuple[int, int]]]:
    """(complete frames, their frame indices, [(frame index, words before its token), ...]) of beats.

    Words of a frame cut by a reset (an interval of ``resets`` beginning between two beats) are dropped.
    """
    frames, ids, aborted = [], [], []
    cur: list[int] = []
    prev = -1
    for b in beats:
        if any(prev < a <= b.edge for a, _ in resets):
            cur = []
        prev = b.edge
        if b.token:
            aborted.append((b.frame, len(cur)))
            cur = []
            continue
        cur.append(b.data)
        if b.eof:
            if len(cur) != width * height:
                raise AssertionError(f"model frame {b.frame} has {len(cur)} words")
            frames.append(np.array(cur, dtype=np.int64).reshape(height, width))
            ids.append(b.frame)
            cur = []
    return frames, ids, aborted


def luma(words: np.ndarray) -> np.ndarray:
    """The Y field of camera words (the 8-bit luma stream of the block)."""
    return WORD.unpack(words)["y"]
