"""The register table (tools/regmap.py), the bank's transaction model and the host driver on it (no simulator).

Expected values here are written out by hand from the issue and the thesis (k = 0.04, 2 x 16 thresholds
of 20 bits, 22 arbiter words), not taken from the code under test.
"""

from __future__ import annotations

import asyncio
import dataclasses

import pytest

from eyestereo.tools import regmap as rm
from eyestereo.tools.host_driver import BusError, HostDriver, ModelBus
from eyestereo.tools.models import cornerness, harris_mono, sram_arbiter
from eyestereo.tools.models.register_bank import RegisterBank, strobe_mask
from eyestereo.tools.regmap import OKAY, REGMAP, SLVERR, Field, Register, RegisterMap, RegisterMapError


def run(coro):
    return asyncio.run(coro)


# ---- the table -------------------------------------------------------------------------------------
def test_widths_and_names_agree_with_the_models():
    assert rm.K_BITS == cornerness.K.wl == 8
    assert rm.THRESHOLD_BITS == cornerness.OUT.wl == 20
    assert rm.K_RESET == harris_mono.k_code(0.04) == 10
    assert len(rm.ARB_WORDS) == len(sram_arbiter.STAT) == 22
    assert [w.split("_", 1)[1] for w in rm.ARB_WORDS[:6]] == list(sram_arbiter.MASTERS)
    assert all(sram_arbiter.STAT[i].startswith("words moved") for i in range(6))
    assert sram_arbiter.STAT[12] == "clocks since reset" and rm.ARB_WORDS[12] == "clocks"


def test_the_map_has_what_issue_15_asks_for():
    names = set(REGMAP.names)
    assert {"CTRL", "CMD", "STATUS", "K_LEFT", "K_RIGHT", "THR_LEFT", "THR_RIGHT", "FRAMES", "FEATURES", "FCOUNT",
            "DROPPED", "OVERFLOWS", "ARB", "SRAM"} <= names
    assert REGMAP["THR_LEFT"].count == REGMAP["THR_RIGHT"].count == 16  # 4x4 blocks per camera
    assert REGMAP["FCOUNT"].count == 32
    assert dict(REGMAP.field("mode")[1].values) == {0: "sequential", 1: "overlapped"}
    assert dict(REGMAP.field("continuous")[1].values) == {0: "single-shot", 1: "continuous"}
    assert REGMAP.addr_bits == 23  # the SRAM window: 1M words at 0x400000, one per 32-bit word


def test_decode():
    assert REGMAP.decode(0x000)[0].name == "ID"
    assert REGMAP.decode(0x00B)[0].name == "CTRL"  # low bits ignored
    assert REGMAP.decode(0x13C) == (REGMAP["THR_LEFT"], 15)
    assert REGMAP.decode(0x140) == (REGMAP["THR_RIGHT"], 0)
    assert REGMAP.decode(0x254) == (REGMAP["ARB"], 21)
    assert REGMAP.decode(0x258) is None  # ARB's unused words
    assert REGMAP.decode(0x01C) is None and REGMAP.decode(0x400) is None and REGMAP.decode(0x3FFFFC) is None
    assert REGMAP.decode(0x7FFFFC) == (REGMAP["SRAM"], (1 << 20) - 1)


@pytest.mark.parametrize("change,match", [
    (lambda regs: regs + (Register("X", 0x008, "rw", "d", (Field("x", 0, 1, "d"),)),), "overlap"),
    (lambda regs: regs + (Register("X", 0x034, "rw", "d", (Field("mode", 0, 1, "d"),)),), "unique"),
    (lambda regs: regs + (Register("CTRL", 0x034, "rw", "d", (Field("x", 0, 1, "d"),)),), "unique"),
    (lambda regs: regs + (Register("X", 0x034, "rw", "d", (Field("x", 30, 4, "d"),)),), "outside the 32-bit"),
    (lambda regs: regs + (Register("X", 0x034, "rw", "d", (Field("x", 0, 2, "d", reset=4),)),), "does not fit"),
    (lambda regs: regs + (Register("X", 0x036, "rw", "d", (Field("x", 0, 2, "d"),)),), "aligned"),
    (lambda regs: regs + (Register("X", 0x034, "bogus", "d", (Field("x", 0, 2, "d"),)),), "unknown kind"),
    (lambda regs: regs + (Register("X", 0x3C8, "array", "d", (Field("x", 0, 2, "d"),), count=3, port="x"),),
     "aligned"),
    (lambda regs: regs + (Register("X", 0x800, "rw", "d", (Field("x", 0, 2, "d"),)),), "local space"),
    (lambda regs: regs + (Register("X", 0x034, "rw", "d", (Field("x", 0, 2, "d"), Field("y", 1, 2, "d"))),),
     "overlaps another field"),
])
def test_bad_tables_are_refused(change, match):
    with pytest.raises(RegisterMapError, match=match):
        RegisterMap(change(rm.REGISTERS))


def test_committed_documents_are_make_regs_output():
    root = rm.Path(rm.__file__).resolve().parent.parent
    assert (root / "docs" / "registers.md").read_text() == REGMAP.document(), "run make regs"
    readme = (root / "README.md").read_text()
    assert rm.readme_section(readme) == readme, "README's register table is not current: run make regs"
    assert "| `0x014` | K_LEFT | rw | `0xa` | k_left[7:0] |" in readme


def test_make_regs_refuses_a_readme_without_markers(tmp_path, capsys):
    (tmp_path / "README.md").write_text("no markers\n")
    assert rm.main(["--doc", str(tmp_path / "r.md"), "--readme", str(tmp_path / "README.md")]) == 1
    assert "regs:begin" in capsys.readouterr().err
    assert not (tmp_path / "r.md").exists()


# ---- the model -------------------------------------------------------------------------------------
def test_strobe_mask():
    assert strobe_mask(0xF) == 0xFFFFFFFF and strobe_mask(0x5) == 0x00FF00FF and strobe_mask(0) == 0
    with pytest.raises(ValueError):
        strobe_mask(16)


def test_model_reset_values_and_rw():
    b = RegisterBank(width=352, height=288)
    assert b.read(0x000) == (0x45530001, OKAY)
    assert b.read(0x004) == (288 << 16 | 352, OKAY)
    assert b.read(0x014) == (10, OKAY) and b.outputs()["k_left"] == 10
    assert b.write(0x008, 0xFFFFFFFF) == OKAY
    assert b.read(0x008) == (0x703, OKAY)  # mode, continuous, rect_want, feat_want, disp_want only
    assert b.write(0x008, 0, strb=0x2) == OKAY  # byte 1: the want bits
    assert b.read(0x008) == (0x003, OKAY)
    assert b.outputs()["mode"] == 1 and b.outputs()["rect_want"] == 0


def test_model_pulses_arrays_windows_memory_and_errors():
    b = RegisterBank()
    assert b.write(0x00C, 0x101) == OKAY and b.read(0x00C) == (0, OKAY)
    assert b.events == [("pulse", "start"), ("pulse", "rect_release")]
    assert b.write(0x00C, 0x2, strb=0x2) == OKAY and len(b.events) == 2  # the stop bit's byte not strobed
    assert b.write(0x104, 0xABCDEF12) == OKAY
    assert b.read(0x104) == (0xDEF12, OKAY) and b.events[-1] == ("write", "thr_left", 1, 0xDEF12)
    assert b.write(0x104, 0x00000034, strb=0x1) == OKAY and b.read(0x104) == (0xDEF34, OKAY)
    b.windows["arb"] = lambda i: 1000 + i
    assert b.read(0x200 + 4 * 12) == (1012, OKAY) and b.read(0x258) == (0, SLVERR)
    b.windows["fcount"] = lambda i: 0x12345 + i
    assert b.read(0x180) == (0x2345, OKAY)  # 16-bit counts
    assert b.write(0x400000 + 8, 0xAAAA5555, strb=0x3) == OKAY and b.read(0x400008) == (0x5555, OKAY)
    assert b.write(0x400008, 0x1200, strb=0x2) == OKAY and b.read(0x400008) == (0x1255, OKAY)
    assert b.write(0x400008, 0xFFFF0000, strb=0xC) == OKAY and b.read(0x400008) == (0x1255, OKAY)
    for bad in (0x01C, 0x400, 0x3FFFFC):
        assert b.read(bad) == (0, SLVERR) and b.write(bad, 1) == SLVERR
    for ro in (0x000, 0x010, 0x020, 0x200):
        assert b.write(ro, 1) == SLVERR
    b.set_input("frames", 7)
    with pytest.raises(ValueError, match=r"^FEATURES\.features_right: 131071 does not fit \(0\.\.65535, 16 bits\)$"):
        b.set_input("features_right", 0x1FFFF)  # 16 bits: refused, not masked
    b.set_input("features_right", 0xFFFF)
    assert b.read(0x020) == (7, OKAY) and b.read(0x024) == (0xFFFF << 16, OKAY)
    b.reset()
    assert b.read(0x104) == (0, OKAY) and b.read(0x014) == (10, OKAY) and b.events == []


# ---- the host driver on the model --------------------------------------------------------------------
def test_driver_by_name_on_the_model():
    b = RegisterBank(width=64, height=48)
    drv = HostDriver(ModelBus(b))

    async def body():
        await drv.check_id()
        assert await drv.geometry() == (64, 48)
        await drv.configure(mode="overlapped", continuous=True, k_left=12, thresholds_right=[5, 6, 7])
        assert b.outputs() | {} == dict(mode=1, continuous=1, rect_want=0, feat_want=0, disp_want=0, k_left=12,
                                        k_right=10, p1=10, p2=30, uniqueness=10, lr_check=1, subpixel=1,
                                        match_limit=891, match_uniqueness=0, match_lr_check=1)
        assert (await drv.read_thresholds("THR_RIGHT"))[:4] == [5, 6, 7, 0]
        await drv.set(rect_want=1, feat_want=1)
        assert await drv.read_ctrl() == 0x303  # disp_want (bit 10) not written: configure leaves it
        await drv.start()
        assert b.events[-1] == ("pulse", "start")
        with pytest.raises(BusError):
            await drv.write("FRAMES", 1)
        with pytest.raises(KeyError):
            await drv.set(frames=1)
        with pytest.raises(ValueError, match="does not fit"):
            await drv.set(k_left=256)
        with pytest.raises(ValueError, match="mode must be"):
            await drv.configure(mode="fast")
        b.set_input("frames", 41)
        b.windows["arb"] = lambda i: i * 3
        assert (await drv.arbiter())["clocks"] == 36
        assert (await drv.counters())["arb_moved_host"] == 15
        with pytest.raises(TimeoutError):
            await drv.wait_frame(timeout_clocks=3000, poll_clocks=1000)
        with pytest.raises(ValueError, match=r"^SRAM word 0xc: 131071 does not fit \(0\.\.65535, 16 bits\)$"):
            await drv.write_sram_words(10, [1, 2, 0x1FFFF])  # refused before anything moves on the bus
        await drv.write_sram_words(10, [1, 2, 0xFFFF])
        assert await drv.read_sram_words(10, 3) == [1, 2, 0xFFFF]

    run(body())
    assert drv.bus.clocks == 3000


def test_driver_accessors_are_generated_from_the_table():
    for r in REGMAP:
        assert hasattr(HostDriver, f"read_{r.name.lower()}")
        assert hasattr(HostDriver, f"write_{r.name.lower()}") == (r.kind in ("rw", "pulse", "array", "memory"))


def test_register_is_frozen():
    with pytest.raises(dataclasses.FrozenInstanceError):
        REGMAP["CTRL"].offset = 4


def test_dense_register_resets_are_the_models_defaults():
    """DENSE's reset values are the dense chain's tuned defaults (the host changes them only on purpose)."""
    from eyestereo.tools.models.dense_stereo import DEFAULTS

    resets = {f.name: f.reset for f in REGMAP["DENSE"].fields}
    assert resets == {k: int(DEFAULTS[k]) for k in ("p1", "p2", "uniqueness", "lr_check", "subpixel")}
    assert REGMAP["DENSE"].reset_value() == 10 | 30 << 8 | 10 << 16 | 1 << 24 | 1 << 25
