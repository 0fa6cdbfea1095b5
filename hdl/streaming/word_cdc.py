"""Word clock-domain crossing: a multi-bit value (a setting, a count) into another clock, never torn."""

from myhdl import Signal, always, block, intbv

from eyestereo.hdl.common.checks import block_error, check_clock, check_distinct, check_signal


@block
def word_cdc(sclk, d, dclk, q):
    """``q`` (destination clock) follows ``d`` (source clock) through a toggle handshake: every value
    ``q`` takes is one ``d`` had, whole, in the order ``d`` had them; when ``d`` stops changing, ``q``
    equals it within 6 destination + 4 source clocks. For what changes rarely or needs only its latest
    value across clocks: the k codes into the Harris clock, the feature counts and the crossing's
    dropped-frame count back into the register bank's clock.

    Source side: when no transfer is under way and ``d`` differs from the word last sent, the word is
    captured in ``held`` and the request bit toggles; ``held`` stays unchanged until the destination's
    acknowledge toggle has come back through two flip-flops. Destination side: the request bit through
    two flip-flops; a change loads ``held`` into ``q`` (``held`` has been stable for two destination
    clocks by then) and toggles the acknowledge. Only the two 1-bit toggles cross (``*_s1``, ``*_s2``:
    mark them ASYNC_REG); ``held`` is a multi-cycle path into ``q`` (a max-delay constraint of one
    destination period covers it).

    No reset: like the FIFO's pointers, the handshake's bits, ``held`` and ``q`` start at 0 with the
    FPGA's configuration and are never reset, so a reset of either domain can never make the other side
    see a false toggle or a torn word; after a reset of the source's logic its new ``d`` comes across
    like any change.

    Ports:
        sclk: source clock.
        d: input, ``Signal(intbv)`` of any width, source clock.
        dclk: destination clock.
        q: output, the width of ``d``, destination clock.

    Parameters: none (the width is the ports').

    Latency: a change of ``d`` is captured at the next source edge when no transfer is under way and
    reaches ``q`` at the third destination edge after that (two synchroniser flops, the load); the
    acknowledge takes three more source edges, so a change during a transfer waits up to 3 destination
    + 4 source clocks before its own capture.

    Resources: 2 x width + 7 flip-flops and a width-bit comparator; 16 bits (make synth, Yosys xc3se):
    72 LUT, 39 FF; nextpnr-ecp5 234 MHz (sclk), 419 MHz (dclk).
    """
    check_clock(sclk, "sclk")
    check_signal("d", d)
    check_clock(dclk, "dclk")
    check_signal("q", q)
    if isinstance(d.val, bool):
        raise block_error("port d must be a Signal(intbv(0)[n:]), got a Signal(bool) (a single flag crosses with "
                          "two flip-flops)")
    n = len(d)
    if isinstance(q.val, bool) or len(q) != n:
        got = "a Signal(bool)" if isinstance(q.val, bool) else f"{len(q)} bits"
        raise block_error(f"port q must be a {n}-bit Signal like d, got {got}")
    check_distinct(dict(q=q), dict(sclk=sclk, d=d, dclk=dclk))

    held = Signal(intbv(0)[n:])
    req, busy = Signal(bool(0)), Signal(bool(0))
    ack_s1, ack_s2 = Signal(bool(0)), Signal(bool(0))
    req_s1, req_s2, req_seen = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    ack = Signal(bool(0))

    @always(sclk.posedge)
    def source():
        if busy:
            if ack_s2 == req:
                busy.next = 0
        elif d != held:
            held.next = d
            req.next = not req
            busy.next = 1

    @always(sclk.posedge)
    def source_sync():
        ack_s1.next = ack
        ack_s2.next = ack_s1

    @always(dclk.posedge)
    def dest_sync():
        req_s1.next = req
        req_s2.next = req_s1

    @always(dclk.posedge)
    def dest():
        if req_s2 != req_seen:
            req_seen.next = req_s2
            q.next = held
            ack.next = req_s2

    return source, source_sync, dest_sync, dest
