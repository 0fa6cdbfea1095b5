"""tools/io.py: all-or-nothing outputs, the modes they get, images read with integrity checks."""

from __future__ import annotations

import os
import zlib
from pathlib import Path

import cv2
import numpy as np
import pytest

from eyestereo.tools import io as IO


def names(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


@pytest.fixture
def umask022():
    old = os.umask(0o022)
    yield 0o022
    os.umask(old)


# --------------------------------------------------------------------------------------------------
# Single files


def test_atomic_output_leaves_nothing_on_failure(tmp_path):
    target = tmp_path / "out.yml"
    target.write_text("old")
    with pytest.raises(RuntimeError):
        with IO.atomic_output(target) as tmp:
            assert tmp.parent == tmp_path and tmp.name.startswith(".out.yml") and tmp.suffix == ".yml"
            tmp.write_text("half")
            raise RuntimeError("boom")
    assert target.read_text() == "old" and names(tmp_path) == ["out.yml"]
    with pytest.raises(ValueError, match="produced no data"):
        with IO.atomic_output(target):
            pass
    assert target.read_text() == "old" and names(tmp_path) == ["out.yml"]
    IO.atomic_write_bytes(target, b"new")
    assert target.read_bytes() == b"new" and names(tmp_path) == ["out.yml"]


def test_atomic_output_refuses_bad_targets(tmp_path):
    with pytest.raises(ValueError, match="folder .* does not exist"):
        IO.atomic_write_text(tmp_path / "no" / "x.txt", "x")
    with pytest.raises(ValueError, match="it is a folder"):
        IO.atomic_write_text(tmp_path, "x")
    assert names(tmp_path) == []


def test_replace_failure_names_the_target_not_the_temporary(tmp_path, monkeypatch):
    target = tmp_path / "out.txt"
    target.write_text("old")

    def boom(src, dst):
        raise OSError(28, "No space left on device", str(src))

    monkeypatch.setattr(os, "replace", boom)
    with pytest.raises(OSError) as info:
        IO.atomic_write_text(target, "new")
    assert str(target) in info.value.strerror and ".eyestereo-" not in info.value.strerror
    assert target.read_text() == "old" and names(tmp_path) == ["out.txt"]


def test_new_files_get_the_umask_mode_old_files_keep_theirs(tmp_path):
    old = os.umask(0o027)
    try:
        IO.atomic_write_text(tmp_path / "new.txt", "x")
        assert (tmp_path / "new.txt").stat().st_mode & 0o777 == 0o640
        (tmp_path / "kept.txt").write_text("a")
        os.chmod(tmp_path / "kept.txt", 0o604)
        IO.atomic_write_text(tmp_path / "kept.txt", "b")
        assert (tmp_path / "kept.txt").stat().st_mode & 0o777 == 0o604
        with IO.Outputs() as out:
            d = out.folder(tmp_path / "dir")
            (d / "f.bin").write_bytes(b"1")
        assert (tmp_path / "dir").stat().st_mode & 0o777 == 0o750
        assert (tmp_path / "dir" / "f.bin").stat().st_mode & 0o777 == 0o640
    finally:
        os.umask(old)


# --------------------------------------------------------------------------------------------------
# Output sets


@pytest.mark.usefixtures("umask022")
def test_outputs_commit_everything_or_nothing(tmp_path):
    (tmp_path / "a.txt").write_text("old a")
    with pytest.raises(KeyboardInterrupt):
        with IO.Outputs() as out:
            out.file(tmp_path / "a.txt").write_text("new a")
            d = out.folder(tmp_path / "pics", {"x.png"})
            (d / "x.png").write_bytes(b"png")
            out.file(tmp_path / "b.txt").write_text("new b")
            raise KeyboardInterrupt  # what a signal turns into
    assert names(tmp_path) == ["a.txt"] and (tmp_path / "a.txt").read_text() == "old a"
    with IO.Outputs() as out:
        out.file(tmp_path / "a.txt").write_text("new a")
        d = out.folder(tmp_path / "pics", {"x.png"})
        (d / "x.png").write_bytes(b"png")
    assert names(tmp_path) == ["a.txt", "pics"] and (tmp_path / "a.txt").read_text() == "new a"
    assert names(tmp_path / "pics") == ["x.png"]


def test_a_failing_rename_puts_the_earlier_targets_back(tmp_path, monkeypatch):
    (tmp_path / "a.json").write_text("old a")
    (tmp_path / "pics").mkdir()
    (tmp_path / "pics" / "x.png").write_text("old x")
    real_rename = os.rename

    def rename(src, dst):
        if Path(dst).name == "pics" and ".eyestereo-" in Path(src).name and "old-" not in Path(src).name:
            raise OSError(5, "Input/output error")
        return real_rename(src, dst)

    monkeypatch.setattr(os, "rename", rename)
    with pytest.raises(OSError, match="cannot write .*pics: Input/output error"):
        with IO.Outputs() as out:
            out.file(tmp_path / "a.json").write_text("new a")
            out.file(tmp_path / "b.json").write_text("new b")
            (out.folder(tmp_path / "pics", {"x.png"}) / "x.png").write_text("new x")
    assert names(tmp_path) == ["a.json", "pics"] and (tmp_path / "a.json").read_text() == "old a"
    assert (tmp_path / "pics" / "x.png").read_text() == "old x"


def test_an_existing_folder_is_replaced_only_when_it_is_ours(tmp_path):
    run = tmp_path / "run"
    run.mkdir()
    for n in ("left01.png", "left02.png", "left03.png"):
        (run / n).write_bytes(b"old")
    pattern = r"left\d+\.png"
    with IO.Outputs() as out:
        d = out.folder(run, pattern)
        (d / "left01.png").write_bytes(b"new")
    assert names(run) == ["left01.png"]  # replaced as a whole: no stale left02/left03
    assert names(tmp_path) == ["run"]
    (run / "notes.txt").write_text("mine")
    with pytest.raises(ValueError, match="holds notes.txt, which this command does not write"):
        IO.Outputs().folder(run, pattern)
    with pytest.raises(ValueError, match="exists and is not a folder"):
        IO.Outputs().folder(run / "notes.txt", pattern)
    with pytest.raises(ValueError, match="does not exist"):
        IO.Outputs().folder(tmp_path / "a" / "b", pattern)
    with pytest.raises(ValueError, match="must be named"):
        IO.Outputs().folder(Path("."), pattern)
    assert names(tmp_path) == ["run"] and names(run) == ["left01.png", "notes.txt"]


def test_a_folder_changed_during_the_run_is_checked_again(tmp_path):
    run = tmp_path / "run"
    with pytest.raises(ValueError, match="holds intruder"):
        with IO.Outputs() as out:
            d = out.folder(run, {"a"})
            (d / "a").write_bytes(b"1")
            run.mkdir()
            (run / "intruder").write_text("x")
    assert names(run) == ["intruder"] and names(tmp_path) == ["run"]


def test_the_same_target_twice_is_refused(tmp_path):
    out = IO.Outputs()
    out.file(tmp_path / "x.json")
    with pytest.raises(ValueError, match="given as two different outputs"):
        out.file(tmp_path / "x.json")
    out.discard()
    assert names(tmp_path) == []


def _swallowed_signal(signum):
    """A signal whose handler's exception Python drops (as it does in a weakref or import-lock
    callback): the handler ran, but the code goes on."""
    try:
        IO.interrupt(signum)
    except IO.Interrupted:
        pass


def test_a_swallowed_signal_still_stops_every_commit(tmp_path):
    IO.clear_interrupt()
    try:
        _swallowed_signal(2)
        with pytest.raises(IO.Interrupted) as e:
            with IO.Outputs() as out:
                out.file(tmp_path / "a.txt").write_text("a")
        assert e.value.signum == 2 and e.value.status == 130 and not e.value.written
        with pytest.raises(IO.Interrupted):
            IO.atomic_write_text(tmp_path / "b.txt", "b")
        assert names(tmp_path) == []
    finally:
        IO.clear_interrupt()


def test_a_signal_after_a_commit_says_an_output_was_written(tmp_path):
    IO.clear_interrupt()
    try:
        IO.atomic_write_text(tmp_path / "a.txt", "a")
        with pytest.raises(IO.Interrupted) as e:
            IO.interrupt(15)
        assert e.value.written and e.value.status == 143
    finally:
        IO.clear_interrupt()


def test_user_text_names_the_target(tmp_path):
    out = IO.Outputs()
    tmp = out.file(tmp_path / "calib.yml")
    assert IO.user_text(f"cannot open {tmp} for writing") == f"cannot open {tmp_path / 'calib.yml'} for writing"
    out.discard()  # still known: the error that discarded it is reported afterwards
    assert IO.user_text(f"{tmp}: No space left") == f"{tmp_path / 'calib.yml'}: No space left"


# --------------------------------------------------------------------------------------------------
# Images


@pytest.fixture
def images(tmp_path):
    rng = np.random.default_rng(3)
    img = rng.integers(0, 256, (60, 80), dtype=np.uint8)
    cv2.imwrite(str(tmp_path / "ok.png"), img)
    cv2.imwrite(str(tmp_path / "ok.jpg"), img)
    data = (tmp_path / "ok.png").read_bytes()
    (tmp_path / "cut.png").write_bytes(data[: len(data) // 2])
    bad_crc = bytearray(data)
    bad_crc[40] ^= 0xFF  # inside the first IDAT (or IHDR): its CRC no longer matches
    (tmp_path / "crc.png").write_bytes(bytes(bad_crc))
    jpg = (tmp_path / "ok.jpg").read_bytes()
    (tmp_path / "cut.jpg").write_bytes(jpg[: len(jpg) * 2 // 3])
    (tmp_path / "empty.png").write_bytes(b"")
    (tmp_path / "text.png").write_text("hello")
    return tmp_path, img


def test_read_image_reads_good_files(images):
    d, img = images
    assert np.array_equal(IO.read_image(d / "ok.png"), img)
    assert IO.read_image(d / "ok.jpg").shape == (60, 80)


@pytest.mark.parametrize("name, message", [
    ("cut.png", "truncated PNG file"), ("crc.png", "corrupt PNG file (CRC error"), ("cut.jpg", "truncated JPEG"),
    ("empty.png", "is an empty file"), ("text.png", "not an image file OpenCV can decode"),
    ("none.png", "does not exist")])
def test_read_image_refuses_damaged_files_naming_them(images, capfd, name, message):
    d, _ = images
    with pytest.raises(ValueError) as info:
        IO.read_image(d / name, what="left image")
    text = str(info.value)
    assert message in text and name in text and "\n" not in text
    assert capfd.readouterr().err == ""  # the decoders said nothing on the terminal


def test_a_jpeg_with_corrupt_data_is_refused_by_what_the_decoder_says(images, capfd):
    d, _ = images
    jpg = bytearray((d / "ok.jpg").read_bytes())
    sos = jpg.find(b"\xff\xda")
    for i in range(sos + 40, len(jpg) - 40, 7):  # scramble the entropy-coded data, keep the markers
        if jpg[i] != 0xFF and jpg[i - 1] != 0xFF:
            jpg[i] = 0xFF
            jpg[i + 1] = 0xD3  # a restart marker where none belongs
            break
    (d / "bad.jpg").write_bytes(bytes(jpg))
    with pytest.raises(ValueError, match="bad.jpg is damaged"):
        IO.read_image(d / "bad.jpg")
    assert capfd.readouterr().err == ""


def test_check_png_accepts_what_opencv_writes_in_every_depth(tmp_path):
    for dtype, shape in ((np.uint8, (5, 7)), (np.uint16, (5, 7)), (np.uint8, (5, 7, 3)), (np.uint16, (4, 4, 4))):
        ok, buf = cv2.imencode(".png", np.ones(shape, dtype))
        IO.check_image_bytes(buf.tobytes(), "x.png")
    # and a deflate stream cut short inside a well-formed chunk is caught
    ok, buf = cv2.imencode(".png", np.arange(64 * 64, dtype=np.uint16).reshape(64, 64))
    data = buf.tobytes()
    i = data.find(b"IDAT") - 4
    n = int.from_bytes(data[i:i + 4], "big")
    body = data[i + 8:i + 8 + n][: n // 2]
    chunk = len(body).to_bytes(4, "big") + b"IDAT" + body + zlib.crc32(b"IDAT" + body).to_bytes(4, "big")
    with pytest.raises(ValueError, match="compressed pixel data ends early"):
        IO.check_image_bytes(data[:i] + chunk + data[i + 12 + n:], "y.png")


def test_to_grey8_depth_rule():
    g8 = np.array([[0, 255]], np.uint8)
    assert IO.to_grey8(g8) is g8
    full = np.array([[0, 65535, 256]], np.uint16)
    assert IO.to_grey8(full).tolist() == [[0, 255, 1]]                       # 16-bit: >> 8
    twelve = np.array([[0, 4095, 16]], np.uint16)
    assert IO.to_grey8(twelve).tolist() == [[0, 255, 1]]                     # 12 bits used: >> 4
    a, b = IO.to_grey8([np.array([[4095]], np.uint16), np.array([[255]], np.uint16)])
    assert a.tolist() == [[255]] and b.tolist() == [[15]]                    # a pair shares one shift
    colour = np.zeros((2, 2, 3), np.uint8)
    colour[..., 2] = 255                                                      # BGR red
    assert IO.to_grey8(colour).tolist() == [[76, 76], [76, 76]]
    with pytest.raises(ValueError, match="im.tif holds floating-point pixels"):
        IO.to_grey8(np.zeros((2, 2), np.float32), "im.tif")
    with pytest.raises(ValueError, match="int16"):
        IO.to_grey8(np.zeros((2, 2), np.int16), "im.png")
