"""Segmented pre-threshold: the image cut into BX x BY blocks, one run-time threshold each (thesis 6.2.4, 6.3)."""

from myhdl import Signal, always, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.common.fixed import fx_signal
from eyestereo.hdl.harris.block_position import block_position
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH, THRESHOLD_BLOCKS
from eyestereo.tools.models import cornerness as corner_model
from eyestereo.tools.models.prethreshold import check_blocks
from eyestereo.hdl.common.checks import (block_error, check_clock, check_distinct, check_frame, check_reset,
                                         check_signal, check_stream, checked)


@block
def prethreshold(clk, rst, sink, source, thr_we, thr_addr, thr_data, *, width: int = FRAME_WIDTH,
                 height: int = FRAME_HEIGHT, blocks: tuple[int, int] = THRESHOLD_BLOCKS):
    """``source`` = cornerness where it is greater than its block's threshold, else 0.

    Block (bx, by) covers columns [bx*W//BX, (bx+1)*W//BX) and rows [by*H//BY, (by+1)*H//BY); its index
    is by*BX + bx (:func:`~eyestereo.hdl.harris.block_position.block_position` follows it). The
    thresholds sit in a small distributed RAM (one LUT per bit for up to 16 blocks) plus one "written"
    flag per entry; the flags clear on ``rst``, so every threshold reads 0 after a reset. The table is
    read one clock ahead, at the block of the beat due next (the block position's ``ahead``), into a
    register, so that the comparison starts from registers only. A write therefore takes effect from the
    second clock after it (the next clock for blocks (1, 1)): write between frames for a consistent frame.

    The camera count comes from the stream. On a stereo stream (left and right beat of each pixel in
    turn, ``cam`` forwarded) each camera has its own thresholds: the table has an entry per block and
    camera, addressed 2 * block + cam (as ``feature_list``'s counts), and one block position serves
    both cameras (:func:`camera_tables`: a memory per camera, both read a clock ahead, the camera due
    picking the comparison). The camera of the beat due next is the one after the last beat's (left
    after a right beat or a reset token), so a beat that breaks the left-right order (two of one camera
    in turn) is compared with the other camera's threshold.

    Ports:
        clk, rst: clock and synchronous active-high reset.
        sink: ImageStream, 20 bits, cornerness (two's complement), e.g. from ``cornerness``; mono or stereo.
        source: ImageStream, 20 bits, same format and kind.
        thr_we: input, write enable of the threshold register port.
        thr_addr: input, unsigned. Mono: at least log2(BX*BY) bits (1 for one block), the block index
            by*BX + bx. Stereo: one bit more, 2 * (by*BX + bx) + cam (cam 0 left, 1 right; e.g.
            ``ConcatSignal(block, cam)``). Writes to blocks >= BX*BY are ignored.
        thr_data: input, 20 bits unsigned: the threshold's two's complement code (cornerness format).

    Parameters:
        width, height: frame size, 1..4096.
        blocks: (BX, BY), each 1..16 and at most the frame size; (1, 1) is a global threshold (per camera),
            written whatever the block bits of ``thr_addr``.

    Latency: 1 clock.

    Resources: BX*BY x 20 bits of LUT-RAM (stereo: two memories of 2^ceil(log2(BX BY)) entries), a flag
    register per entry, the threshold register (stereo: one per camera, and two comparators), the block
    position counters, one comparator; (1, 1): one threshold register per camera and no counters.
    """
    nb = corner_model.OUT.wl
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, width=nb, stereo=None)
    check_stream("source", source, width=nb, stereo=sink.stereo)
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
    cams = 2 if sink.stereo else 1
    if len(thr_addr) < abits + cams - 1:
        raise block_error(f"port thr_addr needs {abits + cams - 1} bits for {nblk} blocks"
                          f"{' of two cameras' if sink.stereo else ''}, has {len(thr_addr)}")

    if nblk == 1:
        return global_threshold(clk, rst, sink, source, thr_we, thr_addr, thr_data)

    x = Signal(intbv(0, min=0, max=width))
    y = Signal(intbv(0, min=0, max=height))
    blk = Signal(intbv(0, min=0, max=nblk))
    ahead = Signal(intbv(0, min=0, max=nblk))  # the block of the beat due next
    value = fx_signal(corner_model.OUT)

    @always_comb
    def signed_view():
        value.next = sink.data

    position = block_position(clk, rst, sink, x, y, blk, ahead, width=width, height=height, blocks=blocks)
    if sink.stereo:
        return [signed_view, position, camera_tables(clk, rst, sink, source, value, thr_we, thr_addr, thr_data,
                                                     ahead, abits=abits, nblk=nblk)]
    stored = Signal(intbv(0)[nb:])
    thr = fx_signal(corner_model.OUT)  # the threshold of the beat due, registered
    mem = [Signal(intbv(0)[nb:]) for _ in range(nblk)]
    written = Signal(intbv(0)[nblk:])
    we = Signal(bool(0))

    @always(clk.posedge)
    def ram():
        if we:
            mem[thr_addr].next = thr_data

    @always_comb
    def read():
        stored.next = mem[ahead]


    return [write_check(thr_we, thr_addr, we, limit=nblk), ram, written_flags(clk, rst, we, thr_addr, written), read,
            entry_register(clk, rst, written, ahead, stored, thr), signed_view, position,
            pass_greater(clk, rst, sink, source, value, thr)]


@block
def write_check(thr_we, thr_addr, we, *, limit: int):
    """``we`` = ``thr_we`` for an address below ``limit`` (the table's entries): a write to an index past
    the last block is ignored."""
    # When every address names a block the check is left out: GHDL 2.0's synthesis truncates the constant
    # of "thr_addr < 16" to 4 bits (0), and the netlist make synth measures would then never write a threshold.
    if limit >= (1 << len(thr_addr)):
        @always_comb
        def all_entries():
            we.next = thr_we
    else:
        @always_comb
        def all_entries():
            we.next = thr_we and thr_addr < limit
    return all_entries


@block
def written_flags(clk, rst, we, addr, written):
    """One flag per table entry, set by a write to it and cleared by ``rst``: an entry never written reads
    as threshold 0."""

    @always_seq(clk.posedge, reset=rst)
    def flags():
        if we:
            written.next[addr] = 1

    return flags


@block
def entry_register(clk, rst, written, index, stored, thr):
    """``thr`` takes the table word read at ``index`` (``stored``), or 0 when that entry was never written."""

    @always_seq(clk.posedge, reset=rst)
    def fetch():
        if written[index]:
            thr.next = stored
        else:
            thr.next = 0

    return fetch


@block
def camera_tables(clk, rst, sink, source, value, thr_we, thr_addr, thr_data, ahead, *, abits: int, nblk: int):
    """:func:`prethreshold` of a stereo stream in BX x BY blocks (``ahead``: the block of the beat due next).

    Entry 2 * block + cam of the table lives in the camera's memory (``mem_l``, ``mem_r``; the flags in
    one vector ``written``, indexed 2 * block + cam). Both cameras' thresholds of the block due next are
    read into registers (``thr_l``, ``thr_r``), and the beat is compared with both: the camera due
    (``due``) picks the result. So the table read waits for no decoding of the beat's flags, and no
    multiplexer stands in front of the comparators. The beat due next is the right camera's after a left
    beat, else the left camera's.
    """
    nb = len(thr_data)
    entries = 1 << (abits + 1)
    mem_l = [Signal(intbv(0)[nb:]) for _ in range(1 << abits)]
    mem_r = [Signal(intbv(0)[nb:]) for _ in range(1 << abits)]
    written = Signal(intbv(0)[entries:])
    we, we_l, we_r = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    wblk = Signal(intbv(0)[abits:])
    raddr_l, raddr_r = Signal(intbv(0)[abits + 1:]), Signal(intbv(0)[abits + 1:])
    stored_l, stored_r = Signal(intbv(0)[nb:]), Signal(intbv(0)[nb:])
    thr_l, thr_r = fx_signal(corner_model.OUT), fx_signal(corner_model.OUT)
    due = Signal(bool(0))  # the camera of the beat due now
    due_next = Signal(bool(0))

    @always_comb
    def split():
        wblk.next = thr_addr[abits + 1:1]
        we_l.next = we and not thr_addr[0]
        we_r.next = we and thr_addr[0]
        raddr_l.next = concat(ahead, False)
        raddr_r.next = concat(ahead, True)

    @always(clk.posedge)
    def ram():
        if we_l:
            mem_l[wblk].next = thr_data
        if we_r:
            mem_r[wblk].next = thr_data

    @always_comb
    def camera_due():
        if sink.valid:
            due_next.next = not sink.cam and not (sink.eof and not sink.eol)
        else:
            due_next.next = due

    @always_seq(clk.posedge, reset=rst)
    def camera():
        due.next = due_next

    @always_comb
    def read():
        stored_l.next = mem_l[ahead]
        stored_r.next = mem_r[ahead]


    return [write_check(thr_we, thr_addr, we, limit=2 * nblk), split, ram,
            written_flags(clk, rst, we, thr_addr, written), camera_due, camera, read,
            entry_register(clk, rst, written, raddr_l, stored_l, thr_l),
            entry_register(clk, rst, written, raddr_r, stored_r, thr_r),
            pass_greater(clk, rst, sink, source, value, thr_l, thr_r, due)]


@block
def global_threshold(clk, rst, sink, source, thr_we, thr_addr, thr_data):
    """blocks=(1, 1): one threshold register per camera (stereo: ``thr_addr``'s bit 0 is the camera), no
    counters. As on a mono stream, the block bits of the address are not looked at: every write is to
    the one block."""
    thr = fx_signal(corner_model.OUT)
    value = fx_signal(corner_model.OUT)
    stored = Signal(intbv(0)[len(thr_data):])
    if sink.stereo:
        stored_r = Signal(intbv(0)[len(thr_data):])

        @always_seq(clk.posedge, reset=rst)
        def registers():
            if thr_we:
                if thr_addr[0]:
                    stored_r.next = thr_data
                else:
                    stored.next = thr_data

        @always_comb
        def choose():
            value.next = sink.data
            if sink.cam:
                thr.next = stored_r
            else:
                thr.next = stored

        return registers, choose, pass_greater(clk, rst, sink, source, value, thr)

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
def pass_greater(clk, rst, sink, source, value, thr, thr_right=None, right=None):
    """The output register: the sink's beat (``cam`` too on a stereo stream), its data kept where
    value > thr, else 0. With ``thr_right`` and ``right``: value > (thr_right where ``right``, else thr),
    both comparisons made and the result picked (no multiplexer in front of a comparator)."""

    @always_seq(clk.posedge, reset=rst)
    def emit():
        source.valid.next = sink.valid
        source.eol.next = sink.eol
        source.eof.next = sink.eof

    # The data register has no reset (its value counts only with valid): the comparison alone clears it, as
    # the flip-flops' synchronous reset, with no gate before.
    if thr_right is None:
        @always(clk.posedge)
        def data():
            if value > thr:
                source.data.next = sink.data
            else:
                source.data.next = 0

        insts = [emit, data]
    else:
        gt_l, gt_r, keep = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))

        # An AND-OR rather than an if: a multiplexer of two comparisons would be folded by the synthesis
        # into one comparison of multiplexed operands.
        @always_comb
        def compare():
            gt_l.next = value > thr
            gt_r.next = value > thr_right

        @always_comb
        def pick():
            keep.next = (gt_l and not right) or (gt_r and right)

        @always(clk.posedge)
        def data():
            if keep:
                source.data.next = sink.data
            else:
                source.data.next = 0

        insts = [emit, compare, pick, data]
    if not sink.stereo:
        return insts

    @always_seq(clk.posedge, reset=rst)
    def camera():
        source.cam.next = sink.cam

    return insts + [camera]
