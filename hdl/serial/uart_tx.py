"""UART transmitter (8N1): bytes from a valid/ready byte port -> the serial line, back to back."""

from myhdl import Signal, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.common.checks import check_clock, check_distinct, check_reset, check_signal
from eyestereo.hdl.serial.uart_rx import DEFAULT_CLOCKS_PER_BIT, check_bytes, check_clocks_per_bit

__all__ = ["uart_tx"]


@block
def uart_tx(clk, rst, sink, tx, *, clocks_per_bit: int = DEFAULT_CLOCKS_PER_BIT):
    """Sends each byte taken from ``sink`` as an 8N1 frame on ``tx``: a start bit (0), the 8 data bits LSB
    first, a stop bit (1), ``clocks_per_bit`` clocks each; the line idles high and is a flip-flop (no
    glitches on the pin).

    ``sink.ready`` is high while the transmitter is idle and in the last clock of a stop bit, so a byte
    waiting on ``sink`` starts right after the previous stop bit: a stream of bytes goes out at the full
    rate, 10 x ``clocks_per_bit`` clocks per byte, with no idle time between frames. ``ready`` comes from
    flip-flops only (it never depends on ``valid``). Timing at 8 clocks per bit: byte A offered in clock 0,
    byte B offered right after it and waiting (``#`` high, ``_`` low, ``.`` don't care; ``a0`` .. ``a7``: A's
    data bits; ``^``: the byte moves at the edge that ends the cycle)::

        clock    0    1..8    9..16   ..   65..72   73..79   80    81..88
        valid    #    #       #            #        #        #     _
        data     A    B       B            B        B        B     .
        ready    #    _       _            _        _        #     _
        tx       #    _       a0      ..   a7       #        #     _        (B's start bit from clock 81)
        moves    ^                                           ^

    (A's start bit is clocks 1..8, its stop bit 73..80; B moves at the end of clock 80, the stop bit's last
    clock, so its start bit follows with no idle clock.) The model is
    :func:`eyestereo.tools.models.uart_tx.uart_tx`, edge for edge.

    Ports:
        clk, rst: clock, synchronous active-high reset (the line goes high).
        sink: :class:`~eyestereo.hdl.serial.uart_rx.ByteStream` in: the bytes to send.
        tx: output, the serial line.

    Parameters:
        clocks_per_bit: clocks per bit, 8..2**20 (100 MHz / 3 Mbaud: 33; / 115200 baud: 868).

    Latency: the start bit begins on ``tx`` the clock after the edge that takes the byte.

    Resources: a 9-bit shift register, a bit counter, a clock counter of ceil(log2(clocks_per_bit)) bits,
    the line's flip-flop: about 25 flip-flops at 33 clocks per bit.
    """
    check_clock(clk)
    check_reset(rst)
    check_bytes("sink", sink)
    check_signal("tx", tx, width=1)
    cpb = check_clocks_per_bit(clocks_per_bit)
    check_distinct(dict(tx=tx), dict(clk=clk, rst=rst, sink=sink))

    busy = Signal(bool(0))
    bit_no = Signal(intbv(0, min=0, max=10))  # the bit on the line: 0 start, 1..8 data, 9 stop
    count = Signal(intbv(0, min=0, max=cpb))
    shreg = Signal(intbv(0)[9:])  # the bits still to send, the next one in bit 0
    line = Signal(bool(1))
    ready = Signal(bool(1))

    @always_comb
    def handshake():
        ready.next = not busy or (bit_no == 9 and count == cpb - 1)

    @always_seq(clk.posedge, reset=rst)
    def send():
        if sink.valid and ready:
            shreg.next = concat(True, sink.data)
            line.next = 0
            busy.next = 1
            bit_no.next = 0
            count.next = 0
        elif busy:
            if count == cpb - 1:
                count.next = 0
                if bit_no == 9:
                    busy.next = 0
                else:
                    bit_no.next = bit_no + 1
                    line.next = shreg[0]
                    shreg.next = concat(True, shreg[9:1])
            else:
                count.next = count + 1

    @always_comb
    def outputs():
        sink.ready.next = ready
        tx.next = line

    return handshake, send, outputs
