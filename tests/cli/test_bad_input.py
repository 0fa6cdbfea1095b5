"""Bad input on the command line, one test per class of defect (issue 8, item 4; docs/bad_input.md).

Every case asserts the exit status, the one-line message (the whole of stderr, file descriptor 2
included: no library warning before it) and that no file was created or changed (a snapshot of the
folder, hidden files, contents and modes included).
"""

from __future__ import annotations

import hashlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import NamedTuple

import cv2
import numpy as np
import pytest

from eyestereo.tools.cli import main as cli
from eyestereo.tools.rectify import calib as C
from eyestereo.tools.rectify import ffc as F
from eyestereo.tools.rectify import judge as J
from eyestereo.tools.rectify import maps as X
from eyestereo.tools.rectify import polyfit as P
from eyestereo.tools.rectify import rig as G

SHARED = Path(os.environ.get("EYESTEREO_SHARED", Path(__file__).resolve().parents[2].parent / "shared"))
REAL = SHARED / "data" / "opencv_stereo_calib"


def snapshot(folder: Path) -> dict[str, tuple[str, int]]:
    """Every file and folder below ``folder`` (hidden ones too): content hash and mode."""
    out = {}
    for p in sorted(folder.rglob("*")):
        key = str(p.relative_to(folder))
        data = hashlib.sha1(p.read_bytes()).hexdigest() if p.is_file() else "dir"
        out[key] = (data, p.stat().st_mode & 0o7777)
    return out


def run(capfd, *argv) -> tuple[int, str, str]:
    code = cli.main([str(a) for a in argv])
    out, err = capfd.readouterr()
    return code, out, err


def clean_line(err: str) -> bool:
    """One ``eyestereo: error:`` line, with no traceback and no temporary's name in it."""
    one = err.startswith("eyestereo: error: ") and err.endswith("\n") and err.count("\n") == 1
    return one and "Traceback" not in err and ".eyestereo-" not in err


class Refusal(NamedTuple):
    """What a refused command did: its status, its standard error, and whether ``folder`` stayed as it was."""
    status: int
    err: str
    unchanged: bool

    def says(self, pieces) -> bool:
        """A :func:`clean_line` holding every piece."""
        return clean_line(self.err) and all(p in self.err for p in ([pieces] if isinstance(pieces, str) else pieces))


def refusal(capfd, folder: Path, *argv) -> Refusal:
    """Run ``argv``; what it returned, printed and left in ``folder``."""
    before = snapshot(folder)
    code, _, err = run(capfd, *argv)
    return Refusal(code, err, snapshot(folder) == before)


def refused(capfd, folder: Path, status: int, pieces, *argv) -> str:
    """Run ``argv``; assert the status, one line holding every piece, and ``folder`` unchanged; the line."""
    r = refusal(capfd, folder, *argv)
    assert r.status == status and r.says(pieces) and r.unchanged, (argv, pieces, r)
    return r.err


@pytest.fixture(scope="module")
def world(tmp_path_factory):
    """A synthetic rig's views and calibration, small maps, polynomials, quantizers, and broken files."""
    d = tmp_path_factory.mktemp("world")
    G.write_rig(d / "rig", n=4, seed=1)
    rig = G.eyebot_rig()
    C.write_yaml(rig.calibration(), d / "calib.yml")
    maps = X.compute_maps(rig.calibration(), size=(48, 36))
    X.save_maps(maps, d / "maps.npz")
    fit = P.fit(maps, 3)
    P.write_poly_json(fit, d / "poly.json")
    F.write_quantizers_json(F.run_ffc({k: list(v) for k, v in fit.coeffs.items()}, 48, 36, max_error=0.05),
                            d / "quantizers.json")
    left = cv2.imread(str(d / "rig" / "left01.png"), cv2.IMREAD_GRAYSCALE)
    cv2.imwrite(str(d / "cam.png"), left)
    cv2.imwrite(str(d / "cam.jpg"), left)
    png, jpg = (d / "cam.png").read_bytes(), (d / "cam.jpg").read_bytes()
    (d / "cut.png").write_bytes(png[: len(png) // 2])
    (d / "cut.jpg").write_bytes(jpg[: len(jpg) // 2])
    cv2.imwrite(str(d / "cam16.png"), left.astype(np.uint16) * 257)
    cv2.imwrite(str(d / "float.tiff"), left.astype(np.float32) / 255)
    return d


@pytest.fixture
def box(world, tmp_path):
    """A fresh copy of the world to run in (its snapshot is what must not change)."""
    import shutil

    shutil.copytree(world, tmp_path / "w")
    return tmp_path / "w"


# --------------------------------------------------------------------------------------------------
# 1. A calibration is judged when it is made, and named with a remedy when it is used


def test_calibrate_refuses_one_camera_given_twice(capfd, box):
    line = refused(capfd, box, 1, ["identical (left01.png / left01.png)", "give each camera's own images"],
            "calibrate", box / "rig" / "left*.png", box / "rig" / "left*.png", "--square", "0.02", "-o",
            box / "out.yml")
    assert line.startswith("eyestereo: error: ")


def test_calibrate_refuses_swapped_cameras(capfd, box):
    line = refused(capfd, box, 1,
                   ["left camera is to the right of the right camera", "give the left camera's images first"],
            "calibrate", box / "rig" / "right*.png", box / "rig" / "left*.png", "--square", "0.02", "-o",
            box / "out.yml")
    assert line.startswith("eyestereo: error: ")


def test_calibrate_refuses_stacked_cameras(capfd, box):
    rot = box / "rot"
    rot.mkdir()
    for p in (box / "rig").glob("*.png"):
        cv2.imwrite(str(rot / p.name), cv2.rotate(cv2.imread(str(p), cv2.IMREAD_GRAYSCALE), cv2.ROTATE_90_CLOCKWISE))
    line = refused(capfd, box, 1, ["the right camera sits below the left one", "rotate every image by 90 degrees"],
            "calibrate", rot / "left*.png", rot / "right*.png", "--square", "0.02", "-o", box / "out.yml")
    assert line.startswith("eyestereo: error: ")


@pytest.mark.skipif(not REAL.is_dir(), reason=f"shared calibration images not found at {REAL}")
def test_calibrate_refuses_a_lens_model_from_too_few_views(capfd, tmp_path):
    """Three of OpenCV's pairs: OpenCV calibrates them, but the right lens model folds inside the image."""
    line = refused(capfd, tmp_path, 1, ["calibration refused: the right camera's lens model (M2, D2) folds back",
                                 "% of the right image", "with the board also near the corners and edges"],
            "calibrate", REAL / "left0[1-3].jpg", REAL / "right0[1-3].jpg", "-o", tmp_path / "c.yml")
    assert line.startswith("eyestereo: error: ")


@pytest.mark.parametrize("change, pieces", [
    (dict(D1=[-0.9, 0.0, 0.0, 0.0, 0.0]), ["calib.yml: the left camera's lens model (M1, D1) folds back",
                                           "Calibrate again with more views"]),
    (dict(T=[1e-9, 0.0, 0.0]), ["the two cameras are only 1e-09 apart", "each camera's own images"]),
    (dict(T=[0.001, -0.066, 0.0]), ["the right camera sits below the left one", "rotate every image"]),
])
@pytest.mark.parametrize("command", ["maps", "rectifier"])
def test_an_unusable_calibration_file_names_the_camera_and_the_remedy(capfd, box, change, pieces, command):
    cal = C.read_yaml(box / "calib.yml")
    for k, v in change.items():
        setattr(cal, k, np.array(v))
    C.write_yaml(cal, box / "calib.yml")
    out = box / ("o.npz" if command == "maps" else "o")
    r = refusal(capfd, box, command, box / "calib.yml", "-o", out)
    assert r.status == 1 and r.unchanged and r.says(pieces), r


def test_judge_conditioning_and_coverage():
    cal = G.eyebot_rig().calibration()
    cal.info.update(focal_spread_left=0.05, board_distance=0.4)
    with pytest.raises(J.CalibrationProblem, match=r"poorly conditioned: the left camera's focal length is known only "
                                                   r"to \+-5.0 % .* board tilted"):
        J.judge_calibration(cal)
    cal.info.update(focal_spread_left=0.001, points_left=[np.array([[170.0, 140], [180, 140], [175, 150]])])
    notes = J.judge_calibration(cal)
    assert len(notes) == 1 and "the boards cover only 0 % of the left image" in notes[0]


# --------------------------------------------------------------------------------------------------
# 2. All or nothing, on errors and on signals; one policy for existing outputs


def test_fit_failing_in_the_plots_leaves_no_poly_json(capfd, box, monkeypatch):
    def half(maps, result, folder, **kw):
        (Path(folder) / "left_quiver.png").write_bytes(b"png")
        raise OSError(28, "No space left on device", str(Path(folder) / "left_contour.png"))

    monkeypatch.setattr(P, "plot_errors", half)
    line = refused(capfd, box, 1, ["No space left on device"], "fit", box / "maps.npz", "--plots", box / "plots",
                   "-o", box / "p2.json")
    assert str(box / "plots") in line  # the user's folder, not the temporary


def test_rig_failing_part_way_leaves_no_images(capfd, box, monkeypatch):
    def boom(*a, **k):
        raise ValueError("cannot write the calibration")

    monkeypatch.setattr(G, "write_yaml", boom)
    r = refusal(capfd, box, "rig", "--views", "2", "-o", box / "newrig")
    assert r.status == 1 and r.unchanged and r.says("cannot write the calibration"), r
    assert not (box / "newrig").exists()


@pytest.mark.parametrize("sig, status, name", [(signal.SIGTERM, 143, "SIGTERM"), (signal.SIGINT, 130, "SIGINT")])
def test_a_signal_leaves_nothing_behind(world, tmp_path, sig, status, name):
    """SIGTERM/SIGINT while the rectifier works: exit 128 + N, one line, no folder, no hidden temporary."""
    exe = Path(sys.executable).parent / "eyestereo"
    cmd = [str(exe)] if exe.exists() else [sys.executable, "-m", "eyestereo.tools.cli.main"]
    proc = subprocess.Popen([*cmd, "rectifier", str(world / "calib.yml"), "-o", str(tmp_path / "out")],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while not list(tmp_path.glob(".out.eyestereo-*")) and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.02)
    assert proc.poll() is None, "the run ended before the signal"
    time.sleep(0.3)  # well inside the run (maps, fit, plots, FFC take seconds)
    proc.send_signal(sig)
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == status, err
    assert clean_line(err) and err == f"eyestereo: error: interrupted ({name}); nothing was written\n"
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("argv", [
    ["rig", "--views", "1", "-o", "{o}"],
    ["rectifier", "{d}/calib.yml", "-o", "{o}"],
    ["fit", "{d}/maps.npz", "-o", "{d}/p2.json", "--plots", "{o}"],
    ["evaluate", "{d}/rig/left01.png", "{d}/rig/right01.png", "{d}/cam.png", "-o", "{o}"],
])
def test_an_existing_folder_that_is_not_ours_is_refused_everywhere(capfd, box, argv):
    (box / "mine").mkdir()
    (box / "mine" / "thesis.tex").write_text("keep me")
    r = refusal(capfd, box, *(a.format(d=box, o=box / "mine") for a in argv))
    assert r.status == 1 and r.unchanged, r
    assert r.says(["mine holds thesis.tex, which this command does not write", "give a new or empty folder"]), r
    assert (box / "mine" / "thesis.tex").read_text() == "keep me"


def test_an_earlier_folder_of_ours_is_replaced_as_a_whole(capfd, box):
    code, _, err = run(capfd, "rig", "--views", "1", "-o", box / "rig")  # box/rig holds 4 views
    assert code == 0, err
    assert sorted(p.name for p in (box / "rig").iterdir()) == ["left01.png", "rig_calib.yml", "right01.png"]
    assert not [p for p in box.iterdir() if p.name.startswith(".")]


@pytest.mark.parametrize("argv", [
    ["calibrate", "{d}/rig/left*.png", "{d}/rig/right*.png", "--square", "0.02", "-o", "{o}"],
    ["maps", "{d}/calib.yml", "--size", "32x24", "-o", "{o}"],
    ["fit", "{d}/maps.npz", "-o", "{o}"],
    ["warp", "{d}/cam.png", "{d}/poly.json", "--side", "left", "-o", "{o}"],
    ["lut", "{d}/maps.npz", "-o", "{o}"],
    ["ffc", "{d}/poly.json", "--max-error", "0.5", "-o", "{o}"],
    ["package", "{d}/quantizers.json", "-o", "{o}"],
])
def test_an_existing_file_is_replaced_keeping_its_mode_and_a_folder_is_refused(capfd, box, argv):
    target = box / ("existing.png" if argv[0] == "warp" else "existing.out")
    target.write_text("old")
    os.chmod(target, 0o640)
    code, _, err = run(capfd, *(a.format(d=box, o=target) for a in argv))
    assert code == 0, err
    assert target.read_bytes() != b"old" and target.stat().st_mode & 0o777 == 0o640
    assert not [p for p in box.iterdir() if p.name.startswith(".")]
    (box / "adir").mkdir()
    refused(capfd, box, 1, "adir: it is a folder", *(a.format(d=box, o=box / "adir") for a in argv))


# --------------------------------------------------------------------------------------------------
# 3. Damaged images are refused naming the file; 16-bit is handled, floating point refused


@pytest.mark.parametrize("name, piece", [("cut.png", "truncated PNG"), ("cut.jpg", "truncated JPEG")])
def test_truncated_images_are_refused_by_every_command(capfd, box, name, piece):
    bad = box / name
    r = refusal(capfd, box, "warp", bad, box / "maps.npz", "--side", "left", "-o", box / "w.png")
    assert r.status == 1 and r.unchanged and r.says(f"{bad} is a {piece}"), r
    glob_dir = box / "pairs"
    glob_dir.mkdir()
    ext = Path(name).suffix
    for i in (1, 2, 3):
        for side in ("left", "right"):
            img = cv2.imread(str(box / "rig" / f"{side}0{i}.png"), cv2.IMREAD_GRAYSCALE)
            cv2.imwrite(str(glob_dir / f"{side}0{i}{ext}"), img)
    (glob_dir / f"left02{ext}").write_bytes(bad.read_bytes())
    r = refusal(capfd, box, "calibrate", glob_dir / "left*", glob_dir / "right*", "-o", box / "c.yml")
    assert r.status == 1 and r.unchanged and r.says([f"left02{ext}", piece]), r
    r = refusal(capfd, box, "evaluate", box / "cam.png", bad, box / "cam.png")
    assert r.status == 1 and r.unchanged and r.says([f"right image {bad}", piece]), r


def test_16_bit_images_are_handled(capfd, box):
    code, out, err = run(capfd, "warp", box / "cam16.png", box / "maps.npz", "--side", "left", "-o", box / "w16.png")
    assert code == 0 and err == "" and "(16-bit)" in out
    code, _, err = run(capfd, "warp", box / "cam.png", box / "maps.npz", "--side", "left", "-o", box / "w8.png")
    assert code == 0, err
    w16 = cv2.imread(str(box / "w16.png"), cv2.IMREAD_UNCHANGED)
    w8 = cv2.imread(str(box / "w8.png"), cv2.IMREAD_UNCHANGED)
    assert w16.dtype == np.uint16 and np.abs(w16.astype(int) - 257 * w8.astype(int)).max() <= 257
    # matching reads 16-bit pairs through the same rule: the same figures as the 8-bit pair
    j8, j16 = box / "e8.json", box / "e16.json"
    assert run(capfd, "evaluate", box / "cam.png", box / "cam.png", box / "cam.png", "--json", j8)[0] == 0
    assert run(capfd, "evaluate", box / "cam16.png", box / "cam16.png", box / "cam.png", "--json", j16)[0] == 0
    a, b = json.loads(j8.read_text()), json.loads(j16.read_text())
    assert a["matches"] == b["matches"] > 0 and a["left_corners"] == b["left_corners"]


def test_floating_point_images_are_refused(capfd, box):
    for argv in (["warp", box / "float.tiff", box / "maps.npz", "--side", "left", "-o", box / "w.png"],
                 ["evaluate", box / "float.tiff", box / "cam.png", box / "cam.png"]):
        r = refusal(capfd, box, *argv)
        assert r.status == 1 and r.unchanged, r
        assert r.says(["float.tiff holds floating-point pixels", "8- or 16-bit PNG"]), r
    r = refusal(capfd, box, "warp", box / "cam16.png", box / "maps.npz", "--side", "left", "-o", box / "w.jpg")
    assert r.status == 1 and r.unchanged and r.says("is 16-bit, which .jpg cannot hold"), r


# --------------------------------------------------------------------------------------------------
# 4. One clear line: no library text, no exception names, no temporaries; one exit code per kind


def test_no_library_text_reaches_the_terminal(capfd, box):
    """What used to print libpng/OpenCV/numpy lines before the error, or an OpenCV assertion instead of it."""
    (box / "text.png").write_text("not a png")
    cases = [
        (["warp", box / "cut.png", box / "maps.npz", "--side", "left", "-o", box / "w.png"], 1, "truncated"),
        (["warp", box / "text.png", box / "maps.npz", "--side", "left", "-o", box / "w.png"], 1, "cannot read image"),
        (["calibrate", box / "rig" / "left*.png", box / "rig" / "right*.png", "--board", "3x2", "-o", box / "c.yml"],
         2, "3..100 inner corners"),
        (["calibrate", box / "rig" / "left*.png", box / "rig" / "right*.png", "--square", "1e300", "-o",
          box / "c.yml"], 2, "--square: must lie in"),
    ]
    for argv, status, piece in cases:
        line = refused(capfd, box, status, piece, *argv)
        assert "OpenCV(" not in line and "(-215" not in line and "WARN" not in line


@pytest.mark.parametrize("edit, piece", [
    (lambda d: d.update(width="big"), "poly.json: width must be a positive integer, got 'big'"),
    (lambda d: d["polynomials"].update(left_x=None), "polynomial 'left_x' must be a list of 10 numbers"),
    (lambda d: d["polynomials"]["left_y"].__setitem__(0, "x"), "p1 is not a number: 'x'"),
])
def test_type_errors_in_files_become_plain_messages(capfd, box, edit, piece):
    doc = json.loads((box / "poly.json").read_text())
    edit(doc)
    (box / "poly.json").write_text(json.dumps(doc))
    line = refused(capfd, box, 1, piece, "ffc", box / "poly.json", "-o", box / "q.json")
    assert "TypeError" not in line and "IndexError" not in line


def test_a_failed_write_names_the_users_path(capfd, box, monkeypatch):
    def full(result, path):
        raise OSError(28, "No space left on device", str(path))

    monkeypatch.setattr(P, "write_poly_json", full)
    line = refused(capfd, box, 1, f"{box / 'p2.json'}: No space left on device", "fit", box / "maps.npz", "-o",
                   box / "p2.json")
    assert ".eyestereo-" not in line


COMMANDS = {  # command -> (its inputs, an output), for the same-mistake-same-status table
    "calibrate": ["{d}/rig/left*.png", "{d}/rig/right*.png", "-o", "{d}/o.yml"],
    "maps": ["{d}/calib.yml", "-o", "{d}/o.npz"],
    "fit": ["{d}/maps.npz", "-o", "{d}/o.json"],
    "warp": ["{d}/cam.png", "{d}/maps.npz", "--side", "left", "-o", "{d}/o.png"],
    "lut": ["{d}/maps.npz", "-o", "{d}/o.h"],
    "rectifier": ["{d}/calib.yml", "-o", "{d}/o"],
    "ffc": ["{d}/poly.json", "-o", "{d}/o.json"],
    "package": ["{d}/quantizers.json", "-o", "{d}/o.vhd"],
    "evaluate": ["{d}/cam.png", "{d}/cam.png", "{d}/cam.png", "--json", "{d}/o.json"],
}


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_the_same_mistake_gives_the_same_status_in_every_command(capfd, box, command):
    argv = [a.format(d=box) for a in COMMANDS[command]]
    first_input = next(i for i, a in enumerate(argv) if str(box) in a)
    missing = list(argv)
    missing[first_input] = str(box / "missing.file")
    r = refusal(capfd, box, command, *missing)
    assert r.status == 1 and r.unchanged, r
    assert r.says(["missing.file", "does not exist" if command != "calibrate" else "no left images match"]), r
    r = refusal(capfd, box, command, *argv, "--frobnicate")
    assert r.status == 2 and r.unchanged and r.says("unrecognized arguments: --frobnicate"), r
    nodir = [a.replace(f"{box}/o", f"{box}/nodir/o") for a in argv]
    r = refusal(capfd, box, command, *nodir)
    assert r.status == 1 and r.unchanged and r.says(f"{box}/nodir"), r


def test_outputs_get_the_users_umask(capfd, box):
    old = os.umask(0o027)
    try:
        for argv in (["rig", "--views", "1", "-o", box / "r"], ["maps", box / "calib.yml", "--size", "8x6", "-o",
                                                                  box / "m.npz"],
                     ["evaluate", box / "cam.png", box / "cam.png", box / "cam.png", "--json", box / "e.json", "-o",
                      box / "pics"]):
            code, _, err = run(capfd, *argv)
            assert code == 0, err
    finally:
        os.umask(old)
    for p in [box / "r", box / "pics"]:
        assert p.stat().st_mode & 0o777 == 0o750
    for p in [*(box / "r").iterdir(), *(box / "pics").iterdir(), box / "m.npz", box / "e.json"]:
        assert p.stat().st_mode & 0o777 == 0o640, p


# --------------------------------------------------------------------------------------------------
# 5. Implausible values


def test_a_focal_length_of_1e300_is_refused(capfd, box):
    text = (box / "calib.yml").read_text()
    cal = C.read_yaml(box / "calib.yml")
    fx = cal.M1[0, 0]
    fs = cv2.FileStorage(str(box / "calib.yml"), cv2.FILE_STORAGE_WRITE)
    m1 = cal.M1.copy()
    m1[0, 0] = 1e300
    for k, v in (("M1", m1), ("D1", cal.D1.reshape(1, -1)), ("M2", cal.M2), ("D2", cal.D2.reshape(1, -1)),
                 ("R", cal.R), ("T", cal.T.reshape(3, 1))):
        fs.write(k, v)
    for k, v in (("image_width", 352), ("image_height", 288), ("rms", 0.1)):
        fs.write(k, v)
    fs.release()
    assert text != (box / "calib.yml").read_text() and fx < 1e4
    for cmd, out in (("maps", "m.npz"), ("rectifier", "out")):
        refused(capfd, box, 1, ["calib.yml: M1: focal length fx = 1e+300 px is implausible", "352 px wide"], cmd,
                box / "calib.yml", "-o", box / out)


@pytest.mark.parametrize("edit, piece", [
    (lambda d: d["quantizers"][4].update(wl=1_000_000), "quantizer q5: word length 1000000 is implausible"),
    (lambda d: [d["polynomials"].pop(k) for k in ("left_y", "right_x", "right_y")],
     "'polynomials' must hold the four left_x, left_y, right_x, right_y; it lacks left_y, right_x, right_y"),
    (lambda d: d.update(width=10 ** 9), "width 1000000000 is implausible"),
])
def test_implausible_quantizer_files_are_refused(capfd, box, edit, piece):
    doc = json.loads((box / "quantizers.json").read_text())
    edit(doc)
    (box / "quantizers.json").write_text(json.dumps(doc))
    r = refusal(capfd, box, "package", box / "quantizers.json", "-o", box / "pkg.vhd")
    assert r.status == 1 and r.unchanged and r.says(piece), r


def test_implausible_sizes_are_refused(capfd, box):
    r = refusal(capfd, box, "maps", box / "calib.yml", "--size", "16384x16384", "-o", box / "m.npz")
    assert r.status == 2 and r.unchanged and r.says("at most 16777216"), r
    doc = json.loads((box / "poly.json").read_text())
    doc["width"] = 10 ** 9
    (box / "poly.json").write_text(json.dumps(doc))
    r = refusal(capfd, box, "ffc", box / "poly.json", "-o", box / "q.json")
    assert r.status == 1 and r.unchanged and r.says("width 1000000000 is implausible"), r


def test_a_signal_whose_exception_was_swallowed_still_ends_the_command(capfd, tmp_path):
    """CI saw SIGINT land in an import-lock callback, where Python drops the handler's exception: the
    command must still end with 128 + N and write nothing."""
    from eyestereo.tools import io as IO
    from eyestereo.tools.cli import common

    def handler(args):
        try:
            IO.interrupt(signal.SIGINT)
        except IO.Interrupted:
            pass  # what Python's "Exception ignored in ..." does
        with IO.Outputs() as out:
            out.file(tmp_path / "result.txt").write_text("done")
        return 0

    parser = common.Parser(prog="eyestereo")
    parser.set_defaults(func=handler)
    assert common.run_command(parser, []) == 130
    assert capfd.readouterr().err == "eyestereo: error: interrupted (SIGINT); nothing was written\n"
    assert list(tmp_path.iterdir()) == []
