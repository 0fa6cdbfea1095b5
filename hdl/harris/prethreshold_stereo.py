"""Stereo pre-threshold: BX x BY blocks, one run-time threshold per block and camera (thesis 6.3)."""

from myhdl import Signal, always, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.common.checks import (block_error, check_clock, check_distinct, check_frame, check_reset,
                                         check_signal, check_stream, checked)
from eyestereo.hdl.common.fixed import fx_signal
from eyestereo.tools.models import cornerness as corner_model
from eyestereo.tools.models.prethreshold import block_edges, check_blocks


@block
def prethreshold_stereo(clk, rst, sink, source, thr_we, thr_cam, thr_addr, thr_data, *, width: int = 352,
                        height: int = 288, blocks: tuple[int, int] = (4, 4)):
    """:func:`~eyestereo.hdl.harris.prethreshold.prethreshold` of a stereo stream, each camera with its own thresholds.

    One table of 2 x BX x BY thresholds (LUT-RAM, addressed by block and camera) and one "written" flag
    per entry, cleared by ``rst`` (every threshold reads 0 after a reset); one set of position counters
    for both cameras (they move on with the right camera's beat).

    Ports:
        clk, rst: clock and synchronous active-high reset.
        sink: stereo ImageStream, 20 bits (cornerness codes).
        source: stereo ImageStream, 20 bits: the code where it is greater than its camera's block
            threshold, else 0.
        thr_we, thr_cam, thr_addr, thr_data: register write port: camera (0 left, 1 right), block index
            by*BX + bx (indices >= BX*BY are ignored), threshold code; effective from the next clock.

    Parameters:
        width, height: frame size, 1..4096.
        blocks: (BX, BY), each 1..16.

    Latency: 1 clock.

    Resources: 2 BX BY x 20 bits of LUT-RAM (two registers for 1x1), flags, counters, one comparator.
    """
    nb = corner_model.OUT.wl
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, width=nb, stereo=True)
    check_stream("source", source, width=nb, stereo=True)
    check_signal("thr_we", thr_we, width=1)
    check_signal("thr_cam", thr_cam, width=1)
    check_signal("thr_addr", thr_addr, signed=False)
    check_signal("thr_data", thr_data, width=nb, signed=False)
    check_distinct(dict(source=source), dict(clk=clk, rst=rst, sink=sink, thr_we=thr_we, thr_cam=thr_cam,
                                             thr_addr=thr_addr, thr_data=thr_data))
    width, height = check_frame(width, height)
    bxn, byn = checked(check_blocks, width, height, blocks)
    nblk = bxn * byn
    abits = max(1, (nblk - 1).bit_length())
    if len(thr_addr) < abits:
        raise block_error(f"port thr_addr needs {abits} bits for {nblk} blocks, has {len(thr_addr)}")
    thr = fx_signal(corner_model.OUT)
    value = fx_signal(corner_model.OUT)

    @always_comb
    def signed_view():
        value.next = sink.data

    @always_seq(clk.posedge, reset=rst)
    def emit():
        source.valid.next = sink.valid
        source.eol.next = sink.eol
        source.eof.next = sink.eof
        source.cam.next = sink.cam
        if value > thr:
            source.data.next = sink.data
        else:
            source.data.next = 0

    if nblk == 1:
        stored_l = Signal(intbv(0)[nb:])
        stored_r = Signal(intbv(0)[nb:])

        @always_seq(clk.posedge, reset=rst)
        def registers():
            if thr_we:
                if thr_cam:
                    stored_r.next = thr_data
                else:
                    stored_l.next = thr_data

        @always_comb
        def choose():
            if sink.cam:
                thr.next = stored_r
            else:
                thr.next = stored_l

        return signed_view, emit, registers, choose

    x_last = tuple(int(e) - 1 for e in block_edges(width, bxn)[1:])
    y_last = tuple(int(e) - 1 for e in block_edges(height, byn)[1:])
    mem = [Signal(intbv(0)[nb:]) for _ in range(1 << (abits + 1))]
    written = Signal(intbv(0)[1 << (abits + 1):])
    x = Signal(intbv(0, min=0, max=width))
    y = Signal(intbv(0, min=0, max=height))
    bx = Signal(intbv(0, min=0, max=bxn))
    by = Signal(intbv(0, min=0, max=byn))
    base = Signal(intbv(0, min=0, max=nblk))
    blk = Signal(intbv(0)[abits:])
    raddr = Signal(intbv(0)[abits + 1:])
    waddr = Signal(intbv(0)[abits + 1:])
    wblk = Signal(intbv(0)[abits:])
    stored = Signal(intbv(0)[nb:])
    xl = Signal(intbv(0, min=0, max=width))
    yl = Signal(intbv(0, min=0, max=height))
    we = Signal(bool(0))
    full = nblk >= (1 << len(thr_addr))  # every address names a block: no range check (see prethreshold)

    @always_comb
    def field():
        wblk.next = thr_addr[abits:]

    if full:
        @always_comb
        def write_check():
            we.next = thr_we
    else:
        @always_comb
        def write_check():
            we.next = thr_we and thr_addr < nblk

    @always_comb
    def addresses():
        waddr.next = concat(wblk, thr_cam)
        raddr.next = concat(blk, sink.cam)

    @always(clk.posedge)
    def ram():
        if we:
            mem[waddr].next = thr_data

    @always_seq(clk.posedge, reset=rst)
    def flags():
        if we:
            written.next[waddr] = 1

    @always_comb
    def lookup():
        blk.next = base + bx
        xl.next = x_last[bx]
        yl.next = y_last[by]

    @always_comb
    def read():
        stored.next = mem[raddr]

    @always_comb
    def choose():
        if written[raddr]:
            thr.next = stored
        else:
            thr.next = 0

    @always_seq(clk.posedge, reset=rst)
    def position():
        if sink.valid and (sink.cam or (sink.eof and not sink.eol)):
            if sink.eof:
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

    return signed_view, emit, field, write_check, addresses, ram, flags, lookup, read, choose, position
