"""GHDL regressions of the stream checker: every fault class, recovery, repair, mono and stereo.

Each configuration is one simulation of many scenarios (sim/benches/tb_stream_checker.py), compared beat for
beat, cycle for cycle, with the bit-true model.
"""

import pytest

from eyestereo.sim.lib.runner import run_bench

pytestmark = pytest.mark.sim


@pytest.mark.parametrize("width,height,stereo,repair,duty", [
    (5, 3, False, False, 1.0),
    (5, 3, False, True, 0.5),
    (4, 3, True, False, 0.7),
    (4, 3, True, True, 1.0),
    (1, 1, False, True, 0.6),   # every pixel is eol and eof
    (7, 1, True, True, 0.8),    # one line: no early eof possible
])
def test_stream_checker(request, width, height, stereo, repair, duty):
    params = dict(width=width, height=height, data_width=8, stereo=stereo, repair=repair)
    report = run_bench("stream_checker", "tb_stream_checker", dict(duty=duty, seed=width + 10 * height),
                       name=request.node.name, params=params)
    names = [s["name"] for s in report["scenarios"]]
    assert "mixed" in names and "good" in names
    assert all(s["faults"] > 0 for s in report["scenarios"] if s["name"] != "good")
    assert report["pixels_compared"] > 0
