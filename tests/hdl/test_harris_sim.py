"""GHDL regressions of the Harris blocks and harris_mono against their bit-true models, bit for bit.

Every case also sends a partial frame cut by a reset token (unless it is a full-size run without one)
and two frames back to back; see tests/test_sim.py for what the bench checks.
"""

import pytest

from eyestereo.sim.lib.runner import fastest_ghdl_backend, fastest_simulator, run_bench
from eyestereo.tools.models import harris_mono as hm
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH, K_CODE_DEFAULT, NMS_DEFAULT, THRESHOLD_BLOCKS

pytestmark = pytest.mark.sim

SMALL = dict(width=23, height=13)
DUTIES = [1.0, 0.5, 0.1]


# Full frames run on GHDL's LLVM back end when it is installed (about twice mcode's speed on these designs;
# docs/benchmarks.md), the small ones on mcode (no elaboration time).
FULL = fastest_ghdl_backend()


def _run(block, bench, params, stim, request, backend=None, sim=None):
    report = run_bench(block, bench, stim, name=request.node.name, params=params, backend=backend, sim=sim)
    assert report["frames"] == len(stim["frames"])
    assert report["pixels_compared"] > 0
    return report


# --- harris_window --------------------------------------------------------------------------------
@pytest.mark.parametrize("duty", DUTIES)
@pytest.mark.parametrize("lim", [128, 256])  # 256: codes beyond a Sobel's range reach the clamps
def test_harris_window_random(request, duty, lim):
    _run("harris_window", "tb_harris_window", SMALL,
         dict(frames=[f"grad:1:{lim}", f"grad:2:{lim}"], duty=duty, seed=3, token_after=70), request)


def test_harris_window_real_image_full_frame(request):
    _run("harris_window", "tb_harris_window", dict(width=FRAME_WIDTH, height=FRAME_HEIGHT),
         dict(frames=["sobel:file:tsukuba_im3.png"], duty=1.0), request, backend=FULL)


# --- cornerness -----------------------------------------------------------------------------------
@pytest.mark.parametrize("k", [0, 10, 61, 255])
@pytest.mark.parametrize("duty", [1.0, 0.3])
def test_cornerness_random_full_range(request, k, duty):
    _run("cornerness", "tb_cornerness", SMALL,
         dict(frames=["rwindow:1", "rwindow:2"], duty=duty, k=k, token_after=50), request)


def test_cornerness_real_windows(request):
    _run("cornerness", "tb_cornerness", dict(width=64, height=48),
         dict(frames=["window:file:chessboard_left01.jpg", "window:file:tsukuba_im3.png"], duty=1.0, k=15),
         request)


# --- prethreshold ----------------------------------------------------------------------------------
THR_4X4 = {i: (i * 37 % 23 - 11) * 40 for i in range(16)}


@pytest.mark.parametrize("duty", DUTIES)
def test_prethreshold_4x4_different_thresholds(request, duty):
    _run("prethreshold", "tb_prethreshold", dict(SMALL, blocks=(4, 4)),
         dict(frames=["rcorner:1:-600:600", "rcorner:2:-600:600"], duty=duty, thresholds=THR_4X4, token_after=40),
         request)


@pytest.mark.parametrize("blocks,thr", [((1, 1), {0: 123}), ((1, 1), {0: -5}), ((3, 2), {0: 50, 4: -50, 5: 300}),
                                        ((4, 4), {})])
def test_prethreshold_blocks(request, blocks, thr):
    _run("prethreshold", "tb_prethreshold", dict(width=17, height=9, blocks=blocks),
         dict(frames=["rcorner:3:-400:400", "rcorner:4:-400:400"], duty=0.7, thresholds=thr, token_after=20), request)


def test_prethreshold_reset_clears_thresholds(request):
    _run("prethreshold", "tb_prethreshold", dict(SMALL, blocks=(4, 4)),
         dict(frames=["rcorner:5:-300:300"], duty=1.0, thresholds=THR_4X4, reset_after_write=True), request)


def test_prethreshold_full_frame(request):
    _run("prethreshold", "tb_prethreshold", dict(width=FRAME_WIDTH, height=FRAME_HEIGHT, blocks=THRESHOLD_BLOCKS),
         dict(frames=["rcorner:6:-1000:1000"], duty=1.0, thresholds=THR_4X4), request)


# --- nms --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("duty", DUTIES)
@pytest.mark.parametrize("size", [1, 3, 5])
def test_nms_random_with_ties(request, size, duty):
    _run("nms", "tb_nms", dict(SMALL, size=size),
         dict(frames=["rcorner:1:-2:3", "rcorner:2:-1:1"], duty=duty, seed=size, token_after=60), request)


@pytest.mark.parametrize("size", [3, 5])
def test_nms_smallest_frame(request, size):
    _run("nms", "tb_nms", dict(width=size, height=size, size=size),
         dict(frames=["rcorner:7:-1:2", "rcorner:8:-1:2", "rcorner:9:-1:2"], duty=1.0), request)


# --- harris_mono -----------------------------------------------------------------------------------
THR_TSUKUBA = [hm.threshold_code(c) for c in (2e8, 4e8, 1e8, 6e8, 3e8, 1e9, 5e7, 2e8,
                                              8e8, 1e8, 3e8, 4e8, 6e8, 2e8, 1e8, 5e8)]


@pytest.mark.parametrize("nms", [1, 3, 5])
@pytest.mark.parametrize("k", [K_CODE_DEFAULT, hm.k_code(0.1)])
def test_harris_mono_random_small(request, nms, k):
    _run("harris_mono", "tb_harris_mono", dict(width=40, height=30, blocks=(2, 2), nms=nms),
         dict(frames=["random:1", "random:2"], duty=0.5, seed=nms, k=k, thresholds=[0, 5, 100, -3], token_after=90),
         request)


def test_harris_mono_fast_numeric_std(request):
    """The bench with the VHDL player/recorder on GHDL's faster numeric_std (sim/lib/ghdl_ieee.py, what the
    speed benchmark's fastest GHDL column uses): bit-exact with the model, reset token and idle cycles
    included (tests/hdl/test_ghdl_ieee.py compares the library itself with IEEE's)."""
    rep = _run("harris_mono", "tb_harris_mono", dict(width=48, height=36, blocks=(2, 2), nms=3),
               dict(frames=["random:5", "file:tsukuba_im3.png", "random:6"], duty=0.6, seed=7, k=K_CODE_DEFAULT,
                    thresholds=[0, 5, 100, -3], token_after=120, drivers="hdl", ieee="fast"), request)
    assert rep["pixels_compared"] == 3 * (48 - 8) * (36 - 8)  # every pixel the model specifies (4 px border)


def test_harris_mono_pattern_small(request):
    _run("harris_mono", "tb_harris_mono", dict(width=64, height=48, blocks=(1, 1), nms=5),
         dict(frames=["ramp", "random:4"], duty=0.8, k=hm.k_code(0.24), thresholds=[2], token_after=200), request)


def test_harris_mono_full_frames_4x4_nms3(request):
    """Two real 352x288 frames back to back at full rate, 4x4 blocks with 16 different thresholds.

    On the fastest simulator (Verilator when installed), as the next one: the VHDL runs full frames in
    test_harris_mono_full_frame_nms1, and
    tests/hdl/test_simulators.py checks GHDL, Icarus and Verilator give the same words on full frames."""
    _run("harris_mono", "tb_harris_mono",
         dict(width=FRAME_WIDTH, height=FRAME_HEIGHT, blocks=THRESHOLD_BLOCKS, nms=NMS_DEFAULT),
         dict(frames=["file:tsukuba_im3.png", "file:chessboard_left01.jpg"], duty=1.0, k=K_CODE_DEFAULT,
              thresholds=THR_TSUKUBA, token_after=3000), request, sim=fastest_simulator())


def test_harris_mono_full_frame_global_nms5_gaps(request):
    _run("harris_mono", "tb_harris_mono", dict(width=FRAME_WIDTH, height=FRAME_HEIGHT, blocks=(1, 1), nms=5),
         dict(frames=["file:chessboard_left01.jpg"], duty=0.6, seed=5, k=hm.k_code(0.06),
              thresholds=[hm.threshold_code(2e8)]), request, sim=fastest_simulator())


def test_harris_mono_full_frame_nms1(request):
    _run("harris_mono", "tb_harris_mono", dict(width=FRAME_WIDTH, height=FRAME_HEIGHT, blocks=THRESHOLD_BLOCKS, nms=1),
         dict(frames=["file:tsukuba_im3.png"], duty=1.0, k=hm.k_code(0.05), thresholds=THR_TSUKUBA), request,
         backend=FULL)


def test_harris_mono_test_pattern_in_hardware(request):
    """The checkerboard test pattern through the hardware: the same flags as the model, bit for bit
    (on the fastest simulator; the VHDL's full frames: test_harris_mono_full_frame_nms1)."""
    _run("harris_mono", "tb_harris_mono", dict(width=FRAME_WIDTH, height=FRAME_HEIGHT, blocks=(1, 1), nms=5),
         dict(frames=["checker:1"], duty=1.0, k=hm.k_code(0.24), thresholds=[13]), request, sim=fastest_simulator())
