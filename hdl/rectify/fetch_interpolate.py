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
FIRST_PIXEL = 12
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

        cycle       0    1    2    3    4    5    6    7    8    9   10   11   12   13   14   15   16
        coord.valid #    .    .    .    .    .    .    .    .    .    .    .    .    .    .    .    .
        read_ack    #    _    _    .    .    .    .    .    .    .    .    .    .    .    .    .    .
        req_valid   _    #L   #R   _    _    _    _    _    _    _    _    _    _    _    _    _    _
        rsp_valid   _    _    F    F    F    F    _    _    _    _    _    _    _    _    _    _    _
        steps (L)   _    _    _    _    _    s0   s1   s2   s3   _    _    _    _    _    _    _    _
        steps (R)   _    _    _    _    _    _    _    _    _    s0   s1   s2   s3   _    _    _    _
        source      _    _    _    _    _    _    _    _    _    _    _    _    L    _    _    _    R

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
    first pixel of a frame comes 12 clocks after its pair is taken (:data:`FIRST_PIXEL`; 9 before the
    stages were split and the response pixel registered for the 110 MHz goal).

    Resources: 2 multipliers (the weight ``(F+1) x (F+1)`` bits, the weight times the pixel), two
    show-ahead FIFOs (queue ``depth`` x 18..32 bits, pixels 4 x ``depth`` x 8 bits, LUT-RAM), 8 kept
    pixels and 2 tags of the camera image's x/y width.
    """
    depth = _check(clk, rst, coord, fetch, source, busy, depth)
    word = model.side_word(coord.frac)
    side, head = FieldSignals(word, _FLAGS), FieldSignals(word, _FLAGS)  # being requested; at the queue's head
    side_in, side_out = Signal(intbv(0)[word.width:]), Signal(intbv(0)[word.width:])
    side_fifo, side_fifo_pop, hq, room = (Signal(intbv(0)[word.width:]), Signal(bool(0)), Signal(bool(0)),
                                          Signal(bool(0)))
    push, pop = Signal(bool(0)), Signal(bool(0))
    queued = Signal(intbv(0, min=0, max=depth + 1))
    pixel, rpop = Signal(intbv(0)[8:]), Signal(bool(0))
    fifo_word, fifo_pop, hv = Signal(intbv(0)[8:]), Signal(bool(0)), Signal(bool(0))
    held = Signal(intbv(0, min=0, max=4 * depth + 1))
    requesting, running = Signal(bool(0)), Signal(bool(0))

    @always_comb
    def busy_out():
        busy.next = requesting or queued != 0 or hq or running

    @always_comb
    def in_flight():
        # sides in flight: the queue's and the one in the head register; at most depth
        if hq:
            room.next = queued < depth - 1
        else:
            room.next = queued < depth

    return (requester(clk, rst, coord, fetch, side, push, room, requesting),
            pack_word(side_in, word, **side.fields()),
            show_ahead_fifo(clk, rst, side_in, push, side_fifo, side_fifo_pop, queued, depth=depth),
            head_register(clk, rst, side_fifo, queued, side_fifo_pop, side_out, hq, pop),
            unpack_word(side_out, word, **head.fields()),
            # at most depth sides wait, each for at most 4 pixels: every response fits
            show_ahead_fifo(clk, rst, fetch.rsp_data, fetch.rsp_valid, fifo_word, fifo_pop, held, depth=4 * depth),
            head_register(clk, rst, fifo_word, held, fifo_pop, pixel, hv, rpop),
            interpolator(clk, rst, head, hq, pixel, hv, pop, rpop, source, running, frac=coord.frac),
            busy_out, in_flight)


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
def requester(clk, rst, coord, fetch, side, push, room, requesting):
    """Takes a pair (``read_ack`` while idle), then its left side and its right: ``push`` queues the side
    (the fields of ``side``) in the clock its request moves, or at once when it needs none; ``requesting``
    is high from the pair's clock to its right side's push."""
    frac = coord.frac
    ix, iy = len(coord.xl) - frac, len(coord.yl) - frac
    IDLE, LEFT, RIGHT = 0, 1, 2
    state = Signal(intbv(0, min=0, max=3))
    take, need, space, to_right = Signal(bool(0)), Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
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
        space.next = room

    @always_comb
    def request():
        push.next = state != IDLE and space and (not need or fetch.req_ready)
        to_right.next = state == LEFT and space and (not need or fetch.req_ready)
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
            pair_side(clk, rst, coord, take, to_right, side, x0, y0), tags(clk, rst, push, side, x0, y0, tx, ty, tv),
            [reuse_rule(cx[c], cy[c], tx[c], ty[c], tv[c], rmask[c], rsrc[c]) for c in range(2)])


@block
def pair_side(clk, rst, coord, take, to_right, side, x0, y0):
    """The pair taken (its right side kept in registers, its ``eol``/``eof`` as the sides') and the current
    side in registers: its integer position ``x0``, ``y0``, fractions and out-of-range flag, loaded with the
    left side's at ``take`` and with the right side's at ``to_right`` (the left side's push). Registers, not
    a multiplexer on ``side.cam``: the position goes straight into the fetch port's address arithmetic
    (the memory clock's goal, issue 23)."""
    frac = coord.frac
    nx, ny, fw = len(coord.xl), len(coord.yl), len(side.dx)
    xr, yr = Signal(intbv(0)[nx:]), Signal(intbv(0)[ny:])
    oorr = Signal(bool(0))

    @always_seq(clk.posedge, reset=rst)
    def capture():
        if take:
            xr.next = coord.xr
            yr.next = coord.yr
            oorr.next = coord.oor_r
            side.eol.next = coord.eol
            side.eof.next = coord.eof
            side.oor.next = coord.oor_l
            x0.next = coord.xl[nx:frac]
            y0.next = coord.yl[ny:frac]
            if frac == 0:
                side.dx.next = 0
                side.dy.next = 0
            else:
                side.dx.next = coord.xl[fw:0]
                side.dy.next = coord.yl[fw:0]
        elif to_right:
            side.oor.next = oorr
            x0.next = xr[nx:frac]
            y0.next = yr[ny:frac]
            if frac == 0:
                side.dx.next = 0
                side.dy.next = 0
            else:
                side.dx.next = xr[fw:0]
                side.dy.next = yr[fw:0]

    return capture


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
    # The tag's neighbours tx - 1, tx + 1 (ty alike) are worked out from the tag alone, so the position on
    # offer (which comes from the coordinate warper's registers, far away in the netlist) meets only
    # equality compares: no carry chain on its way to the rule's registers (issue 23). On ix + 1 bits, so
    # that tx - 1 for tx = 0 (all ones) and tx + 1 for the last column never equal a position.
    xm, xp = Signal(intbv(0)[ix + 1:]), Signal(intbv(0)[ix + 1:])
    ym, yp = Signal(intbv(0)[iy + 1:]), Signal(intbv(0)[iy + 1:])
    xmw, ymw = Signal(intbv(0)[ix + 2:]), Signal(intbv(0)[iy + 2:])
    XM, YM = (1 << (ix + 1)) - 1, (1 << (iy + 1)) - 1  # + 2**(n+1) - 1: minus one, modulo 2**(n+1)
    cx, cy = Signal(intbv(0)[2:]), Signal(intbv(0)[2:])
    code = Signal(intbv(0)[4:])

    @always_comb
    def neighbours():
        xmw.next = tx + XM
        ymw.next = ty + YM
        xp.next = tx + 1
        yp.next = ty + 1

    @always_comb
    def neighbours_low():
        xm.next = xmw[ix + 1:0]
        ym.next = ymw[iy + 1:0]

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

    return (neighbours, neighbours_low, step_code(x0, tx, xm, xp, cx), step_code(y0, ty, ym, yp, cy), table_index,
            mask_rom, src_rom)


@block
def step_code(pos, tag, below, above, code):
    """The reuse rule's step on one axis: ``pos - tag`` = -1 -> 0, 0 -> 1, +1 -> 2, anything else 3 (no
    reuse), from equality compares with the tag and its neighbours ``below`` = tag - 1, ``above`` = tag + 1."""

    @always_comb
    def comb():
        if pos == tag:
            code.next = 1
        elif pos == below:
            code.next = 0
        elif pos == above:
            code.next = 2
        else:
            code.next = 3

    return comb


# ------------------------------------------------------------------ interpolator


@block
def interpolator(clk, rst, head, hq, pixel, hv, pop, rpop, source, running, *, frac: int):
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
        fire.next = hq and (not fetched or hv)
        last.next = head.oor or step == 3
        rpop.next = hq and fetched and hv
        pop.next = hq and (not fetched or hv) and (head.oor or step == 3)
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
def head_register(clk, rst, fifo_word, level, fifo_pop, pixel, hv, take):
    """A show-ahead FIFO's oldest word in a register (``pixel``, valid while ``hv``): refilled from the
    FIFO in the clock the interpolator ``take``s it, or whenever it is empty. The interpolator's paths
    (the side's flags, the response pixel) then start at this register, not at the FIFO's pointer and
    LUT-RAM (the memory clock's worst paths, issue 23); one clock more from the FIFO to the step."""

    @always_comb
    def refill():
        fifo_pop.next = level != 0 and (not hv or take)

    @always_seq(clk.posedge, reset=rst)
    def valid():
        if level != 0 and (not hv or take):
            hv.next = True
        elif take:
            hv.next = False

    @always(clk.posedge)
    def word():
        if level != 0 and (not hv or take):
            pixel.next = fifo_word

    return refill, valid, word


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
    def valid_bits():
        v1.next = fire
        v2.next = v1
        v3.next = v2
        v4.next = v3 and last3
        source.valid.next = v4

    # The data registers have no reset (the valid bits say what they hold): so the multipliers' operand
    # and product registers can live inside the ECP5's DSP blocks (hdl/flow/dsp_regs.py).
    @always(clk.posedge)
    def stages():
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
        first2.next = first1
        last2.next = last1
        t2.next = t1
        w2.next = wa1 * wb1
        p2.next = p1
        first3.next = first2
        last3.next = last2
        t3.next = t2
        m3.next = w2 * p2
        if v3:
            t4.next = t3
            if first3:
                acc.next = m3
            else:
                acc.next = acc + m3
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

    return valid_bits, stages, rounding, running_out
