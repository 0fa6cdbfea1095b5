"""GHDL (and Icarus) regressions of the SRAM controller and the SRAM subsystem against the SRAM model.

The controller: random reads and writes for both kinds of part and read latencies 1..3, checked by the
SRAM model's rules, a scoreboard and the controller's cycle-true model; and boards whose part differs
from what the controller was built for, which the model or the scoreboard must reject.
"""

import pytest

from eyestereo.sim.sram_runner import run_sram_bench

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
    _ctrl(request, dict(kind=kind, read_latency=2), dict(seed=seed, commands=400, duty=1.0,
                                                           write_share=0.3 if seed % 2 else 0.7))


@pytest.mark.parametrize("kind", ["nobl", "pipelined"])
def test_controller_icarus(request, kind):
    """The Verilog conversion on Icarus passes the same bench."""
    _ctrl(request, dict(kind=kind, read_latency=2), dict(seed=3, commands=200, duty=0.8), sim="icarus")


def _failure_text(request, block) -> str:
    from eyestereo.sim.runner import BUILD, slug

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
