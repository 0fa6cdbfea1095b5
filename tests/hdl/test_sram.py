"""GHDL (and Icarus) regressions of the SRAM controller and the SRAM subsystem against the SRAM model.

The controller: random reads and writes for both kinds of part and read latencies 1..3, checked by the
SRAM model's rules, a scoreboard and the controller's cycle-true model; and boards whose part differs
from what the controller was built for, which the model or the scoreboard must reject.
"""

import pytest

from eyestereo.sim.lib.sram_runner import run_sram_bench

pytestmark = pytest.mark.sim


def _ctrl(request, params, cfg, sim="ghdl"):
    return run_sram_bench("sram_controller", "tb_sram_controller", cfg, name=request.node.name,
                          params=dict(tag_bits=5, **params), sim=sim)


# --- sram_controller -------------------------------------------------------------------------------
@pytest.mark.parametrize("kind", ["nobl", "pipelined"])
@pytest.mark.parametrize("lat", [1, 2, 3])
def test_controller_random(request, kind, lat):
    rep = _ctrl(request, dict(kind=kind, read_latency=lat), dict(seed=lat, commands=300, duty=0.8))
    assert rep["reads"] > 100 and rep["writes"] > 100
    assert rep["sram"]["reads"] == rep["reads"]
    if kind == "nobl":
        assert rep["stall_clocks"] == 0  # NoBL: every command taken when offered
    else:
        assert rep["stall_clocks"] > 0  # the turnaround


@pytest.mark.parametrize("kind", ["nobl", "pipelined"])
@pytest.mark.parametrize("seed", [11, 12])
def test_controller_back_to_back(request, kind, seed):
    """Commands every clock, write share 0.3 and 0.7: the densest read/write mixes."""
    rep = _ctrl(request, dict(kind=kind, read_latency=2), dict(seed=seed, commands=400, duty=1.0,
                                                                 write_share=0.3 if seed % 2 else 0.7))
    assert rep["reads"] > 50 and rep["writes"] > 50, rep


# The Verilog conversion: on Icarus in make test, on Verilator in make test-sims (marker othersims).
VERILOG_SIMS = ["icarus", pytest.param("verilator", marks=pytest.mark.othersims)]


@pytest.mark.parametrize("sim", VERILOG_SIMS)
@pytest.mark.parametrize("kind", ["nobl", "pipelined"])
def test_controller_verilog(request, kind, sim):
    """The Verilog conversion passes the same bench."""
    rep = _ctrl(request, dict(kind=kind, read_latency=2), dict(seed=3, commands=200, duty=0.8), sim=sim)
    assert rep["sim"] == sim and rep["reads"] > 50 and rep["writes"] > 50


def _failure_text(request, block) -> str:
    from eyestereo.sim.lib.runner import BUILD, slug

    return " ".join(p.read_text() for p in (BUILD / block / slug(request.node.name)).glob("*.xml"))


@pytest.mark.parametrize("built,board,why", [
    (("nobl", 2), ("pipelined", 2), "write data in the right cycle"),
    (("pipelined", 2), ("nobl", 2), "write data in the right cycle"),
    (("nobl", 2), ("nobl", 3), "SRAM rule broken"),
    (("pipelined", 2), ("pipelined", 1), "SRAM rule broken")],
    ids=["nobl-on-pipelined", "pipelined-on-nobl", "latency2-on-3", "latency2-on-1"])
def test_controller_for_the_wrong_part_fails(request, built, board, why):
    """The bench can fail: a controller built for another part breaks the model's rules."""
    # (under pytest the cocotb runner ends a failed simulation with SystemExit, else AssertionError)
    with pytest.raises((AssertionError, SystemExit)):
        _ctrl(request, dict(kind=built[0], read_latency=built[1]),
              dict(seed=1, commands=100, part_kind=board[0], part_latency=board[1]))
    assert why in _failure_text(request, "sram_controller")


# --- sram_subsystem: all six masters at once ---------------------------------------------------------
SMALL = dict(width=17, height=9, feature_words=32)


def _sub(request, params, cfg, sim="ghdl"):
    return run_sram_bench("sram_subsystem", "tb_sram_subsystem", cfg, name=request.node.name,
                          params=dict(SMALL, **params), sim=sim)


@pytest.mark.parametrize("kind", ["nobl", "pipelined"])
@pytest.mark.parametrize("seed", [1, 2])
def test_subsystem_random_traffic(request, kind, seed):
    """Overlapped mode: cameras at 9 M words/s, the rectified stream, feature lists (some longer than a
    buffer), the fetch pass over every held pair, the host's random accesses and buffer reads."""
    rep = _sub(request, dict(kind=kind, read_latency=2),
               dict(seed=seed, clocks=6000, rect_duty=0.15, feat_duty=0.05, host_duty=0.05))
    assert rep["takes"]["cam"] >= 2 and rep["frames"]["cam0"] >= 3 and rep["frames"]["cam1"] >= 3
    assert rep["takes"]["rect"] >= 1 and rep["takes"]["feat"] >= 1
    assert rep["fetch_reads"] > 1500 and rep["host_area_reads"] > 20 and rep["host_buffer_reads"] > 100
    assert max(rep["cam_max_fill"]) <= 4


@pytest.mark.parametrize("kind,lat", [("nobl", 1), ("pipelined", 3)])
def test_subsystem_read_latency(request, kind, lat):
    rep = _sub(request, dict(kind=kind, read_latency=lat), dict(seed=3, clocks=4000))
    assert rep["fetch_reads"] > 0, rep


@pytest.mark.parametrize("kind", ["nobl", "pipelined"])
def test_subsystem_sequential_mode(request, kind):
    """Sequential mode: the cameras armed for one frame each, the pair taken, the fetch pass, then the
    host reads the rectified image and the feature list; frames arriving meanwhile are not captured."""
    rep = _sub(request, dict(kind=kind, read_latency=2), dict(seed=4, clocks=9000, mode="sequential"))
    assert rep["arms"] >= 3 and rep["takes"]["cam"] >= 3
    for c in ("cam0", "cam1"):
        assert rep["arms"] - 1 <= rep["frames"][c] <= rep["arms"]
        assert rep["frames"][c] < rep["frames_sent"][c]  # frames arriving during a pass were skipped
    assert rep["takes"]["rect"] >= 2 and rep["takes"]["feat"] >= 2


def test_subsystem_reset_token_and_full_speed_fetch(request):
    """A reset token cuts the first rectified frame; the rectifier fetches without pause (continuous
    random requests) while both cameras stream: no camera FIFO overflows."""
    rep = _sub(request, dict(kind="pipelined", read_latency=2),
               dict(seed=5, clocks=6000, token_after=40, fetch_mode="continuous", rect_duty=0.25))
    assert rep["stat"]["rectified frames: dropped << 16 | published"] & 0xFFFF >= 1
    assert rep["fetch_reads"] > 1500


@pytest.mark.parametrize("sim", VERILOG_SIMS)
def test_subsystem_verilog(request, sim):
    """The Verilog conversion passes the same bench."""
    rep = _sub(request, dict(kind="pipelined", read_latency=2), dict(seed=6, clocks=3000), sim=sim)
    assert rep["sim"] == sim and rep["takes"]["cam"] >= 1 and rep["fetch_reads"] > 0


def test_subsystem_bench_catches_early_release(request):
    """The bench can fail: a consumer that releases the camera pair while still fetching lets the
    cameras overwrite the frame it reads, and the bench reports the read of a half-written frame."""
    with pytest.raises((AssertionError, SystemExit)):
        _sub(request, dict(kind="nobl", read_latency=2),
             dict(seed=1, clocks=8000, early_release=True, fetch_duty=0.05))
    assert "half-written frame" in _failure_text(request, "sram_subsystem")


# --- double_buffer against its clock-true model --------------------------------------------------------
@pytest.mark.parametrize("seed,rate", [(1, 0.2), (2, 0.6)])
def test_double_buffer_model(request, seed, rate):
    rep = run_sram_bench("double_buffer", "tb_double_buffer", dict(seed=seed, clocks=3000, frame_rate=rate),
                         name=request.node.name)
    assert rep["grants"] > 20 and rep["takes"] > 5 and rep["published"] > 10
    assert rep["denies"] + rep["overwritten"] > 0  # the contested cases happened


@pytest.mark.parametrize("kind", ["nobl", "pipelined"])
def test_subsystem_documented_latency(request, kind):
    """On a quiet bus the fetch port's first pixel and a host read take the clocks the docstrings state."""
    from eyestereo.hdl.interfaces.fetch_port import __doc__ as fetch_doc
    from eyestereo.hdl.memory.sram_arbiter import sram_arbiter

    doc = " ".join(sram_arbiter.__doc__.split())
    assert "fetch request's first pixel comes 11 clocks after" in doc and "host read's word 7 clocks after" in doc
    assert "the first pixel comes 11 clocks after its request is taken" in " ".join(fetch_doc.split())
    rep = _sub(request, dict(kind=kind, read_latency=2),
               dict(seed=3, clocks=3000, cam_frames=1, cam_rate=0.5, rect=False, feat=False, host_duty=0.01,
                    fetch_mode="continuous", hold=True, fetch_duty=0.02))
    assert min(rep["fetch_latency"]) == 11 and min(rep["host_latency"]) == 7


@pytest.mark.parametrize("kind", ["nobl", "pipelined"])
def test_subsystem_no_starvation_under_overload(request, kind):
    """Every master asks for more than the SRAM has (cameras 20 M words/s each, the fetch port without
    pause, a dense rectified stream, feature lists and host accesses back to back): the cameras and the
    rectified writer still lose nothing, and every other master keeps moving words with bounded waits."""
    rep = _sub(request, dict(kind=kind, read_latency=2),
               dict(seed=21, clocks=8000, window=3000, cam_rate=0.2, cam_fifo=256, fetch_mode="continuous",
                    hold=True, rect_duty=0.6, feat_duty=0.5, feat_max=40, host_duty=0.6))
    m = rep["measured"]["words_per_clock"]
    assert rep["measured"]["total_per_clock"] > 0.85          # the bus is full
    assert m["cam0"] > 0.19 and m["cam1"] > 0.19               # cameras at their rate
    assert m["rect"] > 0.25                                    # the stream's 0.3 words/clock, nothing lost
    # the round robin is by turns (fetch and features 8 words a turn, the host 1): every one keeps moving
    assert m["fetch"] > 0.05 and m["feat"] > 0.05 and m["host"] > 0.01
    assert max(rep["host_latency"]) < 200, max(rep["host_latency"])


@pytest.mark.othersims
@pytest.mark.parametrize("sim", ["icarus", "verilator"])
def test_double_buffer_verilog(request, sim):
    """double_buffer's Verilog conversion against the same clock-true model."""
    rep = run_sram_bench("double_buffer", "tb_double_buffer", dict(seed=2, clocks=3000, frame_rate=0.6),
                         name=request.node.name, sim=sim)
    assert rep["grants"] > 20 and rep["takes"] > 5 and rep["published"] > 10
