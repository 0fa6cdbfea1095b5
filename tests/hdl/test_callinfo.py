"""The shallow stack look-up for MyHDL (eyestereo.hdl.common.callinfo) changes nothing MyHDL writes."""

import inspect
import os
import subprocess
import sys
import textwrap

import eyestereo.hdl  # noqa: F401  (installs the look-up)
from eyestereo.hdl.common import callinfo

# Blocks whose elaboration covers the ways MyHDL finds callers: plain blocks, blocks made in list
# comprehensions (line delays of the window machinery), @instance and @always_seq generators, sub-blocks
# in several levels (harris_mono, rectifier), interfaces and memories.
BLOCKS = ("sobel", "harris_mono", "rectifier", "camera_interface")

_SCRIPT = textwrap.dedent("""
    import sys
    from pathlib import Path
    from eyestereo.hdl.common import callinfo
    from eyestereo.hdl.flow.convert import convert
    on, out = sys.argv[1] == "1", Path(sys.argv[2])
    (callinfo.install if on else callinfo.uninstall)()
    assert callinfo.installed() == on
    for hdl in ("VHDL", "Verilog"):
        for name in sys.argv[3:]:
            convert(name, out / hdl / name, hdl=hdl)
""")


def _strip(text: str) -> list[str]:
    # The header names the output path and the time of conversion.
    return [l for l in text.splitlines() if not l.startswith(("-- File", "-- Date", "// File", "// Date"))]


def test_installed_on_import():
    assert callinfo.installed()
    import myhdl._block

    assert myhdl._block.inspect is not inspect and myhdl._block.inspect.signature is inspect.signature


def test_records_are_the_nearest_frames_of_inspect_stack():
    def inner():
        return callinfo.stack(), inspect.stack()

    def outer(n):
        return outer(n - 1) if n else inner()

    short, full = outer(30)
    assert len(short) == callinfo.DEPTH < len(full)
    for s, f in zip(short, full):
        assert s.frame is f.frame and s.function == f.function and s.lineno == f.lineno
        assert s.filename == f.filename
    frame = sys._getframe()
    assert [r.frame for r in callinfo.getouterframes(frame)] == [r.frame for r in inspect.getouterframes(frame)][
        :callinfo.DEPTH]


def test_conversion_is_byte_identical_with_and_without(tmp_path):
    # Separate processes with one hash seed: MyHDL's sensitivity lists follow set order, and its instance
    # names a process-wide counter, so two conversions in one process differ anyway.
    env = dict(os.environ, PYTHONHASHSEED="0")
    procs = [subprocess.Popen([sys.executable, "-c", _SCRIPT, on, str(tmp_path / on), *BLOCKS], env=env,
                              stderr=subprocess.PIPE, text=True) for on in ("1", "0")]
    for p in procs:
        _, err = p.communicate(timeout=600)
        assert p.returncode == 0, err
    files = sorted(p.relative_to(tmp_path / "1") for p in (tmp_path / "1").rglob("*") if p.is_file())
    assert len([f for f in files if f.suffix in (".vhd", ".v")]) >= 2 * len(BLOCKS)
    assert files == sorted(p.relative_to(tmp_path / "0") for p in (tmp_path / "0").rglob("*") if p.is_file())
    for f in files:
        a, b = (tmp_path / "1" / f).read_text(), (tmp_path / "0" / f).read_text()
        assert _strip(a) == _strip(b), f"{f} differs with the shallow look-up"
