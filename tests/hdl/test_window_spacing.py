"""Regression of a formal finding: time-shared window filters keep every output beat share clocks apart.

The bench (sim/benches/tb_window_spacing.py) sends a stereo frame with its beats ``share`` clocks apart
and then a reset token, the token's clock swept over the whole tail; before window_control held tokens
(hdl/streaming/window.py), a token one clock after a tail beat left one clock after it (docs/formal.md).
"""

import pytest

from eyestereo.sim.lib.runner import run_bench

pytestmark = pytest.mark.sim

# block, parameters, the clocks from a sink beat to its source beat (the docstrings' latencies: sobel 6,
# harris_window stereo with share 2: 12), the lead in pixels of a camera (r * width + r)
CASES = [("sobel", dict(width=3, height=3, share=2), 6, 4),
         ("sobel", dict(width=4, height=3, share=3), 6, 5),
         ("harris_window", dict(width=5, height=5, share=2), 12, 12)]


@pytest.mark.parametrize("block,params,latency,lead", CASES, ids=lambda v: str(v) if not isinstance(v, dict)
                         else "x".join(str(v[k]) for k in ("width", "height")) + f"_share{v['share']}")
def test_tokens_keep_the_spacing(request, block, params, latency, lead):
    share = params["share"]
    report = run_bench(block, "tb_window_spacing", dict(latency=latency, lead=lead),
                       name=request.node.name, params=dict(params, stereo=True))
    assert report["tokens"] == 2 * lead * share + share and report["min_gap"] >= share


@pytest.mark.parametrize("sim", ["icarus", "verilator"])
def test_tokens_keep_the_spacing_verilog(request, sim):
    """The same on MyHDL's Verilog conversion (sobel 3x3, share 2)."""
    report = run_bench("sobel", "tb_window_spacing", dict(latency=6, lead=4), name=request.node.name, sim=sim,
                       params=dict(width=3, height=3, share=2, stereo=True))
    assert report["tokens"] == 2 * 4 * 2 + 2 and report["min_gap"] >= 2
