"""Fixed-point operations with the toolbox's quantizer semantics: exact result, floor, two's complement wrap.

Each block computes ``out = quantize(op(a, b, ...), fo)`` combinationally, where the operands are codes of
:class:`~eyestereo.tools.fixed.Fmt` formats (a signal is signed exactly when its format is, and has its
format's word length) and ``quantize`` is :func:`eyestereo.tools.fixed.quantize` with floor rounding and
wrap -- what :func:`eyestereo.tools.rectify.ffc.fixed_stages` computes for every quantizer q11..q24:

* :func:`fx_resize`: ``out = quantize(a, fo)`` (a change of format);
* :func:`fx_mul`: ``out = quantize(a * b, fo)`` (one multiplier, operands at their own widths);
* :func:`fx_mul_reg`: the same product across a register stage, split into partial products that each
  fit an 18x18 hardware multiplier (the only block here with a clock);
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

from eyestereo.hdl.common.registers import assign, en_reg
from eyestereo.tools.fixed import Fmt

__all__ = ["DSP_INPUT_BITS", "fmt_signal", "fx_add", "fx_mul", "fx_mul_reg", "fx_resize", "cut_exact"]

#: Signed input width of the hardware multipliers fx_mul_reg splits its operands for (Spartan-3E MULT18X18,
#: ECP5 MULT18X18D).
DSP_INPUT_BITS = 18


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
    a, b, copies, signed = _operands(a, fa, b, fb, "fx_mul")
    p = _signed_sig(len(a) + len(b)) if signed else Signal(intbv(0)[len(a) + len(b):])
    return [assign(o, c) for o, c in copies] + [q_mul(a, b, p), cut_exact(p, fa.fl + fb.fl, out, fo)]


def _operands(a, fa: Fmt, b, fb: Fmt, what: str):
    """A product's operands checked against their formats and, when either is signed, both as signed
    signals: (a, b, [(original, signed copy) to assign], signed)."""
    _check(a, fa, f"{what} operand a")
    _check(b, fb, f"{what} operand b")
    if not (fa.signed or fb.signed):
        return a, b, [], False
    sa, sb = _signed_copy(a), _signed_copy(b)
    return sa, sb, [(o, c) for o, c in ((a, sa), (b, sb)) if c is not o], True


@block
def fx_mul_reg(clk, enable, a, fa: Fmt, b, fb: Fmt, out, fo: Fmt):
    """``out = quantize(a * b, fo)`` one enabled clock after ``a``, ``b``: partial products registered.

    When an operand needs more than :data:`DSP_INPUT_BITS` signed bits, a single product is two hardware
    multipliers joined by an adder, and the multiplier, that adder and the routing between them do not fit
    one clock at the memory clock's goal (issue 23). Here the wider operand is split into a low part of
    ``DSP_INPUT_BITS - 1`` unsigned bits and a signed high part; each partial product (one hardware
    multiplier each) is registered on ``clk`` when ``enable`` is high, and ``out`` is their sum, shifted
    into place and cut: combinational from those registers (one carry chain). Operands that fit give one
    registered product. Exact before the cut, so bit for bit :func:`fx_mul` a clock later.
    """
    a, b, copies, signed = _operands(a, fa, b, fb, "fx_mul_reg")
    insts: list = [assign(o, c) for o, c in copies]
    width = len(a) + len(b)
    exact = _signed_sig(width) if signed else Signal(intbv(0)[width:])
    fl = fa.fl + fb.fl
    wa, wb = (len(a), len(b)) if signed else (len(a) + 1, len(b) + 1)
    if max(wa, wb) <= DSP_INPUT_BITS:
        p = _signed_sig(width) if signed else Signal(intbv(0)[width:])
        insts += [q_mul(a, b, p), en_reg(clk, enable, p, exact), cut_exact(exact, fl, out, fo)]
        return insts
    if not signed:
        raise ValueError(f"fx_mul_reg: unsigned operands of {len(a)} and {len(b)} bits need a signed split; "
                         f"give one operand a signed format")
    if wb > wa:
        a, b, wa, wb = b, a, wb, wa
    low = DSP_INPUT_BITS - 1
    if wb > DSP_INPUT_BITS or wa - low > DSP_INPUT_BITS:
        raise ValueError(f"fx_mul_reg splits one operand into two parts; {wa} x {wb} signed bits need more")
    lo_bits, hi = Signal(intbv(0)[low:]), Signal(intbv(0)[wa - low:])
    lo_s, hi_s = _signed_sig(low + 1), _signed_sig(wa - low)
    p_lo, p_hi = _signed_sig(low + 1 + wb), _signed_sig(wa - low + wb)
    r_lo, r_hi = _signed_sig(len(p_lo)), _signed_sig(len(p_hi))
    x_lo, x_hi, s_hi = _signed_sig(width), _signed_sig(width), _signed_sig(width)
    insts += [q_slice(a, lo_bits, low, 0), q_slice(a, hi, wa, low),
              assign(lo_bits, lo_s), assign(hi, hi_s),  # zero extension; the high part's own sign
              q_mul(lo_s, b, p_lo), q_mul(hi_s, b, p_hi),
              en_reg(clk, enable, p_lo, r_lo), en_reg(clk, enable, p_hi, r_hi),
              assign(r_lo, x_lo), assign(r_hi, x_hi), q_shift(x_hi, s_hi, low),
              q_add([s_hi, x_lo], exact), cut_exact(exact, fl, out, fo)]
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
