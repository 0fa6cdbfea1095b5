"""Image stream -> AXI4-Stream video (Xilinx UG934): a FIFO that absorbs back-pressure, cut frames on overflow."""

from myhdl import Signal, always, always_comb, always_seq, block, concat, intbv, modbv

from eyestereo.hdl.axi.bridge_checks import check_bridge
from eyestereo.hdl.common.checks import check_choice, check_int
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH

COMMITS = ("line", "frame")


@block
def stream_to_axis(clk, rst, sink, source, overflow, *, width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT,
                   depth: int = 1024, commit: str = "line"):
    """Send an image stream out as AXI4-Stream video, honouring ``tready`` through a FIFO.

    Every pixel of ``sink`` is written into a FIFO of ``depth`` words (pixel, EOL, SOF); the AXI side
    reads it out, one transfer per clock while ``tready`` is high. The image stream cannot wait, so
    when the AXI side stalls longer than the FIFO can absorb, the frame in progress is **cut**, never
    corrupted:

    * Words become visible to the AXI side only when their ``commit`` unit is complete: a whole line
      (``commit="line"``) or a whole frame (``commit="frame"``).
    * A pixel that finds the FIFO full pulses ``overflow`` for one clock, removes the uncommitted words
      of its frame from the FIFO again, and drops every further pixel of that frame (up to its ``eof``).
      The AXI side thus ends the frame after its last complete line (line commit; the next frame's
      SOF comes early, UG934's "early SOF") or never sees it at all (frame commit). Every line that
      goes out is a whole, correct line; the frames after the cut one are untouched.
    * A reset token on ``sink`` does the same without ``overflow``: it drops the uncommitted part of the
      frame in progress.

    With ``commit="frame"`` a frame is sent whole or not at all, but the FIFO must hold a whole frame
    (``depth >= width * height``: small frames, or external memory); with ``commit="line"`` it must hold
    a line (``depth >= width``), and a frame can be cut after any line.

    Ports:
        clk: clock, rising edge (both sides).
        rst: synchronous reset, active high; empties the FIFO.
        sink: :class:`~eyestereo.hdl.interfaces.stream.ImageStream` (mono), any data width.
        source: :class:`~eyestereo.hdl.interfaces.axis.AxiStream` master of the same pixel width (``tdata`` padded
            to whole bytes, ``tuser`` = SOF, ``tlast`` = EOL).
        overflow: output, one-clock pulse for every frame cut because the FIFO was full.

    Parameters:
        width, height: frame size (1..4096); the FIFO's minimum size depends on them.
        depth: FIFO words, a power of two, 4..65536 (default 1024: one RAMB16 for pixels of up to 16 bits).
        commit: ``"line"`` (default) or ``"frame"``, see above.

    Latency: with an empty FIFO and ``tready`` high, a line's first pixel leaves 3 clocks after its
    line's last pixel came in (line commit: a line waits for its ``eol``); then one pixel per clock.

    Resources: ``depth x (data_width + 2)`` bits of block RAM (one RAMB16 for 1024 x 18), three
    pointers, a two-word output stage; no multipliers.

    Handshakes: the image stream's (``hdl/interfaces/stream.py``) in, AXI4-Stream video
    (``hdl/interfaces/axis.py``) out.
    Overflow of 4-pixel lines with ``depth = 4``, ``tready`` held low (``words``: words in the FIFO; the
    WaveDrom form is ``docs/wavedrom/stream_to_axis_overflow.json``)::

        cycle     0    1    2    3    4    5    6
        valid     #    #    #    #    #    #    #
        data     0,0  1,0  2,0  3,0  0,1  1,1  2,1
        eol       _    _    _    #    _    _    _
        words     0    1    2    3    4    3    2
        overflow  _    _    _    _    _    #    _
        tvalid    _    _    _    _    _    _    #

    (3,0) commits line 0 and the AXI side starts reading it; (0,1) finds the FIFO full, so ``overflow``
    pulses and (0,1), (1,1), ... up to the frame's end are dropped; line 0 is offered from cycle 6 and
    waits for ``tready``.
    """
    dw, width, height = check_bridge(clk, rst, ("sink", sink), ("source", source), ("overflow", overflow),
                                     outputs=("source", "overflow"), width=width, height=height)
    depth = check_int("depth", depth, 4, 1 << 16)
    if depth & (depth - 1):
        raise ValueError(f"parameter depth={depth} must be a power of two")
    commit = check_choice("commit", commit, COMMITS)
    need = width if commit == "line" else width * height
    if depth < need:
        raise ValueError(f"parameter depth={depth} is too small: commit={commit!r} needs the FIFO to hold a "
                         f"whole {commit} ({need} words for {width}x{height})")

    aw = depth.bit_length() - 1  # address bits; the pointers carry one more (wrap) bit
    ww = dw + 2  # FIFO word: SOF, EOL, pixel
    mem = [Signal(intbv(0)[ww:]) for _ in range(depth)]

    # Write side.
    wptr = Signal(modbv(0)[aw + 1:])  # next word to write (uncommitted words lie in [cptr, wptr))
    cptr = Signal(modbv(0)[aw + 1:])  # end of the committed words: the read side sees [rptr, cptr)
    rptr = Signal(modbv(0)[aw + 1:])  # next word to read
    first = Signal(bool(1))  # the next pixel starts a frame
    dropping = Signal(bool(0))  # the rest of this frame is discarded
    full = Signal(bool(0))
    we = Signal(bool(0))
    wdata = Signal(intbv(0)[ww:])
    waddr = Signal(intbv(0)[aw:])
    commit_eol = commit == "line"

    @always_comb
    def write_decode():
        full.next = (wptr[aw] != rptr[aw]) and (wptr[aw:] == rptr[aw:])
        waddr.next = wptr[aw:]
        wdata.next = concat(sink.data, sink.eol, first)
        we.next = sink.valid and (sink.eol or not sink.eof) and not dropping and not full

    @always_seq(clk.posedge, reset=rst)
    def write_side():
        overflow.next = 0
        if sink.valid:
            if sink.eof and not sink.eol:
                # Reset token: forget the uncommitted part of the frame in progress.
                wptr.next = cptr
                first.next = 1
                dropping.next = 0
            elif dropping:
                if sink.eof:
                    dropping.next = 0
                    first.next = 1
            elif full:
                overflow.next = 1
                wptr.next = cptr
                first.next = 1
                dropping.next = not sink.eof
            else:
                wptr.next = wptr + 1
                first.next = sink.eof
                if (commit_eol and sink.eol) or sink.eof:
                    cptr.next = wptr + 1

    @always(clk.posedge)
    def ram_write():
        if we:
            mem[waddr].next = wdata

    # Read side: block RAM read (1 clock) -> two-word output stage (O: on the bus, S: behind it).
    q = Signal(intbv(0)[ww:])
    raddr = Signal(intbv(0)[aw:])
    issue = Signal(bool(0))
    b_valid = Signal(bool(0))  # q holds a word read in the clock before
    o_valid = Signal(bool(0))
    o_word = Signal(intbv(0)[ww:])
    s_valid = Signal(bool(0))
    s_word = Signal(intbv(0)[ww:])
    take = Signal(bool(0))
    o_stays = Signal(bool(0))

    @always_comb
    def read_decode():
        take.next = o_valid and source.tready
        o_stays.next = o_valid and not source.tready
        raddr.next = rptr[aw:]

    @always_comb
    def read_issue():
        # Read only if the word will have a place: after this clock O and S hold what stays in O, what
        # is in S and the word already read (b); a new read is safe while at most one of them is there.
        issue.next = (rptr != cptr) and not ((o_stays and s_valid) or (o_stays and b_valid)
                                             or (s_valid and b_valid))

    @always(clk.posedge)
    def ram_read():
        # No reset: a memory read port with a reset does not map to block RAM.
        if issue:
            q.next = mem[raddr]

    @always_seq(clk.posedge, reset=rst)
    def read_side():
        b_valid.next = issue
        if issue:
            rptr.next = rptr + 1
        if take or not o_valid:
            if s_valid:
                o_word.next = s_word
                o_valid.next = 1
                s_valid.next = b_valid
                if b_valid:
                    s_word.next = q
            elif b_valid:
                o_word.next = q
                o_valid.next = 1
            else:
                o_valid.next = 0
        elif b_valid:
            s_word.next = q
            s_valid.next = 1

    @always_comb
    def axi_out():
        source.tvalid.next = o_valid
        source.tuser.next = o_word[0]
        source.tlast.next = o_word[1]
        source.tdata.next = o_word[ww:2]

    return write_decode, write_side, ram_write, read_decode, read_issue, ram_read, read_side, axi_out
