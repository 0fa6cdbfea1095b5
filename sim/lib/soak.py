"""The fault soak of the complete front end: the faults, what the system must do with each, the camera scripts.

:data:`FAULTS` is the expected behaviour, written before the soak was run (docs/reliability.md prints it); the
soak bench (:mod:`eyestereo.sim.benches.tb_frontend_soak`) injects the faults and checks every rule. Camera
faults are played by the camera players from their scripts (:func:`camera_runs` builds each camera's script from
the frames and a :class:`CameraPlan`); host faults are the host's own actions between frames.

Rules common to every fault: every frame the host reads is bit-exact (its rectified pair equals the rectification
model of one left and one right camera frame that were sent whole, its feature list the model's list of that
pair with the Harris settings in effect, see ``settings``); nothing hangs (each wait of the host has a deadline:
the run fails at the first one missed); the SRAM part sees no broken rule; the register bus answers OKAY; at the
end DROPPED equals the camera frames the faults broke (exactly, or within the bounds the resets give) and
OVERFLOWS.harris_overflows equals the Harris-domain resets' bound.
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field

import numpy as np

from eyestereo.tools.camera import CameraTiming, Fault, frame_schedule

#: Fault kind -> (who injects it, what is done, what the system must do). "Frames" are camera frame periods.
FAULTS = {
    "short_line": ("camera", "one line (not the first) of a frame carries 1 .. 2w-1 bytes: HREF drops early",
                   "camera_stream aborts the frame: DROPPED of that camera +1 (exactly); the frame is never read; "
                   "the next whole frames go on"),
    "long_line": ("camera", "one line (not the first) carries 2w+1 .. 2w+h_blank-1 bytes (extra 0x5A)",
                  "as short_line: DROPPED +1 exactly, the frame never read"),
    "short_frame": ("camera", "VSYNC comes early: a frame ends after 1 .. h-1 of its lines",
                    "as short_line: DROPPED +1 exactly, the frame never read"),
    "mid_frame": ("camera", "a frame begun mid-way: its VSYNC and first 1 .. h-1 lines lost (blanking instead)",
                  "camera_stream ignores its lines until the next VSYNC: the frame is never read, not counted "
                  "in DROPPED (no word of it was taken)"),
    "pclk_stop": ("camera", "PCLK stops for 2 .. 2000 PCLK periods inside a frame's active lines",
                  "the frame arrives late but whole: nothing dropped, the frame may be read"),
    "late_start": ("camera", "a camera stops before a frame's VSYNC for 1 .. 2 camera frames, then starts again",
                   "the other camera's frames go on into its buffers (the newest kept): nothing dropped; the next "
                   "pair read (its two frames may be of different indices) within 3 frames after the camera is back"),
    "host_pause": ("host", "the host holds the buffers it took for 1 .. 3 frames before releasing them",
                   "the system goes on into the other buffers (overlapped) or waits (sequential): nothing dropped; "
                   "the next frame read is bit-exact"),
    "settings_write": ("host", "k (both cameras) and all 32 block thresholds rewritten while a frame runs (one of "
                       "two settings in turn)",
                       "no shadow registers: the frames in flight when the write lands (at most the two frames read "
                       "next) may use the old settings or a mix (the rectified pair still exact, the list the "
                       "model's with neither); every later frame equals the model with the new settings"),
    "mode_change": ("host", "stop, wait until not busy, switch sequential <-> overlapped, start",
                    "stop ends after the frame in progress (busy falls within 3 frames); the next frame read "
                    "bit-exact"),
    "reset_camera": ("host", "one camera domain's reset (wrst_l or wrst_r) held for 8 PCLK at a random time",
                     "the frame that camera was sending is lost: DROPPED of it +0 or +1 (+1 when a word of it had "
                     "reached the FIFO); the next frames whole"),
    "reset_harris": ("host", "the Harris domain's reset (hrst) held for 8 Harris clocks at a random time",
                     "a frame crossing into or out of the Harris clock is cut: OVERFLOWS.harris_overflows and "
                     "LOST.lists_lost +0 or +1 each (the sequencer's list watchdog gives the cut frame's lists up; "
                     "in the sequential mode busy falls with FRAMES unchanged and the host starts again); k and the "
                     "thresholds hold in the Harris clock (k's crossing has no reset; the thresholds are sent again "
                     "after the reset); the frame read next may hold a cut list (its rectified pair exact), the "
                     "frames after it are bit-exact; nothing hangs"),
}
CAMERA_FAULTS = tuple(k for k, v in FAULTS.items() if v[0] == "camera")
HOST_FAULTS = tuple(k for k, v in FAULTS.items() if v[0] == "host")
#: Camera faults that break a frame camera_stream had started: each adds exactly one to DROPPED.
BREAKING = ("short_line", "long_line", "short_frame")


@dataclass
class CameraPlan:
    """One camera's faults: camera frame index -> (kind, details)."""

    faults: dict[int, tuple[str, dict]] = field(default_factory=dict)

    def broken(self) -> list[int]:
        return sorted(f for f, (k, _) in self.faults.items() if k in BREAKING + ("mid_frame",))


def fault_details(kind: str, timing: CameraTiming, rng: random.Random) -> dict:
    """A camera fault's details, drawn (the ranges of :data:`FAULTS`)."""
    w, h = timing.width, timing.height
    if kind == "short_line":
        return dict(line=rng.randrange(1, h), n=rng.randrange(1, 2 * w))
    if kind == "long_line":
        return dict(line=rng.randrange(1, h), n=2 * w + rng.randrange(1, max(2, timing.h_blank)))
    if kind in ("short_frame", "mid_frame"):
        return dict(lines=rng.randrange(1, h))
    if kind == "pclk_stop":
        # log-uniform 2 .. 2000: short glitches as often as long stops
        return dict(line=rng.randrange(h), at=rng.randrange(2 * w), n=min(2000, int(2 * 1000 ** rng.random())))
    if kind == "late_start":
        return dict(n=int(timing.frame_pclk * rng.uniform(1.0, 2.0)))
    raise ValueError(f"{kind!r} is not a camera fault: {', '.join(CAMERA_FAULTS)}")


def plan_cameras(n_frames: int, rate: float, timing: CameraTiming, rng: random.Random,
                 kinds=CAMERA_FAULTS, skip: int = 2, forced=()) -> tuple[CameraPlan, CameraPlan]:
    """Each camera frame from ``skip`` on carries a fault with probability ``rate`` (a kind of ``kinds``, one
    camera chosen at random; never both cameras in the same frame, never two frames in a row of one camera);
    ``forced``: (camera "l" or "r", frame, kind) faults placed as given (the regression tests' plans)."""
    plans = (CameraPlan(), CameraPlan())
    last = [-2, -2]
    for f in range(skip, n_frames):
        if rng.random() >= rate:
            continue
        cam = rng.randrange(2)
        if f - last[cam] < 2:
            continue
        kind = rng.choice(kinds)
        plans[cam].faults[f] = (kind, fault_details(kind, timing, rng))
        last[cam] = f
    for cam, f, kind in forced:
        if cam not in ("l", "r") or not 0 <= int(f) < n_frames:
            raise ValueError(f"forced camera fault {(cam, f, kind)}: camera 'l' or 'r', frame 0..{n_frames - 1}")
        plans["lr".index(cam)].faults[int(f)] = (kind, fault_details(kind, timing, rng))
    return plans


def camera_runs(frames, timing: CameraTiming, plan: CameraPlan, *, lead: int = 0) -> tuple[list, list[int]]:
    """One camera's script runs for its ``frames`` (camera words) with the ``plan``'s faults, after ``lead``
    stopped PCLK periods; and the sample at which each frame's schedule starts (its VSYNC, or its late_start
    stop before it)."""
    runs, starts, at = [], [], 0
    if lead:
        runs.append(("stop", int(lead)))
        at += int(lead)
    for i, f in enumerate(frames):
        kind, d = plan.faults.get(i, (None, {}))
        starts.append(at)
        if kind == "short_line":
            fr = frame_schedule([f], timing, faults={0: Fault(line_bytes={d["line"]: d["n"]})})
        elif kind == "long_line":
            fr = frame_schedule([f], timing, faults={0: Fault(line_bytes={d["line"]: d["n"]})})
        elif kind == "short_frame":
            fr = frame_schedule([f], timing, faults={0: Fault(lines=d["lines"])})
        elif kind == "mid_frame":
            fr = _begun_mid_way(frame_schedule([f], timing), d["lines"])
        elif kind == "pclk_stop":
            fr = _stopped(frame_schedule([f], timing), d["line"], d["at"], d["n"])
        else:
            fr = frame_schedule([f], timing)
            if kind == "late_start":
                fr = [("stop", d["n"])] + fr
        runs += fr
        at += sum(len(p) if k == "line" else int(p) for k, p in fr)
    return runs, starts


def _begun_mid_way(runs, lines: int) -> list:
    """The frame's VSYNC and its first ``lines`` lines replaced by blanking of the same length."""
    out, seen, lost = [], 0, 0
    for kind, p in runs:
        if kind == "vsync" or (kind == "line" and seen < lines):
            n = len(p) if kind == "line" else int(p)
            out.append(("idle", n))
            lost += n
            seen += kind == "line"
        else:
            out.append((kind, p))
    return out


def _stopped(runs, line: int, at: int, n: int) -> list:
    """PCLK stopped for ``n`` periods after byte ``at`` of line ``line`` (the bus holds its values)."""
    out, seen = [], 0
    for kind, p in runs:
        if kind == "line":
            if seen == line:
                b = np.asarray(p)
                out += [("line", b[:at + 1]), ("stop", n)] + ([("line", b[at + 1:])] if at + 1 < b.size else [])
                seen += 1
                continue
            seen += 1
        out.append((kind, p))
    return out


def settings_pair(thr: int, k: int) -> tuple[dict, dict]:
    """The two Harris settings the soak alternates between: (k, thresholds) of the run, and a second one."""
    return (dict(k=k, thr=thr), dict(k=k + 3, thr=max(1, thr // 2)))
