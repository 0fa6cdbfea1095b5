"""Segmented pre-threshold: the image cut into BX x BY blocks, one run-time threshold each (thesis 6.2.4)."""

from myhdl import Signal, always, always_comb, always_seq, block, intbv

from eyestereo.hdl.common.fixed import fx_signal
from eyestereo.tools.models import cornerness as corner_model
from eyestereo.tools.models.prethreshold import block_edges, check_blocks
from eyestereo.hdl.common.checks import (block_error, check_clock, check_distinct, check_frame, check_reset,
                                         check_signal, check_stream, checked)


@block
def prethreshold(clk, rst, sink, source, thr_we, thr_addr, thr_data, *, width: int = 352, height: int = 288,
                 blocks: tuple[int, int] = (4, 4)):
    """``source`` = cornerness where it is greater than its block's threshold, else 0.

    Block (bx, by) covers columns [bx*W//BX, (bx+1)*W//BX) and rows [by*H//BY, (by+1)*H//BY); its index
    is by*BX + bx. The thresholds sit in a small distributed RAM (one LUT per bit for up to 16 blocks)
    plus one "written" flag per block; the flags clear on ``rst``, so every threshold reads 0 after a
    reset. A write takes effect from the next clock: write between frames for a consistent frame.

    Ports:
        clk, rst: clock and synchronous active-high reset.
        sink: ImageStream, 20 bits, cornerness (two's complement), e.g. from ``cornerness``; mono only
            (a stereo stream is refused).
        source: ImageStream, 20 bits, same format.
        thr_we: input, write enable of the threshold register port.
        thr_addr: input, unsigned, at least log2(BX*BY) bits (1 for one block): block index by*BX + bx
            (writes to indices >= BX*BY are ignored).
        thr_data: input, 20 bits unsigned: the threshold's two's complement code (cornerness format).

    Parameters:
        width, height: frame size, 1..4096.
        blocks: (BX, BY), each 1..16 and at most the frame size; (1, 1) is a global threshold.

    Latency: 1 clock.

    Resources: BX*BY x 20 bits of LUT-RAM, BX*BY flag registers, position counters, one comparator.
    """
    nb = corner_model.OUT.wl
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, width=nb)
    check_stream("source", source, width=nb)
    check_signal("thr_we", thr_we, width=1)
    check_signal("thr_addr", thr_addr, signed=False)
    check_signal("thr_data", thr_data, width=nb, signed=False)
    check_distinct(dict(source=source), dict(clk=clk, rst=rst, sink=sink, thr_we=thr_we, thr_addr=thr_addr,
                                             thr_data=thr_data))
    width, height = check_frame(width, height)
    blocks = checked(check_blocks, width, height, blocks)
    bxn, byn = blocks
    nblk = bxn * byn
    abits = max(1, (nblk - 1).bit_length())
    if len(thr_addr) < abits:
        raise block_error(f"port thr_addr needs {abits} bits for {nblk} blocks, has {len(thr_addr)}")

    if nblk == 1:
        return global_threshold(clk, rst, sink, source, thr_we, thr_data)

    # Last column / row of each block, as ROM tables indexed by the block counters.
    x_last = tuple(int(e) - 1 for e in block_edges(width, bxn)[1:])
    y_last = tuple(int(e) - 1 for e in block_edges(height, byn)[1:])
    mem = [Signal(intbv(0)[nb:]) for _ in range(nblk)]
    written = Signal(intbv(0)[nblk:])
    x = Signal(intbv(0, min=0, max=width))
    y = Signal(intbv(0, min=0, max=height))
    bx = Signal(intbv(0, min=0, max=bxn))
    by = Signal(intbv(0, min=0, max=byn))
    base = Signal(intbv(0, min=0, max=nblk))  # by * BX
    blk = Signal(intbv(0, min=0, max=nblk))
    stored = Signal(intbv(0)[nb:])
    thr = fx_signal(corner_model.OUT)
    value = fx_signal(corner_model.OUT)
    xl = Signal(intbv(0, min=0, max=width))
    yl = Signal(intbv(0, min=0, max=height))

    # A write to an index past the last block is ignored. When every address names a block the check
    # is left out: GHDL 2.0's synthesis truncates the constant of "thr_addr < 16" to 4 bits (0), and
    # the netlist make synth measures would then never write a threshold.
    we = Signal(bool(0))
    if nblk >= (1 << len(thr_addr)):
        @always_comb
        def write_check():
            we.next = thr_we
    else:
        @always_comb
        def write_check():
            we.next = thr_we and thr_addr < nblk

    @always(clk.posedge)
    def ram():
        if we:
            mem[thr_addr].next = thr_data

    @always_seq(clk.posedge, reset=rst)
    def flags():
        if we:
            written.next[thr_addr] = 1

    @always_comb
    def lookup():
        blk.next = base + bx
        xl.next = x_last[bx]
        yl.next = y_last[by]

    @always_comb
    def read():
        stored.next = mem[blk]

    @always_comb
    def choose():
        value.next = sink.data
        if written[blk]:
            thr.next = stored
        else:
            thr.next = 0

    @always_seq(clk.posedge, reset=rst)
    def position():
        if sink.valid:
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

    return write_check, ram, flags, lookup, read, choose, position, pass_greater(clk, rst, sink, source, value, thr)


@block
def global_threshold(clk, rst, sink, source, thr_we, thr_data):
    """blocks=(1, 1): one threshold register, no position counters."""
    thr = fx_signal(corner_model.OUT)
    value = fx_signal(corner_model.OUT)
    stored = Signal(intbv(0)[len(thr_data):])

    @always_seq(clk.posedge, reset=rst)
    def register():
        if thr_we:
            stored.next = thr_data

    @always_comb
    def signed_view():
        value.next = sink.data
        thr.next = stored

    return register, signed_view, pass_greater(clk, rst, sink, source, value, thr)


@block
def pass_greater(clk, rst, sink, source, value, thr):
    """The output register: the sink's beat, its data kept where value > thr, else 0."""

    @always_seq(clk.posedge, reset=rst)
    def emit():
        source.valid.next = sink.valid
        source.eol.next = sink.eol
        source.eof.next = sink.eof
        if value > thr:
            source.data.next = sink.data
        else:
            source.data.next = 0

    return emit
