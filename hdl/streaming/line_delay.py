"""Line delay: the pixel one line above, from a line FIFO in inferred block RAM (thesis Fig. 6.8)."""

from myhdl import Signal, always, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.common.checks import block_error, check_clock, check_distinct, check_frame, check_reset, check_stream
from eyestereo.hdl.interfaces.stream import ImageStream

MAX_DATA_WIDTH = 36


@block
def line_delay(clk, rst, sink, source, *, width: int = 352, height: int = 288):
    """Delay a stream's data by one line: ``source`` pixel (x, y) carries ``sink`` pixel (x, y-1).

    A ``width``-deep memory addressed by the column counter: each pixel beat reads the word stored one
    line earlier at its column and writes itself in its place (read-before-write). Only pixel beats
    advance it; ``eof`` (end of frame or reset token) clears the column counter, so every frame starts
    at address 0. The memory itself has no reset, so the first line of each frame comes out with
    unspecified data (the last line of the frame before, after a whole frame).

    Stereo streams (``stereo=True`` on both ports, interleaved as in :mod:`eyestereo.hdl.interfaces.stream`: the
    left and the right pixel of each (x, y) in turn) are supported: the memory is ``2 * width`` deep,
    addressed by (column, ``cam``), so each camera's pixel (x, y) carries that camera's (x, y-1), and
    ``cam`` is forwarded with the beat. The column counter moves on with the right camera's beat.

    Ports:
        clk: clock, rising edge.
        rst: synchronous reset, active high; clears the control registers, not the memory.
        sink: :class:`~eyestereo.hdl.interfaces.stream.ImageStream`, 1..36 data bits, mono or stereo.
        source: ImageStream of the same data width and kind; same frames, one clock later.

    Parameters:
        width: pixels per line (1..4096), the memory depth (twice that for stereo streams).
        height: lines per frame (1..4096); only checked, the block does not count lines.

    Latency: 1 clock; 1 line in the data.

    Resources: one RAMB16 for width x data_width up to 512x36 / 1024x18 / 2048x9 (Spartan-3E; stereo:
    2 * width words), a column counter and the output flags; no multipliers.
    """
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, stereo=None)
    dw = sink.data_width
    if dw > MAX_DATA_WIDTH:
        raise block_error(f"port sink data is {dw} bits wide, at most {MAX_DATA_WIDTH} fit one block RAM word")
    if isinstance(source, ImageStream) and source.data_width != dw:
        raise block_error(f"port source data width {source.data_width} differs from sink's {dw}")
    check_stream("source", source, width=dw, stereo=sink.stereo)
    check_distinct(dict(source=source), dict(clk=clk, rst=rst, sink=sink))
    width, height = check_frame(width, height)

    stereo = sink.stereo
    depth = 2 * width if stereo else width
    mem = [Signal(intbv(0)[dw:]) for _ in range(depth)]
    col = Signal(intbv(0, min=0, max=width))
    addr = Signal(intbv(0, min=0, max=depth))
    step = Signal(bool(0))  # the column moves on (or is cleared) this clock
    pixel = Signal(bool(0))  # a valid beat that is not a reset token

    # The one difference between the kinds: the address and the beat that moves the column on.
    if stereo:
        @always_comb
        def address():
            addr.next = concat(col, sink.cam)
            # the column moves on with the right camera's beat; a reset token (either cam) clears it
            step.next = sink.valid and (sink.cam or (sink.eof and not sink.eol))

        @always_seq(clk.posedge, reset=rst)
        def camera():
            source.cam.next = sink.cam
    else:
        @always_comb
        def address():
            addr.next = col
            step.next = sink.valid

    @always(clk.posedge)
    def ram():
        # No reset here: a memory with a reset cannot be mapped to block RAM.
        if pixel:
            mem[addr].next = sink.data
            source.data.next = mem[addr]

    @always_seq(clk.posedge, reset=rst)
    def control():
        source.valid.next = sink.valid
        source.eol.next = sink.eol
        source.eof.next = sink.eof
        if step:
            if sink.eof or col == width - 1:
                col.next = 0
            else:
                col.next = col + 1

    @always(sink.valid, sink.eol, sink.eof)
    def decode():
        pixel.next = sink.valid and (sink.eol or not sink.eof)

    if stereo:
        return address, camera, ram, control, decode
    return address, ram, control, decode
