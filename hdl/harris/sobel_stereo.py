"""Stereo Sobel: both cameras' Ix, Iy in one datapath, the two line delays shared (thesis Fig. 6.14)."""

from myhdl import Signal, always, block, intbv

from eyestereo.hdl.common import range_signal, shift_add
from eyestereo.hdl.common.checks import check_clock, check_distinct, check_frame, check_int, check_reset, check_stream
from eyestereo.hdl.common.fixed import fx_signal
from eyestereo.hdl.common.packed import pack_word
from eyestereo.hdl.common.registers import delay
from eyestereo.hdl.common.stereo_window import pair_chain, pair_regs, stereo_column_taps, stereo_window_control
from eyestereo.hdl.harris.sobel import LATENCY
from eyestereo.tools.fixed import shift_between
from eyestereo.tools.models.sobel import GRAD, OUT, WORD


@block
def sobel_stereo(clk, rst, sink, source, *, width: int = 352, height: int = 288, share: int = 1):
    """:func:`~eyestereo.hdl.harris.sobel.sobel` of each camera of a stereo stream, one datapath for both.

    The arithmetic of the mono block once; its two line delays are stereo line delays (2 x width
    words of 8 bits: one RAMB16 each for width <= 1024), and each horizontal register becomes a chain of
    three (left and right beats in turn, the window reads every other one).

    Ports:
        clk, rst: clock and synchronous active-high reset (control only).
        sink: stereo ImageStream, 8-bit grey pixels, left and right in turn.
        source: stereo ImageStream, 18 bits (the Sobel word, :data:`eyestereo.tools.models.sobel.WORD`).

    Parameters:
        width, height: frame size, each 3..4096.
        share: the tail after each frame is emitted one beat every ``share`` clocks.

    Latency: 5 clocks after the camera's input pixel (x + 1, y + 1): 1 line + 1 pixel of that camera
    (2 width + 2 beats) + 5 clocks.

    Resources: 2 stereo line delays (2 RAMB16 for width <= 1024), shift-and-add logic, no multipliers.
    """
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, width=8, stereo=True)
    check_stream("source", source, width=WORD.width, stereo=True)
    check_distinct(dict(source=source), dict(clk=clk, rst=rst, sink=sink))
    width, height = check_frame(width, height, min_size=3)
    share = check_int("share", share, 1, 3)

    top, mid, bot = taps = [Signal(intbv(0)[8:]) for _ in range(3)]
    tap_valid = Signal(bool(0))
    insts = [stereo_column_taps(clk, rst, sink, taps, tap_valid, width=width, height=height)]

    smooth_c, smooth = range_signal(0, 1020), range_signal(0, 1020)
    diff_c, diff = range_signal(-255, 255), range_signal(-255, 255)
    col_valid = Signal(bool(0))
    insts += [shift_add([(top, 1), (mid, 2), (bot, 1)], smooth_c),
              shift_add([(bot, 1), (top, -1)], diff_c),
              delay(clk, smooth_c, smooth, clocks=1), delay(clk, diff_c, diff, clocks=1),
              delay(clk, tap_valid, col_valid, clocks=1)]
    rs, rd = pair_regs(smooth, 3), pair_regs(diff, 3)
    insts += [pair_chain(clk, col_valid, smooth, rs), pair_chain(clk, col_valid, diff, rd)]
    s, d = rs[0::2], rd[0::2]

    gx = fx_signal(GRAD)
    gy = fx_signal(GRAD)
    insts += [shift_add([(s[0], 1), (s[2], -1)], gx),
              shift_add([(d[0], 1), (d[1], 2), (d[2], 1)], gy)]
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
              stereo_window_control(clk, rst, sink, source, width=width, height=height, radius=1,
                                    latency=LATENCY, share=share)]
    return insts
