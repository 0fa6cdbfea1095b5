"""The ECP5 PLL (EHXPLLL) settings for a set of exact output clocks from one input clock.

Project Trellis's ``ecppll`` (yowasp-ecppll) picks the VCO for the primary output alone and then divides it for
the secondary outputs, which can miss them: from the ULX3S's 25 MHz, a 125 MHz primary gives a 625 MHz VCO,
from which 100 MHz cannot be divided (``ecppll`` gives 104.17). The board needs four clocks exactly (memory 100,
TMDS 125, Harris 50, pixel 25 MHz), so :func:`plan` searches the VCO that divides to all of them, with
ecppll's rules for the rest: the limits below (Lattice TN1263 and Trellis's ecppll), feedback from CLKOP, the
primary's coarse phase half its period (as ecppll, which follows Lattice's tools), and the secondary outputs
at 0 degrees aligned to it. For a single output :func:`plan` chooses what ecppll chooses (the same search
order: input divider, feedback divider, output divider; among exact settings the VCO nearest 600 MHz, the
first found on a tie); the tests compare them. Only exact settings are planned (ecppll also takes the nearest).
"""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = ["PllPlan", "plan", "LIMITS"]

#: EHXPLLL's limits (MHz; dividers inclusive), as ecppll checks them.
LIMITS = dict(pfd=(3.125, 400.0), vco=(400.0, 800.0), out=(3.125, 400.0), input_div=(1, 128), feedback_div=(1, 80),
              output_div=(1, 128))
#: The outputs in EHXPLLL's order.
OUTPUTS = ("CLKOP", "CLKOS", "CLKOS2", "CLKOS3")


@dataclass(frozen=True)
class PllPlan:
    """One EHXPLLL's settings: the input divider, the feedback divider (feedback from CLKOP), each output's divider
    and coarse phase, and the frequencies they give."""

    fin: float
    input_div: int
    feedback_div: int
    output_divs: tuple[int, ...]
    vco: float
    outputs: tuple[float, ...]
    cphases: tuple[int, ...] = field(default=())

    def parameters(self) -> dict[str, object]:
        """EHXPLLL's parameters (the names of Lattice's primitive; strings as the primitive wants them)."""
        p: dict[str, object] = {"PLLRST_ENA": "DISABLED", "INTFB_WAKE": "DISABLED", "STDBY_ENABLE": "DISABLED",
                                "DPHASE_SOURCE": "DISABLED", "OUTDIVIDER_MUXA": "DIVA", "OUTDIVIDER_MUXB": "DIVB",
                                "OUTDIVIDER_MUXC": "DIVC", "OUTDIVIDER_MUXD": "DIVD", "CLKI_DIV": self.input_div,
                                "FEEDBK_PATH": "CLKOP", "CLKFB_DIV": self.feedback_div}
        for i, name in enumerate(OUTPUTS):
            if i < len(self.output_divs):
                p[f"{name}_ENABLE"] = "ENABLED"
                p[f"{name}_DIV"] = self.output_divs[i]
                p[f"{name}_CPHASE"] = self.cphases[i]
                p[f"{name}_FPHASE"] = 0
        return p

    def attributes(self) -> dict[str, str]:
        """The synthesis attributes Lattice's flow and ecppll put on the primitive (frequencies for the timing
        analysis, the loop filter)."""
        a = {"FREQUENCY_PIN_CLKI": _mhz(self.fin)}
        for name, f in zip(OUTPUTS, self.outputs):
            a[f"FREQUENCY_PIN_{name}"] = _mhz(f)
        a.update(ICP_CURRENT="12", LPF_RESISTOR="8", MFG_ENABLE_FILTEROPAMP="1", MFG_GMCREF_SEL="2")
        return a


def _mhz(f: float) -> str:
    return f"{f:.6f}".rstrip("0").rstrip(".")


def _check(fin, outs):
    if isinstance(fin, bool) or not isinstance(fin, (int, float)) or not 8.0 <= fin <= 400.0:
        raise ValueError(f"the PLL's input must be 8..400 MHz, got {fin!r}")
    if not 1 <= len(outs) <= 4:
        raise ValueError(f"an EHXPLLL has 1 to 4 outputs, got {len(outs)}")
    lo, hi = LIMITS["out"]
    for f in outs:
        if isinstance(f, bool) or not isinstance(f, (int, float)) or not lo <= f <= hi:
            raise ValueError(f"a PLL output must be {lo}..{hi} MHz, got {f!r}")


def plan(fin: float, outputs) -> PllPlan:
    """The EHXPLLL settings that give every frequency of ``outputs`` (MHz; the first is CLKOP, the feedback)
    exactly from ``fin``; ValueError when no VCO in 400..800 MHz divides to all of them."""
    outs = tuple(float(f) for f in outputs)
    _check(fin, outs)
    pfd_lo, pfd_hi = LIMITS["pfd"]
    vco_lo, vco_hi = LIMITS["vco"]
    best: PllPlan | None = None
    for idiv in range(LIMITS["input_div"][0], LIMITS["input_div"][1] + 1):
        pfd = fin / idiv
        if not pfd_lo <= pfd <= pfd_hi:
            continue
        for fbdiv in range(LIMITS["feedback_div"][0], LIMITS["feedback_div"][1] + 1):
            fop = pfd * fbdiv
            if abs(fop - outs[0]) > 1e-9 * outs[0]:
                continue
            for odiv in range(LIMITS["output_div"][0], LIMITS["output_div"][1] + 1):
                vco = fop * odiv
                if not vco_lo <= vco <= vco_hi:
                    continue
                divs = [odiv]
                for f in outs[1:]:
                    d = round(vco / f)
                    if not 1 <= d <= LIMITS["output_div"][1] or abs(vco / d - f) > 1e-9 * f:
                        break
                    divs.append(d)
                else:
                    cph = (odiv - 1) // 2  # about half the primary's period in VCO cycles (ecppll's convention)
                    p = PllPlan(fin=float(fin), input_div=idiv, feedback_div=fbdiv, output_divs=tuple(divs),
                                vco=vco, outputs=tuple(vco / d for d in divs), cphases=(cph,) * len(divs))
                    # ecppll's choice among exact settings: the VCO nearest 600 MHz, the first found on a tie
                    if best is None or abs(vco - 600.0) < abs(best.vco - 600.0):
                        best = p
    if best is not None:
        return best
    raise ValueError(f"no EHXPLLL setting gives {', '.join(_mhz(f) for f in outs)} MHz exactly from {_mhz(fin)} MHz "
                     f"(the VCO must lie in {vco_lo:g}..{vco_hi:g} MHz and divide to every output)")
