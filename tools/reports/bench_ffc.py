"""Benchmark of the float-to-fixed conversion: ``python -m eyestereo.tools.reports.bench_ffc``.

Runs :func:`eyestereo.tools.rectify.ffc.run_ffc` over every pixel of a 352x288 image (101,376 points, the
four polynomials, coarse search + greedy tuning + merge) on realistic polynomials and writes the
measured figures into the "Measured" section of the page given by ``--out`` (``make bench``:
``docs/ffc.md``; between the ``bench:begin`` and ``bench:end`` markers); they are printed in any case.

The polynomials come from a synthetic stereo rig like the thesis's (EyeBot M6, 352x288, f ~ 544 px):
radial distortion k1 = -0.3, k2 = 0.08 in normalized coordinates, a small rectifying rotation per
camera and a few pixels of principal point offset, which displace pixels by up to ~25 px.  For each
camera the backward map rectified pixel -> source pixel is computed exactly and the degree-3
polynomials (thesis eq. 4.1) are fitted to it by least squares over all pixels.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np
import numpy.typing as npt

from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH
from eyestereo.tools.rectify.ffc import POLY_NAMES, FFCResult, fixed_eval, float_eval, run_ffc
from eyestereo.tools.rectify.synthetic_rig import fit_poly3, rig_maps, synthetic_rig_polynomials
from eyestereo.tools.fixed import Fmt
from eyestereo.tools.reports import publish

__all__ = ["TABLE_A2", "fit_poly3", "main", "rig_maps", "synthetic_rig_polynomials"]

#: Thesis Table A.2 (quantizer settings produced by the MATLAB Rectification Toolbox), transcribed from
#: the thesis: one row per quantizer q1..q26, columns X left, Y left, X right, Y right, merged.
_TABLE_A2_TEXT = """\
q   left_x       left_y       right_x      right_y      merged
q1  ufix[11,7]   ufix[7,6]    ufix[9,6]    ufix[6,7]    ufix[11,7]
q2  ufix[14,14]  sfix[13,15]  ufix[12,12]  sfix[14,15]  sfix[16,15]
q3  sfix[14,15]  ufix[14,14]  sfix[13,15]  ufix[13,13]  sfix[16,15]
q4  ufix[9,18]   ufix[11,22]  ufix[13,22]  ufix[10,21]  ufix[13,22]
q5  ufix[11,22]  ufix[12,22]  ufix[11,21]  ufix[9,18]   ufix[13,22]
q6  ufix[12,22]  ufix[12,21]  ufix[12,22]  ufix[11,20]  ufix[13,22]
q7  sfix[13,30]  sfix[6,27]   sfix[13,30]  ufix[5,30]   sfix[14,30]
q8  ufix[7,31]   sfix[13,30]  sfix[5,28]   sfix[11,28]  sfix[15,31]
q9  sfix[1,25]   sfix[13,30]  sfix[6,28]   sfix[13,30]  sfix[13,30]
q10 sfix[13,30]  sfix[9,30]   sfix[12,29]  sfix[6,30]   sfix[13,30]
q11 ufix[5,21]   sfix[13,22]  sfix[7,21]   sfix[12,21]  sfix[14,22]
q12 sfix[13,22]  sfix[9,22]   sfix[12,21]  sfix[6,22]   sfix[13,22]
q13 sfix[12,21]  sfix[9,22]   sfix[13,22]  ufix[5,22]   sfix[14,22]
q14 sfix[6,21]   sfix[13,22]  sfix[8,22]   sfix[13,22]  sfix[13,22]
q15 sfix[12,14]  ufix[11,14]  sfix[12,14]  ufix[11,14]  sfix[13,14]
q16 ufix[12,14]  ufix[13,14]  ufix[13,15]  ufix[13,14]  ufix[14,15]
q17 ufix[12,14]  sfix[13,15]  ufix[12,14]  sfix[14,15]  sfix[15,15]
q18 sfix[12,7]   ufix[14,5]   sfix[11,6]   ufix[14,5]   sfix[17,7]
q19 ufix[14,5]   sfix[13,6]   ufix[14,5]   sfix[15,7]   sfix[17,7]
q20 sfix[11,21]  ufix[11,21]  sfix[11,21]  ufix[13,22]  sfix[14,22]
q21 ufix[12,21]  sfix[12,22]  ufix[13,22]  sfix[12,22]  sfix[14,22]
q22 sfix[13,15]  ufix[14,13]  sfix[12,14]  ufix[14,13]  sfix[17,15]
q23 ufix[13,13]  sfix[13,14]  ufix[14,14]  sfix[14,14]  sfix[15,14]
q24 ufix[14,5]   sfix[15,5]   ufix[14,5]   sfix[15,5]   sfix[16,5]
q25 ufix[9,0]    ufix[9,0]    ufix[9,0]    ufix[8,-1]   ufix[9,0]
q26 ufix[7,-2]   ufix[9,0]    ufix[9,0]    ufix[9,0]    ufix[9,0]
"""
_TABLE_A2_HEAD, *_TABLE_A2_ROWS = (line.split() for line in _TABLE_A2_TEXT.splitlines())

#: :data:`_TABLE_A2_TEXT` by column: ``TABLE_A2["merged"][i]`` is quantizer i + 1's merged format.
TABLE_A2: dict[str, list[str]] = {name: [row[k] for row in _TABLE_A2_ROWS]
                                  for k, name in enumerate(_TABLE_A2_HEAD) if name != "q"}


def table_a2_formats(column: str) -> list[Fmt]:
    """One column of :data:`TABLE_A2` as formats."""
    return [Fmt.parse(s) for s in TABLE_A2[column]]


# ---------------------------------------------------------------------------
# the benchmark


def _dist_stats(ax: npt.NDArray[np.float64], ay: npt.NDArray[np.float64],
                bx: npt.NDArray[np.float64], by: npt.NDArray[np.float64]) -> tuple[float, float]:
    d = np.hypot(ax - bx, ay - by)
    return float(np.mean(d)), float(np.max(d))


def run_bench(width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT, max_error: float = 0.01) -> tuple[str, FFCResult]:
    maps = rig_maps(width, height)
    polys = {name: fit_poly3(maps[name]) for name in POLY_NAMES}
    ys, xs = np.mgrid[0:height, 0:width].astype(np.float64)
    shift = max(float(np.max(np.hypot(maps[f"{s}_x"] - xs, maps[f"{s}_y"] - ys))) for s in ("left", "right"))

    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    t0 = time.perf_counter()
    result = run_ffc(polys, width, height, max_error=max_error)
    seconds = time.perf_counter() - t0
    result_max = run_ffc(polys, width, height, max_error=0.1, measure="max")

    flt = {n: float_eval(p, width, height) for n, p in polys.items()}
    fix = {n: fixed_eval(p, result.merged, width, height)[1] for n, p in polys.items()}
    thesis = table_a2_formats("merged")
    lines = []
    w = lines.append
    w(f"Measured by `python -m eyestereo.tools.reports.bench_ffc` on {width}x{height} = {width * height:,} points, "
      f"{len(polys)} polynomials, bound {max_error} px^2 (mse per polynomial), "
      f"{int(result.timings['threads'])} worker threads, {os.cpu_count()} CPUs, load average {load:.1f} "
      "at the start (other jobs share the machine; timings scale with it).")
    w("")
    w(f"Synthetic rig: maximum displacement of a pixel by the exact map {shift:.1f} px.")
    w("")
    w("| step | seconds |")
    w("|---|---|")
    for name, r in result.per_polynomial.items():
        w(f"| {name}: ranges + coarse (p = {r.coarse_p}) + greedy ({r.greedy_steps} reductions, "
          f"{r.evaluations} bit-true evaluations) | {sum(r.seconds.values()):.2f} |")
    w(f"| merge + verification + overflow check | {result.timings['merge']:.2f} |")
    w(f"| **whole run (wall clock)** | **{seconds:.2f}** |")
    w("")
    w("Quantizer settings (this run's per-polynomial and merged formats; the thesis's merged column of "
      "Table A.2 for comparison, from its own calibration):")
    w("")
    w("| quantizer | " + " | ".join(result.per_polynomial) + " | merged | thesis merged |")
    w("|---" * (len(result.per_polynomial) + 3) + "|")
    for i in range(26):
        per = [("0" if r.zero[i] else str(r.formats[i])) for r in result.per_polynomial.values()]
        w(f"| q{i + 1} | " + " | ".join(per) + f" | {result.merged[i]} | {thesis[i]} |")
    total_thesis = sum(f.wl for f in thesis)
    w("| **total bits** | " + " | ".join(str(sum(f.wl for f in r.formats)) for r in result.per_polynomial.values())
      + f" | **{result.total_bits}** | **{total_thesis}** |")
    w("")
    w(f"Merged total: {result.total_bits} bits here, {total_thesis} bits in Table A.2 "
      f"({result.total_bits - total_thesis:+d}). "
      f"Merge extra bits needed: {result.merge_extra_bits}.")
    wide = ", ".join(str(x) for x in result.wide_inputs) or "none"
    w(f"Multiplier operands wider than 18 signed bits: {wide}.")
    w("")
    w("Errors (fixed vs float polynomial, all pixels):")
    w("")
    w("| polynomial | mse after greedy (px^2) | mse merged (px^2) | max abs merged (px) |")
    w("|---|---|---|---|")
    for n, r in result.per_polynomial.items():
        w(f"| {n} | {r.error:.5f} | {result.merged_errors[n]:.5f} | {float(np.max(np.abs(fix[n] - flt[n]))):.4f} |")
    worse = [n for n, r in result.per_polynomial.items() if result.merged_errors[n] > r.error]
    w("")
    w("Merged errors below the per-polynomial ones: " + ("yes, for all four." if not worse
      else "no, larger for " + ", ".join(worse) + " (still within the bound)."))
    w("")
    w("Distances per side (Fig. 4.6: what the quantization adds to the polynomial's own fit error):")
    w("")
    w("| side | fit: float poly vs exact map, mean / max (px) | quantized vs exact map, mean / max (px) "
      "| quantized vs float poly, mean / max (px) |")
    w("|---|---|---|---|")
    for s in ("left", "right"):
        kx, ky = f"{s}_x", f"{s}_y"
        a = _dist_stats(flt[kx], flt[ky], maps[kx], maps[ky])
        b = _dist_stats(fix[kx], fix[ky], maps[kx], maps[ky])
        c = _dist_stats(fix[kx], fix[ky], flt[kx], flt[ky])
        w(f"| {s} | {a[0]:.3f} / {a[1]:.3f} | {b[0]:.3f} / {b[1]:.3f} | {c[0]:.4f} / {c[1]:.4f} |")
    w("")
    w(f"With `--measure max --max-error 0.1` instead: merged total {result_max.total_bits} bits, "
      f"whole run {result_max.timings['total']:.2f} s, max |error| "
      + ", ".join(f"{n} {e:.3f}" for n, e in result_max.merged_errors.items()) + " px.")
    return "\n".join(lines) + "\n", result


BEGIN, END = "<!-- bench:begin -->", "<!-- bench:end -->"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m eyestereo.tools.reports.bench_ffc", description=__doc__.split("\n")[0])
    ap.add_argument("--width", type=int, default=FRAME_WIDTH)
    ap.add_argument("--height", type=int, default=FRAME_HEIGHT)
    ap.add_argument("--max-error", type=float, default=0.01)
    ap.add_argument("--out", "--doc", dest="out", type=Path, default=None,
                    help="page whose bench section is replaced (e.g. docs/ffc.md); without it: print only")
    args = ap.parse_args(argv)
    text, _ = run_bench(args.width, args.height, args.max_error)
    publish(text, args.out, BEGIN, END)
    return 0


if __name__ == "__main__":
    sys.exit(main())
