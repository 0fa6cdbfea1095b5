"""AXI4-Lite arbiter: two masters share one AXI4-Lite slave, one transaction at a time, round robin.

On the board the UART bridge (the host PC) and the display engine both reach the front end's register bank
through it. Each of the three ports keeps the rules of :mod:`eyestereo.hdl.interfaces.axil`: the
arbiter is a slave on ``m0`` and ``m1`` and a master on ``s``; every output is a flip-flop (or a
flip-flop gated by the registered grant), so no path runs from an input to an output.

The rule (checked cycle for cycle by :mod:`eyestereo.tools.models.axil_arbiter`): a master *requests*
when its ``awvalid`` (a write) or ``arvalid`` (a read) is high; ``wvalid`` alone is no request (its
address must follow: a master never waits for a ready before raising a valid). The arbiter decides
at a rising edge when it is idle and a request is sampled:

* one master requests: it is granted; both: the one **not** granted last (round robin, ``m0`` first
  after reset);
* the granted master offers a read and a write: the kind it was **not** granted last (a write first
  after reset).

The grant holds for one whole transaction: a write is its AW, its W and its B; a read its AR and its R.
The arbiter is idle again in the clock after the master's B (R) transfer. Hence the bound on waiting:
while a master requests, the other master is granted at most once before it; a particular request
(a read, say) waits for at most 2 transactions of the other master and 1 of its own other kind.

Added latency (the figures of the diagram): the grant's ready 1 clock after the valid is sampled (the
master's address moves 1 clock after its valid at the earliest), the address and data on ``s`` in the
clock after they moved on the master's port, the response on the master's port in the clock after it
moved on ``s``; one idle clock between transactions. A write (or read) in a quiet arbiter with a
slave and master that never hold their readys low: the master's response valid comes 2 clocks later
than with the slave alone (the latencies :class:`~eyestereo.sim.lib.axil.AxiLiteChecker` measures:
master port = slave port + 2).

Timing: ``m0`` writes while ``m1`` requests a read; ``m1`` is granted in the clock after ``m0``'s B has
moved (``#`` high, ``_`` low; ``^`` transfers at the edge ending that cycle; the slave answers each
access one clock after its address)::

    cycle        0    1    2    3    4    5    6    7    8    9    10
    m0.awvalid   #    #    _    _    _    _    _    _    _    _    _
    m0.wvalid    #    #    _    _    _    _    _    _    _    _    _
    m0.aw/wready _    #    _    _    _    _    _    _    _    _    _
    s.awvalid    _    _    #    _    _    _    _    _    _    _    _
    s.wvalid     _    _    #    _    _    _    _    _    _    _    _
    s.bvalid     _    _    _    #    _    _    _    _    _    _    _
    m0.bvalid    _    _    _    _    #    _    _    _    _    _    _
    m1.arvalid   _    #    #    #    #    #    #    _    _    _    _
    m1.arready   _    _    _    _    _    _    #    _    _    _    _
    s.arvalid    _    _    _    _    _    _    _    #    _    _    _
    s.rvalid     _    _    _    _    _    _    _    _    #    _    _
    m1.rvalid    _    _    _    _    _    _    _    _    _    #    _
    moves             ^    ^    ^    ^         ^    ^    ^    ^

The moves: ``m0``'s AW and W (1), on ``s`` (2), B on ``s`` (3) and on ``m0`` (4); ``m1``'s AR (6), on ``s``
(7), R on ``s`` (8) and on ``m1`` (9).

Cycle 5 is the idle clock (the decision for ``m1`` is taken at its end). ``bready`` and ``rready`` of
``s`` are high from the grant until the slave's response moves; the masters hold theirs high here.
"""

from __future__ import annotations

from myhdl import Signal, always_comb, always_seq, block, intbv

from eyestereo.hdl.common.checks import block_error, check_clock, check_distinct, check_int, check_port, check_reset
from eyestereo.hdl.common.registers import assign
from eyestereo.hdl.interfaces.axil import AxiLite
from eyestereo.tools.regmap import REGMAP

__all__ = ["axil_arbiter"]


def check_axil_ports(ports: dict, bits: dict) -> None:
    """Each port an :class:`AxiLite` of ``bits[name]`` address bits, else a one-line ValueError."""
    for name, port in ports.items():
        check_port(name, port, AxiLite)
        if port.addr_bits != bits[name]:
            raise block_error(f"port {name} must have {bits[name]} address bits, got an AxiLite of {port.addr_bits}")


@block
def axil_arbiter(clk, rst, m0, m1, s, *, addr_bits=REGMAP.addr_bits):
    """Two AXI4-Lite masters (on ``m0``, ``m1``) onto one slave (on ``s``): one transaction at a time,
    round robin between the masters, reads and writes of one master alternating (module docstring).

    Ports:
        clk: clock.
        rst: synchronous active-high reset (``ResetSignal(0, active=1, isasync=False)``): idle, every
            valid and ready low, ``m0`` and a write preferred at the first tie.
        m0, m1: ``AxiLite(addr_bits)``, slave ports: the masters plug in here.
        s: ``AxiLite(addr_bits)``, master port: to the slave. ``awprot`` and ``arprot`` are passed on.

    Parameters:
        addr_bits: byte-address bits of all three ports (3..32; default the register map's, 23).

    Latency: the granted master's address moves 1 clock after its valid is sampled, appears on ``s`` 1
    clock later; the response reaches the master 1 clock after it moved on ``s``; 1 idle clock between
    transactions (the module docstring's diagram).

    Resources: the address and data registers towards ``s`` (2 x (addr_bits + 3) + 36 flip-flops), the
    response registers (32 + 2 + 2), about 16 control flip-flops and the two-way multiplexers of the
    masters' payloads; default configuration (make synth's flow, Yosys xc3se): 141 LUT, 140 FF;
    nextpnr-ecp5 238.6 MHz (the slowest of seeds 1-4, out of context).
    """
    check_clock(clk)
    check_reset(rst)
    addr_bits = check_int("addr_bits", addr_bits, 3, 32)
    check_axil_ports(dict(m0=m0, m1=m1, s=s), dict(m0=addr_bits, m1=addr_bits, s=addr_bits))
    check_distinct(dict(s=s), dict(clk=clk, rst=rst, m0=m0, m1=m1))

    # ---- state --------------------------------------------------------------------------------------
    busy = Signal(bool(0))       # a transaction is granted
    gnt = Signal(bool(0))        # the granted master (0: m0)
    is_write = Signal(bool(0))      # the granted transaction is a write
    # the master granted last; 1 after reset so that m0 wins the first tie
    last = Signal(bool(1))
    last_w0 = Signal(bool(0))    # m0's last grant was a write (0 after reset: a write wins its first tie)
    last_w1 = Signal(bool(0))
    # towards the granted master (gated by gnt below)
    awready, wready, arready = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    bvalid, rvalid = Signal(bool(0)), Signal(bool(0))
    bresp, rresp, rdata = Signal(intbv(0)[2:]), Signal(intbv(0)[2:]), Signal(intbv(0)[32:])
    # towards the slave
    fw_awvalid, fw_wvalid, fw_arvalid = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    fw_bready, fw_rready = Signal(bool(0)), Signal(bool(0))
    fw_awaddr, fw_araddr = Signal(intbv(0)[addr_bits:]), Signal(intbv(0)[addr_bits:])
    fw_awprot, fw_arprot = Signal(intbv(0)[3:]), Signal(intbv(0)[3:])
    fw_wdata, fw_wstrb = Signal(intbv(0)[32:]), Signal(intbv(0)[4:])
    # the granted master's outputs (a multiplexer on the registered grant)
    g_awvalid, g_wvalid, g_arvalid = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    g_bready, g_rready = Signal(bool(0)), Signal(bool(0))
    g_awaddr, g_araddr = Signal(intbv(0)[addr_bits:]), Signal(intbv(0)[addr_bits:])
    g_awprot, g_arprot = Signal(intbv(0)[3:]), Signal(intbv(0)[3:])
    g_wdata, g_wstrb = Signal(intbv(0)[32:]), Signal(intbv(0)[4:])

    @always_comb
    def granted():
        if gnt:
            g_awvalid.next = m1.awvalid
            g_wvalid.next = m1.wvalid
            g_arvalid.next = m1.arvalid
            g_bready.next = m1.bready
            g_rready.next = m1.rready
            g_awaddr.next = m1.awaddr
            g_araddr.next = m1.araddr
            g_awprot.next = m1.awprot
            g_arprot.next = m1.arprot
            g_wdata.next = m1.wdata
            g_wstrb.next = m1.wstrb
        else:
            g_awvalid.next = m0.awvalid
            g_wvalid.next = m0.wvalid
            g_arvalid.next = m0.arvalid
            g_bready.next = m0.bready
            g_rready.next = m0.rready
            g_awaddr.next = m0.awaddr
            g_araddr.next = m0.araddr
            g_awprot.next = m0.awprot
            g_arprot.next = m0.arprot
            g_wdata.next = m0.wdata
            g_wstrb.next = m0.wstrb

    @always_seq(clk.posedge, reset=rst)
    def control():
        if not busy:
            # the decision (only here: a grant holds for the whole transaction)
            req0 = m0.awvalid or m0.arvalid
            req1 = m1.awvalid or m1.arvalid
            if req0 or req1:
                pick = req1 and (not req0 or not last)
                wr = m0.awvalid and (not m0.arvalid or not last_w0)
                if pick:
                    wr = m1.awvalid and (not m1.arvalid or not last_w1)
                    last_w1.next = wr
                else:
                    last_w0.next = wr
                busy.next = 1
                gnt.next = pick
                last.next = pick
                is_write.next = wr
                if wr:
                    awready.next = 1
                    wready.next = 1
                    fw_bready.next = 1
                else:
                    arready.next = 1
        elif is_write:
            # address and data from the master, each in its own clock if it comes so
            if awready and g_awvalid:
                awready.next = 0
                fw_awaddr.next = g_awaddr
                fw_awprot.next = g_awprot
                fw_awvalid.next = 1
            if wready and g_wvalid:
                wready.next = 0
                fw_wdata.next = g_wdata
                fw_wstrb.next = g_wstrb
                fw_wvalid.next = 1
            if fw_awvalid and s.awready:
                fw_awvalid.next = 0
            if fw_wvalid and s.wready:
                fw_wvalid.next = 0
            if fw_bready and s.bvalid:
                fw_bready.next = 0
                bresp.next = s.bresp
                bvalid.next = 1
            if bvalid and g_bready:
                bvalid.next = 0
                busy.next = 0
        else:
            if arready and g_arvalid:
                arready.next = 0
                fw_araddr.next = g_araddr
                fw_arprot.next = g_arprot
                fw_arvalid.next = 1
                fw_rready.next = 1
            if fw_arvalid and s.arready:
                fw_arvalid.next = 0
            if fw_rready and s.rvalid:
                fw_rready.next = 0
                rdata.next = s.rdata
                rresp.next = s.rresp
                rvalid.next = 1
            if rvalid and g_rready:
                rvalid.next = 0
                busy.next = 0

    @always_comb
    def to_masters():
        # the handshake outputs of the granted master only; the response payload is shared
        m0.awready.next = awready and not gnt
        m0.wready.next = wready and not gnt
        m0.arready.next = arready and not gnt
        m0.bvalid.next = bvalid and not gnt
        m0.rvalid.next = rvalid and not gnt
        m1.awready.next = awready and gnt
        m1.wready.next = wready and gnt
        m1.arready.next = arready and gnt
        m1.bvalid.next = bvalid and gnt
        m1.rvalid.next = rvalid and gnt

    outs = [assign(q, port) for q, port in (
        (bresp, m0.bresp), (bresp, m1.bresp), (rresp, m0.rresp), (rresp, m1.rresp), (rdata, m0.rdata),
        (rdata, m1.rdata), (fw_awvalid, s.awvalid), (fw_awaddr, s.awaddr), (fw_awprot, s.awprot),
        (fw_wvalid, s.wvalid), (fw_wdata, s.wdata), (fw_wstrb, s.wstrb), (fw_bready, s.bready),
        (fw_arvalid, s.arvalid), (fw_araddr, s.araddr), (fw_arprot, s.arprot), (fw_rready, s.rready))]
    return granted, control, to_masters, outs
