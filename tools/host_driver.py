"""The host driver of the stereo front end: registers and fields by name, frames, counters, SRAM reads.

Built at import time from the register table (:data:`eyestereo.tools.regmap.REGMAP`): every register
gets ``read_<name>()`` / ``write_<name>(value)`` coroutines (``read_ctrl``, ``write_k_left``, ...; arrays
and windows take an index), every field is reachable by name through :meth:`HostDriver.get` and
:meth:`HostDriver.set`. It runs on any bus object with three coroutines::

    async def read(address) -> (data, resp)          # one 32-bit bus read
    async def write(address, data, strb=0xF) -> resp  # one bus write
    async def wait(clocks)                            # let time pass (polling)

``eyestereo.sim.lib.axil.AxiLiteBus`` is that object in the cocotb benches (cocotbext-axi's AxiLiteMaster
with the bus checker); :class:`ModelBus` runs the driver on the bank's model; a real host wraps its
memory-mapped window the same way. A response other than OKAY raises :class:`BusError`.

Every value given to the driver (a word, a field, a threshold, an SRAM word, an index or an SRAM range)
is checked against the table before anything moves on the bus (:meth:`eyestereo.tools.regmap.Field.check`,
:meth:`~eyestereo.tools.regmap.Register.check_value`): a value that does not fit raises one-line
ValueError naming the register, the value and the range, instead of being masked into another value
(a threshold of 2**20 into 0, -1 into 0xFFFFF, 1.9 into 1). Words read back are masked to their fields.

Plain Python (no MyHDL, no cocotb).
"""

from __future__ import annotations

from eyestereo.tools.constants import MATCH_MARKER
from eyestereo.tools.regmap import ARB_WORDS, OKAY, REGMAP, RegisterMap, check_bits

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
        """The word of register ``name`` (word ``index`` of an array, window or memory; an index outside
        0..count-1 is refused: :meth:`~eyestereo.tools.regmap.Register.check_index`)."""
        r = self.regmap[name]
        index = r.check_index(index)
        data, resp = await self.bus.read(r.address(index))
        if resp != OKAY:
            raise BusError(f"read of {name}[{index}] at {r.address(index):#x}: response {resp}")
        return int(data)

    async def write(self, name: str, value: int, index: int = 0, strb: int = 0xF) -> None:
        """Write the word ``value`` to register ``name`` (word ``index``; byte strobes ``strb``).

        Refused (ValueError, nothing written): an index outside the register's words, a value that is not
        an integer or sets bits outside the register's fields (THR_LEFT: 0..2**20-1, SRAM: 0..65535;
        :meth:`~eyestereo.tools.regmap.Register.check_value`), a ``strb`` outside 0..15.
        """
        r = self.regmap[name]
        word = r.check_value(value, index)
        strb = check_bits(strb, 0xF, f"{r.label(int(index))} wstrb")
        resp = await self.bus.write(r.address(index), word, strb)
        if resp != OKAY:
            raise BusError(f"write of {name}[{index}] at {r.address(index):#x}: response {resp}")

    # ---- fields --------------------------------------------------------------------------------------
    async def get(self, field: str, index: int = 0) -> int:
        """A field's value (``"mode"`` or ``"CTRL.mode"``)."""
        r, f = self.regmap.field(field)
        return (await self.read(r.name, index) >> f.lsb) & ((1 << f.width) - 1)

    async def set(self, **fields: int) -> None:
        """Set fields; fields of one ``rw`` register are written together (read-modify-write), a ``pulse``
        register's given fields are written as ones (zeros do nothing).

        Every value is checked before anything is written (:meth:`~eyestereo.tools.regmap.Field.check`):
        an integer 0..2**width-1, a bool only for a 1-bit field; otherwise ValueError, e.g.
        ``K_LEFT.k_left: 256 does not fit (0..255, 8 bits)``.
        """
        by_reg: dict[str, list] = {}
        for name, value in fields.items():
            r, f = self.regmap.field(name)
            if r.kind not in ("rw", "pulse"):
                raise KeyError(f"field {name} is in {r.kind} register {r.name}: set() takes rw and pulse fields")
            by_reg.setdefault(r.name, []).append((f, f.check(value, f"{r.name}.{f.name}")))
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
        """Mode, k codes and block thresholds (codes; ``None`` leaves a value as it is).

        Every value is checked before anything is written: ``mode`` one of the field's names,
        ``continuous`` a bool (or 0/1), the k codes 0..255, the thresholds as :meth:`write_thresholds`
        takes them; a value that does not fit raises ValueError (never masked or truncated: k 1.9 is refused,
        not written as 1).
        """
        modes = dict(self.regmap.field("mode")[1].values)
        code = {v: k for k, v in modes.items()}.get(mode)
        if code is None:
            raise ValueError(f"mode must be one of {sorted(modes.values())}, got {mode!r}")
        ctrl = dict(mode=code, continuous=continuous)
        ks = {name: k for name, k in (("k_left", k_left), ("k_right", k_right)) if k is not None}
        thrs = [(reg, self._threshold_codes(reg, thr)) for reg, thr in
                (("THR_LEFT", thresholds_left), ("THR_RIGHT", thresholds_right)) if thr is not None]
        for name, value in {**ctrl, **ks}.items():
            r, f = self.regmap.field(name)
            f.check(value, f"{r.name}.{f.name}")
        await self.set(**ctrl)
        for name, k in ks.items():
            await self.set(**{name: k})
        for reg, codes in thrs:
            for i, c in enumerate(codes):
                await self.write(reg, c, i)

    def _threshold_codes(self, reg: str, codes) -> list[int]:
        """The threshold codes as Python ints, every one checked (:meth:`write_thresholds`)."""
        r = self.regmap[reg]
        if r.kind != "array":
            raise ValueError(f"{reg} is a {r.kind} register, thresholds go to an array (THR_LEFT, THR_RIGHT)")
        codes = list(codes)
        if len(codes) > r.count:
            raise ValueError(f"{reg} has {r.count} blocks, got {len(codes)} thresholds")
        return [r.check_value(c, i) for i, c in enumerate(codes)]

    async def write_thresholds(self, reg: str, codes) -> None:
        """Block thresholds (codes, block 0 first) into the array ``reg`` (THR_LEFT or THR_RIGHT).

        All codes are checked before the first is written: at most ``count`` of them, each an integer
        0..2**20-1 (numpy integers too); a code that does not fit (2**20, -1, 1.9, 2.0, True) raises
        ValueError, e.g. ``THR_LEFT[3]: 1048576 does not fit (0..1048575, 20 bits)``, instead of being
        masked into another threshold (2**20 would become 0: every pixel passes).
        """
        for i, c in enumerate(self._threshold_codes(reg, codes)):
            await self.write(reg, c, i)

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
        """``count`` SRAM words from word address ``word`` (through the host port); a range that leaves
        the SRAM window is refused before the first read
        (:meth:`~eyestereo.tools.regmap.Register.check_words`). A bus with ``read_burst`` (the board's serial
        link, :class:`eyestereo.tools.board.serial_bus.SerialBus`) reads them in bursts; BusError on a response
        that is not OKAY."""
        r = self.regmap["SRAM"]
        words = r.check_words(word, count)
        if not hasattr(self.bus, "read_burst") or count == 0:
            return [await self.read("SRAM", i) for i in words]
        # a bus with bursts (the board's serial link): one request per 256 words instead of one per word
        out = []
        for k, (data, resp) in enumerate(await self.bus.read_burst(r.address(words[0]), count)):
            if resp != OKAY:
                raise BusError(f"{r.label(words[k])}: read response {resp} (not OKAY)")
            out.append(int(data))
        return out

    async def take_disparity(self, amap, *, timeout_clocks: int = 10_000_000, poll_clocks: int = 50) -> list[int]:
        """The dense option's newest disparity map: take it (CTRL.disp_want until STATUS.disp_held), read its
        ``amap.width x amap.height`` codes from the buffer held (``amap``: the front end's
        :class:`~eyestereo.tools.models.sram_arbiter.AddressMap` with ``dense=True``), give it back
        (CMD.disp_release); the codes row by row (1/16 px, 0xFFFF where none). TimeoutError when no map comes
        within ``timeout_clocks`` (the option off, or the system stopped)."""
        await self.set(disp_want=1)
        waited = 0
        while not (st := await self.status())["disp_held"]:
            if waited >= timeout_clocks:
                await self.set(disp_want=0)
                raise TimeoutError(f"no disparity map within {timeout_clocks} clocks (is the dense option built? "
                                   f"DENSE_STATUS.disp_frames = {st['disp_frames']})")
            await self.bus.wait(poll_clocks)
            waited += poll_clocks
        await self.set(disp_want=0)
        codes = await self.read_sram_words(amap.disparity(st["disp_buf"]), amap.width * amap.height)
        await self.pulse("disp_release")
        return codes

    async def read_match_list(self, base: int, *, limit: int = 3 * 32768) -> list[int]:
        """The words of a match list from SRAM word ``base`` (the front end's matcher option: the held feature
        buffer's :meth:`~eyestereo.tools.models.sram_arbiter.AddressMap.features` +
        :func:`~eyestereo.tools.models.sram_arbiter.match_offset`), its trailer included: three words per match,
        up to the trailer's marker (0x8000 at a match's first word), then the trailer's count and candidates.
        BusError when no trailer comes within ``limit`` words."""
        words: list[int] = []
        while len(words) < limit:
            trip = await self.read_sram_words(base + len(words), 3)
            words += trip
            if trip[0] == MATCH_MARKER:
                return words
        raise BusError(f"no match list trailer within {limit} words from SRAM word {base}")

    async def write_sram_words(self, word: int, values) -> None:
        """SRAM words ``values`` from word address ``word`` on. The range must lie in the SRAM window and
        every value be an integer 0..65535 (16-bit words); both are checked before the first write, a
        value that does not fit raises ValueError (``SRAM word 0x5: 65536 does not fit (0..65535, 16 bits)``)
        instead of being masked into another word."""
        r = self.regmap["SRAM"]
        values = list(values)
        words = [(i, r.check_value(v, i)) for i, v in zip(r.check_words(word, len(values)), values)]
        if not hasattr(self.bus, "write_burst") or not words:
            for i, v in words:
                await self.write("SRAM", v, i)
            return
        for k, resp in enumerate(await self.bus.write_burst(r.address(words[0][0]), [v for _, v in words])):
            if resp != OKAY:
                raise BusError(f"{r.label(words[k][0])}: write response {resp} (not OKAY)")


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
