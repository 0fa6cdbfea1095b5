"""The complete front end's scenes and model, shared by its benches (tb_stereo_frontend, tb_frontend_fast, the soak).

* the scenes: :func:`stereo_frames` (``random:S``, ``shift:S``, ``match:S``, ``files:LEFT,RIGHT``), :func:`file_pair`,
  :func:`pair_frames` (a pair of .npy arrays);
* the model's parameters for a top: :data:`MODEL_PARAMS`, :func:`model_params`;
* :func:`frame_digest` (a frame's identity for the model caches) and :func:`choose_thresholds` (the threshold code
  that keeps the lists under a target).
"""

from __future__ import annotations

import hashlib
import inspect

import numpy as np

from eyestereo.sim.lib.camera import camera_frame
from eyestereo.tools.models import stereo_frontend as model


def stereo_frames(spec: str, n: int, width: int, height: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """``n`` stereo pairs of camera words: ``random:S`` (independent random frames), ``shift:S`` (one
    random scene, the right camera's view shifted by a disparity, the scene moving a pixel per frame),
    ``match:S`` (the same with the disparity's sign a real rig gives: the matcher option's scene) or
    ``files:LEFT,RIGHT`` (two image files, every frame: :func:`file_pair`)."""
    kind, _, arg = spec.partition(":")
    seed = int(arg or 1) if kind != "files" else 0
    out = []
    for i in range(n):
        if kind == "random":
            out.append((camera_frame(f"random:{seed + 2 * i}", width, height),
                        camera_frame(f"random:{seed + 2 * i + 1}", width, height)))
        elif kind == "shift":
            big = camera_frame(f"random:{seed}", width + 2 * n + 8, height)
            out.append((big[:, i + 8:i + 8 + width].copy(), big[:, i + 4:i + 4 + width].copy()))
        elif kind == "match":  # as shift, the right view 4 pixels the other way: disparity +4, as a rig sees
            big = camera_frame(f"random:{seed}", width + 2 * n + 8, height)
            out.append((big[:, i + 4:i + 4 + width].copy(), big[:, i + 8:i + 8 + width].copy()))
        elif kind == "files":  # a stereo pair of image files, resized to the camera size, every frame
            out.append(out[0] if out else file_pair(arg.split(","), width, height))
        else:
            raise ValueError(f"unknown stereo frame spec {spec!r}")
    return out


def file_pair(files, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """The camera words of a stereo pair of image files: read by the library's one image-input rule
    (:func:`eyestereo.tools.io.read_image` grey, :func:`~eyestereo.tools.io.to_grey8` on the pair: a
    16-bit pair shares one shift), resized to the camera size (``cv2.INTER_AREA``)."""
    import cv2

    from eyestereo.tools.camera import yuv_frame
    from eyestereo.tools.io import read_image, to_grey8

    files = [str(f) for f in files]
    if len(files) != 2:
        raise ValueError(f"files: a stereo pair is two image files, got {len(files)}: {files}")
    imgs = to_grey8([read_image(f, grey=True) for f in files], files)
    return tuple(yuv_frame(cv2.resize(img, (width, height), interpolation=cv2.INTER_AREA)) for img in imgs)


def pair_frames(pair, n: int, width: int, height: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """``n`` stereo frames of camera words from the config's ``pair``: [left.npy, right.npy], each an
    (height, width) uint8 array at the camera size, the Y of every frame of that camera (U = V = 128)."""
    from eyestereo.tools.camera import yuv_frame

    if not isinstance(pair, (list, tuple)) or len(pair) != 2:
        raise ValueError(f"pair: [left.npy, right.npy] expected, got {pair!r}")
    words = []
    for side, f in zip(("left", "right"), pair):
        try:
            a = np.load(f, allow_pickle=False)
        except (OSError, ValueError) as e:
            raise ValueError(f"pair: cannot read the {side} array {f}: {e}") from None
        if a.dtype != np.uint8 or a.shape != (height, width):
            raise ValueError(f"pair: the {side} array {f} is {a.dtype} {a.shape}; the cameras need uint8 "
                             f"({height}, {width}) (height, width)")
        words.append(yuv_frame(a))
    return [tuple(words)] * n


#: The top's parameters that change what the system computes, handed to the model by the bench
#: (quantizers, the calibration, is handed as ``cal``). The others (feature_words, cam_depth, kind,
#: read_latency, rect_depth) change timing or resources only; ``order`` is the cameras' byte order, which the
#: camera models send in the default order (YUYV) only.
MODEL_PARAMS = ("nms", "border", "max_features", "frac")


def model_params(params: dict) -> dict:
    """The keyword arguments of :func:`eyestereo.tools.models.stereo_frontend.stereo_frontend` for a top built
    with ``params``: each of :data:`MODEL_PARAMS` from ``params``, else the block's own default (read from
    :func:`eyestereo.hdl.system.stereo_frontend.stereo_frontend`'s signature, so the two cannot drift apart)."""
    from eyestereo.hdl.system.stereo_frontend import stereo_frontend as top

    sig = inspect.signature(top).parameters
    return {name: params[name] if name in params else sig[name].default for name in MODEL_PARAMS}


def frame_digest(words: np.ndarray) -> str:
    """A frame's identity for the model cache (identical frames, e.g. a still pair, are modelled once)."""
    a = np.ascontiguousarray(words, dtype=np.int64)
    return hashlib.sha1(a.tobytes() + str(a.shape).encode()).hexdigest()


def choose_thresholds(cal, frames, k, target: int, mp: dict) -> int:
    """The smallest power-of-two threshold code giving at most ``target`` features per camera on every
    frame (computed with the model, before the simulation; ``mp``: :func:`model_params`)."""
    for e in range(0, 20):
        code = 1 << e
        ok = True
        for left, right in frames[:2]:
            tot = model.stereo_frontend(cal, left, right, k, [code] * 16, **mp)["list"]["totals"]
            ok &= int(max(tot)) <= target
        if ok:
            return code
    return (1 << 20) - 1


def match_settings(cfg: dict) -> dict | None:
    """The matcher option's model settings (None without it): the top's parameters (``match_cost``,
    ``match_window``, ``match_d_max``, ``match_rows``, ``max_matches``, else the top's defaults) and the run-time
    settings the host writes into MATCH (config ``match``: ``t_max`` or ``h_max``, ``uniqueness``, ``lr_check``;
    defaults t_max 11, h_max 15, 0, True), with the ``limit`` they give."""
    p = cfg["params"]
    if not p.get("matcher"):
        return None
    from eyestereo.hdl.system.stereo_frontend import stereo_frontend as top
    from eyestereo.tools.models.feature_matcher import cost_limit

    sig = inspect.signature(top).parameters
    top_p = {n: p.get(n, sig[n].default) for n in ("match_cost", "match_window", "match_d_max", "match_rows",
                                                   "max_matches")}
    run = dict(dict(t_max=11, h_max=15, uniqueness=0, lr_check=True), **cfg.get("match", {}))
    return dict(cost=top_p["match_cost"], window=top_p["match_window"], d_max=top_p["match_d_max"],
                rows=top_p["match_rows"], max_matches=top_p["max_matches"], **run,
                limit=cost_limit(top_p["match_cost"], top_p["match_window"], run["t_max"], run["h_max"]))


def match_list_of(m: dict, mp: dict, ms: dict) -> dict:
    """The feature matcher model's list for a pair of the front end's model (``m``): its rectified images and the
    corners of its flags inside the feature list's border."""
    from eyestereo.tools.models.corner_descriptors import corners
    from eyestereo.tools.models.feature_matcher import feature_matcher
    from eyestereo.tools.models.harris_mono import radius

    border = mp["border"] if mp["border"] is not None else radius(mp["nms"])  # the feature list's (the model's rule)
    fl, fr = (corners(f, border) for f in m["flags"][:2])
    return feature_matcher(*m["rectified"], fl, fr, window=ms["window"], cost=ms["cost"], t_max=ms["t_max"],
                           h_max=ms["h_max"], d_min=0, d_max=ms["d_max"], rows=ms["rows"], uniqueness=ms["uniqueness"],
                           lr_check=bool(ms["lr_check"]), max_matches=ms["max_matches"])
