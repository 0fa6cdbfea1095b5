"""Calibrations for the rectification hardware: ``quantizers.json`` documents built by the toolbox, cached.

The calculation unit and the coordinate warper (``hdl/rectify/poly_unit.py``, ``hdl/rectify/coordinate_warper.py``) are
elaborated from a ``quantizers.json`` (:func:`eyestereo.tools.rectify.ffc.write_quantizers_json`): the 26
merged formats and the ten coefficient codes of each polynomial. :func:`load` turns a *calibration spec*
into such a document (checked by :func:`~eyestereo.tools.rectify.ffc.read_quantizers_json`):

``"rig"`` (the default)
    The synthetic rig of the FFC benchmark (:func:`eyestereo.tools.rectify.synthetic_rig.synthetic_rig_polynomials`,
    352x288, k1 about -0.3, about 1 degree of misalignment), converted with the default bound
    (mse 0.01 px^2 per polynomial). The repository rebuilds it from nothing in a few seconds.
``"rig:WxH"``
    The same rig at another rectified size (the geometry scales with the width); W and H are 2..4096
    (the hardware's frame limit, :data:`MAX_SIDE`), also in ``seed:...@WxH``.
``"seed:N[:SPREAD][@WxH]"``
    A random EyeBot-like rig: :func:`eyestereo.tools.rectify.rig.eyebot_rig` with its rotation, principal
    points, focal lengths, lens distortion and baseline direction perturbed by seed ``N`` (``SPREAD`` scales
    the perturbation, default 1; 3 and more give maps that leave the camera image over a large part of
    the frame). Exact maps (:func:`~eyestereo.tools.rectify.maps.ground_truth_maps`) of a ``WxH`` rectified
    image (default 352x288) into the 352x288 camera images, degree-3 fit, FFC.
``"opencv[@WxH]"``
    The shared OpenCV chessboard pairs (``$EYESTEREO_SHARED_DATA/opencv_stereo_calib``, default
    ``../shared/data`` beside the repository): calibration, thesis maps at 640x480, fit, FFC -- the whole
    toolbox as ``eyestereo calibrate`` + ``eyestereo rectifier`` run it. With ``@WxH`` the calibration is
    scaled to cameras of W x H pixels (the camera matrices' rows 0 and 1 times W/640 and H/480: the same
    sensors read out at a lower resolution; distortion and pose unchanged) and the maps are W x H.
a path
    Any ``quantizers.json`` (e.g. written by ``eyestereo rectifier``).

The documents built here carry keys beyond the FFC's schema: ``source_width``/``source_height``, the
size of the camera images the maps point into (the range checks of the hardware compare against it;
for a file without them the rectified size is used), ``origin`` (the spec) and ``float_polynomials``
(the fitted polynomials before the conversion, for error studies).

Built documents are cached as JSON under ``build/cache/quantizers/`` of the repository (or
``$EYESTEREO_CACHE``, else ``~/.cache/eyestereo``), keyed by the spec, the generator version, the
polynomials and the source of the float-to-fixed conversion, and written atomically, so parallel test
workers may build the same one.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import re
from pathlib import Path
from typing import Any

import numpy as np

from eyestereo.tools.io import atomic_write_text
from eyestereo.tools.rectify.ffc import (
    POLY_NAMES,
    FFCError,
    dumps_json,
    quantizers_dict,
    read_quantizers_json,
    run_ffc,
)

__all__ = ["DEFAULT_SPEC", "MAX_SIDE", "cache_dir", "load", "scaled", "seeded_rig", "shared_data_dir"]

DEFAULT_SPEC = "rig"
#: Bump when a generator below changes what it builds (invalidates the cache).
GENERATOR_VERSION = 2
_ROOT = Path(__file__).resolve().parents[2]


def cache_dir() -> Path:
    """Where built documents are kept (created on demand)."""
    env = os.environ.get("EYESTEREO_CACHE")
    if env:
        return Path(env) / "quantizers"
    if (_ROOT / "pyproject.toml").exists():
        return _ROOT / "build" / "cache" / "quantizers"
    return Path.home() / ".cache" / "eyestereo" / "quantizers"


def shared_data_dir() -> Path:
    """The project's shared data folder (``$EYESTEREO_SHARED_DATA`` or ``../shared/data``)."""
    env = os.environ.get("EYESTEREO_SHARED_DATA")
    return Path(env) if env else _ROOT.parent / "shared" / "data"


#: The sides a generated calibration may have: the rectifier hardware's frame limit (the fetch port's
#: 2..4096, the blocks' counters up to 4096: ``hdl/interfaces/fetch_port.py``, ``hdl/common/checks.py``), checked
#: before anything is built or allocated.
MIN_SIDE, MAX_SIDE = 2, 4096


def _size(text: str | None, default: tuple[int, int]) -> tuple[int, int]:
    if not text:
        return default
    m = re.fullmatch(r"(\d{1,9})x(\d{1,9})", text)
    if not m or not all(MIN_SIDE <= int(v) <= MAX_SIDE for v in m.groups()):
        raise ValueError(f"bad size {text!r}: want WxH with {MIN_SIDE}..{MAX_SIDE} pixels a side (the rectifier "
                         f"hardware's frame limit)")
    return int(m.group(1)), int(m.group(2))


def seeded_rig(seed: int, spread: float = 1.0):
    """:func:`~eyestereo.tools.rectify.rig.eyebot_rig` perturbed by ``seed`` (a :class:`StereoRig`).

    Per unit of ``spread``: rotation vector of the right camera +-0.015 rad per axis, principal points
    +-8 px, focal lengths +-1.5 %, k1 +-0.06, k2 +-0.05, tangential terms +-0.001, baseline direction
    +-0.003 m in y and z. Seed 0 with spread 0 is the rig itself.
    """
    import cv2

    from eyestereo.tools.rectify.rig import StereoRig, eyebot_rig

    base = eyebot_rig()
    rng = np.random.default_rng(int(seed))
    s = float(spread)

    def u(a: float, n: int | None = None):
        return rng.uniform(-a * s, a * s, n)

    m1, m2 = base.M1.copy(), base.M2.copy()
    for m in (m1, m2):
        m[0, 0] *= 1 + u(0.015)
        m[1, 1] *= 1 + u(0.015)
        m[0, 2] += u(8.0)
        m[1, 2] += u(8.0)
    d1, d2 = base.D1.copy(), base.D2.copy()
    for d in (d1, d2):
        d[0] += u(0.06)
        d[1] += u(0.05)
        d[2:4] += u(0.001, 2)
    rvec = cv2.Rodrigues(base.R)[0].ravel() + u(0.015, 3)
    r = cv2.Rodrigues(rvec)[0]
    t = base.T.copy()
    t[1:] += u(0.003, 2)
    return StereoRig(base.width, base.height, m1, d1, m2, d2, r, t)


def _parse(spec: str) -> tuple[str, dict[str, Any]]:
    if spec == "rig" or spec.startswith("rig:"):
        w, h = _size(spec[4:] if spec.startswith("rig:") else None, (352, 288))
        return "rig", dict(width=w, height=h)
    if spec.startswith("seed:"):
        body, _, size = spec[5:].partition("@")
        parts = body.split(":")
        if not 1 <= len(parts) <= 2 or not re.fullmatch(r"\d+", parts[0]):
            raise ValueError(f"bad calibration spec {spec!r}: want seed:N[:SPREAD][@WxH]")
        try:
            spread = float(parts[1]) if len(parts) == 2 else 1.0
        except ValueError:
            raise ValueError(f"bad spread in calibration spec {spec!r}") from None
        if not (math.isfinite(spread) and spread >= 0):
            raise ValueError(f"bad spread in calibration spec {spec!r}: want a number >= 0")
        w, h = _size(size or None, (352, 288))
        return "seed", dict(seed=int(parts[0]), spread=spread, width=w, height=h)
    if spec == "opencv" or spec.startswith("opencv@"):
        size = _size(spec[7:], (0, 0)) if spec.startswith("opencv@") else None
        return "opencv", dict(size=size)
    raise ValueError(f"unknown calibration spec {spec!r}: 'rig', 'rig:WxH', 'seed:N[:SPREAD][@WxH]', "
                     f"'opencv[@WxH]' or the path of a quantizers.json")


def _polynomials(kind: str, args: dict[str, Any]) -> tuple[dict[str, list[float]], int, int, int, int]:
    """(polynomials, rectified width, height, camera width, height) of a generated calibration."""
    from eyestereo.tools.rectify.polyfit import fit

    if kind == "rig":
        from eyestereo.tools.rectify.synthetic_rig import synthetic_rig_polynomials

        w, h = args["width"], args["height"]
        return synthetic_rig_polynomials(w, h), w, h, w, h
    if kind == "seed":
        from eyestereo.tools.rectify.maps import ground_truth_maps

        rig = seeded_rig(args["seed"], args["spread"])
        maps = ground_truth_maps(rig, size=(args["width"], args["height"]))
        f = fit(maps, 3)
        return ({n: [float(c) for c in f.coeffs[n]] for n in POLY_NAMES}, args["width"], args["height"],
                rig.width, rig.height)
    from eyestereo.tools.rectify.calib import calibrate_stereo
    from eyestereo.tools.rectify.maps import compute_maps

    data = shared_data_dir() / "opencv_stereo_calib"
    if not data.is_dir():
        raise FileNotFoundError(f"the shared OpenCV calibration pairs are not at {data} "
                                f"(set EYESTEREO_SHARED_DATA to the shared data folder)")
    cal = calibrate_stereo(str(data / "left*.jpg"), str(data / "right*.jpg"), board=(9, 6), square=0.025,
                           progress=False)
    if args.get("size"):
        cal = scaled(cal, *args["size"])
    maps = compute_maps(cal, method="thesis")
    f = fit(maps, 3)
    return ({n: [float(c) for c in f.coeffs[n]] for n in POLY_NAMES}, maps.width, maps.height,
            cal.image_width, cal.image_height)


def scaled(cal, width: int, height: int):
    """A :class:`~eyestereo.tools.rectify.calib.StereoCalibration` for the same cameras read out at ``width`` x
    ``height`` pixels: each camera matrix's x row times ``width / image_width``, its y row times
    ``height / image_height`` (pixel centres kept: ``c' = (c + 0.5) * s - 0.5``); distortion, R, T unchanged."""
    from eyestereo.tools.rectify.calib import StereoCalibration

    sx, sy = width / cal.image_width, height / cal.image_height
    ms = []
    for m in (cal.M1, cal.M2):
        m = m.copy()
        m[0, 0] *= sx
        m[0, 1] *= sx
        m[0, 2] = (m[0, 2] + 0.5) * sx - 0.5
        m[1, 1] *= sy
        m[1, 2] = (m[1, 2] + 0.5) * sy - 0.5
        ms.append(m)
    return StereoCalibration(ms[0], cal.D1, ms[1], cal.D2, cal.R, cal.T, width, height, cal.rms)


def _cache_name(spec: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", spec)


def _build(spec: str, kind: str, args: dict[str, Any]) -> dict[str, Any]:
    folder = cache_dir()
    # The OpenCV calibration is the slow part (seconds); its polynomials are cached on their own.
    key_src: Any
    if kind == "opencv":
        poly_file = folder / f"{_cache_name(spec)}.v{GENERATOR_VERSION}.poly.json"
        if poly_file.exists():
            pdoc = json.loads(poly_file.read_text(encoding="utf-8"))
            polys, w, h, sw, sh = (pdoc["polynomials"], pdoc["width"], pdoc["height"], pdoc["source_width"],
                                   pdoc["source_height"])
        else:
            polys, w, h, sw, sh = _polynomials(kind, args)
            folder.mkdir(parents=True, exist_ok=True)
            atomic_write_text(poly_file, json.dumps(dict(polynomials=polys, width=w, height=h, source_width=sw,
                                                         source_height=sh)) + "\n")
    else:
        polys, w, h, sw, sh = _polynomials(kind, args)
    # The key holds the float-to-fixed conversion's own source: a changed FFC rebuilds every entry.
    from eyestereo.tools.rectify import ffc

    ffc_src = hashlib.sha256(Path(ffc.__file__).read_bytes()).hexdigest()
    key_src = json.dumps([GENERATOR_VERSION, spec, w, h, sw, sh, polys, ffc_src], sort_keys=True)
    digest = hashlib.sha256(key_src.encode()).hexdigest()[:16]
    path = folder / f"{_cache_name(spec)}.{digest}.quantizers.json"
    if path.exists():
        try:
            return read_quantizers_json(path)
        except FFCError:
            pass  # a damaged cache entry is rebuilt
    result = run_ffc(polys, w, h)
    doc = quantizers_dict(result)
    doc.update(source_width=int(sw), source_height=int(sh), origin=spec, float_polynomials=polys)
    folder.mkdir(parents=True, exist_ok=True)
    atomic_write_text(path, dumps_json(doc) + "\n")
    return read_quantizers_json(path)


def load(spec: str | os.PathLike[str] | dict[str, Any] | None = None) -> dict[str, Any]:
    """The checked ``quantizers.json`` document of a calibration spec (see the module docstring).

    A dict is taken as an already read document (it is checked again). Raises ValueError (one line)
    for a bad spec or file, FileNotFoundError when the OpenCV pairs are missing.
    """
    if spec is None:
        spec = DEFAULT_SPEC
    if isinstance(spec, dict):
        doc = dict(spec)
        if "_formats" not in doc:
            import tempfile

            with tempfile.TemporaryDirectory() as tmp:
                p = Path(tmp) / "quantizers.json"
                p.write_text(json.dumps({k: v for k, v in doc.items() if not k.startswith("_")}))
                doc = read_quantizers_json(p)
        return doc
    if isinstance(spec, os.PathLike) or (isinstance(spec, str) and (spec.endswith(".json") or os.sep in spec)):
        return read_quantizers_json(spec)
    if not isinstance(spec, str):
        raise ValueError(f"a calibration is a spec string, a path or a quantizers.json document, got {spec!r}")
    kind, args = _parse(spec)
    return _build(spec, kind, args)
