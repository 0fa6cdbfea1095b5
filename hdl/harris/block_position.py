"""Block position: the pixel a stream beat carries and the threshold block it lies in (thesis 6.2.4)."""

from myhdl import Signal, always_comb, always_seq, block, intbv

from eyestereo.hdl.common.checks import (block_error, check_clock, check_distinct, check_frame, check_reset,
                                         check_signal, check_stream, checked)
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH, THRESHOLD_BLOCKS
from eyestereo.tools.models.prethreshold import block_edges, check_blocks


@block
def block_position(clk, rst, sink, x, y, blk, ahead=None, *, width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT,
                   blocks: tuple[int, int] = THRESHOLD_BLOCKS):
    """Count the beats of ``sink``: ``x``, ``y`` = the pixel of the current beat, ``blk`` = its block.

    Block (bx, by) of a BX x BY grid covers columns [bx*W//BX, (bx+1)*W//BX) and rows [by*H//BY,
    (by+1)*H//BY) (:func:`eyestereo.tools.models.prethreshold.block_index`); ``blk`` = by*BX + bx. The
    block counters move on where ``x`` / ``y`` pass a block's last column / row, so no division or
    comparison against every edge is needed. Whether the current pixel is its block's last column or row,
    or the frame's, is kept in four flag registers, set one pixel ahead (``x`` against the column before
    the block's last, read from a small ROM indexed by the block counter): the next block, and so
    ``ahead``, follows from registers and the beat's flags in two logic levels. A beat with ``eof`` (the
    frame's last pixel, or a reset token) brings the counters back to pixel (0, 0), as does the last pixel
    of a ``width`` x ``height`` frame; ``eol`` ends a row early.

    The camera count comes from the stream: on a stereo stream (left and right beat of each pixel in
    turn) the counters move on with the right camera's beat or a reset token of either camera, so both
    beats of a pixel see the same position.

    Ports:
        clk, rst: clock and synchronous active-high reset (clears the counters).
        sink: ImageStream (any data width, mono or stereo); only its flags are read.
        x, y: outputs, unsigned Signals that can hold width - 1 / height - 1: the current beat's pixel
            (registered).
        blk: output, unsigned, at least log2(BX*BY) bits (1 for one block): by*BX + bx of (x, y)
            (registered).
        ahead: optional output, as ``blk``: the block of the next beat, i.e. ``blk``'s next value
            (combinational: the beat on ``sink`` now moves the position on or not), for a table read
            registered one clock ahead (``prethreshold``).

    Parameters:
        width, height: frame size, 1..4096.
        blocks: (BX, BY), each 1..16 and at most the frame size.

    Latency: 0 (the position of the beat on ``sink`` now).

    Resources: the x, y counters, bx, by, by*BX and block registers, four flag registers, four ROMs of BX
    and BY entries, two small adders (blk + 1, by*BX + BX) and four comparators; no RAM, no multiplier.
    """
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, stereo=None)
    width, height = check_frame(width, height)
    bxn, byn = checked(check_blocks, width, height, blocks)
    nblk = bxn * byn
    outs = dict(x=x, y=y, blk=blk)
    if ahead is not None:
        outs["ahead"] = ahead
    for name, sig in outs.items():
        need = dict(x=width, y=height).get(name, nblk)
        check_signal(name, sig, signed=False)
        if (1 << len(sig)) < need:
            raise block_error(f"port {name} has {len(sig)} bits, too few for values up to {need - 1}")
    check_distinct(outs, dict(clk=clk, rst=rst, sink=sink))

    # Per block: its last column / row, the one before (where the flag is set for the next pixel; a block
    # one wide never uses its entry), and whether the block after it is one column / row wide.
    x_last = [int(e) - 1 for e in block_edges(width, bxn)[1:]]
    y_last = [int(e) - 1 for e in block_edges(height, byn)[1:]]
    x_pre = tuple(max(e - 1, 0) for e in x_last)
    y_pre = tuple(max(e - 1, 0) for e in y_last)
    x_one = tuple(int(b - a == 1) for a, b in zip(x_last, x_last[1:])) + (0,)
    y_one = tuple(int(b - a == 1) for a, b in zip(y_last, y_last[1:])) + (0,)
    # the flags at pixel (0, 0); comparisons for the pixel before the frame's last column / row (unused when
    # the frame is one wide / high: the flag is then always set)
    xe0, xw0, ye0, yh0 = x_last[0] == 0, width == 1, y_last[0] == 0, height == 1
    x_wpre, y_hpre = max(width - 2, 0), max(height - 2, 0)
    bx = Signal(intbv(0, min=0, max=bxn))
    by = Signal(intbv(0, min=0, max=byn))
    base = Signal(intbv(0, min=0, max=nblk))  # by * BX
    xe, xw = Signal(bool(xe0)), Signal(bool(xw0))  # x is its block's / the frame's last column
    ye, yh = Signal(bool(ye0)), Signal(bool(yh0))  # y is its block's / the frame's last row
    xp = Signal(intbv(0, min=0, max=width))
    yp = Signal(intbv(0, min=0, max=height))
    xo, yo = Signal(bool(0)), Signal(bool(0))
    row = Signal(intbv(0, min=0, max=nblk))  # the block of the next row's first pixel
    nxt = ahead if ahead is not None else Signal(intbv(0, min=0, max=nblk))
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
        xp.next = x_pre[bx]
        yp.next = y_pre[by]
        xo.next = x_one[bx]
        yo.next = y_one[by]

    @always_comb
    def next_block():
        if yh:
            row.next = 0
        elif ye:
            row.next = base + bxn
        else:
            row.next = base
        nxt.next = blk
        if step:
            if sink.eof:
                nxt.next = 0
            elif sink.eol or xw:
                nxt.next = row
            elif xe:
                nxt.next = blk + 1

    @always_seq(clk.posedge, reset=rst)
    def position():
        blk.next = nxt
        if step:
            if sink.eof:
                # end of frame or reset token: back to pixel (0, 0)
                x.next = 0
                y.next = 0
                bx.next = 0
                by.next = 0
                base.next = 0
                xe.next = xe0
                xw.next = xw0
                ye.next = ye0
                yh.next = yh0
            elif sink.eol or xw:
                x.next = 0
                bx.next = 0
                xe.next = xe0
                xw.next = xw0
                if yh:
                    y.next = 0
                    by.next = 0
                    base.next = 0
                    ye.next = ye0
                    yh.next = yh0
                else:
                    y.next = y + 1
                    yh.next = y == y_hpre
                    if ye:
                        by.next = by + 1
                        base.next = base + bxn
                        ye.next = yo
                    else:
                        ye.next = y == yp
            else:
                x.next = x + 1
                xw.next = x == x_wpre
                if xe:
                    bx.next = bx + 1
                    xe.next = xo
                else:
                    xe.next = x == xp

    return insts + [lookup, next_block, position]
