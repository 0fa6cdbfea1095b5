"""``eyestereo sim system``: the complete front end's VHDL in GHDL on a stereo pair (added by ``eyestereo.sim.cli``).

``eyestereo sim system LEFT RIGHT -o OUT [--json FILE]``: both images, resized to the camera size
(``--size``, default 48x32, with the synthetic rig's calibration of that size), are played by two camera
models (18 and 17.9 MHz) through the whole stereo_frontend (SRAM model, rectifier, stereo Harris, feature
lists) in both modes (``--modes``); the host driver reads every frame back over AXI4-Lite and compares it
with the numpy chain. Writes ``OUT/rectified.png`` (the rectified pair side by side with row lines and
the corners), ``OUT/matches.png`` (the host's feature lists matched by the matching package, coloured by
disparity) and ``OUT/summary.json``; ``--json FILE`` the same figures (frames, fps per mode, SRAM share
per master, bit_exact). A one-screen summary on stdout. Small frames keep it to a few minutes on 2 cores
(GHDL runs the system at a few thousand clocks per second). Errors: one line, exit status 1, nothing
written.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

from eyestereo.tools.models.sram_arbiter import MASTERS

MODES = ("sequential", "overlapped")


def frame_size(text: str) -> tuple[int, int]:
    """A camera size for the front end, ``WxH``: width even, 16..352 x 16..288 (argparse type)."""
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WxH like 48x32, got {text!r}") from None
    if not (16 <= w <= 352 and 16 <= h <= 288 and w % 2 == 0):
        raise argparse.ArgumentTypeError(f"size {text}: width even, 16..352 x 16..288")
    return w, h


def add_system(sub: Any) -> None:
    """Add ``sim system`` to the ``sim`` group's subparsers (``eyestereo.sim.cli.register`` calls it)."""
    p = sub.add_parser("system", help="the complete front end (cameras -> SRAM -> rectifier -> Harris -> lists) "
                       "in GHDL on a stereo pair", description=__doc__.splitlines()[0])
    p.add_argument("left", type=Path, help="left camera image (resized to --size)")
    p.add_argument("right", type=Path, help="right camera image")
    p.add_argument("-o", "--output", type=Path, required=True, help="folder for rectified.png and summary.json")
    p.add_argument("--json", type=Path, help="also write the figures to this file")
    p.add_argument("--size", type=frame_size, default=(48, 32), help="camera size WxH (default 48x32)")
    p.add_argument("--frames", type=int, default=2, help="stereo frames the host reads per mode (default 2)")
    p.add_argument("--modes", default="sequential,overlapped", help="comma list of modes (default both)")
    p.add_argument("--sim", choices=("ghdl", "icarus", "verilator"), default=None,
                   help="simulator (default: the fastest here: Verilator on MyHDL's Verilog if installed, else GHDL)")
    p.set_defaults(func=cmd_sim_system)


def _picture(rect: np.ndarray, features, path: Path) -> None:
    import cv2

    left = (rect & 0xFF).astype(np.uint8)
    right = (rect >> 8).astype(np.uint8)
    h, w = left.shape
    s = max(1, 480 // w)
    img = cv2.cvtColor(np.hstack([left, right]), cv2.COLOR_GRAY2BGR)
    img = cv2.resize(img, (2 * w * s, h * s), interpolation=cv2.INTER_NEAREST)
    for y in range(0, h * s, max(s * 4, 8)):
        cv2.line(img, (0, y), (2 * w * s - 1, y), (0, 160, 0), 1)
    for x, y, cam in features:
        cv2.circle(img, ((x + cam * w) * s + s // 2, y * s + s // 2), max(2, s), (0, 0, 255), 1)
    cv2.imwrite(str(path), img)


def _matches_picture(rect: np.ndarray, features, path: Path) -> dict:
    """The matched features coloured by disparity: the host's feature lists (left and right corners of the
    last frame it read) matched by the matching package (:func:`eyestereo.tools.matching.sparse.match_features`,
    the defaults of ``eyestereo evaluate``: NCC 11x11 >= 0.75, left-right check, disparities 0 .. width / 4,
    same row) on the rectified pair it read. Each match is a filled dot on the left image at the left
    corner, a line to where its right corner lies, coloured by disparity (jet: blue near 0, red at the
    largest); unmatched corners are grey rings. Returns the count of corners and matches and the
    disparities' range (empty lists give no matches, not an error)."""
    import cv2

    from eyestereo.tools.matching.evaluate import DEFAULTS, default_d_max
    from eyestereo.tools.matching.sparse import match_features

    left = (rect & 0xFF).astype(np.uint8)
    right = (rect >> 8).astype(np.uint8)
    h, w = left.shape
    fl = np.array([(x, y) for x, y, cam in features if cam == 0], np.int64).reshape(-1, 2)
    fr = np.array([(x, y) for x, y, cam in features if cam == 1], np.int64).reshape(-1, 2)
    disp = np.zeros(0, np.int64)
    lxy = rxy = np.zeros((0, 2), np.int64)
    if len(fl) and len(fr):
        m = match_features(left, right, fl, fr, window=DEFAULTS["window"], cost=DEFAULTS["cost"],
                           ncc_min=DEFAULTS["ncc_min"], lr_check=DEFAULTS["lr_check"], d_min=0,
                           d_max=default_d_max(w), rows=DEFAULTS["rows"])
        disp, lxy, rxy = m.disparity, m.left, m.right
    s = max(1, 480 // w)
    img = cv2.cvtColor(left, cv2.COLOR_GRAY2BGR)
    img = cv2.resize(img, (w * s, h * s), interpolation=cv2.INTER_NEAREST)
    img = (img * 0.7).astype(np.uint8)
    d_hi = max(1, int(disp.max())) if len(disp) else 1
    for x, y in fl:
        cv2.circle(img, (int(x) * s + s // 2, int(y) * s + s // 2), max(3, s), (160, 160, 160), 1)
    for (xl, yl), (xr, yr), d in zip(lxy, rxy, disp):
        c = cv2.applyColorMap(np.array([[int(255 * d / d_hi)]], np.uint8), cv2.COLORMAP_JET)[0, 0].tolist()
        pl = (int(xl) * s + s // 2, int(yl) * s + s // 2)
        cv2.line(img, pl, (int(xr) * s + s // 2, int(yr) * s + s // 2), c, 1)
        cv2.circle(img, pl, max(3, s), c, -1)
    bar = cv2.applyColorMap(np.tile(np.linspace(0, 255, w * s).astype(np.uint8), (12, 1)), cv2.COLORMAP_JET)
    cv2.putText(bar, f"d = 0 .. {d_hi}", (4, 10), cv2.FONT_HERSHEY_SIMPLEX, 0.35, (255, 255, 255), 1)
    cv2.imwrite(str(path), np.vstack([img, bar]))
    return dict(corners=[len(fl), len(fr)], matches=int(len(disp)),
                disparity=[int(disp.min()), int(disp.max())] if len(disp) else None)


def main_system(left: Path, right: Path, output: Path, *, size=(48, 32), frames: int = 2,
                modes=("sequential", "overlapped"), sim: str | None = None) -> dict:
    """Run the system (see the module doc) and write OUTPUT/; returns the summary. Raises AssertionError
    when the simulation fails."""
    from eyestereo.sim.bench_stereo_frontend import PUBLIC, figures, sim_label
    from eyestereo.sim.runner import fastest_simulator, run_bench
    from eyestereo.tools.camera import CameraTiming

    w, h = size
    sim = sim or fastest_simulator()
    timing = dict(h_blank=64, v_sync=1, v_back=1, v_front=1)
    tmp = Path(tempfile.mkdtemp(prefix=".system.", dir=Path(output).parent))
    try:
        def one(mode):
            return run_bench("stereo_frontend", "tb_stereo_frontend",
                             dict(mode=mode, frames=frames, images=f"files:{Path(left).resolve()},{Path(right).resolve()}",
                                  timing=timing),
                             name=f"cli_{mode}_{w}x{h}", params=dict(quantizers=f"rig:{w}x{h}", feature_words=512,
                                                                     max_features=255),
                             log_file=tmp / f"{mode}.log", sim=sim, public=PUBLIC if sim == "verilator" else None)

        # GHDL: both modes at once (2 cores); a Verilator build already uses both cores: one after the other
        with ThreadPoolExecutor(1 if sim == "verilator" else 2) as ex:
            reps = dict(zip(modes, ex.map(one, modes)))
        ct = CameraTiming(width=w, height=h, **timing)
        figs = {m: figures(r, ct) for m, r in reps.items()}
        last = reps[modes[-1]]["last"]
        _picture(np.array(last["rect"], np.int64), last["features"], tmp / "rectified.png")
        matched = _matches_picture(np.array(last["rect"], np.int64), last["features"], tmp / "matches.png")
        summary = dict(size=f"{w}x{h}", frames={m: len(r["frames"]) for m, r in reps.items()},
                       fps={m: f["fps"] for m, f in figs.items()},
                       sram_share={m: f["sram_share"] for m, f in figs.items()},
                       sram_busy={m: f["sram_busy"] for m, f in figs.items()},
                       features_last_frame=len(last["features"]), matches_last_frame=matched,
                       bit_exact=all(r["bit_exact"] for r in reps.values()), simulator=sim_label(sim),
                       clocks={"memory": 100.0, "harris": 50.0, "camera_l": 18.0, "camera_r": 17.9})
        (tmp / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
        for m in modes:
            (tmp / f"{m}.log").unlink(missing_ok=True)
            (tmp / f"{m}.build.log").unlink(missing_ok=True)
        if Path(output).exists():
            shutil.rmtree(output)
        tmp.rename(output)
        tmp = None
        return summary
    finally:
        if tmp is not None:
            shutil.rmtree(tmp, ignore_errors=True)


def cmd_sim_system(args) -> int:
    modes = [m.strip() for m in args.modes.split(",") if m.strip()]
    bad = [m for m in modes if m not in MODES]
    if bad or not modes:
        print(f"error: --modes: choose from {list(MODES)}, got {args.modes!r}", file=sys.stderr)
        return 1
    for f in (args.left, args.right):
        if not f.is_file():
            print(f"error: {f}: no such image", file=sys.stderr)
            return 1
    if args.frames < 1:
        print("error: --frames must be at least 1", file=sys.stderr)
        return 1
    if not args.output.parent.is_dir():
        print(f"error: {args.output.parent}: no such folder", file=sys.stderr)
        return 1
    w, h = args.size
    try:
        summary = main_system(args.left, args.right, args.output, size=args.size, frames=args.frames, modes=modes,
                              sim=args.sim)
    except (AssertionError, RuntimeError) as e:
        print(f"error: the system simulation failed ({str(e).splitlines()[0][:200]})", file=sys.stderr)
        return 1
    if args.json:
        args.json.write_text(json.dumps(summary, indent=2) + "\n")
    print(f"stereo front end, {w}x{h} cameras (18 / 17.9 MHz), memory 100 MHz, Harris 50 MHz "
          f"({summary['simulator']}, simulated time)")
    for m in modes:
        sh = summary["sram_share"][m]
        print(f"  {m:11s} frames {summary['frames'][m]}  fps {summary['fps'][m]:8.1f}  SRAM busy "
              f"{100 * summary['sram_busy'][m]:5.1f} %  " + " ".join(f"{x} {100 * sh[x]:.1f}%" for x in MASTERS))
    mt = summary["matches_last_frame"]
    print(f"  features in the last frame: {summary['features_last_frame']}, matched {mt['matches']} "
          f"(disparities {mt['disparity']}); bit-exact: {'yes' if summary['bit_exact'] else 'no'}; "
          f"pictures: {args.output}/rectified.png, matches.png")
    return 0
