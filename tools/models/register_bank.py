"""Bit-true model of :func:`eyestereo.hdl.system.register_bank.register_bank`, transaction by transaction.

The model knows nothing but the register table (:data:`eyestereo.tools.regmap.REGMAP`) and the bus rules
of docs/registers.md: what every read returns (data and response), what every write changes, which
output ports it moves and which pulses and write-port writes it causes. The bench drives the VHDL and
this model with the same accesses and compares the two; the host driver's tests run on it directly.

State: ``rw`` (stored word per rw register), ``arrays`` (stored words per array, 0 after reset),
``inputs`` (what the status input ports are driven with: field -> value; set by the user), ``windows``
(port -> function(index) -> word: what the external read port answers), ``sram`` (word address ->
16-bit word). ``events`` lists, in order, what writes caused on the ports: ``("pulse", field)`` for a
one-clock pulse and ``("write", port, index, data)`` for a write-port write.

User values are checked, not masked: ``width``/``height`` as the VHDL block checks them
(:func:`eyestereo.tools.regmap.check_frame_size`), :meth:`RegisterBank.set_input` against the field
(:meth:`eyestereo.tools.regmap.Field.check`). The bus side stays the hardware's: a bus write carries 32
bits, and the bank keeps the bits its strobes and fields select.
"""

from __future__ import annotations

from collections.abc import Callable

from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH
from eyestereo.tools.regmap import OKAY, REGMAP, SLVERR, WRITABLE, RegisterMap, check_frame_size

__all__ = ["RegisterBank", "strobe_mask"]


def strobe_mask(strb: int) -> int:
    """The 32-bit mask of the bytes ``strb`` selects (bit i: bits 8i+7..8i)."""
    if not 0 <= strb <= 0xF:
        raise ValueError(f"wstrb must be 4 bits, got {strb!r}")
    return sum(0xFF << (8 * i) for i in range(4) if strb >> i & 1)


class RegisterBank:
    """The register bank's behaviour (see the module docstring); ``width``/``height`` are its parameters.

    ``width``/``height`` must be integers in 2..4096 (:func:`eyestereo.tools.regmap.check_frame_size`, the
    rule the VHDL block elaborates with): the model refuses what the block refuses, with the same
    ValueError (without the block's name in front), so a bench cannot check the VHDL against a model of
    a bank that cannot be built.
    """

    def __init__(self, regmap: RegisterMap = REGMAP, *, width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT):
        self.regmap = regmap
        width, height = check_frame_size(width, height)
        self.params = dict(width=width, height=height)
        self.inputs: dict[str, int] = {f.name: 0 for r in regmap.of_kind("status") for f in r.fields}
        self.windows: dict[str, Callable[[int], int]] = {r.port: (lambda i: 0) for r in regmap.of_kind("window")}
        self.sram: dict[int, int] = {}
        self.reset()

    def reset(self) -> None:
        """The bank's ``rst``: registers to their reset values, arrays to 0 (the SRAM keeps its words)."""
        self.rw = {r.name: r.reset_value(self.params) for r in self.regmap.of_kind("rw")}
        self.arrays = {r.name: [0] * r.count for r in self.regmap.of_kind("array")}
        self.events: list[tuple] = []

    # ---- ports -------------------------------------------------------------------------------------
    def outputs(self) -> dict[str, int]:
        """Field -> value of every rw field's output port now."""
        out = {}
        for r in self.regmap.of_kind("rw"):
            for f in r.fields:
                out[f.name] = (self.rw[r.name] >> f.lsb) & ((1 << f.width) - 1)
        return out

    def set_input(self, name: str, value: int) -> None:
        """Drive the status input port of field ``name`` with ``value``: an integer that fits the field's
        port (0..2**width-1; :meth:`~eyestereo.tools.regmap.Field.check`), else ValueError, e.g.
        ``FEATURES.features_right: 131071 does not fit (0..65535, 16 bits)`` (a port has no bits for more)."""
        r, f = self.regmap.field(name)
        if r.kind != "status":
            raise KeyError(f"field {name} is not a status input")
        self.inputs[f.name] = f.check(value, f"{r.name}.{f.name}")

    # ---- bus ---------------------------------------------------------------------------------------
    def write(self, address: int, data: int, strb: int = 0xF) -> int:
        """A bus write; returns the response (OKAY or SLVERR)."""
        hit = self.regmap.decode(address)
        if hit is None or hit[0].kind not in WRITABLE:
            return SLVERR
        r, i = hit
        m = strobe_mask(strb)
        data = int(data) & 0xFFFFFFFF
        if r.kind == "rw":
            keep = r.mask & m
            self.rw[r.name] = (self.rw[r.name] & ~keep) | (data & keep)
        elif r.kind == "pulse":
            for f in r.fields:
                if (data & m) >> f.lsb & ((1 << f.width) - 1):
                    self.events.append(("pulse", f.name))
        elif r.kind == "array":
            keep = r.mask & m
            new = (self.arrays[r.name][i] & ~keep) | (data & keep)
            self.arrays[r.name][i] = new
            self.events.append(("write", r.port, i, new))
        elif r.kind == "memory" and strb & 3:
            be = strb & 3
            old = self.sram.get(i, 0)
            keep = strobe_mask(be)
            self.sram[i] = (old & ~keep) | (data & keep & 0xFFFF)
        return OKAY

    def read(self, address: int) -> tuple[int, int]:
        """A bus read; returns (data, response)."""
        hit = self.regmap.decode(address)
        if hit is None:
            return 0, SLVERR
        r, i = hit
        if r.kind == "const":
            return r.reset_value(self.params), OKAY
        if r.kind == "rw":
            return self.rw[r.name], OKAY
        if r.kind == "pulse":
            return 0, OKAY
        if r.kind == "status":
            v = 0
            for f in r.fields:
                v |= (self.inputs[f.name] & ((1 << f.width) - 1)) << f.lsb
            return v, OKAY
        if r.kind == "array":
            return self.arrays[r.name][i], OKAY
        if r.kind == "window":
            return int(self.windows[r.port](i)) & r.mask, OKAY
        return self.sram.get(i, 0), OKAY  # memory
