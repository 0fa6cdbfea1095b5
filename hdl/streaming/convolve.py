"""General NxN convolution (correlation) with constant integer kernels, separable or not (thesis 6.2.1)."""

import numpy as np
from myhdl import Signal, always, always_comb, block, intbv

from eyestereo.hdl.common import delay, en_reg, range_signal, shift_add, signal_range
from eyestereo.hdl.common.checks import (block_error, check_clock, check_distinct, check_frame, check_int,
                                         check_reset, check_stream, checked)
from eyestereo.hdl.common.fixed import fx_signal
from eyestereo.hdl.streaming.window import column_taps, tap_latency, window_control, window_row
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH
from eyestereo.tools.models.convolve import check_kernel, output_format


@block
def convolve(clk, rst, sink, source, *, kernel=None, col=None, row=None, shift: int = 0,
             width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT):
    """``source`` pixel (x, y) = floor(sum k[i, j] * p(x - r + j, y - r + i) / 2**shift), r = N // 2.

    The window is centred on the output pixel (correlation, no kernel flip). Give ``kernel`` (NxN) for
    the inseparable form (N x N register window, row sums, then the total) or ``col`` and ``row``
    (1-D, kernel = outer(col, row)) for the separable form (vertical sums of each incoming column, a
    row of N registers, then the horizontal sum). Constant coefficients become shifts and adds.
    Pixels whose window leaves the image carry unspecified data (border treatment option 3).

    Ports:
        clk, rst: clock and synchronous active-high reset (control only).
        sink: ImageStream, unsigned pixels of any width up to 36 bits; mono only (a stereo stream
            is refused).
        source: ImageStream whose data width is :func:`eyestereo.tools.models.convolve.output_width`
            (two's complement when the kernel has negative coefficients).

    Parameters:
        kernel / col, row: integer coefficients, N = 3 or 5, |k| < 2**16.
        shift: right shift (floor) applied to the sum, >= 0.
        width, height: frame size, each at least N.

    Latency: N + 3 clocks after input pixel (x + r, y + r), i.e. r lines + r pixels + N + 3 clocks (the
    column taps N, the vertical sums or the row sums 1, the window row 1, the output register 1).

    Resources: N - 1 line delays (one RAMB16 each for width x data bits up to 512x36), adders and
    registers; no multipliers.
    """
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink)
    check_stream("source", source)
    check_distinct(dict(source=source), dict(clk=clk, rst=rst, sink=sink))
    dw = sink.data_width
    if dw > 36:
        raise block_error(f"port sink data is {dw} bits wide, at most 36 fit the line delays' block RAM words")
    k, separable = checked(check_kernel, kernel, col, row)
    n = k.shape[0]
    r = n // 2
    width, height = check_frame(width, height, min_size=n)
    shift = check_int("shift", shift, 0)
    fmt = output_format(k, dw, shift)
    bits = fmt.wl
    if source.data_width != bits:
        raise block_error(f"port source needs {bits} data bits for this kernel and shift, has {source.data_width}")

    taps = [Signal(intbv(0)[dw:]) for _ in range(n)]
    tap_valid = Signal(bool(0))
    insts = [column_taps(clk, rst, sink, taps, tap_valid, width=width, height=height)]

    if separable:
        cv = [int(c) for c in np.asarray(col, dtype=np.int64)]  # integral: checked by check_kernel
        rv = [int(c) for c in np.asarray(row, dtype=np.int64)]
        vlo = sum(min(c * 0, c * ((1 << dw) - 1)) for c in cv)
        vhi = sum(max(c * 0, c * ((1 << dw) - 1)) for c in cv)
        vsum = range_signal(vlo, vhi)
        vreg = range_signal(vlo, vhi)
        vvalid = Signal(bool(0))
        insts += [shift_add(list(zip(taps, cv)), vsum), delay(clk, vsum, vreg, clocks=1),
                  delay(clk, tap_valid, vvalid, clocks=1)]
        links, hregs = window_row(vreg, n, stereo=False)  # hregs[0] newest = rightmost column
        for src, h in links:
            insts.append(en_reg(clk, vvalid, src, h))
        total = _sum_sig(hregs, rv[::-1])
        insts.append(shift_add(list(zip(hregs, rv[::-1])), total))
    else:
        rowsums = []
        for i in range(n):
            links, w = window_row(taps[i], n, stereo=False)  # w[0] newest = rightmost column
            for src, reg in links:
                insts.append(en_reg(clk, tap_valid, src, reg))
            coeffs = [int(c) for c in k[i][::-1]]
            rs = _sum_sig(w, coeffs)
            rreg = range_signal(*signal_range(rs))
            insts += [shift_add(list(zip(w, coeffs)), rs), delay(clk, rs, rreg, clocks=1)]
            rowsums.append(rreg)
        total = _sum_sig(rowsums, [1] * n)
        insts.append(shift_add([(s, 1) for s in rowsums], total))

    scaled = fx_signal(fmt)

    @always_comb
    def scale():
        scaled.next = total >> shift

    @always(clk.posedge)
    def outreg():
        source.data.next = scaled[bits:]

    insts += [scale, outreg,
              window_control(clk, rst, sink, source, width=width, height=height, radius=r, latency=tap_latency(n) + 3)]
    return insts


def _sum_sig(sigs, coeffs):
    lo = hi = 0
    for s, c in zip(sigs, coeffs):
        a, b = signal_range(s)
        lo += min(a * c, b * c)
        hi += max(a * c, b * c)
    return range_signal(lo, hi)
