"""The monitor picture of the board: the newest rectified pair side by side with its corners marked."""

from __future__ import annotations

import numbers

from myhdl import ConcatSignal, Signal, always, always_comb, always_seq, block, concat, enum, intbv

from eyestereo.hdl.common.checks import block_error, check_bool, check_clock, check_int, check_reset, check_signal
from eyestereo.hdl.interfaces.axil import check_axil
from eyestereo.hdl.video.video_timing import video_timing
from eyestereo.tools.models.feature_list import MARKER
from eyestereo.tools.models.match_engine import MARKER as MATCH_MARKER
from eyestereo.tools.models.match_engine import MATCH, MAX_MATCHES
from eyestereo.tools.models.pair_display import (CROSS, MARK, PIXEL_MAX, SEGMENT_RGB, SRAM_BASE, check_geometry,
                                                 ctrl_words, start_words)
from eyestereo.tools.models.sram_arbiter import match_offset
from eyestereo.tools.models.video_timing import MODES
from eyestereo.tools.regmap import REGMAP

__all__ = ["pair_display", "MARK_DRAIN", "PLANE_BANK", "PLANE_LATENCY"]

#: Clocks the mark pipeline (coordinates, address, the plane's write register) needs to drain after a cross's
#: last pixel.
MARK_DRAIN = 3


@block
def pd_sync(clk, rst, tog, pulse):
    """pulse (one clock of ``clk``): ``tog`` (a toggle from another clock) changed; three flip-flops."""
    s1, s2, s3 = (Signal(bool(0)) for _ in range(3))

    @always_seq(clk.posedge, reset=rst)
    def sync():
        s1.next = tog
        s2.next = s1
        s3.next = s2
        pulse.next = s2 != s3

    return sync


#: Entries of one mark-plane bank: one ECP5 DP16KD as 16384 x 1.
PLANE_BANK = 1 << 14
#: Clocks from the pixel index to its mark bit: the read address's register, the bank's read, the bank's output
#: register, the bank multiplexer's.
PLANE_LATENCY = 4


@block
def pd_bank(clk, we, waddr, wval, raddr, q, *, depth: int):
    """One bank of a mark plane: a ``depth`` x 1 RAM, written at ``waddr`` when ``we``, read at ``raddr`` into a
    register and a second one (the block RAM's own output register: the bank's bit leaves at a flip-flop).

    The display never uses a read of an address in the clock it writes it (a pixel's bit is cleared in the clock
    the pixel is written, and the next bit it uses is read :data:`PLANE_LATENCY` clocks later; the crosses are
    drawn before the pixel phase reads): the memory is named ``_norw``, so Yosys builds no collision logic between
    the RAM and its register, and the board flow moves that register into the block RAM."""
    mem_norw = [Signal(bool(0)) for _ in range(depth)]
    rd = Signal(bool(0))

    @always(clk.posedge)
    def ram():
        if we:
            mem_norw[int(waddr)].next = wval
        rd.next = mem_norw[int(raddr)]

    @always(clk.posedge)
    def out():
        q.next = rd

    return ram, out


@block
def pd_plane(clk, we, waddr, wval, raddr, q, *, depth: int):
    """A ``depth`` x 1 mark plane in banks of :data:`PLANE_BANK` (one block RAM each), read in three clocks
    (the display's address register makes :data:`PLANE_LATENCY`): each bank's bit from its output register, then
    the bank chosen into ``q``; written a clock after ``we`` (the bank's write enable, address and bit from
    registers: the display's state decoded straight into the banks' enables, spread over the block-RAM columns,
    was the matcher build's slowest path). A
    single memory of 76,800 bits put the multiplexer of its block RAMs between their outputs and the next
    flip-flop: that path was the memory clock's slowest on the board (12.9 ns)."""
    banks = (depth + PLANE_BANK - 1) // PLANE_BANK
    if banks == 1:
        one = Signal(bool(0))
        we1, wval1 = Signal(bool(0)), Signal(bool(0))
        waddr1 = Signal(intbv(0)[len(waddr):])

        @always(clk.posedge)
        def last():
            we1.next = we
            waddr1.next = waddr
            wval1.next = wval
            q.next = one

        return pd_bank(clk, we1, waddr1, wval1, raddr, one, depth=depth), last
    abits = len(waddr)
    lo = PLANE_BANK.bit_length() - 1
    sbits = abits - lo
    bank_q = [Signal(bool(0)) for _ in range(banks)]
    q_vec = ConcatSignal(*reversed(bank_q))  # bit b: bank b's output register
    we_vec = Signal(intbv(0)[banks:])
    w_lo, r_lo = Signal(intbv(0)[lo:]), Signal(intbv(0)[lo:])
    w_hi = Signal(intbv(0)[sbits:])
    wval1 = Signal(bool(0))
    r_sel0, r_sel1 = Signal(intbv(0)[sbits:]), Signal(intbv(0)[sbits:])  # the read's bank, delayed with it
    insts = [pd_bank(clk, we_vec(b), w_lo, wval1, r_lo, bank_q[b], depth=PLANE_BANK) for b in range(banks)]

    @always_comb
    def split():
        r_lo.next = raddr[lo:0]
        w_hi.next = waddr[abits:lo]

    @always(clk.posedge)
    def decode():
        # the write a clock later, from registers: each bank's enable, the address in the bank, the bit
        we_vec.next = 0
        if we:
            we_vec.next[int(w_hi)] = 1
        w_lo.next = waddr[lo:0]
        wval1.next = wval

    @always(clk.posedge)
    def select():
        r_sel0.next = raddr[abits:lo]
        r_sel1.next = r_sel0
        q.next = q_vec[int(r_sel1)]

    return insts, split, decode, select


@block
def pair_display(clk, rst, pclk, prst, bus, run, copies, idle, hsync, vsync, de, red, green, blue, *, width: int = 320,
                 height: int = 240, rect_base: tuple[int, int] = (0, 76800),
                 feat_base: tuple[int, int] = (153600, 155648), max_features: int = 1023, mode: str = "640x480@60",
                 poll_gap: int = 64, polls: int = 4096, autostart: bool = False, matches: bool = False,
                 max_matches: int = 1023):
    """The newest rectified pair and its corners on a monitor: a copy of the pair in block RAM, taken over the
    register bus as the host would, shown in the pixel clock.

    The front end keeps its rectified pairs and feature lists in the frame store, where the host takes them with
    the buffer handshake (CTRL.rect_want/feat_want, STATUS.rect_held/feat_held, CMD.rect_release/feat_release;
    docs/registers.md). This block is such a host, on the bus beside the board's UART bridge (an AXI4-Lite
    arbiter between them): once per monitor frame it takes the newest pair and lists, reads the list (each corner's
    cross of :data:`~eyestereo.tools.models.pair_display.CROSS` pixels into its camera's mark plane), then the pair's
    ``width x height`` words through the SRAM window into two block RAMs (left, right; 8 bits a pixel, codes 255
    clipped to 254, a marked pixel written as the mark code 255), and gives the buffers back. In the pixel
    clock a :func:`~eyestereo.hdl.video.video_timing.video_timing` scans the mode; the top ``height`` lines show
    the left image at x < ``width`` and the right one beside it; the next ``height`` lines an anaglyph of the two
    (red the left, green and blue the right: rows that line up are grey); everything else is black. The colour
    rule is :func:`~eyestereo.tools.models.pair_display.colour_rule` (marks: red on the left image, green on the
    right, yellow in the anaglyph).

    Tearing: one copy of the pair, written while it is shown. The copy starts when the scan enters the anaglyph
    half (line ``height``), so that the scan of the next frame's top half starts behind the copy; a copy that
    takes less than the time from there to the end of the next frame's top half (about 26 ms at 640x480@60
    with 320x240 images) is never overtaken (an estimate from the mode's timing, not a measurement). The copy
    reads the list first and draws each corner's cross into a 1-bit mark plane per camera, then writes every pixel
    with its mark in one write (code 255 where the plane says so): a pixel and its mark change together.

    Matches (``matches``, the front end's matcher option): after the features the copy reads the frame's match list
    from the list buffer's word :func:`~eyestereo.tools.models.sram_arbiter.match_offset` (``max_features``) on,
    three words a match (:data:`~eyestereo.tools.models.match_engine.MATCH`) up to its trailer, and draws each
    match's :func:`~eyestereo.tools.models.pair_display.segment` (the left corner's row, from x - disparity to x,
    one pixel a clock) into a third plane; its bits are copied with the pixels into a 1-bit RAM, and the anaglyph
    shows them in :data:`~eyestereo.tools.models.pair_display.SEGMENT_RGB` (a corner's mark wins).

    Ports:
        clk, rst: the bus clock (the memory clock) and its synchronous reset.
        pclk, prst: the pixel clock (25 MHz for 640x480@60) and its synchronous reset.
        bus: :class:`~eyestereo.hdl.interfaces.axil.AxiLite` **master** (the front end's register map; its address
            bits at least the map's 23).
        run: 1 = take pairs (a constant or a board register); 0 = stop after the copy in progress, the buffers
            given back; the picture keeps the last pair.
        copies: pairs copied since reset (16 bits, wraps), bus clock.
        idle: 1 while the display holds no buffer and wants none (between copies, and for good once ``run`` is 0
            and the copy in progress has ended): a host may then take pairs itself with the same handshake.
        hsync, vsync, de, red, green, blue: the picture, pixel clock (8 bits a colour), into the TMDS encoders;
            sync polarity as the mode says.

    Parameters:
        width, height: the rectified pair's size (the front end's GEOMETRY); 2 x width must fit the mode's
            active width and 2 x height its lines.
        rect_base, feat_base: SRAM word addresses of rectified buffers 0 and 1 and of feature-list buffers 0 and 1
            (the front end's :class:`~eyestereo.tools.models.sram_arbiter.AddressMap`).
        max_features: the longest list read (the front end's); a list without its trailer is cut there.
        mode: :data:`~eyestereo.tools.models.video_timing.MODES`' name.
        poll_gap, polls: bus clocks between two STATUS polls, and polls before a copy is given up for this frame
            (no pair came: the cameras stopped); the wants are withdrawn then.
        autostart: False (default) or True: after reset, first start the front end as a board without a host needs
            it: CTRL's mode and continuous bits (overlapped, continuous; byte 0 alone) and CMD.start.
        matches: False (default) or True: draw the match list's segments (the front end built with
            ``matcher=True``; its list buffers hold the match list after the features).
        max_matches: the longest match list drawn (1..32767); a list without its trailer is cut there.

    Latency: a pixel is shown 2 pixel clocks after video_timing's outputs (RAM read, colour register); sync and
    ``de`` are delayed with it. A copy takes about ``width x height`` reads of the SRAM window (each a bank read
    plus the memory's wait) and 9 writes per listed corner; with ``matches``, 3 reads and disparity + 2 clocks per
    match.

    Resources: two ``width x height x 8`` block RAMs (320x240: 38 DP16KD each on the ECP5), two ``width x
    height`` x 1 mark planes in banks of 16,384 (5 DP16KD each), the FSM, constant multipliers for the scan and the
    crosses' addresses; with ``matches`` a third plane and a ``width x height`` x 1 RAM (5 + 5 DP16KD at 320x240)
    (the whole board's figures: docs/boards.md).
    """
    check_clock(clk)
    check_reset(rst)
    check_clock(pclk, "pclk")
    check_reset(prst, "prst")
    if mode not in MODES:
        raise block_error(f"mode {mode!r} is not one of {', '.join(MODES)}")
    m = MODES[mode]
    width = check_int("width", width, 8, 4096)
    height = check_int("height", height, 8, 4096)
    try:
        check_geometry(width, height, m)
    except ValueError as e:
        raise block_error(str(e)) from None
    check_int("max_features", max_features, 1, 32767)
    check_int("poll_gap", poll_gap, 1, 1 << 16)
    check_int("polls", polls, 1, 1 << 20)
    autostart = check_bool("autostart", autostart)
    matches = check_bool("matches", matches)
    max_matches = check_int("max_matches", max_matches, 1, MAX_MATCHES)
    for name, pair in (("rect_base", rect_base), ("feat_base", feat_base)):
        if not isinstance(pair, (tuple, list)) or len(pair) != 2 or any(
                isinstance(v, bool) or not isinstance(v, numbers.Integral) or not 0 <= v < (1 << 20) for v in pair):
            raise block_error(f"parameter {name} must be a pair of ints, two SRAM word addresses (0..2**20-1), "
                              f"got {pair!r}")
    abits = len(bus.araddr)
    if abits < REGMAP.addr_bits:
        raise block_error(f"bus needs at least the register map's {REGMAP.addr_bits} address bits, has {abits}")
    check_axil("bus", bus, addr_bits=abits)
    check_signal("run", run, width=1)
    check_signal("copies", copies, width=16)
    check_signal("idle", idle, width=1)
    for name, s in (("hsync", hsync), ("vsync", vsync), ("de", de)):
        check_signal(name, s, width=1)
    for name, s in (("red", red), ("green", green), ("blue", blue)):
        check_signal(name, s, width=8)

    npix = width * height
    pbits = max(1, (npix - 1).bit_length())
    want_word, release_word, want_strb = ctrl_words()
    run_word, start_word = start_words()
    a_ctrl, a_cmd, a_status = REGMAP["CTRL"].offset, REGMAP["CMD"].offset, REGMAP["STATUS"].offset
    rect_held, feat_held, rect_buf, feat_buf = (REGMAP.field(f"STATUS.{n}")[1].lsb
                                                for n in ("rect_held", "feat_held", "rect_buf", "feat_buf"))
    r0, r1 = (int(v) for v in rect_base)
    f0, f1 = (int(v) for v in feat_base)
    n_cross = len(CROSS)
    cdx = tuple(dx for dx, _ in CROSS)
    cdy = tuple(dy for _, dy in CROSS)
    moff = match_offset(max_features)  # the match list's first word in a list buffer
    mx_hi, mx_lo = MATCH.bits("x")
    my_hi, my_lo = MATCH.bits("y")
    md_hi, md_lo = MATCH.bits("disparity")

    ram_l = [Signal(intbv(0)[8:]) for _ in range(npix)]
    ram_r = [Signal(intbv(0)[8:]) for _ in range(npix)]
    we_l, we_r = Signal(bool(0)), Signal(bool(0))
    w_addr = Signal(intbv(0)[pbits:])
    w_l, w_r = Signal(intbv(0)[8:]), Signal(intbv(0)[8:])
    # the mark planes: a bit per pixel and camera, set by the crosses, read (and cleared) as the pixels are copied
    m_we_l, m_we_r, m_val = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    m_addr = Signal(intbv(0)[pbits:])
    mark_l, mark_r = Signal(bool(0)), Signal(bool(0))
    mwait = Signal(intbv(0, min=0, max=MARK_DRAIN + PLANE_LATENCY + 1))
    paddr = Signal(intbv(0)[pbits:])
    p1_valid, p2_we = Signal(bool(0)), Signal(bool(0))
    p1_cam, p2_cam = Signal(intbv(0)[2:]), Signal(intbv(0)[2:])  # the plane: 0 left, 1 right, 2 the matches
    p2_addr = Signal(intbv(0)[pbits:])

    # ---------------------------------------------------------------- bus clock: the copy
    st = enum("S_BOOT", "S_START", "S_IDLE", "S_WR", "S_WR_B", "S_POLL", "S_POLL_R", "S_GAP", "S_PIX", "S_PIX_R",
              "S_FEAT", "S_FEAT_R", "S_MARK", "S_UNWANT", "S_MATCH", "S_MATCH_R", "S_SEG0", "S_SEG")
    state = Signal(st.S_BOOT if autostart else st.S_IDLE)
    awv, wv, rr = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    resume = Signal(st.S_IDLE)  # where a register write goes when its response came
    tog = Signal(bool(0))  # pixel clock: toggles when the scan enters line `height`
    start = Signal(bool(0))
    pending = Signal(bool(0))
    copied = Signal(bool(0))  # the write in flight is the release of a copied pair
    gap = Signal(intbv(0, min=0, max=poll_gap + 1))
    tries = Signal(intbv(0, min=0, max=polls + 1))
    rbase = Signal(intbv(0)[20:])
    fbase = Signal(intbv(0)[20:])
    idx = Signal(intbv(0, min=0, max=max(npix, moff + 3 * max_matches + 3) + 1))
    half = Signal(bool(0))  # the feature word read is the entry's second (y)
    fx = Signal(intbv(0)[15:])
    fcam = Signal(bool(0))
    fy = Signal(intbv(0)[16:])
    nfeat = Signal(intbv(0, min=0, max=max_features + 1))
    k = Signal(intbv(0, min=0, max=n_cross + MARK_DRAIN + 1))
    cnt = Signal(intbv(0)[16:])
    reach = max(max(abs(d) for d in cdx), max(abs(d) for d in cdy))
    dxk = Signal(intbv(0, min=-reach, max=reach + 1))
    dyk = Signal(intbv(0, min=-reach, max=reach + 1))
    xk = Signal(intbv(0, min=-reach, max=(1 << 15) + reach))
    yk = Signal(intbv(0, min=-reach, max=(1 << 16) + reach))
    p1_x = Signal(intbv(0, min=-reach, max=(1 << 15) + reach))
    p1_y = Signal(intbv(0, min=-reach, max=(1 << 16) + reach))
    # the match list: a match's three words, the segment being drawn (columns seg_x .. seg_end of row seg_y)
    mw = Signal(intbv(0)[MATCH.width:])
    mword = Signal(intbv(0, min=0, max=3))
    nmatch = Signal(intbv(0, min=0, max=max_matches + 1))
    seg_x = Signal(intbv(0)[mx_hi - mx_lo:])
    seg_end = Signal(intbv(0)[mx_hi - mx_lo:])
    seg_y = Signal(intbv(0)[my_hi - my_lo:])
    m_we_m, mark_m = Signal(bool(0)), Signal(bool(0))

    sync = pd_sync(clk, rst, tog, start)

    @always_seq(clk.posedge, reset=rst)
    def copy():
        bus.awprot.next = 0
        bus.arprot.next = 0
        we_l.next = 0
        we_r.next = 0
        if start:
            pending.next = 1
        # the pixel phase: the read's data is taken only once the pixel's marks are out of the planes
        # (PLANE_LATENCY clocks after idx moved)
        if mwait != 0:
            mwait.next = mwait - 1
            if mwait == 1:
                rr.next = 1
        if state == st.S_BOOT:
            # start the front end: overlapped and continuous (CTRL byte 0), then CMD.start
            bus.awaddr.next = a_ctrl
            bus.wdata.next = run_word
            bus.wstrb.next = 1
            awv.next = 1
            wv.next = 1
            resume.next = st.S_START
            state.next = st.S_WR
        elif state == st.S_START:
            bus.awaddr.next = a_cmd
            bus.wdata.next = start_word
            bus.wstrb.next = 1
            awv.next = 1
            wv.next = 1
            resume.next = st.S_IDLE
            state.next = st.S_WR
        elif state == st.S_IDLE:
            if (pending or start) and run:
                pending.next = 0
                tries.next = 0
                bus.awaddr.next = a_ctrl
                bus.wdata.next = want_word
                bus.wstrb.next = want_strb
                awv.next = 1
                wv.next = 1
                resume.next = st.S_POLL
                state.next = st.S_WR
        elif state == st.S_WR:
            # one register write: address and data offered together, each dropped when taken
            if bus.awready:
                awv.next = 0
            if bus.wready:
                wv.next = 0
            if (bus.awready or not awv) and (bus.wready or not wv):
                bus.bready.next = 1
                state.next = st.S_WR_B
        elif state == st.S_WR_B:
            if bus.bvalid:
                bus.bready.next = 0
                if copied:
                    cnt.next = (cnt + 1) % 65536
                    copied.next = 0
                if resume == st.S_POLL:
                    bus.araddr.next = a_status
                    bus.arvalid.next = 1
                    rr.next = 1
                state.next = resume
        elif state == st.S_UNWANT:
            # the wants withdrawn (after a release, or when no pair came)
            bus.awaddr.next = a_ctrl
            bus.wdata.next = 0
            bus.wstrb.next = want_strb
            awv.next = 1
            wv.next = 1
            resume.next = st.S_IDLE
            state.next = st.S_WR
        elif state == st.S_POLL:
            if bus.arready:
                bus.arvalid.next = 0
                state.next = st.S_POLL_R
        elif state == st.S_POLL_R:
            if bus.rvalid:
                rr.next = 0
                if bus.rdata[rect_held] and bus.rdata[feat_held]:
                    # the corners first (into the mark planes), then the pixels
                    if bus.rdata[rect_buf]:
                        rbase.next = r1
                    else:
                        rbase.next = r0
                    if bus.rdata[feat_buf]:
                        fbase.next = f1
                        bus.araddr.next = SRAM_BASE + 4 * f1
                    else:
                        fbase.next = f0
                        bus.araddr.next = SRAM_BASE + 4 * f0
                    idx.next = 0
                    half.next = 0
                    nfeat.next = 0
                    state.next = st.S_FEAT
                    bus.arvalid.next = 1
                    rr.next = 1
                elif tries == polls - 1 or not run:
                    state.next = st.S_UNWANT  # give up for this frame
                else:
                    tries.next = tries + 1
                    gap.next = poll_gap
                    state.next = st.S_GAP
        elif state == st.S_GAP:
            if gap == 0:
                bus.araddr.next = a_status
                bus.arvalid.next = 1
                rr.next = 1
                state.next = st.S_POLL
            else:
                gap.next = gap - 1
        elif state == st.S_PIX:
            if bus.arready:
                bus.arvalid.next = 0
                state.next = st.S_PIX_R
        elif state == st.S_PIX_R:
            if bus.rvalid and rr:
                # a pixel and its mark in one write: the picture never shows a pixel without the mark it has
                w_addr.next = idx
                if mark_l:
                    w_l.next = MARK
                elif bus.rdata[8:0] > PIXEL_MAX:
                    w_l.next = PIXEL_MAX
                else:
                    w_l.next = bus.rdata[8:0]
                if mark_r:
                    w_r.next = MARK
                elif bus.rdata[16:8] > PIXEL_MAX:
                    w_r.next = PIXEL_MAX
                else:
                    w_r.next = bus.rdata[16:8]
                we_l.next = 1
                we_r.next = 1
                if idx == npix - 1:
                    # the pair is copied: both buffers given back
                    rr.next = 0
                    bus.awaddr.next = a_cmd
                    bus.wdata.next = release_word
                    bus.wstrb.next = want_strb
                    awv.next = 1
                    wv.next = 1
                    copied.next = 1
                    resume.next = st.S_UNWANT
                    state.next = st.S_WR
                else:
                    idx.next = idx + 1
                    bus.araddr.next = SRAM_BASE + 4 * (rbase + idx + 1)
                    bus.arvalid.next = 1
                    rr.next = 0
                    mwait.next = PLANE_LATENCY
                    state.next = st.S_PIX
        elif state == st.S_FEAT:
            if bus.arready:
                bus.arvalid.next = 0
                state.next = st.S_FEAT_R
        elif state == st.S_FEAT_R:
            if bus.rvalid:
                if not half:
                    if bus.rdata[16:0] == MARKER and matches:
                        state.next = st.S_MATCH  # the trailer: the match list next
                        idx.next = moff
                        mword.next = 0
                        nmatch.next = 0
                        bus.araddr.next = SRAM_BASE + 4 * (fbase + moff)
                        bus.arvalid.next = 1
                    elif bus.rdata[16:0] == MARKER:
                        state.next = st.S_PIX  # the trailer: the list is done, the pixels next
                        idx.next = 0
                        bus.araddr.next = SRAM_BASE + 4 * rbase
                        bus.arvalid.next = 1
                        rr.next = 0
                        mwait.next = MARK_DRAIN + PLANE_LATENCY
                    else:
                        fx.next = bus.rdata[15:0]
                        fcam.next = bus.rdata[15]
                        half.next = 1
                        idx.next = idx + 1
                        bus.araddr.next = SRAM_BASE + 4 * (fbase + idx + 1)
                        bus.arvalid.next = 1
                        state.next = st.S_FEAT
                else:
                    rr.next = 0
                    fy.next = bus.rdata[16:0]
                    half.next = 0
                    k.next = 0
                    state.next = st.S_MARK
        elif state == st.S_MARK:
            # the corner's cross into its camera's mark plane, one pixel a clock, those inside the image (a
            # two-stage pipeline: the pixel's coordinates, then its address; MARK_DRAIN clocks drain it)
            if k == n_cross + MARK_DRAIN:
                nfeat.next = nfeat + 1
                bus.arvalid.next = 1
                rr.next = 1
                if nfeat == max_features - 1 and matches:
                    idx.next = moff
                    mword.next = 0
                    nmatch.next = 0
                    bus.araddr.next = SRAM_BASE + 4 * (fbase + moff)
                    state.next = st.S_MATCH
                elif nfeat == max_features - 1:
                    idx.next = 0
                    bus.araddr.next = SRAM_BASE + 4 * rbase
                    rr.next = 0
                    mwait.next = PLANE_LATENCY
                    state.next = st.S_PIX
                else:
                    idx.next = idx + 1
                    bus.araddr.next = SRAM_BASE + 4 * (fbase + idx + 1)
                    state.next = st.S_FEAT
            else:
                k.next = k + 1
        elif state == st.S_MATCH:
            if bus.arready:
                bus.arvalid.next = 0
                state.next = st.S_MATCH_R
        elif state == st.S_MATCH_R:
            if bus.rvalid:
                if mword == 0 and bus.rdata[16:0] == MATCH_MARKER:
                    # the trailer: the pixels next (the last segment's writes drain meanwhile)
                    state.next = st.S_PIX
                    idx.next = 0
                    bus.araddr.next = SRAM_BASE + 4 * rbase
                    bus.arvalid.next = 1
                    rr.next = 0
                    mwait.next = MARK_DRAIN + PLANE_LATENCY
                else:
                    mw.next = concat(bus.rdata[16:0], mw[MATCH.width:16])  # low word first
                    if mword == 2:
                        mword.next = 0
                        rr.next = 0
                        state.next = st.S_SEG0
                    else:
                        mword.next = mword + 1
                        idx.next = idx + 1
                        bus.araddr.next = SRAM_BASE + 4 * (fbase + idx + 1)
                        bus.arvalid.next = 1
                        state.next = st.S_MATCH
        elif state == st.S_SEG0:
            # the segment: from the right corner's column (x - disparity; columns left of the image are not drawn,
            # so it starts at 0 there: unsigned arithmetic alone) to the left corner's
            seg_x.next = 0
            if mw[mx_hi:mx_lo] >= mw[md_hi:md_lo]:
                seg_x.next = mw[mx_hi:mx_lo] - mw[md_hi:md_lo]
            seg_end.next = mw[mx_hi:mx_lo]
            seg_y.next = mw[my_hi:my_lo]
            state.next = st.S_SEG
        elif state == st.S_SEG:
            # one pixel a clock into the match plane (the marks' pipeline, plane 2)
            if seg_x == seg_end:
                nmatch.next = nmatch + 1
                if nmatch == max_matches - 1:
                    idx.next = 0
                    bus.araddr.next = SRAM_BASE + 4 * rbase
                    bus.arvalid.next = 1
                    mwait.next = MARK_DRAIN + PLANE_LATENCY
                    state.next = st.S_PIX
                else:
                    idx.next = idx + 1
                    bus.araddr.next = SRAM_BASE + 4 * (fbase + idx + 1)
                    bus.arvalid.next = 1
                    rr.next = 1
                    state.next = st.S_MATCH
            else:
                seg_x.next = seg_x + 1

    @always_comb
    def cross_rom():
        dxk.next = cdx[k]
        dyk.next = cdy[k]

    @always_comb
    def cross_pos():
        xk.next = fx + dxk
        yk.next = fy + dyk

    @always_comb
    def outs():
        # the bus's valids and ready from registers of their own (VHDL-93 cannot read an output port)
        bus.awvalid.next = awv
        bus.wvalid.next = wv
        bus.rready.next = rr
        copies.next = cnt
        idle.next = state == st.S_IDLE

    @always(clk.posedge)
    def write():
        if we_l:
            ram_l[int(w_addr)].next = w_l
        if we_r:
            ram_r[int(w_addr)].next = w_r

    @always(clk.posedge)
    def plane_read():
        # idx counts feature words too (up to 2 x max_features + 2): only a pixel's index reads the planes. A
        # register: the compare in front of the banks' read addresses was the memory clock's slowest path
        paddr.next = 0
        if idx < npix:
            paddr.next = idx

    @always_seq(clk.posedge, reset=rst)
    def mark_pipe():
        # stage 1: the cross pixel's coordinates; stage 2: inside the image?, its address (registered: the
        # constant multiply and the compares stay off the RAM's write port)
        if state == st.S_SEG:
            p1_valid.next = 1
            p1_x.next = seg_x
            p1_y.next = seg_y
            p1_cam.next = 2
        else:
            p1_valid.next = state == st.S_MARK and k < n_cross
            p1_x.next = xk
            p1_y.next = yk
            p1_cam.next = fcam
        p2_we.next = 0
        p2_addr.next = 0
        p2_cam.next = p1_cam
        if p1_valid and p1_x >= 0 and p1_x < width and p1_y >= 0 and p1_y < height:
            p2_we.next = 1
            p2_addr.next = p1_y * width + p1_x

    @always_comb
    def plane_port():
        # one write port per plane: the crosses' 1s while marking, the 0s that clear each bit as its pixel is
        # written (the planes are empty again when the copy ends)
        m_addr.next = 0
        m_we_l.next = 0
        m_we_r.next = 0
        m_we_m.next = 0
        m_val.next = 0
        if p2_we:
            m_addr.next = p2_addr
            m_val.next = 1
            if p2_cam == 2:
                m_we_m.next = 1
            elif p2_cam == 1:
                m_we_r.next = 1
            else:
                m_we_l.next = 1
        elif state == st.S_PIX_R and bus.rvalid and rr:
            # cleared as the pixel is written (not while its read waits for the mark: rr low)
            m_addr.next = idx
            m_we_l.next = 1
            m_we_r.next = 1
            m_we_m.next = 1

    planes = [pd_plane(clk, m_we_l, m_addr, m_val, paddr, mark_l, depth=npix),
              pd_plane(clk, m_we_r, m_addr, m_val, paddr, mark_r, depth=npix)]
    pm = Signal(bool(0))  # pixel clock: the scan's match bit
    if matches:
        ram_m = [Signal(bool(0)) for _ in range(npix)]
        planes.append(pd_plane(clk, m_we_m, m_addr, m_val, paddr, mark_m, depth=npix))

        @always(clk.posedge)
        def write_m():
            if we_l:
                ram_m[int(w_addr)].next = mark_m

        planes.append(write_m)
    else:
        @always(clk.posedge)
        def no_match_plane():
            # without the option the match bit is 0 (a flip-flop: MyHDL declares only driven signals)
            mark_m.next = 0

        planes.append(no_match_plane)

    # ---------------------------------------------------------------- pixel clock: the scan
    vhs, vvs, vde = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    vx = Signal(intbv(0, min=0, max=m.h_active))
    vy = Signal(intbv(0, min=0, max=m.v_active))
    timing = video_timing(pclk, prst, vhs, vvs, vde, vx, vy, mode=mode)
    hs1, vs1, de1 = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    zone1 = Signal(intbv(0)[2:])  # 0 black, 1 left image, 2 right image, 3 anaglyph
    pl, pr = Signal(intbv(0)[8:]), Signal(intbv(0)[8:])
    raddr = Signal(intbv(0)[pbits:])
    zone0 = Signal(intbv(0)[2:])
    arow = Signal(intbv(0, min=0, max=m.v_active))
    line_seen = Signal(bool(0))

    @always_comb
    def anaglyph_row():
        # the anaglyph's image row, unsigned on its own (in one expression with vx, Verilog would mix signedness)
        arow.next = 0
        if vy >= height:
            arow.next = vy - height

    @always_comb
    def scan_addr():
        zone0.next = 0
        raddr.next = 0
        if vde:
            if vy < height:
                if vx < width:
                    zone0.next = 1
                    raddr.next = vy * width + vx
                elif vx < 2 * width:
                    zone0.next = 2
                    raddr.next = vy * width + vx - width
            elif vy < 2 * height and vx < width:
                zone0.next = 3
                raddr.next = arow * width + vx

    @always(pclk.posedge)
    def read():
        pl.next = ram_l[int(raddr)]
        pr.next = ram_r[int(raddr)]

    if matches:
        @always(pclk.posedge)
        def read_m():
            pm.next = ram_m[int(raddr)]
    else:
        @always(pclk.posedge)
        def read_m():
            pm.next = 0

    @always_seq(pclk.posedge, reset=prst)
    def stage1():
        hs1.next = vhs
        vs1.next = vvs
        de1.next = vde
        zone1.next = zone0
        # the copy's start: the first pixel of line `height`
        if vde and vy == height and vx == 0:
            if not line_seen:
                tog.next = not tog
            line_seen.next = 1
        else:
            line_seen.next = 0

    @always_seq(pclk.posedge, reset=prst)
    def stage2():
        hsync.next = hs1
        vsync.next = vs1
        de.next = de1
        red.next = 0
        green.next = 0
        blue.next = 0
        if zone1 == 1:
            if pl == MARK:
                red.next = 255
            else:
                red.next = pl
                green.next = pl
                blue.next = pl
        elif zone1 == 2:
            if pr == MARK:
                green.next = 255
            else:
                red.next = pr
                green.next = pr
                blue.next = pr
        elif zone1 == 3:
            if pl == MARK or pr == MARK:
                red.next = 255
                green.next = 255
            elif pm:
                red.next = SEGMENT_RGB[0]
                green.next = SEGMENT_RGB[1]
                blue.next = SEGMENT_RGB[2]
            else:
                red.next = pl
                green.next = pr
                blue.next = pr

    return (sync, copy, cross_rom, cross_pos, outs, write, plane_read, mark_pipe, plane_port, planes, timing,
            anaglyph_row, scan_addr, read, read_m, stage1, stage2)
