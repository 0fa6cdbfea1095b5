"""Fetch and interpolation: coordinate pairs in, the rectified stereo stream out (thesis 4.3, Figs. 4.9-4.11)."""

from __future__ import annotations

from myhdl import Signal, always, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.common.checks import (block_error, check_clock, check_distinct, check_int, check_reset,
                                         check_signal, check_stream)
from eyestereo.hdl.common.fifo import show_ahead_fifo
from eyestereo.hdl.common.packed import FieldSignals, pack_word, unpack_word
from eyestereo.hdl.interfaces.coord_pair import CoordPair
from eyestereo.hdl.interfaces.fetch_port import check_fetch
from eyestereo.tools.models import fetch_interpolate as model

__all__ = ["DEFAULT_DEPTH", "FIRST_PIXEL", "fetch_interpolate"]

#: Clocks from the clock a pair is taken to its left pixel on ``source``, both sides in range and the
#: memory answering at once (the timing diagram of :func:`fetch_interpolate`).
FIRST_PIXEL = 11
#: Default number of sides (requests or black pixels) in flight between the request and the output.
DEFAULT_DEPTH = 4
#: The 1-bit fields of the side word (:func:`eyestereo.tools.models.fetch_interpolate.side_word`), bool signals here.
_FLAGS = ("eof", "eol", "cam", "oor")


def _tables():
    """The reuse rule as two 16-entry ROMs indexed by ``4 * (ddy + 1) + (ddx + 1)``: the mask of the pixels
    to fetch and, per index, the kept pixel's index (2 bits each, index 0 in the low bits)."""
    masks, srcs = [], []
    for code in range(16):
        cx, cy = code & 3, code >> 2
        if cx > 2 or cy > 2:
            masks.append(15)
            srcs.append(0)
            continue
        mask, src = model.REUSE[(cx - 1, cy - 1)]
        masks.append(mask)
        srcs.append(sum((max(s, 0) & 3) << (2 * i) for i, s in enumerate(src)))
    return tuple(masks), tuple(srcs)


@block
def fetch_interpolate(clk, rst, coord, fetch, source, busy, *, depth: int = DEFAULT_DEPTH):
    """Take coordinate pairs, fetch their 2x2 neighbourhoods, interpolate: one stereo pixel pair per pair.

    Two parts with a queue of *side descriptors* between them (one per side of a pair: camera, out of
    range, request mask, where each kept pixel comes from, the fractions, eol/eof; the packed word
    :func:`eyestereo.tools.models.fetch_interpolate.side_word`, in a
    :func:`~eyestereo.hdl.common.fifo.show_ahead_fifo`):

    * the **requester** takes a pair (``coord.read_ack`` high while it is idle), then for the left side and
      then the right: if the side is out of range, queues a black pixel without any request; else compares
      the integer position (x0, y0) with that camera's previous neighbourhood (its tag), asks the fetch
      port for the pixels not kept (mask from the reuse rule of
      :mod:`eyestereo.tools.models.fetch_interpolate`; no request for mask 0) and queues the side when the
      request moves. At most ``depth`` sides are queued or being interpolated, so the responses of all
      outstanding requests (at most 4 x ``depth`` pixels) fit the response FIFO: the port's rule "the
      master takes every beat" holds. The tags are emptied by ``rst`` and after a pair with ``eof``.
    * the **interpolator** takes the queued sides in order and runs four multiply-accumulate steps per
      side, index 0..3 (the fetch port's order, (x0+1, y0+1) first): the weight ``w_i`` from the first
      multiplier (``dx*dy``, ``(S-dx)*dy``, ``dx*(S-dy)``, ``(S-dx)*(S-dy)``, S = 2**frac), the pixel from
      the response FIFO (a fetched index) or from that camera's kept neighbourhood (a reused one);
      ``acc += w_i * p_i`` in the second. A step waits while its pixel has not arrived. A black side takes
      one step. The result ``(acc + S*S/2) >> 2*frac`` (round half up; exact bilinear interpolation
      otherwise) goes out four clocks after the last step (five registered stages, one multiplier or adder
      each: the weight, the product, the sum, the output); the four pixels become that camera's kept
      neighbourhood.

    Timing, one pair with both sides in range, the memory answering at once (``F`` a fetch beat, ``s``
    an interpolation step)::

        cycle       0    1    2    3    4    5    6    7    8    9   10   11   12   13   14   15
        coord.valid #    .    .    .    .    .    .    .    .    .    .    .    .    .    .    .
        read_ack    #    _    _    .    .    .    .    .    .    .    .    .    .    .    .    .
        req_valid   _    #L   #R   _    _    _    _    _    _    _    _    _    _    _    _    _
        rsp_valid   _    _    F    F    F    F    _    _    _    _    _    _    _    _    _    _
        steps (L)   _    _    _    _    s0   s1   s2   s3   _    _    _    _    _    _    _    _
        steps (R)   _    _    _    _    _    _    _    _    s0   s1   s2   s3   _    _    _    _
        source      _    _    _    _    _    _    _    _    _    _    _    L    _    _    _    R

    (with 2 pixels fetched per side; the steps of the next pairs follow without gaps while pairs come):
    8 clocks per stereo output pixel when both sides are in range, fewer for black sides.

    Ports:
        clk, rst: clock; synchronous active-high reset (empties the queue, the FIFO and the tags; a frame
            in progress is abandoned: reset the memory side too, or let it finish its responses first).
        coord: :class:`~eyestereo.hdl.interfaces.coord_pair.CoordPair` (in: valid, coordinates, flags; out:
            ``read_ack``) from the coordinate warper; its ``frac`` (0..8) is the interpolation's.
        fetch: :class:`~eyestereo.hdl.interfaces.fetch_port.FetchPort` (master side) sized for the camera images
            (the CoordPair's source size).
        source: 8-bit stereo :class:`~eyestereo.hdl.interfaces.stream.ImageStream`: left pixel (x, y) with ``cam``
            0, then right pixel (x, y) with ``cam`` 1, ``eol``/``eof`` of the pair on both beats.
        busy: out, 1 bit: a pair is being requested or a side is queued or being interpolated (low again
            in the clock the last beat is on ``source``).

    Parameters:
        depth: sides in flight, 1..16 (default 4): enough to hide the memory's latency (the SRAM arbiter
            answers a request 11 clocks later: 4 sides of 4 clocks hide it); the response FIFO has
            4 x ``depth`` entries.

    Latency: a side's pixel leaves 4 clocks after its last step; with a memory answering at once the
    first pixel of a frame comes 11 clocks after its pair is taken (:data:`FIRST_PIXEL`; 9 before the
    stages were split for the 110 MHz goal).

    Resources: 2 multipliers (the weight ``(F+1) x (F+1)`` bits, the weight times the pixel), two
    show-ahead FIFOs (queue ``depth`` x 18..32 bits, pixels 4 x ``depth`` x 8 bits, LUT-RAM), 8 kept
    pixels and 2 tags of the camera image's x/y width.
    """
    depth = _check(clk, rst, coord, fetch, source, busy, depth)
    word = model.side_word(coord.frac)
    side, head = FieldSignals(word, _FLAGS), FieldSignals(word, _FLAGS)  # being requested; at the queue's head
    side_in, side_out = Signal(intbv(0)[word.width:]), Signal(intbv(0)[word.width:])
    push, pop = Signal(bool(0)), Signal(bool(0))
    queued = Signal(intbv(0, min=0, max=depth + 1))
    pixel, rpop = Signal(intbv(0)[8:]), Signal(bool(0))
    held = Signal(intbv(0, min=0, max=4 * depth + 1))
    requesting, running = Signal(bool(0)), Signal(bool(0))

    @always_comb
    def busy_out():
        busy.next = requesting or queued != 0 or running

    return (requester(clk, rst, coord, fetch, side, push, queued, requesting, depth=depth),
            pack_word(side_in, word, **side.fields()),
            show_ahead_fifo(clk, rst, side_in, push, side_out, pop, queued, depth=depth),
            unpack_word(side_out, word, **head.fields()),
            # at most depth sides wait, each for at most 4 pixels: every response fits
            show_ahead_fifo(clk, rst, fetch.rsp_data, fetch.rsp_valid, pixel, rpop, held, depth=4 * depth),
            interpolator(clk, rst, head, queued, pixel, held, pop, rpop, source, running, frac=coord.frac),
            busy_out)


def _check(clk, rst, coord, fetch, source, busy, depth) -> int:
    """The elaboration checks of :func:`fetch_interpolate` (a ValueError naming the port or parameter);
    returns ``depth``."""
    check_clock(clk)
    check_reset(rst)
    if not isinstance(coord, CoordPair):
        raise block_error(f"port coord must be a CoordPair, got {type(coord).__name__}")
    check_fetch("fetch", fetch)
    check_stream("source", source, width=8, stereo=True)
    check_signal("busy", busy, width=1)
    depth = check_int("depth", depth, 1, 16)
    if coord.frac > model.MAX_FRAC:
        raise block_error(f"port coord has frac={coord.frac}; the interpolation takes at most {model.MAX_FRAC} "
                          f"fraction bits (both products in 18x18 multipliers)")
    if (fetch.width, fetch.height) != (coord.source_width, coord.source_height):
        raise block_error(f"port fetch is sized for {fetch.width}x{fetch.height} images, port coord for "
                          f"{coord.source_width}x{coord.source_height}: one camera image size for both")
    check_distinct(dict(coord_read_ack=coord.read_ack, fetch_req_valid=fetch.req_valid, fetch_req_x=fetch.req_x,
                        fetch_req_y=fetch.req_y, fetch_req_cam=fetch.req_cam, fetch_req_mask=fetch.req_mask,
                        source=source, busy=busy),
                   dict(clk=clk, rst=rst, coord_valid=coord.valid, coord_xl=coord.xl, coord_yl=coord.yl,
                        coord_xr=coord.xr, coord_yr=coord.yr, coord_oor_l=coord.oor_l,
                        coord_oor_r=coord.oor_r, coord_eol=coord.eol, coord_eof=coord.eof,
                        fetch_req_ready=fetch.req_ready, fetch_rsp_valid=fetch.rsp_valid,
                        fetch_rsp_idx=fetch.rsp_idx, fetch_rsp_data=fetch.rsp_data))
    return depth


# ------------------------------------------------------------------ requester


@block
def requester(clk, rst, coord, fetch, side, push, queued, requesting, *, depth: int):
    """Takes a pair (``read_ack`` while idle), then its left side and its right: ``push`` queues the side
    (the fields of ``side``) in the clock its request moves, or at once when it needs none; ``requesting``
    is high from the pair's clock to its right side's push."""
    frac = coord.frac
    ix, iy = len(coord.xl) - frac, len(coord.yl) - frac
    IDLE, LEFT, RIGHT = 0, 1, 2
    state = Signal(intbv(0, min=0, max=3))
    take, need, space = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    x0, y0 = Signal(intbv(0)[ix:]), Signal(intbv(0)[iy:])
    # per camera: the integer position of the pair on offer, its tag, the reuse rule's mask and sources on
    # them (computed while the pair is offered and registered when it is taken, so that the request path
    # starts at registers: the memory clock's goal, issue 23)
    cx = [Signal(intbv(0)[ix:]) for _ in range(2)]
    cy = [Signal(intbv(0)[iy:]) for _ in range(2)]
    tx = [Signal(intbv(0)[ix:]) for _ in range(2)]
    ty = [Signal(intbv(0)[iy:]) for _ in range(2)]
    tv = [Signal(bool(0)) for _ in range(2)]
    rmask = [Signal(intbv(0)[len(side.mask):]) for _ in range(2)]
    rsrc = [Signal(intbv(0)[len(side.src):]) for _ in range(2)]
    kmask = [Signal(intbv(0)[len(side.mask):]) for _ in range(2)]
    ksrc = [Signal(intbv(0)[len(side.src):]) for _ in range(2)]

    @always_comb
    def control():
        take.next = state == IDLE and coord.valid
        coord.read_ack.next = state == IDLE
        requesting.next = state != IDLE
        side.cam.next = state == RIGHT
        need.next = not side.oor and side.mask != 0
        space.next = queued < depth

    @always_comb
    def request():
        push.next = state != IDLE and space and (not need or fetch.req_ready)
        fetch.req_valid.next = state != IDLE and need and space
        fetch.req_cam.next = side.cam
        fetch.req_mask.next = side.mask
        if side.oor:
            fetch.req_x.next = 0
            fetch.req_y.next = 0
        else:
            fetch.req_x.next = x0
            fetch.req_y.next = y0

    @always_seq(clk.posedge, reset=rst)
    def states():
        if state == IDLE:
            if coord.valid:
                state.next = LEFT
        elif push:
            if state == LEFT:
                state.next = RIGHT
            else:
                state.next = IDLE

    @always_comb
    def offered():
        cx[0].next = coord.xl[len(coord.xl):frac]
        cy[0].next = coord.yl[len(coord.yl):frac]
        cx[1].next = coord.xr[len(coord.xr):frac]
        cy[1].next = coord.yr[len(coord.yr):frac]

    @always_seq(clk.posedge, reset=rst)
    def rule_taken():
        if take:
            for c in range(2):
                kmask[c].next = rmask[c]
                ksrc[c].next = rsrc[c]

    @always_comb
    def rule_of_side():
        if side.cam:
            side.mask.next = kmask[1]
            side.src.next = ksrc[1]
        else:
            side.mask.next = kmask[0]
            side.src.next = ksrc[0]

    return (control, request, states, offered, rule_taken, rule_of_side,
            pair_side(clk, rst, coord, take, side, x0, y0), tags(clk, rst, push, side, x0, y0, tx, ty, tv),
            [reuse_rule(cx[c], cy[c], tx[c], ty[c], tv[c], rmask[c], rsrc[c]) for c in range(2)])


@block
def pair_side(clk, rst, coord, take, side, x0, y0):
    """The pair taken (registers, with its ``eol``/``eof`` as the side's) and, by ``side.cam``, the side's
    integer position ``x0``, ``y0``, its fractions and its out-of-range flag."""
    frac = coord.frac
    nx, ny, fw = len(coord.xl), len(coord.yl), len(side.dx)
    xl, xr = Signal(intbv(0)[nx:]), Signal(intbv(0)[nx:])
    yl, yr = Signal(intbv(0)[ny:]), Signal(intbv(0)[ny:])
    oorl, oorr = Signal(bool(0)), Signal(bool(0))

    @always_seq(clk.posedge, reset=rst)
    def capture():
        if take:
            xl.next = coord.xl
            yl.next = coord.yl
            xr.next = coord.xr
            yr.next = coord.yr
            oorl.next = coord.oor_l
            oorr.next = coord.oor_r
            side.eol.next = coord.eol
            side.eof.next = coord.eof

    @always_comb
    def position():
        if side.cam:
            side.oor.next = oorr
            x0.next = xr[nx:frac]
            y0.next = yr[ny:frac]
        else:
            side.oor.next = oorl
            x0.next = xl[nx:frac]
            y0.next = yl[ny:frac]

    @always_comb
    def fractions():
        if frac == 0:
            side.dx.next = 0
            side.dy.next = 0
        elif side.cam:
            side.dx.next = xr[fw:0]
            side.dy.next = yr[fw:0]
        else:
            side.dx.next = xl[fw:0]
            side.dy.next = yl[fw:0]

    return capture, position, fractions


@block
def tags(clk, rst, push, side, x0, y0, tx, ty, tv):
    """Per camera c the tag of its kept neighbourhood: ``tx[c]``, ``ty[c]``, the position of its last
    in-range side, valid if ``tv[c]``; emptied after a pair with ``eof`` (the frame buffers change).

    A side's tag is up to date when the next pair is taken: the left tag changes with the left side's
    push, the right one with the right side's, and a pair is taken only after both."""

    @always_seq(clk.posedge, reset=rst)
    def update():
        if push:
            if not side.cam:
                if not side.oor:
                    tx[0].next = x0
                    ty[0].next = y0
                    tv[0].next = 1
            else:
                if not side.oor:
                    tx[1].next = x0
                    ty[1].next = y0
                    tv[1].next = 1
                if side.eof:
                    tv[0].next = 0
                    tv[1].next = 0

    return update


@block
def reuse_rule(x0, y0, tx, ty, tv, mask, src):
    """The reuse rule (:func:`_tables`): from a side's position and its camera's tag, the request ``mask``
    and where each kept pixel comes from, ``src``."""
    ix, iy = len(x0), len(y0)
    MASK_T, SRC_T = _tables()
    XOFF, YOFF = (1 << (ix + 1)) + 1, (1 << (iy + 1)) + 1
    ex, ey = Signal(intbv(0)[ix + 2:]), Signal(intbv(0)[iy + 2:])
    exl, eyl = Signal(intbv(0)[ix + 1:]), Signal(intbv(0)[iy + 1:])
    cx, cy = Signal(intbv(0)[2:]), Signal(intbv(0)[2:])
    code = Signal(intbv(0)[4:])

    @always_comb
    def offsets():
        # x0 - tx + 1 kept positive by 2**(ix+1): its low ix+1 bits are 0, 1, 2 for ddx = -1, 0, 1 (one
        # subtraction; no signed values, no negative constants: MyHDL's Verilog compares a signed case
        # expression with unsigned negative items)
        ex.next = x0 + XOFF - tx
        ey.next = y0 + YOFF - ty

    @always_comb
    def offsets_low():
        exl.next = ex[ix + 1:0]
        eyl.next = ey[iy + 1:0]

    @always_comb
    def steps():
        # 3 = no reuse (the low ix+1 bits are 0..2 only for ddx = -1..1)
        if exl < 3:
            cx.next = exl[2:0]
        else:
            cx.next = 3
        if eyl < 3:
            cy.next = eyl[2:0]
        else:
            cy.next = 3

    @always_comb
    def table_index():
        if tv:
            code.next = concat(cy, cx)
        else:
            code.next = 15

    @always_comb
    def mask_rom():
        mask.next = MASK_T[code]

    @always_comb
    def src_rom():
        src.next = SRC_T[code]

    return offsets, offsets_low, steps, table_index, mask_rom, src_rom


# ------------------------------------------------------------------ interpolator


@block
def interpolator(clk, rst, head, queued, pixel, held, pop, rpop, source, running, *, frac: int):
    """Four multiply-accumulate steps per queued side, one for a black side (module docstring): ``pop``
    with the side's last step, ``rpop`` with each step whose pixel comes from the response FIFO."""
    step = Signal(intbv(0, min=0, max=4))
    fetched = Signal(bool(0))  # the step's pixel comes from the response FIFO
    fire, last = Signal(bool(0)), Signal(bool(0))
    pix, kpix = Signal(intbv(0)[8:]), Signal(intbv(0)[8:])
    wa, wb = Signal(intbv(0)[frac + 1:]), Signal(intbv(0)[frac + 1:])

    @always_comb
    def step_fire():
        fetched.next = not head.oor and head.mask[step]
        fire.next = queued != 0 and (not fetched or held != 0)
        last.next = head.oor or step == 3
        rpop.next = queued != 0 and fetched and held != 0
        pop.next = queued != 0 and (not fetched or held != 0) and (head.oor or step == 3)
        pix.next = pixel if fetched else kpix

    @always_seq(clk.posedge, reset=rst)
    def steps():
        if fire:
            if last:
                step.next = 0
            else:
                step.next = step + 1

    return (step_fire, steps, kept_pixels(clk, fire, head, step, pix, kpix), step_weight(step, head, wa, wb, frac=frac),
            mac(clk, rst, fire, last, step, head, wa, wb, pix, source, running, frac=frac))


@block
def kept_pixels(clk, fire, head, step, pix, kpix):
    """Per camera the four pixels of its last in-range side (``kept[4 * cam + index]``), and ``kpix``: the
    one the current step reuses (index ``head.src`` names for it)."""
    kept = [Signal(intbv(0)[8:]) for _ in range(8)]
    taken = [Signal(intbv(0)[8:]) for _ in range(3)]  # the side's pixels 0..2 until its step 3
    src_i = Signal(intbv(0)[2:])
    kidx = Signal(intbv(0, min=0, max=8))

    @always_comb
    def source_index():
        if step == 0:
            src_i.next = head.src[2:0]
        elif step == 1:
            src_i.next = head.src[4:2]
        elif step == 2:
            src_i.next = head.src[6:4]
        else:
            src_i.next = head.src[8:6]

    @always_comb
    def kept_index():
        kidx.next = concat(head.cam, src_i)

    @always_comb
    def kept_read():
        kpix.next = kept[kidx]

    @always(clk.posedge)
    def keep():
        # the side's pixels become its camera's kept neighbourhood (in-range sides only)
        if fire and not head.oor:
            for i in range(3):
                if step == i:
                    taken[i].next = pix
            if step == 3 and head.cam:
                kept[4].next = taken[0]
                kept[5].next = taken[1]
                kept[6].next = taken[2]
                kept[7].next = pix
            elif step == 3:
                kept[0].next = taken[0]
                kept[1].next = taken[1]
                kept[2].next = taken[2]
                kept[3].next = pix

    return source_index, kept_index, kept_read, keep


@block
def step_weight(step, head, wa, wb, *, frac: int):
    """The step's weight factors ``wa``, ``wb`` (their product, in :func:`mac`, is the weight): index 0
    ``dx*dy``, 1 ``(S-dx)*dy``, 2 ``dx*(S-dy)``, 3 ``(S-dx)*(S-dy)`` (S = 2**frac)."""
    S = 1 << frac

    @always_comb
    def factors():
        if step == 0 or step == 2:
            wa.next = head.dx
        else:
            wa.next = S - head.dx
        if step == 0 or step == 1:
            wb.next = head.dy
        else:
            wb.next = S - head.dy

    return factors


@block
def mac(clk, rst, fire, last, step, head, wa, wb, pix, source, running, *, frac: int):
    """Five registered stages, one multiplier or adder each, so that no path runs through a multiplier
    and more (the memory clock's goal, issue 23): 1 registers the step's weight factors and pixel (0 for
    a black side), 2 the weight ``wa * wb`` (the first multiplier), 3 the product ``w * p`` (the second),
    4 accumulates (``acc = w * p`` at index 0, ``acc + w * p`` after), the output register takes
    ``(acc + S*S/2) >> 2*frac`` after a side's last step; ``running`` while a step is in the stages."""
    v1, v2, v3, v4 = (Signal(bool(0)) for _ in range(4))
    first1, first2, first3 = (Signal(bool(0)) for _ in range(3))
    last1, last2, last3 = (Signal(bool(0)) for _ in range(3))
    wa1, wb1 = Signal(intbv(0)[frac + 1:]), Signal(intbv(0)[frac + 1:])
    w2 = Signal(intbv(0)[2 * frac + 2:])
    p1, p2 = Signal(intbv(0)[8:]), Signal(intbv(0)[8:])
    m3 = Signal(intbv(0)[2 * frac + 10:])
    t1, t2, t3, t4 = (Signal(intbv(0)[3:]) for _ in range(4))  # cam, eol, eof
    ACC = 8 + 2 * frac + 1
    acc = Signal(intbv(0)[ACC:])
    rounded = Signal(intbv(0)[ACC + 1:])
    HALF = (1 << (2 * frac)) >> 1

    @always_seq(clk.posedge, reset=rst)
    def stages():
        v1.next = fire
        if fire:
            first1.next = step == 0
            last1.next = last
            t1.next = concat(head.cam, head.eol, head.eof)
            if head.oor:
                wa1.next = 0
                p1.next = 0
            else:
                wa1.next = wa
                p1.next = pix
            wb1.next = wb
        v2.next = v1
        first2.next = first1
        last2.next = last1
        t2.next = t1
        w2.next = wa1 * wb1
        p2.next = p1
        v3.next = v2
        first3.next = first2
        last3.next = last2
        t3.next = t2
        m3.next = w2 * p2
        v4.next = v3 and last3
        if v3:
            t4.next = t3
            if first3:
                acc.next = m3
            else:
                acc.next = acc + m3
        source.valid.next = v4
        if v4:
            source.data.next = rounded[ACC:2 * frac]
            source.cam.next = t4[2]
            source.eol.next = t4[1]
            source.eof.next = t4[0]

    @always_comb
    def rounding():
        rounded.next = acc + HALF

    @always_comb
    def running_out():
        running.next = v1 or v2 or v3 or v4

    return stages, rounding, running_out
