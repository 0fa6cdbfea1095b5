"""Critical paths of nextpnr's report (hdl/flow/paths.py) and the seeds' figures in make synth's tables.

The report is an excerpt of a real one, written out by hand: ``make synth --block poly_unit`` (seed 1,
nextpnr-0.11.1, LFE5U-25F speed 6; fmax 121.82 MHz): its register-to-register path (a multiplier, then a
carry chain of four slices) and one path from an input port. The expected levels and delays were added up
by hand from the segments below.
"""

import json

import pytest

from eyestereo.hdl.flow import paths
from eyestereo.hdl.flow.paths import (SourceMap, clock_paths, clock_port, fmax_stats, margin, netlist_name,
                                      parse_report, worst)
from eyestereo.hdl.flow.synth import goals_table, parse_fmax, parse_seeds, paths_section

CLK = "posedge $glbnet$clk$TRELLIS_IO_IN"


def seg(kind, delay, frm, fport, to, tport, net=None):
    s = {"type": kind, "delay": delay, "from": {"cell": frm, "port": fport, "loc": [0, 0]},
         "to": {"cell": to, "port": tport, "loc": [0, 0]}}
    if net:
        s["net"] = net
    return s


C = "n398_o_TRELLIS_FF_Q_{}_DI_CCU2C_S{}$CCU2_COMB{}"
REPORT = {
    "fmax": {"$glbnet$clk$TRELLIS_IO_IN": {"achieved": 121.81752014160156, "constraint": 100}},
    "critical_paths": [
        {"from": CLK, "to": CLK, "path": [
            seg("clk-to-q", 0.525, "n558_q_TRELLIS_FF_Q_7", "Q", "n558_q_TRELLIS_FF_Q_7", "Q"),
            seg("routing", 1.217, "n558_q_TRELLIS_FF_Q_7", "Q", "n388_o_MULT18X18D_P9", "A7", "n558_q[7]"),
            seg("logic", 3.927, "n388_o_MULT18X18D_P9", "A7", "n388_o_MULT18X18D_P9", "P20"),
            seg("routing", 1.378, "n388_o_MULT18X18D_P9", "P20", C.format(10, 1, 0), "B", "n388_o_MULT18X18D_P9_P20"),
            seg("logic", 0.447, C.format(10, 1, 0), "B", C.format(10, 1, 0), "FCO"),
            seg("routing", 0, C.format(10, 1, 0), "FCO", C.format(10, 1, 1), "FCI"),
            seg("logic", 0, C.format(10, 1, 1), "FCI", C.format(10, 1, 1), "FCO"),
            seg("routing", 0, C.format(10, 1, 1), "FCO", C.format(12, 1, 0), "FCI"),
            seg("logic", 0.071, C.format(12, 1, 0), "FCI", C.format(12, 1, 0), "FCO"),
            seg("routing", 0, C.format(12, 1, 0), "FCO", C.format(12, 1, 1), "FCI"),
            seg("logic", 0, C.format(12, 1, 1), "FCI", C.format(12, 1, 1), "FCO"),
            seg("routing", 0, C.format(12, 1, 1), "FCO", C.format(14, 1, 0), "FCI"),
            seg("logic", 0.071, C.format(14, 1, 0), "FCI", C.format(14, 1, 0), "FCO"),
            seg("routing", 0, C.format(14, 1, 0), "FCO", C.format(14, 1, 1), "FCI"),
            seg("logic", 0, C.format(14, 1, 1), "FCI", C.format(14, 1, 1), "FCO"),
            seg("routing", 0, C.format(14, 1, 1), "FCO", C.format(15, 0, 0), "FCI"),
            seg("logic", 0.443, C.format(15, 0, 0), "FCI", C.format(15, 0, 0), "F"),
            seg("routing", 0.130, C.format(15, 0, 0), "F", "n398_o_TRELLIS_FF_Q_15", "DI", "n398_o_TRELLIS_FF_Q_15_DI"),
            seg("setup", 0, "n398_o_TRELLIS_FF_Q_15", "DI", "n398_o_TRELLIS_FF_Q_15", "DI")]},
        {"from": "<async>", "to": CLK, "path": [
            seg("source", 0, "select_coord[0]$tr_io", "O", "select_coord[0]$tr_io", "O"),
            seg("routing", 3.082, "select_coord[0]$tr_io", "O", "n518_q_TRELLIS_FF_Q_4_DI_LUT4_Z", "D", "n215_o[0]"),
            seg("logic", 0.236, "n518_q_TRELLIS_FF_Q_4_DI_LUT4_Z", "D", "n518_q_TRELLIS_FF_Q_4_DI_LUT4_Z", "F"),
            seg("routing", 0.219, "n518_q_TRELLIS_FF_Q_4_DI_LUT4_Z", "F", "n518_q_TRELLIS_FF_Q_4_DI_LUT4_D", "D",
                "n518_q_TRELLIS_FF_Q_4_DI[1]"),
            seg("logic", 0.236, "n518_q_TRELLIS_FF_Q_4_DI_LUT4_D", "D", "n518_q_TRELLIS_FF_Q_4_DI_LUT4_D", "F"),
            seg("routing", 0.842, "n518_q_TRELLIS_FF_Q_4_DI_LUT4_D", "F", "n520_q_TRELLIS_FF_Q_1", "LSR",
                "n518_q_TRELLIS_FF_Q_4_DI_LUT4_D_Z"),
            seg("setup", 0.424, "n520_q_TRELLIS_FF_Q_1", "LSR", "n520_q_TRELLIS_FF_Q_1", "LSR")]},
    ],
}


def test_register_path_levels_and_delays():
    ps = parse_report(json.loads(json.dumps(REPORT)), ["clk"])
    assert [(p["from_clock"], p["to_clock"]) for p in ps] == [("clk", "clk"), ("async", "clk")]  # slowest first
    p = clock_paths(ps)["clk"]
    assert (p["start"], p["end"]) == ("n558_q_TRELLIS_FF_Q_7", "n398_o_TRELLIS_FF_Q_15")
    assert (p["start_kind"], p["end_kind"]) == ("FF", "FF")
    # the multiplier and the carry chain's first slice are entered by routing; six carry hops follow
    assert (p["levels"], p["carry"]) == (2, 6)
    # logic: 0.525 clk-to-q + 3.927 + 0.447 + 0.071 + 0.071 + 0.443; routing: 1.217 + 1.378 + 0.130
    assert p["logic_ns"] == pytest.approx(5.484) and p["routing_ns"] == pytest.approx(2.725)
    assert p["total_ns"] == pytest.approx(8.209)
    assert 1000 / p["total_ns"] == pytest.approx(121.82, abs=0.01)  # the report's fmax
    assert p["nets"] == ["n558_q[7]", "n388_o_MULT18X18D_P9_P20", "n398_o_TRELLIS_FF_Q_15_DI"]


def test_port_path():
    p = parse_report(REPORT, ["clk"])[1]
    assert (p["start_kind"], p["end_kind"], p["end_port"]) == ("port", "FF", "LSR")
    assert (p["levels"], p["carry"]) == (2, 0)
    assert p["logic_ns"] == pytest.approx(0.896) and p["routing_ns"] == pytest.approx(4.143)
    assert "async" not in clock_paths([p])


def test_clock_names():
    assert clock_port(CLK) == "clk"
    assert clock_port("<async>") == "async"
    assert clock_port("posedge $glbnet$cam_l_pclk$TRELLIS_IO_IN", ["cam_l_pclk", "clk"]) == "cam_l_pclk"
    assert clock_port("hclk$TRELLIS_IO_IN_DCC", ["clk", "hclk"]) == "hclk"  # out of context: no global net
    assert parse_fmax(REPORT, ["clk"])["clk"]["achieved"] == 121.82


def test_netlist_names_of_cells():
    assert netlist_name("n14503_q_TRELLIS_FF_Q_1") == "n14503_q"
    assert netlist_name("n398_o_TRELLIS_FF_Q_15_DI_CCU2C_S0$CCU2_COMB0") == "n398_o"
    assert netlist_name("n14853_o_MULT18X18D_P9") == "n14853_o"
    assert netlist_name("a0_0_fifo0_0_mem.0.6$DPRAM_COMB0") == "a0_0_fifo0_0_mem"
    assert netlist_name("a0_0_fifo0_0_mem.0.6_DO[0]") == "a0_0_fifo0_0_mem"
    assert netlist_name("bus_bresp_TRELLIS_FF_Q") == "bus_bresp"
    assert netlist_name("wrst_l$tr_io") == "wrst_l"
    assert netlist_name("$nextpnr_CCU2C_25$CCU2_COMB0") == ""


HDL_SRC = '''\
from myhdl import Signal, always, block, intbv


@block
def scaler(clk, p, out, *, bits):
    """A made-up block: only parsed, never run."""
    prod = Signal(intbv(0)[18:])
    lo, hi = Signal(bool(0)), Signal(bool(0))
    taps = [Signal(intbv(0)[8:]) for _ in range(4)]

    @always(clk.posedge)
    def reg():
        out.next = prod
        count.next = 1

    return reg


@block
def top(clk, sink, source):
    r22 = Signal(intbv(0)[9:])
    s = scaler(clk, r22, source.data, bits=9)
    return s
'''

NETLIST = """\
  always @*
    r22 = n558_q; // (isignal)
  always @*
    scaler0_0_1_prod = n388_o; // (isignal)
  always @*
    scaler0_0_1_hi = n12_q; // (isignal)
  always @*
    source_data = scaler0_0_1_out; // (isignal)
  always @*
    scaler0_0_1_out = n398_q; // (isignal)
  always @*
    top_alias = n398_q; // (isignal)
  assign n400_o = {8'b0, scaler0_0_1_prod};  //  uext
  assign n401_o = n400_o * n399_o; // smul
  assign n402_o = {{10{scaler0_0_1_prod[17]}}, scaler0_0_1_prod}; // sext
"""


@pytest.fixture
def smap(tmp_path):
    root = tmp_path / "hdl"
    root.mkdir()
    (root / "blk.py").write_text(HDL_SRC)
    (tmp_path / "top_netlist.v").write_text(NETLIST)
    paths.block_functions.cache_clear()
    yield SourceMap(tmp_path / "top_netlist.v", "top", root=root)
    paths.block_functions.cache_clear()


def test_source_map_of_registers(smap):
    where = lambda cell: smap.locate(smap.signal(cell))  # noqa: E731
    loc = where("n558_q_TRELLIS_FF_Q_7")  # a signal of the top itself: no instance prefix
    assert (loc["block"], loc["name"], loc["line"], loc["how"]) == ("top", "r22", 21, "assigned")
    loc = where("n388_o_MULT18X18D_P9")
    assert (loc["block"], loc["name"], loc["line"]) == ("scaler", "prod", 7)
    assert where("n12_q_TRELLIS_FF_Q")["line"] == 8  # one of two names assigned on one line
    # several aliases of one register: the innermost (longest) name is where it is made; it is a port
    loc = where("n398_q_TRELLIS_FF_Q_3")
    assert (loc["name"], loc["line"], loc["how"]) == ("out", 5, "port")
    # a net that only widens a named signal (Yosys names the flip-flops after it)
    assert where("n400_o_TRELLIS_FF_Q_1")["name"] == "prod"
    assert where("n402_o_TRELLIS_FF_Q_1")["name"] == "prod"  # sign-extended
    assert where("n401_o_TRELLIS_FF_Q_1")["file"] is None  # an operator output: no name
    assert smap.where("n401_o_LUT4_Z") == "not found"


def test_source_map_of_names(smap):
    assert smap.split("scaler0_0_1_taps_3") == (["scaler"], "taps_3")
    loc = smap.locate("scaler0_0_1_taps_3")  # an element of a list of signals
    assert (loc["line"], loc["file"].endswith("blk.py")) == (9, True)
    loc = smap.locate("source_valid")  # an interface's member: the interface (a port of the top)
    assert loc["line"] == 20 and "interface source" in loc["how"]
    assert smap.locate("scaler0_0_1_count")["how"] == "first assignment"
    assert smap.locate("scaler0_0_1_count")["line"] == 14
    assert smap.locate("nothing_here")["how"] == "not found"


def test_source_map_on_the_tree():
    """A real instance path: the fetch unit's show-ahead FIFO read pointer, declared in hdl/common/fifo.py."""
    smap = SourceMap(None, "stereo_frontend")
    loc = smap.locate("rectifier0_0_fetch_interpolate0_0_1_show_ahead_fifo0_0_1_rp")
    assert loc["block"] == "show_ahead_fifo" and loc["file"] == "hdl/common/fifo.py", loc
    line = (paths.REPO / loc["file"]).read_text().splitlines()[loc["line"] - 1]
    assert "rp" in line and "Signal(" in line


def _path(seed, total, start, end):
    return dict(from_clock="clk", to_clock="clk", start=start, end=end, total_ns=total, seed=seed, levels=3, carry=0,
                logic_ns=total / 2, routing_ns=total / 2, start_kind="FF", end_kind="FF", nets=[], cells=[],
                start_source=dict(signal=start, block="b", name=start, file="hdl/x.py", line=1),
                end_source=dict(signal=end, block="b", name=end, file="hdl/x.py", line=2), through=[])


def test_worst_over_seeds_and_margin():
    runs = {1: [_path(1, 10.0, "a", "b")], 2: [_path(2, 12.5, "c", "d")], 3: [_path(3, 11.0, "a", "b")],
            4: [_path(4, 9.0, "e", "f")]}
    w = worst(runs, "clk")
    assert [(p["seed"], p["start"]) for p in w] == [(2, "c"), (3, "a"), (4, "e")]  # a -> b once, its slowest seed
    st = fmax_stats([80.0, 100.0, 90.9, 111.1])
    assert (st["min"], st["median"], st["max"]) == (80.0, 95.45, 111.1)
    assert fmax_stats([None]) == dict(min=None, median=None, max=None, seeds=1)
    assert margin(110.0, 100.0) == 10.0 and margin(75.5, 100.0) == -24.5 and margin(None, 100.0) is None


def test_goal_table_and_paths_section():
    worst_p = _path(2, 12.5, "rp", "w1")
    res = [dict(label="rectifier", block="rectifier", clocks={"clk": 100.0}, seeds=[1, 2, 3, 4],
                fmax={"clk": dict(achieved=80.0, min=80.0, median=84.0, max=88.0, per_seed={1: 88.0, 2: 80.0,
                                                                                          3: 84.0, 4: 84.0})},
                worst={"clk": [worst_p]}),
           dict(label="prethreshold", block="prethreshold", clocks={"clk": 50.0}, seeds=[1, 2, 3, 4],
                fmax={"clk": dict(achieved=60.0, min=60.0, median=70.0, max=75.0, per_seed={1: 60.0, 2: 70.0,
                                                                                          3: 70.0, 4: 75.0})},
                worst={"clk": [_path(1, 16.7, "s", "t")]})]
    t = goals_table(res)
    assert "| rectifier | clk | 100 (memory clock) | 80.0 / 84.0 / 88.0 | -20.0 % | no | - |" in t
    assert "| prethreshold | clk | 50 (Harris clock) | 60.0 / 70.0 / 75.0 | +20.0 % | yes | -40.0 % |" in t
    s = paths_section(res)
    row = "| rectifier | clk | 100 | 80.0 | `b.rp` (hdl/x.py:1) -> `b.w1` (hdl/x.py:2) | 3 | 12.50 = 6.25 + 6.25 |"
    assert row in s
    assert "prethreshold" not in s.split("|---", 1)[1]  # met with the margin: no row


def test_goal_table_shows_the_figures_before_and_the_spartan3e_fit():
    before = {"stereo_frontend": dict(LUT=5000, LUTRAM=200, FF=6000, RAMB16=16, MULT18X18=19,
                                      fmax={"clk": 76.1, "hclk": 86.3})}
    fe = dict(label="stereo_frontend", block="stereo_frontend", clocks={"clk": 100.0, "hclk": 50.0}, seeds=[1],
              fmax={"clk": dict(achieved=111.0, min=111.0, median=111.0, max=111.0, per_seed={1: 111.0}),
                    "hclk": dict(achieved=120.0, min=120.0, median=120.0, max=120.0, per_seed={1: 120.0})},
              summary=dict(LUT=5400, LUTRAM=300, FF=6500, RAMB16=17, MULT18X18=19))
    big = dict(fe, label="stereo_frontend single-clock", summary=dict(LUT=9000, LUTRAM=400, FF=6500, RAMB16=17,
                                                                      MULT18X18=19))
    t = goals_table([fe, big], before)
    assert "| stereo_frontend | clk | 100 (memory clock) | 111.0 / 111.0 / 111.0 | +11.0 % | yes | - | 76.1 |" in t
    # 5700 LUTs against 5200 before: +9.6 %, within 10 %; the single-clock row compares with the same figures
    assert "| stereo_frontend | 5400 + 300 = 5700 of 9312 | 6500 of 9312 | 17 of 20 | 19 of 20 | yes | " \
           "5000 + 200 | +9.6 % | yes |" in t
    assert "| stereo_frontend single-clock | 9000 + 400 = 9400 of 9312 | 6500 of 9312 | 17 of 20 | 19 of 20 | " \
           "**no** | 5000 + 200 | +80.8 % | **no** |" in t


def test_seeds_option():
    assert parse_seeds("1,2,3,4") == [1, 2, 3, 4] and parse_seeds("1") == [1]
    for bad in ("", "0", "1,1", "a"):
        with pytest.raises(ValueError):
            parse_seeds(bad)
