"""Window machinery shared by the filters (thesis 6.2.1): column taps, shift-and-add sums, border control.

A filter is assembled from three parts:

* :func:`column_taps` -- N-1 chained :func:`~eyestereo.hdl.streaming.line_delay.line_delay` blocks and alignment
  registers: N pixels of one image column (rows y-r .. y+r), all valid in the same clock.
* arithmetic on the taps, by :func:`~eyestereo.hdl.common.arith.shift_add` (constant coefficients as shifts and adds) and plain
  registers, free-running: it needs no enable, because the control path carries the timing.
* :func:`window_control` -- the control unit of "border treatment, option 3": the output frame has the
  input's size and valid/eol/eof pattern; output pixel (x, y) is the response of the window centred on
  input pixel (x, y). The output runs ``r * width + r`` pixels behind the input; after the input frame's
  last pixel the control unit emits the missing pixels by itself, one per clock, so no further input is
  needed. Those pixels, and all others whose window leaves the image, carry unspecified data.

These are helpers, not stream blocks: they are instantiated inside blocks such as
:func:`~eyestereo.hdl.streaming.convolve.convolve` and :func:`~eyestereo.hdl.harris.sobel.sobel`.
"""

from myhdl import Signal, always_comb, always_seq, block, intbv

from eyestereo.hdl.common.checks import (block_error, check_clock, check_frame, check_int, check_reset,
                                         check_signal, check_stream)
from eyestereo.hdl.common.registers import assign, delay, delay_rst
from eyestereo.hdl.streaming.line_delay import line_delay
from eyestereo.hdl.interfaces.stream import ImageStream


@block
def column_taps(clk, rst, sink, taps, tap_valid, *, width: int, height: int):
    """N pixels of one column, rows y-r (``taps[0]``) .. y+r (``taps[-1]``), aligned to one clock.

    ``taps[-1]`` is the newest pixel (the sink's), ``taps[0]`` the one N-1 lines earlier. The taps and
    ``tap_valid`` (a pixel beat, not a reset token) are registered N-1 clocks after the sink beat.
    ``sink`` must be a mono stream (a stereo one would mix the cameras in the window).
    """
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink)
    dw = sink.data_width
    if not isinstance(taps, (list, tuple)) or len(taps) < 2:
        raise block_error(f"taps must be a list of at least 2 Signals, got {taps!r}"[:120])
    for i, t in enumerate(taps):
        check_signal(f"taps[{i}]", t, width=dw)
    check_signal("tap_valid", tap_valid, width=1)
    width, height = check_frame(width, height)
    n = len(taps)
    insts = []
    streams = [sink]
    for _ in range(n - 1):
        s = ImageStream(dw)
        insts.append(line_delay(clk, rst, streams[-1], s, width=width, height=height))
        streams.append(s)
    # streams[k] is k lines old and k clocks late; bring them all to n-1 clocks.
    for k, s in enumerate(streams):
        tap = taps[n - 1 - k]
        if k == n - 1:
            insts.append(assign(s.data, tap))
        else:
            insts.append(delay(clk, s.data, tap, clocks=n - 1 - k))
    pix = Signal(bool(0))

    @always_comb
    def decode():
        pix.next = sink.valid and (sink.eol or not sink.eof)

    insts.append(decode)
    insts.append(delay(clk, pix, tap_valid, clocks=n - 1))
    return insts

@block
def window_control(clk, rst, sink, source, *, width: int, height: int, radius: int, latency: int):
    """Control unit for border treatment option 3: drives ``source.valid/eol/eof``.

    The data path must put output pixel (x, y) on ``source.data`` exactly ``latency`` clocks after the
    sink beat of input pixel (x + r, y + r) (r = ``radius``). This unit emits that pixel's flags at the
    same time, counts the output raster, emits the last ``r * width + r`` pixels of each frame on its own
    after the input frame's last pixel (one per clock), and forwards a reset token after ``latency``
    clocks, clearing its counters.

    Why no collision: a frame's own first output needs ``r * width + r + 1`` of its pixels, so it comes
    after the previous frame's self-emitted tail even when frames arrive back to back.
    """
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink)
    check_stream("source", source)
    width, height = check_frame(width, height)
    radius = check_int("radius", radius, 0)
    latency = check_int("latency", latency, 1)
    lead = radius * width + radius
    if lead >= width * height:
        raise block_error(f"a {2 * radius + 1}x{2 * radius + 1} window needs a frame larger than {width}x{height}")
    skip = Signal(intbv(lead, min=0, max=lead + 1))
    tail = Signal(intbv(0, min=0, max=lead + 1))
    ox = Signal(intbv(0, min=0, max=width))
    oy = Signal(intbv(0, min=0, max=height))
    v0, l0, f0 = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))

    @always_seq(clk.posedge, reset=rst)
    def count():
        emit = False
        v0.next = False
        l0.next = False
        f0.next = False
        if sink.valid and sink.eof and not sink.eol:
            # Reset token: abandon the frame in progress and pass the token on.
            skip.next = lead
            tail.next = 0
            ox.next = 0
            oy.next = 0
            v0.next = True
            f0.next = True
        else:
            if sink.valid:
                if skip == 0:
                    emit = True
                if sink.eof:
                    skip.next = lead
                    tail.next = lead
                elif skip != 0:
                    skip.next = skip - 1
            if tail != 0:
                emit = True
                if not (sink.valid and sink.eof):
                    tail.next = tail - 1
            if emit:
                v0.next = True
                if ox == width - 1:
                    l0.next = True
                    ox.next = 0
                    if oy == height - 1:
                        f0.next = True
                        oy.next = 0
                    else:
                        oy.next = oy + 1
                else:
                    ox.next = ox + 1

    insts = [count]
    if latency == 1:
        insts += [assign(v0, source.valid), assign(l0, source.eol), assign(f0, source.eof)]
    else:
        for a, b in ((v0, source.valid), (l0, source.eol), (f0, source.eof)):
            insts.append(delay_rst(clk, rst, a, b, clocks=latency - 1))
    return insts
