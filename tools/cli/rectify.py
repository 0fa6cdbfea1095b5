"""The Rectification Toolbox commands: ``calibrate``, ``maps``, ``fit``, ``warp``, ``lut``, ``rig``, ``rectifier``.

::

    eyestereo calibrate 'left*.jpg' 'right*.jpg' --board 9x6 --square 0.025 -o calib.yml
    eyestereo maps calib.yml -o maps.npz [--method thesis|opencv] [--size WxH] [--focal mean|min]
    eyestereo fit maps.npz -o poly.json [--degree 3] [--plots DIR]
    eyestereo warp IMAGE maps.npz|poly.json --side left|right -o OUT.png
    eyestereo lut maps.npz -o lut.h [--frac-bits 5]
    eyestereo rig -o DIR [--views 10] [--seed 0] [--layout random|cover]
    eyestereo rectifier calib.yml -o OUTDIR [--degree 3] [--max-error 0.01] [--size WxH] ...

Outputs, errors and exit codes: :mod:`eyestereo.tools.cli.common` and :mod:`eyestereo.tools.io`
(every output is checked before the work starts and written all or nothing; a folder output is
created, or replaced as a whole when it holds only this command's files).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from eyestereo.tools.cli.common import board, count, integer, nonneg_bits, positive, print_note, size, square
from eyestereo.tools.io import Outputs

__all__ = ["register"]


# --------------------------------------------------------------------------------------------------
# Handlers


def cmd_calibrate(args: argparse.Namespace) -> int:
    from eyestereo.tools.rectify.calib import calibrate_stereo, write_yaml

    with Outputs() as out:
        tmp = out.file(args.output)
        skipped: list[str] = []  # reported only on success: a failure is one line
        calib = calibrate_stereo(args.left, args.right, board=args.board, square=args.square,
                                 refine=not args.fix_intrinsics, log=skipped.append)
        write_yaml(calib, tmp)
    for line in skipped + calib.info.get("notes", []):
        print_note(line)
    used, n_skipped = len(calib.info["used"]), len(calib.info["skipped"])
    print(f"calibrated from {used} of {used + n_skipped} pairs: RMS {calib.rms:.4f} px "
          f"(left {calib.info['rms_left']:.4f}, right {calib.info['rms_right']:.4f}), "
          f"baseline {calib.baseline:.6g} -> {args.output}")
    return 0


def read_calibration(path: Any):
    """A calibration file, checked as :func:`eyestereo.tools.rectify.judge.judge_calibration` does for a file."""
    from eyestereo.tools.rectify.calib import read_yaml
    from eyestereo.tools.rectify.judge import judge_calibration

    cal = read_yaml(path)
    judge_calibration(cal, where=str(path), allow_swapped=True)
    return cal


def cmd_maps(args: argparse.Namespace) -> int:
    from eyestereo.tools.rectify.maps import compute_maps, save_maps

    if args.method == "opencv" and args.focal != "mean":
        raise ValueError("--focal min is only available with --method thesis")
    with Outputs() as out:
        tmp = out.file(args.output)
        calib = read_calibration(args.calib)
        maps = compute_maps(calib, method=args.method, size=args.size, focal=args.focal)
        save_maps(maps, tmp)
    print(f"{args.method} maps {maps.width}x{maps.height}, f = {maps.K[0, 0]:.3f} px, "
          f"principal point ({maps.K[0, 2]:.3f}, {maps.K[1, 2]:.3f}) -> {args.output}")
    return 0


def _format_report(report: dict, degree: int) -> str:
    rows = [("none", report["none"]["both"]), (f"degree {degree}", report["fit"]["both"])]
    head = (f"{'both sides':<10} {'max x':>8} {'max y':>8} {'max r':>8} {'mean x':>8} {'mean y':>8} {'mean r':>8} "
            f"{'var x':>8} {'var y':>8} {'var r':>8}")
    lines = [head]
    for name, s in rows:
        vals = [s[k][c] for k in ("max", "mean", "var") for c in ("x", "y", "r")]
        lines.append(f"{name:<10} " + " ".join(f"{v:8.3f}" for v in vals))
    return "\n".join(lines)


def cmd_fit(args: argparse.Namespace) -> int:
    from eyestereo.tools.rectify.maps import load_maps
    from eyestereo.tools.rectify.polyfit import fit, plot_errors, write_poly_json
    from eyestereo.tools.rectify.run import PLOT_FILES

    with Outputs() as out:
        tmp = out.file(args.output)
        plots = None if args.plots is None else out.folder(args.plots, PLOT_FILES)
        maps = load_maps(args.maps)
        result = fit(maps, args.degree)
        write_poly_json(result, tmp)
        written = [] if plots is None else plot_errors(maps, result, plots)
    print(_format_report(result.report, args.degree))
    print(f"degree-{args.degree} polynomials -> {args.output}")
    if written:
        print(f"{len(written)} error plots -> {args.plots}/")
    return 0


def load_any_maps(path: str):
    """A maps.npz or a poly.json (told apart by content), as :class:`~eyestereo.tools.rectify.maps.Maps`."""
    from eyestereo.tools.rectify.maps import load_maps
    from eyestereo.tools.rectify.warp import maps_from_poly

    p = Path(path)
    if not p.is_file():
        raise ValueError(f"maps file {p} does not exist")
    with open(p, "rb") as fh:
        head = fh.read(4)
    if head.startswith(b"PK"):
        return load_maps(p)
    if p.suffix.lower() == ".npz":
        raise ValueError(f"{p} is not a readable .npz maps file")
    try:
        return maps_from_poly(p)
    except ValueError as e:  # e.g. polynomials that overflow to inf: name the file
        text = str(e)
        raise ValueError(text if str(p) in text else f"{p}: {text}") from None


#: Image formats ``warp`` writes, by suffix, and the pixel depths each can hold.
WARP_FORMATS = {".png": ("uint8", "uint16"), ".tif": ("uint8", "uint16"), ".tiff": ("uint8", "uint16"),
                ".pgm": ("uint8", "uint16"), ".ppm": ("uint8", "uint16"), ".bmp": ("uint8",),
                ".jpg": ("uint8",), ".jpeg": ("uint8",)}


def cmd_warp(args: argparse.Namespace) -> int:
    import cv2

    from eyestereo.tools.io import read_image
    from eyestereo.tools.rectify.warp import warp_side

    ext = Path(args.output).suffix.lower()
    with Outputs() as out:
        tmp = out.file(args.output)
        if ext not in WARP_FORMATS:
            raise ValueError(f"cannot write an image of type {ext or '(none)'!r}; use one of "
                             f"{', '.join(sorted(WARP_FORMATS))}")
        img = read_image(args.image)
        if img.dtype.name not in ("uint8", "uint16"):
            kind = "floating-point" if img.dtype.kind == "f" else img.dtype.name
            raise ValueError(f"image {args.image} holds {kind} pixels; warp takes 8- or 16-bit images (save it as "
                             "an 8- or 16-bit PNG)")
        if img.dtype.name not in WARP_FORMATS[ext]:
            raise ValueError(f"image {args.image} is 16-bit, which {ext} cannot hold; write .png or .tiff")
        maps = load_any_maps(args.maps)
        rect = warp_side(img, maps, args.side)
        ok, buf = cv2.imencode(ext, rect)
        if not ok:
            raise ValueError(f"cannot encode the rectified image as {ext}")
        tmp.write_bytes(buf.tobytes())
    depth = "16-bit" if img.dtype.name == "uint16" else "8-bit"
    print(f"{args.side} image {img.shape[1]}x{img.shape[0]} ({depth}) rectified to {rect.shape[1]}x{rect.shape[0]} "
          f"-> {args.output}")
    return 0


def c_prefix(text: str) -> str:
    """A C name prefix for ``lut`` (:func:`eyestereo.tools.rectify.lut.check_prefix`), as an argparse type."""
    from eyestereo.tools.rectify.lut import check_prefix

    try:
        return check_prefix(text)
    except ValueError as e:
        raise argparse.ArgumentTypeError(str(e)) from None


def cmd_lut(args: argparse.Namespace) -> int:
    from eyestereo.tools.rectify.lut import create_c_lut

    with Outputs() as out:
        tmp = out.file(args.output)
        maps = load_any_maps(args.maps)
        create_c_lut(maps, tmp, frac_bits=args.frac_bits, prefix=args.prefix, guard=Path(args.output).name)
    print(f"C look-up tables {maps.width}x{maps.height}, {args.frac_bits} fraction bits -> {args.output}")
    return 0


def cmd_rig(args: argparse.Namespace) -> int:
    from eyestereo.tools.rectify.rig import write_rig

    written = write_rig(Path(args.output), n=args.views, seed=args.seed, layout=args.layout)
    print(f"{args.views} synthetic stereo views ({args.layout} layout) and the true calibration "
          f"rig_calib.yml -> {args.output}/ ({len(written)} files)")
    return 0


def cmd_rectifier(args: argparse.Namespace) -> int:
    from eyestereo.tools.rectify.run import run_all

    res = run_all(args.calib, args.output, degree=args.degree, max_error=args.max_error, measure=args.measure,
                  size=args.size, method=args.method, focal=args.focal, low=args.low, high=args.high)
    ffc = res["ffc"]
    print(f"rectified {res['width']}x{res['height']}, degree {res['degree']}: mean residual "
          f"{res['table']['fit']['both']['mean']['r']:.4f} px, max {res['table']['fit']['both']['max']['r']:.4f} px")
    if ffc is None:
        print_note(f"no FFC and no VHDL package: they need degree 3 (this run: degree {res['degree']})")
    else:
        errs = ", ".join(f"{n} {e:.3g}" for n, e in ffc.merged_errors.items())
        print(f"fixed point: {ffc.total_bits} bits in 26 quantizers; {ffc.measure.name} ({ffc.measure.unit}) "
              f"{errs} <= {ffc.max_error:g}")
        for w in ffc.wide_inputs:
            print(f"note: {w} (costs a second MULT18X18)")
    print(f"{len(res['files'])} files in {res['timings']['total']:.1f} s -> {res['outdir']}/ (see report.txt)")
    return 0


# --------------------------------------------------------------------------------------------------
# Parsers


def register(sub: Any) -> None:
    """Add the toolbox commands to an ``argparse`` sub-parsers object."""
    p = sub.add_parser("calibrate", help="stereo calibration from chessboard image pairs -> calib.yml",
                       description="Stereo calibration from chessboard image pairs. The result is judged before it "
                       "is written: coinciding, stacked or swapped cameras, a lens model that folds back inside "
                       "the image, or a poorly conditioned estimate are refused with what to do.")
    p.add_argument("left", metavar="LEFT_GLOB", help="left images, e.g. 'left*.jpg' (quote it)")
    p.add_argument("right", metavar="RIGHT_GLOB", help="right images, paired with the left ones in sorted order")
    p.add_argument("--board", type=board, default=(9, 6), help="inner corners COLSxROWS (default 9x6)")
    p.add_argument("--square", type=square, default=0.025, help="square size, the unit of T (default 0.025)")
    p.add_argument("--fix-intrinsics", action="store_true",
                   help="keep the per-camera intrinsics in the stereo step (default: refine them jointly)")
    p.add_argument("-o", "--output", required=True, help="calibration file to write (.yml)")
    p.set_defaults(func=cmd_calibrate, usage_hint="quote the globs, e.g. 'left*.jpg', so the shell does not "
                   "expand them")

    p = sub.add_parser("maps", help="backward rectification maps from a calibration -> maps.npz")
    p.add_argument("calib", metavar="CALIB", help="calibration file (.yml)")
    p.add_argument("--method", choices=("thesis", "opencv"), default="thesis",
                   help="numpy construction of thesis 3.4-3.5 (default) or OpenCV's stereoRectify")
    p.add_argument("--size", type=size, default=None, help="rectified image size WxH (default: calibrated size)")
    p.add_argument("--focal", choices=("mean", "min"), default="mean",
                   help="common focal length: mean (default) or min of the vertical focal lengths")
    p.add_argument("-o", "--output", required=True, help="maps file to write (.npz)")
    p.set_defaults(func=cmd_maps)

    p = sub.add_parser("fit", help="regression polynomials of the maps (thesis eq. 4.1) -> poly.json")
    p.add_argument("maps", metavar="MAPS", help="maps file (.npz)")
    p.add_argument("--degree", type=int, choices=(2, 3, 4), default=3, help="polynomial degree (default 3)")
    p.add_argument("--plots", metavar="DIR", default=None,
                   help="also write the four error plots (PNG) into DIR (created; an existing DIR may hold only "
                        "earlier plots)")
    p.add_argument("-o", "--output", required=True, help="polynomial file to write (.json)")
    p.set_defaults(func=cmd_fit)

    p = sub.add_parser("warp", help="rectify an image by maps or polynomials")
    p.add_argument("image", metavar="IMAGE", help="camera image (8- or 16-bit, grey or colour)")
    p.add_argument("maps", metavar="MAPS", help="maps.npz or poly.json")
    p.add_argument("--side", choices=("left", "right"), required=True, help="which camera the image is from")
    p.add_argument("-o", "--output", required=True,
                   help="rectified image to write (.png, .tif, .pgm, .ppm: same depth as IMAGE; .bmp, .jpg: 8-bit)")
    p.set_defaults(func=cmd_warp)

    p = sub.add_parser("lut", help="the backward look-up tables as a C header")
    p.add_argument("maps", metavar="MAPS", help="maps.npz or poly.json")
    p.add_argument("--frac-bits", type=int, choices=range(0, 15), default=5, metavar="0..14",
                   help="fraction bits of the int16 codes (default 5)")
    p.add_argument("--prefix", type=c_prefix, default="eyestereo_lut",
                   help="C name prefix: a C identifier, no keyword, not starting with _ (default eyestereo_lut)")
    p.add_argument("-o", "--output", required=True, help="header to write (.h)")
    p.set_defaults(func=cmd_lut)

    p = sub.add_parser("rig", help="synthetic EyeBot-like rig: rendered chessboard pairs + true calibration")
    p.add_argument("--views", type=count, default=10, help="number of stereo views (default 10)")
    p.add_argument("--seed", type=integer(0, 2**32 - 1, "--seed"), default=0,
                   help="random seed of the board poses, 0..2^32-1 (default 0)")
    p.add_argument("--layout", choices=("random", "cover"), default="random",
                   help="board poses: random, near the image centre (default), or cover, spread over the "
                        "whole field of view (use about 27 views)")
    p.add_argument("-o", "--output", required=True,
                   help="folder to write (created; its parent must exist; an existing one may hold only an "
                        "earlier rig's files and is replaced as a whole)")
    p.set_defaults(func=cmd_rig)

    p = sub.add_parser("rectifier", help="the whole toolbox: calib.yml -> maps, polynomials, plots, "
                       "quantizers, VHDL package and report in one folder",
                       description="The thesis's run_all: calib.yml -> OUTDIR/maps.npz, poly.json, plots/, "
                       "quantizers.json, stereo_calibration_pkg.vhd, report.txt. OUTDIR is written only "
                       "when every step succeeded (it must be new, empty, or an earlier run's output).")
    p.add_argument("calib", metavar="CALIB", help="calibration file (.yml)")
    p.add_argument("--degree", type=int, choices=(2, 3, 4), default=3,
                   help="polynomial degree (default 3; the FFC and the VHDL package need 3)")
    p.add_argument("--max-error", type=positive, default=0.01,
                   help="FFC error bound per polynomial (mse: px^2, max: px; default 0.01)")
    p.add_argument("--measure", choices=("mse", "max"), default="mse",
                   help="mse: mean square difference fixed vs float; max: largest absolute difference")
    p.add_argument("--size", type=size, default=None,
                   help="rectified image size WxH (default: the calibrated size)")
    p.add_argument("--method", choices=("thesis", "opencv"), default="thesis",
                   help="maps construction (default thesis)")
    p.add_argument("--focal", choices=("mean", "min"), default="mean", help="common focal length (default mean)")
    p.add_argument("--low", type=nonneg_bits, default=0, help="FFC: lowest common extra precision L (default 0)")
    p.add_argument("--high", type=nonneg_bits, default=32, help="FFC: highest common extra precision H (default 32)")
    p.add_argument("-o", "--output", required=True, metavar="OUTDIR",
                   help="output folder (its parent must exist)")
    p.set_defaults(func=cmd_rectifier)
