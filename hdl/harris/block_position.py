"""Block position: the pixel a stream beat carries and the threshold block it lies in (thesis 6.2.4)."""

from myhdl import Signal, always_comb, always_seq, block, intbv

from eyestereo.hdl.common.checks import (block_error, check_clock, check_distinct, check_frame, check_reset,
                                         check_signal, check_stream, checked)
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH, THRESHOLD_BLOCKS
from eyestereo.tools.models.prethreshold import block_edges, check_blocks


@block
def block_position(clk, rst, sink, x, y, blk, *, width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT,
                   blocks: tuple[int, int] = THRESHOLD_BLOCKS):
    """Count the beats of ``sink``: ``x``, ``y`` = the pixel of the current beat, ``blk`` = its block.

    Block (bx, by) of a BX x BY grid covers columns [bx*W//BX, (bx+1)*W//BX) and rows [by*H//BY,
    (by+1)*H//BY) (:func:`eyestereo.tools.models.prethreshold.block_index`); ``blk`` = by*BX + bx. The
    block counters move on where ``x`` / ``y`` pass a block's last column / row (read from a small ROM
    indexed by the block counter), so no division or comparison against every edge is needed. A beat
    with ``eof`` (the frame's last pixel, or a reset token) brings the counters back to pixel (0, 0), as
    does the last pixel of a ``width`` x ``height`` frame; ``eol`` ends a row early.

    The camera count comes from the stream: on a stereo stream (left and right beat of each pixel in
    turn) the counters move on with the right camera's beat or a reset token of either camera, so both
    beats of a pixel see the same position.

    Ports:
        clk, rst: clock and synchronous active-high reset (clears the counters).
        sink: ImageStream (any data width, mono or stereo); only its flags are read.
        x, y: outputs, unsigned Signals that can hold width - 1 / height - 1: the current beat's pixel
            (registered).
        blk: output, unsigned, at least log2(BX*BY) bits (1 for one block): by*BX + bx of (x, y),
            combinational from registers.

    Parameters:
        width, height: frame size, 1..4096.
        blocks: (BX, BY), each 1..16 and at most the frame size.

    Latency: 0 (the position of the beat on ``sink`` now).

    Resources: the x, y counters, bx, by and by*BX registers, two ROMs of BX and BY last-column / -row
    entries, one adder (blk) and four comparators; no RAM, no multiplier.
    """
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, stereo=None)
    width, height = check_frame(width, height)
    bxn, byn = checked(check_blocks, width, height, blocks)
    nblk = bxn * byn
    for name, sig, need in (("x", x, width), ("y", y, height), ("blk", blk, nblk)):
        check_signal(name, sig, signed=False)
        if (1 << len(sig)) < need:
            raise block_error(f"port {name} has {len(sig)} bits, too few for values up to {need - 1}")
    check_distinct(dict(x=x, y=y, blk=blk), dict(clk=clk, rst=rst, sink=sink))

    # Last column / row of each block, as ROM tables indexed by the block counters.
    x_last = tuple(int(e) - 1 for e in block_edges(width, bxn)[1:])
    y_last = tuple(int(e) - 1 for e in block_edges(height, byn)[1:])
    bx = Signal(intbv(0, min=0, max=bxn))
    by = Signal(intbv(0, min=0, max=byn))
    base = Signal(intbv(0, min=0, max=nblk))  # by * BX
    xl = Signal(intbv(0, min=0, max=width))
    yl = Signal(intbv(0, min=0, max=height))
    insts = []
    if sink.stereo:
        # One position for both beats of a pixel: move on after the right camera's beat; a reset token
        # (eof without eol) of either camera goes back to (0, 0) at once.
        step = Signal(bool(0))

        @always_comb
        def camera():
            step.next = sink.valid and (sink.cam or (sink.eof and not sink.eol))

        insts.append(camera)
    else:
        step = sink.valid

    @always_comb
    def lookup():
        blk.next = base + bx
        xl.next = x_last[bx]
        yl.next = y_last[by]

    @always_seq(clk.posedge, reset=rst)
    def position():
        if step:
            if sink.eof:
                # end of frame or reset token: back to pixel (0, 0)
                x.next = 0
                y.next = 0
                bx.next = 0
                by.next = 0
                base.next = 0
            elif sink.eol or x == width - 1:
                x.next = 0
                bx.next = 0
                if y == height - 1:
                    y.next = 0
                    by.next = 0
                    base.next = 0
                else:
                    y.next = y + 1
                    if y == yl:
                        by.next = by + 1
                        base.next = base + bxn
            else:
                x.next = x + 1
                if x == xl:
                    bx.next = bx + 1

    return insts + [lookup, position]
