"""Feature list: stereo corner flags in, feature words (x, y, cam) out on a queue port, counts (thesis 7.1-7.2)."""

from myhdl import Signal, always, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.common.checks import (block_error, check_clock, check_distinct, check_frame, check_int,
                                         check_reset, check_signal, check_stream, checked)
from eyestereo.hdl.common.fifo import sync_fifo
from eyestereo.hdl.harris.block_position import block_position
from eyestereo.hdl.interfaces.queue import check_queue
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH, THRESHOLD_BLOCKS
from eyestereo.tools.models import feature_list as model
from eyestereo.tools.models.prethreshold import check_blocks

KIND_FEATURE, KIND_TRAILER, KIND_TOKEN = 0, 1, 2


def count_bits(width: int, height: int) -> int:
    """Bits of the count outputs: enough for every pixel of a frame."""
    return (width * height).bit_length()


def addr_bits(blocks) -> int:
    """Bits of ``count_addr``: the block index and the camera (address = 2 * block + cam)."""
    return max(1, (blocks[0] * blocks[1] - 1).bit_length()) + 1


@block
def feature_list(clk, rst, sink, source, count_addr, count_data, total_left, total_right, overflow, frame_done, *,
                 width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT, blocks: tuple[int, int] = THRESHOLD_BLOCKS,
                 border: int = 4, max_features: int = 1023, depth: int = 16):
    """The features of each stereo frame as a list of words on a queue port, and their counts.

    Every set flag at least ``border`` pixels from each edge is a feature (x, y, cam). Its 32-bit word
    (:data:`eyestereo.tools.models.feature_list.FEATURE`) goes into a ``depth``-entry FIFO (LUT-RAM)
    and leaves as two 16-bit queue words, low half first; after each frame's last flag a trailer
    (0xFFFF, count | overflow << 15) with ``eol``/``eof`` on its second word closes the list; a reset
    token on ``sink`` aborts the list with a queue reset token. The words are the format the SRAM
    feature writer (``sram_arbiter``'s ``feat`` port) stores and the host reads (see the model's
    module doc). At most ``max_features`` features per frame are listed; the others, and any that
    find the FIFO full (the consumer held ``ready`` low too long), set the overflow flag. A list's end
    that finds the FIFO full (a stall across two more frame ends) is replaced by a reset token as soon as
    there is room, and no feature is listed until then: that list is aborted, lists that ended meanwhile
    are dropped whole; a list is never closed with a wrong trailer, and no FIFO entry is overwritten.

    Counts: every feature is counted in a counter per (camera, threshold block) (BX x BY blocks as in
    the pre-threshold) and per camera. At the end of each frame (the right camera's last flag) they are
    published: ``total_left``, ``total_right``, ``overflow`` hold the last whole frame's figures,
    ``count_data`` shows the count of entry ``count_addr`` = 2 * block + cam of that frame (read
    combinationally from LUT-RAM), and ``frame_done`` pulses for one clock. Two banks of counters in
    LUT-RAM, cleared by a flag per entry, so publishing takes no clock.

    Ports:
        clk, rst: clock and synchronous active-high reset.
        sink: stereo ImageStream, 1 bit: corner flags (as from ``harris_stereo``), any beat spacing.
        source: QueuePort, 16 bits: the list words.
        count_addr: input, :func:`addr_bits` bits: 2 * block + cam.
        count_data, total_left, total_right: outputs, :func:`count_bits` bits.
        overflow: output: the last frame's list was cut.
        frame_done: output, one-clock pulse when the counts of a frame are published.

    Parameters:
        width, height: frame size (1..4096).
        blocks: (BX, BY) count blocks, each 1..16 (default 4x4, as the thresholds).
        border: pixels at the border without features (>= 1; harris_stereo's r = 3 + nms // 2).
        max_features: 1..32767 features per list (default 1023: 2048 words with the trailer).
        depth: FIFO entries, a power of two 4..64.

    Latency: a feature's first word is on ``source`` 2 clocks after its flag (FIFO empty, ``ready`` high;
    measured by the bench).
    Throughput: one word per clock, one feature per 2 clocks sustained; the FIFO absorbs bursts.

    Resources: the FIFO (34 x depth LUT-RAM), 2 x 2 x BX BY counters in LUT-RAM (read at two addresses
    besides the write's: the counter of the beat due, a clock ahead, and the published count; on a
    LUT-RAM with one read port of its own, as the Spartan-3E's, two copies), the counter register, the
    block position counters (:func:`~eyestereo.hdl.harris.block_position.block_position`) and two border
    flags.
    """
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, width=1, stereo=True)
    check_queue("source", source, width=16)
    width, height = check_frame(width, height)
    bxn, byn = checked(check_blocks, width, height, blocks)
    border = check_int("border", border, 1)
    max_features = check_int("max_features", max_features, 1, model.MAX_FEATURES)
    depth = check_int("depth", depth, 4, 64)
    if depth & (depth - 1):
        raise block_error(f"parameter depth={depth} must be a power of two")
    if 2 * border > min(width, height):
        raise block_error(f"parameter border={border} is more than half of a {width}x{height} frame")
    cb = count_bits(width, height)
    ab = addr_bits((bxn, byn))
    check_signal("count_addr", count_addr, width=ab, signed=False)
    check_signal("count_data", count_data, width=cb, signed=False)
    check_signal("total_left", total_left, width=cb, signed=False)
    check_signal("total_right", total_right, width=cb, signed=False)
    check_signal("overflow", overflow, width=1)
    check_signal("frame_done", frame_done, width=1)
    outs = dict(source=source, count_data=count_data, total_left=total_left, total_right=total_right,
                overflow=overflow, frame_done=frame_done)
    check_distinct(outs, dict(clk=clk, rst=rst, sink=sink, count_addr=count_addr))

    # Position of the beat (one for both cameras), its block, inside the border.
    x = Signal(intbv(0, min=0, max=width))
    y = Signal(intbv(0, min=0, max=height))
    blk = Signal(intbv(0)[ab - 1:])
    ahead = Signal(intbv(0)[ab - 1:])  # the block of the next beat
    token = Signal(bool(0))
    last = Signal(bool(0))  # the right camera's beat of the frame's last pixel
    hit = Signal(bool(0))  # a listed feature on this beat (not "event": a Verilog keyword)
    step = Signal(bool(0))  # the position moves on (as in block_position)
    inx, iny = Signal(bool(0)), Signal(bool(0))  # x / y inside the border
    # the column / row before the first inside and before the first outside the border; the frame's last
    x_in, x_out, y_in, y_out = border - 1, width - border - 1, border - 1, height - border - 1
    x_end, y_end = width - 1, height - 1

    @always_comb
    def decode():
        token.next = sink.valid and sink.eof and not sink.eol
        last.next = sink.valid and sink.eof and sink.eol and sink.cam
        step.next = sink.valid and (sink.cam or (sink.eof and not sink.eol))
        hit.next = sink.valid and not (sink.eof and not sink.eol) and sink.data[0] and inx and iny

    # Inside the border, as flags that follow the position (the moves of block_position): set one pixel
    # before the first column / row inside, cleared one before the first outside (both at once when no
    # column / row is inside), so that a beat's hit takes no comparison. Column and row 0 are outside.
    @always_seq(clk.posedge, reset=rst)
    def borders():  # (not "inside": a SystemVerilog keyword)
        if step:
            if sink.eof:
                inx.next = False
                iny.next = False
            elif sink.eol or x == x_end:
                inx.next = False
                if y == y_end:
                    iny.next = False
                else:
                    iny.next = (iny or y == y_in) and y != y_out
            else:
                inx.next = (inx or x == x_in) and x != x_out

    # Counters: LUT-RAM of 2 banks x 2^ab entries, address (bank, block, cam); a "fresh" flag per entry
    # says it was written in its bank's frame (a cleared flag reads as 0), so a bank is cleared in one
    # clock. The flags are kept as the counting bank's and the published bank's (they move over when the
    # banks swap). The counters of the block due next (both cameras') and their flags are read a clock ahead
    # (the block from the block position's ``ahead``) into registers, and the camera due (the one after the
    # last beat's: left after a right beat or a token) picks one; the increment starts from it. On the stereo
    # protocol no beat's counter is the one its predecessor (the clock before) writes; a beat that breaks the
    # left-right order (two of one camera in turn) is counted from the other camera's counter.
    nent = 1 << ab
    cmem = [Signal(intbv(0)[cb:]) for _ in range(2 * nent)]
    fcnt = Signal(intbv(0)[nent:])  # the counting bank's flags
    fpub = Signal(intbv(0)[nent:])  # the published bank's
    bank = Signal(bool(0))
    nbank = Signal(bool(0))
    cidx = Signal(intbv(0)[ab:])
    waddr = Signal(intbv(0)[ab + 1:])
    raddr = Signal(intbv(0)[ab + 1:])
    rfresh = Signal(bool(0))
    due = Signal(bool(0))  # the camera of the beat due now
    due_next = Signal(bool(0))
    # both cameras' counters of the block due next, and their flags, registered; the camera due picks one after
    # the registers (issue 26: picking it before the read made the beat's camera -> LUT-RAM address -> register
    # the memory clock's slowest path of the single-clock front end)
    aidx_l, aidx_r = Signal(intbv(0)[ab:]), Signal(intbv(0)[ab:])
    aaddr_l, aaddr_r = Signal(intbv(0)[ab + 1:]), Signal(intbv(0)[ab + 1:])
    aread_l, aread_r = Signal(intbv(0)[cb:]), Signal(intbv(0)[cb:])
    afresh_l, afresh_r = Signal(bool(0)), Signal(bool(0))
    cur = Signal(intbv(0)[cb:])
    tot0 = Signal(intbv(0)[cb:])
    tot1 = Signal(intbv(0)[cb:])
    listed = Signal(intbv(0, min=0, max=model.MAX_FEATURES + 1))
    ovf = Signal(bool(0))

    @always_comb
    def caddr():
        cidx.next = concat(blk, sink.cam)
        waddr.next = concat(bank, blk, sink.cam)
        nbank.next = not bank
        raddr.next = concat(nbank, count_addr)

    @always_comb
    def cflags():
        if sink.valid:
            due_next.next = not sink.cam and not (sink.eof and not sink.eol)
        else:
            due_next.next = due
        aidx_l.next = concat(ahead, False)
        aidx_r.next = concat(ahead, True)
        aaddr_l.next = concat(bank, ahead, False)
        aaddr_r.next = concat(bank, ahead, True)
        rfresh.next = fpub[count_addr]

    @always_comb
    def cread():
        if rfresh:
            count_data.next = cmem[raddr]
        else:
            count_data.next = 0
        if due:
            if afresh_r:
                cur.next = aread_r
            else:
                cur.next = 0
        elif afresh_l:
            cur.next = aread_l
        else:
            cur.next = 0

    @always_seq(clk.posedge, reset=rst)
    def cahead():
        due.next = due_next
        aread_l.next = cmem[aaddr_l]
        aread_r.next = cmem[aaddr_r]
        # a list's end clears the bank that counts next (token: this one; last: the other)
        afresh_l.next = fcnt[aidx_l] and not (token or last)
        afresh_r.next = fcnt[aidx_r] and not (token or last)

    @always(clk.posedge)
    def cwrite():
        if hit:
            cmem[waddr].next = cur + 1

    # FIFO of entries kind (2 bits) | 32-bit payload.
    din = Signal(intbv(0)[34:])
    dout = Signal(intbv(0)[34:])
    push, pop, fvalid = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    fcount = Signal(intbv(0, min=0, max=depth + 1))
    accept = Signal(bool(0))
    fx = Signal(intbv(0)[15:])
    fy = Signal(intbv(0)[16:])
    tcount = Signal(intbv(0)[15:])
    # constants (never driven)
    k_feature = Signal(intbv(KIND_FEATURE)[2:])
    k_trailer = Signal(intbv(KIND_TRAILER)[2:])
    k_token = Signal(intbv(KIND_TOKEN)[2:])
    marker = Signal(intbv(model.MARKER)[16:])
    zero32 = Signal(intbv(0)[32:])

    # A list's end (trailer or token) that finds the FIFO full (the consumer held ``ready`` low across two
    # more frame ends: features stop at depth - 2, ends did not) is not pushed: an entry would be
    # overwritten (found by the formal proof, docs/formal.md). ``lost_end`` remembers it; until a reset token
    # is pushed in its place (at the first clock with room), no feature is listed, so the consumer sees the
    # list whose end was lost cut by that token, and the lists that ended meanwhile not at all.
    lost_end = Signal(bool(0))
    room = Signal(bool(0))

    @always_comb
    def entry():
        room.next = fcount < depth
        accept.next = hit and listed < max_features and fcount < depth - 2 and not lost_end
        fx.next = x
        fy.next = y
        tcount.next = listed
        push.next = (hit and listed < max_features and fcount < depth - 2 and not lost_end) or (
            (last or token or lost_end) and fcount < depth)
        if token or lost_end:
            din.next = concat(k_token, zero32)
        elif last:
            din.next = concat(k_trailer, ovf, tcount, marker)
        else:
            din.next = concat(k_feature, fy, sink.cam, fx)

    @always_seq(clk.posedge, reset=rst)
    def ends():
        if (last or token) and not room:
            lost_end.next = True
        elif lost_end and room:
            lost_end.next = False

    @always_seq(clk.posedge, reset=rst)
    def lists():
        frame_done.next = False
        if token:
            listed.next = 0
            ovf.next = False
            tot0.next = 0
            tot1.next = 0
            fcnt.next = 0
        elif last:
            # publish: the other bank becomes the counting one, cleared by its flags
            listed.next = 0
            ovf.next = False
            total_left.next = tot0
            total_right.next = tot1
            overflow.next = ovf
            tot0.next = 0
            tot1.next = 0
            frame_done.next = True
            bank.next = not bank
            fpub.next = fcnt
            fcnt.next = 0
        elif hit:
            fcnt.next[cidx] = 1
            if sink.cam:
                tot1.next = tot1 + 1
            else:
                tot0.next = tot0 + 1
            if accept:
                listed.next = listed + 1
            else:
                ovf.next = True

    # Serializer: an entry leaves as two words (a token as one).
    half = Signal(bool(0))
    kind = Signal(intbv(0)[2:])
    move = Signal(bool(0))

    @always_comb
    def serial():
        kind.next = dout[34:32]
        source.valid.next = fvalid
        if half:
            source.data.next = dout[32:16]
        elif dout[34:32] == KIND_TOKEN:
            source.data.next = 0
        else:
            source.data.next = dout[16:0]
        source.eol.next = half and dout[34:32] == KIND_TRAILER
        source.eof.next = (half and dout[34:32] == KIND_TRAILER) or (not half and dout[34:32] == KIND_TOKEN)
        move.next = fvalid and source.ready
        pop.next = fvalid and source.ready and (half or dout[34:32] == KIND_TOKEN)

    @always_seq(clk.posedge, reset=rst)
    def halves():
        if move:
            if half or kind == KIND_TOKEN:
                half.next = False
            else:
                half.next = True

    return [decode, block_position(clk, rst, sink, x, y, blk, ahead, width=width, height=height, blocks=(bxn, byn)),
            borders, caddr, cflags, cahead, cread, cwrite, entry, ends, lists, serial, halves,
            sync_fifo(clk, rst, din, push, dout, pop, fcount, fvalid, depth=depth)]
