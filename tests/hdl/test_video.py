"""The video output's blocks (issue 27): video_timing, tmds_encoder, tmds_serializer against their models.

GHDL runs the VHDL (marker sim); Icarus and Verilator run MyHDL's Verilog of the same benches (marker
othersims, ``make test-sims``). The serializer's bench also decodes what the block sends with the DVI
receiver model and gets the test images back. The models themselves are checked against DVI 1.0 and the
published mode tables in tests/models/test_tmds.py.
"""

import shutil

import pytest
from myhdl import ResetSignal, Signal, intbv

from eyestereo.hdl.flow.convert import GHDL_STDS, analyse, check_verilog, convert
from eyestereo.hdl.flow.vlint import mixed_signedness
from eyestereo.hdl.video.tmds_encoder import tmds_encoder
from eyestereo.hdl.video.tmds_serializer import tmds_serializer
from eyestereo.hdl.video.video_timing import video_timing
from eyestereo.sim.lib.runner import run_bench
from eyestereo.tools.models.video_timing import MODES

SIMS = ["ghdl", pytest.param("icarus", marks=pytest.mark.othersims),
        pytest.param("verilator", marks=pytest.mark.othersims)]
needs_ghdl = pytest.mark.skipif(shutil.which("ghdl") is None, reason="GHDL not installed")


def _sig(n):
    return Signal(bool(0)) if n == 1 else Signal(intbv(0)[n:])


def _rst():
    return ResetSignal(0, active=1, isasync=False)


# --- benches ---------------------------------------------------------------------------------------------------
@pytest.mark.sim
@needs_ghdl
@pytest.mark.parametrize("sim", SIMS)
@pytest.mark.parametrize("mode", ["sim-64x48", "sim-32x24"])
def test_video_timing_two_frames(request, sim, mode):
    m = MODES[mode]
    rep = run_bench("video_timing", "tb_video_timing", dict(clocks=2 * m.frame_clocks), name=request.node.name,
                    params=dict(mode=mode), sim=sim)
    assert rep["clocks"] == 2 * m.frame_clocks and rep["restart"] > m.h_total


@pytest.mark.sim
@needs_ghdl
def test_video_timing_640x480_first_lines(request):
    """Vertical sync, back porch (35 lines) and the first two active lines of 640x480, then a reset mid-line."""
    m = MODES["640x480@60"]
    rep = run_bench("video_timing", "tb_video_timing", dict(clocks=37 * m.h_total, gap=300), name=request.node.name,
                    params=dict(mode="640x480@60"))
    assert rep["clocks"] == 29600


@pytest.mark.sim
@needs_ghdl
@pytest.mark.parametrize("sim", SIMS)
@pytest.mark.parametrize("seed,max_run", [(1, 40), (2, 6)])
def test_tmds_encoder_random(request, sim, seed, max_run):
    rep = run_bench("tmds_encoder", "tb_tmds_encoder", dict(clocks=3000, seed=seed, max_run=max_run),
                    name=request.node.name, sim=sim)
    assert rep["characters"] == 3000 and rep["data"] > 1000 and rep["control"] > 1000
    assert rep["distinct"] > 200  # many different characters, the four control ones among them


@pytest.mark.sim
@needs_ghdl
@pytest.mark.parametrize("sim,mode,fast_phase", [
    ("ghdl", "sim-32x24", 2000), ("ghdl", "sim-32x24", 7000), ("ghdl", "sim-64x48", 4000),
    *(pytest.param(s, "sim-32x24", 2000, marks=pytest.mark.othersims) for s in ("icarus", "verilator"))])
def test_tmds_serializer_to_receiver(request, sim, mode, fast_phase):
    """The fast clock's edges 2, 7 and 4 ns after the pixel clock's (the same latency: the third fast edge)."""
    rep = run_bench("tmds_serializer", "tb_tmds_serializer",
                    dict(mode=mode, frames=2, seed=len(request.node.name), fast_phase=fast_phase),
                    name=request.node.name, sim=sim)
    assert rep["frames"] == 2 and rep["fast_clocks"] == 5 * (rep["characters"] + 3)
    assert rep["timing"]["h_total"] == MODES[mode].h_total


# --- make vhdl / make verilog ------------------------------------------------------------------------------------
@pytest.mark.skipif(shutil.which("ghdl") is None or shutil.which("iverilog") is None, reason="GHDL and Icarus needed")
@pytest.mark.parametrize("name", ["video_timing", "tmds_encoder", "tmds_serializer"])
def test_video_blocks_convert_and_analyse(tmp_path, name):
    files = convert(name, tmp_path / "vhdl")
    for std in GHDL_STDS:
        analyse(files, std, tmp_path / std)
    v = convert(name, tmp_path / "verilog", hdl="Verilog")
    check_verilog(v, name, tmp_path / "icarus")
    assert not mixed_signedness(v[0].read_text())


# --- elaboration checks ------------------------------------------------------------------------------------------
def _timing_ports(xw=10, yw=9):
    return [Signal(bool(0)), _rst(), _sig(1), _sig(1), _sig(1), _sig(xw), _sig(yw), _sig(1), _sig(1)]


def test_video_timing_elaborates_with_and_without_the_pulses():
    assert video_timing(*_timing_ports()) is not None
    assert video_timing(*_timing_ports(6, 6)[:7], mode="sim-64x48") is not None


@pytest.mark.parametrize("ports,kw,match", [
    (_timing_ports(), dict(mode="1080p"), r"^video_timing: unknown video mode '1080p'; the modes are"),
    (_timing_ports(9, 9), {}, r"^video_timing: port x must be an unsigned Signal\(intbv\(0\)\[10:\]\) for the 640 "
                              r"columns of mode 640x480@60, got 9 bits$"),
    (_timing_ports(), dict(mode="sim-64x48"), r"^video_timing: port x must be .*\[6:\]"),
    (_timing_ports(10, 1), {}, r"^video_timing: port y must be .* got a Signal\(bool\)$"),
])
def test_video_timing_refuses(ports, kw, match):
    with pytest.raises(ValueError, match=match):
        video_timing(*ports, **kw)


def test_video_timing_refuses_swapped_clock_and_reset():
    p = _timing_ports()
    p[0], p[1] = p[1], p[0]
    with pytest.raises(ValueError, match=r"^video_timing: port clk must be the clock"):
        video_timing(*p)


def _encoder_ports(dw=8, qw=10):
    return [Signal(bool(0)), _rst(), _sig(dw), _sig(1), _sig(1), _sig(1), _sig(qw)]


@pytest.mark.parametrize("ports,match", [
    (_encoder_ports(dw=9), r"^tmds_encoder: port data must be 8 bits wide, got 9$"),
    (_encoder_ports(qw=8), r"^tmds_encoder: port q must be 10 bits wide, got 8$"),
    (_encoder_ports()[:2] + [Signal(intbv(0, min=-128, max=128))] + _encoder_ports()[3:],
     r"^tmds_encoder: port data must be an unsigned"),
])
def test_tmds_encoder_refuses(ports, match):
    with pytest.raises(ValueError, match=match):
        tmds_encoder(*ports)


def _serializer_ports(dw=10, qw=2):
    return [Signal(bool(0)), Signal(bool(0)), _rst()] + [_sig(dw) for _ in range(3)] + [_sig(qw) for _ in range(4)]


def test_tmds_serializer_refuses():
    with pytest.raises(ValueError, match=r"^tmds_serializer: port d0 must be 10 bits wide, got 8$"):
        tmds_serializer(*_serializer_ports(dw=8))
    with pytest.raises(ValueError, match=r"^tmds_serializer: port q0 must be 2 bits wide, got 1$"):
        tmds_serializer(*_serializer_ports(qw=1))
    p = _serializer_ports()
    p[1] = p[0]
    with pytest.raises(ValueError, match=r"^tmds_serializer: ports clk and clk5 are the same signal"):
        tmds_serializer(*p)
    assert tmds_serializer(*_serializer_ports()) is not None
