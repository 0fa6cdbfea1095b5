"""A small synchronous FIFO in distributed RAM (LUT-RAM), first word falls through."""

from myhdl import Signal, always, always_comb, always_seq, block, intbv


@block
def sync_fifo(clk, rst, din, push, dout, pop, count, *, depth: int):
    """``dout`` shows the oldest word while ``count > 0``; ``push`` stores ``din``, ``pop`` drops the head.

    The caller must not push when ``count == depth`` (unless it pops in the same clock) nor pop when
    ``count == 0``. ``count`` (0..depth) is a register. Reset empties the FIFO, not the memory.

    Resources: ``len(din)`` LUT-RAM cells of ``depth`` x 1 (RAM16X1D up to 16 deep), two pointers, the count.
    """
    if depth < 2 or depth & (depth - 1):
        raise ValueError(f"sync_fifo depth must be a power of two >= 2, got {depth}")
    if count.max is None or count.max < depth + 1 or (count.min or 0) != 0:
        raise ValueError(f"sync_fifo count must hold 0..{depth}")
    aw = depth.bit_length() - 1
    mem = [Signal(intbv(0)[len(din):]) for _ in range(depth)]
    wp = Signal(intbv(0)[aw:])
    rp = Signal(intbv(0)[aw:])

    @always(clk.posedge)
    def write():
        if push:
            mem[wp].next = din

    @always_comb
    def read():
        dout.next = mem[rp]

    @always_seq(clk.posedge, reset=rst)
    def pointers():
        if push:
            wp.next = (wp + 1) % depth
        if pop:
            rp.next = (rp + 1) % depth
        if push and not pop:
            count.next = count + 1
        elif pop and not push:
            count.next = count - 1

    return write, read, pointers
