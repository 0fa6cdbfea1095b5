"""``eyestereo``: the Rectification Toolbox on the command line.

::

    eyestereo calibrate 'left*.jpg' 'right*.jpg' --board 9x6 --square 0.025 -o calib.yml
    eyestereo maps calib.yml -o maps.npz [--method thesis|opencv] [--size WxH] [--focal mean|min]
    eyestereo fit maps.npz -o poly.json [--degree 3] [--plots DIR]
    eyestereo warp IMAGE maps.npz|poly.json --side left|right -o OUT.png
    eyestereo lut maps.npz -o lut.h [--frac-bits 5]
    eyestereo rig -o DIR [--views 10] [--seed 0] [--layout random|cover]
    eyestereo rectifier calib.yml -o OUTDIR [--degree 3] [--max-error 0.01] [--size WxH] ...

Every failure ends with one line ``eyestereo: error: ...`` on stderr and exit status 2 (bad command
line) or 1 (anything found at run time: missing or corrupt files, no chessboard, wrong sizes); outputs
are written atomically, so a failed command leaves no partial file behind. Subcommands of the
float-to-fixed conversion are added by ``eyestereo.tools.cli.ffc``, ``evaluate`` and ``sweep`` by
``eyestereo.tools.cli.matching``.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import NoReturn

__all__ = ["main", "build_parser"]

PROG = "eyestereo"


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors: ``eyestereo: error: ...`` and exit status 2."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{PROG}: error: {' '.join(message.split())}\n")


def _board(text: str) -> tuple[int, int]:
    from eyestereo.tools.rectify.calib import parse_board

    try:
        return parse_board(text)
    except ValueError as e:
        raise argparse.ArgumentTypeError(str(e)) from None


def _size(text: str) -> tuple[int, int]:
    import re

    m = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", text)
    if m is None or not (1 <= int(m.group(1)) <= 16384 and 1 <= int(m.group(2)) <= 16384):
        raise argparse.ArgumentTypeError(f"size must be WxH with 1..16384 pixels per side, e.g. 352x288; got {text!r}")
    return int(m.group(1)), int(m.group(2))


def _positive(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not v > 0 or v == float("inf"):
        raise argparse.ArgumentTypeError(f"must be a positive number, got {text!r}")
    return v


def _count(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None
    if not 1 <= v <= 99:
        raise argparse.ArgumentTypeError(f"must be 1..99, got {v}")
    return v


def _err(text: str) -> None:
    print(f"{PROG}: {text}", file=sys.stderr)


# --------------------------------------------------------------------------------------------------
# Commands


def _cmd_calibrate(args: argparse.Namespace) -> int:
    from eyestereo.tools.rectify.calib import calibrate_stereo, write_yaml

    skipped: list[str] = []  # reported only on success: a failure is one line
    calib = calibrate_stereo(args.left, args.right, board=args.board, square=args.square,
                             refine=not args.fix_intrinsics, log=skipped.append)
    write_yaml(calib, args.output)
    for line in skipped:
        _err(f"note: {line}")
    used, skipped = len(calib.info["used"]), len(calib.info["skipped"])
    print(f"calibrated from {used} of {used + skipped} pairs: RMS {calib.rms:.4f} px "
          f"(left {calib.info['rms_left']:.4f}, right {calib.info['rms_right']:.4f}), "
          f"baseline {calib.baseline:.6g} -> {args.output}")
    return 0


def _cmd_maps(args: argparse.Namespace) -> int:
    from eyestereo.tools.rectify.calib import read_yaml
    from eyestereo.tools.rectify.maps import compute_maps, save_maps

    calib = read_yaml(args.calib)
    if args.method == "opencv" and args.focal != "mean":
        raise ValueError("--focal min is only available with --method thesis")
    maps = compute_maps(calib, method=args.method, size=args.size, focal=args.focal)
    save_maps(maps, args.output)
    print(f"{args.method} maps {maps.width}x{maps.height}, f = {maps.K[0, 0]:.3f} px, "
          f"principal point ({maps.K[0, 2]:.3f}, {maps.K[1, 2]:.3f}) -> {args.output}")
    return 0


def _format_report(report: dict, degree: int) -> str:
    rows = [("none", report["none"]["both"]), (f"degree {degree}", report["fit"]["both"])]
    head = f"{'both sides':<10} {'max x':>8} {'max y':>8} {'max r':>8} {'mean x':>8} {'mean y':>8} {'mean r':>8} {'var x':>8} {'var y':>8} {'var r':>8}"
    lines = [head]
    for name, s in rows:
        vals = [s[k][c] for k in ("max", "mean", "var") for c in ("x", "y", "r")]
        lines.append(f"{name:<10} " + " ".join(f"{v:8.3f}" for v in vals))
    return "\n".join(lines)


def _cmd_fit(args: argparse.Namespace) -> int:
    from eyestereo.tools.rectify.polyfit import fit, plot_errors, write_poly_json
    from eyestereo.tools.rectify.maps import load_maps

    maps = load_maps(args.maps)
    if args.plots is not None and not Path(args.plots).is_dir():
        raise ValueError(f"plot folder {args.plots} does not exist")
    result = fit(maps, args.degree)
    write_poly_json(result, args.output)
    print(_format_report(result.report, args.degree))
    print(f"degree-{args.degree} polynomials -> {args.output}")
    if args.plots is not None:
        for p in plot_errors(maps, result, args.plots):
            print(f"plot -> {p}")
    return 0


def _load_any_maps(path: str):
    from eyestereo.tools.rectify.warp import maps_from_poly
    from eyestereo.tools.rectify.maps import load_maps

    p = Path(path)
    if not p.is_file():
        raise ValueError(f"maps file {p} does not exist")
    with open(p, "rb") as fh:
        head = fh.read(4)
    if head.startswith(b"PK"):
        return load_maps(p)
    if p.suffix.lower() == ".npz":
        raise ValueError(f"{p} is not a readable .npz maps file")
    return maps_from_poly(p)


def _cmd_warp(args: argparse.Namespace) -> int:
    import cv2

    from eyestereo.tools.rectify.calib import atomic_write_bytes
    from eyestereo.tools.rectify.warp import warp_side

    if not Path(args.image).is_file():
        raise ValueError(f"image {args.image} does not exist")
    img = cv2.imread(args.image, cv2.IMREAD_UNCHANGED)
    if img is None:
        raise ValueError(f"cannot read image {args.image} (not an image file?)")
    maps = _load_any_maps(args.maps)
    out = warp_side(img, maps, args.side)
    ext = Path(args.output).suffix or ".png"
    try:
        ok, buf = cv2.imencode(ext, out)
    except cv2.error:
        ok = False
    if not ok:
        raise ValueError(f"cannot write an image of type {ext!r}; use e.g. .png")
    atomic_write_bytes(args.output, buf.tobytes())
    print(f"{args.side} image {img.shape[1]}x{img.shape[0]} rectified to {out.shape[1]}x{out.shape[0]} -> {args.output}")
    return 0


def _cmd_lut(args: argparse.Namespace) -> int:
    from eyestereo.tools.rectify.lut import create_c_lut

    maps = _load_any_maps(args.maps)
    create_c_lut(maps, args.output, frac_bits=args.frac_bits, prefix=args.prefix)
    print(f"C look-up tables {maps.width}x{maps.height}, {args.frac_bits} fraction bits -> {args.output}")
    return 0


def _cmd_rig(args: argparse.Namespace) -> int:
    from eyestereo.tools.rectify.rig import write_rig

    out = Path(args.output)
    written = write_rig(out, n=args.views, seed=args.seed, layout=args.layout)
    print(f"{args.views} synthetic stereo views ({args.layout} layout) and the true calibration "
          f"rig_calib.yml -> {out}/ ({len(written)} files)")
    return 0


def _cmd_rectifier(args: argparse.Namespace) -> int:
    from eyestereo.tools.rectify.run import run_all

    res = run_all(args.calib, args.output, degree=args.degree, max_error=args.max_error, measure=args.measure,
                  size=args.size, method=args.method, focal=args.focal, low=args.low, high=args.high)
    ffc = res["ffc"]
    print(f"rectified {res['width']}x{res['height']}, degree {res['degree']}: mean residual "
          f"{res['table']['fit']['both']['mean']['r']:.4f} px, max {res['table']['fit']['both']['max']['r']:.4f} px")
    if ffc is None:
        _err(f"note: no FFC and no VHDL package: they need degree 3 (this run: degree {res['degree']})")
    else:
        errs = ", ".join(f"{n} {e:.3g}" for n, e in ffc.merged_errors.items())
        print(f"fixed point: {ffc.total_bits} bits in 26 quantizers; {ffc.measure.name} ({ffc.measure.unit}) "
              f"{errs} <= {ffc.max_error:g}")
        for w in ffc.wide_inputs:
            print(f"note: {w} (costs a second MULT18X18)")
    print(f"{len(res['files'])} files in {res['timings']['total']:.1f} s -> {res['outdir']}/ (see report.txt)")
    return 0


def _nonneg(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None
    if not 0 <= v <= 62:
        raise argparse.ArgumentTypeError(f"must be 0..62, got {v}")
    return v


# --------------------------------------------------------------------------------------------------
# Parser


def build_parser() -> argparse.ArgumentParser:
    """The full argument parser."""
    parser = _Parser(prog=PROG, description="eyestereo's software side: the rectification toolbox (stereo "
                     "calibration, maps, regression polynomials, float-to-fixed conversion, VHDL package, "
                     "warping; thesis 2-4 and Appendix A) and the feature-matching evaluation (thesis 7.3).")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)

    p = sub.add_parser("calibrate", help="stereo calibration from chessboard image pairs -> calib.yml")
    p.add_argument("left", metavar="LEFT_GLOB", help="left images, e.g. 'left*.jpg' (quote it)")
    p.add_argument("right", metavar="RIGHT_GLOB", help="right images, paired with the left ones in sorted order")
    p.add_argument("--board", type=_board, default=(9, 6), help="inner corners COLSxROWS (default 9x6)")
    p.add_argument("--square", type=_positive, default=0.025, help="square size, the unit of T (default 0.025)")
    p.add_argument("--fix-intrinsics", action="store_true",
                   help="keep the per-camera intrinsics in the stereo step (default: refine them jointly)")
    p.add_argument("-o", "--output", required=True, help="calibration file to write (.yml)")
    p.set_defaults(func=_cmd_calibrate)

    p = sub.add_parser("maps", help="backward rectification maps from a calibration -> maps.npz")
    p.add_argument("calib", metavar="CALIB", help="calibration file (.yml)")
    p.add_argument("--method", choices=("thesis", "opencv"), default="thesis",
                   help="numpy construction of thesis 3.4-3.5 (default) or OpenCV's stereoRectify")
    p.add_argument("--size", type=_size, default=None, help="rectified image size WxH (default: calibrated size)")
    p.add_argument("--focal", choices=("mean", "min"), default="mean",
                   help="common focal length: mean (default) or min of the vertical focal lengths")
    p.add_argument("-o", "--output", required=True, help="maps file to write (.npz)")
    p.set_defaults(func=_cmd_maps)

    p = sub.add_parser("fit", help="regression polynomials of the maps (thesis eq. 4.1) -> poly.json")
    p.add_argument("maps", metavar="MAPS", help="maps file (.npz)")
    p.add_argument("--degree", type=int, choices=(2, 3, 4), default=3, help="polynomial degree (default 3)")
    p.add_argument("--plots", metavar="DIR", default=None, help="also write error plots (PNG) into DIR")
    p.add_argument("-o", "--output", required=True, help="polynomial file to write (.json)")
    p.set_defaults(func=_cmd_fit)

    p = sub.add_parser("warp", help="rectify an image by maps or polynomials")
    p.add_argument("image", metavar="IMAGE", help="camera image")
    p.add_argument("maps", metavar="MAPS", help="maps.npz or poly.json")
    p.add_argument("--side", choices=("left", "right"), required=True, help="which camera the image is from")
    p.add_argument("-o", "--output", required=True, help="rectified image to write (.png)")
    p.set_defaults(func=_cmd_warp)

    p = sub.add_parser("lut", help="the backward look-up tables as a C header")
    p.add_argument("maps", metavar="MAPS", help="maps.npz or poly.json")
    p.add_argument("--frac-bits", type=int, choices=range(0, 15), default=5, metavar="0..14",
                   help="fraction bits of the int16 codes (default 5)")
    p.add_argument("--prefix", default="eyestereo_lut", help="C name prefix (default eyestereo_lut)")
    p.add_argument("-o", "--output", required=True, help="header to write (.h)")
    p.set_defaults(func=_cmd_lut)

    p = sub.add_parser("rig", help="synthetic EyeBot-like rig: rendered chessboard pairs + true calibration")
    p.add_argument("--views", type=_count, default=10, help="number of stereo views (default 10)")
    p.add_argument("--seed", type=int, default=0, help="random seed of the board poses (default 0)")
    p.add_argument("--layout", choices=("random", "cover"), default="random",
                   help="board poses: random, near the image centre (default), or cover, spread over the "
                        "whole field of view (use about 27 views)")
    p.add_argument("-o", "--output", required=True, help="folder to write into (created if missing; its parent must exist)")
    p.set_defaults(func=_cmd_rig)

    p = sub.add_parser("rectifier", help="the whole toolbox: calib.yml -> maps, polynomials, plots, "
                       "quantizers, VHDL package and report in one folder",
                       description="The thesis's run_all: calib.yml -> OUTDIR/maps.npz, poly.json, plots/, "
                       "quantizers.json, stereo_calibration_pkg.vhd, report.txt. OUTDIR is written only "
                       "when every step succeeded (it must be new, empty, or an earlier run's output).")
    p.add_argument("calib", metavar="CALIB", help="calibration file (.yml)")
    p.add_argument("--degree", type=int, choices=(2, 3, 4), default=3,
                   help="polynomial degree (default 3; the FFC and the VHDL package need 3)")
    p.add_argument("--max-error", type=_positive, default=0.01,
                   help="FFC error bound per polynomial (mse: px^2, max: px; default 0.01)")
    p.add_argument("--measure", choices=("mse", "max"), default="mse",
                   help="mse: mean square difference fixed vs float; max: largest absolute difference")
    p.add_argument("--size", type=_size, default=None,
                   help="rectified image size WxH (default: the calibrated size)")
    p.add_argument("--method", choices=("thesis", "opencv"), default="thesis", help="maps construction (default thesis)")
    p.add_argument("--focal", choices=("mean", "min"), default="mean", help="common focal length (default mean)")
    p.add_argument("--low", type=_nonneg, default=0, help="FFC: lowest common extra precision L (default 0)")
    p.add_argument("--high", type=_nonneg, default=32, help="FFC: highest common extra precision H (default 32)")
    p.add_argument("-o", "--output", required=True, metavar="OUTDIR",
                   help="output folder (its parent must exist)")
    p.set_defaults(func=_cmd_rectifier)

    # The float-to-fixed conversion (ffc, package) and the matching study (evaluate, sweep) live in
    # their own modules.
    from eyestereo.tools.cli import matching as cli_eval, ffc as cli_ffc

    cli_ffc.register(sub)
    cli_eval.register(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status (0 ok, 1 run-time error, 2 usage error)."""
    try:
        parser = build_parser()
        args = parser.parse_args(argv)
    except SystemExit as e:  # --help or a usage error (already reported in one line)
        return e.code if isinstance(e.code, int) else (0 if e.code is None else 2)
    try:
        return int(args.func(args))
    except KeyboardInterrupt:
        print(f"{PROG}: error: interrupted", file=sys.stderr)
        return 130
    except SystemExit as e:  # a subcommand's own parser-style exit
        return e.code if isinstance(e.code, int) else 1
    except Exception as e:  # noqa: BLE001 - every failure becomes one line, never a traceback
        text = " ".join(str(e).split()) or type(e).__name__
        if not isinstance(e, (ValueError, OSError)):
            text = f"{type(e).__name__}: {text}"
        print(f"{PROG}: error: {text}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
