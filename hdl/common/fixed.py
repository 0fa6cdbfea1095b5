"""MyHDL signals and bit vectors sized for ``eyestereo.tools.fixed`` formats.

The value of such a signal is the integer code of the format; its real
meaning (``code * 2**-fl``) is bookkeeping that stays on the Python side.
Signedness comes purely from the ``min``/``max`` bounds, which is what
MyHDL's converter uses to declare ``signed``/``unsigned`` ports, so no
``.signed()`` call is needed (it is not convertible in MyHDL 0.11.52).
"""

from __future__ import annotations

from myhdl import Signal, intbv

from eyestereo.tools.fixed import Fmt, intbv_bounds

__all__ = ["fx_intbv", "fx_signal"]


def _as_fmt(fmt: Fmt | str) -> Fmt:
    return Fmt.parse(fmt) if isinstance(fmt, str) else fmt


def fx_intbv(fmt: Fmt | str, value: int = 0) -> intbv:
    """An ``intbv`` holding integer code ``value`` with exactly ``fmt.wl`` bits."""
    fmt = _as_fmt(fmt)
    lo, hi = intbv_bounds(fmt)
    # intbv itself raises ValueError for a code outside [lo, hi)
    bv = intbv(int(value), min=lo, max=hi)
    if len(bv) != fmt.wl:  # guards against a change in MyHDL's width rule
        raise AssertionError(f"intbv for {fmt} has {len(bv)} bits, expected {fmt.wl}")
    return bv


def fx_signal(fmt: Fmt | str, value: int = 0) -> Signal:
    """A MyHDL ``Signal`` of ``fmt.wl`` bits (signed when ``fmt.signed``) with initial code ``value``."""
    sig = Signal(fx_intbv(fmt, value))
    if len(sig) != _as_fmt(fmt).wl:
        raise AssertionError(f"Signal for {fmt} has {len(sig)} bits")
    return sig
