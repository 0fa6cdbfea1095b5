"""List append: a frame's match list written after its feature list, at a fixed word, into the same list buffer."""

from __future__ import annotations

from myhdl import Signal, always_comb, always_seq, block, enum, intbv

from eyestereo.hdl.common.checks import check_clock, check_distinct, check_int, check_reset, check_signal
from eyestereo.hdl.interfaces.queue import check_queue

__all__ = ["list_append"]


@block
def list_append(clk, rst, sink, matches, source, count, overflow, *, offset: int = 2048):
    """One list per frame from two: the feature list of ``sink``, filler words up to word ``offset``, then the
    frame's match list from ``matches``; ``eof`` only on the match list's end.

    The front end's matcher option (issue 29): the feature writer (the memory's ``feat`` port) stores the
    result in a feature-list buffer, so the host takes features and matches of a frame with one handshake
    (CTRL.feat_want / CMD.feat_release) and finds the matches at a fixed word of the buffer
    (:meth:`eyestereo.tools.models.sram_arbiter.AddressMap.features` + ``offset``) without reading the features.
    The two lists come in frame order, one of each per frame (feature_list and feature_matcher see the same
    flags); the match list waits (``matches.ready`` low) until its frame's feature list has gone out.

    * A feature list's last word (``eol`` and ``eof``: its trailer) goes out with ``eol`` only; then words of 0
      until ``offset`` words of the frame have gone; then the match list, its ``eol``/``eof`` on its trailer's
      last word.
    * A reset token on ``sink`` (the feature list aborted) goes out as it is and the frame's match list, when it
      comes, is taken and dropped (the list buffer is not kept either way).
    * ``count`` and ``overflow``: the trailer of the last match list that went out (count, overflow flag).

    Timing (features f0 f1 and their trailer t0 t1, ``offset`` 6, matches m0 m1 m2 and the trailer u0 u1 u2;
    ``#`` high, ``_`` low)::

        source data   f0 f1 t0 t1  0  0 m0 m1 m2 u0 u1 u2
        source eol     _  _  _  #  _  _  _  _  _  _  _  #
        source eof     _  _  _  _  _  _  _  _  _  _  _  #

    Ports:
        clk, rst: clock and synchronous active-high reset.
        sink: QueuePort, 16 bits: the feature lists (``feature_list``'s source).
        matches: QueuePort, 16 bits: the match lists (``feature_matcher``'s source).
        source: QueuePort, 16 bits: the joined lists (to the feature writer).
        count: output, 15 bits; overflow: output, 1 bit.

    Parameters:
        offset: the word of the list buffer where the matches begin (at least the longest feature list with its
            trailer, ``2 * max_features + 2``), 2..65535; default 2048, the front end's 1023 features.

    Latency: none: the words pass combinationally (``source.valid`` from the chosen input's ``valid``, its
    ``ready`` from ``source.ready``); the filler words come one per clock the consumer takes.

    Resources: a 16-bit word counter, a two-bit state, the last word and the count registers, the multiplexer.
    Measured (make synth's flow on this block, offset 2048): Yosys xc3se 59 LUT, 46 FF; ECP5 197.2 / 228.3 / 237.0
    MHz (min / median / max of nextpnr seeds 1-4; goal 100 MHz, the memory clock).
    """
    check_clock(clk)
    check_reset(rst)
    check_queue("sink", sink, width=16)
    check_queue("matches", matches, width=16)
    check_queue("source", source, width=16)
    offset = check_int("offset", offset, 2, 65535)
    check_signal("count", count, width=15, signed=False)
    check_signal("overflow", overflow, width=1)
    check_distinct(dict(source=source, count=count, overflow=overflow), dict(clk=clk, rst=rst, sink=sink,
                                                                                 matches=matches))
    State = enum("ST_FEATURES", "ST_FILL", "ST_MATCHES", "ST_DROP")
    state = Signal(State.ST_FEATURES)
    words = Signal(intbv(0, min=0, max=offset + 1))  # words of the frame gone out (features and filler)
    prev = Signal(intbv(0)[16:])  # the last match word gone out: the trailer's count before its last word
    count_r = Signal(intbv(0)[15:])
    ovf_r = Signal(bool(0))

    @always_comb
    def route():
        sink.ready.next = False
        matches.ready.next = False
        source.valid.next = False
        source.data.next = 0
        source.eol.next = False
        source.eof.next = False
        if state == State.ST_FEATURES:
            sink.ready.next = source.ready
            source.valid.next = sink.valid
            source.data.next = sink.data
            source.eol.next = sink.eol
            source.eof.next = sink.eof and not sink.eol  # a token stays a token; the trailer's eof waits
        elif state == State.ST_FILL:
            source.valid.next = True
        elif state == State.ST_MATCHES:
            matches.ready.next = source.ready
            source.valid.next = matches.valid
            source.data.next = matches.data
            source.eol.next = matches.eol
            source.eof.next = matches.eof
        else:
            matches.ready.next = True

    @always_seq(clk.posedge, reset=rst)
    def steps():
        if state == State.ST_FEATURES:
            if sink.valid and source.ready:
                if sink.eof and not sink.eol:
                    words.next = 0
                    state.next = State.ST_DROP
                elif sink.eol and sink.eof:
                    if words + 1 >= offset:
                        state.next = State.ST_MATCHES
                    else:
                        words.next = words + 1
                        state.next = State.ST_FILL
                elif words < offset:
                    words.next = words + 1
        elif state == State.ST_FILL:
            if source.ready:
                words.next = words + 1
                if words + 1 >= offset:
                    state.next = State.ST_MATCHES
        elif state == State.ST_MATCHES:
            if matches.valid and source.ready:
                prev.next = matches.data
                if matches.eof:
                    words.next = 0
                    state.next = State.ST_FEATURES
                    if matches.eol:
                        count_r.next = prev[15:]
                        ovf_r.next = prev[15]
        else:
            if matches.valid and matches.eof:
                state.next = State.ST_FEATURES

    @always_comb
    def outputs():
        count.next = count_r
        overflow.next = ovf_r

    return route, steps, outputs

