"""Build a catalogue block for GHDL and run one of its cocotb benches on it.

Each configuration gets its own folder under ``build/sim/`` (conversion, GHDL library, results,
waveforms), so configurations can run in parallel. ``WAVES=1`` keeps a GHDL waveform (``.ghw``).
"""

from __future__ import annotations

import json
import os
import re
import shutil
from pathlib import Path

from cocotb_tools.runner import get_results, get_runner

from eyestereo.hdl.convert import convert

SIM_DIR = Path(__file__).resolve().parent
ROOT = SIM_DIR.parent
BUILD = ROOT / "build" / "sim"
GHDL_ARGS = ["--std=08"]
# Uninitialised pipeline registers make numeric_std warn about metavalues until real data arrives; the
# benches check the outputs themselves (X/U on a specified pixel fails), so the warnings are noise.
GHDL_RUN_OPTIONS = ["--ieee-asserts=disable"]


def slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("_")[:120]


def run_bench(block: str, bench: str, config: dict, *, name: str, params: dict | None = None,
              waves: bool | None = None, build_root: Path = BUILD, log_file: Path | None = None) -> dict:
    """Convert ``block`` with ``params``, simulate it with cocotb module ``eyestereo.sim.<bench>``.

    ``config`` is handed to the bench as JSON (environment variable ``EYESTEREO_TB``); the bench may
    write a JSON report to ``report.json`` in the build folder, which is returned. Raises AssertionError
    when any cocotb test fails or no test ran. ``log_file``: the simulator's output goes there instead of
    to stdout (for commands that show their own progress).
    """
    if shutil.which("ghdl") is None:
        raise RuntimeError("ghdl not found: install it (Debian: apt-get install ghdl)")
    params = dict(params or {})
    build_dir = Path(build_root) / slug(block) / slug(name)
    if build_dir.exists():
        shutil.rmtree(build_dir)
    build_dir.mkdir(parents=True)
    sources = convert(block, build_dir, **params)
    if waves is None:
        waves = os.environ.get("WAVES", "0") not in ("", "0")
    full = dict(config, block=block, params=_jsonable(params), report=str(build_dir / "report.json"))
    runner = get_runner("ghdl")
    runner.build(sources=[str(s) for s in sources], hdl_toplevel=block, build_dir=build_dir,
                 build_args=GHDL_ARGS, always=True, waves=waves,
                 log_file=None if log_file is None else str(Path(log_file).with_suffix('.build.log')))
    env = {"EYESTEREO_TB": json.dumps(full),
           "PYTHONPATH": os.pathsep.join([str(SIM_DIR), os.environ.get("PYTHONPATH", "")])}
    results = runner.test(hdl_toplevel=block, hdl_toplevel_lang="vhdl", test_module=f"eyestereo.sim.{bench}",
                          build_dir=build_dir, test_dir=build_dir, test_args=GHDL_ARGS, extra_env=env,
                          plusargs=GHDL_RUN_OPTIONS, waves=waves,
                          log_file=None if log_file is None else str(log_file))
    n_tests, n_failed = get_results(results)
    assert n_tests > 0, f"no cocotb test ran for {block}/{name}"
    assert n_failed == 0, f"{n_failed} of {n_tests} cocotb tests failed for {block}/{name} (see {build_dir})"
    report = build_dir / "report.json"
    return json.loads(report.read_text()) if report.exists() else {}


def _jsonable(p: dict) -> dict:
    import numpy as np

    return {k: (np.asarray(v).tolist() if isinstance(v, (np.ndarray, tuple)) else v) for k, v in p.items()}
