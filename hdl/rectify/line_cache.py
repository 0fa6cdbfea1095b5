"""The line cache: the last L lines of both cameras in block RAM, answering the rectifier's pixel fetches."""

from __future__ import annotations

from myhdl import Signal, always, always_comb, always_seq, block, intbv

from eyestereo.hdl.common.checks import block_error, check_clock, check_distinct, check_int, check_reset, check_signal
from eyestereo.hdl.interfaces.fetch_port import check_fetch
from eyestereo.hdl.interfaces.queue import check_queue
from eyestereo.tools.camera import WORD as CAMERA_WORD
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH

__all__ = ["BANK", "FIRST_BEAT", "line_cache"]

#: Bytes of one block RAM of the ring (an ECP5 DP16KD or a Spartan-3E RAMB16 as 2048 x 9).
BANK = 2048
BANK_BITS = BANK.bit_length() - 1

#: Banks per first-stage select: the response picks a bank in two registered steps, one of GROUP banks, then
#: one of the groups and the camera (a 40:1 select from block RAMs spread over the chip missed 110 MHz at VGA).
GROUP = 4

#: Clocks from a request moving (``req_valid`` and ``req_ready`` at an edge) to its first beat on the
#: response, its rows being in: the request register, the beat expander, the block RAMs, each one's output register
#: (a block RAM's clock-to-output takes most of a clock: issue 26), the group select, the response register (the
#: group's and camera's select).
FIRST_BEAT = 7


@block
def line_cache(clk, rst, cam0, cam1, fetch, start, run, arm, begun, overrun, *, width: int = FRAME_WIDTH,
               height: int = FRAME_HEIGHT, lines: int = 32):
    """The camera frames as the cameras write them, ``lines`` lines deep, behind a fetch port (slave).

    Each camera's words (its queue read port, :data:`eyestereo.tools.camera.WORD`: the Y byte is kept) go
    into a ring of ``lines`` lines of ``width`` bytes in block RAM, line ``y`` of a frame in slot
    ``y mod lines``; the cache never holds a camera back (``ready`` is always high). A fetch of the 2x2
    neighbourhood at row ``y`` waits until the camera has completed the neighbourhood's lower row (``y + 1``
    when the mask asks for it, else ``y``) and is then answered from the block RAM, one pixel per clock.
    A line the cameras have overwritten cannot be read: the rectifier must keep up (the line count comes
    from :func:`eyestereo.tools.models.line_cache.plan`, which models both paces); when it does not, the
    fetch is answered with whatever the slot holds and ``overrun`` pulses.

    Frames: ``start`` (the rectifier's) binds the rectifier to the frame each camera is writing (its rows are
    the ones counted); ``run`` is high while the rectifier works on that frame. A camera that begins its next
    frame, or ends its frame with a reset token, while ``run`` is high has *lapped* the rectifier: ``overrun``
    pulses and that camera's fetches are no longer held back (so nothing hangs), until ``run`` falls.
    ``begun`` is high when both cameras have begun a frame since the last ``start`` or ``arm`` and while
    ``run`` was low: the rectifier may start (a frame begun while it worked is not offered: its first lines
    may be overwritten before it could start).
    The first word after ``rst`` or after a frame's end (``eof``, or a reset token) is pixel (0, 0).

    Timing of two requests whose rows are in (``#`` high, ``_`` low, ``.`` don't care; a request moves at the
    rising edge that ends a cycle with ``req_valid`` and ``req_ready`` high; :data:`FIRST_BEAT` = 7)::

        cycle      0    1    2    3    4    5    6    7    8    9   10   11   12
        req_valid  #    _    #    #    _    _    _    _    _    _    _    _    _
        req_ready  #    _    #    _    #    #    #    #    #    #    #    #    #
        req_mask   1111 .    0101 .    .    .    .    .    .    .    .    .    .
        rsp_valid  _    _    _    _    _    _    _    #    #    #    #    #    #
        rsp_idx    .    .    .    .    .    .    .    0    1    2    3    0    2

    A request is taken every other clock at most (``req_ready`` is low in the clock after one moves); the
    beats of consecutive requests follow each other without a gap.

    Ports:
        clk, rst: the memory clock; synchronous active-high reset (the counters and flags, not the RAM).
        cam0, cam1: :class:`~eyestereo.hdl.interfaces.queue.QueuePort` of camera words (left, right),
            consumed; ``ready`` is driven high.
        fetch: :class:`~eyestereo.hdl.interfaces.fetch_port.FetchPort` (slave), sized ``width`` x ``height``.
        start: in, 1 bit: the rectifier starts a frame (binds it to the cameras' frames in progress).
        run: in, 1 bit: the rectifier is working on a frame (from the clock after ``start``).
        arm: in, 1 bit: forget the frames begun so far (``begun`` waits for frames that begin later).
        begun: out, 1 bit: both cameras have begun a frame not bound yet.
        overrun: out, 1 bit: one-clock pulse: a fetch read a line already overwritten, or a camera lapped the
            rectifier. The frame being rectified is not the cameras' (count it as dropped).

    Parameters:
        width, height: the camera frames (2..4096).
        lines: L, the lines kept per camera, a power of two 2..64 (default 32: the synthetic rig's and the OpenCV
            calibration's at CIF; :func:`eyestereo.tools.models.line_cache.plan`).

    Latency: a fetch of rows already in: :data:`FIRST_BEAT` = 7 clocks to its first pixel, then one pixel per
    clock. A fetch waiting for its rows: 7 clocks after the camera word that completes the lower row.

    Resources: per camera ``ceil(lines * width / 2048)`` block RAMs of 2048 bytes (one write and one read port
    each; 6 at 352 x 32 lines, 20 at 640 x 64), their output registers and the two-step bank select, a ROM
    of the ``lines`` slot addresses, two row counters, a request register and the beat expander (docs/memory.md).
    """
    check_clock(clk)
    check_reset(rst)
    check_queue("cam0", cam0, width=CAMERA_WORD.width)
    check_queue("cam1", cam1, width=CAMERA_WORD.width)
    check_fetch("fetch", fetch)
    check_signal("start", start, width=1)
    check_signal("run", run, width=1)
    check_signal("arm", arm, width=1)
    check_signal("begun", begun, width=1)
    check_signal("overrun", overrun, width=1)
    width = check_int("width", width, 2, 4096)
    height = check_int("height", height, 2, 4096)
    lines = check_int("lines", lines, 2, 64)
    if lines & (lines - 1):
        raise block_error(f"parameter lines={lines} must be a power of two (a row's slot is its low bits)")
    if lines > height:
        raise block_error(f"parameter lines={lines}: more lines than the frame's {height}")
    if (fetch.width, fetch.height) != (width, height):
        raise block_error(f"port fetch is sized for {fetch.width}x{fetch.height} images; the cameras' are "
                          f"{width}x{height}")
    check_distinct(dict(begun=begun, overrun=overrun),
                   dict(clk=clk, rst=rst, cam0=cam0, cam1=cam1, fetch=fetch, start=start, run=run,
                        arm=arm))

    depth = lines * width
    sb = max(1, (lines - 1).bit_length())  # slot bits
    slot_base = tuple(s * width for s in range(lines))  # the ROM: the first address of each slot

    insts = []
    nbanks = -(-depth // BANK)  # the ring in block RAMs of BANK bytes each, the address's low bits within one
    rows = [Signal(intbv(0, min=0, max=height + 1)) for _ in range(2)]  # complete rows of the frame written
    lapped = [Signal(bool(0)) for _ in range(2)]
    fresh = [Signal(bool(0)) for _ in range(2)]
    lap_event = [Signal(bool(0)) for _ in range(2)]
    raddr = Signal(intbv(0, min=0, max=depth))
    # each bank's word, registered straight after its block RAM: the bank select comes a clock later (issue 26:
    # a ring of several block RAMs read through their select into one register missed 110 MHz)
    # by groups of GROUP banks (each group's list is the memory its select reads; a signal lives in one list)
    ngroups = -(-nbanks // GROUP)
    sizes = [min(GROUP, nbanks - g * GROUP) for g in range(ngroups)]
    q0 = [[Signal(intbv(0)[8:]) for _ in range(n)] for n in sizes]
    q1 = [[Signal(intbv(0)[8:]) for _ in range(n)] for n in sizes]
    r_lo = Signal(intbv(0)[BANK_BITS:])
    r_hi, d_hi = (Signal(intbv(0, min=0, max=nbanks)) for _ in range(2))
    o_lo = Signal(intbv(0)[2:])  # the bank within its group (GROUP = 4)
    o_grp, p_grp = (Signal(intbv(0, min=0, max=max(2, ngroups))) for _ in range(2))
    p0 = [Signal(intbv(0)[8:]) for _ in range(ngroups)]  # each group's word, both cameras
    p1 = [Signal(intbv(0)[8:]) for _ in range(ngroups)]

    @block
    def bank(we, waddr, wdata, q, *, index):
        """One block RAM of the ring: BANK bytes, written where ``waddr`` falls in it, read at ``r_lo``."""
        # "_norw": never read at the address written in the same clock (a fetch reads complete lines, the camera
        # writes the next one), so the flow tells Yosys to leave out its collision logic (hdl/flow/netlist.py)
        mem_norw = [Signal(intbv(0)[8:]) for _ in range(BANK)]
        sel = Signal(bool(0))
        w_lo = Signal(intbv(0)[BANK_BITS:])
        d = Signal(intbv(0)[8:])

        @always_comb
        def select():
            sel.next = we and waddr // BANK == index
            w_lo.next = waddr % BANK

        @always(clk.posedge)
        def ram():
            # no reset: a memory with a reset is not a block RAM
            if sel:
                mem_norw[w_lo].next = wdata
            d.next = mem_norw[r_lo]

        @always(clk.posedge)
        def out():
            q.next = d

        return select, ram, out

    @block
    def writer(cam, qs, row, lap, frsh, lap_ev):
        waddr = Signal(intbv(0, min=0, max=depth))
        at_start = Signal(bool(1))
        we = Signal(bool(0))
        token = Signal(bool(0))

        @always_comb
        def decode():
            cam.ready.next = True
            token.next = cam.valid and cam.eof and not cam.eol
            we.next = cam.valid and not (cam.eof and not cam.eol)

        wdata = Signal(intbv(0)[8:])

        @always_comb
        def luma():
            wdata.next = cam.data[8:0]

        banks = [bank(we, waddr, wdata, qs[b], index=b) for b in range(nbanks)]

        @always_seq(clk.posedge, reset=rst)
        def count():
            lap_ev.next = False
            if token:
                # a frame broken off: the next word is pixel (0, 0) of a new one
                at_start.next = True
                waddr.next = 0
                if run and not start:
                    lap.next = True
                    lap_ev.next = True
            elif we:
                if at_start:
                    row.next = 0
                    if run and not start:
                        lap.next = True
                        lap_ev.next = True
                    else:
                        frsh.next = True
                at_start.next = cam.eof
                if cam.eol:
                    if at_start:
                        row.next = 1
                    else:
                        row.next = row + 1
                if cam.eof:
                    waddr.next = 0
                elif waddr == depth - 1:
                    waddr.next = 0
                else:
                    waddr.next = waddr + 1
            if start or arm:
                frsh.next = False
            if start:
                lap.next = False
            elif not run:
                lap.next = False

        return decode, luma, banks, count

    for c, port in enumerate((cam0, cam1)):
        # a tuple: the writer hands each bank its own word (not a memory of the writer's)
        flat = tuple(q for grp in (q0, q1)[c] for q in grp)
        insts.append(writer(port, flat, rows[c], lapped[c], fresh[c], lap_event[c]))

    @block
    def group_select(qa, qb, pa, pb):
        """One group's word of each camera, registered: the first step of the bank select."""
        n = len(qa)
        if n == 1:
            @always(clk.posedge)
            def select():
                pa.next = qa[0]
                pb.next = qb[0]
        elif n == GROUP:
            @always(clk.posedge)
            def select():
                pa.next = qa[o_lo]
                pb.next = qb[o_lo]
        else:  # the last group, short: o_lo never points past it when it is the one selected
            @always(clk.posedge)
            def select():
                if o_lo < n:
                    pa.next = qa[o_lo]
                    pb.next = qb[o_lo]

        return select

    insts += [group_select(q0[g], q1[g], p0[g], p1[g]) for g in range(ngroups)]

    # ---- requests: one register, then the beat expander -------------------------------------------------
    q_valid = Signal(bool(0))
    q_cam = Signal(bool(0))
    q_mask = Signal(intbv(0)[4:])
    q_x0 = Signal(intbv(0, min=0, max=width))
    q_x1 = Signal(intbv(0, min=0, max=width + 1))
    q_slot0, q_slot1 = Signal(intbv(0)[sb:]), Signal(intbv(0)[sb:])
    q_need = Signal(intbv(0, min=0, max=height + 1))  # the lower row the request reads
    q_low = Signal(intbv(0, min=0, max=height + lines + 1))  # its upper row + L: gone once rows reach it - 1
    e_mask = Signal(intbv(0)[4:])
    e_cam = Signal(bool(0))
    e_base0, e_base1 = Signal(intbv(0, min=0, max=depth)), Signal(intbv(0, min=0, max=depth))
    e_x0 = Signal(intbv(0, min=0, max=width))
    e_x1 = Signal(intbv(0, min=0, max=width + 1))
    go = Signal(bool(0))
    r_valid, r_cam = Signal(bool(0)), Signal(bool(0))
    r_idx = Signal(intbv(0)[2:])
    d_valid, d_cam = Signal(bool(0)), Signal(bool(0))
    d_idx = Signal(intbv(0)[2:])
    o_valid, o_cam = Signal(bool(0)), Signal(bool(0))
    o_idx = Signal(intbv(0)[2:])
    p_valid, p_cam = Signal(bool(0)), Signal(bool(0))
    p_idx = Signal(intbv(0)[2:])
    e_last = Signal(bool(0))
    pick = Signal(intbv(0)[2:])
    q_rows = Signal(intbv(0, min=0, max=height + 1))
    q_lapped = Signal(bool(0))
    late = Signal(bool(0))

    @always_comb
    def request_ready():
        fetch.req_ready.next = not q_valid

    @always_comb
    def expander_state():
        # the lowest index still to read, and whether it is the request's last
        m = e_mask
        if m[0]:
            pick.next = 0
        elif m[1]:
            pick.next = 1
        elif m[2]:
            pick.next = 2
        else:
            pick.next = 3
        e_last.next = m == 0 or m == 1 or m == 2 or m == 4 or m == 8

    @always_comb
    def camera_state():
        if q_cam:
            q_rows.next = rows[1]
            q_lapped.next = lapped[1]
        else:
            q_rows.next = rows[0]
            q_lapped.next = lapped[0]

    @always_comb
    def gate():
        go.next = q_valid and e_last and (q_lapped or q_rows > q_need)
        # the upper row's slot holds a newer line once the camera is writing row y + L (one line of margin
        # for the few clocks to the read)
        late.next = q_valid and not q_lapped and q_low <= q_rows + 1

    @always_seq(clk.posedge, reset=rst)
    def requests():
        if fetch.req_valid and not q_valid:
            q_valid.next = True
            q_cam.next = fetch.req_cam
            q_mask.next = fetch.req_mask
            q_x0.next = fetch.req_x
            q_x1.next = fetch.req_x + 1
            q_slot0.next = fetch.req_y % lines
            q_slot1.next = (fetch.req_y + 1) % lines
            if fetch.req_mask[0] or fetch.req_mask[1]:
                q_need.next = fetch.req_y + 1
            else:
                q_need.next = fetch.req_y
            q_low.next = fetch.req_y + lines
        elif go:
            q_valid.next = False
        if go:
            e_mask.next = q_mask
        elif pick == 0:
            e_mask.next = e_mask & 0b1110
        elif pick == 1:
            e_mask.next = e_mask & 0b1100
        elif pick == 2:
            e_mask.next = e_mask & 0b1000
        else:
            e_mask.next = 0
        r_valid.next = e_mask != 0
        d_valid.next = r_valid
        o_valid.next = d_valid
        p_valid.next = o_valid
        overrun.next = (go and late) or lap_event[0] or lap_event[1]

    @always(clk.posedge)
    def expander():
        if go:
            e_cam.next = q_cam
            e_base0.next = slot_base[int(q_slot0)]
            e_base1.next = slot_base[int(q_slot1)]
            e_x0.next = q_x0
            e_x1.next = q_x1
        # index i: (x + 1, y + 1), (x, y + 1), (x + 1, y), (x, y)
        if pick[1]:
            if pick[0]:
                raddr.next = e_base0 + e_x0
            else:
                raddr.next = e_base0 + e_x1
        else:
            if pick[0]:
                raddr.next = e_base1 + e_x0
            else:
                raddr.next = e_base1 + e_x1
        r_idx.next = pick
        r_cam.next = e_cam

    @always_seq(clk.posedge, reset=rst)
    def response_valid():
        fetch.rsp_valid.next = p_valid
        begun.next = fresh[0] and fresh[1] and not start and not arm

    @always(clk.posedge)
    def response():
        d_idx.next = r_idx
        d_cam.next = r_cam
        o_idx.next = d_idx
        o_cam.next = d_cam
        d_hi.next = r_hi
        o_lo.next = d_hi % GROUP
        o_grp.next = d_hi // GROUP
        p_idx.next = o_idx
        p_cam.next = o_cam
        p_grp.next = o_grp
        fetch.rsp_idx.next = p_idx
        if p_cam:
            fetch.rsp_data.next = p1[p_grp]
        else:
            fetch.rsp_data.next = p0[p_grp]

    @always_comb
    def read_address():
        r_lo.next = raddr % BANK
        r_hi.next = raddr // BANK

    insts += [request_ready, expander_state, camera_state, gate, requests, expander, response_valid,
              response, read_address]
    return insts
