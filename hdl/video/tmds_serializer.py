"""TMDS serializer: three 10-bit characters and the clock channel per pixel clock -> DDR bit pairs at 5x the clock."""

from myhdl import Signal, always, block, intbv

from eyestereo.hdl.common.checks import block_error, check_clock, check_distinct, check_reset, check_signal
from eyestereo.tools.models.tmds_serializer import CLOCK_WORD


@block
def tmds_serializer(clk, clk5, rst, d0, d1, d2, q0, q1, q2, qc):
    """The four TMDS channels of a DVI link as 2-bit words for ECP5 DDR output cells (``ODDRX1F``, one per
    channel, clocked by ``clk5``): each pixel clock's characters ``d0``, ``d1``, ``d2`` and the clock
    channel's fixed character 0b0000011111, bit 0 first, two bits per ``clk5`` period.

    ``clk5`` is 5x ``clk`` from the same PLL (640x480: 25 and 125 MHz; the bits leave at 250 Mbit/s per
    channel). The crossing needs no timed path between the two clocks: at every ``clk`` edge the pixel
    side captures the three characters in ``held`` and flips ``toggle``; the fast side passes ``toggle``
    through two flip-flops (``t1``, ``t2``: the only flops that sample the other clock's signal; mark them
    ASYNC_REG) and, one fast clock after ``t2`` changed (``t2 != t3``), loads ``held`` into its shift
    registers, 2 to 3 fast clocks after ``held`` changed and 2 to 3 before it changes again: ``held`` ->
    shift registers is at least a two-fast-clock path (constrain it as a false path or a 2-cycle multicycle
    path; unconstrained, a tool times it as a one-fast-clock path, which is stricter than needed). The four shift
    registers then send two bits per fast clock; after five fast clocks
    the next load comes (the toggle flips every pixel clock, so the loads are periodic). Fast edges counted
    from the ``clk`` edge E (the bar) that captures character B (edge 1 the first after E; A, C the characters
    before and after B; "toggle": the edge at which t1, t2, t3 take its new value; "load": t2 != t3 seen)::

        fast edge  -2     -1     0      | 1      2      3      4      5      6      7      8
        held       A      A      A      | B      B      B      B      B      B      B      B
        toggle                          | t1 new t2 new t3 new
        load                            |               yes                                yes
        q after    A[1:0] A[3:2] A[5:4] | A[7:6] A[9:8] B[1:0] B[3:2] B[5:4] B[7:6] B[9:8] C[1:0]

    Each 2-bit output holds the earlier bit in bit 0 (the DDR cell's D0, sent while ``clk5`` is high: the
    rising edge's) and the later in bit 1 (D1, the falling edge's).

    Reset: ``rst`` (pixel clock) makes ``held`` the control character for (C1, C0) = (0, 0) on the data
    channels, so the link carries blanking; the toggle keeps running. The fast side has no reset: its
    registers start at 0 with the FPGA's configuration and are reloaded every pixel clock, so they hold
    nothing a reset would have to clear.

    Ports:
        clk: pixel clock.
        clk5: the fast clock, 5x ``clk``, from the same PLL.
        rst: the library's synchronous active-high reset, in ``clk``'s domain.
        d0, d1, d2: inputs, ``Signal(intbv(0)[10:])``: channel 0..2's characters (``tmds_encoder`` outputs),
            ``clk`` domain.
        q0, q1, q2, qc: outputs, ``Signal(intbv(0)[2:])``, ``clk5`` domain, registered: channel 0..2's and the
            clock channel's next two bits (bit 0 first).

    Parameters: none.

    Latency: a character captured at a ``clk`` edge is on ``q`` from the third ``clk5`` edge after it (when
    no ``clk5`` edge coincides with it; with coincident edges the 2nd or the 3rd, fixed while the clocks
    run) for five ``clk5`` clocks; the last pair of a character leaves 8 fast clocks (1.6 pixel clocks)
    after its capture.

    Resources: 31 flip-flops in the pixel clock, 3 + 32 + 8 in the fast one (the clock channel's constant
    bits fold away), 2-input multiplexers; make synth's flow (Yosys xc3se): 26 LUT, 68 FF; nextpnr-ecp5
    clk5 374.4 MHz (goal 125), clk 894.5 MHz.
    """
    check_clock(clk)
    check_clock(clk5, "clk5")
    check_reset(rst)
    for name, sig in (("d0", d0), ("d1", d1), ("d2", d2)):
        check_signal(name, sig, width=10)
    for name, sig in (("q0", q0), ("q1", q1), ("q2", q2), ("qc", qc)):
        check_signal(name, sig, width=2)
    for name, sig in (("d0", d0), ("d1", d1), ("d2", d2), ("q0", q0), ("q1", q1), ("q2", q2), ("qc", qc)):
        if isinstance(sig.val, bool):
            raise block_error(f"port {name} must be a Signal(intbv(0)[{len(sig) if name[0] == 'd' else 2}:]), "
                              f"got a Signal(bool)")
    if clk is clk5:
        raise block_error("ports clk and clk5 are the same signal: clk5 must be the 5x fast clock")
    check_distinct(dict(q0=q0, q1=q1, q2=q2, qc=qc), dict(clk=clk, clk5=clk5, rst=rst, d0=d0, d1=d1, d2=d2))
    BLANK = 0b1101010100  # the control character for (C1, C0) = (0, 0)
    held0, held1, held2 = (Signal(intbv(BLANK)[10:]) for _ in range(3))
    toggle = Signal(bool(0))
    t1, t2, t3 = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    s0, s1, s2, sc = (Signal(intbv(0)[8:]) for _ in range(4))  # bits 2..9 of the characters, shifted out
    CLK_LO, CLK_HI = CLOCK_WORD & 3, CLOCK_WORD >> 2  # constants outside the generator (they convert as such)

    @always(clk.posedge)
    def capture():
        toggle.next = not toggle
        if rst:
            held0.next = BLANK
            held1.next = BLANK
            held2.next = BLANK
        else:
            held0.next = d0
            held1.next = d1
            held2.next = d2

    @always(clk5.posedge)
    def sync():
        t1.next = toggle
        t2.next = t1
        t3.next = t2

    @always(clk5.posedge)
    def shift():
        if t2 != t3:
            q0.next = held0[2:0]
            q1.next = held1[2:0]
            q2.next = held2[2:0]
            qc.next = CLK_LO
            s0.next = held0[10:2]
            s1.next = held1[10:2]
            s2.next = held2[10:2]
            sc.next = CLK_HI
        else:
            q0.next = s0[2:0]
            q1.next = s1[2:0]
            q2.next = s2[2:0]
            qc.next = sc[2:0]
            s0.next = s0[8:2]
            s1.next = s1[8:2]
            s2.next = s2[8:2]
            sc.next = sc[8:2]

    return capture, sync, shift
