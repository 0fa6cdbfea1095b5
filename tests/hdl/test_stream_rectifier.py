"""The stream rectifier (rectify="stream"): the line cache and the rectifier against the rectification model.

sim/benches/tb_stream_rectifier.py plays two cameras into the block with a camera's timing (the pixel clock and
blanking in memory clocks, the right camera some lines behind the left); every beat of every frame is compared
with :func:`eyestereo.tools.models.rectifier.stream` of that frame's camera images. Full 352x288 frames of both
calibrations are in the benchmark (sim/measure/bench_stream_rectifier.py).
"""

import pytest

from eyestereo.sim.lib.runner import run_bench
from eyestereo.tools.models.line_cache import plan
from eyestereo.tools.models.poly_unit import Calibration

pytestmark = pytest.mark.sim

# small frames, the CIF camera's blanking scaled down: lines of 2 x 48 PCLK + 40, at 8.9 MHz (11.2 memory
# clocks a pixel, as the OV6630's 17.73 MHz PCLK gives at 100 MHz)
SMALL = dict(timing=dict(h_blank=40, v_sync=1, v_back=2, v_front=8), pclk_mhz=17.73)


def small_plan(spec: str):
    from eyestereo.tools.camera import CameraTiming

    cal = Calibration.load(spec)
    timing = CameraTiming(width=cal.source_width, height=cal.source_height, **SMALL["timing"])
    return plan(cal, timing=timing, pixel_clock_hz=SMALL["pclk_mhz"] * 1e6)


def test_stream_rectifier_two_frames(request):
    spec = "rig:48x36"
    p = small_plan(spec)
    rep = run_bench("stream_rectifier", "tb_stream_rectifier",
                    dict(SMALL, frames=2, images=["random:3", "random:4"], skew=1.5), name=request.node.name,
                    params=dict(quantizers=spec, lines=p.lines))
    assert rep["bit_exact"] and rep["overruns"] == 0 and rep["beats"] == 2 * 2 * 48 * 36


def test_stream_rectifier_plan_is_what_the_bench_needs(request):
    """The plan of the bench's own timing, and a cache of an eighth of it: overrun pulses (the block catches a
    cache too small for its calibration instead of rectifying lines of another row), once in each frame (the
    line cache pulses at every read of an overwritten line: the front end's DROPPED counts frames)."""
    spec = "rig:48x36"
    p = small_plan(spec)
    assert p.lines >= 8
    rep = run_bench("stream_rectifier", "tb_stream_rectifier",
                    dict(SMALL, frames=2, images="random:5", skew=0, expect_overrun=True), name=request.node.name,
                    params=dict(quantizers=spec, lines=p.lines // 8))
    assert rep["overruns"] == rep["frames_rectified"] == 2


@pytest.mark.parametrize("sim", ["icarus", pytest.param("verilator", marks=pytest.mark.othersims)])
def test_stream_rectifier_verilog(request, sim):
    """MyHDL's Verilog conversion of the block (line cache, rectifier) on the Verilog simulators: the same beats
    (Verilator with ``make test-sims``)."""
    import shutil

    if sim == "icarus" and shutil.which("iverilog") is None:
        pytest.skip("Icarus Verilog not installed")
    spec = "rig:32x24"
    p = small_plan(spec)
    rep = run_bench("stream_rectifier", "tb_stream_rectifier",
                    dict(SMALL, frames=2, images=["random:7", "file:chessboard_left01.jpg"], skew=0.5),
                    name=request.node.name, params=dict(quantizers=spec, lines=p.lines), sim=sim)
    assert rep["bit_exact"] and rep["overruns"] == 0 and rep["beats"] == 2 * 2 * 32 * 24
