"""GHDL regressions of harris_stereo: each camera bit for bit the harris_mono model of its frame.

Random frame pairs at a small size over every share factor, NMS size and threshold layout, duty cycles
from full speed (a beat every ``share`` clocks) down to sparse (0.1), two frame pairs back to back after
a partial pair cut by a reset token (after a left beat), different k and thresholds for the two cameras.
What the bench checks: sim/benches/tb_harris_stereo.py. Full 352x288 real pairs: sim/measure/bench_harris_stereo.py
(``make bench``), not here (about a minute of GHDL each).
"""

import pytest

from eyestereo.sim.lib.runner import run_bench
from eyestereo.tools.models import harris_mono as hm

pytestmark = pytest.mark.sim

SMALL = dict(width=23, height=13)
THR = {(1, 1): [[3], [40]], (2, 2): [[0, 5, 100, -3], [7, 0, -20, 50]],
       (3, 2): [[0, 10, 20, 30, -5, 2], [60, 0, 1, -40, 8, 0]],
       (4, 4): [[(i * 37 % 23 - 11) * 9 for i in range(16)], [(i * 29 % 19 - 7) * 11 for i in range(16)]]}


@pytest.mark.parametrize("share,duty,nms,blocks,token_cam", [
    (1, 1.0, 3, (2, 2), 1),
    (1, 0.3, 5, (4, 4), 0),
    (2, 0.5, 5, (1, 1), 1),
    (2, 1.0, 1, (4, 4), 0),
    (3, 1.0, 3, (2, 2), 1),
    (3, 0.1, 1, (3, 2), 1),
])
def test_harris_stereo_random(request, share, duty, nms, blocks, token_cam):
    k = [hm.k_code(0.04), hm.k_code(0.12)]
    report = run_bench("harris_stereo", "tb_harris_stereo",
                       dict(frames=[f"random:{share}|random:{share + 10}", "ramp|random:7"], duty=duty, seed=share,
                            k=k, thresholds=THR[blocks], token_after=2 * 23 * 3 + 7, token_cam=token_cam),
                       name=request.node.name, params=dict(SMALL, blocks=blocks, nms=nms, share=share))
    r = 3 + nms // 2
    assert report["frames"] == 2
    assert report["pixels_compared"] == 2 * 2 * (23 - 2 * r) * (13 - 2 * r)
    assert report["frame_beats_out"] == 2 * 2 * 23 * 13  # both frame pairs, after the token
