"""SRAM arbiter: six masters of their own kinds share the SRAM controller's word port."""

from myhdl import ConcatSignal, Signal, always, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.common.checks import check_clock, check_int, check_reset, check_stream
from eyestereo.hdl.fetch_port import FetchPort
from eyestereo.hdl.frame_buffers import BufferSide, FrameControl, double_buffer
from eyestereo.hdl.queue_port import QueuePort
from eyestereo.hdl.sram_bus import HostPort, SramCmd, SramRsp, StatPort
from eyestereo.hdl.sram_masters import (ENTRY_BITS, Head, camera_in, feature_in, fetch_slave, frame_writer, host_slave,
                                        rect_in)
from eyestereo.tools.models.sram_arbiter import MASTERS, STAT, AddressMap

NM = len(MASTERS)
CAM0, CAM1, FETCH, RECT, FEAT, HOST = range(NM)
TAG_BITS = 3  # tag of a read: host << 2 | fetch index


def _check_port(name, port, cls):
    if not isinstance(port, cls):
        raise ValueError(f"port {name} must be a {cls.__name__}, got {type(port).__name__}")


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
                 fetch_burst: int = 8, host_burst: int = 2, counter_bits: int = 32):
    """Six masters, each a port of its own kind, share one SRAM word port, with double-buffered frames.

    Masters (index, port): 0, 1 ``cam0``/``cam1`` -- camera writers (queue read ports of 16-bit camera
    words, from the cameras' async FIFOs); 2 ``fetch`` -- the rectifier's pixel fetch port (slave side);
    3 ``rect`` -- the rectified-image writer (stereo image stream of 8-bit pixels: left and right pixel
    of the same (x, y) packed into one word); 4 ``feat`` -- the feature-list writer (queue read port of
    16-bit words, ``eof`` on a list's last word); 5 ``host`` -- the host port (reads and writes).

    Arbitration, one access per clock: the master holding the bus keeps it for up to its burst length
    while it has accesses (writers: ``burst``; fetch: ``fetch_burst`` reads, i.e. whole requests; host:
    ``host_burst``). Then the next master is chosen round robin from the one after the last to start a
    turn, among the *urgent* masters if any, else among all that ask for a turn. Camera writers are
    always urgent when they ask (they ask when ``burst`` words or a frame's end wait in their FIFO), and
    an urgent master takes the bus from a non-urgent one at the next clock; the rectified writer becomes
    urgent when its FIFO is 3/4 full. So a camera waits at most for the other camera's burst and the
    bus turnaround, whatever the rest does, and every master is served within one round: no
    starvation. On a pipelined SyncBurst part the controller holds a write back during the turnaround;
    the turn is kept meanwhile, so a stream of reads cannot starve a write.

    Frame buffers (hdl/frame_buffers.py): each writer has two buffers (address map:
    :class:`eyestereo.tools.models.sram_arbiter.AddressMap`) and a :func:`double_buffer` state; the system's
    controller drives the :class:`FrameControl` handshake. The fetch port reads the camera buffers held
    by ``cam_want``/``cam_held``.

    Status port (``stat``): address -> 32-bit word, one clock later: 0..5 words moved per master,
    6..11 clocks each master waited (it asked or held a turn and was not granted), 12 clocks since
    reset, 13..18 frames published / dropped / overwritten per double buffer, 19 buffer states and the
    rectified writer's lost words, 20..21 the feature lists' word counts (``STAT`` in the model module).

    Ports:
        clk, rst: clock (the SRAM's, 100 MHz) and synchronous active-high reset.
        cam0, cam1: :class:`~eyestereo.hdl.queue_port.QueuePort`, 16 bits.
        fetch: :class:`~eyestereo.hdl.fetch_port.FetchPort` for ``width`` x ``height``.
        rect: :class:`~eyestereo.hdl.stream.ImageStream`, 8 bits, stereo.
        feat: QueuePort, 16 bits.
        host: :class:`~eyestereo.hdl.sram_bus.HostPort`.
        ctl: :class:`~eyestereo.hdl.frame_buffers.FrameControl`.
        stat: :class:`~eyestereo.hdl.sram_bus.StatPort` (5 address bits, 32 data bits).
        cmd, rsp: the controller's word port (:class:`~eyestereo.hdl.sram_bus.SramCmd` /
            :class:`~eyestereo.hdl.sram_bus.SramRsp`, 3 tag bits).

    Parameters:
        width, height: frame size of the camera and rectified buffers (2..4096; the map must fit).
        feature_words: capacity of each feature-list buffer (2..65536).
        depth: writer FIFO depth (8, 16 or 32 words of LUT-RAM).
        burst: writer burst length (2..depth/2), fetch_burst (4..16), host_burst (1..8).
        counter_bits: width of the words-moved and clocks-waited counters (16..32).

    Latency: a fetch request's first pixel comes read_latency + 6 clocks after it is taken when the bus
    is free (3 stages here, the controller's read_latency + 2, one output register); host reads
    read_latency + 4.

    Resources: see docs/sram.md (Yosys, Spartan-3E).
    """
    check_clock(clk)
    check_reset(rst)
    for name, port, cls in (("cam0", cam0, QueuePort), ("cam1", cam1, QueuePort), ("fetch", fetch, FetchPort),
                            ("feat", feat, QueuePort), ("host", host, HostPort), ("ctl", ctl, FrameControl),
                            ("stat", stat, StatPort), ("cmd", cmd, SramCmd), ("rsp", rsp, SramRsp)):
        _check_port(name, port, cls)
    check_stream("rect", rect, width=8, stereo=True)
    for name, port in (("cam0", cam0), ("cam1", cam1), ("feat", feat)):
        if port.data_width != 16:
            raise ValueError(f"port {name} must carry 16-bit words, got {port.data_width}")
    width = check_int("width", width, 2, 4096)
    height = check_int("height", height, 2, 4096)
    feature_words = check_int("feature_words", feature_words, 2, 65536)
    depth = check_int("depth", depth, 8, 32)
    if depth & (depth - 1):
        raise ValueError(f"parameter depth={depth} must be a power of two (8, 16, 32)")
    burst = check_int("burst", burst, 2, depth // 2)
    fetch_burst = check_int("fetch_burst", fetch_burst, 4, 16)
    host_burst = check_int("host_burst", host_burst, 1, 8)
    counter_bits = check_int("counter_bits", counter_bits, 16, 32)
    if (fetch.width, fetch.height) != (width, height):
        raise ValueError(f"port fetch is for {fetch.width}x{fetch.height} frames, the arbiter for {width}x{height}")
    if cmd.tag_bits != TAG_BITS or rsp.tag_bits != TAG_BITS:
        raise ValueError(f"ports cmd and rsp need {TAG_BITS} tag bits, got {cmd.tag_bits} and {rsp.tag_bits}")
    if len(stat.addr) < 5 or len(stat.data) != 32:
        raise ValueError("port stat needs at least 5 address bits and 32 data bits")
    try:
        amap = AddressMap(width, height, feature_words)
    except ValueError as e:
        raise ValueError(f"parameters width, height, feature_words: {e}") from None

    insts = []
    heads = [Head() for _ in range(NM)]
    sides = [BufferSide() for _ in range(4)]  # cam0, cam1, rect, feat
    for sd in sides:
        insts.append(double_buffer(clk, rst, sd))

    # ---- frame handshake ------------------------------------------------------------------------
    run0, run1, arm0, arm1 = (Signal(bool(0)) for _ in range(4))
    cams_take = Signal(bool(0))
    s_c0, s_c1, s_r, s_f = sides

    @always_comb
    def control():
        run0.next = ctl.cam_run[0]
        run1.next = ctl.cam_run[1]
        arm0.next = ctl.cam_arm[0]
        arm1.next = ctl.cam_arm[1]
        take = ctl.cam_want and s_c0.c_avail and s_c1.c_avail
        s_c0.c_take.next = take
        s_c1.c_take.next = take
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

    full = [Signal(bool(0)) for _ in range(4)]

    @always_comb
    def avail_bits():
        ctl.avail.next = concat(full[3], full[2], full[1], full[0])

    for i, sd in enumerate(sides):
        insts.append(any_full(sd.state, full[i]))
    insts += [control, avail_bits]

    # ---- writers ------------------------------------------------------------------------------
    lbits = max(2, feature_words.bit_length())
    lcounts = [Signal(intbv(0)[lbits:]) for _ in range(2)]
    lovf = Signal(intbv(0)[2:])
    rect_lost = Signal(intbv(0)[16:])

    def dummy_counts():
        return Signal(intbv(0)[2:]), Signal(intbv(0)[2:]), Signal(intbv(0)[2:])

    def fifo_signals():
        return (Signal(intbv(0)[ENTRY_BITS:]), Signal(bool(0)), Signal(bool(0)),
                Signal(intbv(0, min=0, max=depth + 1)))

    wkw = dict(depth=depth, burst=burst, urgent_level=depth * 3 // 4)
    for c, (q, run, arm) in enumerate(((cam0, run0, arm0), (cam1, run1, arm1))):
        e_in, push, push_eof, count = fifo_signals()
        insts.append(frame_writer(clk, rst, e_in, push, push_eof, count, heads[c], sides[c], *dummy_counts(),
                                  base0=amap.camera(c, 0), base1=amap.camera(c, 1), always_urgent=True, **wkw))
        insts.append(camera_in(clk, rst, q, push, e_in, push_eof, count, sides[c], run, arm, depth=depth))
    e_in, push, push_eof, count = fifo_signals()
    insts.append(frame_writer(clk, rst, e_in, push, push_eof, count, heads[RECT], s_r, *dummy_counts(),
                              base0=amap.rectified(0), base1=amap.rectified(1), always_urgent=False, **wkw))
    insts.append(rect_in(clk, rst, rect, push, e_in, push_eof, count, s_r, rect_lost, depth=depth))
    e_in, push, push_eof, count = fifo_signals()
    insts.append(frame_writer(clk, rst, e_in, push, push_eof, count, heads[FEAT], s_f, lcounts[0], lcounts[1], lovf,
                              base0=amap.features(0), base1=amap.features(1), always_urgent=False, **wkw))
    insts.append(feature_in(clk, rst, feat, push, e_in, push_eof, count, s_f, depth=depth, capacity=feature_words))

    # ---- readers ------------------------------------------------------------------------------
    bases = ((amap.camera(0, 0), amap.camera(0, 1)), (amap.camera(1, 0), amap.camera(1, 1)))
    insts.append(fetch_slave(clk, rst, fetch, heads[FETCH], s_c0.c_buf, s_c1.c_buf, width=width, height=height,
                             bases=bases))
    insts.append(host_slave(clk, rst, host, heads[HOST]))

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
    h0, h1, h2, h3, h4, h5 = heads
    reqv = ConcatSignal(h5.req, h4.req, h3.req, h2.req, h1.req, h0.req)
    startv = ConcatSignal(h5.start, h4.start, h3.start, h2.start, h1.start, h0.start)
    urgv = ConcatSignal(h5.urgent, h4.urgent, h3.urgent, h2.urgent, h1.urgent, h0.urgent)
    bursts = (burst, burst, fetch_burst, burst, burst, host_burst)
    maxb = max(bursts)
    own = Signal(intbv(0, min=0, max=NM))
    own_v = Signal(bool(0))
    own_urg = Signal(bool(0))
    beats = Signal(intbv(0, min=0, max=maxb + 1))
    rr = Signal(intbv(NM - 1, min=0, max=NM))
    sel = Signal(intbv(0, min=0, max=NM))
    go = Signal(bool(0))
    keep = Signal(bool(0))
    sel_urg = Signal(bool(0))
    granted = Signal(bool(0))
    gv = Signal(intbv(0)[NM:])
    urg = Signal(intbv(0)[NM:])
    blen = Signal(intbv(0, min=0, max=maxb + 1))
    wantv = Signal(intbv(0)[NM:])

    @always_comb
    def urgency():
        urg.next = urgv & startv

    @always_comb
    def choose():
        k = own_v and reqv[own] and beats != 0 and (own_urg or urg == 0)
        keep.next = k
        s = int(own)
        g = False
        u = bool(own_urg)
        if not k:
            u = urg != 0
            for i in range(NM):
                m = int(rr) + 1 + i
                if m >= NM:
                    m = m - NM
                if not g:
                    if urg != 0:
                        if urg[m]:
                            s = m
                            g = True
                    elif startv[m]:
                        s = m
                        g = True
        else:
            g = True
        sel.next = s
        go.next = g
        sel_urg.next = u

    @always_comb
    def mux():
        cmd.valid.next = go
        cmd.we.next = False
        cmd.addr.next = 0
        cmd.wdata.next = 0
        cmd.be.next = 3
        cmd.tag.next = 0
        if sel == CAM0:
            cmd.we.next = h0.we
            cmd.addr.next = h0.addr
            cmd.wdata.next = h0.wdata
            cmd.be.next = h0.be
        elif sel == CAM1:
            cmd.we.next = h1.we
            cmd.addr.next = h1.addr
            cmd.wdata.next = h1.wdata
            cmd.be.next = h1.be
        elif sel == FETCH:
            cmd.we.next = h2.we
            cmd.addr.next = h2.addr
            cmd.tag.next = h2.idx
        elif sel == RECT:
            cmd.we.next = h3.we
            cmd.addr.next = h3.addr
            cmd.wdata.next = h3.wdata
            cmd.be.next = h3.be
        elif sel == FEAT:
            cmd.we.next = h4.we
            cmd.addr.next = h4.addr
            cmd.wdata.next = h4.wdata
            cmd.be.next = h4.be
        else:
            cmd.we.next = h5.we
            cmd.addr.next = h5.addr
            cmd.wdata.next = h5.wdata
            cmd.be.next = h5.be
            cmd.tag.next = 4

    @always_comb
    def grants():
        gr = go and cmd.ready
        granted.next = gr
        h0.grant.next = gr and sel == CAM0
        h1.grant.next = gr and sel == CAM1
        h2.grant.next = gr and sel == FETCH
        h3.grant.next = gr and sel == RECT
        h4.grant.next = gr and sel == FEAT
        h5.grant.next = gr and sel == HOST

    @always_comb
    def bookkeeping():
        gv.next = concat(h5.grant, h4.grant, h3.grant, h2.grant, h1.grant, h0.grant)
        w = intbv(0)[NM:]
        for i in range(NM):
            w[i] = startv[i] or (own_v and own == i and reqv[i] and beats != 0)
        wantv.next = w

    @always_comb
    def burst_length():
        blen.next = bursts[sel]

    @always_seq(clk.posedge, reset=rst)
    def turn():
        if go:
            own.next = sel
            own_v.next = True
            if keep:
                if granted:
                    beats.next = beats - 1
            else:
                own_urg.next = sel_urg
                rr.next = sel
                if granted:
                    beats.next = blen - 1
                else:
                    beats.next = blen

    insts += [urgency, choose, mux, grants, bookkeeping, burst_length, turn]

    # ---- counters and status ----------------------------------------------------------------------
    words = [Signal(intbv(0)[counter_bits:]) for _ in range(NM)]
    waits = [Signal(intbv(0)[counter_bits:]) for _ in range(NM)]
    waiting = [Signal(bool(0)) for _ in range(NM)]
    moved = [Signal(bool(0)) for _ in range(NM)]
    clocks = Signal(intbv(0)[counter_bits:])
    one = Signal(bool(1))

    @always_comb
    def wait_flags():
        for i in range(NM):
            moved[i].next = gv[i]
            waiting[i].next = wantv[i] and not gv[i]

    insts.append(wait_flags)
    for i in range(NM):
        insts.append(counter(clk, rst, moved[i], words[i]))
        insts.append(counter(clk, rst, waiting[i], waits[i]))
    insts.append(counter(clk, rst, one, clocks))

    nstat = max(STAT) + 1
    vals = [Signal(intbv(0)[32:]) for _ in range(nstat)]
    insts.append(stat_words(words, waits, clocks, sides, rect_lost, lcounts, lovf, vals))

    @always(clk.posedge)
    def stat_read():
        if stat.addr < nstat:
            stat.data.next = vals[stat.addr]
        else:
            stat.data.next = 0

    insts.append(stat_read)
    return insts


@block
def any_full(state, full):
    """A buffer of a double buffer is FULL (state 2 in either 2-bit field)."""

    @always_comb
    def comb():
        full.next = state[2:0] == 2 or state[4:2] == 2

    return comb


@block
def stat_words(words, waits, clocks, sides, rect_lost, lcounts, lovf, vals):
    """The status port's words (register map: ``STAT`` in eyestereo.tools.models.sram_arbiter)."""
    s0, s1, s2, s3 = sides
    l0, l1 = lcounts
    pad = Signal(intbv(0)[31 - len(l0):])  # never driven: constant 0
    ovf0, ovf1 = Signal(bool(0)), Signal(bool(0))

    @always_comb
    def flags():
        ovf0.next = lovf[0]
        ovf1.next = lovf[1]
    w0, w1, w2, w3, w4, w5 = words
    t0, t1, t2, t3, t4, t5 = waits

    @always_comb
    def comb():
        vals[0].next = w0
        vals[1].next = w1
        vals[2].next = w2
        vals[3].next = w3
        vals[4].next = w4
        vals[5].next = w5
        vals[6].next = t0
        vals[7].next = t1
        vals[8].next = t2
        vals[9].next = t3
        vals[10].next = t4
        vals[11].next = t5
        vals[12].next = clocks
        vals[13].next = concat(s0.dropped, s0.published)
        vals[14].next = concat(s1.dropped, s1.published)
        vals[15].next = concat(s2.dropped, s2.published)
        vals[16].next = concat(s3.dropped, s3.published)
        vals[17].next = concat(s1.overwritten, s0.overwritten)
        vals[18].next = concat(s3.overwritten, s2.overwritten)
        vals[19].next = concat(rect_lost, s3.state, s2.state, s1.state, s0.state)
        vals[20].next = concat(ovf0, pad, l0)
        vals[21].next = concat(ovf1, pad, l1)

    return flags, comb
