"""UART bridge: a host PC reads and writes the AXI4-Lite register bus over a serial line, in bursts."""

from myhdl import Signal, always_comb, always_seq, block, concat, enum, intbv, modbv

from eyestereo.hdl.common.checks import block_error, check_clock, check_distinct, check_int, check_reset, \
    check_signal
from eyestereo.hdl.common.fifo import show_ahead_fifo
from eyestereo.hdl.interfaces.axil import check_axil
from eyestereo.hdl.serial.uart_rx import ByteStream, DEFAULT_CLOCKS_PER_BIT, check_clocks_per_bit, uart_rx
from eyestereo.hdl.serial.uart_tx import uart_tx
from eyestereo.tools.models.uart_bridge import (DEFAULT_TIMEOUT, ERRORS_MAX, IDENTIFY, READ, REPLY_ERROR,
                                                REPLY_IDENTIFY, REPLY_READ, REPLY_WRITE, TIMEOUT, VERSION, WRITE)

__all__ = ["uart_bridge"]

#: the error count's width (the ``errors`` port)
ERROR_BITS = 16
#: the timeout reply's second byte, where the sender takes it (a Python constant: a shift converts badly)
TIMEOUT_WORD = TIMEOUT << 24
#: the receive FIFO's depth limits (LUT-RAM bytes)
FIFO_MIN, FIFO_MAX = 2, 1024


@block
def uart_bridge(clk, rst, rx, tx, bus, errors, *, clocks_per_bit: int = DEFAULT_CLOCKS_PER_BIT, addr_bits=24,
                timeout=DEFAULT_TIMEOUT, fifo=16):
    """Serves a host's read and write requests, received on ``rx`` (8N1, ``clocks_per_bit`` clocks per bit),
    as accesses on the AXI4-Lite bus ``bus`` (this block is its master), and sends the replies on ``tx``.

    The protocol (all multi-byte fields big-endian; the constants are declared once, in
    :mod:`eyestereo.tools.models.uart_bridge`, which is also the bit-true model; the host's side is
    :mod:`eyestereo.tools.board.protocol`)::

        identify   host:  'I' 0x49
                   board: 'i' 0x69 | version[4] = 0x45 0x53 0x42 0x31 ("ESB1")
        read       host:  'R' 0x52 | addr[4] | count[1]                     count + 1 = 1..256 words
                   board: 'r' 0x72 | resp[1] data[4] | resp[1] data[4] | ...  (count + 1 times)
        write      host:  'W' 0x57 | addr[4] | count[1] | strb[1] | data[4] | data[4] | ...  (count + 1 words)
                   board: 'w' 0x77 | resp[1] | resp[1] | ...                 (one per word, after its write)
        unknown    host:  any other first byte b
                   board: '?' 0x3F | b
        timeout    host:  a request whose next byte does not come within `timeout` clocks
                   board: (what it had sent of its reply) | '?' 0x3F | 'T' 0x54

    Word i of a request goes to byte address ``addr + 4 i``; resp is the AXI response (0 OKAY, 2 SLVERR,
    3 DECERR), the word read (RRESP, RDATA) or the write's BRESP; ``strb`` is every write's WSTRB (its low
    4 bits; the high 4 are ignored). Address bits above ``addr_bits`` are ignored (the bus has
    ``addr_bits``; the address wraps there), the two low bits reach the bus as given. After a reply, or
    after an abandoned request, the bridge waits for a new request: a host that lost track waits longer
    than the timeout and sends 'I'.

    Flow, and the receive FIFO's limit: a read burst sends 5 bytes per word, the next word's bus read
    overlapping the current word's bytes (the line stays busy while each read takes less than about 4
    byte times, 40 x ``clocks_per_bit`` clocks). A write burst's data keep coming while the bridge writes:
    the received bytes wait in a FIFO of ``fifo`` bytes (LUT-RAM) plus the receiver's byte and the head
    register's, so a write may wait on the bus up to ``fifo`` byte times (16 bytes at 3 Mbaud: 53 us)
    without loss, and the writes must average no more than 4 byte times each (a word's 4 bytes). Beyond
    that a byte is lost: it is counted as an error and the request goes wrong (it ends in a timeout); a host that cannot
    bound the bus's wait sends at most ``fifo // 4`` words ahead of the resp bytes it has received. The
    host must read each reply before its next request exceeds the FIFO (SerialBus does).

    ``errors`` counts, saturating at 0xFFFF: bytes dropped by the receiver (a framing error: a 0 stop
    bit; an overrun: the FIFO full), unknown request bytes and abandoned requests.

    Bus rules (:mod:`eyestereo.hdl.interfaces.axil`): one access at a time; a write raises ``awvalid`` and
    ``wvalid`` together and lowers each after its own transfer, then ``bready`` until the response; a read
    raises ``arvalid``, then ``rready`` until the data; the valids are flip-flops and never wait for a
    ready. ``awprot``/``arprot`` are 0.

    Ports:
        clk, rst: clock, synchronous active-high reset.
        rx: input, the serial line from the host (idle high; asynchronous: synchronised inside).
        tx: output, the serial line to the host (a flip-flop, idle high).
        bus: :class:`~eyestereo.hdl.interfaces.axil.AxiLite` of ``addr_bits`` address bits, driven as master.
        errors: output, 16 bits: the error count (above).

    Parameters:
        clocks_per_bit: clocks per bit, 8..2**20 (the board: 100 MHz / 3 Mbaud = 33; 868 for 115200 baud).
        addr_bits: the bus's address bits, 3..32 (default 24: the register bank's 23 and the board's own
            registers above).
        timeout: clocks without a byte after which a request in progress is abandoned (default 100,000:
            1 ms at 100 MHz); more than 2 byte times (20 x ``clocks_per_bit``), at most 2**31 - 1.
        fifo: receive FIFO bytes, 2..1024 (default 16).

    Latency: an identify reply's start bit 4 clocks after the receiver delivers the 'I' (the FIFO, the head
    register, the request machine, the transmitter); a read's first bus access 3 clocks after the count byte
    is delivered, its data's first byte on the line as soon as the 'r' has gone out; a write's bus access
    3 clocks after its fourth data byte is delivered.

    Resources: uart_rx, uart_tx, the FIFO (8 x ``fifo`` LUT-RAM bits), the 32-bit address shift register,
    address, data and reply registers, the timeout counter, the error counter. The catalogue's
    configuration (33 clocks per bit, 24 address bits, timeout 100,000, FIFO 16; make synth's flow,
    Yosys xc3se): 470 LUT + 8 LUT-RAM, 289 FF, 0 RAMB16, 0 MULT; nextpnr-ecp5 142.5 MHz (the slowest of seeds
    1-4).
    """
    check_clock(clk)
    check_reset(rst)
    check_signal("rx", rx, width=1)
    check_signal("tx", tx, width=1)
    cpb = check_clocks_per_bit(clocks_per_bit)
    abits = check_int("addr_bits", addr_bits, 3, 32)
    check_axil("bus", bus, addr_bits=abits)
    check_signal("errors", errors, width=ERROR_BITS)
    tmo = check_int("timeout", timeout, None, (1 << 31) - 1)
    if tmo <= 20 * cpb:
        raise block_error(f"parameter timeout={tmo} must be more than 2 byte times (20 x clocks_per_bit = "
                          f"{20 * cpb} clocks), else a request would be abandoned between its bytes")
    depth = check_int("fifo", fifo, FIFO_MIN, FIFO_MAX)
    check_distinct(dict(tx=tx, bus=bus, errors=errors), dict(clk=clk, rst=rst, rx=rx))

    # receiver -> FIFO
    rx_bytes = ByteStream()
    frame_error, overrun = Signal(bool(0)), Signal(bool(0))
    receiver = uart_rx(clk, rst, rx, rx_bytes, frame_error, overrun, clocks_per_bit=cpb)
    push, pop, q_pop = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    q_head = Signal(intbv(0)[8:])
    # the request machine reads its byte from a register (head, valid while has_head) that the FIFO fills: the
    # LUT-RAM's read and the compares behind it in one clock were the board's slowest memory-clock path (a
    # byte every other clock at most, the line brings one every 10 x clocks_per_bit)
    head, has_head = Signal(intbv(0)[8:]), Signal(bool(0))
    level = Signal(intbv(0, min=0, max=depth + 1))
    queue = show_ahead_fifo(clk, rst, rx_bytes.data, push, q_head, q_pop, level, depth=depth)

    # reply sender -> transmitter: tx_first is the next byte to send, tx_rest the (up to 4) after it
    tx_bytes = ByteStream()
    transmitter = uart_tx(clk, rst, tx_bytes, tx, clocks_per_bit=cpb)
    tx_first = Signal(intbv(0)[8:])
    tx_rest = Signal(intbv(0)[32:])
    tx_left = Signal(intbv(0, min=0, max=6))

    # names with a prefix: VHDL has one name space for literals and signals (addr, strb, rdata)
    st = enum("S_IDLE", "S_ADDR", "S_COUNT", "S_STRB", "S_RHEAD", "S_RADDR", "S_RDATA", "S_RSEND", "S_WHEAD",
              "S_WDATA", "S_WBUS", "S_WRESP", "S_WSEND", "S_TMO")
    state = Signal(st.S_IDLE)
    waiting = Signal(bool(0))  # a request in progress waits for its next byte (the timeout runs)
    is_write = Signal(bool(0))
    nb = Signal(intbv(0, min=0, max=4))  # bytes of the address / data word so far
    hdr = Signal(intbv(0)[32:])
    addr = Signal(modbv(0)[abits:])
    words_left = Signal(intbv(0, min=0, max=256))
    strb = Signal(intbv(0)[4:])
    wdata = Signal(intbv(0)[32:])
    resp = Signal(intbv(0)[2:])
    rdata = Signal(intbv(0)[32:])
    awvalid, wvalid, arvalid = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    timer = Signal(intbv(0, min=0, max=tmo + 1))
    fault = Signal(bool(0))  # an unknown byte or an abandoned request (counted next clock)
    count = Signal(intbv(0)[ERROR_BITS:])

    @always_comb
    def flow():
        rx_bytes.ready.next = level != depth
        push.next = rx_bytes.valid and level != depth
        waiting.next = state == st.S_ADDR or state == st.S_COUNT or state == st.S_STRB or state == st.S_WDATA
        pop.next = has_head and ((state == st.S_IDLE and tx_left == 0) or state == st.S_ADDR or state == st.S_COUNT
                                 or state == st.S_STRB or state == st.S_WDATA)
        q_pop.next = level != 0 and not has_head
        tx_bytes.valid.next = tx_left != 0
        tx_bytes.data.next = tx_first

    @always_seq(clk.posedge, reset=rst)
    def machine():
        fault.next = 0
        # the sender: one byte per transmitter handshake (loads below only when it is empty)
        if tx_left != 0 and tx_bytes.ready:
            tx_first.next = tx_rest[32:24]
            tx_rest.next = concat(tx_rest[24:0], intbv(0)[8:])
            tx_left.next = tx_left - 1
        # the head register: filled from the FIFO, emptied by the machine's pop
        if q_pop:
            head.next = q_head
            has_head.next = 1
        elif pop:
            has_head.next = 0
        # the timeout: clocks a request waits for a byte with the FIFO and the head register empty
        if waiting and level == 0 and not has_head:
            if timer == tmo - 1:
                timer.next = 0
                state.next = st.S_TMO
                fault.next = 1
            else:
                timer.next = timer + 1
        else:
            timer.next = 0

        if state == st.S_IDLE:
            if pop:
                nb.next = 0
                if head == IDENTIFY:
                    tx_first.next = REPLY_IDENTIFY
                    tx_rest.next = VERSION
                    tx_left.next = 5
                elif head == READ:
                    is_write.next = 0
                    state.next = st.S_ADDR
                elif head == WRITE:
                    is_write.next = 1
                    state.next = st.S_ADDR
                else:
                    tx_first.next = REPLY_ERROR
                    tx_rest.next = concat(head, intbv(0)[24:])
                    tx_left.next = 2
                    fault.next = 1
        elif state == st.S_ADDR:
            if pop:
                hdr.next = concat(hdr[24:0], head)
                if nb == 3:
                    state.next = st.S_COUNT
                else:
                    nb.next = nb + 1
        elif state == st.S_COUNT:
            if pop:
                words_left.next = head
                addr.next = hdr[abits:0]
                if is_write:
                    state.next = st.S_STRB
                else:
                    state.next = st.S_RHEAD
        elif state == st.S_STRB:
            if pop:
                strb.next = head[4:0]
                state.next = st.S_WHEAD
        elif state == st.S_RHEAD:
            if tx_left == 0:
                tx_first.next = REPLY_READ
                tx_left.next = 1
                arvalid.next = 1
                state.next = st.S_RADDR
        elif state == st.S_RADDR:
            if bus.arready:
                arvalid.next = 0
                state.next = st.S_RDATA
        elif state == st.S_RDATA:
            if bus.rvalid:
                resp.next = bus.rresp
                rdata.next = bus.rdata
                state.next = st.S_RSEND
        elif state == st.S_RSEND:
            # loaded when the sender is empty: the last word's fifth byte has just gone to the transmitter,
            # so this word's bus read ran while that word's bytes went out
            if tx_left == 0:
                tx_first.next = resp
                tx_rest.next = rdata
                tx_left.next = 5
                if words_left == 0:
                    state.next = st.S_IDLE
                else:
                    words_left.next = words_left - 1
                    addr.next = addr + 4
                    arvalid.next = 1
                    state.next = st.S_RADDR
        elif state == st.S_WHEAD:
            if tx_left == 0:
                tx_first.next = REPLY_WRITE
                tx_left.next = 1
                nb.next = 0
                state.next = st.S_WDATA
        elif state == st.S_WDATA:
            if pop:
                wdata.next = concat(wdata[24:0], head)
                if nb == 3:
                    awvalid.next = 1
                    wvalid.next = 1
                    state.next = st.S_WBUS
                else:
                    nb.next = nb + 1
        elif state == st.S_WBUS:
            if bus.awready:
                awvalid.next = 0
            if bus.wready:
                wvalid.next = 0
            if (not awvalid or bus.awready) and (not wvalid or bus.wready):
                state.next = st.S_WRESP
        elif state == st.S_WRESP:
            if bus.bvalid:
                resp.next = bus.bresp
                state.next = st.S_WSEND
        elif state == st.S_WSEND:
            if tx_left == 0:
                tx_first.next = resp
                tx_left.next = 1
                if words_left == 0:
                    state.next = st.S_IDLE
                else:
                    words_left.next = words_left - 1
                    addr.next = addr + 4
                    nb.next = 0
                    state.next = st.S_WDATA
        else:  # TMO
            if tx_left == 0:
                tx_first.next = REPLY_ERROR
                tx_rest.next = TIMEOUT_WORD
                tx_left.next = 2
                state.next = st.S_IDLE

    @always_seq(clk.posedge, reset=rst)
    def error_count():
        # the receiver's drops and the machine's events can come in the same clock: two at once
        if (frame_error or overrun) and fault:
            if count >= ERRORS_MAX - 1:
                count.next = ERRORS_MAX
            else:
                count.next = count + 2
        elif frame_error or overrun or fault:
            if count != ERRORS_MAX:
                count.next = count + 1

    @always_comb
    def bus_out():
        bus.awaddr.next = addr
        bus.araddr.next = addr
        bus.awprot.next = 0
        bus.arprot.next = 0
        bus.awvalid.next = awvalid
        bus.wvalid.next = wvalid
        bus.wdata.next = wdata
        bus.wstrb.next = strb
        bus.arvalid.next = arvalid
        bus.bready.next = state == st.S_WRESP
        bus.rready.next = state == st.S_RDATA
        errors.next = count

    return receiver, queue, transmitter, flow, machine, error_count, bus_out
