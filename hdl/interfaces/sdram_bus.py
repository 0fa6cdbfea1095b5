"""The SDR SDRAM, both sides: its pins and the burst port of
:func:`~eyestereo.hdl.memory.sdram_controller.sdram_controller`.

**Pins** (:class:`SdramPins`, the FPGA's side of a 16-bit SDR SDRAM such as the ULX3S's; the parts, their
timings and the rules are :mod:`eyestereo.tools.sdram`). Ports come out as ``<arg>_<field>``, e.g.
``sdram_cs_n``:

``cke``, ``cs_n``, ``ras_n``, ``cas_n``, ``we_n``, ``ba`` (2 bits), ``a`` (13 bits), ``dqm`` (2 bits: bit 1 =
DQ15..8, bit 0 = DQ7..0)
    Outputs to the part, every one straight from a flip-flop (so it can sit in the I/O block). The
    command is ``cs_n ras_n cas_n we_n`` (tools/sdram.py lists the codes).
``dq_o`` (16 bits), ``dq_oe``
    The FPGA's side of the bidirectional data bus, as for the SRAM (:mod:`eyestereo.hdl.interfaces.sram_bus`):
    the value and output enable of the DQ buffers, both from flip-flops; the system top joins them with
    ``dq_i`` in an ``IOBUF`` per line (``dq <= dq_o when dq_oe = '1' else (others => 'Z')``).
``dq_i`` (16 bits)
    Input from the DQ buffers; the controller registers it at once (the I/O block's input flip-flop).

The SDRAM's clock is the controller's clock, forwarded to the pin by the top (an ``ODDR`` or the PLL's
phase-shifted copy); the benches model it as the same edge.

**Burst port** (:class:`SdramPort`, masters -> controller; members and directions in ``MEMBERS``, shown in
docs/interfaces.md). One command per burst; bursts are carried out in command order::

    cmd_valid  a burst is offered: cmd_we (1 write, 0 read), cmd_addr, cmd_len; held until it moves
    cmd_ready  the controller takes it (it moves on a rising edge with cmd_valid & cmd_ready)
    cmd_addr   word address of the burst's first word (25 bits for 32 M words; row | bank | column)
    cmd_len    words in the burst, 1..max_burst; the burst stays in the row of its first word (a burst
               that would leave the row wraps round to the row's column 0)
    wr_ready   controller -> master: the burst's next write word is taken in this clock
    wr_data    the write word the master offers (the next word of the oldest write burst taken)
    wr_be      2 bits, the bytes of wr_data written (bit 1: 15..8, bit 0: 7..0; 0 bits are masked by DQM)
    rd_valid   controller -> master: a read word, in command and address order; no back-pressure
    rd_data    the word read

``cmd_ready`` comes from a register (the controller holds the burst it works on and the next one);
``cmd_addr`` goes through the controller's row comparison (a few LUTs) before a register, so the master
should drive it from one. Write
data is *pulled*: once a write burst is taken the master must offer its words on ``wr_data``/``wr_be``
(from a FIFO that holds them, show-ahead), one moving in every clock with ``wr_ready`` high; ``wr_ready``
may fall for a clock inside a burst (the controller takes the command slot for another bank's ACTIVATE or
PRECHARGE, or refreshes) and depends on registers only. Reads come back ``rd_valid`` word by word in
order. Writes need no answer; a read taken after a write returns the written words.

A write burst of 3 words and then a read burst of 2 to the same open row, CAS latency 2 (``#`` high, ``_``
low, ``.`` don't care; ``command`` is the pins' command, sampled by the part at the end of its cycle;
``DQ`` is the bus, driven by the FPGA for writes and by the part for reads)::

    cycle      0    1    2    3    4    5    6    7    8    9    10   11
    cmd_valid  #    _    _    #    _    _    _    _    _    _    _    _
    cmd_ready  #    #    #    #    #    #    #    #    #    #    #    #
    cmd_we     #    .    .    _    .    .    .    .    .    .    .    .
    cmd_len    3    .    .    2    .    .    .    .    .    .    .    .
    wr_ready   _    #    #    #    _    _    _    _    _    _    _    _
    wr_data    .    w0   w1   w2   .    .    .    .    .    .    .    .
    command    NOP  NOP  WR   WR   WR   RD   RD   NOP  NOP  NOP  NOP  NOP
    a (column) .    .    c    c+1  c+2  c    c+1  .    .    .    .    .
    dq_oe      _    _    #    #    #    _    _    _    _    _    _    _
    DQ (bus)   .    .    w0   w1   w2   .    .    r0   r1   .    .    .
    rd_valid   _    _    _    _    _    _    _    _    r0   r1   _    _

The write burst is taken in cycle 0; its WRITE commands are decided in cycles 1..3 (``wr_ready``) and go
out on the pins in cycles 2..4 with their data. The read burst taken in cycle 3 starts right after it
(cycle 4); the part drives its words CAS latency clocks after their READs (cycles 7, 8), the FPGA's input
register samples them and ``rd_valid`` shows them a cycle later (cycles 8, 9): a read on an open row
comes ``CL + 3`` clocks after its command is taken (5 at CL 2, 6 at CL 3), and a write on an open row has
its first ``wr_ready`` 1 clock after. A row that is not open adds its ACTIVATE (tRCD: 2 or 3 clocks), a row
miss a PRECHARGE before it (tRP); a WRITE after a READ waits until the part has let go of the bus (one idle
bus cycle after the last read word). The bench asserts these latencies (``tb_sdram_controller``'s
``latency`` pattern, ``tests/hdl/test_sdram.py::test_read_latency``).
"""

from __future__ import annotations

import numbers

from eyestereo.hdl.interfaces.bundle import IN, OUT, Bundle, Member
from eyestereo.tools.sdram import ULX3S, part as sdram_part

__all__ = ["SdramPins", "SdramPort", "MAX_BURST"]

#: The longest burst a port can ask for (a full row of the largest part).
MAX_BURST = 4096


def _int(owner: str, name: str, value, lo: int, hi: int) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or not lo <= value <= hi:
        raise ValueError(f"{owner} {name} must be an int in [{lo}, {hi}], got {value!r}")
    return int(value)


class SdramPins(Bundle):
    """The FPGA's pins to an SDR SDRAM (see the module docstring), sized by the part (a
    :class:`~eyestereo.tools.sdram.SdramPart` or its name). The FPGA is the producer: ``dq_i`` is the one
    member the part drives."""

    PARAMS = ("bank_bits", "a_bits", "data_bits")
    MEMBERS = (Member("cke", bool, OUT, init=1), Member("cs_n", bool, OUT, init=1), Member("ras_n", bool, OUT, init=1),
               Member("cas_n", bool, OUT, init=1), Member("we_n", bool, OUT, init=1),
               Member("ba", "bank_bits", OUT), Member("a", "a_bits", OUT), Member("dqm", "be_bits", OUT, init=-1),
               Member("dq_o", "data_bits", OUT), Member("dq_oe", bool, OUT), Member("dq_i", "data_bits", IN))

    def __init__(self, part=ULX3S):
        p = sdram_part(part)
        self.bank_bits, self.a_bits, self.data_bits = p.bank_bits, p.a_bits, p.data_bits
        self.be_bits = p.data_bits // 8
        self.make()


class SdramPort(Bundle):
    """The masters' burst port of the SDRAM controller (see the module docstring): ``addr_bits`` word
    address bits, bursts of 1..``max_burst`` words of ``data_bits`` (whole bytes)."""

    PARAMS = ("addr_bits", "max_burst", "data_bits")
    MEMBERS = (Member("cmd_valid", bool, OUT), Member("cmd_ready", bool, IN), Member("cmd_we", bool, OUT),
               Member("cmd_addr", "addr_bits", OUT), Member("cmd_len", "len_bits", OUT),
               Member("wr_ready", bool, IN), Member("wr_data", "data_bits", OUT), Member("wr_be", "be_bits", OUT),
               Member("rd_valid", bool, IN), Member("rd_data", "data_bits", IN))

    def __init__(self, addr_bits: int = 25, max_burst: int = 8, data_bits: int = 16):
        self.addr_bits = _int("SdramPort", "addr_bits", addr_bits, 8, 32)
        self.max_burst = _int("SdramPort", "max_burst", max_burst, 1, MAX_BURST)
        self.data_bits = _int("SdramPort", "data_bits", data_bits, 8, 32)
        if self.data_bits % 8:
            raise ValueError(f"SdramPort data_bits must be a multiple of 8, got {data_bits}")
        self.be_bits = self.data_bits // 8
        self.len_bits = self.max_burst.bit_length()
        self.make()
