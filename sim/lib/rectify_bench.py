"""What the benches of the rectify blocks share: their configuration's calibration, the fetch-port memory,
reset, waiting for beats, the quiet end, and the coefficient port.

The calibration comes from :func:`eyestereo.hdl.rectify.calibration.calibration_of` on the block
parameters the runner hands the bench: the function the block and the catalogue resolved it with, so
the bench checks against the calibration the HDL was converted from.
"""

from __future__ import annotations

import numpy as np
from cocotb.triggers import ClockCycles, FallingEdge, ReadOnly, RisingEdge

from eyestereo.hdl.rectify.calibration import calibration_of
from eyestereo.sim.lib.bench import load_config
from eyestereo.sim.lib.fetch_memory import FetchMemory, StereoMonitor
from eyestereo.tools.models import poly_unit as unit_model

__all__ = ["PERIOD", "memory", "quiet", "random_codes", "rectify_config", "reset", "wait_beats",
           "write_coefficients"]

PERIOD = 10  # ns


def rectify_config() -> tuple[dict, unit_model.Calibration, int]:
    """The bench's configuration, the calibration of its ``params`` and the coordinates' fraction bits."""
    cfg = load_config()
    p = cfg["params"]
    cal = calibration_of(p)
    return cfg, cal, unit_model.resolve_frac(cal, p.get("frac"))


def memory(dut, cfg: dict, images: dict) -> FetchMemory:
    """The fetch-port memory holding ``images`` ({cam: image}) with the configuration's timing."""
    return FetchMemory(dut, images, seed=int(cfg.get("seed", 1)), ready_p=float(cfg.get("ready_p", 1.0)),
                       latency=int(cfg.get("latency", 0)), wait_p=float(cfg.get("wait_p", 0.0)),
                       stall_p=float(cfg.get("stall_p", 0.0)), stall=tuple(cfg.get("stall", (50, 400))))


async def reset(dut, clk) -> None:
    """``rst`` high for three clocks, changed at falling edges."""
    await FallingEdge(clk)
    dut.rst.value = 1
    await ClockCycles(clk, 3)
    await FallingEdge(clk)
    dut.rst.value = 0


async def wait_beats(clk, mon: StereoMonitor, n: int, timeout: int, what: str) -> None:
    """Until ``mon`` holds ``n`` beats; an AssertionError after ``timeout`` clocks."""
    waited = 0
    while len(mon.beats) < n:
        await ClockCycles(clk, 256)
        waited += 256
        if waited > timeout:
            raise AssertionError(f"{what}: {len(mon.beats)} of {n} beats after {waited} clocks")


async def quiet(dut, clk, mem: FetchMemory, mon: StereoMonitor, busy_name: str = "busy") -> None:
    """Wait for the memory to drain, then check that nothing more happens."""
    for _ in range(400):
        await RisingEdge(clk)
        await ReadOnly()
        if mem.idle and not int(getattr(dut, busy_name).value):
            break
    assert int(getattr(dut, busy_name).value) == 0, f"{busy_name} still high after the last frame"
    n_beats, n_req = len(mon.beats), len(mem.requests)
    await ClockCycles(clk, 300)
    assert len(mon.beats) == n_beats, f"{len(mon.beats) - n_beats} beats after the last frame"
    assert len(mem.requests) == n_req, f"{len(mem.requests) - n_req} requests after the last frame"
    assert mem.idle, f"{len(mem.beats)} responses never delivered"


def random_codes(cal: unit_model.Calibration, rng: np.random.Generator) -> list[list[int]]:
    """Random coefficient codes p1..p10 of the four polynomials, each within its format."""
    return [[int(rng.integers(f.lo, f.hi + 1)) for f in cal.formats[:10]] for _ in range(4)]


async def write_coefficients(dut, clk, writes) -> None:
    """Drive the coefficient port, one write per clock (inputs change just after a falling edge)."""
    for addr, data in writes:
        await FallingEdge(clk)
        dut.coef_we.value = 1
        dut.coef_addr.value = addr
        dut.coef_data.value = data
    await FallingEdge(clk)
    dut.coef_we.value = 0
