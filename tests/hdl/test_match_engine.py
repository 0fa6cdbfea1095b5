"""match_engine (issue 29) against its bit-true model, word for word: the match list of every frame.

GHDL runs the VHDL, Icarus and Verilator MyHDL's Verilog (one case each here, the rest under the marker
othersims, ``make test-sims``). The bench (sim/benches/tb_match_engine.py) feeds the corners row by row
with idle gaps, holds the list port's ``ready`` low in random stretches, and checks that nothing is left
over and that ``dropped`` stays low; the overload cases check that it rises.
"""

import pytest

from eyestereo.hdl.matching.match_engine import match_engine
from eyestereo.sim.lib.runner import run_bench

BASE = dict(width=64, height=24, d_min=1, d_max=25, slots=32, corners=63, max_matches=1023, events=16)
FRAMES = ["random:1:40", "texture:2:40"]


def _run(request, sim="ghdl", *, cost, window, rows, limit, frames=FRAMES, params=None, **cfg):
    p = dict(BASE, cost=cost, window=window, rows=rows, **(params or {}))
    report = run_bench("match_engine", "tb_match_engine", dict(frames=frames, limit=limit, seed=3, **cfg),
                       name=request.node.name, params=p, sim=sim)
    assert report["frames"] == len(frames)
    return report


CASES = {
    # cost, window, rows, limit (census: 13 of 24 bits; SAD: 2200 of 25 pixels), then the bench's settings
    "census5_r1_lr_u10": dict(cost="census", window=5, rows=1, limit=13, uniqueness=10, lr_check=True, stall=0.3,
                              row_clocks=120),
    "sad5_r2_lr_u5": dict(cost="sad", window=5, rows=2, limit=2200, uniqueness=5, lr_check=True, stall=0.2,
                          row_clocks=300),
    "census7_r0": dict(cost="census", window=7, rows=0, limit=26, row_clocks=100),
    "sad9_r0_lr": dict(cost="sad", window=9, rows=0, limit=11 * 81, lr_check=True, stall=0.1, row_clocks=400,
                       frames=["texture:4:50", "texture:5:50"], params=dict(d_min=0, d_max=30)),
}


@pytest.mark.sim
@pytest.mark.parametrize("case", list(CASES))
def test_match_engine_lists(request, case):
    report = _run(request, **CASES[case])
    assert sum(report["matches"]) > 5 and sum(report["candidates"]) > 40  # the cases exercise the ranking


@pytest.mark.sim
@pytest.mark.parametrize("sim", ["icarus", "verilator"])
def test_match_engine_on_the_verilog(request, sim):
    """MyHDL's Verilog of the engine gives the same lists (census, R = 1, both checks, back-pressure)."""
    report = _run(request, sim, **CASES["census5_r1_lr_u10"])
    assert sum(report["matches"]) > 5


@pytest.mark.othersims
@pytest.mark.parametrize("sim", ["icarus", "verilator"])
@pytest.mark.parametrize("case", ["sad5_r2_lr_u5", "census7_r0", "sad9_r0_lr"])
def test_match_engine_lists_other_sims(request, sim, case):
    _run(request, sim, **CASES[case])


@pytest.mark.sim
def test_census11_and_a_cut_list(request):
    """The widest word (120 census bits) and max_matches = 4: the list is cut, the trailer says so."""
    report = _run(request, cost="census", window=11, rows=1, limit=60, lr_check=False, row_clocks=120,
                  params=dict(max_matches=4))
    assert all(m == 4 for m in report["matches"])  # the model's list, cut at 4 (it has more)


@pytest.mark.sim
@pytest.mark.parametrize("overload", ["slots", "corners", "pace"])
def test_dropped_rises_when_the_engine_cannot_keep_up(request, overload):
    """A store too small for the rows in flight, a frame with more left corners than the result table, or
    rows faster than the engine matches them: ``dropped`` rises."""
    params = dict(slots=dict(slots=4), corners=dict(corners=10), pace={})[overload]
    row_clocks = 4 if overload == "pace" else 120
    _run(request, cost="sad", window=5, rows=2, limit=2200, row_clocks=row_clocks, gap=0, params=params,
         frames=["random:1:40"], expect_dropped=True)


@pytest.mark.parametrize("change,match", [
    (dict(cost="ssd"), "cost"), (dict(window=6), "window"), (dict(d_min=9, d_max=8), "empty"),
    (dict(rows=8), "rows"), (dict(slots=48), "power of two"), (dict(events=3), "power of two"),
    (dict(corners=0), "corners"), (dict(max_matches=40000), "max_matches"), (dict(d_max=300), "d_max"),
])
def test_parameters_are_checked(change, match):
    from eyestereo.hdl.flow.catalog import BLOCKS

    spec = BLOCKS["match_engine"]
    ports, kw, _ = spec.ports()
    with pytest.raises(ValueError, match=match):
        match_engine(*ports.values(), **dict(kw, **change))
