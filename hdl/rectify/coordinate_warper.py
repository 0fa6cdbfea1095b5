"""The coordinate warper: x/y counters, the calculation unit and the double-buffered pair output (thesis 4.2.3)."""

from __future__ import annotations

from myhdl import Signal, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.common.checks import block_error, check_clock, check_distinct, check_int, check_reset, check_signal
from eyestereo.hdl.common.registers import en_reg
from eyestereo.hdl.interfaces.coord_pair import CoordPair
from eyestereo.hdl.rectify.calibration import calibration_param
from eyestereo.hdl.rectify.poly_unit import poly_unit
from eyestereo.tools.models import poly_unit as unit_model

__all__ = ["FIRST_PAIR", "coordinate_warper"]

#: Clocks from the ``start`` clock to the first clock with ``valid`` high (enable high throughout).
FIRST_PAIR = unit_model.LATENCY + 5


@block
def tag_delay(clk, en, din, dout, *, clocks: int):
    """``dout`` = ``din`` after ``clocks`` enabled clocks (the calculation unit's latency)."""
    stages = [Signal(intbv(0)[len(din):]) for _ in range(clocks - 1)] + [dout]
    insts = []
    src = din
    for dst in stages:
        insts.append(en_reg(clk, en, src, dst))
        src = dst
    return insts


@block
def coordinate_warper(clk, rst, start, enable, busy, done, coord, coef=None, *, quantizers=None,
                      frac: int | None = unit_model.DEFAULT_FRAC, source_width: int | None = None,
                      source_height: int | None = None):
    """Source coordinates of every rectified pixel of both cameras, one pair (Pl, Pr) per pixel.

    Counters step through the rectified image (x with two extra low bits forming ``select_coord``:
    X-L, Y-L, X-R, Y-R of one pixel in four clocks) and feed :func:`~eyestereo.hdl.rectify.poly_unit.poly_unit`;
    its results fill the first register level R1 (X-L, Y-L, X-R, and the out-of-range flags); with Y-R the
    pair moves to R2, the output registers of the :class:`~eyestereo.hdl.interfaces.coord_pair.CoordPair` handshake.
    The double buffer is the thesis's three-state machine (Fig. 4.7)::

        empty  --Y-R out-------------------------> R2 full     (R1 + Y-R -> R2)
        R2 full --read_ack & Y-R out-------------> R2 full     (R1 + Y-R -> R2)
        R2 full --read_ack-----------------------> empty
        R2 full --Y-R out, no read_ack-----------> both full   (Y-R -> R1; the unit stops)
        both full --read_ack---------------------> R2 full     (R1 -> R2; the unit runs again)

    ``valid`` is "R2 full"; the unit's enable is "not both full" (a register, so the unit stops one clock
    after R1 fills and runs one clock after it empties). A consumer that takes each pair within four
    clocks never stops the unit: one pair every 4 clocks.

    The handshake and its timing diagram (pairs taken at once, after a wait, and the stall of the unit:
    ``enable cu`` low while both levels are full) are documented once, in
    :mod:`eyestereo.hdl.interfaces.coord_pair` ("Timing").

    A frame: ``start`` (sampled while ``busy`` is low and ``enable`` high) begins one; ``busy`` is high
    from the next clock until the frame's last pair (``eof``) has been taken; ``done`` is high for the one
    clock after that take (``busy`` low again; a ``start`` in that clock begins the next frame)::

        cycle     s   s+1  ...  s+14 ...    e   e+1
        start     #    _         _          _    .
        busy      _    #    #    #    #     #    _
        valid     _    _    _    #   ...    #    .      (first pair in clock s + 14; last pair: eof)
        read_ack  .    .    .    .   ...    #    .
        done      _    _    _    _    _     _    #

    With a consumer that takes every pair at once, ``e + 1 = s + 4 x width x height + 10``.

    Ports:
        clk, rst: clock; synchronous active-high reset (back to idle: counters, state machine, the unit's
            valid bits; a frame in progress is abandoned).
        start: in, 1 bit: begin a frame (ignored while ``busy``).
        enable: in, 1 bit: clock enable of the whole warper; while low no register changes (the outputs
            hold, ``start`` and ``read_ack`` are ignored). Tie high when not needed.
        busy: out, 1 bit: a frame is in progress.
        done: out, 1 bit: one clock after the frame's last pair was taken.
        coord: :class:`~eyestereo.hdl.interfaces.coord_pair.CoordPair` (ports ``coord_valid``, ``coord_read_ack``,
            ``coord_xl`` ...) sized for ``source_width`` x ``source_height`` and ``frac``.
        coef: optional :class:`~eyestereo.hdl.rectify.poly_unit.CoefPort`: run-time coefficients (see
            :func:`~eyestereo.hdl.rectify.poly_unit.poly_unit`).

    Parameters:
        quantizers, frac, source_width, source_height: as for :func:`~eyestereo.hdl.rectify.poly_unit.poly_unit`
            (default: the synthetic rig, 352x288, frac = q24's fraction length, 5). The rectified size (the
            counters) is the calibration's ``width`` x ``height``.

    Latency: the first pair is offered 14 clocks after the ``start`` clock (:data:`FIRST_PAIR`); then one
    pair per 4 clocks while the consumer keeps up: ``done`` 4 x width x height + 10 clocks after ``start``.

    Resources: the calculation unit, two counters, the R1 and R2 register levels (2 x 4 coordinates,
    2 x 4 flags), a 2-bit state and an 8-stage, 2-bit tag delay (eol/eof), no multiplier of its own.
    """
    check_clock(clk)
    check_reset(rst)
    cal = calibration_param(quantizers, source_width, source_height)
    frac = unit_model.resolve_frac(cal, None if frac is None else check_int("frac", frac, 0, unit_model.MAX_FRAC))
    for name, sig in (("start", start), ("enable", enable), ("busy", busy), ("done", done)):
        check_signal(name, sig, width=1)
    if not isinstance(coord, CoordPair):
        raise block_error(f"port coord must be a CoordPair, got {type(coord).__name__}")
    if (coord.source_width, coord.source_height, coord.frac) != (cal.source_width, cal.source_height, frac):
        raise block_error(f"port coord is sized for {coord.source_width}x{coord.source_height} images and frac "
                         f"{coord.frac}; this warper has {cal.source_width}x{cal.source_height} and frac {frac}")
    check_distinct(dict(busy=busy, done=done, coord_valid=coord.valid, coord_xl=coord.xl, coord_yl=coord.yl,
                        coord_xr=coord.xr, coord_yr=coord.yr, coord_oor_l=coord.oor_l, coord_oor_r=coord.oor_r,
                        coord_eol=coord.eol, coord_eof=coord.eof),
                   dict(clk=clk, rst=rst, start=start, enable=enable, coord_read_ack=coord.read_ack))
    w, h = cal.width, cal.height
    if w < 2 or h < 2:
        raise block_error(f"parameter quantizers: the rectified image must be at least 2x2 pixels, got {w}x{h}")
    nb = unit_model.coord_bits(cal, frac)
    nx, ny = coord.x_format.wl, coord.y_format.wl

    # --- counters: xs = 4 x + select (X-L, Y-L, X-R, Y-R), y
    running = Signal(bool(0))
    xs = Signal(intbv(0, min=0, max=4 * w))
    yc = Signal(intbv(0, min=0, max=h))
    x_in = Signal(intbv(0)[unit_model.int_bits(w):])
    y_in = Signal(intbv(0)[unit_model.int_bits(h):])
    sel_in = Signal(intbv(0)[3:])
    tag_in = Signal(intbv(0)[2:])  # bit 0 eol, bit 1 eof of the coordinate's pixel
    last_x, last = 4 * w - 1, 4 * (w - 1)

    xtop = len(xs)

    @always_comb
    def feed():
        x_in.next = xs[xtop:2]
        y_in.next = yc
        sel_in.next = concat(running, xs[2:])  # valid, camera, coordinate (thesis Table 4.3)
        if xs >= last and yc == h - 1:
            tag_in.next = 3
        elif xs >= last:
            tag_in.next = 1
        else:
            tag_in.next = 0

    # --- the calculation unit and the tags that travel beside it
    pipe_en = Signal(bool(0))
    u_coord = Signal(intbv(0)[nb:])
    u_oor = Signal(bool(0))
    u_sel = Signal(intbv(0)[3:])
    u_tag = Signal(intbv(0)[2:])
    unit = poly_unit(clk, rst, pipe_en, x_in, y_in, sel_in, u_coord, u_oor, u_sel, coef, quantizers=cal, frac=frac)
    tags = tag_delay(clk, pipe_en, tag_in, u_tag, clocks=unit_model.LATENCY)

    # --- the double buffer (r2full is coord.valid; internal copies of the outputs read back)
    r1full, r2full, busy_r, eof2 = Signal(bool(0)), Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    take = Signal(bool(0))
    capture = Signal(bool(0))  # the unit's output is consumed on this edge
    yr_out = Signal(bool(0))   # ... and it is Y-R: a pair is complete
    to_r2 = Signal(bool(0))    # R1 + Y-R -> R2
    idx = Signal(intbv(0)[2:])

    @always_comb
    def control():
        pipe_en.next = enable and not r1full
        take.next = enable and r2full and coord.read_ack
        capture.next = enable and not r1full and u_sel[2]
        idx.next = u_sel[2:]

    @always_comb
    def control2():
        yr_out.next = capture and idx == 3
        to_r2.next = capture and idx == 3 and (take or not r2full)

    @always_comb
    def outputs():
        coord.valid.next = r2full
        coord.eof.next = eof2
        busy.next = busy_r

    @always_seq(clk.posedge, reset=rst)
    def fsm():
        if enable:
            done.next = 0
            # counters
            if start and not busy_r:
                running.next = 1
                busy_r.next = 1
                xs.next = 0
                yc.next = 0
            elif running and not r1full:  # the unit takes a coordinate
                if xs == last_x:
                    xs.next = 0
                    if yc == h - 1:
                        running.next = 0
                    else:
                        yc.next = yc + 1
                else:
                    xs.next = xs + 1
            # the buffer levels
            if r1full:
                if take:
                    r1full.next = 0
            elif r2full:
                if yr_out and not take:
                    r1full.next = 1
                elif take and not yr_out:
                    r2full.next = 0
            elif yr_out:
                r2full.next = 1
            if take and eof2:
                done.next = 1
                busy_r.next = 0

    # R1: X-L, Y-L, X-R (and Y-R when R2 is still full); flags accumulate per side.
    xl1, xr1 = Signal(intbv(0)[nx:]), Signal(intbv(0)[nx:])
    yl1, yr1 = Signal(intbv(0)[ny:]), Signal(intbv(0)[ny:])
    oorl1, oorr1 = Signal(bool(0)), Signal(bool(0))
    tag1 = Signal(intbv(0)[2:])

    # Reset too, so that the outputs are defined (0) from the reset on, before the first pair.
    @always_seq(clk.posedge, reset=rst)
    def registers():
        if capture:
            if idx == 0:
                xl1.next = u_coord[nx:]
                oorl1.next = u_oor
            elif idx == 1:
                yl1.next = u_coord[ny:]
                oorl1.next = oorl1 or u_oor
            elif idx == 2:
                xr1.next = u_coord[nx:]
                oorr1.next = u_oor
            elif not to_r2:
                yr1.next = u_coord[ny:]
                oorr1.next = oorr1 or u_oor
                tag1.next = u_tag
        if to_r2:
            coord.xl.next = xl1
            coord.yl.next = yl1
            coord.xr.next = xr1
            coord.yr.next = u_coord[ny:]
            coord.oor_l.next = oorl1
            coord.oor_r.next = oorr1 or u_oor
            coord.eol.next = u_tag[0]
            eof2.next = u_tag[1]
        elif r1full and take:
            coord.xl.next = xl1
            coord.yl.next = yl1
            coord.xr.next = xr1
            coord.yr.next = yr1
            coord.oor_l.next = oorl1
            coord.oor_r.next = oorr1
            coord.eol.next = tag1[0]
            eof2.next = tag1[1]

    return feed, unit, tags, control, control2, outputs, fsm, registers
