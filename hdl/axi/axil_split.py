"""AXI4-Lite split: one master reaches two slaves, chosen by one address bit, one transaction at a time.

On the board the UART bridge's 24-bit address space is cut in two at bit ``split_bit`` = 23: addresses
with the bit 0 go to the front end's register bank (``s0``), with the bit 1 to the board's own registers
(``s1``). Each port keeps the rules of :mod:`eyestereo.hdl.interfaces.axil`; the split is a slave on
``m`` and a master on ``s0`` and ``s1``, and every output is a flip-flop (or one gated by the registered
choice of slave), so no path runs from an input to an output.

The address each slave sees: the master's address **with bit** ``split_bit`` **cleared**, cut to the
slave's ``addr_bits`` (its low bits). So each slave's space starts at 0 and the register bank on ``s0``
(23 address bits) sees exactly the register map's addresses; a slave narrower than ``split_bit`` bits
sees its space repeated (it decodes its own bits only). ``awprot``/``arprot``, ``wdata``/``wstrb`` and the
responses (``bresp``, ``rresp``: OKAY, SLVERR, DECERR, whatever the slave says) pass unchanged; the
split never answers by itself.

The rule (:mod:`eyestereo.tools.models.axil_split`): a request is an ``awvalid`` (a write) or an
``arvalid`` (a read) sampled at a rising edge while the split is idle; when both are there the kind not
served last goes first (a write after reset). A write's address moves first (``awready`` in the clock
after ``awvalid`` was sampled); ``wready`` rises in the clock after that, when the slave is known, so a
write's W may come before, with or after its AW, in any clock (a slave may wait for anything before its
ready; the master never waits for a ready before its valid). The chosen slave sees its address (and
its data) in the clock after they moved on ``m``; the response reaches ``m`` in the clock after it moved
on the slave's port; one idle clock between transactions.

Timing: a write to ``s1`` whose ``wvalid`` rises 2 clocks after its ``awvalid``, then a read of ``s0``; the
slaves answer one clock after the address (``#`` high, ``_`` low; ``^`` transfers at the edge ending that cycle)::

    cycle        0    1    2    3    4    5    6    7    8    9    10   11
    m.awvalid    #    #    _    _    _    _    _    _    _    _    _    _
    m.awready    _    #    _    _    _    _    _    _    _    _    _    _
    m.wvalid     _    _    #    _    _    _    _    _    _    _    _    _
    m.wready     _    _    #    _    _    _    _    _    _    _    _    _
    s1.awvalid   _    _    #    #    #    _    _    _    _    _    _    _
    s1.wvalid    _    _    _    #    #    _    _    _    _    _    _    _
    s1.aw/wready _    _    _    _    #    _    _    _    _    _    _    _
    s1.bvalid    _    _    _    _    _    #    _    _    _    _    _    _
    m.bvalid     _    _    _    _    _    _    #    _    _    _    _    _
    m.arvalid    _    _    _    _    _    #    #    #    #    _    _    _
    m.arready    _    _    _    _    _    _    _    _    #    _    _    _
    s0.arvalid   _    _    _    _    _    _    _    _    _    #    _    _
    s0.rvalid    _    _    _    _    _    _    _    _    _    _    #    _
    m.rvalid     _    _    _    _    _    _    _    _    _    _    _    #
    moves             ^    ^         ^    ^    ^         ^    ^    ^    ^

The moves: AW on ``m`` (1), W on ``m`` (2), AW and W on ``s1`` (4), B on ``s1`` (5) and on ``m`` (6); AR on
``m`` (8) and on ``s0`` (9), R on ``s0`` (10) and on ``m`` (11).

Here the slave ``s1`` raises ``awready`` only with both AW and W valid (like the register bank), so
its address waits for the data. ``s0`` and ``s1`` see the address registers' value whenever their
valid is low (don't-care there).
"""

from __future__ import annotations

from myhdl import Signal, always_comb, always_seq, block, intbv

from eyestereo.hdl.common.checks import block_error, check_clock, check_distinct, check_int, check_port, \
    check_reset
from eyestereo.hdl.common.registers import assign
from eyestereo.hdl.interfaces.axil import AxiLite

__all__ = ["axil_split"]


@block
def axil_split(clk, rst, m, s0, s1, *, split_bit=23):
    """One AXI4-Lite master (on ``m``) onto two slaves (``s0``: address bit ``split_bit`` = 0, ``s1``: = 1),
    one transaction at a time, the address passed on with that bit cleared (module docstring).

    Ports:
        clk: clock.
        rst: synchronous active-high reset (``ResetSignal(0, active=1, isasync=False)``): idle, every
            valid and ready low, a write preferred at the first tie.
        m: ``AxiLite(n)``, slave port: the master plugs in here; ``n > split_bit``.
        s0, s1: ``AxiLite`` master ports to the two slaves, each of at most ``n`` address bits (the low
            bits of the master's address with bit ``split_bit`` cleared).

    Parameters:
        split_bit: the address bit that chooses the slave, 2..n-1 (bits 1..0 select a byte within a
            word, which must not be split; 23 on the board).

    Latency: ``awready`` (``arready``) 1 clock after the valid is sampled, ``wready`` 1 clock after the
    address moved; address and data on the slave's port 1 clock after they moved on ``m``; the response
    on ``m`` 1 clock after it moved on the slave's port; 1 idle clock between transactions.

    Resources: one address register (n + 3 flip-flops, the slaves share it), the write data (36) and
    response (36) registers, about 14 control flip-flops; no multiplexer on the request side, one on the
    slaves' responses; default configuration (make synth's flow, Yosys xc3se): 172 LUT, 111 FF;
    nextpnr-ecp5 257.5 MHz (the slowest of seeds 1-4, out of context).
    """
    check_clock(clk)
    check_reset(rst)
    check_port("m", m, AxiLite)
    n = m.addr_bits
    split_bit = check_int("split_bit", split_bit, 2, n - 1)
    for name, port in (("s0", s0), ("s1", s1)):
        check_port(name, port, AxiLite)
        if port.addr_bits > n:
            raise block_error(f"port {name} must have at most {n} address bits (port m's), got an AxiLite of "
                              f"{port.addr_bits}")
    check_distinct(dict(s0=s0, s1=s1), dict(clk=clk, rst=rst, m=m))

    keep = ((1 << n) - 1) & ~(1 << split_bit)   # the address bits a slave is given (Python constant)
    b0, b1 = s0.addr_bits, s1.addr_bits

    busy = Signal(bool(0))       # a transaction is accepted
    is_write = Signal(bool(0))      # ... and it is a write
    last_w = Signal(bool(0))     # the last transaction was a write (0 after reset: a write wins the first tie)
    sel = Signal(bool(0))        # the chosen slave (1: s1), known once the address moved
    # towards the master
    awready, wready, arready = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    bvalid, rvalid = Signal(bool(0)), Signal(bool(0))
    bresp, rresp, rdata = Signal(intbv(0)[2:]), Signal(intbv(0)[2:]), Signal(intbv(0)[32:])
    # towards the slaves (valids and readys gated by sel below; the payload shared)
    awvalid, wvalid, arvalid = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    bready, rready = Signal(bool(0)), Signal(bool(0))
    addr, prot = Signal(intbv(0)[n:]), Signal(intbv(0)[3:])
    wdata, wstrb = Signal(intbv(0)[32:]), Signal(intbv(0)[4:])
    # the chosen slave's outputs
    c_awready, c_wready, c_arready = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    c_bvalid, c_rvalid = Signal(bool(0)), Signal(bool(0))
    c_bresp, c_rresp, c_rdata = Signal(intbv(0)[2:]), Signal(intbv(0)[2:]), Signal(intbv(0)[32:])

    @always_comb
    def chosen():
        if sel:
            c_awready.next = s1.awready
            c_wready.next = s1.wready
            c_arready.next = s1.arready
            c_bvalid.next = s1.bvalid
            c_rvalid.next = s1.rvalid
            c_bresp.next = s1.bresp
            c_rresp.next = s1.rresp
            c_rdata.next = s1.rdata
        else:
            c_awready.next = s0.awready
            c_wready.next = s0.wready
            c_arready.next = s0.arready
            c_bvalid.next = s0.bvalid
            c_rvalid.next = s0.rvalid
            c_bresp.next = s0.bresp
            c_rresp.next = s0.rresp
            c_rdata.next = s0.rdata

    @always_seq(clk.posedge, reset=rst)
    def control():
        if not busy:
            if m.awvalid or m.arvalid:
                wr = m.awvalid and (not m.arvalid or not last_w)
                busy.next = 1
                is_write.next = wr
                last_w.next = wr
                if wr:
                    awready.next = 1
                else:
                    arready.next = 1
        elif is_write:
            if awready and m.awvalid:
                # the slave is known now: W may move from the next clock on
                awready.next = 0
                wready.next = 1
                sel.next = m.awaddr[split_bit]
                addr.next = m.awaddr & keep
                prot.next = m.awprot
                awvalid.next = 1
                bready.next = 1
            if wready and m.wvalid:
                wready.next = 0
                wdata.next = m.wdata
                wstrb.next = m.wstrb
                wvalid.next = 1
            if awvalid and c_awready:
                awvalid.next = 0
            if wvalid and c_wready:
                wvalid.next = 0
            if bready and c_bvalid:
                bready.next = 0
                bresp.next = c_bresp
                bvalid.next = 1
            if bvalid and m.bready:
                bvalid.next = 0
                busy.next = 0
        else:
            if arready and m.arvalid:
                arready.next = 0
                sel.next = m.araddr[split_bit]
                addr.next = m.araddr & keep
                prot.next = m.arprot
                arvalid.next = 1
                rready.next = 1
            if arvalid and c_arready:
                arvalid.next = 0
            if rready and c_rvalid:
                rready.next = 0
                rdata.next = c_rdata
                rresp.next = c_rresp
                rvalid.next = 1
            if rvalid and m.rready:
                rvalid.next = 0
                busy.next = 0

    @always_comb
    def to_slaves():
        s0.awvalid.next = awvalid and not sel
        s0.wvalid.next = wvalid and not sel
        s0.bready.next = bready and not sel
        s0.arvalid.next = arvalid and not sel
        s0.rready.next = rready and not sel
        s1.awvalid.next = awvalid and sel
        s1.wvalid.next = wvalid and sel
        s1.bready.next = bready and sel
        s1.arvalid.next = arvalid and sel
        s1.rready.next = rready and sel
        s0.awaddr.next = addr[b0:]
        s0.araddr.next = addr[b0:]
        s1.awaddr.next = addr[b1:]
        s1.araddr.next = addr[b1:]

    outs = [assign(q, port) for q, port in (
        (awready, m.awready), (wready, m.wready), (arready, m.arready), (bvalid, m.bvalid), (bresp, m.bresp),
        (rvalid, m.rvalid), (rresp, m.rresp), (rdata, m.rdata),
        (prot, s0.awprot), (prot, s0.arprot), (wdata, s0.wdata), (wstrb, s0.wstrb),
        (prot, s1.awprot), (prot, s1.arprot), (wdata, s1.wdata), (wstrb, s1.wstrb))]
    return chosen, control, to_slaves, outs
