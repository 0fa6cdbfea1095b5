"""Fetch and interpolation: coordinate pairs in, the rectified stereo stream out (thesis 4.3, Figs. 4.9-4.11)."""

from __future__ import annotations

from myhdl import Signal, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.common.checks import block_error, check_clock, check_distinct, check_int, check_reset, \
    check_signal, check_stream
from eyestereo.hdl.interfaces.coord_pair import CoordPair
from eyestereo.hdl.interfaces.fetch_port import FetchPort, check_fetch
from eyestereo.tools.models import fetch_interpolate as model

__all__ = ["DEFAULT_DEPTH", "fetch_interpolate"]

#: Default number of sides (requests or black pixels) in flight between the request and the output.
DEFAULT_DEPTH = 4


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
    range, request mask, where each kept pixel comes from, the fractions, eol/eof):

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
      otherwise) goes out two clocks after the last step; the four pixels become that camera's kept
      neighbourhood.

    Timing, one pair with both sides in range, the memory answering at once (``F`` a fetch beat, ``s``
    an interpolation step)::

        cycle       0    1    2    3    4    5    6    7    8    9   10   11   12   13
        coord.valid #    .    .    .    .    .    .    .    .    .    .    .    .    .
        read_ack    #    _    _    .    .    .    .    .    .    .    .    .    .    .
        req_valid   _    #L   #R   _    _    _    _    _    _    _    _    _    _    _
        rsp_valid   _    _    F    F    F    F    _    _    _    _    _    _    _    _
        steps (L)   _    _    _    _    s0   s1   s2   s3   _    _    _    _    _    _
        steps (R)   _    _    _    _    _    _    _    _    s0   s1   s2   s3   _    _
        source      _    _    _    _    _    _    _    _    _    L    _    _    _    R

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

    Latency: a side's pixel leaves 2 clocks after its last step; with a memory answering at once the
    first pixel of a frame comes 9 clocks after its pair is taken.

    Resources: 2 multipliers (the weight ``(F+1) x (F+1)`` bits, the weight times the pixel), two
    small FIFOs (queue ``depth`` x 16..32 bits, pixels 4 x ``depth`` x 8 bits, LUT-RAM), 8 kept pixels and
    2 tags of the camera image's x/y width.
    """
    check_clock(clk)
    check_reset(rst)
    if not isinstance(coord, CoordPair):
        raise block_error(f"port coord must be a CoordPair, got {type(coord).__name__}")
    check_fetch("fetch", fetch)
    check_stream("source", source, width=8, stereo=True)
    check_signal("busy", busy, width=1)
    depth = check_int("depth", depth, 1, 16)
    frac = coord.frac
    if frac > model.MAX_FRAC:
        raise block_error(f"port coord has frac={frac}; the interpolation takes at most {model.MAX_FRAC} "
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

    nx, ny = coord.x_format.wl, coord.y_format.wl
    ix, iy = nx - frac, ny - frac
    fw = max(frac, 1)
    S = 1 << frac
    MASK_T, SRC_T = _tables()

    # ------------------------------------------------------------------ requester
    IDLE, LEFT, RIGHT = 0, 1, 2
    state = Signal(intbv(0, min=0, max=3))
    xl, xr = Signal(intbv(0)[nx:]), Signal(intbv(0)[nx:])
    yl, yr = Signal(intbv(0)[ny:]), Signal(intbv(0)[ny:])
    oorl, oorr, eol, eof = Signal(bool(0)), Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    # tags: the previous in-range neighbourhood of each camera
    txl, txr = Signal(intbv(0)[ix:]), Signal(intbv(0)[ix:])
    tyl, tyr = Signal(intbv(0)[iy:]), Signal(intbv(0)[iy:])
    tvl, tvr = Signal(bool(0)), Signal(bool(0))
    # the side being requested
    cam = Signal(bool(0))
    oor = Signal(bool(0))
    x0, tx = Signal(intbv(0)[ix:]), Signal(intbv(0)[ix:])
    y0, ty = Signal(intbv(0)[iy:]), Signal(intbv(0)[iy:])
    tv = Signal(bool(0))
    dx, dy = Signal(intbv(0)[fw:]), Signal(intbv(0)[fw:])
    XOFF, YOFF = (1 << (ix + 1)) + 1, (1 << (iy + 1)) + 1
    ex, ey = Signal(intbv(0)[ix + 2:]), Signal(intbv(0)[iy + 2:])
    exl, eyl = Signal(intbv(0)[ix + 1:]), Signal(intbv(0)[iy + 1:])
    cx, cy = Signal(intbv(0)[2:]), Signal(intbv(0)[2:])
    code = Signal(intbv(0)[4:])
    rom_mask = Signal(intbv(0)[4:])
    rom_src = Signal(intbv(0)[8:])
    mask = Signal(intbv(0)[4:])
    need = Signal(bool(0))
    space = Signal(bool(0))
    advance = Signal(bool(0))
    # the side queue
    DW = 2 * fw + 16
    dword = Signal(intbv(0)[DW:])
    dmem = [Signal(intbv(0)[DW:]) for _ in range(depth)]
    dwp, drp = Signal(intbv(0, min=0, max=depth)), Signal(intbv(0, min=0, max=depth))
    dcount = Signal(intbv(0, min=0, max=depth + 1))
    pop = Signal(bool(0))

    @always_comb
    def side():
        if state == RIGHT:
            cam.next = 1
            oor.next = oorr
            x0.next = xr[nx:frac]
            y0.next = yr[ny:frac]
            tx.next = txr
            ty.next = tyr
            tv.next = tvr
        else:
            cam.next = 0
            oor.next = oorl
            x0.next = xl[nx:frac]
            y0.next = yl[ny:frac]
            tx.next = txl
            ty.next = tyl
            tv.next = tvl

    @always_comb
    def fractions():
        if frac == 0:
            dx.next = 0
            dy.next = 0
        elif state == RIGHT:
            dx.next = xr[fw:0]
            dy.next = yr[fw:0]
        else:
            dx.next = xl[fw:0]
            dy.next = yl[fw:0]

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
    def reuse_code():
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
    def reuse_code2():
        if tv:
            code.next = concat(cy, cx)
        else:
            code.next = 15

    @always_comb
    def mask_rom():
        rom_mask.next = MASK_T[code]

    @always_comb
    def src_rom():
        rom_src.next = SRC_T[code]

    @always_comb
    def request():
        mask.next = rom_mask
        need.next = not oor and rom_mask != 0
        space.next = dcount < depth
        dword.next = concat(dy, dx, rom_src, rom_mask, oor, cam, eol, eof)

    @always_comb
    def request2():
        advance.next = state != IDLE and space and (not need or fetch.req_ready)
        fetch.req_valid.next = state != IDLE and need and space
        coord.read_ack.next = state == IDLE
        fetch.req_cam.next = cam
        fetch.req_mask.next = mask
        if oor:
            fetch.req_x.next = 0
            fetch.req_y.next = 0
        else:
            fetch.req_x.next = x0
            fetch.req_y.next = y0

    @always_seq(clk.posedge, reset=rst)
    def requester():
        if state == IDLE:
            if coord.valid:
                xl.next = coord.xl
                yl.next = coord.yl
                xr.next = coord.xr
                yr.next = coord.yr
                oorl.next = coord.oor_l
                oorr.next = coord.oor_r
                eol.next = coord.eol
                eof.next = coord.eof
                state.next = LEFT
        elif advance:
            if dwp == depth - 1:
                dwp.next = 0
            else:
                dwp.next = dwp + 1
            if state == LEFT:
                if not oor:
                    txl.next = x0
                    tyl.next = y0
                    tvl.next = 1
                state.next = RIGHT
            else:
                if not oor:
                    txr.next = x0
                    tyr.next = y0
                    tvr.next = 1
                state.next = IDLE
                if eof:  # a new frame follows: the frame buffers change
                    tvl.next = 0
                    tvr.next = 0
        if advance and not pop:
            dcount.next = dcount + 1
        elif pop and not advance:
            dcount.next = dcount - 1

    @always_seq(clk.posedge, reset=None)
    def queue_mem():
        if state != IDLE and advance:
            dmem[dwp].next = dword

    # ------------------------------------------------------------------ response FIFO
    RD = 4 * depth
    rmem = [Signal(intbv(0)[8:]) for _ in range(RD)]
    rwp, rrp = Signal(intbv(0, min=0, max=RD)), Signal(intbv(0, min=0, max=RD))
    rcount = Signal(intbv(0, min=0, max=RD + 1))
    rhead = Signal(intbv(0)[8:])
    rpop = Signal(bool(0))

    @always_seq(clk.posedge, reset=None)
    def rfifo_mem():
        if fetch.rsp_valid:
            rmem[rwp].next = fetch.rsp_data

    @always_seq(clk.posedge, reset=rst)
    def rfifo():
        if fetch.rsp_valid:
            if rwp == RD - 1:
                rwp.next = 0
            else:
                rwp.next = rwp + 1
        if rpop:
            if rrp == RD - 1:
                rrp.next = 0
            else:
                rrp.next = rrp + 1
        if fetch.rsp_valid and not rpop:
            rcount.next = rcount + 1
        elif rpop and not fetch.rsp_valid:
            rcount.next = rcount - 1

    @always_comb
    def rfifo_head():
        rhead.next = rmem[rrp]

    # ------------------------------------------------------------------ interpolator
    head = Signal(intbv(0)[DW:])
    h_eof, h_eol, h_cam, h_oor = Signal(bool(0)), Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    h_mask = Signal(intbv(0)[4:])
    h_src = Signal(intbv(0)[8:])
    h_dx, h_dy = Signal(intbv(0)[fw:]), Signal(intbv(0)[fw:])
    step = Signal(intbv(0, min=0, max=4))
    fetched = Signal(bool(0))  # the step's pixel comes from the response FIFO
    fire = Signal(bool(0))
    last = Signal(bool(0))
    src_i = Signal(intbv(0)[2:])
    kept = [Signal(intbv(0)[8:]) for _ in range(8)]  # kept[4 * cam + index]
    kidx = Signal(intbv(0, min=0, max=8))
    kpix = Signal(intbv(0)[8:])
    pix = Signal(intbv(0)[8:])
    nbuf = [Signal(intbv(0)[8:]) for _ in range(3)]
    wa, wb = Signal(intbv(0)[frac + 1:]), Signal(intbv(0)[frac + 1:])
    weight = Signal(intbv(0)[2 * frac + 2:])
    # stage 1 (the weight and the pixel), stage 2 (the accumulator)
    v1, first1, last1 = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    w1 = Signal(intbv(0)[2 * frac + 2:])
    p1 = Signal(intbv(0)[8:])
    t1 = Signal(intbv(0)[3:])  # cam, eol, eof
    ACC = 8 + 2 * frac + 1
    acc = Signal(intbv(0)[ACC:])
    v2 = Signal(bool(0))
    t2 = Signal(intbv(0)[3:])
    rounded = Signal(intbv(0)[ACC + 1:])
    HALF = (1 << (2 * frac)) >> 1

    @always_comb
    def unpack():
        head.next = dmem[drp]

    @always_comb
    def unpack2():
        h_eof.next = head[0]
        h_eol.next = head[1]
        h_cam.next = head[2]
        h_oor.next = head[3]
        h_mask.next = head[8:4]
        h_src.next = head[16:8]
        h_dx.next = head[16 + fw:16]
        h_dy.next = head[16 + 2 * fw:16 + fw]

    @always_comb
    def step_select():
        fetched.next = not h_oor and h_mask[step]
        if step == 0:
            src_i.next = h_src[2:0]
        elif step == 1:
            src_i.next = h_src[4:2]
        elif step == 2:
            src_i.next = h_src[6:4]
        else:
            src_i.next = h_src[8:6]

    @always_comb
    def kept_index():
        kidx.next = concat(h_cam, src_i)

    @always_comb
    def kept_read():
        kpix.next = kept[kidx]

    @always_comb
    def step_fire():
        fire.next = dcount != 0 and (not fetched or rcount != 0)
        last.next = h_oor or step == 3
        rpop.next = dcount != 0 and fetched and rcount != 0
        pop.next = dcount != 0 and (not fetched or rcount != 0) and (h_oor or step == 3)
        if fetched:
            pix.next = rhead
        else:
            pix.next = kpix

    @always_comb
    def weights():
        # index 0 dx*dy, 1 (S-dx)*dy, 2 dx*(S-dy), 3 (S-dx)*(S-dy)
        if step == 0 or step == 2:
            wa.next = h_dx
        else:
            wa.next = S - h_dx
        if step == 0 or step == 1:
            wb.next = h_dy
        else:
            wb.next = S - h_dy

    @always_comb
    def multiply_weight():
        weight.next = wa * wb

    @always_seq(clk.posedge, reset=rst)
    def interpolator():
        v1.next = fire
        if fire:
            first1.next = step == 0
            last1.next = last
            t1.next = concat(h_cam, h_eol, h_eof)
            if h_oor:
                w1.next = 0
                p1.next = 0
            else:
                w1.next = weight
                p1.next = pix
            if last:
                step.next = 0
                if drp == depth - 1:
                    drp.next = 0
                else:
                    drp.next = drp + 1
            else:
                step.next = step + 1
        # stage 2: multiply-accumulate
        v2.next = v1 and last1
        if v1:
            t2.next = t1
            if first1:
                acc.next = w1 * p1
            else:
                acc.next = acc + w1 * p1
        # output register
        source.valid.next = v2
        if v2:
            source.data.next = rounded[ACC:2 * frac]
            source.cam.next = t2[2]
            source.eol.next = t2[1]
            source.eof.next = t2[0]

    @always_seq(clk.posedge, reset=None)
    def keep():
        # the side's pixels become its camera's kept neighbourhood (in-range sides only)
        if fire and not h_oor:
            if step == 0:
                nbuf[0].next = pix
            elif step == 1:
                nbuf[1].next = pix
            elif step == 2:
                nbuf[2].next = pix
            else:
                if h_cam:
                    kept[4].next = nbuf[0]
                    kept[5].next = nbuf[1]
                    kept[6].next = nbuf[2]
                    kept[7].next = pix
                else:
                    kept[0].next = nbuf[0]
                    kept[1].next = nbuf[1]
                    kept[2].next = nbuf[2]
                    kept[3].next = pix

    @always_comb
    def rounding():
        rounded.next = acc + HALF

    @always_comb
    def busy_out():
        busy.next = state != IDLE or dcount != 0 or v1 or v2

    return (side, fractions, offsets, offsets_low, reuse_code, reuse_code2, mask_rom, src_rom, request, request2, requester, queue_mem,
            rfifo_mem, rfifo, rfifo_head, unpack, unpack2, step_select, kept_index, kept_read, step_fire,
            weights, multiply_weight, interpolator, keep, rounding, busy_out)
