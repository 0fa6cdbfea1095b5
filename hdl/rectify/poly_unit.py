"""The merged, fully pipelined calculation unit of the rectification polynomials (thesis 4.2.1, Fig. 4.5)."""

from __future__ import annotations

from myhdl import Signal, always, always_comb, always_seq, block, intbv

from eyestereo.hdl.common.checks import block_error, check_clock, check_distinct, check_int, check_reset, check_signal
from eyestereo.hdl.common.quantize import fmt_signal, fx_add, fx_mul, fx_mul_reg, fx_resize
from eyestereo.hdl.common.registers import assign
from eyestereo.hdl.rectify.calibration import calibration_param
from eyestereo.tools.fixed import Fmt, ufix
from eyestereo.tools.models import poly_unit as model

LATENCY = model.LATENCY

__all__ = ["LATENCY", "CoefPort", "poly_unit"]


class CoefPort:
    """Run-time coefficient write port of :func:`poly_unit` / the coordinate warper (ports ``coef_*``).

    ``we`` (1 bit), ``addr`` (6 bits), ``data`` (the widest of q1..q10): on a rising edge with ``we`` high,
    coefficient p_i (i = ``addr // 4 + 1``, 1..10) of polynomial ``addr % 4`` (0 left_x, 1 left_y,
    2 right_x, 3 right_y) takes the low ``wl_i`` bits of ``data`` (its two's complement code in q_i).
    Addresses 40..63 are ignored. A write changes the coefficient for every coordinate that enters the
    unit from the next clock on; load a calibration between frames (40 writes, one per clock:
    :func:`eyestereo.tools.models.poly_unit.register_writes`). The formats stay those of the elaboration.

    Parameters:
        data_bits: width of ``data`` (:func:`eyestereo.tools.models.poly_unit.coef_data_bits`).
    """

    ADDR_BITS = 6

    def __init__(self, data_bits: int):
        self.data_bits = check_int("data_bits", data_bits, 1, 64)
        self.we = Signal(bool(0))
        self.addr = Signal(intbv(0)[self.ADDR_BITS:])
        self.data = Signal(intbv(0)[self.data_bits:])

    def fields(self) -> list[str]:
        return ["we", "addr", "data"]


@block
def coef_rom(index, out, codes: tuple[int, ...]):
    """``out`` = ``codes[index]`` (a 4-entry constant table: one coefficient of the four polynomials)."""

    @always_comb
    def read():
        out.next = codes[index]

    return read


@block
def coef_ram(clk, index, out, coef, number: int, codes: tuple[int, ...]):
    """A coefficient memory: written through ``coef`` at addresses 4 * number + 0..3, read by ``index``
    (asynchronous read); starts with ``codes``. It is 16 words deep (12 never used): the depth of a
    Spartan-3E LUT-RAM (RAM16X1S), so synthesis maps it to one LUT-RAM per bit instead of flip-flops."""
    wl = len(out)
    mem = [Signal(intbv(c)[wl:]) for c in codes] + [Signal(intbv(0)[wl:]) for _ in range(12)]
    word = Signal(intbv(0)[wl:])
    slot = Signal(intbv(0)[4:])
    raddr = Signal(intbv(0)[4:])
    hit = Signal(bool(0))

    @always_comb
    def decode():
        word.next = coef.data[wl:]
        slot.next = coef.addr[2:]
        raddr.next = index
        hit.next = coef.we and coef.addr[6:2] == number

    @always(clk.posedge)
    def write():
        if hit:
            mem[slot].next = word

    @always_comb
    def read():
        out.next = mem[raddr]

    return decode, write, read


@block
def low2(sel, index):
    @always_comb
    def comb():
        index.next = sel[2:]

    return comb


@block
def poly_unit(clk, rst, enable, x, y, select_coord, coord, out_of_range, select_coord_out, coef=None, *,
              quantizers=None, frac: int | None = model.DEFAULT_FRAC, source_width: int | None = None,
              source_height: int | None = None):
    """Four degree-3 polynomials in one 9-stage pipeline with 9 multipliers: one coordinate per clock.

    Evaluates ``p1 + y(p3 + p6 x + y(p5 + p8 y + p10 x)) + x(p2 + x(p4 + p7 x + p9 y))`` bit for bit as
    the toolbox's float-to-fixed conversion defines it (26 quantizers, floor and wrap, numbered as
    :mod:`eyestereo.tools.rectify.ffc` does; :func:`eyestereo.tools.rectify.ffc.fixed_stages_codes`),
    for the polynomial that ``select_coord`` names, then checks the full-precision result against the camera
    image (out of range: below 0, or above width-2 / height-2) and cuts it to ``frac`` fraction bits
    (:mod:`eyestereo.tools.models.poly_unit`). The formats and the coefficients come from a
    ``quantizers.json`` at elaboration; with ``coef`` the coefficients live in LUT-RAM instead and can be
    reloaded at run time in the same formats.

    Pipeline (every register takes its input only when ``enable`` is high)::

        stage  registers                                        coefficients (of the polynomial in flight)
        A      X = q25(x), Y = q26(y), select_coord             p8 p10 p7 p9 registered here
        B      q11 = p8 Y, q12 = p10 X, q13 = p7 X, q14 = p9 Y  p6 registered here
        C      q20 = p5 + q11 + q12, q21 = p4 + q13 + q14       p5 p4 into the adders
        D      q15 = q20 Y, q16 = p6 X, q17 = q21 X
        E      q22 = q15 + p3 + q16, q23 = q17 + p2             p3 p2 into the adders
        F      partial products of q22 Y and q23 X              (one per 18x18 multiplier)
        G      q18 = q22 Y, q19 = q23 X (the partial products added)
        H      q24 = p1 + q18 + q19                             p1 into the adder
        I      coord = q24 cut to frac bits, out_of_range, select_coord_out

    The multipliers' coefficients are chosen by the select code one stage ahead and registered, so every
    multiplier takes both operands straight from registers; the addends p1..p5 are chosen in the stage
    that adds them, where the 4-entry table and the adder's first level share LUTs.

    Ports:
        clk, rst: clock; synchronous active-high reset (clears the valid bits of the pipeline only).
        enable: in, 1 bit: the pipeline advances on rising edges where it is high; low freezes every
            register (the outputs hold).
        x: in, bits(width - 1) bits, the rectified column 0..width-1 (quantized by q25 inside).
        y: in, bits(height - 1) bits, the rectified row 0..height-1 (q26).
        select_coord: in, 3 bits (thesis Table 4.3): bit 2 valid, bit 1 right camera, bit 0 y coordinate:
            100 left X, 101 left Y, 110 right X, 111 right Y; 0xx: no coordinate (a bubble).
        coord: out, bits(max(source_width, source_height) - 1) + frac bits: floor(v * 2**frac) of the
            polynomial value v, unsigned, modulo 2**len (meaningful when in range).
        out_of_range: out, 1 bit: v < 0, or v > source_width - 2 (x) / source_height - 2 (y), decided
            on the full-precision q24 code.
        select_coord_out: out, 3 bits: the select code of the coordinate at the output (valid bit included).
        coef: optional :class:`CoefPort` (ports ``coef_we``, ``coef_addr``, ``coef_data``): run-time
            coefficients, initialised with the elaboration's codes where the conversion keeps initial
            values (else write all 40 before use).

    Parameters:
        quantizers: the calibration: a ``quantizers.json`` path or document, a spec of
            :func:`eyestereo.tools.rectify.calibrations.load` (default ``"rig"``: the synthetic rig,
            352x288) or a :class:`~eyestereo.tools.models.poly_unit.Calibration`.
        frac: fraction bits of ``coord`` (0..16). Default ``None``: q24's own fraction length (5 for the
            synthetic rig, 6 for the OpenCV calibration at 640x480), which the interpolation study in
            docs/rectifier.md picks: fewer bits add image error, more bits add only zeros.
        source_width, source_height: the camera images the coordinates point into (default: the
            document's ``source_width``/``source_height``, else its rectified size).

    Latency: 9 clocks (9 enabled clocks): a coordinate presented at the input in clock t is at the
    output in clock t + 9 when ``enable`` stays high. (The thesis's unit has 8 stages; the last products
    take two here, issue 23: with the synthetic rig q22 has 19 bits, so q22 * Y is two hardware
    multipliers and an adder, too slow for one 110 MHz clock in the whole front end.)

    Resources: 9 multipliers (MULT18X18 where the merged formats keep both operands within 18 signed
    bits; the synthetic rig's q18 = q22 * Y has a 19-bit operand: two, their partial products registered
    and added in the next stage), the adders, pipeline registers for
    X, Y, select and the coefficients (4-entry constant tables, or LUT-RAM with ``coef``).
    """
    check_clock(clk)
    check_reset(rst)
    cal = calibration_param(quantizers, source_width, source_height)
    frac = model.resolve_frac(cal, None if frac is None else check_int("frac", frac, 0, model.MAX_FRAC))
    fm = cal.formats
    xbits, ybits = model.int_bits(cal.width), model.int_bits(cal.height)
    nb = model.coord_bits(cal, frac)
    check_signal("enable", enable, width=1)
    check_signal("x", x, width=xbits, signed=False)
    check_signal("y", y, width=ybits, signed=False)
    check_signal("select_coord", select_coord, width=3, signed=False)
    check_signal("coord", coord, width=nb, signed=False)
    check_signal("out_of_range", out_of_range, width=1)
    check_signal("select_coord_out", select_coord_out, width=3, signed=False)
    check_distinct(dict(coord=coord, out_of_range=out_of_range, select_coord_out=select_coord_out),
                   dict(clk=clk, rst=rst, enable=enable, x=x, y=y, select_coord=select_coord))
    if coef is not None:
        if not isinstance(coef, CoefPort):
            raise block_error(f"port coef must be a CoefPort or None, got {type(coef).__name__}")
        if coef.data_bits != model.coef_data_bits(fm):
            raise block_error(f"port coef must carry {model.coef_data_bits(fm)} data bits (the widest of "
                              f"q1..q10), got {coef.data_bits}")

    def q(n: int) -> Fmt:
        return fm[n - 1]

    insts = []

    # --- select pipeline (valid bits reset) and the coefficient index of each stage
    sels = {s: Signal(intbv(0)[3:]) for s in "ABCDEFGH"}
    idx = {s: Signal(intbv(0)[2:]) for s in ("in", "A", "B", "D", "G")}
    insts.append(low2(select_coord, idx["in"]))
    for s in "ABDG":
        insts.append(low2(sels[s], idx[s]))
    sa, sb, sc, sd, se, sf, sg, sh = (sels[s] for s in "ABCDEFGH")

    @always_seq(clk.posedge, reset=rst)
    def select_pipe():
        if enable:
            sa.next = select_coord
            sb.next = sa
            sc.next = sb
            sd.next = sc
            se.next = sd
            sf.next = se
            sg.next = sf
            sh.next = sg
            select_coord_out.next = sh

    insts.append(select_pipe)

    # --- coefficients: p_i of the four polynomials, chosen by the select code one stage ahead
    # Multiplier operands are registered (chosen one stage ahead), so each multiplier takes both operands
    # from registers; the addends of the sums are chosen in their own stage and go straight into the
    # adder, where the table and the adder's first level share LUTs.
    chooser = {8: "in", 10: "in", 7: "in", 9: "in", 6: "B", 5: "B", 4: "B", 3: "D", 2: "D", 1: "G"}
    registered = (8, 10, 7, 9, 6)
    cbits, creg = {}, {}
    for i, where in chooser.items():
        f = q(i)
        codes = tuple(cal.codes[k][i - 1] & ((1 << f.wl) - 1) for k in range(4))
        # Starts with the table's entry 0, where every index starts: in MyHDL's Verilog the table is an
        # ``always @(index)`` block, which (SystemVerilog semantics, Icarus -g2012) never runs while the
        # index keeps the value of its declaration, so the output would keep its own declared value
        # (GHDL and Verilator evaluate every combinational process once at time 0).
        cbits[i] = Signal(intbv(codes[0])[f.wl:])
        creg[i] = fmt_signal(f)
        if i not in registered:
            insts.append(assign(cbits[i], creg[i]))  # reinterpretation only
        if coef is None:
            insts.append(coef_rom(idx[where], cbits[i], codes))
        else:
            insts.append(coef_ram(clk, idx[where], cbits[i], coef, i - 1, codes))
    c1, c2, c3, c4, c5, c6, c7, c8, c9, c10 = (creg[i] for i in range(1, 11))
    b1, b2, _, _, _, b6, b7, b8, b9, b10 = (cbits[i] for i in range(1, 11))  # b3..b5 feed no shift-add

    # --- stage A inputs: the counters quantized by q25 / q26
    xq, yq = fmt_signal(q(25)), fmt_signal(q(26))
    insts += [fx_resize(x, ufix(xbits, 0), xq, q(25)), fx_resize(y, ufix(ybits, 0), yq, q(26))]
    xa, ya, xb, yb, xc, yc, xd, yd, xe, ye = (fmt_signal(q(25 + k % 2)) for k in range(10))

    # --- the levelized operations (combinational), each into its quantizer's format
    node = {n: fmt_signal(q(n)) for n in range(11, 25)}  # combinational results
    reg = {n: fmt_signal(q(n)) for n in range(11, 25)}  # their stage registers
    insts += [
        fx_mul(c8, q(8), ya, q(26), node[11], q(11)),
        fx_mul(c10, q(10), xa, q(25), node[12], q(12)),
        fx_mul(c7, q(7), xa, q(25), node[13], q(13)),
        fx_mul(c9, q(9), ya, q(26), node[14], q(14)),
        fx_add([(c5, q(5)), (reg[11], q(11)), (reg[12], q(12))], node[20], q(20)),
        fx_add([(c4, q(4)), (reg[13], q(13)), (reg[14], q(14))], node[21], q(21)),
        fx_mul(reg[20], q(20), yc, q(26), node[15], q(15)),
        fx_mul(c6, q(6), xc, q(25), node[16], q(16)),
        fx_mul(reg[21], q(21), xc, q(25), node[17], q(17)),
        fx_add([(reg[15], q(15)), (c3, q(3)), (reg[16], q(16))], node[22], q(22)),
        fx_add([(reg[17], q(17)), (c2, q(2))], node[23], q(23)),
        # registered partial products (stage F), their sums cut into q18 / q19 in stage G
        fx_mul_reg(clk, enable, reg[22], q(22), ye, q(26), node[18], q(18)),
        fx_mul_reg(clk, enable, reg[23], q(23), xe, q(25), node[19], q(19)),
        fx_add([(c1, q(1)), (reg[18], q(18)), (reg[19], q(19))], node[24], q(24)),
    ]
    n11, n12, n13, n14, n15, n16, n17, n18, n19, n20, n21, n22, n23, n24 = (node[n] for n in range(11, 25))
    r11, r12, r13, r14, r15, r16, r17, r18, r19, r20, r21, r22, r23, r24 = (reg[n] for n in range(11, 25))

    # --- stage H: range check on the full-precision q24, cut to frac bits
    f24 = q(24)
    lim_x = model.range_limit(f24, cal.source_width)
    lim_y = model.range_limit(f24, cal.source_height)
    cut = Signal(intbv(0)[nb:])
    insts.append(fx_resize(r24, f24, cut, ufix(nb, frac)))
    oor = Signal(bool(0))
    if f24.signed:
        @always_comb
        def range_check():
            if r24 < 0:
                oor.next = 1
            elif sh[0]:
                oor.next = r24 > lim_y
            else:
                oor.next = r24 > lim_x
    else:
        @always_comb
        def range_check():
            if sh[0]:
                oor.next = r24 > lim_y
            else:
                oor.next = r24 > lim_x
    insts.append(range_check)

    # Coefficient tables hand over unsigned bits; the registers hold the formats' codes.
    @always(clk.posedge)
    def stages():
        if enable:
            # A
            xa.next = xq
            ya.next = yq
            c8.next = b8
            c10.next = b10
            c7.next = b7
            c9.next = b9
            # B
            r11.next = n11
            r12.next = n12
            r13.next = n13
            r14.next = n14
            xb.next = xa
            yb.next = ya
            # C
            r20.next = n20
            r21.next = n21
            xc.next = xb
            yc.next = yb
            c6.next = b6
            # D
            r15.next = n15
            r16.next = n16
            r17.next = n17
            xd.next = xc
            yd.next = yc
            # E
            r22.next = n22
            r23.next = n23
            xe.next = xd
            ye.next = yd
            # F: the partial products of q18 and q19 (inside fx_mul_reg)
            # G
            r18.next = n18
            r19.next = n19
            # H
            r24.next = n24
            # I
            coord.next = cut
            out_of_range.next = oor

    insts.append(stages)
    return insts
