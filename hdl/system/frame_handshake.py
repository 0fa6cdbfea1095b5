"""The register bank's frame-handshake fields wired to the SRAM arbiter's FrameControl (the host's hold on buffers)."""

from __future__ import annotations

from myhdl import block

from eyestereo.hdl.common.registers import assign
from eyestereo.hdl.interfaces.sram_bus import check_bundle
from eyestereo.hdl.memory.frame_buffers import FrameControl
from eyestereo.hdl.system.register_bank import RegisterPorts
from eyestereo.tools.regmap import FRAME_CONTROL, REGMAP

__all__ = ["frame_handshake", "HANDSHAKE"]

#: The wired fields, in the register map's order: (name, True where the bank drives the arbiter's member).
#: Every field whose ``connect`` is :data:`~eyestereo.tools.regmap.FRAME_CONTROL` + its name: the bank's
#: ``rw`` and ``pulse`` fields (``rect_want``, ``feat_want``, ``rect_release``, ``feat_release``) go to the
#: arbiter, its ``status`` fields (``avail``, ``rect_held``, ``feat_held``, ``rect_buf``, ``feat_buf``) come
#: from it: the table's "Connections" in docs/registers.md.
HANDSHAKE = tuple((f.name, r.kind != "status") for r in REGMAP for f in r.fields
                  if f.connect == FRAME_CONTROL + f.name)


@block
def frame_handshake(regs, ctl):
    """The host side of the arbiter's frame handshake: the register fields of :data:`HANDSHAKE` and the
    :class:`~eyestereo.hdl.memory.frame_buffers.FrameControl` members of the same names, wired one to one.

    One place for the wiring that the system top (:func:`eyestereo.hdl.system.stereo_frontend.stereo_frontend`)
    and the bench top ``host_system_tb`` (:mod:`eyestereo.sim.harnesses.host_harness`) share. The camera
    side of the handshake (``cam_*``) is not the host's: the caller drives it (the sequencer, the bench).

    Ports:
        regs: the register bank's :class:`~eyestereo.hdl.system.register_bank.RegisterPorts`; its want and
            release fields are read here, its avail, held and buf fields driven.
        ctl: the arbiter's :class:`~eyestereo.hdl.memory.frame_buffers.FrameControl`; ``rect_want``,
            ``feat_want``, ``rect_release``, ``feat_release`` driven here, ``avail``, ``rect_held``,
            ``feat_held``, ``rect_buf``, ``feat_buf`` read.

    Parameters: none (the fields come from the register map).

    Latency: 0 (wires).

    Resources: none (wires).
    """
    check_bundle("regs", regs, RegisterPorts)
    check_bundle("ctl", ctl, FrameControl)
    insts = []
    for name, to_arbiter in HANDSHAKE:
        bank, arbiter = getattr(regs, name), getattr(ctl, name)
        insts.append(assign(bank, arbiter) if to_arbiter else assign(arbiter, bank))
    return insts
