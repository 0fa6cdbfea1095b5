"""Window machinery for stereo streams: one datapath, two cameras (thesis 6.3, Figs. 6.14-6.16).

A stereo stream (:mod:`eyestereo.hdl.interfaces.stream`) carries the left and the right pixel of each (x, y) in
turn. The filters of the stereo Harris detector process both cameras in one datapath:

* :func:`stereo_column_taps` -- like :func:`~eyestereo.hdl.common.window.column_taps`, but its line
  delays are stereo :func:`~eyestereo.hdl.streaming.line_delay.line_delay` blocks (2 x width words addressed by
  (column, cam)): both cameras share each block RAM, so a stereo filter needs no more block RAMs than a
  mono one with the same total number of words.
* :func:`pair_chain` -- the horizontal registers of a window: 2N - 1 registers shifted on every pixel
  beat. Beats alternate left, right, so register 2j holds the current beat's camera j columns back; a
  window reads the even registers only.
* :func:`stereo_window_control` -- the control unit of "border treatment option 3" for stereo
  streams: the output raster of both cameras, the tail of ``r * width + r`` pixels per camera emitted
  after the frame's last pixel (left, right, left, ...), one beat every ``share`` clocks so that the
  time-shared multipliers behind it always see beats at least ``share`` clocks apart.

Helpers, not stream blocks: used by :func:`eyestereo.hdl.harris.harris_stereo.harris_stereo`.
"""

from myhdl import Signal, always_comb, always_seq, block, intbv

from eyestereo.hdl.common.checks import (block_error, check_clock, check_frame, check_int, check_reset,
                                         check_signal, check_stream)
from eyestereo.hdl.common.registers import assign, delay, delay_rst, en_reg, like_signal
from eyestereo.hdl.streaming.line_delay import line_delay
from eyestereo.hdl.interfaces.stream import ImageStream


@block
def stereo_column_taps(clk, rst, sink, taps, tap_valid, *, width: int, height: int):
    """N pixels of one column of the beat's camera, rows y-r (``taps[0]``) .. y+r (``taps[-1]``).

    As :func:`~eyestereo.hdl.common.window.column_taps` for a stereo ``sink``: the taps and
    ``tap_valid`` (a pixel beat, not a reset token) come N-1 clocks after the sink beat, all from the
    beat's own camera (the stereo line delays keep the cameras apart).
    """
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, stereo=True)
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
        s = ImageStream(dw, stereo=True)
        insts.append(line_delay(clk, rst, streams[-1], s, width=width, height=height))
        streams.append(s)
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


def pair_regs(first, n: int) -> list:
    """The 2n - 1 registers of a :func:`pair_chain` after ``first`` (like it in width and sign)."""
    return [like_signal(first) for _ in range(2 * n - 1)]


@block
def pair_chain(clk, en, first, regs):
    """Shift ``first`` through ``regs`` (from :func:`pair_regs`) when ``en``.

    With beats alternating between the cameras, ``regs[0::2]`` hold the current beat's camera's values
    0, 1, ..., n-1 columns back (index 0 the newest, as the mono filters count).
    """
    insts = []
    src = first
    for reg in regs:
        insts.append(en_reg(clk, en, src, reg))
        src = reg
    return insts


@block
def stereo_window_control(clk, rst, sink, source, *, width: int, height: int, radius: int, latency: int,
                          share: int, lead_pixels: int | None = None):
    """Control unit for border treatment option 3 on stereo streams: drives ``source.valid/eol/eof/cam``.

    The data path puts camera c's output pixel (x, y) on ``source.data`` exactly ``latency`` clocks after
    the sink beat of camera c's input pixel (x + r, y + r). After a frame's last beat this unit emits
    the remaining ``r * width + r`` pixels of each camera itself (left and right in turn), one beat
    every ``share`` clocks, then stops; a reset token (either cam) clears it and is passed on.

    Why no collision: the next frame's first output needs ``2 (r * width + r) + 1`` of its beats, which
    come at least ``share`` clocks apart, so the tail (as many beats at exactly ``share`` clocks) is
    over, and the first output comes at least ``share`` clocks after the tail's last beat.
    """
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, stereo=True)
    check_stream("source", source, stereo=True)
    width, height = check_frame(width, height)
    radius = check_int("radius", radius, 0)
    latency = check_int("latency", latency, 1)
    share = check_int("share", share, 1, 3)
    # lead_pixels: a data path that decides pixel (x, y) later than at input (x + r, y + r) (nms_stereo's
    # one-delay 3x3 form: at (x + 2, y + 1), i.e. width + 2 pixels behind)
    lead = 2 * (radius * width + radius if lead_pixels is None else check_int("lead_pixels", lead_pixels, 0))
    if lead // 2 >= width * height:
        raise block_error(f"a {2 * radius + 1}x{2 * radius + 1} window needs a frame larger than {width}x{height}")
    skip = Signal(intbv(lead, min=0, max=lead + 1))
    tail = Signal(intbv(0, min=0, max=lead + 1))
    wait = Signal(intbv(0, min=0, max=share))
    half = Signal(bool(0))  # camera of the next tail beat
    ox = Signal(intbv(0, min=0, max=width))
    oy = Signal(intbv(0, min=0, max=height))
    v0, l0, f0, c0 = Signal(bool(0)), Signal(bool(0)), Signal(bool(0)), Signal(bool(0))

    @always_seq(clk.posedge, reset=rst)
    def count():
        emit = False
        cam = False
        v0.next = False
        l0.next = False
        f0.next = False
        c0.next = False
        if wait != 0:
            wait.next = wait - 1
        if sink.valid and sink.eof and not sink.eol:
            skip.next = lead
            tail.next = 0
            half.next = False
            ox.next = 0
            oy.next = 0
            v0.next = True
            f0.next = True
            c0.next = sink.cam
            wait.next = share - 1
        else:
            if sink.valid and skip == 0:
                emit = True
                if sink.cam:
                    cam = True
            elif tail != 0 and wait == 0:
                # a beat of the tail, in a clock the sink leaves free of output
                emit = True
                if half:
                    cam = True
                half.next = not half
                tail.next = tail - 1
            if sink.valid:
                if sink.eof and sink.cam:
                    skip.next = lead
                    tail.next = lead
                    half.next = False
                elif skip != 0:
                    skip.next = skip - 1
            if emit:
                v0.next = True
                c0.next = cam
                wait.next = share - 1
                if ox == width - 1:
                    l0.next = True
                    if oy == height - 1:
                        f0.next = True
                if cam:
                    if ox == width - 1:
                        ox.next = 0
                        if oy == height - 1:
                            oy.next = 0
                        else:
                            oy.next = oy + 1
                    else:
                        ox.next = ox + 1

    insts = [count]
    pairs = ((v0, source.valid), (l0, source.eol), (f0, source.eof), (c0, source.cam))
    if latency == 1:
        insts += [assign(a, b) for a, b in pairs]
    else:
        insts += [delay_rst(clk, rst, a, b, clocks=latency - 1) for a, b in pairs]
    return insts
