"""The rectification unit: calibration in, rectified stereo stream out (thesis 4.3, Fig. 4.2)."""

from __future__ import annotations

from myhdl import Signal, always_comb, block

from eyestereo.hdl.common.checks import (block_error, check_clock, check_distinct, check_int, check_reset,
                                         check_signal, check_stream)
from eyestereo.hdl.interfaces.coord_pair import CoordPair
from eyestereo.hdl.interfaces.fetch_port import check_fetch
from eyestereo.hdl.rectify.calibration import calibration_param
from eyestereo.hdl.rectify.coordinate_warper import FIRST_PAIR, coordinate_warper
from eyestereo.hdl.rectify.fetch_interpolate import DEFAULT_DEPTH, fetch_interpolate
from eyestereo.hdl.rectify.fetch_interpolate import FIRST_PIXEL as FETCH_FIRST_PIXEL
from eyestereo.tools.models import fetch_interpolate as fi_model
from eyestereo.tools.models import poly_unit as unit_model

__all__ = ["FIRST_PIXEL", "rectifier"]

#: Clocks from the ``start`` clock to the first output beat with a memory answering at once (both sides
#: of the first pixel in range): the warper's first pair, then the fetch and the interpolation.
FIRST_PIXEL = FIRST_PAIR + FETCH_FIRST_PIXEL


@block
def rectifier(clk, rst, start, fetch, source, busy, coef=None, *, quantizers=None,
              frac: int | None = unit_model.DEFAULT_FRAC, source_width: int | None = None,
              source_height: int | None = None, depth: int = DEFAULT_DEPTH):
    """Rectified left and right images of the frames in memory, as one 8-bit stereo stream.

    :func:`~eyestereo.hdl.rectify.coordinate_warper.coordinate_warper` (x/y counters, the calculation unit, the
    coordinate pairs) feeds :func:`~eyestereo.hdl.rectify.fetch_interpolate.fetch_interpolate` (fetch port,
    reuse of the previous neighbourhood, bilinear multiply-accumulate, the stereo stream). ``start``
    rectifies one frame: ``width x height`` (the calibration's rectified size) stereo pixel pairs in
    raster order, left pixel (x, y) with ``cam`` 0 then right pixel (x, y) with ``cam`` 1, ``eol``/``eof``
    on both beats; pixels whose source point is out of range are 0. The stream has no back-pressure and
    is an ordinary stereo :class:`~eyestereo.hdl.interfaces.stream.ImageStream` (no reset tokens: ``rst`` abandons a
    frame).

    Timing of a frame::

        cycle     s   s+1  ...  s+22  ...            e
        start     #    _          _                  .
        busy      _    #    #     #    ...     #     _
        source    _    _    _     L0,0  R0,0 ...  R(w-1,h-1)   (eof on the last two beats)

    Ports:
        clk, rst: clock; synchronous active-high reset (back to idle, a frame abandoned; let the memory
            side finish or reset it too).
        start: in, 1 bit: begin a frame (ignored while ``busy``).
        fetch: :class:`~eyestereo.hdl.interfaces.fetch_port.FetchPort` (master) sized for the camera images.
        source: 8-bit stereo :class:`~eyestereo.hdl.interfaces.stream.ImageStream`.
        busy: out, 1 bit: high from the clock after ``start`` until the frame's last beat is on
            ``source``.
        coef: optional :class:`~eyestereo.hdl.rectify.poly_unit.CoefPort` (run-time coefficients, see
            :func:`~eyestereo.hdl.rectify.poly_unit.poly_unit`).

    Parameters:
        quantizers, frac, source_width, source_height: the calibration (a spec, a ``quantizers.json`` or a
            :class:`~eyestereo.tools.models.poly_unit.Calibration`; default: the synthetic rig) and the
            coordinates' fraction bits (default q24's, at most 8 here), as for the warper.
        depth: sides in flight in the fetch/interpolate unit (1..16, default 4).

    Latency: the first beat 26 clocks after ``start`` with an immediate memory (:data:`FIRST_PIXEL`); then
    8 clocks per stereo pixel pair with both sides in range (the two multipliers do four steps per
    side), fewer where a side is black; the memory's wait clocks add where the queue cannot hide them.

    Resources: the warper's (with its calculation unit, 10 MULT18X18 on the rig) and fetch/interpolate's
    (2 MULT18X18, two LUT-RAM FIFOs, 8 kept pixels); measured figures in docs/rectifier.md.
    """
    check_clock(clk)
    check_reset(rst)
    cal = calibration_param(quantizers, source_width, source_height)
    frac = unit_model.resolve_frac(cal, None if frac is None else check_int("frac", frac, 0, unit_model.MAX_FRAC))
    if frac > fi_model.MAX_FRAC:
        raise block_error(f"parameter frac={frac}: the interpolation takes at most {fi_model.MAX_FRAC} fraction "
                         f"bits (pass frac= explicitly)")
    check_signal("start", start, width=1)
    check_fetch("fetch", fetch)
    if (fetch.width, fetch.height) != (cal.source_width, cal.source_height):
        raise block_error(f"port fetch is sized for {fetch.width}x{fetch.height} images; the calibration's camera "
                         f"images are {cal.source_width}x{cal.source_height}")
    check_stream("source", source, width=8, stereo=True)
    check_signal("busy", busy, width=1)
    check_distinct(dict(fetch_req_valid=fetch.req_valid, fetch_req_x=fetch.req_x, fetch_req_y=fetch.req_y,
                        fetch_req_cam=fetch.req_cam, fetch_req_mask=fetch.req_mask, source=source, busy=busy),
                   dict(clk=clk, rst=rst, start=start, fetch_req_ready=fetch.req_ready,
                        fetch_rsp_valid=fetch.rsp_valid, fetch_rsp_idx=fetch.rsp_idx, fetch_rsp_data=fetch.rsp_data))
    depth = check_int("depth", depth, 1, 16)

    coord = CoordPair(cal.source_width, cal.source_height, frac)
    enable = Signal(bool(1))  # undriven: a constant 1 in the VHDL (the warper never pauses)
    w_busy, w_done, f_busy = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    warper = coordinate_warper(clk, rst, start, enable, w_busy, w_done, coord, coef, quantizers=cal, frac=frac)
    fi = fetch_interpolate(clk, rst, coord, fetch, source, f_busy, depth=depth)

    @always_comb
    def busy_out():
        busy.next = w_busy or f_busy

    return warper, fi, busy_out
