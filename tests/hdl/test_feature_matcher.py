"""feature_matcher (issue 29: corner_descriptors + match_engine) against its bit-true model, word for word.

The whole hardware matcher on a rectified stereo stream and its flags: the list of every frame equals
:func:`eyestereo.tools.models.feature_matcher.feature_matcher` on the flags' corners inside the border. GHDL
runs the VHDL, Icarus and Verilator MyHDL's Verilog (one case each here, the rest under othersims). Full
352 x 288 frames of the Middlebury pairs with 500 Harris corners per image: sim/measure/bench_matcher.py
(docs/matching.md).
"""

import pytest

from eyestereo.hdl.interfaces.queue import QueuePort
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.hdl.matching.feature_matcher import feature_matcher
from eyestereo.sim.lib.runner import run_bench

BASE = dict(width=64, height=32, border=4, lead=4, queue=32, d_min=0, d_max=20, rows=0, slots=32, corners=255,
            max_matches=1023, events=16)
LAG = dict(lag_rows=4, lag_pixels=5, lag_clocks=30)  # harris_stereo's at nms 3 and a pipeline


def _run(request, sim="ghdl", *, cost, window, frames, params=None, **cfg):
    p = dict(BASE, cost=cost, window=window, **(params or {}))
    report = run_bench("feature_matcher", "tb_feature_matcher", dict(frames=frames, seed=7, **cfg),
                       name=request.node.name, params=p, sim=sim)
    assert report["frames"] == len(frames)
    return report


CASES = {
    # shifted textures with their Harris corners: most corners find their match
    "sad9_lr": dict(cost="sad", window=9, frames=["texture:1:40:6", "texture:2:40:9"], t_max=11, lr_check=True,
                    idle=0.2, stall=0.2, **LAG),
    "census7_r1_u10": dict(cost="census", window=7, frames=["texture:3:40:5", "texture:4:40:7"], h_max=25,
                           uniqueness=10, lr_check=True, idle=0.1, stall=0.3, params=dict(rows=1), **LAG),
    # random flags: many candidates, ties; frames back to back
    "sad5_random": dict(cost="sad", window=5, frames=["random:5:0.04", "random:6:0.04"], t_max=100, idle=0.0,
                        **LAG),
}


@pytest.mark.sim
@pytest.mark.parametrize("case", list(CASES))
def test_feature_matcher_lists(request, case):
    report = _run(request, **CASES[case])
    assert sum(report["matches"]) > 10 and sum(report["candidates"]) > 40  # the cases match


@pytest.mark.sim
@pytest.mark.parametrize("sim", ["icarus", "verilator"])
def test_feature_matcher_on_the_verilog(request, sim):
    report = _run(request, sim, **CASES["sad9_lr"])
    assert sum(report["matches"]) > 10


@pytest.mark.othersims
@pytest.mark.parametrize("sim", ["icarus", "verilator"])
@pytest.mark.parametrize("case", ["census7_r1_u10", "sad5_random"])
def test_feature_matcher_lists_other_sims(request, sim, case):
    _run(request, sim, **CASES[case])


@pytest.mark.parametrize("change,match", [
    (dict(queue=24), "parameter queue=24"), (dict(slots=24), "parameter slots=24"), (dict(border=2), "border"),
    (dict(d_min=9, d_max=8), "empty"), (dict(window=4), "window"),
])
def test_parameters_are_checked_and_named_as_the_top_names_them(change, match):
    from myhdl import ResetSignal, Signal, intbv

    p = dict(BASE, cost="sad", window=9)
    p.update(change)
    ports = [Signal(bool(0)), ResetSignal(0, active=1, isasync=False), ImageStream(8, stereo=True),
             ImageStream(1, stereo=True), QueuePort(16), Signal(intbv(0)[13:]), Signal(intbv(0)[7:]),
             Signal(bool(0)), Signal(bool(0)), Signal(intbv(0)[16:]), Signal(intbv(0)[16:])]
    with pytest.raises(ValueError, match=match) as e:
        feature_matcher(*ports, **p)
    assert str(e.value).startswith("feature_matcher: ")
