"""Control of a window filter that flushes its line delays itself: the beats into the column taps, the
output raster and the border flags (issue 28; census and median3 share it).

Unlike :func:`~eyestereo.hdl.streaming.window.window_control`, whose tail pixels carry unspecified data, a
filter with defined borders needs the real windows of a frame's last lines, and those lines sit in the line
delays after the frame's last beat. :func:`flush_control` therefore feeds the line delays itself: the sink's
pixels, and after a frame's end its own flush beats until the frame's tail is out.
"""

from myhdl import Signal, always, always_comb, always_seq, block, intbv

from eyestereo.hdl.common.checks import block_error, check_int
from eyestereo.hdl.common.registers import delay, delay_rst
from eyestereo.hdl.streaming.window import tap_latency


@block
def flush_control(clk, rst, sink, shift, source, row_ok, col_ok, *, width: int, height: int, latency: int):
    """The beats that move a window's line delays (``shift``), ``source``'s flags and the border flags.

    ``shift`` is the sink one clock late (its data and camera), with the block's own flush beats added in
    free clocks and ``eol`` / ``eof`` held low: the line delays' column counters never clear, so a frame
    may begin at any column, as long as all its lines begin at the same one, and the flush beats need not
    be aligned to a line. The output runs r lines + r pixels (of each camera) behind the input
    (N = ``len(row_ok)``, r = N // 2): a frame's last r lines + r pixels are emitted on the flush beats
    after its last beat, one per free clock (stereo: a left and a right beat in two clocks following a
    free clock, so the input register's look-ahead sees the sink free for both). When the next frame
    arrives before the tail is out, its beats stand in for the flush beats (their own windows are not
    output: they belong to the new frame's top rows, still being filled), and no flush beat is put
    between two beats of the new frame (that would shift its lines against each other).

    ``source.valid``, ``eol``, ``eof`` (and ``cam``) come ``latency`` clocks after the sink beat whose
    ``shift`` beat completes the output pixel's window (input (x + r, y + r), or the flush beat standing
    in for it); a reset token passes on after ``latency`` clocks, clearing the tail and the raster.
    ``source.data`` is the caller's.

    Border flags (the caller's lists of N Signals, the centre entries left alone): ``row_ok[k]`` is
    0 <= y + k - r <= height - 1 for the emitted pixel (x, y), ``col_ok[k]`` the same of x + k - r and
    ``width``. They are valid ``tap_latency(N) + 1`` clocks after the ``shift`` beat: in the clock the
    window rows behind :func:`~eyestereo.hdl.streaming.window.column_taps` hold that pixel's window.

    Latency ``latency`` (>= 3): the input register, the raster register, then a delay line of
    ``latency - 2`` clocks of the flags.
    """
    n = len(row_ok)
    if n < 3 or n % 2 == 0 or len(col_ok) != n:
        raise block_error(f"row_ok and col_ok must be lists of the same odd length >= 3, got {n} and {len(col_ok)}")
    latency = check_int("latency", latency, 3)
    stereo = sink.stereo
    r = n // 2
    # pixels (of each camera) the output runs behind the input; counted in beats on a stereo stream
    lead = (r * width + r) * (2 if stereo else 1)

    # --- input register: one clock of look-ahead, so that a stereo flush pair (left, right) is only
    # started in a clock whose next clock is free of sink beats too
    d1 = Signal(intbv(0)[sink.data_width:])
    v1, l1, f1, c1 = (Signal(bool(0)) for _ in range(4))
    insts = [delay(clk, sink.data, d1, clocks=1), delay_rst(clk, rst, sink.valid, v1, clocks=1),
             delay_rst(clk, rst, sink.eol, l1, clocks=1), delay_rst(clk, rst, sink.eof, f1, clocks=1)]
    if stereo:
        insts.append(delay_rst(clk, rst, sink.cam, c1, clocks=1))

    # --- the beats that move the line delays: the sink's pixels and the block's own flush beats
    skip = Signal(intbv(lead, min=0, max=lead + 1))  # beats of the frame still before its first output
    tail = Signal(intbv(0, min=0, max=lead + 1))  # outputs of the last frame still to come
    fcam = Signal(bool(0))  # camera of the next flush beat (stereo)
    pix, token, flush, emit, ecam = (Signal(bool(0)) for _ in range(5))

    @always_comb
    def beats():
        pix.next = v1 and (l1 or not f1)
        token.next = v1 and f1 and not l1
        # a flush beat: the tail is not out, the clock is free, and the next frame has not begun
        # (skip == lead until its first pixel); a stereo left flush beat also needs the sink free now,
        # so that its right beat has the next clock (the sink's beat of now waits in the input register)
        flush.next = False
        if tail != 0 and not v1 and skip == lead:
            if not stereo or fcam or not sink.valid:
                flush.next = True

    @always_comb
    def merge():
        shift.data.next = d1  # a flush beat's pixel never reaches an output, so no multiplexer
        shift.valid.next = pix or flush
        shift.eol.next = False  # held low: the line delays' column counters never clear
        shift.eof.next = False
        # an output pixel: the tail of the last frame, or this frame's pixel once lead beats came
        emit.next = (pix or flush) and (tail != 0 or (pix and skip == 0))

    insts += [beats, merge]
    if stereo:
        @always_comb
        def camera():
            # the beat's camera: the sink's, or the flush beat's (left, right in turn)
            if pix:
                shift.cam.next = c1
                ecam.next = c1
            else:
                shift.cam.next = fcam
                ecam.next = fcam

        insts.append(camera)

    # --- the output raster, its flags and the border flags, one clock after the beat
    ox = Signal(intbv(0, min=0, max=width))
    oy = Signal(intbv(0, min=0, max=height))
    x_last, y_last = Signal(bool(0)), Signal(bool(0))
    o_valid, o_eol, o_eof, o_cam = (Signal(bool(0)) for _ in range(4))

    @always_seq(clk.posedge, reset=rst)
    def counters():
        if token:
            # abandon the frame and any tail; the next beat is a new frame's first
            skip.next = lead
            tail.next = 0
            fcam.next = False
        else:
            if (pix or flush) and tail != 0:
                tail.next = tail - 1
            if pix:
                if f1 and (c1 or not stereo):
                    # the frame's last beat: its tail follows, the next frame starts skipping
                    skip.next = lead
                    tail.next = lead
                elif skip != 0:
                    skip.next = skip - 1
            if flush and stereo:
                fcam.next = not fcam

    @always_comb
    def edges():
        x_last.next = ox == width - 1
        y_last.next = oy == height - 1

    @always_seq(clk.posedge, reset=rst)
    def raster():
        # the output beat's flags (a token passes on as it came), and the position of the next one:
        # the right camera's beat moves it on (every beat on a mono stream)
        o_valid.next = token or emit
        o_eol.next = emit and x_last
        o_eof.next = token or (emit and x_last and y_last)
        o_cam.next = (token and c1) or (emit and ecam)
        if token:
            ox.next = 0
            oy.next = 0
        elif emit and (ecam or not stereo):
            if not x_last:
                ox.next = ox + 1
            else:
                ox.next = 0
                if y_last:
                    oy.next = 0
                else:
                    oy.next = oy + 1

    insts += [counters, edges, raster]

    # Border flags of the emitted pixel: row k of the window (dy = k - r) lies inside the image when
    # 0 <= y + dy <= height - 1, column k (dx = k - r) when 0 <= x + dx <= width - 1. Registered with
    # the control, then delayed to the window rows; the centre row and column are always inside.
    for k in range(n):
        if k != r:
            insts.append(inside_flag(clk, oy, k - r, height, row_ok[k], clocks=tap_latency(n)))
            insts.append(inside_flag(clk, ox, k - r, width, col_ok[k], clocks=tap_latency(n)))
    flags = [(o_valid, source.valid), (o_eol, source.eol), (o_eof, source.eof)]
    flags += [(o_cam, source.cam)] if stereo else []
    for a, b in flags:
        insts.append(delay_rst(clk, rst, a, b, clocks=latency - 2))
    return insts


@block
def inside_flag(clk, pos, offset: int, size: int, ok, *, clocks: int):
    """``ok`` = (0 <= pos + offset <= size - 1), registered, then ``clocks`` clocks later (read in the
    clock a pixel is emitted, ``pos`` is that pixel's position)."""
    lo, hi = max(0, -offset), size - 1 - max(0, offset)
    now = Signal(bool(0))

    @always(clk.posedge)
    def flag():
        now.next = lo <= pos and pos <= hi

    return flag, delay(clk, now, ok, clocks=clocks)

