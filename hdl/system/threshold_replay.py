"""The block thresholds' way into the Harris clock, and their replay after a reset of the Harris domain."""

from myhdl import Signal, always, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.common.checks import check_clock, check_int, check_reset, check_signal
__all__ = ["threshold_replay", "ENTRIES"]

#: Thresholds kept: 16 blocks per camera, left first (entry = 16 * camera + block).
ENTRIES = 32


@block
def threshold_replay(clk, rst, hrst, l_we, l_addr, l_data, r_we, r_addr, r_data, source, *, gap: int = 4):
    """Each threshold the host writes as a one-beat frame (camera, block, code) towards the Harris clock, and all
    32 again after the Harris domain's reset.

    harris_stereo keeps the block thresholds in the Harris clock, and its reset clears them (prethreshold: an
    entry not written since reset reads 0), while the register bank, in the memory clock, still reads the values
    the host wrote. A reset of the Harris domain alone (``hrst``) would leave every later frame thresholded at 0
    until the host wrote them again (the fault soak found it: docs/reliability.md). This block keeps a copy of
    the 32 thresholds (an entry not written since ``rst`` is 0, as in the bank) and, when ``hrst`` falls, sends
    all 32 again, one every ``gap + 1`` clocks; a bus write in the same clock goes first (the replay waits a
    clock).

    Beat format (``source``, an :class:`~eyestereo.hdl.interfaces.stream.ImageStream` of 1 + 4 + T bits, ``eol`` =
    ``eof`` = 1 on every beat): bit T + 4 the camera (1 right), bits T + 3..T the block, bits T - 1..0 the code.

    Ports:
        clk, rst: the memory clock and its synchronous reset (the copy's written flags clear).
        hrst: the Harris domain's reset, from its clock: synchronised here (two flip-flops), its fall starts the
            replay. A constant 0 when harris_stereo runs in the memory clock (``single_clock``).
        l_we, l_addr, l_data, r_we, r_addr, r_data: the register bank's THR_LEFT and THR_RIGHT write ports (4-bit
            block, T-bit code; at most one of the two in a clock).
        source: the beats, into the crossing (no back-pressure: its FIFO takes a beat per Harris clock).

    Parameters:
        gap: idle clocks between two replayed beats (2..16; default 4: a beat every 5 clocks; the crossing's reader
            takes a beat per Harris clock, at least every second memory clock, and bus writes slip in between).

    Latency: a bus write's beat in the same clock (combinational, as the bank's write port); the replay's first
    beat ``gap + 4`` clocks after ``hrst`` falls (the synchroniser, the gap), then one every ``gap + 1`` clocks:
    32 beats in ``32 * (gap + 1)`` clocks (160 at the default, 1.6 us at 100 MHz).

    Resources: a 32 x T LUT-RAM copy and its 32 written flags, a 5-bit index, a gap counter, 3 synchroniser
    flip-flops.
    """
    check_clock(clk)
    check_reset(rst)
    check_int("gap", gap, 2, 16)
    for name, s in (("hrst", hrst), ("l_we", l_we), ("r_we", r_we)):
        check_signal(name, s, width=1)
    check_signal("l_addr", l_addr, width=4)
    check_signal("r_addr", r_addr, width=4)
    tb = len(l_data)
    check_signal("r_data", r_data, width=tb)
    check_signal("source_data", source.data, width=1 + 4 + tb)

    copy = [Signal(intbv(0)[tb:]) for _ in range(ENTRIES)]
    written = Signal(intbv(0)[ENTRIES:])
    h1, h2, h3 = (Signal(bool(0)) for _ in range(3))
    busy = Signal(bool(0))
    idx = Signal(intbv(0)[5:])
    wait = Signal(intbv(0, min=0, max=gap + 1))
    stored = Signal(intbv(0)[tb:])
    value = Signal(intbv(0)[tb:])
    waddr = Signal(intbv(0)[5:])
    wdata = Signal(intbv(0)[tb:])

    @always_comb
    def write_port():
        if l_we:
            waddr.next = concat(False, l_addr)
            wdata.next = l_data
        else:
            waddr.next = concat(True, r_addr)
            wdata.next = r_data

    @always(clk.posedge)
    def keep():
        # the copy (LUT-RAM: no reset; the written flags say which entries hold a value)
        if l_we or r_we:
            copy[waddr].next = wdata

    @always(clk.posedge)
    def sync():
        # hrst from the Harris clock: no reset here, like the crossings' synchronisers
        h1.next = hrst
        h2.next = h1
        h3.next = h2

    @always_comb
    def read():
        stored.next = copy[idx]

    @always_comb
    def pick():
        if written[idx]:
            value.next = stored
        else:
            value.next = 0

    @always_seq(clk.posedge, reset=rst)
    def replay():
        nw = intbv(0)[ENTRIES:]
        nw[:] = written
        if l_we or r_we:
            nw[waddr] = 1
        written.next = nw
        if h3 and not h2:  # hrst has fallen: all again from the first entry
            busy.next = 1
            idx.next = 0
            wait.next = gap
        elif busy and not (l_we or r_we):
            if wait != 0:
                wait.next = wait - 1
            else:
                wait.next = gap
                idx.next = (idx + 1) % ENTRIES
                if idx == ENTRIES - 1:
                    busy.next = 0

    @always_comb
    def out():
        source.eol.next = 1
        source.eof.next = 1
        source.valid.next = l_we or r_we or (busy and wait == 0 and not (h3 and not h2))
        if l_we:
            source.data.next = concat(False, l_addr, l_data)
        elif r_we:
            source.data.next = concat(True, r_addr, r_data)
        else:
            source.data.next = concat(idx, value)

    return write_port, keep, sync, read, pick, replay, out
