"""``eyestereo sim harris``: the stereo Harris HDL in a simulator on an image pair.

A command of ``eyestereo sim``, added by ``eyestereo.sim.apps.cli``.

``eyestereo sim harris LEFT RIGHT -o OUT``: the generated ``harris_stereo`` on a stereo pair of images of
any size (5..4096 pixels a side), read by the library's one image rule (colour to grey, 16-bit to its 8
most significant used bits, floating point refused: :func:`eyestereo.sim.apps.cli_rectify.read_pair`); the
VHDL in GHDL by default, MyHDL's Verilog in Icarus or Verilator with ``--sim`` (or ``$SIM``), the summary
line naming the one that ran. Writes ``OUT/corners.json`` (``{"left": [[x, y], ...], "right": [...]}``:
the flags outside the detector's unspecified border, raster order) and ``OUT/left.png``, ``OUT/right.png``
(each image with its corners marked). Options: k and the block thresholds (in
:func:`eyestereo.tools.models.harris_mono.harris_float` units), globally or per camera, per block as a
comma list of BX*BY values; NMS size; share factor; ``--build-dir``. Errors: one line, exit status 1
(bad input) or 2 (bad command line), checked before the build; nothing written (the output folder appears
whole or not at all, and never replaces a folder holding the inputs); SIGINT/SIGTERM stop the simulator
within a second or two (:mod:`eyestereo.sim.apps.job`).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np

from eyestereo.sim.apps.cli_rectify import add_build_dir
from eyestereo.tools.cli.common import number
from eyestereo.tools.constants import FRAME_MAX, K_DEFAULT, NMS_DEFAULT, NMS_SIZES, SHARE_FACTORS, THRESHOLD_BLOCKS
from eyestereo.tools.io import Outputs
from eyestereo.tools.progress import progress_bar

PICTURES = ("corners.json", "left.png", "right.png")


def _blocks(text: str) -> tuple[int, int]:
    try:
        bx, by = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected BXxBY like 4x4, got {text!r}") from None
    if not (1 <= bx <= 16 and 1 <= by <= 16):
        raise argparse.ArgumentTypeError(f"--blocks {text}: BX and BY must be 1..16")
    return bx, by


def _thresholds(text: str) -> list[float]:
    try:
        vals = [float(v) for v in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number or a comma list of numbers, got {text!r}") from None
    if not all(np.isfinite(vals)):
        raise argparse.ArgumentTypeError(f"thresholds must be finite numbers, got {text!r}")
    return vals


def add_harris(sub: Any) -> None:
    """Add ``sim harris`` to the ``sim`` group's subparsers (``eyestereo.sim.apps.cli.register`` calls it)."""
    p = sub.add_parser("harris", help="stereo Harris corners of an image pair by the harris_stereo VHDL in GHDL",
                       description="Both images through the generated harris_stereo VHDL in GHDL (one datapath for "
                                   "the two cameras, as on the FPGA); writes corners.json and overlay PNGs.")
    p.add_argument("left", type=Path, help="left grey image (colour is converted to grey; 8-bit)")
    p.add_argument("right", type=Path, help="right grey image, the same size")
    p.add_argument("-o", "--output", type=Path, required=True,
                   help="folder for corners.json, left.png, right.png; created, or replaced when it holds only these")
    p.add_argument("--k", type=lambda t: number(t, float, 0.0, 255 / 256, "--k"), default=K_DEFAULT,
                   help=f"Harris k for both cameras (default {K_DEFAULT})")
    p.add_argument("--k-left", dest="k_left", type=lambda t: number(t, float, 0.0, 255 / 256, "--k-left"), default=None)
    p.add_argument("--k-right", dest="k_right", type=lambda t: number(t, float, 0.0, 255 / 256, "--k-right"),
                   default=None)
    p.add_argument("--threshold", type=_thresholds, default=[1e8],
                   help="cornerness threshold(s) for both cameras, harris_float units: one value for every "
                        "block, or BX*BY comma-separated values by block index by*BX+bx (default 1e8)")
    p.add_argument("--threshold-left", dest="threshold_left", type=_thresholds, default=None)
    p.add_argument("--threshold-right", dest="threshold_right", type=_thresholds, default=None)
    p.add_argument("--blocks", type=_blocks, default=THRESHOLD_BLOCKS,
                   help="threshold blocks BXxBY (default {}x{})".format(*THRESHOLD_BLOCKS))
    p.add_argument("--nms", type=int, choices=NMS_SIZES, default=NMS_DEFAULT,
                   help=f"non-maximum suppression (default {NMS_DEFAULT})")
    p.add_argument("--share", type=int, choices=SHARE_FACTORS, default=3,
                   help="clocks the multipliers are shared over (default 3, the thesis's design)")
    p.add_argument("--sim", choices=("ghdl", "icarus", "verilator"), default=None,
                   help="simulator: ghdl (the VHDL; default, or $SIM), icarus or verilator (MyHDL's Verilog)")
    add_build_dir(p)
    p.set_defaults(func=cmd_harris)


def _per_block(vals: list[float], n: int, name: str) -> list[int]:
    from eyestereo.tools.models.harris_mono import threshold_code

    if len(vals) == 1:
        vals = vals * n
    if len(vals) != n:
        raise ValueError(f"{name} has {len(vals)} values; --blocks gives {n} blocks (one value, or one per block)")
    return [threshold_code(v) for v in vals]


def _overlay(img: np.ndarray, pts: list) -> np.ndarray:
    import cv2

    out = cv2.cvtColor(img.astype(np.uint8), cv2.COLOR_GRAY2BGR)
    for x, y in pts:
        cv2.circle(out, (int(x), int(y)), 3, (0, 0, 255), 1, lineType=cv2.LINE_AA)
    return out


def cmd_harris(args: argparse.Namespace) -> int:
    import cv2

    from eyestereo.sim.apps.cli_rectify import read_pair
    from eyestereo.sim.apps.job import check_build_dir, run_folder
    from eyestereo.sim.lib.runner import check_simulator, describe
    from eyestereo.tools.models.border import interior_mask
    from eyestereo.tools.models.harris_mono import features, k_code, radius

    # every input checked before anything is built
    left, right = read_pair(args.left, args.right)
    h, w = left.shape
    r = radius(args.nms)
    if min(w, h) < max(5, 2 * r + 1) or max(w, h) > FRAME_MAX:
        raise ValueError(f"the images are {w}x{h}: harris_stereo takes {2 * r + 1}..{FRAME_MAX} pixels a side "
                         f"(nms {args.nms})")
    bx, by = args.blocks
    if bx > w or by > h:
        raise ValueError(f"--blocks {bx}x{by} is more than the image's {w}x{h} pixels")
    n = bx * by
    k = [k_code(args.k if args.k_left is None else args.k_left),
         k_code(args.k if args.k_right is None else args.k_right)]
    thr = [_per_block(args.threshold if args.threshold_left is None else args.threshold_left, n, "--threshold-left"
                      if args.threshold_left is not None else "--threshold"),
           _per_block(args.threshold if args.threshold_right is None else args.threshold_right, n, "--threshold-right"
                      if args.threshold_right is not None else "--threshold")]
    sim = check_simulator(args.sim)
    check_build_dir(args.build_dir)
    what = describe(sim)
    with Outputs() as out:
        folder = out.folder(args.output, PICTURES, inputs=[args.left, args.right])
        with run_folder("sim-harris", args.build_dir) as work:
            flags = _simulate(left, right, k, thr, blocks=(bx, by), nms=args.nms, share=args.share, sim=sim,
                              work=work, what=what)
        mask = interior_mask(h, w, r)
        pts = {side: features(flags[i], mask).tolist() for i, side in enumerate(("left", "right"))}
        (folder / "corners.json").write_text(json.dumps(pts) + "\n")
        for side, img in (("left", left), ("right", right)):
            if not cv2.imwrite(str(folder / f"{side}.png"), _overlay(img, pts[side])):
                raise ValueError(f"cannot write {side}.png")
    print(f"corners: {len(pts['left'])} left, {len(pts['right'])} right ({w}x{h}, k codes {k[0]}/{k[1]}, "
          f"{bx}x{by} blocks, nms {args.nms}, share {args.share}; harris_stereo, {what})")
    print(f"-> {args.output / 'corners.json'}, left.png, right.png")
    return 0


def _simulate(left, right, k, thr, *, blocks, nms, share, sim, work: Path, what: str) -> np.ndarray:
    """(2, H, W) flags of the pair from the generated HDL, built and run in ``work`` by a child process
    (:func:`eyestereo.sim.apps.job.run_job`: a signal stops it at once)."""
    from eyestereo.sim.apps.job import file_progress, run_job

    h, w = left.shape
    np.save(work / "pair.npy", np.stack([left, right]).astype(np.int64))
    prog = work / "progress"
    prog.write_text("0")
    cfg = dict(input=str(work / "pair.npy"), output=str(work / "flags.npy"), progress=str(prog), k=k,
               thresholds=thr)
    total = 2 * w * h
    with progress_bar(total, f"harris_stereo ({sim})") as bar:
        run_job("eyestereo.sim.lib.runner:run_bench",
                dict(block="harris_stereo", bench="tb_harris_cli", config=cfg, name="run", build_root=work / "build",
                     log_file=work / "sim.log", sim=sim,
                     params=dict(width=w, height=h, blocks=list(blocks), nms=nms, share=share)),
                work, progress=file_progress(prog, bar, total), what=f"the simulation ({what})")
    return np.load(work / "flags.npy")
