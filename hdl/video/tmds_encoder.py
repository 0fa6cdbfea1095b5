"""One TMDS channel's encoder (DVI 1.0 section 3.2.2): a byte or two control bits per clock -> a 10-bit character."""

from myhdl import Signal, always, always_comb, block, concat, intbv

from eyestereo.hdl.common.checks import block_error, check_clock, check_distinct, check_reset, check_signal
from eyestereo.tools.models.tmds_encoder import CONTROL, DISPARITY_BOUND


@block
def tmds_encoder(clk, rst, data, c0, c1, de, q):
    """DVI 1.0's 8b/10b TMDS encoding of one channel: transition minimised and DC balanced while ``de`` is
    high, one of the four control characters for (``c1``, ``c0``) while it is low.

    Two steps, as the spec's flow chart (figure 3-5). Combinational: ``q_m`` = ``data`` through an XOR
    chain, or an XNOR chain when ``data`` has more than four ones (or four and ``data[0]`` = 0), which
    leaves at most three transitions in ``q_m[7:0]``; ``q_m[8]`` says which chain; and the balance
    (ones minus zeros) of ``q_m[7:0]``. Registered: ``q`` = ``q_m`` with ``q_m[7:0]`` complemented or not
    (``q[9]`` says which) as the running disparity ``cnt`` of what was sent asks, and ``cnt`` updated;
    the disparity stays within +-8 (the reachable states; the counter has room for +-15) and restarts at
    0 in every control period. The model (:mod:`eyestereo.tools.models.tmds_encoder`) is the same flow
    chart in Python; the channel's character leaves ``q[0]`` first (:func:`tmds_serializer`).

    On a DVI link channel 0 (blue) carries ``c0`` = HSYNC, ``c1`` = VSYNC; channels 1 and 2 carry 0.

    Ports:
        clk: pixel clock.
        rst: the library's synchronous active-high reset: ``q`` = the control character for (0, 0)
            (0b1101010100) and ``cnt`` = 0 while it is high.
        data: input, ``Signal(intbv(0)[8:])``: the pixel's byte (used while ``de``).
        c0, c1: inputs, Signal(bool): the control bits (used while not ``de``).
        de: input, Signal(bool): data enable.
        q: output, ``Signal(intbv(0)[10:])``, registered: the character, bit 0 sent first.

    Parameters: none.

    Latency: 1 clock (inputs at an edge -> ``q`` after it).

    Resources: two popcounts, an 8-bit XOR chain, a 5-bit disparity register and adder, 10 output
    flip-flops; make synth's flow (Yosys xc3se): 329 LUT, 14 FF (205 LUT4 on the ECP5); nextpnr-ecp5
    182.0 MHz (goal 25).
    """
    check_clock(clk)
    check_reset(rst)
    check_signal("data", data, width=8)
    for name, sig in (("c0", c0), ("c1", c1), ("de", de)):
        check_signal(name, sig, width=1)
    check_signal("q", q, width=10)
    if isinstance(data.val, bool) or (data.min is not None and data.min < 0):
        raise block_error("port data must be an unsigned Signal(intbv(0)[8:])")
    check_distinct(dict(q=q), dict(clk=clk, rst=rst, data=data, c0=c0, c1=c1, de=de))

    CTRL0, CTRL1, CTRL2, CTRL3 = CONTROL
    qm = Signal(intbv(0)[9:])
    inv_low = Signal(intbv(0)[8:])  # ~q_m[7:0]
    # ones minus zeros of q_m[7:0]: -8 .. 8, even
    bal = Signal(intbv(0, min=-8, max=9))
    # the running disparity: reachable -8 .. 8 (model: DISPARITY_BOUND); sized for one step past it
    cnt = Signal(intbv(0, min=-2 * DISPARITY_BOUND, max=2 * DISPARITY_BOUND))

    @always_comb
    def minimise():
        ones = 0
        for i in range(8):
            if data[i]:
                ones += 1
        use_xnor = ones > 4 or (ones == 4 and not data[0])
        m = intbv(0)[9:]
        m[0] = data[0]
        for i in range(1, 8):
            m[i] = m[i - 1] ^ data[i] ^ use_xnor  # XNOR = XOR inverted
        m[8] = not use_xnor
        qm.next = m

    @always_comb
    def balance():
        ones = 0
        for i in range(8):
            if qm[i]:
                ones += 1
        bal.next = 2 * ones - 8
        inv_low.next = ~qm[8:0]

    @always(clk.posedge)
    def encode():
        if rst:
            q.next = CTRL0
            cnt.next = 0
        elif not de:
            cnt.next = 0
            if c1:
                q.next = CTRL3 if c0 else CTRL2
            else:
                q.next = CTRL1 if c0 else CTRL0
        elif cnt == 0 or bal == 0:
            # no disparity to correct: q_m[8] = 1 (XOR) sends q_m[7:0] as it is, XNOR its complement
            if qm[8]:
                q.next = concat(False, True, qm[8:0])
                cnt.next = cnt + bal
            else:
                q.next = concat(True, False, inv_low)
                cnt.next = cnt - bal
        elif (cnt > 0 and bal > 0) or (cnt < 0 and bal < 0):
            # more of what the line already has too much of: complement
            q.next = concat(True, qm[8], inv_low)
            if qm[8]:
                cnt.next = cnt - bal + 2
            else:
                cnt.next = cnt - bal
        else:
            q.next = concat(False, qm[8], qm[8:0])
            if qm[8]:
                cnt.next = cnt + bal
            else:
                cnt.next = cnt + bal - 2

    return minimise, balance, encode
