"""Benchmark of the rectification unit: full frames in GHDL, reads and clocks per pixel, accuracy, resources.

``python -m eyestereo.sim.measure.bench_rectifier [--phase sim|report|all] [--quick]`` (``make bench`` runs it):

* **full frames** of the rectifier's VHDL in GHDL with the fetch-port memory model
  (:mod:`eyestereo.sim.lib.fetch_memory`), every beat and every request compared with the bit-true model:
  synthetic-rig pairs at 352x288 (the ``rig`` calibration; a chessboard scene rendered through the rig's
  exact maps) and one of the shared OpenCV chessboard pairs at 640x480 with the toolbox's calibration
  (``opencv``); the memory answering at once and with random delays (wait clocks before beats, a
  request not taken at once, long stalls);
* **clocks per stereo output pixel** and **memory reads per output pixel** next to the thesis's 4;
* the hardware images against OpenCV's ``remap`` (float maps, bilinear): mean and 99th percentile of the
  absolute difference over the pixels in range, against the exact maps and against the float
  polynomials the hardware was converted from;
* **row alignment**: chessboard corners found in the hardware-rectified synthetic-rig images against the
  corners of the exact rectification (the scene's known corners, and corners found in OpenCV's remap
  with the exact maps);
* **resources** of ``fetch_interpolate`` and ``rectifier`` from make synth's flow beside Table 4.4;
* ``docs/img/rectifier_fig412.png``, like the thesis's Fig. 4.12.

Simulation results (reports and the rectified images) stay in ``build/bench_rectifier/``; ``--phase
report`` rebuilds the docs section from them. Writes the section between ``<!-- rectifier-bench:begin
-->`` and ``<!-- rectifier-bench:end -->`` of ``docs/rectifier.md``.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import cv2
import numpy as np

from eyestereo.sim.lib.runner import BUILD, ROOT, hdl_revision, revision_note, run_bench, slug
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH
from eyestereo.tools.reports import publish

OUT = ROOT / "build" / "bench_rectifier"
DOC = ROOT / "docs" / "rectifier.md"
FIG = ROOT / "docs" / "img" / "rectifier_fig412.png"
FIG_RIG = ROOT / "docs" / "img" / "rectifier_rig.png"
BEGIN, END = "<!-- rectifier-bench:begin -->", "<!-- rectifier-bench:end -->"
#: Thesis Table 4.4 (Xilinx ISE): MULT18X18, LUTs.
THESIS = {"fetch_interpolate": (2, 23), "rectifier": (11, 384)}
BOARD = (9, 6)  # inner corners of the synthetic scene's board
SQUARE = 22     # px in the rectified image
DISPARITY = 14  # px, right view shifted left

RANDOM = dict(ready_p=0.7, wait_p=0.3, latency=6, stall_p=0.0005, stall=(50, 400))
MEMORIES = {"at once": dict(ready_p=1.0, wait_p=0.0, latency=0), "random delays": RANDOM}


# ---------------------------------------------------------------------------------------------- scenes
def board_value(x: np.ndarray, y: np.ndarray, width: int, height: int, shift: float = 0.0) -> np.ndarray:
    """The rectified scene: a 10x7-square chessboard on a white margin, a smooth texture around it."""
    bw, bh = (BOARD[0] + 1) * SQUARE, (BOARD[1] + 1) * SQUARE
    x0, y0 = (width - bw) / 2.0 - shift, (height - bh) / 2.0
    u, v = (x - x0) / SQUARE, (y - y0) / SQUARE
    inside = (u >= 0) & (u < BOARD[0] + 1) & (v >= 0) & (v < BOARD[1] + 1)
    margin = (u >= -0.8) & (u < BOARD[0] + 1.8) & (v >= -0.8) & (v < BOARD[1] + 1.8)
    tex = 120 + 50 * np.sin(x / 9.0) * np.cos(y / 13.0) + 30 * np.sin((x + 2 * y) / 5.0)
    sq = ((np.floor(u) + np.floor(v)) % 2 == 0)
    val = np.where(margin, 225.0, tex)
    return np.where(inside, np.where(sq, 25.0, 225.0), val)


def board_corners(width: int, height: int, shift: float = 0.0) -> np.ndarray:
    """The scene's inner corners in rectified coordinates (pixel centres at integers), row by row."""
    bw, bh = (BOARD[0] + 1) * SQUARE, (BOARD[1] + 1) * SQUARE
    x0, y0 = (width - bw) / 2.0 - shift, (height - bh) / 2.0
    # pixel (i, j) samples the scene at its centre (i, j): a corner at scene position x lies at x - 0.0
    return np.array([[x0 + (i + 1) * SQUARE, y0 + (j + 1) * SQUARE] for j in range(BOARD[1])
                     for i in range(BOARD[0])], dtype=np.float64)


def _invert(mx: np.ndarray, my: np.ndarray, u: np.ndarray, v: np.ndarray, iterations: int = 30):
    """Rectified (x, y) with map(x, y) = (u, v), by fixed-point iteration (the maps are near identity)."""
    x, y = u.astype(np.float32).copy(), v.astype(np.float32).copy()
    for _ in range(iterations):
        px = cv2.remap(mx.astype(np.float32), x, y, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
        py = cv2.remap(my.astype(np.float32), x, y, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
        x += u - px
        y += v - py
    return x, y


def synthetic_pair(width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT, ss: int = 4) -> dict:
    """Camera images of the board scene seen through the synthetic rig (exact maps), anti-aliased."""
    from eyestereo.tools.rectify.synthetic_rig import rig_maps

    maps = rig_maps(width, height)
    out = {"maps": maps}
    g = (np.arange(width * ss) + 0.5) / ss - 0.5, (np.arange(height * ss) + 0.5) / ss - 0.5
    u, v = np.meshgrid(*g)
    for side, shift in (("left", 0.0), ("right", float(DISPARITY))):
        x, y = _invert(maps[f"{side}_x"], maps[f"{side}_y"], u.astype(np.float32), v.astype(np.float32))
        val = board_value(x, y, width, height, shift).reshape(height, ss, width, ss).mean(axis=(1, 3))
        out[side] = np.clip(np.floor(val + 0.5), 0, 255).astype(np.uint8)
        out[f"{side}_corners"] = board_corners(width, height, shift)
    return out


def opencv_pair(index: int = 1) -> dict:
    from eyestereo.tools.rectify.calibrations import shared_data_dir

    data = shared_data_dir() / "opencv_stereo_calib"
    out = {}
    for side in ("left", "right"):
        img = cv2.imread(str(data / f"{side}{index:02d}.jpg"), cv2.IMREAD_GRAYSCALE)
        if img is None:
            raise FileNotFoundError(f"cannot read {data / f'{side}{index:02d}.jpg'}")
        out[side] = img
    return out


def opencv_maps():
    from eyestereo.tools.rectify.calib import calibrate_stereo
    from eyestereo.tools.rectify.calibrations import shared_data_dir
    from eyestereo.tools.rectify.maps import compute_maps

    data = shared_data_dir() / "opencv_stereo_calib"
    cal = calibrate_stereo(str(data / "left*.jpg"), str(data / "right*.jpg"), board=(9, 6), square=0.025,
                           progress=False)
    m = compute_maps(cal, method="thesis")
    return {"left_x": m.left_x, "left_y": m.left_y, "right_x": m.right_x, "right_y": m.right_y}


def poly_maps(spec: str) -> dict:
    from eyestereo.tools.rectify import calibrations
    from eyestereo.tools.rectify.polyfit import evaluate

    doc = calibrations.load(spec)
    return {n: evaluate(np.asarray(c, dtype=np.float64), int(doc["degree"]), int(doc["width"]), int(doc["height"]))
            for n, c in doc["float_polynomials"].items()}


# ---------------------------------------------------------------------------------------------- runs
def run_frame(label: str, spec: str, left: np.ndarray, right: np.ndarray, mem: dict, seed: int) -> dict:
    folder = OUT / slug(label)
    folder.mkdir(parents=True, exist_ok=True)
    np.save(folder / "left_in.npy", left)
    np.save(folder / "right_in.npy", right)
    cfg = dict(mem, seed=seed, frames=1, images={"left": str(folder / "left_in.npy"), "right": str(folder / "right_in.npy")},
               dump=str(folder / "out.npz"))
    t0 = time.perf_counter()
    rep = run_bench("rectifier", "tb_rectifier", cfg, name=f"bench_{slug(label)}", params=dict(quantizers=spec))
    rep.update(label=label, spec=spec, memory=mem, seed=seed, wall=time.perf_counter() - t0,
               backend=os.environ.get("GHDL_BACKEND", "mcode"), revision=hdl_revision())
    (folder / "report.json").write_text(json.dumps(rep, indent=2) + "\n")
    print(f"bench_rectifier: {label}: {rep['clocks_per_pixel']:.3f} clocks/px, {rep['reads_per_output_pixel']:.3f} "
          f"reads/px, bit exact {rep['bit_exact']}, {rep['wall']:.0f} s", flush=True)
    return rep


#: Seeds of the further full camera frames with the random-delay memory.
EXTRA_SEEDS = (5, 6, 7, 8)
#: The synthetic rig's runs are labelled (and their folders and figure found) by this.
RIG = f"synthetic rig {FRAME_WIDTH}x{FRAME_HEIGHT}"


def frames_to_run(quick: bool) -> list[tuple[str, str, str, dict, int]]:
    runs = [(f"{RIG}, memory at once", "rig", "synthetic", MEMORIES["at once"], 1),
            (f"{RIG}, random delays", "rig", "synthetic", MEMORIES["random delays"], 2)]
    if not quick:
        runs += [("OpenCV chessboard 640x480, memory at once", "opencv", "opencv", MEMORIES["at once"], 3),
                 ("OpenCV chessboard 640x480, random delays", "opencv", "opencv", MEMORIES["random delays"], 4)]
        # more seeds of the random memory on full frames (the small-frame regressions run many more)
        runs += [(f"{RIG}, random delays, seed {s}", "rig", "synthetic", MEMORIES["random delays"], s)
                 for s in EXTRA_SEEDS]
    return runs


def phase_sim(quick: bool, only: str | None = None) -> None:
    scenes = {}
    for label, spec, scene, mem, seed in frames_to_run(quick):
        if only and only not in label:
            continue
        if scene not in scenes:
            scenes[scene] = synthetic_pair() if scene == "synthetic" else opencv_pair()
        s = scenes[scene]
        run_frame(label, spec, s["left"], s["right"], mem, seed)


# ---------------------------------------------------------------------------------------------- analysis
def remap_error(hw: np.ndarray, cam: np.ndarray, mx: np.ndarray, my: np.ndarray, oor: np.ndarray) -> dict:
    ref = cv2.remap(cam.astype(np.float32), mx.astype(np.float32), my.astype(np.float32), cv2.INTER_LINEAR)
    h, w = cam.shape
    ok = (~oor.astype(bool)) & (mx >= 0) & (mx <= w - 1) & (my >= 0) & (my <= h - 1)
    d = np.abs(hw.astype(np.float64) - ref)[ok]
    return dict(mean=float(d.mean()), p99=float(np.percentile(d, 99)), max=float(d.max()), n=int(ok.sum()))


def corners(img: np.ndarray):
    from eyestereo.tools.rectify.calib import find_corners

    c = find_corners(img, BOARD)
    return None if c is None else c.reshape(-1, 2).astype(np.float64)


def analyse() -> dict:
    from eyestereo.hdl.rectify.calibration import calibration_param
    from eyestereo.tools.models.coordinate_warper import coordinate_warper
    from eyestereo.tools.models.poly_unit import resolve_frac
    from eyestereo.tools.models import rectifier as rect_model

    res = {"frames": [], "remap": [], "rows": None}
    scene = None
    for label, *_ in frames_to_run(False):
        f = OUT / slug(label) / "report.json"
        if f.exists():
            res["frames"].append(json.loads(f.read_text()))
    for spec, kind in (("rig", "synthetic"), ("opencv", "opencv")):
        runs = [r for r in res["frames"] if r["spec"] == spec]
        if not runs:
            continue
        folder = OUT / slug(runs[0]["label"])
        hw = np.load(folder / "out.npz")
        cams = {s: np.load(folder / f"{s}_in.npy") for s in ("left", "right")}
        cal = calibration_param(spec)  # what the bench's rectifier (quantizers=spec) was built from
        frac = resolve_frac(cal, None)
        pr = coordinate_warper(cal, frac)
        model_l, model_r = rect_model.rectifier(cal, cams["left"], cams["right"], frac)
        exact_model = bool(np.array_equal(model_l, hw["left"]) and np.array_equal(model_r, hw["right"]))
        exact = synthetic_pair()["maps"] if kind == "synthetic" else opencv_maps()
        poly = poly_maps(spec)
        for n in exact:
            dd = np.abs(np.asarray(exact[n], dtype=np.float64) - poly[n])
            res.setdefault("fit", []).append(dict(spec=spec, map=n, mean=float(dd.mean()),
                                                   p99=float(np.percentile(dd, 99)), max=float(dd.max())))
        for side, oor in (("left", pr["oor_l"]), ("right", pr["oor_r"])):
            for mname, maps in (("exact maps", exact), ("float polynomials", poly)):
                e = remap_error(hw[side], cams[side], maps[f"{side}_x"], maps[f"{side}_y"], oor)
                res["remap"].append(dict(spec=spec, side=side, maps=mname, **e))
        res.setdefault("model_equal", {})[spec] = exact_model
        if kind == "synthetic":
            scene = synthetic_pair()
            rows = {}
            for side in ("left", "right"):
                ch = corners(hw[side])
                ref = cv2.remap(cams[side].astype(np.float32), exact[f"{side}_x"].astype(np.float32),
                                exact[f"{side}_y"].astype(np.float32), cv2.INTER_LINEAR)
                ce = corners(np.clip(np.floor(ref + 0.5), 0, 255).astype(np.uint8))
                truth = scene[f"{side}_corners"]
                rows[side] = dict(hw=ch, exact_remap=ce, truth=truth)
            out = {}
            for side in ("left", "right"):
                r = rows[side]
                if r["hw"] is None:
                    out[side] = None
                    continue
                out[side] = dict(vs_truth=_stats(r["hw"][:, 1] - r["truth"][:, 1]),
                                 vs_exact_remap=None if r["exact_remap"] is None else
                                 _stats(r["hw"][:, 1] - r["exact_remap"][:, 1]),
                                 n=len(r["hw"]))
            if rows["left"]["hw"] is not None and rows["right"]["hw"] is not None:
                out["left_vs_right_hw"] = _stats(rows["left"]["hw"][:, 1] - rows["right"]["hw"][:, 1])
            if rows["left"]["exact_remap"] is not None and rows["right"]["exact_remap"] is not None:
                out["left_vs_right_exact"] = _stats(rows["left"]["exact_remap"][:, 1] - rows["right"]["exact_remap"][:, 1])
            res["rows"] = out
    return res


def _stats(d: np.ndarray) -> dict:
    a = np.abs(np.asarray(d, dtype=np.float64))
    return dict(mean=float(a.mean()), max=float(a.max()), n=int(a.size))


def figure(path: Path = FIG, pattern: str = "*640x480*at_once*") -> Path | None:
    """Fig. 4.12: a pair before and after the hardware rectification, with horizontal lines."""
    runs = sorted(OUT.glob(f"{pattern}/out.npz"))
    if not runs:
        return None
    folder = runs[0].parent
    hw = np.load(folder / "out.npz")
    cams = [np.load(folder / f"{s}_in.npy") for s in ("left", "right")]
    top = np.hstack(cams)
    bottom = np.hstack([hw["left"], hw["right"]])
    if bottom.shape[1] != top.shape[1]:
        bottom = cv2.resize(bottom, (top.shape[1], int(bottom.shape[0] * top.shape[1] / bottom.shape[1])))
    gap = np.full((8, top.shape[1]), 255, np.uint8)
    img = cv2.cvtColor(np.vstack([top, gap, bottom]), cv2.COLOR_GRAY2BGR)
    for y in range(20, img.shape[0], 32):
        cv2.line(img, (0, y), (img.shape[1] - 1, y), (0, 0, 255) if y < top.shape[0] else (0, 160, 0), 1)
    path.parent.mkdir(parents=True, exist_ok=True)
    ok, buf = cv2.imencode(".png", img, [cv2.IMWRITE_PNG_COMPRESSION, 9])
    if not ok:
        raise RuntimeError("PNG encoding failed")
    tmp = path.with_suffix(".tmp.png")
    tmp.write_bytes(buf.tobytes())
    tmp.replace(path)
    return path


def resources(reuse: bool = False) -> list[dict]:
    """Yosys xc3se cell counts of GHDL's netlist (make synth's flow); ``reuse``: from an earlier run's
    ``stat.txt`` where there is one."""
    from eyestereo.hdl.flow import synth

    folder = BUILD.parent / "synth_rectifier"
    out = []
    for label, block, params in (("fetch_interpolate", "fetch_interpolate", {}), ("rectifier", "rectifier", {}),
                                 ("rectifier, OpenCV 640x480", "rectifier", dict(quantizers="opencv"))):
        stat = folder / slug(label) / "stat.txt"
        if reuse:
            if stat.exists():
                out.append(dict(label=label, block=block, revision=_synth_revision(stat),
                                **synth.summarize(synth.parse_stat(stat.read_text()))))
            continue
        print(f"bench_rectifier: synthesizing {label} ...", flush=True)
        try:
            r = synth.synth_block(block, folder, label=label, pnr=False, **params)
        except (FileNotFoundError, RuntimeError, ValueError) as exc:
            print(f"bench_rectifier: skipped {label}: {exc}", file=sys.stderr)
            continue
        out.append(dict(label=label, block=block, revision=hdl_revision(), **r["summary"]))
        (folder / slug(label) / "revision.txt").write_text(hdl_revision() + "\n")
    (OUT / "resources.json").write_text(json.dumps(out, indent=2, default=str) + "\n")
    return out


def _synth_revision(stat: Path) -> str:
    f = stat.parent / "revision.txt"
    return f.read_text().strip() if f.exists() else "?"


def report_text(res: dict, rs: list[dict]) -> str:
    L = []
    fr = res["frames"]
    if fr:
        L += [f"Measured by `python -m eyestereo.sim.measure.bench_rectifier` on GHDL ({fr[0].get('backend', 'mcode')} back end): "
              "the rectifier's VHDL with the fetch-port memory model of `sim/lib/fetch_memory.py` (which checks the port's "
              "rules on every clock); every output beat (data, cam, eol, eof) and every memory request (x, y, cam, "
              "mask) compared with the bit-true model. Clocks per stereo output pixel: from `start` to the last beat, "
              "per rectified pixel (two beats, left and right). Reads: pixels the memory sent, per output pixel of one "
              "camera (the thesis reads 4 per output pixel); per in-range output pixel: without the black ones, which "
              "need no read.", "",
              "| frame | memory | stereo pixels | bit-exact | clocks / stereo pixel | reads / output pixel | "
              "reads / in-range pixel | thesis | black sides | sim wall | HDL revision |", "|---|---|---:|---|---:|---:|---:|---:|---:|---:|---|"]
        for r in fr:
            m = r["memory"]
            mem = ("at once" if m.get("wait_p", 0) == 0 and m.get("ready_p", 1) >= 1 else
                   f"ready p={m['ready_p']}, latency {m['latency']}, wait p={m['wait_p']} per beat, stalls "
                   f"{m['stall'][0]}..{m['stall'][1]} clocks p={m['stall_p']}/clock")
            L.append(f"| {r['label'].split(',')[0]} (`{r['spec']}`, seed {r['seed']}) | {mem} | {r['width'] * r['height']:,} | "
                     f"{'yes' if r['bit_exact'] else 'NO'} | {r['clocks_per_pixel']:.3f} | {r['reads_per_output_pixel']:.3f} | "
                     f"{r['reads_per_inrange_pixel']:.3f} | 4 | {100 * r['oor_sides'] / (2 * r['width'] * r['height']):.1f} % | "
                     f"{r['wall']:.0f} s | {r.get('revision', '4d75c52')} |")
        L += revision_note((r.get("revision", "4d75c52") for r in fr),
                           "python -m eyestereo.sim.measure.vhdl_diff REV rectifier:quantizers=rig")
        L.append("")
    if res["remap"]:
        L += ["Hardware images against OpenCV's `remap` (float32 maps, `INTER_LINEAR`) of the same camera images, "
              "over the pixels in range (the hardware's flag low and the map inside the image); grey levels. "
              "\"exact maps\": the rig's exact maps / the toolbox's thesis maps of the OpenCV calibration; \"float "
              "polynomials\": the degree-3 fit the hardware was converted from (so only the fixed-point arithmetic "
              "and the rounding differ). Goal: mean below 1.", "",
              "| calibration | side | maps | pixels | mean abs diff | p99 | max |", "|---|---|---|---:|---:|---:|---:|"]
        for e in res["remap"]:
            L.append(f"| `{e['spec']}` | {e['side']} | {e['maps']} | {e['n']:,} | {e['mean']:.3f} | {e['p99']:.2f} | {e['max']:.1f} |")
        L += ["", "Against the float polynomials the hardware is within the goal on both calibrations: what remains is "
              "the coordinates' `frac` fraction bits (floor, 1/32 px on the rig, 1/64 px on the OpenCV calibration) "
              "and the final rounding, largest at the board's sharp edges (the p99). Against the exact maps the "
              "degree-3 regression's own residual adds to it (|exact map - float polynomial| below, px): small on "
              "the rig, larger towards the corners of the OpenCV calibration's 640x480 maps; the hardware inherits "
              "it from the polynomials it evaluates (the toolbox's Table 4.1, docs/toolbox.md), not from its "
              "arithmetic.", "", "| calibration | map | mean (px) | p99 (px) | max (px) |", "|---|---|---:|---:|---:|"]
        for e in res.get("fit", []):
            L.append(f"| `{e['spec']}` | {e['map']} | {e['mean']:.3f} | {e['p99']:.3f} | {e['max']:.3f} |")
        L.append("")
    rows = res.get("rows")
    if rows:
        L += [f"Row alignment on the synthetic rig (a {BOARD[0]}x{BOARD[1]}-corner board, squares of {SQUARE} px, disparity "
              f"{DISPARITY} px, rendered through the rig's exact maps with 4x4 supersampling): corners found (the toolbox's "
              "`find_corners`, saddle refinement) in the hardware-rectified images, rows against the scene's true corner "
              "rows (the exact rectification) and against the corners found in OpenCV's remap with the exact maps; "
              "and left against right. Goal: mean within 0.15 px.", "",
              "| compared | corners | mean abs row difference (px) | max (px) |", "|---|---:|---:|---:|"]
        for side in ("left", "right"):
            r = rows.get(side)
            if not r:
                L.append(f"| {side}: hardware | - | board not found | - |")
                continue
            L.append(f"| {side}: hardware vs exact rectification (true corners) | {r['vs_truth']['n']} | "
                     f"{r['vs_truth']['mean']:.3f} | {r['vs_truth']['max']:.3f} |")
            if r.get("vs_exact_remap"):
                L.append(f"| {side}: hardware vs corners in the exact remap | {r['vs_exact_remap']['n']} | "
                         f"{r['vs_exact_remap']['mean']:.3f} | {r['vs_exact_remap']['max']:.3f} |")
        for k, name in (("left_vs_right_hw", "left vs right, hardware"), ("left_vs_right_exact", "left vs right, exact remap")):
            if rows.get(k):
                L.append(f"| {name} | {rows[k]['n']} | {rows[k]['mean']:.3f} | {rows[k]['max']:.3f} |")
        L.append("")
    if rs:
        L += ["Resources from make synth's flow (GHDL's netlist of the VHDL, Yosys `synth_xilinx -family xc3se`), "
              "beside the thesis's Table 4.4 (Xilinx ISE):", "",
              "| block | LUT | LUT-RAM | FF | RAMB16 | MULT18X18 | thesis MULT18X18 | thesis LUT | HDL revision |", "|---|---:|---:|---:|---:|---:|---:|---:|---|"]
        for r in rs:
            th = THESIS.get(r.get("block", ""), ("-", "-"))
            L.append(f"| {r.get('label')} | {r.get('LUT', '?')} | {r.get('LUTRAM', 0)} | {r.get('FF', '?')} | "
                     f"{r.get('RAMB16', 0)} | {r.get('MULT18X18', '?')} | {th[0]} | {th[1]} | {r.get('revision', '?')} |")
        L.append("")
    if FIG.exists():
        L += ["![Fig. 4.12](img/rectifier_fig412.png)", "",
              "The OpenCV chessboard pair 01 before (top, camera images) and after (bottom) the rectification in GHDL "
              "(the rectifier's VHDL, memory model at once), lines every 32 rows.", ""]
    if FIG_RIG.exists():
        L += ["![synthetic rig](img/rectifier_rig.png)", "",
              f"The synthetic-rig scene ({FRAME_WIDTH}x{FRAME_HEIGHT}) before and after the rectification in GHDL, "
              "lines every 32 rows.", ""]
    return "\n".join(L)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--phase", choices=("sim", "report", "all"), default="all")
    ap.add_argument("--quick", action="store_true", help="the synthetic rig only")
    ap.add_argument("--only", help="run only the frames whose label contains this")
    ap.add_argument("--no-synth", action="store_true")
    ap.add_argument("--reuse-synth", action="store_true", help="cell counts of an earlier synthesis only (none where there is none)")
    ap.add_argument("--no-write", action="store_true")
    a = ap.parse_args(argv)
    OUT.mkdir(parents=True, exist_ok=True)
    if a.phase in ("sim", "all"):
        phase_sim(a.quick, a.only)
    if a.phase in ("report", "all"):
        res = analyse()
        (OUT / "analysis.json").write_text(json.dumps(res, indent=2, default=lambda o: None) + "\n")
        rs = [] if a.no_synth else resources(a.reuse_synth)
        if not rs and (OUT / "resources.json").exists():
            rs = json.loads((OUT / "resources.json").read_text())
        figure()
        figure(FIG_RIG, f"{slug(RIG)}*at_once*")
        # the section keeps a blank line before its end marker
        publish(report_text(res, rs) + "\n", None if a.no_write else DOC, BEGIN, END)
    return 0


if __name__ == "__main__":
    sys.exit(main())
