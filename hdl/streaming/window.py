"""Window machinery of the filters (thesis 6.2.1, 6.3): column taps, row registers, border control.

A filter is assembled from three parts, for mono and stereo streams alike (the kind is the sink's):

* :func:`column_taps` -- N-1 chained :func:`~eyestereo.hdl.streaming.line_delay.line_delay` blocks and
  alignment registers: N pixels of one image column (rows y-r .. y+r), all valid in the same clock. On a
  stereo stream the line delays are stereo ones (2 x width words addressed by (column, cam)): both
  cameras share each block RAM, and each beat's taps are its own camera's.
* arithmetic on the taps, by :func:`~eyestereo.hdl.common.arith.shift_add` (constant coefficients as
  shifts and adds) and plain registers, free-running: it needs no enable, because the control path
  carries the timing. The horizontal registers of a window are laid out by :func:`window_row`: N
  registers shifted on every pixel beat, or 2N - 1 on a stereo stream, whose beats alternate left, right,
  so that register 2j holds the current beat's camera j columns back and the window reads the even ones.
* :func:`window_control` -- the control unit of "border treatment, option 3": the output frame has the
  input's size and valid/eol/eof(/cam) pattern; output pixel (x, y) is the response of the window centred
  on input pixel (x, y). The output runs ``r * width + r`` pixels (of each camera) behind the input;
  after the input frame's last pixel the control unit emits the missing pixels by itself, so no further
  input is needed. Those pixels, and all others whose window leaves the image, carry unspecified data.

These are helpers, not stream blocks: they are instantiated inside blocks such as
:func:`~eyestereo.hdl.streaming.convolve.convolve` and :func:`~eyestereo.hdl.harris.sobel.sobel`.
"""

from myhdl import Signal, always_comb, always_seq, block, intbv

from eyestereo.hdl.common.checks import (block_error, check_choice, check_clock, check_frame, check_int,
                                         check_reset, check_signal, check_stream)
from eyestereo.hdl.common.registers import assign, delay, delay_rst, like_signal
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.hdl.streaming.line_delay import line_delay
from eyestereo.tools.constants import SHARE_FACTORS


def check_share(share, sink) -> int:
    """The ``share`` parameter of a block on ``sink``: one of SHARE_FACTORS, and 1 for a mono stream.

    Only a stereo stream leaves a block clocks to share: its beats come at least ``share`` clocks apart,
    while a mono stream may bring a pixel every clock.
    """
    share = check_choice("share", share, SHARE_FACTORS)
    if share != 1 and not sink.stereo:
        raise block_error(f"parameter share={share} needs a stereo sink: a mono stream may bring a pixel "
                          f"every clock, so there are no clocks to share the arithmetic over (use share=1)")
    return share


@block
def column_taps(clk, rst, sink, taps, tap_valid, *, width: int, height: int, skew: bool = False):
    """N pixels of one column, rows y-r (``taps[0]``) .. y+r (``taps[-1]``), aligned to one clock.

    ``taps[-1]`` is the newest pixel (the sink's), ``taps[0]`` the one N-1 lines earlier. The taps and
    ``tap_valid`` (a pixel beat, not a reset token) are registered :func:`tap_latency` (N) clocks after
    the sink beat. On a stereo ``sink`` all taps come from the beat's own camera (the stereo line delays
    keep the cameras apart).

    ``skew=True``: the taps are not aligned; the one k lines old (``taps[-1 - k]``) is registered k + 1
    clocks after the sink beat (one register each), ``tap_valid`` still N clocks after it, with the
    oldest. For a weighted column sum that adds one tap per clock
    (:func:`~eyestereo.hdl.common.arith.chain_sum`): its partial sums wait instead of the taps.

    Every block RAM read is registered once before anything else sees it (the role of the RAM's output
    register, which the ECP5 mapping does not use): a block RAM's clock-to-output takes most of a
    100 MHz clock on its own, so an adder or comparator behind it cannot meet 110 MHz. The line delays
    are chained from the RAM outputs themselves (RAM to RAM, no logic), so the chain stays one clock per
    line delay and the alignment costs one register per tap more than without the output registers.
    """
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, stereo=None)
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
        s = ImageStream(dw, stereo=sink.stereo)
        insts.append(line_delay(clk, rst, streams[-1], s, width=width, height=height))
        streams.append(s)
    # streams[k] is k lines old and k clocks late; bring them all to n clocks (so the oldest, a RAM
    # output, passes one register: the output register).
    for k, s in enumerate(streams):
        insts.append(delay(clk, s.data, taps[n - 1 - k], clocks=1 if skew else tap_latency(n) - k))
    pix = Signal(bool(0))

    @always_comb
    def decode():
        pix.next = sink.valid and (sink.eol or not sink.eof)

    insts.append(decode)
    insts.append(delay(clk, pix, tap_valid, clocks=tap_latency(n)))
    return insts


def tap_latency(n: int) -> int:
    """Clocks from a sink beat to its :func:`column_taps` of ``n`` rows: n - 1 line delays of one clock
    each and the register behind the last one's block RAM."""
    return n


def row_regs(first, n: int, *, stereo: bool) -> list:
    """The registers of a window row after ``first`` (like it in width and sign): n, or 2n - 1 on a stereo
    stream."""
    return [like_signal(first) for _ in range(2 * n - 1 if stereo else n)]


def window_row(first, n: int, *, stereo: bool) -> tuple[list, list]:
    """(links, row): the n values of a window row, ``row[j]`` the one j columns back (index 0 the newest),
    and the (d, q) pairs of the registers that shift ``first`` along the row.

    The caller makes an ``en_reg(clk, en, d, q)`` of each link in its own body (MyHDL takes block
    instances only from the body of a block). On a stereo stream the chain is 2n - 1 registers long:
    beats alternate between the cameras, so the even registers hold the current beat's camera.
    """
    regs = row_regs(first, n, stereo=stereo)
    return list(zip([first] + regs, regs)), (regs[0::2] if stereo else regs)


@block
def window_control(clk, rst, sink, source, *, width: int, height: int, radius: int, latency: int,
                   share: int = 1, lead_pixels: int | None = None):
    """Control unit for border treatment option 3: drives ``source.valid/eol/eof`` (and ``cam``).

    The data path must put (camera c's) output pixel (x, y) on ``source.data`` exactly ``latency`` clocks
    after the sink beat of (camera c's) input pixel (x + r, y + r) (r = ``radius``). This unit emits that
    pixel's flags at the same time, counts the output raster, emits the last ``r * width + r`` pixels of
    each frame (of each camera) on its own after the input frame's last pixel, and forwards a reset token
    after ``latency`` clocks, clearing its counters.

    Mono streams: the tail comes one pixel per clock. Stereo streams: left and right in turn, one beat
    every ``share`` clocks, in clocks the sink leaves free of output, so that time-shared multipliers behind
    it always see beats at least ``share`` clocks apart. ``share`` must be 1 for a mono stream. A reset token
    is forwarded after ``latency`` clocks, or, with ``share`` > 1 and a tail beat emitted in the last
    ``share - 1`` clocks, held until ``share`` clocks after that beat (at most ``share - 1`` clocks more):
    so tokens keep the spacing too (the formal proof found a token one clock after a tail beat before it
    was held; docs/formal.md). Nothing else can be emitted while it is held: the token has cleared the
    tail, and the sink's next beat comes ``share`` clocks after the token at the earliest.

    ``lead_pixels`` (default ``r * width + r``): for a data path that decides pixel (x, y) later than at
    input (x + r, y + r), how many pixels of its camera the output runs behind the input (the stereo NMS's
    one-delay 3x3 form: at (x + 2, y + 1), i.e. ``width + 2``).

    Why no collision: a frame's own first output needs ``lead + 1`` of its pixels (of each camera), so it
    comes after the previous frame's self-emitted tail even when frames arrive back to back (stereo: the
    next frame's ``2 lead + 1`` beats come at least ``share`` clocks apart, as the tail's beats do).
    """
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, stereo=None)
    check_stream("source", source, stereo=sink.stereo)
    width, height = check_frame(width, height)
    radius = check_int("radius", radius, 0)
    latency = check_int("latency", latency, 1)
    share = check_share(share, sink)
    lead = radius * width + radius if lead_pixels is None else check_int("lead_pixels", lead_pixels, 0)
    if lead >= width * height:
        raise block_error(f"a {2 * radius + 1}x{2 * radius + 1} window needs a frame larger than {width}x{height}")
    if sink.stereo:
        lead *= 2  # counted in beats, the two cameras'
    skip = Signal(intbv(lead, min=0, max=lead + 1))
    tail = Signal(intbv(0, min=0, max=lead + 1))
    ox = Signal(intbv(0, min=0, max=width))
    oy = Signal(intbv(0, min=0, max=height))
    v0, l0, f0 = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    flags = [(v0, source.valid), (l0, source.eol), (f0, source.eof)]
    if sink.stereo:
        c0 = Signal(bool(0))
        flags.append((c0, source.cam))
        wait = Signal(intbv(0, min=0, max=share))
        half = Signal(bool(0))  # camera of the next tail beat
        # a reset token held until the spacing allows it (share > 1), and its camera
        held, held_cam = Signal(bool(0)), Signal(bool(0))
        hold_tokens = share > 1

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
                if hold_tokens and wait != 0:
                    # a beat left less than share clocks ago: the token waits for the spacing
                    held.next = True
                    held_cam.next = sink.cam
                else:
                    v0.next = True
                    f0.next = True
                    c0.next = sink.cam
                    wait.next = share - 1
                    held.next = False
            elif hold_tokens and held:
                if wait == 0:
                    held.next = False
                    v0.next = True
                    f0.next = True
                    c0.next = held_cam
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
                    # the right camera's beat moves the raster on
                    if cam:
                        if ox == width - 1:
                            ox.next = 0
                            if oy == height - 1:
                                oy.next = 0
                            else:
                                oy.next = oy + 1
                        else:
                            ox.next = ox + 1
    else:

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
        insts += [assign(a, b) for a, b in flags]
    else:
        for a, b in flags:
            insts.append(delay_rst(clk, rst, a, b, clocks=latency - 1))
    return insts
