"""The line cache's plan (tools.models.line_cache): how many lines a calibration needs, and its errors."""

import numpy as np
import pytest

from eyestereo.tools.camera import DEFAULT_TIMING, VGA_PCLK_HZ, VGA_TIMING, CameraTiming
from eyestereo.tools.models.line_cache import fetch, plan, row_spans
from eyestereo.tools.models.poly_unit import Calibration


def test_fetch_reads_the_mask_in_index_order():
    img = np.arange(12, dtype=np.uint8).reshape(3, 4)
    # index 0 = (x+1, y+1), 1 = (x, y+1), 2 = (x+1, y), 3 = (x, y): at (1, 0): 6, 5, 2, 1
    assert fetch((img, img), 1, 0, 0, 0b1111) == [(0, 6), (1, 5), (2, 2), (3, 1)]
    assert fetch((img, img * 0), 1, 0, 1, 0b0101) == [(0, 0), (2, 0)]


def test_vga_timing_is_30_fps():
    # 784 pixel times x 2 PCLK x 510 lines at 24 MHz (the OV7670's VGA frame)
    frame_pclk = (2 * 784) * 510
    assert abs(VGA_PCLK_HZ / frame_pclk - 30.0) < 0.02
    assert VGA_TIMING.width == 640 and VGA_TIMING.height == 480


def test_a_flat_map_needs_its_interpolation_row_and_the_lag():
    """An identity-like calibration (the rig at a small size reads rows near its own): the span of each row is
    a few lines; the plan's lines are at least the span plus the skew, and a power of two."""
    cal = Calibration.load("rig:48x36")
    lo, hi = row_spans(cal)
    assert (hi - lo >= 1).all()  # two rows at least: the interpolation's
    p = plan(cal)
    assert p.lines & (p.lines - 1) == 0 and p.lines >= p.span + p.skew
    assert p.needed <= p.lines < 2 * p.needed


def test_plan_refuses_what_does_not_fit():
    cal = Calibration.load("rig:48x36")
    with pytest.raises(ValueError, match="rig:48x36 needs a line cache of"):
        plan(cal, max_lines=2)
    with pytest.raises(ValueError, match="camera timing is 352x288"):
        plan(cal, timing=DEFAULT_TIMING)
    slow = CameraTiming(width=48, height=36, h_blank=2, v_sync=1, v_back=0, v_front=0)
    with pytest.raises(ValueError, match="rig:48x36 needs a line cache of .* lines per camera"):
        # a rectifier 50x slower than the cameras falls behind by hundreds of lines
        plan(cal, timing=slow, clock_hz=2e6)
    with pytest.raises(ValueError, match="after the cameras' next frame begins"):
        # one just slower than the cameras keeps within the cache but ends after the next frame began
        plan(cal, timing=slow, clock_hz=100e6, pixel_clock_hz=100e6 / 8 * 2 * 1.02, max_lines=64)
    for bad in (dict(skew=-1), dict(clocks_per_pair=0), dict(max_lines=48), dict(clock_hz=float("nan"))):
        with pytest.raises(ValueError):
            plan(cal, **bad)
