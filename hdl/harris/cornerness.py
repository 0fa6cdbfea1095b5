"""Harris cornerness c = det(G) - k trace(G)^2, fully pipelined, multiplier inputs <= 18 bits (thesis 6.2.3)."""

from myhdl import Signal, always, always_comb, block, intbv

from eyestereo.hdl.common.arith import signed_copy
from eyestereo.hdl.common.registers import assign
from eyestereo.hdl.common.fixed import fx_signal
from eyestereo.hdl.common import delay_rst
from eyestereo.hdl.common.packed import unpack_word
from eyestereo.tools.models import cornerness as model
from eyestereo.tools.models import harris_window as window_model
from eyestereo.hdl.common.checks import (check_clock, check_distinct, check_frame, check_reset, check_signal,
                                         check_stream)

LATENCY = model.LATENCY


@block
def cornerness(clk, rst, sink, source, k, *, width: int = 352, height: int = 288):
    """Cornerness of every pixel from the window sums; a point operation, 6 pipeline stages.

    Stages (formats in :mod:`eyestereo.tools.models.cornerness`): the sums are cut to 17 bits (a, b, c, and
    the half trace t), so each of the 4 multipliers (a*b, c*c, k*t, (k*t >> 8)*t) takes operands that
    fit a MULT18X18's signed 18-bit inputs; det - 4 k t^2 is formed in 37 bits and shifted right by 13
    into the 20-bit output with saturation, which never triggers on the positive side for windows of
    Sobel gradients, so corners are never wrapped or clamped and keep their order.

    Ports:
        clk, rst: clock and synchronous active-high reset (control only).
        sink: ImageStream, 57 bits from ``harris_window`` (Sxy | Syy | Sxx); mono only (a stereo
            stream is refused).
        source: ImageStream, 20 bits: the cornerness, two's complement (units:
            :func:`eyestereo.tools.models.harris_mono.harris_float` / 2**21).
        k: input, 8 bits unsigned, ufix[8,8]: k = code / 256 (:func:`eyestereo.tools.models.harris_mono.k_code`);
            sampled every clock, change it between frames.

    Parameters:
        width, height: frame size (only checked: a point operation keeps no position).

    Latency: 6 clocks.

    Resources: 4 MULT18X18, adders and pipeline registers, no block RAM.
    """
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, width=window_model.OUT_BITS)
    check_stream("source", source, width=model.OUT.wl)
    check_signal("k", k, width=model.K.wl, signed=False)
    check_distinct(dict(source=source), dict(clk=clk, rst=rst, sink=sink, k=k))
    width, height = check_frame(width, height)

    S = model.STAGES
    sxx, syy = fx_signal(window_model.SUM_SQ), fx_signal(window_model.SUM_SQ)
    sxy = fx_signal(window_model.SUM_XY)
    a, b, c, t = fx_signal(S["a"]), fx_signal(S["b"]), fx_signal(S["c"]), fx_signal(S["t"])
    ab, cc, kt, t2 = fx_signal(S["ab"]), fx_signal(S["cc"]), fx_signal(S["kt"]), fx_signal(S["t"])
    det, kt8, t3 = fx_signal(S["det"]), fx_signal(S["kt8"]), fx_signal(S["t"])
    ktt, det4 = fx_signal(S["ktt"]), fx_signal(S["det"])
    cr = fx_signal(S["cr"])
    crs = Signal(intbv(0, min=S["cr"].lo >> model.OUT_SHIFT, max=(S["cr"].hi >> model.OUT_SHIFT) + 1))
    cout = fx_signal(model.OUT)
    shift, lo, hi, nb = model.OUT_SHIFT, model.OUT.lo, model.OUT.hi, model.OUT.wl

    # ktt is unsigned, det4 signed: stage 5 subtracts a signed copy (see signed_copy: MyHDL's Verilog
    # would otherwise compute det4 - 4 ktt unsigned and turn every negative det4 positive).
    ktt_s = signed_copy(ktt)
    trace = Signal(intbv(0, min=0, max=2 * window_model.SUM_SQ.hi + 1))

    # A sum of its own: VHDL adds in the operands' width (19 bits), which would wrap.
    @always_comb
    def add():
        trace.next = sxx + syy

    @always(clk.posedge)
    def pipeline():
        # 1: cut to 17 bits
        a.next = sxx >> 2
        b.next = syy >> 2
        c.next = sxy >> 2
        t.next = trace >> 3
        # 2: the three multipliers of the first rank
        ab.next = a * b
        cc.next = c * c
        kt.next = k * t
        t2.next = t
        # 3
        det.next = ab - cc
        kt8.next = kt >> 8
        t3.next = t2
        # 4: the fourth multiplier
        ktt.next = kt8 * t3
        det4.next = det
        # 5: trace^2 = (2t)^2 = 4 t^2
        cr.next = det4 - (ktt_s << 2)
        # 6
        source.data.next = cout[nb:]

    @always_comb
    def clamp():
        crs.next = cr >> shift

    @always_comb
    def saturate():
        if crs > hi:
            cout.next = hi
        elif crs < lo:
            cout.next = lo
        else:
            cout.next = crs

    insts = [unpack_word(sink.data, window_model.WORD, sxx=sxx, syy=syy, sxy=sxy), add, assign(ktt, ktt_s), pipeline, clamp, saturate]
    for s, d in ((sink.valid, source.valid), (sink.eol, source.eol), (sink.eof, source.eof)):
        insts.append(delay_rst(clk, rst, s, d, clocks=LATENCY))
    return insts
