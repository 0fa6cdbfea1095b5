"""median3 (issue 28) against its bit-true model, bit for bit on every pixel, borders included.

GHDL runs the VHDL (marker sim); Icarus and Verilator run MyHDL's Verilog of the same cases (marker
othersims, ``make test-sims``). The bench (sim/benches/tb_median3.py) also checks the latency of every
non-tail pixel, the reset token, the frame count and that nothing is left over.
"""

import shutil
from pathlib import Path

import pytest
from myhdl import ResetSignal, Signal

from eyestereo.hdl.dense.median3 import LATENCY, median3
from eyestereo.hdl.flow.convert import GHDL_STDS, analyse, check_verilog, convert, vhdl_ports
from eyestereo.hdl.flow.vlint import mixed_signedness
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.sim.lib.runner import run_bench

TSUKUBA = Path("/work/shared/data/middlebury/tsukuba")
SIMS = ["ghdl", pytest.param("icarus", marks=pytest.mark.othersims),
        pytest.param("verilator", marks=pytest.mark.othersims)]


def _run(request, sim, *, width, height, frames, **stim):
    report = run_bench("median3", "tb_median3", dict(frames=frames, **stim), name=request.node.name,
                       params=dict(width=width, height=height), sim=sim)
    assert report["frames"] == len(frames)
    assert report["pixels_compared"] == len(frames) * width * height
    assert report["latency"] == 7
    assert report["latency_checked"] == len(frames) * (width * height - width - 1)
    return report


@pytest.mark.sim
@pytest.mark.parametrize("sim", SIMS)
@pytest.mark.parametrize("width,height,duty", [(20, 12, 1.0), (9, 5, 0.6)])
def test_median3_random(request, sim, width, height, duty):
    """Random maps with invalid codes and a map of few levels (ties) back to back, after a token cut
    into a frame; with duty 1 the second frame's beats carry the first frame's tail."""
    report = _run(request, sim, width=width, height=height, duty=duty, seed=width,
                  frames=["random:1", "levels:2", "random:3"], token_after=width + 3)
    assert report["invalid_out"] > 0


@pytest.mark.sim
@pytest.mark.parametrize("sim", SIMS)
def test_median3_tsukuba(request, sim):
    """A real disparity map (the model's census + SGM on a Tsukuba crop), with idle gaps, twice."""
    report = _run(request, sim, width=20, height=12, duty=0.4, seed=5,
                  frames=[f"dense:{TSUKUBA}", f"dense:{TSUKUBA}"])
    assert report["invalid_out"] > 0


@pytest.mark.sim
def test_median3_smallest_frame(request):
    """3 x 3 frames: one inner pixel, the tail as long as most of the frame, a token after one beat."""
    _run(request, "ghdl", width=3, height=3, duty=0.7, seed=1, frames=["levels:4", "random:5", "random:6"],
         token_after=1)


# --- elaboration checks ---------------------------------------------------------------------------
def _ports(bits=16):
    return Signal(bool(0)), ResetSignal(0, active=1, isasync=False), ImageStream(bits), ImageStream(bits)


@pytest.mark.parametrize("width,height,words", [
    (2, 288, "frame 2x288 is smaller than the 3x3 median window"),
    (352, 2, "frame 352x2 is smaller than the 3x3 median window"),
    (5000, 288, "width=5000 is too large"),
    (352, 12.0, "parameter height must be an integer"),
])
def test_median3_parameters_refused(width, height, words):
    with pytest.raises(ValueError, match="^median3") as e:
        median3(*_ports(), width=width, height=height)
    assert words in str(e.value)


def test_median3_ports_refused():
    clk, rst, sink, source = _ports()
    with pytest.raises(ValueError, match="must carry 16-bit data"):
        median3(clk, rst, ImageStream(8), source)
    with pytest.raises(ValueError, match="must carry 16-bit data"):
        median3(clk, rst, sink, ImageStream(12))
    with pytest.raises(ValueError, match="mono streams only"):
        median3(clk, rst, ImageStream(16, stereo=True), source)
    with pytest.raises(ValueError, match="mono streams only"):
        median3(clk, rst, sink, ImageStream(16, stereo=True))
    with pytest.raises(ValueError, match="median3"):
        median3(clk, rst, sink, sink)


def test_median3_latency():
    assert LATENCY == 7


# --- make vhdl / make verilog: the catalogue's configuration (352x288) ----------------------------------
@pytest.mark.skipif(shutil.which("ghdl") is None or shutil.which("iverilog") is None, reason="GHDL and Icarus needed")
def test_median3_converts_and_analyses(tmp_path):
    files = convert("median3", tmp_path / "vhdl")
    for std in GHDL_STDS:
        analyse(files, std, tmp_path / std)  # raises with GHDL's messages
    ports = {p["name"]: p["type"] for p in vhdl_ports(files[-1])}
    assert ports["sink_data"] == "unsigned(15 downto 0)" and ports["source_data"] == "unsigned(15 downto 0)"
    assert "sink_cam" not in ports and "source_cam" not in ports
    v = convert("median3", tmp_path / "verilog", hdl="Verilog")
    check_verilog(v, "median3", tmp_path / "icarus")
    assert not mixed_signedness(v[0].read_text())


def test_a_saved_code_map_is_cropped_at_its_bottom_right(tmp_path):
    """``npy:FILE`` (bench_dense's full-frame median3 case): the bottom-right width x height of the saved map;
    an array too small, or not 2-D, is one clear error naming the file."""
    import numpy as np

    from eyestereo.sim.benches.tb_median3 import codes

    m = np.arange(6 * 8).reshape(6, 8)
    f = tmp_path / "codes.npy"
    np.save(f, m)
    assert codes(f"npy:{f}", 3, 2).tolist() == [[37, 38, 39], [45, 46, 47]]
    assert codes(f"npy:{f}", 8, 6).tolist() == m.tolist()
    with pytest.raises(ValueError, match=r"codes.npy: a \(6, 8\) array holds no 6 x 9 code map"):
        codes(f"npy:{f}", 9, 6)
    np.save(f, np.zeros(5))
    with pytest.raises(ValueError, match="holds no"):
        codes(f"npy:{f}", 1, 1)
