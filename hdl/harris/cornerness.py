"""Harris cornerness c = det(G) - k trace(G)^2, fully pipelined, multiplier inputs <= 18 bits (thesis 6.2.3,
Fig. 6.16)."""

from myhdl import Signal, always, always_comb, always_seq, block, intbv

from eyestereo.hdl.common import delay_rst
from eyestereo.hdl.common.arith import signed_copy
from eyestereo.hdl.common.checks import (block_error, check_clock, check_distinct, check_frame, check_reset,
                                         check_signal, check_stream)
from eyestereo.hdl.common.fixed import fx_signal
from eyestereo.hdl.common.packed import unpack_word
from eyestereo.hdl.common.registers import assign
from eyestereo.hdl.streaming.window import check_share
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH
from eyestereo.tools.fixed import sfix
from eyestereo.tools.models import cornerness as model
from eyestereo.tools.models import harris_window as window_model

LATENCY = model.LATENCY


def multipliers(share: int = 1) -> int:
    """MULT18X18s: 4, or 2 when shared over 2 or 3 clocks (stereo streams)."""
    return 4 if share == 1 else 2


def latency(share: int = 1) -> int:
    """Clocks from a beat in to its cornerness out: 6 (:data:`LATENCY`), 5 when shared (stereo streams)."""
    return LATENCY if share == 1 else 5


@block
def cornerness(clk, rst, sink, source, k, k_right=None, *, width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT,
               share: int = 1):
    """Cornerness of every pixel from the window sums; a point operation, 6 pipeline stages.

    Stages (formats in :mod:`eyestereo.tools.models.cornerness`): the sums are cut to 17 bits (a, b, c, and
    the half trace t), so each of the 4 multipliers (a*b, c*c, k*t, (k*t >> 8)*t) takes operands that
    fit a MULT18X18's signed 18-bit inputs; det - 4 k t^2 is formed in 37 bits and shifted right by 13
    into the 20-bit output with saturation, which never triggers on the positive side for windows of
    Sobel gradients, so corners are never wrapped or clamped and keep their order.

    A stereo stream (left and right beat of each (x, y) in turn) goes through the same arithmetic, each
    beat with its camera's k (``k`` left, ``k_right`` right; same intermediate formats, so the same
    codes). share 1: the pipeline above, 4 multipliers. share 2 and 3 (beats at least that many clocks
    apart): two multipliers over two clocks, a*b with k*t, then c*c with (k t >> 8) * t (thesis Fig. 6.16:
    two multipliers instead of eight for two mono detectors); det - 4 k t^2 in one subtraction stage.
    Every multiplier reads registers only: the beat loads its operand registers (a, b and the camera's
    k), the first phase reloads them (c, c and k t >> 8, the latter straight from the product).

    Ports:
        clk, rst: clock and synchronous active-high reset (control only).
        sink: ImageStream, 57 bits from ``harris_window`` (Sxy | Syy | Sxx), mono or stereo.
        source: ImageStream of the sink's kind, 20 bits: the cornerness, two's complement (units:
            :func:`eyestereo.tools.models.harris_mono.harris_float` / 2**21).
        k: input, 8 bits unsigned, ufix[8,8]: k = code / 256 (:func:`eyestereo.tools.models.harris_mono.k_code`);
            sampled every clock, change it between frames. With a stereo stream, the left camera's.
        k_right: stereo streams only (and needed there; None for a mono one, else a ValueError): the
            right camera's k, as ``k``.

    Parameters:
        width, height: frame size (only checked: a point operation keeps no position).
        share: stereo streams only (1 for a mono one, else a ValueError): 1, 2 or 3.

    Latency: 6 clocks (:func:`latency`; share 2 and 3: 5 clocks).

    Resources: :func:`multipliers`: 4 MULT18X18 (share 1) or 2, adders and pipeline registers, no block RAM.
    """
    check_clock(clk)
    check_reset(rst)
    check_stream("sink", sink, width=window_model.OUT_BITS, stereo=None)
    check_stream("source", source, width=model.OUT.wl, stereo=sink.stereo)
    check_signal("k", k, width=model.K.wl, signed=False)
    controls = dict(k=k)
    if sink.stereo:
        if k_right is None:
            raise block_error("port k_right is missing: a stereo stream needs the right camera's k "
                              "(k is the left camera's)")
        check_signal("k_right", k_right, width=model.K.wl, signed=False)
        controls.update(k_right=k_right)
    elif k_right is not None:
        raise block_error("port k_right is for stereo streams: a mono stream has one camera, whose k is k")
    check_distinct(dict(source=source), dict(clk=clk, rst=rst, sink=sink, **controls))
    width, height = check_frame(width, height)
    share = check_share(share, sink)

    S = model.STAGES
    sxx, syy = fx_signal(window_model.SUM_SQ), fx_signal(window_model.SUM_SQ)
    sxy = fx_signal(window_model.SUM_XY)
    a, b, c, t = fx_signal(S["a"]), fx_signal(S["b"]), fx_signal(S["c"]), fx_signal(S["t"])
    ab, cc, kt = fx_signal(S["ab"]), fx_signal(S["cc"]), fx_signal(S["kt"])
    ktt = fx_signal(S["ktt"])
    cr = fx_signal(S["cr"])
    crs = Signal(intbv(0, min=S["cr"].lo >> model.OUT_SHIFT, max=(S["cr"].hi >> model.OUT_SHIFT) + 1))
    cout = fx_signal(model.OUT)
    shift, lo, hi, nb = model.OUT_SHIFT, model.OUT.lo, model.OUT.hi, model.OUT.wl

    # ktt is unsigned, det signed: the last subtraction takes a signed copy (see signed_copy: MyHDL's
    # Verilog would otherwise compute det - 4 ktt unsigned and turn every negative det positive).
    ktt_s = signed_copy(ktt)
    trace = Signal(intbv(0, min=0, max=2 * window_model.SUM_SQ.hi + 1))
    # (Every signal is made before the first instance: MyHDL declares them in the order it first sees them.)
    if share == 1:
        t2, t3 = fx_signal(S["t"]), fx_signal(S["t"])
        det, kt8, det4 = fx_signal(S["det"]), fx_signal(S["kt8"]), fx_signal(S["det"])
    else:
        # Stage 1 loads the multipliers' operand registers; phase 0 (the clock after it): a*b and k*t;
        # phase 1: c*c and (k*t >> 8) * t.
        p0 = Signal(bool(0))
        ma, mb = fx_signal(sfix(18)), fx_signal(sfix(18))
        m2a = Signal(intbv(0)[S["kt8"].wl:])
        m1 = Signal(intbv(0, min=-(1 << 34), max=1 << 34))
        m2 = Signal(intbv(0)[S["kt8"].wl + S["t"].wl:])
        det = fx_signal(S["det"])

    # A sum of its own: VHDL adds in the operands' width (19 bits), which would wrap.
    @always_comb
    def add():
        trace.next = sxx + syy

    insts = [unpack_word(sink.data, window_model.WORD, sxx=sxx, syy=syy, sxy=sxy), add, assign(ktt, ktt_s)]
    if share == 1:
        if sink.stereo:
            kq = Signal(intbv(0)[model.K.wl:])

            # The beat's camera's k, registered with stage 1 (the multipliers take it in stage 2).
            @always(clk.posedge)
            def select_k():
                if sink.cam:
                    kq.next = k_right
                else:
                    kq.next = k

            insts.append(select_k)
        else:
            kq = k

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
            kt.next = kq * t
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

        insts.append(pipeline)
    else:
        # Every multiplier reads registers only and writes one (a multiplexer of the phases in front of
        # it was the block's slowest path): the beat loads the operand registers (ma, mb = a, b; m2a =
        # the camera's k), phase 0 reloads them for phase 1 (ma, mb = c; m2a = k t >> 8 straight from
        # the product).
        # (shared multipliers take stereo streams only: k_right is there)
        @always(clk.posedge)
        def operands():
            if sink.valid:
                ma.next = sxx >> 2
                mb.next = syy >> 2
                if sink.cam:
                    m2a.next = k_right
                else:
                    m2a.next = k
                c.next = sxy >> 2
                t.next = trace >> 3
            elif p0:
                ma.next = c
                mb.next = c
                m2a.next = m2 >> 8

        @always_seq(clk.posedge, reset=rst)
        def phases():
            p0.next = sink.valid

        @always_comb
        def multiply():
            m1.next = ma * mb
            m2.next = m2a * t

        # ab is held through phase 1; cc and ktt load every clock, right in phase 1 (the clock the
        # subtraction reads them is the one after it).
        @always(clk.posedge)
        def products():
            if p0:
                ab.next = m1
            cc.next = m1
            ktt.next = m2

        @always_comb
        def difference():
            det.next = ab - cc

        @always(clk.posedge)
        def finish():
            cr.next = det - (ktt_s << 2)
            source.data.next = cout[nb:]

        insts += [operands, phases, multiply, products, difference, finish]

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

    insts += [clamp, saturate]
    flags = [(sink.valid, source.valid), (sink.eol, source.eol), (sink.eof, source.eof)]
    if sink.stereo:
        flags.append((sink.cam, source.cam))
    for s, d in flags:
        insts.append(delay_rst(clk, rst, s, d, clocks=latency(share)))
    return insts
