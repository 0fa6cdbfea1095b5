"""The board's SRAM: a synchronous pipelined 1M x 18 part, as a behavioural model that checks the part's rules.

The EyeBot M6 carries one 18-Mbit synchronous SRAM organised 1M x 18 (thesis 1.1), wired straight to the
FPGA and clocked at 100 MHz; 16 of its 18 DQ lines carry data (the two parity lines DQPa/DQPb are not
used). Two kinds of such part exist, pin for pin nearly alike, and the model is either (``kind``):

``"pipelined"`` -- a standard pipelined SyncBurst SRAM (Cypress CY7C1382D / ISSI IS61LPS102418-class).
    A single write started with ADSC# takes its data *with the address*; a read drives its data
    ``read_latency - 1`` clocks after the address edge. Reads and writes therefore claim the data bus at
    different distances from their address, and a write after reads must wait until the part has let go
    of the bus, with one dead bus cycle for the part's clock-to-high-Z time (tCHZ / tOEHZ): the
    read-to-write turnaround.
``"nobl"`` -- a No-Bus-Latency (NoBL, ZBT-style) pipelined part (CY7C1372D / IS61NLP102418-class). Write data
    follows its address by the same ``read_latency`` as read data, so every clock can carry a read or a
    write in any order without a dead cycle.

Pins as the FPGA drives them (all active-low pins end in ``_n``; ``CE2`` tied high, ``CE3#``, ``ZZ`` and
``MODE`` tied low, ``GW#`` and ``ADSP#`` (pipelined) or ``CEN#`` (NoBL) tied to their inactive/active
level on the board):

=========  ==========================================  =========================================
FPGA pin   pipelined SyncBurst                         NoBL
=========  ==========================================  =========================================
addr       A19..A0                                     A19..A0
ce_n       CE1#                                        CE1#
ld_n       ADSC# (address strobe, controller)          ADV/LD# (low: load a new address)
we_n       BWE# (byte write enable)                    WE#
bw_n[1:0]  BWb#, BWa# (DQ15..8, DQ7..0)                BWb#, BWa#
oe_n       OE# (asynchronous output enable)            OE#
dq         DQ15..0 (the FPGA's side: dq_o, dq_oe, dq_i through its I/O buffers)
=========  ==========================================  =========================================

Rules checked at every rising clock edge (a violation names the rule, the edge and the time):

* **inputs defined**: ``ld_n``, ``ce_n``, ``dq_oe`` never undefined; during an access also ``addr``,
  ``we_n`` and (writes) ``bw_n``; the bytes a write enables carry defined data at the edge that samples it.
* **single accesses only**: ``ld_n`` low at every edge. ``ld_n`` high would continue or suspend a burst on
  both kinds of part (they then ignore ``ce_n`` and repeat or advance the last access); the controller
  idles by *deselecting* (``ce_n`` high with ``ld_n`` low).
* **byte writes**: a write enables at least one byte (``bw_n`` not all high: that is a write abort, which
  in a controller is a bug).
* **write data in the right cycle**: the FPGA drives DQ exactly in the bus cycle before the edge that
  samples a write's data (the address edge for pipelined parts, ``read_latency`` edges later for NoBL);
  driving in any other cycle is a stray drive.
* **no bus contention**: the FPGA never drives in a cycle in which the part drives read data.
* **turnaround** (pipelined only): a cycle in which the part drives and one in which the FPGA drives are
  separated by at least ``turnaround`` (1) idle bus cycle, in either order (the part lets go of DQ only
  tCHZ after the clock edge and grabs it tCLZ after it; the FPGA's output buffers are no faster).
* **output enable**: ``oe_n`` low throughout every cycle in which read data is due (else the part would
  not drive it).

Reads return the stored word with the part's coherency: a read sees every write registered before it (a
NoBL part forwards a write whose data has not arrived yet), never one registered after it. A word never
written reads as :func:`power_up_word` (a fixed pseudo-random pattern: a real part powers up with random
contents), so scoreboards can predict it.

Timing convention of :meth:`SramChip.edge`: edge ``t`` sees the pins the FPGA set after edge ``t-1`` (they
were stable during bus cycle ``t-1``, the interval between edges ``t-1`` and ``t``), and returns the word
the part drives during bus cycle ``t`` (sampled by the FPGA at edge ``t+1``), or None. A read registered at
edge ``k`` is driven in cycle ``k + read_latency - 1``; the FPGA samples it at edge ``k + read_latency``.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

__all__ = ["KINDS", "SramPart", "Pins", "SramChip", "SramViolation", "power_up_word"]

KINDS = ("pipelined", "nobl")
#: Words of the 18-Mbit part (1M x 18) and the address width.
WORDS = 1 << 20
ADDR_BITS = 20
#: DQ lines the FPGA uses (16 of the 18; DQPa/DQPb unused).
DATA_BITS = 16


@dataclass(frozen=True)
class SramPart:
    """Which part: ``kind`` (see the module docstring) and its read latency in clocks (1 = flow-through,
    2 = pipelined, the 100 MHz parts; 3 = a late-late part).

    ``write_latency`` (edges from a write's address to the edge that samples its data) and ``turnaround``
    (idle bus cycles the FPGA leaves after the part drove) follow from the kind.
    """

    kind: str = "nobl"
    read_latency: int = 2
    words: int = WORDS
    data_bits: int = DATA_BITS

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"SRAM kind must be one of {KINDS}, got {self.kind!r}")
        if isinstance(self.read_latency, bool) or not isinstance(self.read_latency, int) \
                or not 1 <= self.read_latency <= 3:
            raise ValueError(f"SRAM read_latency must be 1, 2 or 3 clocks, got {self.read_latency!r}")
        if self.words < 1 or self.words & (self.words - 1):
            raise ValueError(f"SRAM words must be a power of two, got {self.words}")
        if self.data_bits % 8 or not 8 <= self.data_bits <= 32:
            raise ValueError(f"SRAM data_bits must be 8, 16, 24 or 32, got {self.data_bits}")

    @property
    def write_latency(self) -> int:
        return 0 if self.kind == "pipelined" else self.read_latency

    @property
    def turnaround(self) -> int:
        return 1 if self.kind == "pipelined" else 0

    @property
    def addr_bits(self) -> int:
        return self.words.bit_length() - 1

    @property
    def nbytes(self) -> int:
        return self.data_bits // 8

    @property
    def name(self) -> str:
        what = "pipelined SyncBurst" if self.kind == "pipelined" else "NoBL (ZBT-style) pipelined"
        return f"{what}, read latency {self.read_latency}"


@dataclass
class Pins:
    """The FPGA's pins as sampled at one rising edge; None = undefined (X, U or Z on any bit).

    ``dq_o`` holds one entry per byte (least significant first), each an int or None.
    """

    ce_n: int | None = 1
    ld_n: int | None = 0
    we_n: int | None = 1
    bw_n: int | None = 3
    oe_n: int | None = 1
    addr: int | None = 0
    dq_oe: int | None = 0
    dq_o: tuple = (0, 0)


class SramViolation(AssertionError):
    """The FPGA broke a rule of the part (the message says which, at which edge and time)."""


def power_up_word(addr: int, bits: int = DATA_BITS) -> int:
    """The model's contents of a never-written word: a fixed pseudo-random function of the address."""
    x = (addr * 0x9E3779B1 + 0x7F4A7C15) & 0xFFFFFFFF
    x ^= x >> 15
    x = (x * 0x2C1B3C6D) & 0xFFFFFFFF
    x ^= x >> 12
    return x & ((1 << bits) - 1)


@dataclass
class _Read:
    edge: int
    addr: int
    value: int
    forwards: list  # writes registered before this read whose data was still to come: [_Write]


@dataclass
class _Write:
    edge: int
    addr: int
    bw_n: int
    data: int | None = None  # filled in when the data is sampled


@dataclass
class SramStats:
    edges: int = 0
    reads: int = 0
    writes: int = 0
    deselects: int = 0
    sram_drive_cycles: int = 0
    fpga_drive_cycles: int = 0
    idle_bus_cycles: int = 0


@dataclass
class SramChip:
    """The part's state and rules; call :meth:`edge` once per rising clock edge, in order.

    Parameters:
        part: which part (:class:`SramPart`).
        strict: raise :class:`SramViolation` at the first broken rule (else collect them in ``violations``).
        period_ns: clock period, only for the times in messages.
    """

    part: SramPart = field(default_factory=SramPart)
    strict: bool = True
    period_ns: float = 10.0
    log: bool = False  # keep every access: write_log (edge, addr, word after the write), read_log (edge, addr)
    violations: list = field(default_factory=list)
    stats: SramStats = field(default_factory=SramStats)

    def __post_init__(self):
        self.mem: dict[int, int] = {}
        self._reads: deque[_Read] = deque()    # registered reads whose data is still to be driven
        self._writes: deque[_Write] = deque()  # registered writes whose data is still to be sampled
        self._drove: dict[int, _Read] = {}      # bus cycle -> read the part drives in it
        self._last_sram_cycle = -(1 << 30)
        self._last_fpga_cycle = -(1 << 30)
        self._t = None
        self._t0 = None
        self.write_log: list[tuple[int, int, int]] = []
        self.read_log: list[tuple[int, int]] = []

    # ---------------------------------------------------------------------------------------------
    def word(self, addr: int) -> int:
        """The stored word at ``addr`` (power-up pattern if never written)."""
        return self.mem.get(addr, power_up_word(addr, self.part.data_bits))

    def _fail(self, t: int, rule: str, detail: str) -> None:
        msg = f"SRAM rule broken at edge {t} ({(t - (self._t0 or 0)) * self.period_ns:.0f} ns after the " \
              f"model started): {rule}: {detail}"
        self.violations.append(msg)
        if self.strict:
            raise SramViolation(msg)

    def _write_bytes(self, old: int, data: int, bw_n: int) -> int:
        for b in range(self.part.nbytes):
            if not (bw_n >> b) & 1:
                m = 0xFF << (8 * b)
                old = (old & ~m) | (data & m)
        return old

    # ---------------------------------------------------------------------------------------------
    def edge(self, t: int, p: Pins) -> int | None:
        """Process rising edge ``t`` with the pins ``p`` sampled at it; return the word driven in cycle t."""
        part = self.part
        if self._t0 is None:
            self._t0 = t
        elif t <= self._t:
            raise ValueError(f"edges must come in order: edge {t} after edge {self._t}")
        gap = None if self._t is None else t - self._t
        self._t = t
        st = self.stats
        st.edges += 1
        if gap is not None and gap > 1 and (self._reads or self._writes):
            raise ValueError(f"edge {t}: {gap - 1} edges skipped while accesses were in flight")

        # 1. the command registered at this edge
        if p.ld_n is None:
            self._fail(t, "inputs defined", "ld_n (ADSC# / ADV-LD#) is undefined")
        elif p.ld_n != 0:
            self._fail(t, "single accesses only", "ld_n (ADSC# / ADV-LD#) high: a burst continue/suspend "
                       "cycle; deselect with ce_n high instead")
        if p.ce_n is None:
            self._fail(t, "inputs defined", "ce_n (CE1#) is undefined")
        elif p.ce_n == 0:
            if p.addr is None:
                self._fail(t, "inputs defined", "addr undefined during an access")
            if p.we_n is None:
                self._fail(t, "inputs defined", "we_n undefined during an access")
            elif p.we_n == 0:
                if p.bw_n is None:
                    self._fail(t, "inputs defined", "bw_n undefined during a write")
                elif p.bw_n & ((1 << part.nbytes) - 1) == (1 << part.nbytes) - 1:
                    self._fail(t, "byte writes", f"write to {p.addr:#07x} with no byte enabled (bw_n all high)")
                st.writes += 1
                self._writes.append(_Write(t, p.addr or 0, p.bw_n if p.bw_n is not None else 0))
            else:
                st.reads += 1
                addr = p.addr or 0
                if self.log:
                    self.read_log.append((t, addr))
                # Coherency: writes registered before this read and still waiting for data are forwarded.
                self._reads.append(_Read(t, addr, self.word(addr), [w for w in self._writes if w.addr == addr]))
        else:
            st.deselects += 1

        # 2. write data sampled at this edge
        due = None
        if self._writes and self._writes[0].edge + part.write_latency == t:
            due = self._writes.popleft()
        # 3. the bus during cycle t-1
        fpga = p.dq_oe
        if fpga is None:
            self._fail(t, "inputs defined", "dq_oe (the FPGA's DQ output enable) is undefined")
            fpga = 0
        sram_read = self._drove.pop(t - 1, None)
        c = t - 1
        if sram_read is not None:
            st.sram_drive_cycles += 1
            if p.oe_n != 0:
                self._fail(t, "output enable", f"oe_n {'undefined' if p.oe_n is None else 'high'} in the cycle "
                           f"the read of edge {sram_read.edge} ({sram_read.addr:#07x}) drives its data")
            if not fpga and c - self._last_fpga_cycle <= part.turnaround:
                self._fail(t, "turnaround", f"the part drives DQ in cycle {c} (read of edge {sram_read.edge}), "
                           f"right after the FPGA drove it in cycle {self._last_fpga_cycle} "
                           f"({part.turnaround} idle cycle needed)")
        if fpga:
            st.fpga_drive_cycles += 1
            if sram_read is not None:
                self._fail(t, "no bus contention", f"the FPGA drives DQ in cycle {c} while the part drives "
                           f"the data of the read of edge {sram_read.edge}")
            elif c - self._last_sram_cycle <= part.turnaround:
                self._fail(t, "turnaround", f"the FPGA drives DQ in cycle {c}, right after the part drove "
                           f"it in cycle {self._last_sram_cycle} ({part.turnaround} idle cycle needed)")
            if due is None:
                self._fail(t, "write data in the right cycle", f"the FPGA drives DQ in cycle {c} but no "
                           f"write samples data at edge {t} (stray drive)")
            self._last_fpga_cycle = c
        elif sram_read is None:
            st.idle_bus_cycles += 1
        if sram_read is not None:
            self._last_sram_cycle = c
        if due is not None:
            if not fpga:
                self._fail(t, "write data in the right cycle", f"the write of edge {due.edge} to "
                           f"{due.addr:#07x} samples DQ at edge {t}, but the FPGA did not drive it")
            data = 0
            for b in range(part.nbytes):
                byte = p.dq_o[b] if b < len(p.dq_o) else None
                if not (due.bw_n >> b) & 1:
                    if byte is None:
                        self._fail(t, "inputs defined", f"byte {b} of the write of edge {due.edge} to "
                                   f"{due.addr:#07x} is undefined")
                        byte = 0
                    data |= (byte & 0xFF) << (8 * b)
            due.data = data
            self.mem[due.addr] = self._write_bytes(self.word(due.addr), data, due.bw_n)
            if self.log:
                self.write_log.append((due.edge, due.addr, self.mem[due.addr]))

        # 4. read data driven during cycle t
        out = None
        if self._reads and self._reads[0].edge + part.read_latency - 1 == t:
            r = self._reads.popleft()
            v = r.value
            for w in r.forwards:
                v = self._write_bytes(v, w.data if w.data is not None else 0, w.bw_n)
            self._drove[t] = r
            out = v
        return out

    @property
    def idle(self) -> bool:
        """No access in flight (no read data or write data still to come)."""
        return not self._reads and not self._writes and not self._drove

    def pending(self) -> str:
        return (f"{len(self._reads)} reads, {len(self._writes)} writes in flight (last edge {self._t}; "
                f"writes of edges {[w.edge for w in self._writes][:4]}, "
                f"reads of edges {[r.edge for r in self._reads][:4]})")
