"""Stream clock-domain crossing: an image stream, mono or stereo, from one clock into another (async_fifo inside)."""

from myhdl import Signal, always_comb, block, concat

from eyestereo.hdl.streaming.async_fifo import async_fifo, check_depth
from eyestereo.hdl.common.checks import check_clock, check_distinct, check_reset, check_signal, check_stream
from eyestereo.hdl.interfaces.queue import QueuePort
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.tools.models.stream_cdc import fifo_width


@block
def stream_cdc(wclk, wrst, sink, rclk, rrst, source, dropped, *, depth: int = 16):
    """Carry an image stream into another clock: the stereo stream from the 100 MHz memory clock (the
    rectifier) into the Harris clock (50 MHz), or any stream between unrelated clocks.

    An :func:`~eyestereo.hdl.streaming.async_fifo.async_fifo` does the crossing (Gray pointers, two-flop
    synchronisers, whole frames or a reset token, dropped frames counted); this block adapts the image
    stream to it on both sides:

    * a stereo stream's ``cam`` travels in the FIFO word, and so do each beat's own ``eol``/``eof``; the
      FIFO's frame logic sees ``eol``/``eof`` only on the right camera's beat (and on reset tokens), so a
      frame ends after its last *pair*: an overflow never cuts a frame between the left and the right
      pixel of its last (x, y) without a token (the FIFO's guarantee holds per stereo frame);
    * the read side has no back-pressure (``ready`` is tied high inside): every word is presented as
      soon as it is in the output register, as a beat of the image stream in the read clock.

    Rate: the crossing needs the read side to take beats at least as fast as they come on average. The
    rectifier's coordinate warper makes a coordinate pair every 4 memory clocks at best, each giving a left
    and a right pixel: at most 2 beats per 4 clocks at 100 MHz, 50 M beats/s, exactly what the Harris
    clock takes at 50 MHz (one beat per clock). Sustained, the SRAM holds the rectifier below that: its
    pixels take 4 SRAM reads each (2 with the 2-read fetch), 8 (4) words per pair at one word per clock,
    while the cameras' writes take 18 % of the SRAM's clocks: at most 20 M (41 M) beats/s. So the
    read side is faster on average and the FIFO holds only the bursts and the synchronisers' delay:
    ``depth=16`` (LUT-RAM) is plenty; the benches measure at most 8 entries in use. A source faster
    than the reader overflows it: the frame is then cut with a reset token and counted in ``dropped``.
    Reset tokens of the sink pass only when they cut a frame of which words are in the FIFO (the queue's
    rule, :mod:`eyestereo.hdl.interfaces.queue`); the read side's chain starts from ``rrst``.

    Ports:
        wclk, wrst: write clock and its synchronous active-high reset (the sink's producer shares it).
        sink: :class:`~eyestereo.hdl.interfaces.stream.ImageStream`, any data width, mono or stereo (write clock).
        rclk, rrst: read clock and its synchronous active-high reset (``source.valid`` low during it).
        source: ImageStream of the sink's width and kind (read clock).
        dropped: 16-bit output, read clock: frames dropped since configuration (the FIFO's counter).

    Parameters:
        depth: FIFO entries, a power of two in 4..16384 (default 16).

    Latency: a beat written at a write edge comes out from the third read edge after it (two
    synchroniser flops and the FIFO's registered read), when the FIFO was empty.

    Resources: the FIFO (depth x (data + 2 (mono) or data + 5 (stereo)) bits, LUT-RAM at depth 16) and
    its pointers; stereo 8-bit pixels, depth 16 (make synth, Yosys xc3se): 103 LUT + 13 LUT-RAM, 137 FF;
    nextpnr-ecp5 205.6 MHz (wclk), 247.3 MHz (rclk).
    """
    check_clock(wclk, "wclk")
    check_reset(wrst, "wrst")
    check_stream("sink", sink, stereo=None)
    check_clock(rclk, "rclk")
    check_reset(rrst, "rrst")
    check_stream("source", source, width=sink.data_width, stereo=sink.stereo)
    check_signal("dropped", dropped, width=16)
    check_distinct(dict(source=source, dropped=dropped), dict(wclk=wclk, wrst=wrst, sink=sink, rclk=rclk, rrst=rrst))
    depth = check_depth(depth)
    dw = sink.data_width
    fw = fifo_width(dw, sink.stereo)
    # A mono stream is the FIFO's own word (data, eol, eof): it goes in unchanged.
    fin = ImageStream(fw) if sink.stereo else sink
    q = QueuePort(fw)
    q.ready = Signal(bool(1))  # never driven: the reader takes every word (no back-pressure downstream)
    fifo = async_fifo(wclk, wrst, fin, rclk, rrst, q, dropped, depth=depth)

    if not sink.stereo:
        @always_comb
        def r_side():
            source.valid.next = q.valid
            source.data.next = q.data
            source.eol.next = q.eol
            source.eof.next = q.eof

        return fifo, r_side

    @always_comb
    def w_side():
        fin.valid.next = sink.valid
        fin.data.next = concat(sink.eof, sink.eol, sink.cam, sink.data)
        # the FIFO's frame ends with the right camera's beat; a reset token ends it whatever its cam
        fin.eol.next = sink.eol and sink.cam
        fin.eof.next = sink.eof and (sink.cam or not sink.eol)

    @always_comb
    def r_side():
        source.valid.next = q.valid
        source.data.next = q.data[dw:0]
        source.cam.next = q.data[dw]
        if q.eof and not q.eol:  # a reset token (the sink's, or the FIFO's own after an overflow)
            source.eol.next = 0
            source.eof.next = 1
        else:
            source.eol.next = q.data[dw + 1]
            source.eof.next = q.data[dw + 2]

    return fifo, w_side, r_side
