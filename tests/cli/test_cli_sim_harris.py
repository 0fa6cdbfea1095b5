"""``eyestereo sim harris``: the harris_stereo VHDL in GHDL on a small real pair, and its bad-input policy."""

from __future__ import annotations

import json
import shutil

import cv2
import numpy as np
import pytest

from eyestereo.tools.models import harris_mono as hm
from eyestereo.tools.models import harris_stereo as hs
from eyestereo.tools.models.border import interior_mask


@pytest.fixture
def pair(tsukuba_pair):
    lp, rp = tsukuba_pair(slice(120, 140), slice(160, 190), 6)  # 30x20, the right view shifted by 6
    return lp, rp, cv2.imread(str(lp), cv2.IMREAD_GRAYSCALE), cv2.imread(str(rp), cv2.IMREAD_GRAYSCALE)


@pytest.mark.sim
@pytest.mark.skipif(shutil.which("ghdl") is None, reason="needs GHDL")
def test_sim_harris_writes_the_vhdl_corners(cli, tmp_path, pair):
    lp, rp, left, right = pair
    out = tmp_path / "out"
    code, so, se = cli("sim", "harris", lp, rp, "-o", out, "--share", "1", "--blocks", "2x2",
                       "--k-left", "0.04", "--k-right", "0.08", "--threshold-left", "1e7",
                       "--threshold-right", "5e6,2e7,1e7,3e7")
    assert code == 0, se
    assert sorted(p.name for p in out.iterdir()) == ["corners.json", "left.png", "right.png"]
    got = json.loads((out / "corners.json").read_text())
    thr_l = [hm.threshold_code(1e7)] * 4
    thr_r = [hm.threshold_code(c) for c in (5e6, 2e7, 1e7, 3e7)]
    fl, fr, _ = hs.harris_stereo(left, right, (hm.k_code(0.04), hm.k_code(0.08)), (thr_l, thr_r), blocks=(2, 2), nms=3)
    mask = interior_mask(20, 30, hm.radius(3))
    assert got["left"] == hm.features(fl, mask).tolist() and got["right"] == hm.features(fr, mask).tolist()
    assert len(got["left"]) + len(got["right"]) > 0
    assert cv2.imread(str(out / "left.png")).shape == (20, 30, 3)
    assert "corners:" in so and se == ""


@pytest.mark.parametrize("case", ["sizes", "missing", "thresholds", "tiny"])
def test_sim_harris_bad_input(cli, tmp_path, pair, case):
    lp, rp, left, _ = pair
    out = tmp_path / "out"
    args = ["sim", "harris", lp, rp, "-o", out]
    if case == "sizes":
        cv2.imwrite(str(rp), np.zeros((21, 30), np.uint8))
        match = "the images differ in size"
    elif case == "missing":
        args[3] = tmp_path / "nope.png"
        match = "right image .*nope.png does not exist"
    elif case == "thresholds":
        args += ["--blocks", "2x2", "--threshold-right", "1,2,3"]
        match = "--threshold-right has 3 values; --blocks gives 4 blocks"
    else:
        cv2.imwrite(str(lp), left[:6, :6])
        cv2.imwrite(str(rp), left[:6, :6])
        match = "the images are 6x6: harris_stereo takes 9..4096"
    before = sorted(p.name for p in tmp_path.iterdir())
    code, so, se = cli(*args)
    assert code == 1
    lines = se.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("eyestereo: error: "), se
    import re
    assert re.search(match, lines[0]), lines[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == before  # nothing written, no temporary left


def test_sim_harris_bad_command_line(cli, pair, tmp_path):
    lp, rp, _, _ = pair
    code, _, se = cli("sim", "harris", lp, rp, "-o", tmp_path / "o", "--blocks", "17x2")
    assert code == 2 and "BX and BY must be 1..16" in se
    code, _, se = cli("sim", "harris", lp, rp, "-o", tmp_path / "o", "--share", "4")
    assert code == 2
