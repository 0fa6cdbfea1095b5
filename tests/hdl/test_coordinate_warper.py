"""GHDL regressions of the coordinate warper against its bit-true model (sim/benches/tb_coordinate_warper.py).

Each case records every pair the warper hands over (an HDL consumer and recorder around it, see
sim/harnesses/warper_harness.py) and compares all of them, with all their fields, with the model: nothing lost,
repeated or reordered. Consumers: at once (combinational and registered pulses), after random delays,
with long bursts of no acknowledgement; random ``enable``; back-to-back frames; ``start`` while busy;
``rst`` in the middle of a frame; run-time coefficients. Small rectified frames of seeded rigs (whose
maps leave the camera image) for the many cases; one full 352x288 frame of the default calibration.
"""

import pytest

import eyestereo.sim.harnesses.warper_harness  # noqa: F401  (registers the bench top)
from eyestereo.sim.lib.runner import fastest_simulator, run_bench

pytestmark = pytest.mark.sim

TOP = "coordinate_warper_tb"


def _run(request, params, sim=None, **cfg):
    rep = run_bench(TOP, "tb_coordinate_warper", cfg, name=request.node.name, params=params, sim=sim)
    assert rep["pairs"] == rep["frames"] * rep["width"] * rep["height"]
    return rep


CONSUMERS = {  # consumer behaviour, frac
    "at_once": (dict(ack_p=256), 5),
    "pulse": (dict(ack_p=256, ack_reg=True), 0),
    "random": (dict(ack_p=40), 3),
    "random_pulse": (dict(ack_p=90, ack_reg=True), 8),
    "bursts": (dict(ack_p=200, burst=True), 5),
}


@pytest.mark.parametrize("consumer", sorted(CONSUMERS))
def test_warper_consumers(request, consumer):
    seed = sorted(CONSUMERS).index(consumer) + 1
    behaviour, frac = CONSUMERS[consumer]
    rep = _run(request, dict(quantizers=f"seed:{seed}:2@40x20", batch=8, frac=frac), frames=2, seed=seed,
               **behaviour)
    assert rep["oor_l"] > 0 and rep["oor_r"] > 0  # maps leave the camera image


@pytest.mark.parametrize("en_p", [200, 60])
def test_warper_random_enable(request, en_p):
    _run(request, dict(quantizers="seed:7:3@24x10", batch=4), frames=2, seed=en_p, en_p=en_p, ack_p=120)


def test_warper_at_once_is_four_clocks_per_pair(request):
    rep = _run(request, dict(quantizers="seed:8@40x20", batch=8), frames=3, seed=8)
    assert rep["clocks_per_pair"] < 4.0 + 40 / (3 * 40 * 20)  # 4 per pair; the frame gaps add a little
    n = 40 * 20
    # first pair offered 14 clocks after the start clock, taken in that clock; done 1 clock after the last
    assert rep["frame_clocks"] == [4 * n + 11] * 3


def test_warper_reset_and_start_while_busy(request):
    _run(request, dict(quantizers="seed:9:2@24x10", batch=4), frames=1, seed=9, ack_p=128, reset_after=37,
         start_while_busy=True)


def test_warper_register_coefficients(request):
    _run(request, dict(quantizers="seed:10@24x10", batch=4, coefficients="register"), frames=1, seed=10,
         ack_p=180, coefficients="random")


def test_warper_full_frame_default_calibration(request):
    """Every pair of a full 352x288 frame of the synthetic rig, the consumer at once.

    On the fastest simulator (Verilator when installed: seconds instead of GHDL's minutes); the VHDL
    runs the same bench on every other case here, and tests/hdl/test_simulators.py checks that the
    simulators agree on the warper."""
    rep = _run(request, dict(quantizers="rig", batch=32), sim=fastest_simulator(), frames=1, seed=12)
    assert rep["clocks_per_pair"] == 4.0
    assert rep["oor_l"] > 0 and rep["oor_r"] > 0


def test_warper_netlist(request):
    """GHDL's netlist of the VHDL (harness and warper; what make synth measures of the warper), in
    Icarus: every pair of two frames, random consumer pulses and random enable."""
    import shutil

    from eyestereo.sim.lib.netlist import run_netlist_bench

    if shutil.which("iverilog") is None:
        pytest.skip("Icarus Verilog not installed")
    rep = run_netlist_bench(TOP, "tb_coordinate_warper", dict(frames=2, seed=13, ack_p=100, ack_reg=True, en_p=220),
                            name=request.node.name, params=dict(quantizers="seed:13:2@40x20", batch=8))
    assert rep["pairs"] == 2 * 40 * 20 and rep["oor_l"] > 0


# --- the Verilog conversion on Icarus and Verilator (make test-sims) -----------------------------------------
@pytest.mark.othersims
@pytest.mark.parametrize("sim", ["icarus", "verilator"])
@pytest.mark.parametrize("case", ["random_pulse", "enable_reset", "register"])
def test_warper_verilog(request, sim, case):
    """The same bench and checks on MyHDL's Verilog: a random consumer, random enable with a reset and a
    start while busy, run-time coefficients (every pair compared with the model)."""
    if case == "random_pulse":
        rep = _run(request, dict(quantizers="seed:4:2@40x20", batch=8, frac=8), sim=sim, frames=2, seed=4,
                   ack_p=90, ack_reg=True)
        assert rep["oor_l"] > 0 and rep["oor_r"] > 0
    elif case == "enable_reset":
        _run(request, dict(quantizers="seed:7:3@24x10", batch=4), sim=sim, frames=2, seed=60, en_p=60, ack_p=120,
             reset_after=37, start_while_busy=True)
    else:
        _run(request, dict(quantizers="seed:10@24x10", batch=4, coefficients="register"), sim=sim, frames=1,
             seed=10, ack_p=180, coefficients="random")
