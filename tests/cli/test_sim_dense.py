"""``eyestereo sim dense``: the dense_stereo HDL in GHDL on a Tsukuba crop, and its bad-input policy.

The expected map and scores come from the bit-true model and the metrics module applied in the test to the
pair and the ground truth as stored (disparity x 16, 0 = unknown), never from the command's files.
"""

from __future__ import annotations

import json
import math
import re
import shutil

import cv2
import numpy as np
import pytest

from eyestereo.tools.dense import datasets
from eyestereo.tools.dense.metrics import scores
from eyestereo.tools.matching.metrics import read_pfm
from eyestereo.tools.models.dense_stereo import dense_stereo

TSUKUBA = datasets.data_dir() / "middlebury" / "tsukuba"
needs_data = pytest.mark.skipif(not (TSUKUBA / "im3.png").is_file(), reason="Middlebury Tsukuba not in the shared data")
ROWS, COLS = slice(150, 174), slice(150, 198)  # 48x24, inside the ground truth's unknown 18-pixel frame


@pytest.fixture
def crops(tmp_path):
    """Grey 48x24 crops of Tsukuba's im3, im4 and disp3 in tmp_path/in; the arrays too."""
    folder = tmp_path / "in"
    folder.mkdir()
    arrays = {}
    for name, flags in (("im3.png", cv2.IMREAD_GRAYSCALE), ("im4.png", cv2.IMREAD_GRAYSCALE),
                        ("disp3.pgm", cv2.IMREAD_UNCHANGED)):
        arrays[name] = cv2.imread(str(TSUKUBA / name), flags)[ROWS, COLS]
        cv2.imwrite(str(folder / name.replace(".pgm", ".png")), arrays[name])
    (tmp_path / "res").mkdir()  # OUT's parent, holding nothing else
    return folder / "im3.png", folder / "im4.png", folder / "disp3.png", arrays


@needs_data
@pytest.mark.sim
@pytest.mark.skipif(shutil.which("ghdl") is None, reason="needs GHDL")
def test_sim_dense_writes_the_model_map_and_its_scores(cli, tmp_path, crops):
    lp, rp, gp, a = crops
    out = tmp_path / "res" / "out"
    code, so, se = cli("sim", "dense", lp, rp, "-o", out, "--gt", gp, "-D", "16", "--sim", "ghdl",
                       "--build-dir", tmp_path / "build")
    assert code == 0, se
    assert sorted(p.name for p in out.iterdir()) == ["disparity.pfm", "disparity.png", "metrics.json"]
    assert sorted(p.name for p in (tmp_path / "res").iterdir()) == ["out"]
    assert list((tmp_path / "build").iterdir()) == []  # the run's folder removed after a good run

    codes = dense_stereo(a["im3.png"], a["im4.png"], disparities=16)
    want = np.where(codes == 0xFFFF, np.nan, codes / 16.0)
    assert np.isfinite(want).sum() > want.size // 2  # a map worth comparing
    pfm = read_pfm(out / "disparity.pfm")
    assert pfm.shape == (24, 48)
    assert np.array_equal(np.isinf(pfm), np.isnan(want))  # Middlebury's unknown: +inf
    assert np.array_equal(pfm[np.isfinite(pfm)], want[np.isfinite(want)].astype(np.float32))
    head = (out / "disparity.pfm").read_bytes()[:14]
    assert head == b"Pf\n48 24\n-1.0\n"

    png = cv2.imread(str(out / "disparity.png"))
    assert png.shape == (24, 48, 3)
    assert (png[np.isnan(want)] == 0).all() and (png[np.isfinite(want)].max(axis=1) > 0).all()

    gt = np.where(a["disp3.pgm"] > 0, a["disp3.pgm"] / 16.0, np.nan)
    expected = scores(want, gt)
    got = json.loads((out / "metrics.json").read_text())
    assert got["bit_exact"] is True and got["disparities"] == 16 and got["size"] == "48x24"
    assert got["sim"] == "ghdl" and "GHDL" in got["simulator"] and got["clocks"] > 48 * 24
    assert got["gt_scale"] == 16
    for key, v in expected.items():
        assert (got[key] is None) if math.isnan(v) else got[key] == pytest.approx(v, rel=1e-12), key
    for key in ("bad1_noc", "bad2_noc", "bad4_noc", "density", "rms"):
        assert got[key] is not None, key
    assert "bit-exact against the model: yes" in so and f"bad-2 {expected['bad2_noc']:.2f} %" in so


@needs_data
@pytest.mark.parametrize("case", ["missing", "sizes", "narrow", "out_file", "gt_size", "d_step"])
def test_sim_dense_bad_input(cli, tmp_path, crops, case):
    lp, rp, gp, a = crops
    res = tmp_path / "res"
    out = res / "out"
    args = ["sim", "dense", lp, rp, "-o", out, "--gt", gp, "-D", "16", "--sim", "ghdl"]
    status = 1
    if case == "missing":
        args[2] = tmp_path / "in" / "nope.png"
        match = r"left image .*nope\.png does not exist"
    elif case == "sizes":
        cv2.imwrite(str(rp), a["im4.png"][:, :47])
        match = "the images differ in size: left .* is 48x24, right .* is 47x24"
    elif case == "narrow":
        args[-3] = "48"
        match = "the images are 48x24: their width must exceed the 48 disparities"
    elif case == "out_file":
        out.write_text("mine\n")
        match = "out exists and is not a folder"
    elif case == "gt_size":
        cv2.imwrite(str(gp), a["disp3.pgm"][:20])
        match = r"ground truth is 48x20 but the images are 48x24"
    else:
        args[-3] = "18"
        status = 2
        match = "D must be a multiple of 4: the block computes 4 disparities a clock"
    before = {p.name: p.read_bytes() for p in res.iterdir()}
    code, so, se = cli(*args)
    assert code == status
    lines = se.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("eyestereo: error: "), se
    assert re.search(match, lines[0]), lines[0]
    assert {p.name: p.read_bytes() for p in res.iterdir()} == before  # nothing written, no temporary left
