"""Separable 3x3 Sobel gradients Ix, Iy by shifts and adds, quantized to sfix[9,-3] (thesis 6.2.1, Fig. 6.14)."""

from myhdl import Signal, always, block, intbv

from eyestereo.hdl.common import delay, en_reg, range_signal, shift_add
from eyestereo.hdl.common.checks import check_clock, check_distinct, check_frame, check_reset, check_stream
from eyestereo.hdl.common.fixed import fx_signal
from eyestereo.hdl.common.packed import pack_word
from eyestereo.hdl.streaming.window import check_share, column_taps, window_control, window_row
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH
from eyestereo.tools.fixed import shift_between
from eyestereo.tools.models.sobel import GRAD, OUT, WORD

LATENCY = 6  # the column taps 3, the vertical pass 1, the window row 1, the output register 1


@block
def sobel(clk, rst, sink, source, *, width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT, share: int = 1):
    """Image gradients: ``source`` pixel (x, y) = (Iy, Ix) of the 3x3 Sobel centred on input (x, y).

    Ix is the response of [[-1,0,1],[-2,0,2],[-1,0,1]] (right minus left, like OpenCV's Sobel with
    dx=1), Iy that of its transpose (down minus up). Both come from one pair of line delays: the
    vertical pass forms the smoothed column p(y-1) + 2p(y) + p(y+1) and the difference p(y+1) - p(y-1),
    the horizontal pass their difference (Ix) and smoothing (Iy). Each is floored to sfix[9,-3]
    (floor(G / 8), codes -128..127 in a 9-bit two's complement field). Border pixels (x or y at the
    image edge) carry unspecified data.

    A stereo stream (left and right pixel of each (x, y) in turn) is filtered camera by camera in the
    same datapath: the line delays are stereo line delays (2 x width words, both cameras in one block
    RAM) and each horizontal register becomes a chain of three (the window reads every other one).

    Ports:
        clk, rst: clock and synchronous active-high reset (control only).
        sink: ImageStream, 8-bit grey pixels, mono or stereo.
        source: ImageStream of the sink's kind, 18 bits (:data:`eyestereo.tools.models.sobel.WORD`): Iy in
            bits 17..9, Ix in bits 8..0, two's complement.

    Parameters:
        width, height: frame size, each 3..4096.
        share: stereo streams only (1 for a mono one, else a ValueError): the tail after each frame is
            emitted one beat every ``share`` clocks (1, 2 or 3), the spacing ``harris_stereo`` keeps.

    Latency: 6 clocks after the (camera's) input pixel (x + 1, y + 1): 1 line + 1 pixel + 6 clocks
    (stereo: 2 width + 2 beats + 6 clocks).

    Resources: 2 line delays (mono: 2 RAMB16 for width <= 2048; stereo: 2 RAMB16 for width <= 1024),
    shift-and-add logic, no multipliers.
    """
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, width=8, stereo=None)
    check_stream("source", source, width=WORD.width, stereo=sink.stereo)
    check_distinct(dict(source=source), dict(clk=clk, rst=rst, sink=sink))
    width, height = check_frame(width, height, min_size=3)
    share = check_share(share, sink)

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
    s_links, s = window_row(smooth, 3, stereo=sink.stereo)
    d_links, d = window_row(diff, 3, stereo=sink.stereo)
    for src, reg in s_links + d_links:
        insts.append(en_reg(clk, col_valid, src, reg))

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
              window_control(clk, rst, sink, source, width=width, height=height, radius=1, latency=LATENCY,
                             share=share)]
    return insts
