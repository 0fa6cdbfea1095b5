"""Run a block bench on GHDL's synthesized netlist of the block's VHDL, in Icarus Verilog.

This is how the netlist that ``make synth`` measures is shown equal to the VHDL: the same cocotb bench
and the same bit-true model, but the simulated design is ``ghdl synth --out=verilog`` of the VHDL
(repaired by :mod:`eyestereo.hdl.flow.netlist`), not the VHDL itself. Each configuration builds in its own
folder under ``build/sim_netlist/``.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

from cocotb_tools.runner import get_results, get_runner

from eyestereo.hdl.flow.convert import convert
from eyestereo.hdl.flow.netlist import ghdl_netlist
from eyestereo.hdl.flow.catalog import jsonable
from eyestereo.sim.lib.runner import ROOT, SIM_DIR, slug

BUILD = ROOT / "build" / "sim_netlist"


def run_netlist_bench(block: str, bench: str, config: dict, *, name: str, params: dict | None = None,
                      build_root: Path = BUILD) -> dict:
    """Like :func:`eyestereo.sim.lib.runner.run_bench`, on GHDL's Verilog netlist of the VHDL in Icarus."""
    for tool in ("ghdl", "iverilog"):
        if shutil.which(tool) is None:
            raise RuntimeError(f"{tool} not found: install it (Debian: apt-get install {tool})")
    params = dict(params or {})
    build_dir = Path(build_root) / slug(block) / slug(name)
    if build_dir.exists():
        shutil.rmtree(build_dir)
    build_dir.mkdir(parents=True)
    files = convert(block, build_dir / "vhdl", **params)
    net = ghdl_netlist(files, block, build_dir)
    full = dict(config, block=block, params=jsonable(params), report=str(build_dir / "report.json"))
    runner = get_runner("icarus")
    runner.build(sources=[str(net)], hdl_toplevel=block, build_dir=build_dir, always=True,
                 timescale=("1ns", "1ps"))
    env = {"EYESTEREO_TB": json.dumps(full),
           "PYTHONPATH": os.pathsep.join([str(SIM_DIR), os.environ.get("PYTHONPATH", "")])}
    results = runner.test(hdl_toplevel=block, test_module=f"eyestereo.sim.benches.{bench}", build_dir=build_dir,
                          test_dir=build_dir, extra_env=env)
    n_tests, n_failed = get_results(results)
    assert n_tests > 0, f"no cocotb test ran for the {block} netlist/{name}"
    assert n_failed == 0, f"{n_failed} of {n_tests} cocotb tests failed on the {block} netlist/{name} (see {build_dir})"
    report = build_dir / "report.json"
    return json.loads(report.read_text()) if report.exists() else {}
