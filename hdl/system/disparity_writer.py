"""The dense option's disparity maps into two frame buffers, written through the memory's host port."""

from __future__ import annotations

from myhdl import Signal, always, always_comb, always_seq, block, intbv

from eyestereo.hdl.common.checks import (block_error, check_clock, check_distinct, check_frame, check_int, check_reset,
                                         check_signal, check_stream)
from eyestereo.hdl.common.fifo import show_ahead_fifo
from eyestereo.hdl.common.packed import pack_word, unpack_word
from eyestereo.hdl.interfaces.sram_bus import HostPort, check_bundle
from eyestereo.hdl.memory.frame_buffers import BufferSide, double_buffer
from eyestereo.tools.packed import PackedWord

__all__ = ["disparity_writer", "ENTRY", "DEFAULT_DEPTH"]

#: The writer FIFO's entry: a disparity code, the frame's first and last code, an abort (a reset token).
ENTRY = PackedWord("disparity writer entry", [("data", 16), ("sof", 1), ("eof", 1), ("abt", 1)])
#: The small show-ahead FIFO after the block RAM (LUT-RAM; the head's flags come from it).
OUT = 4
#: FIFO entries: sgm hands a row's codes over at one per clock and the host port takes at most one word per two
#: clocks, so a row of up to 1024 codes must wait here: 512 (one block RAM) for rows up to 1024 pixels.
DEFAULT_DEPTH = 512


@block
def disparity_writer(clk, rst, sink, bank, mem, want, release, held, avail, buf, frames, lost, *, base0: int,
                     base1: int, width: int, height: int, depth: int = DEFAULT_DEPTH):
    """Write each disparity frame of ``sink`` into one of two buffers and let the host take the newest.

    The codes wait in a FIFO (block RAM); from there each frame goes to consecutive words from its buffer's
    base address (``base0`` or ``base1``, :meth:`eyestereo.tools.models.sram_arbiter.AddressMap.disparity`),
    written through the memory's host port: the register bank's requests (``bank``) and the writer's share
    ``mem``, alternating when both wait (the bank's reads get their responses; the writer only writes).
    The buffers are a :func:`~eyestereo.hdl.memory.frame_buffers.double_buffer`: a frame takes a buffer the
    host does not hold (FREE, else the older FULL), is FULL when its last word has moved into the host port
    (the port is in order: a read the host makes after taking the buffer comes after it), and the host takes
    the newest FULL one with ``want`` and gives it back with ``release``, as for the rectified pairs.

    Timing of the handshake (``#`` high, ``_`` low)::

        cycle    0    1    2    3    4    5
        avail    _    #    #    _    _    _      a frame's last word moved in cycle 0
        want     #    #    #    #    #    _
        held     _    _    #    #    _    _      taken at the edge after cycle 1
        release  _    _    _    #    _    _

    Ports:
        clk, rst: the memory clock and its synchronous reset (the buffers FREE, the FIFO empty).
        sink: mono :class:`~eyestereo.hdl.interfaces.stream.ImageStream` (16 bits): the codes, ``width`` x
            ``height`` per frame (dense_stereo's source); a reset token abandons the frame being written.
        bank: :class:`~eyestereo.hdl.interfaces.sram_bus.HostPort` from the register bank (this block serves it).
        mem: HostPort to the memory subsystem's host port (this block is its master).
        want, release: in, 1 bit each: take the newest complete map whenever none is held / give it back (pulse).
        held, avail, buf: out, 1 bit each: a map is held; a complete map can be taken; the buffer held (the
            last one held when none is).
        frames: out, 16 bits: maps completed since reset (wraps).
        lost: out, 1 bit: a code found the FIFO full and was lost (sticky until ``rst``: the memory did not keep
            up; the map it belonged to is wrong).

    Parameters:
        base0, base1: the buffers' first word addresses (each must hold ``width`` x ``height`` words below
            2 ** len(mem.req_addr)).
        width, height: the frame.
        depth: the FIFO's entries, a power of two 16..16384 (default :data:`DEFAULT_DEPTH`).

    Latency: a code is in the FIFO's head 4 clocks after its beat (the block RAM, its read register, q2, the
    small FIFO), and moves into the host port when the port and the alternation let it (at most one word per
    two clocks).

    Resources: the FIFO (``depth`` x 19 bits: one block RAM at 512; 4 more entries of LUT-RAM), the double
    buffer's registers, a 20-bit address counter and the port multiplexer (about 100 LUTs).
    """
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, width=16, stereo=False)
    check_bundle("bank", bank, HostPort)
    check_bundle("mem", mem, HostPort)
    for name, sig in (("want", want), ("release", release), ("held", held), ("avail", avail), ("buf", buf),
                      ("lost", lost)):
        check_signal(name, sig, width=1)
    check_signal("frames", frames, width=16)
    check_distinct(dict(mem=mem, held=held, avail=avail, buf=buf, frames=frames, lost=lost),
                   dict(clk=clk, rst=rst, sink=sink, bank=bank, want=want, release=release))
    width, height = check_frame(width, height)
    depth = check_int("depth", depth, 16, 1 << 14)
    if depth & (depth - 1):
        raise block_error(f"parameter depth={depth} must be a power of two (the FIFO's pointers wrap)")
    abits = len(mem.req_addr)
    frame = width * height
    for name, base in (("base0", base0), ("base1", base1)):
        base = check_int(name, base, 0)
        if base + frame > 1 << abits:
            raise block_error(f"parameter {name}={base}: a {width}x{height} map ends at word {base + frame - 1}, "
                              f"past the {abits}-bit address space")
    if abs(base0 - base1) < frame:
        raise block_error(f"parameters base0={base0}, base1={base1}: the two {frame}-word buffers overlap")
    if len(bank.req_addr) != abits:
        raise block_error(f"ports bank and mem: {len(bank.req_addr)} and {abits} address bits, one memory")

    insts = []
    # ---- the FIFO: the entries in block RAM, read ahead into a small show-ahead FIFO whose head decides the port ----
    # The block RAM's registered output comes late in the clock (5.8 ns on the ECP5): it goes only into a
    # flip-flop beside it (q2), and from there into OUT entries of LUT-RAM; the head's flags (which drive the
    # port's multiplexer and the double buffer's handshake) then come from LUT-RAM. Reads are issued on credit:
    # the small FIFO's entries and the two reads on their way never exceed OUT.
    aw = depth.bit_length() - 1
    # _norw: never read where written in the same clock (a read needs n != 0, a write n != depth: rp == wp only
    # when empty or full), so Yosys builds no collision logic between the RAM and q
    ram_norw = [Signal(intbv(0)[ENTRY.width:]) for _ in range(depth)]
    din, q, q2, head = (Signal(intbv(0)[ENTRY.width:]) for _ in range(4))
    wp, rp = Signal(intbv(0)[aw:]), Signal(intbv(0)[aw:])
    n = Signal(intbv(0, min=0, max=depth + 1))  # entries in the block RAM
    level = Signal(intbv(0, min=0, max=OUT + 1))  # entries in the show-ahead FIFO
    busy = Signal(intbv(0, min=0, max=OUT + 3))
    v1, v2, hv, issue, push, pop, lost_r = (Signal(bool(0)) for _ in range(7))
    d_sof, d_eof, d_abt, fresh = Signal(bool(0)), Signal(bool(0)), Signal(bool(0)), Signal(bool(1))
    h_data = Signal(intbv(0)[16:])
    h_sof, h_eof, h_abt = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    insts.append(pack_word(din, ENTRY, data=sink.data, sof=d_sof, eof=d_eof, abt=d_abt))
    insts.append(unpack_word(head, ENTRY, data=h_data, sof=h_sof, eof=h_eof, abt=h_abt))
    insts.append(show_ahead_fifo(clk, rst, q2, v2, head, pop, level, depth=OUT))

    @always_comb
    def entry_in():
        token = sink.eof and not sink.eol
        d_abt.next = token
        d_eof.next = sink.eof and sink.eol
        d_sof.next = fresh and not token
        push.next = sink.valid and n != depth

    @always_seq(clk.posedge, reset=rst)
    def framing():
        # the next code is a frame's first after a frame's last, a token, or reset
        if sink.valid:
            fresh.next = sink.eof
            if n == depth:
                lost_r.next = True

    @always_comb
    def credit():
        # the small FIFO's entries and the reads on their way (no sum of a bool and a vector: MyHDL's VHDL)
        if v1 and v2:
            busy.next = level + 2
        elif v1 or v2:
            busy.next = level + 1
        else:
            busy.next = level

    @always_comb
    def refill():
        issue.next = n != 0 and busy < OUT
        hv.next = level != 0

    @always(clk.posedge)
    def storage():
        # no reset: a block RAM with a registered, enabled read port (q), then a plain register (q2)
        if push:
            ram_norw[wp].next = din
        if issue:
            q.next = ram_norw[rp]
        q2.next = q

    @always_seq(clk.posedge, reset=rst)
    def pointers():
        if push:
            wp.next = (wp + 1) % depth
        if issue:
            rp.next = (rp + 1) % depth
        v1.next = issue
        v2.next = v1
        if push and not issue:
            n.next = n + 1
        elif issue and not push:
            n.next = n - 1

    # ---- the frames into the buffers -------------------------------------------------------------------
    side = BufferSide()
    insts.append(double_buffer(clk, rst, side))
    claimed, discard, cur, turn, w_req, sel_w, w_move = (Signal(bool(0)) for _ in range(7))
    addr = Signal(intbv(0)[abits:])

    @always_comb
    def present():
        w_req.next = hv and claimed and not h_abt and not discard
        # words that leave without a write: aborts, a dropped frame's words, words of a frame begun before reset
        drop = hv and (h_abt or discard or (not claimed and not h_sof))
        s = hv and claimed and not h_abt and not discard and (not bank.req_valid or turn)
        sel_w.next = s
        w_move.next = s and mem.req_ready
        pop.next = (s and mem.req_ready) or drop
        side.p_done.next = s and mem.req_ready and h_eof
        side.p_done_buf.next = cur
        side.p_abort.next = hv and h_abt and claimed
        side.p_abort_buf.next = cur
        side.c_take.next = want
        side.c_release.next = release

    @always_seq(clk.posedge, reset=rst)
    def frames_in():
        if side.p_grant:
            side.p_start.next = False
            claimed.next = True
            cur.next = side.p_gbuf
            if side.p_gbuf:
                addr.next = base1
            else:
                addr.next = base0
        elif side.p_deny:
            # cannot happen (a writer holding no buffer always finds one, docs/formal.md); drop the frame
            side.p_start.next = False
            discard.next = True
        else:
            side.p_start.next = hv and h_sof and not claimed and not h_abt and not discard
        if w_move:
            addr.next = addr + 1
            if h_eof:
                claimed.next = False
        if hv and h_abt:
            claimed.next = False
            discard.next = False
        elif discard and hv and h_eof:
            discard.next = False
        # who goes first when both wait: the other one than last time
        if w_move:
            turn.next = False
        elif bank.req_valid and mem.req_ready and not sel_w:
            turn.next = True

    @always_comb
    def port():
        mem.req_valid.next = w_req or bank.req_valid
        if sel_w:
            mem.req_we.next = True
            mem.req_addr.next = addr
            mem.req_wdata.next = h_data
            mem.req_be.next = 3
        else:
            mem.req_we.next = bank.req_we
            mem.req_addr.next = bank.req_addr
            mem.req_wdata.next = bank.req_wdata
            mem.req_be.next = bank.req_be
        bank.req_ready.next = mem.req_ready and not sel_w
        bank.rsp_valid.next = mem.rsp_valid
        bank.rsp_data.next = mem.rsp_data

    @always_comb
    def status():
        held.next = side.c_held
        avail.next = side.c_avail
        buf.next = side.c_buf
        frames.next = side.published
        lost.next = lost_r

    insts += [entry_in, framing, credit, refill, storage, pointers, present, frames_in, port, status]
    return insts
