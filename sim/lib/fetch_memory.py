"""cocotb memory model answering the pixel fetch port (:mod:`eyestereo.hdl.interfaces.fetch_port`), rules checked.

:class:`FetchMemory` is the slave side: two camera images, a request taken whenever ``req_ready`` (the
model's) and ``req_valid`` are high at a rising edge, the popcount(mask) pixels answered in index order,
requests answered in order. Timing, drawn from a seeded generator:

``ready_p``   probability that ``req_ready`` is high in a clock (1: always ready)
``latency``   fixed wait clocks from a request's edge to its first beat can come (0: the next clock)
``wait_p``    probability of a wait clock before each beat (the thesis's "random delays")
``stall_p``, ``stall``  probability per clock of a long stall (no beat, not ready) of ``stall`` (lo, hi)
              clocks

Rules checked at every edge (an AssertionError names the clock and the rule): ``req_valid`` defined; a
request's fields defined; mask not 0; x, y inside the image and x+1 / y+1 inside it for the indices
asked; a request offered and not taken stays offered, unchanged, until it moves. Every request is
recorded (x, y, cam, mask).

:class:`StereoMonitor` records the DUT's 8-bit stereo ``source`` stream (data, cam, eol, eof) beat by
beat. Both run in one coroutine per clock (:func:`run_clock`), so Python wakes once per clock.
"""

from __future__ import annotations

import random
from collections import deque
from pathlib import Path

import numpy as np
from cocotb.triggers import RisingEdge

from eyestereo.hdl.interfaces.fetch_port import OFFSETS


def _int(handle, what: str, clock: int) -> int:
    v = handle.value
    if not v.is_resolvable:
        raise AssertionError(f"clock {clock}: {what} is undefined ({v})")
    return int(v)


class FetchMemory:
    """The slave side of ``<prefix>_*`` (module docstring)."""

    def __init__(self, dut, images: dict[int, np.ndarray], *, prefix: str = "fetch", seed: int = 1,
                 ready_p: float = 1.0, latency: int = 0, wait_p: float = 0.0, stall_p: float = 0.0,
                 stall: tuple[int, int] = (50, 400)):
        g = lambda f: getattr(dut, f"{prefix}_{f}")  # noqa: E731
        self.valid, self.x, self.y, self.cam, self.mask = (g(f) for f in ("req_valid", "req_x", "req_y", "req_cam",
                                                                          "req_mask"))
        self.ready, self.rsp_valid, self.rsp_idx, self.rsp_data = (g(f) for f in ("req_ready", "rsp_valid",
                                                                                  "rsp_idx", "rsp_data"))
        self.images = {c: np.asarray(im, dtype=np.uint8) for c, im in images.items()}
        h, w = self.images[0].shape
        self.w, self.h = w, h
        self.rng = random.Random(seed)
        self.ready_p, self.latency, self.wait_p, self.stall_p = ready_p, latency, wait_p, stall_p
        self.stall_range = stall
        self.requests: list[tuple[int, int, int, int]] = []
        self.beats: deque = deque()  # (earliest clock, idx, data)
        self.ready_now = False
        self.offered = None
        self.stall_left = 0
        self.reads = 0
        self.ready.value = 0
        self.rsp_valid.value = 0
        self.rsp_idx.value = 0
        self.rsp_data.value = 0

    def edge(self, clock: int) -> None:
        """Sample the request at this edge, then drive ``req_ready`` and the response for the next clock."""
        rv = _int(self.valid, "fetch req_valid", clock)
        if rv:
            req = (_int(self.x, "req_x", clock), _int(self.y, "req_y", clock), _int(self.cam, "req_cam", clock),
                   _int(self.mask, "req_mask", clock))
            if self.offered is not None:
                assert req == self.offered, (f"clock {clock}: an offered request changed before it moved: "
                                             f"{self.offered} -> {req}")
            if self.ready_now:
                self._take(req, clock)
                self.offered = None
            else:
                self.offered = req
        else:
            assert self.offered is None, f"clock {clock}: an offered request {self.offered} was withdrawn"
        # next clock
        if self.stall_left:
            self.stall_left -= 1
            stalled = True
        elif self.stall_p and self.rng.random() < self.stall_p:
            self.stall_left = self.rng.randint(*self.stall_range)
            stalled = True
        else:
            stalled = False
        ready = not stalled and (self.ready_p >= 1.0 or self.rng.random() < self.ready_p)
        if ready != self.ready_now:
            self.ready.value = int(ready)
            self.ready_now = ready
        beat = None
        if not stalled and self.beats and self.beats[0][0] <= clock + 1:
            if not self.wait_p or self.rng.random() >= self.wait_p:
                beat = self.beats.popleft()
        if beat is not None:
            self.rsp_valid.value = 1
            self.rsp_idx.value = beat[1]
            self.rsp_data.value = beat[2]
            self._driving = True
        elif getattr(self, "_driving", False):
            self.rsp_valid.value = 0
            self._driving = False

    def _take(self, req, clock: int) -> None:
        x, y, cam, mask = req
        n = len(self.requests)
        assert mask != 0, f"clock {clock}: request {n} {req} has mask 0 (send no request instead)"
        assert cam in (0, 1), f"clock {clock}: request {n}: cam {cam}"
        for i, (ox, oy) in enumerate(OFFSETS):
            if (mask >> i) & 1:
                px, py = x + ox, y + oy
                assert px < self.w and py < self.h, (f"clock {clock}: request {n} {req}: index {i} = ({px}, {py}) "
                                                     f"lies outside the {self.w}x{self.h} image")
        self.requests.append(req)
        img = self.images[cam]
        first = clock + 1 + self.latency
        for i, (ox, oy) in enumerate(OFFSETS):
            if (mask >> i) & 1:
                self.beats.append((first, i, int(img[y + oy, x + ox])))
                self.reads += 1

    def clear(self) -> None:
        """Forget everything (the memory side reset together with the DUT)."""
        self.requests.clear()
        self.beats.clear()
        self.offered = None
        self.stall_left = 0
        self.reads = 0

    @property
    def idle(self) -> bool:
        return not self.beats and self.offered is None

    def request_arrays(self) -> dict[str, np.ndarray]:
        r = np.asarray(self.requests, dtype=np.int64).reshape(-1, 4)
        return {k: r[:, i] for i, k in enumerate(("x", "y", "cam", "mask"))}


class StereoMonitor:
    """Records every valid beat of an 8-bit stereo stream ``<prefix>_*``."""

    def __init__(self, dut, prefix: str = "source"):
        g = lambda f: getattr(dut, f"{prefix}_{f}")  # noqa: E731
        self.valid, self.data, self.cam, self.eol, self.eof = (g(f) for f in ("valid", "data", "cam", "eol", "eof"))
        self.beats: list[tuple[int, int, int, int]] = []
        self.clocks: list[int] = []

    def edge(self, clock: int) -> None:
        if _int(self.valid, "source_valid", clock):
            self.beats.append((_int(self.data, "source_data", clock), _int(self.cam, "source_cam", clock),
                               _int(self.eol, "source_eol", clock), _int(self.eof, "source_eof", clock)))
            self.clocks.append(clock)

    def arrays(self) -> dict[str, np.ndarray]:
        b = np.asarray(self.beats, dtype=np.int64).reshape(-1, 4)
        return {k: b[:, i] for i, k in enumerate(("data", "cam", "eol", "eof"))}


class Clocked:
    """Calls ``edge(clock)`` of its agents at every rising edge; ``clock`` counts edges."""

    def __init__(self, clk, agents, *, progress: str | None = None, total: int = 0, monitor=None):
        self.clk = clk
        self.agents = list(agents)
        self.clock = 0
        self.progress = Path(progress) if progress else None
        self.total = total
        self.monitor = monitor

    async def run(self) -> None:
        edges = [a.edge for a in self.agents]
        last = 0
        while True:
            await RisingEdge(self.clk)
            self.clock += 1
            for e in edges:
                e(self.clock)
            if self.progress is not None and self.monitor is not None and self.clock - last >= 20000:
                last = self.clock
                self.progress.write_text(f"{len(self.monitor.beats)} {self.total}\n")


def _first_difference(got: dict, want: dict, fields: tuple[str, ...], what: str, unit: str, where) -> int:
    """The common part of the comparisons: the first differing record of the fields, in that order
    (``where(k, field)`` describes record ``k``), then the counts; returns the records compared."""
    n_got, n_want = len(got[fields[0]]), len(want[fields[0]])
    n = min(n_got, n_want)
    for f in fields:
        bad = np.nonzero(got[f][:n] != want[f][:n])[0]
        if len(bad):
            raise AssertionError(f"{what}: {len(bad)} {unit} differ in {f}; first: {where(int(bad[0]), f)}")
    assert n_got == n_want, f"{what}: {n_got} {unit}, {n_want} expected by the model"
    return n


def compare_stream(got: dict, want: dict, width: int, what: str) -> int:
    """All beats equal, all fields; an AssertionError names the first difference."""

    def where(k: int, f: str) -> str:
        px = k // 2
        return (f"beat {k} (pixel ({px % width}, {px // width}), cam {k % 2}): got {int(got[f][k])}, "
                f"expected {int(want[f][k])}")

    return _first_difference(got, want, ("cam", "eol", "eof", "data"), what, "beats", where)


def compare_requests(got: dict, want: dict, what: str) -> int:
    """All requests equal (x, y, cam, mask); an AssertionError names the first difference."""
    fields = ("x", "y", "cam", "mask")

    def where(k: int, f: str) -> str:
        return f"request {k}: got {[int(got[g][k]) for g in fields]}, expected {[int(want[g][k]) for g in fields]}"

    return _first_difference(got, want, ("cam", "x", "y", "mask"), what, "requests", where)
