"""hdl/common/checks.py: each bad port or parameter raises a ValueError naming it."""

import numpy as np
import pytest
from myhdl import ResetSignal, Signal, intbv

from eyestereo.hdl.common.checks import (check_bool, check_choice, check_clock, check_int, check_reset,
                                         check_signal, check_stream)
from eyestereo.hdl.interfaces.stream import ImageStream


@pytest.mark.parametrize("clk", [None, 1, Signal(intbv(0)[2:]), "clk"])
def test_clock(clk):
    with pytest.raises(ValueError, match="port clk must be a 1-bit Signal"):
        check_clock(clk)


@pytest.mark.parametrize("rst, msg", [
    (Signal(bool(0)), "must be a ResetSignal"), (None, "got None"), (0, "got int 0"),
    (ResetSignal(0, active=1, isasync=True), "asynchronous"), (ResetSignal(1, active=0, isasync=False), "active-low"),
])
def test_reset(rst, msg):
    with pytest.raises(ValueError, match=msg):
        check_reset(rst)
    check_reset(ResetSignal(0, active=1, isasync=False))


def test_stream():
    with pytest.raises(ValueError, match="port sink must be an ImageStream, got None"):
        check_stream("sink", None)
    with pytest.raises(ValueError, match="port sink must carry 8-bit data, got an ImageStream of 9 bits"):
        check_stream("sink", ImageStream(9), width=8)
    with pytest.raises(ValueError, match="port source is a stereo stream .* mono streams only"):
        check_stream("source", ImageStream(8, stereo=True))
    with pytest.raises(ValueError, match="port sink must be a stereo stream"):
        check_stream("sink", ImageStream(8), stereo=True)
    check_stream("sink", ImageStream(8, stereo=True), width=8, stereo=True)


def test_signal():
    with pytest.raises(ValueError, match="port k must be a MyHDL Signal, got int 3"):
        check_signal("k", 3)
    with pytest.raises(ValueError, match="port k must be 8 bits wide, got 7"):
        check_signal("k", Signal(intbv(0)[7:]), width=8)
    with pytest.raises(ValueError, match="port t must be signed"):
        check_signal("t", Signal(intbv(0)[8:]), signed=True)
    check_signal("we", Signal(bool(0)), width=1)


def test_int_choice_bool():
    assert check_int("width", np.int64(352), 3, 4096) == 352 and type(check_int("w", np.int32(5))) is int
    for bad, msg in ((352.0, "must be an integer, got float"), (True, "must be an integer"),
                     (2, "too small: at least 3"), (5000, "too large: at most 4096")):
        with pytest.raises(ValueError, match=f"parameter width.*{msg}"):
            check_int("width", bad, 3, 4096)
    assert check_choice("nms", np.int64(3), (1, 3, 5)) == 3
    with pytest.raises(ValueError, match=r"parameter nms must be one of \[1, 3, 5\], got float 3.0"):
        check_choice("nms", 3.0, (1, 3, 5))
    with pytest.raises(ValueError, match="parameter packed must be True or False"):
        check_bool("packed", 1)


def test_messages_name_the_block_inside_a_block():
    from myhdl import always_comb, block

    @block
    def my_block(clk, rst):
        check_clock(clk)
        check_reset(rst)

        @always_comb
        def comb():
            pass

        return comb

    with pytest.raises(ValueError, match=r"^my_block: port rst is an asynchronous reset"):
        my_block(Signal(bool(0)), ResetSignal(0, active=1, isasync=True))
    with pytest.raises(ValueError, match=r"^port clk must be"):  # outside any block: no name
        check_clock(None)


def test_checked_and_block_error_name_the_block():
    from myhdl import block

    from eyestereo.hdl.common.checks import block_error, checked

    def model_check(v):
        if v < 0:
            raise ValueError("parameter v must be >= 0")
        return v * 2

    @block
    def outer(v):
        assert checked(model_check, v) == 2 * v
        raise block_error("something else")

    with pytest.raises(ValueError, match=r"^outer: parameter v must be >= 0$"):
        outer(-1)
    with pytest.raises(ValueError, match=r"^outer: something else$"):
        outer(1)
    assert checked(model_check, 2) == 4


def test_signal_kinds():
    with pytest.raises(ValueError, match=r"port k has no bit width"):
        check_signal("k", Signal(intbv(0)))
    with pytest.raises(ValueError, match=r"port k must be a Signal\(bool\) or Signal\(intbv"):
        check_signal("k", Signal(3))
    with pytest.raises(ValueError, match=r"port k must be a MyHDL Signal, got an ImageStream"):
        check_signal("k", ImageStream(8))
    with pytest.raises(ValueError, match=r"port k must be unsigned, got an 8-bit signed Signal\(intbv\)"):
        check_signal("k", Signal(intbv(0, min=-128, max=128)), signed=False)
    check_signal("we", Signal(intbv(0)[1:]), width=1)  # a 1-bit intbv is as good as a bool


def test_clock_reset_swapped():
    with pytest.raises(ValueError, match=r"port clk must be the clock.*swapped"):
        check_clock(ResetSignal(0, active=1, isasync=False))


def test_stream_fields_tampered():
    s = ImageStream(8)
    s.data = Signal(intbv(0)[10:])
    with pytest.raises(ValueError, match=r"port sink: its data field is a 10-bit unsigned Signal\(intbv\), "
                                         r"the ImageStream says 8 bits"):
        check_stream("sink", s)
    s = ImageStream(8)
    s.valid = None
    with pytest.raises(ValueError, match=r"port sink: field valid of the ImageStream is None"):
        check_stream("sink", s)
    check_stream("sink", ImageStream(8, stereo=True), stereo=None)
    check_stream("sink", ImageStream(8), stereo=None)


def test_distinct():
    from eyestereo.hdl.common.checks import check_distinct

    a, b = ImageStream(8), ImageStream(8)
    k = Signal(bool(0))
    check_distinct(dict(source=b), dict(sink=a, k=k, we=k))  # inputs may share a signal
    with pytest.raises(ValueError, match=r"ports source and sink share a signal; the output port source"):
        check_distinct(dict(source=a), dict(sink=a))
    with pytest.raises(ValueError, match=r"ports error and k share a signal; the output port error"):
        check_distinct(dict(error=k), dict(k=k))


def test_frame_and_bool():
    from eyestereo.hdl.common.checks import check_frame

    assert check_frame(np.int16(5), 7, min_size=5) == (5, 7)
    with pytest.raises(ValueError, match=r"parameter height=4 is too small: at least 5"):
        check_frame(5, 4, min_size=5)
    assert check_bool("repair", np.bool_(True)) is True
    with pytest.raises(ValueError, match=r"parameter nms must be one of \[1, 3, 5\], got bool True"):
        check_choice("nms", True, (1, 3, 5))
