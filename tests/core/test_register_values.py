"""Values that do not fit a register are refused, never masked (issue 30, "silent wrong values").

The host driver (tools/host_driver.py) and the bank's model (tools/models/register_bank.py) check every
user value against the register table (tools/regmap.py: ``Field.check``, ``Register.check_value``,
``Register.check_index``, ``Register.check_words``, ``check_frame_size``). Each test here is one defect
of the masking driver: the value it sent instead (in the comment) and the one-line message it now gives,
compared whole. The driver runs on ``ModelBus(RegisterBank())``, so a refused call must also leave the
bank untouched (no write-port event, no SRAM word).
"""

from __future__ import annotations

import asyncio

import numpy as np
import pytest

from eyestereo.tools.host_driver import HostDriver, ModelBus
from eyestereo.tools.models.register_bank import RegisterBank
from eyestereo.tools.regmap import FRAME_MAX, FRAME_MIN, REGMAP, RegisterIndexError


def run(coro):
    return asyncio.run(coro)


@pytest.fixture
def bank():
    return RegisterBank(width=64, height=48)


@pytest.fixture
def drv(bank):
    return HostDriver(ModelBus(bank))


def refused(call, line: str, exc=ValueError):
    """``call()`` (a function or a coroutine) raises ``exc`` whose message is exactly the one line ``line``."""
    with pytest.raises(exc) as e:
        run(call) if asyncio.iscoroutine(call) else call()
    msg = str(e.value)
    assert "\n" not in msg
    assert msg == line
    return e.value


THR = "(0..1048575, 20 bits)"


# ---- write_thresholds: was `c & r.mask` after int(c) -----------------------------------------------
@pytest.mark.parametrize("bad,shown,why", [
    (1 << 20, "1048576", "does not fit"),        # was 0: every pixel of the block passed
    (-1, "-1", "does not fit"),                  # was 0xFFFFF: no pixel passed
    (1.9, "1.9", "is not an integer"),           # was 1 (int() truncates)
    (2.0, "2.0", "is not an integer"),           # was 2: a float is not a code, even a whole one
    (True, "True", "is a bool, not an integer"),  # was 1: a flag is not a 20-bit code
])
def test_a_threshold_that_does_not_fit_is_refused(bank, drv, bad, shown, why):
    codes = [5, 6, 7, bad]
    refused(drv.write_thresholds("THR_LEFT", codes), f"THR_LEFT[3]: {shown} {why} {THR}")
    assert bank.events == [] and bank.arrays["THR_LEFT"] == [0] * 16  # checked before the first write
    refused(drv.configure(thresholds_right=codes), f"THR_RIGHT[3]: {shown} {why} {THR}")
    assert bank.events == []


def test_thresholds_that_fit_are_written_as_given(bank, drv):
    codes = np.array([0, 1, (1 << 20) - 1] + [7] * 13, dtype=np.int64)  # numpy integers are integers
    run(drv.write_thresholds("THR_LEFT", codes))
    assert bank.arrays["THR_LEFT"] == [int(c) for c in codes]
    assert run(drv.read_thresholds("THR_LEFT")) == [int(c) for c in codes]
    refused(drv.write_thresholds("THR_LEFT", [0] * 17), "THR_LEFT has 16 blocks, got 17 thresholds")


# ---- fields: set() and configure() -------------------------------------------------------------------
def test_a_field_that_does_not_fit_is_refused(bank, drv):
    refused(drv.set(k_left=256), "K_LEFT.k_left: 256 does not fit (0..255, 8 bits)")
    refused(drv.set(k_right=-1), "K_RIGHT.k_right: -1 does not fit (0..255, 8 bits)")
    refused(drv.configure(k_left=256), "K_LEFT.k_left: 256 does not fit (0..255, 8 bits)")
    # configure(k_left=1.9) wrote int(1.9) = 1
    refused(drv.configure(k_left=1.9), "K_LEFT.k_left: 1.9 is not an integer (0..255, 8 bits)")
    refused(drv.set(k_left=True), "K_LEFT.k_left: True is a bool, not an integer (0..255, 8 bits)")
    refused(drv.set(mode=2), "CTRL.mode: 2 does not fit (0..1, 1 bit)")
    # configure(continuous="no") wrote bool("no") = 1; it is checked before mode and k are written
    refused(drv.configure(mode="overlapped", continuous="no", k_left=3),
            "CTRL.continuous: 'no' is not an integer (0..1, 1 bit)")
    assert bank.outputs()["mode"] == 0 and bank.outputs()["k_left"] == 10
    run(drv.set(rect_want=True, k_left=np.uint8(200)))  # a bool in a 1-bit field, a numpy integer
    assert bank.outputs()["rect_want"] == 1 and bank.outputs()["k_left"] == 200


# ---- write(name, value): was `int(value) & 0xFFFFFFFF` ---------------------------------------------
def test_a_word_that_does_not_fit_is_refused(bank, drv):
    # was 5 (the 32-bit mask, then the bank kept the field's 8 bits)
    refused(drv.write("K_LEFT", (1 << 32) + 5), "K_LEFT: 4294967301 does not fit (0..255, 8 bits)")
    refused(drv.write_k_left(0x105), "K_LEFT: 261 does not fit (0..255, 8 bits)")  # was 5
    refused(drv.write("CTRL", 0x4), "CTRL: 4 does not fit (the fields' bits 0x703 only)")  # a bit no field has
    refused(drv.write("THR_LEFT", 1 << 20, 3), f"THR_LEFT[3]: 1048576 does not fit {THR}")
    refused(drv.write("THR_LEFT", 7.0, 3), f"THR_LEFT[3]: 7.0 is not an integer {THR}")
    refused(drv.write("CTRL", 1, strb=0x10), "CTRL wstrb: 16 does not fit (0..15, 4 bits)")
    assert bank.outputs()["k_left"] == 10 and bank.events == []
    run(drv.write("CTRL", 0x303))
    assert bank.rw["CTRL"] == 0x303


# ---- indices -------------------------------------------------------------------------------------------
def test_an_index_outside_an_array_is_refused(bank, drv):
    e = refused(drv.write("THR_LEFT", 5, 16), "THR_LEFT: index 16 is outside 0..15")
    assert isinstance(e, RegisterIndexError) and isinstance(e, IndexError)  # what address() raised before
    refused(drv.write_thr_right(5, -1), "THR_RIGHT: index -1 is outside 0..15")
    refused(drv.read("ARB", 22), "ARB: index 22 is outside 0..21")
    refused(drv.read("FCOUNT", 1.0), "FCOUNT: index 1.0 is not an integer (0..31)")
    refused(drv.write("CTRL", 1, 1), "CTRL: index 1 is outside 0..0")
    refused(lambda: REGMAP["THR_LEFT"].address(16), "THR_LEFT: index 16 is outside 0..15", IndexError)
    assert bank.events == []


# ---- SRAM: write_sram_words masked `int(v) & 0xFFFF` ---------------------------------------------------
@pytest.mark.parametrize("bad,shown,why", [
    (0x12345, "74565", "does not fit"),     # was 0x2345
    (0x1_0000, "65536", "does not fit"),    # was 0
    (-1, "-1", "does not fit"),             # was 0xFFFF
    (1.5, "1.5", "is not an integer"),      # was 1
])
def test_an_sram_word_that_does_not_fit_is_refused(bank, drv, bad, shown, why):
    refused(drv.write_sram_words(0x12340, [1, 2, bad]),
            f"SRAM word 0x12342: {shown} {why} (0..65535, 16 bits)")
    refused(drv.write("SRAM", bad, 0x12340), f"SRAM word 0x12340: {shown} {why} (0..65535, 16 bits)")
    assert bank.sram == {}  # nothing written, not even the words before the bad one


def test_sram_addresses_outside_the_window_are_refused(bank, drv):
    last = REGMAP["SRAM"].count - 1
    assert last == 0xFFFFF  # 1M words: 0x12345 is inside the window (written below), 0x100000 is not
    window = "is outside the window (0..0xfffff)"
    refused(drv.write_sram_words(0x100000, [1]), f"SRAM word 0x100000 {window}")
    refused(drv.write_sram_words(0xFFFFE, [1, 2, 3, 4]),
            f"SRAM word 0x100000 {window}; asked for 4 words from 0xffffe")
    refused(drv.read_sram_words(0xFFFFF, 2), f"SRAM word 0x100000 {window}; asked for 2 words from 0xfffff")
    refused(drv.read_sram_words(-1, 1), f"SRAM word -0x1 {window}")
    refused(drv.read_sram_words(5, -1), "SRAM: word count -1 is not an integer >= 0")
    refused(drv.read_sram_words(5.0, 1), "SRAM word 5.0 is not an integer (the window is 0..0xfffff)")
    assert bank.sram == {}
    run(drv.write_sram_words(0x12345, [0xFFFF, np.uint16(7)]))
    run(drv.write_sram_words(last, [0x1234]))
    assert bank.sram == {0x12345: 0xFFFF, 0x12346: 7, last: 0x1234}
    assert run(drv.read_sram_words(0x12345, 2)) == [0xFFFF, 7]


# ---- the model: set_input masked, width/height taken where the block refuses -------------------------
def test_model_inputs_that_do_not_fit_are_refused(bank):
    # was 0xFFFF (the port's 16 bits)
    refused(lambda: bank.set_input("features_right", 0x1FFFF),
            "FEATURES.features_right: 131071 does not fit (0..65535, 16 bits)")
    refused(lambda: bank.set_input("busy", 2), "STATUS.busy: 2 does not fit (0..1, 1 bit)")
    refused(lambda: bank.set_input("frames", 1.0), "FRAMES.frames: 1.0 is not an integer (0..4294967295, 32 bits)")
    bank.set_input("frames", 0xFFFFFFFF)
    bank.set_input("busy", True)
    assert bank.read(REGMAP["FRAMES"].offset)[0] == 0xFFFFFFFF and bank.inputs["busy"] == 1


def _elaborate_bank(**kw):
    from eyestereo.hdl.flow.catalog import BLOCKS
    from eyestereo.hdl.system.register_bank import register_bank

    return register_bank(*BLOCKS["register_bank"].ports()[0].values(), **kw)


@pytest.mark.parametrize("kw", [dict(width=1), dict(height=0), dict(width=-5), dict(height=FRAME_MAX + 1),
                                dict(width=8.0), dict(height=np.float64(64)), dict(width=True), dict(width="64"),
                                dict(height=None)], ids=str)
def test_the_model_refuses_the_frame_sizes_the_block_refuses(kw):
    with pytest.raises(ValueError) as block:
        _elaborate_bank(**kw)
    with pytest.raises(ValueError) as model:  # was accepted (int(width)): a model of a bank that cannot be built
        RegisterBank(**kw)
    name, value = next(iter(kw.items()))
    msg = str(model.value)
    assert str(block.value) == f"register_bank: {msg}" and "\n" not in msg
    assert msg.startswith(f"parameter {name}") and f"{FRAME_MIN}..{FRAME_MAX}" in msg


def test_the_frame_size_messages():
    # refused() asserts the exception and its exact one-line message; the messages name what was refused
    errors = [refused(lambda: RegisterBank(width=1), "parameter width=1 is too small: the bank takes 2..4096"),
              refused(lambda: RegisterBank(height=4097), "parameter height=4097 is too large: the bank takes 2..4096"),
              refused(lambda: RegisterBank(width=8.0),
                      "parameter width must be an integer, got float 8.0 (the bank takes 2..4096)")]
    assert [str(e).split()[1].split("=")[0] for e in errors] == ["width", "height", "width"]


@pytest.mark.parametrize("kw", [dict(width=FRAME_MIN, height=FRAME_MIN), dict(width=FRAME_MAX, height=FRAME_MAX),
                                dict(width=np.int64(64), height=np.uint16(48))], ids=str)
def test_the_model_takes_the_frame_sizes_the_block_takes(kw):
    _elaborate_bank(**kw)
    b = RegisterBank(**kw)
    assert b.read(REGMAP["GEOMETRY"].offset)[0] == int(kw["height"]) << 16 | int(kw["width"])
    assert type(b.params["width"]) is int


def test_the_bounds_are_the_blocks_own():
    from eyestereo.hdl.common.checks import MAX_SIZE

    assert (FRAME_MIN, FRAME_MAX) == (2, MAX_SIZE)
    assert FRAME_MAX < 1 << REGMAP.field("GEOMETRY.width")[1].width  # GEOMETRY can report it


# ---- the bus itself still carries 32 bits (the hardware's behaviour, not a user value) -----------------
def test_the_model_bus_keeps_the_hardware_masking(bank):
    assert bank.write(REGMAP["THR_LEFT"].address(1), 0xABCDEF12) == 0  # OKAY: the bank keeps its 20 bits
    assert bank.arrays["THR_LEFT"][1] == 0xDEF12
