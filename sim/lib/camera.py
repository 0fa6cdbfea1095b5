"""cocotb camera model: plays a camera bus schedule on a DUT's CameraBus ports, with its own PCLK.

The camera owns its clock: :class:`CameraModel` starts PCLK (any period and phase, in ps) and drives
VSYNC, HREF and the data bus from a schedule of :mod:`eyestereo.tools.camera` (frames from images,
blanking, polarities, byte order, faults, a start part-way through a frame). Like the OV6630 it changes
its outputs after the falling edge of PCLK, so they are stable at the rising edge that samples them:
sample ``j`` of the schedule is on the bus at PCLK rising edge ``j`` (edge 0 at ``phase``).

The model checks its own rules as it plays: the schedule's runs have the timing's polarities, lines are
separated by blanking (HREF inactive for at least one PCLK), and PCLK has the configured period (the
bench can measure it).

Python wakes once per data byte and once per blanking run (a ``Timer`` to the next change), not on every
clock; PCLK itself is the simulator's own clock (``Clock(impl="gpi")``).
"""

from __future__ import annotations

import cv2
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import Timer

from eyestereo.sim.lib.bench import DATA, make_frame
from eyestereo.sim.lib.stream import port_handles
from eyestereo.tools.camera import CameraTiming, run_length, yuv_frame, yuv_from_bgr
from eyestereo.tools.io import centre_crop


def camera_frame(spec: str, width: int, height: int) -> np.ndarray:
    """Camera words (height, width) for a stimulus spec.

    ``random:S`` (Y, U, V random, seed S), ``grey:IMG`` (Y from a :func:`~eyestereo.sim.lib.bench.make_frame`
    image spec, U = V = 128), ``file:NAME`` (a centre crop of a colour image in tests/data: Y from its grey
    version, U and V from its colour, 4:2:2), ``ramp`` (Y = x + y, U = x, V = y, easy to read in waves).
    """
    kind, _, arg = spec.partition(":")
    if kind == "random":
        rng = np.random.default_rng(int(arg))
        return yuv_frame(rng.integers(0, 256, (height, width)), rng.integers(0, 256, (height, width // 2)),
                         rng.integers(0, 256, (height, width // 2)))
    if kind == "grey":
        return yuv_frame(make_frame(arg, width, height))
    if kind == "ramp":
        yy, xx = np.mgrid[0:height, 0:width]
        return yuv_frame((xx + yy) % 256, (xx[:, 0::2] // 2) % 256, yy[:, 0::2] % 256)
    if kind == "file":
        img = cv2.imread(str(DATA / arg), cv2.IMREAD_COLOR)
        if img is None:
            raise FileNotFoundError(f"cannot read stimulus image {DATA / arg}")
        crop = np.ascontiguousarray(centre_crop(img, width, height, arg))
        return yuv_from_bgr(crop, grey=make_frame(spec, width, height))
    raise ValueError(f"unknown camera frame spec {spec!r}")


class CameraModel:
    """One camera on the DUT ports ``<prefix>_pclk``, ``_vsync``, ``_href``, ``_data``.

    Args:
        dut: the cocotb DUT handle.
        prefix: port prefix (``cam``, ``cam_l``, ...).
        timing: the camera's :class:`~eyestereo.tools.camera.CameraTiming` (polarities).
        period_ps: PCLK period in ps (even: the clock is high for half of it).
        phase_ps: time of PCLK edge 0, in ps (at least half a period: sample 0 is driven before it).
    """

    def __init__(self, dut, prefix: str, timing: CameraTiming, period_ps: int, phase_ps: int):
        if period_ps < 2 or period_ps % 2:
            raise ValueError(f"camera PCLK period must be an even number of ps, got {period_ps}")
        if phase_ps < period_ps // 2:
            raise ValueError(f"camera phase {phase_ps} ps is less than half a period ({period_ps // 2} ps)")
        self.pclk, self.vsync, self.href, self.data = port_handles(dut, prefix, ("pclk", "vsync", "href", "data"))
        self.timing = timing
        self.period = int(period_ps)
        self.phase = int(phase_ps)
        self.samples = 0  # samples played so far
        self.done = False
        self._idle()
        self.pclk.value = 0

    def _idle(self):
        self.vsync.value = 1 - self.timing.vsync_active
        self.href.value = 1 - self.timing.href_active
        self.data.value = 0

    async def start_clock(self):
        await Timer(self.phase, unit="ps")
        Clock(self.pclk, self.period, unit="ps", impl="gpi").start(start_high=True)

    async def play(self, runs):
        """Drive the schedule; sample j changes the bus at (edge j) - T/2 and is sampled at edge j."""
        t = self.timing
        T = self.period
        now = self.phase - T // 2
        if now > 0:
            await Timer(now, unit="ps")
        prev = None
        for kind, p in runs:
            n = run_length((kind, p))
            if n <= 0:
                continue
            if kind == "line":
                if prev == "line":
                    raise AssertionError("camera model: two lines without blanking between them")
                self.vsync.value = 1 - t.vsync_active
                self.href.value = t.href_active
                for b in np.asarray(p).tolist():
                    self.data.value = int(b)
                    await Timer(T, unit="ps")
            else:
                self.vsync.value = t.vsync_active if kind == "vsync" else 1 - t.vsync_active
                self.href.value = 1 - t.href_active
                self.data.value = 0
                await Timer(n * T, unit="ps")
            prev = kind
            self.samples += n
        self._idle()
        self.done = True
