"""Corner descriptors: the rectified stereo stream and its corner flags in, every corner's descriptor out (issue 29)."""

from myhdl import ConcatSignal, Signal, always, always_comb, always_seq, block, concat, enum, intbv

from eyestereo.hdl.common.checks import (block_error, check_choice, check_clock, check_distinct, check_frame,
                                         check_int, check_reset, check_signal, check_stream, checked)
from eyestereo.hdl.common.fifo import sync_fifo
from eyestereo.hdl.interfaces.descriptor import check_descriptor
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH
from eyestereo.tools.models import corner_descriptors as model
from eyestereo.tools.models import match_engine as engine_model

#: Clocks from a read's issue to its word on ``source``: the line buffers' read, the camera's byte, the
#: window column, the output register.
PIPELINE = 4
#: Rows the corner flags of ``harris_stereo`` lag its input by, at nms 3 (``harris_stereo.latency(3, s)[1]``).
DEFAULT_LEAD = 4


def lines(window: int, lead: int) -> int:
    """Line buffers of the block: the window's rows above the centre, the rows until both the flag and the
    window's last row have come (``max(window // 2, lead)``), and 3 rows of slack (a flag that comes in the row
    after its lead row still leaves its window a whole row before the reads' margin row)."""
    return window // 2 + max(window // 2, lead) + 3


@block
def corner_descriptors(clk, rst, sink, flags, source, late, lost, *, cost: str = "sad", window: int = 9,
                       width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT, border: int = 4,
                       lead: int = DEFAULT_LEAD, slots: int = 32):
    """Every flagged corner of both cameras with its descriptor, row by row, for the match engine.

    The first half of the hardware matcher (:func:`~eyestereo.hdl.matching.match_engine.match_engine` is the
    second): bit for bit :func:`eyestereo.tools.models.corner_descriptors.corner_descriptors` (the beats of a
    frame: each row's corners in the flags' order with their words, then the row's end).

    How: the pixels go into :func:`lines` line buffers of block RAM, one per row (modulo), each word the left
    and right pixel of one column; the flags are joined to them **by position**, not by counting beats, so
    any lag of the flags (Harris's rows and pipeline, a clock crossing) is allowed up to ``lead`` rows (and a
    row more). A flag at least ``border`` pixels from every edge becomes a pending corner (x, y, camera) in a
    queue of ``slots``; the queue's head waits until its window is complete in the buffers (the row
    ``y + window // 2`` written past column ``x + window // 2``), then its window is read a column per clock
    (every buffer at the same address, the rows rotated into place): SAD sends each column as a word, census
    reads the centre column first and sends one word of the ``window**2 - 1`` comparisons with the centre.
    When the flags of a row have all come and no corner of that row is left in the queue, the row's end goes
    out (``eof`` on the frame's last row). A head whose window has been overwritten (the flags too late) is
    dropped and counted in ``late``; a flag that finds the queue full is counted in ``lost``.

    Ports:
        clk, rst: clock and synchronous active-high reset.
        sink: stereo ImageStream, 8 bits: the rectified pixels, any beat spacing.
        flags: stereo ImageStream, 1 bit: the corner flags of the same frames (``harris_stereo``'s source, after
            any crossing), any beat spacing, up to ``lead`` rows (plus one) behind ``sink``.
        source: DescriptorPort of :func:`~eyestereo.tools.models.match_engine.word_bits` bits, the frame size.
        late, lost: outputs, 16 bits, saturating counts since ``rst`` of the corners dropped (their window gone;
            the queue full). While both stay 0 the beats are the model's.

    Reset tokens: one on ``sink`` restarts the pixel position; one on ``flags`` ends the frame in progress
    (its rows not yet flagged end without corners, so the engine sees a whole frame). Corners of a frame
    aborted by a token may get wrong windows; the frames after it are right.

    Parameters:
        cost: "sad" or "census"; window: 5, 7, 9 or 11.
        width, height: the frame size (width 16..4096, height 1..4096, both more than twice ``border``).
        border: corners closer to an edge are not sent; at least ``window // 2`` (every window inside the
            frame) and, for the frame's last corners, at least ``lead`` (their flags come before the next
            frame's pixels; :func:`feature_list <eyestereo.hdl.harris.feature_list.feature_list>`'s default
            3 + nms // 2 is harris_stereo's lead).
        lead: rows the flags lag the pixels by (harris_stereo's ``latency(nms, share)[1]``: 4 at nms 3), 0..15.
        slots: the pending queue's corners (a power of two, 4..256).

    Latency: a corner's first word :data:`PIPELINE` + 3 clocks after its flag, when its window is complete by
    then and the queue is empty (a corner takes ``window`` + 3 clocks, census one more); the row's end as soon
    as its corners are out.

    Resources: :func:`lines` block RAMs of ``width`` x 16 bits (9 x 9, lead 4: 11 at 352 wide), the queue in
    LUT-RAM, the rotation of ``lines`` bytes into the window's column (a barrel shifter), the output word;
    census ``window`` comparators and the word's ``window**2`` flip-flops. Measured (make synth's flow on this
    block, the catalogue's configuration: SAD 9 x 9, 352 x 288, lead 4, 32 slots): Yosys xc3se 1000 LUT, 569 FF,
    12 RAMB16 (the 11 buffers and the queue); ECP5 (LFE5U-25F) 589 FF, 11 DP16KD, the queue in LUT-RAM,
    122.6 / 128.8 / 134.6 MHz (min / median / max of nextpnr seeds 1-4; goal 100 MHz, the memory clock).
    """
    check_clock(clk)
    check_reset(rst)
    cost = check_choice("cost", cost, engine_model.COSTS)
    window = check_choice("window", window, engine_model.WINDOWS)
    width, height = check_frame(width, height)
    border = check_int("border", border, 0)
    lead = check_int("lead", lead, 0, 15)
    slots = check_int("slots", slots, 4, 256)
    if slots & (slots - 1):
        raise block_error(f"parameter slots={slots} must be a power of two")
    if width < 16:
        raise block_error(f"parameter width={width}: at least 16 (a window's reads must end before the pixels of "
                          "the row after next reach it)")
    checked(model.check_params, cost=cost, window=window, border=border, width=width, height=height)
    if border < lead:
        raise block_error(f"parameter border={border}: must be at least lead={lead} (the frame's last corners' flags "
                          "must come before the next frame's pixels overwrite their windows)")
    wb = engine_model.word_bits(cost, window)
    check_stream("sink", sink, width=8, stereo=True)
    check_stream("flags", flags, width=1, stereo=True)
    check_descriptor("source", source, data_width=wb, width=width, height=height)
    check_signal("late", late, width=16, signed=False)
    check_signal("lost", lost, width=16, signed=False)
    check_distinct(dict(source=source, late=late, lost=lost), dict(clk=clk, rst=rst, sink=sink, flags=flags))
    sad = cost == "sad"
    W = window
    r = W // 2
    L = lines(W, lead)
    xb, yb = (width - 1).bit_length(), (height - 1).bit_length()
    top = (1 << 16) - 1

    # ---------------------------------------------------------------------------------------------------
    # Writer: the pixel position and the line buffers (row wy in buffer ws; the left pixel waits for the right)
    wx = Signal(intbv(0, min=0, max=width + 1))  # columns written in the current row
    wy = Signal(intbv(0, min=0, max=height))
    wbit = Signal(bool(0))  # the frame's parity (both sides count frames: a corner is of the writer's or the last)
    ws = Signal(intbv(0, min=0, max=L))
    lpix = Signal(intbv(0)[8:])
    we = Signal(bool(0))
    wd = Signal(intbv(0)[16:])
    wa = Signal(intbv(0)[xb:])
    w_token = Signal(bool(0))

    @always_comb
    def writer_decode():
        w_token.next = sink.valid and sink.eof and not sink.eol
        we.next = sink.valid and sink.cam and not (sink.eof and not sink.eol)
        wd.next = concat(sink.data, lpix)
        wa.next = wx[xb:]

    @always_seq(clk.posedge, reset=rst)
    def writer():
        if w_token:
            wx.next = 0
            wy.next = 0
            wbit.next = False
        elif sink.valid and not sink.cam:
            lpix.next = sink.data
        elif we:
            if sink.eol:
                wx.next = 0
                ws.next = 0 if ws == L - 1 else ws + 1
                if sink.eof:
                    wy.next = 0
                    wbit.next = not wbit
                else:
                    wy.next = wy + 1
            else:
                wx.next = wx + 1

    raddr = Signal(intbv(0)[xb:])
    rcam = Signal(bool(0))  # the camera of the read issued (a clock later: the byte to take)
    qbytes = [Signal(intbv(0)[8:]) for _ in range(L)]
    buffers = [line_buffer(clk, we, ws, wa, wd, raddr, rcam, qbytes[j], index=j, width=width) for j in range(L)]
    qall = ConcatSignal(*reversed(qbytes))  # buffer j's byte at bits 8 j + 7 .. 8 j

    # ---------------------------------------------------------------------------------------------------
    # Flags: the position, the border, the pending queue, the rows ended
    fx = Signal(intbv(0, min=0, max=width))
    fy = Signal(intbv(0, min=0, max=height))
    fbit = Signal(bool(0))
    f_token, f_right = Signal(bool(0)), Signal(bool(0))
    in_border = Signal(bool(0))
    eb = xb + yb + 2
    q_in, q_out = Signal(intbv(0)[eb:]), Signal(intbv(0)[eb:])
    q_push, q_pop, q_valid = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    q_count = Signal(intbv(0, min=0, max=slots + 1))
    # rows whose flags have all come, and rows whose end has gone out (counted modulo: only their difference counts,
    # kept apart so that neither count adds more than one term)
    cb = (4 * height).bit_length()
    flagged, ended = Signal(intbv(0)[cb:]), Signal(intbv(0)[cb:])
    fleft = Signal(intbv(height, min=0, max=height + 1))  # the flags' rows left in the frame (height - fy)
    pending = Signal(bool(0))  # a row's flags have all come and its end has not gone out
    row_done = Signal(bool(0))  # the FSM sends a row's end this clock
    lost_n, late_n = Signal(intbv(0)[16:]), Signal(intbv(0)[16:])
    lost_inc, late_inc = Signal(bool(0)), Signal(bool(0))

    @always_comb
    def flag_decode():
        f_token.next = flags.valid and flags.eof and not flags.eol
        f_right.next = flags.valid and flags.cam and not (flags.eof and not flags.eol)
        in_border.next = fx >= border and fx < width - border and fy >= border and fy < height - border
        q_in.next = concat(fbit, flags.cam, fy[yb:], fx[xb:])

    @always_comb
    def flag_push():
        hit = flags.valid and not (flags.eof and not flags.eol) and flags.data[0] and in_border
        q_push.next = hit and q_count != slots
        lost_inc.next = hit and q_count == slots

    @always_seq(clk.posedge, reset=rst)
    def flag_side():
        nxt = intbv(0)[cb + 1:]
        if f_token:
            if fx != 0 or fy != 0:
                nxt[:] = flagged + fleft  # the frame in progress ends: its rows left end without corners
                flagged.next = nxt[cb:]
            fx.next = 0
            fy.next = 0
            fleft.next = height
            fbit.next = False
        elif f_right:
            if flags.eol:
                nxt[:] = flagged + 1
                flagged.next = nxt[cb:]
                fx.next = 0
                if flags.eof:
                    fy.next = 0
                    fleft.next = height
                    fbit.next = not fbit
                else:
                    fy.next = fy + 1
                    fleft.next = fleft - 1
            else:
                fx.next = fx + 1
        if lost_inc and lost_n != top:
            lost_n.next = lost_n + 1
        if late_inc and late_n != top:
            late_n.next = late_n + 1

    @always_seq(clk.posedge, reset=rst)
    def rows_ended():
        nxt = intbv(0)[cb + 1:]
        if row_done:
            nxt[:] = ended + 1
            ended.next = nxt[cb:]

    @always_comb
    def rows_pending():
        pending.next = flagged != ended

    queue = sync_fifo(clk, rst, q_in, q_push, q_out, q_pop, q_count, q_valid, depth=slots)

    @always_comb
    def counts():
        late.next = late_n
        lost.next = lost_n

    # ---------------------------------------------------------------------------------------------------
    # The state machine: the queue's head, its window's readiness, the reads; the rows' ends.
    # (states named ST_*: an enumeration literal may not share a signal's name in case-insensitive VHDL)
    State = enum("ST_IDLE", "ST_READ")
    state = Signal(State.ST_IDLE)
    hx = Signal(intbv(0, min=0, max=width))
    hx0 = Signal(intbv(0, min=0, max=width))  # the window's first column, hx - r (the border keeps it >= 0)
    hy = Signal(intbv(0, min=0, max=height))
    hcam = Signal(bool(0))
    # every clock, from the head and the writer's registers: the rows the writer is past the head's row, and the
    # writer's column and buffer of that clock; decided on in the next ("fresh": the head has not changed since)
    row_lag = Signal(intbv(0, min=-height, max=2 * height))
    ws_s = Signal(intbv(0, min=0, max=L))
    v_prev, pop_prev, fresh, x_ok = Signal(bool(0)), Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    ready, too_late = Signal(bool(0)), Signal(bool(0))
    oy = Signal(intbv(0, min=0, max=height))  # the next row to end
    k = Signal(intbv(0, min=0, max=W + 1))  # the column read next (census: the centre first, then 0 .. W - 1)
    centre_done = Signal(bool(0))
    # the issue stage's tags (registers): what the read in flight is for
    i_valid, i_row_end, i_eof, i_cam, i_last, i_centre = (Signal(bool(0)) for _ in range(6))
    i_x = Signal(intbv(0, min=0, max=width))
    i_y = Signal(intbv(0, min=0, max=height))
    i_s0 = Signal(intbv(0, min=0, max=L))
    s0 = Signal(intbv(0, min=0, max=L))
    head_x = Signal(intbv(0, min=0, max=width))
    head_y = Signal(intbv(0, min=0, max=height))
    head_cam, head_bit = Signal(bool(0)), Signal(bool(0))

    @always_comb
    def head_fields():
        head_x.next = q_out[xb:]
        head_y.next = q_out[xb + yb:xb]
        head_cam.next = q_out[xb + yb]
        head_bit.next = q_out[xb + yb + 1]

    @always_seq(clk.posedge, reset=rst)
    def head_lag():
        # a corner is of the writer's frame or of the one before (its flag never comes before its pixel)
        if wbit == head_bit:
            row_lag.next = wy - head_y
        else:
            row_lag.next = wy + height - head_y
        x_ok.next = wx > head_x + r  # the window's last column is written (in the head's last row)
        ws_s.next = ws
        v_prev.next = q_valid
        pop_prev.next = q_pop

    @always_comb
    def head_state():
        fresh.next = q_valid and v_prev and not pop_prev
        # the window's top row is about to be overwritten (a row of margin for the reads), or it is complete
        too_late.next = row_lag >= L - r - 1
        ready.next = row_lag > r or (row_lag == r and x_ok)

    @always_comb
    def machine_comb():
        q_pop.next = False
        late_inc.next = False
        row_done.next = False
        if state == State.ST_IDLE:
            if pending and (q_count == 0 or (q_valid and head_y != oy)):
                row_done.next = True
            elif fresh and too_late:
                q_pop.next = True
                late_inc.next = True
            elif fresh and ready:
                q_pop.next = True

    @always_seq(clk.posedge, reset=rst)
    def machine():
        t = intbv(0, min=-2 * height - L, max=L + 1)
        i_valid.next = False
        i_row_end.next = False
        i_eof.next = False
        i_last.next = False
        i_centre.next = False
        if state == State.ST_IDLE:
            if row_done:
                i_valid.next = True
                i_row_end.next = True
                i_y.next = oy
                i_x.next = 0
                i_cam.next = False
                if oy == height - 1:
                    i_eof.next = True
                    oy.next = 0
                else:
                    oy.next = oy + 1
            elif q_pop and not late_inc:
                hx.next = head_x
                hx0.next = head_x - r
                hy.next = head_y
                hcam.next = head_cam
                t[:] = ws_s - row_lag - r  # the buffer holding the window's top row
                if t < 0:
                    s0.next = t + L
                else:
                    s0.next = t
                if sad:
                    k.next = 0
                    centre_done.next = True
                else:
                    k.next = r
                    centre_done.next = False
                state.next = State.ST_READ
        elif state == State.ST_READ:
            i_valid.next = True
            i_cam.next = hcam
            i_x.next = hx
            i_y.next = hy
            i_s0.next = s0
            raddr.next = hx0 + k  # unsigned + unsigned: no signed operand in MyHDL's Verilog
            rcam.next = hcam
            i_centre.next = not centre_done
            if not centre_done:
                centre_done.next = True
                k.next = 0
            elif k == W - 1:
                i_last.next = True
                state.next = State.ST_IDLE
            else:
                k.next = k + 1

    # ---------------------------------------------------------------------------------------------------
    # Pipeline: edge 1 the buffers' words, edge 2 the camera's bytes (in the buffers), edge 3 the window's
    # column (the buffers' bytes rotated so the top row is lowest), edge 4 the output.
    t1_valid, t1_row_end, t1_eof, t1_cam, t1_last, t1_centre = (Signal(bool(0)) for _ in range(6))
    t2_valid, t2_row_end, t2_eof, t2_cam, t2_last, t2_centre = (Signal(bool(0)) for _ in range(6))
    t3_valid, t3_row_end, t3_eof, t3_cam, t3_last, t3_centre = (Signal(bool(0)) for _ in range(6))
    t1_x, t2_x, t3_x = (Signal(intbv(0, min=0, max=width)) for _ in range(3))
    t1_y, t2_y, t3_y = (Signal(intbv(0, min=0, max=height)) for _ in range(3))
    t1_s0, t2_s0 = Signal(intbv(0, min=0, max=L)), Signal(intbv(0, min=0, max=L))
    col = Signal(intbv(0)[8 * W:])
    out_valid = Signal(bool(0))

    @always_seq(clk.posedge, reset=rst)
    def tags_valid():
        t1_valid.next = i_valid
        t2_valid.next = t1_valid
        t3_valid.next = t2_valid

    @always(clk.posedge)
    def tags():
        t1_row_end.next = i_row_end
        t1_eof.next = i_eof
        t1_cam.next = i_cam
        t1_last.next = i_last
        t1_centre.next = i_centre
        t1_x.next = i_x
        t1_y.next = i_y
        t1_s0.next = i_s0
        t2_row_end.next = t1_row_end
        t2_eof.next = t1_eof
        t2_cam.next = t1_cam
        t2_last.next = t1_last
        t2_centre.next = t1_centre
        t2_x.next = t1_x
        t2_y.next = t1_y
        t2_s0.next = t1_s0
        t3_row_end.next = t2_row_end
        t3_eof.next = t2_eof
        t3_cam.next = t2_cam
        t3_last.next = t2_last
        t3_centre.next = t2_centre
        t3_x.next = t2_x
        t3_y.next = t2_y

    @always(clk.posedge)
    def rotate():
        # the buffers' bytes twice in a row, shifted down by the top row's buffer: row i of the window lowest
        v = intbv(0)[16 * L:]
        v[:] = concat(qall, qall)
        v[:] = v >> (8 * t2_s0)
        col.next = v[8 * W:]

    insts = [writer_decode, writer, buffers, flag_decode, flag_push, flag_side, rows_ended, rows_pending, queue,
             counts, head_fields,
             head_lag, head_state, machine_comb, machine, tags_valid, tags, rotate]

    if sad:
        @always(clk.posedge)
        def words_out():
            source.data.next = col
        insts.append(words_out)
    else:
        # census: the centre's grey level from the first read, then each column's comparisons shifted in
        # (column k at bits W k + W - 1 .. W k); the word, in the window's raster order, is their wiring
        centre = Signal(intbv(0)[8:])
        less = [Signal(bool(0)) for _ in range(W)]
        lts = ConcatSignal(*reversed(less))
        cols = Signal(intbv(0)[W * W:])
        cnew = Signal(intbv(0)[W * W:])
        comps = [darker(col, centre, less[i], lo=8 * i) for i in range(W)]
        # bit of the raster neighbour (i, j): the top-left the most significant, the centre left out; it is bit
        # W j + i of the shifted columns
        src = [W * j + i for i in range(W) for j in range(W) if (i, j) != (r, r)]  # raster order: the MSB first
        cword = ConcatSignal(*(cnew(q) for q in src))

        @always_comb
        def shift_in():
            cnew.next = concat(lts, cols[W * W:W])

        @always(clk.posedge)
        def census_word():
            if t3_valid and t3_centre:
                centre.next = col[8 * r + 8:8 * r]
            elif t3_valid and not t3_row_end:
                cols.next = cnew
            source.data.next = cword

        insts += [comps, shift_in, census_word]

    @always_seq(clk.posedge, reset=rst)
    def valid_out():
        # census: one beat per corner (its last column); SAD: one per column
        out_valid.next = t3_valid and (t3_row_end or sad or t3_last)

    @always_comb
    def valid_port():
        source.valid.next = out_valid

    @always(clk.posedge)
    def fields_out():
        source.last.next = t3_last
        source.cam.next = t3_cam
        source.x.next = t3_x
        source.y.next = t3_y
        source.row_end.next = t3_row_end
        source.eof.next = t3_eof

    insts += [valid_out, valid_port, fields_out]
    return insts


@block
def line_buffer(clk, we, slot, wa, wd, ra, cam, q, *, index: int, width: int):
    """One line buffer: the left and right pixels of a row's columns (left low); the read's byte of camera
    ``cam`` two clocks after its address (the block RAM's read, then the byte into a register)."""
    mem_oreg_norw = [Signal(intbv(0)[16:]) for _ in range(width)]
    word = Signal(intbv(0)[16:])
    cam_r = Signal(bool(0))

    @always(clk.posedge)
    def ram():
        if we and slot == index:
            mem_oreg_norw[wa].next = wd
        word.next = mem_oreg_norw[ra]
        cam_r.next = cam

    @always(clk.posedge)
    def byte():
        if cam_r:
            q.next = word[16:8]
        else:
            q.next = word[8:0]

    return ram, byte


@block
def darker(col, centre, out, *, lo: int):
    """``out``: the 8-bit field at bit ``lo`` of ``col`` is darker than ``centre`` (a census bit)."""

    @always_comb
    def logic():
        out.next = col[lo + 8:lo] < centre

    return logic
