"""``eyestereo rectifier --vhdl`` and ``eyestereo sim rectify``: the rectifier's VHDL for a calibration, run
in GHDL on a stereo pair (a small rectified size, to stay quick), and the bad-input policy (one line, exit
status 1, nothing written)."""

from __future__ import annotations

import hashlib
import json
import shutil
from pathlib import Path

import cv2
import numpy as np
import pytest

from eyestereo.tools.cli import main as cli
from eyestereo.tools.models.poly_unit import Calibration
from eyestereo.tools.models.rectifier import rectifier as model
from eyestereo.tools.rectify import rig as G

pytestmark = [pytest.mark.sim, pytest.mark.skipif(shutil.which("ghdl") is None, reason="ghdl not installed")]


def run(capfd, *argv) -> tuple[int, str, str]:
    code = cli.main([str(a) for a in argv])
    out, err = capfd.readouterr()
    return code, out, err


def snapshot(folder: Path) -> dict:
    return {str(p.relative_to(folder)): hashlib.sha1(p.read_bytes()).hexdigest() if p.is_file() else "dir"
            for p in sorted(folder.rglob("*"))}


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    d = tmp_path_factory.mktemp("simcli")
    G.write_rig(d / "rig", n=2, seed=2)
    code = cli.main(["rectifier", str(d / "rig" / "rig_calib.yml"), "--size", "40x24", "-o", str(d / "rect"), "--vhdl"])
    assert code == 0
    return d


def test_rectifier_writes_vhdl(made):
    man = json.loads((made / "rect" / "vhdl" / "rectifier.json").read_text())
    assert (man["width"], man["height"], man["source_width"], man["source_height"]) == (40, 24, 352, 288)
    assert set(man["files"]) <= {p.name for p in (made / "rect" / "vhdl").iterdir()}
    assert "entity rectifier is" in (made / "rect" / "vhdl" / "rectifier.vhd").read_text()
    assert {p["name"] for p in man["ports"]} >= {"clk", "rst", "start", "fetch_req_valid", "source_data", "busy"}


def test_sim_rectify_is_bit_exact(made, capfd):
    out = made / "out"
    code, text, err = run(capfd, "sim", "rectify", made / "rect", made / "rig" / "left01.png",
                          made / "rig" / "right01.png", "-o", out, "--memory", "random", "--seed", "5")
    assert code == 0, err
    assert sorted(p.name for p in out.iterdir()) == ["left.png", "report.json", "right.png"]
    rep = json.loads((out / "report.json").read_text())
    assert rep["bit_exact"] is True and (rep["width"], rep["height"]) == (40, 24)
    assert rep["clocks_per_pixel"] > 7 and 0 < rep["reads_per_output_pixel"] <= 4
    # the PNGs are the model's images (independently of the bench's own comparison)
    cal = Calibration.load(str(made / "rect" / "quantizers.json"), source_width=352, source_height=288)
    left = cv2.imread(str(made / "rig" / "left01.png"), cv2.IMREAD_GRAYSCALE)
    right = cv2.imread(str(made / "rig" / "right01.png"), cv2.IMREAD_GRAYSCALE)
    ml, mr = model(cal, left, right, 5)
    assert np.array_equal(cv2.imread(str(out / "left.png"), cv2.IMREAD_GRAYSCALE), ml)
    assert np.array_equal(cv2.imread(str(out / "right.png"), cv2.IMREAD_GRAYSCALE), mr)
    assert "bit exact true" in text


def test_sim_rectify_bad_input(made, capfd):
    small = made / "small.png"
    cv2.imwrite(str(small), np.zeros((20, 30), np.uint8))
    (made / "broken.png").write_bytes(b"\x89PNG\r\n\x1a\n garbage")
    plain = made / "plain"
    plain.mkdir(exist_ok=True)
    (plain / "quantizers.json").write_text("{}")
    left, right = made / "rig" / "left01.png", made / "rig" / "right01.png"
    cases = [
        ((made / "nope", left, right), "no such folder"),
        ((plain, left, right), "has no vhdl/rectifier.json"),
        ((made / "rig", left, right), "holds no quantizers.json"),
        ((made / "rect", small, small), "the images are 30x20; the rectifier in"),
        ((made / "rect", small, right), "the images differ in size: left"),
        ((made / "rect", left, made / "broken.png"), "broken.png"),
        ((made / "rect", left, made / "missing.png"), "missing.png"),
    ]
    for args, piece in cases:
        before = snapshot(made)
        code, out, err = run(capfd, "sim", "rectify", *args, "-o", made / "bad_out")
        assert code == 1, (args, err)
        assert err.startswith("eyestereo: error: ") and err.count("\n") == 1 and piece in err, (piece, err)
        assert snapshot(made) == before and not (made / "bad_out").exists()
    # an output folder holding other files is refused before any work
    other = made / "other"
    other.mkdir(exist_ok=True)
    (other / "notes.txt").write_text("mine")
    code, out, err = run(capfd, "sim", "rectify", made / "rect", left, right, "-o", other)
    assert code == 1 and (other / "notes.txt").read_text() == "mine"
    assert sorted(p.name for p in other.iterdir()) == ["notes.txt"]
