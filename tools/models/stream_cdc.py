"""Clock-accurate model of :func:`eyestereo.hdl.streaming.stream_cdc.stream_cdc`: the FIFO's model on packed words.

The block puts a stereo beat's ``cam``, ``eol`` and ``eof`` into the FIFO word and shows the FIFO
``eol``/``eof`` only on the right camera's beats and on reset tokens; the read side unpacks. So the
model packs the beats the same way, runs :func:`eyestereo.tools.models.async_fifo.async_fifo` (the
FIFO's own clock-accurate model, with ``ready`` always high), and unpacks what comes out.
"""

from __future__ import annotations

from eyestereo.tools.models.async_fifo import ClockSpec, FifoResult, async_fifo

__all__ = ["fifo_width", "pack", "unpack", "stream_cdc", "ClockSpec"]


def fifo_width(data_width: int, stereo: bool) -> int:
    """Bits of the FIFO's data field: the pixel, and for a stereo stream cam, eol and eof above it."""
    return int(data_width) + (3 if stereo else 0)


def pack(beat, data_width: int, stereo: bool) -> tuple[int, bool, bool]:
    """A sink beat ``(data, eol, eof[, cam])`` -> the FIFO's ``(data, eol, eof)``."""
    if not stereo:
        d, eol, eof = beat[:3]
        return int(d), bool(eol), bool(eof)
    d, eol, eof, cam = beat[:4]
    token = eof and not eol
    word = int(d) | int(cam) << data_width | int(eol) << (data_width + 1) | int(eof) << (data_width + 2)
    return word, bool(eol and cam), bool(eof and (cam or token))


def unpack(word: int, eol: bool, eof: bool, data_width: int, stereo: bool) -> tuple:
    """The FIFO's ``(data, eol, eof)`` -> the source beat ``(data, eol, eof[, cam])``."""
    if not stereo:
        return int(word), bool(eol), bool(eof)
    d = word & ((1 << data_width) - 1)
    cam = bool(word >> data_width & 1)
    if eof and not eol:
        return d, False, True, cam
    return d, bool(word >> (data_width + 1) & 1), bool(word >> (data_width + 2) & 1), cam


def stream_cdc(beats, *, data_width: int, stereo: bool, depth: int, wclk: ClockSpec, rclk: ClockSpec,
               wresets=(), rresets=()) -> tuple[list[tuple], FifoResult]:
    """Run the crossing on sink beats ``(data, eol, eof[, cam], edge, tag)`` (``edge``: write-clock edge).

    Returns ``(out, result)``: ``out`` the source beats ``(data, eol, eof[, cam], read_edge)`` in order,
    ``result`` the FIFO model's result (``dropped``, ``lost``, ``max_level``, entries with their tags).
    """
    n = 4 if stereo else 3
    fifo_beats = [(*pack(b[:n], data_width, stereo), b[n], b[n + 1]) for b in beats]
    res = async_fifo(fifo_beats, depth=depth, wclk=wclk, rclk=rclk, wresets=wresets, rresets=rresets)
    out = [(*unpack(e.data, e.eol, e.eof, data_width, stereo), e.leave) for e in res.out]
    return out, res
