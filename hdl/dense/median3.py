"""3 x 3 median of 16-bit disparity codes, the invalid code 0xFFFF the largest, borders passed through (issue 28)."""

from myhdl import Signal, always, always_comb, block, intbv

from eyestereo.hdl.common import delay, en_reg
from eyestereo.hdl.common.checks import (block_error, check_clock, check_distinct, check_frame, check_reset,
                                         check_stream)
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.hdl.streaming.flush_control import flush_control
from eyestereo.hdl.streaming.window import column_taps, tap_latency, window_row
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH

#: bits of a disparity code (:mod:`eyestereo.tools.models.median3`)
CODE_BITS = 16
#: the window is 3 x 3
SIZE = 3
#: Clocks from the sink beat of input (x + 1, y + 1) to output (x, y): the input register 1, the column
#: taps 3, the sorted window row 1, the row / column reduction 1, the median of three (the output
#: register) 1.
LATENCY = 1 + tap_latency(SIZE) + 3


@block
def median3(clk, rst, sink, source, *, width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT):
    """Median filter: ``source`` pixel (x, y) is the median of the nine codes of the 3 x 3 window centred on
    sink pixel (x, y), or that pixel itself on the image's border.

    Bit for bit :func:`eyestereo.tools.models.median3.median3`: the median is the 5th smallest of the nine
    unsigned 16-bit codes, so the invalid code 0xFFFF needs no special case (it is the largest value); a
    pixel of the first or last row or column passes through unchanged. Mono streams only.

    The median network is the separable one of a 3 x 3 window: each column is sorted once, when it enters
    the window (the window row shifts sorted columns, so a column is sorted once, not three times); of the
    three sorted columns, the maximum of the smallest codes, the median of the middle ones and the minimum
    of the largest ones; the median of those three is the median of the nine. Every 3-input step
    (:func:`sort3`) compares its three inputs in parallel and selects by the three results, so each
    registered stage has one comparator's depth: five 3-input steps, 15 16-bit comparators (the 19
    compare-exchange cells of the usual 9-input median network chain 9 deep).

    Border: in the clock the window rows hold pixel (x, y)'s window, the border flags of
    :func:`~eyestereo.hdl.streaming.flush_control.flush_control` say whether it leaves the image; then
    the maximum of the smallest and the minimum of the largest codes are both replaced by the centre
    code, and the median of three, with two of them the centre, is the centre.

    Bottom rows: the output runs one line and one pixel behind the input; the frame's last line and pixel
    are computed after the frame's last beat from the block's own flush beats through the line delays,
    in the clocks the sink leaves free, or on the next frame's beats when it has begun
    (:func:`~eyestereo.hdl.streaming.flush_control.flush_control`, shared with census).

    Ports:
        clk, rst: clock and synchronous active-high reset (control only; the line delays and the data
            registers have none).
        sink: mono ImageStream of 16-bit disparity codes.
        source: mono ImageStream of 16-bit codes: the median-filtered map, the sink's frame size.

    Parameters:
        width, height: frame size, each at least 3 (and at most FRAME_MAX).

    Latency: :data:`LATENCY` = 7 clocks after input pixel (x + 1, y + 1): one line + one pixel + 7 clocks.
    The frame's last line + one pixel come after its last beat, one per free clock or, when the next frame
    has begun, one per beat of the next frame. A reset token passes on after 7 clocks. Measured by the
    bench (tests/hdl/test_median3.py asserts it on every non-tail pixel).

    Resources: 2 line delays of 16 bits (one RAMB16 each for width <= 1024), 15 16-bit comparators,
    flip-flops for the input register (16), the column taps' alignment (6 x 16), the sorted window
    (9 x 16), the centre (2 x 16), the reduced three (3 x 16) and the output (16); no multipliers.
    Measured (``synth --block median3``, Yosys ``synth_xilinx -family xc3se``, 352x288): 617 LUT,
    447 FF, 246 carry cells, 2 RAMB16.

    Timing: each stage is one 16-bit comparison and a three-way select between registers. ECP5-25
    speed 6, nextpnr seeds 1-4: 128.3 / 129.8 / 131.7 MHz (min / median / max), above 1.1 x the 100 MHz
    goal; the slowest paths are a line delay's block RAM read (RAM to its output register) and the column
    sort (tap register to the sorted window row), not the later stages.
    """
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, width=CODE_BITS)
    check_stream("source", source, width=CODE_BITS)
    check_distinct(dict(source=source), dict(clk=clk, rst=rst, sink=sink))
    width, height = check_frame(width, height)
    if width < SIZE or height < SIZE:
        # a smaller frame has no inner pixel, and the output would lag less than one window (no tail)
        raise block_error(f"frame {width}x{height} is smaller than the 3x3 median window: width and height must "
                          f"each be at least 3")

    # --- control: the beats into the line delays (the sink's and the flush beats), the output raster and
    # its flags, the border flags of the emitted pixel in the clock the window rows hold its window
    shift = ImageStream(CODE_BITS)
    row_ok = [Signal(bool(1)) for _ in range(SIZE)]
    col_ok = [Signal(bool(1)) for _ in range(SIZE)]
    insts = [flush_control(clk, rst, sink, shift, source, row_ok, col_ok, width=width, height=height,
                           latency=LATENCY)]

    def code():
        return Signal(intbv(0)[CODE_BITS:])

    # --- the column taps (rows y - 1, y, y + 1), sorted as they enter the window row
    taps = [code() for _ in range(SIZE)]
    tap_valid = Signal(bool(0))
    insts.append(column_taps(clk, rst, shift, taps, tap_valid, width=width, height=height))
    ranked = [code() for _ in range(SIZE)]  # smallest, middle, largest of the column
    insts.append(sort3(*taps, *ranked))
    rows = []  # rows[k][j]: rank k of the column j back
    for first in ranked:
        links, row = window_row(first, SIZE, stereo=False)
        insts += [en_reg(clk, tap_valid, d, q) for d, q in links]
        rows.append(row)
    # the centre code, unsorted: the middle tap one column back
    links, centre_row = window_row(taps[1], 2, stereo=False)
    insts += [en_reg(clk, tap_valid, d, q) for d, q in links]
    centre = centre_row[1]

    # --- the three candidates: max of the smallest, median of the middle, min of the largest codes
    low_max, mid_med, high_min = code(), code(), code()
    insts += [sort3(*rows[0], code(), code(), low_max), sort3(*rows[1], code(), mid_med, code()),
              sort3(*rows[2], high_min, code(), code())]
    inner = Signal(bool(0))
    lo_c, mid_c, hi_c = code(), code(), code()

    @always_comb
    def border():
        inner.next = row_ok[0] and row_ok[2] and col_ok[0] and col_ok[2]

    # on the border two of the three are the centre, so their median is the centre
    insts += [border, inner_or(clk, inner, low_max, centre, lo_c), delay(clk, mid_med, mid_c, clocks=1),
              inner_or(clk, inner, high_min, centre, hi_c)]

    # --- the median of the three, into the output register
    median = code()
    insts += [sort3(lo_c, mid_c, hi_c, code(), median, code()),
              delay(clk, median, source.data, clocks=1)]
    return insts


@block
def inner_or(clk, inner, value, centre, q):
    """``q``: ``value`` for a pixel inside the border, the ``centre`` code on it; registered."""

    @always(clk.posedge)
    def pick():
        q.next = centre
        if inner:
            q.next = value

    return pick


@block
def sort3(a, b, c, lo, mid, hi):
    """``lo``, ``mid``, ``hi``: the smallest, middle and largest of three unsigned values.

    The three comparisons run in parallel; each output selects by them (a three-way multiplexer after
    one comparator's delay, where compare-exchange cells would chain three deep). Equal values are
    ranked by position (a before b before c), which keeps the three ranks a permutation; the values
    selected do not depend on that choice. An output nobody reads is removed by synthesis.
    """
    ab, ac, bc = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))

    @always_comb
    def compare():
        ab.next = a > b
        ac.next = a > c
        bc.next = b > c

    @always_comb
    def select():
        # rank of a: ab + ac; of b: (not ab) + bc; of c: (not ac) + (not bc)
        if not ab and not ac:
            lo.next = a
        elif ab and not bc:
            lo.next = b
        else:
            lo.next = c
        if ab != ac:
            mid.next = a
        elif ab == bc:
            mid.next = b
        else:
            mid.next = c
        if ab and ac:
            hi.next = a
        elif bc and not ab:
            hi.next = b
        else:
            hi.next = c

    return compare, select
