"""Benchmark: the complete front end's frame rate in simulated time, both modes (docs/system.md, build/system/framerate.json).

Runs sim/benches/tb_stereo_frontend.py at the thesis's clocks (cameras 18 and 17.9 MHz, memory 100 MHz, Harris
50 MHz) on the fastest simulator here (Verilator on MyHDL's Verilog of the top, ``--sim``), the host
reading every frame it gets back through the AXI4-Lite bus (15 bus clocks per SRAM word) and checking it
bit for bit against the numpy chain:

* **full frames** (``--size``, default 352x288 with the OV6630's real blanking: 50 frames/s per camera)
  in both modes, ``--frames`` host frames per mode (sequential ``--frames``, overlapped ``--frames-ovl``);
* **small frames** (``--small``, default 48x32, short blanking, 3 frames per mode), from which the old
  linear-in-pixels derivation of the full-frame figures is kept as a cross-check of the measurement;
* the **closed threshold loop** (``--adaptive-frames``, sequential, ``--adaptive-size``): the host's
  SecantController on the FCOUNT window, the feature count settling to its target, plotted;
* **GHDL's speed** on the full-size top (``--ghdl-speed US``: the bench's speed probe, US microseconds
  of simulated time on GHDL_BACKEND=llvm) and, if one has been run (``--ghdl-frame MODE``, hours), the
  full frame on GHDL;
* a **real scene with more corners than a list holds** (``--real MODES``, issue 30): a real stereo pair
  (``--real-pair LEFT RIGHT``, default Middlebury Tsukuba from ../shared/data) resized to ``--real-size``
  (default 352x288, ``cv2.INTER_AREA`` as the bench's ``files:``), handed to the bench as ``pair`` (.npy),
  threshold code ``--real-threshold`` (default 16), lists of 255 features: every list is cut (overflow flag
  in its trailer, ``list_overflows``), bit-exact. Only these runs; their section of ``--out`` is replaced in
  place (the other sections are left as they are) and kept in build/system/runs/ for later full rewrites.

Measured: the frame period of each mode (sequential: start to start, the host's read-out included, one
stage after the other; overlapped: the interval between completed frames, the feature list's
``frame_done``), the sequencer's FRAME_CLOCKS, the stage times from probes inside the top, the host
read-out time, the arbiter's per-master word counts (SRAM share), the wall time and the simulation
speed. Every run's report is kept in build/system/runs/ (``--reuse`` takes them from there).

    python -m eyestereo.sim.measure.bench_stereo_frontend [--sim verilator] [--size 352x288] [--frames 2]
        [--small 48x32] [--adaptive-frames 16] [--ghdl-speed 200] [--reuse] [--out docs/system.md]
    python -m eyestereo.sim.measure.bench_stereo_frontend --single-clock [--size 352x288] [--frames 2] [--frames-ovl 3]
    python -m eyestereo.sim.measure.bench_stereo_frontend --dense [--memory sram] [--rectify fetch] [--frames 1]
        [--frames-ovl 3] [--options-out docs/dense.md]
    python -m eyestereo.sim.measure.bench_stereo_frontend --matcher [--size 352x288] [--frames 2] [--frames-ovl 3]
    python -m eyestereo.sim.measure.bench_stereo_frontend --real sequential,overlapped [--real-frames 1]
        [--real-pair LEFT RIGHT] [--real-size 352x288] [--real-threshold 16] [--sim verilator] [--reuse]
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import sys
import time
from pathlib import Path

from eyestereo.hdl.system.stereo_frontend import CAM_DEPTH
from eyestereo.sim.apps.cli_system import frame_size
from eyestereo.sim.lib.frontend_runs import CLOCKS, PUBLIC, SHORT_BLANKING, figures
from eyestereo.sim.lib.runner import ROOT, fastest_simulator, hdl_revision, revision_note, run_bench
from eyestereo.tools.camera import CameraTiming
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH
from eyestereo.tools.models.sram_arbiter import MASTERS

THESIS_FPS = 20.01
FULL = (FRAME_WIDTH, FRAME_HEIGHT)
SHORT = SHORT_BLANKING
RUNS = ROOT / "build" / "system" / "runs"
SPEED_SKIP_US = 1200  # the speed probe's window starts here: the cameras' active lines
SIM_NAMES = {"verilator": "Verilator (MyHDL's Verilog of the top)", "icarus": "Icarus Verilog",
             "ghdl": "GHDL (mcode)", "ghdl-llvm": "GHDL (LLVM back end, -O2)"}


def timing_of(size: str) -> dict:
    """The camera timing of a size: the real OV6630 blanking at 352x288, the short one otherwise."""
    return {} if tuple(int(v) for v in size.split("x")) == FULL else dict(SHORT)


def sim_label(sim: str, backend: str | None = None) -> str:
    return SIM_NAMES["ghdl-llvm" if sim == "ghdl" and backend == "llvm" else sim]


def _kept(tag: str) -> Path:
    return RUNS / f"{tag}.json"


def run_mode(mode: str, size: str, frames: int, timing: dict, sim: str, reuse: bool = False,
             backend: str | None = None, single_clock: bool = False, options: dict | None = None, **extra) -> dict:
    """One bench run, its report kept in build/system/runs/ (with the wall time and the simulator);
    ``single_clock``: the top built with harris_stereo in the memory clock (issue 23's option); ``options``: more
    parameters of the top (``memory``, ``rectify``: issue 26's front-end options)."""
    options = dict(options or {})
    opt_tag = "".join(f"_{v}" for _, v in sorted(options.items()))
    tag = (f"{sim}{'-' + backend if backend else ''}_{mode}_{size}" + ("_speed" if extra.get("speed_us") else "")
           + ("_single" if single_clock else "") + opt_tag)
    kept = _kept(tag)
    if reuse and kept.is_file():
        rep = json.loads(kept.read_text())
        if extra.get("speed_us") or len(rep.get("frames", [])) == frames:
            return rep
    RUNS.mkdir(parents=True, exist_ok=True)
    t0 = time.time()
    print(f"[bench] {tag}: {frames} frame(s) on {sim_label(sim, backend)} ...", flush=True)
    full = tuple(int(v) for v in size.split("x")) == FULL
    # full frames: a threshold leaving at most 200 features per camera (the lists hold 255)
    rep = run_bench("stereo_frontend", "tb_stereo_frontend",
                    dict(dict(mode=mode, frames=frames, images="shift:3", timing=timing, target=200 if full else 40,
                              require_features=not extra.get("speed_us")), **extra),
                    name=f"bench_{mode}_{size}" + ("_speed" if extra.get("speed_us") else "") +
                    ("_single" if single_clock else "") + opt_tag, sim=sim, backend=backend,
                    params=dict(quantizers=f"rig:{size}", feature_words=512, max_features=255,
                                **(dict(single_clock=True) if single_clock else {}), **options),
                    log_file=RUNS / f"{tag}.log", public=PUBLIC if sim == "verilator" else None)
    # the speed probe's own wall_s is the probe's time alone; the run's (build included) beside it
    rep["wall_total_s" if rep.get("speed") else "wall_s"] = round(time.time() - t0, 1)
    rep["simulator"] = sim_label(sim, backend)
    rep.pop("last", None)
    RUNS.mkdir(parents=True, exist_ok=True)
    kept.write_text(json.dumps(rep) + "\n")
    print(f"[bench] {tag}: done in {rep['wall_s']} s", flush=True)
    return rep


def full_frame(seq: dict, ovl: dict) -> dict:
    """Full 352x288 figures derived from small-frame ones (linear in pixels) and the real camera: the
    cross-check of the full-frame measurement."""
    cam = CameraTiming()  # the OV6630's 352x288 timing: 50 frames/s at 18 MHz
    cam_ms = cam.frame_pclk / 18e3
    scale = FULL[0] * FULL[1] / seq["pixels"]
    # sequential: what is not the camera's capture, per pixel, times the full frame, plus one camera frame
    # and on average half a frame waiting for the next VSYNC after arming
    small_cam = seq["camera_frame_us"] / 1e3
    rest_ms = max(0.0, seq["period_us"] / 1e3 - 1.5 * small_cam)
    seq_ms = rest_ms * scale + 1.5 * cam_ms
    rect = seq.get("stages", {}).get("rectify_us")
    read_ms = ovl["read_out_us"] / 1e3 * scale
    return dict(camera_ms=round(cam_ms, 2), sequential_ms=round(seq_ms, 2), sequential_fps=round(1e3 / seq_ms, 1),
                host_read_out_ms=round(read_ms, 2),
                rectify_ms=None if rect is None else round(rect / 1e3 * scale, 2),
                overlapped_fps_bound=round(min(1e3 / cam_ms, 1e3 / read_ms), 1))


# --- the closed threshold loop ---------------------------------------------------------------------
ADAPTIVE_TARGET = 4.0  # features per block wanted
SETTLE_TOL = 0.2       # settled: the total within +-20 % of its target from that frame on


def run_adaptive(frames: int, size: str, sim: str, reuse: bool) -> dict:
    """The host's closed threshold loop (SecantController on FCOUNT, thesis 7.2) over ``frames`` frames."""
    tag = f"{sim}_adaptive_{size}"
    kept = _kept(tag)
    if reuse and kept.is_file():
        rep = json.loads(kept.read_text())
        if len(rep["frames"]) == frames:
            return rep
    RUNS.mkdir(parents=True, exist_ok=True)
    t0 = time.time()
    print(f"[bench] {tag}: {frames} frames on {sim_label(sim)} ...", flush=True)
    # the initial thresholds leave at most 8 features per camera: the loop has to pull the count up
    rep = run_bench("stereo_frontend", "tb_stereo_frontend",
                    dict(mode="sequential", frames=frames, images="shift:3", adaptive=ADAPTIVE_TARGET, target=8,
                         timing=dict(SHORT, h_blank=8), require_features=True),
                    name=f"bench_adaptive_{size}", sim=sim,
                    params=dict(quantizers=f"rig:{size}", feature_words=512, max_features=255),
                    log_file=RUNS / f"{tag}.log", public=PUBLIC if sim == "verilator" else None)
    rep["wall_s"] = round(time.time() - t0, 1)
    rep["simulator"] = sim_label(sim)
    rep["size"] = size
    rep.pop("last", None)
    RUNS.mkdir(parents=True, exist_ok=True)
    kept.write_text(json.dumps(rep) + "\n")
    return rep


def settling(totals: list[int], target: float, tol: float = SETTLE_TOL) -> int | None:
    """The first frame from which every total stays within +-tol * target (None: never)."""
    from eyestereo.tools.matching.adaptive import settling_frames

    return settling_frames(totals, 0, target, tol=tol)


def adaptive_section(rep: dict, img: Path) -> list[str]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    tot = [f["totals"] for f in rep["frames"]]
    target = 16 * ADAPTIVE_TARGET
    s_l, s_r = settling([t[0] for t in tot], target), settling([t[1] for t in tot], target)
    fig, ax = plt.subplots(figsize=(6, 3.2), dpi=90)
    ax.plot([t[0] for t in tot], "o-", label="left")
    ax.plot([t[1] for t in tot], "s-", label="right")
    ax.axhline(target, color="k", ls="--", label="target")
    ax.axhspan(target * (1 - SETTLE_TOL), target * (1 + SETTLE_TOL), color="0.9", label=f"±{SETTLE_TOL:.0%}")
    ax.set_xlabel("frame")
    ax.set_ylabel("features (FEATURES register)")
    ax.set_title(f"closed loop on {rep.get('simulator', '?')}, {rep.get('size', '?')}", fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    img.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(img)
    plt.close(fig)
    rows = [f"| {i} | {f['rect_pair'][0]} | {t[0]} | {t[1]} | {min(f['thresholds'][0])}..{max(f['thresholds'][0])} | "
            f"{min(f['thresholds'][1])}..{max(f['thresholds'][1])} |"
            for i, (t, f) in enumerate(zip(tot, rep["frames"]))]

    def said(s):
        return f"from frame {s} on" if s is not None else "not within the run"

    size = rep.get("size", "?")
    return ["## Closed-loop adaptive thresholds", "",
            f"Sequential mode, {size} cameras ({len(tot)} consecutive frames of a moving random-texture scene: "
            "the scene moves a pixel per camera frame, so every block's content changes from frame to frame), "
            f"{rep.get('simulator', '?')}, {rep.get('wall_s', '?')} s wall. The host runs the matching package's "
            f"`SecantController` (tools/matching/adaptive.py) on the FCOUNT window: target {ADAPTIVE_TARGET:g} "
            f"features per block ({target:.0f} per camera); each frame's 16 + 16 thresholds are written over the "
            "bus before the next start, and every frame is bit-exact with the model run on the thresholds it ran "
            "with. The first thresholds (one code for all blocks, chosen with the model) leave at most 8 features "
            "per camera: the loop has to find the target from far below.", "",
            f"**Settling criterion:** the camera's total (FEATURES) stays within ±{SETTLE_TOL:.0%} of the target "
            f"({target * (1 - SETTLE_TOL):.0f}..{target * (1 + SETTLE_TOL):.0f}) from that frame to the end of the "
            f"run. Measured: left {said(s_l)}, right {said(s_r)}.", "",
            f"![adaptive](img/system/{img.name})", "",
            "| frame | camera frame captured | features left | features right | threshold codes left | right |",
            "|---:|---:|---:|---:|---:|---:|", *rows, ""]


# --- a real scene with more corners than a list holds (issue 30) ------------------------------------
SHARED = ROOT.parent / "shared" / "data" / "middlebury"
REAL_PAIR = (SHARED / "tsukuba" / "im3.png", SHARED / "tsukuba" / "im4.png")
REAL_THRESHOLD = 16       # threshold code of every block: several hundred corners per frame in Tsukuba
REAL_MAX_FEATURES = 255   # the lists of the full-frame runs (feature_words 512)
REAL_TITLE = "## A real scene with more corners than a list holds"


def real_pair_arrays(files, size: str):
    """The Y planes (uint8, the camera size) of a real stereo pair: the library's image-input rule
    (``read_image`` grey, ``to_grey8`` on the pair), resized with ``cv2.INTER_AREA`` as the bench's ``files:``."""
    import cv2

    from eyestereo.tools.io import read_image, to_grey8

    w, h = (int(v) for v in size.split("x"))
    imgs = to_grey8([read_image(f, grey=True) for f in files], [str(f) for f in files])
    return [cv2.resize(img, (w, h), interpolation=cv2.INTER_AREA) for img in imgs]


def real_model(left, right, size: str, threshold: int, max_features: int) -> dict:
    """What the model finds in the pair (the bench's chain and parameters): per camera totals, listed, overflow."""
    from eyestereo.hdl.rectify.calibration import calibration_param
    from eyestereo.sim.lib.frontend_model import model_params
    from eyestereo.tools.camera import yuv_frame
    from eyestereo.tools.models import stereo_frontend as model
    from eyestereo.tools.models.harris_mono import k_code

    cal = calibration_param(f"rig:{size}", None, None)
    m = model.stereo_frontend(cal, yuv_frame(left), yuv_frame(right), k_code(0.04), [threshold] * 16,
                              **model_params(dict(max_features=max_features)))["list"]
    return dict(totals=[int(v) for v in m["totals"]], listed=len(m["features"]), overflow=bool(m["overflow"]))


def uncommitted_hdl() -> list[str]:
    """The files of ``hdl/`` and ``tools/models/`` with uncommitted changes (what a ``+`` after the revision
    stands for; ``git status``, read only)."""
    import subprocess

    try:
        out = subprocess.run(["git", "status", "--porcelain", "hdl", "tools/models"], cwd=ROOT, capture_output=True,
                             text=True).stdout
    except OSError:
        return []
    return sorted(line[3:].strip() for line in out.splitlines() if line.strip())


def run_real(mode: str, size: str, frames: int, sim: str, *, files=REAL_PAIR, threshold: int = REAL_THRESHOLD,
             reuse: bool = False) -> dict:
    """One bench run of a real stereo pair (every camera frame the same pair, handed as ``pair`` .npy files),
    lists of :data:`REAL_MAX_FEATURES`; the report kept in build/system/runs/ with the date, the HDL's
    revision, the simulator, the wall time and the model's features of the pair."""
    import numpy as np

    tag = f"{sim}_real_{mode}_{size}"
    kept = _kept(tag)
    if reuse and kept.is_file():
        rep = json.loads(kept.read_text())
        if len(rep.get("frames", [])) == frames:
            return rep
    RUNS.mkdir(parents=True, exist_ok=True)
    left, right = real_pair_arrays(files, size)
    pair = [RUNS / f"real_{size}_left.npy", RUNS / f"real_{size}_right.npy"]
    np.save(pair[0], left)
    np.save(pair[1], right)
    found = real_model(left, right, size, threshold, REAL_MAX_FEATURES)
    print(f"[bench] {tag}: {frames} frame(s) on {sim_label(sim)}; the model finds {found['totals']} corners "
          f"(left, right), lists {found['listed']}, overflow {found['overflow']} ...", flush=True)
    revision, dirty, t0 = hdl_revision(), uncommitted_hdl(), time.time()
    rep = run_bench("stereo_frontend", "tb_stereo_frontend",
                    dict(mode=mode, frames=frames, pair=[str(f) for f in pair], threshold=threshold,
                         timing=timing_of(size), require_features=True),
                    name=f"bench_real_{mode}_{size}", sim=sim,
                    params=dict(quantizers=f"rig:{size}", feature_words=2 * REAL_MAX_FEATURES + 2,
                                max_features=REAL_MAX_FEATURES),
                    log_file=RUNS / f"{tag}.log", public=PUBLIC if sim == "verilator" else None)
    rep.update(wall_s=round(time.time() - t0, 1), simulator=sim_label(sim), revision=revision, uncommitted=dirty,
               date=datetime.date.today().isoformat(), size=size, model=found, threshold_code=threshold,
               files=[os.path.relpath(Path(f).resolve(), ROOT) for f in files])
    rep.pop("last", None)
    kept.write_text(json.dumps(rep) + "\n")
    print(f"[bench] {tag}: done in {rep['wall_s']} s", flush=True)
    return rep


MATCH_TITLE = "## The front end with the matcher option (issue 29)"
MATCH_THRESHOLD = 4  # threshold code of every block: about 450 corners per camera in Tsukuba, a list of about 910


def run_matcher(mode: str, read: str, size: str, frames: int, sim: str, *, reuse: bool = False) -> dict:
    """One bench run of the top with ``matcher=True`` (SAD 9 x 9, d 0..64, R 0, the MATCH register's reset
    settings: t_max 11, the left-right check) on Tsukuba as the rig's cameras see it
    (:func:`eyestereo.sim.lib.scenes.camera_views`: its rectification gives the pair back), lists of 1023
    features; ``read``: "matches" (the host takes the list buffer only and reads the match list alone) or "all"
    (the pair, the features and the matches). The report kept in build/system/runs/."""
    import numpy as np

    from eyestereo.hdl.rectify.calibration import calibration_param
    from eyestereo.sim.lib.scenes import camera_views

    tag = f"{sim}_matcher_{mode}_{read}_{size}"
    kept = _kept(tag)
    if reuse and kept.is_file():
        rep = json.loads(kept.read_text())
        if len(rep.get("frames", [])) == frames:
            return rep
    RUNS.mkdir(parents=True, exist_ok=True)
    cal = calibration_param(f"rig:{size}", None, None)
    views = camera_views(cal, *real_pair_arrays(REAL_PAIR, size))
    pair = [RUNS / f"matcher_{size}_left.npy", RUNS / f"matcher_{size}_right.npy"]
    for f, a in zip(pair, views):
        np.save(f, a)
    print(f"[bench] {tag}: {frames} frame(s) on {sim_label(sim)} ...", flush=True)
    revision, dirty, t0 = hdl_revision(), uncommitted_hdl(), time.time()
    rep = run_bench("stereo_frontend", "tb_stereo_frontend",
                    dict(mode=mode, frames=frames, pair=[str(f) for f in pair], threshold=MATCH_THRESHOLD,
                         timing=timing_of(size), require_features=True, read=read),
                    name=f"bench_matcher_{mode}_{read}_{size}", sim=sim,
                    params=dict(quantizers=f"rig:{size}", matcher=True),
                    log_file=RUNS / f"{tag}.log", public=PUBLIC if sim == "verilator" else None)
    rep.update(wall_s=round(time.time() - t0, 1), simulator=sim_label(sim), revision=revision, uncommitted=dirty,
               date=datetime.date.today().isoformat(), size=size, read=read, threshold_code=MATCH_THRESHOLD)
    rep.pop("last", None)
    kept.write_text(json.dumps(rep) + "\n")
    print(f"[bench] {tag}: done in {rep['wall_s']} s", flush=True)
    return rep


def matcher_section(reps: list[dict], size: str) -> list[str]:
    """docs/system.md's section on the matcher option's runs."""
    w, h = (int(v) for v in size.split("x"))
    cam = CameraTiming(width=w, height=h, **timing_of(size))
    rows = []
    for r in reps:
        f = figures(r, cam)
        fr = r["frames"]
        if r["read"] == "matches":
            read = [x["read_ns"] - x["held_ns"] for x in fr]
            words = [x["match_words"] for x in fr]
            what = "the match list alone"
        else:
            read = [x["read_ns"] - x["frame_ns"] for x in fr]
            words = [w * h + x["match_words"] for x in fr]
            what = "the pair, the features, the matches"
        rows.append(f"| {r['mode']} | {what} | {len(fr)} | {f['frames_done']} | {f['period_us'] / 1e3:.2f} ms | "
                    f"{f['fps']:.2f} | {', '.join(str(x['matches']) for x in fr)} | "
                    f"{', '.join(str(x['features']) for x in fr)} | {sum(words) / len(words):.0f} | "
                    f"{sum(read) / len(read) / 1e6:.3f} ms | yes | {r['wall_s']:.0f} s |")
    rev = reps[0].get("revision", "?") + ("+" if reps[0].get("uncommitted") else "")
    return [MATCH_TITLE, "",
            f"`stereo_frontend(matcher=True)` at {size} (the OV6630's timing, cameras 18 / 17.9 MHz), SAD 9 x 9, "
            "d 0..64, R = 0, the MATCH register's reset settings (t_max 11, the left-right check); the scene is "
            "Tsukuba (im3, im4 resized) as the rig's cameras see it (`sim/lib/scenes.py`: the rectification gives the "
            f"pair back), threshold code {MATCH_THRESHOLD} in every block; {reps[0]['simulator']}, HDL revision "
            f"{rev}. Every match list the host read equals the feature matcher model's for a frame sent (the "
            "model's rectified pair and flags), word for word; `match_dropped`, `match_late` and `match_lost` 0.", "",
            "| mode | the host reads | frames read | frames done | frame period | fps | matches | corners listed | "
            "SRAM words read per frame | host read-out per frame | bit-exact | wall |",
            "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|", *rows, "",
            "The read-out is the host's AXI4-Lite reads of the words named (15 bus clocks per SRAM word) from the buffer "
            "taken to the last word; with the match list alone it is a few hundred words instead of the pair's "
            f"{w * h} (16.66 ms in the overlapped mode above, the pair and the lists).", ""]


def main_matcher(args) -> int:
    """``--matcher``: the matcher option's runs (overlapped and sequential, the host reading the matches alone), the
    section spliced into ``--out``."""
    sim = args.sim or fastest_simulator()
    try:
        reps = [run_matcher("overlapped", "matches", args.size, args.frames_ovl, sim, reuse=args.reuse),
                run_matcher("sequential", "matches", args.size, args.frames, sim, reuse=args.reuse)]
    except (AssertionError, RuntimeError) as e:
        print(f"error: a bench run failed ({str(e).splitlines()[0][:200]})", file=sys.stderr)
        return 1
    splice_section(args.out, matcher_section(reps, args.size), title=MATCH_TITLE)
    print(json.dumps([dict(mode=r["mode"], read=r["read"], frames=len(r["frames"]), bit_exact=r["bit_exact"],
                           fps=figures(r, CameraTiming(**timing_of(args.size)))["fps"], wall_s=r["wall_s"])
                      for r in reps]))
    return 0


def kept_real(size: str = "352x288") -> list[dict]:
    """The real-scene runs kept in build/system/runs/ (sequential first)."""
    order = {"sequential": 0, "overlapped": 1}
    reps = [json.loads(f.read_text()) for f in sorted(RUNS.glob(f"*_real_*_{size}.json"))]
    return sorted(reps, key=lambda r: (order.get(r["mode"], 2), r.get("simulator", "")))


def real_section(reps: list[dict]) -> list[str]:
    """The section of the real-scene runs: what the model finds, what the host read back."""
    if not reps:
        return []
    r0 = reps[0]
    m = r0["model"]
    mp = r0.get("model_params", {})
    out = [REAL_TITLE, "",
           f"Issue 30: a real stereo pair, {' and '.join(f'`{f}`' for f in r0['files'])}, resized to {r0['size']} "
           "(`cv2.INTER_AREA`), the same pair in every camera frame (the bench's `pair` of .npy files), every "
           f"threshold block at code {r0['threshold_code']}: the model finds **{m['totals'][0]} + {m['totals'][1]} = "
           f"{sum(m['totals'])} corners** a frame (left + right), " +
           (f"more than a list holds (`max_features` {mp.get('max_features', REAL_MAX_FEATURES)}): each list holds "
            f"the first {m['listed']} in stream order and its trailer's overflow flag is set; the FEATURES and FCOUNT "
            "registers count them all." if m["overflow"] else
            f"which a list of {mp.get('max_features', REAL_MAX_FEATURES)} holds (no overflow: lower the threshold "
            "for the case of the title).") +
           f" The bench hands the model the top's parameters (`nms` {mp.get('nms')}, `border` " +
           (f"{mp['border']}" if mp.get("border") is not None else
            f"{3 + mp.get('nms', 3) // 2} (the top's default, 3 + nms // 2)") +
           f", `max_features` {mp.get('max_features')}) and checks every rectified pair and list read back bit for "
           "bit, trailer "
           "included, and `list_overflows` (OVERFLOWS: the completed frames whose list was cut) against the "
           "model's count. Before the fix the bench ran the model with its own 1023 features per list and failed "
           "on such a scene (\"no stereo pair of the frames sent gives what the host read\").", "",
           "| date | HDL commit | simulator | mode | frames read (done) | features per frame, model: left + right = "
           "total (listed) | overflow flag read back | list_overflows (expected) | bit-exact | wall |",
           "|---|---|---|---|---:|---|---|---:|---|---:|"]
    for r in reps:
        fr = r["frames"]
        feats = "; ".join(f"{f['model_totals'][0]} + {f['model_totals'][1]} = {sum(f['model_totals'])} "
                          f"({f['features']})" for f in fr)
        flags = ", ".join("set" if f["overflow"] else "clear" for f in fr)
        lo = r.get("list_overflows") or {}
        exp = lo.get("expected", ["?", "?"])
        exp_s = str(exp[0]) if exp[0] == exp[1] else f"{exp[0]}..{exp[1]}"
        out.append(f"| {r['date']} | {r['revision']} | {r['simulator']} | {r['mode']} | {len(fr)} "
                   f"({r['frames_done']}) | {feats} | {flags} | {lo.get('counted', '?')} ({exp_s}) | "
                   f"{'yes' if r['bit_exact'] else 'no'} | {r['wall_s']:.0f} s ({r['wall_s'] / 60:.1f} min) |")
    revs = sorted({r["revision"] for r in reps})
    if any("+" in v for v in revs):
        files = sorted({f for r in reps for f in r.get("uncommitted", [])})
        out += ["", "A commit marked `+`: `hdl/` or `tools/models/` had uncommitted changes when the run was "
                "converted (the checkout is shared with other work in progress), so the measured HDL is that commit's "
                "with those changes" + (f" ({', '.join(f'`{f}`' for f in files)})" if files else "") + "."]
    out += revision_note((r["revision"] for r in reps if "+" not in r["revision"]),
                         "python -m eyestereo.sim.measure.vhdl_diff REV stereo_frontend")
    out += ["", "Run again with `python -m eyestereo.sim.measure.bench_stereo_frontend --real sequential,overlapped` (wall "
            "time includes the Verilator build of the top; one simulation at a time on a 2-core machine shared with "
            "other jobs).", ""]
    return out


def splice_section(path: Path, section: list[str], title: str = REAL_TITLE, before: str = "## On GHDL") -> None:
    """Replace the section ``title`` of the document at ``path`` (up to the next ``## `` heading) with
    ``section``, or insert it before the heading ``before`` (at the end when there is none)."""
    lines = path.read_text().splitlines() if path.is_file() else []
    if title in lines:
        i = lines.index(title)
        j = next((k for k in range(i + 1, len(lines)) if lines[k].startswith("## ")), len(lines))
    else:
        i = j = next((k for k, v in enumerate(lines) if v.startswith(before)), len(lines))
    new = lines[:i] + section + lines[j:]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(new) + "\n")


# --- the document ----------------------------------------------------------------------------------
def _mode_rows(figs: dict) -> list[str]:
    rows = ["| mode | frames (host read) | frames done | frame period | fps | FRAME_CLOCKS | host read-out | "
            "bit-exact |", "|---|---:|---:|---:|---:|---:|---:|---|"]
    for m, f in figs.items():
        rows.append(f"| {m} | {f['frames_read']} | {f['frames_done']} | {f['period_us'] / 1e3:.3f} ms | "
                    f"**{f['fps']:.2f}** | {f['frame_clocks']} | {f['read_out_us'] / 1e3:.3f} ms | "
                    f"{'yes' if f['bit_exact'] else 'no'} |")
    return rows


def _stage_rows(figs: dict) -> list[str]:
    rows = ["| mode | start to pair held (capture) | rectification | lists complete after the rectifier | "
            "host read-out |", "|---|---:|---:|---:|---:|"]
    for m, f in figs.items():
        st = f["stages"]

        def ms(v):
            return "-" if v is None else f"{v / 1e3:.3f} ms"

        cap = ms(st.get("capture_us")) if m == "sequential" else "(overlapped)"
        rows.append(f"| {m} | {cap} | {ms(st.get('rectify_us'))} | {ms(st.get('lists_after_rectifier_us'))} | "
                    f"{ms(f['read_out_us'])} |")
    return rows


def _share_rows(figs: dict) -> list[str]:
    rows = ["| mode | " + " | ".join(MASTERS) + " | all |", "|---|" + "---:|" * (len(MASTERS) + 1)]
    for m, f in figs.items():
        rows.append(f"| {m} | " + " | ".join(f"{100 * f['sram_share'][x]:.1f} %" for x in MASTERS) +
                    f" | {100 * f['sram_busy']:.1f} % |")
    return rows


def _speed_rows(figs: dict) -> list[str]:
    rows = ["| mode | simulator | simulated | wall (build + run) | test alone | memory clocks / s |",
            "|---|---|---:|---:|---:|---:|"]
    for m, f in figs.items():
        rows.append(f"| {m} | {f.get('simulator')} | {f.get('sim_ms')} ms | {f.get('wall_s')} s | "
                    f"{f.get('test_s')} s | {f.get('memory_clocks_per_s')} |")
    return rows


def full_section(size: str, figs: dict) -> list[str]:
    s, o = figs["sequential"], figs["overlapped"]
    cam = CameraTiming(*(int(v) for v in size.split("x"))) if size != "352x288" else CameraTiming()
    cam_ms = cam.frame_pclk / 18e3
    st = s["stages"]
    lines = [f"## Full {size} frames through the whole system (measured, simulated time)", "",
             f"{s.get('simulator')}; the OV6630's real timing ({cam.frame_pclk} PCLK a frame: "
             f"{cam_ms:.2f} ms at 18 MHz, **{1e3 / cam_ms:.1f} fps**, the cameras' limit), a moving random-texture "
             "scene (`shift:3`), the host reading every frame it takes back (the rectified pair packed, both "
             "feature lists) over AXI4-Lite and the bench comparing it bit for bit with the numpy chain (camera "
             "model -> rectification model -> stereo Harris model -> feature list).", "",
             *_mode_rows(figs), "",
             f"Against the thesis: its estimate for the sequential system was **{THESIS_FPS} fps**; measured "
             f"**{s['fps']:.2f} fps** ({s['fps'] / THESIS_FPS:.2f} x; period {s['period_from']}). The overlapped "
             f"goal was the cameras' **{1e3 / cam_ms:.1f} fps**: measured **{o['fps']:.2f} fps** "
             f"(period {o['period_from']}).", "",
             "Stage times (simulated; probes on the rectifier's `busy`, the feature list's `frame_done` and the "
             "arbiter's `cam_held` inside the top):", "", *_stage_rows(figs), ""]
    seq_parts = []
    if st.get("capture_us") is not None and st.get("rectify_us") is not None:
        seq_parts = [f"Sequential, one stage after the other: the cameras are armed and their next frames captured "
                     f"({st['capture_us'] / 1e3:.2f} ms from start to the pair held, the camera's active lines being "
                     f"{cam.height * (2 * cam.width + cam.h_blank) / 18e3:.2f} ms of its {cam_ms:.2f} ms frame), then "
                     f"the rectification ({st['rectify_us'] / 1e3:.2f} ms; Harris and the lists are complete "
                     f"{st.get('lists_after_rectifier_us', 0) / 1e3:.3f} ms after it), then the host's read-out through "
                     f"the bus ({s['read_out_us'] / 1e3:.2f} ms, 15 bus clocks per SRAM word), then the next start."]
    if s.get("periods_us"):
        seq_parts += ["", "Sequential periods frame by frame: " + ", ".join(f"{v / 1e3:.2f}" for v in s["periods_us"]) +
                      f" ms. A camera frame is captured from its first active line (camera_in: a frame is taken when "
                      f"it *starts* while armed), so arming during VSYNC or the back porch ({cam.v_sync + cam.v_back} "
                      f"lines, {(cam.v_sync + cam.v_back) * (2 * cam.width + cam.h_blank) / 18e3:.2f} ms) still takes "
                      "that frame. Capture of the active lines, rectification and read-out take just over two camera "
                      f"frames ({2 * cam_ms:.2f} ms), so the next start falls just after the next-but-one VSYNC and "
                      "the period settles at two camera frames, while both cameras' first lines are still ahead; the "
                      "two cameras drift apart (18 / 17.9 MHz: 0.11 ms a frame), and when one's first line has just "
                      "passed the frame waits a whole camera frame longer.",
                      "", "Stage by stage against the thesis's estimate (section 7.1's transfer times; its 20.01 fps "
                      "leaves out arbitration and waiting):", "",
                      "| stage | thesis estimate | measured |", "|---|---:|---:|",
                      f"| image transfer into the SRAM (both cameras) | 11.26 ms (overlapped) | "
                      f"{st['capture_us'] / 1e3:.2f} ms from start to the pair held (the camera's active lines) |",
                      f"| rectification: reads of both frames and the rectified writes | 20.28 + 2.02 ms | "
                      f"{st['rectify_us'] / 1e3:.2f} ms (rectifier busy) |",
                      f"| Harris and the feature lists | (in the stream) | +{st['lists_after_rectifier_us'] / 1e3:.3f} "
                      "ms after the rectifier |",
                      f"| host transfer of the rectified pair and the features | 16.22 ms | {s['read_out_us'] / 1e3:.2f} "
                      "ms (AXI4-Lite, 15 bus clocks per SRAM word) |",
                      f"| frame period | 49.97 ms (20.01 fps) | {s['period_us'] / 1e3:.2f} ms ({s['fps']:.2f} fps) |"]
    read_ms = o["read_out_us"] / 1e3
    lim = ("the cameras are the limit (the read-out of a frame takes "
           f"{read_ms:.2f} ms of the {cam_ms:.2f} ms camera frame)" if read_ms < cam_ms else
           f"the host's read-out ({read_ms:.2f} ms a frame at 15 bus clocks per SRAM word, longer than the "
           f"{cam_ms:.2f} ms camera frame) is the limit; a burst host port (or DMA) would lift it")
    lines += seq_parts + ["", f"Overlapped: {lim}.", "",
                          "SRAM share of each master (words moved / memory clocks over the run, the arbiter's "
                          "counters):", "", *_share_rows(figs), "",
                          "Simulation (one run at a time, `nice`, on a 2-core machine shared with other jobs):", "",
                          *_speed_rows(figs), ""]
    return lines


def small_section(size: str, figs: dict, full: dict, measured: dict | None) -> list[str]:
    lines = [f"## Small frames ({size}) and the derived full-frame figures (cross-check)", "",
             f"{figs['sequential'].get('simulator')}, {size} (calibration `rig:{size}`), short blanking {SHORT} "
             "(the camera model's rules allow it: HREF inactive for at least one PCLK between lines, VSYNC for at "
             "least one line), the same bench.", "", *_mode_rows(figs), "", *_stage_rows(figs), "",
             *_share_rows(figs), "",
             "Derived from these small frames for 352x288, linear in pixels (what this document gave before the "
             "full frames were simulated; kept only as a cross-check of the measurement above):", "",
             f"* sequential: (measured period - 1.5 camera frames) x {FULL[0] * FULL[1]} / pixels + 1.5 full camera "
             f"frames = {full['sequential_ms']} ms, {full['sequential_fps']} fps" +
             (f" (measured: {measured['sequential']['period_us'] / 1e3:.2f} ms, "
              f"{measured['sequential']['fps']:.2f} fps)" if measured else "") + ";",
             f"* rectification, scaled: {full['rectify_ms'] if full['rectify_ms'] is not None else '(no probe)'} ms" +
             (f" (measured: {measured['sequential']['stages'].get('rectify_us', 0) / 1e3:.2f} ms)" if measured else "")
             + ";",
             f"* host read-out, scaled: {full['host_read_out_ms']} ms" +
             (f" (measured: {measured['overlapped']['read_out_us'] / 1e3:.2f} ms)" if measured else "") +
             f"; overlapped bound: {full['overlapped_fps_bound']} fps" +
             (f" (measured: {measured['overlapped']['fps']:.2f} fps)" if measured else "") + ".", ""]
    return lines


def ghdl_section(speed: dict | None, frame: dict | None, full_figs: dict | None) -> list[str]:
    out = ["## On GHDL", ""]
    if frame is not None:
        f = frame
        out += [f"A full 352x288 frame on {f['simulator']}, {f['mode']}: {f['frames_read']} frame(s) read back, "
                f"bit-exact: {'yes' if f['bit_exact'] else 'no'}; period {f['period_us'] / 1e3:.3f} ms "
                f"({f['fps']:.2f} fps; frame 0, start to read-out done" +
                (f": Verilator's frame 0 took {full_figs['sequential']['periods_us'][0] / 1e3:.3f} ms on a "
                 "different random scene (the bench's scene depends on the number of frames), the read-out's length "
                 "depending on the features" if full_figs and
                 full_figs['sequential'].get('periods_us') else "") +
                f"), {f['wall_s']} s wall ({f['wall_s'] / 60:.0f} minutes), {f.get('memory_clocks_per_s')} memory "
                "clocks/s over the whole run.", ""]
    if speed is not None:
        need = None
        v = speed.get("verilator")
        if full_figs and v and full_figs["sequential"].get("test_s"):
            s = full_figs["sequential"]
            # Verilator's time per full frame, and the same with the simulator's share slowed down by the probe's
            # ratio: between "only the simulator's own part is slower" and "everything is slower"
            per = s["test_s"] / s["frames_read"]
            clocks = s["period_us"] * 100
            low = per + clocks * (1 / speed["memory_clocks_per_s"] - 1 / v["memory_clocks_per_s"])
            high = per * v["memory_clocks_per_s"] / speed["memory_clocks_per_s"]
            need = (low, high)
        out += [f"Speed, the bench's probe (`speed_us`): the full-size top from {SPEED_SKIP_US / 1e3:.1f} ms on (both "
                f"cameras sending their active lines into the SRAM, the SRAM model and the host's polling running), "
                f"{speed['sim_us']:.0f} us of simulated time: {speed['simulator']} at "
                f"**{speed['memory_clocks_per_s']:.0f} memory clocks per second** ({speed['wall_s']} s; "
                f"{speed.get('wall_total_s')} s with analysis, elaboration and set-up)" +
                (f", {v['simulator']} at **{v['memory_clocks_per_s']:.0f}** ({v['wall_s']} s; {v.get('wall_total_s')} s "
                 "with its build)" if v else "") + ". The whole full-frame runs above averaged "
                f"{full_figs['sequential'].get('memory_clocks_per_s') if full_figs else '?'} (sequential) and "
                f"{full_figs['overlapped'].get('memory_clocks_per_s') if full_figs else '?'} (overlapped) memory clocks "
                "per second on Verilator, the host's bus read-out (cocotbext-axi, a Python coroutine step per bus "
                "clock) included." +
                (f" Projected for one sequential 352x288 frame (the {s['period_us'] / 1e3:.2f} ms measured above, "
                 f"{s['period_us'] * 100:.0f} memory clocks; Verilator took {per:.0f} s a frame): "
                 f"**{need[0] / 60:.0f} to {need[1] / 60:.0f} minutes** on {speed['simulator']} (the lower figure if only "
                 "the simulator's own share slows down, the higher if everything did)." if need else ""), ""]
    if frame is None:
        out += ["No full frame has been run on GHDL: it did not fit in the time this session had on a 2-core machine "
                "shared with other jobs (the projection above). `python -m eyestereo.sim.measure.bench_stereo_frontend "
                "--ghdl-frame sequential --reuse` runs one (one frame, bit-exact check) and adds it here.", ""]
    return out


#: ``make demo`` from a fresh state, measured by hand (``rm -rf build; time make demo``, ccache disabled so that
#: Verilator compiles everything as on a fresh machine); update it when the demo changes.
DEMO = dict(seconds=232, date="2026-12-01", note="the front end 121 s (two Verilator builds of the top and both modes), Sobel 10 s, Harris 48 + 51 s; an earlier run, before the rig views and with the set-up reinstalling the venv's packages, took 270 s; the machine's 2 cores shared with other jobs")


def demo_section() -> list[str]:
    from eyestereo.sim.apps import demo

    w, h = demo.SYSTEM_SIZE
    out = ["## make demo", "",
           f"`make demo` runs the complete front end first ({w}x{h} cameras, {demo.SYSTEM_FRAMES} frames in each of "
           f"the modes {', '.join(demo.SYSTEM_MODES)}, on the fastest simulator here: Verilator on MyHDL's Verilog of "
           "the top, GHDL if Verilator is missing; `eyestereo sim system`'s pictures: the rectified pair with row "
           "lines and corners, the matched features coloured by disparity), then the Sobel and Harris VHDL on GHDL "
           "at 352x288. The size and frame count are chosen to keep it under 5 minutes on 2 cores: a full 352x288 "
           "system frame alone takes about 5 minutes on Verilator (above)."]
    if DEMO["seconds"]:
        out[-1] += (f" Measured from a fresh state (`rm -rf build; time make demo`, ccache disabled, the venv "
                    f"installed): **{DEMO['seconds'] // 60:.0f} min {DEMO['seconds'] % 60:.0f} s** ({DEMO['date']}; "
                    f"{DEMO['note']}).")
    out += ["", "The demo's stereo pair: two crops of one Tsukuba view 6 px apart (4.5 px at 96x72), each rendered "
            "through the inverse of the synthetic rig's map for its camera (sim/apps/demo.py `rig_view`), so that the top, "
            "rectifying with the rig's calibration (`rig:WxH`), gives them back row-aligned. (The first timing above "
            "used the crops as they were: the rectified pair was then not row-aligned and same-row matching found no "
            "match.) `eyestereo sim system` on that pair, one overlapped frame on Verilator: 64 corners, 13 matched, "
            "disparities 4..5, bit-exact:", "",
            "![rectified pair with corners](img/system/rectified.png)", "",
            "![matched features coloured by disparity](img/system/matches.png)"]
    return out + [""]


def write_doc(path: Path, *, size: str, figs: dict, small: tuple | None, ghdl: tuple, adaptive=None) -> None:
    lines = ["# The complete front end: frame rate in simulated time", "",
             "Written by `python -m eyestereo.sim.measure.bench_stereo_frontend` (sim/measure/bench_stereo_frontend.py): the "
             "stereo_frontend top level, two camera models with independent clocks (18 and 17.9 MHz), memory clock "
             "100 MHz (SRAM model checking the part's rules), Harris clock 50 MHz; the host driver configures the "
             "registers, waits for frames, reads every frame it takes back through the AXI4-Lite bus and the bench "
             "compares it bit for bit with the numpy chain.", ""]
    lines += full_section(size, figs)
    if small is not None:
        lines += small_section(*small, measured=figs if size == "352x288" else None)
    lines += real_section(kept_real())
    sim = (figs["sequential"].get("simulator") or "").split(" ")[0].lower()
    two = {m: json.loads(f.read_text()) for m in ("sequential", "overlapped") if (f := _kept(f"{sim}_{m}_{size}")).is_file()}
    lines += single_section(size, kept_single(size, sim), two) if sim else []
    lines += ghdl_section(*ghdl, figs)
    lines += resources_section()
    lines += demo_section()
    if adaptive is not None:
        lines += adaptive_section(adaptive, path.parent / "img" / "system" / "adaptive.png")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines) + "\n")


#: The Spartan-3E 500 (XC3S500E).
DEVICE = dict(LUT=9312, FF=9312, RAMB16=20, MULT18X18=20)
#: make synth's row of the default top (2026-12-01, docs/benchmarks.md), used when build/synth/resources.json
#: is not there
SYNTH_FALLBACK = dict(summary=dict(LUT=5770, LUTRAM=252, FF=6186, RAMB16=16, MULT18X18=19),
                      fmax=dict(clk=81.05, hclk=84.05, cam_l_pclk=132.66, cam_r_pclk=122.8),
                      ecp5_device="--85k --package CABGA756 --speed 6")


def resources_section() -> list[str]:
    """The whole system's resources against the Spartan-3E 500, from make synth's resources.json (the
    default stereo_frontend: 352x288, the synthetic rig's calibration), or the figures measured before."""
    f = ROOT / "build" / "synth" / "resources.json"
    rows = [r for r in (json.loads(f.read_text()) if f.is_file() else []) if r.get("block") == "stereo_frontend"
            and not r.get("params")]
    out = ["## Resources of the whole system", ""]
    row = rows[-1] if rows else SYNTH_FALLBACK
    s = row["summary"]
    luts = s["LUT"] + s["LUTRAM"]  # distributed RAM occupies LUTs of SLICEMs
    used = dict(LUT=luts, FF=s["FF"], RAMB16=s["RAMB16"], MULT18X18=s["MULT18X18"])
    out += ["`python -m eyestereo.hdl.flow.synth --block stereo_frontend --no-pnr`: GHDL's synthesis of the generated VHDL "
            "(the default top: 352x288 cameras, the synthetic rig's calibration, harris_stereo share 1, nms 3, "
            f"{CAM_DEPTH}-word camera FIFOs), Yosys `synth_xilinx -family xc3se`, not placed" +
            ("" if rows else " (figures of the last run; build/synth/resources.json not present)") + ".", "",
            "| resource | used | Spartan-3E 500 | share | margin |", "|---|---:|---:|---:|---:|"]
    for k, cap in DEVICE.items():
        note = f" ({s['LUT']} logic + {s['LUTRAM']} LUT-RAM)" if k == "LUT" else ""
        out.append(f"| {k} | {used[k]}{note} | {cap} | {100 * used[k] / cap:.0f} % | {cap - used[k]} |")
    fits = all(used[k] <= cap for k, cap in DEVICE.items())
    out += ["", f"It {'fits' if fits else 'does not fit'}: the multipliers are the tight resource (rectifier 12, "
            "harris_stereo at share 1 7); share 2 would free 3 but cannot take the rectifier's stream without a "
            "pacing buffer. Carry cells (MUXCY/XORCY) use no LUT. Yosys counts, not ISE's: the thesis's own "
            "figures came from ISE 10.", ""]
    fmax = {k: (v["achieved"] if isinstance(v, dict) else v) for k, v in (row.get("fmax") or {}).items()}
    if fmax:
        names = dict(clk="memory clock", hclk="Harris clock", cam_l_pclk="left camera", cam_r_pclk="right camera")
        goals = dict(clk=100.0, hclk=50.0, cam_l_pclk=18.0, cam_r_pclk=18.0)
        seeds = row.get("seeds") or [1]
        out += [f"Placed by `make synth` on an ECP5 (`nextpnr-ecp5 {row.get('ecp5_device', '?')}`), fmax per clock "
                f"(the slowest of nextpnr seeds {', '.join(map(str, seeds))}): "
                + ", ".join(f"{names.get(k, k)} {v:.1f} MHz (goal {goals.get(k, '?')})" for k, v in fmax.items())
                + ".", ""]
    return out


SINGLE_TITLE = "## The single-clock build (rectification and Harris in the memory clock)"


def kept_single(size: str, sim: str) -> dict[str, dict]:
    """The single-clock runs of ``size`` kept in build/system/runs/ (mode -> report)."""
    out = {}
    for mode in ("sequential", "overlapped"):
        f = _kept(f"{sim}_{mode}_{size}_single")
        if f.is_file():
            out[mode] = json.loads(f.read_text())
    return out


def single_section(size: str, reps: dict[str, dict], two_clock: dict[str, dict]) -> list[str]:
    """The single-clock build's frames beside the default build's (same bench, same scene)."""
    if not reps:
        return []
    w, h = (int(v) for v in size.split("x"))
    cam = CameraTiming(width=w, height=h, **timing_of(size))
    figs = {m: figures(r, cam) for m, r in reps.items()}
    lines = [SINGLE_TITLE, "",
             "`stereo_frontend(single_clock=True)`: harris_stereo runs in the memory clock (100 MHz) instead of its own "
             "50 MHz clock, with no clock-domain crossing for the rectified stream, k, the thresholds and the flags "
             "(issue 23's build option; `make synth` places it as `stereo_frontend single-clock`). Same bench, scene "
             f"and host as above, {size}, bit for bit against the same numpy chain:", "", *_mode_rows(figs), ""]
    if two_clock:
        tf = {m: figures(r, cam) for m, r in two_clock.items()}
        lines += ["Against the two-clock build (the table above): " + "; ".join(
            f"{m} {figs[m]['fps']:.2f} fps (two clocks: {tf[m]['fps']:.2f})" for m in figs if m in tf) + ".", ""]
    return lines


def main_single(args) -> int:
    """``--single-clock``: both modes on the single-clock top, their section spliced into ``--out``."""
    sim = args.sim or fastest_simulator()
    try:
        timing = timing_of(args.size)
        reps = {"sequential": run_mode("sequential", args.size, args.frames, timing, sim, args.reuse, single_clock=True),
                "overlapped": run_mode("overlapped", args.size, args.frames_ovl, timing, sim, args.reuse,
                                       single_clock=True)}
    except (AssertionError, RuntimeError) as e:
        print(f"error: a bench run failed ({str(e).splitlines()[0][:200]})", file=sys.stderr)
        return 1
    two = {m: json.loads(f.read_text()) for m in reps if (f := _kept(f"{sim}_{m}_{args.size}")).is_file()}
    splice_section(args.out, single_section(args.size, reps, two), title=SINGLE_TITLE)
    print(json.dumps(dict(single_clock=True, size=args.size, simulator=sim,
                          bit_exact={m: r["bit_exact"] for m, r in reps.items()})))
    return 0


OPTIONS_TITLE = "## The front end with its memory and rectification options (issue 26)"


def main_options(args) -> int:
    """``--memory`` / ``--rectify``: both modes of the top with those options at --size (352x288: the OV6630's
    timing at 17.73-18 MHz; 640x480: the OV7670's VGA frame at 24 MHz), the section of ``docs/memory.md``."""
    from eyestereo.tools.camera import VGA_TIMING

    sim = args.sim or fastest_simulator()
    options = dict(memory=args.memory, rectify=args.rectify)
    if args.dense:
        options["dense"] = True
    w, h = (int(v) for v in args.size.split("x"))
    vga = (w, h) == (VGA_TIMING.width, VGA_TIMING.height)
    timing = (dict(h_blank=VGA_TIMING.h_blank, v_sync=VGA_TIMING.v_sync, v_back=VGA_TIMING.v_back,
                   v_front=VGA_TIMING.v_front) if vga else timing_of(args.size))
    # VGA: the OV7670's 30 frames/s need its 24 MHz PCLK; the cameras slightly apart as two oscillators are, the
    # slower at that figure (as CIF's 18 / 17.9 MHz are both above the OV6630's 17.73 MHz for 50 frames/s)
    cams = dict(cam_l_mhz=24.1, cam_r_mhz=24.0) if vga else {}
    cam_mhz = (cams["cam_l_mhz"], cams["cam_r_mhz"]) if vga else (18.0, 17.9)
    try:
        reps = {m: run_mode(m, args.size, n, timing, sim, args.reuse, options=options, **cams)
                for m, n in (("sequential", args.frames), ("overlapped", args.frames_ovl))}
    except (AssertionError, RuntimeError) as e:
        print(f"error: a bench run failed ({str(e).splitlines()[0][:200]})", file=sys.stderr)
        return 1
    cam = CameraTiming(width=w, height=h, **timing)
    figs = {m: figures(r, cam) for m, r in reps.items()}
    title = f"{OPTIONS_TITLE[:-1]}, {args.size}: memory={args.memory}, rectify={args.rectify})"
    if args.dense:
        title = f"{DENSE_TITLE}, {args.size}: memory={args.memory}, rectify={args.rectify}"
    arb = reps["overlapped"].get("arb", {})
    moved = {k[6:]: v for k, v in arb.items() if k.startswith("moved_")}
    total = sum(moved.values()) or 1
    section = [title, "",
               f"`stereo_frontend(memory=\"{args.memory}\", rectify=\"{args.rectify}\"" +
               (", dense=True)` (D 64, PU 4, 4 paths, census 5 x 5, the median; the DENSE register's reset settings)"
                if args.dense else ")`") + ", rig calibration at "
               f"{args.size}, cameras {cam_mhz[0]:g} / {cam_mhz[1]:g} MHz, {sim_label(sim)}; every frame read back "
               "by the host over AXI4-Lite bit for bit against the numpy chain"
               + (", the SDRAM model checking every rule of the part (none broken, no refresh late)"
                  if args.memory == "sdram" else "") + ":", "", *_mode_rows(figs), "",
               "Words moved per master in the overlapped run (share of the memory's traffic): " + ", ".join(
                   f"{k} {v} ({100 * v / total:.1f} %)" for k, v in moved.items()) + "; "
               f"clocks of the run: {arb.get('clocks', '?')}.", "",
               f"The cameras' own rate: {min(cam_mhz) * 1e6 / cam.frame_pclk:.2f} frames/s (the slower camera, "
               f"{cam.frame_pclk} PCLK a frame at {min(cam_mhz):g} MHz): the overlapped mode keeps their pace when its "
               "frame period is the slower camera's.", ""]
    if args.dense:
        section += dense_lines(reps, figs, w, h)
    if args.memory == "sdram":
        sd = {m: r.get("sdram") or {} for m, r in reps.items()}
        section += ["SDRAM refreshes: " + ", ".join(f"{m} {v.get('refreshes', '?')} (late "
                                                    f"{v.get('late_refreshes', '?')})" for m, v in sd.items()) + ".", ""]
    splice_section(args.options_out, section, title=title)
    print(json.dumps(dict(options=options, size=args.size, simulator=sim,
                          fps={m: round(f["fps"], 2) for m, f in figs.items()},
                          bit_exact={m: r["bit_exact"] for m, r in reps.items()})))
    return 0


DENSE_TITLE = "## The front end with the dense option"


def dense_lines(reps: dict, figs: dict, w: int, h: int) -> list[str]:
    """What the dense runs add: the maps read and matched, the rectification's pace, the FIFO and writer flags."""
    from eyestereo.hdl.dense.sgm import spacing

    sp = spacing(64, 4)
    out = []
    for m, r in reps.items():
        pairs = [tuple(f["disp_pair"]) for f in r["frames"]]
        rect_us = (r.get("stages") or {}).get("rectify_us")
        out.append(f"- {m}: {len(pairs)} disparity maps read by the host, each equal bit for bit to the dense model "
                   f"of a rectified pair sent (pairs {pairs}); {r.get('disp_frames')} maps completed; "
                   + (f"rectification {rect_us / 1e3:.3f} ms per pair (paced by the core, which takes {w} x {h} x "
                      f"{sp} clocks = {w * h * sp / 1e5:.3f} ms at 100 MHz: the rectifier ends its FIFO's worth "
                      "ahead of it); " if rect_us else "")
                   + "the core's FIFO never overran and the writer lost no code (the bench's checks).")
    return out + [""]


def _size(text: str) -> str:
    if text == "640x480":  # VGA: the line cache's front end (its address map has no camera buffers, so it fits)
        return text
    return "{}x{}".format(*frame_size(text))


def main_real(args) -> int:
    """``--real``: the real-scene runs alone, their section spliced into ``--out``."""
    modes = [m.strip() for m in args.real.split(",") if m.strip()]
    if not modes or any(m not in ("sequential", "overlapped") for m in modes):
        print(f"error: --real: sequential and/or overlapped, got {args.real!r}", file=sys.stderr)
        return 1
    if args.real_frames < 1:
        print("error: --real-frames must be at least 1", file=sys.stderr)
        return 1
    sim = args.sim or fastest_simulator()
    try:
        reps = [run_real(m, args.real_size, args.real_frames, sim, files=args.real_pair,
                         threshold=args.real_threshold, reuse=args.reuse) for m in modes]
    except ValueError as e:  # an unreadable image
        print(f"error: {e}", file=sys.stderr)
        return 1
    except (AssertionError, RuntimeError) as e:
        print(f"error: a bench run failed ({str(e).splitlines()[0][:200]})", file=sys.stderr)
        return 1
    # the document: every kept real-scene run of this size (a mode run earlier stays in its row)
    kept = kept_real(args.real_size)
    splice_section(args.out, real_section(kept or reps))
    print(json.dumps([dict(mode=r["mode"], frames=len(r["frames"]), bit_exact=r["bit_exact"], model=r["model"],
                           list_overflows=r.get("list_overflows"), wall_s=r["wall_s"]) for r in reps]))
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sim", choices=("verilator", "icarus", "ghdl"), default=None,
                    help="simulator of the runs (default: the fastest here, Verilator if installed)")
    ap.add_argument("--size", type=_size, default="352x288")
    ap.add_argument("--frames", type=int, default=2, help="host frames of the sequential run (default 2)")
    ap.add_argument("--frames-ovl", type=int, default=3, help="host frames of the overlapped run (default 3)")
    ap.add_argument("--small", type=_size, default="48x32", help="the small frames' size (cross-check)")
    ap.add_argument("--no-small", action="store_true", help="leave the small frames out")
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "system.md")
    ap.add_argument("--json", type=Path, default=ROOT / "build" / "system" / "framerate.json")
    ap.add_argument("--adaptive-frames", type=int, default=0,
                    help="also run the closed threshold loop (sequential, --adaptive-size) for this many frames")
    ap.add_argument("--adaptive-size", type=_size, default="64x48")
    ap.add_argument("--ghdl-speed", type=int, default=0, metavar="US",
                    help="measure GHDL's (llvm) speed on the full-size top over US microseconds of simulated time")
    ap.add_argument("--ghdl-frame", choices=("sequential", "overlapped"),
                    help="also run one full frame on GHDL (llvm): hours")
    ap.add_argument("--real", metavar="MODES",
                    help="only the real scene with more corners than a list holds (issue 30): these modes "
                         "(sequential, overlapped, comma-separated); its section of --out is replaced in place")
    ap.add_argument("--real-frames", type=int, default=1, help="host frames of each real-scene run (default 1)")
    ap.add_argument("--real-pair", nargs=2, type=Path, metavar=("LEFT", "RIGHT"), default=list(REAL_PAIR),
                    help="the real stereo pair (default Middlebury Tsukuba im3, im4 from ../shared/data)")
    ap.add_argument("--real-size", type=_size, default="352x288")
    ap.add_argument("--real-threshold", type=int, default=REAL_THRESHOLD,
                    help=f"threshold code of every block (default {REAL_THRESHOLD})")
    ap.add_argument("--single-clock", action="store_true",
                    help="only the single-clock build (stereo_frontend(single_clock=True)), both modes at --size "
                         "(--frames, --frames-ovl); its section of --out is replaced in place")
    ap.add_argument("--reuse", action="store_true", help="take the runs' reports from build/system/runs/ if there")
    ap.add_argument("--matcher", action="store_true", help="only the matcher option's runs at --size (overlapped "
                    "--frames-ovl, sequential --frames, the host reading the match lists alone); its section of --out "
                    "is replaced in place")
    ap.add_argument("--memory", choices=("sram", "sdram"), help="only the top with this frame store, both modes at "
                    "--size; its section of --options-out is replaced in place")
    ap.add_argument("--rectify", choices=("fetch", "stream"), default=None,
                    help="with --memory or --dense: the rectification option (default stream; fetch with --dense)")
    ap.add_argument("--dense", action="store_true", help="the top with the dense option (D 64, PU 4), both modes at "
                    "--size (default memory sram, rectify fetch); its section of --options-out (default docs/dense.md) "
                    "is replaced in place")
    ap.add_argument("--options-out", type=Path, default=None, help="default docs/memory.md (docs/dense.md with --dense)")
    args = ap.parse_args(argv)
    if args.memory is not None or args.dense:
        args.memory = args.memory or "sram"
        args.rectify = args.rectify or ("fetch" if args.dense else "stream")
        args.options_out = args.options_out or ROOT / "docs" / ("dense.md" if args.dense else "memory.md")
        return main_options(args)
    if args.real is not None:
        return main_real(args)
    if args.matcher:
        return main_matcher(args)
    if args.single_clock:
        return main_single(args)
    if args.frames < 1 or args.frames_ovl < 1:
        print("error: --frames and --frames-ovl must be at least 1", file=sys.stderr)
        return 1
    if args.adaptive_frames < 0 or args.ghdl_speed < 0:
        print("error: --adaptive-frames and --ghdl-speed must not be negative", file=sys.stderr)
        return 1
    sim = args.sim or fastest_simulator()
    try:
        # one simulation at a time (the machine has 2 cores; a Verilator build uses both)
        timing = timing_of(args.size)
        reps = {"sequential": run_mode("sequential", args.size, args.frames, timing, sim, args.reuse),
                "overlapped": run_mode("overlapped", args.size, args.frames_ovl, timing, sim, args.reuse)}
        w, h = (int(v) for v in args.size.split("x"))
        figs = {m: figures(r, CameraTiming(width=w, height=h, **timing)) for m, r in reps.items()}
        small = None
        if not args.no_small:
            sreps = {m: run_mode(m, args.small, 3, SHORT, sim, args.reuse) for m in ("sequential", "overlapped")}
            sw, sh = (int(v) for v in args.small.split("x"))
            sfigs = {m: figures(r, CameraTiming(width=sw, height=sh, **SHORT)) for m, r in sreps.items()}
            small = (args.small, sfigs, full_frame(sfigs["sequential"], sfigs["overlapped"]))
        from eyestereo.sim.lib.runner import fastest_ghdl_backend

        backend = fastest_ghdl_backend()
        speed = frame = None
        speed_file = _kept(f"ghdl-{backend}_sequential_352x288_speed")
        if args.ghdl_speed:
            # the same window on both simulators: from 1.2 ms (the cameras' active lines, both writing into
            # the SRAM) on, ``--ghdl-speed`` microseconds
            speed = run_mode("sequential", "352x288", 1, {}, "ghdl", False, backend=backend, speed_us=args.ghdl_speed,
                             speed_skip_us=SPEED_SKIP_US)
            speed["verilator"] = run_mode("sequential", "352x288", 1, {}, "verilator", False, speed_us=args.ghdl_speed,
                                          speed_skip_us=SPEED_SKIP_US)
            _kept(f"ghdl-{backend}_sequential_352x288_speed").write_text(json.dumps(speed) + "\n")
        elif speed_file.is_file():
            speed = json.loads(speed_file.read_text())
        for mode in ("sequential", "overlapped"):
            f = _kept(f"ghdl-{backend}_{mode}_352x288")
            if args.ghdl_frame == mode:
                rep = run_mode(mode, "352x288", 1, {}, "ghdl", args.reuse, backend=backend)
            elif f.is_file():
                rep = json.loads(f.read_text())
            else:
                continue
            frame = dict(figures(rep, CameraTiming()), mode=mode)
        adaptive = run_adaptive(args.adaptive_frames, args.adaptive_size, sim, args.reuse) \
            if args.adaptive_frames else None
    except (AssertionError, RuntimeError) as e:
        print(f"error: a bench run failed ({str(e).splitlines()[0][:200]})", file=sys.stderr)
        return 1
    write_doc(args.out, size=args.size, figs=figs, small=small, ghdl=(speed, frame), adaptive=adaptive)
    args.json.parent.mkdir(parents=True, exist_ok=True)
    frames = sum(len(r["frames"]) for r in reps.values())
    measured_full = args.size == "352x288"
    derived = small[2] if small else None
    args.json.write_text(json.dumps(dict(
        fps=figs["sequential"]["fps"], fps_modes={m: f["fps"] for m, f in figs.items()},
        frames=frames, size=args.size, clocks=CLOCKS,
        simulator=f"{figs['sequential'].get('simulator')}, simulated time, measured at {args.size}" +
                  ("" if measured_full else " (not 352x288)"),
        measured=figs, derived_from_small=derived, bit_exact=all(f["bit_exact"] for f in figs.values())),
        indent=2) + "\n")
    print(json.dumps(dict(fps_modes={m: f["fps"] for m, f in figs.items()}, size=args.size, simulator=sim)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
