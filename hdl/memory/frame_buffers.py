"""Double-buffered frames in the SRAM: who may write and who may read which buffer (thesis 7.1, second mode).

Every producer (each camera writer, the rectified-image writer, the feature writer) owns two buffers in
the SRAM (the address map: :class:`eyestereo.tools.models.sram_arbiter.AddressMap`). One
:func:`double_buffer` per producer keeps each buffer's state::

    FREE --producer starts a frame--> WRITING --its last word is issued--> FULL --consumer takes--> READING
      ^                                  |                                   |                          |
      +----------- aborted (token) ------+      a newer frame overwrites ----+      consumer releases --+
                                                or is taken (the older FULL) -+

* A producer starting a frame takes a buffer that is neither being written nor read: a FREE one if
  there is one, else the older FULL one (the newest frame is kept for the consumer). The block would
  deny a start that finds no such buffer (the frame dropped, counted, its words discarded by the writer),
  but with the arbiter's writers that cannot happen: a writer asks only while it holds no buffer, so one
  of the two is always FREE or FULL (proven: formal/double_buffer_props.vh, docs/formal.md); a frame is
  overwritten, never dropped, and ``dropped`` stays 0.
* A frame becomes FULL when the writer has issued its last word to the SRAM controller; the controller
  is in order, so a consumer's read issued after that sees the whole frame. Nobody can read a
  half-written frame: the fetch port and the host address only buffers a consumer holds.
* The consumer *takes* the newest FULL buffer (``c_take``, when ``c_avail``) and holds it (READING,
  ``c_held``, ``c_buf``) until it releases it (``c_release``); a frame published meanwhile waits FULL.
  A take wins over a producer's start in the same clock. When both are FULL the take frees the older one
  (counted as overwritten): a consumer never gets a frame older than one it has had.

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
from eyestereo.hdl.interfaces.bundle import IN, OUT, Bundle, Member

__all__ = ["FrameControl", "double_buffer", "FREE", "WRITING", "FULL", "READING"]

FREE, WRITING, FULL, READING = 0, 1, 2, 3
COUNT_BITS = 16


class FrameControl(Bundle):
    """The frame handshake of the SRAM arbiter with the system's controller (ports ``<arg>_<field>``).

    Members, widths and directions are declared once in ``MEMBERS`` (``out``: the controller drives it,
    ``in``: the arbiter; docs/interfaces.md lists them). What they mean:

        cam_run       2 bits: camera c captures every frame it can (bit c)
        cam_arm       2 bits: a pulse on bit c captures camera c's next whole frame once
        cam_want      the rectifier side wants a camera pair: both cameras' newest FULL buffers are
                      taken together as soon as both have one
        cam_held      a pair is held: the fetch port reads it
        cam_buf       2 bits: the buffer held of camera 0 (bit 0) and camera 1 (bit 1)
        cam_release   pulse: release the pair (only after the last response of the last request:
                      the buffers are written again at once)
        rect_want / rect_held / rect_buf / rect_release    the same for the rectified images (the host
        feat_want / feat_held / feat_buf / feat_release    reads buffer rect_buf / feat_buf)
        avail         4 bits: a FULL frame waits in camera 0, camera 1, rectified, features (bit 0..3)

    A ``*_want`` held high takes the newest frame whenever none is held; a ``*_release`` pulse and a
    ``*_want`` in the same clock release the held frame and take the next one in a later clock.
    Timing (``#`` high, ``_`` low)::

        cycle        0    1    2    3    4    5    6
        avail[0:1]   01   11   11   00   00   00   01     camera 1 finishes, camera 0 finishes
        cam_want     #    #    #    #    #    #    #
        cam_held     _    _    _    #    #    _    _      taken at the second edge after both are available
        cam_release  _    _    _    _    #    _    _

    The camera pair's take is registered in the arbiter (cycle 1 decides, the edge after cycle 2 takes):
    ``cam_held`` rises two clocks after the clock in which both cameras' ``avail`` bits are high, the
    rectified and feature consumers' one clock after theirs.
    """

    MEMBERS = (Member("cam_run", 2, OUT), Member("cam_arm", 2, OUT), Member("cam_want", bool, OUT),
               Member("cam_held", bool, IN), Member("cam_buf", 2, IN), Member("cam_release", bool, OUT),
               Member("rect_want", bool, OUT), Member("rect_held", bool, IN), Member("rect_buf", bool, IN),
               Member("rect_release", bool, OUT), Member("feat_want", bool, OUT), Member("feat_held", bool, IN),
               Member("feat_buf", bool, IN), Member("feat_release", bool, OUT), Member("avail", 4, IN))

    def __init__(self):
        self.make()


class BufferSide(Bundle):
    """Signals between a writer, its reader and their :func:`double_buffer` (internal to the arbiter).

    ``out`` members are driven by the writer (``p_*``) or the reader (``c_take``, ``c_release``), ``in``
    members by the double buffer. The producer's request and answer are registered, so that no
    combinational path crosses: ``p_start`` (level: a frame wants a buffer, held until answered),
    ``p_grant`` (pulse: it got buffer ``p_gbuf``), ``p_deny`` (pulse: no buffer, the frame is dropped and
    counted), ``p_avail``/``p_pick`` (a buffer can be taken now / which), ``p_done`` (pulse: the frame in
    buffer ``p_done_buf`` is complete), ``p_abort`` (pulse: the frame in ``p_abort_buf`` is abandoned).
    The consumer: ``c_take`` (take the newest FULL buffer, only while ``c_avail`` and not held),
    ``c_release``, ``c_avail`` (a FULL buffer can be taken), ``c_held``, ``c_buf`` (the held buffer; the
    last one held when none is). Status: ``state`` (buffer 1's state in bits 3..2, buffer 0's in 1..0) and
    the counters ``published``, ``dropped``, ``overwritten``.
    """

    MEMBERS = (Member("p_start", bool, OUT), Member("p_grant", bool, IN), Member("p_gbuf", bool, IN),
               Member("p_deny", bool, IN), Member("p_avail", bool, IN), Member("p_pick", bool, IN),
               Member("p_done", bool, OUT), Member("p_done_buf", bool, OUT), Member("p_abort", bool, OUT),
               Member("p_abort_buf", bool, OUT), Member("c_take", bool, OUT), Member("c_release", bool, OUT),
               Member("c_avail", bool, IN), Member("c_held", bool, IN), Member("c_buf", bool, IN),
               Member("state", 4, IN), Member("published", COUNT_BITS, IN), Member("dropped", COUNT_BITS, IN),
               Member("overwritten", COUNT_BITS, IN))

    def __init__(self):
        self.make()


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
            # Two FULL: the older one is stale once the newer is taken (a consumer must never get a frame older
            # than one it already had: the fault soak found a late camera's older frame paired after a newer
            # one). It is freed and counted as overwritten, unless the producer starts on it in this clock.
            if s0 == FULL and s1 == FULL and not (starting and p_pick != take_buf):
                overwritten.next = overwritten + 1
                if take_buf:
                    s0.next = FREE
                else:
                    s1.next = FREE

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
