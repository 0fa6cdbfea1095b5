"""hdl/flow/bram_regs.py: the flip-flops after a block-RAM read into the DP16KD's output register, on
hand-made Yosys JSON netlists."""

import copy

import pytest

from eyestereo.hdl.flow.bram_regs import MAX_LEVELS, pack_bram_registers

CLK, CLK2, CE, RST = 2, 3, 4, 5


def _ff(d, q, *, clk=CLK, ce="1", lsr="0"):
    conn = dict(CLK=[clk], LSR=[lsr], DI=[d], Q=[q])
    if ce != "1":
        conn["CE"] = [CE]
    return dict(type="TRELLIS_FF", parameters=dict(CEMUX=ce, CLKMUX="CLK", GSR="DISABLED", LSRMUX="LSR",
                                                    REGSET="RESET"),
                attributes={}, port_directions=dict(CLK="input", LSR="input", CE="input", DI="input", Q="output"),
                connections=conn)


def _lut(a, z):
    return dict(type="LUT4", parameters=dict(INIT="1" * 16), attributes={},
                port_directions=dict(A="input", B="input", C="input", D="input", Z="output"),
                connections=dict(A=[a], B=["0"], C=["0"], D=["0"], Z=[z]))


def _design(*, ce="1", lsr="0", clk=CLK, extra_load=False, one_unregistered=False, chain=0):
    """A 4-bit read on port B: DOB0..3 (nets 30..33) -> FFs -> Q nets 40..43 (read by a LUT, then ``chain`` LUTs
    more, into a flip-flop); port A writes."""
    cells = {f"q{i}": _ff(30 + i, 40 + i, clk=clk, ce=ce, lsr=lsr) for i in range(4)}
    conn = dict(CLKA=[CLK], CLKB=[CLK], CEA=["1"], CEB=["1"], OCEA=["1"], OCEB=["1"], RSTA=["0"], RSTB=["0"],
                WEA=[7], WEB=["0"])
    conn |= {f"DOB{i}": [30 + i] if i < 4 else [100 + i] for i in range(18)}
    conn |= {f"DOA{i}": [200 + i] for i in range(18)}  # the write port's read data: unused
    dirs = {k: "input" for k in conn} | {f"DO{p}{i}": "output" for p in "AB" for i in range(18)}
    cells["ram"] = dict(type="DP16KD", parameters=dict(REGMODE_A="NOREG", REGMODE_B="NOREG", CLKBMUX="CLKB"),
                        attributes={}, port_directions=dirs, connections=conn)
    d = [40, 41, 42, 43]
    if extra_load:
        d[3] = 31  # a LUT reads DOB1 beside its flip-flop
    if one_unregistered:
        del cells["q2"]
        d[2] = 32  # DOB2 goes straight into logic
    cells["use"] = dict(type="LUT4", parameters=dict(INIT="1" * 16), attributes={},
                        port_directions=dict(A="input", B="input", C="input", D="input", Z="output"),
                        connections=dict(A=[d[0]], B=[d[1]], C=[d[2]], D=[d[3]], Z=[60]))
    for i in range(chain):
        cells[f"chain{i}"] = _lut(60 + i, 61 + i)
    cells["end"] = _ff(60 + chain, 90)
    ports = dict(clk=dict(direction="input", bits=[CLK]), clk2=dict(direction="input", bits=[CLK2]),
                 ce=dict(direction="input", bits=[CE]), rst=dict(direction="input", bits=[RST]),
                 y=dict(direction="output", bits=[90]))
    return dict(modules=dict(top=dict(attributes={}, ports=ports, cells=cells, netnames={})))


def test_the_read_register_moves_into_the_block_ram():
    n = _design()
    assert pack_bram_registers(n, "top") == dict(ports=1, ffs_removed=4)
    cells = n["modules"]["top"]["cells"]
    assert set(cells) == {"ram", "use", "end"}
    ram = cells["ram"]
    assert [ram["connections"][f"DOB{i}"] for i in range(4)] == [[40], [41], [42], [43]]  # the FFs' Q nets
    assert ram["parameters"]["REGMODE_B"] == "OUTREG" and ram["connections"]["OCEB"] == ["1"]
    assert ram["parameters"]["REGMODE_A"] == "NOREG"  # port A's data is read by nothing
    assert ram["connections"]["RSTB"] == ["0"]


def test_the_enable_goes_to_the_output_clock_enable():
    n = _design(ce="CE")
    assert pack_bram_registers(n, "top")["ports"] == 1
    ram = n["modules"]["top"]["cells"]["ram"]
    assert ram["connections"]["OCEB"] == [CE] and ram["port_directions"]["OCEB"] == "input"


@pytest.mark.parametrize("case", [dict(lsr=RST), dict(clk=CLK2), dict(ce="INV"), dict(extra_load=True),
                                  dict(one_unregistered=True)],
                         ids=["reset", "other-clock", "inverted-enable", "read-elsewhere", "one-bit-unregistered"])
def test_what_cannot_move_stays(case):
    n = _design(**case)
    before = copy.deepcopy(n)
    assert pack_bram_registers(n, "top") == dict(ports=0, ffs_removed=0)
    assert n == before


def test_a_port_already_registered_is_left():
    n = _design()
    n["modules"]["top"]["cells"]["ram"]["parameters"]["REGMODE_B"] = "OUTREG"
    before = copy.deepcopy(n)
    assert pack_bram_registers(n, "top")["ports"] == 0 and n == before


def test_deep_logic_after_the_register_keeps_it_in_a_slice():
    # the register's fanout crosses MAX_LEVELS cells (the reading LUT and two more): it moves
    n = _design(chain=MAX_LEVELS - 1)
    assert pack_bram_registers(n, "top")["ports"] == 1
    # one cell more: the path after it would start 0.45 ns later, in the block-RAM column: it stays
    n = _design(chain=MAX_LEVELS)
    before = copy.deepcopy(n)
    assert pack_bram_registers(n, "top")["ports"] == 0 and n == before


def test_a_memory_named_oreg_moves_its_register_over_deep_logic():
    """``_oreg`` in the memory's name (sgm's path rings): the register moves whatever follows it; the other
    conditions still hold (a reset keeps it in a slice)."""
    n = _design(chain=MAX_LEVELS + 3)
    cells = n["modules"]["top"]["cells"]
    cells["path1_ring_oreg_norw.0.2"] = cells.pop("ram")
    assert pack_bram_registers(n, "top") == dict(ports=1, ffs_removed=4)
    assert cells["path1_ring_oreg_norw.0.2"]["parameters"]["REGMODE_B"] == "OUTREG"
    n = _design(chain=MAX_LEVELS + 3, lsr=RST)
    cells = n["modules"]["top"]["cells"]
    cells["path1_ring_oreg_norw.0.2"] = cells.pop("ram")
    before = copy.deepcopy(n)
    assert pack_bram_registers(n, "top")["ports"] == 0 and n == before
