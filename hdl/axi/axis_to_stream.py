"""AXI4-Stream video (Xilinx UG934) -> image stream: frames of the stated geometry only, reset tokens for the rest."""

from myhdl import Signal, always_comb, always_seq, block, intbv

from eyestereo.hdl.axi.bridge_checks import check_bridge
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH


@block
def axis_to_stream(clk, rst, sink, source, error, *, width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT):
    """Turn AXI4-Stream video into an image stream of ``width`` x ``height`` frames.

    Transfers are counted into lines and frames: ``tuser`` (SOF) starts a frame at pixel (0, 0), ``tlast``
    (EOL) must come with pixel ``width - 1`` of every line, and a frame ends with its pixel
    (``width - 1``, ``height - 1``), which goes out with ``eol`` and ``eof``. Whatever does not fit that
    geometry is not passed on as pixels:

    * a line that ends early (``tlast`` before pixel ``width - 1``) or late (no ``tlast`` on it), or an
      SOF inside a frame (UG934's early SOF: a cut frame, e.g. from a
      :func:`~eyestereo.hdl.axi.stream_to_axis.stream_to_axis` that overflowed): the frame in progress is
      aborted with a **reset token** on ``source`` and ``error`` pulses; after a faulty line the
      bridge waits for the next SOF, after an early SOF that SOF starts the next frame at once;
    * transfers before the first SOF (after ``rst``, a fault or a finished frame) are dropped: after
      ``rst`` silently (joining a video stream mid-frame), between frames with one ``error`` pulse
      (a frame with too many lines).

    So ``source`` carries only whole frames of the stated geometry, each a complete frame or cut by a
    reset token, which every eyestereo block takes as "abort this frame".

    ``tready`` is high except in the clock after an early SOF (the token takes that clock's output
    beat; the SOF pixel follows) and during ``rst``: the image stream has no back-pressure, so the
    bridge never holds the AXI side back otherwise.

    Ports:
        clk: clock, rising edge.
        rst: synchronous reset, active high.
        sink: :class:`~eyestereo.hdl.interfaces.axis.AxiStream` slave (``tuser`` = SOF, ``tlast`` = EOL).
        source: :class:`~eyestereo.hdl.interfaces.stream.ImageStream` (mono) of the same pixel width.
        error: output, one-clock pulse per geometry fault (see above).

    Parameters:
        width, height: frame size, 1..4096 each.

    Latency: 1 clock from transfer to image-stream beat (2 for an SOF that follows an early-SOF token).

    Resources: column and row counters, the output registers, one held word; no memory, no multipliers.

    Handshakes: AXI4-Stream video (``hdl/interfaces/axis.py``) in, the image stream (``hdl/interfaces/stream.py``) out.
    An early SOF in 4x2 frames (``tok``: the reset token; WaveDrom: ``docs/wavedrom/axis_to_stream_early_sof.json``)::

        cycle    0    1    2    3    4    5    6
        tvalid   #    #    #    #    #    #    _
        tready   #    #    #    #    _    #    #
        tuser    #    _    _    #    _    _    .
        tlast    _    _    _    _    _    _    .
        tdata   0,0  1,0  2,0  0,0  1,0  1,0   .
        valid    _    #    #    #    #    #    #
        data     .   0,0  1,0  2,0  tok  0,0  1,0
        eof      .    _    _    _    #    _    _
        error    _    _    _    _    #    _    _

    The SOF in cycle 3 comes after 3 pixels of line 0: the frame is aborted with a token, the SOF
    pixel follows one clock later, and ``tready`` is low for that clock (the next transfer waits).
    """
    dw, width, height = check_bridge(clk, rst, ("source", source), ("sink", sink), ("error", error),
                                     outputs=("source", "error"), width=width, height=height)

    x = Signal(intbv(0, min=0, max=width))  # position of the next pixel in the frame in progress
    y = Signal(intbv(0, min=0, max=height))
    cx = Signal(intbv(0, min=0, max=width))  # position of this clock's pixel: (0, 0) for an SOF
    cy = Signal(intbv(0, min=0, max=height))
    in_frame = Signal(bool(0))  # a frame is in progress: the next transfer is pixel (x, y)
    synced = Signal(bool(0))  # an SOF was seen since rst or the last fault (drops after that are faults)
    held = Signal(bool(0))  # the SOF pixel after an early-SOF token waits in held_data
    held_data = Signal(intbv(0)[dw:])
    pixel = Signal(intbv(0)[dw:])
    beat = Signal(bool(0))
    ready = Signal(bool(0))
    at_end = Signal(bool(0))  # this clock's pixel ends its line
    last = Signal(bool(0))  # ... and its frame

    @always_comb
    def position():
        if sink.tuser and not held:
            cx.next = 0
            cy.next = 0
        else:
            cx.next = x
            cy.next = y

    @always_comb
    def decode():
        pixel.next = sink.tdata[dw:]
        beat.next = sink.tvalid and ready
        at_end.next = cx == width - 1
        last.next = (cx == width - 1) and (cy == height - 1)
        sink.tready.next = ready

    @always_seq(clk.posedge, reset=rst)
    def control():
        source.valid.next = 0
        error.next = 0
        ready.next = 1
        emit = False
        abort = False  # a reset token (data 0) and an error pulse end the frame in progress
        if held:
            # Pixel (0, 0) of the frame whose early SOF was answered with a token in the clock before
            # (x and y were set to 0 then).
            held.next = 0
            source.data.next = held_data
            emit = True
        elif beat:
            if sink.tuser and in_frame:
                # Early SOF: abort the frame in progress, keep the SOF pixel for the next clock.
                abort = True
                held.next = 1
                held_data.next = pixel
                ready.next = 0
                synced.next = 1
                x.next = 0
                y.next = 0
            elif sink.tuser or in_frame:
                if sink.tuser:
                    synced.next = 1
                if sink.tlast != at_end:
                    # The line ends early or late: abort the frame, wait for the next SOF.
                    abort = True
                    synced.next = 0
                else:
                    source.data.next = pixel
                    emit = True
            elif synced:
                # A transfer between frames: the frame before had too many lines. Drop until an SOF.
                error.next = 1
                synced.next = 0
        if abort:
            source.valid.next = 1
            source.data.next = 0
            source.eol.next = 0
            source.eof.next = 1
            error.next = 1
            in_frame.next = 0
        if emit:
            source.valid.next = 1
            source.eol.next = at_end
            source.eof.next = last
            in_frame.next = not last
            if at_end:
                x.next = 0
                if last:
                    y.next = 0
                else:
                    y.next = cy + 1
            else:
                x.next = cx + 1
                y.next = cy

    return position, decode, control
