"""Packed stream words: a word made of named fixed-point fields, declared once.

Blocks that pass several values per pixel (Sobel's Ix and Iy, the window sums, a coordinate with its
flags) pack them into one unsigned stream word. A :class:`PackedWord` declares the fields of such a word,
from the least significant bit up, each with its :class:`~eyestereo.tools.fixed.Fmt`. Everything else is
derived from that one declaration:

* the word's width (the catalogue's and the block's stream width),
* :meth:`PackedWord.pack` / :meth:`PackedWord.unpack` for the numpy models and the benches,
* each field's bit positions (:meth:`PackedWord.bits`) for the MyHDL side
  (:mod:`eyestereo.hdl.common.packed` builds the slices and the concatenation from it).

Field codes are the integer codes of their formats: signed fields are two's complement inside the word,
and :meth:`~PackedWord.unpack` sign-extends them again.

Example (the Sobel word)::

    SOBEL = PackedWord("sobel", [("ix", sfix(9, -3)), ("iy", sfix(9, -3))])
    SOBEL.width            # 18
    SOBEL.bits("iy")       # (18, 9): bits 17..9, as MyHDL's word[18:9]
    w = SOBEL.pack(ix=ix, iy=iy)
    SOBEL.unpack(w)["ix"]  # == ix
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TypeVar

import numpy as np

from eyestereo.tools.fixed import Fmt

__all__ = ["Field", "PackedWord", "lookup"]

#: Widest word :meth:`PackedWord.pack` handles with int64 arrays (non-negative codes below 2**63).
MAX_WORD_BITS = 63

T = TypeVar("T")


def lookup(table: Mapping[str, T], name: str, what: str, error: type[Exception] = ValueError) -> T:
    """``table[name]``; a name not in the table raises ``error`` with the message "<what> <name>; it has
    [<the table's names>]" (``what`` says whose table and of what, e.g. "packed word 'sobel' has no field"),
    so a misspelt name comes back with the names to choose from."""
    try:
        return table[name]
    except KeyError:
        raise error(f"{what} {name!r}; it has {list(table)}") from None


@dataclass(frozen=True)
class Field:
    """One field of a packed word: its name, format and least significant bit in the word."""

    name: str
    fmt: Fmt
    lsb: int

    @property
    def msb(self) -> int:
        return self.lsb + self.fmt.wl - 1

    @property
    def mask(self) -> int:
        return (1 << self.fmt.wl) - 1


class PackedWord:
    """An unsigned word of named fixed-point fields, least significant field first.

    Parameters:
        name: what the word is (used in error messages).
        fields: ``[(name, Fmt or bit count), ...]`` from the least significant bit up; an int ``n``
            means an unsigned ``n``-bit field (``ufix[n,0]``).
    """

    def __init__(self, name: str, fields: Sequence[tuple[str, Fmt | int]]):
        if not fields:
            raise ValueError(f"packed word {name!r} needs at least one field")
        out: list[Field] = []
        lsb = 0
        for fname, fmt in fields:
            if not isinstance(fname, str) or not fname.isidentifier():
                raise ValueError(f"packed word {name!r}: field name {fname!r} is not an identifier")
            if any(f.name == fname for f in out):
                raise ValueError(f"packed word {name!r}: field {fname!r} declared twice")
            if isinstance(fmt, (int, np.integer)) and not isinstance(fmt, bool):
                fmt = Fmt(False, int(fmt), 0)
            if not isinstance(fmt, Fmt):
                raise ValueError(f"packed word {name!r}: field {fname!r} needs a Fmt or a bit count, got {fmt!r}")
            out.append(Field(fname, fmt, lsb))
            lsb += fmt.wl
        self.name = name
        self.fields: tuple[Field, ...] = tuple(out)
        self.width = lsb
        self._by_name = {f.name: f for f in out}

    def __repr__(self) -> str:
        inner = ", ".join(f"{f.name}:{f.fmt}@{f.lsb}" for f in self.fields)
        return f"PackedWord({self.name!r}, {self.width} bits: {inner})"

    def __contains__(self, name: str) -> bool:
        return name in self._by_name

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(f.name for f in self.fields)

    def field(self, name: str) -> Field:
        return lookup(self._by_name, name, f"packed word {self.name!r} has no field")

    def bits(self, name: str) -> tuple[int, int]:
        """(msb + 1, lsb) of a field: the bounds of MyHDL's slice ``word[msb+1:lsb]``."""
        f = self.field(name)
        return f.msb + 1, f.lsb

    def pack(self, values: Mapping[str, object] | None = None, **codes) -> np.ndarray:
        """Words from field codes (arrays of one shape, or scalars); every field must be given.

        Codes outside their field's format raise ValueError (nothing is cut silently).
        """
        if self.width > MAX_WORD_BITS:
            raise ValueError(f"packed word {self.name!r} has {self.width} bits; numpy packing handles "
                             f"at most {MAX_WORD_BITS}")
        codes = {**(values or {}), **codes}
        missing = [n for n in self.names if n not in codes]
        extra = sorted(set(codes) - set(self.names))
        if missing or extra:
            raise ValueError(f"packed word {self.name!r}: missing fields {missing}, unknown fields {extra}")
        arrays = {n: np.asarray(codes[n]) for n in self.names}
        shape = np.broadcast_shapes(*(a.shape for a in arrays.values()))
        word = np.zeros(shape, dtype=np.int64)
        for f in self.fields:
            a = arrays[f.name]
            if a.dtype == bool:
                a = a.astype(np.int64)
            if not np.issubdtype(a.dtype, np.integer):
                raise ValueError(f"packed word {self.name!r}: field {f.name!r} needs integer codes, got {a.dtype}")
            a = a.astype(np.int64)
            if a.size and (a.min() < f.fmt.lo or a.max() > f.fmt.hi):
                raise ValueError(f"packed word {self.name!r}: field {f.name!r} codes span [{a.min()}, {a.max()}],"
                                 f" outside {f.fmt} [{f.fmt.lo}, {f.fmt.hi}]")
            word |= (a & f.mask) << f.lsb
        return word

    def unpack(self, words) -> dict[str, np.ndarray]:
        """Field codes (int64 arrays, signed fields sign-extended) from words."""
        w = np.asarray(words)
        if not np.issubdtype(w.dtype, np.integer):
            raise ValueError(f"packed word {self.name!r}: words must be integers, got {w.dtype}")
        w = w.astype(np.int64)
        if w.size and (w.min() < 0 or (self.width < 63 and w.max() >> self.width)):
            raise ValueError(f"packed word {self.name!r}: words must be {self.width}-bit unsigned codes")
        out = {}
        for f in self.fields:
            v = (w >> f.lsb) & f.mask
            if f.fmt.signed:
                v = np.where(v >> (f.fmt.wl - 1), v - (1 << f.fmt.wl), v)
            out[f.name] = v.astype(np.int64)
        return out

    def describe(self) -> str:
        """One line per field, most significant first: ``bits 17..9  iy  sfix[9,-3]``."""
        return "\n".join(f"bits {f.msb}..{f.lsb}  {f.name}  {f.fmt}" for f in reversed(self.fields))
