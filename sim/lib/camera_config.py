"""What the camera benches (``tb_camera_interface``, ``tb_camera_stream``) read from their config alike.

A camera bench's JSON config names the block's parameters, the blanking, the frames a camera plays (with
faults, a start part-way into the schedule and idle samples before it) and the clock edges with a reset
high. These helpers turn those entries into :mod:`eyestereo.tools.camera` objects, one rule for every
camera bench (a bench imports no other bench).
"""

from __future__ import annotations

import numpy as np

from eyestereo.sim.lib.camera import camera_frame
from eyestereo.tools.camera import CameraTiming, Fault, cut, frame_schedule, vsyncs_before

#: Edges of each clock domain with its reset high at the start of every camera bench.
INIT_RESET = (0, 3)


def timing_of(cfg: dict) -> CameraTiming:
    """The camera timing of a config: the block's ``params`` (size, byte order, polarities) and ``timing``
    (the blanking; absent entries keep :class:`CameraTiming`'s defaults)."""
    p = cfg["params"]
    return CameraTiming(width=p["width"], height=p["height"], order=p["order"], vsync_active=p["vsync_active"],
                        href_active=p["href_active"], **cfg.get("timing", {}))


def faults_of(spec: dict | None) -> dict[int, Fault]:
    """``{frame: {lines, line_bytes}}`` of the config (JSON keys are strings) as :class:`Fault` per frame."""
    return {int(i): Fault(lines=f.get("lines"), line_bytes={int(k): int(v) for k, v in f.get("line_bytes", {}).items()})
            for i, f in (spec or {}).items()}


def resets_of(extra) -> list[tuple[int, int]]:
    """The initial reset followed by the config's ``[[first, end], ...]`` edges with the reset high."""
    return [INIT_RESET] + [tuple(r) for r in (extra or [])]


def camera_schedule(cam: dict, timing: CameraTiming) -> tuple[list[np.ndarray], int, list]:
    """One camera's ``frames`` (camera words), the VSYNCs cut off before its ``start`` and the runs it plays
    (``preroll`` idle samples, default 8, then the schedule from ``start`` on, with the config's ``faults``)."""
    frames = [camera_frame(s, timing.width, timing.height) for s in cam["frames"]]
    full = frame_schedule(frames, timing, faults=faults_of(cam.get("faults")))
    start = int(cam.get("start", 0))
    return frames, vsyncs_before(full, start), cut(full, start, preroll=int(cam.get("preroll", 8)))
