"""MyHDL side of :class:`eyestereo.tools.packed.PackedWord`: field slices and the packing of a word.

The model, the catalogue, the bench and the block all take a word's layout from its one
:class:`~eyestereo.tools.packed.PackedWord` declaration; these two blocks are how a block reads and writes it::

    unpack_word(sink.data, SOBEL, ix=ix, iy=iy)    # ix, iy: signals sized like the fields
    pack_word(word, SOBEL, ix=qx, iy=qy)           # word: Signal(intbv(0)[SOBEL.width:])

Both are combinational. :class:`FieldSignals` makes one signal per field, sized from the declaration, for
a block that packs or unpacks every field. Signed fields are signals with ``min < 0`` (MyHDL declares them
``signed``); their bits enter the word through an unsigned copy, because VHDL does not assign a ``signed``
slice to an ``unsigned`` vector, and leave it through a reinterpreting assignment.
"""

from myhdl import ConcatSignal, Signal, always_comb, block, intbv

from eyestereo.hdl.common.registers import assign
from eyestereo.tools.packed import PackedWord


def _check(packed: PackedWord, name: str, sig, role: str) -> None:
    f = packed.field(name)
    n = 1 if isinstance(sig.val, bool) else len(sig)
    if n != f.fmt.wl:
        raise ValueError(f"{role}: field {name!r} of {packed.name} is {f.fmt} ({f.fmt.wl} bits), "
                         f"its signal has {n}")
    signed = getattr(sig, "min", None) is not None and sig.min < 0
    if signed != f.fmt.signed:
        raise ValueError(f"{role}: field {name!r} of {packed.name} is {f.fmt}, its signal is "
                         f"{'signed' if signed else 'unsigned'}")


class FieldSignals:
    """One signal per field of a :class:`~eyestereo.tools.packed.PackedWord`, as attributes (``sigs.dx``).

    Each is sized from its field's format (signed fields signed); the 1-bit fields named in ``flags`` are
    ``bool`` signals, the others intbv. An interface for sub-blocks; ``pack_word(word, packed,
    **sigs.fields())`` / ``unpack_word(word, packed, **sigs.fields())`` move them all at once.
    """

    def __init__(self, packed: PackedWord, flags: tuple[str, ...] = ()):
        for f in packed.fields:
            if f.name in flags:
                if f.fmt.wl != 1:
                    raise ValueError(f"FieldSignals: flag {f.name!r} of {packed.name} is {f.fmt}, not 1 bit")
                sig = Signal(bool(0))
            elif f.fmt.signed:
                sig = Signal(intbv(0, min=-(1 << (f.fmt.wl - 1)), max=1 << (f.fmt.wl - 1)))
            else:
                sig = Signal(intbv(0)[f.fmt.wl:])
            setattr(self, f.name, sig)

    def fields(self) -> dict:
        """Field name -> signal, in declaration order."""
        return dict(vars(self))


@block
def field_bits(sig, bits):
    n = len(sig)

    @always_comb
    def comb():
        bits.next = sig[n:]

    return comb


@block
def unpack_word(word, packed: PackedWord, **fields):
    """Drive each given field signal from its bits of ``word`` (any subset of the fields)."""
    if len(word) != packed.width:
        raise ValueError(f"unpack_word: {packed.name} is {packed.width} bits, the word signal {len(word)}")
    insts = []
    for name, sig in fields.items():
        _check(packed, name, sig, "unpack_word")
        hi, lo = packed.bits(name)
        insts.append(field_bit(word, sig, lo) if isinstance(sig.val, bool) else field_slice(word, sig, hi, lo))
    return insts


# Plain processes rather than MyHDL shadow slices: a shadow slice of a block's port signal gets an
# undeclared name in the VHDL when it is taken inside a sub-block.
@block
def field_slice(word, out, hi: int, lo: int):
    """``out = word[hi:lo]`` (reinterpreted as signed when ``out`` is)."""

    @always_comb
    def comb():
        out.next = word[hi:lo]

    return comb


@block
def field_bit(word, out, bit: int):
    """``out = word[bit]`` for a 1-bit field."""

    @always_comb
    def comb():
        out.next = word[bit]

    return comb


@block
def pack_word(word, packed: PackedWord, **fields):
    """Drive ``word`` with the concatenation of every field signal (all fields must be given)."""
    if len(word) != packed.width:
        raise ValueError(f"pack_word: {packed.name} is {packed.width} bits, the word signal {len(word)}")
    missing = [n for n in packed.names if n not in fields]
    extra = sorted(set(fields) - set(packed.names))
    if missing or extra:
        raise ValueError(f"pack_word: {packed.name} misses fields {missing}, has no fields {extra}")
    insts = []
    parts = []
    for f in packed.fields:
        sig = fields[f.name]
        _check(packed, f.name, sig, "pack_word")
        if f.fmt.signed:
            bits = Signal(intbv(0)[f.fmt.wl:])
            insts.append(field_bits(sig, bits))
            sig = bits
        parts.append(sig)
    src = parts[0] if len(parts) == 1 else ConcatSignal(*reversed(parts))
    insts.append(assign(src, word))
    return insts
