"""The netlist ``make synth`` measures is the VHDL's: GHDL's synthesis, repaired, simulated bit-exact.

GHDL 2.0 writes two constructs of its netlist wrongly in Verilog (see :mod:`eyestereo.hdl.flow.netlist`); the
unit tests show each repair on GHDL's own output, and the benches run the repaired netlist in Icarus
Verilog against the bit-true models, with the same stimulus kinds as the VHDL regressions.
"""

import shutil

import pytest

from eyestereo.hdl.flow.netlist import NetlistError, fix_arithmetic_shifts, lint_vhdl, patch_pmux_defaults, repair, \
    vhdl_select_defaults
from eyestereo.tools.models import harris_mono as hm
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH, K_CODE_DEFAULT, NMS_DEFAULT, THRESHOLD_BLOCKS

needs_tools = pytest.mark.skipif(shutil.which("ghdl") is None or shutil.which("iverilog") is None,
                                 reason="GHDL and Icarus Verilog needed")

VERILOG = """\
  always @*
    case (n90_o)
      3'b100: n95_o <= 9'b011010111;
      3'b010: n95_o <= 9'b010001111;
      3'b001: n95_o <= 9'b001000111;
    endcase
  always @*
    case (n72_o)
      2'b00: n73_o <= n56_o;
      2'b01: n73_o <= n57_o;
      2'b10: n73_o <= n58_o;
      2'b11: n73_o <= n59_o;
    endcase
  assign n373_o = $signed(gx) >> 31'b0000000000000000000000000000011;
  assign n374_o = gy >> 31'b0000000000000000000000000000001;
"""
VHDL = """\
  with n90_o select n95_o <=
    "011010111" when "100",
    "010001111" when "010",
    "001000111" when "001",
    "100011111" when others;
  with n72_o select n73_o <=
    n56_o when "00",
    n57_o when "01",
    n58_o when "10",
    n59_o when "11",
    'X' when others;
"""


def test_case_defaults_come_back_from_the_vhdl_netlist():
    d = vhdl_select_defaults(VHDL)
    assert d == {"n95_o": "9'b100011111", "n73_o": "1'bx"}
    text, n = patch_pmux_defaults(VERILOG, d)
    assert n == 2
    assert "      3'b001: n95_o <= 9'b001000111;\n      default: n95_o <= 9'b100011111;\n    endcase" in text


def test_arithmetic_shift_becomes_verilog_arithmetic():
    text, n = fix_arithmetic_shifts(VERILOG)
    assert n == 1
    assert "$signed(gx) >>> 31'b" in text and "gy >> 31'b" in text  # the logical shift stays logical


def test_repair_refuses_what_it_cannot_map():
    with pytest.raises(NetlistError, match="no 'when others' value for n95_o"):
        patch_pmux_defaults(VERILOG, {"n73_o": "1'bx"})
    with pytest.raises(NetlistError, match="no Verilog case"):
        patch_pmux_defaults(VERILOG, {"n95_o": "9'b0", "n73_o": "1'bx", "n99_o": "1'b0"})
    with pytest.raises(NetlistError, match="cannot translate"):
        vhdl_select_defaults('  with s select o <=\n    a when "0",\n    resize(b, 4) when others;\n')
    with pytest.raises(NetlistError, match="writes wrongly"):
        repair("  assign n1_o = a % b; // smod\n", "")
    text, counts = repair(VERILOG, VHDL)
    assert counts == dict(arithmetic_shifts=1, case_defaults=2, no_rw_check=0)


def test_lint_refuses_comparisons_ghdl_synthesizes_wrongly(tmp_path):
    f = tmp_path / "x.vhd"
    body = ("        thr_addr: in unsigned(3 downto 0);\n        signal v: signed(7 downto 0);\n"
            "        if (bool(thr_we) and ({})) then\n")
    for ok in ("thr_addr < 15", "thr_addr = 0", "v > -128", "v < 127"):
        f.write_text(body.format(ok))
        lint_vhdl([f])
    for bad in ("thr_addr < 16", "v > -129", "v < 128"):
        f.write_text(body.format(bad))
        with pytest.raises(NetlistError, match="x.vhd:3: .* outside its range"):
            lint_vhdl([f])


# --- the repaired netlist in Icarus, bit for bit against the models --------------------------------
def _run(block, bench, params, stim, request):
    from eyestereo.sim.lib.netlist import run_netlist_bench

    report = run_netlist_bench(block, bench, stim, name=request.node.name, params=params)
    assert report["frames"] == len(stim["frames"]) and report["pixels_compared"] > 0
    return report


SMALL = dict(width=17, height=9)
CASES = {
    "line_delay": ("tb_line_delay", dict(SMALL, data_width=8), dict(frames=["random:1", "random:2"])),
    "convolve": ("tb_convolve", dict(SMALL, col=[-1, 3, -1], row=[1, 0, -1], shift=0, kernel=None),
                 dict(frames=["random:1", "random:2"])),
    "sobel": ("tb_sobel", SMALL, dict(frames=["random:1", "random:2"])),
    "harris_window": ("tb_harris_window", SMALL, dict(frames=["grad:1:256", "grad:2:256"])),
    "cornerness": ("tb_cornerness", SMALL, dict(frames=["rwindow:1", "rwindow:2"], k=61)),
    "prethreshold": ("tb_prethreshold", dict(SMALL, blocks=(4, 4)),
                     dict(frames=["rcorner:1:-600:600"], thresholds={i: (i * 37 % 23 - 11) * 40 for i in range(16)})),
    "nms": ("tb_nms", dict(SMALL, size=5), dict(frames=["rcorner:1:-2:3", "rcorner:2:-1:1"])),
    "harris_mono": ("tb_harris_mono", dict(width=40, height=30, blocks=(4, 4), nms=3),
                    dict(frames=["random:1", "random:2"], k=K_CODE_DEFAULT,
                         thresholds=[0, 5, 100, -3, 7, 1, 0, 2, 9, 0, 3, 1, 4, 4, 0, 8])),
}


@needs_tools
@pytest.mark.sim
@pytest.mark.parametrize("block", sorted(CASES))
def test_netlist_equals_model(request, block):
    bench, params, stim = CASES[block]
    _run(block, bench, params, dict(stim, duty=0.6, seed=2, token_after=23), request)


@needs_tools
@pytest.mark.sim
def test_axis_bridges_netlists(request):
    """The AXI4-Stream bridges as synthesized, under back-pressure and with an overflow, on Icarus."""
    from eyestereo.sim.lib.netlist import run_netlist_bench

    frames = ["random:1", "random:2", "random:3"]
    rep = run_netlist_bench("stream_to_axis", "tb_stream_to_axis",
                            dict(frames=frames, duty=0.5, pause=0.3, seed=3, expect="exact"),
                            name=request.node.name + "_exact", params=dict(SMALL, depth=64))
    assert rep["whole"] == [0, 1, 2] and rep["overflows"] == 0
    rep = run_netlist_bench("stream_to_axis", "tb_stream_to_axis",
                            dict(frames=frames + ["random:4"], duty=1.0, pause=0.5, seed=7, expect="cut"),
                            name=request.node.name + "_cut", params=dict(SMALL, depth=32))
    assert rep["overflows"] >= 2
    rep = run_netlist_bench("axis_to_stream", "tb_axis_to_stream",
                            dict(frames=frames + ["random:4"], pause=0.3, seed=4,
                                 faults=[[0, "junk"], [1, "early_sof"], [2, "short_line"]]),
                            name=request.node.name + "_a2s", params=SMALL)
    assert rep["tokens"] == 2 and rep["frames"] == 2


@needs_tools
@pytest.mark.sim
def test_harris_mono_netlist_full_frame(request):
    """The whole mono Harris as make synth measures it, on a real 352x288 frame, 16 block thresholds."""
    thr = [hm.threshold_code(c) for c in (2e8, 4e8, 1e8, 6e8, 3e8, 1e9, 5e7, 2e8,
                                          8e8, 1e8, 3e8, 4e8, 6e8, 2e8, 1e8, 5e8)]
    _run("harris_mono", "tb_harris_mono",
         dict(width=FRAME_WIDTH, height=FRAME_HEIGHT, blocks=THRESHOLD_BLOCKS, nms=NMS_DEFAULT),
         dict(frames=["file:tsukuba_im3.png"], duty=1.0, k=K_CODE_DEFAULT, thresholds=thr), request)


def test_norw_memories_are_marked_for_yosys():
    from eyestereo.hdl.flow.netlist import mark_no_rw_check

    text = "  reg [7:0] a_bank0_mem_norw[2047:0] ; // memory\n  reg [7:0] fifo_mem[15:0] ; // memory\n"
    out, n = mark_no_rw_check(text)
    assert n == 1
    assert "(* no_rw_check *) reg [7:0] a_bank0_mem_norw[2047:0] ;" in out and "\n  reg [7:0] fifo_mem[15:0]" in out
    # MyHDL's own Verilog (the board flow's input): a space before the range, a 1-bit memory without a width
    text = ("reg [7:0] lc_bank0_mem_norw [0:2048-1];\nreg pd_bank0_mem_norw [0:16384-1];\n"
            "reg [17:0] fifo_mem [0:32-1];\nreg norw_flag;\n")
    out, n = mark_no_rw_check(text)
    assert n == 2 and out.count("(* no_rw_check *)") == 2
    assert "(* no_rw_check *) reg pd_bank0_mem_norw [0:16384-1];" in out and "\nreg [17:0] fifo_mem [0:32-1];" in out
