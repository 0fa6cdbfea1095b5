"""SDR SDRAM parts: geometry, datasheet timings, the address map, the mode register, and a model of the part
that checks its rules at every rising clock edge (pure Python; the cocotb side is
:mod:`eyestereo.sim.lib.sdram_model`).

**Parts** (:data:`PARTS`, :class:`SdramPart`; figures in ns unless the name says otherwise):

``AS4C32M16SB-7`` / ``-6``
    Alliance Memory AS4C32M16SB, 512 Mbit, 4 banks x 8192 rows x 1024 columns x 16 bits (32 M words,
    64 MB), the part the ULX3S v3.1 carries. Figures from the datasheet Rev. 1.0 (June 2016), Table 16
    "Electrical Characteristics and Recommended A.C. Operating Conditions": -7 (-6): tRC 63 (60), tRFC 63
    (60), tRCD 21 (18), tRP 21 (18), tRRD 14 (12), tMRD 14 (12) ns = 2 clocks at the fastest clock, tRAS 42
    .. 120 000, tWR 14 (12), tCK 10 at CL 2 (100 MHz) and 7 (6) at CL 3 (143 / 166 MHz), tREFI 7.8 us
    (8192 refresh cycles / 64 ms). Power-up: 200 us of NOPs, PRECHARGE ALL, 8 AUTO REFRESH, LOAD MODE
    REGISTER. Not checked against the datasheet's own power-up section: the copies of Rev. 1.0 found (its
    revision history and features, the command pages 8 and 11 of 55) do not include it. 200 us and 8
    refreshes are the safe side of the usual figures (Micron's part below asks for 100 us and 2, JEDEC's
    minimum is 2 refreshes; more refreshes and a longer wait do no harm), so a part asking for less is met.
``MT48LC16M16A2-7E`` / ``-75``
    Micron MT48LC16M16A2, 256 Mbit, 4 banks x 8192 rows x 512 columns x 16 bits (16 M words, 32 MB: the
    size of the ULX3S's first boards, and pin-compatible with ISSI IS42S16160). Micron's "256Mb: x4, x8,
    x16 SDRAM" data sheet, Table 12 "Electrical Characteristics and Recommended AC Operating Conditions":
    -7E (-75): tRAS 37 (44) .. 120 000, tRC 60 (66), tRCD 15 (20), tRFC 66 (66), tRP 15 (20), tRRD 14 (15),
    tWR 14 (15) ("1 CLK + 7 ns"; the 14 / 15 ns figure), tCK 7.5 (10) at CL 2 and 7 (7.5) at CL 3, tMRD
    2 clocks, 8192 rows / 64 ms; power-up (note 6): 100 us, then two AUTO REFRESH.

:func:`part` takes a part's name with overrides, ``"AS4C32M16SB-7:refresh_ms=8.192,powerup_us=1"``: a
string that elaboration parameters, bench configurations and the model share (the benches shrink the
power-up wait and the refresh period this way, and the model checks the shrunk figures).

**Address map** (:func:`split`, :func:`join`): a word address is ``row | bank | column`` from the top
bit down, so a sequential run that leaves a row continues in the next bank (whose row can be opened while
the first is still read).

**Commands** at a rising edge with ``cke`` high (``cs_n ras_n cas_n we_n``): ``1xxx`` inhibit, ``0111`` NOP,
``0011`` ACTIVATE (``ba``, row on ``a``), ``0101`` READ and ``0100`` WRITE (``ba``, column on ``a``; ``a[10]``
auto precharge), ``0010`` PRECHARGE (``a[10]``: all banks), ``0001`` AUTO REFRESH, ``0000`` LOAD MODE
REGISTER (mode word on ``a``), ``0110`` BURST TERMINATE.

**Rules** that :class:`SdramChip` checks (a violation names the rule, the edge and the time):

* *inputs defined*: ``cke``, ``cs_n`` always; the command pins, ``ba``, ``a`` with a command; the bytes a
  write enables (``dqm`` low) when the write samples them; ``cke`` high throughout (no power-down).
* *power-up*: nothing but inhibit / NOP for ``powerup_us`` after the model starts; then PRECHARGE ALL, at
  least ``init_refreshes`` AUTO REFRESH and LOAD MODE REGISTER (before or after the refreshes) before any
  ACTIVATE, READ or WRITE; the mode register's CAS latency the one expected, burst length 1.
* *bank state*: no ACTIVATE to a bank with an open row; no READ / WRITE to a bank without one; AUTO
  REFRESH and LOAD MODE REGISTER with every bank idle; no auto precharge (the controller precharges).
* *timings* (ns rules compared in ns with the model's clock period, never in the controller's counts):
  tRCD (ACTIVATE -> READ/WRITE), tRP (PRECHARGE -> ACTIVATE / REFRESH / MODE), tRAS min (ACTIVATE ->
  PRECHARGE) and max (a row open no longer), tRC (ACTIVATE -> ACTIVATE, same bank), tRRD (ACTIVATE ->
  ACTIVATE, any banks), tWR (last write data -> PRECHARGE), tRFC (REFRESH -> ACTIVATE / REFRESH / MODE),
  tMRD (MODE -> any command, in clocks).
* *refresh*: counted from the end of the power-up sequence, refreshes fall due every tREFI = refresh_ms /
  refresh_rows; at most ``max_postponed`` (8) may be owed at any time and no more than 8 x tREFI may pass
  without one. A due refresh still owed one tREFI after it fell due counts as *late*
  (:attr:`SdramStats.late_refreshes`; the benches assert 0).
* *data bus*: a WRITE samples DQ at its own edge, so the FPGA drives DQ (``dq_oe``) in the cycle before it
  and in no other cycle (stray drive); the FPGA never drives while the part drives read data (contention)
  and leaves one idle cycle between the part's last read word and its own write data (turnaround).
* *DQM*: a write's byte is written only where ``dqm`` is low at the write's edge; a read's byte is
  driven only where ``dqm`` was low two edges before the edge at which the FPGA samples it (read DQM
  latency 2); a byte not driven reads as undefined in the bench.

Timing convention of :meth:`SdramChip.edge` (the SRAM model's): edge ``t`` sees the pins set after edge
``t-1``; it returns what the part drives in bus cycle ``t`` (between edges ``t`` and ``t+1``, sampled by the
FPGA at edge ``t+1``). A READ at edge ``k`` with CAS latency CL is driven in cycle ``k + CL - 1`` and sampled
at edge ``k + CL``. Words never written read as :func:`power_up_word`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

from eyestereo.tools.sram import power_up_word

__all__ = ["SdramPart", "SdramClocks", "PARTS", "part", "split", "join", "mode_register", "Pins", "SdramChip",
           "SdramStats", "SdramViolation", "power_up_word", "CMD"]

#: (ras_n, cas_n, we_n) of each command (cs_n low).
CMD = {"ACT": (0, 1, 1), "READ": (1, 0, 1), "WRITE": (1, 0, 0), "PRE": (0, 1, 0), "REF": (0, 0, 1),
       "MRS": (0, 0, 0), "BST": (1, 1, 0), "NOP": (1, 1, 1)}
_DECODE = {v: k for k, v in CMD.items()}
#: burst length -> the mode register's A2..A0 code (7 = full page)
_BL_CODE = {1: 0, 2: 1, 4: 2, 8: 3, "page": 7}


@dataclass(frozen=True)
class SdramClocks:
    """A part's timings at one clock, in whole clocks: minimum spacings round up, ``refi`` and ``ras_max``
    (maxima) round down, ``powerup`` is the wait in clocks."""

    rcd: int
    rp: int
    ras: int
    ras_max: int
    rc: int
    rrd: int
    wr: int
    rfc: int
    mrd: int
    refi: int
    powerup: int


@dataclass(frozen=True)
class SdramPart:
    """One SDR SDRAM part (see the module docstring): geometry, datasheet timings in ns (``t_mrd`` in clocks),
    refresh and power-up figures, the fastest clock period at CAS latency 2 and 3. Checked when made: a
    ValueError says which figure is wrong."""

    name: str
    banks: int = 4
    rows: int = 8192
    columns: int = 1024
    data_bits: int = 16
    t_rcd: float = 21.0
    t_rp: float = 21.0
    t_ras: float = 42.0
    t_ras_max: float = 120_000.0
    t_rc: float = 63.0
    t_rrd: float = 14.0
    t_wr: float = 14.0
    t_rfc: float = 63.0
    t_mrd: int = 2
    refresh_rows: int = 8192
    refresh_ms: float = 64.0
    powerup_us: float = 200.0
    init_refreshes: int = 8
    tck_cl2: float = 10.0
    tck_cl3: float = 7.0
    max_postponed: int = 8

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            raise ValueError(f"SDRAM part name must be a non-empty string, got {self.name!r}")
        for f, lo, hi in (("banks", 2, 8), ("rows", 256, 1 << 16), ("columns", 64, 4096)):
            v = getattr(self, f)
            if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi or v & (v - 1):
                raise ValueError(f"SDRAM part {self.name}: {f} must be a power of two in [{lo}, {hi}], got {v!r}")
        if self.data_bits not in (8, 16, 32):
            raise ValueError(f"SDRAM part {self.name}: data_bits must be 8, 16 or 32, got {self.data_bits!r}")
        for f in ("t_rcd", "t_rp", "t_ras", "t_ras_max", "t_rc", "t_rrd", "t_wr", "t_rfc", "refresh_ms",
                  "powerup_us", "tck_cl2", "tck_cl3"):
            v = getattr(self, f)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v <= 0:
                raise ValueError(f"SDRAM part {self.name}: {f} must be a positive number, got {v!r}")
        for f, lo in (("t_mrd", 1), ("refresh_rows", 1), ("init_refreshes", 2), ("max_postponed", 0)):
            v = getattr(self, f)
            if isinstance(v, bool) or not isinstance(v, int) or v < lo:
                raise ValueError(f"SDRAM part {self.name}: {f} must be an integer >= {lo}, got {v!r}")
        if self.t_ras_max <= self.t_ras:
            raise ValueError(f"SDRAM part {self.name}: t_ras_max ({self.t_ras_max} ns) must exceed t_ras "
                             f"({self.t_ras} ns)")
        if self.t_rc < self.t_ras:
            raise ValueError(f"SDRAM part {self.name}: t_rc ({self.t_rc} ns) must be at least t_ras ({self.t_ras} ns)")
        if self.tck_cl3 > self.tck_cl2:
            raise ValueError(f"SDRAM part {self.name}: CAS latency 3 cannot need a slower clock than 2 "
                             f"(tck_cl3 {self.tck_cl3} ns > tck_cl2 {self.tck_cl2} ns)")
        if self.t_refi <= self.t_rfc + self.t_rp:
            raise ValueError(f"SDRAM part {self.name}: tREFI ({self.t_refi:.1f} ns) leaves no time beside a "
                             f"refresh (t_rfc + t_rp = {self.t_rfc + self.t_rp} ns)")

    # --- geometry ------------------------------------------------------------------------------------
    @property
    def words(self) -> int:
        return self.banks * self.rows * self.columns

    @property
    def bank_bits(self) -> int:
        return self.banks.bit_length() - 1

    @property
    def row_bits(self) -> int:
        return self.rows.bit_length() - 1

    @property
    def col_bits(self) -> int:
        return self.columns.bit_length() - 1

    @property
    def addr_bits(self) -> int:
        """Bits of a word address (25 for 32 M words)."""
        return self.bank_bits + self.row_bits + self.col_bits

    @property
    def a_bits(self) -> int:
        """Address pins A0..: the row's bits, at least 11 (A10 is the precharge-all / auto-precharge bit)."""
        return max(self.row_bits, self.col_bits + 1, 11)

    @property
    def megabytes(self) -> float:
        return self.words * self.data_bits / 8 / (1 << 20)

    # --- timing --------------------------------------------------------------------------------------
    @property
    def t_refi(self) -> float:
        """Average refresh interval in ns (64 ms / 8192 rows = 7812.5 ns)."""
        return self.refresh_ms * 1e6 / self.refresh_rows

    def max_mhz(self, cas_latency: int) -> float:
        """The fastest clock at this CAS latency (2 or 3)."""
        if cas_latency not in (2, 3):
            raise ValueError(f"CAS latency must be 2 or 3, got {cas_latency!r}")
        return 1000.0 / (self.tck_cl2 if cas_latency == 2 else self.tck_cl3)

    def clocks(self, clock_mhz: float) -> SdramClocks:
        """The timings as clock counts at ``clock_mhz``: spacings rounded up, maxima (tREFI, tRAS max)
        rounded down. ValueError for a clock that is not a positive number."""
        if isinstance(clock_mhz, bool) or not isinstance(clock_mhz, (int, float)) or not 0 < clock_mhz <= 1000:
            raise ValueError(f"clock_mhz must be a number in (0, 1000], got {clock_mhz!r}")
        period = 1000.0 / clock_mhz

        def up(ns):
            return max(1, math.ceil(ns / period - 1e-9))

        def down(ns):
            return math.floor(ns / period + 1e-9)

        return SdramClocks(rcd=up(self.t_rcd), rp=up(self.t_rp), ras=up(self.t_ras), ras_max=down(self.t_ras_max),
                           rc=up(self.t_rc), rrd=up(self.t_rrd), wr=up(self.t_wr), rfc=up(self.t_rfc),
                           mrd=self.t_mrd, refi=down(self.t_refi), powerup=up(self.powerup_us * 1000.0))

    @property
    def spec(self) -> str:
        """This part as :func:`part` reads it: the table's name plus the figures that differ from it."""
        base_name = self.name.split(":")[0]
        base = PARTS.get(base_name)
        if base is None:
            raise ValueError(f"SDRAM part {self.name} is not in the table (PARTS): it has no spec string")
        diff = [f"{f.name}={getattr(self, f.name)!r}" for f in dataclasses.fields(self)
                if f.name != "name" and getattr(self, f.name) != getattr(base, f.name)]
        return base_name + (":" + ",".join(diff) if diff else "")


def _p(name, **kw) -> SdramPart:
    return SdramPart(name, **kw)


#: The parts by name (see the module docstring for the datasheets).
PARTS: dict[str, SdramPart] = {p.name: p for p in (
    _p("AS4C32M16SB-7"),
    _p("AS4C32M16SB-6", t_rcd=18.0, t_rp=18.0, t_rc=60.0, t_rrd=12.0, t_wr=12.0, t_rfc=60.0, tck_cl3=6.0),
    _p("MT48LC16M16A2-7E", columns=512, t_rcd=15.0, t_rp=15.0, t_ras=37.0, t_rc=60.0, t_rrd=14.0, t_wr=14.0,
       t_rfc=66.0, powerup_us=100.0, init_refreshes=2, tck_cl2=7.5, tck_cl3=7.0),
    _p("MT48LC16M16A2-75", columns=512, t_rcd=20.0, t_rp=20.0, t_ras=44.0, t_rc=66.0, t_rrd=15.0, t_wr=15.0,
       t_rfc=66.0, powerup_us=100.0, init_refreshes=2, tck_cl2=10.0, tck_cl3=7.5),
)}
#: The ULX3S's part.
ULX3S = "AS4C32M16SB-7"


def part(spec) -> SdramPart:
    """A part from its name in :data:`PARTS`, optionally with figures replaced: ``"NAME:field=value,..."``
    (``"AS4C32M16SB-7:refresh_ms=8.192,powerup_us=1"``). An :class:`SdramPart` is returned as it is.
    ValueError for an unknown name or field, a value of the wrong kind, or figures the part rejects."""
    if isinstance(spec, SdramPart):
        return spec
    if not isinstance(spec, str):
        raise ValueError(f"an SDRAM part is a name from {sorted(PARTS)} (with overrides) or an SdramPart, "
                         f"got {type(spec).__name__}")
    name, _, rest = spec.partition(":")
    if name not in PARTS:
        raise ValueError(f"unknown SDRAM part {name!r}: the parts are {sorted(PARTS)}")
    base = PARTS[name]
    if not rest:
        return base
    kinds = {f.name: type(getattr(base, f.name)) for f in dataclasses.fields(base) if f.name != "name"}
    changes = {}
    for item in rest.split(","):
        key, eq, text = item.partition("=")
        key = key.strip()
        if not eq or key not in kinds:
            raise ValueError(f"SDRAM part spec {spec!r}: {item!r} is not field=value with a field of "
                             f"{sorted(kinds)}")
        try:
            changes[key] = kinds[key](float(text)) if kinds[key] is float else int(text)
        except ValueError:
            raise ValueError(f"SDRAM part spec {spec!r}: {key} must be a {kinds[key].__name__}, got {text!r}") from None
    changed = dataclasses.replace(base, **changes)
    return dataclasses.replace(changed, name=changed.spec)  # the name: the canonical spec


# --- address map and mode register -------------------------------------------------------------------
def split(p: SdramPart, addr: int) -> tuple[int, int, int]:
    """(bank, row, column) of word address ``addr`` (``row | bank | column``); ValueError outside the part."""
    if isinstance(addr, bool) or not isinstance(addr, int) or not 0 <= addr < p.words:
        raise ValueError(f"word address must be an int in [0, {p.words}), got {addr!r}")
    col = addr & (p.columns - 1)
    bank = (addr >> p.col_bits) & (p.banks - 1)
    return bank, addr >> (p.col_bits + p.bank_bits), col


def join(p: SdramPart, bank: int, row: int, col: int) -> int:
    """The word address of (bank, row, column); ValueError for a coordinate outside the part."""
    for what, v, n in (("bank", bank, p.banks), ("row", row, p.rows), ("column", col, p.columns)):
        if isinstance(v, bool) or not isinstance(v, int) or not 0 <= v < n:
            raise ValueError(f"{what} must be an int in [0, {n}), got {v!r}")
    return (((row << p.bank_bits) | bank) << p.col_bits) | col


def mode_register(burst_length=1, cas_latency: int = 2, *, interleaved: bool = False,
                  single_write: bool = False) -> int:
    """The LOAD MODE REGISTER word on A12..A0: burst length (A2..A0; 1, 2, 4, 8 or ``"page"``), burst type
    (A3, 1 = interleaved), CAS latency (A6..A4: 2 or 3), operating mode 0 (A8..A7), write burst mode (A9, 1 =
    single-location writes)."""
    if burst_length not in _BL_CODE or isinstance(burst_length, bool):
        raise ValueError(f"burst length must be one of 1, 2, 4, 8, 'page', got {burst_length!r}")
    if isinstance(cas_latency, bool) or cas_latency not in (2, 3):
        raise ValueError(f"CAS latency must be 2 or 3, got {cas_latency!r}")
    if burst_length == "page" and interleaved:
        raise ValueError("a full-page burst is sequential only")
    return _BL_CODE[burst_length] | (int(interleaved) << 3) | (cas_latency << 4) | (int(single_write) << 9)


# --- the part's rules ----------------------------------------------------------------------------------
@dataclass
class Pins:
    """The FPGA's pins at one rising edge; None = undefined. ``dq_o`` is the driven word (None: undefined;
    only read where a write samples it)."""

    cke: int | None = 1
    cs_n: int | None = 1
    ras_n: int | None = 1
    cas_n: int | None = 1
    we_n: int | None = 1
    ba: int | None = 0
    a: int | None = 0
    dqm: int | None = 0
    dq_oe: int | None = 0
    dq_o: int | None = 0


class SdramViolation(AssertionError):
    """The FPGA broke a rule of the part (the message says which, at which edge and time)."""


@dataclass
class SdramStats:
    edges: int = 0
    commands: dict = field(default_factory=dict)  # name -> count
    refreshes: int = 0            # after the power-up sequence
    late_refreshes: int = 0
    max_owed: int = 0             # most refreshes owed at once
    max_refresh_gap_ns: float = 0.0
    read_words: int = 0
    write_words: int = 0
    ready_edge: int | None = None  # the edge that completed the power-up sequence


@dataclass
class _Bank:
    row: int | None = None
    act: float = -1e18        # edge of the last ACTIVATE
    pre: float = -1e18        # edge of the last PRECHARGE that closed it
    write: float = -1e18      # edge of the last write data
    ras_max_told: bool = False


@dataclass
class SdramChip:
    """The part's state and rules; call :meth:`edge` once per rising edge, in order (edges may be skipped
    while nothing is in flight and the command is inhibit / NOP).

    Parameters:
        part: the part (:class:`SdramPart` or a :func:`part` spec).
        period_ns: the clock period: the ns rules are checked against it.
        cas_latency: the CAS latency the mode register must set (None: any of 2, 3).
        strict: raise :class:`SdramViolation` at the first broken rule; else collect them in ``violations``.
        record: keep every access, as :class:`~eyestereo.tools.sram.SramChip` does with ``log``: ``write_log``
            (edge of the WRITE, word address, the word after the write), ``read_log`` (edge of the READ, word
            address); a bench checks its reads and writes against them.
    """

    part: object = ULX3S
    period_ns: float = 10.0
    cas_latency: int | None = None
    strict: bool = False
    log: int = 0  # keep the last ``log`` commands in ``command_log`` as (edge, command, bank, a)
    record: bool = False  # keep every access in write_log / read_log
    violations: list = field(default_factory=list)
    stats: SdramStats = field(default_factory=SdramStats)

    def __post_init__(self):
        self.part = part(self.part)
        if not self.period_ns > 0:
            raise ValueError(f"period_ns must be positive, got {self.period_ns!r}")
        p = self.part
        self.mem: dict[int, int] = {}
        self.banks = [_Bank() for _ in range(p.banks)]
        self._t0 = None
        self._t = None
        self._first_cmd = None
        self._precharged_all = False
        self._init_refs = 0
        self._mode = None           # (burst length code, CL) once loaded
        self._mrs = -1e18
        self._ref = -1e18           # edge of the last AUTO REFRESH
        self._last_act = -1e18
        self._ready = None          # edge the power-up sequence completed
        self._due = 0               # refreshes due so far (after the power-up sequence)
        self._gap_told = False
        self._owed_told = False
        self._reads = {}            # drive cycle -> [address, dqm or None]
        self._part_drove = -1 << 40  # last cycle the part drove DQ
        self._fpga_drove = -1 << 40
        self.cl = self.cas_latency
        self._full = (1 << p.data_bits) - 1
        self._nbytes = p.data_bits // 8
        self.command_log: list = []
        self.write_log: list[tuple[int, int, int]] = []
        self.read_log: list[tuple[int, int]] = []

    # ----------------------------------------------------------------------------------------------------
    def word(self, addr: int) -> int:
        return self.mem.get(addr, power_up_word(addr, self.part.data_bits))

    def _fail(self, t: int, rule: str, detail: str) -> None:
        msg = (f"SDRAM rule broken at edge {t} ({(t - (self._t0 or 0)) * self.period_ns:.0f} ns after the model "
               f"started): {rule}: {detail}")
        self.violations.append(msg)
        if self.strict:
            raise SdramViolation(msg)

    def _ns(self, t: int, since: float) -> float:
        return (t - since) * self.period_ns

    def _after(self, t, since, ns, rule, what):
        """Rule: at least ``ns`` ns from edge ``since`` to edge ``t`` (a tolerance for float periods)."""
        if self._ns(t, since) < ns - 1e-6:
            self._fail(t, rule, f"{what} {self._ns(t, since):.1f} ns after, {ns} ns needed")

    @property
    def idle(self) -> bool:
        """No read data still to be driven."""
        return not self._reads

    def pending(self) -> str:
        """What is in flight, for a message."""
        return f"{len(self._reads)} reads in flight (last edge {self._t}; data cycles {sorted(self._reads)[:4]})"

    def wants_dqm(self, t: int) -> bool:
        """Whether edge ``t``'s ``dqm`` masks read data (a read's word is driven in cycle ``t + 1``)."""
        return (t + 1) in self._reads

    @property
    def ready(self) -> bool:
        return self._ready is not None

    # ----------------------------------------------------------------------------------------------------
    def _refresh_clock(self, t: int) -> None:
        """Refreshes falling due up to edge ``t``: owed, late, postponed too often, too long without one."""
        if self._ready is None:
            return
        p, st = self.part, self.stats
        due = int(self._ns(t, self._ready) // p.t_refi)
        while self._due < due:
            self._due += 1
            owed = self._due - st.refreshes
            st.max_owed = max(st.max_owed, owed)
            if owed >= 2:
                st.late_refreshes += 1
            if owed > p.max_postponed and not self._owed_told:
                self._owed_told = True
                self._fail(t, "refresh", f"{owed} refreshes owed: more than {p.max_postponed} postponed")
        last = max(self._ref, self._ready)
        if self._ns(t, last) > 8 * p.t_refi and not self._gap_told:
            self._gap_told = True
            self._fail(t, "refresh", f"no AUTO REFRESH for {self._ns(t, last):.0f} ns (more than 8 x tREFI "
                       f"= {8 * p.t_refi:.0f} ns)")

    def _check_ras_max(self, t: int) -> None:
        for b, bank in enumerate(self.banks):
            if bank.row is not None and not bank.ras_max_told and self._ns(t, bank.act) > self.part.t_ras_max:
                bank.ras_max_told = True
                self._fail(t, "tRAS max", f"bank {b} row {bank.row} open for {self._ns(t, bank.act):.0f} ns, "
                           f"at most {self.part.t_ras_max} ns")

    def finish(self, t: int) -> None:
        """The end of the run at edge ``t``: the refresh and open-row limits up to then."""
        self._refresh_clock(t)
        self._check_ras_max(t)

    # ----------------------------------------------------------------------------------------------------
    def edge(self, t: int, p: Pins) -> tuple[int, int] | None:
        """Process rising edge ``t``; return (word, mask of the bytes driven) for bus cycle ``t``, or None."""
        st = self.stats
        if self._t0 is None:
            self._t0 = t
        elif t <= self._t:
            raise ValueError(f"edges must come in order: edge {t} after edge {self._t}")
        elif t - self._t > 1 and self._reads:
            raise ValueError(f"edge {t}: edges skipped while read data was in flight")
        self._t = t
        st.edges += 1
        if p.cke != 1:
            self._fail(t, "inputs defined", f"cke {'undefined' if p.cke is None else 'low'} (power-down and "
                       f"self refresh are not used)")
        cmd = None
        if p.cs_n is None:
            self._fail(t, "inputs defined", "cs_n undefined")
        elif p.cs_n == 0:
            key = (p.ras_n, p.cas_n, p.we_n)
            cmd = _DECODE.get(key)
            if cmd is None:
                self._fail(t, "inputs defined", f"ras_n, cas_n, we_n undefined ({key})")
            elif cmd == "NOP":
                cmd = None
        if cmd is not None:
            st.commands[cmd] = st.commands.get(cmd, 0) + 1
            if self.log:
                self.command_log.append((t, cmd, p.ba, p.a))
                del self.command_log[:-self.log]
            if cmd != "BST" and (p.a is None or p.ba is None):
                self._fail(t, "inputs defined", f"{cmd} with ba or a undefined")
            self._command(t, cmd, p.ba or 0, p.a or 0, p)
        else:
            self._refresh_clock(t)
        if self._ready is not None and (cmd is not None or t % 64 == 0):
            self._check_ras_max(t)

        # the data bus during cycle t-1: the FPGA's drive
        c = t - 1
        fpga = p.dq_oe
        if fpga is None:
            self._fail(t, "inputs defined", "dq_oe undefined")
            fpga = 0
        if fpga:
            if cmd != "WRITE":
                self._fail(t, "data bus", f"the FPGA drives DQ in cycle {c}, but no WRITE samples it at edge {t} "
                           f"(stray drive)")
            if c == self._part_drove:
                self._fail(t, "data bus", f"the FPGA drives DQ in cycle {c} while the part drives read data")
            elif c - self._part_drove < 2:
                self._fail(t, "data bus", f"the FPGA drives DQ in cycle {c}, right after the part drove it in "
                           f"cycle {self._part_drove} (turnaround: one idle cycle needed)")
            self._fpga_drove = c
        # read DQM (latency 2): the mask of the word driven in cycle t+1 is the dqm at this edge
        nxt = self._reads.get(t + 1)
        if nxt is not None:
            if p.dqm is None:
                self._fail(t, "inputs defined", "dqm undefined two edges before read data is sampled")
            nxt[1] = p.dqm if p.dqm is not None else 0
        out = None
        r = self._reads.pop(t, None)
        if r is not None:
            addr, dqm = r
            mask = 0
            for b in range(self._nbytes):
                if not (dqm >> b) & 1:
                    mask |= 0xFF << (8 * b)
            out = (self.word(addr) & mask, mask)
            if t - self._fpga_drove < 2:
                self._fail(t, "data bus", f"the part drives read data in cycle {t}, right after the FPGA drove DQ "
                           f"in cycle {self._fpga_drove} (turnaround: one idle cycle needed)")
            self._part_drove = t
            st.read_words += 1
        return out

    # ----------------------------------------------------------------------------------------------------
    def _command(self, t: int, cmd: str, ba: int, a: int, p: Pins) -> None:
        part = self.part
        if self._first_cmd is None:
            self._first_cmd = t
            self._after(t, self._t0, part.powerup_us * 1000.0, "power-up", f"first command ({cmd})")
        self._refresh_clock(t)
        if cmd != "BST" and t - self._mrs < part.t_mrd:
            self._fail(t, "tMRD", f"{cmd} {t - self._mrs} clocks after LOAD MODE REGISTER, {part.t_mrd} needed")
        if cmd in ("ACT", "READ", "WRITE") and self._ready is None:
            self._fail(t, "power-up", f"{cmd} before the power-up sequence completed (precharge all: "
                       f"{self._precharged_all}, refreshes: {self._init_refs} of {part.init_refreshes}, mode "
                       f"register: {self._mode is not None})")
        if ba >= part.banks:
            self._fail(t, "inputs defined", f"bank {ba} out of range")
            return
        bank = self.banks[ba]
        if cmd == "ACT":
            if bank.row is not None:
                self._fail(t, "bank state", f"ACTIVATE to bank {ba}, whose row {bank.row} is open")
            self._after(t, bank.pre, part.t_rp, "tRP", f"ACTIVATE bank {ba}: PRECHARGE")
            self._after(t, bank.act, part.t_rc, "tRC", f"ACTIVATE bank {ba}: its last ACTIVATE")
            self._after(t, self._last_act, part.t_rrd, "tRRD", f"ACTIVATE bank {ba}: the last ACTIVATE")
            self._after(t, self._ref, part.t_rfc, "tRFC", f"ACTIVATE bank {ba}: AUTO REFRESH")
            if a >= part.rows:
                self._fail(t, "inputs defined", f"row {a} out of range")
            bank.row, bank.act, bank.ras_max_told = a, t, False
            self._last_act = t
        elif cmd in ("READ", "WRITE"):
            if bank.row is None:
                self._fail(t, "bank state", f"{cmd} to bank {ba}, which has no open row")
            else:
                self._after(t, bank.act, part.t_rcd, "tRCD", f"{cmd} bank {ba}: ACTIVATE")
            if (a >> 10) & 1:
                self._fail(t, "bank state", f"{cmd} with auto precharge (a[10] high)")
            col = a & ((1 << part.col_bits) - 1)
            if a & ~((1 << part.col_bits) - 1) & ~(1 << 10):
                self._fail(t, "inputs defined", f"{cmd} column {a:#x} has bits above the column's")
            from_row = bank.row if bank.row is not None else 0
            addr = (((from_row << part.bank_bits) | ba) << part.col_bits) | col
            if cmd == "READ":
                if self.cl is None:
                    self._fail(t, "power-up", "READ before the mode register set the CAS latency")
                    return
                self._reads[t + self.cl - 1] = [addr, 0]  # its dqm: at edge t + CL - 2 (below, in edge())
                if self.record:
                    self.read_log.append((t, addr))
            else:
                self._write(t, ba, addr, p)
        elif cmd == "PRE":
            closing = range(part.banks) if (a >> 10) & 1 else [ba]
            if (a >> 10) & 1 and self._ready is None:
                self._precharged_all = True
            for b in closing:
                k = self.banks[b]
                if k.row is None:
                    continue  # precharging an idle bank is a NOP
                self._after(t, k.act, part.t_ras, "tRAS", f"PRECHARGE bank {b}: ACTIVATE")
                self._after(t, k.write, part.t_wr, "tWR", f"PRECHARGE bank {b}: the last write data")
                k.row, k.pre = None, t
        elif cmd in ("REF", "MRS"):
            name = "AUTO REFRESH" if cmd == "REF" else "LOAD MODE REGISTER"
            for b, k in enumerate(self.banks):
                if k.row is not None:
                    self._fail(t, "bank state", f"{name} while bank {b} has row {k.row} open")
                self._after(t, k.pre, part.t_rp, "tRP", f"{name}: PRECHARGE of bank {b}")
                self._after(t, k.act, part.t_rc, "tRC", f"{name}: ACTIVATE of bank {b}")
            self._after(t, self._ref, part.t_rfc, "tRFC", f"{name}: the last AUTO REFRESH")
            if cmd == "REF":
                if self._ready is None:
                    if not self._precharged_all:
                        self._fail(t, "power-up", "AUTO REFRESH before PRECHARGE ALL")
                    self._init_refs += 1
                else:
                    last = max(self._ref, self._ready)
                    self.stats.max_refresh_gap_ns = max(self.stats.max_refresh_gap_ns, self._ns(t, last))
                    self.stats.refreshes += 1
                self._ref = t
            else:
                self._mode_register(t, a)
            if (self._ready is None and self._precharged_all and self._mode is not None
                    and self._init_refs >= part.init_refreshes):
                self._ready = t
                self.stats.ready_edge = t

    def _mode_register(self, t: int, a: int) -> None:
        if not self._precharged_all:
            self._fail(t, "power-up", "LOAD MODE REGISTER before PRECHARGE ALL")
        bl, cl = a & 7, (a >> 4) & 7
        if bl != 0:
            self._fail(t, "mode register", f"burst length code {bl}: the model runs burst length 1 (code 0)")
        if cl not in (2, 3) or (self.cas_latency is not None and cl != self.cas_latency):
            self._fail(t, "mode register", f"CAS latency {cl}, expected {self.cas_latency or '2 or 3'}")
        if (a >> 7) & 3 or (a >> 3) & 1:
            self._fail(t, "mode register", f"word {a:#06x}: test mode or interleaved burst set")
        self._mode = (bl, cl)
        self.cl = cl if cl in (2, 3) else (self.cas_latency or 2)
        self._mrs = t

    def _write(self, t: int, ba: int, addr: int, p: Pins) -> None:
        if not p.dq_oe:
            self._fail(t, "data bus", f"WRITE to {addr:#x} at edge {t}, but the FPGA does not drive DQ")
            return
        dqm = p.dqm
        if dqm is None:
            self._fail(t, "inputs defined", "dqm undefined at a WRITE")
            dqm = 0
        if p.dq_o is None and dqm != (1 << self._nbytes) - 1:
            self._fail(t, "inputs defined", f"WRITE to {addr:#x}: the data bytes it enables are undefined")
            return
        old = self.word(addr)
        for b in range(self._nbytes):
            if not (dqm >> b) & 1:
                m = 0xFF << (8 * b)
                old = (old & ~m) | (p.dq_o & m)
        self.mem[addr] = old
        if self.record:
            self.write_log.append((t, addr, old))
        self.banks[ba].write = t
        self.stats.write_words += 1
