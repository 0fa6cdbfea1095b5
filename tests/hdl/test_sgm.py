"""sgm (issue 28) against its bit-true model, bit for bit on every pixel.

GHDL runs the VHDL (marker sim); Icarus and Verilator run MyHDL's Verilog of the same cases (marker
othersims). The bench (sim/benches/tb_sgm.py) feeds census words of stereo pairs at a pixel rate the block
sustains, with idle gaps, and checks the codes, the frames, the token, and that ``overrun`` stays low.
"""

import shutil
from pathlib import Path

import pytest
from myhdl import ResetSignal, Signal, intbv

from eyestereo.hdl.dense.sgm import SPACING_MIN, sgm, spacing, tree_latency
from eyestereo.hdl.flow.convert import GHDL_STDS, analyse, check_verilog, convert, vhdl_ports
from eyestereo.hdl.flow.vlint import mixed_signedness
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.sim.lib.runner import run_bench

TSUKUBA = Path("/work/shared/data/middlebury/tsukuba")
REAL = [f"image:{TSUKUBA / 'im3.png'}", f"image:{TSUKUBA / 'im4.png'}"]
HW = dict(path_bits=7, sum_shift=1, frac_bits=4, window=5, fifo=64)


def _run(request, sim, *, frames, disparities=16, pu=4, paths=4, width=40, height=10, hw=None, **cfg):
    params = dict(HW, disparities=disparities, pu=pu, paths=paths, width=width, height=height, **(hw or {}))
    report = run_bench("sgm", "tb_sgm", dict(frames=frames, **cfg), name=request.node.name, params=params, sim=sim)
    if not cfg.get("expect_overrun"):
        assert report["frames"] == len(frames)
        assert report["pixels_compared"] == len(frames) * width * height
        assert report["valid_codes"] > 0
    return report


@pytest.mark.sim
@pytest.mark.parametrize("sim,paths", [("ghdl", 2), ("ghdl", 4), pytest.param("icarus", 4, marks=pytest.mark.othersims),
                                       pytest.param("verilator", 4, marks=pytest.mark.othersims)])
def test_sgm_tsukuba(request, sim, paths):
    """A Tsukuba crop twice (the second with the cameras swapped: other disparities), back to back."""
    _run(request, sim, paths=paths, width=48, height=12, seed=paths, frames=[REAL, REAL[::-1]])


@pytest.mark.sim
@pytest.mark.parametrize("pu", [1, 8])
def test_sgm_pu(request, pu):
    """The result does not depend on the disparities per clock (D = 16: 16, 8, 2 groups)."""
    _run(request, "ghdl", pu=pu, seed=pu, frames=[["shift:3:5", ""], REAL])


@pytest.mark.sim
@pytest.mark.parametrize("case", ["options_off_d24", "penalties_seven", "token"])
def test_sgm_settings(request, case):
    """Run-time settings (the options off with a D that is not a power of two; P1 = 3, P2 = 120 -- saturating
    path costs -- and uniqueness 40 with the 7x7 census's costs) and a reset token mid-frame."""
    kw = dict(options_off_d24=dict(lr_check=False, subpixel=False, uniqueness=0, disparities=24, pu=8, width=36),
              penalties_seven=dict(p1=3, p2=120, uniqueness=40, hw=dict(window=7)),
              token=dict(token_after=2 * 40 * 3 + 7))[case]
    _run(request, "ghdl", seed=7, frames=[REAL, ["random:4", "random:5"]], **kw)


@pytest.mark.sim
def test_sgm_overrun(request):
    """Pixels faster than the block takes them: ``overrun`` rises once the FIFO is full, and stays."""
    _run(request, "ghdl", frames=[REAL], pixel_clocks=2, expect_overrun=True, hw=dict(fifo=4))


# --- elaboration checks ---------------------------------------------------------------------------
def _ports(bits=24):
    return (Signal(bool(0)), ResetSignal(0, active=1, isasync=False), ImageStream(bits, stereo=True), ImageStream(16),
            Signal(intbv(0)[8:]), Signal(intbv(0)[8:]), Signal(intbv(0)[7:]), Signal(bool(0)), Signal(bool(0)),
            Signal(bool(0)))


@pytest.mark.parametrize("kw,words", [
    (dict(disparities=8), "parameter disparities=8 is too small"),
    (dict(disparities=200), "parameter disparities=200 is too large"),
    (dict(pu=3), "parameter pu must be one of"),
    (dict(disparities=16, pu=16), "at least 2 groups"),
    (dict(disparities=24, pu=16), "must divide disparities=24"),
    (dict(paths=8), "parameter paths must be one of [2, 4]"),
    (dict(fifo=24), "fifo=24 must be a power of two"),
    (dict(width=64), "width must exceed the 64 disparities"),
    (dict(path_bits=3), "parameter path_bits=3 is too small: at least 4"),
    (dict(frac_bits=5), "parameter frac_bits=5 is too large: at most 4"),
])
def test_sgm_parameters_refused(kw, words):
    with pytest.raises(ValueError, match="sgm") as e:
        sgm(*_ports(), **kw)
    assert words in str(e.value)


def test_sgm_ports_refused():
    ports = list(_ports())
    bad = list(ports)
    bad[2] = ImageStream(48, stereo=True)
    with pytest.raises(ValueError, match="must carry 24-bit data"):
        sgm(*bad)
    bad = list(ports)
    bad[4] = Signal(intbv(0)[6:])
    with pytest.raises(ValueError, match="p1"):
        sgm(*bad)
    bad = list(ports)
    bad[3] = ImageStream(16, stereo=True)
    with pytest.raises(ValueError, match="source"):
        sgm(*bad)


def test_sgm_spacing():
    """D / PU groups plus the left path's loop, at least SPACING_MIN."""
    assert (tree_latency(1), tree_latency(4), tree_latency(8), tree_latency(16)) == (1, 1, 2, 2)
    assert spacing(64, 4) == 18 and spacing(64, 8) == 11 and spacing(16, 4) == SPACING_MIN == 9
    assert spacing(128, 4) == 34


@pytest.mark.skipif(shutil.which("ghdl") is None or shutil.which("iverilog") is None, reason="GHDL and Icarus needed")
def test_sgm_converts_and_analyses(tmp_path):
    files = convert("sgm", tmp_path / "vhdl", disparities=16, width=40, height=10)
    for std in GHDL_STDS:
        analyse(files, std, tmp_path / std)
    ports = {p["name"]: p["type"] for p in vhdl_ports(files[-1])}
    assert ports["sink_data"] == "unsigned(23 downto 0)" and ports["source_data"] == "unsigned(15 downto 0)"
    assert ports["p1"] == "unsigned(7 downto 0)" and ports["overrun"] == "std_logic"
    v = convert("sgm", tmp_path / "verilog", hdl="Verilog", disparities=16, width=40, height=10)
    check_verilog(v, "sgm", tmp_path / "icarus")
    assert not mixed_signedness(v[0].read_text())
