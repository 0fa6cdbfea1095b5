"""The board simulation's top: the ULX3S board top with the parts around it that the bench cannot be.

The board top (:func:`eyestereo.hdl.boards.ulx3s.ulx3s`) is simulated whole, its ECP5 primitives included: the
test models here stand in for them and for the board's parts (hand-written VHDL and Verilog, instantiated through
MyHDL's user-defined code like the fast harness's, :mod:`eyestereo.sim.harnesses.frontend_harness`):

EHXPLLL (``EHXPLLL``)
    Lattice's PLL by its parameters: it measures two periods of CLKI, then (after 4 more input clocks, LOCK
    high) runs each enabled output at CLKI's frequency x CLKFB_DIV x CLKOP_DIV / (CLKI_DIV x the output's DIV),
    all starting together on a CLKI rising edge (0 degrees, as the plan's equal coarse phases make them). The
    25 MHz oscillator gives 100, 125, 50 and 25 MHz exactly.
ODDRX1F (``ODDRX1F``)
    D0 and D1 registered on SCLK's rising edge; Q is D0's register while SCLK is high, D1's while it is low.
pull-up (``pullup``)
    A weak 1 on a pin nobody drives (the camera modules' SIO_D resistors).

The cameras are the fast harness's camera players (a script per camera, PCLK gated from a base clock: the
OV7670's DVP timing is the script's); the SCCB slaves, the SDRAM part and the DVI receiver are the bench's Python
(they wake on the lines' edges, the SDRAM's command pins and the TMDS bit clock): SIO_D and DQ are the board's
bidirectional pins, the slaves and the SDRAM drive them through a ``tristate`` like the FPGA's (``pull_l``,
``pull_r``; ``mem_dq_val``, ``mem_dq_drive``), and see them as ``siod_l``, ``siod_r``, ``mem_dq``.

Ports: the board top's own (``osc`` = clk_25mhz, ``ftdi_txd``, ``ftdi_rxd``, ``gpdi_dp``, ``led``, ``btn``, the
SDRAM's command pins as ``mem_*`` and its DQ pins ``sdram_d``, the cameras' ``sioc_l``/``sioc_r``, their SIO_D pins
``pad_l``/``pad_r``, ``xclk_l``/``xclk_r``; the bidirectional pins are ports so that the HDL declares them), the
camera players' ``base_l``, ``base_r``, ``cam_go``, ``cam_*_done``, ``cam_*_samples``, and the pins' model sides
above. Registered as the simulation-only catalogue top ``board_harness``; its parameters are the board top's.
"""

from __future__ import annotations

from myhdl import Signal, TristateSignal, always, block, intbv

from eyestereo.hdl.boards.ecp5 import tristate
from eyestereo.hdl.boards.ulx3s import ulx3s
from eyestereo.hdl.flow.catalog import BENCH_TOPS, BlockSpec, block_defaults
from eyestereo.hdl.interfaces.camera_bus import CameraBus
from eyestereo.sim.harnesses.frontend_harness import MODELS as FRONTEND_MODELS
from eyestereo.sim.harnesses.frontend_harness import camera_player
from eyestereo.sim.lib.harness_files import SCRIPT_FILES
from eyestereo.tools.camera import CameraTiming

NAME = "board_harness"

_PLL_STRINGS = ("PLLRST_ENA", "INTFB_WAKE", "STDBY_ENABLE", "DPHASE_SOURCE", "OUTDIVIDER_MUXA", "OUTDIVIDER_MUXB",
                "OUTDIVIDER_MUXC", "OUTDIVIDER_MUXD", "FEEDBK_PATH")
_OUTS = ("CLKOP", "CLKOS", "CLKOS2", "CLKOS3")
_PLL_INS = ("CLKI", "CLKFB", "RST", "STDBY", "PHASESEL0", "PHASESEL1", "PHASEDIR", "PHASESTEP", "PHASELOADREG",
            "PLLWAKESYNC", "ENCLKOP")

def _pll_params() -> list[tuple[str, str, str]]:
    """EHXPLLL's parameters the models declare: (name, VHDL type, default), in the instance's order."""
    out = [(g, "string", '""') for g in _PLL_STRINGS] + [("CLKI_DIV", "integer", "1"), ("CLKFB_DIV", "integer", "1")]
    for o in _OUTS:
        out += [(f"{o}_ENABLE", "string", '"DISABLED"'), (f"{o}_DIV", "integer", "1"),
                (f"{o}_CPHASE", "integer", "0"), (f"{o}_FPHASE", "integer", "0")]
    return out


def _vhdl_generics() -> str:
    return ";\n".join(f"    {n}: {t} := {d}" for n, t, d in _pll_params()) + "\n"


def _vhdl_output(o: str) -> str:
    return f"""  out_{o.lower()}: process
  begin
    wait until locked = '1';
    if {o}_ENABLE = "ENABLED" then
      loop
        {o} <= '1';
        wait for vco_half * {o}_DIV;
        {o} <= '0';
        wait for vco_half * {o}_DIV;
      end loop;
    end if;
    wait;
  end process;

"""


def _verilog_params() -> str:
    return ",\n".join(f"  parameter {n} = {d}" for n, _, d in _pll_params()) + "\n"


def _verilog_output(o: str) -> str:
    return f"""  initial begin
    wait (LOCK);
    if ({o}_ENABLE == "ENABLED")
      forever begin
        {o} = 1;
        #(vco_half * {o}_DIV);
        {o} = 0;
        #(vco_half * {o}_DIV);
      end
  end
"""


_PLL_PORTS = ", ".join(_PLL_INS)

# Test models of the ECP5 primitives the board top instantiates.
ECP5_VHDL = r"""-- Test models of the ECP5 primitives (eyestereo.sim.harnesses.board_harness).
library ieee;
use ieee.std_logic_1164.all;

entity EHXPLLL is
  generic (
""" + _vhdl_generics() + r"""  );
  port (
    """ + _PLL_PORTS + r""": in std_logic;
    CLKOP, CLKOS, CLKOS2, CLKOS3, LOCK: out std_logic := '0'
  );
end entity;

architecture model of EHXPLLL is
  signal vco_half: time := 0 ns;  -- half a VCO period
  signal locked: std_logic := '0';
begin
  measure: process
    variable t0: time;
  begin
    wait until rising_edge(CLKI);
    t0 := now;
    wait until rising_edge(CLKI);
    vco_half <= (now - t0) * CLKI_DIV / (CLKFB_DIV * CLKOP_DIV * 2);
    for i in 1 to 4 loop
      wait until rising_edge(CLKI);
    end loop;
    locked <= '1';
    wait;
  end process;
  LOCK <= locked;

""" + "".join(_vhdl_output(o) for o in _OUTS) + r"""end architecture;

library ieee;
use ieee.std_logic_1164.all;

entity ODDRX1F is
  port (D0, D1, SCLK, RST: in std_logic; Q: out std_logic);
end entity;

architecture model of ODDRX1F is
  signal r0, r1: std_logic := '0';
begin
  process (SCLK)
  begin
    if rising_edge(SCLK) then
      r0 <= D0;
      r1 <= D1;
    end if;
  end process;
  Q <= r0 when SCLK = '1' else r1;
end architecture;
"""

ECP5_V = r"""// Test models of the ECP5 primitives (eyestereo.sim.harnesses.board_harness).
`timescale 1ps/1ps
module EHXPLLL #(
""" + _verilog_params() + r""") (
  input """ + _PLL_PORTS + r""",
  output reg CLKOP = 0, output reg CLKOS = 0, output reg CLKOS2 = 0, output reg CLKOS3 = 0, output reg LOCK = 0
);
  realtime t0, vco_half;
  integer i;
  initial begin
    @(posedge CLKI) t0 = $realtime;
    @(posedge CLKI) vco_half = ($realtime - t0) * CLKI_DIV / (CLKFB_DIV * CLKOP_DIV * 2);
    for (i = 0; i < 4; i = i + 1) @(posedge CLKI);
    LOCK = 1;
  end
""" + "".join(_verilog_output(o) for o in _OUTS) + r"""endmodule

module ODDRX1F (input D0, input D1, input SCLK, input RST, output Q);
  reg r0 = 0, r1 = 0;
  always @(posedge SCLK) begin
    r0 <= D0;
    r1 <= D1;
  end
  assign Q = SCLK ? r0 : r1;
endmodule
"""

MODELS = {"vhdl": {"camera_player.vhd": FRONTEND_MODELS["vhdl"]["camera_player.vhd"], "ecp5_models.vhd": ECP5_VHDL},
          "verilog": {"camera_player.v": FRONTEND_MODELS["verilog"]["camera_player.v"], "ecp5_models.v": ECP5_V}}


@block
def pullup(pad):
    """A weak 1 on ``pad`` (a TristateSignal): the pull-up resistor of an open-drain line."""
    pad.driven = "wire"

    @always(pad)
    def model():  # the user code below
        pass

    return model


pullup.vhdl_code = "$pad <= 'H';"
pullup.verilog_code = "pullup ($pad);"


@block
def board_harness(osc, base_l, base_r, cam_go, ftdi_txd, ftdi_rxd, gpdi_dp, led, btn, mem_clk, mem_cke, mem_cs_n,
                  mem_ras_n, mem_cas_n, mem_we_n, mem_ba, mem_a, mem_dqm, sdram_d, mem_dq, mem_dq_val, mem_dq_drive,
                  sioc_l, sioc_r, pad_l, pad_r, siod_l, siod_r, pull_l, pull_r, xclk_l, xclk_r, cam_l_done,
                  cam_l_samples, cam_r_done, cam_r_samples, **params):
    """The ULX3S top (``params``) with its primitives' models, two camera players and the pins' model sides."""
    t = CameraTiming()
    cam_l, cam_r = CameraBus(), CameraBus()
    rst_l, pwdn_l, rst_r, pwdn_r = (Signal(bool(0)) for _ in range(4))
    top = ulx3s(osc, led, btn, ftdi_txd, ftdi_rxd, mem_clk, mem_cke, mem_cs_n, mem_we_n, mem_ras_n, mem_cas_n, mem_a,
                mem_ba, mem_dqm, sdram_d, gpdi_dp, cam_l, xclk_l, sioc_l, pad_l, rst_l, pwdn_l, cam_r, xclk_r,
                sioc_r, pad_r, rst_r, pwdn_r, **params)
    zero = Signal(bool(0))  # the slaves' open-drain low (from a process: user code alone leaves it undeclared)

    @always(osc.posedge)
    def zero_tie():
        zero.next = 0
    pins = [tristate(mem_dq_val, mem_dq_drive, mem_dq, sdram_d, label="model_dq"),
            tristate(zero, pull_l, siod_l, pad_l, label="slave_l"), tristate(zero, pull_r, siod_r, pad_r,
                                                                              label="slave_r"),
            pullup(pad_l), pullup(pad_r)]
    players = [camera_player(base, cam_go, cam.pclk, cam.vsync, cam.href, cam.data, done, samples,
                             file_name=SCRIPT_FILES[side], vsync_active=t.vsync_active, href_active=t.href_active,
                             label=f"u_camera_player_{side}")
               for side, base, cam, done, samples in (("l", base_l, cam_l, cam_l_done, cam_l_samples),
                                                     ("r", base_r, cam_r, cam_r_done, cam_r_samples))]
    return top, pins, players, zero_tie


def _build(p):
    b = lambda: Signal(bool(0))  # noqa: E731
    return dict(osc=b(), base_l=b(), base_r=b(), cam_go=b(), ftdi_txd=Signal(bool(1)), ftdi_rxd=Signal(bool(1)),
                gpdi_dp=Signal(intbv(0)[4:]), led=Signal(intbv(0)[8:]), btn=Signal(intbv(1)[7:]), mem_clk=b(),
                mem_cke=b(), mem_cs_n=Signal(bool(1)), mem_ras_n=Signal(bool(1)), mem_cas_n=Signal(bool(1)),
                mem_we_n=Signal(bool(1)), mem_ba=Signal(intbv(0)[2:]), mem_a=Signal(intbv(0)[13:]),
                mem_dqm=Signal(intbv(3)[2:]), sdram_d=TristateSignal(intbv(0)[16:]), mem_dq=Signal(intbv(0)[16:]),
                mem_dq_val=Signal(intbv(0)[16:]),
                mem_dq_drive=b(), sioc_l=Signal(bool(1)), sioc_r=Signal(bool(1)), pad_l=TristateSignal(bool(1)),
                pad_r=TristateSignal(bool(1)), siod_l=Signal(bool(1)),
                siod_r=Signal(bool(1)), pull_l=b(), pull_r=b(), xclk_l=b(), xclk_r=b(), cam_l_done=b(),
                cam_l_samples=Signal(intbv(0)[32:]), cam_r_done=b(), cam_r_samples=Signal(intbv(0)[32:]))


_DEFAULTS = block_defaults(ulx3s)
BENCH_TOPS[NAME] = BlockSpec(
    NAME, "bench top: the ULX3S board top with models of its PLL, DDR outputs, camera players and pull-ups",
    board_harness,
    dict(_DEFAULTS), sink_width=lambda p: 8, source_width=lambda p: 8, hw_params=tuple(_DEFAULTS), build=_build,
    clocks=(("osc", 25.0),), sources=lambda lang: MODELS[lang])
