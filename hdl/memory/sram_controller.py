"""SRAM controller: the 1M x 18 synchronous SRAM's pins on one side, a simple in-order word port on the other."""

from myhdl import Signal, always, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.common.checks import block_error, check_choice, check_clock, check_distinct, check_int, check_reset
from eyestereo.hdl.common.registers import delay, en_reg
from eyestereo.hdl.interfaces.sram_bus import SramCmd, SramPins, SramRsp, check_bundle
from eyestereo.tools.models.sram_controller import write_block_window
from eyestereo.tools.sram import KINDS


def _check_ports(cmd, rsp, sram):
    check_bundle("cmd", cmd, SramCmd)
    check_bundle("rsp", rsp, SramRsp)
    check_bundle("sram", sram, SramPins)
    if cmd.addr_bits != sram.addr_bits:
        raise block_error(f"port cmd has {cmd.addr_bits} address bits, the SRAM pins {sram.addr_bits}")
    for name, b in (("cmd", cmd.data_bits), ("rsp", rsp.data_bits)):
        if b != sram.data_bits:
            raise block_error(f"port {name} has {b} data bits, the SRAM pins {sram.data_bits}")
    if rsp.tag_bits != cmd.tag_bits:
        raise block_error(f"port rsp has {rsp.tag_bits} tag bits, cmd {cmd.tag_bits}: they must match")


@block
def sram_controller(clk, rst, cmd, rsp, sram, *, kind: str = "nobl", read_latency: int = 2):
    """One access per clock where the part allows it; read data back in order with a valid flag.

    The word port and the pins, with timing diagrams for both kinds of part, are documented in
    :mod:`eyestereo.hdl.interfaces.sram_bus`; the part's rules in :mod:`eyestereo.tools.sram`.

    Every pin output comes straight from a flip-flop, and the read data is registered as it enters, so
    all of them can be packed into the I/O blocks. The controller idles by deselecting the part
    (``ce_n`` high, ``ld_n`` low), never by a burst-continue cycle. On a pipelined SyncBurst part a write
    is held off (``cmd_ready`` low) while a read taken in the last ``read_latency + 1`` clocks could still
    be on the bus, which leaves one idle bus cycle in each direction (the turnaround); a NoBL part takes
    reads and writes in any order, every clock.

    Ports:
        clk, rst: clock and synchronous active-high reset (clears the access pipeline and deselects).
        cmd: :class:`~eyestereo.hdl.interfaces.sram_bus.SramCmd`, the commands (20-bit address, 16-bit data, 2 byte
            enables, any tag width).
        rsp: :class:`~eyestereo.hdl.interfaces.sram_bus.SramRsp`, the read data, with the tag of its command.
        sram: :class:`~eyestereo.hdl.interfaces.sram_bus.SramPins`, the part's pins.

    Parameters:
        kind: ``"nobl"`` (default) or ``"pipelined"``, the part on the board.
        read_latency: the part's read latency in clocks, 1..3 (2 for the pipelined 100 MHz parts).

    Latency: read_latency + 2 clocks from a read's command to its ``rsp_valid`` (4 for the 100 MHz
    parts); writes are posted.

    Resources: the pin registers (about 45 flip-flops), a read_latency + 1 stage pipeline of the read
    flags and tags, for NoBL a read_latency stage write-data pipeline; a few LUTs.
    """
    check_clock(clk)
    check_reset(rst)
    _check_ports(cmd, rsp, sram)
    check_distinct(dict(rsp=rsp, sram=sram), dict(clk=clk, rst=rst, cmd=cmd))
    kind = check_choice("kind", kind, KINDS)
    lat = check_int("read_latency", read_latency, 1, 3)

    nb = sram.data_bits // 8
    tb = cmd.tag_bits
    lo, hi = write_block_window(kind, lat)  # a write waits while a read was taken lo..hi clocks before it
    hw = max(hi, 1)
    fire = Signal(bool(0))
    wfire = Signal(bool(0))
    rfire = Signal(bool(0))
    rhist = Signal(intbv(0)[hw:])  # bit j: a read was taken j+1 clocks ago
    block_w = Signal(bool(0))
    no_bytes = (1 << nb) - 1
    be_n = Signal(intbv(no_bytes)[nb:])

    insts = []

    if hi >= lo:
        mask = 0
        for d in range(lo, hi + 1):
            mask |= 1 << (d - 1)

        @always_comb
        def hazard():
            # Registered history only: cmd_ready depends on cmd_we and flip-flops, nothing else.
            block_w.next = (rhist & mask) != 0

        insts.append(hazard)
    # (NoBL: block_w is never driven and converts to a constant '0'.)

    @always_comb
    def handshake():
        cmd.ready.next = not (cmd.we and block_w)
        fire.next = cmd.valid and not (cmd.we and block_w)
        wfire.next = cmd.valid and cmd.we and not block_w
        rfire.next = cmd.valid and not cmd.we
        be_n.next = ~cmd.be

    insts.append(handshake)

    if hw > 1:
        @always_seq(clk.posedge, reset=rst)
        def history():
            rhist.next = concat(rhist[hw - 1:0], rfire)
    else:
        @always_seq(clk.posedge, reset=rst)
        def history():
            rhist.next[0] = rfire

    insts.append(history)

    # Pin registers. Control pins take the reset's deselect; the address and data registers need none.
    @always_seq(clk.posedge, reset=rst)
    def control_pins():
        sram.ce_n.next = not fire
        sram.ld_n.next = False
        sram.we_n.next = not wfire
        if wfire:
            sram.bw_n.next = be_n
        else:
            sram.bw_n.next = no_bytes

    insts += [control_pins, en_reg(clk, fire, cmd.addr, sram.addr)]

    # Write data: with the address on a pipelined SyncBurst part (ADSC# write), read_latency clocks later
    # on a NoBL part.
    if kind == "pipelined":
        @always_seq(clk.posedge, reset=rst)
        def data_enable():
            sram.dq_oe.next = wfire

        insts += [data_enable, en_reg(clk, wfire, cmd.wdata, sram.dq_o)]
    else:
        wflags = Signal(intbv(0)[lat:])  # bit i: a write was taken i+1 clocks ago
        wd_first = Signal(intbv(0)[sram.data_bits:])
        wd_last = wd_first if lat == 1 else Signal(intbv(0)[sram.data_bits:])

        if lat > 1:
            @always_seq(clk.posedge, reset=rst)
            def write_flags():
                wflags.next = concat(wflags[lat - 1:0], wfire)
                sram.dq_oe.next = wflags[lat - 1]
        else:
            @always_seq(clk.posedge, reset=rst)
            def write_flags():
                wflags.next[0] = wfire
                sram.dq_oe.next = wflags[0]

        @always(clk.posedge)
        def write_data_in():
            wd_first.next = cmd.wdata

        @always(clk.posedge)
        def data_out():
            sram.dq_o.next = wd_last

        insts += [write_flags, write_data_in, data_out]
        if lat > 1:
            insts.append(delay(clk, wd_first, wd_last, clocks=lat - 1))

    # Read side: OE# low in the cycle the part drives a read's data (read_latency clocks after the pins
    # carry the read), the input register samples at the next edge and is rsp_data itself.
    rpipe = Signal(intbv(0)[lat + 1:])  # bit i: a read was taken i+1 clocks ago

    @always_seq(clk.posedge, reset=rst)
    def read_flags():
        rpipe.next = concat(rpipe[lat:0], rfire)
        sram.oe_n.next = not rpipe[lat - 1]
        rsp.valid.next = rpipe[lat]

    @always(clk.posedge)
    def read_data():
        rsp.data.next = sram.dq_i

    tag_in = Signal(intbv(0)[tb:])
    tag_out = Signal(intbv(0)[tb:])

    @always_comb
    def tag_src():
        tag_in.next = cmd.tag

    @always_comb
    def tag_dst():
        rsp.tag.next = tag_out

    insts += [read_flags, read_data, tag_src, tag_dst, delay(clk, tag_in, tag_out, clocks=lat + 2)]
    return insts
