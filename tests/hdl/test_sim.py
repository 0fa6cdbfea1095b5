"""GHDL regressions: every block against its bit-true numpy model, bit for bit (cocotb benches in sim/).

Each case converts the block with its hardware parameters into its own folder under build/sim/ and runs
the bench: optionally a partial frame and a reset token, then two (or one full-size) frames back to
back, with random idle cycles at the given duty. The bench checks protocol, geometry, data on every
pixel whose window lies inside the image, frame and token counts, and that nothing is left over.
"""

import pytest

from eyestereo.sim.lib.runner import run_bench
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH

pytestmark = pytest.mark.sim

SMALL = dict(width=17, height=9)
DUTIES = [1.0, 0.5, 0.1]


def _run(block, bench, params, stim, request):
    report = run_bench(block, bench, stim, name=request.node.name, params=params)
    assert report["frames"] == len(stim["frames"])
    assert report["pixels_compared"] > 0
    return report


# --- line_delay --------------------------------------------------------------------------------
@pytest.mark.parametrize("data_width", [8, 36])
@pytest.mark.parametrize("duty", DUTIES)
@pytest.mark.parametrize("seed", [1, 2])
def test_line_delay_random(request, data_width, duty, seed):
    _run("line_delay", "tb_line_delay", dict(SMALL, data_width=data_width),
         dict(frames=[f"random:{seed}", f"random:{seed + 10}"], duty=duty, seed=seed, token_after=23), request)


@pytest.mark.parametrize("geometry", [(1, 4), (5, 2), (2, 2)], ids=lambda g: f"{g[0]}x{g[1]}")
def test_line_delay_tiny(request, geometry):
    w, h = geometry
    _run("line_delay", "tb_line_delay", dict(width=w, height=h, data_width=4),
         dict(frames=["random:3", "random:4"], duty=0.7, seed=3, token_after=1), request)


def test_line_delay_full_frame(request):
    _run("line_delay", "tb_line_delay", dict(width=FRAME_WIDTH, height=FRAME_HEIGHT, data_width=8),
         dict(frames=["file:chessboard_left01.jpg"], duty=1.0), request)


# --- convolve (the window machinery, both forms, 3x3 and 5x5) -----------------------------------
KERNELS = {
    "sep3": dict(col=[1, 2, 1], row=[1, 2, 1], shift=4, kernel=None),
    "sep3neg": dict(col=[-1, 3, -1], row=[1, 0, -1], shift=0, kernel=None),
    "sep5": dict(col=[1, 4, 6, 4, 1], row=[-1, -2, 0, 2, 1], shift=3, kernel=None),
    "full3": dict(kernel=[[0, -1, 0], [-1, 5, -1], [0, -1, 0]], shift=0, col=None, row=None),
    "full5": dict(kernel=[[1, -2, 3, 0, 1], [0, 1, 2, 3, 4], [5, -6, 7, 1, 1], [1, 1, 1, 1, 1], [0, 0, -9, 0, 0]],
                  shift=2, col=None, row=None),
}


@pytest.mark.parametrize("duty", DUTIES)
@pytest.mark.parametrize("kernel", sorted(KERNELS))
def test_convolve_random(request, kernel, duty):
    seed = sorted(KERNELS).index(kernel) + int(duty * 10)
    _run("convolve", "tb_convolve", dict(SMALL, **KERNELS[kernel]),
         dict(frames=[f"random:{seed}", f"random:{seed + 1}"], duty=duty, seed=seed, token_after=40), request)


@pytest.mark.parametrize("kernel,size", [("sep3", 3), ("full5", 5), ("sep5", 5)])
def test_convolve_smallest_frame(request, kernel, size):
    # The smallest frame a window fits: the self-emitted tail is most of the frame here.
    _run("convolve", "tb_convolve", dict(width=size, height=size, **KERNELS[kernel]),
         dict(frames=["random:5", "random:6", "random:7"], duty=1.0, token_after=size + 1), request)


def test_convolve_full_frame(request):
    _run("convolve", "tb_convolve", dict(width=FRAME_WIDTH, height=FRAME_HEIGHT, **KERNELS["sep5"]),
         dict(frames=["file:tsukuba_im3.png"], duty=1.0), request)


# --- sobel -------------------------------------------------------------------------------------
@pytest.mark.parametrize("duty", DUTIES)
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_sobel_random(request, seed, duty):
    _run("sobel", "tb_sobel", dict(width=23, height=11),
         dict(frames=[f"random:{seed}", f"random:{seed + 10}"], duty=duty, seed=seed, token_after=50), request)


def test_sobel_full_frames_back_to_back(request):
    _run("sobel", "tb_sobel", dict(width=FRAME_WIDTH, height=FRAME_HEIGHT),
         dict(frames=["file:tsukuba_im3.png", "file:chessboard_left01.jpg"], duty=1.0, token_after=1000), request)


def test_sobel_full_frame_gaps(request):
    _run("sobel", "tb_sobel", dict(width=FRAME_WIDTH, height=FRAME_HEIGHT),
         dict(frames=["file:chessboard_left01.jpg"], duty=0.5, seed=7), request)


# --- documented latency and one pixel per clock --------------------------------------------------
@pytest.mark.parametrize("block,bench,params,radius,latency,doc,stim", [
    ("line_delay", "tb_line_delay", dict(width=20, height=6, data_width=8), 0, 1, "Latency: 1 clock", "random"),
    ("convolve", "tb_convolve", dict(width=20, height=8, **KERNELS["sep3"]), 1, 6, "Latency: N + 3 clocks", "random"),
    ("convolve", "tb_convolve", dict(width=20, height=8, **KERNELS["full5"]), 2, 8, "Latency: N + 3 clocks",
     "random"),
    ("sobel", "tb_sobel", dict(width=20, height=8), 1, 6, "Latency: 6 clocks", "random"),
    ("harris_window", "tb_harris_window", dict(width=20, height=8), 2, 10, "Latency: 10 clocks", "grad"),
    ("cornerness", "tb_cornerness", dict(width=20, height=8), 0, 6, "Latency: 6 clocks", "rwindow"),
    ("prethreshold", "tb_prethreshold", dict(width=20, height=8, blocks=(4, 4)), 0, 1, "Latency: 1 clock",
     "rcorner"),
    ("nms", "tb_nms", dict(width=20, height=8, size=1), 0, 1, "size 1: 1 clock", "rcorner"),
    ("nms", "tb_nms", dict(width=20, height=8, size=3), 1, 6, "N = 3, 5: N + 3 clocks", "rcorner"),
    ("nms", "tb_nms", dict(width=20, height=8, size=5), 2, 8, "N = 3, 5: N + 3 clocks", "rcorner"),
    ("harris_mono", "tb_harris_mono", dict(width=24, height=14, blocks=(2, 2), nms=3), 4, 29,
     "nms 3: 4 lines + 4 pixels + 29 clocks", "random"),
    ("harris_mono", "tb_harris_mono", dict(width=24, height=14, blocks=(1, 1), nms=5), 5, 31,
     "nms 5: 5 lines + 5 pixels +", "random"),
], ids=["line_delay", "convolve3", "convolve5", "sobel", "harris_window", "cornerness", "prethreshold", "nms1",
        "nms3", "nms5", "harris_mono3", "harris_mono5"])
def test_latency_and_throughput(request, block, bench, params, radius, latency, doc, stim):
    """Latency equals the docstring's, and back-to-back frames come out at one pixel per clock."""
    import numpy as np

    from eyestereo.hdl.flow.catalog import get

    assert doc in " ".join(get(block).func.__doc__.split())
    spec = {"random": "random:{}", "grad": "grad:{}:128", "rwindow": "rwindow:{}", "rcorner": "rcorner:{}:-9:9"}[stim]
    rep = _run(block, bench, params, dict(frames=[spec.format(i) for i in (1, 2, 3)], duty=1.0, timing=True),
               request)
    w, h = params["width"], params["height"]
    n = w * h
    sent, recv = np.array(rep["sent_cycles"]), np.array(rep["received_cycles"])
    assert len(sent) == len(recv) == 3 * n
    lead = radius * w + radius
    for f in range(3):
        p = np.arange(n - lead)
        lat = recv[f * n + p] - sent[f * n + p + lead]
        assert lat.min() == lat.max() == latency, (lat.min(), lat.max())
    # Frames 2 and 3 each take exactly n clocks at the output: one pixel per clock, no stall.
    assert recv[2 * n - 1] - recv[n - 1] == n
    assert recv[3 * n - 1] - recv[2 * n - 1] == n
