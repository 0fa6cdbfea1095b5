"""The SRAM arbiter's masters: each port's engine that turns its traffic into word accesses.

Helpers of :func:`eyestereo.hdl.memory.sram_arbiter.sram_arbiter` (not catalogue blocks). Every engine presents
its next access on a :class:`Head` and learns by ``grant`` that the arbiter issued it at this edge:

* :func:`camera_in` + :func:`writer_issue` -- a camera's queue read port into its double buffer;
* :func:`rect_in` + :func:`writer_issue` -- the stereo image stream, left and right pixel of each (x, y)
  packed into one word, into the rectified double buffer;
* :func:`feature_in` + :func:`writer_issue` -- feature-list words into the feature double buffer;
* :func:`fetch_slave` -- the pixel fetch port: up to four reads per request;
* :func:`host_slave` -- the host port: single reads and writes.

Writers buffer their words in a small LUT-RAM FIFO and ask for the bus in bursts (``start``: a burst's
worth is waiting, or a frame's last word), so that writes come grouped and the bus turns round once per
burst, not once per word. Which engine serves which port, and the engine's urgency, burst and read tag,
come from the one description of the masters, :data:`eyestereo.tools.models.sram_arbiter.MASTER_TABLE`:
the arbiter builds each master's :class:`Head` and engine from its entry.
"""

from __future__ import annotations

from myhdl import ConcatSignal, Signal, always, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.common.arith import shift_add
from eyestereo.hdl.common.packed import pack_word, unpack_word
from eyestereo.tools.models.sram_arbiter import FETCH_OFFSETS, Master
from eyestereo.tools.packed import PackedWord
from eyestereo.tools.sram import ADDR_BITS, DATA_BITS

#: FIFO entry of the writers: the word, its frame's first / last word, the list's overflow flag, an abort
#: (a reset token: the frame is abandoned).
ENTRY = PackedWord("writer FIFO entry", [("data", DATA_BITS), ("sof", 1), ("eof", 1), ("ovf", 1), ("abt", 1)])
ENTRY_BITS = ENTRY.width
#: Tag of a read on the controller's word port: the master's ``read_tag`` above the fetch index.
TAG_BITS = 3
#: One access as a master presents it and the arbiter passes it to the controller.
ACCESS = PackedWord("access", [("addr", ADDR_BITS), ("wdata", DATA_BITS), ("we", 1), ("be", 2), ("tag", TAG_BITS)])


class Head:
    """One master's next access, as the arbiter sees it.

    ``req``: an access is ready (a register in every engine, so that the arbiter's grant starts at
    flip-flops); ``start``: the master may start a turn (a writer: a burst is waiting);
    ``urgent``: it must be served before the round robin (the writers of streams that cannot wait);
    ``we, addr, wdata, be``: the access; ``tag``: the read's tag (``read_tag`` above the fetch index);
    ``grant`` (from the arbiter): the access is issued at this edge; ``access``: the access packed as
    :data:`ACCESS`. The fields an engine does not drive keep the constant the master's description gives
    them (a writer only writes whole words, the fetch port only reads, only writers are urgent).
    """

    def __init__(self, master: Master):
        self.req = Signal(bool(0))
        self.start = Signal(bool(0))
        self.urgent = Signal(bool(0))
        self.we = Signal(bool(master.writer))
        self.addr = Signal(intbv(0)[ADDR_BITS:])
        self.wdata = Signal(intbv(0)[DATA_BITS:])
        self.be = Signal(intbv(3)[2:])
        self.tag = Signal(intbv(master.read_tag << 2)[TAG_BITS:])
        self.grant = Signal(bool(0))
        self.access = self.packed()

    def packed(self):
        """The access packed as :data:`ACCESS` (a shadow signal of the fields)."""
        return ConcatSignal(*(getattr(self, f.name) for f in reversed(ACCESS.fields)))


class EntrySignals:
    """A writer's FIFO entry as its input engine builds it: the engine drives the flags it has (``sof``;
    ``ovf`` the feature lists, ``abt`` the streams with reset tokens; the others stay constant 0) and
    ``pack_word(entry.word, ENTRY, data=..., eof=..., **entry.flags())`` packs them with its port's word
    and ``eof`` into ``word`` (:data:`ENTRY`)."""

    def __init__(self):
        self.sof, self.ovf, self.abt = (Signal(bool(0)) for _ in range(3))
        self.word = Signal(intbv(0)[ENTRY_BITS:])

    def flags(self) -> dict:
        return dict(sof=self.sof, ovf=self.ovf, abt=self.abt)


# ------------------------------------------------------------------------------------------------------
@block
def writer_issue(clk, rst, din, push, push_eof, count, pop, head, side, lcount0, lcount1, lovf,
                 *, base0: int, base1: int, depth: int, burst: int, urgent: bool):
    """The SRAM side of a writer: its FIFO (``depth`` entries of LUT-RAM, the head in a register) and the
    FIFO's words to consecutive addresses of a buffer, frame by frame.

    A frame's first word (``sof``) takes a buffer from the double buffer when it reaches the head of the
    FIFO, i.e. after the previous frame's last word was issued and published, so back-to-back frames
    find their buffer (this costs one clock per frame). If none is free the frame is dropped: its words
    leave the FIFO without an access. Then the words go to the buffer's base address and on; issuing
    the word flagged ``eof`` publishes the buffer (``side.p_done``) and records the frame's word count
    (``lcount0``/``lcount1``) and overflow flag (``lovf``). An abort entry (a reset token) abandons the
    frame (``side.p_abort``).

    ``head.req`` is a register: its next value is worked out for both answers of the arbiter (granted
    or not, from registers and the LUT-RAM word behind the head) and the grant only chooses between the
    two, so that the grant reaches every register here through one or two LUTs. A word pushed into an
    empty FIFO is at the head (and asks) two clocks later; ``count`` (a register) counts every entry held.
    """
    aw = depth.bit_length() - 1
    mem = [Signal(intbv(0)[ENTRY_BITS:]) for _ in range(depth)]
    wp, rp = Signal(intbv(0)[aw:]), Signal(intbv(0)[aw:])
    stored = Signal(intbv(0, min=0, max=depth + 1))  # entries in the LUT-RAM (behind the head)
    entry = Signal(intbv(0)[ENTRY_BITS:])            # the head entry
    behind = Signal(intbv(0)[ENTRY_BITS:])           # the LUT-RAM's oldest entry (next at the head)
    waddr = head.addr
    eofs = Signal(intbv(0, min=0, max=depth + 1))  # entries with eof in the FIFO (frame ends, aborts)
    nwords = Signal(intbv(0)[len(lcount0):])       # words of the current frame issued so far
    (sof, eof, ovf, abt, b_sof, b_abt, has, claim, claimed, cur, discard, popped_eof, load, claimed_n, discard_n,
     req_g, req_n) = (Signal(bool(0)) for _ in range(17))
    cmax = (1 << len(lcount0)) - 1
    fields = unpack_word(entry, ENTRY, data=head.wdata, sof=sof, eof=eof, ovf=ovf, abt=abt)
    ahead = unpack_word(behind, ENTRY, sof=b_sof, abt=b_abt)

    @always_comb
    def read():
        behind.next = mem[rp]

    @always(clk.posedge)
    def store():
        # the LUT-RAM and the head register (no reset: the valid flag says what they hold)
        if load:
            entry.next = behind
        if push:
            mem[wp].next = din

    @always_comb
    def present():
        h = has
        claim.next = h and sof and not claimed and not abt and not discard
        # entries that leave the FIFO without an access: aborts, a dropped frame's words
        drop = h and (abt or discard or side.p_deny)
        p = head.grant or drop
        pop.next = p
        load.next = stored != 0 and (not h or p)
        side.p_done.next = head.grant and eof
        side.p_done_buf.next = cur
        side.p_abort.next = h and abt and claimed
        side.p_abort_buf.next = cur

    @always_comb
    def frame_state():
        # the buffer claim and the dropping of a frame after this edge, the grant's effect aside
        claimed_n.next = (claimed or side.p_grant) and not (has and abt)
        if discard and has and (eof or abt):
            discard_n.next = False
        elif side.p_deny and not side.p_grant:
            discard_n.next = not eof
        else:
            discard_n.next = discard

    @always_comb
    def lookahead():
        # head.req after this edge, granted (the head leaves; a frame's last word gives up the buffer) or not
        drop = has and (abt or discard or side.p_deny)
        req_g.next = stored != 0 and not b_abt and not discard_n and ((claimed_n and not eof) or not b_sof)
        if stored != 0 and (not has or drop):
            req_n.next = not b_abt and not discard_n and (claimed_n or not b_sof)
        else:
            req_n.next = has and not drop and not abt and not discard_n and (claimed_n or not sof)

    @always_seq(clk.posedge, reset=rst)
    def fifo():
        # the grant only selects between the two precomputed answers
        if head.grant:
            head.req.next = req_g
        else:
            head.req.next = req_n
        if load:
            has.next = True
            rp.next = (rp + 1) % depth
            if not push:
                stored.next = stored - 1
        else:
            if pop:
                has.next = False
            if push:
                stored.next = stored + 1
        if push:
            wp.next = (wp + 1) % depth
            if not pop:
                count.next = count + 1
        elif pop:
            count.next = count - 1

    @always_seq(clk.posedge, reset=rst)
    def track():
        # start/urgent registered (a clock late: only the arbiter's next-turn choice reads them)
        wants = count >= burst or eofs != 0
        head.start.next = wants
        head.urgent.next = wants and urgent
        # a frame's first word at the head asks the double buffer for a buffer (answered a clock later)
        if side.p_grant:
            side.p_start.next = False
            cur.next = side.p_gbuf
            if side.p_gbuf:
                waddr.next = base1
            else:
                waddr.next = base0
        elif side.p_deny:
            side.p_start.next = False
        else:
            side.p_start.next = claim
        claimed.next = claimed_n
        discard.next = discard_n
        if head.grant:
            waddr.next = waddr + 1
            if sof:
                nwords.next = 1
            elif nwords != cmax:
                nwords.next = nwords + 1
            if eof:
                claimed.next = False
                if cur:
                    if sof:
                        lcount1.next = 1
                    elif nwords != cmax:
                        lcount1.next = nwords + 1
                    lovf.next[1] = ovf
                else:
                    if sof:
                        lcount0.next = 1
                    elif nwords != cmax:
                        lcount0.next = nwords + 1
                    lovf.next[0] = ovf
        # (the count of eof entries follows the pops a clock late: it only feeds the start flag)
        popped_eof.next = pop and eof
        if push_eof and not popped_eof:
            eofs.next = eofs + 1
        elif popped_eof and not push_eof:
            eofs.next = eofs - 1

    return fields, ahead, read, store, present, frame_state, lookahead, fifo, track


# ------------------------------------------------------------------------------------------------------
@block
def camera_in(clk, rst, q, push, entry, count, run, arm, *, depth: int):
    """A camera's queue read port into the writer FIFO (``entry``: :class:`EntrySignals`).

    A frame is captured when it starts while ``run`` is high or the camera is armed (an ``arm`` pulse,
    used up by the next frame captured *whole*); otherwise its words are taken and discarded. A reset token
    (``eof`` without ``eol``) in a captured frame becomes an abort entry, and an arm that frame used up is
    given back: the next frame is captured instead (the fault soak found the sequential mode waiting for ever
    after one broken camera frame). ``ready`` comes from the FIFO count register only.
    """
    take, want, in_frame, cap, armed, by_arm = (Signal(bool(0)) for _ in range(6))
    token, first = entry.abt, entry.sof
    wires = pack_word(entry.word, ENTRY, data=q.data, eof=q.eof, **entry.flags())

    @always_comb
    def decide():
        q.ready.next = count != depth
        t = q.valid and count != depth
        tok = t and q.eof and not q.eol
        take.next = t
        token.next = tok
        first.next = t and not in_frame and not tok
        want.next = run or armed
        if in_frame:
            push.next = t and cap
        else:
            push.next = t and not tok and (run or armed)

    @always_seq(clk.posedge, reset=rst)
    def frames():
        if arm:
            armed.next = True
        if token:
            in_frame.next = False
            if in_frame and cap and by_arm:
                armed.next = True  # the broken frame gives its arm back
        elif take:
            if first:
                cap.next = want
                by_arm.next = armed
                if want and not arm:
                    armed.next = False
                in_frame.next = not q.eof
            elif q.eof:
                in_frame.next = False

    return wires, decide, frames


# ------------------------------------------------------------------------------------------------------
@block
def rect_in(clk, rst, s, push, entry, count, overflows, *, depth: int):
    """The stereo image stream (8-bit, ``cam``) into the writer FIFO: one word per (x, y), left pixel in
    bits 7..0, right pixel in 15..8, pushed with the right pixel's beat; every frame is captured. The
    stream cannot wait: a word that finds the FIFO full is lost and counted in ``overflows`` (the
    arbiter's priorities keep it at 0). A reset token inside a frame becomes an abort entry.
    """
    left = Signal(intbv(0)[8:])
    pair, in_frame, want = (Signal(bool(0)) for _ in range(3))
    token, rfirst = entry.abt, entry.sof
    pixels = Signal(intbv(0)[DATA_BITS:])  # the word: right pixel (this beat) over the left one
    wires = pack_word(entry.word, ENTRY, data=pixels, eof=s.eof, **entry.flags())

    @always_comb
    def decide():
        tok = s.valid and s.eof and not s.eol
        pr = s.valid and s.cam and not tok
        token.next = tok
        pair.next = pr
        w = pr or (tok and in_frame)
        want.next = w
        push.next = w and count != depth
        rfirst.next = pr and not in_frame
        pixels.next = concat(s.data, left)

    @always_seq(clk.posedge, reset=rst)
    def frames():
        if s.valid and not s.cam and not (s.eof and not s.eol):
            left.next = s.data
        if want and count == depth:
            overflows.next = overflows + 1
        if token:
            in_frame.next = False
        elif pair:
            in_frame.next = not s.eof

    return wires, decide, frames


# ------------------------------------------------------------------------------------------------------
@block
def feature_in(clk, rst, q, push, entry, count, *, depth: int, capacity: int):
    """Feature-list words (queue read port) into the writer FIFO, one list per buffer, ``eof`` on a
    list's last word. A list longer than the buffer's ``capacity`` keeps its first ``capacity - 1``
    words and its last one, and is flagged as overflowed.
    """
    n = Signal(intbv(0, min=0, max=capacity + 1))  # words of the list taken (saturating)
    # room: the next word (if not the last) still has a slot, n < capacity - 1
    take, in_list, room = (Signal(bool(0)) for _ in range(3))
    ovf, ffirst = entry.ovf, entry.sof
    wires = pack_word(entry.word, ENTRY, data=q.data, eof=q.eof, **entry.flags())

    @always_comb
    def decide():
        q.ready.next = count != depth
        t = q.valid and count != depth
        take.next = t
        if in_list:
            push.next = t and (room or q.eof)
        else:
            push.next = t
        ffirst.next = t and not in_list

    @always_seq(clk.posedge, reset=rst)
    def lists():
        # room kept in a register, so that no comparator sits in the push path
        if take:
            if not in_list:
                in_list.next = not q.eof
                n.next = 1
                room.next = capacity > 2
                ovf.next = False
            else:
                if n != capacity:
                    n.next = n + 1
                room.next = n < capacity - 2
                if not room and not q.eof:
                    ovf.next = True
                if q.eof:
                    in_list.next = False

    return wires, decide, lists


# ------------------------------------------------------------------------------------------------------
@block
def fetch_slave(clk, rst, fp, head, cbuf0, cbuf1, *, width: int, height: int, bases: tuple):
    """The pixel fetch port's slave side: up to four reads per request, lowest index first.

    Four register stages, each with one adder at most between registers: A takes the request
    (``req_ready`` = A empty) with y * width (shifts and adds); B adds x; P adds the buffer's base and
    the four neighbours' offsets (four addresses); C issues the wanted ones, one per grant.
    ``bases[c][b]`` is the base address of camera c's buffer b; ``cbuf0``/``cbuf1`` say which buffer of
    each camera is held for reading.
    """
    yw_max = (height - 1) * width
    yx_max = yw_max + width - 1
    yw = Signal(intbv(0, min=0, max=yw_max + 1))
    a_v, b_v, p_v, c_v = (Signal(bool(0)) for _ in range(4))
    a_yw = Signal(intbv(0, min=0, max=yw_max + 1))
    a_x = Signal(intbv(0, min=0, max=width))
    a_cam, b_cam = Signal(bool(0)), Signal(bool(0))
    a_mask, b_mask, p_mask, c_mask = (Signal(intbv(0)[4:]) for _ in range(4))
    b_yx = Signal(intbv(0, min=0, max=yx_max + 1))
    base = Signal(intbv(0)[ADDR_BITS:])
    c0, c1, c2, c3 = cs = [Signal(intbv(0)[ADDR_BITS:]) for _ in FETCH_OFFSETS]
    c_idx = Signal(intbv(0)[2:])
    c_last = Signal(bool(0))
    c_rest, p_rest, r_rest = (Signal(intbv(0)[4:]) for _ in range(3))
    move_a, move_b, move_p, move_c = (Signal(bool(0)) for _ in range(4))
    (l0b0, l0b1), (l1b0, l1b1) = bases

    insts = [shift_add([(fp.req_y, width)], yw)]
    # stages P and C of each neighbour's address (fetch index i: FETCH_OFFSETS[i])
    insts += [neighbour_address(clk, move_b, move_p, base, b_yx, c, offset=dy * width + dx)
              for c, (dx, dy) in zip(cs, FETCH_OFFSETS)]
    del cs  # (the list stays out of the converted design: the addresses are plain signals)

    @always_comb
    def base_select():
        if b_cam:
            if cbuf1:
                base.next = l1b1
            else:
                base.next = l1b0
        else:
            if cbuf0:
                base.next = l0b1
            else:
                base.next = l0b0

    @always_comb
    def current():
        if c_mask[0]:
            c_idx.next = 0
            head.addr.next = c0
        elif c_mask[1]:
            c_idx.next = 1
            head.addr.next = c1
        elif c_mask[2]:
            c_idx.next = 2
            head.addr.next = c2
        else:
            c_idx.next = 3
            head.addr.next = c3

    @always_comb
    def present():
        head.req.next = c_v
        head.start.next = c_v
        head.tag.next = c_idx
        fp.req_ready.next = not a_v
        # a stage moves on when the next one is empty or moves on itself (each written out flat, so that
        # the grant meets the stages' flags in one LUT, not through the chain of moves)
        move_c.next = head.grant and c_last
        move_p.next = p_v and (not c_v or (head.grant and c_last))
        move_b.next = b_v and (not p_v or not c_v or (head.grant and c_last))
        move_a.next = a_v and (not b_v or not p_v or not c_v or (head.grant and c_last))

    @always_seq(clk.posedge, reset=rst)
    def stages():
        if fp.req_valid and not a_v:
            a_v.next = True
        elif move_a:
            a_v.next = False
        if move_a:
            b_v.next = True
        elif move_b:
            b_v.next = False
        if move_b:
            p_v.next = True
        elif move_p:
            p_v.next = False
        if move_p:
            c_v.next = True
        elif move_c:
            c_v.next = False

    @always(clk.posedge)
    def data():
        if fp.req_valid and not a_v:
            a_yw.next = yw
            a_x.next = fp.req_x
            a_cam.next = fp.req_cam
            a_mask.next = fp.req_mask
        if move_a:
            b_yx.next = a_yw + a_x
            b_cam.next = a_cam
            b_mask.next = a_mask
        if move_b:
            p_mask.next = b_mask
        # the mask after this grant (c_rest) and whether this grant is the request's last (c_last) are kept
        # in registers, worked out from the mask loaded or the rest before, so that the grant meets only
        # a multiplexer on its way into them (the memory clock's goal, issue 23)
        if move_p:
            c_mask.next = p_mask
            c_rest.next = p_rest
            c_last.next = p_mask != 0 and p_rest == 0
        elif head.grant:
            c_mask.next = c_rest
            c_rest.next = r_rest
            c_last.next = c_rest != 0 and r_rest == 0

    insts += [base_select, current, present, stages, data, lowest_cleared(p_mask, p_rest),
              lowest_cleared(c_rest, r_rest)]
    return insts


@block
def lowest_cleared(mask, rest):
    """``rest`` = the 4-bit ``mask`` without its lowest set bit (the fetch index granted first)."""

    @always_comb
    def comb():
        if mask[0]:
            rest.next = mask & 0b1110
        elif mask[1]:
            rest.next = mask & 0b1100
        elif mask[2]:
            rest.next = mask & 0b1000
        else:
            rest.next = 0

    return comb


@block
def neighbour_address(clk, move_b, move_p, base, b_yx, c, *, offset: int):
    """One neighbour's address in the fetch pipeline: ``base + y * width + x + offset`` into stage P, then
    stage C (``c``)."""
    p = Signal(intbv(0)[len(c):])

    @always(clk.posedge)
    def stages():
        if move_b:
            p.next = base + b_yx + offset
        if move_p:
            c.next = p

    return stages


# ------------------------------------------------------------------------------------------------------
@block
def host_slave(clk, rst, hp, head):
    """The host port: one request register, taken when empty (``req_ready``), issued when granted."""
    hv = Signal(bool(0))
    hwe = Signal(bool(0))
    haddr = Signal(intbv(0)[ADDR_BITS:])
    hdata = Signal(intbv(0)[DATA_BITS:])
    hbe = Signal(intbv(0)[2:])

    @always_comb
    def present():
        hp.req_ready.next = not hv
        head.req.next = hv
        head.start.next = hv
        head.we.next = hwe
        head.addr.next = haddr
        head.wdata.next = hdata
        head.be.next = hbe

    @always_seq(clk.posedge, reset=rst)
    def valid():
        if hp.req_valid and not hv:
            hv.next = True
        elif head.grant:
            hv.next = False

    @always(clk.posedge)
    def regs():
        if hp.req_valid and not hv:
            hwe.next = hp.req_we
            haddr.next = hp.req_addr
            hdata.next = hp.req_wdata
            hbe.next = hp.req_be

    return present, valid, regs


@block
def frame_writer(clk, rst, entry, push, count, head, side, lcount0, lcount1, lovf, *, base0: int, base1: int,
                 depth: int, burst: int, urgent: bool):
    """A writer's FIFO and SRAM side (:func:`writer_issue`); the input side (:func:`camera_in`,
    :func:`rect_in`, :func:`feature_in`) pushes ``entry`` (:class:`EntrySignals`)."""
    if depth < 2 or depth & (depth - 1):
        raise ValueError(f"frame_writer depth must be a power of two >= 2, got {depth}")
    pop, push_eof = Signal(bool(0)), Signal(bool(0))
    eof_bit = ENTRY.bits("eof")[1]

    @always_comb
    def frame_end():
        push_eof.next = push and entry.word[eof_bit]

    issue = writer_issue(clk, rst, entry.word, push, push_eof, count, pop, head, side, lcount0, lcount1, lovf,
                         base0=base0, base1=base1, depth=depth, burst=burst, urgent=urgent)
    return frame_end, issue
