"""Bit-true model of :func:`eyestereo.hdl.axi.stream_to_axis.stream_to_axis`: frames as AXI4-Stream video beats.

A beat is ``(tdata, tlast, tuser)``: ``tuser`` (SOF) on pixel (0, 0), ``tlast`` (EOL) on the last pixel of
every line (Xilinx UG934). Without overflow the bridge sends exactly :func:`to_axis` of each frame.
When its FIFO overflows, which frames are cut depends on the timing of ``tready``, so the model gives
the rule the output must follow instead: :func:`match_frames` checks a received sequence against the
sent frames.
"""

from __future__ import annotations

import numpy as np

AxisBeat = tuple[int, bool, bool]


def to_axis(frame: np.ndarray) -> list[AxisBeat]:
    """The AXI4-Stream video beats of one frame."""
    frame = np.asarray(frame)
    if frame.ndim != 2 or frame.size == 0:
        raise ValueError(f"a frame must be a non-empty 2-D array, got shape {frame.shape}")
    h, w = frame.shape
    return [(int(frame[y, x]), x == w - 1, x == 0 and y == 0) for y in range(h) for x in range(w)]


def split_frames(beats: list[AxisBeat]) -> list[list[list[int]]]:
    """Received beats -> frames (lists of lines of pixel values), split at SOF and at ``tlast``.

    A line not ended by ``tlast`` before the next SOF or the end is kept as it is (a faulty line; the
    bridge never sends one). Beats before the first SOF form a frame of their own.
    """
    frames: list[list[list[int]]] = []
    line: list[int] = []

    def close_line():
        nonlocal line
        if line:
            if not frames:
                frames.append([])
            frames[-1].append(line)
            line = []

    for data, last, user in beats:
        if user:
            close_line()
            frames.append([])
        line.append(int(data))
        if last:
            close_line()
    close_line()
    return frames


def match_frames(sent: list[np.ndarray], received: list[list[list[int]]], *, commit: str = "line"
                 ) -> tuple[list[int], list[int]]:
    """Check received frames against the sent ones, in order; return (indices sent whole, indices cut).

    Every received frame must be a sent frame, whole, or (``commit="line"``) its first k >= 1 complete
    lines with k < height; sent frames may be missing altogether (dropped). Anything else (a wrong or
    partial line, a frame out of order, a cut frame with ``commit="frame"``) raises AssertionError.
    Sent frames that were not received whole are counted as cut (this includes dropped ones).
    """
    whole: list[int] = []
    i = 0
    for k, got in enumerate(received):
        while True:
            if i >= len(sent):
                raise AssertionError(f"received frame {k} ({len(got)} lines) matches no remaining sent frame")
            f = np.asarray(sent[i])
            lines = [list(map(int, r)) for r in f]
            n = len(got)
            if n == len(lines) and got == lines:
                whole.append(i)
                i += 1
                break
            if commit == "line" and 0 < n < len(lines) and got == lines[:n]:
                i += 1  # cut after n whole lines
                break
            i += 1  # frame i was dropped whole; try the next one
    cut = [j for j in range(len(sent)) if j not in whole]
    return whole, cut
