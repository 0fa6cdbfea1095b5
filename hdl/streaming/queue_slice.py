"""Queue register slice: a queue read port passed on from flip-flops, both ways, at full rate."""

from myhdl import Signal, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.common.checks import block_error, check_clock, check_reset
from eyestereo.hdl.interfaces.queue import check_queue


@block
def queue_slice(clk, rst, sink, source):
    """Pass a :class:`~eyestereo.hdl.interfaces.queue.QueuePort` on with every output from a flip-flop.

    Why: a queue whose word comes straight out of a block RAM (the async FIFO's read port) gives its
    consumer the RAM's clock-to-output time, 5.8 ns on the ECP5 without the RAM's output register, before
    any of the consumer's logic: the memory clock's critical path at 86 MHz (issue 23). Behind this slice
    the consumer's logic starts at a flip-flop, and the queue's ``ready`` comes from one too.

    Two word registers: the output register and a skid register that catches the word the queue moved in
    the clock the consumer stopped taking (``sink.ready`` is registered, so it falls a clock late). One
    word per clock in and out while the consumer takes; the frame rules of the queue port pass unchanged
    (words in order, none lost or added; a reset token is a word like any other).

    Timing (the queue offers ``w0``..``w3``; the consumer stalls in cycle 3; ``*`` the consumer takes)::

        cycle          0    1    2    3    4    5    6
        sink.valid     #    #    #    #    _    _    _
        sink.ready     #    #    #    #    _    #    #
        sink.data     w0   w1   w2   w3    .    .    .
        source.valid   _    #    #    #    #    #    _
        source.ready   #    #    #    _    #    #    #
        source.data    .   w0   w1   w2   w2   w3    .
        skid           .    .    .    .   w3    .    .
        takes               *    *         *    *

    Ports:
        clk, rst: clock; synchronous active-high reset (empties both registers; the queue side sees
            ``ready`` high again the clock after). Reset it with the queue's read side: words in the
            slice are discarded with it, as the queue discards the word in its own output register, so
            the queue's rule "after a read reset the next word is the first of a frame" still holds
            (the queue skips the rest of a frame whose last word that left it had no ``eof``).
        sink: QueuePort, the queue (consumer side: ``sink.ready`` is driven here).
        source: QueuePort of the same data width, to the consumer.

    Latency: a word offered by the queue is offered on ``source`` one clock later.

    Resources: 2 x (data width + 2) flip-flops, 2 control flip-flops, one multiplexer per bit.
    """
    check_clock(clk)
    check_reset(rst)
    check_queue("sink", sink)
    check_queue("source", source)
    if source.data_width != sink.data_width:
        raise block_error(f"port source carries {source.data_width}-bit data, port sink {sink.data_width}: "
                          f"a slice passes words unchanged")
    dw = sink.data_width
    W = dw + 2  # data, eol, eof
    word_in = Signal(intbv(0)[W:])
    out, skid = Signal(intbv(0)[W:]), Signal(intbv(0)[W:])
    out_v, skid_v = Signal(bool(0)), Signal(bool(0))

    @always_comb
    def pack():
        word_in.next = concat(sink.eof, sink.eol, sink.data)

    @always_seq(clk.posedge, reset=rst)
    def registers():
        moved_in = sink.valid and not skid_v  # sink.ready is "not skid_v"
        if source.ready or not out_v:
            # the output register is free in the next clock: the skid word first, else the queue's
            if skid_v:
                out.next = skid
                out_v.next = True
                skid_v.next = False
            elif moved_in:
                out.next = word_in
                out_v.next = True
            else:
                out_v.next = False
        elif moved_in:
            skid.next = word_in
            skid_v.next = True

    @always_comb
    def ports():
        sink.ready.next = not skid_v
        source.valid.next = out_v
        source.data.next = out[dw:]
        source.eol.next = out[dw]
        source.eof.next = out[dw + 1]

    return pack, registers, ports
