"""GHDL regressions of feature_list against its model: list words, per-frame counts, overflow.

Random flag frames and the stereo Harris model's flags, input duty 1.0 .. 0.2, consumer ready 1.0 ..
0.3, three frames back to back after a partial frame cut by a reset token, a maximum per frame that
cuts the list (overflow), 1x1 .. 4x4 count blocks. What the bench checks: sim/benches/tb_feature_list.py.
"""

import pytest

from eyestereo.sim.lib.runner import run_bench

pytestmark = pytest.mark.sim


@pytest.mark.parametrize("duty,ready,max_features,blocks,depth", [
    (1.0, 1.0, 40, (2, 2), 16),
    (0.5, 0.7, 1023, (4, 4), 8),
    (0.2, 0.4, 7, (1, 1), 8),
])
def test_feature_list(request, duty, ready, max_features, blocks, depth):
    report = run_bench("feature_list", "tb_feature_list",
                       dict(frames=["flags:0.05", "harris:3", "flags:0.2"], duty=duty, ready=ready, seed=3,
                            token_after=201),
                       name=request.node.name,
                       params=dict(width=23, height=13, blocks=blocks, border=3, max_features=max_features,
                                   depth=depth))
    assert report["frames"] == 3 and report["lists"] == 4  # the aborted list and three whole ones
    assert sum(report["features"]) > 0
    if max_features < 40:
        assert any(report["overflow"])
    if ready == 1.0:
        assert report["latency"] == 2  # as the block's docstring says


def test_feature_list_consumer_stall_drops_and_flags(request):
    """Dense flags at full rate and a consumer taking a word every ~5 clocks: the FIFO overflows; the
    lists keep the model's order with features left out and the overflow flag set, the counts stay exact."""
    report = run_bench("feature_list", "tb_feature_list",
                       dict(frames=["flags:0.3", "flags:0.3"], duty=1.0, ready=0.2, seed=4, lossy=True),
                       name=request.node.name,
                       params=dict(width=23, height=13, blocks=(2, 2), border=3, max_features=1023, depth=4))
    assert report["frames"] == 2 and all(report["overflow"])


@pytest.mark.parametrize("frames", [3, 5])
def test_feature_list_lists_ends_lost_in_a_long_stall(request, frames):
    """Regression of a formal finding (docs/formal.md, feature_list): the consumer takes nothing while
    several frames end; the ends that find the FIFO full are replaced by one reset token (no FIFO entry
    overwritten, no list closed with a wrong trailer), the lists before are whole, the counts exact."""
    report = run_bench("feature_list", "tb_feature_list",
                       dict(frames=["flags:0.3"] * frames, duty=1.0, ready=1.0, seed=5, stall=True),
                       name=request.node.name,
                       params=dict(width=7, height=5, blocks=(1, 1), border=1, max_features=1023, depth=4))
    assert report["frames"] == frames and report["lists"] < frames + 1
