"""hdl/common/checks.py: each bad port or parameter raises a ValueError naming it."""

import numpy as np
import pytest
from myhdl import ResetSignal, Signal, intbv

from eyestereo.hdl.common.checks import (check_bool, check_choice, check_clock, check_int, check_reset,
                                         check_signal, check_stream)
from eyestereo.hdl.stream import ImageStream


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
