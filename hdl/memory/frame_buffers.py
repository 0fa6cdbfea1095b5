"""Double-buffered frames in the SRAM: who may write and who may read which buffer (thesis 7.1, second mode).

Every producer (each camera writer, the rectified-image writer, the feature writer) owns two buffers in
the SRAM (the address map: :class:`eyestereo.tools.models.sram_arbiter.AddressMap`). One
:func:`double_buffer` per producer keeps each buffer's state::

    FREE --producer starts a frame--> WRITING --its last word is issued--> FULL --consumer takes--> READING
      ^                                  |                                   |                          |
      +----------- aborted (token) ------+      a newer frame overwrites ----+      consumer releases --+

* A producer starting a frame takes a buffer that is neither being written nor read: a FREE one if
  there is one, else the older FULL one (the newest frame is kept for the consumer). With the other
  buffer held by the consumer and this one still being written, there is none: the frame is dropped
  (counted) and the producer's writer discards its words.
* A frame becomes FULL when the writer has issued its last word to the SRAM controller; the controller
  is in order, so a consumer's read issued after that sees the whole frame. Nobody can read a
  half-written frame: the fetch port and the host address only buffers a consumer holds.
* The consumer *takes* the newest FULL buffer (``c_take``, when ``c_avail``) and holds it (READING,
  ``c_held``, ``c_buf``) until it releases it (``c_release``); a frame published meanwhile waits FULL.
  A take wins over a producer's start in the same clock.

Both operating modes of the complete system use this one handshake (:class:`FrameControl`):

* **sequential** (thesis 7.1, first mode): arm each camera for one frame (``cam_arm``), wait for
  ``avail``, take the pair (``cam_want``), run the rectifier, release; take the rectified image and the
  feature list, read them out through the host port, release; arm again.
* **overlapped** (double buffering): keep ``cam_run`` high and ``cam_want``, ``rect_want``, ``feat_want``
  high: each consumer takes the newest frame as soon as it releases the previous one, while the
  producers fill the other buffers.

:func:`double_buffer` has only registers and a few LUTs: 2 state bits per buffer, the newest-buffer bit,
the held buffer, and three 16-bit event counters (frames published, dropped, overwritten).
"""

from __future__ import annotations

from myhdl import Signal, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.common.checks import block_error, check_clock, check_reset

__all__ = ["FrameControl", "double_buffer", "FREE", "WRITING", "FULL", "READING"]

FREE, WRITING, FULL, READING = 0, 1, 2, 3
COUNT_BITS = 16


class FrameControl:
    """The frame handshake of the SRAM arbiter with the system's controller (ports ``<arg>_<field>``)::

        cam_run       in   2 bits: camera c captures every frame it can (bit c)
        cam_arm       in   2 bits: a pulse on bit c captures camera c's next whole frame once
        cam_want      in   the rectifier side wants a camera pair: both cameras' newest FULL buffers are
                           taken together as soon as both have one
        cam_held      out  a pair is held: the fetch port reads it
        cam_buf       out  2 bits: the buffer held of camera 0 (bit 0) and camera 1 (bit 1)
        cam_release   in   pulse: release the pair (only after the last response of the last request:
                           the buffers are written again at once)
        rect_want / rect_held / rect_buf / rect_release    the same for the rectified images (the host
        feat_want / feat_held / feat_buf / feat_release    reads buffer rect_buf / feat_buf)
        avail         out  4 bits: a FULL frame waits in camera 0, camera 1, rectified, features (bit 0..3)

    A ``*_want`` held high takes the newest frame whenever none is held; a ``*_release`` pulse and a
    ``*_want`` in the same clock release the held frame and take the next one in a later clock.
    Timing (``#`` high, ``_`` low)::

        cycle        0    1    2    3    4    5    6
        avail[0:1]   01   11   11   00   00   00   01     camera 1 finishes, camera 0 finishes
        cam_want     #    #    #    #    #    #    #
        cam_held     _    _    #    #    #    _    _      taken at the edge after both are available
        cam_release  _    _    _    _    #    _    _
    """

    def __init__(self):
        self.cam_run = Signal(intbv(0)[2:])
        self.cam_arm = Signal(intbv(0)[2:])
        self.cam_want = Signal(bool(0))
        self.cam_held = Signal(bool(0))
        self.cam_buf = Signal(intbv(0)[2:])
        self.cam_release = Signal(bool(0))
        self.rect_want = Signal(bool(0))
        self.rect_held = Signal(bool(0))
        self.rect_buf = Signal(bool(0))
        self.rect_release = Signal(bool(0))
        self.feat_want = Signal(bool(0))
        self.feat_held = Signal(bool(0))
        self.feat_buf = Signal(bool(0))
        self.feat_release = Signal(bool(0))
        self.avail = Signal(intbv(0)[4:])

    def fields(self) -> list[str]:
        return ["cam_run", "cam_arm", "cam_want", "cam_held", "cam_buf", "cam_release", "rect_want", "rect_held",
                "rect_buf", "rect_release", "feat_want", "feat_held", "feat_buf", "feat_release", "avail"]


class BufferSide:
    """Signals between a writer and its :func:`double_buffer` (internal to the arbiter)."""

    def __init__(self):
        # producer: a registered request/answer, so that no combinational path crosses
        self.p_start = Signal(bool(0))      # level: a frame wants a buffer (held until answered)
        self.p_grant = Signal(bool(0))      # pulse: it got buffer p_gbuf
        self.p_gbuf = Signal(bool(0))
        self.p_deny = Signal(bool(0))       # pulse: no buffer: the frame is dropped (counted)
        self.p_avail = Signal(bool(0))      # (internal) a buffer can be taken now
        self.p_pick = Signal(bool(0))       # (internal) which
        self.p_done = Signal(bool(0))       # pulse: the frame in buffer p_done_buf is complete
        self.p_done_buf = Signal(bool(0))
        self.p_abort = Signal(bool(0))      # pulse: the frame in buffer p_abort_buf is abandoned
        self.p_abort_buf = Signal(bool(0))
        # consumer
        self.c_take = Signal(bool(0))       # take the newest FULL buffer (only while c_avail and not held)
        self.c_release = Signal(bool(0))
        self.c_avail = Signal(bool(0))      # a FULL buffer can be taken
        self.c_held = Signal(bool(0))
        self.c_buf = Signal(bool(0))        # the held buffer (the last one held when none is)
        # status
        self.state = Signal(intbv(0)[4:])   # buffer 1's state in bits 3..2, buffer 0's in 1..0
        self.published = Signal(intbv(0)[COUNT_BITS:])
        self.dropped = Signal(intbv(0)[COUNT_BITS:])
        self.overwritten = Signal(intbv(0)[COUNT_BITS:])


@block
def double_buffer(clk, rst, side: BufferSide):
    """The state of one producer's two buffers and the take/release handshake (module docstring).

    Ports:
        clk, rst: clock and synchronous reset (both buffers FREE, counters 0).
        side: :class:`BufferSide`; ``p_avail``, ``p_pick`` and ``c_avail`` are combinational from the
            registers (and ``c_take``), everything else registered.

    Latency: a change is seen in the clock after the edge that makes it.

    Resources: about 40 flip-flops (3 x 16-bit counters) and 20 LUTs.
    """
    check_clock(clk)
    check_reset(rst)
    if not isinstance(side, BufferSide):
        raise block_error(f"port side must be a BufferSide, got {'None' if side is None else type(side).__name__}")
    s0 = Signal(intbv(FREE)[2:])
    s1 = Signal(intbv(FREE)[2:])
    newest = Signal(bool(0))
    take_buf = Signal(bool(0))
    # internal copies of the outputs the block reads back (VHDL-93 cannot read an out port)
    c_avail, c_held, c_buf, p_avail, p_pick, p_grant, p_gbuf, p_deny = (Signal(bool(0)) for _ in range(8))
    published, dropped, overwritten = (Signal(intbv(0)[COUNT_BITS:]) for _ in range(3))

    @always_comb
    def consumer_choice():
        # the newest FULL buffer (or the other one if only it is FULL)
        full0 = s0 == FULL
        full1 = s1 == FULL
        c_avail.next = (full0 or full1) and not c_held
        if full0 and full1:
            take_buf.next = newest
        else:
            take_buf.next = full1

    @always_comb
    def producer_choice():
        taking = side.c_take and c_avail
        ok0 = (s0 == FREE or s0 == FULL) and not (taking and not take_buf)
        ok1 = (s1 == FREE or s1 == FULL) and not (taking and take_buf)
        p_avail.next = ok0 or ok1
        if ok0 and ok1:
            # both FREE or both FULL: the one that is not the newest; one FREE: that one
            if s0 == s1:
                p_pick.next = not newest
            else:
                p_pick.next = s1 == FREE
        else:
            p_pick.next = ok1

    @always_comb
    def status():
        side.state.next = concat(s1, s0)

    @always_seq(clk.posedge, reset=rst)
    def update():
        taking = side.c_take and c_avail
        asking = side.p_start and not p_grant and not p_deny  # not the clock it was answered
        starting = asking and p_avail
        p_grant.next = starting
        p_deny.next = asking and not p_avail
        p_gbuf.next = p_pick
        # producer
        if starting:
            if p_pick:
                if s1 == FULL:
                    overwritten.next = overwritten + 1
                s1.next = WRITING
            else:
                if s0 == FULL:
                    overwritten.next = overwritten + 1
                s0.next = WRITING
        if asking and not p_avail:
            dropped.next = dropped + 1
        if side.p_done:
            published.next = published + 1
            newest.next = side.p_done_buf
            if side.p_done_buf:
                s1.next = FULL
            else:
                s0.next = FULL
        if side.p_abort:
            if side.p_abort_buf:
                s1.next = FREE
            else:
                s0.next = FREE
        # consumer
        if side.c_release and c_held:
            c_held.next = False
            if c_buf:
                s1.next = FREE
            else:
                s0.next = FREE
        elif taking:
            c_held.next = True
            c_buf.next = take_buf
            if take_buf:
                s1.next = READING
            else:
                s0.next = READING

    @always_comb
    def outputs():
        side.c_avail.next = c_avail
        side.c_held.next = c_held
        side.c_buf.next = c_buf
        side.p_avail.next = p_avail
        side.p_pick.next = p_pick
        side.p_grant.next = p_grant
        side.p_gbuf.next = p_gbuf
        side.p_deny.next = p_deny
        side.published.next = published
        side.dropped.next = dropped
        side.overwritten.next = overwritten

    return consumer_choice, producer_choice, status, update, outputs
