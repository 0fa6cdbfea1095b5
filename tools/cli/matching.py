"""``eyestereo evaluate`` and ``eyestereo sweep``: sparse feature matching against ground truth (thesis 7.3).

::

    eyestereo evaluate LEFT RIGHT GT [--scale S] [--json FILE] [-o DIR] [--dense] [matching options]
    eyestereo sweep LEFT RIGHT GT --vary t_max|window|split|cost|rows|ncc_min --values LIST [--scale S]
                    [--json FILE] [--plot PNG] [matching options]

GT is a disparity map of the left view: an 8/16-bit PGM/PNG holding disparity x ``--scale`` (Middlebury:
16 for Tsukuba, 8 for Venus), 0 = unknown; or a PFM/.npy of float disparities (0, NaN, inf = unknown).
The ground truth only scores the result: the matcher's parameters come from the command line or from
the images (:mod:`eyestereo.tools.matching.evaluate`: corners from the bit-true Harris model with one
threshold code for both images, about ``--corners`` in the left one; NCC 11x11 >= 0.75 with the
left-right check; disparities 0 .. width / 4 unless ``--max-disparity`` says otherwise).

``evaluate`` prints the figures and, with ``--json``, writes ``matches``, ``good``, ``bad``,
``bad_percent``, ``rms``, ``seconds`` (the time of the matching step; ``seconds_features`` holds the
corner detection's) and the details; with ``-o DIR`` it writes ``matches.png`` and ``disparity.png``
(and ``dense.png`` with ``--dense``) into DIR. Outputs, errors and exit codes:
:mod:`eyestereo.tools.cli.common` (all outputs are written together, only when everything is computed).
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path
from typing import Any

import numpy as np

from eyestereo.tools.cli.common import EXIT_USAGE, number, positive, print_error, window
from eyestereo.tools.constants import NMS_SIZES
from eyestereo.tools.io import Outputs
from eyestereo.tools.matching import metrics as Q
from eyestereo.tools.matching import sparse as M
from eyestereo.tools.matching.evaluate import DEFAULTS, VARY, evaluate_pair, parse_values, summary, sweep_pair

__all__ = ["cmd_evaluate", "cmd_sweep", "register"]

#: The files ``evaluate -o DIR`` writes (an existing DIR may hold only these).
PICTURES = ("matches.png", "disparity.png", "dense.png")


# --------------------------------------------------------------------------------------------------
# Outputs


def _json_writer(doc: dict):
    def write(tmp: Path) -> None:
        tmp.write_text(json.dumps(doc, indent=2) + "\n", encoding="utf-8")
    return write


def _figure(w_in: float, h_in: float):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(w_in, h_in), dpi=100)
    FigureCanvasAgg(fig)
    return fig


def _matches_writer(left, right, result, gt):
    def write(tmp: Path) -> None:
        m: M.Matches = result["matches"]
        h, w = left.shape
        fig = _figure(2 * w / 100 + 0.4, h / 100 + 0.6)
        ax = fig.add_axes([0.01, 0.01, 0.98, 0.9])
        ax.imshow(np.hstack([left, right]), cmap="gray", vmin=0, vmax=255, interpolation="nearest")
        true = gt[m.left[:, 1], m.left[:, 0]] if len(m) else np.zeros(0)
        known = np.isfinite(true)
        bad = known & (np.abs(m.disparity - np.where(known, true, 0)) > 1)
        for sel, col in ((known & ~bad, "lime"), (bad, "red"), (~known, "yellow")):
            if sel.any():
                xs = np.stack([m.left[sel, 0], m.right[sel, 0] + w])
                ys = np.stack([m.left[sel, 1], m.right[sel, 1]])
                ax.plot(xs, ys, "-", color=col, lw=0.6, alpha=0.8)
        lx, rx = result["left_xy"], result["right_xy"]
        ax.plot(lx[:, 0], lx[:, 1], ".", color="deepskyblue", ms=2)
        ax.plot(rx[:, 0] + w, rx[:, 1], ".", color="deepskyblue", ms=2)
        s = result["scores"]
        ax.set_title(f"{len(m)} matches: {s.good} good (green), {s.bad} bad (red), {s.unknown} unknown "
                     f"(yellow); corners blue", fontsize=9)
        ax.set_axis_off()
        fig.savefig(tmp, format="png")
    return write


def _disparity_writer(left, result, gt):
    def write(tmp: Path) -> None:
        m: M.Matches = result["matches"]
        h, w = left.shape
        vmax = max(result["d_max"], 1)
        fig = _figure(2 * w / 100 + 1.2, h / 100 + 0.7)
        a1 = fig.add_axes([0.01, 0.02, 0.44, 0.86])
        a2 = fig.add_axes([0.47, 0.02, 0.44, 0.86])
        cax = fig.add_axes([0.93, 0.1, 0.015, 0.7])
        im = a1.imshow(np.where(np.isfinite(gt), gt, np.nan), cmap="viridis", vmin=0, vmax=vmax,
                       interpolation="nearest")
        a1.set_title("ground truth (white: unknown)", fontsize=9)
        a2.imshow(left, cmap="gray", vmin=0, vmax=255, interpolation="nearest")
        if len(m):
            a2.scatter(m.left[:, 0], m.left[:, 1], c=m.disparity, cmap="viridis", vmin=0, vmax=vmax, s=9,
                       edgecolors="none")
        a2.set_title(f"matched corners coloured by disparity (0..{vmax})", fontsize=9)
        for a in (a1, a2):
            a.set_axis_off()
        fig.colorbar(im, cax=cax)
        fig.savefig(tmp, format="png")
    return write


def _dense_writer(dense: np.ndarray, gt, d_max: int):
    def write(tmp: Path) -> None:
        h, w = dense.shape
        fig = _figure(2 * w / 100 + 0.4, h / 100 + 0.7)
        a1 = fig.add_axes([0.01, 0.02, 0.48, 0.86])
        a2 = fig.add_axes([0.51, 0.02, 0.48, 0.86])
        a1.imshow(dense, cmap="viridis", vmin=0, vmax=max(d_max, 1), interpolation="nearest")
        a1.set_title("dense SAD disparity", fontsize=9)
        err = np.abs(dense - gt)
        rgb = np.full((h, w, 3), 0.5)
        known = np.isfinite(err)
        rgb[known & (err <= 1)] = (1, 1, 1)
        rgb[known & (err > 1)] = (0.85, 0, 0)
        a2.imshow(rgb, interpolation="nearest")
        a2.set_title("bad pixels (red), good (white), not evaluated (grey)", fontsize=9)
        for a in (a1, a2):
            a.set_axis_off()
        fig.savefig(tmp, format="png")
    return write


# --------------------------------------------------------------------------------------------------
# Commands


def _match_kw(args) -> dict:
    return dict(window=args.window, t_max=args.t_max, cost=args.cost, split=args.split, rows=args.rows,
                lr_check=args.lr_check, ncc_min=args.ncc_min)


def _load(args):
    left, right = M.load_pair(args.left, args.right)
    gt = Q.check_gt(Q.load_disparity(args.gt, args.scale), left.shape)
    return left, right, gt


def _detect_kw(args) -> dict:
    return dict(corners=args.corners, threshold=args.threshold, k=args.k, nms=args.nms, d_max=args.max_disparity)


def cmd_evaluate(args: argparse.Namespace) -> int:
    """Handler of ``evaluate``."""
    with Outputs() as out:
        json_tmp = None if args.json is None else out.file(args.json)
        pics = None if args.output is None else out.folder(args.output, PICTURES)
        left, right, gt = _load(args)
        result = evaluate_pair(left, right, gt, **_detect_kw(args), **_match_kw(args))
        if args.dense:
            from eyestereo.tools.matching.dense import sad_disparity

            t0 = time.perf_counter()
            dense = sad_disparity(left, right, result["d_max"], window=args.dense_window)
            dt = time.perf_counter() - t0
            ds = Q.dense_scores(dense, gt)
            result["dense"] = dict(ds.as_dict(), seconds=round(dt, 6), window=args.dense_window)
        doc = summary(result)
        if json_tmp is not None:
            _json_writer(doc)(json_tmp)
        written = []
        if pics is not None:
            _matches_writer(left, right, result, gt)(pics / "matches.png")
            _disparity_writer(left, result, gt)(pics / "disparity.png")
            written = ["matches.png", "disparity.png"]
            if args.dense:
                _dense_writer(dense, gt, result["d_max"])(pics / "dense.png")
                written.append("dense.png")
    s = result["scores"]
    bp = "n/a" if math.isnan(s.bad_percent) else f"{s.bad_percent:.2f} %"
    rms = "n/a" if math.isnan(s.rms) else f"{s.rms:.3f} px"
    p = result["matches"].params
    what = f"NCC >= {p['ncc_min']:g}" if p["cost"] == "ncc" else f"{p['cost'].upper()} < t_max {p['t_max']:g}"
    print(f"corners: {len(result['left_xy'])} left, {len(result['right_xy'])} right (threshold code "
          f"{doc['threshold_code']}); disparities 0..{result['d_max']}; {p['window'][0]}x{p['window'][1]} {what}"
          f"{', left-right check' if p['lr_check'] else ''}")
    print(f"matches: {len(result['matches'])} ({s.good} good, {s.bad} bad, {s.unknown} without ground truth); "
          f"bad {bp}; RMS {rms}; matching {result['seconds'] * 1e3:.2f} ms")
    if args.dense:
        d = result["dense"]
        dbp = "n/a" if d["bad_percent"] is None else f"{d['bad_percent']:.2f} %"
        drms = "n/a" if d["rms"] is None else f"{d['rms']:.3f} px"
        print(f"dense SAD {args.dense_window}x{args.dense_window}: {d['evaluated']} pixels, bad {dbp}, "
              f"RMS {drms}, {d['seconds'] * 1e3:.1f} ms")
    if args.json is not None:
        print(f"-> {args.json}")
    for name in written:
        print(f"-> {Path(args.output) / name}")
    return 0


def _sweep_plot_writer(rows: list[dict], vary: str):
    def write(tmp: Path) -> None:
        fig = _figure(6.4, 4.0)
        ax = fig.add_subplot(111)
        labels = [("x".join(map(str, r["value"])) if isinstance(r["value"], list) else str(r["value"])) for r in rows]
        x = np.arange(len(rows))
        numeric = vary in ("t_max", "rows", "ncc_min")
        if numeric:
            x = np.array([r["value"] for r in rows], float)
        ax.plot(x, [r["matches"] for r in rows], "o-", label="matches")
        ax.plot(x, [r["good"] for r in rows], "s-", label="good")
        ax.plot(x, [r["bad"] for r in rows], "^-", label="bad (|e| > 1)")
        ax.set_xlabel(vary)
        if not numeric:
            ax.set_xticks(x, labels)
        ax.set_ylabel("count")
        ax2 = ax.twinx()
        ax2.plot(x, [r["seconds"] * 1e3 for r in rows], "k:", label="matching time")
        ax2.set_ylabel("matching time (ms)")
        ax.legend(loc="upper left", fontsize=8)
        ax.grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(tmp, format="png")
    return write


def cmd_sweep(args: argparse.Namespace) -> int:
    """Handler of ``sweep``."""
    try:
        values = parse_values(args.vary, args.values)
    except ValueError as exc:
        print_error(f"argument --values: {exc}")
        return EXIT_USAGE
    with Outputs() as out:
        json_tmp = None if args.json is None else out.file(args.json)
        plot_tmp = None if args.plot is None else out.file(args.plot)
        left, right, gt = _load(args)
        kw = {**_detect_kw(args), **_match_kw(args)}
        kw.pop(args.vary, None)
        rows = sweep_pair(left, right, gt, args.vary, values, repeat=args.repeat, **kw)
        if json_tmp is not None:
            _json_writer({"vary": args.vary, "rows": rows})(json_tmp)
        if plot_tmp is not None:
            _sweep_plot_writer(rows, args.vary)(plot_tmp)
    print(f"{'value':>8} {'matches':>8} {'good':>6} {'bad':>5} {'bad %':>7} {'RMS px':>7} {'ms':>8}")
    for r in rows:
        v = "x".join(map(str, r["value"])) if isinstance(r["value"], list) else str(r["value"])
        bp = "n/a" if r["bad_percent"] is None else f"{r['bad_percent']:.2f}"
        rms = "n/a" if r["rms"] is None else f"{r['rms']:.3f}"
        print(f"{v:>8} {r['matches']:>8} {r['good']:>6} {r['bad']:>5} {bp:>7} {rms:>7} {r['seconds'] * 1e3:8.3f}")
    for p in (args.json, args.plot):
        if p is not None:
            print(f"-> {p}")
    return 0


def _add_common(p: argparse.ArgumentParser) -> None:
    d = DEFAULTS
    p.add_argument("left", metavar="LEFT", help="rectified left image")
    p.add_argument("right", metavar="RIGHT", help="rectified right image (same size)")
    p.add_argument("gt", metavar="GT", help="ground-truth disparity of the left view (PGM/PNG, PFM or .npy); "
                   "used for scoring only")
    p.add_argument("--scale", type=positive, default=1.0,
                   help="GT value per pixel of disparity (Middlebury: 16 Tsukuba, 8 Venus; default 1); 0 = unknown")
    g = p.add_argument_group("corners (bit-true Harris model)")
    g.add_argument("--corners", type=lambda t: number(t, int, 1, 100000, "--corners"), default=d["corners"],
                   help=f"aim at this many corners in the left image (default {d['corners']})")
    g.add_argument("--threshold", type=lambda t: number(t, int, 0, (1 << 19) - 1, "--threshold"), default=None,
                   help="threshold code instead of --corners (same for both images)")
    g.add_argument("--k", type=lambda t: number(t, float, 0, 255 / 256, "--k"), default=d["k"],
                   help=f"Harris k (default {d['k']})")
    g.add_argument("--nms", type=int, choices=NMS_SIZES, default=d["nms"], help=f"NMS window (default {d['nms']})")
    g = p.add_argument_group("matching (defaults: NCC 11x11 >= 0.75, left-right check, disparities 0..width/4)")
    g.add_argument("--cost", choices=M.COSTS, default=d["cost"], help=f"cost function (default {d['cost']})")
    g.add_argument("--window", type=window, default=d["window"],
                   help=f"window WxH or N, odd (default {d['window'][0]}x{d['window'][1]})")
    g.add_argument("--ncc-min", dest="ncc_min", type=lambda t: number(t, float, -1, 1, "--ncc-min"),
                   default=d["ncc_min"], help=f"NCC: accept NCC >= this (default {d['ncc_min']})")
    g.add_argument("--t-max", dest="t_max", type=positive, default=d["t_max"],
                   help=f"SAD: accept SAD < t_max*W*H; SSD: < t_max^2*W*H (default {d['t_max']:g})")
    g.add_argument("--split", type=int, choices=M.SPLITS, default=d["split"],
                   help="split correlation (SAD, SSD): 1 window, 5 or 9 windows (default 1)")
    g.add_argument("--rows", type=lambda t: number(t, int, 0, 16, "--rows"), default=d["rows"],
                   help="also search +-ROWS rows (default 0)")
    g.add_argument("--lr-check", dest="lr_check", action=argparse.BooleanOptionalAction, default=d["lr_check"],
                   help="left-right consistency check (default on)")
    g.add_argument("--max-disparity", dest="max_disparity",
                   type=lambda t: number(t, int, 0, 100000, "--max-disparity"), default=None,
                   help="disparity range 0..D (default: a quarter of the image width)")


def register(subparsers: Any) -> None:
    """Add the ``evaluate`` and ``sweep`` sub-commands to an ``argparse`` sub-parsers object."""
    p = subparsers.add_parser(
        "evaluate", help="feature matching on a stereo pair with ground truth: figures, JSON, PNGs",
        description="Harris corners (bit-true model) of both images, matching along the rows (thesis 7.3), "
                    "RMS error and bad matches (|d - d_true| > 1) against the ground truth, which is used "
                    "for scoring only.")
    _add_common(p)
    p.add_argument("--json", type=Path, default=None, help="write the figures to this JSON file")
    p.add_argument("-o", "--output", type=Path, default=None,
                   help="folder for matches.png, disparity.png (and dense.png); created, or replaced when it "
                        "holds only these")
    p.add_argument("--dense", action="store_true", help="also dense SAD block matching over all pixels")
    p.add_argument("--dense-window", dest="dense_window", type=int, choices=range(3, 32, 2), default=9,
                   metavar="N", help="dense SAD window (odd, default 9)")
    p.set_defaults(func=cmd_evaluate)

    q = subparsers.add_parser(
        "sweep", help="matching figures over a range of one parameter (thesis Fig. 7.5)",
        description="Detect corners once, then match with each value of one parameter and tabulate "
                    "matches, good, bad, bad %, RMS and matching time.")
    _add_common(q)
    q.add_argument("--vary", choices=VARY, required=True, help="parameter to sweep")
    q.add_argument("--values", required=True,
                   help="comma list (t_max 5,9,11; window 5x7,9; split 1,5,9; cost sad,ncc; ncc_min 0.7,0.8) "
                        "or a:b[:step] for t_max, ncc_min and rows")
    q.add_argument("--repeat", type=lambda t: number(t, int, 1, 100, "--repeat"), default=1,
                   help="time each matching this many times, keep the fastest (default 1)")
    q.add_argument("--json", type=Path, default=None, help="write the table to this JSON file")
    q.add_argument("--plot", type=Path, default=None, help="write a PNG plot of the table")
    q.set_defaults(func=cmd_sweep)
