"""PackedWord: one declaration of a stream word's fields, and its MyHDL slices and packing."""

import subprocess

import numpy as np
import pytest

from eyestereo.tools.fixed import sfix, ufix
from eyestereo.tools.models import cornerness, harris_window, sobel
from eyestereo.tools.packed import PackedWord

W = PackedWord("test", [("a", sfix(9, -3)), ("b", 5), ("f", 1), ("c", ufix(12, 4))])


def test_layout_from_the_declaration():
    assert W.width == 9 + 5 + 1 + 12
    assert W.bits("a") == (9, 0) and W.bits("b") == (14, 9) and W.bits("f") == (15, 14) and W.bits("c") == (27, 15)
    assert W.describe().splitlines()[0] == "bits 26..15  c  ufix[12,4]"


def test_pack_matches_hand_written_bit_arithmetic():
    rng = np.random.default_rng(0)
    a = rng.integers(-256, 256, 1000)
    b = rng.integers(0, 32, 1000)
    f = rng.integers(0, 2, 1000)
    c = rng.integers(0, 4096, 1000)
    words = W.pack(a=a, b=b, f=f, c=c)
    expect = (a & 511) | (b << 9) | (f << 14) | (c << 15)
    np.testing.assert_array_equal(words, expect)
    back = W.unpack(words)
    for name, v in dict(a=a, b=b, f=f, c=c).items():
        np.testing.assert_array_equal(back[name], v)


@pytest.mark.parametrize("codes, msg", [
    (dict(a=256, b=0, f=0, c=0), "outside sfix[9,-3]"),
    (dict(a=0, b=32, f=0, c=0), "outside ufix[5,0]"),
    (dict(a=0, b=0, f=0), "missing fields ['c']"),
    (dict(a=0, b=0, f=0, c=0, d=1), "unknown fields ['d']"),
    (dict(a=0.5, b=0, f=0, c=0), "integer codes"),
])
def test_pack_rejects_bad_codes(codes, msg):
    with pytest.raises(ValueError, match=msg.replace("[", r"\[").replace("]", r"\]")):
        W.pack(**codes)


def test_unpack_rejects_words_too_wide_or_negative():
    with pytest.raises(ValueError, match="27-bit unsigned"):
        W.unpack([1 << 27])
    with pytest.raises(ValueError, match="27-bit unsigned"):
        W.unpack([-1])


@pytest.mark.parametrize("fields, msg", [
    ([], "at least one field"), ([("a", 3), ("a", 4)], "declared twice"), ([("1x", 3)], "not an identifier"),
    ([("a", "sfix[3,0]")], "needs a Fmt"),
])
def test_declaration_errors(fields, msg):
    with pytest.raises(ValueError, match=msg):
        PackedWord("bad", fields)


def test_library_words():
    # The words the Harris chain passes on, as the thesis lays them out (6.2): Sobel 2 x 9 bits, the
    # window products 3 x 12 in one 36-bit block RAM word, the window sums 3 x 19, the cornerness 20.
    assert (sobel.WORD.width, harris_window.PRODUCTS.width, harris_window.WORD.width, cornerness.WORD.width) == \
        (18, 36, 57, 20)
    assert sobel.WORD.bits("iy") == (18, 9) and harris_window.WORD.bits("sxy") == (57, 38)


def test_hdl_pack_and_unpack_convert_and_agree(tmp_path):
    """unpack_word then pack_word is the identity, in GHDL (VHDL-93c and 2008) and in Icarus (Verilog)."""
    pytest.importorskip("myhdl")
    from myhdl import Signal, block, intbv

    from eyestereo.hdl.common.packed import pack_word, unpack_word

    @block
    def roundtrip(word, dout):
        a = Signal(intbv(0, min=-256, max=256))
        b, c = Signal(intbv(0)[5:]), Signal(intbv(0)[12:])
        f = Signal(bool(0))
        return unpack_word(word, W, a=a, b=b, f=f, c=c), pack_word(dout, W, a=a, b=b, f=f, c=c)

    for hdl in ("VHDL", "Verilog"):
        roundtrip(Signal(intbv(0)[W.width:]), Signal(intbv(0)[W.width:])).convert(
            hdl=hdl, path=str(tmp_path), name="roundtrip", initial_values=False)  # MyHDL keeps the last setting
    for std in ("93c", "08"):
        r = subprocess.run(["ghdl", "-a", f"--std={std}", f"--workdir={tmp_path}",
                            str(tmp_path / "pck_myhdl_011.vhd"), str(tmp_path / "roundtrip.vhd")],
                           capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
    (tmp_path / "tb.v").write_text(
        "module tb; reg [26:0] w; wire [26:0] d; integer i, bad; roundtrip t(.word(w), .dout(d));\n"
        "initial begin bad = 0; for (i = 0; i < 500; i = i + 1) begin w = $random; #1;\n"
        "if (d !== w) bad = bad + 1; end $display(\"BAD=%0d\", bad); end endmodule\n")
    r = subprocess.run(["iverilog", "-o", str(tmp_path / "sim"), str(tmp_path / "roundtrip.v"),
                        str(tmp_path / "tb.v")], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    out = subprocess.run(["vvp", str(tmp_path / "sim")], capture_output=True, text=True).stdout
    assert "BAD=0" in out, out


def test_hdl_pack_checks_field_signals():
    pytest.importorskip("myhdl")
    from myhdl import Signal, intbv

    from eyestereo.hdl.common.packed import pack_word

    good = dict(a=Signal(intbv(0, min=-256, max=256)), b=Signal(intbv(0)[5:]), f=Signal(bool(0)),
                c=Signal(intbv(0)[12:]))
    with pytest.raises(ValueError, match="field 'b' of test is ufix\\[5,0\\] \\(5 bits\\), its signal has 6"):
        pack_word(Signal(intbv(0)[27:]), W, **dict(good, b=Signal(intbv(0)[6:])))
    with pytest.raises(ValueError, match="field 'a' of test is sfix\\[9,-3\\], its signal is unsigned"):
        pack_word(Signal(intbv(0)[27:]), W, **dict(good, a=Signal(intbv(0)[9:])))
    with pytest.raises(ValueError, match="misses fields \\['c'\\]"):
        pack_word(Signal(intbv(0)[27:]), W, **{k: v for k, v in good.items() if k != "c"})
