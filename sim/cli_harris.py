"""``eyestereo sim harris``: the stereo Harris VHDL in GHDL on an image pair (added by ``eyestereo.sim.cli``).

``eyestereo sim harris LEFT RIGHT -o OUT``: the generated ``harris_stereo`` VHDL in GHDL on a stereo pair
of grey images of any size (5..4096 pixels a side); writes ``OUT/corners.json``
(``{"left": [[x, y], ...], "right": [...]}``: the flags outside the detector's unspecified border, raster
order) and ``OUT/left.png``, ``OUT/right.png`` (each image with its corners marked). Options: k and the
block thresholds (in :func:`eyestereo.tools.models.harris_mono.harris_float` units), globally or per
camera, per block as a comma list of BX*BY values; NMS size; share factor. Errors: one line, exit status
1 (bad input) or 2 (bad command line), nothing written (the output folder appears whole or not at all).
"""

from __future__ import annotations

import argparse
import json
import shutil
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np

from eyestereo.tools.cli.common import number
from eyestereo.tools.io import Outputs, read_image
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
    """Add ``sim harris`` to the ``sim`` group's subparsers (``eyestereo.sim.cli.register`` calls it)."""
    p = sub.add_parser("harris", help="stereo Harris corners of an image pair by the harris_stereo VHDL in GHDL",
                       description="Both images through the generated harris_stereo VHDL in GHDL (one datapath for "
                                   "the two cameras, as on the FPGA); writes corners.json and overlay PNGs.")
    p.add_argument("left", type=Path, help="left grey image (colour is converted to grey; 8-bit)")
    p.add_argument("right", type=Path, help="right grey image, the same size")
    p.add_argument("-o", "--output", type=Path, required=True,
                   help="folder for corners.json, left.png, right.png; created, or replaced when it holds only these")
    p.add_argument("--k", type=lambda t: number(t, float, 0.0, 255 / 256, "--k"), default=0.04,
                   help="Harris k for both cameras (default 0.04)")
    p.add_argument("--k-left", dest="k_left", type=lambda t: number(t, float, 0.0, 255 / 256, "--k-left"), default=None)
    p.add_argument("--k-right", dest="k_right", type=lambda t: number(t, float, 0.0, 255 / 256, "--k-right"),
                   default=None)
    p.add_argument("--threshold", type=_thresholds, default=[1e8],
                   help="cornerness threshold(s) for both cameras, harris_float units: one value for every "
                        "block, or BX*BY comma-separated values by block index by*BX+bx (default 1e8)")
    p.add_argument("--threshold-left", dest="threshold_left", type=_thresholds, default=None)
    p.add_argument("--threshold-right", dest="threshold_right", type=_thresholds, default=None)
    p.add_argument("--blocks", type=_blocks, default=(4, 4), help="threshold blocks BXxBY (default 4x4)")
    p.add_argument("--nms", type=int, choices=(1, 3, 5), default=3, help="non-maximum suppression (default 3)")
    p.add_argument("--share", type=int, choices=(1, 2, 3), default=3,
                   help="clocks the multipliers are shared over (default 3, the thesis's design)")
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

    from eyestereo.tools.models.harris_mono import features, k_code, radius
    from eyestereo.tools.models.border import interior_mask

    with Outputs() as out:
        folder = out.folder(args.output, PICTURES)
        left = read_image(args.left, what="left image", grey=True)
        right = read_image(args.right, what="right image", grey=True)
        for name, img in (("left", left), ("right", right)):
            if img.dtype != np.uint8:
                raise ValueError(f"{name} image {getattr(args, name)} is {img.dtype}, not 8-bit grey")
        if left.shape != right.shape:
            raise ValueError(f"the images differ in size: left {left.shape[1]}x{left.shape[0]}, "
                             f"right {right.shape[1]}x{right.shape[0]}")
        h, w = left.shape
        r = radius(args.nms)
        if min(w, h) < max(5, 2 * r + 1) or max(w, h) > 4096:
            raise ValueError(f"the images are {w}x{h}: harris_stereo takes {2 * r + 1}..4096 pixels a side "
                             f"(nms {args.nms})")
        bx, by = args.blocks
        if bx > w or by > h:
            raise ValueError(f"--blocks {bx}x{by} is more than the image's {w}x{h} pixels")
        n = bx * by
        k = [k_code(args.k if args.k_left is None else args.k_left), k_code(args.k if args.k_right is None else args.k_right)]
        thr = [_per_block(args.threshold if args.threshold_left is None else args.threshold_left, n, "--threshold-left"
                          if args.threshold_left is not None else "--threshold"),
               _per_block(args.threshold if args.threshold_right is None else args.threshold_right, n, "--threshold-right"
                          if args.threshold_right is not None else "--threshold")]
        if shutil.which("ghdl") is None:
            raise ValueError("ghdl not found: install it (Debian: apt-get install ghdl)")
        flags = _simulate(left, right, k, thr, blocks=(bx, by), nms=args.nms, share=args.share)
        mask = interior_mask(h, w, r)
        pts = {side: features(flags[i], mask).tolist() for i, side in enumerate(("left", "right"))}
        (folder / "corners.json").write_text(json.dumps(pts) + "\n")
        for i, (side, img) in enumerate((("left", left), ("right", right))):
            if not cv2.imwrite(str(folder / f"{side}.png"), _overlay(img, pts[side])):
                raise ValueError(f"cannot write {side}.png")
    print(f"corners: {len(pts['left'])} left, {len(pts['right'])} right ({w}x{h}, k codes {k[0]}/{k[1]}, "
          f"{bx}x{by} blocks, nms {args.nms}, share {args.share}; harris_stereo VHDL in GHDL)")
    print(f"-> {args.output / 'corners.json'}, left.png, right.png")
    return 0


def _simulate(left, right, k, thr, *, blocks, nms, share) -> np.ndarray:
    """(2, H, W) flags of the pair from the generated VHDL (a temporary build folder, removed after)."""
    from eyestereo.sim.runner import run_bench

    h, w = left.shape
    tmp = Path(tempfile.mkdtemp(prefix="eyestereo-sim-harris-"))
    try:
        np.save(tmp / "pair.npy", np.stack([left, right]).astype(np.int64))
        prog = tmp / "progress"
        prog.write_text("0")
        cfg = dict(input=str(tmp / "pair.npy"), output=str(tmp / "flags.npy"), progress=str(prog), k=k,
                   thresholds=thr)
        err: list[BaseException] = []

        def work():
            try:
                run_bench("harris_stereo", "tb_harris_cli", cfg, name="run", build_root=tmp / "build", log_file=tmp / "sim.log",
                          params=dict(width=w, height=h, blocks=blocks, nms=nms, share=share))
            except BaseException as e:  # noqa: BLE001 - reported in the main thread
                err.append(e)

        t = threading.Thread(target=work, daemon=True)
        total = 2 * w * h
        with progress_bar(total, "harris_stereo in GHDL") as bar:
            t.start()
            done = 0
            while t.is_alive():
                t.join(0.5)
                try:
                    now = int(prog.read_text() or 0)
                except (OSError, ValueError):
                    continue
                bar.update(max(0, now - done))
                done = max(done, now)
        if err:
            raise ValueError(f"the GHDL simulation failed ({type(err[0]).__name__}: "
                             f"{str(err[0]).splitlines()[0] if str(err[0]) else ''})")
        return np.load(tmp / "flags.npy")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
