"""Census transform of a 5x5 or 7x7 window, both cameras of a stereo stream, borders defined (issue 28)."""

from myhdl import ConcatSignal, Signal, always, always_comb, block, intbv

from eyestereo.hdl.common import en_reg
from eyestereo.hdl.common.checks import (block_error, check_choice, check_clock, check_distinct, check_frame,
                                         check_reset, check_stream)
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.hdl.streaming.flush_control import flush_control
from eyestereo.hdl.streaming.window import column_taps, tap_latency, window_row
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH
from eyestereo.tools.models.census import WINDOWS, census_bits


def latency(window: int) -> int:
    """Clocks from the sink beat of input (x + r, y + r) to output (x, y): the input register 1, the
    column taps ``window``, the window row 1, the output register 1."""
    return 1 + tap_latency(window) + 2


@block
def census(clk, rst, sink, source, *, window: int = 5, width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT):
    """Census words: ``source`` pixel (x, y) has one bit per neighbour of the window centred on input (x, y).

    The bit is 1 when the neighbour is strictly below the centre, 0 otherwise and 0 for a neighbour
    outside the image; bits in the window's raster order, the top-left neighbour the most significant,
    the centre left out (:func:`eyestereo.tools.models.census.census`, bit for bit on every pixel,
    border pixels included). A stereo stream is transformed camera by camera in one datapath (stereo
    line delays, window rows of 2N - 1 registers); a mono stream works the same way.

    The border rule is a mask, not a multiplexer of pixels: the output raster position (x, y) gives
    N - 1 row flags (y + dy inside the image) and N - 1 column flags (x + dx inside), and each census
    bit is its comparison ANDed with its row's and its column's flag (one gate per bit).

    Bottom rows: the output runs r lines + r pixels behind the input, so the last r lines of a frame
    are computed after the frame's last beat. Their windows still need the image's last lines, which
    sit in the line delays: the block pushes its own flush beats through the line delays (in clocks
    the sink leaves free, or the next frame's beats standing in for them) until the frame's tail is
    out (:func:`~eyestereo.hdl.streaming.flush_control.flush_control`, which also counts the output
    raster and gives the border flags; median3 shares it).

    Ports:
        clk, rst: clock and synchronous active-high reset (control only; the line delays and the
            window registers have none).
        sink: ImageStream, 8-bit grey pixels, stereo (left and right beat of each pixel in turn) or mono.
        source: ImageStream of the sink's kind, ``window**2 - 1`` bits (24 or 48): the census word.

    Parameters:
        window: 5 or 7 (:data:`eyestereo.tools.models.census.WINDOWS`).
        width, height: frame size, each at least ``window`` (and at most FRAME_MAX).

    Latency: :func:`latency` = ``window + 3`` clocks (8 for 5x5, 10 for 7x7) after the (camera's) input
    pixel (x + r, y + r) (r = window // 2): r lines + r pixels + window + 3 clocks (stereo: 2 (r width
    + r) beats + window + 3 clocks). The last r lines + r pixels of a frame come after its last beat:
    one beat per free clock (stereo: a left and a right beat in two clocks following a free clock),
    or, when the next frame has begun, one per beat of the next frame. Measured by the bench
    (tests/hdl/test_census.py asserts it on every non-tail pixel).

    Resources: ``window - 1`` line delays of 8 bits (stereo: 2 x width words each; one RAMB16 each
    for width <= 1024), ``window**2 - 1`` 8-bit comparators, the window's registers (N x N, stereo
    N x (2N - 1), of 8 bits), the tap alignment registers, 2 (N - 1) position comparators; no
    multipliers. Measured (``synth --block census``, Yosys ``synth_xilinx -family xc3se``, 352x288
    stereo): 5x5 363 LUT, 680 FF, 276 carry cells, 4 RAMB16; 7x7 613 LUT, 1258 FF, 422 carry cells,
    6 RAMB16. Most flip-flops are the stereo window rows (N x (2N - 1) x 8) and the tap alignment.

    Timing: each comparison reads two window registers and ends in the output register (an 8-bit
    compare and a 3-input AND); the centre register fans out to all ``window**2 - 1`` comparators.
    The block RAM outputs are registered before anything reads them (:func:`column_taps`). ECP5-25
    speed 6, nextpnr seeds 1-4: 5x5 138.1 / 146.4 / 147.3 MHz (min / median / max), 7x7 131.5 /
    135.1 / 137.9 MHz, both above 1.1 x the 100 MHz goal; the slowest paths are the line delays'
    block RAM reads (RAM to RAM, RAM to its output register), not the census logic.
    """
    check_clock(clk)
    check_reset(rst)
    window = check_choice("window", window, WINDOWS)
    check_stream("sink", sink, width=8, stereo=None)
    nbits = census_bits(window)
    check_stream("source", source, width=nbits, stereo=sink.stereo)
    check_distinct(dict(source=source), dict(clk=clk, rst=rst, sink=sink))
    width, height = check_frame(width, height)
    if width < window or height < window:
        # smaller frames would leave the output less than one window behind the input (no tail)
        raise block_error(f"frame {width}x{height} is smaller than the {window}x{window} census window: width and "
                          f"height must each be at least {window}")
    stereo = sink.stereo
    n, r = window, window // 2

    # --- control: the beats into the line delays (the sink's and the flush beats), the output raster and
    # its flags, the border flags of the emitted pixel in the clock the window rows hold its window
    shift = ImageStream(8, stereo=stereo)
    row_ok = [Signal(bool(1)) for _ in range(n)]
    col_ok = [Signal(bool(1)) for _ in range(n)]
    insts = [flush_control(clk, rst, sink, shift, source, row_ok, col_ok, width=width, height=height,
                           latency=latency(n))]

    # --- data path: N taps of one column, then N window rows of N columns
    taps = [Signal(intbv(0)[8:]) for _ in range(n)]
    tap_valid = Signal(bool(0))
    insts.append(column_taps(clk, rst, shift, taps, tap_valid, width=width, height=height))
    rows = []
    for t in taps:
        links, row = window_row(t, n, stereo=stereo)
        insts += [en_reg(clk, tap_valid, d, q) for d, q in links]
        rows.append(row)
    centre = rows[r][r]
    bits = []
    for wy in range(n):
        for wx in range(n):
            if wy == r and wx == r:
                continue
            b = Signal(bool(0))
            # row[j] is the column j back: window column wx (0 = left) is j = n - 1 - wx
            insts.append(census_bit(rows[wy][n - 1 - wx], centre, row_ok[wy], col_ok[wx], b))
            bits.append(b)
    word = ConcatSignal(*bits)  # the first (top-left) bit is the most significant

    @always(clk.posedge)
    def outreg():
        source.data.next = word

    insts.append(outreg)
    return insts


@block
def census_bit(neighbour, centre, row_ok, col_ok, bit):
    """One census bit: the neighbour below the centre, and inside the image (the border mask)."""

    @always_comb
    def compare():
        bit.next = neighbour < centre and row_ok and col_ok

    return compare
