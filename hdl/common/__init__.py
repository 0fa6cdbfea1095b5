"""Helpers every block uses: registers and delays, shift-and-add arithmetic, the window machinery of the
filters, fixed-point signals and packed stream words. Everything is re-exported here::

    from eyestereo.hdl.common import column_taps, delay, en_reg, shift_add, window_control, fx_signal
"""

from eyestereo.hdl.common.arith import csd, range_signal, shift_add, signal_range, term_range
from eyestereo.hdl.common.fixed import fx_intbv, fx_signal
from eyestereo.hdl.common.registers import assign, delay, delay_rst, dreg, dreg_rst, en_reg, like_signal
from eyestereo.hdl.common.window import column_taps, window_control

__all__ = ["assign", "column_taps", "csd", "delay", "delay_rst", "dreg", "dreg_rst", "en_reg", "fx_intbv",
           "fx_signal", "like_signal", "range_signal", "shift_add", "signal_range", "term_range",
           "window_control"]
