"""Registers and delay lines shared by the blocks (free-running, with enable, or with a synchronous reset)."""

from myhdl import Signal, always, always_comb, always_seq, block, intbv

from eyestereo.hdl.common.checks import check_int


def like_signal(sig):
    """A fresh Signal with the same width and signedness as ``sig`` (value 0)."""
    return Signal(intbv(0, min=sig.min, max=sig.max)) if sig.min is not None else Signal(intbv(0)[len(sig):])


@block
def assign(a, b):
    """Combinational ``b = a`` (also reinterprets bits between unsigned and signed signals of one width)."""

    @always_comb
    def comb():
        b.next = a

    return comb


@block
def dreg(clk, d, q):
    """One free-running register: ``q`` takes ``d`` on every rising edge (no reset, no enable)."""

    @always(clk.posedge)
    def reg():
        q.next = d

    return reg


@block
def delay(clk, din, dout, *, clocks: int):
    """``dout`` = ``din`` delayed by ``clocks`` (>= 1) free-running registers (no reset, no enable)."""
    clocks = check_int("clocks", clocks, 1)
    stages = [like_signal(din) for _ in range(clocks - 1)] + [dout]
    insts = []
    src = din
    for dst in stages:
        insts.append(dreg(clk, src, dst))
        src = dst
    return insts


@block
def en_reg(clk, en, d, q):
    """q takes d on the clock edges where en is high (a register with enable, no reset)."""

    @always(clk.posedge)
    def reg():
        if en:
            q.next = d

    return reg


@block
def dreg_rst(clk, rst, d, q):
    """One register with the block's synchronous reset (for control bits that must not survive ``rst``)."""

    @always_seq(clk.posedge, reset=rst)
    def reg():
        q.next = d

    return reg


@block
def delay_rst(clk, rst, din, dout, *, clocks: int):
    """Like :func:`delay` for 1-bit control, with a synchronous reset so no stale flag survives ``rst``."""
    clocks = check_int("clocks", clocks, 1)
    stages = [Signal(bool(0)) for _ in range(clocks - 1)] + [dout]
    insts = []
    src = din
    for dst in stages:
        insts.append(dreg_rst(clk, rst, src, dst))
        src = dst
    return insts
