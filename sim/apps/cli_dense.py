"""``eyestereo sim dense``: the dense_stereo HDL (census, semi-global matching, median) in a simulator on a pair.

A command of ``eyestereo sim``, added by ``eyestereo.sim.apps.cli``.

``eyestereo sim dense LEFT RIGHT -o OUT [--gt GT [--gt-scale S]] [--disparities D] [--sim ghdl|icarus|verilator]``:
a rectified pair (any size the block takes: width D+1..4096, height 5..4096; read by the library's one image
rule, :func:`eyestereo.sim.apps.cli_rectify.read_pair`: colour to grey, 16-bit to its 8 most significant
used bits, floating point refused) through the generated ``dense_stereo`` block (5 x 5 census, 4 paths, the
3 x 3 median; :data:`~eyestereo.tools.models.dense_stereo.DEFAULTS` at run time) on its bench,
:mod:`eyestereo.sim.benches.tb_sgm`, which compares every disparity code with the bit-true model
(:func:`eyestereo.tools.models.dense_stereo.dense_stereo`): a single differing code fails the run, and
nothing is written. Writes

* ``OUT/disparity.png``: the map colour-coded on 0 .. D px (the turbo colours of
  :func:`eyestereo.tools.dense.pictures.map_indices`), black where the block found no disparity;
* ``OUT/disparity.pfm``: the map in px as Middlebury writes it (``Pf``, little-endian float32, rows bottom
  to top), +inf where there is none (Middlebury's "unknown");
* ``OUT/metrics.json``, with ``--gt`` only: :func:`eyestereo.tools.dense.metrics.scores` (bad-1/2/4 over the
  visible pixels ``_noc`` and all known ones ``_all``, density, RMS, ...) and the run: ``bit_exact``, the
  simulator, the size, D, ``clocks`` (from the first input beat to the last output beat), the ground
  truth's file and scale.

GT is the left view's ground truth as :func:`eyestereo.tools.matching.metrics.load_disparity` reads it (the
same reader as ``eyestereo evaluate``): an 8/16-bit PGM/PNG holding disparity x ``--gt-scale``, 0 = unknown,
or a PFM/.npy of float disparities (0, NaN, inf = unknown). The scale of an integer image is the scene's:
Middlebury's 2001 scenes store disparity x 8, Tsukuba x 16 (:data:`eyestereo.tools.dense.datasets.FILES`),
the 2003 ones (Cones, Teddy) x 4; the default, :data:`GT_SCALE`, is Tsukuba's, and the report names the
scale it used. A float file is taken as px (scale 1) unless ``--gt-scale`` says otherwise.

The block computes ``pu`` of the D disparities a clock (8 when D is a multiple of 8, else 4: at least two
groups a pixel), the pixels come at about 1.2 x its pixel spacing (:func:`eyestereo.hdl.dense.sgm.spacing`).
Every input is checked before the build; errors are one line, exit status 1 (bad input) or 2 (bad command
line); outputs are written all or nothing (a temporary folder next to OUT, moved into place at the end; OUT
new, empty or holding only this command's files, never a folder holding the inputs); the simulation runs
in a child process (:mod:`eyestereo.sim.apps.job`) that SIGINT/SIGTERM stop within a second or two, built
in a fresh folder under ``--build-dir``.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from eyestereo.sim.apps.cli_rectify import add_build_dir
from eyestereo.tools.constants import FRAME_MAX
from eyestereo.tools.models.dense_stereo import DEFAULTS, WIDTHS
from eyestereo.tools.models.sgm import D_RANGE

#: What the command writes into OUT (metrics.json only with --gt).
OWNED = ("disparity.png", "disparity.pfm", "metrics.json")
#: The default scale of an integer ground-truth image: Middlebury Tsukuba's disp3.pgm (disparity x 16).
GT_SCALE = 16.0
#: D must be a multiple of this: the block computes PU = 4 (or 8) disparities a clock, D / PU groups a pixel.
D_STEP = 4
#: sgm's input FIFO: the chain's own choice (None: room for census's frame tail, dense_stereo.fifo_depth).
FIFO = None
#: The bench's pixel rate: this many times the block's pixel spacing (clocks between two pixels).
RATE_MARGIN = 1.2


def disparities_arg(text: str) -> int:
    """``--disparities``: D in :data:`~eyestereo.tools.models.sgm.D_RANGE`, a multiple of :data:`D_STEP`
    (argparse type)."""
    try:
        d = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None
    lo, hi = D_RANGE
    if not lo <= d <= hi:
        raise argparse.ArgumentTypeError(f"D must lie in {lo}..{hi} (the sgm block's range), got {d}")
    if d % D_STEP:
        raise argparse.ArgumentTypeError(f"D must be a multiple of {D_STEP}: the block computes {D_STEP} "
                                         f"disparities a clock (D / {D_STEP} groups a pixel), got {d}")
    return d


def _scale_arg(text: str) -> float:
    try:
        s = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not (math.isfinite(s) and s > 0):
        raise argparse.ArgumentTypeError(f"the scale must be a number above 0, got {text}")
    return s


def add_dense(sub: Any) -> None:
    """Add ``sim dense`` to the ``sim`` group's subparsers (``eyestereo.sim.apps.cli.register`` calls it)."""
    p = sub.add_parser("dense", help="a depth map of a rectified pair by the dense_stereo HDL (census + SGM) in a "
                       "simulator, checked against its bit-true model", description=__doc__.splitlines()[0])
    p.set_defaults(func=cmd_sim_dense)
    for side, text in (("left", "rectified left image (colour is converted to grey)"),
                       ("right", "rectified right image, the same size")):
        p.add_argument(side, type=Path, help=text)
    p.add_argument("-o", "--output", type=Path, required=True,
                   help="folder for disparity.png, disparity.pfm (and metrics.json): new, empty, or holding "
                        "only these")
    p.add_argument("--gt", type=Path, default=None,
                   help="ground truth of the left view (PGM/PNG: disparity x --gt-scale, 0 = unknown; or "
                        "PFM/.npy in px): writes metrics.json")
    p.add_argument("--gt-scale", dest="gt_scale", type=_scale_arg, default=None, metavar="S",
                   help=f"GT value per px of an integer image (default {GT_SCALE:g}, Tsukuba's; Middlebury's "
                        "other 2001 scenes: 8, Cones/Teddy: 4); a PFM/.npy is in px unless given")
    p.add_argument("--disparities", "-D", type=disparities_arg, default=DEFAULTS["disparities"], metavar="D",
                   help=f"disparities searched, 0 .. D-1: {D_RANGE[0]}..{D_RANGE[1]}, a multiple of {D_STEP} "
                        f"(default {DEFAULTS['disparities']}); the images must be wider than D")
    p.add_argument("--sim", choices=("ghdl", "icarus", "verilator"), default=None,
                   help="simulator (default: the fastest here: Verilator on MyHDL's Verilog if installed, else "
                        "GHDL on the VHDL)")
    add_build_dir(p)


def pu_of(disparities: int) -> int:
    """The disparities the block computes a clock: 8 when it divides D (at least two groups: D >= 16), else 4."""
    return 8 if disparities % 8 == 0 else D_STEP


def params_of(width: int, height: int, disparities: int) -> dict:
    """The dense_stereo block's elaboration parameters for a ``width`` x ``height`` pair."""
    return dict(window=DEFAULTS["window"], disparities=disparities, pu=pu_of(disparities), paths=DEFAULTS["paths"],
                median=DEFAULTS["median"], path_bits=WIDTHS["path_bits"], sum_shift=WIDTHS["sum_shift"],
                frac_bits=WIDTHS["frac_bits"], fifo=FIFO, width=width, height=height)


def check_size(width: int, height: int, disparities: int) -> None:
    """ValueError (one line) unless the block takes a ``width`` x ``height`` pair with D ``disparities``."""
    window = DEFAULTS["window"]
    if width > FRAME_MAX or height > FRAME_MAX:
        raise ValueError(f"the images are {width}x{height}: dense_stereo takes at most {FRAME_MAX} pixels a side")
    if width <= disparities:
        raise ValueError(f"the images are {width}x{height}: their width must exceed the {disparities} disparities "
                         f"(--disparities; a pixel is matched at 0..{disparities - 1} px to its left)")
    if height < window:
        raise ValueError(f"the images are {width}x{height}: dense_stereo needs at least {window} rows (its "
                         f"{window}x{window} census window)")


def load_gt(path: Path, scale: float | None, shape: tuple[int, int]) -> tuple[np.ndarray, float]:
    """The ground truth in px (NaN unknown) of the images' ``shape`` and the scale used; ValueError (one line)."""
    from eyestereo.tools.matching.metrics import check_gt, load_disparity

    if scale is None:
        scale = 1.0 if path.suffix.lower() in (".pfm", ".npy") else GT_SCALE
    gt = check_gt(load_disparity(path, scale), shape)
    if not np.isfinite(gt).any():
        raise ValueError(f"ground truth {path} holds no known disparity (0 = unknown)")
    top = float(np.nanmax(gt))
    if top >= shape[1]:
        raise ValueError(f"ground truth {path} reaches {top:g} px at scale {scale:g}, more than the images' "
                         f"{shape[1]} px width: give its scale with --gt-scale")
    return gt, scale


def write_pfm(path: Path, disparity: np.ndarray) -> None:
    """A float map (px, NaN = none) as a Middlebury PFM: "Pf", width height, scale -1.0 (little endian),
    rows bottom to top, +inf where there is no disparity."""
    d = np.asarray(disparity, np.float32)
    h, w = d.shape
    d = np.where(np.isfinite(d), d, np.float32(np.inf)).astype("<f4")
    path.write_bytes(b"Pf\n" + f"{w} {h}\n".encode() + b"-1.0\n" + d[::-1].tobytes())


def write_picture(path: Path, disparity: np.ndarray, vmax: float) -> None:
    """The map colour-coded on 0 .. ``vmax`` px (the accuracy page's turbo palette), black where none."""
    import cv2

    from eyestereo.tools.dense.pictures import PALETTE, map_indices

    rgb = PALETTE[map_indices(disparity, vmax)]
    if not cv2.imwrite(str(path), np.ascontiguousarray(rgb[..., ::-1])):
        raise ValueError(f"cannot write {path.name}")


def _jsonable(scores: dict) -> dict:
    return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in scores.items()}


def simulate(left: np.ndarray, right: np.ndarray, work: Path, *, disparities: int, sim: str, what: str) -> tuple:
    """The codes (uint16, H x W) of the pair from the generated HDL, checked against the model by the bench,
    built and run in ``work`` by a child process; and the bench's report."""
    import cv2

    from eyestereo.hdl.dense.sgm import spacing
    from eyestereo.sim.apps.job import run_job
    from eyestereo.tools.progress import progress_bar

    h, w = left.shape
    paths = []
    for side, img in (("left", left), ("right", right)):
        paths.append(work / f"{side}.png")  # 8-bit grey: the bench reads back exactly these pixels
        if not cv2.imwrite(str(paths[-1]), img):
            raise ValueError(f"cannot write the {side} image into the run folder {work}")
    params = params_of(w, h, disparities)
    pixel_clocks = math.ceil(RATE_MARGIN * spacing(disparities, params["pu"]))
    cfg = dict(frames=[[f"image:{paths[0]}", f"image:{paths[1]}"]], pixel_clocks=pixel_clocks,
               save=str(work / "codes.npy"))
    public = ["clk", "rst", "sink_*", "source_*", "p1", "p2", "uniqueness", "lr_check", "subpixel", "overrun"]
    with progress_bar(1, f"dense_stereo {w}x{h}, D {disparities} ({sim})", unit="run") as bar:
        report = run_job("eyestereo.sim.lib.runner:run_bench",
                         dict(block="dense_stereo", bench="tb_sgm", config=cfg, name="run", params=params,
                              build_root=work / "build", log_file=work / "sim.log", sim=sim,
                              public=public if sim == "verilator" else None),
                         work, progress=bar.refresh, what=f"the simulation ({what})")
        bar.update(1)
    codes = np.load(work / "codes.npy")
    if codes.shape != (1, h, w) or report.get("pixels_compared") != w * h:
        raise ValueError(f"the simulation gave {codes.shape[1:]} codes, compared {report.get('pixels_compared')}; "
                         f"expected one {w}x{h} frame")
    return codes[0].astype(np.uint16), dict(report, pixel_clocks=pixel_clocks, **params)


def cmd_sim_dense(args: argparse.Namespace) -> int:
    from eyestereo.sim.apps.cli_rectify import read_pair
    from eyestereo.sim.apps.job import check_build_dir, run_folder
    from eyestereo.sim.lib.runner import check_simulator, describe, fastest_simulator
    from eyestereo.tools.dense.metrics import scores
    from eyestereo.tools.io import Outputs
    from eyestereo.tools.models.dense_stereo import to_float

    # every input checked before anything is built
    d = args.disparities
    left, right = read_pair(args.left, args.right)
    h, w = left.shape
    check_size(w, h, d)
    gt = scale = None
    if args.gt is not None:
        gt, scale = load_gt(args.gt, args.gt_scale, left.shape)
    elif args.gt_scale is not None:
        raise ValueError("--gt-scale is the scale of the ground truth: give it with --gt GT")
    sim = check_simulator(args.sim or fastest_simulator())
    check_build_dir(args.build_dir)
    what = describe(sim)
    inputs = [args.left, args.right] + ([args.gt] if args.gt is not None else [])
    with Outputs() as out:
        folder = out.folder(args.output, OWNED, inputs=inputs)
        print(f"dense_stereo on {w}x{h}, D {d}: building and simulating {what} ...", flush=True)
        with run_folder("sim-dense", args.build_dir) as work:
            codes, rep = simulate(left, right, work, disparities=d, sim=sim, what=what)
        disp = to_float(codes)
        write_picture(folder / "disparity.png", disp, float(d))
        write_pfm(folder / "disparity.pfm", disp)
        clocks = int(rep["last_out"] - rep["first_in"])
        run = dict(bit_exact=True, simulator=what, sim=sim, size=f"{w}x{h}", width=w, height=h, disparities=d,
                   pu=rep["pu"], paths=rep["paths"], window=rep["window"], median=rep["median"], clocks=clocks,
                   clocks_per_pixel=round(clocks / (w * h), 3), spacing=rep["spacing"],
                   pixel_clocks=rep["pixel_clocks"], valid_codes=rep["valid_codes"])
        measured = None
        if gt is not None:
            measured = _jsonable(scores(disp, gt))
            (folder / "metrics.json").write_text(json.dumps(dict(run, gt=str(args.gt), gt_scale=scale,
                                                                 **measured), indent=2) + "\n")
    print(f"dense_stereo ({rep['window']}x{rep['window']} census, {rep['paths']} paths, PU {rep['pu']}, median) on "
          f"{w}x{h}, D {d}, {what}: bit-exact against the model: yes ({w * h} codes, {rep['valid_codes']} with a "
          f"disparity)")
    print(f"  {clocks:,} clocks, {clocks / (w * h):.2f} a pixel (the block's spacing {rep['spacing']}, pixels "
          f"offered every {rep['pixel_clocks']})")
    if measured is not None:
        def pct(key: str) -> str:
            v = measured[key]
            return "n/a" if v is None else f"{v:.2f} %"

        rms = "n/a" if measured["rms"] is None else f"{measured['rms']:.3f} px"
        print(f"  against {args.gt} (scale {scale:g}), visible pixels: bad-1 {pct('bad1_noc')}, bad-2 "
              f"{pct('bad2_noc')}, bad-4 {pct('bad4_noc')}, RMS {rms}; density {pct('density')}")
        top = float(np.nanmax(gt))
        if top > d - 1:
            print(f"  note: the ground truth reaches {top:g} px, beyond the {d} disparities searched (--disparities)")
    names = ", ".join(OWNED if measured is not None else OWNED[:2])
    print(f"-> {args.output}/: {names}")
    return 0
