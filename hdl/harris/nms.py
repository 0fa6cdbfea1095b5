"""Non-maximum suppression 1x1 / 3x3 / 5x5, separable, with a raster-order tie rule (thesis Fig. 6.13)."""

from myhdl import Signal, always, always_comb, always_seq, block, intbv

from eyestereo.hdl.common.fixed import fx_signal
from eyestereo.hdl.common import assign, column_taps, delay, en_reg, window_control
from eyestereo.tools.models import cornerness as corner_model
from eyestereo.hdl.common.checks import (check_choice, check_clock, check_distinct, check_frame, check_reset,
                                         check_stream)

SIZES = (1, 3, 5)


@block
def nms(clk, rst, sink, source, *, width: int = 352, height: int = 288, size: int = 3):
    """``source`` = 1 where the value is > 0 and beats every other value of the size x size window.

    "Beats" is the tie rule: strictly greater than the neighbours before the centre in raster order
    (rows above, and to the left on its row), greater or equal to those after it. A plateau of equal
    values that fits in the window therefore yields exactly one feature, its first pixel in raster
    order. Separable form: the vertical pass reduces each incoming column to (max of the rows above,
    the centre row, max of the rows below); the horizontal pass keeps ``size`` such triples and compares
    them with the centre, with the rule above for columns left of, at and right of it. Border pixels
    (within size // 2 of the edge) carry unspecified flags.

    Ports:
        clk, rst: clock and synchronous active-high reset (control only).
        sink: ImageStream, 20 bits, two's complement (the pre-thresholded cornerness); mono only (a
            stereo stream is refused).
        source: ImageStream, 1 bit: the feature flag.

    Parameters:
        width, height: frame size, each at least ``size``.
        size: 1, 3 or 5.

    Latency: size 1: 1 clock. Size N = 3, 5: N + 2 clocks after input pixel (x + r, y + r), r = N // 2.

    Resources: N - 1 line delays of 20 bits (one RAMB16 each), 3N registers of 20 bits, 3N - 1 comparators.
    """
    nb = corner_model.OUT.wl
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, width=nb)
    check_stream("source", source, width=1)
    check_distinct(dict(source=source), dict(clk=clk, rst=rst, sink=sink))
    size = check_choice("size", size, SIZES)
    width, height = check_frame(width, height, min_size=size)

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

        return value, flag

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

    # Horizontal pass: index 0 is the newest column, dx = +r (right of the centre).
    cols = []
    for _ in range(size):
        cols.append(tuple(fx_signal(corner_model.OUT) for _ in range(3)))
    for j, regs in enumerate(cols):
        srcs = (up, mid, down) if j == 0 else cols[j - 1]
        for s, d in zip(srcs, regs):
            insts.append(en_reg(clk, col_valid, s, d))
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
                                     latency=size + 2)]
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
