"""The SDRAM controller against the SDRAM model (GHDL, and the Verilog conversion on Icarus / Verilator).

Each test is one simulation running several seeds in turn (the controller reset between them, the model
fresh, so every seed checks the power-up sequence too). The test parts shrink only the part's own
figures (the power-up wait, the refresh period), through the part spec that both the controller and the
model read, so the model checks the controller against the figures it was built for.
"""

import pytest

from eyestereo.sim.lib.runner import run_bench
from eyestereo.tools.sdram import part as sdram_part

pytestmark = pytest.mark.sim

#: The ULX3S's part with a 1 us power-up wait and tREFI = 1 us (refresh_ms / 8192 rows): ~10 refreshes a seed.
FAST = "AS4C32M16SB-7:powerup_us=1,refresh_ms=8.192"
#: The 32 MB part (512 columns) with tREFI = 0.6 us: bursts of up to 64 words, longer than some refresh
#: intervals' slack, so refreshes interrupt running bursts.
FAST_32MB = "MT48LC16M16A2-7E:powerup_us=1,refresh_ms=4.9152"


def _run(request, params, cfg, sim="ghdl"):
    return run_bench("sdram_controller", "tb_sdram_controller", cfg, name=request.node.name, params=params, sim=sim)


def _check(rep, seeds):
    runs = rep["runs"]
    assert [r["seed"] for r in runs] == list(seeds)
    for r in runs:
        assert r["bursts"] > 0 and r["words_read"] > 50 and r["words_written"] > 50, r
        assert r["refreshes"] >= 2 and r["late"] == 0 and r["max_owed"] <= 2, r
        assert r["commands"]["ACT"] > 10 and r["commands"]["PRE"] > 10, r["commands"]
    return runs


def test_random_20_seeds_cl2_100mhz(request):
    """20 seeds of random traffic, the ULX3S's part at 100 MHz, CAS latency 2, bursts of up to 8."""
    seeds = range(1, 21)
    rep = _run(request, dict(part=FAST, clock_mhz=100.0, cas_latency=2, max_burst=8),
               dict(seeds=list(seeds), bursts=150))
    runs = _check(rep, seeds)
    assert sum(r["words_read"] for r in runs) > 2000


def test_random_cl3_133mhz(request):
    """CAS latency 3 at 133 MHz (the -7 part's timings in 3-clock counts)."""
    seeds = range(21, 27)
    _check(_run(request, dict(part=FAST, clock_mhz=133.0, cas_latency=3, max_burst=8),
                dict(seeds=list(seeds), bursts=150)), seeds)


def test_random_long_bursts_32mb_part(request):
    """The 32 MB part (512 columns, 24 address bits), bursts of up to 64 words, a short tREFI: refreshes
    fall due inside bursts and some bursts are paused for them."""
    seeds = range(31, 35)
    _check(_run(request, dict(part=FAST_32MB, clock_mhz=100.0, cas_latency=2, max_burst=64),
                dict(seeds=list(seeds), bursts=100)), seeds)


def test_one_word_bursts(request):
    """max_burst 1, as sdram_subsystem builds it (the SRAM arbiter's words through sdram_bridge): random traffic
    for 6 seeds, then single words at sequential addresses, reads and writes: a word per clock on an open row,
    less the refreshes (PRECHARGE ALL, tRP, tRFC: about 10 clocks each 100 here) and the row changes."""
    seeds = range(51, 57)
    params = dict(part=FAST, clock_mhz=100.0, cas_latency=2, max_burst=1)
    _check(_run(request, params, dict(seeds=list(seeds), bursts=300)), seeds)
    runs = run_bench("sdram_controller", "tb_sdram_controller",
                     dict(patterns=["seq1", "wseq1"], seeds=[1], clocks=3000),
                     name=request.node.name + "_sequential", params=params)["runs"]
    for r in runs:
        words = r["words_read"] + r["words_written"]
        assert r["violations"] == [] and r["late"] == 0 and r["refreshes"] >= 25, r
        assert 0.8 < words / r["clocks"] <= 1.0, (r["pattern"], words, r["clocks"])


def test_real_figures_several_refreshes(request):
    """The ULX3S's part as the datasheet gives it: the 200 us power-up wait, tREFI 7.8 us; traffic, then a
    quiet stretch, 60 us in all: the controller keeps refreshing with nothing to do."""
    rep = _run(request, dict(part="AS4C32M16SB-7", clock_mhz=100.0, cas_latency=2, max_burst=8),
               dict(seeds=[41], bursts=80, tail_clocks=5000))
    (r,) = rep["runs"]
    assert r["ready_edge"] * 10.0 >= 200_000  # the wait, at 10 ns per edge
    assert r["run_clocks"] * 10.0 > 6 * sdram_part("AS4C32M16SB-7").t_refi
    assert r["refreshes"] >= 6 and r["late"] == 0 and r["max_owed"] <= 1, r


@pytest.mark.parametrize("mhz, cl", [(100.0, 2), (133.0, 3)])
def test_read_latency(request, mhz, cl):
    """The documented latencies (the controller's docstring, the port's timing diagram): from the clock a
    command is taken to its first rd_valid, CL + 3 on an open row, + tRCD on an idle bank, + tRP + tRCD on a
    row miss; to the first wr_ready, 1 on an open row, 1 + tRCD on an idle bank (tRCD, tRP: the datasheet's
    21 ns in clocks). The bench asserts them too."""
    spec = "AS4C32M16SB-7:powerup_us=1"
    rep = _run(request, dict(part=spec, clock_mhz=mhz, cas_latency=cl, max_burst=8),
               dict(patterns=["latency"], seeds=[71]))
    (r,) = rep["runs"]
    assert not r["violations"] and r["late"] == 0, r
    rcd = rp = 3  # 21 ns: 2.1 clocks at 100 MHz, 2.8 at 133 MHz, rounded up
    got = [(rd, n) for _, rd, n in sorted(r["latency"])]
    assert got == [(False, 1 + rcd), (True, cl + 3), (True, cl + 3 + rcd), (True, cl + 3 + rp + rcd), (False, 1)]


# The Verilog conversion: on Icarus in make test, on Verilator in make test-sims (marker othersims).
@pytest.mark.parametrize("sim", ["icarus", pytest.param("verilator", marks=pytest.mark.othersims)])
def test_random_verilog(request, sim):
    seeds = range(51, 54)
    rep = _run(request, dict(part=FAST, clock_mhz=100.0, cas_latency=2, max_burst=8),
               dict(seeds=list(seeds), bursts=120), sim=sim)
    assert rep["sim"] == sim
    _check(rep, seeds)


def test_bench_catches_a_slow_part(request):
    """The bench can fail: the controller counts its clocks for a faster part (-6) than the board's (-7),
    and the model, which checks the -7 figures, reports the broken spacings."""
    import json

    from eyestereo.sim.lib.runner import BUILD, slug

    # (under pytest the cocotb runner ends a failed simulation with SystemExit, else AssertionError)
    with pytest.raises((AssertionError, SystemExit)):
        _run(request, dict(part="AS4C32M16SB-6:powerup_us=1,refresh_ms=8.192", clock_mhz=100.0, cas_latency=2,
                           max_burst=8), dict(seeds=[61], bursts=100, model_part=FAST))
    report = BUILD / "sdram_controller" / slug(request.node.name) / "report.json"
    rules = {v.split(": ")[1] for v in json.loads(report.read_text())["runs"][0]["violations"]}
    assert rules and rules <= {"tRCD", "tRP", "tRC", "tRFC"}, rules
