"""``eyestereo sim system``: the whole front end's VHDL in GHDL on a real pair, and its bad-input policy."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import cv2
import pytest


@pytest.fixture
def pair(tsukuba_pair):
    return tsukuba_pair(slice(100, 196), slice(150, 278), 6)


@pytest.mark.sim
@pytest.mark.skipif(shutil.which("ghdl") is None, reason="needs GHDL")
def test_sim_system_runs_the_front_end(cli, tmp_path, pair):
    """The whole front end on a real pair; the pair's names hold a comma (the bench once split them there),
    the build goes to --build-dir and is removed after, nothing is built inside the package, and the
    output folder's mode follows the umask (it was the temporary folder's 0700)."""
    import os

    lp, rp = pair
    lc, rc = tmp_path / "left,1.png", tmp_path / "right, 1.png"
    lp.rename(lc)
    rp.rename(rc)
    out, js, build = tmp_path / "out", tmp_path / "fig.json", tmp_path / "build"
    package_build = Path(__file__).resolve().parents[2] / "build" / "sim" / "stereo_frontend"
    before = sorted(package_build.glob("cli_*")) if package_build.exists() else []
    old = os.umask(0o027)
    try:
        code, so, se = cli("sim", "system", lc, rc, "-o", out, "--json", js, "--size", "32x24",
                           "--frames", "1", "--modes", "overlapped", "--sim", "ghdl", "--build-dir", build)
    finally:
        os.umask(old)
    assert code == 0, se
    assert sorted(p.name for p in out.iterdir()) == ["matches.png", "rectified.png", "summary.json"]
    assert out.stat().st_mode & 0o777 == 0o750 and (out / "summary.json").stat().st_mode & 0o777 == 0o640
    assert list(build.iterdir()) == []
    assert (sorted(package_build.glob("cli_*")) if package_build.exists() else []) == before
    fig = json.loads(js.read_text())
    assert fig == json.loads((out / "summary.json").read_text())
    assert fig["bit_exact"] is True and fig["frames"] == {"overlapped": 1} and fig["fps"]["overlapped"] > 0
    assert set(fig["sram_share"]["overlapped"]) == {"cam0", "cam1", "fetch", "rect", "feat", "host"}
    assert cv2.imread(str(out / "rectified.png")) is not None
    m = fig["matches_last_frame"]
    assert sum(m["corners"]) == fig["features_last_frame"] and 0 <= m["matches"] <= min(m["corners"])
    assert fig["simulator"] == "the VHDL in GHDL (mcode)"
    pic = cv2.imread(str(out / "matches.png"))
    assert pic is not None and pic.shape[1] == 32 * (480 // 32)
    assert "bit-exact: yes" in so


@pytest.mark.othersims
def test_sim_system_with_the_dense_option(cli, tmp_path, pair):
    """--dense D: the front end with the dense option on Verilator; the host reads the disparity maps (the bench
    compares them with the model), disparity.png is the last one, the summary gives D and the maps read."""
    lp, rp = pair
    out = tmp_path / "out"
    code, so, se = cli("sim", "system", lp, rp, "-o", out, "--size", "48x32", "--frames", "2", "--modes",
                       "overlapped", "--sim", "verilator", "--dense", "16", "--build-dir", tmp_path / "build")
    assert code == 0, se
    assert sorted(p.name for p in out.iterdir()) == ["disparity.png", "matches.png", "rectified.png", "summary.json"]
    fig = json.loads((out / "summary.json").read_text())
    assert fig["bit_exact"] is True and fig["dense"]["disparities"] == 16
    assert fig["dense"]["maps_read"] == {"overlapped": 2} and fig["dense"]["maps_completed"]["overlapped"] >= 2
    assert 0.3 < fig["dense"]["valid_last_map"] <= 1.0
    pic = cv2.imread(str(out / "disparity.png"))
    assert pic is not None and pic.shape[:2] == (32, 48)
    assert "dense: D 16, disparity maps read 2" in so


@pytest.mark.parametrize("case", ["missing", "modes", "size", "frames", "parent", "sim", "dense", "dense_wide"])
def test_sim_system_bad_input(cli, tmp_path, pair, case):
    lp, rp = pair
    out = tmp_path / "out"
    argv = ["sim", "system", lp, rp, "-o", out]
    if case == "missing":
        argv[2] = tmp_path / "nope.png"
    elif case == "modes":
        argv += ["--modes", "fast"]
    elif case == "size":
        argv += ["--size", "7x3"]
    elif case == "frames":
        argv += ["--frames", "0"]
    elif case == "sim":
        argv += ["--sim", "modelsim"]
    elif case == "dense":
        argv += ["--dense", "10"]
    elif case == "dense_wide":
        argv += ["--dense", "48"]  # the default 48x32 cameras: D must stay below 48
    else:
        argv[-1] = tmp_path / "no" / "out"
    code, so, se = cli(*argv)
    assert code in (1, 2) and se.startswith("eyestereo: error: ") and se.count("\n") == 1, se
    assert not out.exists() and not (tmp_path / "no").exists()


def test_matches_picture_colours_the_known_disparity(tmp_path):
    """The matched-features picture on a pair with a known shift: every corner found again at d = 5."""
    import numpy as np

    from eyestereo.sim.apps.cli_system import _matches_picture

    rng = np.random.default_rng(3)
    big = rng.integers(0, 256, (48, 80))
    left, right = big[:, 8:72], big[:, 13:77]  # right(x - 5) = left(x): disparity 5 everywhere
    rect = left.astype(np.int64) | right.astype(np.int64) << 8
    pts = [(20, 10), (30, 20), (40, 30), (25, 36), (45, 15)]
    feats = [(x, y, 0) for x, y in pts] + [(x - 5, y, 1) for x, y in pts]
    m = _matches_picture(rect, feats, tmp_path / "m.png")
    assert m == dict(corners=[5, 5], matches=5, disparity=[5, 5])
    assert cv2.imread(str(tmp_path / "m.png")) is not None
    assert _matches_picture(rect, [], tmp_path / "e.png") == dict(corners=[0, 0], matches=0, disparity=None)


@pytest.mark.sim
@pytest.mark.skipif(shutil.which("ghdl") is None, reason="needs GHDL")
def test_sim_system_with_the_matcher(cli, tmp_path, pair):
    """--matcher: the front end with the hardware matcher (the bench compares every match list the host reads with
    the model); matches.png is the hardware's list, the summary gives its count and the host's read-out time."""
    lp, rp = pair
    out = tmp_path / "out"
    code, so, se = cli("sim", "system", lp, rp, "-o", out, "--size", "48x32", "--frames", "1", "--modes",
                       "sequential", "--sim", "ghdl", "--matcher")
    assert code == 0, se
    fig = json.loads((out / "summary.json").read_text())
    hm = fig["hardware_matches"]
    assert fig["bit_exact"] is True and hm["matches_last_frame"] == fig["matches_last_frame"]["matches"] > 0
    assert hm["match_words_last_frame"] == 3 * hm["matches_last_frame"] + 3
    assert 0 < hm["read_out_us"]["sequential"] < 1000
    assert "hardware matcher:" in so and cv2.imread(str(out / "matches.png")) is not None


def test_hardware_matches_picture_draws_the_list(tmp_path):
    """The hardware's list drawn: each match at its left corner, the right corner d to the left and dy below."""
    import numpy as np

    from eyestereo.sim.apps.cli_system import _hardware_matches_picture

    rect = np.zeros((32, 48), np.int64)
    feats = [(20, 10, 0), (30, 20, 0), (15, 10, 1)]
    m = _hardware_matches_picture(rect, feats, [[20, 10, 5, 100], [30, 20, 9, 50]], [0, 1], tmp_path / "h.png")
    assert m == dict(corners=[2, 1], matches=2, disparity=[5, 9])
    assert cv2.imread(str(tmp_path / "h.png")) is not None
