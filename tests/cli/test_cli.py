"""The ``eyestereo`` command line (tools/cli/): end to end on real data, bad command lines, groups, progress.

The shared data is found at ``../shared`` beside the repository or where ``EYESTEREO_SHARED`` points."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest

from eyestereo.tools.rectify import calib as C
from eyestereo.tools.cli import main as cli
from eyestereo.tools.rectify import maps as X
from eyestereo.tools.rectify import rig as G

SHARED = Path(os.environ.get("EYESTEREO_SHARED", Path(__file__).resolve().parents[2].parent / "shared"))
DATA = SHARED / "data" / "opencv_stereo_calib"
needs_data = pytest.mark.skipif(not DATA.is_dir(), reason=f"shared calibration images not found at {DATA}")


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def files(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


@needs_data
def test_end_to_end_on_the_shared_images(tmp_path, capsys):
    calib, maps, poly = tmp_path / "calib.yml", tmp_path / "maps.npz", tmp_path / "poly.json"
    code, out, err = run(capsys, "calibrate", DATA / "left*.jpg", DATA / "right*.jpg", "--board", "9x6",
                         "--square", "0.025", "-o", calib)
    assert code == 0, err
    assert "from 13 of 13 pairs" in out and err == ""
    cal = C.read_yaml(calib)
    assert 0.15 < cal.rms < 0.5 and cal.image_size == (640, 480)

    code, out, err = run(capsys, "maps", calib, "-o", maps)
    assert code == 0, err
    m = X.load_maps(maps)
    assert (m.width, m.height) == (640, 480) and m.source_size == (640, 480)
    assert X.map_difference(m, X.compute_maps(cal))["max"] == 0

    code, out, err = run(capsys, "maps", calib, "-o", tmp_path / "maps_cv.npz", "--method", "opencv",
                         "--size", "320x240")
    assert code == 0, err
    assert X.load_maps(tmp_path / "maps_cv.npz").left_x.shape == (240, 320)

    (tmp_path / "plots").mkdir()
    code, out, err = run(capsys, "fit", maps, "-o", poly, "--degree", "3", "--plots", tmp_path / "plots")
    assert code == 0, err
    doc = json.loads(poly.read_text())
    assert doc["degree"] == 3 and doc["width"] == 640 and len(doc["polynomials"]["right_y"]) == 10
    assert files(tmp_path / "plots") == ["left_contour.png", "left_quiver.png", "right_contour.png", "right_quiver.png"]
    assert "degree 3" in out

    for src, name in ((maps, "rect_map.png"), (poly, "rect_poly.png")):
        code, out, err = run(capsys, "warp", DATA / "left01.jpg", src, "--side", "left", "-o", tmp_path / name)
        assert code == 0, err
        img = cv2.imread(str(tmp_path / name), cv2.IMREAD_UNCHANGED)
        assert img.shape == (480, 640)
    a = cv2.imread(str(tmp_path / "rect_map.png"), cv2.IMREAD_GRAYSCALE).astype(int)
    b = cv2.imread(str(tmp_path / "rect_poly.png"), cv2.IMREAD_GRAYSCALE).astype(int)
    # the polynomials (mean residual ~0.3 px here) rectify nearly like the exact maps
    assert np.abs(a - b).mean() < 5 and np.corrcoef(a.ravel(), b.ravel())[0, 1] > 0.97

    code, out, err = run(capsys, "lut", maps, "-o", tmp_path / "lut.h")
    assert code == 0, err
    assert "#define EYESTEREO_LUT_WIDTH 640" in (tmp_path / "lut.h").read_text()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary files


def test_rig_command_then_calibrate_its_views(tmp_path, capsys):
    out_dir = tmp_path / "rig"
    code, out, err = run(capsys, "rig", "-o", out_dir, "--views", "6", "--seed", "3")
    assert code == 0, err
    assert len(files(out_dir)) == 13 and "rig_calib.yml" in files(out_dir)
    code, out, err = run(capsys, "calibrate", out_dir / "left*.png", out_dir / "right*.png", "--square", "0.02",
                         "-o", tmp_path / "est.yml")
    assert code == 0, err
    est, truth = C.read_yaml(tmp_path / "est.yml"), C.read_yaml(out_dir / "rig_calib.yml")
    assert est.rms < 0.1
    assert np.allclose(np.diag(est.M1)[:2], np.diag(truth.M1)[:2], rtol=0.005)
    assert np.linalg.norm(est.T - truth.T) < 0.002


def test_rig_cover_layout_calibrates_well(tmp_path, capsys):
    code, out, err = run(capsys, "rig", "-o", tmp_path / "rig", "--views", "9", "--layout", "cover")
    assert code == 0 and "cover layout" in out, err
    assert len(files(tmp_path / "rig")) == 19
    code, out, err = run(capsys, "calibrate", tmp_path / "rig" / "left*.png", tmp_path / "rig" / "right*.png",
                         "--square", "0.02", "-o", tmp_path / "est.yml")
    assert code == 0, err
    est, truth = C.read_yaml(tmp_path / "est.yml"), G.eyebot_rig()
    assert est.rms < 0.1 and np.linalg.norm(est.T - truth.T) < 0.002
    assert np.allclose(np.diag(est.M2)[:2], np.diag(truth.M2)[:2], rtol=0.005)


# --------------------------------------------------------------------------------------------------
# Bad input: one line on stderr, exit status 2 (command line) or 1 (run time), nothing written


@pytest.fixture
def inputs(tmp_path):
    """A folder with valid and broken input files of every kind."""
    rig = G.eyebot_rig()
    C.write_yaml(rig.calibration(), tmp_path / "calib.yml")
    maps = X.compute_maps(rig.calibration(), size=(40, 30))
    maps.image_width, maps.image_height = 352, 288
    X.save_maps(maps, tmp_path / "maps.npz")
    (tmp_path / "corrupt.yml").write_text("%YAML:1.0\nM1: [ 1, 2\n")
    (tmp_path / "nokey.yml").write_text((tmp_path / "calib.yml").read_text().replace("rms:", "rmsx:"))
    (tmp_path / "corrupt.npz").write_bytes(b"PK\x03\x04 broken zip")
    (tmp_path / "corrupt.json").write_text("{ not json")
    (tmp_path / "badpoly.json").write_text(json.dumps({"width": 4, "height": 3, "degree": 3, "terms": ["1"],
                                                       "polynomials": {}}))
    cv2.imwrite(str(tmp_path / "small.png"), np.zeros((30, 40), np.uint8))
    cv2.imwrite(str(tmp_path / "cam.png"), np.zeros((288, 352), np.uint8))
    cv2.imwrite(str(tmp_path / "blank_l1.png"), np.full((288, 352), 128, np.uint8))
    cv2.imwrite(str(tmp_path / "blank_r1.png"), np.full((288, 352), 120, np.uint8))
    (tmp_path / "notimage.png").write_text("hello")
    return tmp_path


BAD = {
    # name: (command line, split at spaces, with {d} for the folder; exit status, expected piece of the message)
    "no command": ("", 2, "required"),
    "unknown command": ("frobnicate", 2, "invalid choice"),
    "bad board": ("calibrate {d}/blank_l*.png {d}/blank_r*.png --board 9by6 -o {d}/out.yml", 2, "board must be"),
    "square board": ("calibrate {d}/blank_l*.png {d}/blank_r*.png --board 6x6 -o {d}/out.yml", 2, "ambiguous"),
    "bad square": ("calibrate {d}/blank_l*.png {d}/blank_r*.png --square -1 -o {d}/out.yml", 2, "positive"),
    "missing -o": ("calibrate {d}/blank_l*.png {d}/blank_r*.png", 2, "required"),
    "no images": ("calibrate {d}/none_*.png {d}/blank_r*.png -o {d}/out.yml", 1, "no left images match"),
    "no chessboard": ("calibrate {d}/blank_l*.png {d}/blank_r*.png -o {d}/out.yml", 1, "in both images of only 0 of 1"),
    "unreadable image": ("calibrate {d}/notimage.png {d}/blank_r*.png -o {d}/out.yml", 1, "cannot read image"),
    "missing calib": ("maps {d}/none.yml -o {d}/out.npz", 1, "does not exist"),
    "corrupt calib": ("maps {d}/corrupt.yml -o {d}/out.npz", 1, "corrupt.yml"),
    "calib without key": ("maps {d}/nokey.yml -o {d}/out.npz", 1, "key 'rms' is missing"),
    "calib is an image": ("maps {d}/cam.png -o {d}/out.npz", 1, "cam.png"),
    "bad size": ("maps {d}/calib.yml --size big -o {d}/out.npz", 2, "size must be WxH"),
    "zero size": ("maps {d}/calib.yml --size 0x10 -o {d}/out.npz", 2, "size must be WxH"),
    "bad method": ("maps {d}/calib.yml --method magic -o {d}/out.npz", 2, "invalid choice"),
    "focal with opencv": ("maps {d}/calib.yml --method opencv --focal min -o {d}/out.npz", 1, "--focal min"),
    "output folder missing": ("maps {d}/calib.yml -o {d}/nodir/out.npz", 1, "does not exist"),
    "missing maps": ("fit {d}/none.npz -o {d}/out.json", 1, "does not exist"),
    "corrupt maps": ("fit {d}/corrupt.npz -o {d}/out.json", 1, "corrupt.npz"),
    "maps are yaml": ("fit {d}/calib.yml -o {d}/out.json", 1, "calib.yml"),
    "bad degree": ("fit {d}/maps.npz --degree 5 -o {d}/out.json", 2, "invalid choice"),
    "plots parent missing": ("fit {d}/maps.npz --plots {d}/noplots/sub -o {d}/out.json", 1, "does not exist"),
    "plots into a used folder": ("fit {d}/maps.npz --plots {d} -o {d}/out.json", 1, "out.json lies inside"),
    "missing image": ("warp {d}/none.png {d}/maps.npz --side left -o {d}/out.png", 1, "does not exist"),
    "not an image": ("warp {d}/notimage.png {d}/maps.npz --side left -o {d}/out.png", 1, "cannot read image"),
    "corrupt poly": ("warp {d}/cam.png {d}/corrupt.json --side left -o {d}/out.png", 1, "not valid JSON"),
    "bad poly": ("warp {d}/cam.png {d}/badpoly.json --side left -o {d}/out.png", 1, "'terms'"),
    "corrupt npz for warp": ("warp {d}/cam.png {d}/corrupt.npz --side left -o {d}/out.png", 1, "corrupt.npz"),
    "bad side": ("warp {d}/cam.png {d}/maps.npz --side up -o {d}/out.png", 2, "invalid choice"),
    "bad output type": ("warp {d}/cam.png {d}/maps.npz --side left -o {d}/out.xyz", 1, "image of type '.xyz'"),
    "bad lut bits": ("lut {d}/maps.npz --frac-bits 20 -o {d}/out.h", 2, "invalid choice"),
    "bad views": ("rig --views 0 -o {d}/out", 2, "view count must lie in 1..99, got 0"),
    "rig onto a file": ("rig -o {d}/calib.yml", 1, "not a folder"),
    "rig parent missing": ("rig -o {d}/a/b", 1, "does not exist"),
    "rig bad layout": ("rig --layout grid -o {d}/out", 2, "invalid choice"),
    "rectifier missing calib": ("rectifier {d}/none.yml -o {d}/out", 1, "does not exist"),
    "rectifier corrupt calib": ("rectifier {d}/corrupt.yml -o {d}/out", 1, "corrupt.yml"),
    "rectifier calib without key": ("rectifier {d}/nokey.yml -o {d}/out", 1, "key 'rms' is missing"),
    "rectifier onto a file": ("rectifier {d}/calib.yml -o {d}/calib.yml", 1, "not a folder"),
    "rectifier onto a used folder": ("rectifier {d}/calib.yml -o {d}", 1, "does not write"),
    "rectifier bad degree": ("rectifier {d}/calib.yml --degree 1 -o {d}/out", 2, "invalid choice"),
    "rectifier bad high": ("rectifier {d}/calib.yml --high x -o {d}/out", 2, "not an integer"),
    "rectifier bad measure": ("rectifier {d}/calib.yml --measure rms -o {d}/out", 2, "invalid choice"),
    "wrong image size": ("warp {d}/small.png {d}/maps.npz --side left -o {d}/out.png", 1,
                         "image is 40x30 but the maps were made for 352x288"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_input_gives_one_line_and_no_output(inputs, capsys, case):
    line, status, piece = BAD[case]
    before = files(inputs)
    code, out, err = run(capsys, *(a.format(d=inputs) for a in line.split()))
    assert code == status
    assert err.startswith("eyestereo: error: ") and err.endswith("\n") and err.count("\n") == 1, err
    assert piece in err
    assert "Traceback" not in err
    assert files(inputs) == before  # nothing written, no temporary files left


def test_help_exits_zero(capsys):
    code, out, _ = run(capsys, "--help")
    assert code == 0 and "calibrate" in out and "warp" in out and "rectifier" in out
    code, out, _ = run(capsys, "maps", "--help")
    assert code == 0 and "--method" in out
    code, out, _ = run(capsys, "rectifier", "--help")
    assert code == 0 and "--max-error" in out and "OUTDIR" in out


def test_console_script_reports_errors_in_one_line(tmp_path):
    exe = Path(sys.executable).parent / "eyestereo"
    cmd = [str(exe)] if exe.exists() else [sys.executable, "-m", "eyestereo.tools.cli.main"]
    r = subprocess.run([*cmd, "maps", str(tmp_path / "none.yml"), "-o", str(tmp_path / "m.npz")],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 1
    assert r.stderr.startswith("eyestereo: error: ") and r.stderr.count("\n") == 1
    assert list(tmp_path.iterdir()) == []


class FakeEntryPoint:
    def __init__(self, name, register):
        self.name, self._register = name, register

    def load(self):
        if isinstance(self._register, Exception):
            raise self._register
        return self._register


def test_groups_from_entry_points_are_registered(monkeypatch, capsys):
    """A layer above tools (the sim commands) adds its group through the "eyestereo.cli" entry points."""
    seen = {}

    def register(subparsers):
        p = subparsers.add_parser("fakesim", help="test")
        p.add_argument("--n", type=int, default=1)
        p.set_defaults(func=lambda args: seen.setdefault("ran", args.n) and 0)
        seen["registered"] = True

    monkeypatch.setattr(cli, "_extension_groups", lambda: [FakeEntryPoint("fakesim", register),
                                                           FakeEntryPoint("broken", ImportError("no myhdl"))])
    code, _, err = run(capsys, "fakesim", "--n", "4")
    assert code == 0 and seen == {"registered": True, "ran": 4}, err
    # errors of an extension's parser are one line too
    code, _, err = run(capsys, "fakesim", "--nope")
    assert code == 2 and err.startswith("eyestereo: error: ") and err.count("\n") == 1
    # a group that cannot load breaks nothing else, and says why when it is used
    code, out, _ = run(capsys, "--help")
    assert code == 0 and "fakesim" in out and "broken" in out
    code, _, err = run(capsys, "broken", "x")
    assert code == 1 and err.count("\n") == 1 and "cannot be loaded (ImportError: no myhdl)" in err


def test_every_subcommand_is_registered(capsys):
    code, out, _ = run(capsys, "--help")
    assert code == 0
    for cmd in ("calibrate", "maps", "fit", "warp", "lut", "rig", "rectifier", "ffc", "package", "evaluate",
                "sweep"):
        assert cmd in out, cmd


@pytest.mark.skipif(shutil.which("cc") is None, reason="no C compiler")
def test_lut_from_poly_json(tmp_path, capsys):
    rig = G.eyebot_rig()
    from eyestereo.tools.rectify import polyfit as P

    f = P.fit(X.compute_maps(rig.calibration(), size=(24, 16)), 3)
    P.write_poly_json(f, tmp_path / "p.json")
    code, out, err = run(capsys, "lut", tmp_path / "p.json", "-o", tmp_path / "p.h", "--prefix", "pl")
    assert code == 0, err
    text = (tmp_path / "p.h").read_text()
    assert "#define PL_WIDTH 24" in text and "#define PL_SOURCE_WIDTH 352" in text


# --------------------------------------------------------------------------------------------------
# The progress bar (tqdm)


class FakeTTY:
    def __init__(self, tty: bool) -> None:
        self.tty, self.text = tty, ""

    def isatty(self) -> bool:
        return self.tty

    def write(self, s: str) -> None:
        self.text += s

    def flush(self) -> None:
        pass


def test_progress_draws_only_on_a_terminal_or_when_forced(monkeypatch):
    from eyestereo.tools.progress import progress_bar

    monkeypatch.delenv("EYESTEREO_PROGRESS", raising=False)
    for tty, force, drawn in ((True, None, True), (False, None, False), (False, True, True), (True, False, False)):
        s = FakeTTY(tty)
        with progress_bar(3, "work", stream=s, force=force) as bar:
            for _ in range(3):
                bar.update()
        assert bool(s.text) == drawn, (tty, force)
        if drawn:  # tqdm's bar, erased when done (leave=False): the command's result line stays alone
            assert "work:" in s.text and "/3 [" in s.text and s.text.endswith("\r")
    monkeypatch.setenv("EYESTEREO_PROGRESS", "0")
    s = FakeTTY(True)
    with progress_bar(2, "x", stream=s) as bar:
        bar.update(2)
    assert s.text == ""
    with pytest.raises(ValueError):
        progress_bar(-1)


def test_cli_stderr_stays_clean_when_not_a_terminal(tmp_path, capsys):
    code, out, err = run(capsys, "rig", "-o", tmp_path, "--views", "2")
    assert code == 0 and err == ""
