"""``make report``: every table and figure of the thesis the project can reproduce, next to the thesis's own.

``python -m eyestereo.tools.reports.thesis [--out docs/thesis.md] [--img DIR] [--synth build/synth/resources.json]
[--section KEY ...]`` writes one Markdown document. Each section is one function in :data:`SECTIONS`; it
checks its own inputs and, when they do not exist yet, says so ("not yet available") instead of
failing, so the sections of work still in progress (the rectifier's Table 4.4, the stereo Harris's
Table 6.4, the measured frame rate) fill in by themselves once their owners' outputs appear:

==============  =====================================================================================
key             what (inputs)
==============  =====================================================================================
regression      Table 4.1 and Fig. 4.1: polynomial regression of the rectification maps (synthetic
                EyeBot rig; the OpenCV sample pairs when ``../shared/data`` has them)
quantized       Table A.2 and Fig. 4.6: the float-to-fixed conversion of the degree-3 polynomials
rectifier       Table 4.4: rectifier resources (``make synth``'s results, rectifier blocks)
convolution     Tables 6.1-6.3: separable vs full convolution, NMS, mono Harris resources (``make synth``)
stereo_harris   Table 6.4: stereo Harris resources (``make synth``, block ``harris_stereo``)
harris          Figs. 5.3/5.4: corners with a global threshold and with 4x4 block thresholds (bit-true model)
matching        Fig. 7.5 and the split-correlation gain (Middlebury Tsukuba/Venus, scikit-image's Motorcycle)
framerate       the frame rate: the thesis's 20.01 fps estimate against the system's measured one
                (``build/system/framerate.json``, written by the complete system's benchmark)
==============  =====================================================================================

Resources come from ``build/synth/resources.json`` (:mod:`eyestereo.hdl.flow.synth`; this module reads the
file and never imports the HDL side). Figures are PNG files in ``--img`` (default: ``img/thesis``
next to ``--out``); ``make report`` writes ``docs/thesis.md`` and ``docs/img/thesis/``. Progress goes to
stderr, one line per section. A section that fails is reported in the document and makes the command
exit with status 1; the document is written whole or not at all.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from collections.abc import Callable

import numpy as np

import eyestereo.tools
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH, K_CODE_DEFAULT, THRESHOLD_BLOCKS

ROOT = Path(eyestereo.tools.__file__).resolve().parents[1]


def _find_shared() -> Path:
    """The project's shared data: $EYESTEREO_SHARED, else the first ``shared/data`` beside the repository
    or one of its parents (a clone in ``X/`` has it in ``X/../shared``; a worktree may sit deeper)."""
    env = os.environ.get("EYESTEREO_SHARED")
    if env:
        return Path(env)
    for p in ROOT.parents:
        if (p / "shared" / "data").is_dir():
            return p / "shared" / "data"
    return ROOT.parent / "shared" / "data"


SHARED = _find_shared()
DATA = ROOT / "tests" / "data"
DEFAULT_SYNTH = ROOT / "build" / "synth" / "resources.json"
DEFAULT_FRAMERATE = ROOT / "build" / "system" / "framerate.json"


class NotYetAvailable(Exception):
    """A section's inputs do not exist yet; the message says which and who makes them.

    ``partial``: Markdown lines the section could write anyway (e.g. the thesis's side of a comparison).
    """

    def __init__(self, message: str, partial: list[str] | None = None):
        super().__init__(message)
        self.partial = partial or []


@dataclass
class Context:
    img: Path
    img_rel: str
    synth: Path = DEFAULT_SYNTH
    framerate: Path = DEFAULT_FRAMERATE
    shared: Path = SHARED  # the project's shared data (Middlebury, the OpenCV calibration pairs)
    quick: bool = False  # small sizes and sweeps (tests)
    cache: dict = field(default_factory=dict)

    def figure(self, name: str, fig) -> str:
        """Save a matplotlib figure as ``img/name.png`` (atomically); the Markdown image line."""
        self.img.mkdir(parents=True, exist_ok=True)
        path = self.img / f"{name}.png"
        fd, tmp = tempfile.mkstemp(prefix=f".{name}.", suffix=".png", dir=self.img)
        os.close(fd)
        try:
            fig.savefig(tmp, format="png")
            os.chmod(tmp, 0o644)
            os.replace(tmp, path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
        return f"![{name}]({self.img_rel}/{name}.png)"


def _figure(w: float, h: float):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(w, h), dpi=90)
    FigureCanvasAgg(fig)
    return fig


def _table(head: list[str], rows: list[list], align: str | None = None) -> list[str]:
    align = align or "|---" + "|---:" * (len(head) - 1) + "|"
    return ["| " + " | ".join(head) + " |", align] + ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]


# --------------------------------------------------------------------------------------------------
# Rectification: Table 4.1, Fig. 4.1, Table A.2, Fig. 4.6

#: Thesis Table 4.1 (EyeBot M6, 352x288): max / mean / var of x, y, r per row.
THESIS_4_1 = {"none": (12.90, 20.32, 25.83, 5.97, 9.03, 11.22, 22.78, 55.14, 47.85),
              "2": (8.14, 9.61, 14.10, 1.90, 1.72, 2.77, 5.54, 4.94, 2.79),
              "3": (1.40, 3.51, 5.22, 0.25, 0.22, 0.36, 0.11, 0.09, 0.08),
              "4": (1.81, 1.76, 2.48, 0.18, 0.16, 0.25, 0.05, 0.04, 0.03)}


def _rig_maps(ctx: Context):
    if "rig_maps" not in ctx.cache:
        from eyestereo.tools.rectify.maps import ground_truth_maps
        from eyestereo.tools.rectify.rig import eyebot_rig

        size = (176, 144) if ctx.quick else (FRAME_WIDTH, FRAME_HEIGHT)
        ctx.cache["rig_maps"] = ground_truth_maps(eyebot_rig(), size=size)
    return ctx.cache["rig_maps"]


def _fits(ctx: Context, key: str, maps) -> dict:
    if key not in ctx.cache:
        from eyestereo.tools.rectify import polyfit

        ctx.cache[key] = {d: polyfit.fit(maps, d) for d in (2, 3, 4)}
    return ctx.cache[key]


def _stat_row(s: dict) -> list[str]:
    def f(v):
        return f"{v:.2f}" if v >= 1 else f"{v:.3f}" if v >= 0.01 else f"{v:.1e}"
    return [f(s[k][c]) for k in ("max", "mean", "var") for c in ("x", "y", "r")]


def _opencv_maps(shared: Path):
    from eyestereo.tools.rectify.calib import calibrate_stereo
    from eyestereo.tools.rectify.maps import compute_maps

    d = shared / "opencv_stereo_calib"
    if not (d / "left01.jpg").is_file():
        return None
    calib = calibrate_stereo(str(d / "left*.jpg"), str(d / "right*.jpg"), board=(9, 6), square=0.025,
                             progress=False)
    return compute_maps(calib)


def section_regression(ctx: Context) -> list[str]:
    """Table 4.1 and Fig. 4.1."""
    maps = _rig_maps(ctx)
    fits = _fits(ctx, "rig_fits", maps)
    head = ["row", "max x", "max y", "max r", "mean x", "mean y", "mean r", "var x", "var y", "var r"]
    rows = [[f"**thesis** {'none' if k == 'none' else 'degree ' + k}"] + [f"{v:.2f}" for v in vals]
            for k, vals in THESIS_4_1.items()]
    sets = [("synthetic EyeBot rig", maps, fits)]
    cv = None if ctx.quick else _opencv_maps(ctx.shared)
    if cv is not None:
        sets.append(("OpenCV sample pairs (640x480)", cv, _fits(ctx, "cv_fits", cv)))
    for name, _, fs in sets:
        for side in ("left", "right"):
            rows.append([f"**{name}, {side}** none"] + _stat_row(fs[3].report["none"][side]))
            for d in (2, 3, 4):
                rows.append([f"degree {d}"] + _stat_row(fs[d].report["fit"][side]))
    out = [f"Residual of the regression polynomials against the exact backward maps over every pixel of the "
           f"rectified image ({maps.width}x{maps.height} for the rig), in pixels: max and mean of |e| and the "
           "variance of e per axis, r the Euclidean residual; *none* is the map against the identity "
           "(how far rectification moves pixels). The synthetic rig copies the EyeBot M6 (f = 4.9 mm, "
           "9 um pixels, 66 mm baseline, barrel lenses; `eyestereo.tools.rectify.rig`)."
           + ("" if cv is not None or ctx.quick else " The OpenCV sample pairs were not found in "
              f"`{ctx.shared / 'opencv_stereo_calib'}` and are left out."), ""]
    out += _table(head, rows)
    r3 = fits[3].report["fit"]["both"]["mean"]["r"]
    r2 = fits[2].report["fit"]["both"]["mean"]["r"]
    out += ["", f"As in the thesis, degree 2 is not enough (mean r {r2:.2f} px on the rig) and degree 3 is "
            f"(mean r {r3:.3f} px), with degree 4 adding little; the rig's smooth lenses leave less "
            "residual than the thesis's real ones.", ""]
    # Fig. 4.1: |e| of the left camera, no correction and degrees 2, 3, 4.
    mx, my = maps.side("left")
    h, w = mx.shape
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float64)
    panels = [("(a) no correction", mx - xx, my - yy)]
    for d, tag in ((2, "(b)"), (3, "(c)"), (4, "(d)")):
        panels.append((f"{tag} degree {d}", fits[d].evaluate("left_x") - mx, fits[d].evaluate("left_y") - my))
    fig = _figure(10, 8.2)
    step = max(8, w // 22)
    for i, (title, ex, ey) in enumerate(panels):
        ax = fig.add_subplot(2, 2, i + 1)
        r = np.hypot(ex, ey)
        levels = [l for l in (0.01, 0.02, 0.05, 0.1, 0.25, 0.5, 1, 2, 5, 10, 20, 50) if l < r.max()]
        im = ax.contourf(r, levels=[0] + levels + [r.max() * 1.001], cmap="viridis")
        ax.contour(r, levels=levels, colors="w", linewidths=0.4)
        gy, gx = np.mgrid[step // 2:h:step, step // 2:w:step]
        ax.quiver(gx, gy, ex[gy, gx], -ey[gy, gx], color="w", width=0.003)
        ax.set_title(f"{title}: max {r.max():.2f} px", fontsize=9)
        ax.set_xlim(0, w - 1)
        ax.set_ylim(h - 1, 0)
        ax.set_aspect("equal")
        fig.colorbar(im, ax=ax, shrink=0.8, label="|e| (px)")
    fig.tight_layout()
    out += ["Fig. 4.1 (left camera of the rig): remaining error |e| in pixels (filled contours) and its "
            "direction (arrows, not to scale).", "", ctx.figure("fig_4_1_residuals", fig), ""]
    return out


def section_quantized(ctx: Context) -> list[str]:
    """Table A.2 and Fig. 4.6: the float-to-fixed conversion of the rig's degree-3 polynomials."""
    from eyestereo.tools.rectify.ffc import fixed_eval, run_ffc
    from eyestereo.tools.reports.bench_ffc import TABLE_A2

    maps = _rig_maps(ctx)
    fit3 = _fits(ctx, "rig_fits", maps)[3]
    w, h = maps.width, maps.height
    polys = {k: [float(v) for v in fit3.coeffs[k]] for k in ("left_x", "left_y", "right_x", "right_y")}
    t0 = time.perf_counter()
    res = run_ffc(polys, w, h, max_error=0.01)
    secs = time.perf_counter() - t0
    head = ["quantizer", "X left", "Y left", "X right", "Y right", "merged", "thesis merged"]
    rows = []
    for i in range(26):
        per = [("0" if r.zero[i] else str(r.formats[i])) for r in res.per_polynomial.values()]
        rows.append([f"q{i + 1}"] + per + [str(res.merged[i]), TABLE_A2["merged"][i]])
    thesis_bits = sum(int(s.split("[")[1].split(",")[0]) for s in TABLE_A2["merged"])
    rows.append(["**total bits**"] + [str(sum(f.wl for f in r.formats)) for r in res.per_polynomial.values()]
                + [f"**{res.total_bits}**", f"**{thesis_bits}**"])
    out = [f"Table A.2: the 26 quantizers of the degree-3 Horner form (Fig. 4.4) found by the automatic "
           f"float-to-fixed conversion (coarse bisection + greedy, bound 0.01 px^2 mean squared error per "
           f"polynomial, all {w * h} pixels; {secs:.1f} s here) for the synthetic rig, per polynomial and "
           "merged, with the thesis's merged column (from its own calibration, so only the kind of formats "
           "compares, not each one).", ""]
    out += _table(head, rows, "|---|---|---|---|---|---|---|")
    out += ["", "Errors of the merged fixed-point polynomials against the float ones: " + ", ".join(
        f"{k} {v:.5f} px^2" for k, v in res.merged_errors.items()) + " (bound 0.01).", ""]
    # Fig. 4.6: residual of the quantized polynomial against the exact map (left), next to the float one.
    mx, my = maps.side("left")
    fx = fixed_eval(polys["left_x"], res.merged, w, h)[1]
    fy = fixed_eval(polys["left_y"], res.merged, w, h)[1]
    flt = np.hypot(fit3.evaluate("left_x") - mx, fit3.evaluate("left_y") - my)
    qnt = np.hypot(fx - mx, fy - my)
    fig = _figure(10, 4.2)
    vmax = float(max(flt.max(), qnt.max()))
    for i, (title, r) in enumerate((("float degree 3 (Fig. 4.1 c)", flt), ("quantized degree 3 (Fig. 4.6)", qnt))):
        ax = fig.add_subplot(1, 2, i + 1)
        im = ax.imshow(r, vmin=0, vmax=vmax, cmap="viridis")
        ax.set_title(f"{title}: mean {r.mean():.3f}, max {r.max():.3f} px", fontsize=9)
        fig.colorbar(im, ax=ax, shrink=0.8, label="|e| (px)")
    fig.tight_layout()
    out += [f"Fig. 4.6 (left camera): the error the quantized polynomials leave against the exact map, "
            f"next to the float polynomial's own: mean {flt.mean():.3f} -> {qnt.mean():.3f} px, max "
            f"{flt.max():.3f} -> {qnt.max():.3f} px: quantization adds {qnt.mean() - flt.mean():.3f} px on "
            "average, small against a pixel, as in the thesis (its Fig. 4.6 against Fig. 4.1 c).", "",
            ctx.figure("fig_4_6_quantized", fig), ""]
    return out


# --------------------------------------------------------------------------------------------------
# Resources: Tables 4.4, 6.1-6.4 (from make synth)

def _resources(ctx: Context) -> dict[str, dict]:
    if not ctx.synth.is_file():
        raise NotYetAvailable(f"no synthesis results at `{ctx.synth}`: run `make synth`")
    try:
        data = json.loads(ctx.synth.read_text())
        return {r["label"]: r for r in data}
    except (json.JSONDecodeError, KeyError, TypeError) as e:
        raise ValueError(f"{ctx.synth} is not make synth's resources.json ({e})") from None


def _res_cells(r: dict | None) -> list[str]:
    if r is None:
        return ["-", "-", "-", "-"]
    s = r["summary"]
    lut = f"{s['LUT']}" + (f" + {s['LUTRAM']} RAM" if s.get("LUTRAM") else "")
    fm = r.get("fmax") or {}
    f = ", ".join(f"{v['achieved']:.0f}" for v in fm.values() if v.get("achieved")) or "-"
    return [lut, str(s["RAMB16"]), str(s["MULT18X18"]), f]


RES_HEAD = ["module", "thesis LUTs", "thesis BRAM", "thesis MUL", "LUTs", "RAMB16", "MULT18X18", "fmax ECP5 (MHz)"]


def _res_note(res: dict) -> str:
    any_r = next(iter(res.values()))
    return ("Ours: Yosys `synth_xilinx -family xc3se` of GHDL's netlist of the generated VHDL (`make synth`; "
            "LUTs are 4-input LUTs, LUT-RAM counted apart); fmax from nextpnr-ecp5 on an ECP5-25 (speed 6), "
            "the open stand-in for the Spartan-3E. Thesis: Xilinx ISE on the Spartan-3E 500 (post-PAR LUTs "
            "for Table 4.4)." + ("" if any_r.get("fmax") else " (fmax: `make synth` ran without place and route.)"))


#: Thesis Table 4.4: (MUL, LUTs) per unit; our blocks that correspond.
THESIS_4_4 = [("Calculation Unit", 9, 262, "poly_unit"), ("Coordinate Warper", 0, 99, "coordinate_warper"),
              ("FAI (fetch and interpolation)", 2, 23, "fetch_interpolate"), ("Total", 11, 384, "rectifier")]


def section_rectifier(ctx: Context) -> list[str]:
    """Table 4.4: the rectification unit's resources."""
    res = _resources(ctx)
    if not any(b in res for *_, b in THESIS_4_4):
        raise NotYetAvailable("the rectifier blocks (poly_unit, coordinate_warper, fetch_interpolate, rectifier) "
                              "are not in make synth's results yet (the rectifier work, issues 10 and 11)")
    rows = []
    for name, mul, lut, block in THESIS_4_4:
        r = res.get(block)
        c = _res_cells(r)
        rows.append([f"{name} (`{block}`)", lut, "-", mul] + c)
    return ["Table 4.4: rectification unit.", ""] + _table(RES_HEAD, rows) + ["", _res_note(res), ""]


#: Thesis Tables 6.1 and 6.2: LUTs unseparated / separated.
THESIS_6_1 = [("Sobel", 314, 259), ("Window", 1241, 843)]
THESIS_6_2 = [("Non-Maximum 3x3", 419, 381), ("Non-Maximum 5x5", 1011, 706)]
#: Thesis Table 6.3 (mono Harris): LUTs, BRAM, MUL per module, and our configuration's label.
THESIS_6_3 = [("Sobel", 259, 2, 0, "sobel"), ("Window", 843, 4, 3, "harris_window"),
              ("Cornerness", 132, 0, 5, "cornerness"), ("Pre-Threshold 1x1", 20, 0, 0, "prethreshold 1x1"),
              ("Pre-Threshold 4x4", 197, 0, 0, "prethreshold"), ("Non-Maximum 1x1", 7, 0, 0, "nms 1x1"),
              ("Non-Maximum 3x3", 381, 2, 0, "nms"), ("Non-Maximum 5x5", 706, 4, 0, "nms 5x5")]


def section_convolution(ctx: Context) -> list[str]:
    """Tables 6.1, 6.2 and 6.3."""
    res = _resources(ctx)
    out = ["Table 6.1: separated against unseparated convolution. The thesis compares its whole Sobel "
           "(Ix and Iy) and window function; here the same comparison is made on one Sobel kernel (Ix, "
           "[-1 0 1] x [1 2 1]) through the generic `convolve` block in both forms, next to the complete "
           "separable `sobel` and `harris_window`.", ""]
    sep, full = res.get("convolve sobel-x separable"), res.get("convolve sobel-x full")
    rows = []
    for (name, un, se), label in zip(THESIS_6_1, ("sobel", "harris_window")):
        r = res.get(label)
        rows.append([name, un, se, "-", r["summary"]["LUT"] if r else "-"])
    rows.append(["Sobel Ix alone (`convolve`)", "-", "-", full["summary"]["LUT"] if full else "-",
                 sep["summary"]["LUT"] if sep else "-"])
    out += _table(["module", "thesis LUTs unseparated", "thesis LUTs separated", "LUTs unseparated",
                   "LUTs separated"], rows)
    out += ["", "Table 6.2: non-maximum suppression; the library builds only the separated form.", ""]
    rows = [[name, un, se, "-", res[label]["summary"]["LUT"] if label in res else "-"]
            for (name, un, se), label in zip(THESIS_6_2, ("nms", "nms 5x5"))]
    out += _table(["module", "thesis LUTs unseparated", "thesis LUTs separated", "LUTs unseparated",
                   "LUTs separated"], rows)
    out += ["", "Table 6.3: mono Harris, per module.", ""]
    rows = []
    for name, lut, bram, mul, label in THESIS_6_3:
        rows.append([name, lut, bram, mul] + _res_cells(res.get(label)))
    tot = [sum(t[i] for t in THESIS_6_3 if t[4] in ("sobel", "harris_window", "cornerness", "prethreshold", "nms"))
           for i in (1, 2, 3)]
    rows.append(["**harris_mono** (4x4, NMS 3x3; thesis: its modules summed)"] + tot
                + _res_cells(res.get("harris_mono")))
    if "harris_mono nms 5x5" in res:
        rows.append(["harris_mono (4x4, NMS 5x5)", "-", "-", "-"] + _res_cells(res["harris_mono nms 5x5"]))
    out += _table(RES_HEAD, rows)
    hm = res.get("harris_mono")
    out += ["", _res_note(res)]
    if hm and hm.get("fmax"):
        a = hm["fmax"]["clk"]["achieved"]
        out += ["", f"Clock: the thesis ran the Harris detector at 50 MHz (ISE estimated 65 MHz); harris_mono "
                f"reaches {a:.1f} MHz on the ECP5 here."]
    return out + [""]


#: Thesis Table 6.4 (stereo Harris): LUTs, BRAM, MUL.
THESIS_6_4 = [("Sobel", 374, 2, 0), ("Window", 1818, 8, 1), ("Cornerness", 266, 0, 2),
              ("Pre-Thresholding 1x1", 34, 0, 0), ("Pre-Thresholding 4x4", 477, 0, 0),
              ("Non-Maximum 1x1", 6, 0, 0), ("Non-Maximum 3x3", 538, 2, 0)]


def section_stereo_harris(ctx: Context) -> list[str]:
    """Table 6.4: the stereo Harris detector."""
    res = _resources(ctx)
    ours = [r for label, r in res.items() if r["block"] == "harris_stereo"]
    if not ours:
        raise NotYetAvailable("harris_stereo is not in make synth's results yet (the stereo Harris work, issue 14)")
    rows = [[n, l, b, m, "", "", "", ""] for n, l, b, m in THESIS_6_4]
    rows.append(["**total (thesis: modules summed)**", sum(t[1] for t in THESIS_6_4), sum(t[2] for t in THESIS_6_4),
                 sum(t[3] for t in THESIS_6_4), "", "", "", ""])
    for r in ours:
        rows.append([f"`{r['label']}`", "-", "-", "-"] + _res_cells(r))
    return ["Table 6.4: stereo Harris (the thesis per module; ours per configuration).", ""] + \
        _table(RES_HEAD, rows) + ["", _res_note(res), ""]


# --------------------------------------------------------------------------------------------------
# Harris: Figs. 5.3 / 5.4

def _load_image(path: Path, w: int, h: int) -> np.ndarray:
    import cv2

    img = cv2.imread(str(path), cv2.IMREAD_GRAYSCALE)
    if img is None:
        raise NotYetAvailable(f"cannot read {path}")
    y0, x0 = (img.shape[0] - h) // 2, (img.shape[1] - w) // 2
    return img[y0:y0 + h, x0:x0 + w].astype(np.int64)


def _features_for(corner, thresholds, blocks, nms) -> np.ndarray:
    from eyestereo.tools.models import nms as nms_model
    from eyestereo.tools.models import prethreshold as pre_model
    from eyestereo.tools.models.border import interior_mask
    from eyestereo.tools.models.harris_mono import radius

    flags, _ = nms_model.nms(pre_model.prethreshold(corner, thresholds, blocks), nms)
    h, w = corner.shape
    return flags.astype(bool) & interior_mask(h, w, radius(nms))


def _threshold_for(count_of, target: int, lo: int, hi: int) -> int:
    """Smallest threshold code in [lo, hi] with count_of(t) <= target (count falls with t)."""
    while lo < hi:
        mid = (lo + hi) // 2
        if count_of(mid) <= target:
            hi = mid
        else:
            lo = mid + 1
    return lo


def section_harris(ctx: Context) -> list[str]:
    """Figs. 5.3 and 5.4: global threshold, NMS, and 4x4 block thresholds (the bit-true model = the VHDL)."""
    from eyestereo.tools.models import harris_mono as hm
    from eyestereo.tools.models.prethreshold import block_index

    w, h = (176, 144) if ctx.quick else (FRAME_WIDTH, FRAME_HEIGHT)
    name = "chessboard_left01.jpg"
    img = _load_image(DATA / name, w, h)
    corner = hm.harris_stages(img, K_CODE_DEFAULT, [0], blocks=(1, 1), nms=1)["cornerness"]
    target = 40 if ctx.quick else 160
    hi = int(corner.max()) + 1
    t_glob = _threshold_for(lambda t: int(_features_for(corner, [t], (1, 1), 5).sum()), target, 1, hi)
    # Per block: the same number of corners in each of the 16 blocks (two passes: NMS sees across borders).
    bidx = block_index(h, w, THRESHOLD_BLOCKS)
    thr = [t_glob] * 16
    for _ in range(2):
        for b in range(16):
            def count(t, b=b):
                th = list(thr)
                th[b] = t
                return int((_features_for(corner, th, THRESHOLD_BLOCKS, 5) & (bidx == b)).sum())
            thr[b] = _threshold_for(count, target // 16, 1, hi)
    cases = [("(a) global threshold, no NMS (Fig. 5.3)", [t_glob], (1, 1), 1),
             ("(b) global threshold, NMS 5x5 (Fig. 5.4 a)", [t_glob], (1, 1), 5),
             ("(c) 4x4 block thresholds, NMS 5x5 (Fig. 5.4 b)", thr, THRESHOLD_BLOCKS, 5)]
    fig = _figure(13, 4.4)
    rows = []
    for i, (title, th, blocks, nms) in enumerate(cases):
        f = _features_for(corner, th, blocks, nms)
        per = np.bincount(bidx[f], minlength=16)
        rows.append([title, int(f.sum()), int((per == 0).sum()), int(per.min()), int(per.max())])
        ax = fig.add_subplot(1, 3, i + 1)
        ax.imshow(img, cmap="gray", vmin=0, vmax=255)
        ys, xs = np.nonzero(f)
        ax.plot(xs, ys, "r+", ms=5, mew=1)
        for e in range(1, 4):
            ax.axvline(e * w / 4 - 0.5, color="y", lw=0.4, alpha=0.6)
            ax.axhline(e * h / 4 - 0.5, color="y", lw=0.4, alpha=0.6)
        ax.set_title(f"{title}\n{int(f.sum())} features", fontsize=8)
        ax.axis("off")
    fig.tight_layout()
    fig.subplots_adjust(top=0.86)
    out = [f"The mono Harris chain (Sobel, 5x5 window, cornerness with k = 0.04, pre-threshold, NMS) on "
           f"`tests/data/{name}` ({w}x{h} crop), computed by the bit-true model, which the GHDL regressions "
           f"show equal to the VHDL bit for bit. The global threshold (code {t_glob}) gives about {target} "
           f"features after a 5x5 NMS; each of the 4x4 block thresholds (codes {min(thr)}..{max(thr)}) is the "
           f"lowest that leaves at most {target // 16} features in its block (blocks with little texture have "
           "fewer). Yellow lines: the 16 blocks.", "",
           ctx.figure("fig_5_3_5_4_harris", fig), ""]
    out += _table(["case", "features", "empty blocks", "min per block", "max per block"], rows)
    out += ["", "As in the thesis: thresholding alone marks clusters of pixels around each corner, the NMS "
            "leaves one per corner, and a global threshold crowds the features where the contrast is "
            "(the chessboard) while block thresholds spread them over the image.", ""]
    return out


# --------------------------------------------------------------------------------------------------
# Matching: Fig. 7.5 and the split correlation

def section_matching(ctx: Context) -> list[str]:
    """Fig. 7.5 (a) t_max, (b) window size, and the split-correlation gain (bench_matching's studies)."""
    from eyestereo.tools.reports import bench_matching as B

    sets = B.load_sets(ctx.shared / "middlebury", lambda m: None)
    if not sets:
        raise NotYetAvailable("no stereo data sets (Middlebury in ../shared/data/middlebury, or scikit-image)")
    if ctx.quick:
        sets = dict(list(sets.items())[:1])
    ctx.img.mkdir(parents=True, exist_ok=True)
    l_tmax, _ = B.study_tmax(sets, ctx.img, True)
    l_win, _ = B.study_window(sets, ctx.img, True)
    l_split, r_split = B.study_split(sets, ctx.img, True)
    for src, dst in (("matching_tmax", "fig_7_5a_tmax"), ("matching_window", "fig_7_5b_window"),
                     ("matching_split", "split_correlation")):
        os.replace(ctx.img / f"{src}.png", ctx.img / f"{dst}.png")
    i11 = B.T_GRID.index(11.0)
    summed = [dict(good=sum(r_split[n]["9 windows 5x7"][i]["good"] for n in sets),
                   bad=sum(r_split[n]["9 windows 5x7"][i]["bad"] for n in sets)) for i in range(len(B.T_GRID))]
    gains = {}
    for ref in ("single 5x7", "single 9x9"):
        g_ref = sum(r_split[n][ref][i11]["good"] for n in sets)
        b_ref = sum(r_split[n][ref][i11]["bad"] for n in sets)
        g9 = B.good_at_bad(summed, b_ref)
        gains[ref] = (100 * (g9 / g_ref - 1) if g_ref else float("nan"), g_ref, b_ref)
    names = ", ".join(f"{n} ({len(s['fl'])} corners)" for n, s in sets.items())
    img = ctx.img_rel
    return [f"Sparse SAD matching of Harris corners (bit-true model) along rows; data: {names}. "
            "`docs/matching.md` has the full studies; here the thesis's figures.", "",
            "Fig. 7.5 (a): matches, good and bad ones (|disparity error| > 1 px) against t_max (SAD 9x9). "
            "Thesis: the best ratio for t_max in [9, 13]; it chose 11. Cells: matches / good / bad (bad %).", ""]\
        + l_tmax + ["", f"![fig_7_5a_tmax]({img}/fig_7_5a_tmax.png)", "",
                    "Fig. 7.5 (b): bad matches and matching time against the window size (t_max = 11). Thesis: "
                    "bigger windows help only up to a point; 7x7 or 9x9 suit the EyeBot.", ""] \
        + l_win + ["", f"![fig_7_5b_window]({img}/fig_7_5b_window.png)", "",
                   "Split correlation (Hirschmueller; thesis 7.3.4): nine 5x7 windows against one window, "
                   "compared at an equal number of bad matches. Thesis: +19.3 % good matches on average.", ""] \
        + l_split + ["", "Gain here, all images summed, of nine 5x7 windows at the bad count of one window "
                     "at t_max = 11: " + "; ".join(
                         f"against a single {ref.split()[1]} window ({b} bad, {g} good): **{v:+.1f} %** good matches"
                         for ref, (v, g, b) in gains.items())
                     + ". The thesis's comparison is the first (the same 5x7 window split into nine): +19.3 %.",
                     "", f"![split_correlation]({img}/split_correlation.png)", ""]


# --------------------------------------------------------------------------------------------------
# Frame rate

#: Thesis 7.1: the sequential estimate, stage by stage (ms), and its result.
THESIS_FRAME = [("image transfer into the SRAM (2 x 9 Mword/s, overlapped)", 11.26),
                ("rectifier reads (2 x 20 Mword/s)", 20.28), ("rectified writes (100 Mword/s)", 2.02),
                ("host transfer of both rectified images and the features (12.5 Mword/s)", 16.22)]
THESIS_FPS = 20.01


def section_framerate(ctx: Context) -> list[str]:
    """The frame rate: the thesis's estimate against the complete system's measurement."""
    rows = [[n, f"{ms:.2f}"] for n, ms in THESIS_FRAME]
    seq = sum(ms for _, ms in THESIS_FRAME[1:])
    out = ["The thesis could not measure its system (the SRAM controller was missing); it estimated "
           f"**{THESIS_FPS} fps** from the data rates, stage by stage:", ""]
    out += _table(["stage", "ms"], rows)
    out += ["", f"(The camera transfer overlaps; the other three add up to {seq:.2f} ms, {1000 / seq:.2f} fps "
            "before arbitration overheads.)", ""]
    if not ctx.framerate.is_file():
        where = ctx.framerate.relative_to(ROOT) if ctx.framerate.is_relative_to(ROOT) else ctx.framerate
        raise NotYetAvailable(f"the measured frame rate: no `{where}` yet (the complete system's benchmark, "
                              "issue 15, writes it: JSON with `fps`, `frames`, `clocks` (domain -> MHz), "
                              "`simulator`)", partial=out)
    try:
        m = json.loads(ctx.framerate.read_text())
        fps = float(m["fps"])
    except (json.JSONDecodeError, KeyError, TypeError, ValueError) as e:
        raise ValueError(f"{ctx.framerate}: not a frame-rate measurement ({e})") from None
    clocks = ", ".join(f"{k} {v} MHz" for k, v in (m.get("clocks") or {}).items())
    size = m.get("size", "352x288")
    # A figure simulated on smaller frames and scaled to 352x288 is called what it is.
    how = (f"Measured: **{fps:.2f} fps** over {m.get('frames', '?')} stereo frames" if size == "352x288" else
           f"Derived for 352x288 from a measurement on {size} frames: **{fps:.2f} fps** (sequential; "
           f"{m.get('frames', '?')} stereo frames simulated)")
    modes = m.get("fps_modes") or {}
    extra = ("; per mode: " + ", ".join(f"{k} {float(v):.1f} fps" for k, v in modes.items())) if modes else ""
    return out + [f"{how} in simulated time ({clocks or 'clocks not given'}; "
                  f"{m.get('simulator', 'simulator not given')}){extra}, against the thesis's {THESIS_FPS} fps "
                  f"estimate ({fps / THESIS_FPS:.2f} x).", ""]


# --------------------------------------------------------------------------------------------------

SECTIONS: list[tuple[str, str, Callable[[Context], list[str]]]] = [
    ("regression", "Table 4.1, Fig. 4.1: regression of the rectification maps", section_regression),
    ("quantized", "Table A.2, Fig. 4.6: float-to-fixed conversion of the polynomials", section_quantized),
    ("rectifier", "Table 4.4: resources of the rectification unit", section_rectifier),
    ("convolution", "Tables 6.1-6.3: separable filters, NMS and the mono Harris", section_convolution),
    ("stereo_harris", "Table 6.4: resources of the stereo Harris", section_stereo_harris),
    ("harris", "Figs. 5.3 and 5.4: features with a global and with 4x4 thresholds", section_harris),
    ("matching", "Fig. 7.5 and the split correlation", section_matching),
    ("framerate", "Frame rate: estimate against measurement", section_framerate),
]


def build(keys: list[str] | None, ctx: Context, progress=None) -> tuple[str, list[dict]]:
    """The Markdown document of the chosen sections (all by default) and one status per section."""
    progress = progress or (lambda m: print(m, file=sys.stderr, flush=True))
    chosen = [s for s in SECTIONS if keys is None or s[0] in keys]
    unknown = sorted(set(keys or []) - {s[0] for s in SECTIONS})
    if unknown:
        raise ValueError(f"unknown section(s) {unknown}; sections are {[s[0] for s in SECTIONS]}")
    parts, status = [], []
    t_all = time.perf_counter()
    for i, (key, title, func) in enumerate(chosen):
        progress(f"report: [{i + 1}/{len(chosen)}] {title} ...")
        t0 = time.perf_counter()
        try:
            body, state = func(ctx), "ok"
        except NotYetAvailable as e:
            body, state = e.partial + [f"**Not yet available:** {e}.", ""], "not yet available"
        except Exception as e:  # noqa: BLE001 - reported in the document and by the exit status
            body, state = [f"**Failed:** `{type(e).__name__}: {e}`", ""], "failed"
        dt = time.perf_counter() - t0
        progress(f"report: [{i + 1}/{len(chosen)}] {title}: {state} ({dt:.1f} s)")
        parts += [f"## {title}", ""] + body
        status.append(dict(key=key, title=title, state=state, seconds=round(dt, 1)))
    head = ["# The thesis's tables and figures, reproduced", "",
            f"Written by `make report` (`eyestereo.tools.reports.thesis`) on {datetime.date.today()} in "
            f"{time.perf_counter() - t_all:.0f} s ({platform.python_implementation()} {platform.python_version()}, "
            f"numpy {np.__version__}). Each section sits next to the thesis's own numbers (B. Dietrich, 2009: "
            "Spartan-3E 500, two 352x288 cameras). Sections whose inputs do not exist yet say so; they fill in "
            "when their blocks land.", ""]
    head += _table(["section", "state", "seconds"], [[s["title"], s["state"], s["seconds"]] for s in status],
                   "|---|---|---:|")
    return "\n".join(head + [""] + parts).rstrip("\n") + "\n", status


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Reproduce the thesis's tables and figures into one Markdown file.")
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "thesis.md")
    ap.add_argument("--img", type=Path, help="figure folder (default: img/thesis next to --out)")
    ap.add_argument("--synth", type=Path, default=DEFAULT_SYNTH, help="make synth's resources.json")
    ap.add_argument("--framerate", type=Path, default=DEFAULT_FRAMERATE, help="the system's frame-rate JSON")
    ap.add_argument("--shared", type=Path, default=SHARED,
                    help=f"the shared data folder (Middlebury, OpenCV calibration pairs; default {SHARED})")
    ap.add_argument("--section", action="append", help="only this section (repeatable)")
    ap.add_argument("--quick", action="store_true", help="small images and sweeps (a smoke run)")
    args = ap.parse_args(argv)
    img = args.img or args.out.parent / "img" / "thesis"
    ctx = Context(img=img, img_rel=os.path.relpath(img, args.out.parent), synth=args.synth,
                  framerate=args.framerate, shared=args.shared, quick=args.quick)
    import cv2

    cv2.setNumThreads(1)
    try:
        text, status = build(args.section, ctx)
    except ValueError as e:
        print(f"make report: {e}", file=sys.stderr)
        return 2
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{args.out.name}.", dir=args.out.parent)
    os.close(fd)
    Path(tmp).write_text(text, encoding="utf-8")
    os.replace(tmp, args.out)
    failed = [s["key"] for s in status if s["state"] == "failed"]
    print(f"report: wrote {args.out}" + (f"; failed sections: {failed}" if failed else ""), file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
