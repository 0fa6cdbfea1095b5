"""Lattice ECP5 primitives a board top needs, as MyHDL user-defined code: the PLL (EHXPLLL), the DDR output
(ODDRX1F) and the bidirectional pins.

MyHDL has no vendor primitives; these blocks emit an instance of the primitive in the converted VHDL and
Verilog (Yosys's ``synth_ecp5`` knows both cells; nextpnr-ecp5 places them). Their MyHDL bodies do nothing:
MyHDL's own simulator is not used on a board top. The board simulation compiles behavioural models of the two
primitives (:mod:`eyestereo.sim.harnesses.board_harness`) under the same names.
"""

from __future__ import annotations

from myhdl import always, block

from eyestereo.hdl.common.checks import block_error, check_signal
from eyestereo.tools.board.ecp5_pll import OUTPUTS, PllPlan

__all__ = ["ecp5_pll", "oddr", "tristate"]


def _wire(*sigs) -> None:
    for s in sigs:
        s.driven = "wire"


def _value(v) -> str:
    """A parameter's value in VHDL and Verilog alike: strings quoted, integers as they are."""
    return f'"{v}"' if isinstance(v, str) else str(int(v))


@block
def ecp5_pll(clki, clkop, clkos, clkos2, clkos3, locked, *, plan: PllPlan, label: str = "pll"):
    """An ECP5 EHXPLLL: up to four clocks from one, feedback from CLKOP, settings from
    :func:`eyestereo.tools.board.ecp5_pll.plan`.

    Ports:
        clki: the input clock (the board's oscillator; a pin with a clock input path: the ULX3S's G2).
        clkop, clkos, clkos2, clkos3: the outputs, in the plan's order (CLKOP the first, also the feedback); an
            output the plan does not use stays disabled (its signal is driven low by nothing: leave it unused).
        locked: the PLL's LOCK (asynchronous: synchronise it into each clock that uses it, e.g. as a reset).

    Parameters:
        plan: the :class:`~eyestereo.tools.board.ecp5_pll.PllPlan` (its dividers, phases and the frequency
            attributes Lattice's primitive carries for timing analysis).
        label: the instance's name.

    Latency: LOCK rises after the loop settles (Lattice TN1263: up to 15 ms worst case; usually well under 1 ms).

    Resources: one of the ECP5-85F's four PLLs.
    """
    if not isinstance(plan, PllPlan):
        raise block_error(f"plan must be a PllPlan (eyestereo.tools.board.ecp5_pll.plan), got {type(plan).__name__}")
    outs = (clkop, clkos, clkos2, clkos3)
    for name, s in zip(("clki",) + tuple(o.lower() for o in OUTPUTS) + ("locked",), (clki,) + outs + (locked,)):
        check_signal(name, s, width=1)
    _wire(*outs, locked)
    clki.read = True
    params = plan.parameters()
    # the instance's text for the user code's template (MyHDL fills $name from this namespace)
    v_attrs = " ".join(f'(* {k}="{v}" *)' for k, v in plan.attributes().items())  # noqa: F841 (template)
    v_params = ", ".join(f".{k}({_value(v)})" for k, v in params.items())  # noqa: F841
    h_params = ", ".join(f"{k} => {_value(v)}" for k, v in params.items())  # noqa: F841

    @always(clki.posedge)
    def model():  # the instance is the user code; MyHDL's simulation of a board top is not used
        pass

    return model


_PLL_TIES = ("STDBY", "PHASESEL0", "PHASESEL1", "PHASEDIR", "PHASESTEP", "PHASELOADREG", "PLLWAKESYNC", "ENCLKOP",
             "RST")
ecp5_pll.verilog_code = (
    "$v_attrs\nEHXPLLL #($v_params) $label (.CLKI($clki), .CLKFB($clkop), "
    + "".join(f".{p}(1'b0), " for p in _PLL_TIES)
    + ".CLKOP($clkop), .CLKOS($clkos), .CLKOS2($clkos2), .CLKOS3($clkos3), .LOCK($locked));")
ecp5_pll.vhdl_code = (
    "$label: entity work.EHXPLLL generic map ($h_params) port map (CLKI => $clki, CLKFB => $clkop, "
    + "".join(f"{p} => '0', " for p in _PLL_TIES)
    + "CLKOP => $clkop, CLKOS => $clkos, CLKOS2 => $clkos2, CLKOS3 => $clkos3, LOCK => $locked);")


@block
def oddr(clk, d0, d1, q, *, label: str = "oddr"):
    """An ECP5 ODDRX1F: two bits a clock onto one pin, ``d0`` in the clock's high half, ``d1`` in its low half.

    Ports:
        clk: the bit clock (``SCLK``; the TMDS serialiser's 125 MHz for 250 Mbit/s, or the memory clock to forward
            it to the SDRAM's clock pin: ``d0 = 1``, ``d1 = 0`` gives the clock, the other way round its inverse).
        d0, d1: the two bits, registered by the cell on ``clk``'s rising edge.
        q: the pin (an output port of the top, nothing else on it).

    Parameters:
        label: the instance's name.

    Latency: ``d0`` appears on the pin about half a clock after the rising edge that samples it, ``d1`` a half
    clock later (Lattice TN1265: the output register pair and its multiplexer in the I/O cell).

    Resources: the pin's output DDR register (no fabric flip-flop).
    """
    for name, s in (("clk", clk), ("d0", d0), ("d1", d1), ("q", q)):
        check_signal(name, s, width=1)
    _wire(q)
    for s in (clk, d0, d1):
        s.read = True

    @always(clk.posedge)
    def model():  # the instance is the user code
        pass

    return model


oddr.verilog_code = "ODDRX1F $label (.D0($d0), .D1($d1), .SCLK($clk), .RST(1'b0), .Q($q));"
oddr.vhdl_code = "$label: entity work.ODDRX1F port map (D0 => $d0, D1 => $d1, SCLK => $clk, RST => '0', Q => $q);"


@block
def tristate(o, oe, i, pad, *, label: str = "tri"):
    """A bidirectional pin (or a bus of them): ``pad`` driven with ``o`` while ``oe`` is high, released otherwise;
    ``i`` is what the pin carries. Yosys maps it to the pins' tristate buffers (the ECP5's ``BB``).

    Ports:
        o: the value driven (as wide as ``pad``); oe: 1 drives all bits (one enable for the bus, as the SDRAM's DQ
        and an open-drain SIO_D need); i: the pin's value back (as wide as ``pad``); pad: a ``TristateSignal`` port
        of the top.

    Parameters:
        label: the assignments' comment.

    Latency: none (wires and the pins' buffers); register ``o``, ``oe`` and ``i`` outside, in the I/O cells. In the
    VHDL ``i`` is the pin's value through ``to_X01``, so a pull-up's weak 1 (``'H'``) reads as ``'1'``.

    Resources: the pins' I/O buffers.
    """
    check_signal("oe", oe, width=1)
    n = len(pad)
    for name, s in (("o", o), ("i", i)):
        if len(s) != n:
            raise block_error(f"port {name} must be {n} bits like pad, got {len(s)}")
    _wire(i)
    pad.driven = "wire"
    for s in (o, oe):
        s.read = True
    zeros = f"{n}'b" + "z" * n if n > 1 else "1'bz"  # noqa: F841 (template)
    hz = "(others => 'Z')" if n > 1 else "'Z'"  # noqa: F841 (template)

    @always(oe.posedge)
    def model():  # the assignments are the user code
        pass

    return model


tristate.verilog_code = "// $label\nassign $pad = $oe ? $o : $zeros;\nassign $i = $pad;"
tristate.vhdl_code = "-- $label\n$pad <= $o when $oe = '1' else $hz;\n$i <= to_X01($pad);"
