"""Image-stream protocol checker: passes a stream through and flags lines and frames of the wrong size."""

from myhdl import Signal, always, always_comb, always_seq, block, intbv

from eyestereo.hdl.common.checks import (check_bool, check_clock, check_distinct, check_frame, check_reset,
                                         check_signal, check_stream)
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH
from eyestereo.tools.models import stream_checker as model

LATENCY = 1


@block
def stream_checker(clk, rst, sink, source, error, code, *, width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT,
                   repair: bool = False):
    """Check that ``sink`` keeps the image-stream protocol for ``width`` x ``height`` frames; pass it on.

    Place it in front of any block (or anywhere in a chain) to catch what the blocks themselves do not
    check: a line too long or too short, a frame without ``eof`` or with ``eof`` too early, and for a
    stereo stream a broken left/right interleaving. The stream leaves unchanged, one clock later;
    ``error`` rises with the first faulty beat's output and stays high until ``rst``, and ``code`` says
    which fault came first (:mod:`eyestereo.tools.models.stream_checker`):

    ====  =============  =====================================================================
    code  name           the first faulty beat
    ====  =============  =====================================================================
    0     OK             (no fault since ``rst``)
    1     LONG_LINE      pixel width-1 of a line without ``eol``
    2     SHORT_LINE     ``eol`` on a pixel before width-1
    3     MISSING_EOF    the last line's ``eol`` without ``eof``
    4     EARLY_EOF      ``eof`` (with ``eol``) on a line before height-1
    5     STEREO         stereo: a beat of the wrong camera, or a right beat whose eol/eof differ
                         from its left beat's
    ====  =============  =====================================================================

    Recovery: after a fault the checker stops checking until the next reset token (valid, ``eof``, not
    ``eol``: the next beat is pixel (0, 0)) or the end of the broken frame (the next beat with ``eof``
    and ``eol``; stereo: the right camera's), and then checks again from pixel (0, 0); a fault on an
    end-of-frame beat (a frame cut short) recovers at once. A missing ``eof`` therefore also costs the
    frame after it (the checker finds the end of a frame only by its ``eof``) unless a token comes.
    Faults found after the first still repair the stream but do not change ``code``. ``rst`` clears
    ``error`` and ``code`` and expects pixel (0, 0) next, like every block.

    With ``repair=True`` the faulty beat leaves as a reset token (``eof`` high, ``eol`` low) and the
    beats up to the recovery point are dropped, so the source always keeps the protocol: every frame
    is whole or cut short by a reset token, and each block behind recovers at that token (a reset
    token puts every block back to its start-of-frame state). Without repair a broken frame goes on as
    it came; the blocks behind make output of unspecified data of it and recover at the next reset
    token (tests/hdl/test_recovery.py).

    Ports:
        clk: clock, rising edge.
        rst: synchronous reset, active high.
        sink: :class:`~eyestereo.hdl.interfaces.stream.ImageStream`, any data width, mono or stereo.
        source: ImageStream of the sink's data width and kind (``cam`` is forwarded).
        error: output, 1 bit: a fault was seen since ``rst`` (registered, high from the cycle the first
            faulty beat leaves at ``source``).
        code: output, 3 bits: the first fault's code (0 while ``error`` is low).

    Parameters:
        width, height: frame size, 1..4096.
        repair: False (pass the stream unchanged) or True (turn broken frames into reset tokens).

    Latency: 1 clock (stream, ``error`` and ``code`` alike).

    Resources: two position counters with registered last-pixel / last-line flags, the error and code
    registers and the output registers; no block RAM, no multiplier. Yosys, Spartan-3E, 352x288, 8-bit
    data: 41 LUT, 36 FF (repair: 44 LUT; stereo: 54 LUT, 40 FF).

    Timing: a 3x2 frame whose second line is one pixel short (code 2, SHORT_LINE), a reset token, and
    the next frame (``#`` high, ``_`` low, ``.`` don't care; the source carries each sink beat one clock
    later)::

        cycle         0    1    2    3    4    5    6    7    8    9
        sink_valid    #    #    #    #    #    _    #    #    #    _
        sink_eol      _    _    #    _    #    .    _    _    _    .
        sink_eof      _    _    _    _    _    .    #    _    _    .
        sink_data    0,0  1,0  2,0  0,1  1,1   .   tok  0,0  1,0   .
        source_valid  _    #    #    #    #    #    _    #    #    #
        source_eol    .    _    _    #    _    #    .    _    _    _
        source_eof    .    _    _    _    _    _    .    #    _    _
        error         _    _    _    _    _    #    #    #    #    #
        code          0    0    0    0    0    2    2    2    2    2

    The eol of cycle 4 comes on pixel 1 of line 1 where pixel 2 (width-1) should carry it: SHORT_LINE,
    flagged with that beat's output in cycle 5. It is not an end-of-frame beat, so the checker waits for
    the token of cycle 6 and checks again from the beat after it. With ``repair=True`` the beat of
    cycle 5 would leave as a token (``source_eol`` low, ``source_eof`` high); with no token coming,
    every beat up to the frame's eof would be dropped.

    """
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, stereo=None)
    check_stream("source", source, width=sink.data_width, stereo=sink.stereo)
    check_signal("error", error, width=1)
    check_signal("code", code, width=model.CODE_BITS)
    check_distinct(dict(source=source, error=error, code=code), dict(clk=clk, rst=rst, sink=sink))
    width, height = check_frame(width, height)
    repair = check_bool("repair", repair)
    stereo = sink.stereo

    x = Signal(intbv(0, min=0, max=width))
    y = Signal(intbv(0, min=0, max=height))
    # x == width-1, y == height-1 as registers of their own: the fault decode then needs no comparator.
    x_last_0, y_last_0 = width == 1, height == 1
    x_last = Signal(bool(x_last_0))
    y_last = Signal(bool(y_last_0))
    xl, yl = width - 1, height - 1
    phase = Signal(bool(0))  # stereo: the right camera's beat is due
    left_eol = Signal(bool(0))  # stereo: the left beat's flags, which the right beat must repeat
    left_eof = Signal(bool(0))
    sync = Signal(bool(1))
    err = Signal(bool(0))
    first = Signal(intbv(0)[model.CODE_BITS:])
    fault = Signal(intbv(0)[model.CODE_BITS:])
    token = Signal(bool(0))
    ok = Signal(bool(0))  # a pixel beat in sync and in order
    bad = Signal(bool(0))  # a pixel beat that is faulty or comes while out of sync
    faulty = Signal(bool(0))  # the faulty beat: in sync, out of order
    advance = Signal(bool(0))  # a pixel beat that moves the position on (stereo: the right camera's)
    frame_end = Signal(bool(0))  # an end-of-frame beat (stereo: the right camera's)
    STEREO = model.STEREO

    if stereo:
        @always_comb
        def decode():
            token.next = sink.valid and sink.eof and not sink.eol
            frame_end.next = sink.valid and sink.eof and sink.eol and sink.cam
    else:
        @always_comb
        def decode():
            token.next = sink.valid and sink.eof and not sink.eol
            frame_end.next = sink.valid and sink.eof and sink.eol

    # The fault of a pixel beat at the expected position (looked at only for pixel beats in sync).
    if stereo:
        geo = Signal(intbv(0)[model.CODE_BITS:])

        @always_comb
        def classify():
            if phase:
                if (not sink.cam) or sink.eol != left_eol or sink.eof != left_eof:
                    fault.next = STEREO
                else:
                    fault.next = 0
            elif sink.cam:
                fault.next = STEREO
            else:
                fault.next = geo

        insts = [classify, geometry(sink, x_last, y_last, geo)]
    else:
        insts = [geometry(sink, x_last, y_last, fault)]

    @always_comb
    def status():
        pixel = sink.valid and (sink.eol or not sink.eof)
        ok.next = pixel and sync and fault == 0
        bad.next = pixel and not (sync and fault == 0)
        faulty.next = pixel and sync and fault != 0

    if stereo:
        @always_comb
        def step():
            advance.next = ok and phase

        @always_seq(clk.posedge, reset=rst)
        def camera():
            source.cam.next = sink.cam
            if token or (bad and frame_end):
                phase.next = False
            elif ok:
                phase.next = not phase
                left_eol.next = sink.eol
                left_eof.next = sink.eof

        insts += [step, camera]
    else:
        @always_comb
        def step():
            advance.next = ok

        insts.append(step)

    @always_seq(clk.posedge, reset=rst)
    def position():
        # token, advance and bad exclude each other (a token is no pixel beat; ok and bad are opposites), and
        # an end-of-frame beat is a pixel beat: not ok, it is bad.
        if token or (frame_end and not ok):
            # A reset token or a broken frame's last beat: the next beat begins a frame, in sync again.
            x.next = 0
            y.next = 0
            x_last.next = x_last_0
            y_last.next = y_last_0
            sync.next = True
        elif advance:
            if sink.eol:
                x.next = 0
                x_last.next = x_last_0
                if sink.eof:
                    y.next = 0
                    y_last.next = y_last_0
                else:
                    y.next = y + 1
                    y_last.next = y == yl - 1
            else:
                x.next = x + 1
                x_last.next = x == xl - 1
        elif bad:
            sync.next = False

    @always_seq(clk.posedge, reset=rst)
    def flag():
        if faulty:
            err.next = True
            if not err:
                first.next = fault

    if repair:
        @always_seq(clk.posedge, reset=rst)
        def flags():
            # The faulty beat leaves as a reset token, the rest of the broken frame not at all.
            source.valid.next = sink.valid and not (bad and not faulty)
            source.eol.next = sink.eol and not faulty
            source.eof.next = sink.eof or faulty
    else:
        @always_seq(clk.posedge, reset=rst)
        def flags():
            source.valid.next = sink.valid
            source.eol.next = sink.eol
            source.eof.next = sink.eof

    @always(clk.posedge)
    def data():
        # Free-running: the data are defined wherever the sink's are.
        source.data.next = sink.data

    @always_comb
    def outputs():
        error.next = err
        code.next = first

    return insts + [decode, status, position, flag, flags, data, outputs]


@block
def geometry(sink, x_last, y_last, fault):
    """The fault of a pixel beat (of one camera) at a position that is (x_last) or is not the line's last
    pixel, on a line that is (y_last) or is not the frame's last."""
    LONG, SHORT, NOEOF, EARLY = model.LONG_LINE, model.SHORT_LINE, model.MISSING_EOF, model.EARLY_EOF

    @always_comb
    def classify():
        # No fault unless a flag comes where the position does not end a line (frame), or fails to come
        # where it does.
        fault.next = 0
        if not x_last:
            if sink.eol:
                fault.next = SHORT
        elif not sink.eol:
            fault.next = LONG
        elif not y_last:
            if sink.eof:
                fault.next = EARLY
        elif not sink.eof:
            fault.next = NOEOF

    return classify
