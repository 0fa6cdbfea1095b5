"""GHDL regressions of line_delay on stereo streams (the library's stereo rule: it forwards cam)."""

import pytest

from eyestereo.sim.lib.runner import run_bench

pytestmark = pytest.mark.sim


@pytest.mark.parametrize("width,height,data_width,duty", [(9, 5, 8, 1.0), (6, 4, 18, 0.5), (1, 3, 4, 0.7)])
def test_line_delay_stereo(request, width, height, data_width, duty):
    report = run_bench("line_delay", "tb_line_delay_stereo", dict(duty=duty, seed=width, frames=3),
                       name=request.node.name,
                       params=dict(width=width, height=height, data_width=data_width, stereo=True))
    assert report["frames"] == 3 and report["pixels_compared"] == 2 * 3 * width * (height - 1)
