"""Separable 3x3 Sobel gradients Ix, Iy by shifts and adds, quantized to sfix[9,-3] (thesis 6.2.1)."""

from myhdl import Signal, always, block, intbv

from eyestereo.hdl.common.fixed import fx_signal
from eyestereo.hdl.common import range_signal, column_taps, delay, en_reg, shift_add, window_control
from eyestereo.tools.fixed import shift_between
from eyestereo.hdl.common.packed import pack_word
from eyestereo.tools.models.sobel import GRAD, OUT, WORD
from eyestereo.hdl.common.checks import check_clock, check_distinct, check_frame, check_reset, check_stream

LATENCY = 5


@block
def sobel(clk, rst, sink, source, *, width: int = 352, height: int = 288):
    """Image gradients: ``source`` pixel (x, y) = (Iy, Ix) of the 3x3 Sobel centred on input (x, y).

    Ix is the response of [[-1,0,1],[-2,0,2],[-1,0,1]] (right minus left, like OpenCV's Sobel with
    dx=1), Iy that of its transpose (down minus up). Both come from one pair of line delays: the
    vertical pass forms the smoothed column p(y-1) + 2p(y) + p(y+1) and the difference p(y+1) - p(y-1),
    the horizontal pass their difference (Ix) and smoothing (Iy). Each is floored to sfix[9,-3]
    (floor(G / 8), codes -128..127 in a 9-bit two's complement field). Border pixels (x or y at the
    image edge) carry unspecified data.

    Ports:
        clk, rst: clock and synchronous active-high reset (control only).
        sink: ImageStream, 8-bit grey pixels; mono only (a stereo stream is refused).
        source: ImageStream, 18 bits: Iy in bits 17..9, Ix in bits 8..0, two's complement.

    Parameters:
        width, height: frame size, each 3..4096.

    Latency: 5 clocks after input pixel (x + 1, y + 1): 1 line + 1 pixel + 5 clocks.

    Resources: 2 line delays (2 RAMB16 for width <= 2048), shift-and-add logic, no multipliers.
    """
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, width=8)
    check_stream("source", source, width=WORD.width)
    check_distinct(dict(source=source), dict(clk=clk, rst=rst, sink=sink))
    width, height = check_frame(width, height, min_size=3)

    top, mid, bot = taps = [Signal(intbv(0)[8:]) for _ in range(3)]
    tap_valid = Signal(bool(0))
    insts = [column_taps(clk, rst, sink, taps, tap_valid, width=width, height=height)]

    # Vertical pass, registered.
    smooth_c, smooth = range_signal(0, 1020), range_signal(0, 1020)
    diff_c, diff = range_signal(-255, 255), range_signal(-255, 255)
    col_valid = Signal(bool(0))
    insts += [shift_add([(top, 1), (mid, 2), (bot, 1)], smooth_c),
              shift_add([(bot, 1), (top, -1)], diff_c),
              delay(clk, smooth_c, smooth, clocks=1), delay(clk, diff_c, diff, clocks=1),
              delay(clk, tap_valid, col_valid, clocks=1)]

    # A row of three columns; index 0 is the newest (right-hand) one.
    s = [range_signal(0, 1020) for _ in range(3)]
    d = [range_signal(-255, 255) for _ in range(3)]
    for regs, first in ((s, smooth), (d, diff)):
        src = first
        for reg in regs:
            insts.append(en_reg(clk, col_valid, src, reg))
            src = reg

    gx = fx_signal(GRAD)
    gy = fx_signal(GRAD)
    insts += [shift_add([(s[0], 1), (s[2], -1)], gx),
              shift_add([(d[0], 1), (d[1], 2), (d[2], 1)], gy)]

    # Floor to sfix[9,-3]: an arithmetic right shift drops the fraction bits toward minus infinity.
    qx = fx_signal(OUT)
    qy = fx_signal(OUT)
    sh = shift_between(GRAD.fl, OUT.fl)
    word = Signal(intbv(0)[WORD.width:])

    @always(gx, gy)
    def quantize():
        qx.next = gx >> sh
        qy.next = gy >> sh

    @always(clk.posedge)
    def outreg():
        source.data.next = word

    insts += [quantize, pack_word(word, WORD, ix=qx, iy=qy), outreg,
              window_control(clk, rst, sink, source, width=width, height=height, radius=1, latency=LATENCY)]
    return insts
