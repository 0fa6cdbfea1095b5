"""census (issue 28) against its bit-true model, bit for bit on every pixel, borders included.

GHDL runs the VHDL (marker sim); Icarus and Verilator run MyHDL's Verilog of the same cases (marker
othersims, ``make test-sims``). The bench (sim/benches/tb_census.py) also checks the latency of every
non-tail pixel, the reset token and that nothing is left over.
"""

import shutil
from pathlib import Path

import pytest
from myhdl import ResetSignal, Signal

from eyestereo.hdl.dense.census import census, latency
from eyestereo.hdl.flow.convert import GHDL_STDS, analyse, check_verilog, convert, vhdl_ports
from eyestereo.hdl.flow.vlint import mixed_signedness
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.sim.lib.runner import run_bench

TSUKUBA = Path("/work/shared/data/middlebury/tsukuba")
REAL = [f"image:{TSUKUBA / 'im3.png'}", f"image:{TSUKUBA / 'im4.png'}"]
SIMS = ["ghdl", pytest.param("icarus", marks=pytest.mark.othersims),
        pytest.param("verilator", marks=pytest.mark.othersims)]


def _run(request, sim, *, window, width, height, frames, stereo=True, **stim):
    report = run_bench("census", "tb_census", dict(frames=frames, **stim), name=request.node.name,
                       params=dict(window=window, width=width, height=height, stereo=stereo), sim=sim)
    assert report["frames"] == len(frames)
    assert report["pixels_compared"] == len(frames) * width * height * (2 if stereo else 1)
    assert report["latency"] == window + 3 and report["latency_checked"] > 0
    return report


@pytest.mark.sim
@pytest.mark.parametrize("sim", SIMS)
@pytest.mark.parametrize("window", [5, 7])
@pytest.mark.parametrize("width,height,duty", [(32, 24, 1.0), (13, 9, 0.6)])
def test_census_random_stereo(request, sim, window, width, height, duty):
    """Random pairs back to back (the second frame carries the first's tail) after a token."""
    _run(request, sim, window=window, width=width, height=height, duty=duty, seed=width + window,
         frames=[["random:1", "random:2"], ["random:3", "flat:77"]], token_after=37)


@pytest.mark.sim
@pytest.mark.parametrize("sim", SIMS)
@pytest.mark.parametrize("window", [5, 7])
def test_census_tsukuba_stereo(request, sim, window):
    """A 32x24 crop of Tsukuba's im3 / im4 (grey), with idle gaps, twice."""
    _run(request, sim, window=window, width=32, height=24, duty=0.3, seed=window, frames=[REAL, REAL[::-1]])


@pytest.mark.sim
@pytest.mark.parametrize("window", [5, 7])
def test_census_mono(request, window):
    """A mono stream (the kind from the sink): the same rule, one camera."""
    _run(request, "ghdl", window=window, width=11, height=window, duty=0.5, seed=3, stereo=False,
         frames=[["random:5", "random:5"], ["random:6", "random:6"]], token_after=4)


# --- elaboration checks ---------------------------------------------------------------------------
def _ports(bits=24, stereo=True):
    return Signal(bool(0)), ResetSignal(0, active=1, isasync=False), ImageStream(8, stereo=stereo), \
        ImageStream(bits, stereo=stereo)


@pytest.mark.parametrize("kw,bits,words", [
    (dict(window=3), 24, "parameter window must be one of [5, 7]"),
    (dict(window=5.0), 24, "parameter window must be one of [5, 7]"),
    (dict(window=7), 24, "must carry 48-bit data"),
    (dict(window=5, width=4), 24, "frame 4x288 is smaller than the 5x5 census window"),
    (dict(window=7, height=6), 48, "frame 352x6 is smaller than the 7x7 census window"),
    (dict(window=5, width=5000), 24, "width=5000 is too large"),
    (dict(window=5, width=32.0), 24, "parameter width must be an integer"),
])
def test_census_parameters_refused(kw, bits, words):
    with pytest.raises(ValueError, match="census") as e:
        census(*_ports(bits), **kw)
    assert words in str(e.value)


def test_census_ports_refused():
    clk, rst, sink, source = _ports()
    with pytest.raises(ValueError, match="must carry 8-bit data"):
        census(clk, rst, ImageStream(10, stereo=True), source)
    with pytest.raises(ValueError, match="must be a stereo stream"):
        census(clk, rst, sink, ImageStream(24))
    with pytest.raises(ValueError, match="port source is a stereo stream"):
        census(clk, rst, ImageStream(8), source)


def test_census_latency_formula():
    assert (latency(5), latency(7)) == (8, 10)


# --- make vhdl / make verilog: the catalogue's configuration (352x288 stereo) and the 7x7 window ----------
@pytest.mark.skipif(shutil.which("ghdl") is None or shutil.which("iverilog") is None, reason="GHDL and Icarus needed")
@pytest.mark.parametrize("window", [5, 7])
def test_census_converts_and_analyses(tmp_path, window):
    files = convert("census", tmp_path / "vhdl", window=window)
    for std in GHDL_STDS:
        analyse(files, std, tmp_path / std)  # raises with GHDL's messages
    ports = {p["name"]: p["type"] for p in vhdl_ports(files[-1])}
    assert ports["sink_data"] == "unsigned(7 downto 0)" and ports["sink_cam"] == "std_logic"
    assert ports["source_data"] == f"unsigned({window * window - 2} downto 0)" and "source_cam" in ports
    v = convert("census", tmp_path / "verilog", hdl="Verilog", window=window)
    check_verilog(v, "census", tmp_path / "icarus")
    assert not mixed_signedness(v[0].read_text())
