"""The SDRAM's pins of a board top, named as boards' constraint files name them, on the front end's SdramPins."""

from __future__ import annotations

from myhdl import always_comb, block

from eyestereo.hdl.boards.ecp5 import tristate
from eyestereo.hdl.common.checks import block_error
from eyestereo.hdl.interfaces.sdram_bus import SdramPins

__all__ = ["sdram_pins"]


@block
def sdram_pins(sdram, sdram_cke, sdram_csn, sdram_wen, sdram_rasn, sdram_casn, sdram_a, sdram_ba, sdram_dqm, sdram_d):
    """The front end's :class:`~eyestereo.hdl.interfaces.sdram_bus.SdramPins` (split DQ: value, enable, input) on
    a board's SDRAM pins: the command and address outputs as they are, DQ through a
    :func:`~eyestereo.hdl.boards.ecp5.tristate` (``sdram_d``, a ``TristateSignal`` port of the top). The names are
    the ULX3S constraint file's (``sdram_csn``, ``sdram_wen``, ..., ``sdram_d``), which other boards' files share.

    Ports:
        sdram: SdramPins (the controller's side).
        sdram_cke, sdram_csn, sdram_wen, sdram_rasn, sdram_casn, sdram_a, sdram_ba, sdram_dqm: the pins (out).
        sdram_d: the DQ pins (in/out).

    Latency: none (wires; every controller output already comes from a flip-flop).

    Resources: the pins' I/O buffers.
    """
    if not isinstance(sdram, SdramPins):
        raise block_error(f"port sdram must be SdramPins, got {type(sdram).__name__}")
    for name, pin, member in (("sdram_a", sdram_a, sdram.a), ("sdram_ba", sdram_ba, sdram.ba),
                              ("sdram_dqm", sdram_dqm, sdram.dqm), ("sdram_d", sdram_d, sdram.dq_o)):
        if len(pin) != len(member):
            raise block_error(f"port {name} must be {len(member)} bits like the part's, got {len(pin)}")

    @always_comb
    def outputs():
        sdram_cke.next = sdram.cke
        sdram_csn.next = sdram.cs_n
        sdram_wen.next = sdram.we_n
        sdram_rasn.next = sdram.ras_n
        sdram_casn.next = sdram.cas_n
        sdram_a.next = sdram.a
        sdram_ba.next = sdram.ba
        sdram_dqm.next = sdram.dqm

    return outputs, tristate(sdram.dq_o, sdram.dq_oe, sdram.dq_i, sdram_d, label="sdram_dq")
