"""Constant-coefficient arithmetic by shifts and adds, with signals sized from exact value ranges."""

from myhdl import Signal, always, always_comb, block, intbv

from eyestereo.hdl.common.registers import assign, delay


def csd(k: int) -> list[tuple[int, int]]:
    """Canonical signed digits of an integer: [(sign, shift), ...] with k = sum(sign << shift)."""
    digits = []
    shift = 0
    while k != 0:
        if k & 1:
            d = 2 - (k & 3)  # +1 or -1, chosen so the next bit is 0
            digits.append((d, shift))
            k -= d
        k >>= 1
        shift += 1
    return digits


def signal_range(sig) -> tuple[int, int]:
    """(lowest, highest) value a Signal can hold."""
    if sig.min is not None:
        return sig.min, sig.max - 1
    return 0, (1 << len(sig)) - 1


def term_range(sig, coeff: int) -> tuple[int, int]:
    """Value range of ``coeff * sig``."""
    lo, hi = signal_range(sig)
    a, b = lo * coeff, hi * coeff
    return min(a, b), max(a, b)


def range_signal(lo: int, hi: int):
    """A Signal just wide enough for every integer in [lo, hi] (unsigned when lo >= 0)."""
    if lo >= 0:
        return Signal(intbv(0, min=0, max=max(hi, 0) + 1))
    return Signal(intbv(0, min=lo, max=max(hi, 0) + 1))


@block
def shift_add(terms, out):
    """Combinational ``out = sum(coeff * sig)`` for constant integer coefficients, by shifts and adds.

    Each coefficient is split into canonical signed digits; the shifted terms are summed by a balanced
    tree of adders whose widths follow the exact value range of each node, so nothing can overflow.
    ``out`` must hold the whole range (checked at elaboration).
    """
    leaves = []  # (signal, lo, hi)
    insts = []
    for sig, coeff in terms:
        for sign, shift in csd(int(coeff)):
            lo, hi = term_range(sig, sign << shift)
            lf = range_signal(lo, hi)
            insts.append(leaf(sig, lf, sign, shift))
            leaves.append((lf, lo, hi))
    if not leaves:
        leaves.append((range_signal(0, 0), 0, 0))
    while len(leaves) > 1:
        nxt = []
        for i in range(0, len(leaves) - 1, 2):
            (a, alo, ahi), (b, blo, bhi) = leaves[i], leaves[i + 1]
            s = range_signal(alo + blo, ahi + bhi)
            insts.append(adder(a, b, s))
            nxt.append((s, alo + blo, ahi + bhi))
        if len(leaves) % 2:
            nxt.append(leaves[-1])
        leaves = nxt
    root = leaves[0][0]
    # The tree's node ranges are loose (a CSD digit pair like 4x - x spans more than 3x does); the
    # output only has to hold the exact range of the sum.
    lo = sum(term_range(sig, int(c))[0] for sig, c in terms)
    hi = sum(term_range(sig, int(c))[1] for sig, c in terms)
    olo, ohi = signal_range(out)
    if lo < olo or hi > ohi:
        raise ValueError(f"shift_add output range [{olo}, {ohi}] cannot hold the sum's [{lo}, {hi}]")
    insts.append(assign(root, out))
    return insts


@block
def chain_sum(clk, terms, out):
    """Registered ``out = sum(coeff * sig)`` of terms that come one clock apart, as a chain of adders.

    ``terms[j]`` is read ``j`` clocks after ``terms[0]`` (the skewed column taps of
    :func:`~eyestereo.hdl.streaming.window.column_taps`); ``out`` holds the sum ``len(terms)`` clocks after
    ``terms[0]``. Each clock adds one term to the registered partial sum of the terms before it, so a
    register holds each partial sum, not each term until the last one comes (fewer registers when the
    terms would wait several clocks), and no path has more than one term's shifts and adds.
    """
    insts = []
    acc, lo, hi = None, 0, 0
    for j, (sig, coeff) in enumerate(terms):
        tlo, thi = term_range(sig, int(coeff))
        lo, hi = lo + tlo, hi + thi
        part = [(sig, coeff)] if acc is None else [(acc, 1), (sig, coeff)]
        s = range_signal(lo, hi)
        nxt = out if j == len(terms) - 1 else range_signal(lo, hi)
        insts += [shift_add(part, s), delay(clk, s, nxt, clocks=1)]
        acc = nxt
    olo, ohi = signal_range(out)
    if lo < olo or hi > ohi:
        raise ValueError(f"chain_sum output range [{olo}, {ohi}] cannot hold the sum's [{lo}, {hi}]")
    return insts


@block
def leaf(sig, out, sign: int, shift: int):
    """``out = sign * (sig << shift)`` for sign +1 or -1."""
    if sign > 0:
        @always_comb
        def pos():
            out.next = sig << shift

        return pos

    # VHDL has no unary minus on unsigned, and a shift keeps its operand's width: shift into a signed
    # signal wide enough for the shifted value first, then negate.
    lo, hi = signal_range(sig)
    mag = max(abs(lo), abs(hi)) << shift
    wide = Signal(intbv(0, min=-mag - 1, max=mag + 1))

    @always_comb
    def widen():
        wide.next = sig << shift

    @always_comb
    def neg():
        out.next = -wide

    return widen, neg


@block
def adder(a, b, s):
    """Combinational ``s = a + b``."""

    @always_comb
    def add():
        s.next = a + b

    return add


@block
def chunk_count(clk, a, b, n, *, lo: int, hi: int):
    """Registered count of the bits lo .. hi-1 where a and b differ (a Hamming distance in chunks: 3-bit chunks
    make each count bit a function of 6 inputs, two LUT levels)."""

    @always(clk.posedge)
    def count():
        c = intbv(0, min=0, max=hi - lo + 1)
        for i in range(lo, hi):
            if a[i] != b[i]:
                c[:] = c + 1
        n.next = c

    return count


@block
def sum_tree(clk, terms, total):
    """Registered sum of ``terms``: a tree of :func:`adder`, each in the total's width, then one register."""
    insts = []
    level = list(terms)
    while len(level) > 1:
        nxt = []
        for i in range(0, len(level) - 1, 2):
            s = Signal(intbv(0, min=0, max=total.max))
            insts.append(adder(level[i], level[i + 1], s))
            nxt.append(s)
        if len(level) % 2:
            nxt.append(level[-1])
        level = nxt
    insts.append(delay(clk, level[0], total, clocks=1))
    return insts


def signed_copy(sig):
    """A signed Signal one bit wider than unsigned ``sig``, for ``assign(sig, copy)`` in the caller's block.

    MyHDL's Verilog back end writes ``signed - unsigned`` as it is, and Verilog then computes the whole
    expression unsigned, zero-extending the signed operand (a negative value turns large and positive);
    its VHDL back end converts the unsigned operand first. Give such an operator a signed copy of the
    unsigned operand and both back ends compute the same thing (no logic: a wire with a 0 on top).
    """
    lo, hi = signal_range(sig)
    if lo < 0:
        raise ValueError("signed_copy: the signal is signed already")
    return Signal(intbv(0, min=-hi - 1, max=hi + 1))
