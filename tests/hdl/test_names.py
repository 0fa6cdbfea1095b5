"""MyHDL's instance names do not grow from one conversion to the next in one process (issue 26: in a test worker
that had converted the front end many times, nested blocks' names passed GHDL's 1023-character limit)."""

from eyestereo.hdl.flow.convert import convert


def longest_identifier(text: str) -> int:
    return max(len(w) for w in text.replace("(", " ").replace(")", " ").split())


def test_the_names_of_a_conversion_do_not_depend_on_the_ones_before(tmp_path):
    texts = ["\n".join(x for x in convert("sobel", tmp_path / str(i), stereo=True)[-1].read_text().splitlines()
                       if not x.startswith("--"))  # the header comments name the file and the time
             for i in range(3)]
    assert texts[0] == texts[1] == texts[2]
    assert longest_identifier(texts[0]) < 200


def test_an_elaboration_that_raised_does_not_shift_the_next_conversions_names(tmp_path):
    """MyHDL counts each block's calls (``en_reg0``, ``en_reg1``, ...) and resets the counts only after an elaboration
    that completes; one refused half-way (a block raising below others already built) left them counting."""
    from myhdl import Signal, block, intbv

    from eyestereo.hdl.common.registers import en_reg

    def strip(text):
        return "\n".join(x for x in text.splitlines() if not x.startswith("--"))

    before = strip(convert("sobel", tmp_path / "a", stereo=True)[-1].read_text())

    @block
    def refused(clk):
        q = Signal(intbv(0)[4:])
        built = [en_reg(clk, Signal(bool(0)), Signal(intbv(0)[4:]), q) for _ in range(5)]  # noqa: F841
        raise ValueError("refused after building five en_regs")

    try:
        refused(Signal(bool(0)))
    except ValueError:
        pass
    else:
        raise AssertionError("the block above must raise")
    after = strip(convert("sobel", tmp_path / "b", stereo=True)[-1].read_text())
    assert "en_reg" in before  # the names this test is about are in the file
    assert after == before
