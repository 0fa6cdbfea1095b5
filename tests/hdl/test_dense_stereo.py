"""dense_stereo (issue 28): census, sgm and median3 joined, against the chain's bit-true model, bit for bit.

The same bench as sgm's (sim/benches/tb_sgm.py: grey pairs in when the block is the chain). GHDL runs the
VHDL; Icarus and Verilator MyHDL's Verilog (marker othersims).
"""

import shutil
from pathlib import Path

import pytest
from myhdl import ResetSignal, Signal, intbv

from eyestereo.hdl.dense.dense_stereo import dense_stereo
from eyestereo.hdl.flow.convert import GHDL_STDS, analyse, check_verilog, convert, vhdl_ports
from eyestereo.hdl.flow.vlint import mixed_signedness
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.sim.lib.runner import run_bench

TSUKUBA = Path("/work/shared/data/middlebury/tsukuba")
REAL = [f"image:{TSUKUBA / 'im3.png'}", f"image:{TSUKUBA / 'im4.png'}"]
HW = dict(window=5, disparities=16, pu=4, paths=4, path_bits=7, sum_shift=1, frac_bits=4, fifo=None)


@pytest.mark.sim
@pytest.mark.parametrize("sim,median", [("ghdl", True), ("ghdl", False),
                                        pytest.param("icarus", True, marks=pytest.mark.othersims),
                                        pytest.param("verilator", True, marks=pytest.mark.othersims)])
def test_dense_stereo_tsukuba(request, sim, median):
    """A Tsukuba crop (grey, both cameras) and a random pair, back to back, with idle gaps."""
    params = dict(HW, median=median, width=40, height=12)
    report = run_bench("dense_stereo", "tb_sgm", dict(frames=[REAL, ["random:1", "random:2"]], seed=3),
                       name=request.node.name, params=params, sim=sim)
    assert report["frames"] == 2 and report["pixels_compared"] == 2 * 40 * 12
    assert report["valid_codes"] > 0


def _ports():
    return (Signal(bool(0)), ResetSignal(0, active=1, isasync=False), ImageStream(8, stereo=True), ImageStream(16),
            Signal(intbv(0)[8:]), Signal(intbv(0)[8:]), Signal(intbv(0)[7:]), Signal(bool(0)), Signal(bool(0)),
            Signal(bool(0)))


@pytest.mark.parametrize("kw,words", [
    (dict(median=1), "parameter median must be True or False"),
    (dict(window=3), "parameter window must be one of [5, 7]"),
    (dict(disparities=16, pu=16), "at least 2 groups"),
    (dict(width=40, disparities=64), "width must exceed the 64 disparities"),
])
def test_dense_stereo_parameters_refused(kw, words):
    with pytest.raises(ValueError) as e:
        dense_stereo(*_ports(), **kw)
    assert words in str(e.value)


def test_dense_stereo_ports_refused():
    ports = list(_ports())
    ports[2] = ImageStream(8)
    with pytest.raises(ValueError, match="must be a stereo stream"):
        dense_stereo(*ports)


@pytest.mark.skipif(shutil.which("ghdl") is None or shutil.which("iverilog") is None, reason="GHDL and Icarus needed")
def test_dense_stereo_converts_and_analyses(tmp_path):
    files = convert("dense_stereo", tmp_path / "vhdl", disparities=16, width=40, height=10)
    for std in GHDL_STDS:
        analyse(files, std, tmp_path / std)
    ports = {p["name"]: p["type"] for p in vhdl_ports(files[-1])}
    assert ports["sink_data"] == "unsigned(7 downto 0)" and ports["source_data"] == "unsigned(15 downto 0)"
    v = convert("dense_stereo", tmp_path / "verilog", hdl="Verilog", disparities=16, width=40, height=10)
    check_verilog(v, "dense_stereo", tmp_path / "icarus")
    assert not mixed_signedness(v[0].read_text())
