"""The host driver of the stereo front end: registers and fields by name, frames, counters, SRAM reads.

Built at import time from the register table (:data:`eyestereo.tools.regmap.REGMAP`): every register
gets ``read_<name>()`` / ``write_<name>(value)`` coroutines (``read_ctrl``, ``write_k_left``, ...; arrays
and windows take an index), every field is reachable by name through :meth:`HostDriver.get` and
:meth:`HostDriver.set`. It runs on any bus object with three coroutines::

    async def read(address) -> (data, resp)          # one 32-bit bus read
    async def write(address, data, strb=0xF) -> resp  # one bus write
    async def wait(clocks)                            # let time pass (polling)

``eyestereo.sim.axil.AxiLiteBus`` is that object in the cocotb benches (cocotbext-axi's AxiLiteMaster
with the bus checker); :class:`ModelBus` runs the driver on the bank's model; a real host wraps its
memory-mapped window the same way. A response other than OKAY raises :class:`BusError`.

Plain Python (no MyHDL, no cocotb).
"""

from __future__ import annotations

from eyestereo.tools.regmap import ARB_WORDS, OKAY, REGMAP, RegisterMap

__all__ = ["HostDriver", "BusError", "ModelBus"]


class BusError(RuntimeError):
    """The bank answered SLVERR (an unmapped address or a write to a read-only register)."""


class ModelBus:
    """The bus interface on the transaction model :class:`eyestereo.tools.models.register_bank.RegisterBank`
    (any object with ``read(address)`` and ``write(address, data, strb)``): for tests and dry runs."""

    def __init__(self, bank):
        self.bank = bank
        self.clocks = 0

    async def read(self, address):
        return self.bank.read(address)

    async def write(self, address, data, strb=0xF):
        return self.bank.write(address, data, strb)

    async def wait(self, clocks):
        self.clocks += clocks


class HostDriver:
    """Registers of :data:`REGMAP` by name over a bus (see the module docstring)."""

    def __init__(self, bus, regmap: RegisterMap = REGMAP):
        self.bus = bus
        self.regmap = regmap

    # ---- words ---------------------------------------------------------------------------------------
    async def read(self, name: str, index: int = 0) -> int:
        """The word of register ``name`` (word ``index`` of an array, window or memory)."""
        r = self.regmap[name]
        data, resp = await self.bus.read(r.address(index))
        if resp != OKAY:
            raise BusError(f"read of {name}[{index}] at {r.address(index):#x}: response {resp}")
        return int(data)

    async def write(self, name: str, value: int, index: int = 0, strb: int = 0xF) -> None:
        r = self.regmap[name]
        resp = await self.bus.write(r.address(index), int(value) & 0xFFFFFFFF, strb)
        if resp != OKAY:
            raise BusError(f"write of {name}[{index}] at {r.address(index):#x}: response {resp}")

    # ---- fields --------------------------------------------------------------------------------------
    async def get(self, field: str, index: int = 0) -> int:
        """A field's value (``"mode"`` or ``"CTRL.mode"``)."""
        r, f = self.regmap.field(field)
        return (await self.read(r.name, index) >> f.lsb) & ((1 << f.width) - 1)

    async def set(self, **fields: int) -> None:
        """Set fields; fields of one ``rw`` register are written together (read-modify-write), a ``pulse``
        register's given fields are written as ones (zeros do nothing)."""
        by_reg: dict[str, list] = {}
        for name, value in fields.items():
            r, f = self.regmap.field(name)
            if r.kind not in ("rw", "pulse"):
                raise KeyError(f"field {name} is in {r.kind} register {r.name}: set() takes rw and pulse fields")
            if not 0 <= int(value) < (1 << f.width):
                raise ValueError(f"field {name} is {f.width} bits wide, {value!r} does not fit")
            by_reg.setdefault(r.name, []).append((f, int(value)))
        for reg, items in by_reg.items():
            r = self.regmap[reg]
            word = await self.read(reg) if r.kind == "rw" else 0
            for f, v in items:
                word = (word & ~f.mask) | (v << f.lsb)
            await self.write(reg, word)

    async def pulse(self, *fields: str) -> None:
        """Write 1 to command fields (``await drv.pulse("start")``)."""
        await self.set(**{f: 1 for f in fields})

    # ---- the system --------------------------------------------------------------------------------
    async def check_id(self) -> None:
        ident = await self.read("ID")
        want = self.regmap["ID"].reset_value()
        if ident != want:
            raise BusError(f"ID reads {ident:#010x}, this driver is for {want:#010x}")

    async def geometry(self) -> tuple[int, int]:
        word = await self.read("GEOMETRY")
        return word & 0xFFFF, word >> 16

    async def configure(self, *, mode: str = "sequential", continuous: bool = False, k_left: int | None = None,
                        k_right: int | None = None, thresholds_left=None, thresholds_right=None) -> None:
        """Mode, k codes and block thresholds (codes; ``None`` leaves a value as it is)."""
        modes = dict(self.regmap.field("mode")[1].values)
        code = {v: k for k, v in modes.items()}.get(mode)
        if code is None:
            raise ValueError(f"mode must be one of {sorted(modes.values())}, got {mode!r}")
        await self.set(mode=code, continuous=int(bool(continuous)))
        for name, k in (("k_left", k_left), ("k_right", k_right)):
            if k is not None:
                await self.set(**{name: int(k)})
        for reg, thr in (("THR_LEFT", thresholds_left), ("THR_RIGHT", thresholds_right)):
            if thr is not None:
                await self.write_thresholds(reg, thr)

    async def write_thresholds(self, reg: str, codes) -> None:
        r = self.regmap[reg]
        codes = [int(c) for c in codes]
        if len(codes) > r.count:
            raise ValueError(f"{reg} has {r.count} blocks, got {len(codes)} thresholds")
        for i, c in enumerate(codes):
            await self.write(reg, c & r.mask, i)

    async def read_thresholds(self, reg: str) -> list[int]:
        return [await self.read(reg, i) for i in range(self.regmap[reg].count)]

    async def start(self) -> None:
        await self.pulse("start")

    async def stop(self) -> None:
        await self.pulse("stop")

    async def wait_frame(self, *, after: int | None = None, timeout_clocks: int = 10_000_000,
                         poll_clocks: int = 1000) -> int:
        """Wait until FRAMES passes ``after`` (default: its value now); returns the new count."""
        start = await self.read("FRAMES") if after is None else int(after)
        waited = 0
        while True:
            n = await self.read("FRAMES")
            if (n - start) & 0xFFFFFFFF:
                return n
            if waited >= timeout_clocks:
                raise TimeoutError(f"no frame after {waited} clocks (FRAMES stays {n})")
            await self.bus.wait(poll_clocks)
            waited += poll_clocks

    async def status(self) -> dict[str, int]:
        """Every status field by name."""
        out = {}
        for r in self.regmap.of_kind("status"):
            word = await self.read(r.name)
            for f in r.fields:
                out[f.name] = (word >> f.lsb) & ((1 << f.width) - 1)
        return out

    async def arbiter(self) -> dict[str, int]:
        """The SRAM arbiter's status words by name (:data:`eyestereo.tools.regmap.ARB_WORDS`)."""
        return {w: await self.read("ARB", i) for i, w in enumerate(ARB_WORDS)}

    async def feature_counts(self) -> tuple[list[int], list[int]]:
        """Features per block (left, right) of the last completed frame."""
        n = self.regmap["FCOUNT"].count // 2
        words = [await self.read("FCOUNT", i) for i in range(2 * n)]
        return words[:n], words[n:]

    async def counters(self) -> dict[str, int]:
        """Status fields and the arbiter's words in one dict."""
        return {**await self.status(), **{f"arb_{k}": v for k, v in (await self.arbiter()).items()}}

    async def read_sram_words(self, word: int, count: int) -> list[int]:
        """``count`` SRAM words from word address ``word`` (through the host port)."""
        return [await self.read("SRAM", word + i) for i in range(count)]

    async def write_sram_words(self, word: int, values) -> None:
        for i, v in enumerate(values):
            await self.write("SRAM", int(v) & 0xFFFF, word + i)


def _accessors(regmap: RegisterMap) -> None:
    """``read_<register>`` / ``write_<register>`` methods on HostDriver, from the table."""
    for r in regmap:
        name = r.name

        async def reader(self, index: int = 0, _n=name) -> int:
            return await self.read(_n, index)

        async def writer(self, value: int, index: int = 0, _n=name) -> None:
            await self.write(_n, value, index)

        reader.__doc__ = f"Read {name} ({r.kind}, {r.offset:#x}): {r.doc}."
        writer.__doc__ = f"Write {name} ({r.kind}, {r.offset:#x}): {r.doc}."
        reader.__name__, writer.__name__ = f"read_{name.lower()}", f"write_{name.lower()}"
        for n in (reader.__name__, writer.__name__):
            if n in HostDriver.__dict__:
                raise RuntimeError(f"register {name}: generated method {n} would replace HostDriver.{n}")
        setattr(HostDriver, reader.__name__, reader)
        if r.kind in ("rw", "pulse", "array", "memory"):
            setattr(HostDriver, writer.__name__, writer)


_accessors(REGMAP)
