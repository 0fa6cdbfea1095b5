"""``eyestereo evaluate`` and ``eyestereo sweep``: sparse feature matching against ground truth (thesis 7.3).

``eyestereo.tools.cli.main`` calls :func:`register` with its sub-parsers; :func:`main` runs the two commands
on their own (``python -m eyestereo.tools.cli.matching evaluate L.png R.png GT.pgm --scale 16``)::

    eyestereo evaluate LEFT RIGHT GT [--scale S] [--json FILE] [-o DIR] [--dense] [matching options]
    eyestereo sweep LEFT RIGHT GT --vary t_max|window|split|cost|rows --values LIST [--scale S]
                    [--json FILE] [--plot PNG] [matching options]

GT is a disparity map of the left view: an 8/16-bit PGM/PNG holding disparity x ``--scale`` (Middlebury:
16 for Tsukuba, 8 for Venus), 0 = unknown; or a PFM/.npy of float disparities (0, NaN, inf = unknown).
Corners come from the bit-true Harris model with one threshold code for both images, chosen so that
the left image gives about ``--corners`` corners (or given by ``--threshold``). The disparity range is
0 .. ceil(max GT) + 1 unless ``--max-disparity`` says otherwise.

``evaluate`` prints the figures and, with ``--json``, writes ``matches``, ``good``, ``bad``,
``bad_percent``, ``rms``, ``seconds`` (the time of the matching step; ``seconds_features`` holds the
corner detection's) and the details; with ``-o DIR`` it writes ``matches.png`` and ``disparity.png``
(and ``dense.png`` with ``--dense``). Failures: one line ``eyestereo: error: ...`` on stderr, exit status 1
(run time) or 2 (command line); every output is written to a temporary file and renamed into place once
everything has been computed, so a failure leaves no partial output.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, NoReturn

import numpy as np

from eyestereo.tools.matching import sparse as M
from eyestereo.tools.matching import metrics as Q

__all__ = ["register", "main", "build_parser", "evaluate_pair", "sweep_pair", "default_d_max",
           "parse_window", "parse_values"]

PROG = "eyestereo"
VARY = ("t_max", "window", "split", "cost", "rows")


# --------------------------------------------------------------------------------------------------
# The computations (also used by tools/bench_matching.py)


def default_d_max(gt: np.ndarray) -> int:
    """ceil(max ground truth) + 1 (the +1 leaves room for sub-pixel ground truth and rounding)."""
    g = np.asarray(gt, np.float64)
    if not np.any(np.isfinite(g)):
        raise ValueError("the ground truth holds no known disparity")
    return int(math.ceil(float(np.nanmax(g)))) + 1


def evaluate_pair(left, right, gt, *, corners: int = 500, threshold: int | None = None, k: float = 0.04,
                  nms: int = 3, d_max: int | None = None, left_xy=None, right_xy=None,
                  **match_kw) -> dict:
    """Corners (unless given), matching and scores of one stereo pair; a dict with the figures and the
    objects (``result["matches"]`` is a :class:`~eyestereo.tools.matching.sparse.Matches`)."""
    left, right = M.check_pair(left, right)
    gt = Q.check_gt(gt, left.shape)
    if d_max is None:
        d_max = default_d_max(gt)
    t0 = time.perf_counter()
    if left_xy is None or right_xy is None:
        if threshold is None:
            threshold = M.threshold_for_count(left, corners, k=k, nms=nms)
        left_xy = M.detect_corners(left, k=k, threshold=threshold, nms=nms)
        right_xy = M.detect_corners(right, k=k, threshold=threshold, nms=nms)
    t1 = time.perf_counter()
    if len(left_xy) == 0 or len(right_xy) == 0:
        side = "left" if len(left_xy) == 0 else "right"
        raise ValueError(f"no corners found in the {side} image (threshold code {threshold}); "
                         "lower --threshold or ask for more --corners")
    m = M.match_features(left, right, left_xy, right_xy, d_max=d_max, **match_kw)
    t2 = time.perf_counter()
    s = Q.sparse_scores(m.left, m.disparity, gt)
    return dict(matches=m, scores=s, left_xy=np.asarray(left_xy), right_xy=np.asarray(right_xy),
                threshold=threshold, d_max=int(d_max), seconds=t2 - t1, seconds_features=t1 - t0)


def summary(result: dict) -> dict:
    """The JSON-able figures of :func:`evaluate_pair`'s result."""
    s: Q.Scores = result["scores"]
    m: M.Matches = result["matches"]
    p = dict(m.params)
    p["window"] = list(p["window"])
    out = {"matches": len(m), "good": s.good, "bad": s.bad,
           "bad_percent": None if math.isnan(s.bad_percent) else round(s.bad_percent, 4),
           "rms": None if math.isnan(s.rms) else round(s.rms, 6),
           "seconds": round(result["seconds"], 6), "seconds_features": round(result["seconds_features"], 6),
           "unknown": s.unknown, "evaluated": s.evaluated, "candidates": m.candidates,
           "left_corners": int(len(result["left_xy"])), "right_corners": int(len(result["right_xy"])),
           "threshold_code": None if result["threshold"] is None else int(np.max(result["threshold"])),
           "params": p}
    if "dense" in result:
        out["dense"] = result["dense"]
    return out


def sweep_pair(left, right, gt, vary: str, values, *, repeat: int = 1, **kw) -> list[dict]:
    """:func:`evaluate_pair` for each value of one matching parameter (corners detected once).

    ``repeat`` > 1 times the matching step that many times and keeps the fastest."""
    if vary not in VARY:
        raise ValueError(f"vary must be one of {VARY}, got {vary!r}")
    values = list(values)
    if not values:
        raise ValueError("no values to sweep")
    base = evaluate_pair(left, right, gt, **kw)
    kw = {k: v for k, v in kw.items() if k not in ("corners", "threshold", "k", "nms")}
    kw["d_max"] = base["d_max"]
    rows = []
    for v in values:
        best = None
        for _ in range(max(1, repeat)):
            r = evaluate_pair(left, right, gt, left_xy=base["left_xy"], right_xy=base["right_xy"],
                              **{**kw, vary: v})
            if best is None or r["seconds"] < best["seconds"]:
                best = r
        best["threshold"] = base["threshold"]
        best["seconds_features"] = base["seconds_features"]
        row = summary(best)
        row["value"] = list(v) if isinstance(v, tuple) else v
        rows.append(row)
    return rows


# --------------------------------------------------------------------------------------------------
# Argument types


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors: ``eyestereo: error: ...`` and exit status 2."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{PROG}: error: {' '.join(message.split())}\n")


def parse_window(text: str) -> tuple[int, int]:
    """'9' or '5x7' (W x H) -> (W, H), odd sides 1..255."""
    m = re.fullmatch(r"\s*(\d+)\s*(?:[xX]\s*(\d+)\s*)?", str(text))
    if m is None:
        raise ValueError(f"window must be N or WxH, e.g. 9 or 5x7; got {text!r}")
    w = int(m.group(1))
    h = int(m.group(2)) if m.group(2) else w
    if not (1 <= w <= 255 and 1 <= h <= 255 and w % 2 and h % 2):
        raise ValueError(f"window sides must be odd, 1..255; got {text!r}")
    return w, h


def _window_arg(text: str) -> tuple[int, int]:
    try:
        return parse_window(text)
    except ValueError as e:
        raise argparse.ArgumentTypeError(str(e)) from None


def _num(text: str, kind=float, lo=None, hi=None, what="number"):
    try:
        v = kind(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a{'n integer' if kind is int else ' number'}: {text!r}") from None
    if isinstance(v, float) and not math.isfinite(v):
        raise argparse.ArgumentTypeError(f"must be finite, got {text!r}")
    if (lo is not None and v < lo) or (hi is not None and v > hi):
        rng = f"{lo if lo is not None else '-inf'}..{hi if hi is not None else 'inf'}"
        raise argparse.ArgumentTypeError(f"{what} must lie in {rng}, got {text}")
    return v


def _pos_float(text):
    v = _num(text)
    if not v > 0:
        raise argparse.ArgumentTypeError(f"must be a positive number, got {text!r}")
    return v


def parse_values(vary: str, text: str) -> list:
    """'1,5,9' or 'a:b[:step]' (inclusive; t_max and rows) -> the list of values of parameter ``vary``."""
    if vary not in VARY:
        raise ValueError(f"vary must be one of {VARY}, got {vary!r}")
    text = str(text).strip()
    if not text:
        raise ValueError("empty --values")
    if ":" in text and vary in ("t_max", "rows"):
        parts = text.split(":")
        if len(parts) not in (2, 3):
            raise ValueError(f"range must be a:b or a:b:step, got {text!r}")
        try:
            a, b = float(parts[0]), float(parts[1])
            st = float(parts[2]) if len(parts) == 3 else 1.0
        except ValueError:
            raise ValueError(f"bad range {text!r}") from None
        if not (st > 0 and b >= a and (b - a) / st <= 1000):
            raise ValueError(f"range {text!r} must rise with a positive step (at most 1000 values)")
        vals = [a + i * st for i in range(int(math.floor((b - a) / st + 1e-9)) + 1)]
    else:
        vals = [v.strip() for v in text.split(",") if v.strip()]
    out = []
    for v in vals:
        if vary == "t_max":
            f = float(v)
            if not (math.isfinite(f) and f > 0):
                raise ValueError(f"t_max values must be positive, got {v}")
            out.append(round(f, 9))
        elif vary == "rows":
            f = float(v)
            if f != int(f) or f < 0:
                raise ValueError(f"rows values must be integers >= 0, got {v}")
            out.append(int(f))
        elif vary == "window":
            out.append(parse_window(v))
        elif vary == "split":
            if v not in ("1", "5", "9"):
                raise ValueError(f"split values must be 1, 5 or 9, got {v!r}")
            out.append(int(v))
        else:
            if v not in M.COSTS:
                raise ValueError(f"cost values must be among {', '.join(M.COSTS)}, got {v!r}")
            out.append(v)
    return out


# --------------------------------------------------------------------------------------------------
# Outputs


def _error(msg: str) -> int:
    print(f"{PROG}: error: {' '.join(str(msg).split())}", file=sys.stderr)
    return 1


def _check_out_file(path: Path) -> Path:
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise ValueError(f"cannot write {path}: folder {folder} does not exist")
    if path.is_dir():
        raise ValueError(f"cannot write {path}: it is a folder")
    return path


def _tmp_beside(path: Path) -> Path:
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    return Path(tmp)


def _commit(writers: list[tuple[Path, Any]]) -> None:
    """Write every output to a temporary file beside it, then rename all into place (all or nothing
    as far as the file system allows: a failed write removes every temporary file)."""
    done: list[tuple[Path, Path]] = []
    try:
        for path, write in writers:
            tmp = _tmp_beside(path)
            done.append((tmp, path))
            write(tmp)
            if tmp.stat().st_size == 0:
                raise OSError(f"nothing was written to {path}")
    except BaseException:
        for tmp, _ in done:
            tmp.unlink(missing_ok=True)
        raise
    for tmp, path in done:
        os.replace(tmp, path)


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
    left, right = M.load_grey(args.left), M.load_grey(args.right)
    left, right = M.check_pair(left, right)
    gt = Q.check_gt(Q.load_disparity(args.gt, args.scale), left.shape)
    return left, right, gt


def _detect_kw(args) -> dict:
    return dict(corners=args.corners, threshold=args.threshold, k=args.k, nms=args.nms, d_max=args.max_disparity)


def cmd_evaluate(args: argparse.Namespace) -> int:
    """Handler of ``evaluate``."""
    try:
        writers = []
        if args.json is not None:
            args.json = _check_out_file(args.json)
        out_dir = None
        if args.output is not None:
            out_dir = Path(args.output)
            if out_dir.exists() and not out_dir.is_dir():
                raise ValueError(f"{out_dir} exists and is not a folder")
            parent = out_dir.parent if str(out_dir.parent) else Path(".")
            if not parent.is_dir():
                raise ValueError(f"cannot create {out_dir}: folder {parent} does not exist")
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
        if args.json is not None:
            writers.append((args.json, _json_writer(doc)))
        if out_dir is not None:
            writers.append((out_dir / "matches.png", _matches_writer(left, right, result, gt)))
            writers.append((out_dir / "disparity.png", _disparity_writer(left, result, gt)))
            if args.dense:
                writers.append((out_dir / "dense.png", _dense_writer(dense, gt, result["d_max"])))
        made = out_dir is not None and not out_dir.exists()
        if made:
            out_dir.mkdir()
        try:
            _commit(writers)
        except BaseException:
            if made:
                try:
                    out_dir.rmdir()
                except OSError:
                    pass
            raise
    except (ValueError, OSError) as exc:
        return _error(exc)
    s = result["scores"]
    bp = "n/a" if math.isnan(s.bad_percent) else f"{s.bad_percent:.2f} %"
    rms = "n/a" if math.isnan(s.rms) else f"{s.rms:.3f} px"
    print(f"corners: {len(result['left_xy'])} left, {len(result['right_xy'])} right (threshold code "
          f"{doc['threshold_code']}); disparities 0..{result['d_max']}")
    print(f"matches: {len(result['matches'])} ({s.good} good, {s.bad} bad, {s.unknown} without ground truth); "
          f"bad {bp}; RMS {rms}; matching {result['seconds'] * 1e3:.2f} ms")
    if args.dense:
        d = result["dense"]
        dbp = "n/a" if d["bad_percent"] is None else f"{d['bad_percent']:.2f} %"
        drms = "n/a" if d["rms"] is None else f"{d['rms']:.3f} px"
        print(f"dense SAD {args.dense_window}x{args.dense_window}: {d['evaluated']} pixels, bad {dbp}, "
              f"RMS {drms}, {d['seconds'] * 1e3:.1f} ms")
    for path, _ in writers:
        print(f"-> {path}")
    return 0


def _sweep_plot_writer(rows: list[dict], vary: str):
    def write(tmp: Path) -> None:
        fig = _figure(6.4, 4.0)
        ax = fig.add_subplot(111)
        labels = [("x".join(map(str, r["value"])) if isinstance(r["value"], list) else str(r["value"])) for r in rows]
        x = np.arange(len(rows))
        if vary in ("t_max", "rows"):
            x = np.array([r["value"] for r in rows], float)
        ax.plot(x, [r["matches"] for r in rows], "o-", label="matches")
        ax.plot(x, [r["good"] for r in rows], "s-", label="good")
        ax.plot(x, [r["bad"] for r in rows], "^-", label="bad (|e| > 1)")
        ax.set_xlabel(vary)
        if vary not in ("t_max", "rows"):
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
        print(f"{PROG}: error: argument --values: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2
    try:
        for p in (args.json, args.plot):
            if p is not None:
                _check_out_file(p)
        left, right, gt = _load(args)
        kw = {**_detect_kw(args), **_match_kw(args)}
        kw.pop(args.vary, None)
        rows = sweep_pair(left, right, gt, args.vary, values, repeat=args.repeat, **kw)
        writers = []
        if args.json is not None:
            writers.append((Path(args.json), _json_writer({"vary": args.vary, "rows": rows})))
        if args.plot is not None:
            writers.append((Path(args.plot), _sweep_plot_writer(rows, args.vary)))
        _commit(writers)
    except (ValueError, OSError) as exc:
        return _error(exc)
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
    p.add_argument("left", metavar="LEFT", help="rectified left image")
    p.add_argument("right", metavar="RIGHT", help="rectified right image (same size)")
    p.add_argument("gt", metavar="GT", help="ground-truth disparity of the left view (PGM/PNG, PFM or .npy)")
    p.add_argument("--scale", type=_pos_float, default=1.0,
                   help="GT value per pixel of disparity (Middlebury: 16 Tsukuba, 8 Venus; default 1); 0 = unknown")
    g = p.add_argument_group("corners (bit-true Harris model)")
    g.add_argument("--corners", type=lambda t: _num(t, int, 1, 100000, "--corners"), default=500,
                   help="aim at this many corners in the left image (default 500)")
    g.add_argument("--threshold", type=lambda t: _num(t, int, 0, (1 << 19) - 1, "--threshold"), default=None,
                   help="threshold code instead of --corners (same for both images)")
    g.add_argument("--k", type=lambda t: _num(t, float, 0, 255 / 256, "--k"), default=0.04,
                   help="Harris k (default 0.04)")
    g.add_argument("--nms", type=int, choices=(1, 3, 5), default=3, help="NMS window (default 3)")
    g = p.add_argument_group("matching")
    g.add_argument("--window", type=_window_arg, default=(9, 9), help="window WxH or N, odd (default 9x9)")
    g.add_argument("--t-max", dest="t_max", type=_pos_float, default=11.0,
                   help="accept SAD < t_max*W*H (SSD: < t_max^2*W*H; default 11)")
    g.add_argument("--cost", choices=M.COSTS, default="sad", help="cost function (default sad)")
    g.add_argument("--ncc-min", dest="ncc_min", type=lambda t: _num(t, float, -1, 1, "--ncc-min"), default=0.8,
                   help="NCC acceptance (default 0.8)")
    g.add_argument("--split", type=int, choices=M.SPLITS, default=1,
                   help="split correlation: 1 window, 5 or 9 windows (default 1)")
    g.add_argument("--rows", type=lambda t: _num(t, int, 0, 16, "--rows"), default=0,
                   help="also search +-ROWS rows (default 0)")
    g.add_argument("--lr-check", dest="lr_check", action="store_true", help="left-right consistency check")
    g.add_argument("--max-disparity", dest="max_disparity", type=lambda t: _num(t, int, 0, 100000, "--max-disparity"),
                   default=None, help="disparity range 0..D (default: ceil(max GT) + 1)")


def register(subparsers: Any) -> None:
    """Add the ``evaluate`` and ``sweep`` sub-commands to an ``argparse`` sub-parsers object."""
    p = subparsers.add_parser(
        "evaluate", help="feature matching on a stereo pair with ground truth: figures, JSON, PNGs",
        description="Harris corners (bit-true model) of both images, SAD/SSD/NCC matching along the rows "
                    "(thesis 7.3), RMS error and bad matches (|d - d_true| > 1) against the ground truth.")
    _add_common(p)
    p.add_argument("--json", type=Path, default=None, help="write the figures to this JSON file")
    p.add_argument("-o", "--output", type=Path, default=None,
                   help="folder for matches.png, disparity.png (and dense.png); created if missing")
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
                   help="comma list (t_max 5,9,11; window 5x7,9; split 1,5,9; cost sad,ncc) or a:b[:step] "
                        "for t_max and rows")
    q.add_argument("--repeat", type=lambda t: _num(t, int, 1, 100, "--repeat"), default=1,
                   help="time each matching this many times, keep the fastest (default 1)")
    q.add_argument("--json", type=Path, default=None, help="write the table to this JSON file")
    q.add_argument("--plot", type=Path, default=None, help="write a PNG plot of the table")
    q.set_defaults(func=cmd_sweep)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog=PROG, description="Sparse stereo matching evaluation (thesis 7.3).")
    register(parser.add_subparsers(dest="command", metavar="COMMAND", required=True))
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run ``evaluate``/``sweep``; returns the exit status (0 ok, 1 run-time error, 2 usage error)."""
    try:
        args = build_parser().parse_args(None if argv is None else [str(a) for a in argv])
    except SystemExit as e:
        return e.code if isinstance(e.code, int) else (0 if e.code is None else 2)
    try:
        return int(args.func(args))
    except KeyboardInterrupt:
        _error("interrupted")
        return 130
    except Exception as e:  # noqa: BLE001 - one line, never a traceback
        return _error(f"{type(e).__name__}: {e}")


if __name__ == "__main__":
    sys.exit(main())
