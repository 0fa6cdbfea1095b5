"""AXI4-Stream video bridges on GHDL: bit-exact both ways under random pauses and back-pressure, and the
overflow rule (a cut frame is never a corrupted one) with cocotbext-axi on the AXI side."""

import numpy as np
import pytest
from myhdl import ResetSignal, Signal

from eyestereo.hdl.interfaces.axis import AxiStream
from eyestereo.hdl.axi.axis_to_stream import axis_to_stream
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.hdl.axi.stream_to_axis import stream_to_axis
from eyestereo.sim.lib.runner import run_bench
from eyestereo.tools.models.axis_to_stream import axis_to_stream as a2s_model
from eyestereo.tools.models.stream_to_axis import match_frames, split_frames, to_axis
from eyestereo.tools.stream import TOKEN

SMALL = dict(width=17, height=9)
FRAMES = ["random:1", "random:2", "random:3"]


def _s2a(request, params, cfg):
    return run_bench("stream_to_axis", "tb_stream_to_axis", cfg, name=request.node.name, params=params)


def _a2s(request, params, cfg):
    return run_bench("axis_to_stream", "tb_axis_to_stream", cfg, name=request.node.name, params=params)


# --- models (pure Python) -----------------------------------------------------------------------------
def test_to_axis_marks_sof_and_eol():
    f = np.arange(6).reshape(2, 3)
    assert to_axis(f) == [(0, False, True), (1, False, False), (2, True, False),
                          (3, False, False), (4, False, False), (5, True, False)]


def test_match_frames_accepts_whole_and_line_cut_frames_only():
    a, b, c = (np.arange(12).reshape(3, 4) + k for k in (0, 100, 200))
    rec = split_frames(to_axis(a) + to_axis(b)[:8] + to_axis(c))
    assert match_frames([a, b, c], rec) == ([0, 2], [1])
    assert match_frames([a, b, c], split_frames(to_axis(a) + to_axis(c))) == ([0, 2], [1])  # b dropped
    with pytest.raises(AssertionError):  # a partial line is corruption
        match_frames([a, b, c], split_frames(to_axis(a) + to_axis(b)[:6] + to_axis(c)))
    with pytest.raises(AssertionError):  # a cut frame is not allowed with frame commit
        match_frames([a, b, c], rec, commit="frame")
    with pytest.raises(AssertionError):  # wrong data
        bad = to_axis(a)
        bad[5] = (99, False, False)
        match_frames([a], split_frames(bad))


def test_axis_to_stream_model_rules():
    f = np.arange(6).reshape(2, 3)
    beats, err = a2s_model([(9, False, False)] + to_axis(f), 3, 2)  # junk before the first SOF: silent
    assert err == 0 and beats == [(0, False, False), (1, False, False), (2, True, False),
                                  (3, False, False), (4, False, False), (5, True, True)]
    beats, err = a2s_model(to_axis(f)[:4] + to_axis(f + 10), 3, 2)  # early SOF
    assert err == 1 and beats[4] == TOKEN and beats[5] == (10, False, False) and len(beats) == 11
    short = to_axis(f)
    short[3] = (3, True, False)  # tlast on pixel 0 of line 1
    beats, err = a2s_model(short + to_axis(f), 3, 2)
    assert err == 1 and beats[3] == TOKEN and len(beats) == 4 + 6


# --- parameter and port checks ------------------------------------------------------------------------
def _ports(dw=8):
    return Signal(bool(0)), ResetSignal(0, active=1, isasync=False), Signal(bool(0))


def test_bridges_reject_bad_parameters_and_ports():
    clk, rst, flag = _ports()
    with pytest.raises(ValueError, match="depth=1000 must be a power of two"):
        stream_to_axis(clk, rst, ImageStream(8), AxiStream(8), flag, depth=1000)
    with pytest.raises(ValueError, match="depth=256 is too small: commit='line'"):
        stream_to_axis(clk, rst, ImageStream(8), AxiStream(8), flag, depth=256)
    with pytest.raises(ValueError, match=r"commit='frame' needs the FIFO to hold a whole frame \(101376 words"):
        stream_to_axis(clk, rst, ImageStream(8), AxiStream(8), flag, commit="frame")
    with pytest.raises(ValueError, match="parameter commit must be one of"):
        stream_to_axis(clk, rst, ImageStream(8), AxiStream(8), flag, commit="pixel")
    with pytest.raises(ValueError, match="port source must be an AxiStream"):
        stream_to_axis(clk, rst, ImageStream(8), ImageStream(8), flag)
    with pytest.raises(ValueError, match="port source must carry 8-bit pixels"):
        stream_to_axis(clk, rst, ImageStream(8), AxiStream(10), flag)
    with pytest.raises(ValueError, match="port sink must be an AxiStream"):
        axis_to_stream(clk, rst, ImageStream(8), ImageStream(8), flag)
    with pytest.raises(ValueError, match="port rst must be a ResetSignal"):
        axis_to_stream(clk, Signal(bool(0)), AxiStream(8), ImageStream(8), flag)
    with pytest.raises(ValueError, match="parameter width=0 is too small"):
        axis_to_stream(clk, rst, AxiStream(8), ImageStream(8), flag, width=0)
    with pytest.raises(ValueError, match="AxiStream data_width"):
        AxiStream(0)
    assert len(AxiStream(10).tdata) == 16 and len(AxiStream(8).tdata) == 8


# --- stream_to_axis on GHDL ---------------------------------------------------------------------------
@pytest.mark.sim
@pytest.mark.parametrize("duty,pause,data_width", [(1.0, 0.0, 8), (0.5, 0.3, 8), (0.3, 0.6, 10), (0.6, 0.2, 18)])
def test_stream_to_axis_exact_with_back_pressure(request, duty, pause, data_width):
    _s2a(request, dict(SMALL, data_width=data_width, depth=64, commit="line"),
         dict(frames=FRAMES, duty=duty, pause=pause, seed=int(pause * 10) + data_width, expect="exact"))


@pytest.mark.sim
def test_stream_to_axis_token_cuts_at_a_line(request):
    _s2a(request, dict(SMALL, depth=32, commit="line"),
         dict(frames=FRAMES[:2], duty=0.7, pause=0.2, seed=4, token_after=40, expect="exact"))


@pytest.mark.sim
def test_stream_to_axis_frame_commit_exact(request):
    _s2a(request, dict(SMALL, depth=256, commit="frame"),
         dict(frames=FRAMES, duty=0.8, pause=0.3, seed=5, token_after=60, expect="exact"))


@pytest.mark.sim
@pytest.mark.parametrize("commit,depth", [("line", 32), ("frame", 256)])
def test_stream_to_axis_overflow_cuts_never_corrupts(request, commit, depth):
    # The AXI side stops for 400 clocks in the second frame: the FIFO overflows; the input (80 % duty)
    # is slower than the AXI side (90 % ready) otherwise, so the FIFO recovers and the last frame is whole.
    rep = _s2a(request, dict(SMALL, depth=depth, commit=commit),
               dict(frames=[f"random:{i}" for i in range(1, 8)], duty=0.8, pause=0.1,
                    seed=6, stalls=[[180, 400]], expect="cut", whole=[6]))
    assert rep["overflows"] >= 1 and rep["cut"], rep


@pytest.mark.sim
def test_stream_to_axis_overflow_under_random_back_pressure(request):
    # Input at full rate, the AXI side ready half the time: most frames are cut, none is corrupted.
    rep = _s2a(request, dict(SMALL, depth=32, commit="line"),
               dict(frames=FRAMES + ["random:4"], duty=1.0, pause=0.5, seed=7, expect="cut"))
    assert rep["overflows"] >= 2, rep


# --- axis_to_stream on GHDL ---------------------------------------------------------------------------
@pytest.mark.sim
@pytest.mark.parametrize("pause,data_width", [(0.0, 8), (0.4, 8), (0.8, 12)])
def test_axis_to_stream_exact_with_pauses(request, pause, data_width):
    rep = _a2s(request, dict(SMALL, data_width=data_width), dict(frames=FRAMES, pause=pause, seed=3))
    assert rep["frames"] == len(FRAMES) and rep["tokens"] == 0 and rep["errors"] == 0, rep


@pytest.mark.sim
def test_axis_to_stream_faults_become_tokens(request):
    faults = [[0, "junk"], [1, "early_sof"], [3, "short_line"], [4, "long_line"], [5, "extra_line"], [6, "junk"]]
    rep = _a2s(request, dict(SMALL), dict(frames=[f"random:{i}" for i in range(1, 9)], pause=0.3, seed=4,
                                         faults=faults))
    # By hand: early SOF, short line, long line (token + error each; junk after a reset is silent), the
    # extra line (error only; the junk right after it is part of the same fault).
    assert rep["tokens"] == 3 and rep["errors"] == 4, rep


@pytest.mark.sim
def test_axis_to_stream_tiny_frames(request):
    rep = _a2s(request, dict(width=1, height=1), dict(frames=["random:1", "random:2", "random:3"], pause=0.5,
                                                      seed=5, faults=[[1, "junk"]]))
    assert rep["frames"] >= 2 and rep["pixels_compared"] == rep["frames"], rep
