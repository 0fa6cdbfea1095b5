"""UART receiver (8N1): the serial line -> bytes on a valid/ready byte port, framing errors and overruns flagged.

Also declares :class:`ByteStream`, the byte port of the serial room (uart_rx's source, uart_tx's sink).
"""

from myhdl import Signal, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.common.checks import check_clock, check_distinct, check_int, check_port, \
    check_reset, check_signal
from eyestereo.hdl.interfaces.bundle import IN, OUT, Bundle, Member
from eyestereo.tools.models.uart_rx import check_offset

__all__ = ["ByteStream", "check_bytes", "check_clocks_per_bit", "uart_rx"]

#: the fewest clocks per bit: the start check and the samples need a few clocks per bit to sit near the middle
MIN_CLOCKS_PER_BIT = 8
#: the most: a 100 MHz clock down to 1200 baud (the counters are sized from the parameter)
MAX_CLOCKS_PER_BIT = 1 << 20


class ByteStream(Bundle):
    """A byte port with a valid/ready handshake (ports ``<arg>_data``, ``<arg>_valid``, ``<arg>_ready``).

    The producer raises ``valid`` with a byte on ``data`` and holds both until a rising edge at which the
    consumer's ``ready`` is high too: the byte moves at that edge. ``ready`` may wait for ``valid``;
    ``valid`` never waits for ``ready``. Timing (``#`` high, ``_`` low, ``.`` don't care; ``^`` a byte
    moves at the edge that ends the cycle)::

        cycle   0    1    2    3    4    5
        valid   _    #    #    #    _    #
        ready   #    _    #    #    #    #
        data    .    A    A    B    .    C
        moves             ^    ^         ^
    """

    MEMBERS = (Member("data", 8, OUT), Member("valid", bool, OUT), Member("ready", bool, IN))

    def __init__(self):
        self.make()

    def __repr__(self) -> str:
        return "ByteStream()"


def check_bytes(name: str, port) -> None:
    """A :class:`ByteStream` port, else a ValueError naming the port (and the block)."""
    check_port(name, port, ByteStream)


#: The default bit time: 33 clocks, 3.03 Mbaud from the board's 100 MHz memory clock (within 1 % of the FT231X's
#: 3 Mbaud, its fastest standard rate); 868 gives 115,200 baud.
DEFAULT_CLOCKS_PER_BIT = 33


def check_clocks_per_bit(clocks_per_bit) -> int:
    """The ``clocks_per_bit`` parameter: an integer in 8..2**20."""
    return check_int("clocks_per_bit", clocks_per_bit, MIN_CLOCKS_PER_BIT, MAX_CLOCKS_PER_BIT)


@block
def uart_rx(clk, rst, rx, source, frame_error, overrun, *, clocks_per_bit: int = DEFAULT_CLOCKS_PER_BIT):
    """Receives 8N1 bytes (start bit, 8 data bits LSB first, stop bit; the line idles high) at
    ``clocks_per_bit`` clocks per bit and offers each on ``source``.

    The line comes from another clock domain: two flip-flops synchronise it (``rx_s1``, ``rx_s2``; mark
    them ASYNC_REG). A low line starts a byte; the start bit is checked near its middle,
    ``(clocks_per_bit + 1) // 2`` clocks after the low was first seen: a glitch shorter than half a bit
    is high again by then and makes nothing. The data bits and the stop bit are sampled a bit apart from
    there, each near its middle, so a sender off in baud by up to about +-4 % is read right (the drift
    over 9.5 bits must stay under the half bit the sample has to spare). Right after the stop bit's
    sample the receiver looks for the next start bit. A stop bit of 0 is a framing error: the byte is
    dropped, ``frame_error`` pulses, and the receiver waits for the line to go high before it looks for a
    start bit (a held-low line, a break, makes one error, not a stream of zeros); the line is waited for
    high after reset too.

    The byte stays on ``source`` until taken (a :class:`ByteStream`); a byte that completes while the last
    one is still there is dropped and ``overrun`` pulses (a consumer with ``ready`` high takes every byte).
    The model is :func:`eyestereo.tools.models.uart_rx.uart_rx`, edge for edge.

    Ports:
        clk, rst: clock, synchronous active-high reset.
        rx: input, the serial line (idle high), asynchronous to ``clk``.
        source: :class:`ByteStream` out: the bytes received.
        frame_error: output, high for one clock when a byte is dropped for its 0 stop bit.
        overrun: output, high for one clock when a byte is dropped because ``source`` still held one.

    Parameters:
        clocks_per_bit: clocks per bit, 8..2**20 (100 MHz / 3 Mbaud: 33; / 115200 baud: 868).

    Latency: ``source.valid`` rises 2 + (clocks_per_bit + 1) // 2 + 9 * clocks_per_bit clocks after the
    first clock the line is low (two synchroniser flops, to the stop bit's middle).

    Resources: the synchroniser, a bit counter, a clock counter of ceil(log2(clocks_per_bit)) bits, a 8-bit
    shift register and the output byte: about 35 flip-flops at 33 clocks per bit.
    """
    check_clock(clk)
    check_reset(rst)
    check_signal("rx", rx, width=1)
    check_bytes("source", source)
    check_signal("frame_error", frame_error, width=1)
    check_signal("overrun", overrun, width=1)
    cpb = check_clocks_per_bit(clocks_per_bit)
    check_distinct(dict(source=source, frame_error=frame_error, overrun=overrun), dict(clk=clk, rst=rst, rx=rx))

    first = check_offset(cpb) - 1  # the counter's value when a start bit is first seen
    rx_s1, rx_s2 = Signal(bool(1)), Signal(bool(1))
    # 0 break (wait for high), 1 idle (wait for a start bit), 2 receiving
    state = Signal(intbv(0, min=0, max=3))
    bit_no = Signal(intbv(0, min=0, max=10))  # 0 start, 1..8 data, 9 stop
    count = Signal(intbv(0, min=0, max=cpb))
    shreg = Signal(intbv(0)[8:])
    valid = Signal(bool(0))

    @always_seq(clk.posedge, reset=rst)
    def synchroniser():
        rx_s1.next = rx
        rx_s2.next = rx_s1

    @always_seq(clk.posedge, reset=rst)
    def receive():
        frame_error.next = 0
        overrun.next = 0
        if valid and source.ready:
            valid.next = 0
        if state == 0:
            if rx_s2:
                state.next = 1
        elif state == 1:
            if not rx_s2:
                state.next = 2
                bit_no.next = 0
                count.next = first
        elif count != 0:
            count.next = count - 1
        else:
            count.next = cpb - 1
            if bit_no == 0:
                if rx_s2:
                    state.next = 1  # a glitch: high again before the start bit's middle
                else:
                    bit_no.next = 1
            elif bit_no != 9:
                shreg.next = concat(rx_s2, shreg[8:1])
                bit_no.next = bit_no + 1
            elif rx_s2:
                state.next = 1
                if valid and not source.ready:
                    overrun.next = 1
                else:
                    source.data.next = shreg
                    valid.next = 1
            else:
                state.next = 0
                frame_error.next = 1

    @always_comb
    def outputs():
        source.valid.next = valid

    return synchroniser, receive, outputs
