"""Asynchronous frame FIFO: an image stream in one clock, a queue read port in another, broken frames dropped."""

from myhdl import Signal, always, always_comb, block, concat, intbv

from eyestereo.hdl.common.registers import assign
from eyestereo.hdl.common.checks import block_error, check_clock, check_int, check_reset, check_signal, check_stream
from eyestereo.hdl.interfaces.queue import check_queue

MAX_DEPTH = 1 << 14
#: The default depth: LUT-RAM, so that the read side's word comes from a flip-flop. A block RAM (1024 x 18 in
#: one RAMB16) gives its word 5.8 ns after the clock edge on the ECP5, in front of the read side's frame
#: logic: make synth measured the read clock at 104.9 / 116.5 / 119.4 MHz (min / median / max over seeds
#: 1-4) with depth 1024, below the memory clock's 110 MHz (issue 23); 32 words hold what the front end's
#: arbiter ever leaves in a camera FIFO (at most 2, docs/sram.md). Take 1024 for a reader that stalls.
DEFAULT_DEPTH = 32


def check_depth(depth) -> int:
    """The FIFO depth checked: a power of two from 4 to MAX_DEPTH (also for the blocks that wrap the FIFO)."""
    depth = check_int("depth", depth, 4, MAX_DEPTH)
    if depth & (depth - 1):
        raise block_error(f"parameter depth={depth} must be a power of two (Gray-coded pointers)")
    return depth


@block
def async_fifo(wclk, wrst, sink, rclk, rrst, source, dropped, full=None, empty=None, *,
               depth: int = DEFAULT_DEPTH):
    """Carry an image stream from the write clock into the read clock; deliver whole frames or abort them.

    The memory is ``depth`` entries of ``data + eol + eof`` (18 bits for camera words: one Spartan-3E
    block RAM holds 1024 of them), written in the write clock, read in the read clock (one write port and
    one registered read port: a dual-port RAMB16 with a clock per port). The pointers are Gray-coded
    binary counters with one wrap bit; each side sees the other's pointer through two flip-flops in its
    own clock.

    The sink has no back-pressure. A pixel that arrives while the FIFO is full is lost, and with it the
    frame: the rest of that frame is discarded on the write side, the dropped-frame counter counts it,
    and, if words of it are already in the FIFO, a reset token follows them as soon as there is space.
    The reader sees that frame's first words and then the token (the queue read port's rule:
    :mod:`eyestereo.hdl.interfaces.queue`), never a frame with missing or extra words ending in ``eof``. The next
    frame that finds space from its first word on comes through whole. A reset token from the sink (the
    camera's frame broke) is handled the same way.

    Clock-domain crossings (everything else stays in its domain):

    * write pointer, Gray code (depth bits + 1), write clock -> two flip-flops in the read clock -> empty;
    * read pointer, Gray code, read clock -> two flip-flops in the write clock -> full;
    * dropped-frame count, Gray code (16 bits), write clock -> two flip-flops in the read clock ->
      converted to binary in a register (``dropped``);
    * the memory: written in the write clock, read in the read clock; an entry is read only after its
      write has come through the write pointer's synchroniser.

    Each crossing carries a value that changes by one Gray step per clock at most, so a synchroniser that
    samples in the middle of a change sees the old or the new value, both safe (a late full or empty).
    A vendor flow should mark the synchroniser pairs (``*_s1``, ``*_s2``) as such (ASYNC_REG) and put a
    max-delay on the paths into them.

    Resets, one per domain, either alone, at any time: pointers and the dropped counter are never reset
    (they start at 0 with the FPGA's configuration, their initial values), so neither side ever sees the
    other's pointer jump. ``wrst`` abandons the frame the write side was taking in (counted as dropped,
    a token follows its words if any are in the FIFO); the sink's producer must share that reset, so that
    its next beat after the reset starts a frame (camera_stream does, in camera_interface). ``rrst`` discards
    the word in the output register;
    if the reader was inside a frame, the read side then loads and discards entries up to the end of that
    frame (or its token), so the next word presented is the first of a frame.

    Ports:
        wclk: write clock, rising edge.
        wrst: write-domain synchronous reset, active high.
        sink: :class:`~eyestereo.hdl.interfaces.stream.ImageStream` (any data width; no back-pressure).
        rclk: read clock, rising edge.
        rrst: read-domain synchronous reset, active high; ``source.valid`` is low while it is high.
        source: :class:`~eyestereo.hdl.interfaces.queue.QueuePort` of the sink's data width (read clock).
        dropped: output, read clock: frames dropped since configuration (wraps), a 16-bit Signal;
            it follows a drop within 4 read clocks after the write side decided it.
        full: optional output, write clock: the memory is full (a pixel now would be lost).
        empty: optional output, read clock: nothing to load (the output register may still hold a word).

    Parameters:
        depth: entries, a power of two in 4..16384 (default :data:`DEFAULT_DEPTH` = 32, LUT-RAM; 1024: one
            RAMB16 at 18 bits, with a slower read side: see :data:`DEFAULT_DEPTH`).

    Latency: a word written at a write edge is presented from the third read edge after it on (two
    synchroniser flops and the registered read), more if the output register is occupied. A read is
    seen as free space by the write side from the third write edge after it.

    Resources: one RAMB16 per 1024 x 18 (or LUT RAM for small depths), the pointer and synchroniser
    registers (4 x (log2(depth) + 1) flip-flops, 2 x 16 for the counter), a few LUTs of control.
    """
    check_clock(wclk, "wclk")
    check_reset(wrst, "wrst")
    check_stream("sink", sink)
    check_clock(rclk, "rclk")
    check_reset(rrst, "rrst")
    dw = sink.data_width
    check_queue("source", source, width=dw)
    check_signal("dropped", dropped, width=16)
    if full is not None:
        check_signal("full", full, width=1)
    if empty is not None:
        check_signal("empty", empty, width=1)
    depth = check_depth(depth)

    A = depth.bit_length() - 1  # address bits
    MOD = 1 << (A + 1)  # pointers carry one wrap bit
    MASK = 3 << (A - 1)  # full: the two top Gray bits differ, the rest equal
    W = dw + 2  # data, eol, eof
    CB = len(dropped)
    CMOD = 1 << CB

    # Internal copies: VHDL-93 cannot read an output port.
    full_s, empty_s = Signal(bool(0)), Signal(bool(0))

    mem = [Signal(intbv(0)[W:]) for _ in range(depth)]

    # ---- write side (wclk) ---------------------------------------------------------------------------
    wbin, wgray = Signal(intbv(0)[A + 1:]), Signal(intbv(0)[A + 1:])
    wbin_nx, wgray_nx = Signal(intbv(0)[A + 1:]), Signal(intbv(0)[A + 1:])
    rgray_s1, rgray_s2 = Signal(intbv(0)[A + 1:]), Signal(intbv(0)[A + 1:])
    waddr = Signal(intbv(0, min=0, max=depth))
    wword = Signal(intbv(0)[W:])
    we = Signal(bool(0))
    wr_tok = Signal(bool(0))
    pix = Signal(bool(0))  # a pixel beat
    tokin = Signal(bool(0))  # a reset token from the sink
    started = Signal(bool(0))  # the sink's current frame has begun
    bad = Signal(bool(0))  # ... and lost a word: discard it up to its eof
    mid = Signal(bool(0))  # words of the current frame are in the memory (a token must close them)
    tok_pend = Signal(bool(0))  # a token waits for space
    inc = Signal(bool(0))  # count a dropped frame
    cbin, cgray = Signal(intbv(0)[CB:]), Signal(intbv(0)[CB:])
    cbin_nx, cgray_nx = Signal(intbv(0)[CB:]), Signal(intbv(0)[CB:])
    tok_word = Signal(intbv(1 << (W - 1))[W:])  # eof high, eol low, data 0

    @always_comb
    def w_decode():
        pix.next = sink.valid and (sink.eol or not sink.eof)
        tokin.next = sink.valid and sink.eof and not sink.eol
        wbin_nx.next = (wbin + 1) % MOD
        waddr.next = wbin[A:]
        cbin_nx.next = (cbin + 1) % CMOD

    @always_comb
    def w_gray():
        wgray_nx.next = wbin_nx ^ (wbin_nx >> 1)
        cgray_nx.next = cbin_nx ^ (cbin_nx >> 1)
        full_s.next = wgray == (rgray_s2 ^ MASK)

    @always_comb
    def w_enable():
        wr_tok.next = (not wrst) and (not full_s) and (
            tok_pend or (tokin and started and (not bad) and mid))
        we.next = (not wrst) and (not full_s) and (
            tok_pend or (tokin and started and (not bad) and mid) or (pix and (not bad)))

    @always_comb
    def w_data():
        if wr_tok:
            wword.next = tok_word
        else:
            wword.next = concat(sink.eof, sink.eol, sink.data)

    @always(wclk.posedge)
    def w_mem():
        # No reset: block RAM.
        if we:
            mem[waddr].next = wword

    @always(wclk.posedge)
    def w_ptr():
        # Pointers, synchroniser and counter: never reset (initial values 0), so a reset of either
        # domain alone never makes the other side see a jump.
        if we:
            wbin.next = wbin_nx
            wgray.next = wgray_nx
        rgray_s1.next = rgray
        rgray_s2.next = rgray_s1
        if inc:
            cbin.next = cbin_nx
            cgray.next = cgray_nx

    @always_comb
    def w_count():
        if wrst:
            inc.next = started and not bad
        elif pix:
            inc.next = (not bad) and (tok_pend or full_s)
        else:
            inc.next = tokin and (not bad) and started

    @always(wclk.posedge)
    def w_ctl():
        if wrst:
            if mid:
                tok_pend.next = True
            mid.next = False
            started.next = False
            bad.next = False
        else:
            if wr_tok and tok_pend:
                tok_pend.next = False
            if pix:
                if bad:
                    if sink.eof:
                        bad.next = False
                        started.next = False
                elif tok_pend or full_s:
                    # the pixel is lost, and with it the frame
                    if mid:
                        tok_pend.next = True
                    mid.next = False
                    bad.next = not sink.eof
                    started.next = not sink.eof
                else:
                    mid.next = not sink.eof
                    started.next = not sink.eof
            elif tokin:
                if bad:
                    bad.next = False
                elif started:
                    if mid and (tok_pend or full_s):
                        tok_pend.next = True
                    mid.next = False
                started.next = False

    # ---- read side (rclk) ----------------------------------------------------------------------------
    rbin, rgray = Signal(intbv(0)[A + 1:]), Signal(intbv(0)[A + 1:])
    rbin_nx, rgray_nx = Signal(intbv(0)[A + 1:]), Signal(intbv(0)[A + 1:])
    wgray_s1, wgray_s2 = Signal(intbv(0)[A + 1:]), Signal(intbv(0)[A + 1:])
    cgray_s1, cgray_s2 = Signal(intbv(0)[CB:]), Signal(intbv(0)[CB:])
    raddr = Signal(intbv(0, min=0, max=depth))
    q = Signal(intbv(0)[W:])  # the block RAM's output register = the port's word
    q_full = Signal(bool(0))
    q_eof = Signal(bool(0))
    skip = Signal(bool(0))  # after rrst inside a frame: discard up to its end
    last_eof = Signal(bool(1))  # the last word that left the output register had eof
    load, take, drop_q = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))

    @always_comb
    def r_decode():
        rbin_nx.next = (rbin + 1) % MOD
        raddr.next = rbin[A:]
        q_eof.next = q[W - 1]
        empty_s.next = rgray == wgray_s2

    @always_comb
    def r_gray():
        rgray_nx.next = rbin_nx ^ (rbin_nx >> 1)

    @always_comb
    def r_enable():
        take.next = q_full and source.ready and (not skip) and (not rrst)
        drop_q.next = q_full and skip and (not rrst)
        load.next = (not rrst) and (not empty_s) and ((not q_full) or take or drop_q)

    @always_comb
    def r_port():
        source.valid.next = q_full and (not skip) and (not rrst)
        source.data.next = q[dw:]
        source.eol.next = q[dw]
        source.eof.next = q[dw + 1]

    @always(rclk.posedge)
    def r_mem():
        # Registered read with enable: the block RAM's own output latch.
        if load:
            q.next = mem[raddr]

    @always(rclk.posedge)
    def r_ptr():
        if load:
            rbin.next = rbin_nx
            rgray.next = rgray_nx
        wgray_s1.next = wgray
        wgray_s2.next = wgray_s1

    @always(rclk.posedge)
    def r_ctl():
        if rrst:
            q_full.next = False
            if q_full:
                last_eof.next = q_eof
                skip.next = not q_eof
            else:
                skip.next = not last_eof
        else:
            if load:
                q_full.next = True
            elif take or drop_q:
                q_full.next = False
            if take or drop_q:
                last_eof.next = q_eof
            if drop_q and q_eof:
                skip.next = False

    @always(rclk.posedge)
    def r_count():
        cgray_s1.next = cgray
        cgray_s2.next = cgray_s1
        # Gray to binary: bit i is the XOR of the Gray bits i and up, each bit on its own (written as the chain
        # b[i] = b[i + 1] ^ g[i], the 16 bits were a 16-LUT path, the memory clock's slowest on the ULX3S board)
        b = intbv(0)[CB:]
        for i in range(CB):
            x = intbv(0)[1:]
            for j in range(i, CB):
                x[0] = x[0] ^ cgray_s2[j]
            b[i] = x[0]
        dropped.next = b

    insts = []
    if full is not None:
        insts.append(assign(full_s, full))
    if empty is not None:
        insts.append(assign(empty_s, empty))
    return insts + [w_decode, w_gray, w_enable, w_data, w_mem, w_ptr, w_count, w_ctl,
            r_decode, r_gray, r_enable, r_port, r_mem, r_ptr, r_ctl, r_count]
