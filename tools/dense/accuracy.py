"""Accuracy of the dense stereo chain: ``python -m eyestereo.tools.dense.accuracy --out docs/dense.md``.

For every pair with ground truth (:mod:`eyestereo.tools.dense.datasets`), at the cameras' size
(352 x 288) and at the pair's own: the bit-true model (:func:`eyestereo.tools.models.dense_stereo.dense_stereo`
with its defaults), the float reference (:func:`eyestereo.tools.dense.reference.reference`), OpenCV's
StereoSGBM and StereoBM, all with the same disparity range, scored by
:func:`eyestereo.tools.dense.metrics.scores`. Then the table of the fixed-point cuts: each width of the
model cut alone, bad-2 (noc) on every pair at 352 x 288; that table is how the default widths were chosen.

Writes the section between ``<!-- dense_accuracy: begin -->`` and ``<!-- dense_accuracy: end -->`` of the
page ``--out`` (it must hold the markers); without ``--out`` it prints only. ``--pictures DIR`` instead
writes one picture per pair of ``--pairs`` at 352 x 288 into ``DIR`` (:func:`write_pictures`) and nothing
else: ``python -m eyestereo.tools.dense.accuracy --pictures docs/img/dense``. Bad input: one line on
stderr, exit status 2.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import cv2
import numpy as np

from eyestereo.tools.dense import datasets, metrics, pictures
from eyestereo.tools.dense.reference import reference
from eyestereo.tools.io import atomic_write_bytes, write_section
from eyestereo.tools.models.dense_stereo import DEFAULTS, WIDTHS, dense_stereo, to_float

__all__ = ["BEGIN", "END", "SGBM_SETTINGS", "BM_SETTINGS", "CUTS", "opencv_sgbm", "opencv_bm", "disparity_maps",
           "evaluate", "cut_table", "report", "PICTURED", "picture_folder", "write_pictures", "main"]

BEGIN, END = "<!-- dense_accuracy: begin -->", "<!-- dense_accuracy: end -->"

#: OpenCV StereoSGBM's settings: those of OpenCV's samples/cpp/stereo_match.cpp for a grey image
#: (block 3, P1 = 8 * 3 * 3, P2 = 32 * 3 * 3, 5 paths).
SGBM_SETTINGS = dict(blockSize=3, P1=8 * 9, P2=32 * 9, disp12MaxDiff=1, preFilterCap=63, uniquenessRatio=10,
                     speckleWindowSize=100, speckleRange=32, mode=cv2.STEREO_SGBM_MODE_SGBM)
#: OpenCV StereoBM's settings: those of the same sample.
BM_SETTINGS = dict(blockSize=9, preFilterCap=31, textureThreshold=10, uniquenessRatio=15, speckleWindowSize=100,
                   speckleRange=32, disp12MaxDiff=1)

#: The fixed-point cuts tried: (model parameter, the values; the first value is the full width).
CUTS = (("cost_bits", (5, 4, 3)), ("path_bits", (9, 7, 6, 5)), ("sum_shift", (0, 1, 2, 3)),
        ("frac_bits", (4, 3, 2, 0)))
#: The model's full widths (nothing can saturate): the cuts start from here.
FULL = dict(cost_bits=None, path_bits=9, sum_shift=0, frac_bits=4)


def _opencv_float(raw: np.ndarray) -> np.ndarray:
    return np.where(raw < 0, np.nan, raw / 16.0)


def opencv_sgbm(left: np.ndarray, right: np.ndarray, disparities: int) -> np.ndarray:
    """OpenCV StereoSGBM with :data:`SGBM_SETTINGS`, disparities 0 .. D-1, float px (NaN = none)."""
    m = cv2.StereoSGBM_create(minDisparity=0, numDisparities=disparities, **SGBM_SETTINGS)
    return _opencv_float(m.compute(left, right))


def opencv_bm(left: np.ndarray, right: np.ndarray, disparities: int) -> np.ndarray:
    """OpenCV StereoBM with :data:`BM_SETTINGS`, disparities 0 .. D-1, float px (NaN = none)."""
    s = BM_SETTINGS
    m = cv2.StereoBM_create(numDisparities=disparities, blockSize=s["blockSize"])
    m.setPreFilterCap(s["preFilterCap"])
    m.setTextureThreshold(s["textureThreshold"])
    m.setUniquenessRatio(s["uniquenessRatio"])
    m.setSpeckleWindowSize(s["speckleWindowSize"])
    m.setSpeckleRange(s["speckleRange"])
    m.setDisp12MaxDiff(s["disp12MaxDiff"])
    return _opencv_float(m.compute(left, right))


METHODS = ("bit-true model", "float reference", "OpenCV StereoSGBM", "OpenCV StereoBM")


def disparity_maps(pair: datasets.Pair, disparities: int, methods: tuple[str, ...] = METHODS,
                   **params) -> dict[str, np.ndarray]:
    """Float maps (px, NaN = none) of ``methods`` (names of :data:`METHODS`) on one pair (``params``: the
    model's and reference's settings over :data:`DEFAULTS`)."""
    cfg = {**DEFAULTS, **params, "disparities": disparities}
    run = {
        METHODS[0]: lambda: to_float(dense_stereo(pair.left, pair.right, **cfg)),
        METHODS[1]: lambda: reference(pair.left, pair.right, **cfg),
        METHODS[2]: lambda: opencv_sgbm(pair.left, pair.right, disparities),
        METHODS[3]: lambda: opencv_bm(pair.left, pair.right, disparities),
    }
    return {m: run[m]() for m in methods}


def evaluate(pair: datasets.Pair, disparities: int, **params) -> dict[str, dict[str, float]]:
    """The scores of the four methods on one pair (``params``: the model's and reference's settings)."""
    vis = metrics.visible_mask(pair.gt)
    return {k: metrics.scores(v, pair.gt, visible=vis) for k, v in disparity_maps(pair, disparities, **params).items()}


def _fmt(v: float, digits: int = 2) -> str:
    return "n/a" if v != v else f"{v:.{digits}f}"


def _table(header: list[str], rows: list[list[str]]) -> list[str]:
    lines = ["| " + " | ".join(header) + " |", "|---" + "|---:" * (len(header) - 1) + "|"]
    return lines + ["| " + " | ".join(r) + " |" for r in rows]


COLUMNS = [("bad1_noc", "bad-1 noc"), ("bad2_noc", "bad-2 noc"), ("bad4_noc", "bad-4 noc"), ("bad1_all", "bad-1 all"),
           ("bad2_all", "bad-2 all"), ("bad4_all", "bad-4 all"), ("density", "density"), ("rms", "RMS noc (px)"),
           ("bad2_filled", "bad-2 noc, holes bad"), ("bad2_interp", "bad-2 noc, holes interpolated")]
#: The goal's three ways to count holes: (scores key, the goal table's name for it).
CONVENTIONS = (("bad2_noc", "valid only"), ("bad2_filled", "holes bad"), ("bad2_interp", "holes interpolated"))


def cut_table(pairs: list[datasets.Pair], disparities: int = 64) -> tuple[list[str], dict[str, int]]:
    """Lines of the cuts' table (each width of :data:`CUTS` cut alone, bad-2 noc per pair) and the widths
    the defaults use (largest path cost and sum seen)."""
    vis = [metrics.visible_mask(p.gt) for p in pairs]
    rows, seen = [], {"max_path": 0, "max_sum": 0}
    for param, values in CUTS:
        for value in values:
            cells = []
            for p, v in zip(pairs, vis):
                stats: dict = {}
                cfg = {**DEFAULTS, **FULL, "disparities": disparities, param: value}
                codes = dense_stereo(p.left, p.right, **cfg, stats=stats)
                if value == values[0] and param == CUTS[0][0]:
                    seen = {k: max(seen[k], stats[k]) for k in seen}
                s = metrics.scores(to_float(codes), p.gt, visible=v)
                cells += [_fmt(s["bad2_noc"]), _fmt(s["rms"], 3)]
            rows.append([f"`{param}`", str(value)] + cells)
    header = ["cut", "value"] + [f"{p.name} {m}" for p in pairs for m in ("bad-2 noc", "RMS")]
    return _table(header, rows), seen


def _settings() -> list[str]:
    ours = ", ".join(f"{k}={v}" for k, v in DEFAULTS.items() if k != "disparities")
    sg = ", ".join(f"{k}={v}" for k, v in SGBM_SETTINGS.items() if k != "mode")
    bm = ", ".join(f"{k}={v}" for k, v in BM_SETTINGS.items())
    widths = ", ".join(f"{k}={'full' if v is None else v}" for k, v in WIDTHS.items())
    return [f"* **ours** (bit-true model and float reference): {ours}; the model's widths: {widths}.",
            f"* **OpenCV StereoSGBM** ({cv2.__version__}): minDisparity=0, numDisparities=D, {sg}, "
            "mode=MODE_SGBM (OpenCV's stereo_match.cpp sample for a grey image).",
            f"* **OpenCV StereoBM**: numDisparities=D, {bm} (the same sample).",
            "* Every method gets the same grey pair (8 bits) and the same range 0 .. D-1; D = 64, or the ground "
            "truth's maximum rounded up to 16 where it is larger (none of these pairs)."]


def report(results: list[tuple[datasets.Pair, int, dict]], cuts: tuple[list[str], dict] | None,
           seconds: float) -> str:
    """The generated section (Markdown)."""
    out = [f"Generated by `python -m eyestereo.tools.dense.accuracy` ({seconds:.0f} s).", "", "Settings:", "",
           *_settings(), "", "Measures (`eyestereo.tools.dense.metrics`): pixels of unknown ground truth are left "
           "out; noc = visible in the right view by the ground truth's own left-right check; bad-t = % of the "
           "valid estimates off by more than t px; density = % of the known pixels with an estimate. Three ways "
           "to count the pixels without an estimate (holes) in bad-2 noc: over the valid estimates only (the "
           "bad-2 noc column); every hole counted bad (holes bad); every hole filled first by background "
           "interpolation, then every pixel counted (holes interpolated, density 100 %). The last is the "
           "benchmarks' standard: KITTI's development kit (stereo 2015, `evaluate_scene_flow.cpp`) fills a "
           "submitted map with `DisparityImage::interpolateBackground` (along each row a gap takes the smaller "
           "of the two disparities around it, a row's ends the nearest valid one; then each column's ends) and "
           "counts the errors of the filled map over every ground-truth pixel, with the errors over the "
           "estimated pixels only and the density beside them. "
           "`metrics.fill_background` does the same, with one choice of ours: a row with nothing valid between "
           "two filled rows takes the smaller of their values (KITTI leaves it invalid). Every method's map, "
           "OpenCV's included, gets the same filling.", ""]
    goal = []
    for pair, d, res in results:
        vis = metrics.visible_mask(pair.gt)
        out += [f"### {pair.name} {pair.size}, D = {d}", "",
                f"Ground truth up to {pair.max_disparity:.1f} px; {100 * vis.mean():.1f} % of the pixels "
                "known and visible.", ""]
        out += _table(["method"] + [c[1] for c in COLUMNS],
                      [[m] + [_fmt(res[m][k]) for k, _ in COLUMNS] for m in METHODS])
        out.append("")
        ours, sgbm, bm = (res[m] for m in (METHODS[0], METHODS[2], METHODS[3]))
        row = [pair.name, pair.size]
        for key, _ in CONVENTIONS:
            row += [_fmt(x[key]) for x in (ours, sgbm, bm)]
            row += ["yes" if ours[key] <= sgbm[key] + 2 else "**no**", "yes" if ours[key] < bm[key] else "**no**"]
        goal.append(row)
    out += ["### The goal: bad-2 noc within 2 points of StereoSGBM, below StereoBM", "",
            "Judged in the three ways to count holes (each a group of five columns): "
            + "; ".join(f"**{name}**" for _, name in CONVENTIONS)
            + " (the standard one, as KITTI's development kit scores).", ""]
    header = ["pair", "size"]
    for _, name in CONVENTIONS:
        header += [f"ours, {name}", "SGBM", "BM", "<= SGBM + 2", "< BM"]
    out += _table(header, goal)
    if cuts is not None:
        lines, seen = cuts
        out += ["", "### What each fixed-point cut costs (352 x 288, D = 64, default P1, P2, uniqueness, median)", "",
                "One width of the bit-true model cut at a time (`cost_bits`: the Hamming cost saturated at "
                "2^b - 1; `path_bits`: path costs saturated at 2^b - 1; `sum_shift`: LSBs dropped from the "
                "sum of the paths; `frac_bits`: fractional bits of the sub-pixel offset), the others at their full "
                "width (the first row of each cut). **Rule**: the smallest width whose bad-2 noc stays within 0.1 "
                "points and whose RMS within 2 % of the full width's on every pair; for the path costs one bit more "
                "than the rule's 6, so that P2 may grow to 103 before anything saturates. The model's widths: "
                + ", ".join(f"{k}={'full' if v is None else v}" for k, v in WIDTHS.items()) + ".", ""]
        out += lines
        out += ["", "Widths used at full width with the default settings on these pairs: largest path cost "
                f"{seen['max_path']} "
                f"({seen['max_path'].bit_length()} bits), largest sum over the paths {seen['max_sum']} "
                f"({seen['max_sum'].bit_length()} bits)."]
    return "\n".join(out) + "\n"


#: The pictures' methods and their labels.
PICTURED = ((METHODS[0], "ours (bit-true model)"), (METHODS[2], "OpenCV StereoSGBM"), (METHODS[3], "OpenCV StereoBM"))


def picture_folder(directory) -> Path:
    """``directory`` as the pictures' folder: an existing folder, or a new one whose parent exists (created);
    anything else is refused with a one-line ValueError."""
    folder = Path(directory)
    if folder.exists() and not folder.is_dir():
        raise ValueError(f"picture folder {folder} is a file, not a folder")
    if not folder.exists():
        if not folder.parent.is_dir():
            raise ValueError(f"picture folder {folder} does not exist and neither does its parent {folder.parent}")
        folder.mkdir()
    return folder


def write_pictures(directory, pairs: list[datasets.Pair], disparities: int | None = None) -> list[Path]:
    """One PNG per pair, ``<name>.png`` in ``directory`` (:func:`picture_folder`): the left image, the ground
    truth and the maps of :data:`PICTURED` (default settings), all on one colour scale, 0 px to the ground
    truth's maximum rounded up (:func:`eyestereo.tools.dense.pictures.picture_row`). ``disparities``: D
    (default :func:`~eyestereo.tools.dense.datasets.disparity_range` of each pair). The written paths."""
    folder = picture_folder(directory)
    written = []
    for pair in pairs:
        d = datasets.disparity_range(pair) if disparities is None else disparities
        maps = disparity_maps(pair, d, tuple(m for m, _ in PICTURED))
        panels = {"ground truth": pair.gt, **{label: maps[m] for m, label in PICTURED}}
        vmax = float(np.ceil(pair.max_disparity))
        row = pictures.picture_row(pair.left, panels, vmax, f"{pair.name} {pair.size}, D = {d}")
        path = folder / f"{pair.name}.png"
        atomic_write_bytes(path, pictures.encode_png(row))
        written.append(path)
    return written


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # one line, exit status 2
        self.exit(2, f"{self.prog}: error: {message}\n")


def main(argv: list[str] | None = None) -> int:
    ap = _Parser(prog="python -m eyestereo.tools.dense.accuracy", description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=Path, help="the page whose dense_accuracy section is written (default: print)")
    ap.add_argument("--pairs", default=",".join(datasets.PAIRS), help="comma-separated pair names")
    ap.add_argument("--sizes", default="cif,own", help="cif (352x288) and/or own")
    ap.add_argument("--no-cuts", action="store_true", help="leave out the table of the fixed-point cuts")
    ap.add_argument("--pictures", type=Path, metavar="DIR",
                    help="write the pictures of --pairs at 352x288 into DIR instead of the tables")
    args = ap.parse_args(argv)
    names = [n for n in args.pairs.split(",") if n]
    sizes = [s for s in args.sizes.split(",") if s]
    bad = [n for n in names if n not in datasets.PAIRS] + [s for s in sizes if s not in ("cif", "own")]
    if not names or not sizes or bad:
        ap.error(f"unknown pair or size {', '.join(bad) or '(none given)'}; pairs: {', '.join(datasets.PAIRS)}; "
                 "sizes: cif, own")
    if args.pictures is not None and args.out is not None:
        ap.error("--pictures writes pictures only; run the tables (--out) separately")
    if args.pictures is not None:
        try:
            picture_folder(args.pictures)  # refused before the pairs are loaded and matched
        except ValueError as e:
            ap.error(str(e))
    if args.out is not None:
        text = args.out.read_text(encoding="utf-8") if args.out.is_file() else ""
        if BEGIN not in text or END not in text:
            ap.error(f"{args.out} has no '{BEGIN}' ... '{END}' section to fill")
    t0 = time.perf_counter()
    try:
        own = [datasets.load(n) for n in names]
    except ValueError as e:
        ap.error(str(e))
    if args.pictures is not None:
        try:
            for path in write_pictures(args.pictures, [datasets.resize(p) for p in own]):
                print(f"written {path} ({path.stat().st_size // 1024} kB)", file=sys.stderr)
        except ValueError as e:
            ap.error(str(e))
        return 0
    results, cif = [], []
    for pair in own:
        small = datasets.resize(pair)
        cif.append(small)
        for p in ([small] if "cif" in sizes else []) + ([pair] if "own" in sizes else []):
            d = datasets.disparity_range(p)
            print(f"{p.name} {p.size} D={d}", file=sys.stderr, flush=True)
            results.append((p, d, evaluate(p, d)))
    cuts = None if args.no_cuts else cut_table(cif)
    text = report(results, cuts, time.perf_counter() - t0)
    sys.stdout.write(text)
    if args.out is not None:
        write_section(args.out, text, BEGIN, END)
        print(f"written to {args.out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
