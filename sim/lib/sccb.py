"""SCCB slave model (an OV7670's register port) that checks the bus timing, and its cocotb bus driver.

:class:`SccbSlave` is plain Python: it is fed every change of the two lines, ``event(t_ps, c, d)``, as a
sensor sees them (SIO_D is the wired-AND of the master's and the slave's drive), and

* records the register writes (3-phase write transmissions, ID 0x42) and answers reads (a 2-phase write
  giving the sub-address, then a 2-phase read with ID 0x43) from a register file seeded with the OV7670's
  PID 0x76 and VER 0x73; a soft reset (COM7 bit 7) resets the file;
* drives SIO_D itself: the "don't care" 9th bit of each write phase low (as a real OV7670 does: the master
  must not rely on it) and the 8 data bits of a read, :attr:`SccbRules.t_aa` after SIO_C falls; a slave
  made with ``answer=False`` is a missing camera: it only watches (the pull-up makes its reads 0xFF);
* checks the rules (:class:`SccbRules`: the OmniVision SCCB specification v2.2's protocol and the OV7670
  data sheet's Table 6 timing): SIO_C period, low and high time; start set-up and hold; stop set-up; bus
  free time between a stop and the next start; data set-up before SIO_C rises and hold after it falls;
  SIO_D stable while SIO_C is high except for a start or a stop; transmissions of whole 9-bit phases (2 or
  3 with ID 0x42, 2 with ID 0x43, no repeated start); the master's SIO_D released in the 9th bit of a
  write phase and during the slave's read bits, the read's NA bit 1; no access within 1 ms of a soft
  reset. A breach raises :class:`SccbError` with what, when and by how much (and is kept in
  :attr:`SccbSlave.errors`).

:class:`SccbBus` (cocotb) connects one slave per camera bus to a master's ``sio_c``, ``sio_d_oe`` (1 =
pull low) and ``sio_d_i`` (one bit per bus): it wakes on the master's two outputs and on its slaves'
own output delays, never on a clock, and records every change of the master's outputs.
"""

from __future__ import annotations

from dataclasses import dataclass

from eyestereo.tools.ov7670 import COM7, COM7_RESET, ID_READ, ID_WRITE, PID, PID_VALUE, RESET_WAIT_S, VER, VER_VALUE

__all__ = ["SccbRules", "RULES", "SccbError", "SccbSlave", "SccbBus"]

PS = 1e12


@dataclass(frozen=True)
class SccbRules:
    """Minimum times in seconds (OV7670 data sheet v1.4, Table 6 "SCCB timing"; the SCCB's 400 kHz)."""

    t_cyc: float = 2.5e-6  # SIO_C period (rising edge to rising edge): at most 400 kHz
    t_low: float = 1.3e-6  # SIO_C low
    t_high: float = 0.6e-6  # SIO_C high
    t_su_sta: float = 0.6e-6  # SIO_C high before SIO_D falls for a start
    t_hd_sta: float = 0.6e-6  # SIO_D low (start) before SIO_C falls
    t_su_dat: float = 100e-9  # SIO_D settled before SIO_C rises
    t_su_sto: float = 0.6e-6  # SIO_C high before SIO_D rises for a stop
    t_buf: float = 1.3e-6  # bus free between a stop and the next start
    t_aa: float = 300e-9  # the slave's own output delay after SIO_C falls (data sheet: 0.1..0.9 us)
    reset_wait: float = RESET_WAIT_S  # no access this soon after a soft reset (COM7 bit 7)

    def ps(self, name: str) -> int:
        return round(getattr(self, name) * PS)


RULES = SccbRules()


class SccbError(AssertionError):
    """A breach of the SCCB rules seen by a slave model."""


def _us(t_ps: int) -> str:
    return f"{t_ps / 1e6:.4g} us"


class SccbSlave:
    """One OV7670's SCCB port (see the module docstring). ``regs``: register values besides PID/VER."""

    def __init__(self, name: str = "camera", *, answer: bool = True, ack: bool = True, rules: SccbRules = RULES,
                 regs: dict[int, int] | None = None):
        self.name, self.answer, self.ack, self.rules = name, answer, ack, rules
        self._seed = {PID: PID_VALUE, VER: VER_VALUE, **(regs or {})}
        self.regs = dict(self._seed)
        self.writes: list[tuple[int, int]] = []  # (reg, value) in order
        self.reads: list[tuple[int, int]] = []  # (reg, value the master saw on the line)
        self.errors: list[str] = []
        self.drive_low = False  # what this slave does to SIO_D now
        self.c, self.d = 1, 1
        self.t_rise = self.t_fall = self.t_d = self.t_start = self.t_stop = self.t_reset = None
        self.t_prev_rise = None
        self.in_tx = False
        self.bits: list[int] = []
        self.first_fall = False
        self.addr = None  # sub-address of the last 2-phase write

    # -- the rules --------------------------------------------------------------------------------------------

    def _fail(self, t: int, msg: str):
        text = f"SCCB slave {self.name} at {_us(t)}: {msg}"
        self.errors.append(text)
        raise SccbError(text)

    def _at_least(self, t: int, since, rule: str, what: str):
        if since is None:
            return
        need = self.rules.ps(rule)
        if t - since < need:
            self._fail(t, f"{what} {_us(t - since)} < {rule} = {_us(need)}")

    def _where(self) -> str:
        n = len(self.bits)
        return f"phase {n // 9}, bit {n % 9 + 1} of 9"

    # -- what the slave does ------------------------------------------------------------------------------

    def _phase_kind(self, phase: int) -> str:
        """'w' a byte the master sends, 'r' the byte this slave sends (phase 1 after ID 0x43)."""
        if phase == 1 and len(self.bits) >= 8 and self._byte(0) == ID_READ:
            return "r"
        return "w"

    def _byte(self, phase: int) -> int:
        return int("".join(map(str, self.bits[9 * phase:9 * phase + 8])), 2)

    def _next_drive(self) -> bool:
        """After SIO_C fell: drive SIO_D low for the next bit?"""
        if not self.answer or not self.in_tx:
            return False
        n = len(self.bits)
        phase, pos = divmod(n, 9)
        if pos == 8:  # the 9th bit follows: a write phase's "don't care" (acknowledged like a real sensor)
            return self.ack and self._phase_kind(phase) == "w" and self._byte(0) in (ID_WRITE, ID_READ)
        if phase == 1 and self._byte(0) == ID_READ:  # the read data, MSB first
            value = self.regs.get(self.addr, 0) if self.addr is not None else 0
            return not (value >> (7 - pos)) & 1
        return False

    def _owner_of_next(self) -> str:
        n = len(self.bits)
        phase, pos = divmod(n, 9)
        if n >= 9 and self._byte(0) == ID_READ and phase == 1:
            return "s" if pos < 8 else "na"
        return "x" if pos == 8 else "m"

    # -- events -------------------------------------------------------------------------------------------------

    def event(self, t: int, c: int, d: int, master_low: bool | None = None) -> bool | None:
        """The lines are now ``c``, ``d`` (time ``t`` in ps); ``master_low``: whether the master drives SIO_D
        low (when known). Returns the SIO_D drive this slave wants after :attr:`SccbRules.t_aa`, or None."""
        c, d = int(c), int(d)
        if c == self.c and d == self.d:
            return None
        want = None
        if c != self.c and d != self.d:
            self._fail(t, f"SIO_C and SIO_D changed at the same instant ({self._where()}): no defined order")
        if c != self.c:
            self.c = c
            if c:
                self._rise(t, d, master_low)
            else:
                self._fall(t)
                want = self._next_drive()
        else:
            self.d = d
            if c and not d:
                self._start(t)
            elif c:
                self._stop(t)
            else:
                if self.t_fall is not None and t <= self.t_fall:
                    self._fail(t, f"SIO_D changed at the instant SIO_C fell ({self._where()}): no hold time")
            self.t_d = t
        return want

    def _rise(self, t: int, d: int, master_low):
        if self.in_tx:
            self._at_least(t, self.t_fall, "t_low", "SIO_C low for")
            if self.t_d is not None and self.t_fall is not None and self.t_d > self.t_fall:
                self._at_least(t, self.t_d, "t_su_dat", "SIO_D set-up before SIO_C rose")
            if self.t_prev_rise is not None:
                self._at_least(t, self.t_prev_rise, "t_cyc", "SIO_C period")
            owner = self._owner_of_next()
            if master_low and owner in ("s", "x", "na"):
                what = {"s": "the slave's read data", "x": "the 9th (don't care) bit of a write phase",
                        "na": "the NA bit of a read"}[owner]
                self._fail(t, f"the master drives SIO_D low during {what} ({self._where()})")
            if owner == "na" and not d:
                self._fail(t, f"the read's NA bit is 0 ({self._where()}): the master must leave it 1")
            self.bits.append(d)
            self.t_prev_rise = t
        self.t_rise = t

    def _fall(self, t: int):
        if self.in_tx:
            self._at_least(t, self.t_rise, "t_high", "SIO_C high for")
            if self.first_fall:
                self._at_least(t, self.t_start, "t_hd_sta", "start hold (SIO_D fell to SIO_C falling)")
                self.first_fall = False
        self.t_fall = t

    def _start(self, t: int):
        if self.in_tx:
            self._fail(t, f"SIO_D fell while SIO_C was high inside a transmission ({self._where()}): only a start "
                          f"may, and SCCB has no repeated start")
        self._at_least(t, self.t_rise, "t_su_sta", "start set-up (SIO_C high before SIO_D fell)")
        self._at_least(t, self.t_stop, "t_buf", "bus free time between a stop and this start")
        if self.t_reset is not None and t - self.t_reset < self.rules.ps("reset_wait"):
            self._fail(t, f"access {_us(t - self.t_reset)} after the soft reset (COM7 bit 7): the sensor needs "
                          f"{_us(self.rules.ps('reset_wait'))}")
        self.in_tx, self.bits, self.first_fall, self.t_start = True, [], True, t
        self.t_prev_rise = None

    def _stop(self, t: int):
        if not self.in_tx:
            self._fail(t, "SIO_D rose while SIO_C was high outside a transmission (a stop without a start)")
        n = max(len(self.bits) - 1, 0)  # the stop's own SIO_C rise clocked one more "bit"
        if n < 9 or n % 9:
            self._fail(t, f"SIO_D rose while SIO_C was high after {n} bits: only a stop may, after whole 9-bit "
                          f"phases")
        self._at_least(t, self.t_rise, "t_su_sto", "stop set-up (SIO_C high before SIO_D rose)")
        self.bits = self.bits[:n]
        phases = [self._byte(i) for i in range(n // 9)]
        self.in_tx, self.t_stop = False, t
        self._transmission(t, phases)

    def _transmission(self, t: int, phases: list[int]):
        ident = phases[0]
        if ident == ID_WRITE and len(phases) == 3:
            reg, value = phases[1], phases[2]
            self.writes.append((reg, value))
            if reg == COM7 and value & COM7_RESET:
                self.regs = dict(self._seed)
                self.t_reset = t
            elif reg not in (PID, VER):  # the IDs are read-only
                self.regs[reg] = value
        elif ident == ID_WRITE and len(phases) == 2:
            self.addr = phases[1]
        elif ident == ID_READ and len(phases) == 2:
            if self.addr is None:
                self._fail(t, "a 2-phase read without a 2-phase write of the sub-address before it")
            self.reads.append((self.addr, phases[1]))
            if self.answer and phases[1] != self.regs.get(self.addr, 0):
                self._fail(t, f"read of {self.addr:#04x} carried {phases[1]:#04x}, the slave sent "
                              f"{self.regs.get(self.addr, 0):#04x}")
        else:
            self._fail(t, f"a transmission of {len(phases)} phases with ID {ident:#04x}: SCCB writes are 3 phases "
                          f"(or 2) with ID 0x42, reads 2 phases with ID 0x43")

    def idle(self) -> bool:
        """No transmission open, SIO_D released by the slave."""
        return not self.in_tx and not self.drive_low


class SccbBus:
    """cocotb: slaves (one per bus, bit k of ``sio_d_i``) on a master's ``sio_c`` / ``sio_d_oe`` ports.

    ``changes``: every change of the master's outputs, ``(t_ps, sio_c, sio_d_oe)``."""

    def __init__(self, dut, slaves: list[SccbSlave], *, sio_c: str = "sio_c", sio_d_oe: str = "sio_d_oe",
                 sio_d_i: str = "sio_d_i"):
        self.c_sig, self.oe_sig, self.in_sig = getattr(dut, sio_c), getattr(dut, sio_d_oe), getattr(dut, sio_d_i)
        self.slaves = slaves
        self.changes: list[tuple[int, int, int]] = []
        self.c, self.oe = 1, 0
        self.pending = 0

    def lines(self) -> list[int]:
        return [0 if (self.oe or s.drive_low) else 1 for s in self.slaves]

    def _write_in(self):
        self.in_sig.value = sum(v << k for k, v in enumerate(self.lines()))

    async def run(self):
        from cocotb.triggers import First, ValueChange
        from cocotb.utils import get_sim_time

        import cocotb

        self._write_in()
        while True:
            await First(ValueChange(self.c_sig), ValueChange(self.oe_sig))
            t = get_sim_time(unit="ps")
            cv, ov = self.c_sig.value, self.oe_sig.value
            if not (cv.is_resolvable and ov.is_resolvable):
                # the Verilog's outputs are X until their time-0 assignment: only then may they be
                assert t == 0, f"sio_c = {cv}, sio_d_oe = {ov} at {_us(t)}"
                continue
            c, oe = int(cv), int(ov)
            if (c, oe) == (self.c, self.oe):
                continue
            self.c, self.oe = c, oe
            self.changes.append((t, c, oe))
            for s, line in zip(self.slaves, self.lines()):
                want = s.event(t, c, line, master_low=bool(oe))
                if want is not None and want != s.drive_low:
                    self.pending += 1
                    cocotb.start_soon(self._drive(s, want))
            self._write_in()

    async def _drive(self, slave: SccbSlave, want: bool):
        from cocotb.triggers import Timer
        from cocotb.utils import get_sim_time

        await Timer(slave.rules.ps("t_aa"), unit="ps")
        slave.drive_low = want
        line = 0 if (self.oe or want) else 1
        slave.event(get_sim_time(unit="ps"), self.c, line, master_low=bool(self.oe))
        self._write_in()
        self.pending -= 1
