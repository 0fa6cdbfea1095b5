"""``eyestereo sim rectify``: a generated rectifier's VHDL in GHDL on a stereo pair.

A command of ``eyestereo sim``, added by ``eyestereo.sim.apps.cli``.

``eyestereo sim rectify DIR LEFT RIGHT -o OUT``: ``DIR`` is the output of ``eyestereo rectifier CALIB -o DIR
--vhdl`` (its ``quantizers.json`` and ``vhdl/``); the pair (the calibration's camera size; read by the
library's one image rule, :func:`eyestereo.tools.io.read_image` and :func:`~eyestereo.tools.io.to_grey8`)
is rectified by that VHDL in GHDL, a memory model answering the fetch port. Writes ``OUT/left.png``,
``OUT/right.png`` (rectified) and ``OUT/report.json``: the rectified size, ``clocks`` (from ``start`` to
the last output beat), ``clocks_per_pixel`` (per stereo output pixel), ``reads`` and
``reads_per_output_pixel`` (pixels the memory sent, per output pixel of one camera; the thesis reads 4),
``bit_exact`` (every beat equal to the bit-true model's), the memory model and the GHDL back end.

Every input is checked before the build; outputs are written all or nothing, never into a folder holding
the inputs; the simulation runs in a child process (:mod:`eyestereo.sim.apps.job`) that SIGINT/SIGTERM stop
within a second or two; the build goes to ``--build-dir`` (default ``$EYESTEREO_BUILD_DIR`` or the
system's temporary folder).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import time
from pathlib import Path
from typing import Any

from eyestereo.tools.cli.common import integer

#: The folder of ``eyestereo rectifier CALIB -o DIR --vhdl`` holding the VHDL, and its manifest.
VHDL_DIR = "vhdl"
MANIFEST = "rectifier.json"
SIM_OUTPUTS = ("left.png", "right.png", "report.json")
MEMORIES = {"at-once": dict(ready_p=1.0, latency=0, wait_p=0.0),
            "random": dict(ready_p=0.7, latency=6, wait_p=0.3, stall_p=0.0005, stall=[50, 400])}


def _load_dir(folder: Path) -> tuple[dict, Path]:
    if not folder.is_dir():
        raise ValueError(f"{folder}: no such folder (the output of 'eyestereo rectifier CALIB -o DIR --vhdl')")
    man = folder / VHDL_DIR / MANIFEST
    q = folder / "quantizers.json"
    if not q.is_file():
        raise ValueError(f"{folder} holds no quantizers.json: not an 'eyestereo rectifier' output folder")
    if not man.is_file():
        raise ValueError(f"{folder} has no {VHDL_DIR}/{MANIFEST}: run 'eyestereo rectifier CALIB -o {folder} --vhdl'")
    try:
        m = json.loads(man.read_text())
        files = [folder / VHDL_DIR / f for f in m["files"]]
        for k in ("frac", "depth", "width", "height", "source_width", "source_height"):
            int(m[k])
    except (ValueError, KeyError, TypeError) as e:
        raise ValueError(f"{man}: damaged manifest ({type(e).__name__}: {e})") from None
    missing = [str(f) for f in files if not f.is_file()]
    if missing:
        raise ValueError(f"{man} names missing files: {', '.join(missing)}")
    return m, q


def read_pair(left: str | os.PathLike[str], right: str | os.PathLike[str]):
    """The pair as 8-bit grey images by the library's one image rule (colour to grey, 16-bit to its 8 most
    significant used bits with one shift for both, floating point refused), both the same size."""
    import numpy as np

    from eyestereo.tools.io import read_image, to_grey8

    imgs = [read_image(left, what="left image"), read_image(right, what="right image")]
    gl, gr = to_grey8(imgs, [f"left image {left}", f"right image {right}"])
    if gl.shape != gr.shape:
        raise ValueError(f"the images differ in size: left {left} is {gl.shape[1]}x{gl.shape[0]}, right {right} "
                         f"is {gr.shape[1]}x{gr.shape[0]}")
    return np.ascontiguousarray(gl, np.uint8), np.ascontiguousarray(gr, np.uint8)


def run_vhdl(sources: list[str], cfg: dict, build_dir: str) -> dict:
    """Run :mod:`eyestereo.sim.benches.tb_rectifier` on the VHDL ``sources`` (entity ``rectifier``) in GHDL (the
    child process of :func:`eyestereo.sim.apps.job.run_job` calls it)."""
    from cocotb_tools.runner import get_results, get_runner

    from eyestereo.sim.lib.runner import GHDL_ARGS, GHDL_RUN_OPTIONS, SIM_DIR

    build = Path(build_dir)
    build.mkdir(parents=True, exist_ok=True)
    report = build / "report.json"
    full = dict(cfg, report=str(report))
    runner = get_runner("ghdl")
    log = build / "ghdl.log"
    runner.build(sources=sources, hdl_toplevel="rectifier", build_dir=build, build_args=GHDL_ARGS, always=True,
                 log_file=build / "build.log")
    env = {"EYESTEREO_TB": json.dumps(full),
           "PYTHONPATH": os.pathsep.join([str(SIM_DIR), os.environ.get("PYTHONPATH", "")])}
    results = runner.test(hdl_toplevel="rectifier", hdl_toplevel_lang="vhdl",
                          test_module="eyestereo.sim.benches.tb_rectifier", build_dir=build, test_dir=build,
                          test_args=GHDL_ARGS, extra_env=env,
                          plusargs=GHDL_RUN_OPTIONS, log_file=log)
    n_tests, n_failed = get_results(results)
    if n_tests == 0 or n_failed:
        raise AssertionError("a fetch-port rule broken or a timeout (see ghdl.log)")
    return json.loads(report.read_text())


def cmd_sim_rectify(args: argparse.Namespace) -> int:
    import cv2
    import numpy as np

    from eyestereo.sim.apps.job import check_build_dir, file_progress, run_folder, run_job
    from eyestereo.tools.io import Outputs, atomic_write_text
    from eyestereo.tools.progress import progress_bar

    folder = Path(args.rectifier_dir)
    m, q = _load_dir(folder)
    left, right = read_pair(args.left, args.right)
    sw, sh = int(m["source_width"]), int(m["source_height"])
    if left.shape != (sh, sw):
        raise ValueError(f"the images are {left.shape[1]}x{left.shape[0]}; the rectifier in {folder} was made for "
                         f"{sw}x{sh} camera images")
    if shutil.which("ghdl") is None:
        raise ValueError("ghdl not found: install GHDL (Debian: apt-get install ghdl)")
    check_build_dir(args.build_dir)
    with Outputs() as out:
        tmp_out = out.folder(Path(args.output), SIM_OUTPUTS, inputs=[args.left, args.right, folder])
        with run_folder("sim-rectify", args.build_dir) as work:
            np.save(work / "left.npy", left)
            np.save(work / "right.npy", right)
            sources = [str((folder / VHDL_DIR / f).resolve()) for f in m["files"]]
            cfg = dict(MEMORIES[args.memory], seed=args.seed, frames=1, lenient=True,
                       params=dict(quantizers=str(q.resolve()), frac=int(m["frac"]), depth=int(m["depth"]),
                                   source_width=sw, source_height=sh),
                       images={"left": str(work / "left.npy"), "right": str(work / "right.npy")},
                       dump=str(work / "out.npz"), progress=str(work / "progress"))
            total = 2 * int(m["width"]) * int(m["height"])
            t0 = time.perf_counter()
            with progress_bar(total, "sim rectify", unit="beat") as bar:
                rep = run_job("eyestereo.sim.apps.cli_rectify:run_vhdl",
                              dict(sources=sources, cfg=cfg, build_dir=str(work / "build")), work,
                              progress=file_progress(work / "progress", bar, total), what="the GHDL simulation")
                bar.update(total - bar.n)
            d = np.load(work / "out.npz")
            for name in ("left", "right"):
                ok, buf = cv2.imencode(".png", d[name])
                if not ok:
                    raise ValueError(f"cannot encode {name}.png")
                (tmp_out / f"{name}.png").write_bytes(buf.tobytes())
        rep = dict(width=rep["width"], height=rep["height"], clocks=rep["clocks"],
                   clocks_per_pixel=rep["clocks_per_pixel"], reads=rep["reads"],
                   reads_per_output_pixel=rep["reads_per_output_pixel"],
                   reads_per_inrange_pixel=rep["reads_per_inrange_pixel"], requests=rep["requests"],
                   bit_exact=bool(rep["bit_exact"]), memory=args.memory, seed=args.seed,
                   ghdl_backend=os.environ.get("GHDL_BACKEND", "mcode"), wall_s=round(time.perf_counter() - t0, 1),
                   rectifier_dir=str(folder), left=str(args.left), right=str(args.right))
        atomic_write_text(tmp_out / "report.json", json.dumps(rep, indent=2) + "\n")
    print(f"rectified {rep['width']}x{rep['height']} in GHDL: {rep['clocks']:,} clocks, {rep['clocks_per_pixel']:.2f} "
          f"clocks/pixel, {rep['reads_per_output_pixel']:.2f} reads/pixel, bit exact {str(rep['bit_exact']).lower()} "
          f"-> {args.output}/")
    return 0


def add_build_dir(p: argparse.ArgumentParser) -> None:
    """``--build-dir`` of the simulation commands."""
    p.add_argument("--build-dir", dest="build_dir", type=Path, default=None, metavar="DIR",
                   help="where the simulator builds (one fresh folder per run, removed after it unless the "
                        "run failed; default $EYESTEREO_BUILD_DIR, else the system's temporary folder)")


def add_rectify(sub: Any) -> None:
    """Add ``sim rectify`` to the ``sim`` group's subparsers (``eyestereo.sim.apps.cli.register`` calls it)."""
    r = sub.add_parser("rectify", help="rectify a stereo pair with the rectifier's VHDL in GHDL",
                       description="Run RECTIFIER_DIR/vhdl/ (from 'eyestereo rectifier CALIB -o DIR --vhdl') in GHDL "
                       "on a stereo pair, a memory model answering the fetch port; write OUT/left.png, right.png "
                       "(rectified) and report.json (clocks, clocks and memory reads per output pixel, bit_exact).")
    r.add_argument("rectifier_dir", metavar="RECTIFIER_DIR")
    r.add_argument("left", metavar="LEFT", help="left camera image (the calibration's camera size)")
    r.add_argument("right", metavar="RIGHT", help="right camera image")
    r.add_argument("-o", "--output", required=True, metavar="OUT",
                   help="output folder: new, empty, or holding only this command's files (its parent must exist)")
    r.add_argument("--memory", choices=sorted(MEMORIES), default="at-once",
                   help="memory model: answers at once (default) or with random delays and stalls")
    r.add_argument("--seed", type=integer(0, 2**31 - 1, "--seed"), default=1,
                   help="seed of the random memory timing (default 1)")
    add_build_dir(r)
    r.set_defaults(func=cmd_sim_rectify)
