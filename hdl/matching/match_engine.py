"""Match engine: corner descriptors of both cameras in, the frame's match list out (issue 29)."""

from myhdl import Signal, always, always_comb, always_seq, block, concat, enum, intbv

from eyestereo.hdl.common.checks import (block_error, check_choice, check_clock, check_distinct,
                                         check_int, check_reset, check_signal)
from eyestereo.hdl.common.fifo import sync_fifo
from eyestereo.hdl.common.arith import chunk_count, sum_tree
from eyestereo.hdl.interfaces.descriptor import check_descriptor
from eyestereo.hdl.interfaces.queue import check_queue
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH
from eyestereo.tools.models import match_engine as model

#: Clocks from a pair's last word read to its cost's comparison (RAM, register, element, group sums,
#: total, accumulation, compare).
PIPELINE = 7


def limit_bits() -> int:
    """Bits of the ``limit`` port: 0..MAX_LIMIT."""
    return model.MAX_LIMIT.bit_length()


@block
def match_engine(clk, rst, sink, source, limit, uniqueness, lr_check, dropped, *, cost: str = "sad",
                 window: int = 9, width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT, d_min: int = 0,
                 d_max: int = 64, rows: int = 0, slots: int = 64, corners: int = 1023, max_matches: int = 1023,
                 events: int = 16):
    """The match list of each frame from the corners' descriptors: candidates, costs, best and second best,
    threshold, uniqueness, left-right check (:func:`eyestereo.tools.models.match_engine.match_engine`, bit for
    bit: the same words).

    How: each camera's descriptors go into a circular store of ``slots`` corners as they come (the sink
    side). A row-end beat queues the two stores' write pointers (an event); the matching side takes the
    events in order and keeps the pointers of the last 2 R + 2 rows, so the corners of any row are a
    pointer range. When row y has ended, left row y - R is matched: for each of its corners (in order) the
    right corners of rows y - 2R .. y are read one descriptor word per clock, the candidates (disparity in
    ``d_min .. d_max``) costed in a pipeline (:data:`PIPELINE` clocks: absolute differences or differing
    bits, two levels of sums, the words of a pair accumulated) and ranked by the order key
    (:data:`~eyestereo.tools.models.match_engine.KEY`): the best key and the second-lowest cost per left
    corner, and per right corner the best key and its left corner so far (a read-modify-write in the right
    store's record; the pipeline drains between left corners so no record is read before its last write).
    The left corner's verdict (threshold, uniqueness: two products) goes into a result table indexed by
    its number in the frame. Then right row y - 2R leaves the store: its corners' best left corners are
    final, and each such left corner gets its left-right flag (its choice is this right corner). After the
    frame's last row the engine runs 2 R more rows without input (the last rows' left corners, the last
    right rows' flags), then writes the list: the result table in order, a :data:`~eyestereo.tools.models.
    match_engine.MATCH` (three words) for each accepted corner, then the trailer; then the next frame's
    events. Meanwhile the sink side keeps storing the next frame's corners.

    Ports:
        clk, rst: clock and synchronous active-high reset.
        sink: DescriptorPort (:mod:`eyestereo.hdl.interfaces.descriptor`) of
            :func:`~eyestereo.tools.models.match_engine.word_bits` bits and the frame size.
        source: QueuePort, 16 bits: the match list (the model's ``words``); ``eol`` and ``eof`` on the
            trailer's last word.
        limit: input, :func:`limit_bits` bits: a best cost is accepted below it (1..4096).
        uniqueness: input, 7 bits: percent (0 off, at most 99): accepted when best * (100 + u) <= second * 100.
        lr_check: input: keep only the matches whose right corner has no better left corner.
        dropped: output, sticky until ``rst``: a corner found its store full, a row end found the event queue
            full, or a frame had more than ``corners`` left corners; the lists are not the model's then.
        The inputs are read while a frame's list is computed: change them between frames.

    Parameters:
        cost: "sad" or "census"; window: 5, 7, 9 or 11 (the descriptor's words and bits follow).
        width, height: frame size (each 2..4096).
        d_min, d_max: the disparity range 0 <= d_min <= d_max <= 255.
        rows: R, 0..7: the right corners of rows yl - R .. yl + R are candidates.
        slots: corners each store holds (a power of two, 4..1024): the corners of 2 R + 1 rows and those
            of the rows still waiting.
        corners: left corners per frame, 1..32767 (the result table's depth, rounded up to a power of two).
        max_matches: 1..32767 matches listed per frame; more set the trailer's overflow flag.
        events: row ends the queue holds (a power of two, 2..64).

    Latency: a frame's list starts after its last row-end beat and the 2 R rows after it; each left corner
    takes (candidate range) x words + :data:`PIPELINE` + 4 clocks, each right corner 3 clocks to leave the
    store, each listed match 3 words (``ready`` high).

    Resources: the stores (descriptor words of ``slots`` x words rounded to a power of two per camera, the
    positions, the right corners' records of 40 bits), the result table (``corners`` x about 60 bits) and
    the flags, in block RAM; the event queue in LUT-RAM; the cost datapath: ``window`` 8-bit absolute
    differences and their sum (SAD) or ``window**2 - 1`` XOR gates and their count (census); two constant
    multiplications by up to 199 for the uniqueness test. Measured (make synth's flow, the catalogue's
    configuration: SAD 9 x 9, 352 x 288, 64 slots, 1023 corners): Yosys xc3se 1195 LUT + 15 LUT-RAM, 1192 FF,
    17 RAMB16, 2 MULT18X18; ECP5 (LFE5U-25F) 1973 LUT4, 1009 FF, 15 DP16KD, 2 MULT18X18D, 114.3 / 125.1 / 134.5
    MHz (min / median / max of nextpnr seeds 1-4; goal 100 MHz, the memory clock).
    """
    check_clock(clk)
    check_reset(rst)
    cost = check_choice("cost", cost, model.COSTS)
    window = check_choice("window", window, model.WINDOWS)
    width = check_int("width", width, 2, 4096)
    height = check_int("height", height, 2, 4096)
    d_min = check_int("d_min", d_min, 0, model.MAX_DISPARITY)
    d_max = check_int("d_max", d_max, 0, model.MAX_DISPARITY)
    if d_min > d_max:
        raise block_error(f"parameters d_min={d_min}, d_max={d_max}: the disparity range is empty")
    rows = check_int("rows", rows, 0, model.MAX_ROWS)
    slots = check_int("slots", slots, 4, 1024)
    if slots & (slots - 1):
        raise block_error(f"parameter slots={slots} must be a power of two")
    corners = check_int("corners", corners, 1, model.MAX_MATCHES)
    max_matches = check_int("max_matches", max_matches, 1, model.MAX_MATCHES)
    events = check_int("events", events, 2, 64)
    if events & (events - 1):
        raise block_error(f"parameter events={events} must be a power of two")
    wb = model.word_bits(cost, window)
    nw = model.descriptor_words(cost, window)
    check_descriptor("sink", sink, data_width=wb, width=width, height=height)
    check_queue("source", source, width=16)
    check_signal("limit", limit, width=limit_bits(), signed=False)
    check_signal("uniqueness", uniqueness, width=7, signed=False)
    check_signal("lr_check", lr_check, width=1)
    check_signal("dropped", dropped, width=1)
    check_distinct(dict(source=source, dropped=dropped),
                   dict(clk=clk, rst=rst, sink=sink, limit=limit, uniqueness=uniqueness, lr_check=lr_check))
    sad = cost == "sad"
    sb = slots.bit_length() - 1  # slot index bits; the pointers have one more (full / empty)
    kb = max(1, (nw - 1).bit_length())  # word index bits
    nwp = 1 << kb
    lb = max(1, (corners - 1).bit_length())  # left number bits
    nres = 1 << lb
    key_bits = model.KEY.width
    nring_r, nring_l = 2 * rows + 2, rows + 2

    # ---------------------------------------------------------------------------------------------------
    # Stores: descriptor words (slot, word), positions (y, x), right records (key, left number), valid flags.
    ldesc_oreg_norw = [Signal(intbv(0)[wb:]) for _ in range(slots * nwp)]
    rdesc_oreg_norw = [Signal(intbv(0)[wb:]) for _ in range(slots * nwp)]
    # (memory names: _norw, no read of an address in the clock it is written, so Yosys needs no collision
    # logic; _oreg, make synth moves the register after the read into the block RAM's output register, whatever
    # the logic after it: hdl/flow/bram_regs.py)
    lpos_norw = [Signal(intbv(0)[24:]) for _ in range(slots)]  # y << 12 | x
    rpos_oreg_norw = [Signal(intbv(0)[24:]) for _ in range(slots)]
    rrec_norw = [Signal(intbv(0)[key_bits + lb:]) for _ in range(slots)]
    rvalid = Signal(intbv(0)[slots:])
    # the result table, from bit 0: x (12), y (12), dy + 8 (4), d (8), cost (12: only accepted costs are
    # listed), the chosen right slot (sb), ok (1)
    rw_bits = 49 + sb
    res_oreg_norw = [Signal(intbv(0)[rw_bits:]) for _ in range(nres)]
    lrok_oreg_norw = [Signal(bool(0)) for _ in range(nres)]

    # sink side
    lw = Signal(intbv(0)[sb + 1:])  # write pointers (next free slot), one bit more than a slot index
    rw = Signal(intbv(0)[sb + 1:])
    lbase = Signal(intbv(0)[sb + 1:])  # the oldest slot still in use (written by the matching side)
    rbase = Signal(intbv(0)[sb + 1:])
    wk = Signal(intbv(0)[kb:])  # the word of the corner being written
    keep = Signal(bool(0))  # the corner being written has a slot
    full_l, full_r = Signal(bool(0)), Signal(bool(0))
    accept = Signal(bool(0))  # this beat's word is written
    dwe_l, dwe_r = Signal(bool(0)), Signal(bool(0))
    dwa = Signal(intbv(0)[sb + kb:])
    pwa = Signal(intbv(0)[sb:])
    x12, y12 = Signal(intbv(0)[12:]), Signal(intbv(0)[12:])
    pos_in = Signal(intbv(0)[24:])
    ev_in = Signal(intbv(0)[2 * sb + 3:])
    ev_push, ev_pop, ev_valid = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    ev_out = Signal(intbv(0)[2 * sb + 3:])
    ev_count = Signal(intbv(0, min=0, max=events + 1))
    drop_corner, drop_event = Signal(bool(0)), Signal(bool(0))

    @always_comb
    def sink_decode():
        full_l.next = lw[sb] != lbase[sb] and lw[sb:] == lbase[sb:]
        full_r.next = rw[sb] != rbase[sb] and rw[sb:] == rbase[sb:]
        x12.next = sink.x
        y12.next = sink.y
        ev_in.next = concat(sink.eof, lw, rw)
        ev_push.next = sink.valid and sink.row_end and ev_count != events

    @always_comb
    def position():
        pos_in.next = concat(y12, x12)

    @always_comb
    def sink_accept():
        if wk == 0:
            if sink.cam:
                accept.next = not full_r
            else:
                accept.next = not full_l
        else:
            accept.next = keep
        if sink.cam:
            dwa.next = concat(rw[sb:], wk)
            pwa.next = rw[sb:]
        else:
            dwa.next = concat(lw[sb:], wk)
            pwa.next = lw[sb:]

    @always_comb
    def sink_write():
        dwe_l.next = sink.valid and not sink.row_end and accept and not sink.cam
        dwe_r.next = sink.valid and not sink.row_end and accept and sink.cam
        drop_corner.next = sink.valid and not sink.row_end and wk == 0 and not accept
        drop_event.next = sink.valid and sink.row_end and ev_count == events

    @always_seq(clk.posedge, reset=rst)
    def sink_side():
        # pointers wrap by dropping the carry (a slice of a wider variable: MyHDL writes `%` of a pointer as a
        # signed modulo, which GHDL's netlist writer cannot write)
        nxt = intbv(0)[sb + 2:]
        if sink.valid and not sink.row_end:
            if sink.last:
                wk.next = 0
                if accept:
                    if sink.cam:
                        nxt[:] = rw + 1
                        rw.next = nxt[sb + 1:]
                    else:
                        nxt[:] = lw + 1
                        lw.next = nxt[sb + 1:]
            else:
                wk.next = (wk + 1) % nwp
            if wk == 0:
                keep.next = accept

    events_fifo = sync_fifo(clk, rst, ev_in, ev_push, ev_out, ev_pop, ev_count, ev_valid, depth=events)

    # ---------------------------------------------------------------------------------------------------
    # Matching side: read addresses and the pipeline's tags come from the state machine's registers.
    # (states named ST_*: VHDL is case-insensitive, and an enumeration literal may not share a signal's name)
    State = enum("ST_EVENT", "ST_ROW", "ST_NEXT_LEFT", "ST_LEFT_READ", "ST_LEFT_SETUP", "ST_SCAN", "ST_DRAIN",
                 "ST_VERDICT1", "ST_VERDICT2", "ST_EVICT", "ST_EVICT_READ", "ST_EVICT_RES", "ST_EVICT_WAIT",
                 "ST_EVICT_FLAG", "ST_EMIT",
                 "ST_EMIT_READ", "ST_EMIT_TEST", "ST_WORDS", "ST_FRAME_END")
    state = Signal(State.ST_EVENT)
    rsn = [Signal(intbv(0)[sb + 1:]) for _ in range(nring_r)]  # rsn[k]: right pointer after row (current - k)
    lsn = [Signal(intbv(0)[sb + 1:]) for _ in range(nring_l)]
    seen = Signal(intbv(0, min=0, max=height + 2 * rows + 2))  # ring shifts this frame (rows, real and virtual)
    tail = Signal(intbv(0, min=0, max=2 * rows + 2))
    last_event = Signal(bool(0))  # the frame's last row has come
    lcur = Signal(intbv(0)[sb + 1:])  # the left corner being matched
    lend = Signal(intbv(0)[sb + 1:])
    scur = Signal(intbv(0)[sb + 1:])  # the right corner being read
    send = Signal(intbv(0)[sb + 1:])
    kcur = Signal(intbv(0)[kb:])
    lid = Signal(intbv(0, min=0, max=nres + 1))  # the left corner's number in the frame
    xl = Signal(intbv(0)[12:])
    yl = Signal(intbv(0)[12:])
    drain = Signal(intbv(0, min=0, max=PIPELINE + 3))

    # read ports of the stores
    la = Signal(intbv(0)[sb + kb:])
    ra = Signal(intbv(0)[sb + kb:])
    lpa = Signal(intbv(0)[sb:])
    rsa = Signal(intbv(0)[sb:])
    ql, qr = Signal(intbv(0)[wb:]), Signal(intbv(0)[wb:])
    qlp, qrp, qrp2 = Signal(intbv(0)[24:]), Signal(intbv(0)[24:]), Signal(intbv(0)[24:])
    qrec = Signal(intbv(0)[key_bits + lb:])
    qval = Signal(bool(0))
    rec_we = Signal(bool(0))
    rec_wa = Signal(intbv(0)[sb:])
    rec_wd = Signal(intbv(0)[key_bits + lb:])
    val_set, val_clear = Signal(bool(0)), Signal(bool(0))
    val_clear_a = Signal(intbv(0)[sb:])
    res_a = Signal(intbv(0)[lb:])
    res_we = Signal(bool(0))
    res_wd = Signal(intbv(0)[rw_bits:])
    qres, qres_r = Signal(intbv(0)[rw_bits:]), Signal(intbv(0)[rw_bits:])
    ok_a = Signal(intbv(0)[lb:])
    ok_we, ok_wd, qok, qok_r = Signal(bool(0)), Signal(bool(0)), Signal(bool(0)), Signal(bool(0))

    @always_comb
    def read_addresses():
        la.next = concat(lcur[sb:], kcur)
        ra.next = concat(scur[sb:], kcur)
        lpa.next = lcur[sb:]
        rsa.next = scur[sb:]

    @always(clk.posedge)
    def left_store():
        if dwe_l:
            ldesc_oreg_norw[dwa].next = sink.data
        ql.next = ldesc_oreg_norw[la]

    @always(clk.posedge)
    def right_store():
        if dwe_r:
            rdesc_oreg_norw[dwa].next = sink.data
        qr.next = rdesc_oreg_norw[ra]

    @always(clk.posedge)
    def positions():
        if dwe_l and wk == 0:
            lpos_norw[pwa].next = pos_in
        if dwe_r and wk == 0:
            rpos_oreg_norw[pwa].next = pos_in
        qlp.next = lpos_norw[lpa]
        qrp.next = rpos_oreg_norw[rsa]

    @always(clk.posedge)
    def records():
        if rec_we:
            rrec_norw[rec_wa].next = rec_wd
        qrec.next = rrec_norw[rsa]

    @always_seq(clk.posedge, reset=rst)
    def valid_flags():
        v = intbv(0)[slots:]
        v[:] = rvalid
        if val_set:
            v[int(rec_wa)] = 1
        if val_clear:
            v[int(val_clear_a)] = 0
        rvalid.next = v
        qval.next = rvalid[rsa]

    @always(clk.posedge)
    def results():
        if res_we:
            res_oreg_norw[res_a].next = res_wd
        qres.next = res_oreg_norw[res_a]
        qres_r.next = qres  # read a clock later: the block RAM's clock-to-output alone is most of a clock

    @always(clk.posedge)
    def flags():
        if ok_we:
            lrok_oreg_norw[ok_a].next = ok_wd
        qok.next = lrok_oreg_norw[ok_a]
        qok_r.next = qok


    # ---------------------------------------------------------------------------------------------------
    # The cost pipeline. Clock n: the state machine holds (right slot, word) (``issue``); edge n + 1: the
    # RAMs' outputs (stage 1); + 2: their registers, the candidate test, d and dy (stage 2); + 3: per element
    # |l - r| (SAD) or the differing bits of a 3-bit chunk (census); + 4: group sums; + 5: the word's sum;
    # + 6: the pair's cost, its words accumulated (they come back to back); + 7: ranked (stage 7, in the
    # state machine's process); + 8: the right record written.
    issue = Signal(bool(0))
    t_go = [Signal(bool(0)) for _ in range(7)]  # index = stage (0 unused)
    t_first = [Signal(bool(0)) for _ in range(7)]
    t_last = [Signal(bool(0)) for _ in range(7)]
    t_slot = [Signal(intbv(0)[sb:]) for _ in range(7)]
    t_cand = [Signal(bool(0)) for _ in range(7)]
    t_d = [Signal(intbv(0)[8:]) for _ in range(7)]
    t_dyc = [Signal(intbv(0)[4:]) for _ in range(7)]
    t_ady = [Signal(intbv(0)[3:]) for _ in range(7)]
    t_rec = [Signal(intbv(0)[key_bits + lb:]) for _ in range(7)]
    t_val = [Signal(bool(0)) for _ in range(7)]
    ql2, qr2 = Signal(intbv(0)[wb:]), Signal(intbv(0)[wb:])

    if sad:
        nel, group, el_max = window, 4, 256
    else:
        nel, group, el_max = (wb + 2) // 3, 8, 4
    ngroups = (nel + group - 1) // group
    els = [Signal(intbv(0, min=0, max=el_max)) for _ in range(nel)]
    gsum = [Signal(intbv(0, min=0, max=(el_max - 1) * min(group, nel) + 1)) for _ in range(ngroups)]
    wsum = Signal(intbv(0, min=0, max=(el_max - 1) * nel + 1))
    acc = Signal(intbv(0)[15:])
    pc = Signal(intbv(0)[15:])  # the pair's cost (stage 6)
    key6 = Signal(intbv(0)[key_bits:])
    rec_key6 = Signal(intbv(0)[key_bits:])

    @always_comb
    def issuing():
        issue.next = state == State.ST_SCAN and scur != send

    @always(clk.posedge)
    def pipeline():
        # stage 1: the tags of the words read
        t_go[1].next = issue
        t_first[1].next = kcur == 0
        t_last[1].next = kcur == nw - 1
        t_slot[1].next = scur[sb:]
        # stage 2: the words, the right corner's record, flag and position registered
        ql2.next = ql
        qr2.next = qr
        t_rec[2].next = qrec
        t_val[2].next = qval
        qrp2.next = qrp
        # stage 3: the candidate test, d and dy, from the registered position
        xr = intbv(0)[13:]
        yr = intbv(0)[13:]
        xr[:] = qrp2[12:]
        yr[:] = qrp2[24:12]
        # d_min <= xl - xr <= d_max, without a negative number (the rows are right by the range read)
        t_cand[3].next = xl >= xr + d_min and xl <= xr + d_max
        # (the differences through 13-bit variables, sliced: no modulo, and in range while the pipeline reads
        # slots that are not candidates)
        dv = intbv(0)[13:]
        if xl >= xr:
            dv[:] = xl - xr
        t_d[3].next = dv[8:]
        yv = intbv(0)[13:]
        if yr + 8 >= yl:
            yv[:] = yr + 8 - yl
        t_dyc[3].next = yv[4:]
        av = intbv(0)[13:]
        if yr >= yl:
            av[:] = yr - yl
        else:
            av[:] = yl - yr
        t_ady[3].next = av[3:]
        for i in range(2, 7):
            t_go[i].next = t_go[i - 1]
            t_first[i].next = t_first[i - 1]
            t_last[i].next = t_last[i - 1]
            t_slot[i].next = t_slot[i - 1]
        for i in range(3, 7):
            t_rec[i].next = t_rec[i - 1]
            t_val[i].next = t_val[i - 1]
        for i in range(4, 7):
            t_cand[i].next = t_cand[i - 1]
            t_d[i].next = t_d[i - 1]
            t_dyc[i].next = t_dyc[i - 1]
            t_ady[i].next = t_ady[i - 1]

    datapath = []
    for j in range(nel):
        if sad:
            datapath.append(abs_diff(clk, ql2, qr2, els[j], lo=8 * j))
        else:
            datapath.append(chunk_count(clk, ql2, qr2, els[j], lo=3 * j, hi=min(wb, 3 * j + 3)))
    for g in range(ngroups):
        datapath.append(sum_tree(clk, els[g * group:(g + 1) * group], gsum[g]))
    datapath.append(sum_tree(clk, gsum, wsum))

    @always(clk.posedge)
    def accumulate():
        if t_first[5]:
            acc.next = wsum
            pc.next = wsum
        else:
            acc.next = acc + wsum
            pc.next = acc + wsum

    @always_comb
    def keys():
        key6.next = concat(pc, t_ady[6], t_d[6], t_dyc[6])
        rec_key6.next = t_rec[6][key_bits + lb:lb]

    # ---------------------------------------------------------------------------------------------------
    # The state machine (and stage 7, the ranking, in the same process: it owns the best and second best).
    best_key = Signal(intbv(0)[key_bits:])
    have_best, have_second = Signal(bool(0)), Signal(bool(0))
    second = Signal(intbv(0)[15:])
    choice = Signal(intbv(0)[sb:])
    cands = Signal(intbv(0)[16:])
    thr_ok = Signal(bool(0))
    p_best = Signal(intbv(0, min=0, max=(1 << 15) * 200))
    p_second = Signal(intbv(0, min=0, max=(1 << 15) * 100))
    ev_lw = Signal(intbv(0)[sb + 1:])
    ev_rw = Signal(intbv(0)[sb + 1:])
    ev_eof = Signal(bool(0))
    emit_i = Signal(intbv(0, min=0, max=nres + 1))
    count = Signal(intbv(0, min=0, max=model.MAX_MATCHES + 1))
    overflow = Signal(bool(0))
    out_w = Signal(intbv(0)[48:])
    out_k = Signal(intbv(0, min=0, max=3))
    trailer = Signal(bool(0))
    marker = Signal(intbv(model.MARKER)[16:])
    drop_any = Signal(bool(0))
    verdict = Signal(bool(0))  # the left corner is accepted (threshold and uniqueness)
    dy_top = Signal(bool(0))  # the top bit of a listed match's dy

    @always_comb
    def decide():
        verdict.next = thr_ok and (not have_second or p_best <= p_second)
        dy_top.next = not qres_r[27]

    @always_comb
    def event_head():
        ev_pop.next = state == State.ST_EVENT and ev_valid
        ev_rw.next = ev_out[sb + 1:]
        ev_lw.next = ev_out[2 * sb + 2:sb + 1]
        ev_eof.next = ev_out[2 * sb + 2]

    @always_seq(clk.posedge, reset=rst)
    def sticky():
        if drop_any or drop_corner or drop_event:
            dropped.next = True

    @always_seq(clk.posedge, reset=rst)
    def machine():
        ln = intbv(0)[sb + 2:]  # the next left / right slot pointer, before its carry is dropped
        sn = intbv(0)[sb + 2:]
        en = intbv(0)[lb + 2:]  # the next left number to list
        rec_we.next = False
        val_set.next = False
        val_clear.next = False
        res_we.next = False
        ok_we.next = False
        drop_any.next = False
        # stage 7: rank the pair whose last word's cost is at stage 6
        if t_go[6] and t_last[6] and t_cand[6]:
            if cands != 0xFFFF:
                cands.next = cands + 1
            if not have_best or key6 < best_key:
                best_key.next = key6
                choice.next = t_slot[6]
                have_best.next = True
                if have_best:
                    second.next = best_key[key_bits:key_bits - 15]
                    have_second.next = True
            elif not have_second or pc < second:
                second.next = pc
                have_second.next = True
            if not t_val[6] or key6 < rec_key6:
                rec_we.next = True
                val_set.next = True
                rec_wa.next = t_slot[6]
                rec_wd.next = concat(key6, lid[lb:])

        if state == State.ST_EVENT:
            if ev_valid:
                rsn[0].next = ev_rw
                for k in range(1, nring_r):
                    rsn[k].next = rsn[k - 1]
                lsn[0].next = ev_lw
                for k in range(1, nring_l):
                    lsn[k].next = lsn[k - 1]
                seen.next = seen + 1
                last_event.next = ev_eof
                state.next = State.ST_ROW
        elif state == State.ST_ROW:
            # left row seen - 1 - rows: [lsn[rows + 1], lsn[rows]) (empty before the frame's row `rows`)
            lcur.next = lsn[rows + 1]
            lend.next = lsn[rows]
            state.next = State.ST_NEXT_LEFT
        elif state == State.ST_NEXT_LEFT:
            if lcur == lend:
                scur.next = rsn[2 * rows + 1]
                send.next = rsn[2 * rows]
                state.next = State.ST_EVICT
            else:
                state.next = State.ST_LEFT_READ
        elif state == State.ST_LEFT_READ:  # the position is read at lcur
            state.next = State.ST_LEFT_SETUP
        elif state == State.ST_LEFT_SETUP:
            xl.next = qlp[12:]
            yl.next = qlp[24:12]
            have_best.next = False
            have_second.next = False
            scur.next = rsn[2 * rows + 1]
            send.next = rsn[0]
            kcur.next = 0
            if lid >= corners:
                drop_any.next = True
                ln[:] = lcur + 1
                lcur.next = ln[sb + 1:]
                state.next = State.ST_NEXT_LEFT
            else:
                state.next = State.ST_SCAN
        elif state == State.ST_SCAN:
            if scur == send:
                drain.next = PIPELINE + 2
                state.next = State.ST_DRAIN
            elif kcur == nw - 1:
                kcur.next = 0
                sn[:] = scur + 1
                scur.next = sn[sb + 1:]
            else:
                kcur.next = kcur + 1
        elif state == State.ST_DRAIN:
            if drain == 0:
                state.next = State.ST_VERDICT1
            else:
                drain.next = drain - 1
        elif state == State.ST_VERDICT1:
            thr_ok.next = have_best and best_key[key_bits:key_bits - 15] < limit
            p_best.next = best_key[key_bits:key_bits - 15] * (uniqueness + 100)
            p_second.next = second * 100
            state.next = State.ST_VERDICT2
        elif state == State.ST_VERDICT2:
            res_we.next = True
            res_a.next = lid[lb:]
            res_wd.next = concat(verdict, choice,
                                 best_key[key_bits - 3:key_bits - 15], best_key[12:4], best_key[4:], yl, xl)
            ok_we.next = True
            ok_a.next = lid[lb:]
            ok_wd.next = False
            lid.next = lid + 1
            ln[:] = lcur + 1
            lcur.next = ln[sb + 1:]
            state.next = State.ST_NEXT_LEFT
        elif state == State.ST_EVICT:  # right row seen - 1 - 2 rows leaves: [rsn[2 rows + 1], rsn[2 rows])
            if scur == send:
                lbase.next = lsn[rows]
                rbase.next = rsn[2 * rows]
                if not last_event:
                    state.next = State.ST_EVENT
                elif tail != 2 * rows:
                    # a row without input: the frame's last left rows and right rows' flags
                    for k in range(1, nring_r):
                        rsn[k].next = rsn[k - 1]
                    for k in range(1, nring_l):
                        lsn[k].next = lsn[k - 1]
                    seen.next = seen + 1
                    tail.next = tail + 1
                    state.next = State.ST_ROW
                else:
                    emit_i.next = 0
                    res_a.next = 0
                    ok_a.next = 0
                    count.next = 0
                    overflow.next = False
                    state.next = State.ST_EMIT
            else:
                state.next = State.ST_EVICT_READ
        elif state == State.ST_EVICT_READ:  # the record and the flag of slot scur are read
            if qval:
                res_a.next = qrec[lb:]
                ok_a.next = qrec[lb:]
                state.next = State.ST_EVICT_RES
            else:
                sn[:] = scur + 1
                scur.next = sn[sb + 1:]
                state.next = State.ST_EVICT
        elif state == State.ST_EVICT_RES:  # the result of its best left corner is read ...
            state.next = State.ST_EVICT_WAIT
        elif state == State.ST_EVICT_WAIT:  # ... and registered
            state.next = State.ST_EVICT_FLAG
        elif state == State.ST_EVICT_FLAG:
            # set, never cleared here: several right corners may have this left corner as their best
            if qres_r[48 + sb:48] == scur[sb:]:
                ok_we.next = True
                ok_wd.next = True
            val_clear.next = True
            val_clear_a.next = scur[sb:]
            sn[:] = scur + 1
            scur.next = sn[sb + 1:]
            state.next = State.ST_EVICT
        elif state == State.ST_EMIT:  # the result and the flag of left corner emit_i are read
            if emit_i == lid:
                out_w.next = concat(cands, overflow, count[15:], marker)
                out_k.next = 0
                trailer.next = True
                state.next = State.ST_WORDS
            else:
                state.next = State.ST_EMIT_READ
        elif state == State.ST_EMIT_READ:
            state.next = State.ST_EMIT_TEST
        elif state == State.ST_EMIT_TEST:
            emit_i.next = emit_i + 1
            en[:] = emit_i + 1
            res_a.next = en[lb:]
            ok_a.next = en[lb:]
            if qres_r[48 + sb] and (qok_r or not lr_check):
                if count == max_matches:
                    overflow.next = True
                    state.next = State.ST_EMIT
                else:
                    count.next = count + 1
                    # MATCH: x, dy (two's complement: dy + 8 with its top bit inverted), y, d, cost
                    out_w.next = concat(qres_r[48:36], qres_r[36:28], qres_r[24:12], dy_top, qres_r[27:24],
                                        qres_r[12:])
                    out_k.next = 0
                    trailer.next = False
                    state.next = State.ST_WORDS
            else:
                state.next = State.ST_EMIT
        elif state == State.ST_WORDS:
            if source.ready and out_valid:
                if out_k == 2:
                    if trailer:
                        state.next = State.ST_FRAME_END
                    else:
                        state.next = State.ST_EMIT
                else:
                    out_k.next = out_k + 1
        elif state == State.ST_FRAME_END:
            lid.next = 0
            cands.next = 0
            seen.next = 0
            tail.next = 0
            last_event.next = False
            trailer.next = False
            for k in range(1, nring_r):
                rsn[k].next = rsn[0]
            for k in range(1, nring_l):
                lsn[k].next = lsn[0]
            state.next = State.ST_EVENT

    out_valid = Signal(bool(0))  # source.valid, read here (VHDL-93 reads no output port)

    @always_comb
    def valid_out():
        source.valid.next = out_valid

    @always_seq(clk.posedge, reset=rst)
    def words_out():
        # the list's words: a register per field of the queue port, loaded as the state machine moves on
        if state == State.ST_WORDS and not (out_valid and source.ready and out_k == 2):
            out_valid.next = True
            k = intbv(0, min=0, max=4)
            if out_valid and source.ready:
                k[:] = out_k + 1
            else:
                k[:] = out_k
            if k == 0:
                source.data.next = out_w[16:]
            elif k == 1:
                source.data.next = out_w[32:16]
            else:
                source.data.next = out_w[48:32]
            source.eol.next = trailer and k == 2
            source.eof.next = trailer and k == 2
        else:
            out_valid.next = False

    return (sink_decode, position, sink_accept, sink_write, sink_side, events_fifo, read_addresses, left_store,
            right_store, positions, records, valid_flags, results, flags, issuing, pipeline, datapath,
            accumulate, keys, decide, event_head, sticky, machine, valid_out, words_out)


@block
def abs_diff(clk, a, b, out, *, lo: int):
    """Registered |a - b| of the 8-bit fields at bit ``lo`` of the two words (stage 3, SAD)."""

    @always(clk.posedge)
    def logic():
        x = intbv(0)[8:]
        y = intbv(0)[8:]
        x[:] = a[lo + 8:lo]
        y[:] = b[lo + 8:lo]
        if x >= y:
            out.next = x - y
        else:
            out.next = y - x

    return logic
