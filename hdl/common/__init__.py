"""Helpers every block uses: registers and delays, shift-and-add arithmetic, fixed-point signals and packed
stream words. Everything is re-exported here::

    from eyestereo.hdl.common import delay, en_reg, shift_add, fx_signal

(The filters' window machinery lives in :mod:`eyestereo.hdl.streaming.window`.)
"""

from eyestereo.hdl.common.arith import csd, range_signal, shift_add, signal_range, term_range
from eyestereo.hdl.common.fixed import fx_intbv, fx_signal
from eyestereo.hdl.common.registers import assign, delay, delay_rst, dreg, dreg_rst, en_reg, like_signal

__all__ = ["assign", "csd", "delay", "delay_rst", "dreg", "dreg_rst", "en_reg", "fx_intbv", "fx_signal",
           "like_signal", "range_signal", "shift_add", "signal_range", "term_range"]
