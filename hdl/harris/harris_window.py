"""Harris window function: Ix^2, Iy^2, IxIy summed over a separable 5x5 [1 2 4 2 1]^2 window (thesis 6.2.2,
Fig. 6.15)."""

from myhdl import Signal, always, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.common import delay, delay_rst, en_reg, range_signal, shift_add
from eyestereo.hdl.common.checks import check_clock, check_distinct, check_frame, check_reset, check_stream
from eyestereo.hdl.common.fixed import fx_signal
from eyestereo.hdl.common.packed import pack_word, unpack_word
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.hdl.streaming.window import check_share, column_taps, window_control, window_row
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH
from eyestereo.tools.fixed import sfix
from eyestereo.tools.models import harris_window as model
from eyestereo.tools.models import sobel as sobel_model

N = 5
LATENCY = 8  # mono: 1 product stage + the window's N + 2


def multipliers(share: int = 1) -> int:
    """Multipliers of the product stage: 3 products in ``share`` clocks (mono streams: share 1, 3)."""
    return -(-3 // share)


def product_latency(share: int = 1, *, stereo: bool = False) -> int:
    """Clocks from a Sobel beat to its product word: mono 1; stereo 1 operand register + one clock per
    phase."""
    return 1 + -(-3 // multipliers(share)) if stereo else 1


def latency(share: int = 1, *, stereo: bool = False) -> int:
    """Clocks from the (camera's) input pixel (x + 2, y + 2) to output pixel (x, y): mono 8 (:data:`LATENCY`);
    stereo 9, 10, 11 for share 1, 2, 3."""
    return product_latency(share, stereo=stereo) + N + 2


@block
def harris_window(clk, rst, sink, source, *, width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT, share: int = 1):
    """Structure-tensor sums: ``source`` pixel (x, y) = (Sxy, Syy, Sxx) over the 5x5 window centred on (x, y).

    Each incoming (Ix, Iy) pair is squared and multiplied first (3 multipliers of 10 x 10 bits: each
    code c enters as 2c + 1, the midpoint of the gradients it stands for), each product rounded by 32
    and saturated to 12 bits (ufix[12,-9], ufix[12,-9], sfix[12,-9]; Sobel codes never saturate), and
    the three are packed into one 36-bit word, so a single set of four line delays (one RAMB16
    each) carries them. The separable weighted sum [1 2 4 2 1] x [1 2 4 2 1] runs by shifts and adds
    on the unpacked taps; its "/128" is a move of the binary point, so no bit is dropped: Sxx, Syy are
    ufix[19,-2], Sxy sfix[19,-2]. Pixels within 2 of the border carry unspecified data.

    A stereo stream (left and right beat of each (x, y) in turn, at least ``share`` clocks apart) is
    processed camera by camera in one datapath (:func:`stereo_products`): the three products of a beat are
    formed by ``3 / share`` multipliers (rounded up) over as many clocks as they need, from registered
    operands (share 1: three multipliers, share 2: two, share 3: one), without the clamps (a Sobel code
    cannot reach the 12-bit limits: same results). The line delays are stereo line delays (2 x width
    words each), and the 5x5 sums read doubled horizontal register chains.

    Ports:
        clk, rst: clock and synchronous active-high reset (control only).
        sink: ImageStream, 18 bits, mono or stereo: Iy in bits 17..9, Ix in 8..0 (sfix[9,-3] codes, as
            from ``sobel``).
        source: ImageStream of the sink's kind, 57 bits: Sxy in 56..38 (two's complement), Syy in 37..19,
            Sxx in 18..0.

    Parameters:
        width, height: frame size, each 5..4096.
        share: stereo streams only (1 for a mono one, else a ValueError): 1, 2 or 3 clocks per beat the
            product multipliers are shared over.

    Latency: 8 clocks after input pixel (x + 2, y + 2): 2 lines + 2 pixels + 8 clocks. Stereo:
    :func:`latency` clocks (9, 10, 11 for share 1, 2, 3) after the camera's input pixel (x + 2, y + 2).

    Resources: 3 multipliers (10x10; stereo :func:`multipliers`: 3 / 2 / 1), 4 line delays of 36 bits
    (4 RAMB16; stereo 8 RAMB16 at width 352), adders and registers.
    """
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, width=sobel_model.WORD.width, stereo=None)
    check_stream("source", source, width=model.OUT_BITS, stereo=sink.stereo)
    check_distinct(dict(source=source), dict(clk=clk, rst=rst, sink=sink))
    width, height = check_frame(width, height, min_size=N)
    share = check_share(share, sink)

    if sink.stereo:
        prod = ImageStream(model.PRODUCTS, stereo=True)
        insts = [stereo_products(clk, rst, sink, prod, share=share)]
    else:
        mx = fx_signal(sfix(10))  # 2 Ix + 1
        my = fx_signal(sfix(10))
        big = 511 * 511
        fxx, fyy, fxy = range_signal(0, big + 16), range_signal(0, big + 16), range_signal(-big + 16, big + 16)
        qxx, qyy = fx_signal(model.PROD_SQ), fx_signal(model.PROD_SQ)
        qxy = fx_signal(model.PROD_XY)
        sq_top = model.PROD_SQ.hi
        xy_lo, xy_hi = model.PROD_XY.lo, model.PROD_XY.hi

        # The midpoint 2c + 1 of each code: its bits with a 1 appended (the field positions of the Sobel word).
        xh, xl = sobel_model.WORD.bits("ix")
        yh, yl = sobel_model.WORD.bits("iy")

        @always_comb
        def fields():
            mx.next = concat(sink.data[xh:xl], True)
            my.next = concat(sink.data[yh:yl], True)

        # The +16 rounds the cut by 32 below; it rides on the multiplier's output adder.
        @always_comb
        def multiply():
            fxx.next = mx * mx + 16
            fyy.next = my * my + 16
            fxy.next = mx * my + 16

        # Only inputs outside the Sobel's range can reach the clamps.
        @always_comb
        def saturate():
            if (fxx >> 5) > sq_top:
                qxx.next = sq_top
            else:
                qxx.next = fxx >> 5
            if (fyy >> 5) > sq_top:
                qyy.next = sq_top
            else:
                qyy.next = fyy >> 5
            if (fxy >> 5) > xy_hi:
                qxy.next = xy_hi
            elif (fxy >> 5) < xy_lo:
                qxy.next = xy_lo
            else:
                qxy.next = fxy >> 5

        prod = ImageStream(model.PRODUCTS)
        prod_word = Signal(intbv(0)[model.PRODUCTS.width:])

        @always(clk.posedge)
        def pack():
            prod.data.next = prod_word

        @always_seq(clk.posedge, reset=rst)
        def flags():
            prod.valid.next = sink.valid
            prod.eol.next = sink.eol
            prod.eof.next = sink.eof

        insts = [fields, multiply, saturate, pack_word(prod_word, model.PRODUCTS, pxx=qxx, pyy=qyy, pxy=qxy), pack,
                 flags]

    taps = [Signal(intbv(0)[model.PACK_BITS:]) for _ in range(N)]
    tap_valid = Signal(bool(0))
    insts.append(column_taps(clk, rst, prod, taps, tap_valid, width=width, height=height))

    weights = [int(w) for w in model.TAPS]
    col_valid = Signal(bool(0))
    insts.append(delay(clk, tap_valid, col_valid, clocks=1))
    sums = []
    for product in model.PRODUCTS.fields:  # pxx, pyy, pxy: each summed over the window on its own
        fmt = product.fmt
        fields_i = [fx_signal(fmt) for _ in range(N)]
        for tap, f in zip(taps, fields_i):
            insts.append(unpack_word(tap, model.PRODUCTS, **{product.name: f}))
        vlo = fmt.lo * sum(weights)
        vhi = fmt.hi * sum(weights)
        vsum, vreg = range_signal(vlo, vhi), range_signal(vlo, vhi)
        insts += [shift_add(list(zip(fields_i, weights)), vsum), delay(clk, vsum, vreg, clocks=1)]
        links, row = window_row(vreg, N, stereo=sink.stereo)
        for src, reg in links:
            insts.append(en_reg(clk, col_valid, src, reg))
        total = fx_signal(model.SUM_XY if fmt.signed else model.SUM_SQ)
        insts.append(shift_add(list(zip(row, weights)), total))
        sums.append(total)
    sxx, syy, sxy = sums
    out_word = Signal(intbv(0)[model.WORD.width:])

    @always(clk.posedge)
    def outreg():
        source.data.next = out_word

    insts += [pack_word(out_word, model.WORD, sxx=sxx, syy=syy, sxy=sxy), outreg,
              window_control(clk, rst, prod, source, width=width, height=height, radius=N // 2, latency=N + 2,
                             share=share)]
    return insts


@block
def stereo_products(clk, rst, sink, prod, *, share: int):
    """:func:`harris_window`'s product stage for stereo streams: ``prod`` = the product word of each beat
    of ``sink`` (beats at least ``share`` clocks apart), :func:`product_latency` clocks later.

    The operands 2c + 1 are registered; ``3 / share`` multipliers (rounded up) form the three products
    over as many clocks as they need (thesis Fig. 6.15: share 3 uses one).
    """
    m = multipliers(share)
    lp = product_latency(share, stereo=True)

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

    insts.append(pack_word(prod.data, model.PRODUCTS, pxx=qxx, pyy=qyy, pxy=qxy))
    for s, d in ((sink.valid, prod.valid), (sink.eol, prod.eol), (sink.eof, prod.eof), (sink.cam, prod.cam)):
        insts.append(delay_rst(clk, rst, s, d, clocks=lp))
    return insts
