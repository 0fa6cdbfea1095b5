"""The SDRAM subsystem (sram_arbiter -> sdram_bridge -> sdram_controller) under the SRAM subsystem's bench.

Every master at once with random traffic (tb_sram_subsystem with ``memory="sdram"``): both cameras, the
rectified writer, feature lists, the fetch passes over every pair taken and the host's random accesses and
buffer reads, in the overlapped and the sequential mode, one simulation per seed. Each seed checks what the
SRAM tests check (every read against what was written, every writer's frames in order, the arbiter's
counters and published frames, no camera FIFO overflow) and, on every edge, the part's rules; at the end
no rule broken and no refresh late. The part is the ULX3S's with a 1 us power-up wait (the block and the
model read the same spec); tREFI stays the datasheet's 7.8 us, so a seed sees a handful of refreshes.
"""

import pytest

from eyestereo.sim.lib.sram_runner import run_sram_bench

pytestmark = pytest.mark.sim

#: The ULX3S's part, power-up wait shortened to 1 us (the controller and the model read the same spec).
PART = "AS4C32M16SB-7:powerup_us=1"
SMALL = dict(width=17, height=9, feature_words=32)
#: Overlapped mode: 14 seeds; sequential mode: 8 more; 2 with larger frames (24 seeds in all).
OVERLAPPED_SEEDS = range(1, 15)
SEQUENTIAL_SEEDS = range(15, 23)


def _sub(request, cfg, sim="ghdl", **params):
    rep = run_sram_bench("sdram_subsystem", "tb_sram_subsystem", dict(cfg, memory="sdram"), name=request.node.name,
                         params=dict(SMALL, part=PART, **params), sim=sim)
    sd = rep["sdram"]
    # (the bench itself fails on a broken rule or a late refresh; these say the run had them to check)
    assert sd["ready_edge"] is not None and sd["late_refreshes"] == 0
    assert sd["refreshes"] >= 3 and sd["max_owed"] <= 1, sd
    assert sd["commands"]["ACT"] >= 10 and sd["commands"]["PRE"] >= 10, sd["commands"]
    assert sd["read_words"] == rep["fetch_reads"] + rep["host_buffer_reads"] + rep["host_area_reads"]
    return rep


@pytest.mark.parametrize("seed", OVERLAPPED_SEEDS)
def test_random_traffic_overlapped(request, seed):
    """Overlapped mode, the SRAM test's traffic: cameras at 9 M words/s, the rectified stream, feature lists
    (some longer than a buffer), the fetch pass over every held pair, the host's accesses and buffer reads."""
    rep = _sub(request, dict(seed=seed, clocks=6000, rect_duty=0.15, feat_duty=0.05, host_duty=0.05))
    assert rep["takes"]["cam"] >= 2 and rep["frames"]["cam0"] >= 3 and rep["frames"]["cam1"] >= 3
    assert rep["takes"]["rect"] >= 1 and rep["takes"]["feat"] >= 1
    assert rep["fetch_reads"] > 1000 and rep["host_area_reads"] > 20 and rep["host_buffer_reads"] > 100
    assert not any(rep["cam_overflow"])


@pytest.mark.parametrize("seed", SEQUENTIAL_SEEDS)
def test_random_traffic_sequential(request, seed):
    """Sequential mode: the cameras armed for one frame each, the pair taken, the fetch pass, then the host
    reads the rectified image and the feature list; frames arriving meanwhile are not captured."""
    rep = _sub(request, dict(seed=seed, clocks=12000, mode="sequential"))
    assert rep["arms"] >= 3 and rep["takes"]["cam"] >= 3
    for c in ("cam0", "cam1"):
        assert rep["arms"] - 1 <= rep["frames"][c] <= rep["arms"]
        assert rep["frames"][c] < rep["frames_sent"][c]
    assert rep["takes"]["rect"] >= 2 and rep["takes"]["feat"] >= 2
    assert rep["fetch_reads"] > 1000 and rep["host_buffer_reads"] > 100


# The Verilog conversion: on Icarus in make test, on Verilator in make test-sims (marker othersims).
VERILOG_SIMS = ["icarus", pytest.param("verilator", marks=pytest.mark.othersims)]


@pytest.mark.parametrize("sim", VERILOG_SIMS)
def test_verilog(request, sim):
    """The Verilog conversion passes the same bench."""
    rep = _sub(request, dict(seed=23, clocks=4000), sim=sim)
    assert rep["sim"] == sim and rep["takes"]["cam"] >= 1 and rep["frames"]["cam0"] >= 2
    assert rep["fetch_reads"] > 500 and rep["host_buffer_reads"] > 100


def _failure_text(request) -> str:
    from eyestereo.sim.lib.runner import BUILD, slug

    return " ".join(p.read_text() for p in (BUILD / "sdram_subsystem" / slug(request.node.name)).glob("*.xml"))


@pytest.mark.parametrize("cfg,why", [
    (dict(early_release=True, fetch_duty=0.05, clocks=8000), "half-written frame"),
    (dict(model_part=PART + ",t_rcd=35", clocks=2000), "SDRAM rules broken"),       # 3 clocks of tRCD: 30 ns
    (dict(model_part=PART + ",refresh_ms=32", clocks=3000), "refreshes late")],      # tREFI 3.9 us, not 7.8
    ids=["early-release", "board-tRCD-35ns", "board-tREFI-3.9us"])
def test_bench_can_fail(request, cfg, why):
    """The bench fails a consumer that releases the camera pair while still fetching (the cameras overwrite
    the frame it reads), and a board whose part is slower than the one the block was built for."""
    with pytest.raises((AssertionError, SystemExit)):
        _sub(request, dict(cfg, seed=1))
    assert why in _failure_text(request)


@pytest.mark.parametrize("seed", [31, 32])
def test_frames_across_rows_and_banks(request, seed):
    """40x30 frames (1200 words): the camera buffers cross the 1024-word rows into the next banks, the
    rectified ones into row 1 of bank 0; lines, fetches and host reads open and close rows all the time."""
    rep = _sub(request, dict(seed=seed, clocks=10000, cam_rate=0.3, rect_duty=0.3, host_duty=0.05),
               width=40, height=30)
    assert rep["frames"]["cam0"] >= 2 and rep["frames"]["cam1"] >= 2 and rep["takes"]["cam"] >= 1
    assert rep["takes"]["rect"] >= 1 and rep["takes"]["feat"] >= 1
    assert rep["fetch_reads"] > 4000 and rep["host_buffer_reads"] > 1000
    assert rep["sdram"]["commands"]["ACT"] > 500


def test_overload_words_per_clock(request):
    """Every master asks for more than the memory has (the SRAM's no-starvation test: cameras 20 M words/s
    each, the fetch port without pause, a dense rectified stream, feature lists and host accesses back to
    back): the cameras and the rectified writer still lose nothing and every other master keeps moving
    words. The arbiter's FIFOs are 32 deep here: at the default 16 the rectified writer loses words on the
    SDRAM (its rounds are longer than the SRAM's: row changes, refreshes)."""
    rep = _sub(request, dict(seed=21, clocks=8000, window=3000, cam_rate=0.2, cam_fifo=256, fetch_mode="continuous",
                             hold=True, rect_duty=0.6, feat_duty=0.5, feat_max=40, host_duty=0.6), depth=32)
    m = rep["measured"]["words_per_clock"]
    assert rep["measured"]["total_per_clock"] > 0.85
    assert m["cam0"] > 0.19 and m["cam1"] > 0.19
    assert m["rect"] > 0.25
    assert m["fetch"] > 0.05 and m["feat"] > 0.05 and m["host"] > 0.01
    assert max(rep["host_latency"]) < 200, max(rep["host_latency"])
