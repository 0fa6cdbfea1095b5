"""GHDL regressions of fetch_interpolate and the rectifier against their bit-true models.

sim/benches/tb_fetch_interpolate.py drives the block with random-walk coordinate pairs (every case of the reuse
rule, jumps, black sides, random gaps); sim/benches/tb_rectifier.py runs the whole unit on small rectified frames.
Both answer the fetch port with the memory model of sim/lib/fetch_memory.py (at once, with random wait
clocks, a request not taken at once, long stalls), which checks the port's rules; every output beat and
every request is compared with the model. Full frames (352x288, 640x480) are in the benchmark
(sim/measure/bench_rectifier.py, make bench).
"""

import pytest

from eyestereo.sim.lib.runner import run_bench

pytestmark = pytest.mark.sim

AT_ONCE = dict(ready_p=1.0, latency=0, wait_p=0.0)
RANDOM = dict(ready_p=0.6, latency=3, wait_p=0.35)
STALLS = dict(ready_p=0.8, latency=11, wait_p=0.1, stall_p=0.01, stall=(20, 200))

FI_CASES = {  # memory, frac, depth, offer_p, oor_p
    "at_once": (AT_ONCE, 5, 4, 1.0, 0.1),
    "random_frac0_depth1": (RANDOM, 0, 1, 1.0, 0.2),
    "stalls_frac8_depth16": (STALLS, 8, 16, 0.5, 0.05),
    "random_gaps": (RANDOM, 6, 2, 0.2, 0.3),
}


@pytest.mark.parametrize("case", sorted(FI_CASES))
def test_fetch_interpolate(request, case):
    mem, frac, depth, offer_p, oor_p = FI_CASES[case]
    seed = sorted(FI_CASES).index(case) + 21
    rep = run_bench("fetch_interpolate", "tb_fetch_interpolate",
                    dict(mem, seed=seed, width=24, height=8, frames=2, offer_p=offer_p, oor_p=oor_p,
                         first_in_range=case == "at_once"),
                    name=request.node.name, params=dict(quantizers="seed:3:2@40x20", frac=frac, depth=depth))
    assert rep["beats"] == 2 * rep["pairs"] and rep["black"] > 0
    if case == "at_once":
        # the documented latency (fetch_interpolate.FIRST_PIXEL): the first pixel 12 clocks after its pair
        assert rep["first_in_range"] and rep["first_pixel"] == 12
    # every non-empty mask of the reuse rule and the full one came up
    assert set(rep["masks"]) == {3, 5, 7, 10, 11, 12, 13, 14, 15}


RECT_CASES = {  # calibration, memory, frames
    "rig_at_once": ("rig:32x20", AT_ONCE, 2),
    "rig_random": ("rig:24x16", RANDOM, 1),
    "seeded_stalls": ("seed:5:3@24x16", STALLS, 1),
    "reset_mid_frame": ("rig:24x16", AT_ONCE, 1),
}


@pytest.mark.parametrize("case", sorted(RECT_CASES))
def test_rectifier(request, case):
    spec, mem, frames = RECT_CASES[case]
    seed = sorted(RECT_CASES).index(case) + 31
    extra = dict(reset_after=301) if case == "reset_mid_frame" else {}
    rep = run_bench("rectifier", "tb_rectifier", dict(mem, seed=seed, frames=frames, images=f"random:{seed}", **extra),
                    name=request.node.name, params=dict(quantizers=spec))
    assert rep["bit_exact"] and rep["beats"] == 2 * frames * rep["width"] * rep["height"]
    assert rep["reads"] == rep["reads_model"]
    if spec.startswith("rig"):
        assert rep["reads_per_inrange_pixel"] < 2.6  # the previous neighbourhood is reused
    if mem is AT_ONCE:
        assert rep["clocks_per_pixel"] <= 8.0 + 0.2


@pytest.mark.parametrize("kind", ["netlist", "verilog"])
def test_fetch_interpolate_other_back_ends(request, kind):
    """GHDL's netlist of the VHDL (what make synth measures) and MyHDL's Verilog, both in Icarus."""
    import shutil

    if shutil.which("iverilog") is None:
        pytest.skip("Icarus Verilog not installed")
    cfg = dict(RANDOM, seed=41, width=16, height=6, frames=2, offer_p=0.7, oor_p=0.15)
    params = dict(quantizers="seed:3:2@40x20", frac=5, depth=3)
    if kind == "netlist":
        from eyestereo.sim.lib.netlist import run_netlist_bench

        rep = run_netlist_bench("fetch_interpolate", "tb_fetch_interpolate", cfg, name=request.node.name, params=params)
    else:
        # the runner's Icarus run: MyHDL's Verilog compiled as Verilog-2005 (runner.ICARUS_ARGS)
        rep = run_bench("fetch_interpolate", "tb_fetch_interpolate", cfg, name=request.node.name, params=params,
                        sim="icarus")
    assert rep["beats"] == 2 * rep["pairs"] and len(rep["masks"]) >= 8
