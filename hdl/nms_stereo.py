"""Stereo non-maximum suppression 1x1 / 3x3 / 5x5: both cameras in one datapath, line delays shared."""

from myhdl import Signal, always, always_comb, always_seq, block, intbv

from eyestereo.hdl.common import assign, delay
from eyestereo.hdl.common.checks import (check_choice, check_clock, check_distinct, check_frame, check_int,
                                         check_reset, check_stream)
from eyestereo.hdl.common.fixed import fx_signal
from eyestereo.hdl.common.registers import en_reg, like_signal
from eyestereo.hdl.common.stereo_window import stereo_column_taps, stereo_window_control
from eyestereo.hdl.nms import SIZES, all_of, beats, maximum
from eyestereo.tools.models import cornerness as corner_model


def latency(size: int) -> int:
    return 1 if size == 1 else size + 2


@block
def nms_stereo(clk, rst, sink, source, *, width: int = 352, height: int = 288, size: int = 3, share: int = 1):
    """:func:`~eyestereo.hdl.nms.nms` of each camera of a stereo stream (same tie rule, same flags).

    The size - 1 line delays are stereo line delays (2 x width words of 20 bits); the horizontal
    pass keeps 2 size - 1 column triples (left and right in turn) and compares the centre with every
    other one.

    Ports:
        clk, rst: clock and synchronous active-high reset (control only).
        sink: stereo ImageStream, 20 bits (pre-thresholded cornerness).
        source: stereo ImageStream, 1 bit: the feature flag.

    Parameters:
        width, height: frame size, each at least ``size``.
        size: 1, 3 or 5.
        share: the tail after each frame is emitted one beat every ``share`` clocks.

    Latency: size 1: 1 clock; size N = 3, 5: N + 2 clocks after the camera's input pixel (x + r, y + r).

    Resources: N - 1 stereo line delays of 20 bits (2 RAMB16 each at width 352), 3 (2N - 1) registers of
    20 bits, 3N - 1 comparators.
    """
    nb = corner_model.OUT.wl
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, width=nb, stereo=True)
    check_stream("source", source, width=1, stereo=True)
    check_distinct(dict(source=source), dict(clk=clk, rst=rst, sink=sink))
    size = check_choice("size", size, SIZES)
    width, height = check_frame(width, height, min_size=size)
    share = check_int("share", share, 1, 3)

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
            source.cam.next = sink.cam
            source.data.next = v > 0

        return value, flag

    r = size // 2
    taps = [Signal(intbv(0)[nb:]) for _ in range(size)]
    tap_valid = Signal(bool(0))
    insts = [stereo_column_taps(clk, rst, sink, taps, tap_valid, width=width, height=height)]
    st = [fx_signal(corner_model.OUT) for _ in range(size)]
    for tap, s in zip(taps, st):
        insts.append(assign(tap, s))
    up_c, down_c = fx_signal(corner_model.OUT), fx_signal(corner_model.OUT)
    insts += [maximum(st[:r], up_c), maximum(st[r + 1:], down_c)]
    up, mid, down = (fx_signal(corner_model.OUT) for _ in range(3))
    col_valid = Signal(bool(0))
    insts += [delay(clk, up_c, up, clocks=1), delay(clk, st[r], mid, clocks=1),
              delay(clk, down_c, down, clocks=1), delay(clk, tap_valid, col_valid, clocks=1)]
    chain = []
    for j in range(2 * size - 1):
        regs = tuple(like_signal(up) for _ in range(3))
        srcs = (up, mid, down) if j == 0 else chain[j - 1]
        for s, d in zip(srcs, regs):
            insts.append(en_reg(clk, col_valid, s, d))
        chain.append(regs)
    cols = chain[0::2]
    centre = cols[r][1]
    oks = []
    for j, (u, m, d) in enumerate(cols):
        ok = Signal(bool(0))
        insts.append(beats(centre, u, m, d, ok, dx=r - j))
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

    insts += [outreg, stereo_window_control(clk, rst, sink, source, width=width, height=height, radius=r,
                                            latency=size + 2, share=share)]
    return insts
