"""Every block recovers from a broken input frame at the next reset token (docs/bad_input.md, "Blocks").

A stream_checker with repair=True turns any broken frame into exactly such a token, so a chain behind
it recovers by itself. One fault kind per block (they all end the same way: the token clears every
counter), small frames.
"""

import pytest

from eyestereo.sim.lib.runner import run_bench

pytestmark = pytest.mark.sim

CASES = [
    ("line_delay", "tb_line_delay:LineDelayTB", dict(width=9, height=5, data_width=8), "random:{}", "short_line"),
    ("convolve", "tb_convolve:ConvolveTB",
     dict(width=11, height=6, data_width=8, col=[1, 2, 1], row=[1, 2, 1], shift=4, kernel=None), "random:{}",
     "missing_eof"),
    ("sobel", "tb_sobel:SobelTB", dict(width=12, height=7), "random:{}", "long_line_extra"),
    ("harris_window", "tb_harris_window:HarrisWindowTB", dict(width=12, height=8), "grad:{}:128", "early_eof"),
    ("cornerness", "tb_cornerness:CornernessTB", dict(width=8, height=4), "rwindow:{}", "long_line"),
    ("prethreshold", "tb_prethreshold:PrethresholdTB", dict(width=12, height=8, blocks=(2, 2)),
     "rcorner:{}:-50:50", "short_last_line"),
    ("nms", "tb_nms:NmsTB", dict(width=10, height=7, size=3), "rcorner:{}:-3:3", "missing_eof"),
    ("harris_mono", "tb_harris_mono:HarrisMonoTB", dict(width=20, height=12, blocks=(2, 2), nms=3), "random:{}",
     "short_line"),
]


@pytest.mark.parametrize("block,tb,params,stim,fault", CASES, ids=[c[0] for c in CASES])
def test_block_recovers_at_reset_token(request, block, tb, params, stim, fault):
    cfg = dict(tb=tb, fault=fault, seed=3, duty=0.8, frames=[stim.format(i) for i in (1, 2, 3)])
    if block == "prethreshold":
        cfg["thresholds"] = {"0": 5, "3": -7}  # the bench's register writes: block index -> code
    report = run_bench(block, "tb_recovery", cfg, name=request.node.name, params=params)
    assert report["frames"] == 2 and report["pixels_compared"] > 0
