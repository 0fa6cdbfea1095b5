"""The simulation commands of ``eyestereo`` (registered through the ``eyestereo.cli`` entry point).

::

    eyestereo rectifier CALIB -o DIR --vhdl          the toolbox's run, plus DIR/vhdl/: the rectifier's VHDL for
                                                     that calibration, analysed by GHDL (--std=93c and 08)
    eyestereo sim rectify DIR LEFT RIGHT -o OUT      DIR/vhdl/ in GHDL on a stereo pair, a memory model on its
                                                     fetch port -> OUT/left.png, right.png, report.json
    eyestereo sim harris LEFT RIGHT -o OUT           harris_stereo's VHDL in GHDL on a grey pair -> corners.json,
                                                     overlays (eyestereo.sim.cli_harris)

``report.json``: the rectified size, ``clocks`` (from ``start`` to the last output beat), ``clocks_per_pixel``
(per stereo output pixel), ``reads`` and ``reads_per_output_pixel`` (pixels the memory sent, per output
pixel of one camera; the thesis reads 4), ``bit_exact`` (every beat equal to the bit-true model's), the
memory model and the GHDL back end. Outputs are written all or nothing; bad input ends in one line.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import shutil
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

VHDL_DIR = "vhdl"
MANIFEST = "rectifier.json"
SIM_OUTPUTS = ("left.png", "right.png", "report.json")
MEMORIES = {"at-once": dict(ready_p=1.0, latency=0, wait_p=0.0),
            "random": dict(ready_p=0.7, latency=6, wait_p=0.3, stall_p=0.0005, stall=[50, 400])}


# ------------------------------------------------------------------------------------------ VHDL
def write_vhdl(quantizers: str | os.PathLike[str], folder: Path, *, source_width: int, source_height: int,
               frac: int | None = None, depth: int = 4) -> list[str]:
    """The rectifier for ``quantizers`` (camera images ``source_width`` x ``source_height``) as VHDL in
    ``folder`` (package, entity ``rectifier``, manifest), analysed by GHDL with --std=93c and --std=08;
    returns the file names."""
    from eyestereo.hdl.convert import GHDL_STDS, analyse, convert, vhdl_ports
    from eyestereo.tools.models.poly_unit import Calibration, resolve_frac

    if shutil.which("ghdl") is None:
        raise ValueError("ghdl not found: install GHDL (Debian: apt-get install ghdl) to write the rectifier's VHDL")
    cal = Calibration.load(str(quantizers), source_width=source_width, source_height=source_height)
    frac = resolve_frac(cal, frac)
    folder.mkdir(parents=True, exist_ok=True)
    files = convert("rectifier", folder, quantizers=str(quantizers), frac=frac, depth=depth,
                    source_width=source_width, source_height=source_height)
    with tempfile.TemporaryDirectory() as tmp:
        for std in GHDL_STDS:
            analyse(files, std, Path(tmp) / std)
    manifest = dict(entity="rectifier", files=[f.name for f in files], frac=frac, depth=depth,
                    width=cal.width, height=cal.height, source_width=cal.source_width,
                    source_height=cal.source_height, ghdl_std=list(GHDL_STDS), ports=vhdl_ports(files[-1]))
    (folder / MANIFEST).write_text(json.dumps(manifest, indent=2) + "\n")
    return [f.name for f in files] + [MANIFEST]


def _owned_with_vhdl(name: str) -> bool:
    from eyestereo.tools.rectify.run import owned

    if name == VHDL_DIR:
        return True
    if name.startswith(VHDL_DIR + "/"):
        rest = name.split("/", 1)[1]
        return "/" not in rest and (rest.endswith(".vhd") or rest == MANIFEST)
    return owned(name)


def _wrap_rectifier(parser: argparse.ArgumentParser) -> None:
    """Add ``--vhdl`` to the toolbox's ``rectifier`` command."""
    orig = parser.get_default("func")
    parser.add_argument("--vhdl", action="store_true",
                        help="also write OUTDIR/vhdl/: the rectifier's VHDL for this calibration (entity "
                             "rectifier, analysed by GHDL); run it with 'eyestereo sim rectify'")

    def cmd(args: argparse.Namespace) -> int:
        if not getattr(args, "vhdl", False):
            return orig(args)
        from eyestereo.tools.io import Outputs

        outdir = Path(args.output)
        with Outputs() as out:
            tmp = out.folder(outdir, _owned_with_vhdl)
            args_inner = argparse.Namespace(**vars(args))
            args_inner.output = str(tmp)
            text = io.StringIO()
            with contextlib.redirect_stdout(text):
                status = orig(args_inner)
            print(text.getvalue().replace(str(tmp), str(outdir)).replace(tmp.name, str(outdir)), end="")
            if status:
                raise ValueError("the toolbox run failed; nothing written")
            if not (tmp / "quantizers.json").exists():
                raise ValueError("no quantizers.json (the VHDL needs degree 3); nothing written")
            from eyestereo.tools.rectify.calib import read_yaml

            sw, sh = read_yaml(Path(args.calib)).image_size
            names = write_vhdl(tmp / "quantizers.json", tmp / VHDL_DIR, source_width=sw, source_height=sh)
            print(f"rectifier VHDL ({', '.join(names)}) analysed by GHDL -> {outdir}/{VHDL_DIR}/")
        return 0

    parser.set_defaults(func=cmd)


# ------------------------------------------------------------------------------------------ sim rectify
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


def _read_pair(left: str, right: str, w: int, h: int):
    import numpy as np

    from eyestereo.tools.io import read_image, to_grey8

    imgs = []
    for what, path in (("left image", left), ("right image", right)):
        img = read_image(path, what=what)
        imgs.append(to_grey8(img, what))
    for what, path, img in (("left image", left, imgs[0]), ("right image", right, imgs[1])):
        if img.shape != (h, w):
            raise ValueError(f"{what} {path} is {img.shape[1]}x{img.shape[0]}; the rectifier was made for "
                             f"{w}x{h} camera images")
    return [np.ascontiguousarray(i, dtype=np.uint8) for i in imgs]


def run_vhdl(sources: list[Path], cfg: dict, build_dir: Path, *, progress=None) -> dict:
    """Run :mod:`eyestereo.sim.tb_rectifier` on the VHDL ``sources`` (entity ``rectifier``) in GHDL."""
    from cocotb_tools.runner import get_results, get_runner

    from eyestereo.sim.runner import GHDL_ARGS, GHDL_RUN_OPTIONS, SIM_DIR

    build_dir.mkdir(parents=True, exist_ok=True)
    report = build_dir / "report.json"
    full = dict(cfg, report=str(report))
    runner = get_runner("ghdl")
    log = build_dir / "ghdl.log"
    runner.build(sources=[str(s) for s in sources], hdl_toplevel="rectifier", build_dir=build_dir,
                 build_args=GHDL_ARGS, always=True, log_file=build_dir / "build.log")
    env = {"EYESTEREO_TB": json.dumps(full),
           "PYTHONPATH": os.pathsep.join([str(SIM_DIR), os.environ.get("PYTHONPATH", "")])}
    results = runner.test(hdl_toplevel="rectifier", hdl_toplevel_lang="vhdl", test_module="eyestereo.sim.tb_rectifier",
                          build_dir=build_dir, test_dir=build_dir, test_args=GHDL_ARGS, extra_env=env,
                          plusargs=GHDL_RUN_OPTIONS, log_file=log)
    n_tests, n_failed = get_results(results)
    if n_tests == 0 or n_failed:
        raise ValueError(f"the simulation failed (a fetch-port rule broken or a timeout; log: {log})")
    return json.loads(report.read_text())


def cmd_sim_rectify(args: argparse.Namespace) -> int:
    import cv2

    from eyestereo.tools.io import Outputs
    from eyestereo.tools.progress import progress_bar

    folder = Path(args.rectifier_dir)
    m, q = _load_dir(folder)
    left, right = _read_pair(args.left, args.right, int(m["source_width"]), int(m["source_height"]))
    if shutil.which("ghdl") is None:
        raise ValueError("ghdl not found: install GHDL (Debian: apt-get install ghdl)")
    import numpy as np

    with Outputs() as out:
        tmp_out = out.folder(Path(args.output), SIM_OUTPUTS)
        with tempfile.TemporaryDirectory(prefix="eyestereo_sim_") as work:
            work = Path(work)
            np.save(work / "left.npy", left)
            np.save(work / "right.npy", right)
            sources = [folder / VHDL_DIR / f for f in m["files"]]
            cfg = dict(MEMORIES[args.memory], seed=args.seed, frames=1, lenient=True,
                       params=dict(quantizers=str(q.resolve()), frac=int(m["frac"]), depth=int(m["depth"]),
                                   source_width=int(m["source_width"]), source_height=int(m["source_height"])),
                       images={"left": str(work / "left.npy"), "right": str(work / "right.npy")},
                       dump=str(work / "out.npz"), progress=str(work / "progress"))
            total = 2 * int(m["width"]) * int(m["height"])
            result: dict[str, Any] = {}

            def target() -> None:
                try:
                    result["report"] = run_vhdl(sources, cfg, work / "build")
                except BaseException as e:  # noqa: BLE001 - handed to the main thread
                    result["error"] = e

            t0 = time.perf_counter()
            th = threading.Thread(target=target, daemon=True)
            th.start()
            with progress_bar(total, "sim rectify", unit="beat") as bar:
                while th.is_alive():
                    th.join(0.5)
                    try:
                        done = int((work / "progress").read_text().split()[0])
                        bar.update(max(0, min(done, total) - bar.n))
                    except (OSError, ValueError, IndexError):
                        pass
                bar.update(total - bar.n)
            if "error" in result:
                raise result["error"]
            rep = result["report"]
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
        (tmp_out / "report.json").write_text(json.dumps(rep, indent=2) + "\n")
    print(f"rectified {rep['width']}x{rep['height']} in GHDL: {rep['clocks']:,} clocks, {rep['clocks_per_pixel']:.2f} "
          f"clocks/pixel, {rep['reads_per_output_pixel']:.2f} reads/pixel, bit exact {str(rep['bit_exact']).lower()} "
          f"-> {args.output}/")
    return 0


def register(sub: Any) -> None:
    """Add the simulation commands (and ``rectifier --vhdl``)."""
    if "rectifier" in sub.choices:
        _wrap_rectifier(sub.choices["rectifier"])
    p = sub.add_parser("sim", help="run generated VHDL in GHDL on your data (rectify, harris, system)",
                       description="Run the generated hardware in GHDL with cocotb.")
    ss = p.add_subparsers(dest="sim_command", metavar="SIMCOMMAND", required=True, parser_class=type(p))
    r = ss.add_parser("rectify", help="rectify a stereo pair with the rectifier's VHDL in GHDL",
                      description="Run RECTIFIER_DIR/vhdl/ (from 'eyestereo rectifier CALIB -o DIR --vhdl') in GHDL "
                      "on a stereo pair, a memory model answering the fetch port; write OUT/left.png, right.png "
                      "(rectified) and report.json (clocks, clocks and memory reads per output pixel, bit_exact).")
    r.add_argument("rectifier_dir", metavar="RECTIFIER_DIR")
    r.add_argument("left", metavar="LEFT", help="left camera image (the calibration's camera size)")
    r.add_argument("right", metavar="RIGHT", help="right camera image")
    r.add_argument("-o", "--output", required=True, metavar="OUT", help="output folder (its parent must exist)")
    r.add_argument("--memory", choices=sorted(MEMORIES), default="at-once",
                   help="memory model: answers at once (default) or with random delays and stalls")
    r.add_argument("--seed", type=int, default=1, help="seed of the random memory timing (default 1)")
    r.set_defaults(func=cmd_sim_rectify)
    from eyestereo.sim.cli_harris import add_harris

    add_harris(ss)
    from eyestereo.sim.cli_system import add_system

    add_system(ss)
