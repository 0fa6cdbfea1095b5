"""pair_display: the monitor's copy of a rectified pair over AXI4-Lite, and the picture it shows (GHDL, numpy model)."""

import shutil

import numpy as np
import pytest
from myhdl import Signal, intbv

from eyestereo.hdl.flow.catalog import get
from eyestereo.sim.lib.runner import run_bench
from eyestereo.tools.models.pair_display import (ANAGLYPH, LEFT, MARK, RIGHT, SEGMENT_RGB, check_geometry, colour_rule,
                                                 copy_pair, ctrl_words, match_plane, picture, segment, start_words)
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


def test_segments_by_hand():
    # a match (x, y, disparity): the left corner's row, from the right corner's column x - d to x
    assert segment(5, 2, 3, 8, 4) == [(2, 2), (3, 2), (4, 2), (5, 2)]
    assert segment(1, 0, 3, 8, 4) == [(0, 0), (1, 0)]  # x - d < 0: cut at the left edge
    assert segment(9, 1, 2, 8, 4) == [(7, 1)]  # x past the right edge: the columns inside
    assert segment(3, 4, 0, 8, 4) == []  # a row below the image
    assert segment(3, 3, 0, 8, 4) == [(3, 3)]  # disparity 0: one pixel
    plane = match_plane([(5, 2, 3, 99), (1, 0, 3, 7), (6, 3, 1, 0)], 8, 4, max_matches=2)
    assert plane.sum() == 4 + 2 and plane[2, 2:6].all() and plane[0, :2].all() and not plane[3].any()


def test_colour_rule_of_a_segment():
    assert colour_rule(ANAGLYPH, 10, 20, True) == SEGMENT_RGB == (0, 255, 255)
    assert colour_rule(ANAGLYPH, MARK, 20, True) == (255, 255, 0)  # a corner's mark wins
    assert colour_rule(LEFT, 10, 20, True) == (10, 10, 10)  # segments only in the anaglyph
    ram = np.full((24, 32), 7, dtype=np.uint8)
    pm = np.zeros((24, 32), dtype=bool)
    pm[3, 4:9] = True
    ram_r = ram.copy()
    ram_r[3, 8] = MARK
    pic = picture(ram, ram_r, MODES["sim-64x48"], pm)
    assert (pic[24 + 3, 4:8] == SEGMENT_RGB).all() and (pic[24 + 3, 8] == (255, 255, 0)).all()
    assert (pic[3, 4:8] == 7).all() and (pic[24 + 3, 9] == (7, 7, 7)).all()
    with pytest.raises(ValueError, match="match plane"):
        picture(ram, ram, MODES["sim-64x48"], pm[:5])


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
def test_picture_with_the_matches(request):
    """matches=True: the match list after the features (from match_offset(max_features)), each match's segment in
    the anaglyph, equal to the model's picture; the list read to its trailer."""
    params = {**SMALL, "matches": True, "max_matches": 12}
    rep = run_bench("pair_display", "tb_pair_display", dict(rect_buf=0, feat_buf=1, seed=5, features=6, matches=8,
                                                            frames=1),
                    name=request.node.name, params=params)
    assert rep["frames_checked"] == 1 and rep["segment_pixels"] > 10
    assert rep["sram_reads"] >= 32 * 24 + 2 * 8 + 3 * 11


@pytest.mark.sim
@ghdl
def test_no_pair_gives_the_wants_back(request):
    rep = run_bench("pair_display", "tb_pair_display", dict(absent=True), name=request.node.name, params=SMALL)
    assert rep["copies"] == 0


@pytest.mark.othersims
@pytest.mark.parametrize("sim", ["icarus", "verilator"])
def test_picture_on_the_verilog_simulators(request, sim):
    """MyHDL's Verilog of the block on Icarus and Verilator, with the matches: the same picture as the model's, bit
    for bit."""
    rep = run_bench("pair_display", "tb_pair_display", dict(rect_buf=1, feat_buf=0, seed=3, features=14, matches=8,
                                                            frames=2),
                    name=request.node.name, params={**SMALL, "autostart": True, "matches": True}, sim=sim)
    assert rep["frames_checked"] == 2 and rep["latency"] == 3 and rep["segment_pixels"] > 10


@pytest.mark.skipif(shutil.which("ghdl") is None or shutil.which("iverilog") is None, reason="GHDL and Icarus needed")
def test_the_match_option_converts_and_analyses(tmp_path):
    """matches=True: the VHDL analyses with both of GHDL's standards, the Verilog compiles and mixes no signed and
    unsigned operands (MyHDL's two back ends can differ there)."""
    from eyestereo.hdl.flow.convert import GHDL_STDS, analyse, check_verilog, convert
    from eyestereo.hdl.flow.vlint import mixed_signedness

    params = {**SMALL, "matches": True}
    files = convert("pair_display", tmp_path / "vhdl", **params)
    for std in GHDL_STDS:
        analyse(files, std, tmp_path / std)
    v = convert("pair_display", tmp_path / "verilog", hdl="Verilog", **params)
    check_verilog(v, "pair_display", tmp_path / "icarus")
    assert not mixed_signedness(v[0].read_text())
    with pytest.raises(ValueError, match="max_matches"):
        get("pair_display").elaborate(**{**SMALL, "matches": True, "max_matches": 0})
