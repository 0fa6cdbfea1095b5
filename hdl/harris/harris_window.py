"""Harris window function: Ix^2, Iy^2, IxIy summed over a separable 5x5 [1 2 4 2 1]^2 window (thesis 6.2.2)."""

from myhdl import Signal, always, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.common.fixed import fx_signal
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.hdl.common import range_signal, column_taps, delay, en_reg, shift_add, window_control
from eyestereo.hdl.common.packed import pack_word, unpack_word
from eyestereo.tools.models import sobel as sobel_model
from eyestereo.tools.models import harris_window as model
from eyestereo.tools.fixed import sfix
from eyestereo.hdl.common.checks import check_clock, check_distinct, check_frame, check_reset, check_stream

N = 5
LATENCY = 8  # 1 product stage + the window's N + 2


@block
def harris_window(clk, rst, sink, source, *, width: int = 352, height: int = 288):
    """Structure-tensor sums: ``source`` pixel (x, y) = (Sxy, Syy, Sxx) over the 5x5 window centred on (x, y).

    Each incoming (Ix, Iy) pair is squared and multiplied first (3 multipliers of 10 x 10 bits: each
    code c enters as 2c + 1, the midpoint of the gradients it stands for), each product rounded by 32
    and saturated to 12 bits (ufix[12,-9], ufix[12,-9], sfix[12,-9]; Sobel codes never saturate), and
    the three are packed into one 36-bit word, so a single set of four line delays (one RAMB16
    each) carries them. The separable weighted sum [1 2 4 2 1] x [1 2 4 2 1] runs by shifts and adds
    on the unpacked taps; its "/128" is a move of the binary point, so no bit is dropped: Sxx, Syy are
    ufix[19,-2], Sxy sfix[19,-2]. Pixels within 2 of the border carry unspecified data.

    Ports:
        clk, rst: clock and synchronous active-high reset (control only).
        sink: ImageStream, 18 bits: Iy in bits 17..9, Ix in 8..0 (sfix[9,-3] codes, as from ``sobel``);
            mono only (a stereo stream is refused).
        source: ImageStream, 57 bits: Sxy in 56..38 (two's complement), Syy in 37..19, Sxx in 18..0.

    Parameters:
        width, height: frame size, each 5..4096.

    Latency: 8 clocks after input pixel (x + 2, y + 2): 2 lines + 2 pixels + 8 clocks.

    Resources: 3 multipliers (10x10), 4 line delays of 36 bits (4 RAMB16), adders and registers.
    """
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, width=sobel_model.WORD.width)
    check_stream("source", source, width=model.OUT_BITS)
    check_distinct(dict(source=source), dict(clk=clk, rst=rst, sink=sink))
    width, height = check_frame(width, height, min_size=N)

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

    taps = [Signal(intbv(0)[model.PACK_BITS:]) for _ in range(N)]
    tap_valid = Signal(bool(0))
    insts = [fields, multiply, saturate, pack_word(prod_word, model.PRODUCTS, pxx=qxx, pyy=qyy, pxy=qxy), pack, flags,
             column_taps(clk, rst, prod, taps, tap_valid, width=width, height=height)]

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
        row = [range_signal(vlo, vhi) for _ in range(N)]
        src = vreg
        for reg in row:
            insts.append(en_reg(clk, col_valid, src, reg))
            src = reg
        total = fx_signal(model.SUM_XY if fmt.signed else model.SUM_SQ)
        insts.append(shift_add(list(zip(row, weights)), total))
        sums.append(total)
    sxx, syy, sxy = sums
    out_word = Signal(intbv(0)[model.WORD.width:])

    @always(clk.posedge)
    def outreg():
        source.data.next = out_word

    insts += [pack_word(out_word, model.WORD, sxx=sxx, syy=syy, sxy=sxy), outreg, window_control(clk, rst, prod, source, width=width, height=height, radius=N // 2,
                                     latency=N + 2)]
    return insts

