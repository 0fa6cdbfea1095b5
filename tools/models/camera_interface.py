"""Model of :func:`eyestereo.hdl.camera.camera_interface.camera_interface`: camera bus in, good frames out.

``camera_interface`` is :func:`~eyestereo.hdl.camera.camera_stream.camera_stream` followed by
:func:`~eyestereo.hdl.streaming.async_fifo.async_fifo`; its model is theirs chained: the camera_stream model turns
the bus schedule into beats (with their PCLK edges), the FIFO model carries them across into the read
clock with the reader's stall windows and both domains' resets. What comes out is described by a
:class:`Result`: the beats the reader takes (bit for bit), the complete frames among them with the index
of the camera frame each one is, the frames aborted on the read side (a prefix of the frame, then a reset
token), and the dropped-frame counter.

The frame-level outcome (which frames arrive, which are aborted, the counter) must not depend on how two
clock edges that coincide in time are resolved, nor on a synchroniser taking one edge more or less:
:func:`camera_interface` checks this by running the FIFO model with each synchroniser one edge shorter and
longer, and raises :class:`AmbiguousSchedule` when the outcome changes. A bench applies only schedules
the model accepts, so its comparison is exact.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from eyestereo.tools.camera import DEFAULT_TIMING, CameraTiming
from eyestereo.tools.models.async_fifo import ClockSpec, FifoResult, async_fifo
from eyestereo.tools.models.camera_stream import camera_stream

__all__ = ["AmbiguousSchedule", "Result", "camera_interface", "outcome"]


class AmbiguousSchedule(Exception):
    """The frame-level outcome depends on clock-edge details the model cannot promise."""


@dataclass
class Result:
    beats: list[tuple[int, bool, bool, int]]  # (data, eol, eof, read edge) of every beat taken
    frames: list[np.ndarray]  # complete frames, in order
    frame_ids: list[int]  # the camera frame (VSYNC pulse index in the schedule) of each
    aborted: list[tuple[int, int]]  # (camera frame, words before its token) of frames aborted on the read side
    cut_off: list[tuple[int, int]]  # (camera frame, words taken) of frames cut by a read-side reset
    dropped: int  # dropped-frame counter at the end
    last_edge: int  # read edge of the last beat (or discard), -1 if none
    fifo: FifoResult

    @property
    def outcome(self):
        return outcome(self.fifo)


def outcome(res: FifoResult) -> tuple:
    """(complete frame tags, aborted frame tags, frames cut by a read-side reset, dropped count): what
    must not depend on edge details."""
    seg = list(res.segments())
    return (tuple(t for k, t, _ in seg if k == "frame"), tuple(t for k, t, _ in seg if k == "token"),
            tuple(t for k, t, _ in seg if k == "reset"), res.dropped)


def _frames(res: FifoResult, width: int, height: int):
    frames, ids, aborted, cut_off = [], [], [], []
    for kind, tag, words in res.segments():
        if kind == "frame":
            if len(words) != width * height:
                raise AssertionError(f"model: frame {tag} came out with {len(words)} words")
            frames.append(np.array(words, dtype=np.int64).reshape(height, width))
            ids.append(tag)
        elif kind == "token":
            aborted.append((tag, len(words)))
        else:
            cut_off.append((tag, len(words)))
    return frames, ids, aborted, cut_off


def camera_interface(runs, timing: CameraTiming = DEFAULT_TIMING, *, depth: int, pclk: ClockSpec,
                     rclk: ClockSpec, wresets=(), rresets=(), stalls=(), check: bool = True) -> Result:
    """What camera_interface delivers for a bus schedule.

    Args:
        runs: the bus schedule (:func:`eyestereo.tools.camera.frame_schedule`, maybe
            :func:`~eyestereo.tools.camera.cut`); sample j is on the bus at PCLK edge j.
        timing: the camera timing the block is built for (geometry, order, polarities).
        depth: FIFO entries.
        pclk, rclk: camera and read clock (edge 0 = the first rising edge of each).
        wresets: PCLK edge intervals with the write-domain reset high; rresets: read-clock edge intervals
            with the read-domain reset high; stalls: read-clock edge intervals with ``ready`` low.
        check: raise :class:`AmbiguousSchedule` if the frame-level outcome changes when either
            synchroniser takes one edge more or less.
    """
    beats = camera_stream(runs, timing, resets=wresets)
    # The FIFO samples camera_stream's output register one edge after it is loaded.
    fifo_in = [(b.data, b.eol, b.eof, b.edge + 1, b.frame) for b in beats]
    kw = dict(depth=depth, wclk=pclk, rclk=rclk, wresets=wresets, rresets=rresets, stalls=stalls)
    res = async_fifo(fifo_in, **kw)
    # Edge details can only matter through an overflow or a reset: without either, and with the level
    # short of the depth by more than one edge's worth of reads, the variants cannot differ.
    margin = -(-pclk.period // rclk.period) + 2
    first = fifo_in[0][3] if fifo_in else 0
    late_w = [r for r in wresets if r[1] > first]
    late_r = [r for r in rresets if r[1] > rclk.first_after(pclk.time(first))]
    quiet = not (late_w or late_r or res.lost) and res.max_level + margin < depth
    if check and not quiet:
        ref = outcome(res)
        for ws, rs in ((1, 2), (3, 2), (2, 1), (2, 3)):
            alt = outcome(async_fifo(fifo_in, w_sync=ws, r_sync=rs, **kw))
            if alt != ref:
                raise AmbiguousSchedule(
                    f"outcome depends on synchroniser timing (write sync {ws}, read sync {rs}): "
                    f"frames {ref[0]} vs {alt[0]}, aborted {ref[1]} vs {alt[1]}, cut by rrst {ref[2]} vs "
                    f"{alt[2]}, dropped {ref[3]} vs {alt[3]}")
    frames, ids, aborted, cut_off = _frames(res, timing.width, timing.height)
    return Result(beats=[(e.data, e.eol, e.eof, e.leave) for e in res.out], frames=frames, frame_ids=ids,
                  aborted=aborted, cut_off=cut_off, dropped=res.dropped, last_edge=res.last_edge, fifo=res)
