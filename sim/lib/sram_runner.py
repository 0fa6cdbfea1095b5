"""Run the SRAM benches (controller, subsystem) on GHDL or Icarus.

These blocks have no image-stream ports, so they run as their own top level with per-clock Python
drivers (``harness=False`` where :func:`eyestereo.sim.lib.runner.run_bench` knows the HDL stream harness).
``sim="icarus"`` runs the Verilog conversion on Icarus Verilog; when ``run_bench`` itself takes ``sim=``
it is used, otherwise this module builds the Icarus run itself.
"""

from __future__ import annotations

import inspect
import json
import os
import shutil
from pathlib import Path

from eyestereo.sim.lib.runner import BUILD, SIM_DIR, jsonable, run_bench, slug


def run_sram_bench(block: str, bench: str, config: dict, *, name: str, params: dict | None = None,
                   sim: str = "ghdl", build_root: Path = BUILD) -> dict:
    """Convert ``block`` with ``params`` and run cocotb module ``eyestereo.sim.<bench>`` on ``sim``."""
    sig = inspect.signature(run_bench).parameters
    kw = {"harness": False} if "harness" in sig else {}
    if sim == "ghdl" or "sim" in sig:
        if "sim" in sig:
            kw["sim"] = sim
        return run_bench(block, bench, config, name=name, params=params, build_root=build_root, **kw)
    if sim != "icarus":
        raise ValueError(f"unknown simulator {sim!r}: ghdl or icarus")
    return _run_icarus(block, bench, config, name=name, params=params or {}, build_root=build_root)


def _run_icarus(block, bench, config, *, name, params, build_root):
    from cocotb_tools.runner import get_results, get_runner

    from eyestereo.hdl.flow.convert import convert

    if shutil.which("iverilog") is None:
        raise RuntimeError("Icarus Verilog not found: install it (Debian: apt-get install iverilog)")
    build_dir = Path(build_root) / slug(block) / f"{slug(name)}.icarus"
    if build_dir.exists():
        shutil.rmtree(build_dir)
    build_dir.mkdir(parents=True)
    sources = convert(block, build_dir, hdl="Verilog", **params)
    full = dict(config, block=block, params=jsonable(params), report=str(build_dir / "report.json"), sim="icarus")
    env = {"EYESTEREO_TB": json.dumps(full),
           "PYTHONPATH": os.pathsep.join([str(SIM_DIR), os.environ.get("PYTHONPATH", "")])}
    runner = get_runner("icarus")
    runner.build(sources=[str(s) for s in sources], hdl_toplevel=block, build_dir=build_dir, always=True,
                 timescale=("1ns", "1ps"))
    results = runner.test(hdl_toplevel=block, hdl_toplevel_lang="verilog", test_module=f"eyestereo.sim.benches.{bench}",
                          build_dir=build_dir, test_dir=build_dir, extra_env=env)
    n_tests, n_failed = get_results(results)
    assert n_tests > 0, f"no cocotb test ran for {block}/{name} on icarus"
    assert n_failed == 0, f"{n_failed} of {n_tests} cocotb tests failed for {block}/{name} on icarus (see {build_dir})"
    report = build_dir / "report.json"
    out = json.loads(report.read_text()) if report.exists() else {}
    out.setdefault("sim", "icarus")
    return out
