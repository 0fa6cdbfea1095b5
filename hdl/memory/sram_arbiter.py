"""SRAM arbiter: six masters of their own kinds share the SRAM controller's word port."""

from myhdl import ConcatSignal, Signal, always, always_comb, always_seq, block, concat, downrange, intbv

from eyestereo.hdl.common.checks import (block_error, check_bool, check_choice, check_clock, check_distinct,
                                         check_frame, check_int, check_reset, check_stream)
from eyestereo.hdl.common.packed import unpack_word
from eyestereo.hdl.common.registers import assign
from eyestereo.hdl.interfaces.fetch_port import check_fetch
from eyestereo.hdl.memory.frame_buffers import BufferSide, FrameControl, double_buffer
from eyestereo.hdl.interfaces.queue import check_queue
from eyestereo.hdl.interfaces.sram_bus import HostPort, SramCmd, SramRsp, StatPort, check_bundle
from eyestereo.hdl.memory.sram_masters import (ACCESS, TAG_BITS, EntrySignals, Head, camera_in, feature_in,
                                               fetch_slave, frame_writer, host_slave, rect_in)
from eyestereo.tools.models.sram_arbiter import MASTER_TABLE, AddressMap

NM = len(MASTER_TABLE)


def _check_port(master, port) -> None:
    """A master's port is of the kind its engine serves."""
    if master.engine in ("camera", "features"):
        check_queue(master.name, port, width=16)
    elif master.engine == "stereo":
        check_stream(master.name, port, width=8, stereo=True)
    elif master.engine == "fetch":
        check_fetch(master.name, port)
    else:
        check_bundle(master.name, port, HostPort)


def check_masters(clk, rst, cam0, cam1, fetch, rect, feat, host, ctl, stat, *, width, height, feature_words, depth,
                  burst, fetch_burst, host_burst, counter_bits, cameras=True) -> tuple:
    """The masters' ports and the arbiter's parameters (shared by :func:`sram_arbiter` and the subsystem,
    so that the block a user instantiates names itself in the message); returns the parameters as ints
    and the address map."""
    check_clock(clk)
    check_reset(rst)
    ports = dict(cam0=cam0, cam1=cam1, fetch=fetch, rect=rect, feat=feat, host=host)
    for m in MASTER_TABLE:
        _check_port(m, ports[m.name])
    check_bundle("ctl", ctl, FrameControl)
    check_bundle("stat", stat, StatPort)
    width, height = check_frame(width, height, min_size=2)
    feature_words = check_int("feature_words", feature_words, 2, 65536)
    depth = check_choice("depth", depth, (8, 16, 32))
    burst = check_int("burst", burst, 2, depth // 2)
    fetch_burst = check_int("fetch_burst", fetch_burst, 4, 16)
    host_burst = check_int("host_burst", host_burst, 1, 8)
    counter_bits = check_int("counter_bits", counter_bits, 16, 32)
    if (fetch.width, fetch.height) != (width, height):
        raise block_error(f"port fetch is for {fetch.width}x{fetch.height} frames, the frame buffers for "
                          f"{width}x{height}")
    if len(stat.addr) < 5 or len(stat.data) != 32:
        raise block_error(f"port stat needs at least 5 address bits and 32 data bits, got {len(stat.addr)} and "
                          f"{len(stat.data)}")
    try:
        amap = AddressMap(width, height, feature_words, cameras=check_bool("cameras", cameras))
    except ValueError as e:
        raise block_error(f"parameters width, height, feature_words: {e}") from None
    return width, height, feature_words, depth, burst, fetch_burst, host_burst, counter_bits, amap


@block
def counter(clk, rst, inc, q):
    """``q`` counts the clocks with ``inc`` high; it wraps round (unsigned arithmetic in VHDL and Verilog;
    MyHDL's own simulator would stop at the top, the benches never get there)."""

    @always_seq(clk.posedge, reset=rst)
    def count():
        if inc:
            q.next = q + 1

    return count


@block
def sram_arbiter(clk, rst, cam0, cam1, fetch, rect, feat, host, ctl, stat, cmd, rsp, *, width: int = 352,
                 height: int = 288, feature_words: int = 8192, depth: int = 16, burst: int = 8,
                 fetch_burst: int = 8, host_burst: int = 1, counter_bits: int = 32, cameras: bool = True):
    """Six masters, each a port of its own kind, share one SRAM word port, with double-buffered frames.

    Masters (index, port): 0, 1 ``cam0``/``cam1`` -- camera writers (queue read ports of 16-bit camera
    words, from the cameras' async FIFOs); 2 ``fetch`` -- the rectifier's pixel fetch port (slave side);
    3 ``rect`` -- the rectified-image writer (stereo image stream of 8-bit pixels: left and right pixel
    of the same (x, y) packed into one word); 4 ``feat`` -- the feature-list writer (queue read port of
    16-bit words, ``eof`` on a list's last word); 5 ``host`` -- the host port (reads and writes). They are
    described once, in :data:`eyestereo.tools.models.sram_arbiter.MASTER_TABLE` (engine, urgency, burst
    parameter, read tag); the arbiter builds each master's engine (hdl/memory/sram_masters.py), its place
    in the round robin, its burst length and its counters from that table, in loops.

    Arbitration, one access per clock: the master owning the bus issues one access per clock while it
    has one, for up to its burst length (writers: ``burst``; fetch: ``fetch_burst`` reads, i.e. whole
    requests; host: ``host_burst``). Writers ask for a turn when ``burst`` words or a frame's end wait in
    their FIFO. The writers of the streams that cannot wait (both cameras and the rectified stream) are
    then *urgent*; the feature writer (its queue port can wait), the fetch port and the host are not.
    The next owner is chosen a clock ahead: round robin among the urgent masters if any asks, else round
    robin among the others, each round robin keeping its own place. An urgent master ends a non-urgent
    turn at the next clock once that turn has moved a word. So an urgent writer waits at most for one
    access, the other urgent writers' bursts and a bus turnaround, whatever the rest does, and every turn
    moves at least one word: no master starves (docs/sram.md measures the waits under overload). On a
    pipelined SyncBurst part the controller holds a write back during the turnaround; the turn is kept
    meanwhile, so a stream of reads cannot starve a write. The owner (also kept one-hot), the next owner,
    every master's ``req`` and the command to the controller are registers: a grant is two LUT levels
    from flip-flops, and each engine's registers follow it within one or two more.

    Frame buffers (hdl/memory/frame_buffers.py): each writer has two buffers (address map:
    :class:`eyestereo.tools.models.sram_arbiter.AddressMap`) and a :func:`double_buffer` state; the system's
    controller drives the :class:`FrameControl` handshake. The fetch port reads the camera buffers held
    by ``cam_want``/``cam_held``.

    Status port (``stat``): address -> 32-bit word, two clocks later: 0..5 words moved per master,
    6..11 clocks each master waited (it asked or held a turn and was not granted; these twelve count a
    clock late, from registered copies of the grants and waits), 12 clocks since reset, 13..18 frames
    published / dropped / overwritten per double buffer, 19 buffer states and the rectified writer's lost
    words, 20..21 the feature lists' word counts (``STAT`` in the model module).

    Ports:
        clk, rst: clock (the SRAM's, 100 MHz) and synchronous active-high reset.
        cam0, cam1: :class:`~eyestereo.hdl.interfaces.queue.QueuePort`, 16 bits.
        fetch: :class:`~eyestereo.hdl.interfaces.fetch_port.FetchPort` for ``width`` x ``height``.
        rect: :class:`~eyestereo.hdl.interfaces.stream.ImageStream`, 8 bits, stereo.
        feat: QueuePort, 16 bits.
        host: :class:`~eyestereo.hdl.interfaces.sram_bus.HostPort`.
        ctl: :class:`~eyestereo.hdl.memory.frame_buffers.FrameControl`.
        stat: :class:`~eyestereo.hdl.interfaces.sram_bus.StatPort` (5 address bits, 32 data bits).
        cmd, rsp: the controller's word port (:class:`~eyestereo.hdl.interfaces.sram_bus.SramCmd` /
            :class:`~eyestereo.hdl.interfaces.sram_bus.SramRsp`, 3 tag bits).

    Parameters:
        width, height: frame size of the camera and rectified buffers (2..4096; the map must fit).
        feature_words: capacity of each feature-list buffer (2..65536).
        depth: writer FIFO depth (8, 16 or 32 words of LUT-RAM).
        burst: writer burst length (2..depth/2), fetch_burst (4..16), host_burst (1..8, default 1).
        counter_bits: width of the words-moved and clocks-waited counters (16..32).
        cameras: the camera buffers in the address map (default); False: none (``rectify="stream"``: the camera
            writers idle, the rectified buffers from address 0; AddressMap's ``cameras``).

    Latency (measured, docs/sram.md): on a quiet bus with a part of read latency 2, a fetch request's
    first pixel comes 11 clocks after the request is taken, a host read's word 7 clocks after; each
    waits longer while other masters hold the bus.

    Resources: see docs/sram.md (Yosys, Spartan-3E); with the defaults about 1260 LUTs, 77 LUT-RAM
    (the writers' FIFOs), 1510 flip-flops (two thirds of them the 32-bit counters).
    """
    width, height, feature_words, depth, burst, fetch_burst, host_burst, counter_bits, amap = check_masters(
        clk, rst, cam0, cam1, fetch, rect, feat, host, ctl, stat, width=width, height=height,
        feature_words=feature_words, depth=depth, burst=burst, fetch_burst=fetch_burst, host_burst=host_burst,
        counter_bits=counter_bits, cameras=cameras)
    check_bundle("cmd", cmd, SramCmd)
    check_bundle("rsp", rsp, SramRsp)
    if cmd.tag_bits != TAG_BITS or rsp.tag_bits != TAG_BITS:
        raise block_error(f"ports cmd and rsp need {TAG_BITS} tag bits, got {cmd.tag_bits} and {rsp.tag_bits}")
    check_distinct(dict(fetch=fetch, stat=stat, cmd=cmd), dict(clk=clk, rst=rst, cam0=cam0, cam1=cam1, rect=rect,
                                                             feat=feat, host=host, ctl=ctl, rsp=rsp))

    insts = []
    ports = dict(cam0=cam0, cam1=cam1, fetch=fetch, rect=rect, feat=feat, host=host)
    params = dict(burst=burst, fetch_burst=fetch_burst, host_burst=host_burst)
    heads = [Head(m) for m in MASTER_TABLE]
    writers = [m.name for m in MASTER_TABLE if m.writer]
    sides = [BufferSide() for _ in writers]  # one double buffer per writer, in the table's order
    side_of = dict(zip(writers, sides))
    for sd in sides:
        insts.append(double_buffer(clk, rst, sd))

    # ---- frame handshake ------------------------------------------------------------------------
    run0, run1, arm0, arm1 = (Signal(bool(0)) for _ in range(4))
    s_c0, s_c1, s_r, s_f = (side_of[n] for n in ("cam0", "cam1", "rect", "feat"))
    cam_take = Signal(bool(0))

    @always_seq(clk.posedge, reset=rst)
    def pair_take():
        # The camera pair is taken a clock after both buffers offer a frame: the decision spans both
        # double buffers and the sequencer's want, and a take feeds each buffer's producer choice and
        # counters (the memory clock's worst path, issue 23), so it starts from this register. A frame
        # offered stays offered for that clock: only a take or a release ends c_avail, and a producer's
        # start there picks a FREE buffer or the older of two FULL ones (the newest stays to be taken).
        cam_take.next = ctl.cam_want and s_c0.c_avail and s_c1.c_avail and not cam_take

    @always_comb
    def control():
        run0.next = ctl.cam_run[0]
        run1.next = ctl.cam_run[1]
        arm0.next = ctl.cam_arm[0]
        arm1.next = ctl.cam_arm[1]
        s_c0.c_take.next = cam_take
        s_c1.c_take.next = cam_take
        s_c0.c_release.next = ctl.cam_release
        s_c1.c_release.next = ctl.cam_release
        ctl.cam_held.next = s_c0.c_held
        ctl.cam_buf.next = concat(s_c1.c_buf, s_c0.c_buf)
        s_r.c_take.next = ctl.rect_want
        s_r.c_release.next = ctl.rect_release
        ctl.rect_held.next = s_r.c_held
        ctl.rect_buf.next = s_r.c_buf
        s_f.c_take.next = ctl.feat_want
        s_f.c_release.next = ctl.feat_release
        ctl.feat_held.next = s_f.c_held
        ctl.feat_buf.next = s_f.c_buf

    fulls = [Signal(bool(0)) for _ in sides]
    insts += [any_full(sd.state, f) for sd, f in zip(sides, fulls)]
    insts += [pair_take, control, assign(ConcatSignal(*reversed(fulls)), ctl.avail)]
    del fulls

    # ---- the masters' engines, from the table -----------------------------------------------------
    lbits = max(2, feature_words.bit_length())
    lcounts = [Signal(intbv(0)[lbits:]) for _ in range(2)]
    lovf = Signal(intbv(0)[2:])
    rect_lost = Signal(intbv(0)[16:])
    camera = dict(cam0=(run0, arm0), cam1=(run1, arm1))
    for m, head in zip(MASTER_TABLE, heads):
        port = ports[m.name]
        if m.writer:
            entry, push = EntrySignals(), Signal(bool(0))
            count = Signal(intbv(0, min=0, max=depth + 1))
            # only the feature lists keep their word counts (status words 20, 21); the others' are left open
            counts = (*lcounts, lovf) if m.engine == "features" else (Signal(intbv(0)[2:]) for _ in range(3))
            base0, base1 = amap.bases(m.name)
            insts.append(frame_writer(clk, rst, entry, push, count, head, side_of[m.name], *counts, base0=base0,
                                      base1=base1, depth=depth, burst=burst, urgent=m.urgent))
            if m.engine == "camera":
                insts.append(camera_in(clk, rst, port, push, entry, count, *camera[m.name], depth=depth))
            elif m.engine == "stereo":
                # (its rate is bounded by the stream's: one word per two beats at most, in the system one
                # per 8 fetch reads; the table makes it urgent, like the cameras: it cannot wait)
                insts.append(rect_in(clk, rst, port, push, entry, count, rect_lost, depth=depth))
            else:
                insts.append(feature_in(clk, rst, port, push, entry, count, depth=depth, capacity=feature_words))
        elif m.engine == "fetch":
            insts.append(fetch_slave(clk, rst, port, head, s_c0.c_buf, s_c1.c_buf, width=width, height=height,
                                     bases=(amap.bases("cam0"), amap.bases("cam1"))))
        else:
            insts.append(host_slave(clk, rst, port, head))

    @always(clk.posedge)
    def responses():
        fetch.rsp_data.next = rsp.data[8:0]
        fetch.rsp_idx.next = rsp.tag[2:0]
        host.rsp_data.next = rsp.data

    @always_seq(clk.posedge, reset=rst)
    def response_valid():
        fetch.rsp_valid.next = rsp.valid and not rsp.tag[2]
        host.rsp_valid.next = rsp.valid and rsp.tag[2]

    insts += [responses, response_valid]

    # ---- arbitration ----------------------------------------------------------------------------
    # Two registered decisions keep the clock-to-clock logic short: the *owner* of the bus (registered)
    # issues one access per clock while it has one, for up to its burst length; the *next* owner is
    # chosen one clock ahead (registered) from the masters' registered start/urgent flags, round robin
    # from the current owner. The command to the controller is registered too (``slot``).
    # The grant is the shortest path of all (every engine updates on it): the owner is also kept one-hot
    # (``own1h``, 0 without an owner), every engine's ``req`` is a register, and the controller's
    # ``cmd.ready`` and ``preempt`` meet in one LUT (``rdy``), so ``gv[i] = own1h[i] and req[i] and rdy``.
    reqv = ConcatSignal(*(h.req for h in reversed(heads)))
    startv = ConcatSignal(*(h.start for h in reversed(heads)))
    urgv = ConcatSignal(*(h.urgent for h in reversed(heads)))
    bursts = tuple(params[m.burst] for m in MASTER_TABLE)
    maxb = max(bursts)
    own = Signal(intbv(NM - 1, min=0, max=NM))
    own_v = Signal(bool(0))
    own1h = Signal(intbv(0)[NM:])  # one-hot of own while own_v, else 0
    own_urg = Signal(bool(0))
    beats = Signal(intbv(0, min=0, max=maxb + 1))
    last_beat = Signal(bool(0))  # beats == 1
    nxt = Signal(intbv(0, min=0, max=NM))
    nxt1h = Signal(intbv(0)[NM:])  # one-hot of nxt while nxt_v, else 0
    nxt_v = Signal(bool(0))
    nxt_urg = Signal(bool(0))
    preempt = Signal(bool(0))
    served = Signal(bool(0))  # the current turn has moved a word
    last1 = Signal(intbv(NM - 1, min=0, max=NM))  # the last non-urgent master to start a turn
    nxt_c = Signal(intbv(0, min=0, max=NM))
    nxt1h_c = Signal(intbv(0)[NM:])
    nxt_vc = Signal(bool(0))
    nxt_urgc = Signal(bool(0))
    preempt_c = Signal(bool(0))
    rdy = Signal(bool(0))
    issue = Signal(bool(0))
    turn_over = Signal(bool(0))
    blen = Signal(intbv(0, min=0, max=maxb + 1))
    urg = Signal(intbv(0)[NM:])
    pool = Signal(intbv(0)[NM:])
    cand = Signal(intbv(0)[NM:])
    above = Signal(intbv(0)[NM:])
    AFTER = tuple(((1 << NM) - 1) & ~((1 << (k + 1)) - 1) for k in range(NM))  # masters above k
    gv = Signal(intbv(0)[NM:])
    slot_v = Signal(bool(0))
    slot_free = Signal(bool(0))
    slot = Signal(intbv(0)[ACCESS.width:])

    @always_comb
    def urgency():
        urg.next = urgv & startv

    @always_comb
    def pools():
        # the urgent masters take turns among themselves, the others among themselves (each round robin
        # keeps its own place, so urgent turns in between do not favour one of the others)
        if urg != 0:
            pool.next = urg
            above.next = AFTER[own]
        else:
            pool.next = startv
            above.next = AFTER[last1]

    @always_comb
    def masked():
        if (pool & above) != 0:
            cand.next = pool & above
        else:
            cand.next = pool

    @always_comb
    def next_choice():
        # round robin: the lowest master above the current owner in the pool, else the lowest in it
        # (the owner itself comes last); the pool is the urgent masters if any, else all that ask
        # (the owner also one-hot: h, 0 when none asks)
        k = NM - 1
        h = intbv(0)[NM:]
        h[NM - 1] = cand[NM - 1]
        for i in downrange(NM - 1):
            if cand[i]:
                k = i
                h[:] = 0
                h[i] = 1
        nxt_c.next = k
        nxt1h_c.next = h
        nxt_vc.next = cand != 0
        nxt_urgc.next = urg != 0
        # an urgent master ends a non-urgent turn, but only after that turn moved a word: every turn
        # moves at least one, so the round robin cannot be starved by preemption
        preempt_c.next = own_v and not own_urg and urg != 0 and served

    @always_comb
    def issue_logic():
        ok = (not slot_v or cmd.ready) and not preempt
        rdy.next = ok
        slot_free.next = not slot_v or cmd.ready
        g = intbv(0)[NM:]
        for i in range(NM):
            g[i] = own1h[i] and reqv[i] and ok
        gv.next = g
        iss = (own1h & reqv) != 0 and ok
        issue.next = iss
        turn_over.next = (own1h & reqv) == 0 or preempt or (iss and last_beat)

    @always_comb
    def burst_length():
        blen.next = bursts[nxt]

    @always_seq(clk.posedge, reset=rst)
    def turn():
        nxt.next = nxt_c
        nxt1h.next = nxt1h_c
        nxt_v.next = nxt_vc
        nxt_urg.next = nxt_urgc
        preempt.next = preempt_c and not turn_over
        if turn_over:
            own.next = nxt
            own_v.next = nxt_v
            own1h.next = nxt1h
            own_urg.next = nxt_urg
            beats.next = blen
            last_beat.next = blen == 1
            served.next = False
            if nxt_v and not nxt_urg:
                last1.next = nxt
        elif issue:
            beats.next = beats - 1
            last_beat.next = beats == 2
            served.next = True
        if issue:
            slot_v.next = True
        elif cmd.ready:
            slot_v.next = False

    # (one process, an if-elif chain on the owner: the cheapest multiplexer after synthesis; a tree of
    # two-way multiplexers built in a loop costs LUTs, a list indexed by the owner an undefined netlist.
    # The slot takes the owner's access whenever it is free, issued or not: ``cmd.valid`` says whether it
    # is a command, and the load enable does not wait for the grant.)
    a0, a1, a2, a3, a4, a5 = (h.access for h in heads)

    @always(clk.posedge)
    def slot_load():
        if slot_free:
            if own == 0:
                slot.next = a0
            elif own == 1:
                slot.next = a1
            elif own == 2:
                slot.next = a2
            elif own == 3:
                slot.next = a3
            elif own == 4:
                slot.next = a4
            else:
                slot.next = a5

    insts += [urgency, pools, masked, next_choice, issue_logic, burst_length, turn, slot_load,
              assign(slot_v, cmd.valid),
              unpack_word(slot, ACCESS, we=cmd.we, addr=cmd.addr, wdata=cmd.wdata, be=cmd.be, tag=cmd.tag)]

    # ---- counters and status ----------------------------------------------------------------------
    # (individual signals in the multiplexers, no lists: a list of signals becomes a memory array, which
    # synthesis turns into wide multiplexers)
    words = [Signal(intbv(0)[counter_bits:]) for _ in range(NM)]
    waits = [Signal(intbv(0)[counter_bits:]) for _ in range(NM)]
    clocks = Signal(intbv(0)[counter_bits:])
    one = Signal(bool(1))
    # the counters count registered grants and waits (a clock late: the grant's fan-out stays small)
    gv_r, wait_r = Signal(intbv(0)[NM:]), Signal(intbv(0)[NM:])
    insts.append(activity(clk, rst, gv, reqv, startv, own1h, gv_r, wait_r))
    for i, head in enumerate(heads):
        moved, waiting = Signal(bool(0)), Signal(bool(0))
        insts.append(grant_bits(gv, gv_r, wait_r, head.grant, moved, waiting, index=i))
        insts.append(counter(clk, rst, moved, words[i]))
        insts.append(counter(clk, rst, waiting, waits[i]))
    insts.append(counter(clk, rst, one, clocks))
    insts.append(stat_mux(clk, stat, words, waits, clocks, sides, rect_lost, lcounts, lovf))
    return insts


@block
def activity(clk, rst, gv, reqv, startv, own1h, gv_r, wait_r):
    """The grants and the waits, registered for the counters: master i was granted an access (moved a word)
    / waited (asked, or held a turn with an access ready, and was not granted) in the clock before."""

    @always_seq(clk.posedge, reset=rst)
    def seq():
        gv_r.next = gv
        wait_r.next = (startv | (own1h & reqv)) & ~gv

    return seq


@block
def grant_bits(gv, gv_r, wait_r, grant, moved, waiting, *, index: int):
    """Master ``index``'s grant (this clock), and its registered grant and wait (the counters' inputs)."""

    @always_comb
    def comb():
        grant.next = gv[index]
        moved.next = gv_r[index]
        waiting.next = wait_r[index]

    return comb


@block
def any_full(state, full):
    """A buffer of a double buffer is FULL (state 2 in either 2-bit field)."""

    @always_comb
    def comb():
        full.next = state[2:0] == 2 or state[4:2] == 2

    return comb


@block
def stat_mux(clk, stat, words, waits, clocks, sides, rect_lost, lcounts, lovf):
    """The status port: the word at ``stat.addr`` (register map ``STAT`` in
    eyestereo.tools.models.sram_arbiter) on ``stat.data`` two clocks later."""
    s0, s1, s2, s3 = sides
    l0, l1 = lcounts
    pad = Signal(intbv(0)[31 - len(l0):])  # never driven: constant 0
    ovf0, ovf1 = Signal(bool(0)), Signal(bool(0))
    w0, w1, w2, w3, w4, w5 = words
    t0, t1, t2, t3, t4, t5 = waits
    f0, f1, f2, f3, f4, f5, f6, f7, f8 = (Signal(intbv(0)[32:]) for _ in range(9))

    @always_comb
    def fields():
        ovf0.next = lovf[0]
        ovf1.next = lovf[1]
        f0.next = concat(s0.dropped, s0.published)
        f1.next = concat(s1.dropped, s1.published)
        f2.next = concat(s2.dropped, s2.published)
        f3.next = concat(s3.dropped, s3.published)
        f4.next = concat(s1.overwritten, s0.overwritten)
        f5.next = concat(s3.overwritten, s2.overwritten)
        f6.next = concat(rect_lost, s3.state, s2.state, s1.state, s0.state)

    @always_comb
    def lists():
        f7.next = concat(ovf0, pad, l0)
        f8.next = concat(ovf1, pad, l1)

    g0, g1, g2 = (Signal(intbv(0)[32:]) for _ in range(3))
    grp = Signal(intbv(0)[2:])
    lo3 = Signal(intbv(0)[3:])
    hi = Signal(intbv(0)[len(stat.addr) - 3:])

    @always_comb
    def split():
        lo3.next = stat.addr[3:0]
        hi.next = stat.addr[len(stat.addr):3]

    # two registered stages: eight words per group, then the group (the counters' wide multiplexer
    # would otherwise be the longest path of the arbiter)
    @always(clk.posedge)
    def stage1():
        if hi == 0:
            grp.next = 0
        elif hi == 1:
            grp.next = 1
        elif hi == 2:
            grp.next = 2
        else:
            grp.next = 3
        if lo3 == 0:
            g0.next = w0
            g1.next = t2
            g2.next = f3
        elif lo3 == 1:
            g0.next = w1
            g1.next = t3
            g2.next = f4
        elif lo3 == 2:
            g0.next = w2
            g1.next = t4
            g2.next = f5
        elif lo3 == 3:
            g0.next = w3
            g1.next = t5
            g2.next = f6
        elif lo3 == 4:
            g0.next = w4
            g1.next = clocks
            g2.next = f7
        elif lo3 == 5:
            g0.next = w5
            g1.next = f0
            g2.next = f8
        elif lo3 == 6:
            g0.next = t0
            g1.next = f1
            g2.next = 0
        else:
            g0.next = t1
            g1.next = f2
            g2.next = 0

    @always(clk.posedge)
    def stage2():
        if grp == 0:
            stat.data.next = g0
        elif grp == 1:
            stat.data.next = g1
        elif grp == 2:
            stat.data.next = g2
        else:
            stat.data.next = 0

    return fields, lists, split, stage1, stage2
