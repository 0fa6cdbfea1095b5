"""Yosys for the Spartan-3E: the async FIFO's memory is one dual-port block RAM with a clock per port."""

import pytest

from eyestereo.hdl.flow.synth import synth_block

pytestmark = pytest.mark.synth


def test_camera_interface_uses_one_dual_clock_block_ram(tmp_path):
    r = synth_block("camera_interface", tmp_path)
    s = r["summary"]
    assert r["cells"].get("RAMB16_S18_S18") == 1, r["cells"]  # 1024 x 18, write port and read port
    assert s["RAMB16"] == 1 and s["LUTRAM"] == 0 and s["MULT18X18"] == 0
    assert r["cells"].get("BUFG") == 2  # two clocks: PCLK and the system clock
    assert s["LUT"] < 400, s


def test_small_fifo_needs_no_block_ram(tmp_path):
    r = synth_block("async_fifo", tmp_path, depth=16)
    assert r["summary"]["RAMB16"] == 0, r["cells"]
