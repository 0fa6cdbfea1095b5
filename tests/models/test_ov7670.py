"""The OV7670 register table, its QVGA timing and the user-table loader (one-line errors)."""

import pytest

from eyestereo.tools.camera import ORDERS
from eyestereo.tools.ov7670 import (DELAY, ENTRIES, QVGA, TABLE, XCLK_HZ, check_table, load_table, parse_table)


def _last(reg: int) -> int:
    """The value a register has after the table (its last write)."""
    return [v for r, v in TABLE if r == reg][-1]


def test_the_table_starts_with_a_reset_and_its_wait():
    assert TABLE[0] == (0x12, 0x80) and TABLE[1][0] == DELAY and TABLE[1][1] >= 1
    assert all(len(c) > 10 for _, _, c in ENTRIES)  # every entry says what it does
    assert check_table(TABLE) == TABLE


def test_the_table_sets_what_the_front_end_expects():
    # COM7: QVGA (bit 4), YUV (bits 2 and 0 clear), [DS] COM7 description
    assert _last(0x12) == 0x10
    # byte order [DS] TSLB[3] / COM13[0]: 0/0 = Y U Y V, the front end's "YUYV"
    assert not _last(0x3A) & 0x08 and not _last(0x3D) & 0x01 and "YUYV" in ORDERS
    # COM10 = 0: VSYNC and HREF active high (camera_stream's defaults), PCLK free-running (bit 5 clear)
    assert _last(0x15) == 0


def test_the_qvga_frame_rate_from_a_25_mhz_xclk():
    # worked by hand: PCLK = 25 MHz / 2 = 12.5 MHz; (510 + 21) rows x 784 PCLK = 416,304 PCLK a frame
    assert QVGA.frame_pclk == 416_304
    assert QVGA.fps(XCLK_HZ / 2) == pytest.approx(12.5e6 / 416_304, rel=1e-12)
    assert 30.0 <= QVGA.fps() < 30.1
    assert QVGA.href_pclk == 2 * 320 and QVGA.line_pclk == 1568 and QVGA.vsync_pclk == 3 * 784
    assert _last(0x92) == QVGA.dummy_rows


def test_the_camera_timing_is_the_qvga_frame_to_a_line():
    t = QVGA.camera_timing()
    assert (t.width, t.height, t.line_pclk) == (320, 240, 1568)
    assert abs(t.frame_pclk - QVGA.frame_pclk) < t.line_pclk
    assert t.vsync_active == 1 and t.href_active == 1 and t.order == "YUYV"


def test_a_text_table_loads(tmp_path):
    f = tmp_path / "cam.txt"
    f.write_text("# my table\n12 80\ndelay 2\n\n0x11 0x01  # clock\n3a,04\n")
    assert load_table(f) == ((0x12, 0x80), (DELAY, 2), (0x11, 0x01), (0x3A, 0x04))


@pytest.mark.parametrize("text,message", [
    ("12 80 00\n", "cam.txt:1: expected 'REG VALUE' (hex) or 'delay MS', got '12 80 00'"),
    ("12 80\n1g 00\n", "cam.txt:2: '1g' is not a hex byte (00..ff, optionally 0x)"),
    ("12 100\n", "cam.txt:1: '100' is not a hex byte (00..ff, optionally 0x)"),
    ("delay 0\n", "cam.txt:1: a delay is 1..255 ms (decimal), got '0'"),
    ("delay x\n", "cam.txt:1: a delay is 1..255 ms (decimal), got 'x'"),
    ("ff 02\n", "cam.txt:1: register 0xff is the delay entry; write 'delay MS' instead"),
    ("# nothing\n\n", "cam.txt: no entries (one 'REG VALUE' in hex a line)"),
])
def test_bad_lines_give_one_line_errors(tmp_path, text, message):
    f = tmp_path / "cam.txt"
    f.write_text(text)
    with pytest.raises(ValueError) as e:
        load_table(f)
    msg = str(e.value)
    assert "\n" not in msg and msg == f"{f}{message[len('cam.txt'):]}"


def test_unreadable_files(tmp_path):
    with pytest.raises(ValueError, match=r"missing.txt: cannot read the register table"):
        load_table(tmp_path / "missing.txt")
    b = tmp_path / "bin.txt"
    b.write_bytes(b"\xff\xfe\x00")
    with pytest.raises(ValueError, match=r"bin.txt: not a text file$"):
        load_table(b)


@pytest.mark.parametrize("table,message", [
    ([(0x12,)], "table entry 0 must be a (reg, value) pair, got (18,)"),
    ([(0x12, 1.0)], "table entry 0: value must be an integer, got 1.0"),
    ([(0x100, 0)], "table entry 0: register 0x100 is not a byte"),
    ("12 80", "table must be a sequence of (reg, value) pairs, got str"),
])
def test_check_table(table, message):
    with pytest.raises(ValueError) as e:
        check_table(table)
    assert str(e.value) == message


def test_parse_table_names_its_source():
    with pytest.raises(ValueError, match=r"^user:1: "):
        parse_table("zz 00", "user")
