"""The SRAM, both sides: its pins and the word port of :func:`~eyestereo.hdl.memory.sram_controller.sram_controller`.

**Pins** (:class:`SramPins`, the FPGA's side of the 1M x 18 synchronous SRAM; the part, its two kinds and
the rules it imposes are documented in :mod:`eyestereo.tools.sram`). Ports come out as ``<arg>_<field>``,
e.g. ``sram_addr``, ``sram_ce_n``:

``addr`` (20 bits), ``ce_n``, ``ld_n``, ``we_n``, ``bw_n`` (2 bits: bit 1 = DQ15..8, bit 0 = DQ7..0), ``oe_n``
    Outputs to the part, every one straight from a flip-flop (so it can sit in the I/O block).
``dq_o`` (16 bits), ``dq_oe``
    The FPGA's side of the bidirectional data bus: the value and output enable of the DQ buffers (the
    system top joins them with ``dq_i`` in an ``IOBUF`` per line, or ``dq <= dq_o when dq_oe = '1' else
    (others => 'Z')``); both from flip-flops.
``dq_i`` (16 bits)
    Input from the DQ buffers; the controller registers it at once (the input flip-flop of the I/O block).

**Word port** (:class:`SramCmd` in, :class:`SramRsp` out; the members' directions and widths are declared
once in each class's ``MEMBERS``, shown in docs/interfaces.md): one access per command, in order::

    cmd_valid  an access is offered: cmd_we (1 write, 0 read), cmd_addr, cmd_wdata, cmd_be, cmd_tag
    cmd_ready  the controller takes it (it moves on a rising edge with cmd_valid & cmd_ready)
    cmd_be     2 bits, the bytes a write changes (bit 1: 15..8, bit 0: 7..0); ignored for reads
    cmd_tag    any bits the master wants back with the read data (the arbiter: who asked)
    rsp_valid  one clock per read, in command order, no back-pressure
    rsp_data   16 bits, the word read
    rsp_tag    the read's cmd_tag

``cmd_ready`` is low only for a write on a pipelined part while the bus turns round after reads (it
depends on ``cmd_we`` and registered state, nothing else); reads are always taken, and on a NoBL part
everything is. A read taken at edge ``e`` comes back with ``rsp_valid`` high in the clock after edge
``e + read_latency + 1`` (latency ``read_latency + 2`` clocks, counted like a stream block's: taken in cycle
0, seen in cycle ``read_latency + 2``). Writes are posted: they need no answer, and a read taken after a
write to the same address returns the written word.

Word port and pins of a pipelined part (read latency 2): reads R0, R1 taken back to back, then a write W2
waits 3 clocks for the turnaround, then a read R3 (``#`` high, ``_`` low, ``.`` don't care or undriven)::

    cycle      0    1    2    3    4    5    6    7    8    9
    cmd_valid  #    #    #    #    #    #    #    _    _    _
    cmd_we     _    _    #    #    #    #    _    .    .    .
    cmd_ready  #    #    _    _    _    #    #    #    #    #
    ce_n       #    _    _    #    #    #    _    _    #    #
    addr       .    R0   R1   .    .    .    W2   R3   .    .
    we_n       #    #    #    #    #    #    _    #    #    #
    DQ (bus)   .    .    .    R0   R1   .    W2   .    .    R3
    dq_oe      _    _    _    _    _    _    #    _    _    _
    oe_n       #    #    #    _    _    #    #    #    #    _
    rsp_valid  _    _    _    _    #    #    _    _    _    _      R0, R1; R3 in cycle 10

The part drives R0 in cycle 3 and R1 in cycle 4 (each sampled by the FPGA at the next edge), leaves cycle
5 idle (tCHZ), and the FPGA drives W2's data in cycle 6 with its address (a SyncBurst write started with
ADSC# takes its data at the address edge). On a NoBL part the same commands go back to back, write data
two cycles after its address like read data::

    cycle      0    1    2    3    4    5    6    7
    cmd_ready  #    #    #    #    #    #    #    #
    addr       .    R0   R1   W2   R3   .    .    .
    DQ (bus)   .    .    .    R0   R1   W2   R3   .
    dq_oe      _    _    _    _    _    #    _    _
"""

from __future__ import annotations

import numbers

from eyestereo.hdl.common.checks import block_error, check_port
from eyestereo.hdl.interfaces.bundle import IN, OUT, Bundle, Member
from eyestereo.tools.sram import ADDR_BITS, DATA_BITS

__all__ = ["SramPins", "SramCmd", "SramRsp", "HostPort", "StatPort", "check_bundle"]


def check_bundle(name: str, port, cls) -> None:
    """An interface port of class ``cls`` (SramPins, SramCmd, ..., FrameControl), else a ValueError that
    names the port and the block. A declared bundle (:class:`~eyestereo.hdl.interfaces.bundle.Bundle`)
    has its members checked too (:func:`~eyestereo.hdl.common.checks.check_port`)."""
    if isinstance(cls, type) and issubclass(cls, Bundle):
        check_port(name, port, cls)
    elif not isinstance(port, cls):
        got = "None" if port is None else (f"{type(port).__name__} {port!r}"[:60] if isinstance(port, (int, str))
                                           else type(port).__name__)
        fields = f" ({', '.join(cls().fields())})" if hasattr(cls, "fields") else ""
        raise block_error(f"port {name} must be a {cls.__name__}{fields}, got {got}")


def _bits(name: str, value, lo: int, hi: int) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or not lo <= value <= hi:
        raise ValueError(f"{name} must be an int in [{lo}, {hi}], got {value!r}")
    return int(value)


class _Word(Bundle):
    """A word port's parameters, checked: ``addr_bits``, ``data_bits`` (whole bytes: ``be_bits`` byte
    enables), ``tag_bits``; the ones a class has no member for stay unset."""

    def _sizes(self, addr_bits: int | None = None, data_bits: int | None = None, tag_bits: int | None = None) -> None:
        kind = type(self).__name__
        if addr_bits is not None:
            self.addr_bits = _bits(f"{kind} addr_bits", addr_bits, 1, 24)
        if data_bits is not None:
            self.data_bits = _bits(f"{kind} data_bits", data_bits, 8, 32)
            if self.data_bits % 8:
                raise ValueError(f"{kind} data_bits must be a multiple of 8, got {data_bits}")
            self.be_bits = self.data_bits // 8
        if tag_bits is not None:
            self.tag_bits = _bits(f"{kind} tag_bits", tag_bits, 1, 16)
        self.make()


class SramPins(_Word):
    """The FPGA's pins to the SRAM (see the module docstring); all outputs reset-free registers in the
    controller. The FPGA is the producer: ``dq_i`` is the one member the part drives."""

    PARAMS = ("addr_bits", "data_bits")
    MEMBERS = (Member("addr", "addr_bits", OUT), Member("ce_n", bool, OUT, init=1), Member("ld_n", bool, OUT),
               Member("we_n", bool, OUT, init=1), Member("bw_n", "be_bits", OUT, init=-1),
               Member("oe_n", bool, OUT, init=1), Member("dq_o", "data_bits", OUT), Member("dq_oe", bool, OUT),
               Member("dq_i", "data_bits", IN))

    def __init__(self, addr_bits: int = ADDR_BITS, data_bits: int = DATA_BITS):
        self._sizes(addr_bits, data_bits)


class SramCmd(_Word):
    """Word port, command side (master -> controller): valid/ready, we, addr, wdata, be, tag."""

    PARAMS = ("addr_bits", "data_bits", "tag_bits")
    MEMBERS = (Member("valid", bool, OUT), Member("ready", bool, IN), Member("we", bool, OUT),
               Member("addr", "addr_bits", OUT), Member("wdata", "data_bits", OUT), Member("be", "be_bits", OUT),
               Member("tag", "tag_bits", OUT))

    def __init__(self, addr_bits: int = ADDR_BITS, data_bits: int = DATA_BITS, tag_bits: int = 1):
        self._sizes(addr_bits, data_bits, tag_bits)


class SramRsp(_Word):
    """Word port, read data (controller -> master): valid, data, tag; no back-pressure."""

    PARAMS = ("data_bits", "tag_bits")
    MEMBERS = (Member("valid", bool, OUT), Member("data", "data_bits", OUT), Member("tag", "tag_bits", OUT))

    def __init__(self, data_bits: int = DATA_BITS, tag_bits: int = 1):
        self._sizes(data_bits=data_bits, tag_bits=tag_bits)


class HostPort(_Word):
    """The host's word port into the SRAM (the processor bus bridge of the complete system is its master).

    Fields (ports ``<arg>_<field>``; directions and widths: ``MEMBERS``, docs/interfaces.md)::

        req_valid  a request is offered, held until it moves
        req_ready  the arbiter takes it (it moves on a rising edge with req_valid & req_ready)
        req_we     1 write, 0 read
        req_addr   20-bit word address (the whole SRAM; the frame buffers' map is
                   eyestereo.tools.models.sram_arbiter.AddressMap)
        req_wdata  16 bits
        req_be     2 bits, the bytes a write changes (bit 1: 15..8, bit 0: 7..0)
        rsp_valid  one clock per read, in request order, no back-pressure
        rsp_data   the word read

    Writes are posted (no response); a read after a write to the same address returns the written word.
    The arbiter takes one request per two clocks at most (``req_ready`` comes from a register)::

        cycle      0    1    2    3    4 ...    n
        req_valid  #    #    #    _    _        _
        req_ready  #    _    #    _    #        #
        req_we     _    #    #    .    .        .
        rsp_valid  _    _    _    _    _        #     the read of cycle 0; n depends on the load
    """

    PARAMS = ("addr_bits", "data_bits")
    MEMBERS = (Member("req_valid", bool, OUT), Member("req_ready", bool, IN), Member("req_we", bool, OUT),
               Member("req_addr", "addr_bits", OUT), Member("req_wdata", "data_bits", OUT),
               Member("req_be", "be_bits", OUT), Member("rsp_valid", bool, IN), Member("rsp_data", "data_bits", IN))

    def __init__(self, addr_bits: int = ADDR_BITS, data_bits: int = DATA_BITS):
        self._sizes(addr_bits, data_bits)


class StatPort(Bundle):
    """Read port of the arbiter's counters and frame-buffer status: ``addr`` in, ``data`` (32 bits) out
    two clocks later (a two-stage registered multiplexer; the register map is ``STAT`` in
    eyestereo.tools.models.sram_arbiter)::

        cycle  0    1    2    3
        addr   a0   a1   .    .
        data   .    .    d0   d1
    """

    PARAMS = ("addr_bits", "data_bits")
    MEMBERS = (Member("addr", "addr_bits", OUT), Member("data", "data_bits", IN))

    def __init__(self, addr_bits: int = 5, data_bits: int = 32):
        self.addr_bits = _bits("StatPort addr_bits", addr_bits, 1, 8)
        self.data_bits = _bits("StatPort data_bits", data_bits, 16, 64)
        self.make()
