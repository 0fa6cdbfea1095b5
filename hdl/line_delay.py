"""Line delay: the pixel one line above, from a line FIFO in inferred block RAM (thesis Fig. 6.8)."""

from myhdl import Signal, always, always_seq, block, intbv

from eyestereo.tools.stream import check_geometry

MAX_DATA_WIDTH = 36


@block
def line_delay(clk, rst, sink, source, *, width: int = 352, height: int = 288):
    """Delay a stream's data by one line: ``source`` pixel (x, y) carries ``sink`` pixel (x, y-1).

    A ``width``-deep memory addressed by the column counter: each pixel beat reads the word stored one
    line earlier at its column and writes itself in its place (read-before-write). Only pixel beats
    advance it; ``eof`` (end of frame or reset token) clears the column counter, so every frame starts
    at address 0. The memory itself has no reset, so the first line of each frame comes out with
    unspecified data (the last line of the frame before, after a whole frame).

    Ports:
        clk: clock, rising edge.
        rst: synchronous reset, active high; clears the control registers, not the memory.
        sink: :class:`~eyestereo.hdl.stream.ImageStream`, 1..36 data bits.
        source: ImageStream of the same data width; same frames, one clock later. With stereo
            streams (``stereo=True``) ``cam`` is forwarded with the beat; the memory does not
            separate the cameras (interleave whole frames, not lines).

    Parameters:
        width: pixels per line (1..4096), the memory depth.
        height: lines per frame (1..4096); only checked, the block does not count lines.

    Latency: 1 clock; 1 line in the data.

    Resources: one RAMB16 for width x data_width up to 512x36 / 1024x18 / 2048x9 (Spartan-3E),
    a column counter and the output flags; no multipliers.
    """
    check_geometry(width, height)
    dw = len(sink.data)
    if dw > MAX_DATA_WIDTH:
        raise ValueError(f"line_delay data width is {dw} bits, at most {MAX_DATA_WIDTH} fit one block RAM word")
    if len(source.data) != dw:
        raise ValueError(f"line_delay source data width {len(source.data)} differs from sink's {dw}")

    if getattr(sink, "stereo", False) != getattr(source, "stereo", False):
        raise ValueError("line_delay sink and source must both be stereo streams (with cam) or both mono")

    mem = [Signal(intbv(0)[dw:]) for _ in range(width)]
    col = Signal(intbv(0, min=0, max=width))
    pixel = Signal(bool(0))  # a valid beat that is not a reset token

    @always(clk.posedge)
    def ram():
        # No reset here: a memory with a reset cannot be mapped to block RAM.
        if pixel:
            mem[col].next = sink.data
            source.data.next = mem[col]

    @always_seq(clk.posedge, reset=rst)
    def control():
        source.valid.next = sink.valid
        source.eol.next = sink.eol
        source.eof.next = sink.eof
        if sink.valid:
            if sink.eof or col == width - 1:
                col.next = 0
            else:
                col.next = col + 1

    @always(sink.valid, sink.eol, sink.eof)
    def decode():
        pixel.next = sink.valid and (sink.eol or not sink.eof)

    insts = [ram, control, decode]
    if sink.stereo:
        @always_seq(clk.posedge, reset=rst)
        def camera():
            source.cam.next = sink.cam

        insts.append(camera)
    return insts
