"""Port bundles declared once: each bundle class lists its members, their widths and their directions in
one table, in the spirit of Amaranth's signatures; everything else derives from that table.

A member is ``Member(name, width, flow)``:

``width``
    ``bool`` for a ``Signal(bool)``; an int for a fixed number of bits; or the name of an attribute of
    the bundle that gives the bits (``"data_width"``): a parameter of the bundle.
``flow``
    :data:`OUT` when the producer drives it (the source of a stream, the master of a request port, the
    FPGA of a pin bus), :data:`IN` when the consumer (slave) drives it (a queue's ``ready``, a fetch
    port's ``req_ready`` and responses).

What derives from the table: the signals (:meth:`Bundle.make`, with the member's initial value), the
field list in port order (:meth:`Bundle.fields`, so the VHDL/Verilog ports are ``<arg>_<field>`` in that
order), which members a block drives (:meth:`Bundle.driven`, used by
:func:`eyestereo.hdl.common.checks.check_distinct`), the elaboration checks of every member
(:func:`eyestereo.hdl.common.checks.check_port`) and the port tables of ``docs/interfaces.md``
(:mod:`eyestereo.hdl.flow.ports`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numbers

from myhdl import Signal, intbv

from eyestereo.tools.packed import PackedWord

__all__ = ["IN", "OUT", "Member", "Bundle", "word_width"]

#: driven by the producer (master)
OUT = "out"
#: driven by the consumer (slave)
IN = "in"


@dataclass(frozen=True)
class Member:
    """One signal of a bundle (see the module docstring).

    ``init``: the initial value (-1: all ones); ``ranged``: an ``intbv(0, min=0, max=<width attribute>)``
    instead of a bit count (a coordinate that never reaches the frame size); ``when``: the name of a
    bundle attribute that must be true for the member to exist (``cam`` of stereo streams only).
    """

    name: str
    width: object
    flow: str
    init: int = 0
    ranged: bool = False
    when: str | None = None

    def __post_init__(self):
        if self.flow not in (IN, OUT):
            raise ValueError(f"member {self.name}: flow must be {IN!r} or {OUT!r}, got {self.flow!r}")

    def bits(self, bundle) -> int:
        """Bits of this member in ``bundle`` (a ranged member: those of its range)."""
        if self.width is bool:
            return 1
        n = self.width if isinstance(self.width, int) else int(getattr(bundle, self.width))
        return (n - 1).bit_length() if self.ranged else n

    def signal(self, bundle) -> Signal:
        """A fresh signal of this member for ``bundle``."""
        if self.width is bool:
            return Signal(bool(self.init))
        if self.ranged:
            return Signal(intbv(self.init, min=0, max=int(getattr(bundle, self.width))))
        n = self.bits(bundle)
        return Signal(intbv(self.init & ((1 << n) - 1) if self.init < 0 else self.init)[n:])

    def width_text(self) -> str:
        """The width as the docs show it: ``1``, ``32``, ``data_width``, ``0..width-1``."""
        if self.width is bool:
            return "1"
        if self.ranged:
            return f"0..{self.width}-1"
        return str(self.width)


class Bundle:
    """Base of the port bundles: a subclass declares ``MEMBERS`` (a tuple of :class:`Member`), sets its
    parameters in ``__init__`` and then calls :meth:`make`."""

    MEMBERS: tuple[Member, ...] = ()
    #: the parameters that size the bundle, shown by ``repr``
    PARAMS: tuple[str, ...] = ()

    def members(self) -> tuple[Member, ...]:
        """The members this bundle has (``when`` applied), in port order."""
        return tuple(m for m in self.MEMBERS if m.when is None or getattr(self, m.when))

    def make(self) -> None:
        """Create the member signals (called by ``__init__`` once the parameters are set)."""
        for m in self.members():
            setattr(self, m.name, m.signal(self))

    def fields(self) -> list[str]:
        """Names of the signal fields, in port order."""
        return [m.name for m in self.members()]

    def driven(self, producer: bool) -> list[str]:
        """The fields a block drives when it is this bundle's producer (master), else its consumer."""
        flow = OUT if producer else IN
        return [m.name for m in self.members() if m.flow == flow]

    def __repr__(self) -> str:
        return f"{type(self).__name__}({', '.join(f'{k}={getattr(self, k)!r}' for k in self.PARAMS)})"

    @classmethod
    def member_list(cls) -> str:
        """The declared members for messages: ``data, valid, eol, eof, cam (if stereo)``."""
        return ", ".join(m.name + (f" (if {m.when})" if m.when else "") for m in cls.MEMBERS)


def word_width(owner: str, data_width) -> tuple[int, PackedWord | None]:
    """(bits, word) of a data member given as an int >= 1 or a :class:`~eyestereo.tools.packed.PackedWord`;
    a ValueError that names ``owner`` (the bundle class) otherwise."""
    word = data_width if isinstance(data_width, PackedWord) else None
    if word is not None:
        data_width = word.width
    if isinstance(data_width, bool) or not isinstance(data_width, numbers.Integral) or data_width < 1:
        raise ValueError(f"{owner} data_width must be an int >= 1 or a PackedWord, got {data_width!r}")
    return int(data_width), word
