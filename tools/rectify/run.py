"""The whole Rectification Toolbox in one run (the thesis's ``run_all``): ``eyestereo rectifier``.

::

    eyestereo rectifier calib.yml -o OUTDIR [--degree 3] [--max-error 0.01] [--measure mse|max]
                        [--size WxH] [--method thesis|opencv] [--focal mean|min] [--low 0 --high 32]

:func:`run_all` goes from a stereo calibration to everything the FPGA design needs, in this order:

1. read ``calib.yml`` (:func:`eyestereo.tools.rectify.calib.read_yaml`);
2. the backward maps of both cameras (:func:`eyestereo.tools.rectify.maps.compute_maps`) -> ``maps.npz``;
3. the regression polynomials (:func:`eyestereo.tools.rectify.polyfit.fit`) -> ``poly.json``, with the
   Table 4.1 statistics of the chosen degree, and the error plots (thesis Fig. 4.1) ->
   ``plots/{left,right}_{quiver,contour}.png``;
4. the float-to-fixed conversion of the four polynomials (:func:`eyestereo.tools.rectify.ffc.run_ffc`, fed
   from the ``poly.json`` just written, exactly as ``eyestereo ffc`` would be) -> ``quantizers.json``;
5. the VHDL package (:func:`eyestereo.tools.rectify.vhdl_package.write_package`) ->
   ``stereo_calibration_pkg.vhd``;
6. ``report.txt``: sizes, the Table 4.1 rows, the achieved fixed-point errors against the bound,
   the total bits, the multiplier operands wider than 18 bits and the time of every step.

**Degree.** The calculation unit evaluates degree-3 polynomials (thesis eq. 4.1), so the FFC and the
package exist for degree 3 only. With ``degree=2`` or ``4`` the run writes ``maps.npz``,
``poly.json``, the plots and ``report.txt`` (which says that the FFC and the package need degree 3)
and skips steps 4 and 5; it does not fail.

**The bound.** ``max_error`` means what it means for ``eyestereo ffc``: with ``measure="mse"``
the mean over all rectified pixels of ``(fixed - float)**2`` in px^2, *per polynomial* (per
coordinate mapping, as the thesis's ``calc_best_quantizers``); a side's mean square distance
``mean(dx**2 + dy**2)`` is then at most twice the bound, and ``report.txt`` gives it too. With
``measure="max"`` it bounds ``max |fixed - float|`` in px.

**Size.** ``size=(W, H)`` is the size of the *rectified* images (the maps, the polynomials, the
X/Y counters of the hardware); the camera images keep the calibrated size. Default: the calibrated
size. The rectified camera is then scaled as :func:`eyestereo.tools.rectify.maps.rectified_camera`
describes (f with the height ratio, the principal point with the width and height ratios), so e.g.
a 640x480 calibration rectified to 352x288 sees a slightly narrower horizontal field.

**No half-written outputs** (the policy of :mod:`eyestereo.tools.io`). Everything is built in a
fresh hidden folder next to ``outdir`` and moved into place with one rename only when every step
succeeded. An existing ``outdir`` is replaced as a whole, and only on success; to protect other
files, an existing ``outdir`` must be empty or hold nothing but the outputs of an earlier run
(checked before the run starts). A failed or interrupted run removes its hidden folder and leaves
``outdir`` as it was (absent, or untouched).
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from eyestereo.tools.io import Outputs, check_output_folder
from eyestereo.tools.progress import progress_bar

__all__ = ["OUTPUT_FILES", "PLOT_FILES", "REPORT_NAME", "run_all"]

#: The files of a complete run (degree 3), in the order they are written; plots live in ``plots/``.
OUTPUT_FILES = ("maps.npz", "poly.json", "quantizers.json", "stereo_calibration_pkg.vhd", "report.txt")
PLOT_FILES = ("left_quiver.png", "left_contour.png", "right_quiver.png", "right_contour.png")
PLOT_DIR = "plots"
REPORT_NAME = "report.txt"
PACKAGE_NAME = "stereo_calibration_pkg"


def owned(name: str) -> bool:
    """Whether ``name`` (relative to the output folder, ``/``-separated) is one the rectifier writes."""
    if "/" in name:
        folder, file = name.split("/", 1)
        return folder == PLOT_DIR and file in PLOT_FILES
    return name in OUTPUT_FILES or name == PLOT_DIR


def _check_outdir(outdir: Path) -> None:
    """Refuse an output folder that cannot be (re)placed safely."""
    check_output_folder(outdir, owned)


def _table(report: dict[str, Any], degree: int, side: str) -> list[str]:
    head = (f"  {side:<9} {'max x':>8} {'max y':>8} {'max r':>8} {'mean x':>8} {'mean y':>8} {'mean r':>8} "
            f"{'var x':>8} {'var y':>8} {'var r':>8}")
    lines = [head]
    for name, s in (("none", report["none"][side]), (f"degree {degree}", report["fit"][side])):
        vals = [s[k][c] for k in ("max", "mean", "var") for c in ("x", "y", "r")]
        lines.append(f"  {name:<9} " + " ".join(f"{v:8.4f}" for v in vals))
    return lines


def _report_text(info: dict[str, Any]) -> str:
    cal, maps, fit = info["calib"], info["maps"], info["fit"]
    w, h = maps.width, maps.height
    K = maps.K
    lines = [
        "eyestereo rectifier report",
        f"calibration: {info['calib_path']} (camera images {cal.image_width}x{cal.image_height}, "
        f"stereo RMS {cal.rms:.4f} px, baseline {cal.baseline:.6g})",
        f"rectified images: {w}x{h} ({w * h} pixels), method {info['method']}, focal {info['focal']}: "
        f"f = {K[0, 0]:.3f} px, principal point ({K[0, 2]:.3f}, {K[1, 2]:.3f})",
        "",
        f"Table 4.1, degree-{fit.degree} polynomials vs the maps over all {w * h} pixels "
        "(px; none = maps vs identity):",
    ]
    for side in ("left", "right", "both"):
        lines += _table(fit.report, fit.degree, side)
    lines.append("")
    res = info.get("ffc")
    if res is None:
        lines += [f"float-to-fixed conversion and VHDL package: not made. The calculation unit evaluates "
                  f"degree-3 polynomials (thesis eq. 4.1), so the FFC and the package need degree 3 "
                  f"(this run: degree {fit.degree}).", ""]
    else:
        m = res.measure
        lines.append(f"float-to-fixed conversion: measure {m.name} ({m.unit}), bound {res.max_error:g} per "
                     f"polynomial, L = {res.L}, H = {res.H}")
        lines.append("  achieved under the merged formats (fixed vs float polynomial, all pixels):")
        for n, e in res.merged_errors.items():
            ok = "<=" if e <= res.max_error else ">"
            lines.append(f"    {n:<8} {e:.6g} {ok} {res.max_error:g}  (after greedy, per polynomial: "
                         f"{res.per_polynomial[n].error:.6g})")
        for side, d in res.sides.items():
            lines.append(f"    {side:<8} mean square distance {d['mean_square_distance']:.6g} px^2, "
                         f"mean {d['mean_distance']:.4f} px, max {d['max_distance']:.4f} px")
        lines.append(f"  merged quantizers: 26, total {res.total_bits} bits (merge extra bits "
                     f"{res.merge_extra_bits})")
        if res.wide_inputs:
            lines.append("  multiplier operands wider than 18 signed bits (each costs a second MULT18X18):")
            lines += [f"    {wi}" for wi in res.wide_inputs]
        else:
            lines.append("  multiplier operands wider than 18 signed bits: none")
        lines.append("")
    lines.append("files: " + ", ".join(info["files"]))
    lines.append("timings (s): " + ", ".join(f"{k} {v:.2f}" for k, v in info["timings"].items()))
    return "\n".join(lines) + "\n"


def run_all(calib_path: str | os.PathLike[str], outdir: str | os.PathLike[str], *, degree: int = 3,
            max_error: float = 0.01, measure: str = "mse", size: tuple[int, int] | None = None,
            method: str = "thesis", focal: str = "mean", low: int = 0, high: int = 32,
            progress: bool | None = None, log: Callable[[str], None] | None = None) -> dict[str, Any]:
    """calib.yml -> ``outdir`` with maps, polynomials, plots, quantizers, VHDL package and report.

    See the module docstring for the steps, the meaning of ``degree``, ``max_error`` and ``size``,
    and the all-or-nothing output folder. ``low``/``high`` are the FFC's L and H. ``progress``: draw a
    step bar on stderr (None: when it is a terminal, see :mod:`eyestereo.tools.progress`). ``log``
    receives one line per finished step. Raises ``ValueError`` (one line) on bad input or an
    unreachable bound; ``outdir`` is then as it was.

    Returns ``{"outdir", "files", "width", "height", "degree", "table", "ffc", "timings", "report"}``:
    ``files`` relative to ``outdir``; ``table`` the Table 4.1 statistics (``fit``/``none`` per side);
    ``ffc`` the :class:`~eyestereo.tools.rectify.ffc.FFCResult` (None for degree 2/4); ``timings`` seconds
    per step and ``total``; ``report`` the text of ``report.txt``.
    """
    from eyestereo.tools.rectify.calib import read_yaml
    from eyestereo.tools.rectify.judge import judge_calibration
    from eyestereo.tools.rectify.polyfit import DEGREES, fit, plot_errors, write_poly_json
    from eyestereo.tools.rectify.maps import compute_maps, save_maps

    if isinstance(degree, bool) or degree not in DEGREES:
        raise ValueError(f"degree must be 2, 3 or 4, got {degree!r}")
    if method not in ("thesis", "opencv"):
        raise ValueError(f"method must be 'thesis' or 'opencv', got {method!r}")
    if method == "opencv" and focal != "mean":
        raise ValueError("focal 'min' is only available with method 'thesis'")
    if focal not in ("mean", "min"):
        raise ValueError(f"focal must be 'mean' or 'min', got {focal!r}")
    if measure not in ("mse", "max"):
        raise ValueError(f"measure must be 'mse' or 'max', got {measure!r}")
    if isinstance(max_error, bool) or not isinstance(max_error, (int, float)) or not 0 < max_error < float("inf"):
        raise ValueError(f"max_error must be a positive finite number, got {max_error!r}")
    for name, v in (("low", low), ("high", high)):
        if isinstance(v, bool) or not isinstance(v, int) or v < 0:
            raise ValueError(f"{name} must be an integer >= 0, got {v!r}")
    if low > high:
        raise ValueError(f"need low <= high, got low={low}, high={high}")
    outdir = Path(outdir)
    _check_outdir(outdir)
    calib_path = Path(calib_path)
    do_ffc = degree == 3
    t_start = time.perf_counter()
    timings: dict[str, float] = {}
    steps = ["read calib", "maps", "fit", "plots"] + (["ffc", "package"] if do_ffc else []) + ["report"]
    with Outputs() as out:
        tmp = out.folder(outdir, owned)
        with progress_bar(len(steps), "rectifier", force=progress) as bar:
            def step(name: str) -> float:
                bar.set_description(f"rectifier: {name}")
                return time.perf_counter()

            def done(name: str, t0: float) -> None:
                timings[name] = time.perf_counter() - t0
                bar.update()
                if log is not None:
                    log(f"{name}: {timings[name]:.2f} s")

            t0 = step("read calib")
            cal = read_yaml(calib_path)
            judge_calibration(cal, where=str(calib_path), allow_swapped=True)
            done("read calib", t0)

            t0 = step("maps")
            maps = compute_maps(cal, method=method, size=size, focal=focal)
            save_maps(maps, tmp / "maps.npz")
            done("maps", t0)

            t0 = step("fit")
            poly = fit(maps, degree)
            write_poly_json(poly, tmp / "poly.json")
            done("fit", t0)

            t0 = step("plots")
            (tmp / PLOT_DIR).mkdir()
            plot_errors(maps, poly, tmp / PLOT_DIR)
            done("plots", t0)

            result = None
            if do_ffc:
                from eyestereo.tools.rectify.ffc import read_poly_json, run_ffc, write_quantizers_json
                from eyestereo.tools.rectify.vhdl_package import write_package

                t0 = step("ffc")
                pf = read_poly_json(tmp / "poly.json")  # the contract, as `eyestereo ffc` reads it
                result = run_ffc(pf.polynomials, pf.width, pf.height, max_error=max_error, measure=measure,
                                 L=low, H=high)
                write_quantizers_json(result, tmp / "quantizers.json")
                done("ffc", t0)

                t0 = step("package")
                write_package(result, tmp / f"{PACKAGE_NAME}.vhd", name=PACKAGE_NAME)
                done("package", t0)

            t0 = step("report")
            files = ["maps.npz", "poly.json"] + [f"{PLOT_DIR}/{p}" for p in PLOT_FILES]
            if do_ffc:
                files += ["quantizers.json", f"{PACKAGE_NAME}.vhd"]
            files.append(REPORT_NAME)
            timings["total"] = time.perf_counter() - t_start
            info = {"calib": cal, "calib_path": calib_path, "maps": maps, "fit": poly, "ffc": result,
                    "method": method, "focal": focal, "files": files, "timings": timings}
            text = _report_text(info)
            (tmp / REPORT_NAME).write_text(text, encoding="utf-8")
            bar.update()
    return {"outdir": outdir, "files": files, "width": maps.width, "height": maps.height, "degree": degree,
            "table": poly.report, "ffc": result, "timings": timings, "report": text}
