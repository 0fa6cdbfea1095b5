"""Stereo Harris window: Ix^2, Iy^2, IxIy of both cameras, time-shared multipliers, shared line delays."""

from myhdl import Signal, always, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.common import range_signal, shift_add
from eyestereo.hdl.common.checks import check_clock, check_distinct, check_frame, check_int, check_reset, check_stream
from eyestereo.hdl.common.fixed import fx_signal
from eyestereo.hdl.common.packed import pack_word, unpack_word
from eyestereo.hdl.common.registers import delay, delay_rst
from eyestereo.hdl.common.stereo_window import pair_chain, pair_regs, stereo_column_taps, stereo_window_control
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.tools.fixed import sfix
from eyestereo.tools.models import harris_window as model
from eyestereo.tools.models import sobel as sobel_model

N = 5


def multipliers(share: int) -> int:
    """Multipliers of the product stage: 3 products in ``share`` clocks."""
    return -(-3 // share)


def product_latency(share: int) -> int:
    """Clocks from a Sobel beat to its product word: 1 operand register + one clock per phase."""
    return 1 + -(-3 // multipliers(share))


def latency(share: int) -> int:
    return product_latency(share) + N + 2


@block
def harris_window_stereo(clk, rst, sink, source, *, width: int = 352, height: int = 288, share: int = 1):
    """:func:`~eyestereo.hdl.harris.harris_window.harris_window` of each camera of a stereo stream.

    The three products of a beat are formed by ``3 / share`` multipliers (rounded up) over as many
    clocks as they need: share 1 three multipliers in one clock, share 2 two (Ix^2 and Iy^2, then
    IxIy), share 3 one (Ix^2, Iy^2, IxIy in three clocks, thesis Fig. 6.15). The operands are the
    midpoints 2c + 1 of the Sobel codes; each product is rounded by 32 into 12 bits (a Sobel code cannot
    reach the 12-bit limits, so the mono block's clamps are left out: same results). The 36-bit product
    words go through four stereo line delays (2 x width words each), the 5x5 sums through doubled
    horizontal register chains.

    Ports:
        clk, rst: clock and synchronous active-high reset (control only).
        sink: stereo ImageStream, 18 bits (Sobel words of 8-bit images, from ``sobel_stereo``); beats at
            least ``share`` clocks apart.
        source: stereo ImageStream, 57 bits (Sxy | Syy | Sxx as from ``harris_window``).

    Parameters:
        width, height: frame size, each 5..4096.
        share: 1, 2 or 3.

    Latency: :func:`latency` (share 1: 9, share 2: 10, share 3: 11) clocks after the camera's input
    pixel (x + 2, y + 2).

    Resources: 3 / 2 / 1 multipliers (10x10); 4 stereo line delays of 36 bits (8 RAMB16 at width 352).
    """
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, width=sobel_model.WORD.width, stereo=True)
    check_stream("source", source, width=model.OUT_BITS, stereo=True)
    check_distinct(dict(source=source), dict(clk=clk, rst=rst, sink=sink))
    width, height = check_frame(width, height, min_size=N)
    share = check_int("share", share, 1, 3)
    m = multipliers(share)
    lp = product_latency(share)

    opx = fx_signal(sfix(10))  # 2 Ix + 1, held for the phases
    opy = fx_signal(sfix(10))
    xh, xl = sobel_model.WORD.bits("ix")
    yh, yl = sobel_model.WORD.bits("iy")

    @always(clk.posedge)
    def operands():
        if sink.valid:
            opx.next = concat(sink.data[xh:xl], True)
            opy.next = concat(sink.data[yh:yl], True)

    # Phase flags: the beat's valid 1, 2, 3 clocks later (beats come at least share clocks apart, so at
    # most one is high at a time).
    ph = [Signal(bool(0)) for _ in range(3)]

    @always_seq(clk.posedge, reset=rst)
    def phases():
        ph[0].next = sink.valid
        ph[1].next = ph[0]
        ph[2].next = ph[1]

    big = 511 * 511
    qxx, qyy = fx_signal(model.PROD_SQ), fx_signal(model.PROD_SQ)
    qxy = fx_signal(model.PROD_XY)
    insts = [operands, phases]
    p0, p1, p2 = ph
    if m == 3:
        fxx, fyy, fxy = range_signal(0, big + 16), range_signal(0, big + 16), range_signal(-big + 16, big + 16)

        @always_comb
        def multiply():
            fxx.next = opx * opx + 16
            fyy.next = opy * opy + 16
            fxy.next = opx * opy + 16

        @always(clk.posedge)
        def cut():
            qxx.next = fxx >> 5
            qyy.next = fyy >> 5
            qxy.next = fxy >> 5

        insts += [multiply, cut]
    elif m == 2:
        b0 = fx_signal(sfix(10))
        f0, f1 = range_signal(-big + 16, big + 16), range_signal(0, big + 16)
        s0 = range_signal((-big + 16) >> 5, (big + 16) >> 5)

        @always_comb
        def choose_operands():
            if p1:
                b0.next = opy
            else:
                b0.next = opx

        @always_comb
        def multiply():
            f0.next = opx * b0 + 16
            f1.next = opy * opy + 16
            s0.next = f0 >> 5

        @always(clk.posedge)
        def cut():
            if p0:
                qxx.next = s0
                qyy.next = f1 >> 5
            if p1:
                qxy.next = s0

        insts += [choose_operands, multiply, cut]
    else:
        a0, b0 = fx_signal(sfix(10)), fx_signal(sfix(10))
        f0 = range_signal(-big + 16, big + 16)
        s0 = range_signal((-big + 16) >> 5, (big + 16) >> 5)

        @always_comb
        def choose_operands():
            if p1:
                a0.next = opy
            else:
                a0.next = opx
            if p0:
                b0.next = opx
            else:
                b0.next = opy

        @always_comb
        def multiply():
            f0.next = a0 * b0 + 16
            s0.next = f0 >> 5

        @always(clk.posedge)
        def cut():
            if p0:
                qxx.next = s0
            if p1:
                qyy.next = s0
            if p2:
                qxy.next = s0

        insts += [choose_operands, multiply, cut]

    prod = ImageStream(model.PRODUCTS, stereo=True)
    insts.append(pack_word(prod.data, model.PRODUCTS, pxx=qxx, pyy=qyy, pxy=qxy))
    for s, d in ((sink.valid, prod.valid), (sink.eol, prod.eol), (sink.eof, prod.eof), (sink.cam, prod.cam)):
        insts.append(delay_rst(clk, rst, s, d, clocks=lp))

    taps = [Signal(intbv(0)[model.PACK_BITS:]) for _ in range(N)]
    tap_valid = Signal(bool(0))
    insts.append(stereo_column_taps(clk, rst, prod, taps, tap_valid, width=width, height=height))
    weights = [int(w) for w in model.TAPS]
    col_valid = Signal(bool(0))
    insts.append(delay(clk, tap_valid, col_valid, clocks=1))
    sums = []
    for product in model.PRODUCTS.fields:
        fmt = product.fmt
        fields_i = [fx_signal(fmt) for _ in range(N)]
        for tap, f in zip(taps, fields_i):
            insts.append(unpack_word(tap, model.PRODUCTS, **{product.name: f}))
        vlo = fmt.lo * sum(weights)
        vhi = fmt.hi * sum(weights)
        vsum, vreg = range_signal(vlo, vhi), range_signal(vlo, vhi)
        insts += [shift_add(list(zip(fields_i, weights)), vsum), delay(clk, vsum, vreg, clocks=1)]
        regs = pair_regs(vreg, N)
        insts.append(pair_chain(clk, col_valid, vreg, regs))
        row = regs[0::2]
        total = fx_signal(model.SUM_XY if fmt.signed else model.SUM_SQ)
        insts.append(shift_add(list(zip(row, weights)), total))
        sums.append(total)
    sxx, syy, sxy = sums
    out_word = Signal(intbv(0)[model.WORD.width:])

    @always(clk.posedge)
    def outreg():
        source.data.next = out_word

    insts += [pack_word(out_word, model.WORD, sxx=sxx, syy=syy, sxy=sxy), outreg,
              stereo_window_control(clk, rst, prod, source, width=width, height=height, radius=N // 2,
                                    latency=N + 2, share=share)]
    return insts
