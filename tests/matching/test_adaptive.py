"""Adaptive Harris thresholds (tools/adaptive.py): controller arithmetic, a synthetic plant, real frames."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

import eyestereo.tools
from eyestereo.tools.matching import adaptive as A
from eyestereo.tools.models import harris_mono as hm
from eyestereo.tools.constants import K_CODE_DEFAULT

SHARED = Path(os.environ.get("EYESTEREO_SHARED", Path(eyestereo.tools.__file__).resolve().parents[1].parent / "shared"))
DATA = SHARED / "data" / "middlebury"
needs_middlebury = pytest.mark.skipif(not (DATA / "tsukuba" / "im3.png").is_file(),
                                      reason=f"Middlebury images not found at {DATA}")


def test_block_counts_by_hand():
    flags = np.zeros((8, 8), int)
    flags[0, 0] = flags[1, 1] = 1            # block 0 (2x2 blocks of 4x4)
    flags[0, 7] = 1                          # block 1
    flags[7, 7] = flags[5, 6] = flags[4, 4] = 1   # block 3
    assert A.block_counts(flags, None, (2, 2)).tolist() == [2, 1, 0, 3]
    mask = np.ones((8, 8), bool)
    mask[0, :] = False
    assert A.block_counts(flags, mask, (2, 2)).tolist() == [1, 0, 0, 3]
    assert A.block_counts(flags, None, (1, 1)).tolist() == [6]
    with pytest.raises(ValueError, match="blocks"):
        A.block_counts(flags, None, (0, 2))


def test_i_controller_arithmetic():
    c = A.IController(10, gain=0.5, init=20, n_blocks=4)
    assert c.codes.tolist() == [20] * 4
    assert c.update([10, 14, 6, 0]).tolist() == [20, 22, 18, 15]
    assert c.update([10, 14, 6, 0]).tolist() == [20, 24, 16, 10]
    # clamped at 0: no wind-up below the smallest code
    c = A.IController(10, gain=4, init=5, n_blocks=1)
    assert c.update([0]).tolist() == [0]
    assert c.update([12]).tolist() == [8]


def test_log_controller_arithmetic():
    c = A.LogController(7, gain=1.0, init=31, n_blocks=3)
    # count + 1 = 2 (target + 1): code + 1 doubles; equal: unchanged; half: halves
    assert c.update([15, 7, 3]).tolist() == [63, 31, 15]
    c = A.LogController(7, gain=1.0, init=31, max_step=0.5, n_blocks=1)
    assert c.update([255]).tolist() == [round(32 * 2 ** 0.5) - 1]   # step limited to 2**0.5


def test_controllers_reject_bad_parameters():
    with pytest.raises(ValueError, match="gain"):
        A.IController(10, gain=0)
    with pytest.raises(ValueError, match="targets"):
        A.LogController(-1)
    with pytest.raises(ValueError, match="initial codes"):
        A.IController(10, init=-3)
    with pytest.raises(ValueError, match="alpha"):
        A.SecantController(10, alpha0=3.0)
    with pytest.raises(ValueError, match="counts"):
        A.IController(10).update([1, 2, 3])


def plant(code, scale, alpha):
    """A synthetic block: count = scale * (code + 1) ** -alpha, rounded."""
    return np.round(scale * (np.asarray(code, float) + 1.0) ** -alpha)


@pytest.mark.parametrize("alpha", [0.3, 0.6, 1.2])
@pytest.mark.parametrize("scale", [200.0, 800.0])   # target reachable below CODE_MAX
def test_secant_controller_settles_on_any_plant(alpha, scale):
    target = 20
    c = A.SecantController(target, n_blocks=1)
    counts = []
    for _ in range(12):
        n = plant(c.codes, scale, alpha)
        counts.append(float(n[0]))
        c.update(n)
    tail = np.array(counts[6:])
    assert np.all(np.abs(tail - target) <= 0.15 * target + 1), counts
    assert c.alpha[0] == pytest.approx(alpha, rel=0.35)


def test_fixed_gain_i_controller_is_slow_where_the_secant_is_not():
    # a steep plant far from code 0: the linear I-controller needs many frames
    target = 20
    i_ctl, s_ctl = A.IController(target, gain=0.5, n_blocks=1), A.SecantController(target, n_blocks=1)
    ni, ns = [], []
    for _ in range(10):
        a, b = plant(i_ctl.codes, 3000, 0.6), plant(s_ctl.codes, 3000, 0.6)
        ni.append(a[0])
        ns.append(b[0])
        i_ctl.update(a)
        s_ctl.update(b)
    assert abs(ns[-1] - target) <= 3 and abs(ni[-1] - target) > 3 * abs(ns[-1] - target)


def test_step_sequence_frames():
    img = (np.arange(40 * 60).reshape(40, 60) % 256).astype(np.uint8)
    frames, steps = A.step_sequence(img, size=(50, 30), frames_per_step=3, gains=(1.0, 0.5), pan=2)
    assert len(frames) == 6 and steps == [3]
    assert all(f.shape == (30, 50) for f in frames)
    assert np.array_equal(frames[0], img[5:35, 0:50])
    assert np.array_equal(frames[1], img[5:35, 2:52])
    exp = np.clip(np.round(128 + 0.5 * (img[5:35, 6:56].astype(float) - 128)), 0, 255)
    assert np.array_equal(frames[3], exp)
    with pytest.raises(ValueError, match="larger"):
        A.step_sequence(img, size=(70, 30))


@needs_middlebury
def test_closed_loop_on_real_frames():
    from eyestereo.tools.matching.sparse import load_grey

    img = load_grey(DATA / "tsukuba" / "im3.png")[40:200, 40:280]
    frames, steps = A.step_sequence(img, size=(200, 140), frames_per_step=8, gains=(1.0, 1.6))
    target = 6.0
    h = A.run_sequence(frames, A.SecantController(target))
    assert h.codes.shape == (16, 16) and h.counts.shape == (16, 16)
    assert h.codes[0].tolist() == [0] * 16                       # after reset
    # the loop's record is consistent with the bit-true model
    f, m = hm.harris_mono(frames[5], K_CODE_DEFAULT, h.codes[5])
    assert A.block_counts(f, m).tolist() == h.counts[5].tolist()
    cap = A.block_counts(*hm.harris_mono(frames[7], K_CODE_DEFAULT, [0] * 16))
    reach = np.minimum(cap, target).sum()
    assert abs(h.totals[0] - reach) > 0.5 * reach                 # far off at first
    assert abs(h.totals[7] - reach) <= 0.2 * reach                # settled before the step
    assert abs(h.totals[-1] - np.minimum(cap, target).sum()) <= 0.3 * reach
    assert A.settling_frames(h.totals, 0, reach, tol=0.2, end=8) is not None
