"""cocotb bench: poly_unit against :func:`eyestereo.tools.models.poly_unit.poly_unit`, bit for bit, every clock.

Random inputs (x, y over their whole port range, select codes valid and invalid) with a random
``enable``; a Python copy of the 8-stage register chain (advancing exactly on the enabled edges) says
which input must be at the output in every clock, and coord, out_of_range and select_coord_out are
compared with the model there -- so latency, the freeze under ``enable`` low and the arithmetic are all
checked cycle by cycle. Configuration (from the runner): ``params`` (the block's), ``cycles``, ``seed``,
``en_p`` (probability that enable is high), ``valid_p``; ``coefficients: "random"`` writes random codes
(each within its format) through the coefficient port first and expects them.
"""

from __future__ import annotations

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, ReadOnly, RisingEdge

from eyestereo.sim.lib.bench import write_report
from eyestereo.sim.lib.rectify_bench import random_codes, rectify_config, write_coefficients
from eyestereo.tools.models import poly_unit as model


def boundary_points(cal: model.Calibration) -> np.ndarray:
    """(x, y, polynomial index) of every input whose q24 code is within one code of 0 or of its limit."""
    gw, gh = 1 << model.int_bits(cal.width), 1 << model.int_bits(cal.height)
    yy, xx = np.mgrid[0:gh, 0:gw]
    out = []
    for index in range(4):
        code = model.q24_codes(cal, index, gw, gh).ravel()
        lim = model.range_limit(cal.out_format, cal.source_height if index & 1 else cal.source_width)
        hit = (np.abs(code) <= 1) | (np.abs(code - lim) <= 1)
        out.append(np.stack([xx.ravel()[hit], yy.ravel()[hit], np.full(hit.sum(), index)], axis=1))
    return np.concatenate(out) if out else np.zeros((0, 3), dtype=np.int64)


@cocotb.test()
async def poly_unit_random(dut):
    cfg, cal, frac = rectify_config()
    p = cfg["params"]
    rng = np.random.default_rng(int(cfg.get("seed", 0)))
    n = int(cfg.get("cycles", 2000))
    en_p, valid_p = float(cfg.get("en_p", 1.0)), float(cfg.get("valid_p", 0.8))

    clk = dut.clk
    Clock(clk, 10, unit="ns").start()
    for s in (dut.enable, dut.x, dut.y, dut.select_coord):
        s.value = 0
    if p.get("coefficients") == "register":
        dut.coef_we.value = 0
        dut.coef_addr.value = 0
        dut.coef_data.value = 0
    dut.rst.value = 1
    await ClockCycles(clk, 3)
    dut.rst.value = 0

    if cfg.get("coefficients") == "random":
        codes = random_codes(cal, rng)
        cal = cal.with_codes(codes)
        await write_coefficients(dut, clk, model.register_writes(codes, cal.formats))
    elif p.get("coefficients") == "register":
        # The conversion may start memories undefined: load the elaboration's own codes.
        await write_coefficients(dut, clk, model.register_writes(cal.codes, cal.formats))

    xs = rng.integers(0, 1 << model.int_bits(cal.width), n)
    ys = rng.integers(0, 1 << model.int_bits(cal.height), n)
    sel = rng.integers(0, 4, n) | np.where(rng.random(n) < valid_p, model.VALID, 0)
    # A third of the inputs sit on the range limits (q24 within one code of 0 or of the limit).
    edge = boundary_points(cal)
    if len(edge):
        pick = np.nonzero(rng.random(n) < 1 / 3)[0]
        chosen = edge[rng.integers(0, len(edge), len(pick))]
        xs[pick], ys[pick], sel[pick] = chosen[:, 0], chosen[:, 1], chosen[:, 2] | model.VALID
    en = rng.random(n) < en_p
    exp_coord, exp_oor = model.poly_unit(cal, xs, ys, sel, frac)

    # Python image of the pipeline: which input (index) each of the 8 stages holds; -1 = the reset state.
    stages = [-1] * model.LATENCY
    compared = valid_out = frozen_checks = 0
    await FallingEdge(clk)
    prev = None
    for t in range(n + 2 * model.LATENCY):
        k = t if t < n else None
        dut.enable.value = int(en[k]) if k is not None else 1
        dut.x.value = int(xs[k]) if k is not None else 0
        dut.y.value = int(ys[k]) if k is not None else 0
        dut.select_coord.value = int(sel[k]) if k is not None else 0
        enabled = bool(en[k]) if k is not None else True
        await RisingEdge(clk)
        if enabled:
            stages = [k if k is not None else -2] + stages[:-1]
        await ReadOnly()
        got_sel = int(dut.select_coord_out.value)
        last = stages[-1]
        want_sel = 0 if last == -1 else (0 if last == -2 else int(sel[last]))
        assert got_sel == want_sel, f"clock {t}: select_coord_out {got_sel:03b}, expected {want_sel:03b} (input {last})"
        if last >= 0:
            got_c, got_o = int(dut.coord.value), int(dut.out_of_range.value)
            assert (got_c, got_o) == (int(exp_coord[last]), int(exp_oor[last])), (
                f"clock {t}: input {last} (x={xs[last]}, y={ys[last]}, select={sel[last]:03b}): coord {got_c:#x} "
                f"oor {got_o}, expected {int(exp_coord[last]):#x} oor {int(exp_oor[last])}")
            compared += 1
            valid_out += int(sel[last]) >> 2
            if not enabled and prev is not None:
                frozen_checks += 1
                assert prev == (got_sel, got_c, got_o), f"clock {t}: outputs changed while enable was low"
            prev = (got_sel, got_c, got_o)
        await FallingEdge(clk)
    assert compared > n // 2, f"only {compared} outputs compared"
    write_report(cfg, dict(compared=compared, valid=valid_out, frozen_checks=frozen_checks, cycles=n,
                           oor=int(exp_oor[sel >= 4].sum())))
