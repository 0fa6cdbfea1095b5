"""Front-end sequencer: the two operating modes of the stereo front end (thesis 7.1), start/stop, counters."""

from myhdl import Signal, always_comb, always_seq, block, enum, intbv

from eyestereo.hdl.common.checks import check_clock, check_reset, check_signal
from eyestereo.hdl.memory.frame_buffers import FrameControl
from eyestereo.hdl.interfaces.sram_bus import check_bundle

__all__ = ["frontend_sequencer"]


@block
def frontend_sequencer(clk, rst, mode, continuous, start, stop, ctl, rect_start, rect_busy, list_done,
                       list_overflow, busy, frames, frame_clocks, list_overflows, ready=None, lists_lost=None, *,
                       list_timeout: int | None = None):
    """Drives the camera side of the frame handshake and the rectifier's ``start`` for the two modes.

    * **sequential** (``mode`` 0, the thesis's estimate): each stereo frame is one stage after the
      other: arm both cameras for their next whole frame (``cam_arm``), take the pair as soon as both
      are in (``cam_want``), rectify it (the stereo stream goes to the rectified buffers and the
      Harris detector), release the pair, wait until the feature lists of the frame are complete
      (``list_done``), and only then arm the cameras again (continuous) or stop (single-shot).
    * **overlapped** (``mode`` 1, double buffers): the cameras capture every frame (``cam_run``) into
      their double buffers while ``cam_want`` stays high; each time a pair is held and the rectifier is
      idle it is rectified and released, so capture of frame n+1 runs while frame n is rectified and
      its features are listed. Single-shot rectifies one pair.

    ``start`` (a pulse) begins; ``stop`` ends continuous operation after the frame in progress; a
    frame is *complete* when its feature lists are (``list_done``: feature_list's ``frame_done``).
    ``busy`` is high from start until the last started frame is complete. ``frames`` counts complete
    frames, ``frame_clocks`` holds the clocks of the last one (sequential: from its arming to its lists;
    overlapped: since the previous complete frame, the frame period), ``list_overflows`` the lists that
    were cut (``list_overflow`` with ``list_done``).

    Ports:
        clk, rst: the memory clock and its synchronous active-high reset.
        mode, continuous, start, stop: inputs, 1 bit (the register bank's CTRL/CMD fields).
        ctl: :class:`~eyestereo.hdl.memory.frame_buffers.FrameControl`; only ``cam_run``, ``cam_arm``,
            ``cam_want``, ``cam_release`` are driven here, ``cam_held`` is read.
        rect_start: output pulse to the rectifier; rect_busy: its ``busy``.
        list_done, list_overflow: feature_list's ``frame_done`` and ``overflow`` (memory clock).
        busy: output, 1 bit; frames, frame_clocks: outputs, 32 bits; list_overflows: output, 16 bits.
        ready: optional input, 1 bit: the frame store is ready (an SDRAM after its power-up sequence); a
            ``start`` before it is kept (``busy`` high) and taken once it is. None: always ready.
        lists_lost: optional output, 16 bits: rectified frames whose lists the watchdog gave up (None: not
            counted outside).

    Parameters:
        list_timeout: None (default): the lists of every rectified frame are waited for, however long (the
            formal properties' environment: one ``list_done`` per rectified frame). An int (memory clocks,
            1..2**24): the *list watchdog*: while the sequencer waits for lists (sequential: after the
            rectification; both modes: draining after a stop) and no ``list_done`` has come for that many clocks,
            the frames still pending are given up (counted in ``lists_lost``) and the sequencer goes on as if
            they were complete. A Harris-domain reset can cut a frame whose lists then never come (the fault
            soak found the front end busy for ever after one); the timeout must exceed the Harris pipeline's
            latency from the rectifier's end to the lists (stereo_frontend's default: :func:`list_timeout`).

    Latency: the rectifier starts one clock after the pair is held; the pair is released one clock
    after the rectifier's ``busy`` falls (its last fetch has been answered by then); the next pair is
    looked for once ``cam_held`` of the released one has fallen.

    Resources: a state register, two 32-bit counters and a 32-bit clock counter, two 16-bit counters, the list
    watchdog's counter (log2 list_timeout bits; none without it).
    """
    check_clock(clk)
    check_reset(rst)
    for name, s in (("mode", mode), ("continuous", continuous), ("start", start), ("stop", stop),
                    ("rect_start", rect_start), ("rect_busy", rect_busy), ("list_done", list_done),
                    ("list_overflow", list_overflow), ("busy", busy)):
        check_signal(name, s, width=1)
    check_bundle("ctl", ctl, FrameControl)
    check_signal("frames", frames, width=32)
    check_signal("frame_clocks", frame_clocks, width=32)
    check_signal("list_overflows", list_overflows, width=16)

    if ready is None:
        ready = Signal(bool(1))  # undriven: a constant 1 in the VHDL
    else:
        check_signal("ready", ready, width=1)
    if list_timeout is not None and (isinstance(list_timeout, bool) or not isinstance(list_timeout, int)
                                     or not 1 <= list_timeout <= 1 << 24):
        raise ValueError(f"list_timeout must be None or an int of clocks in 1..2**24, got {list_timeout!r}")
    limit = 0 if list_timeout is None else int(list_timeout)  # 0: no watchdog
    if lists_lost is not None:
        check_signal("lists_lost", lists_lost, width=16)
    wd = Signal(intbv(0, min=0, max=limit + 2))   # clocks the lists have been waited for without a list_done
    nlost = Signal(intbv(0)[16:])
    pend = Signal(bool(0))  # a start waiting for the frame store
    st_t = enum("IDLE", "ARM", "PAIR", "RSTART", "RFIRST", "RECT", "REL", "LISTS", "DRAIN")
    st = Signal(st_t.IDLE)
    md = Signal(bool(0))
    more = Signal(bool(0))       # continue after this frame (continuous and no stop yet)
    pending = Signal(intbv(0, min=0, max=4))  # rectified frames whose lists are not complete (overlapped)
    t = Signal(intbv(0)[32:])
    nframes = Signal(intbv(0)[32:])
    novf = Signal(intbv(0)[16:])

    @always_seq(clk.posedge, reset=rst)
    def fsm():
        ctl.cam_arm.next = 0
        ctl.cam_release.next = 0
        rect_start.next = 0
        t.next = t + 1
        done_now = bool(list_done)
        if done_now:
            nframes.next = nframes + 1
            if list_overflow:
                novf.next = novf + 1
        if stop:
            more.next = 0
        if st == st_t.IDLE:
            ctl.cam_run.next = 0
            ctl.cam_want.next = 0
            if (start or pend) and not ready:
                pend.next = 1
            elif start or pend:
                pend.next = 0
                md.next = mode
                more.next = continuous
                t.next = 0
                if mode:
                    ctl.cam_run.next = 3
                    ctl.cam_want.next = 1
                    st.next = st_t.PAIR
                else:
                    st.next = st_t.ARM
        elif st == st_t.ARM:
            ctl.cam_arm.next = 3
            ctl.cam_want.next = 1
            st.next = st_t.PAIR
        elif st == st_t.PAIR:
            if ctl.cam_held:
                rect_start.next = 1
                st.next = st_t.RSTART
        elif st == st_t.RSTART:
            st.next = st_t.RFIRST
        elif st == st_t.RFIRST:
            st.next = st_t.RECT
        elif st == st_t.RECT:
            if not rect_busy:
                ctl.cam_release.next = 1
                if md:
                    if more and not stop:
                        st.next = st_t.REL
                    else:
                        ctl.cam_run.next = 0
                        ctl.cam_want.next = 0
                        st.next = st_t.DRAIN
                else:
                    ctl.cam_want.next = 0
                    st.next = st_t.LISTS
        elif st == st_t.REL:
            # the released pair's cam_held falls a clock later: do not take it for the next one
            if not ctl.cam_held:
                st.next = st_t.PAIR
        elif st == st_t.LISTS:
            if done_now:
                if more and not stop:
                    t.next = 0
                    st.next = st_t.ARM
                else:
                    st.next = st_t.IDLE
        else:  # DRAIN: the lists of every rectified frame
            if pending == 0 or (pending == 1 and done_now):
                st.next = st_t.IDLE
        # frames rectified and not yet listed (overlapped); the frame period between complete frames
        started = st == st_t.RECT and not rect_busy
        if started and not done_now:
            if pending < 3:
                pending.next = pending + 1
        elif done_now and not started:
            if pending > 0:
                pending.next = pending - 1
        # the list watchdog (limit 0: none): lists waited for and none come for `limit` clocks -> given up
        waiting = st == st_t.LISTS or (st == st_t.DRAIN and pending != 0)
        if limit != 0 and waiting and not done_now:
            if wd == limit:
                wd.next = 0
                nlost.next = nlost + pending
                pending.next = 0
                if st == st_t.LISTS and more and not stop:
                    t.next = 0
                    st.next = st_t.ARM
                else:
                    st.next = st_t.IDLE
            else:
                wd.next = wd + 1
        else:
            wd.next = 0
        if done_now:
            frame_clocks.next = t + 1 if st == st_t.LISTS else t
            if md and st != st_t.LISTS:
                t.next = 0

    @always_seq(clk.posedge, reset=rst)
    def outputs():
        busy.next = st != st_t.IDLE or pend
        frames.next = nframes
        list_overflows.next = novf

    insts = [fsm, outputs]
    if lists_lost is not None:
        @always_comb
        def lost_out():
            lists_lost.next = nlost

        insts.append(lost_out)
    return insts
