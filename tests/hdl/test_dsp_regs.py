"""hdl/flow/dsp_regs.py: flip-flops into the MULT18X18D's registers, on hand-made Yosys JSON netlists."""

import copy

from eyestereo.hdl.flow.dsp_regs import pack_dsp_registers

CLK, CE, RST = 2, 3, 4


def _ff(d, q, *, ce="1 ", lsr="0"):
    conn = dict(CLK=[CLK], LSR=[lsr], DI=[d], Q=[q])
    if ce.strip() != "1":
        conn["CE"] = [CE]
    return dict(type="TRELLIS_FF", parameters=dict(CEMUX=ce, CLKMUX="CLK", GSR="DISABLED", LSRMUX="LSR",
                                                    REGSET="RESET"),
                attributes={}, port_directions=dict(CLK="input", LSR="input", CE="input", DI="input", Q="output"),
                connections=conn)


def _design(*, ce="1 ", lsr="0", a_extra_load=False, p_extra_load=False, const_one=False):
    """A 2-bit x 2-bit product: FFs a0 a1 b0 b1 -> DSP -> FFs on P0..P3; D nets 10..13, Q nets 20..23,
    P nets 30..33, product FF outputs 40..43 (read by a LUT)."""
    cells = {}
    for i in range(4):
        cells[f"in{i}"] = _ff(10 + i, 20 + i, ce=ce, lsr=lsr)
        cells[f"out{i}"] = _ff(30 + i, 40 + i, ce=ce, lsr=lsr)
    conn = {f"A{i}": ["0"] for i in range(18)} | {f"B{i}": ["0"] for i in range(18)}
    conn.update(A0=[20], A1=[21], B0=[22], B1=[23])
    if const_one:
        conn["B5"] = ["1"]
    conn.update({f"P{i}": [30 + i] if i < 4 else [100 + i] for i in range(36)})
    dirs = {k: "input" for k in conn if k[0] in "AB"} | {f"P{i}": "output" for i in range(36)}
    cells["mul"] = dict(type="MULT18X18D", parameters={}, attributes={}, port_directions=dirs, connections=conn)
    cells["use"] = dict(type="LUT4", parameters=dict(INIT="1" * 16), attributes={},
                        port_directions=dict(A="input", B="input", C="input", D="input", Z="output"),
                        connections=dict(A=[40], B=[41], C=[42], D=[43] if not a_extra_load else [20], Z=[60]))
    if p_extra_load:
        cells["use"]["connections"]["D"] = [31]
    ports = dict(clk=dict(direction="input", bits=[CLK]), ce=dict(direction="input", bits=[CE]),
                 rst=dict(direction="input", bits=[RST]), y=dict(direction="output", bits=[60]))
    return dict(modules=dict(top=dict(attributes={}, ports=ports, cells=cells, netnames={})))


def test_operand_and_product_registers_move_into_the_multiplier():
    n = _design()
    st = pack_dsp_registers(n, "top")
    assert st == dict(dsps=1, input_regs=1, output_regs=1, ffs_removed=8, inverters=0)
    cells = n["modules"]["top"]["cells"]
    mul = cells["mul"]
    assert set(cells) == {"mul", "use"}
    c, p = mul["connections"], mul["parameters"]
    assert (c["A0"], c["A1"], c["B0"], c["B1"]) == ([10], [11], [12], [13])  # the FFs' D nets
    assert [c[f"P{i}"] for i in range(4)] == [[40], [41], [42], [43]]  # the product FFs' Q nets
    assert p["REG_INPUTA_CLK"] == p["REG_INPUTB_CLK"] == p["REG_OUTPUT_CLK"] == "CLK0" and c["CLK0"] == [CLK]
    assert p["REG_INPUTA_CE"] == "CE3" and c["CE3"] == ["1"]  # always loading
    assert c["RST0"] == ["0"] and mul["port_directions"]["CE3"] == "input"


def test_enables_are_kept_and_an_inverted_enable_gets_a_lut():
    n = _design(ce="CE")
    pack_dsp_registers(n, "top")
    mul = n["modules"]["top"]["cells"]["mul"]
    assert mul["parameters"]["REG_INPUTA_CE"] == "CE0" and mul["connections"]["CE0"] == [CE]
    n = _design(ce="INV")
    st = pack_dsp_registers(n, "top")
    cells = n["modules"]["top"]["cells"]
    inv = [c for c in cells.values() if c["type"] == "LUT4" and c["connections"]["A"] == [CE]]
    assert st["inverters"] == 1 and len(inv) == 1 and inv[0]["parameters"]["INIT"] == "0101010101010101"
    assert cells["mul"]["connections"]["CE0"] == inv[0]["connections"]["Z"]


def test_what_cannot_move_stays():
    # a reset on the operand and product FFs: nothing moves
    n = _design(lsr=RST)
    before = copy.deepcopy(n)
    assert pack_dsp_registers(n, "top")["dsps"] == 0 and n == before
    # an operand FF read elsewhere too: copied into the DSP, the FF stays for its other reader
    n = _design(a_extra_load=True)
    st = pack_dsp_registers(n, "top")
    cells = n["modules"]["top"]["cells"]
    assert st["input_regs"] == 1 and "in0" in cells and "in1" not in cells
    # a product bit read by more than its FF: the output register stays off, the input registers move
    n = _design(p_extra_load=True)
    st = pack_dsp_registers(n, "top")
    assert st["output_regs"] == 0 and st["input_regs"] == 1
    assert "REG_OUTPUT_CLK" not in n["modules"]["top"]["cells"]["mul"]["parameters"]
    # a constant 1 on an operand would be 0 in the register until the first clock: the inputs stay
    n = _design(const_one=True)
    st = pack_dsp_registers(n, "top")
    assert st["input_regs"] == 0 and st["output_regs"] == 1
