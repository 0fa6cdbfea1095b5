"""AXI4-Lite: the register bus between the processor and the stereo front end (slave side).

AMBA AXI4-Lite (ARM IHI 0022, part B): five channels, each a valid/ready handshake; a transfer moves on a
rising edge with both high. All signals are active high and sampled on the rising edge of the bus clock;
VHDL/Verilog ports come out as ``<arg>_<field>`` (``bus_awaddr``, ``bus_rready``, ...), the names
Vivado's interface inference and cocotbext-axi's ``AxiLiteBus.from_prefix(dut, "bus")`` look for.

Fields (their directions and widths are declared once, in ``AxiLite.MEMBERS``, from the master's side;
docs/interfaces.md shows them; the slave is :func:`eyestereo.hdl.system.register_bank.register_bank`):

``awaddr``, ``awprot``, ``awvalid``, ``awready``
    Write address: a byte address of ``addr_bits`` bits; ``awprot`` is accepted and ignored.
``wdata``, ``wstrb``, ``wvalid``, ``wready``
    Write data; ``wstrb`` bit i: byte i (bits 8i+7..8i) is written.
``bresp``, ``bvalid``, ``bready``
    Write response: 0 OKAY, 2 SLVERR.
``araddr``, ``arprot``, ``arvalid``, ``arready``
    Read address.
``rdata``, ``rresp``, ``rvalid``, ``rready``
    Read data and response.

Rules (both sides; ``eyestereo.sim.lib.axil.AxiLiteChecker`` checks them in every bench): a valid, once
high, stays high with its payload unchanged until its transfer; a valid never waits for the ready of
its own channel (a ready may wait for valid); a write response comes only after both the write address
and the write data of its write have moved, a read response only after its read address; during reset
the master keeps ``awvalid``, ``wvalid``, ``arvalid`` low and the slave ``bvalid``, ``rvalid``.

The register bank serves one access at a time and raises ``awready`` and ``wready`` together, in the
clock after it has seen both ``awvalid`` and ``wvalid``; ``arready`` in the clock after ``arvalid``. When a
read and a write both wait, it alternates. Timing of a write to a register (its response valid 3 clocks
after the address and data moved; the master holds ``bready`` low for a clock), then a read of a
register or window (data valid 5 clocks after the address moved). The bank's output ports take the
written value at the edge that ends cycle 3 (``#`` high, ``_`` low, ``.`` don't care; ``^`` transfers)::

    cycle     0    1    2    3    4    5    6    7    8    9    10   11   12
    awvalid   #    #    _    _    _    _    _    _    _    _    _    _    _
    wvalid    #    #    _    _    _    _    _    _    _    _    _    _    _
    awready   _    #    _    _    _    _    _    _    _    _    _    _    _
    wready    _    #    _    _    _    _    _    _    _    _    _    _    _
    bvalid    _    _    _    _    #    #    _    _    _    _    _    _    _
    bready    #    #    #    #    _    #    #    #    #    #    #    #    #
    arvalid   _    _    _    _    _    _    #    #    _    _    _    _    _
    arready   _    _    _    _    _    _    _    #    _    _    _    _    _
    rvalid    _    _    _    _    _    _    _    _    _    _    _    _    #
    rready    #    #    #    #    #    #    #    #    #    #    #    #    #
    rdata     .    .    .    .    .    .    .    .    .    .    .    .    D
    moves          ^                   ^         ^                        ^

The figures are measured on GHDL (``register_bank_latency`` in ``sim/benches/tb_register_bank.py`` times the
accesses with the bus checker); accesses to the ``SRAM`` window wait for the arbiter's host port in
addition.
"""

from __future__ import annotations

import numbers

from eyestereo.hdl.common.checks import block_error, check_port
from eyestereo.hdl.interfaces.bundle import IN, OUT, Bundle, Member

__all__ = ["AxiLite", "check_axil"]


class AxiLite(Bundle):
    """A MyHDL interface bundle for an AXI4-Lite slave port (see the module docstring). The declaration
    is the master's view: ``out`` members are the master's outputs, ``in`` members the slave's
    (``driven(producer=False)``).

    Parameters:
        addr_bits: byte-address bits (3..32); data is always 32 bits (4 byte strobes).
    """

    DATA_BITS = 32

    PARAMS = ("addr_bits",)
    MEMBERS = (Member("awaddr", "addr_bits", OUT), Member("awprot", 3, OUT), Member("awvalid", bool, OUT),
               Member("awready", bool, IN),
               Member("wdata", DATA_BITS, OUT), Member("wstrb", DATA_BITS // 8, OUT), Member("wvalid", bool, OUT),
               Member("wready", bool, IN),
               Member("bresp", 2, IN), Member("bvalid", bool, IN), Member("bready", bool, OUT),
               Member("araddr", "addr_bits", OUT), Member("arprot", 3, OUT), Member("arvalid", bool, OUT),
               Member("arready", bool, IN),
               Member("rdata", DATA_BITS, IN), Member("rresp", 2, IN), Member("rvalid", bool, IN),
               Member("rready", bool, OUT))

    def __init__(self, addr_bits: int = 32):
        if isinstance(addr_bits, bool) or not isinstance(addr_bits, numbers.Integral) or not 3 <= addr_bits <= 32:
            raise ValueError(f"AxiLite addr_bits must be an int in [3, 32], got {addr_bits!r}")
        self.addr_bits = int(addr_bits)
        self.make()



def check_axil(name: str, port, *, addr_bits: int | None = None) -> None:
    """An :class:`AxiLite` port (of ``addr_bits`` address bits), else a ValueError naming the port and block."""
    check_port(name, port, AxiLite)
    if addr_bits is not None and port.addr_bits != addr_bits:
        raise block_error(f"port {name} must have {addr_bits} address bits (the register map's), got {port.addr_bits}")
