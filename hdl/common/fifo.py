"""A small synchronous FIFO in distributed RAM (LUT-RAM) with a registered head."""

from myhdl import Signal, always, always_comb, always_seq, block, intbv


@block
def sync_fifo(clk, rst, din, push, dout, pop, count, valid, *, depth: int):
    """``dout`` is the oldest word while ``valid`` is high; ``push`` stores ``din``, ``pop`` drops the head.

    The head sits in a register, loaded from the LUT-RAM, so whatever decodes it starts from a flip-flop:
    a word pushed into an empty FIFO is at the head two clocks later. ``count`` (0..depth, a register)
    counts every word held; the caller must not push when ``count == depth`` nor pop while ``valid``
    is low. Reset empties the FIFO, not the memory.

    Resources: ``len(din)`` LUT-RAM cells of ``depth`` x 1 (RAM16X1D up to 16 deep), the head register,
    two pointers, two counts.
    """
    if depth < 2 or depth & (depth - 1):
        raise ValueError(f"sync_fifo depth must be a power of two >= 2, got {depth}")
    if count.max is None or count.max < depth + 1 or (count.min or 0) != 0:
        raise ValueError(f"sync_fifo count must hold 0..{depth}")
    aw = depth.bit_length() - 1
    mem = [Signal(intbv(0)[len(din):]) for _ in range(depth)]
    wp = Signal(intbv(0)[aw:])
    rp = Signal(intbv(0)[aw:])
    stored = Signal(intbv(0, min=0, max=depth + 1))  # words in the LUT-RAM (not the head)
    load = Signal(bool(0))
    ram_out = Signal(intbv(0)[len(din):])

    @always(clk.posedge)
    def write():
        if push:
            mem[wp].next = din

    @always_comb
    def read():
        ram_out.next = mem[rp]

    @always_comb
    def refill():
        load.next = stored != 0 and (not valid or pop)

    @always(clk.posedge)
    def head():
        if load:
            dout.next = ram_out

    @always_seq(clk.posedge, reset=rst)
    def pointers():
        if push:
            wp.next = (wp + 1) % depth
        if load:
            rp.next = (rp + 1) % depth
        if push and not load:
            stored.next = stored + 1
        elif load and not push:
            stored.next = stored - 1
        if load:
            valid.next = True
        elif pop:
            valid.next = False
        if push and not pop:
            count.next = count + 1
        elif pop and not push:
            count.next = count - 1

    return write, read, refill, head, pointers


@block
def show_ahead_fifo(clk, rst, din, push, dout, pop, level, *, depth: int):
    """``dout`` is the oldest word whenever ``level != 0``: read straight from the LUT-RAM (show-ahead).

    A word pushed is at the head in the next clock (one clock sooner than :func:`sync_fifo`, for a
    consumer that decides from the head in the clock it pops it). ``level`` (0..depth, a register) counts
    the words held; the caller must not push when ``level == depth`` nor pop when ``level == 0``.
    Reset empties the FIFO, not the memory. Any depth from 1 up (the pointers wrap by comparison).

    Resources: ``len(din)`` LUT-RAM cells of ``depth`` x 1 (RAM16X1D up to 16 deep), two pointers, the
    level; no head register.
    """
    if not isinstance(depth, int) or isinstance(depth, bool) or depth < 1:
        raise ValueError(f"show_ahead_fifo depth must be an integer >= 1, got {depth!r}")
    if level.max is None or level.max < depth + 1 or (level.min or 0) != 0:
        raise ValueError(f"show_ahead_fifo level must hold 0..{depth}")
    mem = [Signal(intbv(0)[len(din):]) for _ in range(depth)]
    wp, rp = Signal(intbv(0, min=0, max=depth)), Signal(intbv(0, min=0, max=depth))

    @always(clk.posedge)
    def store():
        if push:
            mem[wp].next = din

    @always_comb
    def head_word():
        dout.next = mem[rp]

    @always_seq(clk.posedge, reset=rst)
    def pointers():
        # wrap by comparison: a depth that is not a power of two (the fetch unit's side queue) works too
        if push:
            if wp == depth - 1:
                wp.next = 0
            else:
                wp.next = wp + 1
        if pop:
            if rp == depth - 1:
                rp.next = 0
            else:
                rp.next = rp + 1
        if push and not pop:
            level.next = level + 1
        elif pop and not push:
            level.next = level - 1

    return store, head_word, pointers
