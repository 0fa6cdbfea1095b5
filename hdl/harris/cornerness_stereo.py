"""Stereo cornerness: det(G) - k trace(G)^2 for both cameras, each with its own k, multipliers time-shared."""

from myhdl import Signal, always, always_comb, always_seq, block, intbv

from eyestereo.hdl.common.checks import (check_clock, check_distinct, check_int, check_reset, check_signal,
                                         check_stream)
from eyestereo.hdl.common.fixed import fx_signal
from eyestereo.hdl.common.packed import unpack_word
from eyestereo.hdl.common.arith import signed_copy
from eyestereo.hdl.common.registers import assign, delay_rst
from eyestereo.tools.fixed import sfix
from eyestereo.tools.models import cornerness as model
from eyestereo.tools.models import harris_window as window_model


def multipliers(share: int) -> int:
    return 4 if share == 1 else 2


def latency(share: int) -> int:
    return model.LATENCY if share == 1 else 5


@block
def cornerness_stereo(clk, rst, sink, source, k_left, k_right, *, share: int = 1):
    """:func:`~eyestereo.hdl.harris.cornerness.cornerness` of a stereo stream, ``k_left`` or ``k_right`` by the beat's cam.

    The arithmetic and every intermediate format are the mono block's (so the results are the same
    codes). share 1: the mono pipeline, 4 multipliers. share 2 and 3: two multipliers over two clocks,
    a*b with k*t, then c*c with (k t >> 8) * t (thesis Fig. 6.16: two multipliers instead of eight for
    two mono detectors); det - 4 k t^2 is formed in one subtraction stage.

    Ports:
        clk, rst: clock and synchronous active-high reset (control only).
        sink: stereo ImageStream, 57 bits (window words); beats at least ``share`` clocks apart.
        source: stereo ImageStream, 20 bits (cornerness codes, two's complement).
        k_left, k_right: inputs, 8 bits, ufix[8,8]; each beat takes its camera's.

    Parameters:
        share: 1, 2 or 3.

    Latency: :func:`latency`: 6 clocks (share 1), 5 clocks (share 2, 3).

    Resources: 4 (share 1) or 2 MULT18X18, adders and registers, no block RAM.
    """
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, width=window_model.OUT_BITS, stereo=True)
    check_stream("source", source, width=model.OUT.wl, stereo=True)
    check_signal("k_left", k_left, width=model.K.wl, signed=False)
    check_signal("k_right", k_right, width=model.K.wl, signed=False)
    check_distinct(dict(source=source), dict(clk=clk, rst=rst, sink=sink, k_left=k_left, k_right=k_right))
    share = check_int("share", share, 1, 3)

    S = model.STAGES
    sxx, syy = fx_signal(window_model.SUM_SQ), fx_signal(window_model.SUM_SQ)
    sxy = fx_signal(window_model.SUM_XY)
    a, b, c, t = fx_signal(S["a"]), fx_signal(S["b"]), fx_signal(S["c"]), fx_signal(S["t"])
    kk = Signal(intbv(0)[model.K.wl:])
    ab, cc, kt = fx_signal(S["ab"]), fx_signal(S["cc"]), fx_signal(S["kt"])
    ktt = fx_signal(S["ktt"])
    # ktt is unsigned, det signed: the last stage subtracts a signed copy (MyHDL's Verilog would
    # otherwise compute det - 4 ktt unsigned and turn every negative det positive; README rule 5).
    ktt_s = signed_copy(ktt)
    cr = fx_signal(S["cr"])
    crs = Signal(intbv(0, min=S["cr"].lo >> model.OUT_SHIFT, max=(S["cr"].hi >> model.OUT_SHIFT) + 1))
    cout = fx_signal(model.OUT)
    shift, lo, hi, nb = model.OUT_SHIFT, model.OUT.lo, model.OUT.hi, model.OUT.wl
    trace = Signal(intbv(0, min=0, max=2 * window_model.SUM_SQ.hi + 1))

    @always_comb
    def add():
        trace.next = sxx + syy

    @always(clk.posedge)
    def stage1():
        a.next = sxx >> 2
        b.next = syy >> 2
        c.next = sxy >> 2
        t.next = trace >> 3
        if sink.cam:
            kk.next = k_right
        else:
            kk.next = k_left

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

    insts = [unpack_word(sink.data, window_model.WORD, sxx=sxx, syy=syy, sxy=sxy), add, assign(ktt, ktt_s), stage1, clamp, saturate]
    lat = latency(share)
    if share == 1:
        det, kt8, t2, t3 = fx_signal(S["det"]), fx_signal(S["kt8"]), fx_signal(S["t"]), fx_signal(S["t"])
        det4 = fx_signal(S["det"])

        @always(clk.posedge)
        def pipeline():
            ab.next = a * b
            cc.next = c * c
            kt.next = kk * t
            t2.next = t
            det.next = ab - cc
            kt8.next = kt >> 8
            t3.next = t2
            ktt.next = kt8 * t3
            det4.next = det
            cr.next = det4 - (ktt_s << 2)
            source.data.next = cout[nb:]

        insts.append(pipeline)
    else:
        # Phase 0 (the clock after stage 1): a*b and k*t; phase 1: c*c and (k*t >> 8) * t.
        p0, p1 = Signal(bool(0)), Signal(bool(0))
        ma, mb = fx_signal(sfix(18)), fx_signal(sfix(18))
        m2a = Signal(intbv(0)[S["kt8"].wl:])
        m1 = Signal(intbv(0, min=-(1 << 34), max=1 << 34))
        m2 = Signal(intbv(0)[S["kt8"].wl + S["t"].wl:])

        @always_seq(clk.posedge, reset=rst)
        def phases():
            p0.next = sink.valid
            p1.next = p0

        @always_comb
        def choose_operands():
            if p1:
                ma.next = c
                mb.next = c
                m2a.next = kt >> 8
            else:
                ma.next = a
                mb.next = b
                m2a.next = kk

        @always_comb
        def multiply():
            m1.next = ma * mb
            m2.next = m2a * t

        @always(clk.posedge)
        def products():
            if p0:
                ab.next = m1
                kt.next = m2
            if p1:
                cc.next = m1
                ktt.next = m2

        det = fx_signal(S["det"])

        @always_comb
        def difference():
            det.next = ab - cc

        @always(clk.posedge)
        def finish():
            cr.next = det - (ktt_s << 2)
            source.data.next = cout[nb:]

        insts += [phases, choose_operands, multiply, products, difference, finish]
    for s, d in ((sink.valid, source.valid), (sink.eol, source.eol), (sink.eof, source.eof), (sink.cam, source.cam)):
        insts.append(delay_rst(clk, rst, s, d, clocks=lat))
    return insts
