"""The stream rectifier: both cameras' streams in, the rectified stereo stream out, from an on-chip line cache."""

from __future__ import annotations

from myhdl import Signal, always_comb, always_seq, block

from eyestereo.hdl.common.checks import block_error, check_clock, check_int, check_reset, check_signal, check_stream
from eyestereo.hdl.interfaces.fetch_port import FetchPort
from eyestereo.hdl.interfaces.queue import check_queue
from eyestereo.hdl.rectify.calibration import calibration_param
from eyestereo.hdl.rectify.fetch_interpolate import DEFAULT_DEPTH
from eyestereo.hdl.rectify.line_cache import line_cache
from eyestereo.hdl.rectify.fetch_gate import fetch_gate
from eyestereo.hdl.rectify.rectifier import rectifier
from eyestereo.tools.camera import WORD as CAMERA_WORD
from eyestereo.tools.models import line_cache as cache_model
from eyestereo.tools.models import poly_unit as unit_model

__all__ = ["stream_rectifier"]


@block
def stream_rectifier(clk, rst, cam0, cam1, source, start, arm, begun, busy, overrun, coef=None, hold=None, *,
                     quantizers=None,
                     frac: int | None = unit_model.DEFAULT_FRAC, lines: int | None = None,
                     depth: int = DEFAULT_DEPTH):
    """Rectify the cameras' frames as they arrive: no frame store, no memory reads (``rectify="stream"``).

    :func:`~eyestereo.hdl.rectify.line_cache.line_cache` keeps the last ``lines`` lines of each camera in
    block RAM; the :func:`~eyestereo.hdl.rectify.rectifier.rectifier` (warper, fetch and interpolation,
    unchanged) fetches its 2x2 neighbourhoods from it instead of the frame store. A frame starts at a clock
    with ``start`` and ``begun`` high and the rectifier idle (hold ``start`` high to rectify every frame the
    rectifier is free for); ``begun``: both cameras have begun a frame since the last start. Its rectified
    rows follow the cameras' lines at about the calibration's vertical reach (a fetch waits for its rows).
    The output is the rectifier's: the stereo stream of the calibration's rectified size, bit-exact with
    :func:`eyestereo.tools.models.rectifier.rectifier` on the two camera frames.

    Timing of a frame (``#`` high, ``_`` low; ``b``: both cameras have begun a frame, from their first words)::

        camera L   ..frame n................................     ..frame n+1
        camera R     ..frame n................................     ..frame n+1
        cycle           b   b+1   ...   (rows in)  ...   e
        start           #    .     .     .     .     .   .
        begun           #    _     _     _     _     _   _
        busy            _    #     #     #     #     #   _
        source          _    _     _     L0,0 R0,0 ... R(w-1,h-1)

    Ports:
        clk, rst: the memory clock; synchronous active-high reset (a frame abandoned).
        cam0, cam1: :class:`~eyestereo.hdl.interfaces.queue.QueuePort` of camera words (left, right), the
            camera FIFOs' read sides; never held back (``ready`` high).
        source: 8-bit stereo :class:`~eyestereo.hdl.interfaces.stream.ImageStream` (the rectifier's).
        start: in, 1 bit: start a frame (taken when ``begun`` is high and the rectifier idle).
        arm: in, 1 bit: forget the frames begun so far: the next start waits for frames beginning later.
        begun: out, 1 bit: both cameras have begun a frame since the last start or arm, while the rectifier was
            idle (a register).
        busy: out, 1 bit: a frame is being rectified (from the start to its last beat).
        overrun: out, 1 bit: one-clock pulse, at most one per frame (a register): the frame being rectified read
            a line the cameras had already overwritten, or a camera began its next frame first: the frame is not
            the cameras' (drop it). The line cache pulses at every such read; this port counts the frame once, so
            a counter of its pulses counts frames (the front end's DROPPED registers).
        coef: optional :class:`~eyestereo.hdl.rectify.poly_unit.CoefPort`, as for the rectifier.
        hold: optional in, 1 bit: while high the rectifier makes no new fetch
            (:func:`~eyestereo.hdl.rectify.fetch_gate.fetch_gate`; the front end's dense option paces it so). A held
            rectifier falls behind the cameras: held too long, its lines are overwritten (``overrun``).

    Parameters:
        quantizers, frac: the calibration and coordinate fraction bits, as for the rectifier; the cameras'
            frames are its camera size.
        lines: the lines kept per camera (a power of two up to 64); default: the calibration's
            :func:`eyestereo.tools.models.line_cache.plan` (CIF cameras at 50 frames/s for a 352x288 calibration,
            the same blanking at other sizes, 100 MHz, cameras within 2 lines of each other); a ValueError
            names the calibration when it needs more than 64.
        depth: fetch_interpolate's sides in flight (1..16).

    Latency: the first beat of a frame comes when the cameras have completed the lines its first fetches read
    (the calibration's reach, :func:`eyestereo.tools.models.line_cache.row_spans`) plus the rectifier's
    :data:`~eyestereo.hdl.rectify.rectifier.FIRST_PIXEL` and the cache's
    :data:`~eyestereo.hdl.rectify.line_cache.FIRST_BEAT`; the last about the reach below the cameras' last line.

    Resources: the rectifier's, and the line cache's 2 x ``lines`` x width bytes of block RAM (docs/memory.md).
    """
    check_clock(clk)
    check_reset(rst)
    check_queue("cam0", cam0, width=CAMERA_WORD.width)
    check_queue("cam1", cam1, width=CAMERA_WORD.width)
    check_stream("source", source, width=8, stereo=True)
    for name, sig in (("start", start), ("arm", arm), ("begun", begun), ("busy", busy), ("overrun", overrun)):
        check_signal(name, sig, width=1)
    cal = calibration_param(quantizers, None, None)
    if lines is None:
        try:
            lines = cache_model.plan(cal, frac).lines
        except ValueError as exc:
            raise block_error(f"parameter quantizers: {exc}") from None
    lines = check_int("lines", lines, 2, cache_model.MAX_LINES)
    if lines & (lines - 1):
        raise block_error(f"parameter lines={lines} must be a power of two (a row's slot is its low bits)")
    depth = check_int("depth", depth, 1, 16)

    fetch = FetchPort(cal.source_width, cal.source_height)
    go, r_busy, c_begun = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    c_overrun, told = Signal(bool(0)), Signal(bool(0))
    cache = line_cache(clk, rst, cam0, cam1, fetch, go, r_busy, arm, c_begun, c_overrun, width=cal.source_width,
                       height=cal.source_height, lines=lines)
    rfetch = fetch
    gate = []
    if hold is not None:
        check_signal("hold", hold, width=1)
        rfetch = FetchPort(cal.source_width, cal.source_height)
        gate = [fetch_gate(clk, rst, rfetch, fetch, hold)]
    rect = rectifier(clk, rst, go, rfetch, source, r_busy, coef, quantizers=cal, frac=frac, depth=depth)

    @always_comb
    def control():
        # begun is a register the cache clears in the clock after a start (the rectifier is busy by then)
        go.next = start and c_begun and not r_busy
        busy.next = r_busy
        begun.next = c_begun  # an output port is not read (VHDL-93)

    @always_seq(clk.posedge, reset=rst)
    def once_per_frame():
        # the cache pulses at every read of an overwritten line (hundreds in a frame); the frame is dropped once
        overrun.next = c_overrun and not told
        if go:
            told.next = False
        elif c_overrun:
            told.next = True

    return cache, rect, control, gate, once_per_frame
