"""A MyHDL bench top: the register bank on the real SRAM subsystem (arbiter + controller), wired as in the system.

The bank's ``arb`` window is the arbiter's status port, its SRAM window the arbiter's host port, and the
host's frame-handshake fields go to the arbiter's :class:`~eyestereo.hdl.memory.frame_buffers.FrameControl`
through :func:`~eyestereo.hdl.system.frame_handshake.frame_handshake`, the system top's own wiring
(docs/registers.md, "Connections"). Everything else stays a port of the top (the masters, the camera side
of the frame handshake, the SRAM pins, the other register fields), driven by the bench
:mod:`eyestereo.sim.benches.tb_host_system`.

Registered as the simulation-only catalogue top ``host_system_tb`` (:data:`eyestereo.hdl.flow.catalog.BENCH_TOPS`).
"""

from __future__ import annotations

from myhdl import ResetSignal, Signal, block

from eyestereo.hdl.interfaces.axil import AxiLite
from eyestereo.hdl.flow.catalog import BENCH_TOPS, BlockSpec, masters as _masters
from eyestereo.hdl.system.frame_handshake import frame_handshake
from eyestereo.hdl.system.register_bank import RegisterPorts, register_bank
from eyestereo.hdl.interfaces.sram_bus import HostPort, SramPins, StatPort
from eyestereo.hdl.memory.sram_subsystem import sram_subsystem
from eyestereo.tools.regmap import REGMAP

NAME = "host_system_tb"


@block
def host_system_tb(clk, rst, bus, regs, fcount, cam0, cam1, fetch, rect, feat, ctl, sram, *, width: int = 16,
                   height: int = 4, feature_words: int = 64):
    """register_bank + sram_subsystem, the bank's windows and frame-handshake fields wired (module docstring)."""
    host, stat = HostPort(), StatPort()
    bank = register_bank(clk, rst, bus, regs, stat, fcount, host, width=width, height=height)
    sub = sram_subsystem(clk, rst, cam0, cam1, fetch, rect, feat, host, ctl, stat, sram, width=width,
                         height=height, feature_words=feature_words)
    return bank, sub, frame_handshake(regs, ctl)


def _build(p):
    m = _masters(dict(p, width=p["width"], height=p["height"]))
    return dict(clk=Signal(bool(0)), rst=ResetSignal(0, active=1, isasync=False), bus=AxiLite(REGMAP.addr_bits),
                regs=RegisterPorts(), fcount=StatPort(5, 16), cam0=m["cam0"], cam1=m["cam1"], fetch=m["fetch"],
                rect=m["rect"], feat=m["feat"], ctl=m["ctl"], sram=SramPins())


BENCH_TOPS[NAME] = BlockSpec(
    NAME, "bench top: register_bank on sram_subsystem", host_system_tb, dict(width=16, height=4, feature_words=64),
    sink_width=lambda p: 16, source_width=lambda p: 16, hw_params=("width", "height", "feature_words"),
    build=_build, clocks=(("clk", 100.0),))
