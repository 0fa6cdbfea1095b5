"""corner_descriptors (issue 29) against its bit-true model, beat for beat: every corner's descriptor, every row end.

GHDL runs the VHDL, Icarus and Verilator MyHDL's Verilog (one case each here, the rest under the marker
othersims, ``make test-sims``). The bench (sim/benches/tb_corner_descriptors.py) feeds the pixels with idle
clocks and the flags rows behind them (as harris_stereo's come), checks that nothing is left over and that
no corner is dropped; the late case checks that corners whose flags come too late are counted, not sent.
"""

import pytest

from eyestereo.hdl.interfaces.descriptor import DescriptorPort
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.hdl.matching.corner_descriptors import corner_descriptors, lines
from eyestereo.sim.lib.runner import run_bench
from eyestereo.tools.models.match_engine import word_bits

BASE = dict(width=40, height=24, border=4, lead=4, slots=32)
# flags as harris_stereo's at nms 3 (4 rows and 5 pixels behind, a pipeline of 30 clocks)
LAG = dict(lag_rows=4, lag_pixels=5, lag_clocks=30)


def _run(request, sim="ghdl", *, cost, window, frames, params=None, **cfg):
    p = dict(BASE, cost=cost, window=window, **(params or {}))
    report = run_bench("corner_descriptors", "tb_corner_descriptors", dict(frames=frames, seed=5, **cfg),
                       name=request.node.name, params=p, sim=sim)
    assert report["frames"] == len(frames)
    return report


CASES = {
    # dense random flags (an eighth of the pixels: rows of 10 corners per camera, the queue under load), idle
    # clocks, harris's lag
    "sad5_dense": dict(cost="sad", window=5, frames=["random:1:0.12", "random:2:0.05"], idle=0.3, **LAG),
    "census7": dict(cost="census", window=7, frames=["random:3:0.1", "random:4:0.1"], idle=0.2, **LAG),
    # back to back beats, frames back to back: the last rows' flags come during the next frame's pixels
    "sad9_back_to_back": dict(cost="sad", window=9, frames=["random:5:0.08", "random:6:0.08", "random:7:0.08"],
                              idle=0.0, **LAG),
    # 11 x 11: the windows end a row after the flags (border 5, lead 4); the flags' tail every 3 clocks
    "census11_late_windows": dict(cost="census", window=11, frames=["random:8:0.06", "random:9:0.06"], idle=0.1,
                                  tail_spacing=3, params=dict(border=5), **LAG),
    # the flags with no lag at all (a lead of 0 rows): the queue waits for every window
    "sad7_flags_first": dict(cost="sad", window=7, frames=["random:10:0.1", "random:11:0.1"], idle=0.2,
                             lag_rows=0, lag_pixels=0, lag_clocks=0, params=dict(lead=0)),
}


@pytest.mark.sim
@pytest.mark.parametrize("case", list(CASES))
def test_corner_descriptors_frames(request, case):
    report = _run(request, **CASES[case])
    assert sum(sum(c) for c in report["corners"]) > 40  # the cases send many corners


@pytest.mark.sim
@pytest.mark.parametrize("sim", ["icarus", "verilator"])
def test_corner_descriptors_on_the_verilog(request, sim):
    """MyHDL's Verilog gives the same beats (census 7 x 7: the comparisons' wiring, SAD: the rotation)."""
    _run(request, sim, **CASES["census7"])
    _run(request, sim, **CASES["sad5_dense"])


@pytest.mark.othersims
@pytest.mark.parametrize("sim", ["icarus", "verilator"])
@pytest.mark.parametrize("case", ["sad9_back_to_back", "census11_late_windows", "sad7_flags_first"])
def test_corner_descriptors_other_sims(request, sim, case):
    _run(request, sim, **CASES[case])


@pytest.mark.sim
def test_flags_too_late_are_counted_not_sent(request):
    """Flags 12 rows behind the pixels (the block allows 4 and a row), frames back to back: the windows of all
    but the last frame's last rows have left the buffers when their flags come (overwritten by the next
    rows); those corners are counted in ``late``, not sent with a wrong window; every row end goes out."""
    report = _run(request, cost="sad", window=5, frames=["random:12:0.05", "random:13:0.05"], expect_late=True,
                  lag_rows=12, lag_pixels=0, lag_clocks=0)
    assert report["late"] > 20 and report["beats"] >= 2 * BASE["height"]


@pytest.mark.parametrize("change,match", [
    (dict(cost="ssd"), "cost"), (dict(window=6), "window"), (dict(border=3, window=9), "border"),
    (dict(border=3, lead=4, window=5), "lead"), (dict(lead=16), "lead"), (dict(slots=24), "slots"),
    (dict(width=8), "width"),
])
def test_parameters_are_checked(change, match):
    p = dict(cost="sad", window=9, width=40, height=24, border=4, lead=4, slots=32)
    p.update(change)
    wb = word_bits(p["cost"], p["window"]) if p["cost"] in ("sad", "census") and p["window"] in (5, 7, 9, 11) else 8
    src = DescriptorPort(wb, width=p["width"], height=p["height"])
    from myhdl import ResetSignal, Signal, intbv

    with pytest.raises(ValueError, match=match):
        corner_descriptors(Signal(bool(0)), ResetSignal(0, active=1, isasync=False), ImageStream(8, stereo=True),
                           ImageStream(1, stereo=True), src, Signal(intbv(0)[16:]), Signal(intbv(0)[16:]), **p)


def test_lines_cover_the_window_the_lead_and_a_row_of_slack():
    assert lines(9, 4) == 11 and lines(5, 4) == 9 and lines(11, 0) == 13 and lines(11, 4) == 13
