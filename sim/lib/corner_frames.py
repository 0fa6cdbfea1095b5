"""Bench helpers for the hardware matcher (issue 29): stereo frames with corner flags, and their two streams.

``frame_case`` makes a frame from a spec; ``stream_plan`` schedules the pixels and the flags of frames as
harris_stereo's would come: the flags lag the pixels by whole rows and pixels of beats plus a pipeline's
clocks, and the flags left after the last pixel come as a tail; ``play_plan`` drives such a schedule;
``check_match_lists`` compares the match lists a bench read with the model's, frame by frame.
"""

from __future__ import annotations

import numpy as np


def frame_case(spec: str, w: int, h: int):
    """(left image, right image, left flags, right flags) of one frame spec:

    * ``"random:SEED:P"``: random grey levels, each pixel of each camera a corner with probability P;
    * ``"texture:SEED:N:SHIFT"``: a smooth random texture, the right view SHIFT columns further with a little
      noise, the strongest N Harris corners of each (:func:`eyestereo.tools.matching.sparse.detect_corners`);
    * ``"pair:LEFT:RIGHT:N"``: two grey images (paths; their centres at the frame size) and the strongest N
      Harris corners of each;
    * ``"dataset:NAME:N"``: a pair of :mod:`eyestereo.tools.dense.datasets` (tsukuba, venus, motorcycle) resized
      to the frame (:func:`~eyestereo.tools.dense.datasets.resize`) and the strongest N Harris corners of each.
    """
    kind, *args = spec.split(":")
    if kind == "random":
        rng = np.random.default_rng(int(args[0]))
        p = float(args[1])
        imgs = rng.integers(0, 256, (2, h, w)).astype(np.uint8)
        flags = rng.random((2, h, w)) < p
        return imgs[0], imgs[1], flags[0], flags[1]
    if kind == "texture":
        import cv2

        rng = np.random.default_rng(int(args[0]))
        shift = int(args[2])
        base = cv2.GaussianBlur(rng.integers(0, 256, (h, w + shift)).astype(np.float32), (0, 0), 1.5)
        base = cv2.normalize(base, None, 0, 255, cv2.NORM_MINMAX)
        left = base[:, :w]  # a point at column X of the texture: left X, right X - shift (disparity shift)
        right = base[:, shift:] + rng.normal(0, 2, (h, w))
        imgs = [np.clip(np.rint(i), 0, 255).astype(np.uint8) for i in (left, right)]
        return (*imgs, *(harris_flags(img, int(args[1])) for img in imgs))
    if kind == "dataset":
        from eyestereo.tools.dense import datasets

        pair = datasets.resize(datasets.load(args[0]), w, h)
        return pair.left, pair.right, harris_flags(pair.left, int(args[1])), harris_flags(pair.right, int(args[1]))
    if kind == "pair":
        import cv2

        imgs = []
        for path in args[:2]:
            img = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
            if img is None:
                raise FileNotFoundError(f"cannot read {path}")
            y0, x0 = (img.shape[0] - h) // 2, (img.shape[1] - w) // 2
            imgs.append(np.ascontiguousarray(img[y0:y0 + h, x0:x0 + w]))
        return (*imgs, *(harris_flags(img, int(args[2])) for img in imgs))
    raise ValueError(f"unknown frame spec {spec!r}")


def harris_flags(img: np.ndarray, count: int) -> np.ndarray:
    """The flags of the strongest ``count`` Harris corners of ``img`` (the bit-true model's)."""
    from eyestereo.tools.matching.sparse import detect_corners

    f = np.zeros(img.shape, bool)
    xy = np.asarray(detect_corners(img, count=count), np.int64).reshape(-1, 2)
    f[xy[:, 1], xy[:, 0]] = True
    return f


def stream_plan(sink: dict, flags: dict, cases, start: int, cfg: dict, rng) -> tuple[dict, list[int]]:
    """{edge: {handle: value}} of the pixel stream (``sink``'s handles: data, valid, cam, eol, eof) and the flag
    stream (``flags``'s) of the frames, and the edge of each frame's last flag beat.

    ``cfg``: ``idle`` (probability of an idle clock after a beat), ``frame_gap`` (idle clocks between frames),
    ``lag_rows`` and ``lag_pixels`` (each flag beat comes with the pixel beat that many rows and pixels later),
    ``lag_clocks`` (and that many clocks after it), ``tail_spacing`` (clocks between the flags after the last
    pixel).
    """
    h, w = cases[0][0].shape
    idle, gap = cfg.get("idle", 0.0), cfg.get("frame_gap", 0)
    pix, flg = [], []  # (values) in beat order
    edges = []
    edge = start
    for left, right, fl, fr in cases:
        for y in range(h):
            for x in range(w):
                for cam, img, f in ((0, left, fl), (1, right, fr)):
                    e = dict(eol=int(x == w - 1), eof=int(x == w - 1 and y == h - 1), cam=cam)
                    pix.append(dict(data=int(img[y, x]), **e))
                    flg.append(dict(data=int(f[y, x]), **e))
                    edges.append(edge)
                    edge += 1 + int(rng.random() < idle)
        edge += gap
    lag = 2 * (cfg.get("lag_rows", 0) * w + cfg.get("lag_pixels", 0))
    lag_clocks, tail = cfg.get("lag_clocks", 3), cfg.get("tail_spacing", 1)
    flag_edges = [(edges[j + lag] if j + lag < len(edges) else edges[-1] + tail * (j + lag - len(edges) + 1))
                  + lag_clocks for j in range(len(flg))]
    plan: dict[int, dict] = {}
    for handles, beats, at in ((sink, pix, edges), (flags, flg, flag_edges)):
        for i, (values, e) in enumerate(zip(beats, at)):
            slot = plan.setdefault(e, {})
            slot[handles["valid"]] = 1
            for n, v in values.items():
                slot[handles[n]] = v
            if i + 1 == len(at) or at[i + 1] != e + 1:
                plan.setdefault(e + 1, {}).setdefault(handles["valid"], 0)
    frame_beats = 2 * w * h
    return plan, [flag_edges[(f + 1) * frame_beats - 1] for f in range(len(cases))]


async def play_plan(clock, plan: dict) -> None:
    """Drive ``plan`` ({edge: {handle: value}}, :func:`stream_plan`'s) half a period before each edge of ``clock``
    (a :class:`~eyestereo.sim.lib.queue.EdgeClock`)."""
    from eyestereo.sim.lib.queue import wait_until

    for e in sorted(plan):
        await wait_until(clock.before(e))
        for handle, v in plan[e].items():
            handle.value = v


def check_match_lists(beats, expected) -> list[int]:
    """The words a :class:`~eyestereo.sim.lib.queue.QueueMonitor` recorded (``beats``) against each frame's model
    list (``expected``: match_engine / feature_matcher results, their ``words``) in order, nothing after the
    last; AssertionError at the first difference. Returns the edge of each frame's last word (its trailer)."""
    got = [(d, eol, eof) for d, eol, eof, _ in beats]
    pos, trailer_edges = 0, []
    for f, e in enumerate(expected):
        want = [(int(d), bool(a), bool(b)) for d, a, b in e["words"]]
        part = got[pos:pos + len(want)]
        if part != want:
            i = next((i for i, (a, b) in enumerate(zip(part, want)) if a != b), min(len(part), len(want)))
            raise AssertionError(f"frame {f}: {len(part)} words out, the model's {len(want)}; first difference at "
                                 f"word {i}: got {part[i] if i < len(part) else None}, want "
                                 f"{want[i] if i < len(want) else None} (model: {e['count']} matches, "
                                 f"{e['candidates']} candidates)")
        pos += len(want)
        trailer_edges.append(beats[pos - 1][3])
    assert pos == len(got), f"{len(got) - pos} words after the last frame's trailer: {got[pos:pos + 3]}"
    return trailer_edges
