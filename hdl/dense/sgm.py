"""Semi-global matching of two census streams: a disparity code per left pixel, bit-exact (issue 28)."""

from myhdl import ConcatSignal, Signal, always, always_comb, block, concat, intbv

from eyestereo.hdl.common.checks import (block_error, check_choice, check_clock, check_distinct,
                                         check_frame, check_int, check_reset, check_signal, check_stream)
from eyestereo.hdl.common.arith import chunk_count, sum_tree
from eyestereo.hdl.common.registers import delay, like_signal
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH
from eyestereo.tools.models.census import WINDOWS, census_bits
from eyestereo.tools.models.sgm import D_RANGE, INVALID, PATHS, check_params

#: Pipeline stages, counted from a group's beat (stage 0): the path costs of the group are registered in
#: stage S_L, their sum in stage S_S.
S_L = 8
S_S = S_L + 2
#: The fewest clocks between two pixels: the previous pixel's path costs are read back from a small RAM
#: (written in stage S_L) by the same group of the next pixel.
SPACING_MIN = S_L + 1
#: Every memory of the block is named ``*_norw``: none is ever read at the address written in the same clock
#: (the rings are read a group ahead of their writes, the row and bank RAMs alternate between two rows, the
#: FIFO never reads its write slot), so Yosys may leave out its collision logic (hdl/flow/netlist.py).
#: Disparities computed per clock that the block offers (powers of two, dividing D).
PU_CHOICES = (1, 2, 4, 8, 16, 32)




def _like(sig):
    """A fresh Signal of ``sig``'s kind (a bool stays a bool)."""
    return Signal(bool(0)) if isinstance(sig.val, bool) else like_signal(sig)


def _clog2(n: int) -> int:
    return max(1, (n - 1).bit_length())


def tree_latency(n: int, per_stage: int = 2) -> int:
    """Clocks of a minimum over ``n`` values: a register after every ``per_stage`` comparator levels (two for
    the 7-bit path costs, one for the wider keys and sums), and at the end (at least one)."""
    levels = (n - 1).bit_length()
    return max(1, (levels + per_stage - 1) // per_stage)


def spacing(disparities: int, pu: int) -> int:
    """Clocks between two pixels: D / PU groups of PU disparities, then the left path's loop (its last
    group's minimum over the disparities, registered, feeds the next pixel's first group):
    ``max(D / PU + 1 + tree_latency(PU), SPACING_MIN)``."""
    return max(disparities // pu + 1 + tree_latency(pu), SPACING_MIN)


@block
def sgm(clk, rst, sink, source, p1, p2, uniqueness, lr_check, subpixel, overrun, *, disparities: int = 64,
        pu: int = 4, paths: int = 4, window: int = 5, path_bits: int = 7, sum_shift: int = 1, frac_bits: int = 4,
        fifo: int = 16, width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT):
    """Disparity codes of the left camera from the census words of both (:func:`eyestereo.tools.models.sgm.sgm`).

    Bit for bit the model: Hamming costs of D disparities, ``paths`` aggregation paths on the raster
    stream (from the left; 4 paths add the previous row's left, same and right neighbours), their sum
    with ``sum_shift`` bits dropped, winner take all with the uniqueness ratio, the right image's
    disparity along the diagonals of the same sums, the left-right check and the sub-pixel parabola
    (a restoring divider). The output is the model's uint16 code per pixel (1/16 px, 0xFFFF invalid).

    How: a pixel is taken from the input FIFO every :func:`spacing` clocks and computed in D / PU
    *groups* of PU disparities, one group per clock, through one pipeline: the right census words of
    the last D pixels in PU RAM copies (one read each per clock), the Hamming costs, per path the
    recurrence (the previous pixel's path costs from a RAM of D / PU words, the previous row's from a
    ring of ``width + 1`` pixels in block RAM, each path's minimum per pixel beside it), the sum. Winner
    take all runs over the groups; a second pass over the pixel's sums (kept in a small RAM) finds the
    best sum more than one disparity away and the two neighbours of the winner, during the next pixel.
    The right disparity: per PU bank the running minimum (sum, d) of each right pixel in a row RAM
    (read-modify-write, one per bank and clock). A row's left results wait in a row RAM; once the row is
    done they are *drained* at one pixel per clock, each looking up its right pixel's disparity (the PU
    banks' minima) for the left-right check. So the output runs one row behind and comes in bursts of
    ``width`` beats, one per clock.

    Ports:
        clk, rst: clock and synchronous active-high reset.
        sink: stereo ImageStream of census words (``window**2 - 1`` bits: the :func:`census` block's
            source): left beat then right beat of each pixel. A pixel pair may come at any rate the
            FIFO absorbs: on average at most one per :func:`spacing` clocks.
        source: mono ImageStream(16): the disparity code of each left pixel, in raster order, frames
            of ``width`` x ``height``; a reset token on the sink passes on (the next clock).
        p1, p2: 8-bit run-time penalties (the model needs P1 <= P2).
        uniqueness: 7-bit run-time percentage 0..99 (a larger value acts as 99).
        lr_check, subpixel: 1-bit run-time switches of the model's options.
        overrun: 1 (sticky until ``rst`` or a reset token) when a pixel pair found the FIFO full and was
            lost.

    Parameters:
        disparities: D, 16..128. pu: disparities per clock, a power of two dividing D with D / pu >= 2.
        paths: 2 or 4. window: the census window (5 or 7): the cost's saturation.
        path_bits, sum_shift, frac_bits: the model's widths (defaults the measured ones).
        fifo: depth of the input FIFO of pixel pairs (a power of two, 2..16384).
        width, height: frame size; width > D.

    Latency: a pixel every :func:`spacing` clocks (D = 64, PU = 4: 18; 54.8 frames/s of 352 x 288 at
    100 MHz). A row's codes start once its last pixel's result is written and follow one per clock: on a
    full 352 x 288 Tsukuba frame, 73 to 202 clocks after the row's last input pixel (the FIFO's backlog;
    docs/dense.md, "Full frames").

    Resources: per path after the first, a ring of ``2**ceil(log2(width + 1)) x 2**ceil(log2(D / PU))``
    words of ``PU x path_bits`` bits (a power of two, so that each block RAM holds a slice of every word:
    no address decoder, no output multiplexer) and a minimum per pixel; PU right-census copies of
    ``2**ceil(log2(D + 1))`` words; 2 x PU banks of ``2 x 2**ceil(log2 width)`` minima; the row RAM of
    left results; PU Hamming costs, ``paths x PU`` recurrence cells, comparator trees of PU. Measured
    (``synth --block sgm``, 352 x 288, D = 64, PU = 4, 4 paths): see docs/dense.md's blocks table; more
    block RAM than the Spartan-3E 500 and the ECP5-25 have (the dense option targets the ECP5-85).
    """
    check_clock(clk)
    check_reset(rst)
    window = check_choice("window", window, WINDOWS)
    nbits = census_bits(window)
    check_stream("sink", sink, width=nbits, stereo=True)
    check_stream("source", source, width=16, stereo=False)
    for name, sig, bits in (("p1", p1, 8), ("p2", p2, 8), ("uniqueness", uniqueness, 7), ("lr_check", lr_check, 1),
                            ("subpixel", subpixel, 1), ("overrun", overrun, 1)):
        check_signal(name, sig, width=bits)
    check_distinct(dict(source=source, overrun=overrun),
                   dict(clk=clk, rst=rst, sink=sink, p1=p1, p2=p2, uniqueness=uniqueness, lr_check=lr_check,
                        subpixel=subpixel))
    dn = check_int("disparities", disparities, *D_RANGE)
    pu = check_choice("pu", pu, PU_CHOICES)
    if dn % pu or dn // pu < 2:
        raise block_error(f"pu={pu} must divide disparities={dn} with at least 2 groups (D / pu >= 2)")
    paths = check_choice("paths", paths, PATHS)
    fifo = check_int("fifo", fifo, 2, 1 << 14)
    if fifo & (fifo - 1):
        raise block_error(f"parameter fifo={fifo} must be a power of two")
    width, height = check_frame(width, height)
    if width <= dn or height < 2:
        raise block_error(f"frame {width}x{height}: width must exceed the {dn} disparities and height be at least 2")
    path_bits = check_int("path_bits", path_bits, 4, 12)
    sum_shift = check_int("sum_shift", sum_shift, 0, 6)
    frac_bits = check_int("frac_bits", frac_bits, 0, 4)
    cmax = checked_widths(window, path_bits, sum_shift, frac_bits, dn, paths)
    pb, sat = path_bits, (1 << path_bits) - 1
    sb = ((paths * sat) >> sum_shift).bit_length()
    db = (dn - 1).bit_length()
    ng = dn // pu                              # groups per pixel
    gb = _clog2(ng)
    npw = 1 << gb                              # words per pixel in a path ring
    sp = spacing(dn, pu)
    tl = tree_latency(pu)
    rr = 1 << _clog2(dn + 1)                   # right census ring
    xw = _clog2(width)
    mm = max(rr, 1 << xw)                      # modulus of the running column index
    ring = width + 1

    insts = []

    # ------------------------------------------------------------------ input: pairs, token, FIFO
    cl_in = Signal(intbv(0)[nbits:])
    push = Signal(bool(0))
    din = Signal(intbv(0)[2 * nbits:])
    tok = Signal(bool(0))                      # registered reset token: clears the whole block
    clr = Signal(bool(0))

    @always(clk.posedge)
    def pairing():
        push.next = False
        tok.next = False
        if rst:
            cl_in.next = 0
        elif sink.valid:
            if sink.eof and not sink.eol:
                tok.next = True
            elif not sink.cam:
                cl_in.next = sink.data
            else:
                din.next = concat(cl_in, sink.data)
                push.next = True

    @always_comb
    def clear():
        clr.next = rst or tok

    fw = fifo.bit_length() - 1
    fifo_norw = [Signal(intbv(0)[2 * nbits:]) for _ in range(fifo)]
    fwp = Signal(intbv(0)[max(fw, 1):])
    frp = Signal(intbv(0)[max(fw, 1):])
    fcount = Signal(intbv(0, min=0, max=fifo + 1))
    fq = Signal(intbv(0)[2 * nbits:])
    pop = Signal(bool(0))
    ready = Signal(bool(0))
    gap = Signal(intbv(sp, min=0, max=sp + 1))  # clocks since the last pop, saturating at the spacing

    @always(clk.posedge)
    def fifo_write():
        if push and fcount != fifo:
            fifo_norw[fwp].next = din

    @always(clk.posedge)
    def fifo_read():
        if pop:
            fq.next = fifo_norw[frp]

    @always_comb
    def popper():
        ready.next = gap == sp
        pop.next = gap == sp and fcount != 0 and not clr

    @always(clk.posedge)
    def fifo_ctrl():
        if clr:
            fwp.next = 0
            frp.next = 0
            fcount.next = 0
            gap.next = sp
            overrun.next = False
        else:
            full = fcount == fifo
            if push and not full:
                fwp.next = (fwp + 1) % fifo
            if push and full and not pop:
                overrun.next = True
            if pop:
                frp.next = (frp + 1) % fifo
                gap.next = 1
            elif gap != sp:
                gap.next = gap + 1
            if push and not full and not pop:
                fcount.next = fcount + 1
            elif pop and not (push and not full):
                fcount.next = fcount - 1

    insts += [pairing, clear, fifo_write, fifo_read, popper, fifo_ctrl]

    # ------------------------------------------------------------------ sequencer: the groups' beats
    popd1 = Signal(bool(0))                    # the popped pair is in fq (the FIFO's block RAM output)
    popd = Signal(bool(0))                     # ... and in fq_r
    # fq registered once more before the census ring: the FIFO RAM's output straight into the lanes' census
    # RAMs was a slowest memory-clock path of the dense front end (5.8 ns of block RAM clock-to-out, then routing)
    fq_r = Signal(intbv(0)[2 * nbits:])
    px = Signal(intbv(0, min=0, max=width))    # the next pixel's position
    py = Signal(intbv(0, min=0, max=height))
    ppos = Signal(intbv(0, min=0, max=ring))   # its place in the previous rows' ring
    # and the places one and two on (the top and top-right neighbours' of the row before), kept as counters
    # so that no adder sits before the rings' read addresses
    ppos1 = Signal(intbv(1 % ring, min=0, max=ring))
    ppos2 = Signal(intbv(2 % ring, min=0, max=ring))
    pk = Signal(intbv(0)[2:])                  # its bank of the sums RAM
    # the beat (stage 0): a group g of pixel bx
    bv, bfirst, blast = (Signal(bool(0)) for _ in range(3))
    bg = Signal(intbv(0, min=0, max=ng))
    bd0 = Signal(intbv(0, min=0, max=dn))
    bx = Signal(intbv(0, min=0, max=width))
    bxm = Signal(intbv(0, min=0, max=mm))      # (x - d0) mod mm
    by = Signal(intbv(0, min=0, max=height))
    bpos = Signal(intbv(0, min=0, max=ring))
    bpos1 = Signal(intbv(0, min=0, max=ring))
    bpos2 = Signal(intbv(0, min=0, max=ring))
    bk = Signal(intbv(0)[2:])
    bx0, bxl, by0 = (Signal(bool(0)) for _ in range(3))

    @always(clk.posedge)
    def sequencer():
        if clr:
            popd1.next = False
            popd.next = False
            bv.next = False
            px.next = 0
            py.next = 0
            ppos.next = 0
            ppos1.next = 1 % ring
            ppos2.next = 2 % ring
            pk.next = 0
        else:
            popd1.next = pop
            popd.next = popd1
            if popd:
                bv.next = True
                bg.next = 0
                bd0.next = 0
                bfirst.next = True
                blast.next = ng == 1
                bx.next = px
                bxm.next = px
                by.next = py
                bpos.next = ppos
                bpos1.next = ppos1
                bpos2.next = ppos2
                bk.next = pk
                bx0.next = px == 0
                bxl.next = px == width - 1
                by0.next = py == 0
                pk.next = (pk + 1) % 4
                if ppos == ring - 1:
                    ppos.next = 0
                else:
                    ppos.next = ppos + 1
                if ppos1 == ring - 1:
                    ppos1.next = 0
                else:
                    ppos1.next = ppos1 + 1
                if ppos2 == ring - 1:
                    ppos2.next = 0
                else:
                    ppos2.next = ppos2 + 1
                if px == width - 1:
                    px.next = 0
                    if py == height - 1:
                        py.next = 0
                    else:
                        py.next = py + 1
                else:
                    px.next = px + 1
            elif bv:
                if blast:
                    bv.next = False
                else:
                    bg.next = bg + 1
                    bd0.next = bd0 + pu
                    bfirst.next = False
                    blast.next = bg == ng - 2
                    if bxm >= pu:
                        bxm.next = bxm - pu
                    else:
                        bxm.next = bxm + (mm - pu)

    insts.append(sequencer)

    # ------------------------------------------------------------------ right census ring, costs
    rb = rr.bit_length() - 1
    cwe = Signal(bool(0))
    cwa = Signal(intbv(0)[rb:])
    cwd = Signal(intbv(0)[nbits:])
    cl_pix = Signal(intbv(0)[nbits:])

    @always(clk.posedge)
    def fq_reg():
        fq_r.next = fq

    @always_comb
    def census_write():
        cwe.next = popd and not clr
        cwa.next = px % rr
        cwd.next = fq_r[nbits:]

    @always(clk.posedge)
    def left_word():
        if bv and bfirst:
            cl_pix.next = fq_r[2 * nbits:nbits]

    insts += [fq_reg, census_write, left_word]

    # candidates d0 + k <= x, per lane (stage 0), for the costs (stage 4) and the sums (stage S_S)
    cand = [Signal(bool(0)) for _ in range(pu)]
    costs = [Signal(intbv(0, min=0, max=cmax + 1)) for _ in range(pu)]
    for k in range(pu):
        insts.append(candidate(bx, bd0, cand[k], k=k))
    cand_s4 = ConcatSignal(*reversed(cand)) if pu > 1 else cand[0]
    cand4 = Signal(intbv(0)[len(cand_s4):])
    insts.append(delay(clk, cand_s4, cand4, clocks=4))
    for k in range(pu):
        xk = Signal(intbv(0, min=0, max=mm))
        insts.append(lane_counter(clk, popd, bv, blast, px, xk, k=k, pu=pu, mm=mm))
        insts.append(cost_lane(clk, cwe, cwa, cwd, xk, cl_pix, cand4, costs[k], k=k, pu=pu, rr=rr, mm=mm,
                               cmax=cmax))

    # ------------------------------------------------------------------ path costs
    from eyestereo.tools.models.sgm import DIRECTIONS
    dirs = DIRECTIONS[paths]
    first3 = _like(bfirst)
    insts.append(pipe(clk, clr, bfirst, first3, clocks=3))
    last3 = _like(blast)
    insts.append(pipe(clk, clr, blast, last3, clocks=3))
    v7 = _like(bv)
    insts.append(pipe(clk, clr, bv, v7, clocks=S_L))
    first7 = _like(bfirst)
    insts.append(pipe(clk, clr, bfirst, first7, clocks=S_L))
    last7 = _like(blast)
    insts.append(pipe(clk, clr, blast, last7, clocks=S_L))
    g7 = _like(bg)
    insts.append(pipe(clk, clr, bg, g7, clocks=S_L))
    pos7 = _like(bpos)
    insts.append(pipe(clk, clr, bpos, pos7, clocks=S_L))
    lpaths = []                                # per path: PU lanes of L (stage S_L)
    for dx, dy in dirs:
        lanes = [Signal(intbv(0)[pb:]) for _ in range(pu)]
        if dy == 0:
            start = bx0
        elif dx == -1:
            start = Signal(bool(0))
            insts.append(either(bx0, by0, start))
        elif dx == 0:
            start = by0
        else:
            start = Signal(bool(0))
            insts.append(either(bxl, by0, start))
        rpos = (bpos, bpos1, bpos2)[dx + 1]  # where this path's p - r sits in the ring
        insts.append(path(clk, clr, bv, bg, rpos, start, first3, last3, v7, first7, last7, g7, pos7, costs, lanes,
                          p1, p2, dx=dx, dy=dy, pu=pu, ng=ng, npw=npw, ring=ring, pb=pb, tl=tl))
        lpaths.append(lanes)

    # ------------------------------------------------------------------ sums, stage S_S
    sums = [Signal(intbv(0)[sb:]) for _ in range(pu)]
    for k in range(pu):
        insts.append(path_sum(clk, [lanes[k] for lanes in lpaths], sums[k], shift=sum_shift))
    v9 = _like(bv)
    insts.append(pipe(clk, clr, bv, v9, clocks=S_S))
    first9 = _like(bfirst)
    insts.append(pipe(clk, clr, bfirst, first9, clocks=S_S))
    last9 = _like(blast)
    insts.append(pipe(clk, clr, blast, last9, clocks=S_S))
    d09 = _like(bd0)
    insts.append(pipe(clk, clr, bd0, d09, clocks=S_S))
    cand9 = Signal(intbv(0)[len(cand_s4):])
    insts.append(delay(clk, cand_s4, cand9, clocks=S_S))
    k9 = _like(bk)
    insts.append(pipe(clk, clr, bk, k9, clocks=S_S))
    g9 = _like(bg)
    insts.append(pipe(clk, clr, bg, g9, clocks=S_S))
    x9 = _like(bx)
    insts.append(pipe(clk, clr, bx, x9, clocks=S_S))
    y9 = _like(by)
    insts.append(pipe(clk, clr, by, y9, clocks=S_S))
    yb = Signal(bool(0))

    @always_comb
    def row_bit():
        yb.next = y9[0]

    insts.append(row_bit)


    # the pixel's sums for the second pass: 4 banks x npw words of PU sums
    sums_word = ConcatSignal(*reversed(sums)) if pu > 1 else sums[0]
    smem_we = Signal(bool(0))
    smem_wa = Signal(intbv(0)[2 + gb:])

    @always_comb
    def sums_addr():
        smem_we.next = v9
        smem_wa.next = concat(k9, g9[gb:])

    insts.append(sums_addr)

    # right disparities: per bank k the running minimum key (sum, d) of right pixel x - d, d = k mod PU
    kb = sb + db
    xm7 = _like(bxm)
    insts.append(pipe(clk, clr, bxm, xm7, clocks=S_S - 3))
    y7b = Signal(bool(0))
    y7 = _like(by)
    insts.append(pipe(clk, clr, by, y7, clocks=S_S - 3))

    @always_comb
    def row_bit7():
        y7b.next = y7[0]

    insts.append(row_bit7)
    drain_addr = [Signal(intbv(0)[xw + 1:]) for _ in range(pu)]
    drain_q = [Signal(intbv(0)[kb:]) for _ in range(pu)]
    for k in range(pu):
        insts.append(right_bank(clk, y7b, xm7, v9, first9, cand9, sums[k], d09, drain_addr[k], drain_q[k], k=k, pu=pu,
                                mm=mm, xw=xw, db=db))

    # ------------------------------------------------------------------ winner take all, pass 1
    keys = [Signal(intbv(0)[kb + 1:]) for _ in range(pu)]
    for k in range(pu):
        insts.append(wta_key(sums[k], d09, cand9, keys[k], k=k, db=db, kb=kb))
    gbest = Signal(intbv(0)[kb + 1:])
    insts.append(min_tree(clk, keys, gbest, per_stage=1))
    tw = S_S + tree_latency(pu, 1)
    vw = _like(bv)
    insts.append(pipe(clk, clr, bv, vw, clocks=tw))
    firstw = _like(bfirst)
    insts.append(pipe(clk, clr, bfirst, firstw, clocks=tw))
    lastw = _like(blast)
    insts.append(pipe(clk, clr, blast, lastw, clocks=tw))
    x_w = _like(bx)
    insts.append(pipe(clk, clr, bx, x_w, clocks=tw))
    k_w = _like(bk)
    insts.append(pipe(clk, clr, bk, k_w, clocks=tw))
    yw = _like(by)
    insts.append(pipe(clk, clr, by, yw, clocks=tw))
    run = Signal(intbv(0)[kb + 1:])
    fin = Signal(intbv(0)[kb + 1:])
    fin_go = Signal(bool(0))
    fin_x = Signal(intbv(0, min=0, max=width))
    fin_y = Signal(intbv(0, min=0, max=height))
    fin_k = Signal(intbv(0)[2:])

    @always(clk.posedge)
    def pass1():
        fin_go.next = False
        if clr:
            pass
        elif vw:
            if firstw or gbest < run:
                run.next = gbest
                if lastw:
                    fin.next = gbest
            else:
                if lastw:
                    fin.next = run
            if lastw:
                fin_go.next = True
                fin_x.next = x_w
                fin_y.next = yw
                fin_k.next = k_w

    insts.append(pass1)

    # ------------------------------------------------------------------ pass 2: second best and neighbours
    res_go = Signal(bool(0))
    res_code = Signal(intbv(0)[16:])
    res_dl = Signal(intbv(0, min=0, max=dn))
    res_uv = Signal(bool(0))
    res_x = Signal(intbv(0, min=0, max=width))
    res_y = Signal(intbv(0, min=0, max=height))
    insts.append(second_pass(clk, clr, smem_we, smem_wa, sums_word, fin_go, fin, fin_x, fin_y, fin_k, uniqueness,
                             subpixel, res_go, res_code, res_dl, res_uv, res_x, res_y, pu=pu, ng=ng, gb=gb, sb=sb,
                             db=db, dn=dn, width=width, height=height, frac_bits=frac_bits))

    # ------------------------------------------------------------------ row of left results, the drain
    insts.append(drain(clk, clr, tok, res_go, res_code, res_dl, res_uv, res_x, res_y, drain_addr, drain_q,
                       lr_check, source, pu=pu, xw=xw, db=db, kb=kb, width=width, height=height))
    return insts


def checked_widths(window, path_bits, sum_shift, frac_bits, dn, paths) -> int:
    """The model's width checks as the block's (ValueError naming sgm); returns the cost saturation."""
    try:
        return check_params(disparities=dn, paths=paths, p1=0, p2=0, uniqueness=0, window=window, cost_bits=None,
                            path_bits=path_bits, sum_shift=sum_shift, frac_bits=frac_bits)
    except ValueError as e:
        raise block_error(str(e)) from None


@block
def pipe(clk, clr, din, dout, *, clocks: int):
    """``din`` delayed by ``clocks``: a flag through :func:`delay_clr`, a word through plain registers."""
    if isinstance(din.val, bool):
        return delay_clr(clk, clr, din, dout, clocks=clocks)
    return delay(clk, din, dout, clocks=clocks)


@block
def delay_clr(clk, clr, din, dout, *, clocks: int):
    """A 1-bit delay line whose every stage is cleared by ``clr`` (a reset token empties the pipeline)."""
    stages = [Signal(bool(0)) for _ in range(clocks - 1)] + [dout]
    chain = [din] + stages
    insts = []
    for a, b in zip(chain[:-1], chain[1:]):
        insts.append(clr_reg(clk, clr, a, b))
    return insts


@block
def clr_reg(clk, clr, d, q):
    @always(clk.posedge)
    def reg():
        if clr:
            q.next = False
        else:
            q.next = d

    return reg


@block
def either(a, b, out):
    @always_comb
    def logic():
        out.next = a or b

    return logic


@block
def candidate(x, d0, cand, *, k: int):
    """Disparity d0 + k is a candidate of pixel x: d0 + k <= x (else its right pixel is outside)."""

    @always_comb
    def logic():
        cand.next = d0 + k <= x

    return logic


@block
def lane_counter(clk, load, step, last, x, xk, *, k: int, pu: int, mm: int):
    """Lane k's right pixel ``(x - d0 - k) mod mm`` of the beat, as a counter beside the sequencer's: loaded
    with the pixel, then PU less per group."""

    @always(clk.posedge)
    def count():
        if load:
            if x >= k:
                xk.next = x - k
            else:
                xk.next = x + (mm - k)
        elif step and not last:
            if xk >= pu:
                xk.next = xk - pu
            else:
                xk.next = xk + (mm - pu)

    return count


@block
def cost_lane(clk, we, wa, wd, xm, cl, cand4, cost, *, k: int, pu: int, rr: int, mm: int, cmax: int):
    """Lane k: its copy of the right census ring, read at (x - d0 - k) mod rr (stage 0: ``xm``, the lane's own
    counter, so no subtraction comes before the RAM's address), registered twice
    (stages 1, 2), the Hamming distance to the left word in 3-bit chunks (stage 3) and their sum (stage 4),
    saturated at cmax, and cmax for a non-candidate (stage 5)."""
    nbits = len(wd)
    census_norw = [Signal(intbv(0)[nbits:]) for _ in range(rr)]
    rb = rr.bit_length() - 1
    ra = Signal(intbv(0)[rb:])
    q = Signal(intbv(0)[nbits:])
    qr = Signal(intbv(0)[nbits:])
    # 3-bit chunks: each count bit a function of 6 inputs (two LUT levels), so that the register after the RAM's
    # (qr) feeds shallow logic and make synth's bram_regs moves it into the block RAM's output register; 6-bit
    # chunks were deeper, qr stayed a slice flip-flop, and RAM -> qr (5.8 ns of clock-to-out, then the route)
    # was the dense front end's slowest memory-clock path (109.8 MHz)
    chunk = 3
    nch = (nbits + chunk - 1) // chunk
    total = Signal(intbv(0, min=0, max=nbits + 1))
    ok4 = Signal(bool(0))

    @always_comb
    def addr():
        ra.next = xm[rb:]

    @always(clk.posedge)
    def ram():
        if we:
            census_norw[wa].next = wd
        q.next = census_norw[ra]

    @always(clk.posedge)
    def out_reg():
        qr.next = q

    insts = [addr, ram, out_reg]
    counts = []
    for c in range(nch):
        n = Signal(intbv(0, min=0, max=chunk + 1))
        insts.append(chunk_count(clk, cl, qr, n, lo=c * chunk, hi=min(nbits, (c + 1) * chunk)))
        counts.append(n)
    insts.append(sum_tree(clk, counts, total))

    @always_comb
    def cand_bit():
        ok4.next = cand4[k]

    @always(clk.posedge)
    def saturate():
        if not ok4 or total > cmax:
            cost.next = cmax
        else:
            cost.next = total

    return insts + [cand_bit, saturate]


@block
def path(clk, clr, bv, bg, rpos, start, first3, last3, v7, first7, last7, g7, pos7, costs, lanes, p1, p2, *,
         dx: int, dy: int, pu: int, ng: int, npw: int, ring: int, pb: int, tl: int):
    """One aggregation path: the previous values of p - r (stage 0 read, stages 1-4 registered), the
    recurrence of each lane (stages 3-7), the path's minimum per pixel (the tree over the lanes, then
    the run over the groups) for the next use as ``minL(p - r)``."""
    ww = pu * pb
    word = ConcatSignal(*reversed(lanes)) if pu > 1 else lanes[0]
    q = Signal(intbv(0)[ww:])
    w2, w3, w4 = (Signal(intbv(0)[ww:]) for _ in range(3))
    insts = []
    # the minimum of p - r, at stage S_L - 1 (the recurrence's last)
    mloop = Signal(intbv(0)[pb:])
    gmin = Signal(intbv(0)[pb:])
    if dy != 0:
        # a row path's minimum is read a row later: a register after every comparator level costs no spacing
        # (two levels in a clock were the dense front end's slowest memory-clock path after placement)
        tl = tree_latency(pu, 1)
        insts.append(min_tree(clk, list(lanes), gmin, per_stage=1))
    else:
        insts.append(min_tree(clk, list(lanes), gmin))  # the loop's: its latency is in the spacing
    vw = Signal(bool(0))
    insts.append(delay_clr(clk, clr, v7, vw, clocks=tl))
    firstw = Signal(bool(0))
    insts.append(delay_clr(clk, clr, first7, firstw, clocks=tl))
    lastw = Signal(bool(0))
    insts.append(delay_clr(clk, clr, last7, lastw, clocks=tl))
    run = Signal(intbv(0)[pb:])
    fin = Signal(intbv(0)[pb:])
    start3 = Signal(bool(0))
    insts.append(delay_clr(clk, clr, start, start3, clocks=3))
    start6 = Signal(bool(0))
    insts.append(delay_clr(clk, clr, start, start6, clocks=S_L - 1))

    @always(clk.posedge)
    def minimum():
        if vw:
            if firstw or gmin < run:
                run.next = gmin
                if lastw:
                    fin.next = gmin
            elif lastw:
                fin.next = run

    insts.append(minimum)
    if dy == 0:
        # the previous pixel's path costs: npw words, read by group (stage 0), written by group (stage S_L)
        prev_norw = [Signal(intbv(0)[ww:]) for _ in range(npw)]

        @always(clk.posedge)
        def left_ram():
            if v7:
                prev_norw[g7].next = word
            q.next = prev_norw[bg]

        @always_comb
        def left_min():
            if start6:
                mloop.next = 0
            else:
                mloop.next = fin

        insts += [left_ram, left_min]
    else:
        # the previous row's: a ring of width + 1 pixels (read at the pixel's own place for the top-left
        # neighbour, one and two places on for the top and top-right), written where read (read first)
        # a power of two of words (the place's bits, then the group's): each block RAM then holds a slice of
        # every word at the full address (ECP5: 8K x 2), with no address decoder before the RAMs and no
        # multiplexer after them -- both were the slowest paths when the ring took only ring x npw words
        # _oreg: the register after it (w2) goes into the block RAM's output register although the last lane's
        # "+ P1" reads it (flow/bram_regs.py): as a slice flip-flop, RAM -> w2 was the dense front end's slowest
        # memory-clock path (105.9 MHz)
        ring_oreg_norw = [Signal(intbv(0)[ww:]) for _ in range(1 << (len(pos7) + len(g7)))]
        mins_norw = [Signal(intbv(0)[pb:]) for _ in range(ring)]
        mq, mr = Signal(intbv(0)[pb:]), Signal(intbv(0)[pb:])
        posw = _like(pos7)
        insts.append(delay(clk, pos7, posw, clocks=tl + 1))
        mwe = Signal(bool(0))
        mwd = Signal(intbv(0)[pb:])

        @always(clk.posedge)
        def ring_ram():
            if v7:
                ring_oreg_norw[concat(pos7, g7)].next = word
            q.next = ring_oreg_norw[concat(rpos, bg)]

        @always(clk.posedge)
        def min_write():
            # registered: the pixel's minimum is written a clock after it is known (its next reader is a
            # row away), so the comparison does not end at the block RAM
            mwe.next = vw and lastw and not clr
            if firstw or gmin < run:
                mwd.next = gmin
            else:
                mwd.next = run

        @always(clk.posedge)
        def min_ram():
            if mwe:
                mins_norw[posw].next = mwd
            mq.next = mins_norw[rpos]

        @always(clk.posedge)
        def min_regs():
            mr.next = mq

        insts += [ring_ram, min_write, min_ram, min_regs]
        mr6 = _like(mr)
        insts.append(delay(clk, mr, mr6, clocks=S_L - 3))

        @always_comb
        def top_min():
            if start6:
                mloop.next = 0
            else:
                mloop.next = mr6

        insts.append(top_min)

    @always(clk.posedge)
    def words():
        w2.next = q
        w3.next = w2
        w4.next = w3

    insts.append(words)
    for k in range(pu):
        own = w3(k * pb + pb, k * pb)
        prv = w3(k * pb, (k - 1) * pb) if k > 0 else w4(ww, ww - pb)
        nxt = w3(k * pb + 2 * pb, k * pb + pb) if k < pu - 1 else w2(pb, 0)
        insts.append(path_cell(clk, own, prv, nxt, start3, first3, last3, costs[k], mloop, p1, p2, lanes[k], pb=pb,
                               at_first=k == 0, at_last=k == pu - 1))
    return insts


@block
def path_cell(clk, own, prv, nxt, start3, first3, last3, cost5, m7, p1, p2, lane, *, pb: int, at_first: bool,
              at_last: bool):
    """One disparity of one path: ``L = C + min(Lp(d), Lp(d -+ 1) + P1, minLp + P2) - minLp``, saturated,
    as ``min(C + m1 - minLp, min(C + P2, sat))`` with ``m1 = min(Lp(d), Lp(d -+ 1) + P1)``: only the last
    stage needs the previous pixel's minimum, which is what keeps the left path's loop short.

    Stages (one carry chain each, at most two side by side): 3 the neighbours plus P1; 4 the minimum of
    three (three comparisons at once); 5 ``av = C + m1`` and ``bs = min(C + P2, sat)``; 6 ``e = av - bs``
    and whether it is negative; 7 (the loop's stage) ``L = av - minLp`` where ``e < minLp``, else ``bs``:
    ``av - minLp < bs`` without a second chain after the subtraction. ``lane`` is registered in S_L."""
    sat = (1 << pb) - 1
    big = sat + 256
    own4, a4, b4 = (Signal(intbv(0, min=0, max=big)) for _ in range(3))
    m1 = Signal(intbv(0)[pb:])
    cmx = cost5.max
    av = Signal(intbv(0, min=0, max=cmx + sat + 1))
    bs = Signal(intbv(0)[pb:])
    av7 = Signal(intbv(0, min=0, max=cmx + sat + 1))
    bs7 = Signal(intbv(0)[pb:])
    e7 = Signal(intbv(0, min=0, max=cmx + sat + 1))
    neg7 = Signal(bool(0))

    @always(clk.posedge)
    def stage3():
        # sums in variables of their full width: a comparison of a sum would be cut to its operands'
        if start3:
            own4.next = 0
            a4.next = big - 1
            b4.next = big - 1
        else:
            own4.next = own
            if at_first and first3:
                a4.next = big - 1          # d - 1 < 0: left out of the minimum
            else:
                a4.next = prv + p1
            if at_last and last3:
                b4.next = big - 1          # d + 1 > D - 1: left out
            else:
                b4.next = nxt + p1

    @always(clk.posedge)
    def stage4():
        # the smallest of three, the first of equal ones: three comparisons side by side, then a choice
        oa = own4 <= a4
        ob = own4 <= b4
        ab = a4 <= b4
        if oa and ob:
            m1.next = own4
        elif ab:
            m1.next = a4
        else:
            m1.next = b4

    @always(clk.posedge)
    def stage5():
        av.next = cost5 + m1
        c = intbv(0, min=0, max=cmx + 256)
        c[:] = cost5 + p2
        if c > sat:
            bs.next = sat
        else:
            bs.next = c

    @always(clk.posedge)
    def stage6():
        av7.next = av
        bs7.next = bs
        if av >= bs:
            e7.next = av - bs
            neg7.next = False
        else:
            e7.next = 0
            neg7.next = True

    @always(clk.posedge)
    def stage7():
        # av - minLp < bs  <=>  av - bs < minLp; av >= minLp on every beat (m1 >= minLp), the test keeps
        # idle clocks' garbage in range
        t = intbv(0, min=0, max=av7.max)
        if av7 >= m7:
            t[:] = av7 - m7
        if neg7 or e7 < m7:
            lane.next = t
        else:
            lane.next = bs7

    return stage3, stage4, stage5, stage6, stage7


@block
def path_sum(clk, ls, out, *, shift: int):
    """The sum of the paths' lane (stage S_L + 1: pairs, stage S_S: the total with ``shift`` bits dropped)."""
    a, b = ls[0], ls[1]
    c, d = (ls[2], ls[3]) if len(ls) == 4 else (None, None)
    pbw = len(a) + 1
    s1, s2 = Signal(intbv(0)[pbw:]), Signal(intbv(0)[pbw:])

    @always(clk.posedge)
    def total():
        t = intbv(0)[pbw + 1:]
        t[:] = s1 + s2  # in a variable of the sum's width: an expression would keep the operands'
        out.next = t >> shift

    if c is None:
        @always(clk.posedge)
        def pair():
            s1.next = a + b

        return pair, total

    @always(clk.posedge)
    def pairs():
        s1.next = a + b
        s2.next = c + d

    return pairs, total


@block
def min_tree(clk, keys, out, *, per_stage: int = 2):
    """``out`` = the smallest of ``keys`` (the first of equal ones), a register after every ``per_stage``
    levels of comparators and at the end: :func:`tree_latency` clocks."""
    insts = []
    level = list(keys)
    depth = 0
    while len(level) > 1:
        nxt = []
        for i in range(0, len(level) - 1, 2):
            m = Signal(intbv(0)[len(out):])
            insts.append(min2(level[i], level[i + 1], m))
            nxt.append(m)
        if len(level) % 2:
            nxt.append(level[-1])
        depth += 1
        if depth % per_stage == 0 and len(nxt) > 1:
            regd = [Signal(intbv(0)[len(out):]) for _ in nxt]
            insts += [delay(clk, a, b, clocks=1) for a, b in zip(nxt, regd)]
            nxt = regd
        level = nxt
    insts.append(delay(clk, level[0], out, clocks=1))
    return insts


@block
def min2(a, b, m):
    @always_comb
    def logic():
        if b < a:
            m.next = b
        else:
            m.next = a

    return logic


@block
def right_bank(clk, yb7, xm7, v9, first9, cand9, s9, d09, drain_addr, drain_q, *, k: int, pu: int, mm: int,
               xw: int, db: int):
    """Bank k of the right disparities: the running minimum key (sum, d) of right pixel xr over the
    disparities d = k mod PU (candidates of left pixels xr + d), row by row (two rows: the drain reads one
    while the next is computed). Read at stage S_S - 2, registered twice, compared and written at stage S_S; a
    second copy_norw takes the same writes for the drain's reads."""
    sb = len(s9)
    kb = sb + db
    depth = 2 << xw
    rmw_norw = [Signal(intbv(0)[kb:]) for _ in range(depth)]
    copy_norw = [Signal(intbv(0)[kb:]) for _ in range(depth)]
    ra = Signal(intbv(0)[xw + 1:])
    wa = Signal(intbv(0)[xw + 1:])
    q, qr = Signal(intbv(0)[kb:]), Signal(intbv(0)[kb:])
    we = Signal(bool(0))
    key = Signal(intbv(0)[kb:])
    insts = []

    @always(clk.posedge)
    def addr():
        # from the stage before the read: the subtraction ends in a register, not at the RAM
        xr = intbv(0, min=0, max=mm)
        if xm7 >= k:
            xr[:] = xm7 - k
        else:
            xr[:] = xm7 + (mm - k)
        ra.next = concat(yb7, xr[xw:])

    insts.append(addr)
    wa9 = _like(ra)
    insts.append(delay(clk, ra, wa9, clocks=2))

    @always(clk.posedge)
    def read():
        q.next = rmw_norw[ra]
        qr.next = q

    @always_comb
    def update():
        d = intbv(0)[db:]
        d[:] = d09 + k
        kk = intbv(0)[kb:]
        kk[:] = concat(s9, d)
        key.next = kk
        we.next = v9 and cand9[k] and (first9 or kk < qr)
        wa.next = wa9

    @always(clk.posedge)
    def write():
        if we:
            rmw_norw[wa].next = key

    @always(clk.posedge)
    def write_copy():
        if we:
            copy_norw[wa].next = key
        drain_q.next = copy_norw[drain_addr]

    insts += [read, update, write, write_copy]
    return insts


@block
def wta_key(s9, d09, cand9, key, *, k: int, db: int, kb: int):
    """Lane k's key for the winner: (sum, d) so that equal sums go to the smaller d; all ones (larger than
    any key) for a non-candidate."""
    none = (1 << (kb + 1)) - 1

    @always_comb
    def logic():
        d = intbv(0)[db:]
        d[:] = d09 + k
        if cand9[k]:
            key.next = concat(False, s9, d)
        else:
            key.next = none

    return logic


@block
def second_pass(clk, clr, we, wa, wd, go, fin, fx, fy, fk, uniqueness, subpixel, res_go, res_code, res_dl, res_uv,
                res_x, res_y, *, pu: int, ng: int, gb: int, sb: int, db: int, dn: int, width: int, height: int,
                frac_bits: int):
    """The pixel's sums again (from a RAM of 4 pixels x D / PU words), during the next pixel: the best sum
    more than one disparity from the winner dL among the candidates, and the sums at dL - 1 and dL + 1;
    then the uniqueness test, the sub-pixel parabola (a restoring divider, one step per clock) and the code."""
    ww = pu * sb
    sums_norw = [Signal(intbv(0)[ww:]) for _ in range(4 << gb)]
    ra = Signal(intbv(0)[2 + gb:])
    q, qr = Signal(intbv(0)[ww:]), Signal(intbv(0)[ww:])
    sv = Signal(bool(0))
    sh = Signal(intbv(0, min=0, max=ng))
    sk = Signal(intbv(0)[2:])
    sdl = Signal(intbv(0, min=0, max=dn))
    sbest = Signal(intbv(0)[sb:])
    sx = Signal(intbv(0, min=0, max=width))
    sy = Signal(intbv(0, min=0, max=height))
    sdb = Signal(intbv(0, min=0, max=dn))      # the first disparity of the word being read
    sdlp = Signal(intbv(0, min=0, max=dn + 1))
    sdlm1, sdlm2 = Signal(intbv(0, min=0, max=dn)), Signal(intbv(0, min=0, max=dn))
    has1, has2 = Signal(bool(0)), Signal(bool(0))
    insts = []

    @always(clk.posedge)
    def sums_ram():
        if we:
            sums_norw[wa].next = wd
        q.next = sums_norw[ra]
        qr.next = q

    @always_comb
    def read_addr():
        ra.next = concat(sk, sh[gb:])

    @always(clk.posedge)
    def scanner():
        if clr:
            sv.next = False
            sh.next = 0
        elif go:
            sv.next = True
            sh.next = 0
            sdb.next = 0
            sk.next = fk
            sdl.next = fin[db:]
            sbest.next = fin[sb + db:db]
            sx.next = fx
            sy.next = fy
            # the winner's neighbourhood as registers, so that each lane only compares
            w = intbv(0)[db:]
            w[:] = fin[db:]
            sdlp.next = w + 1
            has1.next = w >= 1
            has2.next = w >= 2
            if w >= 1:
                sdlm1.next = w - 1
            else:
                sdlm1.next = 0
            if w >= 2:
                sdlm2.next = w - 2
            else:
                sdlm2.next = 0
        elif sv:
            if sh == ng - 1:
                sv.next = False
            else:
                sh.next = sh + 1
                sdb.next = sdb + pu

    insts += [sums_ram, read_addr, scanner]
    sv2 = Signal(bool(0))
    insts.append(delay_clr(clk, clr, sv, sv2, clocks=2))
    sh2 = _like(sh)
    insts.append(delay(clk, sh, sh2, clocks=2))
    first2 = Signal(bool(0))
    last2 = Signal(bool(0))

    @always_comb
    def ends():
        first2.next = sh2 == 0
        last2.next = sh2 == ng - 1

    insts.append(ends)
    none = (1 << (sb + 1)) - 1
    far = [Signal(intbv(0)[sb + 1:]) for _ in range(pu)]
    cm_l = [Signal(intbv(0)[sb:]) for _ in range(pu)]
    cp_l = [Signal(intbv(0)[sb:]) for _ in range(pu)]
    sdb1 = _like(sdb)
    insts.append(delay(clk, sdb, sdb1, clocks=1))
    for i in range(pu):
        di = Signal(intbv(0, min=0, max=dn))
        insts.append(lane_disparity(clk, sdb1, di, i=i))
        insts.append(second_lane(clk, qr, di, sdlp, sdlm1, sdlm2, has1, has2, sx, far[i], cm_l[i], cp_l[i], i=i,
                                 sb=sb))
    sec_g = Signal(intbv(0)[sb + 1:])
    insts.append(min_tree(clk, far, sec_g, per_stage=1))
    tl = tree_latency(pu, 1)
    cm_g, cp_g = Signal(intbv(0)[sb:]), Signal(intbv(0)[sb:])
    insts.append(or_reduce(clk, cm_l, cm_g, clocks=tl))
    insts.append(or_reduce(clk, cp_l, cp_g, clocks=tl))
    va = Signal(bool(0))
    insts.append(delay_clr(clk, clr, sv2, va, clocks=1 + tl))
    fa = Signal(bool(0))
    insts.append(delay_clr(clk, clr, first2, fa, clocks=1 + tl))
    la = Signal(bool(0))
    insts.append(delay_clr(clk, clr, last2, la, clocks=1 + tl))
    sec_r = Signal(intbv(none)[sb + 1:])
    cm_r, cp_r = Signal(intbv(0)[sb:]), Signal(intbv(0)[sb:])
    done = Signal(bool(0))
    e_sec = Signal(intbv(0)[sb + 1:])
    e_cm, e_cp = Signal(intbv(0)[sb:]), Signal(intbv(0)[sb:])
    e_dl = Signal(intbv(0, min=0, max=dn))
    e_best = Signal(intbv(0)[sb:])
    e_x = Signal(intbv(0, min=0, max=width))
    e_y = Signal(intbv(0, min=0, max=height))
    # the pixel's values, kept for the results once its last word is read (the next pixel may begin)
    k_dl = Signal(intbv(0, min=0, max=dn))
    k_best = Signal(intbv(0)[sb:])
    k_x = Signal(intbv(0, min=0, max=width))
    k_y = Signal(intbv(0, min=0, max=height))

    @always(clk.posedge)
    def keep():
        if sv and sh == ng - 1:
            k_dl.next = sdl
            k_best.next = sbest
            k_x.next = sx
            k_y.next = sy

    @always(clk.posedge)
    def runs():
        done.next = False
        if clr:
            pass
        elif va:
            s = intbv(0)[sb + 1:]
            a = intbv(0)[sb:]
            b = intbv(0)[sb:]
            if fa:
                s[:] = sec_g
                a[:] = cm_g
                b[:] = cp_g
            else:
                if sec_g < sec_r:
                    s[:] = sec_g
                else:
                    s[:] = sec_r
                a[:] = cm_r | cm_g
                b[:] = cp_r | cp_g
            sec_r.next = s
            cm_r.next = a
            cp_r.next = b
            if la:
                done.next = True
                e_sec.next = s
                e_cm.next = a
                e_cp.next = b
                e_dl.next = k_dl
                e_best.next = k_best
                e_x.next = k_x
                e_y.next = k_y

    insts += [keep, runs]
    insts.append(results(clk, clr, done, e_sec, e_cm, e_cp, e_dl, e_best, e_x, e_y, uniqueness, subpixel, res_go,
                         res_code, res_dl, res_uv, res_x, res_y, dn=dn, frac_bits=frac_bits))
    return insts


@block
def lane_disparity(clk, base, d, *, i: int):
    """Lane i's disparity of the word read, registered: ``base + i``."""

    @always(clk.posedge)
    def logic():
        d.next = base + i

    return logic


@block
def second_lane(clk, qr, d, sdlp, sdlm1, sdlm2, has1, has2, sx, far, cm, cp, *, i: int, sb: int):
    """Lane i of a word of sums (disparity ``d``): its sum for the second best (a candidate, |d - dL| > 1;
    else all ones), and for dL - 1 and dL + 1 (else 0), registered. The winner's neighbours come as
    registers (dL + 1, dL - 1, dL - 2 and whether the last two exist): comparisons only."""
    none = (1 << (sb + 1)) - 1

    @always(clk.posedge)
    def logic():
        s = qr[(i + 1) * sb:i * sb]
        if d <= sx and (d > sdlp or (has2 and d <= sdlm2)):
            far.next = s
        else:
            far.next = none
        if has1 and d == sdlm1:
            cm.next = s
        else:
            cm.next = 0
        if d == sdlp and d <= sx:
            cp.next = s
        else:
            cp.next = 0

    return logic


@block
def or_reduce(clk, words, out, *, clocks: int):
    """The OR of ``words`` (at most one is not 0), registered, then delayed to ``clocks`` clocks."""
    acc = Signal(intbv(0)[len(out):])
    n = len(words)
    insts = []
    level = list(words)
    while len(level) > 1:
        nxt = []
        for j in range(0, len(level) - 1, 2):
            o = Signal(intbv(0)[len(out):])
            insts.append(or2(level[j], level[j + 1], o))
            nxt.append(o)
        if len(level) % 2:
            nxt.append(level[-1])
        level = nxt
    del n
    insts.append(delay(clk, level[0], acc, clocks=1))
    if clocks > 1:
        insts.append(delay(clk, acc, out, clocks=clocks - 1))
    else:
        insts.append(assign_word(acc, out))
    return insts


@block
def or2(a, b, o):
    @always_comb
    def logic():
        o.next = a | b

    return logic


@block
def assign_word(a, b):
    @always_comb
    def logic():
        b.next = a

    return logic


@block
def results(clk, clr, go, sec, cm, cp, dl, best, x, y, uniqueness, subpixel, res_go, res_code, res_dl, res_uv,
            res_x, res_y, *, dn: int, frac_bits: int):
    """Uniqueness (``100 best <= (100 - u) second``), the parabola's offset ``num / (2 den)`` by a restoring
    divider of ``frac_bits + 1`` steps, and the code ``16 dL + q 2**(4 - frac_bits)``; at most one carry
    chain per stage (two side by side)."""
    sb = len(best)
    none = (1 << (sb + 1)) - 1
    fb = frac_bits
    um = Signal(intbv(0)[7:])
    # stage 1: the terms
    v1, found, neg, near_ok = (Signal(bool(0)) for _ in range(4))
    both = Signal(intbv(0)[sb + 1:])
    twice = Signal(intbv(0)[sb + 1:])
    an = Signal(intbv(0)[sb + 1:])
    p64 = Signal(intbv(0)[sb + 7:])
    b4 = Signal(intbv(0)[sb + 7:])
    pun1 = Signal(intbv(0)[sb + 7:])
    dl1 = Signal(intbv(0, min=0, max=dn))
    x1 = Signal(intbv(0, min=0, max=x.max))
    y1 = Signal(intbv(0, min=0, max=y.max))

    @always(clk.posedge)
    def factor():
        if uniqueness > 99:
            um.next = 1
        else:
            um.next = 100 - uniqueness

    @always(clk.posedge)
    def stage1():
        v1.next = go and not clr
        b = intbv(0)[sb + 7:]
        b[:] = best
        p64.next = (b << 6) + (b << 5)
        b4.next = b << 2
        found.next = sec != none
        pun1.next = um * sec[sb:]
        both.next = cm + cp
        tw = intbv(0)[sb + 1:]
        tw[:] = best
        twice.next = tw << 1
        if cm < cp:
            neg.next = True
            an.next = cp - cm
        else:
            neg.next = False
            an.next = cm - cp
        # 1 <= dL <= min(D - 1, x) - 1, as comparisons without a sum
        near_ok.next = subpixel and dl >= 1 and dl < dn - 1 and dl < x
        dl1.next = dl
        x1.next = x
        y1.next = y

    # stage 2: 100 best, the parabola's denominator
    v2, found2, neg2, inner2 = (Signal(bool(0)) for _ in range(4))
    p100 = Signal(intbv(0)[sb + 7:])
    pun = Signal(intbv(0)[sb + 7:])
    an2 = Signal(intbv(0)[sb + 1:])
    den = Signal(intbv(0)[sb + 2:])

    @always(clk.posedge)
    def stage2():
        v2.next = v1 and not clr
        p100.next = p64 + b4
        pun.next = pun1
        found2.next = found
        neg2.next = neg
        an2.next = an
        if both > twice:
            den.next = both - twice
            inner2.next = near_ok
        else:
            den.next = 0
            inner2.next = False

    # stage 3: the uniqueness verdict; the divider's dividend
    v3 = Signal(bool(0))
    uv3 = Signal(bool(0))
    rem = [Signal(intbv(0)[sb + 2 + fb:]) for _ in range(fb + 2)]
    quo = [Signal(intbv(0)[fb + 1:]) for _ in range(fb + 2)]
    rem0, quo0, quof = rem[0], quo[0], quo[fb + 1]

    @always(clk.posedge)
    def stage3():
        v3.next = v2 and not clr
        uv3.next = not found2 or p100 <= pun
        rem0.next = an2 << fb
        quo0.next = 0

    insts = [factor, stage1, stage2, stage3]
    for j in range(fb + 1):
        dj = _like(den)
        insts.append(delay(clk, den, dj, clocks=1 + j))
        insts.append(div_step(clk, rem[j], quo[j], dj, rem[j + 1], quo[j + 1], shift=fb - j))
    lat = fb + 1
    vq = Signal(bool(0))
    insts.append(delay_clr(clk, clr, v3, vq, clocks=lat))
    uvq = Signal(bool(0))
    insts.append(delay_clr(clk, clr, uv3, uvq, clocks=lat))
    negq = Signal(bool(0))
    insts.append(delay_clr(clk, clr, neg2, negq, clocks=lat + 1))
    innerq = Signal(bool(0))
    insts.append(delay_clr(clk, clr, inner2, innerq, clocks=lat + 1))
    dlq = _like(dl1)
    insts.append(delay(clk, dl1, dlq, clocks=lat + 2))
    xq = _like(x1)
    insts.append(delay(clk, x1, xq, clocks=lat + 2))
    yq = _like(y1)
    insts.append(delay(clk, y1, yq, clocks=lat + 2))

    @always(clk.posedge)
    def code():
        res_go.next = vq and not clr
        half = intbv(0)[16:]
        half[:] = quof + 1
        half[:] = half >> 1
        half[:] = half << (4 - fb)
        base = intbv(0)[16:]
        base[:] = dlq
        base[:] = base << 4
        if innerq:
            if negq:
                res_code.next = base - half
            else:
                res_code.next = base + half
        else:
            res_code.next = base
        res_dl.next = dlq
        res_uv.next = uvq
        res_x.next = xq
        res_y.next = yq

    insts.append(code)
    return insts


@block
def div_step(clk, rem_in, quo_in, den, rem_out, quo_out, *, shift: int):
    """One step of the restoring divider: subtract ``den << shift`` when it fits, the quotient bit."""

    bit = 1 << shift

    @always(clk.posedge)
    def step():
        dd = intbv(0)[len(rem_in) + 1:]
        dd[:] = den
        dd[:] = dd << shift  # the divisor's place, shifted in the remainder's width (not in den's)
        if rem_in >= dd:
            rem_out.next = rem_in - dd
            quo_out.next = quo_in | bit
        else:
            rem_out.next = rem_in
            quo_out.next = quo_in

    return step


@block
def drain(clk, clr, tok, go, code, dl, uv, x, y, drain_addr, drain_q, lr_check, source, *, pu: int, xw: int,
          db: int, kb: int, width: int, height: int):
    """The row RAM of left results (two rows) and the drain: once a row's last result is written, its
    pixels go out one per clock, each checked against its right pixel's disparity (the banks' minimum)."""
    rw = 1 + db + 16
    rows_norw = [Signal(intbv(0)[rw:]) for _ in range(2 << xw)]
    wa = Signal(intbv(0)[xw + 1:])
    wd = Signal(intbv(0)[rw:])
    dv = Signal(bool(0))
    dx = Signal(intbv(0, min=0, max=width))
    drow = Signal(bool(0))
    dlast = Signal(bool(0))                    # the drained row is the frame's last
    ra = Signal(intbv(0)[xw + 1:])
    q, qr = Signal(intbv(0)[rw:]), Signal(intbv(0)[rw:])
    insts = []

    @always_comb
    def addrs():
        wa.next = concat(y[0], x[xw:])
        wd.next = concat(uv, dl[db:], code)
        ra.next = concat(drow, dx[xw:])

    @always(clk.posedge)
    def row_ram():
        if go:
            rows_norw[wa].next = wd
        q.next = rows_norw[ra]
        qr.next = q

    @always(clk.posedge)
    def counter():
        if clr:
            dv.next = False
            dx.next = 0
        elif go and x == width - 1:
            dv.next = True
            dx.next = 0
            drow.next = y[0]
            dlast.next = y == height - 1
        elif dv:
            if dx == width - 1:
                dv.next = False
            else:
                dx.next = dx + 1

    insts += [addrs, row_ram, counter]
    v2 = Signal(bool(0))
    insts.append(delay_clr(clk, clr, dv, v2, clocks=2))
    eol_now, eof_now = Signal(bool(0)), Signal(bool(0))

    @always_comb
    def flags():
        eol_now.next = dx == width - 1
        eof_now.next = dx == width - 1 and dlast

    insts.append(flags)
    eol2 = Signal(bool(0))
    insts.append(delay_clr(clk, clr, eol_now, eol2, clocks=2))
    eof2 = Signal(bool(0))
    insts.append(delay_clr(clk, clr, eof_now, eof2, clocks=2))
    x2 = _like(dx)
    insts.append(delay(clk, dx, x2, clocks=2))
    row2 = Signal(bool(0))
    insts.append(delay_clr(clk, clr, drow, row2, clocks=2))
    xr3 = Signal(intbv(0, min=0, max=width))
    row3 = Signal(bool(0))

    @always(clk.posedge)
    def right_pixel():
        # the right pixel x - dL, registered before it addresses the banks
        row3.next = row2
        if x2 >= qr[16 + db:16]:
            xr3.next = x2 - qr[16 + db:16]
        else:
            xr3.next = 0

    insts.append(right_pixel)
    for k in range(pu):
        insts.append(bank_addr(row3, xr3, drain_addr[k], xw=xw))
    # drain_q holds at stage 4; masked into a register (stage 5), then reduced one level per clock
    tl = tree_latency(pu, 1)
    xr4 = _like(xr3)
    insts.append(delay(clk, xr3, xr4, clocks=1))
    keys = []
    for k in range(pu):
        mk = Signal(intbv(0)[kb + 1:])
        insts.append(bank_key(clk, drain_q[k], xr4, mk, k=k, width=width))
        keys.append(mk)
    best = Signal(intbv(0)[kb + 1:])
    insts.append(min_tree(clk, keys, best, per_stage=1))
    n = 3 + tl
    vq = Signal(bool(0))
    insts.append(delay_clr(clk, clr, v2, vq, clocks=n))
    eolq = Signal(bool(0))
    insts.append(delay_clr(clk, clr, eol2, eolq, clocks=n))
    eofq = Signal(bool(0))
    insts.append(delay_clr(clk, clr, eof2, eofq, clocks=n))
    wq = _like(qr)
    insts.append(delay(clk, qr, wq, clocks=n))

    @always(clk.posedge)
    def output():
        if tok:
            source.valid.next = True
            source.eol.next = False
            source.eof.next = True
            source.data.next = 0
        elif clr:
            source.valid.next = False
        else:
            source.valid.next = vq
            source.eol.next = eolq
            source.eof.next = eofq
            dr = intbv(0)[db:]
            dr[:] = best[db:]
            dlq = intbv(0)[db:]
            dlq[:] = wq[16 + db:16]
            ok = True
            up1 = intbv(0)[db + 1:]
            up1[:] = dlq + 1
            ur1 = intbv(0)[db + 1:]
            ur1[:] = dr + 1
            if lr_check:
                if dr > up1 or dlq > ur1:
                    ok = False
            if wq[16 + db] and ok:
                source.data.next = wq[16:]
            else:
                source.data.next = INVALID

    insts.append(output)
    return insts


@block
def bank_addr(row, xr, addr, *, xw: int):
    @always_comb
    def logic():
        addr.next = concat(row, xr[xw:])

    return logic


@block
def bank_key(clk, q, xr, key, *, k: int, width: int):
    """A bank's minimum for right pixel xr, or all ones where no disparity of the bank reached it
    (xr + k beyond the row: the entry is of an older row), registered."""
    none = (1 << len(key)) - 1
    last = width - 1 - k                       # xr + k <= width - 1, as a comparison with a constant

    @always(clk.posedge)
    def logic():
        if xr <= last:
            key.next = q
        else:
            key.next = none

    return logic
