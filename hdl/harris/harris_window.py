"""Harris window function: Ix^2, Iy^2, IxIy summed over a separable 5x5 [1 2 4 2 1]^2 window (thesis 6.2.2,
Fig. 6.15)."""

from myhdl import Signal, always, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.common import delay, delay_rst, en_reg, range_signal, shift_add, signal_range
from eyestereo.hdl.common.arith import chain_sum
from eyestereo.hdl.common.checks import check_clock, check_distinct, check_frame, check_reset, check_stream
from eyestereo.hdl.common.fixed import fx_signal
from eyestereo.hdl.common.packed import pack_word, unpack_word
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.hdl.streaming.window import check_share, column_taps, tap_latency, window_control, window_row
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH
from eyestereo.tools.fixed import sfix
from eyestereo.tools.models import harris_window as model
from eyestereo.tools.models import sobel as sobel_model

N = 5
LATENCY = 10  # mono: 2 product stages + the window's tap_latency(N) + 3


def multipliers(share: int = 1) -> int:
    """Multipliers of the product stage: 3 products in ``share`` clocks (mono streams: share 1, 3)."""
    return -(-3 // share)


def product_latency(share: int = 1, *, stereo: bool = False) -> int:
    """Clocks from a Sobel beat to its product word: mono 2 (product register, rounding and clamps);
    stereo 2 + one clock per phase (operand register, one product register per phase, rounding)."""
    return 2 + -(-3 // multipliers(share)) if stereo else 2


def latency(share: int = 1, *, stereo: bool = False) -> int:
    """Clocks from the (camera's) input pixel (x + 2, y + 2) to output pixel (x, y): mono 10
    (:data:`LATENCY`); stereo 11, 12, 13 for share 1, 2, 3."""
    return product_latency(share, stereo=stereo) + tap_latency(N) + 3


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

    Latency: 10 clocks after input pixel (x + 2, y + 2): 2 lines + 2 pixels + 10 clocks (the products 2,
    the column taps 5, the vertical sums 1, the window row 1, the output register 1). Stereo:
    :func:`latency` clocks (11, 12, 13 for share 1, 2, 3) after the camera's input pixel (x + 2, y + 2).

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
        fxx, fyy, fxy = range_signal(0, big), range_signal(0, big), range_signal(-big, big)
        cxx, cyy, cxy = cut_signal(), cut_signal(), cut_signal()
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

        # The multipliers read the sink's register (the Sobel's output register) and write their own: a
        # multiplier with the rounding and the clamps behind it would not fit a 110 MHz clock.
        @always(clk.posedge)
        def multiply():
            fxx.next = mx * mx
            fyy.next = my * my
            fxy.next = mx * my

        # Only inputs outside the Sobel's range can reach the clamps.
        @always_comb
        def saturate():
            if cxx > sq_top:
                qxx.next = sq_top
            else:
                qxx.next = cxx
            if cyy > sq_top:
                qyy.next = sq_top
            else:
                qyy.next = cyy
            if cxy > xy_hi:
                qxy.next = xy_hi
            elif cxy < xy_lo:
                qxy.next = xy_lo
            else:
                qxy.next = cxy

        prod = ImageStream(model.PRODUCTS)
        prod_word = Signal(intbv(0)[model.PRODUCTS.width:])

        @always(clk.posedge)
        def pack():
            prod.data.next = prod_word

        insts = [fields, multiply, rounding(fxx, cxx), rounding(fyy, cyy), rounding(fxy, cxy), saturate,
                 pack_word(prod_word, model.PRODUCTS, pxx=qxx, pyy=qyy, pxy=qxy), pack]
        for s, d in ((sink.valid, prod.valid), (sink.eol, prod.eol), (sink.eof, prod.eof)):
            insts.append(delay_rst(clk, rst, s, d, clocks=product_latency()))

    taps = [Signal(intbv(0)[model.PACK_BITS:]) for _ in range(N)]
    tap_valid = Signal(bool(0))
    # Skewed taps and a chain of adders: the 36-bit words do not wait for the oldest row, the partial
    # sums do (fewer registers; the vertical sums come tap_latency(N) + 1 clocks after the beat either way).
    insts.append(column_taps(clk, rst, prod, taps, tap_valid, width=width, height=height, skew=True))

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
        vreg = range_signal(vlo, vhi)
        insts.append(chain_sum(clk, list(zip(fields_i, weights))[::-1], vreg))  # the newest row first
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
              window_control(clk, rst, prod, source, width=width, height=height, radius=N // 2,
                             latency=tap_latency(N) + 3, share=share)]
    return insts


@block
def stereo_products(clk, rst, sink, prod, *, share: int):
    """:func:`harris_window`'s product stage for stereo streams: ``prod`` = the product word of each beat
    of ``sink`` (beats at least ``share`` clocks apart), :func:`product_latency` clocks later.

    ``3 / share`` multipliers (rounded up) form the three products over as many clocks (phases) as they
    need (thesis Fig. 6.15: share 3 uses one). Each multiplier is registered on both sides: its operands
    2c + 1 come from registers loaded with the phase's pair (the sink's fields at the beat, the held
    copies after it), its product goes into a register; the rounding cut of the next clock writes the
    phase's field of the product word. With three multipliers (share 1) each has operand registers of
    its own (x * y reads the negated pair), so that none is shared by two multipliers.
    """
    m = multipliers(share)
    phases = -(-3 // m)
    lp = product_latency(share, stereo=True)

    xh, xl = sobel_model.WORD.bits("ix")
    yh, yl = sobel_model.WORD.bits("iy")
    sx = fx_signal(sfix(10))  # 2 Ix + 1 of the sink's beat
    sy = fx_signal(sfix(10))
    opx = fx_signal(sfix(10))  # the same, held for the later phases
    opy = fx_signal(sfix(10))

    @always_comb
    def fields():
        sx.next = concat(sink.data[xh:xl], True)
        sy.next = concat(sink.data[yh:yl], True)

    @always(clk.posedge)
    def hold():
        if sink.valid:
            opx.next = sx
            opy.next = sy

    # Phase flags: the beat's valid 1 .. phases + 1 clocks later (beats come at least share clocks apart,
    # so at most one is high at a time). Phase j's operands are in their registers while ph[j - 1] is
    # high (ph[-1]: the beat itself), its product while ph[j] is high.
    ph = [Signal(bool(0)) for _ in range(phases + 1)]

    @always_seq(clk.posedge, reset=rst)
    def phase_flags():
        ph[0].next = sink.valid
        for j in range(1, phases + 1):
            ph[j].next = ph[j - 1]

    big = 511 * 511
    qxx, qyy = fx_signal(model.PROD_SQ), fx_signal(model.PROD_SQ)
    qxy = fx_signal(model.PROD_XY)
    insts = [fields, hold, phase_flags]
    if m == 3:
        # One phase. Each multiplier has operand registers of its own, so that the placer can put each
        # beside its multiplier: the squares read the held operands, x * y reads a negated pair,
        # -(2c + 1) = 2 ~c + 1 (the code's bits inverted, a 1 appended; (-x) (-y) = x y). Being
        # different bits, the pair is not merged with the held operands by the synthesis.
        fxx, fyy, fxy = range_signal(0, big), range_signal(0, big), range_signal(-big, big)
        nx = fx_signal(sfix(10))  # -(2 Ix + 1)
        ny = fx_signal(sfix(10))
        sink_nx = fx_signal(sfix(10))
        sink_ny = fx_signal(sfix(10))

        @always_comb
        def negated():
            sink_nx.next = concat(~sink.data[xh:xl], True)
            sink_ny.next = concat(~sink.data[yh:yl], True)

        @always(clk.posedge)
        def hold_negated():
            if sink.valid:
                nx.next = sink_nx
                ny.next = sink_ny

        @always(clk.posedge)
        def multiply():
            fxx.next = opx * opx
            fyy.next = opy * opy
            fxy.next = nx * ny

        sxx, syy, sxy = cut_signal(), cut_signal(), cut_signal()

        @always(clk.posedge)
        def cut():
            qxx.next = sxx
            qyy.next = syy
            qxy.next = sxy

        insts += [negated, hold_negated, multiply, rounding(fxx, sxx), rounding(fyy, syy), rounding(fxy, sxy), cut]
    elif m == 2:
        # Multiplier 0: x * x, then x * y (the operand register b0 takes x at the beat, y after it);
        # multiplier 1: y * y on the held operand.
        b0 = fx_signal(sfix(10))
        f0, f1 = range_signal(-big, big), range_signal(0, big)
        p0, p1, p2 = ph

        @always(clk.posedge)
        def operands():
            if sink.valid:
                b0.next = sx
            elif p0:
                b0.next = opy

        @always(clk.posedge)
        def multiply():
            f0.next = opx * b0
            f1.next = opy * opy

        s0, s1 = cut_signal(), cut_signal()

        @always(clk.posedge)
        def cut():
            if p1:
                qxx.next = s0
                qyy.next = s1
            if p2:
                qxy.next = s0

        insts += [operands, multiply, rounding(f0, s0), rounding(f1, s1), cut]
    else:
        # One multiplier: x * x, y * y, x * y in turn.
        a0, b0 = fx_signal(sfix(10)), fx_signal(sfix(10))
        f0 = range_signal(-big, big)
        p0, p1, p2, p3 = ph

        @always(clk.posedge)
        def operands():
            if sink.valid:
                a0.next = sx
                b0.next = sx
            elif p0:
                a0.next = opy
                b0.next = opy
            elif p1:
                a0.next = opx
                b0.next = opy

        @always(clk.posedge)
        def multiply():
            f0.next = a0 * b0

        s0 = cut_signal()

        @always(clk.posedge)
        def cut():
            if p1:
                qxx.next = s0
            if p2:
                qyy.next = s0
            if p3:
                qxy.next = s0

        insts += [operands, multiply, rounding(f0, s0), cut]

    insts.append(pack_word(prod.data, model.PRODUCTS, pxx=qxx, pyy=qyy, pxy=qxy))
    for s, d in ((sink.valid, prod.valid), (sink.eol, prod.eol), (sink.eof, prod.eof), (sink.cam, prod.cam)):
        insts.append(delay_rst(clk, rst, s, d, clocks=lp))
    return insts


def cut_signal():
    """A product of two 2c + 1 operands rounded and cut by 32 (:func:`rounding`'s output)."""
    big = 511 * 511
    return range_signal((-big + 16) >> 5, (big + 16) >> 5)


@block
def rounding(f, out):
    """Combinational ``out = (f + 16) >> 5``: a product rounded to its field's unit (1/32)."""
    lo, hi = signal_range(f)
    r = range_signal(lo + 16, hi + 16)

    @always_comb
    def add():
        r.next = f + 16

    @always_comb
    def cut():
        out.next = r >> 5

    return add, cut
