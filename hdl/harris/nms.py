"""Non-maximum suppression 1x1 / 3x3 / 5x5 with a raster-order tie rule, mono or stereo (thesis Fig. 6.13)."""

from myhdl import Signal, always, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.common.checks import (check_choice, check_clock, check_distinct, check_frame, check_reset,
                                         check_stream)
from eyestereo.hdl.common.fixed import fx_signal
from eyestereo.hdl.common.registers import assign, delay, en_reg
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.hdl.streaming.line_delay import line_delay
from eyestereo.hdl.streaming.window import check_share, column_taps, tap_latency, window_control, window_row
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH, NMS_DEFAULT, NMS_SIZES
from eyestereo.tools.models import cornerness as corner_model


def stereo_latency(size: int) -> int:
    """Stereo streams: clocks from the input beat that completes a flag's window to the flag (see
    :func:`stereo_lead`)."""
    return {1: 1, 3: 3, 5: 8}[size]


def stereo_lead(size: int) -> tuple[int, int]:
    """Stereo streams: (lines, pixels), flag (x, y) is computed at the camera's input beat of pixel
    (x + pixels, y + lines)."""
    return {1: (0, 0), 3: (1, 2), 5: (2, 2)}[size]


@block
def nms(clk, rst, sink, source, *, width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT, size: int = NMS_DEFAULT,
        share: int = 1):
    """``source`` = 1 where the value is > 0 and beats every other value of the size x size window.

    "Beats" is the tie rule: strictly greater than the neighbours before the centre in raster order
    (rows above, and to the left on its row), greater or equal to those after it. A plateau of equal
    values that fits in the window therefore yields exactly one feature, its first pixel in raster
    order. Separable form: the vertical pass reduces each incoming column to (max of the rows above,
    the centre row, max of the rows below); the horizontal pass keeps ``size`` such triples and compares
    them with the centre, with the rule above for columns left of, at and right of it. Border pixels
    (within size // 2 of the edge) carry unspecified flags.

    The camera count comes from the stream. On a stereo stream (left and right beat of each pixel in
    turn, ``cam`` forwarded) each camera gets the same flags as alone, in one datapath: size 5 runs the
    separable form on stereo line delays (2 x width words), its horizontal pass keeping 2 size - 1
    triples (left and right in turn) and comparing the centre with every other one; size 3 uses one
    line delay that carries each row's "beats the row above" flags (:func:`nms3_one_delay`).

    Ports:
        clk, rst: clock and synchronous active-high reset (control only).
        sink: ImageStream, 20 bits, two's complement (the pre-thresholded cornerness); mono or stereo.
        source: ImageStream, 1 bit: the feature flag; the sink's kind.

    Parameters:
        width, height: frame size, each at least ``size``.
        size: 1, 3 or 5.
        share: stereo streams only (1, 2 or 3): the tail after each frame is emitted one beat every
            ``share`` clocks (the Harris chain's beat spacing). A mono stream has no tail spacing: any
            share but 1 is refused there.

    Latency: mono: size 1: 1 clock; size N = 3, 5: N + 3 clocks after input pixel (x + r, y + r),
    r = N // 2 (the column taps N, the vertical pass 1, the window row 1, the output register 1). Stereo:
    :func:`stereo_latency` clocks after the camera's input pixel :func:`stereo_lead` (size 1: the pixel
    itself, 1 clock; 3: (x + 2, y + 1), 3 clocks; 5: (x + 2, y + 2), 8 clocks).

    Resources: mono: N - 1 line delays of 20 bits (one RAMB16 each), 3N registers of 20 bits, 3N - 1
    comparators. Stereo: size 3: one stereo line delay of 20 bits (2 RAMB16 at width 352); size 5:
    4 stereo line delays of 20 bits, 3 x 9 registers of 20 bits, 14 comparators.
    """
    nb = corner_model.OUT.wl
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, width=nb, stereo=None)
    check_stream("source", source, width=1, stereo=sink.stereo)
    check_distinct(dict(source=source), dict(clk=clk, rst=rst, sink=sink))
    size = check_choice("size", size, NMS_SIZES)
    width, height = check_frame(width, height, min_size=size)
    share = check_share(share, sink)

    if size == 1:
        v = fx_signal(corner_model.OUT)

        @always_comb
        def value():
            v.next = sink.data

        @always_seq(clk.posedge, reset=rst)
        def flag():
            source.valid.next = sink.valid
            source.eol.next = sink.eol
            source.eof.next = sink.eof
            source.data.next = v > 0

        if not sink.stereo:
            return value, flag

        @always_seq(clk.posedge, reset=rst)
        def camera():
            source.cam.next = sink.cam

        return value, flag, camera

    if size == 3 and sink.stereo:
        return nms3_one_delay(clk, rst, sink, source, width=width, height=height, share=share)
    r = size // 2
    taps = [Signal(intbv(0)[nb:]) for _ in range(size)]
    tap_valid = Signal(bool(0))
    insts = [column_taps(clk, rst, sink, taps, tap_valid, width=width, height=height)]
    st = [fx_signal(corner_model.OUT) for _ in range(size)]
    for tap, s in zip(taps, st):
        insts.append(assign(tap, s))  # reinterpret the bits as signed

    # Vertical pass (registered): rows above the centre, the centre row, rows below.
    up_c, down_c = fx_signal(corner_model.OUT), fx_signal(corner_model.OUT)
    insts += [maximum(st[:r], up_c), maximum(st[r + 1:], down_c)]
    up, mid, down = (fx_signal(corner_model.OUT) for _ in range(3))
    col_valid = Signal(bool(0))
    insts += [delay(clk, up_c, up, clocks=1), delay(clk, st[r], mid, clocks=1),
              delay(clk, down_c, down, clocks=1), delay(clk, tap_valid, col_valid, clocks=1)]

    # Horizontal pass: three window rows of column values (above, centre, below); index 0 is the newest
    # column, dx = +r (right of the centre). The registers are made column by column, as before the fold
    # (the instance names, and so the mono HDL, stay as they were).
    rows = [window_row(first, size, stereo=sink.stereo) for first in (up, mid, down)]
    for j in range(len(rows[0][0])):
        for links, _ in rows:
            insts.append(en_reg(clk, col_valid, *links[j]))
    cols = list(zip(*(row for _, row in rows)))
    centre = cols[r][1]
    oks = []
    for j, (u, m, d) in enumerate(cols):
        ok = Signal(bool(0))
        dx = r - j
        insts.append(beats(centre, u, m, d, ok, dx=dx))
        oks.append(ok)
    pos = Signal(bool(0))

    @always_comb
    def positive():
        pos.next = centre > 0

    result = Signal(bool(0))
    insts += [positive, all_of(oks + [pos], result)]

    @always(clk.posedge)
    def outreg():
        source.data.next = result

    insts += [outreg, window_control(clk, rst, sink, source, width=width, height=height, radius=r,
                                     latency=tap_latency(size) + 3, share=share)]
    return insts


@block
def maximum(ins, out):
    """Combinational max of 1 or 2 signals (the vertical half-columns of a 3 or 5 window)."""
    if len(ins) == 1:
        a = ins[0]

        @always_comb
        def one():
            out.next = a

        return one
    if len(ins) != 2:
        raise ValueError("maximum takes 1 or 2 inputs")
    a, b = ins

    @always_comb
    def two():
        if a > b:
            out.next = a
        else:
            out.next = b

    return two


@block
def beats(c, u, m, d, ok, *, dx: int):
    """Does centre value c beat column (u above, m on the centre row, d below) at offset dx?"""
    if dx < 0:  # left: the centre row precedes the centre
        @always_comb
        def left():
            ok.next = c > u and c > m and c >= d

        return left
    if dx == 0:
        @always_comb
        def centre():
            ok.next = c > u and c >= d

        return centre

    @always_comb
    def right():
        ok.next = c > u and c >= m and c >= d

    return right


@block
def all_of(flags, out):
    """out = AND of a list of 1-bit signals, as a chain of 2-input gates."""
    insts = []
    acc = flags[0]
    for f in flags[1:]:
        nxt = Signal(bool(0))
        insts.append(and2(acc, f, nxt))
        acc = nxt
    insts.append(assign(acc, out))
    return insts


@block
def and2(a, b, y):
    @always_comb
    def gate():
        y.next = a and b

    return gate


@block
def nms3_one_delay(clk, rst, sink, source, *, width: int, height: int, share: int):
    """3x3 NMS with a single stereo line delay: each row's words carry the "beats the row above" flags.

    Negative values are clamped to 0 first (a centre must be > 0 to be a feature, and a neighbour <= 0
    loses to any positive centre under both > and >=, so no flag changes); that leaves 19 bits. For each
    pixel (x, y) the flag A(x, y) = v(x, y) > each of v(x-1..x+1, y-1) (the strict rule for the rows
    above) is formed when row y passes the line delay's output, and stored with the row: the word of
    column x holds v(x, y) and A(x - 2, y) (A of a pixel is known two pixels late). One row later the
    line delay returns both, and flag (x, y) is decided at the input beat of (x + 2, y + 1): A(x, y),
    v(x, y) > v(x - 1, y), >= v(x + 1, y), >= each of v(x-1..x+1, y+1), > 0. One 20-bit stereo line
    delay (2 RAMB16 at width 352) instead of two.

    Unspecified besides the border: flags within 2 pixels of the right edge (their decision beat would
    fall in the next row) -- inside harris_stereo's border of 4 pixels.
    """
    vb = corner_model.OUT.wl - 1  # 19 bits: the value clamped at 0
    v = fx_signal(corner_model.OUT)
    vc = Signal(intbv(0)[vb:])

    @always_comb
    def clamp():
        v.next = sink.data
        if v > 0:
            vc.next = v[vb:]
        else:
            vc.next = 0

    # The line delay's word: A field (bit vb) | value.
    a_in = Signal(bool(0))
    ld_in = ImageStream(vb + 1, stereo=True)
    ld_out = ImageStream(vb + 1, stereo=True)

    @always_comb
    def ld_word():
        ld_in.data.next = concat(a_in, vc)
        ld_in.valid.next = sink.valid
        ld_in.eol.next = sink.eol
        ld_in.eof.next = sink.eof
        ld_in.cam.next = sink.cam

    insts = [clamp, ld_word, line_delay(clk, rst, ld_in, ld_out, width=width, height=height)]

    # Beat strobes: b1 = the beat one clock later (line delay output valid), cam with it.
    pix = Signal(bool(0))
    b1, c1, b2, c2 = Signal(bool(0)), Signal(bool(0)), Signal(bool(0)), Signal(bool(0))

    @always_comb
    def decode():
        pix.next = sink.valid and (sink.eol or not sink.eof)

    @always_seq(clk.posedge, reset=rst)
    def strobes():
        b1.next = pix
        c1.next = sink.cam
        b2.next = b1
        c2.next = c1

    vreg = Signal(intbv(0)[vb:])
    above_raw = Signal(intbv(0)[vb:])
    a_d = Signal(bool(0))

    @always(clk.posedge)
    def capture():
        if pix:
            vreg.next = vc

    @always_comb
    def unpack():
        above_raw.next = ld_out.data[vb:]
        a_d.next = ld_out.data[vb]

    # Per-camera chains, shifted one clock after the beat: cur = this row, prv = the row above (from the
    # line delay), index j = j pixels back of the beat's camera.
    cur_links, cur = window_row(vreg, 4, stereo=True)
    prv_links, prv = window_row(above_raw, 4, stereo=True)
    insts += [decode, strobes, capture, unpack]
    insts += [en_reg(clk, b1, d, q) for d, q in cur_links + prv_links]
    aflag = Signal(bool(0))  # A(x-2, y) of the beat

    @always(clk.posedge)
    def a_shift():
        if b1:
            aflag.next = a_d

    # Decide flag (x-2, y) for the beat (x, y+1): centre prv[2].
    c = prv[2]
    result = Signal(bool(0))

    @always_comb
    def decide():
        result.next = (aflag and c > prv[3] and c >= prv[1] and c >= cur[3] and c >= cur[2] and c >= cur[1]
                       and c > 0)

    # A(x-1, y+1) for the next beat of the camera: cur[1] against prv[2], prv[1], prv[0]. Only prv[0]
    # comes from the line delay in the clock before; the two other comparisons are made a clock earlier,
    # on the registers the chains shift into cur[1], prv[1], prv[2] (a_pre), so that the path into the
    # line delay's write holds one comparator.
    # (single names, not a list: MyHDL converts no signal that is in two lists)
    cur_q1, prv_q1, prv_q3 = cur_links[1][1], prv_links[1][1], prv_links[3][1]
    a_pre = Signal(bool(0))
    a_new = Signal(bool(0))
    a_hold = [Signal(bool(0)) for _ in range(2)]

    @always(clk.posedge)
    def above_early():
        a_pre.next = cur_q1 > prv_q3 and cur_q1 > prv_q1

    @always_comb
    def above():
        a_new.next = a_pre and cur[1] > prv[0]

    @always(clk.posedge)
    def hold():
        if b2:
            if c2:
                a_hold[1].next = a_new
            else:
                a_hold[0].next = a_new

    @always_comb
    def bypass():
        if b2 and c2 == sink.cam:
            a_in.next = a_new
        elif sink.cam:
            a_in.next = a_hold[1]
        else:
            a_in.next = a_hold[0]

    @always(clk.posedge)
    def outreg():
        source.data.next = result

    insts += [a_shift, decide, above_early, above, hold, bypass, outreg,
              window_control(clk, rst, sink, source, width=width, height=height, radius=1, latency=3, share=share,
                             lead_pixels=width + 2)]
    return insts
