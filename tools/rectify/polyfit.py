"""2-D regression polynomials for the backward maps (thesis 4, eq. 4.1 and Table 4.1).

The FPGA has no room for look-up tables, so each map (x and y of the source point, left and right
camera) is approximated by a polynomial of total degree 2, 3 or 4 in the *rectified integer pixel
coordinates* ``x`` (column 0..W-1) and ``y`` (row 0..H-1). Term order (the thesis's ``p1..p10`` for
degree 3):

* degree 2: ``1, x, y, x^2, y^2, xy``
* degree 3: degree 2, then ``x^3, y^3, x^2y, xy^2``
* degree 4: degree 3, then ``x^4, y^4, x^3y, x^2y^2, xy^3``

The least-squares problem is solved on a well-conditioned basis, the same monomials of
``u = (x - cx)/sx`` and ``v = (y - cy)/sy`` scaled to [-1, 1], and the coefficients are then converted
exactly (binomial expansion) to **raw pixel units**, the form the hardware evaluates; tests check
that both evaluate to the same values.

Error report per fit (thesis Table 4.1; ``e = polynomial - map``, ``r = |e|`` the Euclidean
residual): ``max`` = largest ``|e_x|``, ``|e_y|``, ``r``; ``mean`` = mean of ``|e_x|``, ``|e_y|``, ``r``;
``var`` = variance of the signed ``e_x``, ``e_y`` and of ``r``. The "none" row is the same statistics
of the map's displacement from the identity (no correction at all).

``poly.json`` (:func:`write_poly_json`) is the contract read by the float-to-fixed conversion::

    {"width": W, "height": H, "degree": d, "terms": ["1", "x", "y", ...],
     "polynomials": {"left_x": [...], "left_y": [...], "right_x": [...], "right_y": [...]},
     "report": {...}}
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from eyestereo.tools.io import atomic_output
from eyestereo.tools.progress import progress_bar
from eyestereo.tools.rectify.maps import MAP_KEYS, Maps, check_map_entries

__all__ = [
    "DEGREES",
    "Fit",
    "error_stats",
    "evaluate",
    "fit",
    "normalised_to_raw",
    "plot_errors",
    "poly_from_dict",
    "read_poly_json",
    "table_4_1",
    "term_names",
    "terms",
    "write_poly_json",
]

DEGREES = (2, 3, 4)

_TERMS = {
    2: [(0, 0), (1, 0), (0, 1), (2, 0), (0, 2), (1, 1)],
}
_TERMS[3] = _TERMS[2] + [(3, 0), (0, 3), (2, 1), (1, 2)]
_TERMS[4] = _TERMS[3] + [(4, 0), (0, 4), (3, 1), (2, 2), (1, 3)]


def _check_degree(degree: int) -> int:
    if isinstance(degree, bool) or not isinstance(degree, (int, np.integer)) or degree not in DEGREES:
        raise ValueError(f"degree must be 2, 3 or 4, got {degree!r}")
    return int(degree)


def terms(degree: int) -> list[tuple[int, int]]:
    """Exponent pairs ``(i, j)`` of ``x^i y^j`` in the thesis's order."""
    return list(_TERMS[_check_degree(degree)])


def _name(i: int, j: int) -> str:
    if i == j == 0:
        return "1"
    part = lambda v, e: "" if e == 0 else (v if e == 1 else f"{v}^{e}")  # noqa: E731
    return part("x", i) + part("y", j)


def term_names(degree: int) -> list[str]:
    """``["1", "x", "y", "x^2", "y^2", "xy", "x^3", "y^3", "x^2y", "xy^2", ...]``."""
    return [_name(i, j) for i, j in terms(degree)]


def _scale(n: int) -> tuple[float, float]:
    c = (n - 1) / 2.0
    return c, (c if c > 0 else 1.0)


def normalised_to_raw(coeffs: np.ndarray, degree: int, width: int, height: int) -> np.ndarray:
    """Convert coefficients of the [-1, 1]-scaled basis to raw pixel units (same term order).

    ``u = (x - cx)/sx`` with ``cx = sx = (W - 1)/2`` (and ``v`` likewise): each ``u^i v^j`` expands by the
    binomial theorem into monomials ``x^a y^b`` with ``a <= i``, ``b <= j``, all present in the basis.
    """
    tl = terms(degree)
    index = {t: k for k, t in enumerate(tl)}
    cx, sx = _scale(width)
    cy, sy = _scale(height)
    T = np.zeros((len(tl), len(tl)))
    for k, (i, j) in enumerate(tl):
        for a in range(i + 1):
            ca = math.comb(i, a) * (-cx) ** (i - a) / sx**i
            for b in range(j + 1):
                cb = math.comb(j, b) * (-cy) ** (j - b) / sy**j
                T[index[(a, b)], k] += ca * cb
    return T @ np.asarray(coeffs, dtype=np.float64)


def _basis(x: np.ndarray, y: np.ndarray, degree: int) -> np.ndarray:
    return np.stack([x**i * y**j for i, j in terms(degree)], axis=-1)


def evaluate(coeffs: np.ndarray, degree: int, width: int, height: int) -> np.ndarray:
    """Evaluate raw-unit coefficients at every integer pixel: array (height, width), float64."""
    c = np.asarray(coeffs, dtype=np.float64).ravel()
    if c.size != len(terms(degree)):
        raise ValueError(f"degree {degree} needs {len(terms(degree))} coefficients, got {c.size}")
    if width < 1 or height < 1:
        raise ValueError(f"size must be positive, got {width}x{height}")
    x = np.arange(width, dtype=np.float64)[None, :]
    y = np.arange(height, dtype=np.float64)[:, None]
    out = np.zeros((height, width))
    for ck, (i, j) in zip(c, terms(degree)):
        out += ck * (x**i * y**j)
    return out


def error_stats(ex: np.ndarray, ey: np.ndarray) -> dict[str, dict[str, float]]:
    """Table 4.1 statistics of an error field: ``{"max"|"mean"|"var": {"x", "y", "r"}}``."""
    ex = np.asarray(ex, dtype=np.float64).ravel()
    ey = np.asarray(ey, dtype=np.float64).ravel()
    r = np.hypot(ex, ey)
    return {
        "max": {"x": float(np.abs(ex).max()), "y": float(np.abs(ey).max()), "r": float(r.max())},
        "mean": {"x": float(np.abs(ex).mean()), "y": float(np.abs(ey).mean()), "r": float(r.mean())},
        "var": {"x": float(ex.var()), "y": float(ey.var()), "r": float(r.var())},
    }


@dataclass
class Fit:
    """Regression polynomials of the four maps.

    ``coeffs[key]`` (key in ``left_x, left_y, right_x, right_y``): raw-unit coefficients in term order;
    ``width``/``height``: the rectified image size; ``report``: Table 4.1 statistics
    (``fit`` = residuals of these polynomials, ``none`` = maps vs identity), per side and ``both``.
    """

    degree: int
    width: int
    height: int
    coeffs: dict[str, np.ndarray]
    report: dict[str, Any] = field(default_factory=dict)

    def evaluate(self, key: str) -> np.ndarray:
        """The polynomial ``key`` at every rectified pixel, (height, width)."""
        return evaluate(self.coeffs[key], self.degree, self.width, self.height)


def _side_stats(ex: dict[str, np.ndarray], ey: dict[str, np.ndarray]) -> dict[str, Any]:
    out = {side: error_stats(ex[side], ey[side]) for side in ("left", "right")}
    out["both"] = error_stats(np.concatenate([ex["left"].ravel(), ex["right"].ravel()]),
                              np.concatenate([ey["left"].ravel(), ey["right"].ravel()]))
    return out


def fit(maps: Maps, degree: int = 3, mask: np.ndarray | None = None) -> Fit:
    """Least-squares polynomials of ``degree`` for the four maps (all finite pixels, or ``mask``).

    NaN entries (no source pixel) are left out; an infinite entry is refused (ValueError naming the
    array and the count, :func:`~eyestereo.tools.rectify.maps.check_map_entries`)."""
    degree = _check_degree(degree)
    check_map_entries(maps)
    h, w = maps.height, maps.width
    if w * h < len(terms(degree)):
        raise ValueError(f"a {w}x{h} map has too few pixels for a degree-{degree} fit")
    cx, sx = _scale(w)
    cy, sy = _scale(h)
    yy, xx = np.mgrid[0:h, 0:w]
    valid = np.ones((h, w), dtype=bool) if mask is None else np.asarray(mask, dtype=bool).copy()
    if valid.shape != (h, w):
        raise ValueError(f"mask shape {valid.shape} does not match the maps ({h}, {w})")
    targets = np.stack([np.asarray(getattr(maps, k), dtype=np.float64) for k in MAP_KEYS], axis=-1)
    valid &= np.all(np.isfinite(targets), axis=-1)
    if valid.sum() < len(terms(degree)):
        raise ValueError("too few finite map values to fit")
    A = _basis((xx[valid] - cx) / sx, (yy[valid] - cy) / sy, degree)
    B = targets[valid]
    sol, *_ = np.linalg.lstsq(A, B, rcond=None)
    coeffs = {k: normalised_to_raw(sol[:, n], degree, w, h) for n, k in enumerate(MAP_KEYS)}
    result = Fit(degree, w, h, coeffs)
    ex, ey, nx, ny = {}, {}, {}, {}
    for side in ("left", "right"):
        mx, my = maps.side(side)
        ex[side] = (result.evaluate(f"{side}_x") - mx)[valid]
        ey[side] = (result.evaluate(f"{side}_y") - my)[valid]
        nx[side] = (mx - xx)[valid]
        ny[side] = (my - yy)[valid]
    result.report = {
        "statistics": "max = max |e|, mean = mean |e|, var = variance of signed e (x, y) and of r; "
                      "e = polynomial - map (fit) or map - identity (none), r = Euclidean residual, pixels",
        "fit": _side_stats(ex, ey),
        "none": _side_stats(nx, ny),
        "pixels": int(valid.sum()),
    }
    if maps.source_size is not None:
        result.report["source_width"], result.report["source_height"] = maps.source_size
    return result


def table_4_1(maps: Maps, degrees: tuple[int, ...] = DEGREES,
              side: str = "both") -> dict[str, dict[str, dict[str, float]]]:
    """Table 4.1 for ``maps``: rows ``"none"`` and each degree, statistics of ``side``."""
    rows: dict[str, Any] = {}
    for d in degrees:
        f = fit(maps, d)
        rows.setdefault("none", f.report["none"][side])
        rows[str(d)] = f.report["fit"][side]
    return rows


# --------------------------------------------------------------------------------------------------
# poly.json


def write_poly_json(result: Fit, path: str | os.PathLike[str]) -> None:
    """Write the ``poly.json`` contract (see the module docstring). Atomic."""
    doc = {
        "width": int(result.width),
        "height": int(result.height),
        "degree": int(result.degree),
        "terms": term_names(result.degree),
        "polynomials": {k: [float(v) for v in result.coeffs[k]] for k in MAP_KEYS},
        "report": result.report,
    }
    text = json.dumps(doc, indent=2, allow_nan=False) + "\n"
    with atomic_output(path, suffix=".json") as tmp:
        tmp.write_text(text, encoding="utf-8")


def read_poly_json(path: str | os.PathLike[str]) -> Fit:
    """Read and validate a ``poly.json`` file; ValueError with a one-line reason if it is not valid."""
    p = Path(path)
    if not p.is_file():
        raise ValueError(f"polynomial file {p} does not exist")
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as e:
        raise ValueError(f"{p} is not valid JSON ({str(e).splitlines()[0]})") from None
    return poly_from_dict(doc, str(p))


def poly_from_dict(doc: Any, name: str = "poly.json") -> Fit:
    """Validate a parsed ``poly.json`` document and return it as a :class:`Fit`."""
    if not isinstance(doc, dict):
        raise ValueError(f"{name}: the top level must be a JSON object")
    for key in ("width", "height", "degree", "terms", "polynomials"):
        if key not in doc:
            raise ValueError(f"{name}: key '{key}' is missing")
    for key in ("width", "height"):
        v = doc[key]
        if not isinstance(v, int) or isinstance(v, bool) or v < 1:
            raise ValueError(f"{name}: '{key}' must be a positive integer, got {v!r}")
        if v > 16384:
            raise ValueError(f"{name}: '{key}' {v} is implausible (at most 16384 pixels)")
    if doc["width"] * doc["height"] > 1 << 24:
        raise ValueError(f"{name}: {doc['width']}x{doc['height']} is implausible (at most {1 << 24} pixels)")
    degree = doc["degree"]
    if not isinstance(degree, int) or isinstance(degree, bool) or degree not in DEGREES:
        raise ValueError(f"{name}: 'degree' must be 2, 3 or 4, got {degree!r}")
    if doc["terms"] != term_names(degree):
        raise ValueError(f"{name}: 'terms' must be {term_names(degree)} for degree {degree}")
    polys = doc["polynomials"]
    if not isinstance(polys, dict):
        raise ValueError(f"{name}: 'polynomials' must be an object")
    coeffs = {}
    n = len(terms(degree))
    for key in MAP_KEYS:
        c = polys.get(key)
        if not isinstance(c, list) or len(c) != n:
            raise ValueError(f"{name}: polynomial '{key}' must be a list of {n} numbers")
        if not all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in c):
            raise ValueError(f"{name}: polynomial '{key}' holds a non-number or non-finite value")
        coeffs[key] = np.array(c, dtype=np.float64)
    report = doc.get("report", {})
    if not isinstance(report, dict):
        raise ValueError(f"{name}: 'report' must be an object")
    return Fit(degree, doc["width"], doc["height"], coeffs, report)


# --------------------------------------------------------------------------------------------------
# Plots (thesis Fig. 4.1)


_CONTOUR_LEVELS = (0.0, 0.01, 0.02, 0.05, 0.1, 0.25, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0)


def plot_errors(maps: Maps, result: Fit, folder: str | os.PathLike[str], *, step: int = 16) -> list[Path]:
    """Quiver and contour plots of the residual (polynomial - map) per side, as PNG files.

    Writes ``{side}_quiver.png`` (error vectors on a grid every ``step`` pixels, scaled so the largest
    spans about two grid cells; the scale is in the title) and ``{side}_contour.png`` (error
    magnitude ``r`` in pixels, filled contours at 0.01, 0.02, 0.05, 0.1, 0.25, 0.5, 1, 2, 5, ... px
    up to the maximum, labelled, with a colour bar) into ``folder``. Atomic per file.
    Uses matplotlib's Agg canvas directly (no pyplot, no global backend change).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    out = Path(folder)
    if not out.is_dir():
        raise ValueError(f"plot folder {out} does not exist")
    if (maps.width, maps.height) != (result.width, result.height):
        raise ValueError(f"maps are {maps.width}x{maps.height} but the fit is {result.width}x{result.height}")
    written = []
    h, w = maps.height, maps.width
    step = max(1, min(step, w, h))  # a small map still gets one arrow per cell
    bar = progress_bar(4, "error plots")
    for side in ("left", "right"):
        mx, my = maps.side(side)
        ex = result.evaluate(f"{side}_x") - mx
        ey = result.evaluate(f"{side}_y") - my
        r = np.hypot(ex, ey)
        gy, gx = np.mgrid[step // 2:h:step, step // 2:w:step]
        qx, qy = ex[gy, gx], ey[gy, gx]
        peak = float(np.nanmax(np.hypot(qx, qy))) or 1.0
        gain = 2 * step / peak
        for kind in ("quiver", "contour"):
            fig = Figure(figsize=(6.4, 6.4 * h / w + 0.6), dpi=100)
            FigureCanvasAgg(fig)
            ax = fig.add_subplot(1, 1, 1)
            if kind == "quiver":
                ax.quiver(gx, gy, qx * gain, qy * gain, angles="xy", scale_units="xy", scale=1, width=0.003)
                ax.set_title(f"{side}: residual, degree {result.degree} (arrows x{gain:.3g})")
            else:
                top = float(r.max())
                levels = [v for v in _CONTOUR_LEVELS if v < top] + [top if top > 0 else 1e-9]
                cs = ax.contourf(np.arange(w), np.arange(h), r, levels=levels, cmap="viridis")
                lines = ax.contour(np.arange(w), np.arange(h), r, levels=levels[1:-1], colors="white",
                                   linewidths=0.6)
                ax.clabel(lines, fmt="%g", fontsize=7)
                fig.colorbar(cs, ax=ax, label="|residual| [px]")
                ax.set_title(f"{side}: residual magnitude, degree {result.degree}")
            ax.set_xlim(0, w - 1)
            ax.set_ylim(h - 1, 0)
            ax.set_aspect("equal")
            ax.set_xlabel("x [px]")
            ax.set_ylabel("y [px]")
            path = out / f"{side}_{kind}.png"
            with atomic_output(path, suffix=".png") as tmp:
                fig.savefig(tmp, format="png")
            written.append(path)
            bar.update()
    bar.close()
    return written
