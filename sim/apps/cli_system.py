"""``eyestereo sim system``: the complete front end in a simulator on a stereo pair.

A command of ``eyestereo sim``, added by ``eyestereo.sim.apps.cli``.

``eyestereo sim system LEFT RIGHT -o OUT [--json FILE]``: both images, read by the library's one image rule
(:func:`eyestereo.sim.apps.cli_rectify.read_pair`: colour to grey, 16-bit to its 8 most significant used bits,
floating point refused) and resized to the camera size (``--size``, default 48x32, with the synthetic
rig's calibration of that size), are played by two camera models (18 and 17.9 MHz) through the whole
stereo_frontend (SRAM model, rectifier, stereo Harris, feature lists) in both modes (``--modes``); the
host driver reads every frame back over AXI4-Lite and compares it with the numpy chain. Writes
``OUT/rectified.png`` (the rectified pair side by side with row lines and the corners), ``OUT/matches.png``
(the host's feature lists matched by the matching package, coloured by disparity) and
``OUT/summary.json``; ``--json FILE`` the same figures (frames, fps per mode, SRAM share per master,
bit_exact). ``--dense D``: the front end built with the dense option (D disparities, below the camera
width): the host also takes every disparity map (compared bit for bit with the dense model of a rectified
pair) and ``OUT/disparity.png`` shows the last one (summary: ``dense``). ``--matcher``: the front end built with
the hardware matcher (issue 29: SAD 9x9, disparities 0 .. width / 4, the left-right check): the two images are
taken as a rectified pair and played as the rig's cameras see it (:func:`eyestereo.sim.lib.scenes.camera_views`,
so that the front end's rectification gives the pair back), every frame's match list is read by the host from
the list buffer and compared bit for bit with the model, and ``OUT/matches.png`` is drawn from the hardware's
list of the last frame (summary: ``hardware_matches``: the count and the host's read-out time of the list). A
one-screen summary on stdout.
Small frames keep it to a few minutes on 2 cores (GHDL runs the system at a few thousand clocks per second);
``--frames`` is 1..64 per mode.

Every input is checked before the build (images, sizes, the simulator, the bench's packages, the output
places); outputs are written all or nothing (``OUT`` and ``--json`` together), ``OUT`` new, empty or
holding only this command's files, never a folder holding the inputs; the simulations run in child
processes (:mod:`eyestereo.sim.apps.job`) that SIGINT/SIGTERM stop within a second or two, built in a fresh
folder under ``--build-dir`` (default ``$EYESTEREO_BUILD_DIR``, else the system's temporary folder), so
two runs at once never collide. Errors: one line, exit status 1 (bad input) or 2 (bad command line).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np

from eyestereo.sim.apps.cli_dense import disparities_arg, pu_of, write_picture
from eyestereo.sim.apps.cli_rectify import add_build_dir
from eyestereo.sim.lib.frontend_runs import CLOCKS, PUBLIC, SHORT_BLANKING, figures
from eyestereo.tools.cli.common import integer
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH
from eyestereo.tools.models.sgm import INVALID
from eyestereo.tools.models.sram_arbiter import MASTERS

MODES = ("sequential", "overlapped")
#: Stereo frames the host reads per mode, at most (each costs a camera frame and more of simulation).
MAX_FRAMES = 64
#: What the command writes into OUT.
OWNED = ("rectified.png", "matches.png", "summary.json", "disparity.png")
#: The camera timing of the command's runs (a short blanking: the small frames go fast).
TIMING = SHORT_BLANKING
#: The bench's Python packages beyond the library's own (named in the error when one is missing).
BENCH_PACKAGES = {"cocotbext.axi": "cocotbext-axi"}


def frame_size(text: str) -> tuple[int, int]:
    """A camera size for the front end, ``WxH``: width even, 16..352 x 16..288 (argparse type)."""
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WxH like 48x32, got {text!r}") from None
    if not (16 <= w <= FRAME_WIDTH and 16 <= h <= FRAME_HEIGHT and w % 2 == 0):
        raise argparse.ArgumentTypeError(f"size {text}: width even, 16..{FRAME_WIDTH} x 16..{FRAME_HEIGHT}")
    return w, h


def modes_list(text: str) -> list[str]:
    """``--modes``: a comma list of :data:`MODES` (argparse type)."""
    modes = [m.strip() for m in text.split(",") if m.strip()]
    bad = [m for m in modes if m not in MODES]
    if bad or not modes:
        raise argparse.ArgumentTypeError(f"choose from {', '.join(MODES)} (a comma list), got {text!r}")
    return list(dict.fromkeys(modes))


def add_system(sub: Any) -> None:
    """Add ``sim system`` to the ``sim`` group's subparsers (``eyestereo.sim.apps.cli.register`` calls it)."""
    p = sub.add_parser("system", help="the complete front end (cameras -> SRAM -> rectifier -> Harris -> lists) "
                       "in a simulator on a stereo pair", description=__doc__.splitlines()[0])
    p.add_argument("left", type=Path, help="left camera image (resized to --size)")
    p.add_argument("right", type=Path, help="right camera image, the same size")
    p.add_argument("-o", "--output", type=Path, required=True,
                   help="folder for rectified.png, matches.png, summary.json: new, empty, or holding only these")
    p.add_argument("--json", type=Path, help="also write the figures to this file (outside OUT)")
    p.add_argument("--size", type=frame_size, default=(48, 32), help="camera size WxH (default 48x32)")
    p.add_argument("--frames", type=integer(1, MAX_FRAMES, "--frames"), default=2,
                   help=f"stereo frames the host reads per mode, 1..{MAX_FRAMES} (default 2)")
    p.add_argument("--modes", type=modes_list, default=list(MODES), help="comma list of modes (default both)")
    p.add_argument("--sim", choices=("ghdl", "icarus", "verilator"), default=None,
                   help="simulator (default: the fastest here: Verilator on MyHDL's Verilog if installed, else GHDL)")
    p.add_argument("--dense", type=disparities_arg, metavar="D", default=None,
                   help="build the front end with the dense option, D disparities (below the width): the host also "
                        "reads the disparity maps (bit for bit against the model); OUT/disparity.png is the last")
    p.add_argument("--matcher", action="store_true",
                   help="build the front end with the hardware matcher: the images are a rectified pair (played as "
                        "the rig's cameras see it); OUT/matches.png shows the hardware's matches")
    add_build_dir(p)
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
    if not cv2.imwrite(str(path), img):
        raise ValueError(f"cannot write {path.name}")


def _matches_picture(rect: np.ndarray, features, path: Path) -> dict:
    """The matched features coloured by disparity: the host's feature lists (left and right corners of the
    last frame it read) matched by the matching package (:func:`eyestereo.tools.matching.sparse.match_features`,
    the defaults of ``eyestereo evaluate``: NCC 11x11 >= 0.75, left-right check, disparities 0 .. width / 4,
    same row) on the rectified pair it read. Each match is a filled dot on the left image at the left
    corner, a line to where its right corner lies, coloured by disparity (jet: blue near 0, red at the
    largest); unmatched corners are grey rings. Returns the count of corners and matches and the
    disparities' range (empty lists give no matches, not an error)."""
    from eyestereo.tools.matching.evaluate import DEFAULTS, default_d_max
    from eyestereo.tools.matching.sparse import match_features

    left = (rect & 0xFF).astype(np.uint8)
    right = (rect >> 8).astype(np.uint8)
    w = left.shape[1]
    fl = np.array([(x, y) for x, y, cam in features if cam == 0], np.int64).reshape(-1, 2)
    fr = np.array([(x, y) for x, y, cam in features if cam == 1], np.int64).reshape(-1, 2)
    disp = np.zeros(0, np.int64)
    lxy = rxy = np.zeros((0, 2), np.int64)
    if len(fl) and len(fr):
        m = match_features(left, right, fl, fr, window=DEFAULTS["window"], cost=DEFAULTS["cost"],
                           ncc_min=DEFAULTS["ncc_min"], lr_check=DEFAULTS["lr_check"], d_min=0,
                           d_max=default_d_max(w), rows=DEFAULTS["rows"])
        disp, lxy, rxy = m.disparity, m.left, m.right
    return _draw_matches(left, fl, lxy, rxy, disp, path, [len(fl), len(fr)])


def _hardware_matches_picture(rect: np.ndarray, features, matches, dy, path: Path) -> dict:
    """The hardware's match list of the last frame drawn as :func:`_matches_picture` draws the software's:
    ``matches`` (x, y, disparity, cost) and ``dy`` (the right corner's row - the left's) as the host read them."""
    left = (rect & 0xFF).astype(np.uint8)
    fl = np.array([(x, y) for x, y, cam in features if cam == 0], np.int64).reshape(-1, 2)
    n_right = sum(1 for *_, cam in features if cam == 1)
    m = np.asarray(matches, np.int64).reshape(-1, 4)
    lxy = m[:, :2]
    rxy = np.stack([m[:, 0] - m[:, 2], m[:, 1] + np.asarray(dy, np.int64)], axis=1)
    return _draw_matches(left, fl, lxy, rxy, m[:, 2], path, [len(fl), n_right])


def _draw_matches(left: np.ndarray, fl, lxy, rxy, disp, path: Path, corners: list[int]) -> dict:
    """Matches on the left image (see :func:`_matches_picture`); returns the counts and the disparities' range."""
    import cv2

    h, w = left.shape
    disp = np.asarray(disp, np.int64)
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
    if not cv2.imwrite(str(path), np.vstack([img, bar])):
        raise ValueError(f"cannot write {path.name}")
    return dict(corners=corners, matches=int(len(disp)),
                disparity=[int(disp.min()), int(disp.max())] if len(disp) else None)


def check_bench_packages() -> None:
    """ValueError naming the package to install when one the system bench needs is missing."""
    import importlib.util

    for module, package in BENCH_PACKAGES.items():
        try:
            found = importlib.util.find_spec(module) is not None
        except (ImportError, ValueError):
            found = False
        if not found:
            raise ValueError(f"'sim system' needs the Python package {package}: pip install {package}")


def run_mode(mode: str, work: Path, *, size, frames: int, sim: str,
             dense: int | None = None, matcher: bool = False) -> tuple[str, dict, Path]:
    """The job (:func:`eyestereo.sim.apps.job.run_jobs`) of one mode's run, in its own folder below ``work``;
    ``dense``: the dense option's D (None: off); ``matcher``: the matcher option (disparities 0 .. width / 4)."""
    w, h = size
    extra = {} if dense is None else dict(dense=True, disparities=dense, pu=pu_of(dense))
    if matcher:
        from eyestereo.tools.matching.evaluate import default_d_max

        extra.update(matcher=True, match_d_max=default_d_max(w), max_matches=255)
    folder = work / mode
    folder.mkdir()
    return ("eyestereo.sim.lib.runner:run_bench",
            dict(block="stereo_frontend", bench="tb_stereo_frontend",
                 config=dict(mode=mode, frames=frames, pair=[str(work / "left.npy"), str(work / "right.npy")],
                             timing=TIMING),
                 name=f"cli_{mode}_{w}x{h}",
                 params=dict(quantizers=f"rig:{w}x{h}", max_features=255, **extra),
                 build_root=folder / "build", log_file=folder / f"{mode}.log", sim=sim,
                 public=PUBLIC if sim == "verilator" else None),
            folder)


def simulate(left: np.ndarray, right: np.ndarray, folder: Path, work: Path, *, size=(48, 32), frames: int = 2,
             modes=MODES, sim: str = "ghdl", dense: int | None = None, matcher: bool = False) -> dict:
    """Run the system on an 8-bit grey pair (any size, resized to ``size``) in ``work`` (a run folder of
    :func:`eyestereo.sim.apps.job.run_folder`) and write the pictures and summary.json into ``folder``;
    returns the summary. :class:`eyestereo.sim.apps.job.JobFailed` when a simulation fails."""
    import cv2

    from eyestereo.sim.apps.job import run_jobs
    from eyestereo.sim.lib.runner import describe
    from eyestereo.tools.camera import CameraTiming
    from eyestereo.tools.io import atomic_write_text

    w, h = size
    pair = [cv2.resize(img, (w, h), interpolation=cv2.INTER_AREA).astype(np.uint8) for img in (left, right)]
    if matcher:  # a rectified pair, as the rig's cameras see it: the front end's rectification gives it back
        from eyestereo.hdl.rectify.calibration import calibration_param
        from eyestereo.sim.lib.scenes import camera_views

        pair = camera_views(calibration_param(f"rig:{w}x{h}", None, None), *pair)
    for name, img in zip(("left", "right"), pair):
        np.save(work / f"{name}.npy", img)
    jobs = [run_mode(m, work, size=size, frames=frames, sim=sim, dense=dense, matcher=matcher) for m in modes]
    # GHDL: both modes at once (2 cores); a Verilator build already uses both cores: one after the other
    reps = dict(zip(modes, run_jobs(jobs, at_once=1 if sim == "verilator" else 2, what=f"the simulation "
                                    f"({describe(sim)})")))
    ct = CameraTiming(width=w, height=h, **TIMING)
    figs = {m: figures(r, ct) for m, r in reps.items()}
    last = reps[modes[-1]]["last"]
    _picture(np.array(last["rect"], np.int64), last["features"], folder / "rectified.png")
    if matcher:
        matched = _hardware_matches_picture(np.array(last["rect"], np.int64), last["features"], last["matches"],
                                            last["dy"], folder / "matches.png")
    else:
        matched = _matches_picture(np.array(last["rect"], np.int64), last["features"], folder / "matches.png")
    summary = dict(size=f"{w}x{h}", frames={m: len(r["frames"]) for m, r in reps.items()},
                   fps={m: f["fps"] for m, f in figs.items()},
                   sram_share={m: f["sram_share"] for m, f in figs.items()},
                   sram_busy={m: f["sram_busy"] for m, f in figs.items()},
                   features_last_frame=len(last["features"]), matches_last_frame=matched,
                   bit_exact=all(r["bit_exact"] for r in reps.values()), simulator=describe(sim),
                   clocks=CLOCKS)
    if matcher:
        fr = reps[modes[-1]]["frames"]
        summary["hardware_matches"] = dict(
            matches_last_frame=int(fr[-1]["matches"]), candidates_last_frame=int(fr[-1]["candidates"]),
            match_words_last_frame=int(fr[-1]["match_words"]),
            read_out_us={m: round(sum(f["match_read_ns"] for f in r["frames"]) / len(r["frames"]) / 1e3, 2)
                         for m, r in reps.items()})
    if dense is not None:
        codes = np.array(last["disparity"], np.int64)
        valid = codes != INVALID
        write_picture(folder / "disparity.png", np.where(valid, codes / 16.0, np.nan), dense)
        summary["dense"] = dict(disparities=dense, maps_read={m: len(r["frames"]) for m, r in reps.items()},
                                maps_completed={m: r.get("disp_frames") for m, r in reps.items()},
                                valid_last_map=round(float(valid.mean()), 4))
    atomic_write_text(folder / "summary.json", json.dumps(summary, indent=2) + "\n")
    return summary


def main_system(left: Path, right: Path, output: Path, *, size=(48, 32), frames: int = 2, modes=MODES,
                sim: str | None = None, json_file: Path | None = None, build_dir: Path | None = None,
                dense: int | None = None, matcher: bool = False) -> dict:
    """The command's work for a library caller (``make demo``): check every input, run, write ``output``
    (and ``json_file``) all or nothing; returns the summary. ValueError for bad input or a failed run."""
    from eyestereo.sim.apps.cli_rectify import read_pair
    from eyestereo.sim.apps.job import check_build_dir, run_folder
    from eyestereo.sim.lib.runner import check_simulator, fastest_simulator
    from eyestereo.tools.io import Outputs

    modes = list(modes)
    if not modes or any(m not in MODES for m in modes):
        raise ValueError(f"modes must be taken from {', '.join(MODES)}, got {modes}")
    if not 1 <= int(frames) <= MAX_FRAMES:
        raise ValueError(f"frames must be 1..{MAX_FRAMES}, got {frames}")
    if dense is not None and dense >= size[0]:
        raise ValueError(f"--dense {dense}: the {size[0]}-pixel rows must be wider than the disparities")
    lg, rg = read_pair(left, right)
    sim = check_simulator(sim or fastest_simulator())
    check_bench_packages()
    check_build_dir(build_dir)
    with Outputs() as out:
        folder = out.folder(output, OWNED, inputs=[left, right])
        js = out.file(json_file) if json_file is not None else None
        with run_folder("sim-system", build_dir) as work:
            summary = simulate(lg, rg, folder, work, size=size, frames=int(frames), modes=modes, sim=sim,
                               dense=dense, matcher=bool(matcher))
        if js is not None:
            js.write_text(json.dumps(summary, indent=2) + "\n")
    return summary


def cmd_sim_system(args) -> int:
    w, h = args.size
    summary = main_system(args.left, args.right, args.output, size=args.size, frames=args.frames, modes=args.modes,
                          sim=args.sim, json_file=args.json, build_dir=args.build_dir, dense=args.dense,
                          matcher=args.matcher)
    print(f"stereo front end, {w}x{h} cameras (18 / 17.9 MHz), memory 100 MHz, Harris 50 MHz "
          f"({summary['simulator']}, simulated time)")
    for m in args.modes:
        sh = summary["sram_share"][m]
        print(f"  {m:11s} frames {summary['frames'][m]}  fps {summary['fps'][m]:8.1f}  SRAM busy "
              f"{100 * summary['sram_busy'][m]:5.1f} %  " + " ".join(f"{x} {100 * sh[x]:.1f}%" for x in MASTERS))
    mt = summary["matches_last_frame"]
    print(f"  features in the last frame: {summary['features_last_frame']}, matched {mt['matches']} "
          f"(disparities {mt['disparity']}); bit-exact: {'yes' if summary['bit_exact'] else 'no'}; "
          f"pictures: {args.output}/rectified.png, matches.png")
    if args.matcher:
        hm = summary["hardware_matches"]
        print(f"  hardware matcher: {hm['matches_last_frame']} matches in the last frame's list (drawn in "
              f"matches.png), {hm['match_words_last_frame']} words; the host read the list in "
              + ", ".join(f"{m} {v} us" for m, v in hm["read_out_us"].items()) + " (bit for bit the model's)")
    if args.dense is not None:
        d = summary["dense"]
        print(f"  dense: D {d['disparities']}, disparity maps read {sum(d['maps_read'].values())} (each bit for bit "
              f"the model's), {100 * d['valid_last_map']:.1f} % valid in the last; {args.output}/disparity.png")
    return 0
