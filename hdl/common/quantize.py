"""Fixed-point operations with the toolbox's quantizer semantics: exact result, floor, two's complement wrap.

Each block computes ``out = quantize(op(a, b, ...), fo)`` combinationally, where the operands are codes of
:class:`~eyestereo.tools.fixed.Fmt` formats (a signal is signed exactly when its format is, and has its
format's word length) and ``quantize`` is :func:`eyestereo.tools.fixed.quantize` with floor rounding and
wrap -- what :func:`eyestereo.tools.rectify.ffc.fixed_stages` computes for every quantizer q11..q24:

* :func:`fx_resize`: ``out = quantize(a, fo)`` (a change of format);
* :func:`fx_mul`: ``out = quantize(a * b, fo)`` (one multiplier, operands at their own widths);
* :func:`fx_add`: ``out = quantize(a + b [+ c ...], fo)``.

How (VHDL and Verilog alike, no mixed signed/unsigned expression anywhere): the exact result is formed
first -- unsigned operands get a signed copy one bit wider when anything is signed, the product has the
sum of the operand widths, the terms of a sum are shifted onto the finest fraction length inside signals
as wide as the exact sum's range (a shift keeps its operand's width in VHDL, so never shift inside an
expression) -- and the quantizer is then a slice: floor drops the low bits, wrap the high bits. Bits
above the exact value's width are its sign (or zero) extension, taken from a wider copy when needed.
"""

from __future__ import annotations

from myhdl import Signal, always_comb, block, intbv

from eyestereo.hdl.common.registers import assign
from eyestereo.tools.fixed import Fmt

__all__ = ["fmt_signal", "fx_add", "fx_mul", "fx_resize", "cut_exact"]


def fmt_signal(fmt: Fmt):
    """A Signal holding codes of ``fmt`` (signed iff the format is, ``fmt.wl`` bits)."""
    if fmt.signed:
        return Signal(intbv(0, min=-(1 << (fmt.wl - 1)), max=1 << (fmt.wl - 1)))
    return Signal(intbv(0)[fmt.wl:])


def _is_signed(sig) -> bool:
    return sig.min is not None and sig.min < 0


def _range(sig) -> tuple[int, int]:
    if _is_signed(sig):
        return sig.min, sig.max - 1
    return 0, (1 << len(sig)) - 1


def _signed_width(lo: int, hi: int) -> int:
    n = 1
    while not (-(1 << (n - 1)) <= lo and hi < (1 << (n - 1))):
        n += 1
    return n


def _signed_sig(width: int):
    return Signal(intbv(0, min=-(1 << (width - 1)), max=1 << (width - 1)))


def _check(sig, fmt: Fmt, what: str) -> None:
    if len(sig) != fmt.wl or _is_signed(sig) != fmt.signed:
        kind = "signed" if _is_signed(sig) else "unsigned"
        raise ValueError(f"{what}: a {fmt} code needs a {'signed' if fmt.signed else 'unsigned'} {fmt.wl}-bit "
                         f"signal, got a {kind} {len(sig)}-bit one")


def _signed_copy(sig):
    """``sig`` itself if signed, else a new signed signal one bit wider to copy it into (exact).

    (MyHDL wants every sub-block created in a block's own body, so the caller makes the ``assign``.)"""
    return sig if _is_signed(sig) else _signed_sig(len(sig) + 1)


@block
def q_slice(src, out, hi: int, lo: int):
    @always_comb
    def comb():
        out.next = src[hi:lo]

    return comb


@block
def q_shift(src, out, k: int):
    @always_comb
    def comb():
        out.next = src << k

    return comb


@block
def q_mul(a, b, p):
    @always_comb
    def comb():
        p.next = a * b

    return comb


@block
def q_add(terms, s):
    # Two or three terms, all of the width and signedness of ``s``: the sum cannot overflow it.
    if len(terms) == 2:
        a, b = terms

        @always_comb
        def add2():
            s.next = a + b

        return add2
    if len(terms) == 3:
        a, b, c = terms

        @always_comb
        def add3():
            s.next = a + b + c

        return add3
    raise ValueError(f"fx_add handles 2 or 3 terms, got {len(terms)}")


@block
def cut_exact(exact, fl: int, out, fo: Fmt):
    """``out = quantize(v, fo)`` for the exact value ``v = exact * 2**-fl`` held in signal ``exact``."""
    _check(out, fo, "cut_exact output")
    insts: list = []
    d = fo.fl - fl
    n = len(exact)
    if d >= 0:
        # The output is the low fo.wl bits of exact << d: the low ``take`` bits of exact above d zeros
        # (take <= 0: all zeros; one bit is still taken so that every signal has a driver with inputs).
        take = max(fo.wl - d, 1)
        src = exact
        if n < take:  # the output reaches above the exact value: extend it first
            src = _signed_sig(take) if _is_signed(exact) else Signal(intbv(0)[take:])
            insts.append(assign(exact, src))
        if d == 0:
            insts.append(q_slice(src, out, take, 0))
            return insts
        low = Signal(intbv(0)[take:])
        wide = Signal(intbv(0)[take + d:])
        insts += [q_slice(src, low, take, 0), q_shift(low, wide, d), q_slice(wide, out, fo.wl, 0)]
        return insts
    s = -d  # floor drops s bits; wrap keeps fo.wl bits above them
    src = exact
    if n < s + fo.wl:  # bits above the exact value: its sign (or zero) extension
        src = _signed_sig(s + fo.wl) if _is_signed(exact) else Signal(intbv(0)[s + fo.wl:])
        insts.append(assign(exact, src))
    insts.append(q_slice(src, out, s + fo.wl, s))
    return insts


@block
def fx_resize(a, fa: Fmt, out, fo: Fmt):
    """``out = quantize(a, fo)`` for a code ``a`` of format ``fa`` (floor, wrap)."""
    _check(a, fa, "fx_resize input")
    return cut_exact(a, fa.fl, out, fo)


@block
def fx_mul(a, fa: Fmt, b, fb: Fmt, out, fo: Fmt):
    """``out = quantize(a * b, fo)``: one multiplier on the operands' own widths (signed if either is)."""
    _check(a, fa, "fx_mul operand a")
    _check(b, fb, "fx_mul operand b")
    insts: list = []
    if fa.signed or fb.signed:
        sa, sb = _signed_copy(a), _signed_copy(b)
        insts += [assign(o, c) for o, c in ((a, sa), (b, sb)) if c is not o]
        a, b = sa, sb
        p = _signed_sig(len(a) + len(b))
    else:
        p = Signal(intbv(0)[len(a) + len(b):])
    insts += [q_mul(a, b, p), cut_exact(p, fa.fl + fb.fl, out, fo)]
    return insts


@block
def fx_add(terms, out, fo: Fmt):
    """``out = quantize(sum of terms, fo)``; ``terms`` = [(signal, Fmt), ...], 2 or 3 of them."""
    if len(terms) not in (2, 3):
        raise ValueError(f"fx_add handles 2 or 3 terms, got {len(terms)}")
    for i, (sig, f) in enumerate(terms):
        _check(sig, f, f"fx_add term {i}")
    insts: list = []
    fine = max(max(f.fl for _, f in terms), fo.fl)
    signed = any(f.signed for _, f in terms)
    lo = hi = 0
    for _, f in terms:
        k = fine - f.fl
        lo += f.lo << k
        hi += f.hi << k
    width = _signed_width(lo, hi) if signed else max(1, hi.bit_length())
    aligned = []
    for sig, f in terms:
        k = fine - f.fl
        src = _signed_copy(sig) if signed else sig
        if src is not sig:
            insts.append(assign(sig, src))
        al = _signed_sig(width) if signed else Signal(intbv(0)[width:])
        insts.append(q_shift(src, al, k) if k else assign(src, al))
        aligned.append(al)
    s = _signed_sig(width) if signed else Signal(intbv(0)[width:])
    insts += [q_add(aligned, s), cut_exact(s, fine, out, fo)]
    return insts
