"""The board simulation: the whole ULX3S top (PLL, SDRAM, cameras over SCCB, rectification, Harris, the HDMI
output, the UART bridge) with its parts' models, the host tool's own code on the serial line (GHDL)."""

import shutil

import pytest

import eyestereo.sim.harnesses.board_harness  # noqa: F401  (registers the bench top)
from eyestereo.sim.lib.runner import run_bench
from eyestereo.sim.measure.bench_board import CONFIG, PARAMS


@pytest.mark.sim
@pytest.mark.skipif(shutil.which("ghdl") is None, reason="GHDL not installed")
def test_pair_through_the_board_to_the_monitor(request):
    # a small board: 32 x 24 cameras, the 64 x 48 monitor mode, a two-entry SCCB table at 400 kHz, 8 clocks a bit on
    # the serial line (the bridge's least), the hardware matcher (rows +-1, the host writes t_max 40): the same top
    # as make bitstream MATCHER=1's, smaller (the measure script's run)
    rep = run_bench("board_harness", "tb_board", dict(CONFIG), name=request.node.name, params=dict(PARAMS))
    assert 1 <= rep["features"] <= 2 * 12
    assert rep["hdmi_frames"] >= 1
    assert rep["copies"] >= 3
    # the matcher's list read over the serial line equals the model's (the bench asserts it), and it is not empty:
    # the monitor's segments are checked pixel for pixel in the picture
    assert rep["matches"] >= 2 and rep["segment_pixels"] >= 2 * 2
    # DROPPED counts frames (a frame the stream rectifier found overwritten once, not each overwritten line it read):
    # at most the frames completed and the one under way
    assert max(rep["dropped"]) <= rep["frames"] + 1, rep
