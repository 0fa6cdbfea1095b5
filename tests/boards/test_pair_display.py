"""pair_display: the monitor's copy of a rectified pair over AXI4-Lite, and the picture it shows (GHDL, numpy model)."""

import shutil

import numpy as np
import pytest
from myhdl import Signal, intbv

from eyestereo.hdl.flow.catalog import get
from eyestereo.sim.lib.runner import run_bench
from eyestereo.tools.models.pair_display import (ANAGLYPH, LEFT, MARK, RIGHT, check_geometry, colour_rule, copy_pair,
                                                 ctrl_words, picture, start_words)
from eyestereo.tools.models.video_timing import MODES

ghdl = pytest.mark.skipif(shutil.which("ghdl") is None, reason="GHDL not installed")
SMALL = dict(width=32, height=24, mode="sim-64x48", rect_base=(100, 900), feat_base=(2000, 4100), max_features=16,
             poll_gap=4, polls=8)


def test_register_words_follow_the_map():
    # CTRL.rect_want is bit 8, feat_want bit 9 (docs/registers.md); CMD's releases the same; byte 1 alone
    assert ctrl_words() == (0x300, 0x300, 0b10)
    # CTRL.mode = 1 (overlapped) and continuous (bit 1); CMD.start bit 0
    assert start_words() == (0x3, 0x1)


def test_copy_clips_and_marks_a_hand_worked_pair():
    left = np.full((5, 6), 255, dtype=np.uint8)
    right = np.arange(30, dtype=np.uint8).reshape(5, 6)
    ram_l, ram_r = copy_pair(left, right, [(0, 0, 0), (5, 4, 1)])
    # every 255 of the image becomes 254; the left corner at (0,0): its cross inside the image, 5 pixels
    assert (ram_l == MARK).sum() == 5 and ram_l[0, 0] == MARK and ram_l[0, 2] == MARK and ram_l[2, 0] == MARK
    assert ram_l[1, 1] == 254 and ram_l[4, 5] == 254
    # the right corner at (5, 4): (5,4) (4,4) (3,4) (5,3) (5,2)
    assert sorted(map(tuple, np.argwhere(ram_r == MARK))) == [(2, 5), (3, 5), (4, 3), (4, 4), (4, 5)]
    assert ram_r[0, 0] == 0 and ram_r[1, 1] == 7


def test_colour_rule_by_hand():
    assert colour_rule(LEFT, 10, 20) == (10, 10, 10)
    assert colour_rule(LEFT, MARK, 20) == (255, 0, 0)
    assert colour_rule(RIGHT, 10, MARK) == (0, 255, 0)
    assert colour_rule(ANAGLYPH, 10, 20) == (10, 20, 20)
    assert colour_rule(ANAGLYPH, 10, MARK) == (255, 255, 0)
    assert colour_rule(0, 10, 20) == (0, 0, 0)


def test_picture_layout():
    ram_l = np.full((24, 32), 7, dtype=np.uint8)
    ram_r = np.full((24, 32), 9, dtype=np.uint8)
    pic = picture(ram_l, ram_r, MODES["sim-64x48"])
    assert pic.shape == (48, 64, 3)
    assert (pic[:24, :32] == 7).all() and (pic[:24, 32:] == 9).all()
    assert (pic[24:, :32] == (7, 9, 9)).all() and (pic[24:, 32:] == 0).all()


def test_geometry_is_checked():
    with pytest.raises(ValueError, match="need 66x48 pixels, the mode shows 64x48"):
        check_geometry(33, 24, MODES["sim-64x48"])
    with pytest.raises(ValueError, match="pair_display: mode 'vga' is not one of"):
        get("pair_display").elaborate(mode="vga")
    with pytest.raises(ValueError, match="pair_display: parameter rect_base must be a pair of ints"):
        get("pair_display").elaborate(**{**SMALL, "rect_base": (0,)})
    with pytest.raises(ValueError, match=r"pair_display: bus needs at least the register map's 23 address bits"):
        get("pair_display").elaborate(**SMALL, addr_bits=8)
    with pytest.raises(ValueError, match="port copies must be"):
        spec = get("pair_display")
        ports, kw, _ = spec.ports(**SMALL)
        ports["copies"] = Signal(intbv(0)[8:])
        spec.func(**ports, **kw)


@pytest.mark.sim
@ghdl
@pytest.mark.parametrize("cfg", [dict(rect_buf=1, feat_buf=0, autostart=True), dict(rect_buf=0, feat_buf=1)],
                         ids=["buf1-autostart", "buf0"])
def test_picture_is_the_models(request, cfg):
    params = {**SMALL, "autostart": cfg.pop("autostart", False)}
    rep = run_bench("pair_display", "tb_pair_display", dict(cfg, seed=3, features=14, frames=2),
                    name=request.node.name, params=params)
    assert rep["frames_checked"] == 2
    assert rep["sram_reads"] >= 32 * 24 + 2 * 16
    # the monitor samples at each rising edge the values before it: counter state k (out of video_timing after edge
    # k) is read at edge k + 1, the picture two registers later at edge k + 3
    assert rep["latency"] == 3


@pytest.mark.sim
@ghdl
def test_no_pair_gives_the_wants_back(request):
    rep = run_bench("pair_display", "tb_pair_display", dict(absent=True), name=request.node.name, params=SMALL)
    assert rep["copies"] == 0


@pytest.mark.othersims
@pytest.mark.parametrize("sim", ["icarus", "verilator"])
def test_picture_on_the_verilog_simulators(request, sim):
    """MyHDL's Verilog of the block on Icarus and Verilator: the same picture as the model's, bit for bit."""
    rep = run_bench("pair_display", "tb_pair_display", dict(rect_buf=1, feat_buf=0, seed=3, features=14, frames=2),
                    name=request.node.name, params={**SMALL, "autostart": True}, sim=sim)
    assert rep["frames_checked"] == 2 and rep["latency"] == 3
